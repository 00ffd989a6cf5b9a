"""Files this test's program really cannot write, and a way to run the program on them.

The tests run as root, and root writes a file whatever its mode says: ``chmod 444`` does not make
a register read-only for root, and patching the program's own check (``guard.writable``) tests
the patch, not the program. So where the tests run as root, the program runs in a subprocess as
uid/gid 65534 (nobody, no supplementary groups, through ``setpriv``) on files root owns in a
folder root owns (mode 0755: nobody reads, never writes, neither the files nor the folder, so
SQLite cannot make a journal). Not as root, the files and the folder are made read-only with
chmod, and the program runs as this user. Where neither holds (chmod does not stop this user,
nobody cannot be) the test is skipped, saying why.

The program gets a home of its own (``HOME``, the XDG folders) that its user may write, so its
per-user data (the journal of temporaries, Qt's settings) goes there, never to the real one.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]

#: nobody's uid and gid on Debian and most Linux systems
NOBODY = 65534


class ReadOnlyPlace:
    """A folder (``folder``) whose files the program run by :meth:`run` can read but not write."""

    def __init__(self) -> None:
        # not under pytest's tmp_path: its folders are 0700, nobody could not even reach them
        self.folder = Path(tempfile.mkdtemp(prefix="fha-read-only-"))
        self.folder.chmod(0o755)
        self.home = Path(tempfile.mkdtemp(prefix="fha-home-"))
        self.home.chmod(0o700)
        self.as_nobody = os.geteuid() == 0
        if self.as_nobody:
            os.chown(self.home, NOBODY, NOBODY)

    def seal(self) -> None:
        """After the files are made (by this process): the program may no longer write them."""
        if self.as_nobody:
            for path in [self.folder, *self.folder.rglob("*")]:
                os.chown(path, 0, 0)
                path.chmod(0o755 if path.is_dir() else 0o644)
            return
        for path in self.folder.rglob("*"):
            path.chmod(0o444 if path.is_file() else 0o555)
        self.folder.chmod(0o555)
        if any(os.access(p, os.W_OK) for p in [self.folder, *self.folder.rglob("*")]):
            pytest.skip("not root, and chmod does not make a file read-only for this user here: "
                        "no read-only register can be made")

    def env(self) -> dict[str, str]:
        home = str(self.home)
        return {
            "PATH": os.environ.get("PATH", "/usr/bin:/bin"),
            "HOME": home,
            "XDG_DATA_HOME": f"{home}/data",
            "XDG_CONFIG_HOME": f"{home}/config",
            "XDG_CACHE_HOME": f"{home}/cache",
            "XDG_RUNTIME_DIR": home,
            "QT_QPA_PLATFORM": "offscreen",
            "PYTHONPATH": str(ROOT),
            "PYTHONDONTWRITEBYTECODE": "1",  # nobody writes no __pycache__ into the checkout
            "LANG": "C.UTF-8",
        }

    def run(self, *args: str, timeout: float = 120.0) -> subprocess.CompletedProcess[str]:
        """``python ARGS`` (``-m fha_studio ...`` or ``-c SCRIPT ...``) as the user that cannot
        write the folder's files; stdout and stderr as text."""
        if self.as_nobody and not self._checked:
            self._check_nobody()
        return self._run([*self._as_user(), sys.executable, *args], timeout)

    def _as_user(self) -> list[str]:
        if not self.as_nobody:
            return []
        # setpriv drops to nobody as it executes Python, so an interpreter under a folder nobody
        # may not enter (a pyenv in /root) still starts; subprocess's user= cannot reach it
        setpriv = shutil.which("setpriv")
        if setpriv is None:
            pytest.skip(f"running as root, and no setpriv to run the program as uid {NOBODY} (nobody)")
        return [setpriv, f"--reuid={NOBODY}", f"--regid={NOBODY}", "--clear-groups"]

    def _run(self, command: list[str], timeout: float) -> subprocess.CompletedProcess[str]:
        return subprocess.run(command, cwd=self.home, env=self.env(), capture_output=True, text=True,
                              timeout=timeout)

    _checked = False

    def _check_nobody(self) -> None:
        """The program really runs as nobody and really cannot write the folder: else the test
        would pass on a register that was writable after all."""
        probe = ("import os, sys; print(os.geteuid(), os.getegid(), os.getgroups(), "
                 "os.access(sys.argv[1], os.W_OK))")
        done = self._run([*self._as_user(), sys.executable, "-c", probe, str(self.folder)], 60.0)
        if done.returncode != 0:
            pytest.skip(f"cannot run Python as uid {NOBODY} (nobody) here: {done.stderr.strip()[-200:]}")
        assert done.stdout.split("\n")[0] == f"{NOBODY} {NOBODY} [] False", done.stdout
        self._checked = True

    def __enter__(self) -> ReadOnlyPlace:
        return self

    def __exit__(self, *exc: object) -> None:
        self.remove()

    def remove(self) -> None:
        if not self.as_nobody:
            for path in [self.folder, *self.folder.rglob("*")]:
                if path.is_dir():
                    path.chmod(0o755)
        shutil.rmtree(self.folder, ignore_errors=True)
        shutil.rmtree(self.home, ignore_errors=True)
