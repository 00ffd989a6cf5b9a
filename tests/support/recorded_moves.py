"""A recording of moves made by the simulated drive itself: servo on, its recorder started, each
move run to its end and a rest after it. One program for every test that checks what such a
recording shows."""

from __future__ import annotations

from collections.abc import Iterable
from pathlib import Path
from typing import Any

from fha_studio.hardware.sim import SimDrive


def record_moves(drive: SimDrive, path: Path, moves: Iterable[tuple[float, float]], rate_hz: float = 1000.0,
                 **recording: Any) -> Path:
    """Record ``moves`` ((angle_deg, speed_rpm) each, relative) on ``drive`` (a SimDrive) into
    ``path`` at ``rate_hz``; ``recording``: start_recording's options (torque_sensor=True...)."""
    drive.set_servo(True)
    drive.start_recording(path, rate_hz, **recording)
    drive.advance(0.2)
    for angle_deg, speed_rpm in moves:
        drive.set_move_speed(speed_rpm)
        drive.move_by(angle_deg)
        while drive.moving:
            drive.advance(0.05)
        drive.advance(0.2)
    drive.stop_recording()
    return path
