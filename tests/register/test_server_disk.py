"""A full disk on the server, for real: the register's tables on a tablespace of the tests' cluster
that lives on a tiny tmpfs, filled to the last byte. A write that needs a new page is refused in
one line (the command's too), nothing of it is half there, and nothing recorded before is lost;
once there is room again the same write goes through. Needs root (to mount the tmpfs): else the
test is skipped, saying so."""

from __future__ import annotations

import secrets
import shutil
import tempfile
from pathlib import Path
from urllib.parse import urlsplit

import psycopg
import pytest

from fha_studio.cli import main
from fha_studio.logic.register import Register, RegisterError
from tests.support.disk import fill, small_disk
from tests.support.postgres import ROLE, SERVER_USER, SUPER_PASSWORD

M = "Press 7"
RAM = f"{M}/ram"


def test_a_full_disk_on_the_server_is_one_line_and_loses_nothing(postgres_cluster, capsys):
    url = postgres_cluster.new_database()
    database = urlsplit(url).path.lstrip("/")
    with Register(url) as reg:
        reg.add_machine(M)
        reg.add_axis(M, "ram", "FHA-25C-50-US250", "HA-655-2-200", "/dev/ttyUSB0")
        before = reg.record_snapshot(RAM, [("tune", k, f"item_{k}", k) for k in range(50)], "link", who="ana")
        reg.record_alarm(RAM, 10, "overspeed", who="ana")
    root = Path(tempfile.mkdtemp(prefix="fha-full-disk-", dir=postgres_cluster.root))
    root.chmod(0o755)
    superuser = postgres_cluster.url(database, "postgres", SUPER_PASSWORD)
    with small_disk(root / "disk", SERVER_USER) as disk, psycopg.connect(superuser, autocommit=True) as db:
        tablespace = f"full_{database}"
        (disk / "pg").mkdir()
        shutil.chown(disk / "pg", SERVER_USER, SERVER_USER)
        db.execute(f"CREATE TABLESPACE {tablespace} LOCATION '{disk / 'pg'}'")
        try:
            # the register's tables and indexes move onto the small disk
            for kind in ("TABLE", "INDEX"):
                db.execute(f"ALTER {kind} ALL IN TABLESPACE pg_default OWNED BY {ROLE}"
                           f" SET TABLESPACE {tablespace}")
            junk = fill(disk)
            with Register(url) as reg:
                with pytest.raises(RegisterError) as full, reg.batch():  # a session's facts: all or none
                    reg.record_alarm(RAM, 11, "overload", who="ana")
                    reg.record_snapshot(RAM, [("tune", k, f"item_{k}", -k) for k in range(500)], "link")
                said = str(full.value)
                assert "\n" not in said and said.endswith(
                    "the server has no space left on its disk: nothing was changed")
                # the command's write: notes too long for a page (kept beside the row, in a new page)
                notes = secrets.token_hex(4000)
                code = main(["register", "--register", url, "add-axis", f"{M}/feed", "--notes", notes])
                err = capsys.readouterr().err
                assert code == 2 and err.count("\n") == 1 and "no space left on its disk" in err
                kinds = [e.kind.value for e in reg.history(RAM)]
                assert kinds == ["axis", "snapshot", "alarm"]  # all there, and nothing of the refused
                assert reg.snapshot(before).values["item_49"].value == 49
                assert [a.name for a in reg.axes(M)] == ["ram"]
                junk.unlink()  # room again: the same write goes through
                with reg.batch():
                    reg.record_alarm(RAM, 11, "overload", who="ana")
                    reg.record_snapshot(RAM, [("tune", k, f"item_{k}", -k) for k in range(500)], "link")
                assert [e.kind.value for e in reg.history(RAM)] == ["axis", "snapshot", "alarm", "alarm",
                                                                      "snapshot"]
        finally:
            with psycopg.connect(postgres_cluster.url("postgres", "postgres", SUPER_PASSWORD),
                                 autocommit=True) as admin:
                admin.execute(f'DROP DATABASE "{database}" WITH (FORCE)')
                admin.execute(f"DROP TABLESPACE IF EXISTS {tablespace}")
    shutil.rmtree(root, ignore_errors=True)
