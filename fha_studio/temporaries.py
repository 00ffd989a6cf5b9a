"""A journal of the temporary files being written, so that a start removes what a killed write left.

:func:`fha_studio.fileio.write_bytes` writes ``.NAME.XXXXXXXX.tmp`` beside its target and renames
it over the target when it is whole. A process killed in between leaves the temporary behind (up
to megabytes: a register export, a report). The next write of the same target removes it; a
target never written again would keep it for good. So every write notes its temporary here
before creating it, with the writer's pid (and the pid's start time, where the system tells it,
so a pid used again by another process is not taken for the writer), and removes the note when
the temporary is gone (renamed or removed). At every start of the command line and the GUI,
:func:`sweep` removes the temporaries whose writer is dead and which nobody has touched for
:data:`STALE_S`, and their notes; a living writer's temporary is left alone.

The journal is a folder of small notes (one JSON file per write, ``PID.XXXXXXXX.json``: the
writer's pid, its start time, the temporary's path, when it was noted) in the
per-user data directory (:func:`fha_studio.paths.user_data_dir`), so that writers never share a
file. The journal helps; it never stands in a write's way: a journal that cannot be written (a
read-only home) leaves the write to do what it did before.
"""

from __future__ import annotations

import contextlib
import json
import logging
import os
import re
import secrets
import stat
from pathlib import Path
from typing import Literal

from fha_studio import clock
from fha_studio.paths import user_data_dir

log = logging.getLogger(__name__)

#: A temporary untouched for this long is not being written (no output of FHA Studio takes a
#: minute to write); a dead writer's younger temporary is left for a later start.
STALE_S = 60.0

#: What a temporary of fileio is called: ``.NAME.`` eight characters ``.tmp``. Nothing else is
#: ever removed by a note, whatever a note says.
TEMPORARY_NAME = re.compile(r"\A\..+\.[A-Za-z0-9_]{8}\.tmp\Z", re.DOTALL)

_NOTE_NAME = re.compile(r"\A(\d+)\.[0-9a-f]{8}\.json\Z")
_NOTE_LIMIT_BYTES = 64 * 1024


def journal_dir() -> Path:
    """Where the notes are: ``temporaries-in-flight`` in the per-user data directory."""
    return user_data_dir() / "temporaries-in-flight"


def temporary_name(target: Path) -> Path:
    """A new temporary's path beside ``target``: ``.NAME.XXXXXXXX.tmp``."""
    return target.with_name(f".{target.name}.{secrets.token_hex(4)}.tmp")


def started_ticks(pid: int) -> int | None:
    """The kernel's start time of process ``pid`` (clock ticks since boot), None where it is not
    told (not Linux, no such process)."""
    try:
        with open(f"/proc/{pid}/stat", "rb") as info:
            fields = info.read().rsplit(b")", 1)[1].split()
        return int(fields[19])
    except (OSError, ValueError, IndexError):
        return None


def process_alive(pid: int, started: int | None) -> bool:
    """Whether the writer ``pid`` (started at ``started`` ticks, if known) is still running: a
    zombie is dead, and so is another process that has since been given the same pid."""
    if pid <= 0:
        return False
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        pass  # someone else's process: it is running
    except OSError:
        return True  # cannot tell: leave it alone
    try:
        with open(f"/proc/{pid}/stat", "rb") as info:
            fields = info.read().rsplit(b")", 1)[1].split()
    except (OSError, IndexError):
        return True  # no /proc: os.kill said it runs
    if fields[:1] in ([b"Z"], [b"X"]):
        return False
    if started is not None:
        with contextlib.suppress(ValueError, IndexError):
            return int(fields[19]) == started
    return True


class Note:
    """The note of one write in flight; :meth:`done` removes it once its temporary is gone."""

    def __init__(self, path: Path | None):
        self.path = path

    def done(self) -> None:
        if self.path is not None:
            with contextlib.suppress(OSError):
                os.unlink(self.path)
            self.path = None


def note(temporary: Path) -> Note:
    """Notes ``temporary`` (about to be created by this process) in the journal. A journal that
    cannot be written gives a note that notes nothing: the write goes on without it."""
    pid = os.getpid()
    content = json.dumps({
        "pid_started_ticks": started_ticks(pid),
        "temporary": os.fspath(temporary.absolute()),
        "noted_utc": clock.utc_iso(),
    })
    folder = journal_dir()
    try:
        folder.mkdir(parents=True, exist_ok=True)
        path = folder / f"{pid}.{secrets.token_hex(4)}.json"
        fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_CLOEXEC", 0), 0o600)
    except OSError as exc:
        log.debug("temporaries journal %s not written: %s", folder, exc)
        return Note(None)
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as out:
            out.write(content)
    except OSError as exc:
        log.debug("temporaries journal note %s not written: %s", path, exc)
        Note(path).done()
        return Note(None)
    return Note(path)


def sweep() -> list[Path]:
    """Removes the temporaries of dead writers that nobody has touched for :data:`STALE_S` (by
    the one clock, :mod:`fha_studio.clock`), and their notes; returns the temporaries removed. A
    note of a dead writer whose temporary is gone (renamed or removed) goes too; a note of a living
    writer, or of a temporary touched within the minute, stays."""
    folder = journal_dir()
    try:
        entries = list(os.scandir(folder))
    except OSError:
        return []
    removed: list[Path] = []
    now_s = clock.now_s()
    for entry in entries:
        found = _NOTE_NAME.match(entry.name)
        if not found:
            continue
        try:
            content = _read_note(entry.path) or {}
            started = content.get("pid_started_ticks")
            if process_alive(int(found.group(1)), started if isinstance(started, int) else None):
                continue
            temporary = content.get("temporary")
            if isinstance(temporary, str) and temporary:
                what = _remove_temporary(Path(temporary), now_s)
                if what == "kept":
                    continue
                if what == "removed":
                    removed.append(Path(temporary))
            os.unlink(entry.path)
        except (OSError, ValueError, TypeError, AttributeError) as exc:
            log.debug("temporaries journal note %s: %s", entry.path, exc)
    return removed


def _read_note(path: str) -> dict[str, object] | None:
    """A note's content, or None for a note its writer was killed while writing (or garbage); the
    writer's pid is in the note's name."""
    try:
        with open(path, "rb") as handle:
            data = handle.read(_NOTE_LIMIT_BYTES + 1)
        content = json.loads(data.decode("utf-8")) if len(data) <= _NOTE_LIMIT_BYTES else None
    except (OSError, ValueError, RecursionError):
        return None
    return content if isinstance(content, dict) else None


def _remove_temporary(temporary: Path, now_s: float) -> Literal["kept", "removed", "absent"]:
    """Removes a dead writer's temporary untouched for :data:`STALE_S`: "kept" when it was touched
    within that time, "absent" when it is not there or is not one of fileio's temporaries (then
    it is never touched)."""
    if not temporary.is_absolute() or not TEMPORARY_NAME.match(temporary.name):
        return "absent"
    try:
        info = os.lstat(temporary)
    except OSError:
        return "absent"
    if not stat.S_ISREG(info.st_mode):
        return "absent"
    if now_s - info.st_mtime <= STALE_S:
        return "kept"
    os.unlink(temporary)
    log.info("removed %s, left by a write that was killed", temporary)
    return "removed"
