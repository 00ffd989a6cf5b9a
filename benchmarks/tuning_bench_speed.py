"""Tuning from the bench: CPU time of its steps on the simulated drive's captures.

Run from the checkout: PYTHONPATH=. python benchmarks/tuning_bench_speed.py

For FHA-25C-50 at 1 x and 3 x the actuator's own inertia: designing the SPD-CMD excitation (its
bounds from the linearised loop driven by the whole file), the simulated bench (the virtual DAQ
output playing the file into SPD-CMD while the virtual instrument records CN2 at 25 kS/s: the
simulation, not FHA Studio's work on a real capture), reading the capture and analysing it
(SPD-CMD recorded; and the file as the input, aligned by cross-correlation), and fitting the loop to
a move captured at 250 kS/s. Each figure is the process's CPU time (the wall time on a shared,
loaded machine is several times it), with the drive time the capture covers.
"""

from __future__ import annotations

import math
import tempfile
import time
from pathlib import Path

from fha_studio.hardware.bench.waveform import write_waveform
from fha_studio.hardware.parameters import Mode, load_parameter_model
from fha_studio.hardware.sim.cn2 import Cn2Settings, VirtualBenchInstrument, record_playback
from fha_studio.hardware.sim.drive import SimDrive
from fha_studio.logic.tuning.bench_excitation import design_excitation
from fha_studio.logic.tuning.bench_session import (
    RoleSignal,
    bench_move_report,
    bench_response_report,
    bench_tuner,
)
from fha_studio.logic.tuning.session import declared_model
from fha_studio.physics import ServoAxis

CODE = "FHA-25C-50-US250"
PARAMETERS = load_parameter_model("HA-655")
RPM = 2 * math.pi / 60


def _values(**extra: int) -> dict[tuple[str, int], int]:
    values = {(str(i.mode), i.number): int(i.default) for i in PARAMETERS
              if i.mode in (Mode.TUNE, Mode.SYSTEM) and i.default is not None}
    values.update({("system", 0): extra.get("control_mode", 0)})
    return values


def _cpu(what: str, job, note: str = ""):  # type: ignore[no-untyped-def]
    start = time.process_time()
    result = job()
    print(f"  {what:<46} {time.process_time() - start:6.2f} s CPU {note}")
    return result


def one_load(folder: Path, ratio: float) -> None:
    own = declared_model(CODE, 0.0).actuator_inertia_kgm2
    load = ratio * own
    print(f"{CODE}, load {ratio:g} x its own inertia ({load:.3g} kg m^2):")
    tuner = bench_tuner(CODE, load, PARAMETERS, _values(control_mode=1))
    excitation = _cpu("design the excitation (bounds from the loop)", lambda: design_excitation(tuner))
    path = write_waveform(folder / f"exc{ratio:g}.csv", excitation.waveform, "csv")

    def bench() -> Path:
        with SimDrive(CODE, load_inertia_kgm2=load, effects={"torsional_compliance": {}},
                      preset=(("system", 0, 1),)) as drive:
            drive.set_servo(True)
            drive.advance(0.05)
            return record_playback(drive, path, 25000.0).write(folder / f"cap{ratio:g}.sr", "sr")

    capture = _cpu("simulated bench (drive + instrument)", bench,
                   f"({excitation.waveform.duration_s:.1f} s of drive time)")
    signals = [RoleSignal("speed_monitor", str(capture), "SPD_MON"),
               RoleSignal("speed_command", str(capture), "SPD_CMD")]
    _cpu("read + analyse, SPD-CMD recorded", lambda: bench_response_report(tuner, signals))
    _cpu("read + analyse, the file aligned", lambda: bench_response_report(tuner, signals[:1], str(path)))

    def move() -> Path:
        settings = bench_tuner(CODE, 0.0, PARAMETERS, _values()).loop({}).settings
        axis = ServoAxis(declared_model(CODE, load), settings)
        axis.servo_on()
        instrument = VirtualBenchInstrument(axis, 250e3, Cn2Settings())
        instrument.record(0.05)
        for angle in (10.0, -10.0):
            axis.move_by(math.radians(angle), speed_rad_s=10 * RPM, accel_rad_s2=200 * RPM)
            instrument.record(0.7)
        return instrument.write(folder / f"move{ratio:g}.sr", "sr")

    moved = _cpu("simulated move (axis + instrument)", move, "(1.45 s at 250 kS/s)")
    roles = {"encoder_a": "ENC_A", "encoder_b": "ENC_B", "command_a": "CMD_A", "command_b": "CMD_B",
             "speed_monitor": "SPD_MON"}
    move_signals = [RoleSignal(r, str(moved), c) for r, c in roles.items()]
    fit_tuner = bench_tuner(CODE, 0.0, PARAMETERS, _values())
    result = _cpu("import + fit the loop to the move",
                  lambda: bench_move_report(fit_tuner, move_signals, _values()))
    print(f"  (the fit: {result['load_inertia_estimate_kgm2']:.3g} kg m^2 for {load:.3g})")


def main() -> None:
    folder = Path(tempfile.mkdtemp(prefix="fha-bench-tuning-"))
    for ratio in (1.0, 3.0):
        one_load(folder, ratio)


if __name__ == "__main__":
    main()
