"""``fha-studio register keys add|list|revoke`` and ``fha-studio register verify REPORT``: each person's
signing key and whether a report file is the one that was signed (exit 0 yes, 5 no).

A passphrase comes from ``$FHA_STUDIO_KEY_PASSPHRASE`` when set (scripts), else it is asked on
the terminal (never echoed; asked twice for a new key; empty: the key file is protected by its
mode 0600 only); without a terminal and without the variable a new key is not encrypted.
"""

from __future__ import annotations

import argparse
import getpass
import json
import os
import sys
from pathlib import Path

from fha_studio.cli import CliError

#: Exit status of ``verify`` when the file is not the one signed (or carries no signature).
NOT_VERIFIED = 5
ENV_PASSPHRASE = "FHA_STUDIO_KEY_PASSPHRASE"


def add_actions(sub: argparse._SubParsersAction, common: argparse.ArgumentParser, opener) -> None:
    """The ``keys`` and ``verify`` actions of ``fha-studio register``; ``opener(args)`` opens the
    register the command names (a context manager)."""
    keys = sub.add_parser("keys", parents=[common], help="each person's signing key (add, list, revoke)")
    actions = keys.add_subparsers(dest="keys_action", metavar="KEYS_ACTION", required=True)
    add = actions.add_parser("add", parents=[common], help="make a person's key pair; the register keeps "
                             "the public key, the private key stays on this computer")
    add.add_argument("--name", required=True, metavar="PERSON",
                     help="who signs with it, as reports name them")
    add.add_argument("--key-file", type=Path, metavar="PATH",
                     help="where the private key goes (default: keys/KEY_ID.pem in the user data directory)")
    add.set_defaults(func=_keys_add, writes=True, open_register=opener)
    revoke = actions.add_parser("revoke", parents=[common], help="a key signs nothing from now on (a lost "
                                "laptop); what it signed before still verifies")
    revoke.add_argument("key_id", metavar="KEY_ID")
    revoke.add_argument("--reason", default="", help="why, for the register")
    revoke.set_defaults(func=_keys_revoke, writes=True, open_register=opener)
    ls = actions.add_parser("list", parents=[common], help="the public keys in the register")
    ls.set_defaults(func=_keys_list, open_register=opener)
    verify = sub.add_parser(
        "verify", parents=[common], help="is this report the one that was signed, and by whom",
        description="Exit 0 when REPORT (a commissioning report's HTML, or its PDF) is the file that was "
        f"signed, with a key of the register; {NOT_VERIFIED} when not, with one line why.")
    verify.add_argument("report", type=Path, metavar="REPORT")
    verify.set_defaults(func=_verify, open_register=opener)


def passphrase(prompt: str, confirm: bool = False) -> str:
    """The passphrase: the environment's, else asked on the terminal; "" when neither."""
    if ENV_PASSPHRASE in os.environ:
        return os.environ[ENV_PASSPHRASE]
    if not sys.stdin.isatty():
        return ""
    first = getpass.getpass(prompt)
    if confirm and first and getpass.getpass("The same passphrase again: ") != first:
        raise CliError("the two passphrases differ: no key made")
    return first


def _keys_add(args) -> int:
    from fha_studio.logic.register.signing import (
        SigningError,
        default_key_path,
        key_id_of,
        new_key,
        public_raw,
        write_private_key,
    )

    person = args.name.strip()
    if not person:
        raise CliError("--name: give the person's name")
    key = new_key()
    key_id = key_id_of(public_raw(key))
    path = args.key_file.expanduser() if args.key_file else default_key_path(key_id)
    if os.path.lexists(path):
        raise CliError(f"key file {path}: already exists (a key is never replaced; choose another path)")
    secret = passphrase(f"Passphrase for {person}'s new key (empty: none): ", confirm=True)
    with args.open_register(args) as reg:
        try:
            write_private_key(key, path, secret)
        except SigningError as exc:
            raise CliError(str(exc)) from None
        try:
            added = reg.add_key(person, public_raw(key).hex(), key_id)
        except BaseException:
            path.unlink(missing_ok=True)  # a private key the register does not know signs nothing
            raise
    if args.json:
        print(json.dumps({"key_id": added.key_id, "person": added.person, "public_key": added.public_key,
                          "created_utc": added.created_utc, "key_file": str(path),
                          "encrypted": bool(secret)}, indent=2, ensure_ascii=False))
    else:
        protected = "encrypted with the passphrase" if secret else "not encrypted: readable by this user only"
        print(f"key {added.key_id} for {added.person}; private key {path} ({protected})")
    return 0


def _keys_revoke(args) -> int:
    with args.open_register(args) as reg:
        reg.revoke_key(args.key_id.strip(), args.reason)
        key = reg.signing_key(args.key_id.strip())
    assert key is not None
    if args.json:
        print(json.dumps({"key_id": key.key_id, "person": key.person, "revoked_utc": key.revoked_utc,
                          "reason": key.revoked_reason}, indent=2, ensure_ascii=False))
    else:
        print(f"key {key.key_id} of {key.person} revoked at {key.revoked_utc[:19].replace('T', ' ')} UTC")
    return 0


def _keys_list(args) -> int:

    with args.open_register(args) as reg:
        keys = reg.signing_keys()
    if args.json:
        print(json.dumps([vars(k) | {"revoked": bool(k.revoked_utc)} for k in keys], indent=2,
                         ensure_ascii=False, default=str))
        return 0
    if not keys:
        print("No signing keys (fha-studio register keys add --name PERSON makes one).")
    for k in keys:
        revoked = f"  revoked {k.revoked_utc[:19]}" if k.revoked_utc else ""
        print(f"{k.key_id}  {k.person}  added {k.created_utc[:19].replace('T', ' ')} UTC{revoked}")
    return 0


def _verify(args) -> int:

    with args.open_register(args) as reg:
        verdict = reg.verify_file(args.report)
    if args.json:
        print(json.dumps(verdict.as_dict(), indent=2, ensure_ascii=False))
    elif verdict.valid:
        when = verdict.signed_utc[:19].replace("T", " ")
        print(f"{args.report}: signed by {verdict.signer} at {when} UTC with key {verdict.key_id}; "
              "the file is the one that was signed")
    else:
        print(f"fha-studio register verify: NOT VERIFIED: {verdict.reason}", file=sys.stderr)
    return 0 if verdict.valid else NOT_VERIFIED
