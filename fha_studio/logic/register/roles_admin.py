"""What the register's owner does with the roles on the server (:mod:`.roles`): set them up,
give and take them; and what anyone may ask: who has which role. Each opens its own connection
to the server; the server's errors are one line (:func:`.server.problem`)."""

from __future__ import annotations

from typing import Any

from fha_studio.logic.register.roles import (
    ROLES,
    Catalog,
    Member,
    RolesError,
    group_role,
    ident,
    is_set_up,
    members,
    protection,
    role_tables,
)
from fha_studio.logic.register.server import problem


def _connect(url: str) -> Any:
    import psycopg

    return psycopg.connect(url, autocommit=True, connect_timeout=10)


def setup(url: str) -> list[str]:
    """Sets the roles up on the register at ``url`` (made and brought up to date before, by its
    owner: :class:`~.store.Register`), run as the register's owner with the right to make roles
    (CREATEROLE). Returns the roles' names. Can be run again (after an upgrade it gives the new
    tables their rights)."""
    import psycopg

    try:
        with _connect(url) as db:
            owner, me, create_role, superuser = db.execute(
                "SELECT (SELECT tableowner FROM pg_tables WHERE tablename = 'register_schema'"
                " AND schemaname = current_schema()), current_user, r.rolcreaterole, r.rolsuper"
                " FROM pg_roles r WHERE r.rolname = current_user").fetchone()
            if owner is None:
                raise RolesError("there is no register in this database yet (its owner makes it: "
                                 "fha-studio register add-machine NAME)")
            if owner != me:
                raise RolesError(f"the roles are set up by the register's owner, {owner}; "
                                 f"this is {me}")
            if not (create_role or superuser):
                raise RolesError(f"{me} may not make roles on this server: its administrator lets it "
                                 f"(sudo -u postgres psql -c 'ALTER ROLE {ident(me)} CREATEROLE')")
            with db.transaction():
                db.execute("SELECT pg_advisory_xact_lock(26027)")
                catalog = Catalog.read(db)
                made = []
                for role in ROLES:
                    name = group_role(catalog.database, role)
                    if db.execute("SELECT 1 FROM pg_roles WHERE rolname = %s", (name,)).fetchone() is None:
                        db.execute(f"CREATE ROLE {ident(name)} NOLOGIN".encode())
                    made.append(name)
                for statement in role_tables(catalog):
                    db.execute(statement.encode())
                for statement in protection(Catalog.read(db)):
                    db.execute(statement.encode())
            return made
    except psycopg.Error as exc:
        raise problem(url, exc) from None


def _person_of(db: Any, login: str) -> str:
    row = db.execute("SELECT person FROM register_person WHERE login = %s ORDER BY id DESC LIMIT 1",
                     (login,)).fetchone()
    return str(row[0]) if row else ""


def _checked_login(db: Any, database: str, login: str, role: str) -> str:
    """The group role of ``role``; RolesError when the roles are not set up or ``login`` is no login."""
    group = group_role(database, role)
    if db.execute("SELECT 1 FROM pg_roles WHERE rolname = %s", (group,)).fetchone() is None:
        raise RolesError("the roles are not set up on this register (its owner runs "
                         "fha-studio register roles setup)")
    row = db.execute("SELECT rolcanlogin FROM pg_roles WHERE rolname = %s", (login,)).fetchone()
    if row is None:
        raise RolesError(f"there is no login {login!r} on the server (createuser --pwprompt {login} "
                         "makes one)")
    if not row[0]:
        raise RolesError(f"{login!r} is no login of the server (a group role): give a person's login")
    return group


def grant(url: str, login: str, role: str, person: str = "") -> Member:
    """Gives ``login`` the register's ``role``; ``person``: who the login is (needed the first
    time; a new name is a new row of who each login is). Run by the owner."""
    import psycopg

    login, person = login.strip(), " ".join(person.split())
    try:
        with _connect(url) as db:
            database = db.execute("SELECT current_database()").fetchone()[0]
            group = _checked_login(db, database, login, role)
            with db.transaction():
                known = _person_of(db, login)
                if not person and not known:
                    raise RolesError(f"say who {login} is: --person NAME (as reports and keys name them)")
                if person and person != known:
                    db.execute("INSERT INTO register_person (login, person) VALUES (%s, %s)", (login, person))
                db.execute(f"GRANT {ident(group)} TO {ident(login)}".encode())
            return next(m for m in members(db, database) if m.login == login)
    except psycopg.Error as exc:
        raise problem(url, exc) from None


def revoke(url: str, login: str, role: str) -> Member:
    """Takes the register's ``role`` from ``login`` (what it recorded stays, with its receipts)."""
    import psycopg

    login = login.strip()
    try:
        with _connect(url) as db:
            database = db.execute("SELECT current_database()").fetchone()[0]
            group = _checked_login(db, database, login, role)
            db.execute(f"REVOKE {ident(group)} FROM {ident(login)}".encode())
            found = [m for m in members(db, database) if m.login == login]
            return found[0] if found else Member(login, "", ())
    except psycopg.Error as exc:
        raise problem(url, exc) from None


def listing(url: str) -> list[Member]:
    """Every login with a role of the register (or a person), for anyone who may read it."""
    import psycopg

    try:
        with _connect(url) as db:
            if not is_set_up(db):
                raise RolesError("the roles are not set up on this register (its owner runs "
                                 "fha-studio register roles setup)")
            return members(db, db.execute("SELECT current_database()").fetchone()[0])
    except psycopg.Error as exc:
        raise problem(url, exc) from None
