"""Convert measured runs of the DFKI torque-limited simple pendulum into fha-recording/1 files, gzipped.

The pendulum (DFKI Robotics Innovation Center, Underactuated Robotics Lab) is a rod with a point
mass driven directly by a T-Motor AK80-6 quasi-direct-drive actuator (6:1 planetary gear, 12 bit
encoder, torque estimated from the motor current). Its ``results/*/data_measured.csv`` files hold
``time`` [s], ``position`` [rad] (counter-clockwise, 0 = hanging down), ``velocity`` [rad/s] and
``torque`` [N m] at the output, the actuator's own readings; ``data_desired.csv`` the trajectory
the controller followed. See README.md beside this file for the source, the licence and the
published parameters.

Written one to one: ``pos`` = degrees(position), ``current`` = torque with
``torque_constant_nm_per_a`` = 1 (the actuator reports N m, not amperes), ``cmd_pos`` =
degrees(the desired position at the measured times). Declared: the pendulum's inertia as DFKI's
model of it holds it (a 0.57288 kg point mass at 0.5 m, I = m l^2) plus the rotor reflected
through the gear (6.0719e-5 kg m^2 x 6^2), as ``actuator_inertia_kgm2`` (no load apart from it),
and the gear ratio 6.

Usage: python tests/modelcheck/real/convert_dfki.py RESULTS_DIR [OUT_DIR]
(RESULTS_DIR: the repository's ``results/``; github.com/dfki-ric-underactuated-lab/
torque_limited_simple_pendulum, commit ed17ea2).
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
from recording_gz import main, write_recording_gz

#: DFKI's model of the pendulum (leaderboard/simulation/sim_parameters.py): mass at its length.
MODEL_MASS_KG = 0.57288
MODEL_LENGTH_M = 0.5
#: The AK80-6's rotor inertia and gear (docs: testbench description, motor constants).
ROTOR_INERTIA_KGM2 = 6.0719e-5
GEAR_RATIO = 6.0
DECLARED_INERTIA_KGM2 = MODEL_MASS_KG * MODEL_LENGTH_M**2 + ROTOR_INERTIA_KGM2 * GEAR_RATIO**2

RUNS = {
    "control_method_ddp": "dfki_pendulum_ddp.csv.gz",  # a swing-up (FDDP trajectory), 6 s at 500 Hz
}


def _read(path: Path) -> np.ndarray:
    data = np.loadtxt(path, delimiter=",", skiprows=1)
    if data.ndim != 2 or data.shape[1] != 4:
        raise ValueError(f"{path}: expected time,position,velocity,torque")
    return data


def convert(run_dir: Path, out_path: Path) -> int:
    """Write one run as a gzipped fha-recording/1 file; returns the number of rows."""
    t, position, _, torque = _read(run_dir / "data_measured.csv").T
    desired = run_dir / "data_desired.csv"
    columns = ["t", "pos", "current"]
    data = [t - t[0], np.degrees(position), torque]
    fmt = ["%.6f", "%.9g", "%.6g"]
    if desired.exists():
        td, pd, _, _ = _read(desired).T
        columns.append("cmd_pos")
        data.append(np.degrees(np.interp(t, td, pd)))
        fmt.append("%.9g")
    rate = 1.0 / float(np.median(np.diff(t)))
    header = [
        f"# sample_rate_hz: {rate:.6g}",
        "# torque_constant_nm_per_a: 1",
        f"# actuator_inertia_kgm2: {DECLARED_INERTIA_KGM2:.6g}",
        f"# motor_turns_per_output_rev: {GEAR_RATIO:g}",
        f"# source: DFKI torque-limited simple pendulum, results/{run_dir.name}, converted by "
        f"{Path(__file__).name}",
        "# units: current = the actuator's torque reading in N m (torque constant 1); pos counter-clockwise,"
        " 0 = hanging down",
    ]
    write_recording_gz(out_path, header, columns, data, fmt)
    return len(t)


if __name__ == "__main__":
    sys.exit(main(sys.argv, RUNS, convert, __file__))
