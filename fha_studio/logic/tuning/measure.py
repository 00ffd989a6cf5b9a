"""Measure the speed loop's frequency response on a drive, over the client and the protocol.

The drive adds its PRBS to the speed command (EXA / EXL / EXG, docs/protocol.md) while the
position loop holds the axis, on a JOG at the plan's bias speed, FWD or REV (so the axis never reverses: see
``excitation``; the JOG is started first and its ramp and the loop's lag settle before the
excitation starts, and it is renewed with it and stopped, STP, at the end). The drive-side trace
records the speed command (monitor 109), the output speed (110, fine), the torque (108: Kt x the
current, finer steps than the current's mA) and the position (100) at the servo rate (TDV 1), one
PRBS period per capture. Before a record the loop settles for the plan's ``settle_s``. The
excitation is renewed at every look at the drive like a held JOG (the drive stops it without a
renewal after 100 ms), and always stopped at the end (also on an error or a STOP: ``should_stop``).

Time is the drive's own, from what it reports: a capture's state and sample count (``TST``)
measure the settling and each record, and ``pace(seconds)`` is called between two looks (a stepped
simulated drive's ``advance``; nothing on a drive that runs by itself, whose link paces the looks).
The read-out of a record holds the link without renewals: the excitation ran on through it when
it took less than the watchdog's 100 ms of the drive's time. ``now()`` tells how long it took at
most (the stepped drive's clock, or the computer's: a drive's time never runs faster than it),
and after a longer read-out the drive has stopped the excitation and the jog (the axis may have
stuck on its friction): the jog runs steadily again, then the excitation starts anew and settles,
before the next record (a line at 19200 baud reads a record for seconds: every record so).
"""

from __future__ import annotations

import contextlib
import math
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from fha_studio.hardware.parameters import MonitorItem
from fha_studio.hardware.protocol import JOG_HOLD_S, Command
from fha_studio.logic.tuning.excitation import RPM, ExcitationPlan, NotExcitable
from fha_studio.logic.tuning.move import until_trace_done, wait_drive_time

#: the channels of each capture
CHANNELS = (MonitorItem.FEEDBACK_POSITION, MonitorItem.SPEED_COMMAND, MonitorItem.OUTPUT_SPEED_FINE,
            MonitorItem.OUTPUT_TORQUE)
NEEDED = frozenset({Command.EXA, Command.EXL, Command.EXG, Command.TCH, Command.TAR, Command.TST,
                    Command.TRB, Command.IOS, Command.ALM, Command.MON})
#: the drive's excitation watchdog (as JOG's, protocol.JOG_HOLD_S)
WATCHDOG_S = JOG_HOLD_S


class Stopped(Exception):
    """STOP during the measurement: the excitation was stopped."""


@dataclass(frozen=True)
class Records:
    """The captures in SI: per record (speed command rad/s, speed rad/s, torque N m, position rad)."""

    records: tuple[tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray], ...]
    sample_rate_hz: float
    bias_rad_s: float = 0.0  # the jog the excitation rode on

    def closed_loop(self) -> list[tuple[np.ndarray, np.ndarray]]:
        return [(r[0], r[1]) for r in self.records]

    def plant(self) -> list[tuple[np.ndarray, np.ndarray]]:
        return [(r[2], r[1]) for r in self.records]

    def reversal_share(self) -> float:
        """The share of the samples at which the output speed changed sign or stood still: where
        the axis sticks on its Coulomb friction (0 on a bias speed that kept it turning one way)."""
        speeds = [r[1] for r in self.records if len(r[1]) > 1]
        if not speeds:
            return 0.0
        stuck = sum(int(np.count_nonzero(np.sign(v[1:]) != np.sign(v[:-1])) + np.count_nonzero(v == 0.0))
                    for v in speeds)
        return stuck / sum(len(v) for v in speeds)

    def travel_deg(self) -> float:
        """How far the excitation took the output from where it started; on a bias speed, half
        the largest swing within a record about the jog's path (the records' starts are apart by
        read-outs of unknown length)."""
        if not self.records or not len(self.records[0][3]):
            return 0.0
        if self.bias_rad_s == 0.0:
            pos = np.concatenate([r[3] for r in self.records])
            return float(np.degrees(np.max(np.abs(pos - pos[0]))))
        swings = []
        for r in self.records:
            about = r[3] - self.bias_rad_s * np.arange(len(r[3])) / self.sample_rate_hz
            swings.append(0.5 * float(np.ptp(about)))
        return float(np.degrees(max(swings)))


def check_excitable(client: Any) -> None:
    """Raise NotExcitable (one line: what is needed) unless the drive can be excited now."""
    missing = NEEDED - set(client.capabilities.commands)
    if missing:
        raise NotExcitable("the drive has no excitation and trace over CN3 (a drive of the manual's "
                           "commands): "
                           "measure on the bench (SPD-CMD from a DAQ's analog output, SPD-MON recorded) "
                           "or use the front-panel worksheet")
    alarm = client.alarm()
    if alarm:
        raise NotExcitable(f"alarm {alarm} is active: clear it before tuning")
    if not client.io_state().servo_on:
        raise NotExcitable("the servo is off: switch it on (nothing moves until the excitation starts)")


def measure(client: Any, plan: ExcitationPlan, servo_rate_hz: float, pace: Callable[[float], None],
            now: Callable[[], float] = time.monotonic, should_stop: Callable[[], bool] = lambda: False,
            output_ppr: int = 1, jog_accel_rpm_s: float = 1.0) -> Records:
    """Run ``plan`` on the drive and read the captures (see the module docstring);
    ``jog_accel_rpm_s``: the drive's JOG acceleration (test item 1), how soon the bias is reached."""
    check_excitable(client)
    client.set_excitation(plan.amplitude_rpm, plan.travel_limit_deg)
    records = []
    biased = plan.bias_rpm > 0.0
    exciting = False

    def renew() -> None:
        if should_stop():
            client.excite(0)
            client.stop()
            raise Stopped("STOP: the excitation was stopped")
        if biased:
            client.jog(plan.jog_speed_rpm)  # FWD or REV as planned
        if exciting:
            client.excite(plan.hold_periods)

    def start() -> None:
        """At the start and after a break (a read-out longer than the watchdog: the drive stopped
        the excitation, and the jog, whose axis may then have stuck on its friction): the jog's
        ramp and the loop's lag behind it settle first, then the excitation starts and settles."""
        nonlocal exciting
        if biased:
            exciting = False
            client.excite(0)  # started anew once the jog runs steadily (its travel limit from there)
            renew()
            wait_drive_time(client, plan.bias_rpm / max(jog_accel_rpm_s, 1e-9) + plan.settle_s, servo_rate_hz,
                            pace, look=renew)
        exciting = True
        renew()
        wait_drive_time(client, plan.settle_s, servo_rate_hz, pace, look=renew)

    running = False  # the excitation ran without a break since the loop settled
    try:
        for _ in range(plan.records):
            if running:
                renew()
            else:
                start()
            channels = client.configure_trace(CHANNELS, divider=1)
            client.arm_trace(plan.period_samples)
            until_trace_done(client, pace, look=renew)
            started = now()
            # the read-out holds the link: no renewals (on a real-time line the watchdog stops it)
            capture = client.read_trace(should_abort=should_stop)
            running = now() - started < WATCHDOG_S
            cols = {item: np.asarray(capture.column(item), float) for item in channels}
            records.append((
                cols[MonitorItem.SPEED_COMMAND] * 1e-4 * RPM,
                cols[MonitorItem.OUTPUT_SPEED_FINE] * 1e-4 * RPM,
                cols[MonitorItem.OUTPUT_TORQUE] * 0.01,
                cols[MonitorItem.FEEDBACK_POSITION] * (2.0 * math.pi / output_ppr),
            ))
    finally:
        # the link may be gone: the drive's watchdog then stops both within 100 ms
        with contextlib.suppress(Exception):
            client.excite(0)
        if biased:
            with contextlib.suppress(Exception):
                client.stop()
    return Records(tuple(records), servo_rate_hz, plan.jog_speed_rpm * RPM)
