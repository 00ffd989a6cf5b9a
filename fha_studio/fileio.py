"""Reading input files safely and writing output files whole (any layer; no Qt).

- :func:`read_text` / :func:`read_bytes`: only a regular file is read as a file (a FIFO, a device
  such as ``/dev/zero``, a directory or a socket is refused before a byte is read, so nothing
  waits on a writer that never comes or reads without end), and reading stops at a stated size.
- :func:`write_text` / :func:`write_bytes`: the one way FHA Studio writes an output file. The
  content goes to a temporary file beside the target, is flushed to the disk, and only then
  renamed over the target; a failed write (disk full, no permission, a path under a file)
  leaves the previous file untouched and no temporary file behind, and raises before the caller
  can print that it succeeded. A write killed halfway leaves its temporary, which the next write
  of the target removes, and the next start too (:mod:`fha_studio.temporaries` notes every
  temporary in flight with its writer's pid).
- :func:`check_output_path`: the same checks as the writers, before any work is done, so that a
  long computation is not lost to a target that can never be written.

Every problem raises :class:`FileProblem` (a ``ValueError``) whose message is one line naming the
file and what is wrong, in words (no errno names).
"""

from __future__ import annotations

import contextlib
import errno
import json
import math
import os
import stat
import tomllib
from pathlib import Path
from typing import Any

from fha_studio import temporaries

#: Default bound on what a reader reads: far above any file FHA Studio writes or reads as input
#: (parameter, session, model and EEPROM files are kilobytes), so a larger file is not one of ours.
DEFAULT_READ_LIMIT_BYTES = 16 * 1024 * 1024


class FileProblem(ValueError):
    """A file cannot be read or written as asked; ``str()`` is one line naming the file."""

    def __init__(self, path: str | os.PathLike[str], reason: str):
        self.path = str(path)
        self.reason = reason
        super().__init__(f"{_shown(self.path)}: {reason}")


def _shown(path: str) -> str:
    # a path a person typed by mistake can be long: keep the message on one readable line
    return path if len(path) <= 120 else path[:60] + "…" + path[-40:]


#: what a path is when it is not a regular file, as a refusal names it
FILE_KINDS = (
    (stat.S_ISDIR, "a directory"),
    (stat.S_ISFIFO, "a FIFO (named pipe)"),
    (stat.S_ISCHR, "a character device"),
    (stat.S_ISBLK, "a block device"),
    (stat.S_ISSOCK, "a socket"),
)


def _kind(mode: int) -> str:
    for test, name in FILE_KINDS:
        if test(mode):
            return name
    return "not a regular file"


def os_reason(exc: OSError) -> str:
    """An OSError in words, without the errno number or the path (the caller names the file)."""
    reasons = {
        errno.ENOENT: "no such file or directory",
        errno.ENOTDIR: "a part of the path is not a directory",
        errno.EISDIR: "is a directory",
        errno.EACCES: "permission denied",
        errno.EPERM: "permission denied",
        errno.ENAMETOOLONG: "the name is too long for the file system",
        errno.ENOSPC: "no space left on the device",
        errno.EROFS: "the file system is read-only",
        errno.ELOOP: "too many symbolic links",
        errno.EIO: "input/output error",
        errno.EDQUOT: "disk quota exceeded",
        errno.EFBIG: "the file is too large for the file system",
    }
    if exc.errno in reasons:
        return reasons[exc.errno]
    return (exc.strerror or str(exc)).lower() if exc.strerror else str(exc)


# ------------------------------------------------------------------------------------------- reading


def _open_to_read(path: str | os.PathLike[str]) -> tuple[str, int]:
    """The file's name and a descriptor open for reading; :class:`FileProblem` when it cannot be."""
    name = os.fspath(path)
    if not name:
        raise FileProblem("''", "no file name given")
    try:
        # O_NONBLOCK: opening a FIFO must not wait for a writer; the kind is checked right after
        return name, os.open(name, os.O_RDONLY | os.O_NONBLOCK | getattr(os, "O_NOCTTY", 0))
    except OSError as exc:
        raise FileProblem(name, os_reason(exc)) from None


def _regular(name: str, fd: int) -> os.stat_result:
    """The open file's status; :class:`FileProblem` unless it is a regular file."""
    info = os.fstat(fd)
    if not stat.S_ISREG(info.st_mode):
        raise FileProblem(name, f"is {_kind(info.st_mode)}, not a regular file: only files are read")
    return info


def read_bytes(path: str | os.PathLike[str], *, limit_bytes: int = DEFAULT_READ_LIMIT_BYTES) -> bytes:
    """The content of a regular file of at most ``limit_bytes``; :class:`FileProblem` otherwise."""
    name, fd = _open_to_read(path)
    try:
        info = _regular(name, fd)
        if info.st_size > limit_bytes:
            raise FileProblem(name, f"is {_size(info.st_size)}, more than the {_size(limit_bytes)} "
                              "such a file can be")
        chunks: list[bytes] = []
        total = 0
        while True:
            # the size the file states in one read (no copies joined), then on until it ends
            chunk = os.read(fd, min(max(1 << 20, info.st_size + 1 - total), limit_bytes + 1 - total))
            if not chunk:
                break
            chunks.append(chunk)
            total += len(chunk)
            if total > limit_bytes:  # a file that grows, or reports no size (/proc)
                raise FileProblem(name, f"holds more than the {_size(limit_bytes)} such a file can be")
        return b"".join(chunks)
    except OSError as exc:
        raise FileProblem(name, f"cannot be read: {os_reason(exc)}") from None
    finally:
        os.close(fd)


def read_head(path: str | os.PathLike[str], max_bytes: int) -> bytes:
    """The first ``max_bytes`` (or fewer) of a regular file; :class:`FileProblem` otherwise."""
    name, fd = _open_to_read(path)
    try:
        _regular(name, fd)
        chunks: list[bytes] = []
        total = 0
        while total < max_bytes:
            chunk = os.read(fd, min(1 << 20, max_bytes - total))
            if not chunk:
                break
            chunks.append(chunk)
            total += len(chunk)
        return b"".join(chunks)
    except OSError as exc:
        raise FileProblem(name, f"cannot be read: {os_reason(exc)}") from None
    finally:
        os.close(fd)


def read_text(path: str | os.PathLike[str], *, limit_bytes: int = DEFAULT_READ_LIMIT_BYTES) -> str:
    """A regular file as UTF-8 text (a leading byte-order mark is dropped); :class:`FileProblem`
    for anything else, including bytes that are not UTF-8 (the message gives the line)."""
    data = read_bytes(path, limit_bytes=limit_bytes)
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = data.count(b"\n", 0, exc.start) + 1
        raise FileProblem(os.fspath(path), f"line {line}: not UTF-8 text (byte {exc.start}); "
                          "is it the right file?") from None
    return text[1:] if text.startswith("\ufeff") else text


def _size(n: int) -> str:
    if n >= 1 << 20:
        return f"{n / (1 << 20):.0f} MB"
    if n >= 1 << 10:
        return f"{n / (1 << 10):.0f} kB"
    return f"{n} bytes"


# ------------------------------------------------------------------------------------------- writing


def check_output_path(path: str | os.PathLike[str]) -> Path:
    """Raises :class:`FileProblem` unless ``path`` can become a regular file: its directory
    exists and is a directory, and the path is absent or a regular file. Returns it as a Path."""
    name = os.fspath(path)
    if not name:
        raise FileProblem("''", "no file name given")
    target = Path(name)
    try:
        info = os.stat(target)
    except FileNotFoundError:
        info = None
    except OSError as exc:
        raise FileProblem(name, os_reason(exc)) from None
    if info is not None and not stat.S_ISREG(info.st_mode):
        raise FileProblem(name, f"is {_kind(info.st_mode)}, not a regular file: only files are written")
    parent = target.parent
    try:
        parent_info = os.stat(parent)
    except OSError as exc:
        raise FileProblem(name, f"its folder {parent}: {os_reason(exc)}") from None
    if not stat.S_ISDIR(parent_info.st_mode):
        raise FileProblem(name, f"{parent} is not a folder")
    if len(target.name.encode()) > 255 - 16:  # room for the temporary file's suffix
        raise FileProblem(name, os_reason(OSError(errno.ENAMETOOLONG, "")))
    return target


def write_bytes(path: str | os.PathLike[str], data: bytes) -> Path:
    """Write ``data`` to ``path`` whole or not at all (temporary file, fsync, rename).

    The new file gets the old file's permissions, or the usual ones for a new file (0666 less the
    umask). Raises :class:`FileProblem`; the target is then as it was before.
    """
    target = check_output_path(path)
    try:
        mode = stat.S_IMODE(os.stat(target).st_mode)
    except FileNotFoundError:
        mode = 0o666 & ~_umask()
    except OSError as exc:
        raise FileProblem(target, os_reason(exc)) from None
    remove_stale_temporaries(target)
    tmp: Path | None = None
    note = None
    try:
        fd, tmp, note = _create_temporary(target)
        with os.fdopen(fd, "wb") as handle:
            handle.write(data)
            handle.flush()
            os.fsync(handle.fileno())
        os.chmod(tmp, mode)
        os.replace(tmp, target)
        tmp = None
    except OSError as exc:
        raise FileProblem(target, f"not written: {os_reason(exc)}") from None
    finally:
        if tmp is not None:
            with contextlib.suppress(OSError):
                os.unlink(tmp)
        if note is not None:
            note.done()
    return target


def _create_temporary(target: Path) -> tuple[int, Path, temporaries.Note]:
    """A new ``.NAME.XXXXXXXX.tmp`` beside ``target``, noted in the journal of temporaries in
    flight before it exists (so a kill at any moment leaves nothing the next start cannot find)."""
    for _ in range(100):
        tmp = temporaries.temporary_name(target)
        note = temporaries.note(tmp)
        try:
            fd = os.open(tmp, os.O_RDWR | os.O_CREAT | os.O_EXCL | getattr(os, "O_CLOEXEC", 0), 0o600)
        except FileExistsError:
            note.done()
            continue
        except OSError:
            note.done()
            raise
        return fd, tmp, note
    raise FileExistsError(errno.EEXIST, "no free temporary file name")


#: A temporary file of a write (``.NAME.XXXXXXXX.tmp``) untouched for this long is left over from
#: a process killed while writing: no write of FHA Studio's outputs takes a minute.
STALE_TEMPORARY_S = 60.0


def remove_stale_temporaries(target: Path) -> list[Path]:
    """Removes the temporary files a killed write of ``target`` left beside it (``.NAME.XXXX.tmp``
    not changed for :data:`STALE_TEMPORARY_S`); returns them. A write going on now is left alone."""
    import time

    prefix = f".{target.name}."
    removed = []
    try:
        entries = list(os.scandir(target.parent))
    except OSError:
        return []
    now = time.time()  # a file's age: the filesystem's clock, never a stamped fact's
    for entry in entries:
        name = entry.name
        if not (name.startswith(prefix) and name.endswith(".tmp") and len(name) == len(prefix) + 12):
            continue
        try:
            info = entry.stat(follow_symlinks=False)
            if stat.S_ISREG(info.st_mode) and now - info.st_mtime > STALE_TEMPORARY_S:
                os.unlink(entry.path)
                removed.append(Path(entry.path))
        except OSError:
            continue
    return removed


def write_text(path: str | os.PathLike[str], text: str) -> Path:
    """:func:`write_bytes` of ``text`` in UTF-8."""
    return write_bytes(path, text.encode("utf-8"))


def _umask() -> int:
    # os.umask() can only read the mask by setting it, which races with other threads creating
    # files; Linux states it in /proc, elsewhere the usual 022 is assumed
    try:
        with open("/proc/self/status", encoding="ascii") as status:
            for line in status:
                if line.startswith("Umask:"):
                    return int(line.split()[1], 8)
    except (OSError, ValueError, IndexError):
        pass
    return 0o022


# ------------------------------------------------------------------------------------------- streams

#: The name a streamed output has until it is complete (``run.csv`` is ``run.csv.partial``).
PARTIAL_SUFFIX = ".partial"


class PartialFile:
    """A streamed output (a recording): written as ``PATH.partial``, renamed to ``PATH`` by
    :meth:`commit`. A process killed while streaming leaves ``PATH.partial`` holding every whole
    block written so far, and never a ``PATH`` that looks complete.

    :meth:`write` writes one block with unbuffered system calls; if the disk refuses part of it the
    file is cut back to the end of the previous block (so it ends with a whole row) and
    :class:`FileProblem` is raised.
    """

    def __init__(self, path: str | os.PathLike[str]):
        self.path = check_output_path(path)
        self.partial_path = check_output_path(self.path.with_name(self.path.name + PARTIAL_SUFFIX))
        try:
            self._fd: int | None = os.open(
                self.partial_path, os.O_WRONLY | os.O_CREAT | os.O_TRUNC | getattr(os, "O_CLOEXEC", 0), 0o666
            )
        except OSError as exc:
            raise FileProblem(self.partial_path, f"cannot be created: {os_reason(exc)}") from None
        self._size = 0

    @property
    def closed(self) -> bool:
        return self._fd is None

    def write(self, data: bytes) -> None:
        """Append ``data`` whole, or leave the file as it was and raise :class:`FileProblem`."""
        if self._fd is None:
            raise FileProblem(self.partial_path, "already closed")
        view = memoryview(data)
        done = 0
        try:
            while done < len(view):
                done += os.write(self._fd, view[done:])
        except OSError as exc:
            with contextlib.suppress(OSError):
                os.ftruncate(self._fd, self._size)
            raise FileProblem(self.partial_path, f"not written: {os_reason(exc)}") from None
        self._size += done

    def commit(self) -> Path:
        """Flush to the disk, close, and rename to the final name; returns it."""
        if self._fd is None:
            raise FileProblem(self.partial_path, "already closed")
        fd, self._fd = self._fd, None
        try:
            os.fsync(fd)
            os.close(fd)
            os.replace(self.partial_path, self.path)
        except OSError as exc:
            with contextlib.suppress(OSError):
                os.close(fd)
            raise FileProblem(self.path, f"not completed: {os_reason(exc)} (the data is in "
                              f"{self.partial_path.name})") from None
        return self.path

    def abandon(self) -> None:
        """Close without renaming: what was written stays in the ``.partial`` file."""
        if self._fd is not None:
            fd, self._fd = self._fd, None
            with contextlib.suppress(OSError):
                os.close(fd)


# ------------------------------------------------------------------------------------------- parsing

#: The deepest nesting of tables and lists an input file may have: FHA Studio's own files go
#: four levels deep (a session's runs.ID.records[N].value); far deeper is not one of ours, and
#: Python's parsers (and whatever walks the result) would exhaust the stack on it.
MAX_DEPTH = 32


class NestedTooDeep(tomllib.TOMLDecodeError):
    """A TOML or JSON text nested deeper than :data:`MAX_DEPTH` (a ``TOMLDecodeError``, so that
    the readers' own refusals of a broken file take it too)."""


def _too_deep() -> NestedTooDeep:
    return NestedTooDeep(f"nested more than {MAX_DEPTH} levels deep")


def _check_depth(data: object) -> None:
    stack: list[tuple[object, int]] = [(data, 0)]
    while stack:
        item, depth = stack.pop()
        if isinstance(item, dict | list):
            if depth >= MAX_DEPTH:
                raise _too_deep()
            children = item.values() if isinstance(item, dict) else item
            stack.extend((child, depth + 1) for child in children)


def parse_toml(text: str) -> dict[str, Any]:
    """``tomllib.loads`` bounded in depth: :class:`NestedTooDeep` (a TOMLDecodeError) for a text
    nested deeper than :data:`MAX_DEPTH`, instead of a RecursionError."""
    try:
        data = tomllib.loads(text)
    except RecursionError:
        raise _too_deep() from None
    _check_depth(data)
    return data


def parse_json(text: str) -> Any:
    """``json.loads`` bounded in depth (:class:`NestedTooDeep`, a ValueError), and strict about
    numbers: ``NaN``, ``Infinity`` and a number too large for a float (``1e999``) are refused."""
    def constant(name: str) -> float:
        raise ValueError(f"{name} is not a number in a file")

    def number(text: str) -> float:
        value = float(text)
        if not math.isfinite(value):
            raise ValueError(f"the number {text[:40]} is too large")
        return value

    try:
        data = json.loads(text, parse_constant=constant, parse_float=number)
    except RecursionError:
        raise _too_deep() from None
    _check_depth(data)
    return data
