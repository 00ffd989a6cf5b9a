"""What may be opened as a register, and SQLite's errors in words (no Qt).

- :func:`check_before_opening`: only a regular file that is an SQLite database (or is absent, or
  empty when a register is being started) is opened. A device (``--db /dev/ttyUSB0`` typed by
  mistake), a FIFO, a directory or a file of another kind is refused before SQLite touches it:
  SQLite would open a device read-write and write database pages onto a drive's line, and create
  ``/dev/NAME-journal`` beside it. Says whether the file can only be read.
- :func:`problem`: an ``sqlite3.Error`` as one :class:`RegisterError` line naming the file and
  what to do: read-only, damaged (at which page, and that ``register check`` says what can be
  saved), locked (by which program, when the system says), full, not a register.
"""

from __future__ import annotations

import functools
import os
import re
import sqlite3
import stat
from collections.abc import Callable
from pathlib import Path
from typing import Any, TypeVar

from fha_studio import fileio
from fha_studio.names import quoted

#: The first 16 bytes of every SQLite 3 database file.
SQLITE_HEADER = b"SQLite format 3\x00"
#: Folders whose entries are devices and never registers, whatever they are called.
DEVICE_FOLDERS = ("/dev/",)


class RegisterError(ValueError):
    """The register cannot be used or a request does not fit it; the message says what and where."""


class ServerAway(RegisterError):
    """The register's server cannot be reached or went away (no answer: not a refusal). A window
    that keeps its facts tries again later; a wrong password or a role's refusal is no such thing."""


#: How the register's refusal to change or remove a fact begins (:mod:`.append_only`).
APPEND_ONLY = "append-only:"


def append_only_refusal(where: str, said: str) -> RegisterError:
    """The database refused to change or remove a fact: one line, from its own words."""
    reason = said.splitlines()[0].strip() if said.strip() else APPEND_ONLY
    return RegisterError(f"the register {where}: its history is {reason}: nothing was changed")


#: The most of a path a refusal shows: a path as people make them, whole (its file's name is at
#: its end: a cut at 80 characters took the name off a register in a folder a few levels down);
#: a pasted 10 kB one is cut.
PATH_SHOWN_MAX = 300


def shown_path(path: str | os.PathLike[str]) -> str:
    """A path as a refusal quotes it: at most PATH_SHOWN_MAX characters, anything unprintable
    escaped."""
    return quoted(os.fspath(path), limit=PATH_SHOWN_MAX, always=False)


def check_before_opening(path: Path, create: bool) -> bool:
    """Raises RegisterError unless ``path`` may be opened as a register; returns True when the
    file exists and this process may only read it."""
    where = shown_path(path)
    absolute = os.path.abspath(path)
    if any(absolute.startswith(folder) for folder in DEVICE_FOLDERS):
        raise RegisterError(f"register {where}: a device, not a register file: nothing was opened")
    try:
        info = os.stat(path)
    except FileNotFoundError:
        if not create:
            raise RegisterError(f"there is no register at {where}") from None
        return False
    except OSError as exc:
        from fha_studio.fileio import os_reason

        raise RegisterError(f"register {where}: {os_reason(exc)}") from None
    if not stat.S_ISREG(info.st_mode):
        kind = next((name for test, name in fileio.FILE_KINDS if test(info.st_mode)), "not a regular file")
        raise RegisterError(f"register {where}: is {kind}, not a register file: nothing was opened")
    if info.st_size == 0:
        if not create:
            raise RegisterError(f"{where} is an empty file, not a register (start one: "
                                "fha-studio register add-machine NAME)")
    else:
        head = _head(path, len(SQLITE_HEADER))
        if head != SQLITE_HEADER:
            raise RegisterError(f"{where} is not a register (not an SQLite database file): not changed")
    return not writable(path)


def writable(path: Path) -> bool:
    """True when this process may write the file (its permissions, the file system)."""
    return os.access(path, os.W_OK)


def _head(path: Path, size: int) -> bytes:
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK | getattr(os, "O_NOCTTY", 0))
    except OSError as exc:
        from fha_studio.fileio import os_reason

        raise RegisterError(f"register {shown_path(path)}: {os_reason(exc)}") from None
    try:
        return os.read(fd, size)
    except OSError:
        return b""
    finally:
        os.close(fd)


def connect_uri(path: Path, readonly: bool, create: bool) -> str:
    """The ``file:`` URI SQLite opens ``path`` with: read-only, read-write, or created."""
    from urllib.parse import quote

    mode = "ro" if readonly else ("rwc" if create else "rw")
    uri = f"file:{quote(os.path.abspath(path))}?mode={mode}"
    if readonly and _unchangeable(path):
        # SQLite reads a WAL file through a shared-memory file beside it; where this user may not
        # create one, a file no one has left a WAL for is read as it is
        uri += "&immutable=1"
    return uri


def _unchangeable(path: Path) -> bool:
    folder = os.path.dirname(os.path.abspath(path))
    wal = f"{path}-wal"
    return not os.access(folder, os.W_OK) and (not os.path.exists(wal) or os.path.getsize(wal) == 0)


def problem(path: Path, exc: sqlite3.Error, db: sqlite3.Connection | None = None,
            busy_timeout_s: float = 0.0, opening: bool = False) -> RegisterError:
    """``exc`` in words, naming the register ``path`` (``opening``: while it was being opened)."""
    where = shown_path(path)
    code = getattr(exc, "sqlite_errorcode", None)
    primary = code & 0xFF if isinstance(code, int) else None
    text = str(exc)
    if text.startswith(APPEND_ONLY):  # the file's triggers refused to change or remove a fact
        return append_only_refusal(where, text)
    if primary == sqlite3.SQLITE_READONLY or "readonly" in text:
        return RegisterError(f"the register {where} is read-only: nothing was changed (it needs write "
                             "access to the file and its folder)")
    if primary in (sqlite3.SQLITE_BUSY, sqlite3.SQLITE_LOCKED) or "locked" in text:
        who = holders(path)
        by = f" by {who}" if who else " by another program"
        waited = f" for more than {busy_timeout_s:g} s" if busy_timeout_s else ""
        return RegisterError(f"the register {where} is locked{by}{waited}: nothing was changed; "
                             "try again when it is done")
    if primary == sqlite3.SQLITE_CORRUPT or "malformed" in text:
        return damaged(path, db)
    if primary == sqlite3.SQLITE_NOTADB or "not a database" in text:
        return RegisterError(f"{where} is not a register (not an SQLite database file): not changed")
    if primary == sqlite3.SQLITE_FULL or "full" in text or (
        primary == sqlite3.SQLITE_IOERR and _no_room(path, code)
    ):
        return RegisterError(f"the register {where}: no space left on the device: nothing was changed")
    if primary == sqlite3.SQLITE_CANTOPEN or "unable to open" in text:
        return RegisterError(f"the register {where} cannot be opened (its folder must be there and "
                             "let this user read it)")
    if primary == sqlite3.SQLITE_IOERR or "I/O" in text:
        return RegisterError(f"the register {where}: input/output error reading or writing it "
                             "(is the disk or the share still there?)")
    said = quoted(text, limit=80, always=False)
    if opening:
        return RegisterError(f"register {where}: not a usable register file ({said})")
    return RegisterError(f"the register {where}: {said}")


#: Free bytes below which a file system cannot take a page of the register and its journal.
ROOM_NEEDED_BYTES = 65536


def _no_room(path: Path, code: int | None) -> bool:
    """Whether an input/output error is a full disk: SQLite could not make room for its shared
    memory file (what a register opened on a full disk meets first; SQLite names that an I/O
    error, not a full disk), or the register's file system has no room left."""
    if code == sqlite3.SQLITE_IOERR_SHMSIZE:
        return True
    try:
        disk = os.statvfs(os.path.dirname(os.path.abspath(path)))
    except OSError:
        return False
    return disk.f_bavail * disk.f_frsize < ROOM_NEEDED_BYTES


def damaged(path: Path, db: sqlite3.Connection | None) -> RegisterError:
    """The refusal of a damaged register: where it is damaged, and what says what can be saved."""
    page = damaged_page(db)
    at = f" at {page}" if page else ""
    return RegisterError(f"{shown_path(path)} is damaged{at}; `fha-studio register check` says what "
                         "can be saved")


def sound(db: sqlite3.Connection) -> bool:
    """SQLite's quick check (the pages and their b-trees, not the indexes' contents) finds
    nothing wrong. A write into a damaged file is refused before it starts: SQLite finds damage
    only where it reads, so a new machine written beside a damaged table of axes would be taken,
    and the file damaged further."""
    try:
        return [str(r[0]) for r in db.execute("PRAGMA quick_check(1)")] == ["ok"]
    except sqlite3.DatabaseError as exc:
        if "malformed" in str(exc) or getattr(exc, "sqlite_errorcode", 0) & 0xFF == sqlite3.SQLITE_CORRUPT:
            return False
        raise


_Class = TypeVar("_Class", bound=type)


def in_words(cls: _Class) -> _Class:
    """Class decorator: every public method of ``cls`` raises SQLite's (and the server's) errors as
    ``self._problem(exc)`` (a :class:`RegisterError` line) instead of ``sqlite3.Error``."""
    for name, member in list(vars(cls).items()):
        if name.startswith("_") or not callable(member) or isinstance(member, staticmethod | classmethod):
            continue
        setattr(cls, name, _translating(member))
    return cls


def is_db_error(exc: BaseException) -> bool:
    """An error of the register's store: SQLite's, or psycopg's (the server's or the connection's
    to it; psycopg is imported only by a register on a server)."""
    return isinstance(exc, sqlite3.Error) or type(exc).__module__.split(".")[0] == "psycopg"


def _translating(method: Callable[..., Any]) -> Callable[..., Any]:
    @functools.wraps(method)
    def call(self: Any, *args: Any, **kwargs: Any) -> Any:
        try:
            return method(self, *args, **kwargs)
        except Exception as exc:
            if not is_db_error(exc):
                raise
            raise self._problem(exc) from None

    return call


_PAGE = re.compile(r"\bpage (\d+)", re.IGNORECASE)


def damaged_page(db: sqlite3.Connection | None) -> str:
    """Where the file is damaged: "page N" as SQLite's integrity check names it, else the root
    page of the first table that cannot be read ("page N (axes)"); "" when neither says."""
    if db is None:
        return ""
    try:
        for (line,) in db.execute("PRAGMA integrity_check(10)"):
            found = _PAGE.search(str(line))
            if found:
                return f"page {found.group(1)}"
    except sqlite3.Error:
        pass  # a table's first page itself is unreadable: find which
    try:
        tables = db.execute("SELECT name, rootpage FROM sqlite_master WHERE type = 'table'").fetchall()
    except sqlite3.Error:
        return "page 1 (the table of tables)"
    for name, rootpage in tables:
        try:
            for _ in db.execute(f'SELECT * FROM "{name}"'):
                pass
        except sqlite3.Error:
            return f"page {rootpage} ({TABLE_WORDS.get(name, name)})"
    return ""


#: The register's tables in words.
TABLE_WORDS = {
    "machine": "machines",
    "axis": "axes",
    "axis_event": "axis history entries",
    "snapshot": "parameter snapshots",
    "snapshot_value": "snapshot values",
    "parameter_write": "parameter writes",
    "procedure_run": "procedure states",
    "check_result": "check results",
    "alarm": "alarms",
    "report": "reports",
    "recording": "recordings",
    "model_check": "model checks",
    "signing_key": "signing keys",
    "key_revocation": "key revocations",
    "report_signature": "report signatures",
    "known_register": "registers known",
    "this_register": "the register's own id",
    "conflict": "conflicts",
    "conflict_resolution": "conflict resolutions",
}


def holders(path: Path) -> str:
    """The other programs that have the register (or its WAL files) open, as "fha-studio (pid
    1234)"; "" when the system does not say (not Linux, or another user's processes)."""
    try:
        target = os.path.realpath(path)
    except OSError:
        return ""
    names = {target, target + "-wal", target + "-shm", target + "-journal"}
    found: list[str] = []
    own = os.getpid()
    try:
        pids = [int(p) for p in os.listdir("/proc") if p.isdigit() and int(p) != own]
    except OSError:
        return ""
    for pid in pids:
        try:
            fds = os.listdir(f"/proc/{pid}/fd")
        except OSError:
            continue
        for fd in fds:
            try:
                if os.readlink(f"/proc/{pid}/fd/{fd}") in names:
                    with open(f"/proc/{pid}/comm", encoding="utf-8", errors="replace") as comm:
                        found.append(f"{quoted(comm.read().strip(), limit=30, always=False)} (pid {pid})")
                    break
            except OSError:
                continue
        if len(found) >= 3:
            break
    return ", ".join(found)
