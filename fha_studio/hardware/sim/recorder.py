"""Writes what the simulated axis does to an ``fha-recording/1`` file (``fha-studio sim --record``)."""

from __future__ import annotations

import math
from pathlib import Path

from fha_studio.hardware.sim.supervision import SUPERVISION_PERIOD_S
from fha_studio.physics import ServoAxis
from fha_studio.recording import RecordingMetadata, RecordingWriter


class SimRecorder:
    """Rows taken at the supervision ticks (t, pos, current, cmd_pos, load_pos, vel; physical frame,
    CW positive), written in blocks of 200. With ``torque_sensor`` also ``torque``: what a torque
    sensor between the output flange and the load reads (ServoAxis.flange_torque_nm), an instrument
    few axes have, so a recording carries it only when asked."""

    COLUMNS = ("t", "pos", "current", "cmd_pos", "load_pos", "vel")

    def __init__(self, path: Path, sample_rate_hz: float, *, actuator_code: str, load_inertia_kgm2: float,
                 supply_voltage: int, recorded_by: str, torque_sensor: bool = False):
        if not 0 < sample_rate_hz <= 1.0 / SUPERVISION_PERIOD_S:
            raise ValueError(f"recording rate {sample_rate_hz:g} Hz: 0 ... {1 / SUPERVISION_PERIOD_S:g}")
        self.every = max(1, round(1.0 / (sample_rate_hz * SUPERVISION_PERIOD_S)))
        metadata = RecordingMetadata(
            actuator=actuator_code,
            load_inertia_kgm2=load_inertia_kgm2,
            supply_voltage=supply_voltage,
            sample_rate_hz=1.0 / (self.every * SUPERVISION_PERIOD_S),
            extra={"recorded_by": recorded_by},
        )
        self.torque_sensor = torque_sensor
        self.writer = RecordingWriter(path, metadata, self.COLUMNS + (("torque",) if torque_sensor else ()))
        self.rows: list[tuple[float, ...]] = []
        self.count = 0

    def tick(self, clock_s: float, axis: ServoAxis) -> None:
        """One supervision tick at drive time ``clock_s``: a row every ``every`` ticks."""
        self.count += 1
        if self.count < self.every:
            return
        self.count = 0
        row = (
            clock_s, math.degrees(axis.output_pos_rad), axis.current_a,
            math.degrees(axis.command_pos_rad), math.degrees(axis.load_pos_rad), axis.output_speed_rpm,
        )
        self.rows.append((*row, axis.flange_torque_nm) if self.torque_sensor else row)
        if len(self.rows) >= 200:
            self.flush()

    def flush(self) -> None:
        if self.rows:
            self.writer.append_rows(self.rows)
            self.rows = []

    def close(self) -> None:
        try:
            self.flush()
        finally:
            self.writer.close()
