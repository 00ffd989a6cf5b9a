"""``fha-studio register roles setup|grant|revoke|list``: the register's roles on a PostgreSQL server
(technician, reviewer, administrator; :mod:`fha_studio.logic.register.roles` says who may what).

``setup``, ``grant`` and ``revoke`` are run as the register's owner (the role that made its tables,
with the right to make roles); ``list`` by anyone who may read the register. A register file has
no users: its protection is the file's permissions, and FHA Studio never changes a fact in it.
"""

from __future__ import annotations

import argparse
import json

from fha_studio.cli import CliError


def add_actions(sub: argparse._SubParsersAction, common: argparse.ArgumentParser) -> None:
    """The ``roles`` action of ``fha-studio register``."""
    from fha_studio.logic.register.roles import ROLE_WORDS, ROLES

    roles = sub.add_parser(
        "roles", parents=[common], help="who may add what to a plant's register on a server",
        description="The register's roles on a PostgreSQL server: "
        + "; ".join(f"a {r} {ROLE_WORDS[r]}" for r in ROLES)
        + ". Nobody changes or removes a fact. setup, grant and revoke are run as the register's owner.")
    actions = roles.add_subparsers(dest="roles_action", metavar="ROLES_ACTION", required=True)
    s = actions.add_parser("setup", parents=[common], help="make the roles, their rights and the server's "
                           "checks (as the register's owner; again after an upgrade)")
    s.set_defaults(func=_setup)
    for name, verb in (("grant", "give"), ("revoke", "take away")):
        s = actions.add_parser(name, parents=[common], help=f"{verb} a login one of the register's roles")
        s.add_argument("login", metavar="LOGIN",
                       help="the person's login on the server (createuser makes it)")
        s.add_argument("role", choices=ROLES, metavar="ROLE", help=" | ".join(ROLES))
        if name == "grant":
            s.add_argument("--person", default="", metavar="NAME",
                           help="who the login is, as reports and keys name them (needed the first time)")
        s.set_defaults(func=_grant if name == "grant" else _revoke)
    s = actions.add_parser("list", parents=[common], help="the logins with a role, and who they are")
    s.set_defaults(func=_list)


def _server_url(args) -> str:
    from fha_studio.logic.register import register_location

    target = register_location(args.register)
    if not isinstance(target, str):
        raise CliError(f"the register {target} is a file: roles are a server's (a file has no users; "
                       "its protection is the file's permissions)")
    return target


def _calling(function, *call_args):
    from fha_studio.logic.register import RegisterError

    try:
        return function(*call_args)
    except RegisterError as exc:
        raise CliError(str(exc)) from None


def _member_text(member) -> str:
    person = f" ({member.person})" if member.person else ""
    return f"{member.login}{person}: {', '.join(member.roles) or 'no role of this register'}"


def _setup(args) -> int:
    from fha_studio.logic.register import Register, RegisterError
    from fha_studio.logic.register.roles import ROLE_WORDS, ROLES
    from fha_studio.logic.register.roles_admin import setup
    from fha_studio.logic.register.server import shown_url

    url = _server_url(args)
    try:
        Register(url).close()  # made, or brought up to date, by its owner first
    except RegisterError as exc:
        raise CliError(str(exc)) from None
    made = _calling(setup, url)
    if args.json:
        print(json.dumps({"register": shown_url(url), "roles": dict(zip(ROLES, made, strict=True))},
                         indent=2))
        return 0
    print(f"Roles set up on the register {shown_url(url)}:")
    for role, name in zip(ROLES, made, strict=True):
        print(f"  {role:<13} {name}: {ROLE_WORDS[role]}")
    print("Give each person's login one: fha-studio register roles grant LOGIN ROLE --person NAME")
    return 0


def _grant(args) -> int:
    from fha_studio.logic.register.roles_admin import grant

    member = _calling(grant, _server_url(args), args.login, args.role, args.person)
    _say(args, member)
    return 0


def _revoke(args) -> int:
    from fha_studio.logic.register.roles_admin import revoke

    member = _calling(revoke, _server_url(args), args.login, args.role)
    _say(args, member)
    return 0


def _say(args, member) -> None:
    if args.json:
        print(json.dumps({"login": member.login, "person": member.person, "roles": list(member.roles)},
                         indent=2, ensure_ascii=False))
    else:
        print(_member_text(member))


def _list(args) -> int:
    from fha_studio.logic.register.roles_admin import listing

    found = _calling(listing, _server_url(args))
    if args.json:
        print(json.dumps([{"login": m.login, "person": m.person, "roles": list(m.roles)} for m in found],
                         indent=2, ensure_ascii=False))
        return 0
    if not found:
        print("No login has a role of this register yet (fha-studio register roles grant LOGIN ROLE "
              "--person NAME).")
    for member in found:
        print(_member_text(member))
    return 0
