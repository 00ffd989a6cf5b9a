"""The simulated drive's EEPROM: a JSON file written atomically.

It holds what a real HA-655 keeps over a power cycle: the tune and parameter (system) items, the
alarm history, and -- for absolute encoders -- the battery-backed multi-turn data, so that a
restarted sim process finds the shaft where it left it.
"""

from __future__ import annotations

import contextlib
import json
import os
import tempfile
from collections.abc import Mapping
from pathlib import Path
from typing import Any

FORMAT = "fha-sim-eeprom/1"


class EepromError(ValueError):
    """The EEPROM file cannot be read or does not hold what it should; the message names the file."""


def default_eeprom_dir() -> Path:
    """The user data directory for simulated drives (``$XDG_DATA_HOME/fha-studio/sim``)."""
    base = os.environ.get("XDG_DATA_HOME") or os.path.join(os.path.expanduser("~"), ".local", "share")
    return Path(base) / "fha-studio" / "sim"


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
        try:
            text = self.path.read_text(encoding="utf-8")
        except FileNotFoundError:
            return None
        except OSError as exc:
            raise EepromError(f"simulated drive EEPROM {self.path}: cannot read it: {exc}") from exc
        try:
            doc = json.loads(text)
        except json.JSONDecodeError as exc:
            raise EepromError(
                f"simulated drive EEPROM {self.path} is corrupt (not JSON: {exc.msg} at line {exc.lineno}); "
                "delete it to start from the factory settings"
            ) from exc
        if not isinstance(doc, dict) or doc.get("format") != FORMAT:
            found = doc.get("format") if isinstance(doc, dict) else type(doc).__name__
            raise EepromError(
                f"simulated drive EEPROM {self.path} is not a {FORMAT} file (format: {found!r}); "
                "delete it to start from the factory settings"
            )
        return doc

    def save(self, doc: Mapping[str, Any]) -> None:
        """Write ``doc`` (the ``format`` key is added) atomically."""
        data = json.dumps({"format": FORMAT, **doc}, indent=1, sort_keys=True)
        self.path.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(prefix=self.path.name + ".", suffix=".tmp", dir=self.path.parent)
        try:
            with os.fdopen(fd, "w", encoding="utf-8") as f:
                f.write(data)
                f.flush()
                os.fsync(f.fileno())
            os.replace(tmp, self.path)
        except BaseException:
            with contextlib.suppress(FileNotFoundError):
                os.unlink(tmp)
            raise
