"""A full disk for the tests, for real: a tiny tmpfs mounted for the test (root and mount(8) are
needed: else the test is skipped, saying so), and a file that fills it to its last byte."""

from __future__ import annotations

import contextlib
import errno
import os
import pwd
import shutil
import subprocess
from collections.abc import Iterator
from pathlib import Path

import pytest

#: The size of the small disk: a few hundred pages of the register, filled in milliseconds.
TMPFS_BYTES = 4 * 1024 * 1024


@contextlib.contextmanager
def small_disk(where: Path, owner: str | None = None) -> Iterator[Path]:
    """A tmpfs of TMPFS_BYTES mounted at ``where`` (made), owned by the user ``owner`` (None: this
    process's); unmounted afterwards."""
    if os.geteuid() != 0 or shutil.which("mount") is None:
        pytest.skip("a full disk needs a tmpfs mounted, which needs root and mount(8)")
    user = pwd.getpwnam(owner) if owner else pwd.getpwuid(os.geteuid())
    where.mkdir()
    done = subprocess.run(
        ["mount", "-t", "tmpfs", "-o", f"size={TMPFS_BYTES},mode=0700,uid={user.pw_uid},gid={user.pw_gid}",
         "fha-full-disk", str(where)], capture_output=True, text=True, timeout=30, check=False)
    if done.returncode != 0:
        pytest.skip(f"a full disk needs a tmpfs mounted; mount said: {done.stderr.strip()[:120]}")
    try:
        yield where
    finally:
        subprocess.run(["umount", "-l", str(where)], capture_output=True, timeout=30, check=False)


def fill(folder: Path) -> Path:
    """Fills the file system of ``folder`` to its last byte; the file that fills it."""
    junk = folder / "junk"
    block = b"\0" * 65536
    with junk.open("wb", buffering=0) as out:
        while True:
            try:
                out.write(block)
            except OSError as exc:
                if exc.errno != errno.ENOSPC:
                    raise
                break
        for size in (4096, 512, 1):  # the last bytes
            with contextlib.suppress(OSError):
                while True:
                    out.write(block[:size])
    return junk
