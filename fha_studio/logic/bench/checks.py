"""The DGR checks of a moving axis, taken from its CN2 outputs on a bench instrument (no Qt).

A real HA-655 answers CN3 with ``s`` while the servo is on, so the checks that need the axis to
move under the controller read the drive's CN2 instead: the command pulses the controller sent
(commanded counts), the encoder's A/B line-driver outputs (counted x4), IN-POS and ALARM.

- ``bench_encoder``: the encoder outputs follow the command: the same sense, and the counts the
  command asked for (through the electronic gear 3/4), within the in-position range at the end;
  the other sense means A and B are swapped (the wiring or the receiver), another size a wrong
  gear or resolution.
- ``bench_direction`` (FHA-C manual 1-10): which way the controller's command turned the axis as
  the encoder outputs count it (a FWD command, command counts up). Which way FWD is seen from the
  output flange (CW with parameter 8 = 0) the encoder outputs alone do not show: the check says
  so and leaves the flange to the technician's eye or the DGR rotary-direction check.
- ``bench_in_position``: IN-POS (CN2-33) came on after the command ended and stayed on.
- ``bench_alarm``: ALARM stayed off all through the capture.

Each result names where its figures came from (the instrument and its channels).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

#: The encoder may end this many counts off the command (the drive's in-position range is unknown
#: here; tune item 4 is often 10 ... 100 counts) or this share of the move, whichever is more.
END_TOLERANCE_COUNTS = 100
END_TOLERANCE_SHARE = 0.01


@dataclass(frozen=True)
class BenchCheck:
    """One check from a bench capture: ``passed`` None = recorded without a verdict."""

    check: str  # "bench_encoder", "bench_direction", "bench_in_position", "bench_alarm"
    passed: bool | None
    detail: str
    values: dict[str, Any] = field(default_factory=dict)


def bench_checks(t_s: ArrayLike, command_counts: ArrayLike, encoder_counts: ArrayLike, *,
                 in_position: ArrayLike | None = None, alarm: ArrayLike | None = None,
                 in_position_time_s: float | None = None, parameter_8: int | None = None,
                 source: str = "the bench") -> list[BenchCheck]:
    """The checks of the move in a capture (see the module's text). ``in_position_time_s``: from
    the command's end until IN-POS stayed on (None: it did not), as the move's figures give it."""
    t = np.asarray(t_s, dtype=float)
    cmd = np.asarray(command_counts, dtype=float)
    enc = np.asarray(encoder_counts, dtype=float)
    commanded = float(cmd[-1] - cmd[0]) if cmd.size else 0.0
    moved = float(enc[-1] - enc[0]) if enc.size else 0.0
    where = f"from {source}"
    values: dict[str, Any] = {"command_counts": commanded, "encoder_counts": moved, "source": source}
    checks: list[BenchCheck] = []
    if commanded == 0:
        checks.append(BenchCheck("bench_encoder", False, f"no command pulses came ({where}): did the "
                                 "controller send the move, and are the command lines mapped?", values))
        return checks
    tolerance = max(END_TOLERANCE_COUNTS, END_TOLERANCE_SHARE * abs(commanded))
    same_sense = moved * commanded > 0
    off = moved - commanded
    if same_sense and abs(off) <= tolerance:
        checks.append(BenchCheck("bench_encoder", True, f"the encoder outputs counted {moved:+.0f} for "
                                 f"{commanded:+.0f} commanded counts ({off:+.0f}) {where}", values))
    elif not same_sense:
        checks.append(BenchCheck("bench_encoder", False, f"the encoder outputs counted {moved:+.0f} for "
                                 f"{commanded:+.0f} commanded counts {where}: the other sense: are A and B "
                                 "swapped (the wiring or the line receiver)?", values))
    else:
        checks.append(BenchCheck("bench_encoder", False, f"the encoder outputs counted {moved:+.0f} for "
                                 f"{commanded:+.0f} commanded counts ({off:+.0f}) {where}: more than "
                                 f"{tolerance:.0f} off: check the electronic gear (parameters 3/4), the "
                                 "model code and that the axis was not held", values))
    way = "FWD" if commanded > 0 else "REV"
    counted = "FWD" if moved > 0 else ("REV" if moved < 0 else "not at all")
    flange = ""
    if parameter_8 in (0, 1):
        flange = (f"; parameter 8 = {parameter_8} says a FWD command turns the output "
                  f"{'CW' if parameter_8 == 0 else 'CCW'} seen from the flange")
    checks.append(BenchCheck(
        "bench_direction", (counted == way) if moved else False,
        f"a {way} command ({commanded:+.0f} counts) turned the axis {counted} as the encoder outputs count "
        f"it {where}{flange}; the encoder outputs do not show CW or CCW: see the flange or the DGR "
        "rotary-direction check (servo off before and after)",
        {**values, "command": way, "counted": counted, "rotary_direction": parameter_8}))
    if in_position is not None:
        on = np.asarray(in_position, dtype=float) > 0.5
        went_off = bool(np.any(~on))
        if in_position_time_s is None:
            checks.append(BenchCheck("bench_in_position", False, f"IN-POS (CN2-33) did not stay on after "
                                     f"the command ended {where}", {**values, "went_off": went_off}))
        else:
            note = "" if went_off else " (it never went off while the axis ran: is the in-position range, " \
                "tune item 4, wider than the following error?)"
            came = f"{in_position_time_s * 1000:.1f} ms after the command ended"
            checks.append(BenchCheck("bench_in_position", True,
                                     f"IN-POS (CN2-33) came on {came} and stayed on {where}{note}",
                                     {**values, "in_position_time_s": in_position_time_s,
                                      "went_off": went_off}))
    if alarm is not None:
        high = np.flatnonzero(np.asarray(alarm, dtype=float) > 0.5)
        if high.size:
            checks.append(BenchCheck("bench_alarm", False, f"ALARM came on at {t[high[0]]:.3f} s {where}: "
                                     "read the code on the front panel (the Alarms page)",
                                     {**values, "alarm_at_s": float(t[high[0]])}))
        else:
            checks.append(BenchCheck("bench_alarm", True, f"ALARM stayed off through the move {where}",
                                     values))
    return checks
