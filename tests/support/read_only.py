"""Files this test's program really cannot write, and a way to run the program on them.

The tests run as root, and root writes a file whatever its mode says: ``chmod 444`` does not make
a register read-only for root, and patching the program's own check (``guard.writable``) tests
the patch, not the program. So the files and the folder are made read-only with chmod, and where
the tests run as root the program runs in a subprocess without the capabilities that let root
write past a file's mode (``setpriv --bounding-set=-dac_override,...``): still root, so it reads
the checkout and the virtual environment wherever they are (a home folder of mode 0700 included,
where a child as uid 65534 could not even import them), but the modes now hold for it too. Where
chmod does not stop this user and the capabilities cannot be dropped, the test is skipped, saying
why.

The program gets a home of its own (``HOME``, the XDG folders) that it may write, so its per-user
data (the journal of temporaries, Qt's settings) goes there, never to the real one.

:func:`without_overrides`, :func:`seal` and :func:`unseal` are the pieces, for the tests'
:class:`ReadOnlyPlace` and for scripts/hostile_inputs.py alike (no pytest in them).
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

#: what lets root write, create and chmod past a file's mode: dropped for the program run here
OVERRIDES = "-dac_override,-dac_read_search,-fowner"


class NoSetpriv(RuntimeError):
    """Running as root, and no setpriv to run a program without root's overrides."""


def without_overrides() -> list[str]:
    """The prefix of a command that runs it so that a file's mode holds for it: as root, through
    setpriv without the capabilities that write past the mode (still root: it reads a checkout in a
    0700 home); as another user, nothing. NoSetpriv when root has no setpriv."""
    if os.geteuid() != 0:
        return []
    setpriv = shutil.which("setpriv")
    if setpriv is None:
        raise NoSetpriv("running as root, and no setpriv to run the program without root's overrides")
    return [setpriv, f"--bounding-set={OVERRIDES}", f"--inh-caps={OVERRIDES}", "--"]


def seal(folder: Path) -> None:
    """``folder`` and everything in it: readable, not writable (files 444, folders 555)."""
    for path in folder.rglob("*"):
        path.chmod(0o444 if path.is_file() else 0o555)
    folder.chmod(0o555)


def unseal(folder: Path) -> None:
    """The folders writable again (so that they can be removed)."""
    for path in [folder, *folder.rglob("*")]:
        if path.is_dir():
            path.chmod(0o755)


class ReadOnlyPlace:
    """A folder (``folder``) whose files the program run by :meth:`run` can read but not write."""

    def __init__(self) -> None:
        # a folder of its own (not under pytest's tmp_path), made read-only whole
        self.folder = Path(tempfile.mkdtemp(prefix="fha-read-only-"))
        self.folder.chmod(0o755)
        self.home = Path(tempfile.mkdtemp(prefix="fha-home-"))
        self.home.chmod(0o700)
        self.as_root = os.geteuid() == 0

    def seal(self) -> None:
        """After the files are made (by this process): the program may no longer write them."""
        seal(self.folder)
        if self.as_root:
            return  # root writes them still: the program runs without the capabilities (run)
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
            "PYTHONDONTWRITEBYTECODE": "1",  # the program writes no __pycache__ into the checkout
            "LANG": "C.UTF-8",
        }

    def run(self, *args: str, timeout: float = 120.0) -> subprocess.CompletedProcess[str]:
        """``python ARGS`` (``-m fha_studio ...`` or ``-c SCRIPT ...``) as the user that cannot
        write the folder's files; stdout and stderr as text."""
        if self.as_root and not self._checked:
            self._check_dropped()
        return self._run([*self._as_user(), sys.executable, *args], timeout)

    def _as_user(self) -> list[str]:
        try:
            return without_overrides()
        except NoSetpriv as exc:
            pytest.skip(str(exc))

    def _run(self, command: list[str], timeout: float) -> subprocess.CompletedProcess[str]:
        return subprocess.run(command, cwd=self.home, env=self.env(), capture_output=True, text=True,
                              timeout=timeout)

    _checked = False

    def _check_dropped(self) -> None:
        """The program really cannot write the folder or its files: else the test would pass on a
        register that was writable after all."""
        probe = ("import os, sys; import fha_studio; "
                 "print([os.access(p, os.W_OK) for p in sys.argv[1:]])")
        files = [str(p) for p in [self.folder, *self.folder.rglob("*")]]
        done = self._run([*self._as_user(), sys.executable, "-c", probe, *files], 60.0)
        if done.returncode != 0:
            pytest.skip(f"cannot run Python without root's overrides here: {done.stderr.strip()[-200:]}")
        assert done.stdout.split("\n")[0] == str([False] * len(files)), done.stdout
        self._checked = True

    def __enter__(self) -> ReadOnlyPlace:
        return self

    def __exit__(self, *exc: object) -> None:
        self.remove()

    def remove(self) -> None:
        unseal(self.folder)
        shutil.rmtree(self.folder, ignore_errors=True)
        shutil.rmtree(self.home, ignore_errors=True)
