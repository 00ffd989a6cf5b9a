"""The DGR checks of a moving axis, taken from its CN2 outputs on a bench instrument (no Qt).

A real HA-655 answers CN3 with ``s`` while the servo is on, so the checks that need the axis to
move under the controller read the drive's CN2 instead: the command pulses the controller sent
(commanded counts), the encoder's A/B line-driver outputs (counted x4), IN-POS and ALARM.

- ``bench_encoder``: the encoder outputs follow the command: the same sense, and the counts the
  command asked for (through the electronic gear 3/4), within the in-position range at the end;
  the other sense means A and B are swapped (the wiring or the receiver), another size a wrong
  gear or resolution.
- ``bench_direction`` (FHA-C manual 1-10): which way the controller's command turned the axis as
  the encoder outputs count it (a FWD command, command counts up), and so which way the output
  flange turned: the encoder outputs count up on a FWD command (``resources/drive/ha655-cn2.toml``,
  an assumption the public manual neither states nor denies), and parameter 8 says which way a
  FWD command turns the flange (0: FWD rotation, CW viewing the output flange; 1: REV rotation,
  CCW). Without parameter 8 the check says what it needs.
- ``bench_in_position``: IN-POS (CN2-33) came on after the command ended and stayed on.
- ``bench_alarm``: ALARM (and the alarm code on ALM-A ... D, where they are mapped) stayed off all
  through the capture; an alarm that came is named by its code in the manual's words.

Each result names where its figures came from (the instrument and its channels).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from fha_studio.catalog.tables import rotary_direction_setting
from fha_studio.hardware.parameters import Cn2Table, load_cn2
from fha_studio.logic.bench.alarm_code import code_text

_SENSE_WORDS = {"FWD command": "a FWD command", "CW": "CW rotation of the flange"}
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


def _same_name(channel: str, signal: str) -> bool:
    """A channel named after the signal it reads (``ALM_A`` for ALM-A, ``in pos`` for IN-POS)."""
    def key(text: str) -> str:
        return "".join(ch for ch in text.upper() if ch.isalnum())
    return key(channel) == key(signal)


def source_words(instrument: str, wired: Sequence[tuple[str, Sequence[str]]]) -> str:
    """Where a bench move's figures came from, as a technician reads it: the instrument, then each
    CN2 signal by its manual name with the instrument's channel once ("IN-POS on D4"); a channel
    named after its signal (a capture's ``ALM_A``) is not repeated beside it. ``wired``: (the
    signal's words, its channels) for each signal mapped, e.g. ("encoder A, B", ("D0", "D1"))."""
    parts = []
    for signal, channels in wired:
        named = [c.strip() for c in channels if c.strip()]
        if not named:
            continue
        if len(named) == 1 and _same_name(named[0], signal):
            parts.append(signal)
        else:
            parts.append(f"{signal} on {', '.join(named)}")
    return f"the bench instrument {instrument}" + (f" ({'; '.join(parts)})" if parts else "")


def bench_checks(t_s: ArrayLike, command_counts: ArrayLike, encoder_counts: ArrayLike, *,
                 in_position: ArrayLike | None = None, alarm: ArrayLike | None = None,
                 in_position_time_s: float | None = None, parameter_8: int | None = None,
                 source: str = "the bench", cn2: Cn2Table | None = None,
                 alarm_code: ArrayLike | None = None, alarm_lines_unmapped: Sequence[str] = ()
                 ) -> list[BenchCheck]:
    """The checks of the move in a capture (see the module's text). ``in_position_time_s``: from
    the command's end until IN-POS stayed on (None: it did not), as the move's figures give it.
    ``alarm_code``: ALM-D C B A as a number per sample (``alarm_lines_unmapped``: the lines no
    channel reads), named in the manual's words when an alarm came."""
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
    cn2 = cn2 or load_cn2()
    forward = in_command_sense(moved, parameter_8, cn2)
    if forward is None:
        checks.append(BenchCheck("bench_encoder", None, f"the encoder outputs counted {moved:+.0f} for "
                                 f"{commanded:+.0f} commanded counts {where}; they count up on CW rotation "
                                 "of the output flange, so which way that is to the command needs parameter "
                                 "8: enter it as the drive's panel shows it", values))
    else:
        checks += _encoder_and_direction(commanded, forward, parameter_8, cn2, where, values)
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
    if alarm is not None or alarm_code is not None:
        checks.append(_alarm_check(t, alarm, alarm_code, alarm_lines_unmapped, where, values))
    return checks


def _alarm_check(t: np.ndarray, alarm: ArrayLike | None, alarm_code: ArrayLike | None,
                 unmapped: Sequence[str], where: str, values: dict[str, Any]) -> BenchCheck:
    """``bench_alarm``: ALARM (or a code on ALM-A ... D) off all through the capture."""
    # a live stream's row is 0.5 where ALARM came on within its window: that is on
    on = np.zeros(t.size, bool) if alarm is None else np.asarray(alarm, dtype=float) >= 0.5
    codes = None if alarm_code is None else np.asarray(alarm_code, dtype=float).astype(np.int64)
    if codes is not None:
        on = on | (codes != 0)
    high = np.flatnonzero(on)
    what = "ALARM" if alarm is not None else "an alarm code"
    if not high.size:
        lines = "ALARM" if alarm is not None else ""
        if codes is not None:
            lines += (" and " if lines else "") + "ALM-A ... D"
        return BenchCheck("bench_alarm", True, f"{lines} stayed off through the move {where}", values)
    at = float(t[high[0]])
    if codes is None:
        return BenchCheck("bench_alarm", False, f"ALARM came on at {at:.3f} s {where}: read the code on the "
                          "front panel (the Alarms page)", {**values, "alarm_at_s": at})
    later = codes[high[0]:]
    code = int(later[later != 0][0]) if np.any(later != 0) else 0
    return BenchCheck("bench_alarm", False, f"{what} came on at {at:.3f} s {where}: "
                      f"{code_text(code, unmapped=unmapped)}; the front panel's code says which",
                      {**values, "alarm_at_s": at, "alm_code": f"{code:04b}"})


def _encoder_and_direction(commanded: float, moved: float, parameter_8: int | None, cn2: Cn2Table,
                           where: str, values: dict[str, Any]) -> list[BenchCheck]:
    """``bench_encoder`` and ``bench_direction`` (``moved``: the encoder counts in the command's sense)."""
    checks = []
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
    turned = flange_direction(moved, parameter_8)
    rotation, flange = turned if turned is not None else (None, None)
    if turned is not None:
        at_flange = (f": with parameter 8 = {parameter_8} that is {rotation}, {flange} viewing the output "
                     "flange (1-10)")
        if cn2.encoder_sense_assumed:
            sense = _SENSE_WORDS[cn2.encoder_counts_up_on]
            at_flange += (f" (taking the encoder outputs to count up on {sense}, which the public HA-655 "
                          "manual does not state)")
    elif moved:
        at_flange = ("; which way that is at the output flange (CW or CCW) follows from parameter 8: enter "
                     "it as the drive's panel shows it")
    else:
        at_flange = ""
    checks.append(BenchCheck(
        "bench_direction", (counted == way) if moved else False,
        f"a {way} command ({commanded:+.0f} counts) turned the axis {counted} as the encoder outputs count "
        f"it {where}{at_flange}",
        {**values, "command": way, "counted": counted, "rotary_direction": parameter_8,
         "rotation": rotation, "flange": flange}))
    return checks


def in_command_sense(encoder_change: float, parameter_8: int | None,
                     cn2: Cn2Table | None = None) -> float | None:
    """The encoder outputs' change as the command counts it (up = the way a FWD command turns the
    axis): as it is where they count up on a FWD command; where they count up on CW rotation of
    the flange, turned by parameter 8 (None without it)."""
    if (cn2 or load_cn2()).encoder_counts_up_on != "CW":
        return encoder_change
    if parameter_8 not in (0, 1):
        return None
    return encoder_change if rotary_direction_setting(int(parameter_8)).fwd_turns_cw else -encoder_change


def flange_direction(command_sense_change: float, parameter_8: int | None) -> tuple[str, str] | None:
    """Which way the output flange turned for a change of the axis's position in the command's sense
    (up = the way a FWD command turns it): (the 1-10 table's words, "FWD rotation" or "REV
    rotation"; "CW" or "CCW" viewing the output flange). None when it did not turn, or without
    parameter 8 (0 or 1)."""
    if command_sense_change == 0 or parameter_8 not in (0, 1):
        return None
    cw = rotary_direction_setting(int(parameter_8)).fwd_turns_cw == (command_sense_change > 0)
    return ("FWD rotation", "CW") if cw else ("REV rotation", "CCW")
