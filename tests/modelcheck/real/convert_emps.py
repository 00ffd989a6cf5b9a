"""Convert the public EMPS data set (MATLAB .mat files) into fha-recording/1 files, gzipped.

The EMPS (Electro-Mechanical Positioning System, ONERA/LS2N) is a linear axis: a DC motor and a
ball screw drive a carriage; a dSPACE card runs a P/P position-velocity loop at 1 kHz and records
the motor position ``qm`` [m], the reference ``qg`` [m], the controller output ``vir`` [V] (the
force is ``gtau * vir``, gtau = 35.15 N/V) and, in the validation run, ``pulses_N`` (the trigger
of the unmeasured force pulses). See README.md beside this file for the source and licence.

A linear axis is written as a rotary one, one to one: 1 m of travel = 1 rad of output, 1 N = 1 N m,
1 kg = 1 kg m^2, 1 N s/m = 1 N m s/rad. So ``pos`` = degrees(qm), ``current`` = vir ("A" here are
the controller's volts), ``torque_constant_nm_per_a`` = gtau, and the declared mass is the
carriage's total inertia (``actuator_inertia_kgm2``; no load declared apart from it).

Usage: python tests/modelcheck/real/convert_emps.py DIR_WITH_MAT_FILES [OUT_DIR]
(scipy.io.loadmat reads the files; the published .mat files come from
github.com/forgi86/sysid-neural-continuous, examples/EMPS/data/).
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
import scipy.io
from recording_gz import main, write_recording_gz

#: The carriage's mass as declared to the check [kg]: the data set's own reference value (Janot,
#: Gautier, Brunot, "Data set and reference models of EMPS", M1 = 95.1089 kg), rounded.
DECLARED_MASS_KG = 95.1

RUNS = {
    "DATA_EMPS.mat": "emps.csv.gz",  # estimation run: bang-bang accelerations, no pulses
    "DATA_EMPS_PULSES.mat": "emps_pulses.csv.gz",  # validation run: the same, with force pulses
}


def convert(mat_path: Path, out_path: Path) -> int:
    """Write one run as a gzipped fha-recording/1 file; returns the number of rows."""
    d = scipy.io.loadmat(str(mat_path))
    t = d["t"].ravel()
    qm = d["qm"].ravel()
    qg = d["qg"].ravel()
    vir = d["vir"].ravel()
    gtau = float(d["gtau"].ravel()[0])
    kp = float(d["kp"].ravel()[0])
    kv = float(d["kv"].ravel()[0])
    columns = ["t", "pos", "current", "cmd_pos"]
    data = [t, np.degrees(qm), vir, np.degrees(qg)]
    fmt = ["%.6f", "%.9g", "%.6g", "%.9g"]
    if "pulses_N" in d:
        columns.append("force_pulse_trigger")
        data.append(d["pulses_N"].ravel().astype(float))
        fmt.append("%.3g")
    header = [
        "# sample_rate_hz: 1000",
        f"# torque_constant_nm_per_a: {gtau:.6g}",
        f"# actuator_inertia_kgm2: {DECLARED_MASS_KG:g}",
        f"# source: EMPS data set (Janot, Gautier, Brunot), {mat_path.name}, "
        f"converted by {Path(__file__).name}",
        "# units: a linear axis written 1 m = 1 rad, 1 N = 1 N m; current = controller output in V",
        f"# loop: position-velocity, kp {kp:g} 1/s, kv {kv:g} V/(m/s), "
        "the velocity loop differentiates 0.5 (q[k] + q[k-1])",
    ]
    # no file name in the header (recording_gz): the same .mat files give the same bytes
    write_recording_gz(out_path, header, columns, data, fmt)
    assert math.isclose(gtau, 35.15, rel_tol=1e-3)
    return len(t)


if __name__ == "__main__":
    sys.exit(main(sys.argv, RUNS, convert, __file__))
