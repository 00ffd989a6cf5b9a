"""Step 5's overlay: the recorded command re-simulated with the nominal and the updated model."""

from __future__ import annotations

import numpy as np
from scipy.signal import savgol_filter

from fha_studio.logic.modelcheck.axis import DeclaredAxis, ModelCheckError, rms
from fha_studio.logic.modelcheck.result import Resimulation
from fha_studio.logic.modelcheck.signals import ARCSEC_PER_RAD, POLYORDER, Signals
from fha_studio.physics import AxisModel, ServoSettings, simulate

RESIM_BANDWIDTH_HZ = 60.0  # speed-loop bandwidth of the stiff servo that follows the measured motion


def resimulate(
    sig: Signals,
    axis: DeclaredAxis,
    nominal: AxisModel,
    updated: AxisModel,
    servo: ServoSettings | None,
    max_s: float,
) -> Resimulation:
    """The recorded command (with ``servo``; else the measured motion through a stiff servo) run
    through the nominal and the updated model, over the first ``max_s`` seconds of the recording."""
    f = sig.filt
    h = f.half
    # the closed loop runs at the servo rate: its cost grows with the duration, not the samples, so
    # only the first max_s seconds are re-simulated (the analysis itself uses all of them)
    n_raw = int(np.searchsorted(sig.raw_t_s, sig.raw_t_s[0] + max_s, side="right"))
    n_raw = max(n_raw, min(len(sig.raw_t_s), 2 * h + 3))
    t = sig.raw_t_s[:n_raw]
    n_valid = n_raw - 2 * h
    if servo is not None and sig.cmd_pos_rad is not None:
        command, cmd = "cmd_pos", sig.cmd_pos_rad[:n_raw]
    else:
        command = "motion (the measured position, smoothed, through a stiff servo)"
        cmd = savgol_filter(sig.raw_pos_rad, f.window, POLYORDER)[:n_raw]
        servo = ServoSettings.tuned_for(nominal, speed_bandwidth_hz=RESIM_BANDWIDTH_HZ, feed_forward_gain=1.0)
    if n_raw < len(sig.raw_t_s):
        command += f", its first {max_s:g} s"
    kt = axis.kt_nm_per_a
    out: dict[str, dict[str, np.ndarray]] = {}
    for name, m in (("nominal", nominal), ("updated", updated)):
        if name == "updated" and updated == nominal:
            # the same model through the same servo: simulate() is deterministic, run it once
            out[name] = out["nominal"]
            continue
        try:
            r = simulate(m, servo, t, cmd)
        except ValueError as exc:
            raise ModelCheckError(f"re-simulation with the {name} model failed: {exc}") from None
        out[name] = r
    meas = sig.torque_f_nm[:n_valid]
    tn = kt * f.apply(out["nominal"]["current"])
    tu = kt * f.apply(out["updated"]["current"])
    res = Resimulation(
        t_s=sig.t_s[:n_valid],
        torque_measured_nm=meas,
        torque_nominal_nm=tn,
        torque_updated_nm=tu,
        pos_measured_deg=np.degrees(sig.pos_rad[:n_valid]),
        pos_nominal_deg=np.degrees(out["nominal"]["pos"][h:-h]),
        pos_updated_deg=np.degrees(out["updated"]["pos"][h:-h]),
        rms_nominal_nm=rms(meas - tn),
        rms_updated_nm=rms(meas - tu),
        command=command,
    )
    if sig.load_diff_f_rad is not None:
        res.load_diff_measured_arcsec = sig.load_diff_f_rad[:n_valid] * ARCSEC_PER_RAD
        for name in ("nominal", "updated"):
            d = f.apply(out[name]["load_pos"] - out[name]["pos"]) * ARCSEC_PER_RAD
            setattr(res, f"load_diff_{name}_arcsec", d)
    return res
