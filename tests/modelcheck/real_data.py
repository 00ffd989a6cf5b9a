"""The public real recordings of tests/modelcheck/real/ (see README.md there), read by the real reader."""

from __future__ import annotations

import gzip
from pathlib import Path

from fha_studio.recording import Recording, parse_recording

REAL = Path(__file__).resolve().parent / "real"

#: The EMPS paper's reference model (IDIM-LS on the estimation run): Janot, Gautier, Brunot,
#: "Data Set and Reference Models of EMPS"; N, N s/m, kg (1 m written as 1 rad).
EMPS_REFERENCE = {
    "mass_kg": 95.1089,
    "viscous_n_s_per_m": 203.5034,
    "coulomb_n": 20.3935,
    "offset_n": -3.1648,
}


#: The DFKI torque-limited simple pendulum's published parameters (README.md beside the files):
#: measured geometry (0.676 kg with its centre of mass 0.45 m from the axis, g = 9.81) and the range
#: of DFKI's own friction figures for the real pendulum.
DFKI_REFERENCE = {
    "gravity_nm": 0.676 * 9.81 * 0.45,
    "coulomb_nm_low": 0.093,  # leaderboard simulation model
    "coulomb_nm_high": 0.5 * 3.141592653589793 * 0.1839,  # their identification: F_c atan(100 q')
}


def real_recording(name: str) -> Recording:
    """One of the converted public recordings, e.g. ``emps_pulses`` (gzipped fha-recording/1)."""
    path = REAL / f"{name}.csv.gz"
    with gzip.open(path, "rt", encoding="utf-8") as fh:
        return parse_recording(fh.read(), source=path.name)
