"""The session log: every parameter write of a commissioning session (time, item, old value, new
value, verified or not), kept as JSON lines so the commissioning report can print it later."""

from __future__ import annotations

import json
from dataclasses import asdict, dataclass
from pathlib import Path

from fha_studio import clock, fileio
from fha_studio.hardware.parameters import MODE_WORDS, Mode, ParameterItem


@dataclass(frozen=True)
class WriteRecord:
    """One write. Values are wire integers; `verified` means the read-back equals `new`."""

    time: str  # ISO 8601, local time with offset
    mode: str
    number: int
    key: str
    name: str
    old: int | None
    new: int
    read_back: int | None
    verified: bool
    error: str | None = None

    def line(self, item: ParameterItem | None = None) -> str:
        """One line for people, in the front panel's words and units when ``item`` (this record's
        parameter item) is given: ``17:05:02 parameter 6, position error allowance: 50000 pulse →
        100 pulse, verified``. Without it the values are the drive's raw numbers."""
        def value(wire: int | None) -> str:
            if wire is None:
                return "unknown"
            return item.format(wire) if item is not None else str(wire)

        if item is not None:
            what = item.label
        else:
            mode = MODE_WORDS[Mode(self.mode)] if self.mode in set(Mode) else self.mode
            what = f"{mode} {self.number}, {self.name}"
        outcome = "verified" if self.verified else f"NOT verified ({self.error or 'the read-back differs'})"
        clock = self.time[11:19] if len(self.time) >= 19 else self.time
        return f"{clock} {what}: {value(self.old)} → {value(self.new)}, {outcome}"


class SessionLog:
    """Appends WriteRecords to a JSON-lines file (when given one) and keeps them in memory."""

    def __init__(self, path: Path | None = None):
        self.path = path
        self.records: list[WriteRecord] = []

    def append(self, record: WriteRecord) -> None:
        self.records.append(record)
        if self.path is not None:
            self.path.parent.mkdir(parents=True, exist_ok=True)
            with self.path.open("a", encoding="utf-8") as fh:
                fh.write(json.dumps(asdict(record)) + "\n")

    @staticmethod
    def now() -> str:
        return clock.local_iso()

    @classmethod
    def read(cls, path: Path) -> SessionLog:
        """A log written before (one JSON object per line)."""
        log = cls(None)
        for number, line in enumerate(fileio.read_text(path).splitlines(), 1):
            if not line.strip():
                continue
            try:
                log.records.append(WriteRecord(**json.loads(line)))
            except (ValueError, TypeError) as exc:
                raise ValueError(f"{path}: line {number}: not a session-log record ({exc})") from None
        log.path = path
        return log
