"""The simulated drive's CN2 outputs as a bench instrument samples them, and that instrument.

:class:`Cn2Signals` turns the servo's trace (position, command and speed per servo period) into
the levels and volts on CN2, at an instrument's sample rate (the positions are interpolated
between servo periods):

- encoder A/B line-driver outputs at the actuator's resolution (the drive's feedback pulses,
  x4: A leads B going forward) and Z once per motor turn (high for one count);
- the command pulses the controller sends (the moves commanded while the servo is on) in the form
  of parameter 1 (two-pulse: FWD pulses on CMD_A, REV on CMD_B; pulse + sign: pulses on CMD_A,
  CMD_B high = REV; two-phase: CMD_A leading CMD_B = FWD, an edge per pulse at x4, a cycle per
  pulse at x1), before the electronic gear 3/4. They are inputs on a real drive: when the servo
  goes off (an alarm) and the axis coasts, the drive's error counter follows the encoder but the
  lines stay still, and clearing the error counter sends nothing (the trace's ``controller_pos``);
- SPD-MON (CN2-23): +10 V at the motor speed of parameter 9, through the monitor's bandwidth,
  with its offset and noise (assumptions of this simulation, :class:`MonitorModel`);
- IN-POS (|command - feedback| within the in-position range), ALARM, and the alarm code on
  ALM-A ... ALM-D (the 4 bits of the alarm table's code, ``resources/drive/ha655-alarms.toml``);
- the encoder outputs count up on a FWD command, or on CW rotation of the flange, as
  ``resources/drive/ha655-cn2.toml`` says (``[encoder_outputs]``);
- optionally an external encoder on the output flange (not on CN2: the bench's own, LOAD_A/LOAD_B,
  x4 at :attr:`Cn2Settings.load_counts_per_turn` counts per output turn, counting up as the
  encoder outputs do), which sees the load after the gear's wind-up, kinematic error and lost
  motion.

:class:`VirtualBenchInstrument` runs a servo axis and samples those outputs like a logic analyzer
with one analog input: whole captures (:meth:`~VirtualBenchInstrument.record`), a stream of
:class:`~fha_studio.hardware.bench.capture.SampleBlock` (:meth:`~VirtualBenchInstrument.stream`),
written as ``.sr``, VCD or CSV (:meth:`~VirtualBenchInstrument.write`). What the drive itself
counted at each sample is kept in :attr:`~VirtualBenchInstrument.truth`, for tests and training.
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from fha_studio.hardware.bench import writers
from fha_studio.hardware.bench.capture import SampleBlock, join_blocks, logic_dtype, pack_logic
from fha_studio.hardware.bench.waveform import Waveform
from fha_studio.hardware.parameters import AlarmTable, load_alarm_table, load_cn2
from fha_studio.hardware.sim.spd_cmd import VirtualAnalogOutput
from fha_studio.physics import ServoAxis

if TYPE_CHECKING:
    from fha_studio.hardware.sim.drive import SimDrive

LOGIC_CHANNELS = ("ENC_A", "ENC_B", "ENC_Z", "CMD_A", "CMD_B", "IN_POS", "ALARM", "ALM_A", "ALM_B", "ALM_C",
                  "ALM_D")
#: The alarm code lines, bit 0 (ALM-A) ... bit 3 (ALM-D) of the code written D C B A.
ALM_CHANNELS = ("ALM_A", "ALM_B", "ALM_C", "ALM_D")
#: an external encoder on the output flange, when the bench has one
LOAD_CHANNELS = ("LOAD_A", "LOAD_B")
ANALOG_CHANNELS = ("SPD_MON",)
RAD_S_PER_RPM = 2.0 * math.pi / 60.0
#: One sample per edge at least: the instrument refuses a rate at which its own edges would merge.
MIN_SAMPLES_PER_EDGE = 2.0
FORMS = ("sr", "vcd", "sigrok-csv", "csv", "csv-semicolon")


@dataclass(frozen=True)
class MonitorModel:
    """SPD-MON's imperfections (assumptions: the public manual states none of them)."""

    offset_v: float = 0.015
    noise_v: float = 0.004  # rms
    bandwidth_hz: float = 2000.0  # first-order
    seed: int | None = 0


@dataclass(frozen=True)
class Cn2Settings:
    """The drive's parameters that shape its CN2 outputs (wire values); the electronic gear
    (parameters 3/4) is the servo's own (``ServoSettings``)."""

    counts_per_motor_turn: int = 10000
    pulse_form: int = 0  # parameter 1
    multiplication: int = 4  # parameter 2
    speed_conversion_rpm: float = 3000.0  # parameter 9
    monitor: MonitorModel = field(default_factory=MonitorModel)
    #: an external encoder on the output flange (x4 counts per output turn), or None
    load_counts_per_turn: int | None = None
    #: SPD-MON on the instrument's analog input (False: a logic analyzer without one wired)
    speed_monitor: bool = True

    @property
    def logic_channels(self) -> tuple[str, ...]:
        """Every line sampled by default: CN2's, and the load's encoder where there is one."""
        return LOGIC_CHANNELS + (LOAD_CHANNELS if self.load_counts_per_turn else ())


@dataclass
class Truth:
    """What the drive counted at each instrument sample (to check a decoding against)."""

    encoder_counts: list[np.ndarray] = field(default_factory=list)
    command_pulses: list[np.ndarray] = field(default_factory=list)
    command_counts: list[np.ndarray] = field(default_factory=list)
    motor_rpm: list[np.ndarray] = field(default_factory=list)
    load_counts: list[np.ndarray] = field(default_factory=list)  # the external encoder's, if any

    def arrays(self) -> dict[str, np.ndarray]:
        return {
            name: np.concatenate(getattr(self, name)) if getattr(self, name) else np.zeros(0)
            for name in ("encoder_counts", "command_pulses", "command_counts", "motor_rpm", "load_counts")
        }


class Cn2Signals:
    """Servo trace chunks in, instrument samples out (state carried from chunk to chunk)."""

    def __init__(
        self,
        sample_rate_hz: float,
        settings: Cn2Settings,
        *,
        output_pulse_rad: float,
        ratio: float,
        in_position_range_counts: int,
        direction: float = 1.0,
        gear: tuple[int, int] = (1, 1),
        alarm_table: AlarmTable | None = None,
        encoder_counts_cw: bool = False,
        logic_channels: tuple[str, ...] | None = None,
        speed_command: Callable[[np.ndarray], np.ndarray] | None = None,
    ):
        """``direction``: +1 when a FWD command turns the flange CW (parameter 8); the encoder
        outputs count up on a FWD command unless ``encoder_counts_cw`` (then on CW rotation).
        ``logic_channels``: the ones sampled, in this order (an instrument's selection; None:
        ``settings.logic_channels``)."""
        if logic_channels is None:
            logic_channels = settings.logic_channels
        self.rate = float(sample_rate_hz)
        #: SPD-CMD's volts at the drive's times, recorded as ``SPD_CMD`` (None: not probed)
        self.speed_command = speed_command
        self.s = settings
        self.pulse_rad = output_pulse_rad
        self.ratio = ratio
        self.in_position_range = in_position_range_counts
        self.direction = direction
        self.gear_numerator, self.gear_denominator = gear
        self.alarm_table = alarm_table or load_alarm_table("HA-655")
        self.encoder_counts_cw = encoder_counts_cw
        known = settings.logic_channels
        unknown = [c for c in logic_channels if c not in known]
        if unknown:
            raise ValueError(f"no CN2 output {', '.join(unknown)} (there are {', '.join(known)})")
        self.logic_channels = tuple(logic_channels)
        self.next_sample = 0
        # t, pos, cmd, vel, controller, load at the last trace point
        self._last: tuple[float, float, float, float, float, float] | None = None
        self._sign = 0
        self._last_pulses: int | None = None
        wc = 2.0 * math.pi * settings.monitor.bandwidth_hz
        alpha = 1.0 - math.exp(-wc / self.rate)
        self._filter = (np.array([alpha]), np.array([1.0, alpha - 1.0]))
        self._zi: np.ndarray | None = None
        self._rng = np.random.default_rng(settings.monitor.seed)

    def feed(
        self, trace: dict[str, np.ndarray], alarm: int = 0
    ) -> tuple[SampleBlock, dict[str, np.ndarray]]:
        """The samples up to the trace's last time, and the drive's own counts at them.
        ``alarm``: the active alarm's code (0: none)."""
        t = trace["t"]
        pos = trace["pos"] * self.direction
        cmd = trace["cmd_pos"] * self.direction
        vel = trace["vel"] * self.direction
        sent = trace["controller_pos"]  # the controller's command, already in the command frame
        load = trace["load_pos"] * self.direction  # the flange, in the command's sense as pos
        if self._last is not None:
            t = np.concatenate(([self._last[0]], t))
            pos = np.concatenate(([self._last[1]], pos))
            cmd = np.concatenate(([self._last[2]], cmd))
            vel = np.concatenate(([self._last[3]], vel))
            sent = np.concatenate(([self._last[4]], sent))
            load = np.concatenate(([self._last[5]], load))
        if t.size == 0:
            return self._empty(), {}
        if self._last is None and self.next_sample == 0:
            self.next_sample = max(0, math.ceil(t[0] * self.rate - 1e-9))  # a drive that ran a while
        last_index = math.floor(t[-1] * self.rate + 1e-9)
        k = np.arange(self.next_sample, last_index + 1)
        ts = k / self.rate
        first = self.next_sample
        self.next_sample = last_index + 1
        self._last = (
            float(t[-1]), float(pos[-1]), float(cmd[-1]), float(vel[-1]), float(sent[-1]), float(load[-1])
        )
        if k.size == 0:
            return self._empty(), {}
        p = np.interp(ts, t, pos)
        c = np.interp(ts, t, cmd)
        v = np.interp(ts, t, vel)
        sent_rad = np.interp(ts, t, sent)
        counts = np.floor(p / self.pulse_rad + 0.5).astype(np.int64)
        # command input pulses (before the electronic gear); two-phase at x2 / x1 takes 2 / 4 edges
        # per pulse, so its lines follow the command edge by edge
        per = 4 // self.s.multiplication if self.s.pulse_form == 2 else 1
        edges = np.floor(
            sent_rad / self.pulse_rad * self.gear_denominator / self.gear_numerator * per + 0.5
        ).astype(np.int64)
        pulses = np.floor_divide(edges, per)
        cmd_counts = np.floor(c / self.pulse_rad + 0.5).astype(np.int64)
        self._check_steps(counts, "encoder edges")
        # the outputs' count: in the command's sense, or the flange's CW one
        outputs = counts if not self.encoder_counts_cw or self.direction > 0 else -counts
        enc_a, enc_b = _quadrature_levels(outputs)
        enc_z = np.mod(outputs, self.s.counts_per_motor_turn) == 0
        cmd_a, cmd_b = self._command_levels(edges if self.s.pulse_form == 2 else pulses)
        in_pos = np.abs(cmd_counts - counts) <= self.in_position_range
        motor_rpm = v / RAD_S_PER_RPM * self.ratio
        m = self.s.monitor
        levels = {"ENC_A": enc_a, "ENC_B": enc_b, "ENC_Z": enc_z, "CMD_A": cmd_a, "CMD_B": cmd_b,
                  "IN_POS": in_pos}
        levels.update(self._alarm_levels(int(alarm), k.size))
        truth = {
            "encoder_counts": outputs,
            "command_pulses": pulses,
            "command_counts": pulses * self.gear_numerator / self.gear_denominator,
            "motor_rpm": motor_rpm,
        }
        if self.s.load_counts_per_turn:
            turns = np.interp(ts, t, load) / (2.0 * math.pi)
            load_counts = np.floor(turns * self.s.load_counts_per_turn + 0.5).astype(np.int64)
            if self.encoder_counts_cw and self.direction < 0:
                load_counts = -load_counts  # counted up as the encoder outputs are
            self._check_steps(load_counts, "load encoder's edges")
            levels["LOAD_A"], levels["LOAD_B"] = _quadrature_levels(load_counts)
            truth["load_counts"] = load_counts
        logic = pack_logic([levels[name] for name in self.logic_channels])
        analog = {}
        if self.s.speed_monitor:
            analog["SPD_MON"] = self._speed_monitor_volts(motor_rpm)
        if self.speed_command is not None:  # the instrument's second input on CN2-31/32
            command = self.speed_command(ts) + self._rng.normal(0.0, m.noise_v, ts.size)
            analog["SPD_CMD"] = np.asarray(command, np.float32)
        block = SampleBlock(self.rate, self.logic_channels, logic, analog, first)
        return block, truth

    def _speed_monitor_volts(self, motor_rpm: np.ndarray) -> np.ndarray:
        """SPD-MON: parameter 9's scale, the monitor's first-order bandwidth, offset and noise."""
        volts = motor_rpm / self.s.speed_conversion_rpm * 10.0
        b, a = self._filter
        # scipy.signal takes a second of CPU to import: only a drive whose CN2 is sampled pays it
        from scipy import signal as _signal

        if self._zi is None:
            self._zi = _signal.lfilter_zi(b, a) * volts[0]
        volts, self._zi = _signal.lfilter(b, a, volts, zi=self._zi)
        m = self.s.monitor
        noisy = volts + m.offset_v + self._rng.normal(0.0, m.noise_v, volts.size)
        out: np.ndarray = noisy.astype(np.float32)
        return out

    def _alarm_levels(self, code: int, n: int) -> dict[str, np.ndarray]:
        """ALARM (on while an alarm is active) and ALM-A ... D: the table's 4-bit code (a code the
        table does not know gives 0000)."""
        known = self.alarm_table.get(code) if code else None
        bits = known.alm_bits if known is not None else 0
        levels = {"ALARM": np.full(n, code != 0)}
        for bit, name in enumerate(ALM_CHANNELS):
            levels[name] = np.full(n, bool(bits >> bit & 1))
        return levels

    def _empty(self) -> SampleBlock:
        return SampleBlock(
            self.rate,
            self.logic_channels,
            np.zeros(0, logic_dtype(max(1, len(self.logic_channels)))),
            {name: np.zeros(0, np.float32)
             for name in (*(("SPD_MON",) if self.s.speed_monitor else ()),
                          *(("SPD_CMD",) if self.speed_command is not None else ()))},
            self.next_sample,
        )

    def _check_steps(self, values: np.ndarray, what: str) -> None:
        if values.size > 1 and np.any(np.abs(np.diff(values)) > 1):
            raise ValueError(
                f"the instrument's {self.rate:g} Hz is too slow for the {what}: more than one "
                "per sample; sample faster"
            )

    def _command_levels(self, pulses: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        prev = self._last_pulses if self._last_pulses is not None else int(pulses[0])
        self._last_pulses = int(pulses[-1])
        steps = np.diff(np.concatenate(([prev], pulses)))
        form = self.s.pulse_form
        if form == 2:  # ``pulses`` are the edges here
            self._check_steps(np.concatenate(([prev], pulses)), "command edges")
            return _quadrature_levels(pulses)
        if np.any(np.abs(steps) > 1):
            raise ValueError(f"the instrument's {self.rate:g} Hz is too slow for the command pulses")
        up = steps > 0
        down = steps < 0
        moved = np.flatnonzero(steps)
        if moved.size > 1 and np.any(np.diff(moved) < 2):
            raise ValueError(
                f"the instrument's {self.rate:g} Hz is too slow for the command pulses: "
                "two in consecutive samples"
            )
        if form == 0:
            return up, down
        # pulse + sign: the sign holds the direction of the last pulse (high = REV)
        sign = np.full(pulses.size, -1, np.int8)
        sign[moved] = down[moved].astype(np.int8)
        last = np.maximum.accumulate(np.where(sign >= 0, np.arange(sign.size), -1))
        held = np.where(last >= 0, sign[np.maximum(last, 0)], self._sign).astype(bool)
        self._sign = int(held[-1])
        return up | down, held


def signals_of_axis(axis: ServoAxis, sample_rate_hz: float, settings: Cn2Settings, *,
                    alarm_table: AlarmTable | None = None,
                    logic_channels: tuple[str, ...] | None = None,
                    speed_command: Callable[[np.ndarray], np.ndarray] | None = None) -> Cn2Signals:
    """The CN2 outputs of a servo axis (its resolution, ratio, in-position range, direction and
    electronic gear) at an instrument's rate, with the driver's alarm table and CN2; with
    ``speed_command`` SPD-CMD's volts beside them."""
    model = axis.model
    table = alarm_table or load_alarm_table("HA-655")
    return Cn2Signals(
        sample_rate_hz,
        settings,
        output_pulse_rad=model.output_pulse_rad,
        ratio=float(model.ratio or 1),
        in_position_range_counts=axis.settings.in_position_range_pulses,
        direction=axis.settings.direction_sign,
        gear=(axis.settings.electronic_gear_numerator, axis.settings.electronic_gear_denominator),
        alarm_table=table,
        encoder_counts_cw=load_cn2(table.driver).encoder_counts_up_on == "CW",
        logic_channels=logic_channels,
        speed_command=speed_command,
    )


def settings_of_drive(
    drive: SimDrive,
    monitor: MonitorModel | None = None,
    load_counts_per_turn: int | None = None,
    speed_monitor: bool = True,
) -> Cn2Settings:
    """The simulated drive's parameters 1, 2 and 9 and its resolution, as CN2 shows them (and the
    bench's external encoder on the output flange, if it has one; SPD-MON unless ``speed_monitor``
    is False)."""
    model = drive.axis.model
    return Cn2Settings(
        counts_per_motor_turn=round(model.output_resolution_ppr / (model.ratio or 1)),
        pulse_form=drive.memory.value("command_pulse_configuration"),
        multiplication=drive.memory.value("two_phase_pulse_multiplication"),
        speed_conversion_rpm=float(drive.memory.value("speed_conversion_factor")),
        monitor=monitor or MonitorModel(),
        load_counts_per_turn=load_counts_per_turn,
        speed_monitor=speed_monitor,
    )


def _quadrature_levels(counts: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """A/B levels of a x4 count: phase 0..3 = 00, 10, 11, 01 (A leads B going forward)."""
    phase = np.mod(counts, 4)
    return (phase == 1) | (phase == 2), phase >= 2


class VirtualBenchInstrument:
    """A logic analyzer with one analog input on the simulated drive's CN2.

    It advances ``axis`` itself, or the drive through ``advance`` (a stepped
    :class:`~fha_studio.hardware.sim.drive.SimDrive`'s, :meth:`on_drive`), tracing every servo
    period; the caller commands moves between calls.
    """

    def __init__(
        self,
        axis: ServoAxis,
        sample_rate_hz: float,
        settings: Cn2Settings | None = None,
        *,
        alarm: Callable[[], int] | None = None,
        advance: Callable[[float], None] | None = None,
        alarm_table: AlarmTable | None = None,
        speed_command: Callable[[np.ndarray], np.ndarray] | None = None,
    ):
        self.axis = axis
        self._advance = advance
        self.settings = settings or Cn2Settings()
        self.signals = signals_of_axis(axis, sample_rate_hz, self.settings, alarm_table=alarm_table,
                                       speed_command=speed_command)
        self.alarm = alarm or (lambda: 0)
        self.truth = Truth()
        self._blocks: list[SampleBlock] = []

    @property
    def sample_rate_hz(self) -> float:
        return self.signals.rate

    def stream(self, seconds: float, block_s: float = 0.01) -> Iterator[SampleBlock]:
        """Blocks of about ``block_s`` while the axis runs for ``seconds`` (drive time)."""
        periods = max(1, round(block_s / self.axis.servo_period_s))
        total = max(1, round(seconds / self.axis.servo_period_s))
        if self.signals._last is None:
            self.axis.start_trace(1)
            self._step(1)  # the first trace point: where the axis is now
        done = 0
        while done < total:
            n = min(periods, total - done)
            self._step(n)
            done += n
            block, truth = self.signals.feed(self.axis.read_trace(clear=True), self.alarm())
            if block.samples:
                for name, values in truth.items():
                    getattr(self.truth, name).append(values)
                yield block

    def _step(self, periods: int) -> None:
        if self._advance is None:
            self.axis.step(periods)
        else:
            self._advance(periods * self.axis.servo_period_s)

    @classmethod
    def on_drive(
        cls, drive: SimDrive, sample_rate_hz: float, monitor: MonitorModel | None = None,
        *, speed_command: bool = False, load_counts_per_turn: int | None = None, speed_monitor: bool = True,
    ) -> VirtualBenchInstrument:
        """The instrument on a stepped simulated drive's CN2: its parameters 1, 2 and 9, its
        resolution, its alarm (code); the drive's time advances as the instrument records. With
        ``speed_command`` an analog input on SPD-CMD (CN2-31/32) too: channel ``SPD_CMD``;
        ``load_counts_per_turn``: an external encoder on the output flange (LOAD_A/LOAD_B);
        ``speed_monitor``: False for a logic analyzer with no analog input on SPD-MON."""
        settings = settings_of_drive(drive, monitor, load_counts_per_turn, speed_monitor)
        return cls(drive.axis, sample_rate_hz, settings, alarm=lambda: drive.alarm, advance=drive.advance,
                   alarm_table=drive.alarm_table,
                   speed_command=drive.speed_command_input.volts if speed_command else None)

    def record(self, seconds: float) -> SampleBlock:
        """Run for ``seconds`` and keep what was sampled; returns everything kept so far."""
        self.keep(seconds, 0.01)
        return self.capture()

    def keep(self, seconds: float, block_s: float = 0.05) -> None:
        """Run for ``seconds`` and keep what was sampled (a capture made piece by piece, between
        the caller's commands, without joining what it holds at every piece; in blocks of
        ``block_s``, longer than a live stream's: fewer, larger array operations)."""
        self._blocks.extend(self.stream(seconds, block_s))

    def capture(self) -> SampleBlock:
        """Everything recorded so far, as one block."""
        if not self._blocks:
            raise ValueError("nothing recorded yet")
        return join_blocks(self._blocks)

    def write(self, path: str | os.PathLike[str], form: str) -> Path:
        """The capture so far in one of :data:`FORMS` (VCD: SPD-MON as a real variable)."""
        block = self.capture()
        if form == "sr":
            return writers.write_sr(path, block)
        if form == "vcd":
            return writers.write_vcd(path, block)
        if form == "sigrok-csv":
            return writers.write_sigrok_csv(path, block)
        if form in ("csv", "csv-semicolon"):
            return writers.write_csv(path, block, semicolon=form == "csv-semicolon")
        raise ValueError(f"form '{form}': one of {', '.join(FORMS)}")

    @staticmethod
    def fastest_edges_hz(motor_rpm: float, counts_per_motor_turn: int) -> float:
        """The encoder's edge rate at a motor speed (to choose the sample rate)."""
        return abs(motor_rpm) / 60.0 * counts_per_motor_turn


def record_playback(drive: SimDrive, wave: Waveform | str | os.PathLike[str], sample_rate_hz: float, *,
                    speed_command: bool = True, margin_s: float = 0.1) -> VirtualBenchInstrument:
    """A DAQ's output (:class:`.spd_cmd.VirtualAnalogOutput`) plays ``wave`` into a stepped
    drive's SPD-CMD while the virtual instrument records its CN2 outputs (and SPD-CMD), from
    ``margin_s`` before the file starts until ``margin_s`` after it ends: a bench capture of an
    excitation, as a technician makes one on a real drive in speed mode."""
    instrument = VirtualBenchInstrument.on_drive(drive, sample_rate_hz, speed_command=speed_command)
    instrument.record(margin_s)
    playback = VirtualAnalogOutput(drive).play(wave)
    instrument.record(playback.end_s - drive.time_s + margin_s)
    return instrument
