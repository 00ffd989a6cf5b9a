"""Twenty writers at once on one register, each with a connection of its own (the file's and the
server's durability tests): each records snapshots and alarms of its own, and the same check."""

from __future__ import annotations

import threading
from collections.abc import Callable

from fha_studio.logic.register import Register

WRITERS, EACH = 20, 6
#: each writer's facts carry this note: "writer/k"
NOTES = sorted(f"{n}/{k}" for n in range(WRITERS) for k in range(EACH))


class SameCheck:
    """A check every writer answers alike: recorded once, whoever comes first."""

    procedure_id, step_id, kind, section, text = "wiring", "w1", "confirm", "1-14", "Motor wired"
    value, expected, unit, passed, who, detail = True, "", "", True, "Ana Lima", ""
    at_utc = "2026-11-30T09:00:00Z"


def write_at_once(open_register: Callable[[], Register], axis: str) -> None:
    """WRITERS threads, each on ``open_register()``, start together and record EACH snapshots (of
    20 values), EACH alarms and the same check for ``axis``; every one ends (within 120 s) without
    an error."""
    start = threading.Barrier(WRITERS, timeout=60)
    failures: list[BaseException] = []

    def write(n: int) -> None:
        try:
            with open_register() as reg:
                start.wait()
                for k in range(EACH):
                    values = [("tune", i, f"item_{i}", n * 100 + k) for i in range(20)]
                    reg.record_snapshot(axis, values, "link", who=f"writer {n}", note=f"{n}/{k}")
                    reg.record_alarm(axis, 10 + k, "overspeed", who=f"writer {n}", note=f"{n}/{k}")
                    reg.record_checks(axis, [SameCheck()])
        except BaseException as exc:  # reported by the test's thread
            failures.append(exc)

    threads = [threading.Thread(target=write, args=(n,), name=f"writer {n}") for n in range(WRITERS)]
    for t in threads:
        t.start()
    for t in threads:
        t.join(timeout=120)
    assert not [t.name for t in threads if t.is_alive()] and not failures, failures
