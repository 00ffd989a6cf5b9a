"""The simulated drive's EEPROM: a JSON file written atomically.

It holds what a real HA-655 keeps over a power cycle: the tune and parameter (system) items, the
alarm history, and -- for absolute encoders -- the battery-backed multi-turn data, so that a
restarted sim process finds the shaft where it left it.
"""

from __future__ import annotations

import contextlib
import json
import math
import os
import re
import tempfile
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from fha_studio import fileio

FORMAT = "fha-sim-eeprom/1"
#: An EEPROM image is about 3 kB; a larger file is not one.
MAX_FILE_BYTES = 1024 * 1024
#: The shaft angle an image may hold [rad]: 65536 output turns either way, more than an absolute
#: encoder's multi-turn counter holds; beyond it the servo's encoder arithmetic would overflow.
MAX_ENCODER_ANGLE_RAD = 2 * math.pi * 65536
#: Seconds since power-on an alarm record may carry: ten years.
MAX_ALARM_SECONDS = 10 * 365 * 24 * 3600.0


class EepromError(ValueError):
    """The EEPROM file cannot be read or does not hold what it should; the message names the file."""


def default_eeprom_dir() -> Path:
    """The user data directory for simulated drives (``$XDG_DATA_HOME/fha-studio/sim``)."""
    base = os.environ.get("XDG_DATA_HOME") or os.path.join(os.path.expanduser("~"), ".local", "share")
    return Path(base) / "fha-studio" / "sim"


def eeprom_path(
    option: str | None, driver: str, actuator_code: str, tempdir: tempfile.TemporaryDirectory[str] | None
) -> Path:
    """Where a simulated drive keeps its EEPROM: option ``eeprom`` ("" or None: in ``tempdir``,
    gone with it; "user": in :func:`default_eeprom_dir`, one file per driver and actuator; else
    the path given)."""
    if option is None or option == "":
        if tempdir is None:
            raise ValueError("a temporary EEPROM needs a temporary directory")
        return Path(tempdir.name) / "eeprom.json"
    if option == "user":
        return default_eeprom_dir() / f"{driver}_{actuator_code}.json"
    return Path(option).expanduser()


class EepromFile:
    """One EEPROM image on disk.

    ``load()`` returns the stored document (or None when the file does not exist yet);
    ``save(doc)`` replaces the file atomically (write a sibling temp file, fsync, rename), so a
    crash mid-write leaves either the old or the new image, never half of one.
    """

    def __init__(self, path: str | os.PathLike[str]):
        self.path = Path(path)

    def load(self) -> dict[str, Any] | None:
        """The stored document, or None if there is no file. Raises EepromError naming the file."""
        self.remove_stale_temporaries()
        if not os.path.lexists(self.path):
            return None
        try:
            text = fileio.read_text(self.path, limit_bytes=MAX_FILE_BYTES)
        except fileio.FileProblem as exc:
            raise EepromError(f"simulated drive EEPROM {exc}") from None
        try:
            doc = json.loads(text)
        except (json.JSONDecodeError, RecursionError) as exc:
            where = f"{exc.msg} at line {exc.lineno}" if isinstance(exc, json.JSONDecodeError) else "too deep"
            raise EepromError(
                f"simulated drive EEPROM {self.path} is corrupt (not JSON: {where}); "
                "delete it to start from the factory settings"
            ) from exc
        if not isinstance(doc, dict) or doc.get("format") != FORMAT:
            found = doc.get("format") if isinstance(doc, dict) else type(doc).__name__
            raise EepromError(
                f"simulated drive EEPROM {self.path} is not a {FORMAT} file (format: {found!r}); "
                "delete it to start from the factory settings"
            )
        problem = _shape_problem(doc)
        if problem:
            raise EepromError(f"simulated drive EEPROM {self.path}: {problem}; delete it to start from "
                              "the factory settings")
        return doc

    def remove_stale_temporaries(self) -> list[Path]:
        """Delete the temporary files a process killed during :meth:`save` left beside the image
        (``.NAME.*.tmp``, and ``NAME.*.tmp`` of earlier versions); returns them. A save in
        progress in another process would lose its temporary file, but two processes must not
        share one image anyway."""
        pattern = re.compile(r"\.?" + re.escape(self.path.name) + r"\.[A-Za-z0-9_]+\.tmp")
        removed: list[Path] = []
        try:
            names = os.listdir(self.path.parent)
        except OSError:
            return removed
        for name in names:
            if pattern.fullmatch(name):
                with contextlib.suppress(OSError):
                    os.unlink(self.path.parent / name)
                    removed.append(self.path.parent / name)
        return removed

    def save(self, doc: Mapping[str, Any]) -> None:
        """Write ``doc`` (the ``format`` key is added) whole or not at all (fha_studio.fileio);
        EepromError names the file if it cannot be written."""
        data = json.dumps({"format": FORMAT, **doc}, indent=1, sort_keys=True)
        try:
            if not os.path.lexists(self.path.parent):
                self.path.parent.mkdir(parents=True, exist_ok=True)
            fileio.write_text(self.path, data)
        except OSError as exc:
            raise EepromError(
                f"simulated drive EEPROM {self.path}: not written: {fileio.os_reason(exc)}") from None
        except fileio.FileProblem as exc:
            raise EepromError(f"simulated drive EEPROM {exc}") from None


def _shape_problem(doc: dict[str, Any]) -> str:
    """What is wrong with the shape of a loaded image ("" if nothing): every value a drive would
    compute with is checked here, so a bad file is refused at start, not in the drive's thread."""
    for key in ("driver", "actuator"):
        if key in doc and not isinstance(doc[key], str):
            return f"'{key}' must be text"
    params = doc.get("parameters", {})
    if not isinstance(params, dict):
        return "'parameters' must be a table of modes"
    for mode, values in params.items():
        if not isinstance(values, dict):
            return f"parameters.{mode} must be a table of items"
        for key, value in values.items():
            if isinstance(value, bool) or not isinstance(value, int):
                return f"parameters.{mode}.{key} must be a whole number, got {value!r:.40}"
    history = doc.get("alarm_history", [])
    if not isinstance(history, list):
        return "'alarm_history' must be a list"
    for i, record in enumerate(history):
        if not isinstance(record, dict):
            return f"alarm_history[{i}] must be a table (code, seconds, time_utc)"
        code, seconds = record.get("code"), record.get("seconds")
        if isinstance(code, bool) or not isinstance(code, int) or not 0 <= code <= 99:
            return f"alarm_history[{i}].code must be an alarm number 0 ... 99"
        if isinstance(seconds, bool) or not isinstance(seconds, int | float) \
                or not 0 <= seconds <= MAX_ALARM_SECONDS:
            return f"alarm_history[{i}].seconds must be 0 ... {MAX_ALARM_SECONDS:g} s since power-on"
        if not isinstance(record.get("time_utc"), str):
            return f"alarm_history[{i}].time_utc must be text"
    encoder = doc.get("encoder", {})
    if not isinstance(encoder, dict):
        return "'encoder' must be a table"
    for key in ("mechanical_angle_rad", "absolute_zero_rad"):
        value = encoder.get(key, 0.0)
        if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value) \
                or abs(value) > MAX_ENCODER_ANGLE_RAD:
            return (f"encoder.{key} must be a number of radians within ±{MAX_ENCODER_ANGLE_RAD:.0f} "
                    "(65536 output turns)")
    return ""
