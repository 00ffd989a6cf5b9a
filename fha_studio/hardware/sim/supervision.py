"""The simulated drive's alarms and their supervision: the active alarm, the alarm history, and
the checks made every :data:`SUPERVISION_PERIOD_S` (10 over speed, 20 overload by I^2 t,
41 abnormal regeneration, 60 error counter overflow, 54 multi-turn overflow)."""

from __future__ import annotations

import math
from dataclasses import dataclass

from fha_studio import clock
from fha_studio.hardware.parameters import AlarmTable
from fha_studio.hardware.sim.constants import SimConstants
from fha_studio.hardware.sim.options import Wiring
from fha_studio.hardware.sim.reply import rejected
from fha_studio.physics import ServoAxis

SUPERVISION_PERIOD_S = 0.001  # alarms, watchdog, sensors and inhibits are checked every 1 ms
ABS_MULTI_TURN_RANGE = (-4096, 4095)  # HA-655 manual (relianca p.5): alarm 54 outside it
#: wiring faults that leave the motor without useful torque (see WiringFaultTrip)
MOTION_WIRING_FAULTS = (Wiring.MOTOR_SWAPPED, Wiring.MOTOR_OPEN, Wiring.ENCODER_SWAPPED)


class WiringFaultTrip:
    """A motor lead open or swapped, or the encoder's A/B swapped (a training drive's wiring
    fault): a commanded motion finds no useful torque (open) or runs away from the command
    (swapped) and the error counter overflows (alarm 60) within ``wiring_fault_trip_s``; a swapped
    lead lurches the axis ``wiring_fault_lurch_deg`` the wrong way before the trip."""

    def __init__(self, wiring: Wiring, constants: SimConstants):
        self.active = wiring in MOTION_WIRING_FAULTS
        self.lurches = wiring is not Wiring.MOTOR_OPEN
        self.lurch_rad = math.radians(constants.wiring_fault_lurch_deg)
        self.trip_s = constants.wiring_fault_trip_s
        self.faulty_motion_s = 0.0  # how long a motion has been commanded into the fault

    def tick(self, commanded: bool) -> bool:
        """One supervision period with a motion ``commanded`` (or not); True: alarm 60 trips."""
        if not commanded:
            self.faulty_motion_s = 0.0
            return False
        self.faulty_motion_s += SUPERVISION_PERIOD_S
        return self.faulty_motion_s >= self.trip_s


@dataclass
class SimAlarmRecord:
    """One entry of the simulated drive's alarm history (the client reads it as AHS lines)."""

    code: int
    seconds_since_power_on: float
    time_utc: str


class AlarmSupervisor:
    """The active alarm (0: none), the history (newest first) and the overload and regeneration
    accumulators of one drive."""

    def __init__(
        self,
        table: AlarmTable,
        constants: SimConstants,
        *,
        max_speed_rad_s: float,
        max_current_a: float,
        continuous_current_a: float,
        absolute_encoder: bool,
    ):
        self.table = table
        self.constants = constants
        self.max_speed_rad_s = max_speed_rad_s
        self.max_current_a = max_current_a
        self.continuous_current_a = continuous_current_a
        self.absolute_encoder = absolute_encoder
        self.code = 0
        self.history: list[SimAlarmRecord] = []
        self.overload_a2s = 0.0  # I^2 t above the continuous current, A^2 s
        self.regen_j = 0.0  # regenerated energy not yet dissipated by the resistor, J
        self._last_i2_a2s = 0.0
        self._last_regen_j = 0.0

    def power_on(self, axis: ServoAxis) -> None:
        """Control power on: no alarm, empty accumulators (the history stays)."""
        self.code = 0
        self.overload_a2s = 0.0
        self.regen_j = 0.0
        self._last_i2_a2s = axis.current_squared_integral_a2s
        self._last_regen_j = axis.regenerated_energy_j

    def describe(self, code: int | None = None) -> str:
        """``"20 Overload"`` for ``code`` (default: the active alarm)."""
        return self.table.describe(self.code if code is None else code)

    def record(self, code: int, time_s: float) -> bool:
        """Make ``code`` the active alarm and add it to the history; False (nothing changes) when
        an alarm is already active, since the first one stays on the display. Raises SimRefused
        (``x``) for a code not in the table or one that needs an absolute encoder."""
        alarm = self.table.get(code)
        if alarm is None:
            raise rejected(f"alarm {code} is not in the {self.table.driver} alarm table")
        if alarm.absolute_only and not self.absolute_encoder:
            raise rejected(f"alarm {code} ({alarm.name}) exists only with an absolute encoder")
        if self.code:
            return False
        self.code = code
        stamp = clock.now_utc().isoformat(timespec="seconds")
        self.history.insert(0, SimAlarmRecord(code, time_s, stamp))
        del self.history[self.constants.alarm_history_length:]
        return True

    def clear(self) -> int:
        """ACL: clears a clearable alarm (20, 60, as the real driver) and returns its code (0 when
        none was active); others raise SimRefused (``x``): they need a power cycle."""
        code = self.code
        if not code:
            return 0
        alarm = self.table.get(code)
        if alarm is None or not alarm.clearable:
            raise rejected(f"alarm {self.table.describe(code)} is cleared only by a power cycle")
        if code == 20:
            self.overload_a2s = 0.0
        self.code = 0
        return code

    def alm_bits(self) -> int:
        """The active alarm's 4-bit ALM output (0 without an alarm)."""
        alarm = self.table.get(self.code)
        return alarm.alm_bits if alarm is not None else 0

    @property
    def overload_threshold_a2s(self) -> float:
        """I^2 t above the continuous current at which alarm 20 trips, A^2 s."""
        i_max = self.max_current_a
        i_cont = self.continuous_current_a
        return (i_max**2 - i_cont**2) * self.constants.overload_time_at_max_current_s

    @property
    def overload_rate(self) -> float:
        """Monitor 105 as a fraction: 1.0 = alarm 20."""
        return self.overload_a2s / self.overload_threshold_a2s

    def check(
        self,
        axis: ServoAxis,
        *,
        error_allowance_pulses: float | None,
        multi_turn: int | None,
    ) -> list[int]:
        """One supervision tick: the alarms the axis trips now, in the order checked (the caller
        raises the first). ``error_allowance_pulses`` is None without a position loop (servo off
        or speed mode); ``multi_turn`` is None with an incremental encoder."""
        c = self.constants
        dt = SUPERVISION_PERIOD_S
        tripped = []
        # 10 over speed (the peak since the last look, so no excursion slips between two)
        if axis.peak_speed_rad_s > c.over_speed_factor * self.max_speed_rad_s:
            tripped.append(10)
        # 20 overload: I^2 t above the continuous current
        i2 = axis.current_squared_integral_a2s
        heat = i2 - self._last_i2_a2s - self.continuous_current_a**2 * dt
        self._last_i2_a2s = i2
        self.overload_a2s = max(0.0, self.overload_a2s + heat)
        if self.overload_a2s >= self.overload_threshold_a2s:
            tripped.append(20)
        # 41 abnormal regeneration: energy fed back beyond what the 40 W resistor dissipates
        regen = axis.regenerated_energy_j
        self.regen_j = max(0.0, self.regen_j + regen - self._last_regen_j - c.regeneration_resistor_w * dt)
        self._last_regen_j = regen
        if self.regen_j > c.regeneration_energy_capacity_j:
            tripped.append(41)
        # 60 error counter overflow against parameter 6
        if error_allowance_pulses is not None and axis.peak_error_pulses > error_allowance_pulses:
            tripped.append(60)
        axis.reset_peaks()
        # 54 multi-turn overflow of the absolute encoder
        if multi_turn is not None and not ABS_MULTI_TURN_RANGE[0] <= multi_turn <= ABS_MULTI_TURN_RANGE[1]:
            tripped.append(54)
        return tripped


__all__ = ["ABS_MULTI_TURN_RANGE", "SUPERVISION_PERIOD_S", "AlarmSupervisor", "SimAlarmRecord"]
