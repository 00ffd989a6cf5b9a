"""A throw-away PostgreSQL server for the tests: one cluster per test session, on a unix socket
only (no TCP), in a temporary folder owned by the server's user (in memory where there is room:
``/dev/shm``); a database of its own for each
test that asks (``postgres_cluster.new_database()``, a ``postgresql://`` URL with a password).

The server refuses to run as root: ``initdb`` and ``pg_ctl`` run as ``postgres`` (``runuser``)
when the tests run as root. Its binaries are Debian's (``scripts/test`` installs ``postgresql``);
where they are missing the tests that need a server are skipped, saying so.
"""

from __future__ import annotations

import contextlib
import itertools
import os
import pwd
import shutil
import subprocess
import tempfile
from collections.abc import Iterator
from pathlib import Path

import pytest

#: Where Debian's package puts the server's programs (not on PATH).
BIN_DIRS = sorted(Path("/usr/lib/postgresql").glob("*/bin"), reverse=True)
SERVER_USER = "postgres"
#: The role the register is used as, and its password.
ROLE, PASSWORD = "fha", "fha-test-password"
SUPER_PASSWORD = "fha-test-superuser"


#: Where a cluster's folder goes when it can: memory (a tmpfs), so that the databases the tests
#: make (7.5 MB each, about 60 a session), the server's checkpoints and the folder's removal at the
#: end cost no disk writes (on this machine's disk, shared with other work, they took 0.4-1 s per
#: database and 16-30 s for the stop and removal under load; in memory 0.2 s and under 1 s).
MEMORY_DIR = Path("/dev/shm")
#: The room the memory folder must have left for a cluster to go there.
MEMORY_NEEDED_BYTES = 2 * 1024**3


def _cluster_parent() -> str | None:
    """The folder for a cluster's folder: memory where it has room, else the temporary folder."""
    try:
        roomy = shutil.disk_usage(MEMORY_DIR).free >= MEMORY_NEEDED_BYTES
    except OSError:
        return None
    return str(MEMORY_DIR) if roomy and os.access(MEMORY_DIR, os.W_OK | os.X_OK) else None


def _binaries() -> Path | None:
    for folder in BIN_DIRS:
        if (folder / "initdb").exists() and (folder / "pg_ctl").exists():
            return folder
    return None


class Cluster:
    """A running throw-away cluster: ``url(db)``, ``new_database()``, ``stop()`` / ``start()``."""

    def __init__(self, bin_dir: Path, root: Path, as_user: list[str]):
        self.bin_dir, self.root, self._as = bin_dir, root, as_user
        self.data, self.socket = root / "data", root / "socket"
        self._numbers = itertools.count(1)

    def _run(self, program: str, *args: str) -> None:
        done = subprocess.run(
            [*self._as, str(self.bin_dir / program), *args],
            capture_output=True, text=True, timeout=120, check=False,
        )
        if done.returncode != 0:
            said = done.stderr.strip() or done.stdout.strip()
            raise RuntimeError(f"{program} {' '.join(args)} failed: {said}")

    def init(self) -> None:
        pwfile = self.root / "pw"
        pwfile.write_text(SUPER_PASSWORD + "\n", encoding="utf-8")
        self._chown(pwfile)
        self._run("initdb", "-D", str(self.data), "-U", "postgres", "--auth-local=scram-sha-256",
                  "--auth-host=reject", f"--pwfile={pwfile}", "-E", "UTF8", "--locale=C.UTF-8", "--no-sync")
        pwfile.unlink()

    def start(self) -> None:
        # throw-away: nothing of it needs to survive a power cut, so no fsync (the suite's time)
        options = (f"-k {self.socket} -c listen_addresses='' -c fsync=off -c synchronous_commit=off "
                   "-c full_page_writes=off")
        self._run("pg_ctl", "-D", str(self.data), "-o", options, "-l", str(self.root / "log"), "-w", "start")

    def stop(self) -> None:
        self._run("pg_ctl", "-D", str(self.data), "-m", "fast", "-w", "stop")

    def url(self, database: str, user: str = ROLE, password: str = PASSWORD) -> str:
        return f"postgresql://{user}:{password}@/{database}?host={self.socket}"

    def new_database(self) -> str:
        """A new, empty database owned by the register's role; its URL."""
        import psycopg

        name = f"register_{next(self._numbers)}"
        with psycopg.connect(self.url("postgres", "postgres", SUPER_PASSWORD), autocommit=True) as db:
            db.execute(f'CREATE DATABASE "{name}" OWNER {ROLE}')
        return self.url(name)

    def _chown(self, path: Path) -> None:
        if os.geteuid() == 0:
            user = pwd.getpwnam(SERVER_USER)
            os.chown(path, user.pw_uid, user.pw_gid)


@contextlib.contextmanager
def throwaway_cluster() -> Iterator[Cluster]:
    """Starts a cluster with the register's role; stops it and removes its folder afterwards."""
    bin_dir = _binaries()
    if bin_dir is None:
        pytest.skip("PostgreSQL's initdb and pg_ctl are not installed "
                    "(scripts/test installs Debian's postgresql)")
    as_user: list[str] = []
    if os.geteuid() == 0:
        try:
            pwd.getpwnam(SERVER_USER)
        except KeyError:
            pytest.skip(f"no user {SERVER_USER!r} to run PostgreSQL as "
                        "(Debian's postgresql package makes it)")
        as_user = ["runuser", "-u", SERVER_USER, "--"]
    root = Path(tempfile.mkdtemp(prefix="fha-postgres-", dir=_cluster_parent()))
    root.chmod(0o755)  # the server's user reaches its folders, this process its socket
    cluster = Cluster(bin_dir, root, as_user)
    for folder in (cluster.data, cluster.socket):
        folder.mkdir()
        cluster._chown(folder)
    cluster._chown(root)
    started = False
    try:
        cluster.init()
        cluster.start()
        started = True
        import psycopg

        with psycopg.connect(cluster.url("postgres", "postgres", SUPER_PASSWORD), autocommit=True) as db:
            db.execute(f"CREATE ROLE {ROLE} LOGIN PASSWORD '{PASSWORD}'")
        yield cluster
    finally:
        if started:
            with contextlib.suppress(RuntimeError):
                cluster.stop()
        shutil.rmtree(root, ignore_errors=True)


@pytest.fixture(scope="session")
def postgres_cluster() -> Iterator[Cluster]:
    """One throw-away PostgreSQL cluster for the whole test session."""
    with throwaway_cluster() as cluster:
        yield cluster


@contextlib.contextmanager
def given_or_throwaway(url: str) -> Iterator[str]:
    """``url`` when one is given (a benchmark's command line); else a new database on a throwaway
    cluster, stopped afterwards."""
    if url:
        yield url
        return
    with throwaway_cluster() as cluster:
        yield cluster.new_database()
