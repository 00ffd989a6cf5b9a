"""The commissioning session of one axis: every check recorded, saved as JSON (``fha-session/1``).

A session is the single source of the commissioning report: the report is rendered from the
session file alone (with the procedures and the parameter model it names), so it can be
reproduced later. Times are UTC, ISO 8601.
"""

from __future__ import annotations

import json
import os
from dataclasses import asdict, dataclass, field
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

FORMAT = "fha-session/1"

# Run states of one procedure in a session.
NOT_STARTED, RUNNING, PAUSED, STOPPED, COMPLETED = "not_started", "running", "paused", "stopped", "completed"


class SessionError(ValueError):
    """A session file cannot be read or does not fit (says which file and what)."""


def utc_now() -> str:
    """Now, UTC, ISO 8601 to the second."""
    return datetime.now(UTC).replace(microsecond=0).isoformat()


@dataclass
class CheckRecord:
    """One answer to one step: who, when (UTC), the value, what passes, pass or fail."""

    procedure_id: str
    step_id: str
    kind: str
    section: str
    text: str
    value: Any
    expected: str
    unit: str
    passed: bool
    who: str
    at_utc: str
    detail: str = ""


@dataclass
class RunState:
    """Where one procedure stands in the session."""

    procedure_id: str
    step_ids: list[str] = field(default_factory=list)  # fingerprint of the procedure as walked
    status: str = NOT_STARTED
    position: int = 0  # index into step_ids of the step waiting for an answer
    answers: dict[str, Any] = field(default_factory=dict)
    records: list[CheckRecord] = field(default_factory=list)
    stop_step_id: str = ""
    stop_warning: str = ""
    started_utc: str = ""
    finished_utc: str = ""

    @classmethod
    def from_json(cls, data: dict[str, Any]) -> RunState:
        records = [CheckRecord(**r) for r in data.get("records", [])]
        fields = {k: v for k, v in data.items() if k != "records"}
        return cls(records=records, **fields)


@dataclass
class ProcedureSession:
    """Everything recorded while commissioning one axis."""

    actuator_code: str
    axis: str = "axis 1"
    operator: str = ""
    site: str = ""
    driver: dict[str, str] = field(
        default_factory=dict
    )  # model, adjusted_for, version (from IDN or the label)
    created_utc: str = field(default_factory=utc_now)
    runs: dict[str, RunState] = field(default_factory=dict)
    sensor_angles_deg: dict[str, float] = field(
        default_factory=dict
    )  # limit_switch_1, limit_switch_2, origin_sensor
    parameters: dict[str, Any] = field(
        default_factory=dict
    )  # {"file": path, "values": {key: value}, "read_utc": ...}
    plots: list[dict[str, str]] = field(default_factory=list)  # {"title": ..., "path": PNG}
    notes: list[dict[str, str]] = field(default_factory=list)  # {"who", "at_utc", "text"}
    signature: dict[str, str] = field(default_factory=dict)  # {"who", "at_utc"}
    path: Path | None = field(default=None, compare=False, repr=False)

    def run(self, procedure_id: str) -> RunState:
        """The run state of a procedure (created, not started, when first asked for)."""
        if procedure_id not in self.runs:
            self.runs[procedure_id] = RunState(procedure_id=procedure_id)
        return self.runs[procedure_id]

    def to_json(self) -> dict[str, Any]:
        data = asdict(self)
        data.pop("path")
        return {"format": FORMAT, **data}

    def save(self, path: str | Path | None = None) -> Path:
        """Write the session (atomically: a crash leaves the old file whole); remembers the path."""
        target = Path(path) if path is not None else self.path
        if target is None:
            raise SessionError("the session has no file yet: give a path to save it to")
        target.parent.mkdir(parents=True, exist_ok=True)
        tmp = target.with_name(target.name + ".tmp")
        tmp.write_text(json.dumps(self.to_json(), indent=2, ensure_ascii=False) + "\n", encoding="utf-8")
        os.replace(tmp, target)
        self.path = target
        return target

    @classmethod
    def load(cls, path: str | Path) -> ProcedureSession:
        """Read a session file; raises :class:`SessionError` naming the file and the problem."""
        path = Path(path)
        try:
            data = json.loads(path.read_text(encoding="utf-8"))
        except FileNotFoundError:
            raise SessionError(f"{path}: no such session file") from None
        except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
            raise SessionError(f"{path}: not a readable session file: {exc}") from None
        if not isinstance(data, dict) or data.get("format") != FORMAT:
            raise SessionError(f"{path}: not an {FORMAT} session file")
        try:
            runs = {k: RunState.from_json(v) for k, v in data.get("runs", {}).items()}
            fields = {k: v for k, v in data.items() if k not in ("format", "runs")}
            session = cls(runs=runs, **fields)
        except TypeError as exc:
            raise SessionError(f"{path}: unexpected content: {exc}") from None
        session.path = path
        return session

    def add_note(self, text: str, who: str = "") -> None:
        self.notes.append({"who": who or self.operator, "at_utc": utc_now(), "text": text})

    def add_plot(self, title: str, png_path: str | Path) -> None:
        self.plots.append({"title": title, "path": str(png_path)})
