"""The simulated drive's analog speed command input SPD-CMD (CN2-31/32, +/-10 V), and a DAQ's
analog output wired to it.

:class:`SpeedCommandInput` is the input: the volts an instrument puts on it, as a function of the
drive's time (0 V while nothing is wired). In speed mode (parameter 0) the drive samples it at the
start of every servo period, adds the speed command offset (tune item 5, mV) and takes
10 V = the motor speed of parameter 9 as its speed command (:func:`spd_cmd_speeds`); in position
mode it is ignored, as on the real drive.

:class:`VirtualAnalogOutput` is a DAQ's (or a generator's) output on that input: it plays a
:class:`~fha_studio.hardware.bench.waveform.Waveform` from a moment of the drive's time, sample
by sample (each value held until the next, as a DAC holds it), gives 0 V before it starts and
holds its last value after the end, as a DAQ does. The virtual bench instrument can record the
input's volts beside SPD-MON (``VirtualBenchInstrument.on_drive(..., speed_command=True)``).
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable
from typing import Any, Protocol

import numpy as np

from fha_studio.hardware.bench.waveform import Waveform, read_waveform

RAD_S_PER_RPM = 2.0 * math.pi / 60.0
#: how far a DAQ's sample clock is off the drive's (a common crystal tolerance)
DAQ_CLOCK_PPM = 30.0
#: SPD-CMD's range: the input clips beyond it
SPD_CMD_LIMIT_V = 10.0
VoltsAt = Callable[[np.ndarray], np.ndarray]


class _Drive(Protocol):
    """What of the simulated drive (:class:`~fha_studio.hardware.sim.drive.SimDrive`) SPD-CMD uses."""

    speed_command_input: SpeedCommandInput
    servo_on: bool
    time_s: float
    servo_rate_hz: float
    ratio: float
    lock: Any

    @property
    def speed_mode(self) -> bool: ...

    def active_parameter(self, key: str) -> int: ...

    def blocked_directions(self) -> tuple[bool, bool]: ...


class SpeedCommandInput:
    """CN2-31/32: the volts on it at the drive's times (see the module docstring)."""

    def __init__(self) -> None:
        self._source: VoltsAt | None = None

    @property
    def connected(self) -> bool:
        return self._source is not None

    def connect(self, source: VoltsAt | None) -> None:
        """Wire an output to the input (``source(t_s)`` -> volts), or unwire it (None: 0 V); hold
        the drive's lock while the drive runs in real time."""
        self._source = source

    def volts(self, t_s: np.ndarray) -> np.ndarray:
        """The volts at the drive's times ``t_s`` (clipped to the input's range)."""
        t = np.asarray(t_s, float)
        if self._source is None:
            return np.zeros(t.shape)
        # np.minimum / np.maximum: np.clip costs several times more on a servo chunk's few values
        volts = np.asarray(self._source(t), float)
        return np.asarray(np.minimum(np.maximum(volts, -SPD_CMD_LIMIT_V), SPD_CMD_LIMIT_V))


def spd_cmd_speeds(drive: _Drive, periods: int, added: list[float] | None = None) -> list[float] | None:
    """The speeds (rad/s, command frame) added to ``drive``'s speed command for its next
    ``periods`` servo periods: ``added`` (the drive's own excitation, or None) plus, in speed mode
    with the servo on and SPD-CMD wired, SPD-CMD sampled at each period's start: the volts plus
    the offset of tune item 5 (mV), 10 V = the motor speed of parameter 9; zero (zero clamp) the
    way an inhibit input or a limit switch blocks."""
    if not (drive.speed_mode and drive.servo_on and drive.speed_command_input.connected):
        return added
    times = drive.time_s + np.arange(periods) / drive.servo_rate_hz
    volts = drive.speed_command_input.volts(times) + 1e-3 * drive.active_parameter("speed_command_offset")
    rad_s = volts / 10.0 * drive.active_parameter("speed_conversion_factor") / drive.ratio * RAD_S_PER_RPM
    fwd_blocked, rev_blocked = drive.blocked_directions()
    if fwd_blocked:
        rad_s = np.minimum(rad_s, 0.0)
    if rev_blocked:
        rad_s = np.maximum(rad_s, 0.0)
    if added is not None:
        rad_s = rad_s + np.asarray(added, float)
    return [float(v) for v in rad_s]


class WaveformPlayback:
    """A waveform played from ``start_s`` by a clock ``clock_ppm`` off the drive's: 0 V before,
    each sample held, the last held after."""

    def __init__(self, wave: Waveform, start_s: float, clock_ppm: float = 0.0) -> None:
        self.wave = wave
        self.start_s = float(start_s)
        self.rate_hz = wave.rate_hz * (1.0 + 1e-6 * clock_ppm)  # in the drive's time
        self.end_s = self.start_s + len(wave.volts) / self.rate_hz

    def __call__(self, t_s: np.ndarray) -> np.ndarray:
        volts = self.wave.volts
        index = np.floor((np.asarray(t_s, float) - self.start_s) * self.rate_hz + 1e-6).astype(np.int64)
        out = volts[np.minimum(np.maximum(index, 0), len(volts) - 1)]
        return np.where(index < 0, 0.0, out)


class VirtualAnalogOutput:
    """A DAQ's analog output wired to the simulated drive's SPD-CMD (see the module docstring).

    ``clock_ppm``: how far the DAQ's sample clock is off the drive's (a crystal's tolerance; 0
    would have the drive sample every step of the output at the same point of it, which no real
    pair of clocks does)."""

    def __init__(self, drive: _Drive, clock_ppm: float = DAQ_CLOCK_PPM) -> None:
        self.drive = drive
        self.clock_ppm = clock_ppm
        self.playback: WaveformPlayback | None = None

    def play(self, wave: Waveform | str | os.PathLike[str], start_s: float | None = None) -> WaveformPlayback:
        """Play a waveform (or a waveform file: CSV or WAV, as written for an instrument) from the
        drive's time ``start_s`` (default: now)."""
        if not isinstance(wave, Waveform):
            wave = read_waveform(wave)
        with self.drive.lock:
            start = self.drive.time_s if start_s is None else float(start_s)
            self.playback = WaveformPlayback(wave, start, self.clock_ppm)
            self.drive.speed_command_input.connect(self.playback)
        return self.playback

    def finished(self) -> bool:
        """True once the whole waveform has been played."""
        return self.playback is None or self.drive.time_s >= self.playback.end_s

    def disconnect(self) -> None:
        """Unwire the output (SPD-CMD at 0 V)."""
        self.playback = None
        with self.drive.lock:
            self.drive.speed_command_input.connect(None)
