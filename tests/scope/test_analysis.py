import numpy as np
import pytest

from fha_studio.logic.scope.analysis import cursor_delta, move_metrics, spectrum


def second_order_step(t, zeta, wn, step=10.0, t0=0.1):
    """Analytic underdamped step response of a second-order system, starting at t0."""
    tau = np.clip(t - t0, 0, None)
    wd = wn * np.sqrt(1 - zeta**2)
    y = 1 - np.exp(-zeta * wn * tau) * (np.cos(wd * tau) + zeta / np.sqrt(1 - zeta**2) * np.sin(wd * tau))
    return step * y


def test_overshoot_and_settling_of_a_known_second_order_step():
    t = np.arange(0, 2, 1e-4)
    zeta, wn = 0.3, 40.0
    cmd = np.where(t >= 0.1, 10.0, 0.0)
    fb = second_order_step(t, zeta, wn)
    m = move_metrics(t, cmd, fb)
    expected_overshoot = 100 * np.exp(-zeta * np.pi / np.sqrt(1 - zeta**2))  # 37.2 %
    assert m.overshoot_percent == pytest.approx(expected_overshoot, rel=1e-3)
    # 2 % settling envelope of the second-order system: about 4 / (zeta wn) = 0.333 s
    assert 0.25 < m.settling_time_s < 0.36
    assert m.command_end_s == pytest.approx(0.1, abs=1e-4)
    assert m.final_error == pytest.approx(0, abs=1e-6)


def test_in_position_time_counts_from_the_end_of_the_command():
    t = np.arange(0, 1, 1e-3)
    cmd = np.clip((t - 0.1) * 100, 0, 20)  # ramp from 0.1 s to 0.3 s
    fb = np.clip((t - 0.15) * 100, 0, 20)  # lags 50 ms
    m = move_metrics(t, cmd, fb, in_position_range=0.5)
    assert m.command_end_s == pytest.approx(0.3, abs=1e-3)
    assert m.in_position_time_s == pytest.approx(0.045, abs=2e-3)  # within 0.5 at 0.345 s
    assert m.overshoot == 0


def test_a_capture_that_never_settles_says_so():
    t = np.arange(0, 1, 1e-3)
    cmd = np.where(t > 0.1, 1.0, 0.0)
    fb = np.where(t > 0.1, 1.0 + 0.2 * np.sin(60 * t), 0.0)
    m = move_metrics(t, cmd, fb, in_position_range=0.01)
    assert m.settling_time_s is None and m.in_position_time_s is None
    assert "not reached" in m.describe("deg")


def test_no_move_is_refused():
    with pytest.raises(ValueError, match="does not move"):
        move_metrics([0, 1, 2], [1, 1, 1], [1, 1, 1])


def test_spectrum_finds_a_kinematic_error_on_a_ramp():
    fs, f_ke = 1000.0, 37.5
    t = np.arange(0, 4, 1 / fs)
    pos = 30.0 * t + 0.002 * np.sin(2 * np.pi * f_ke * t)  # constant speed + periodic error
    s = spectrum(t, pos)
    (f_peak, a_peak), *_ = s.peaks(1, min_hz=1)
    assert f_peak == pytest.approx(f_ke, abs=0.3)
    assert a_peak == pytest.approx(0.002, rel=0.1)


def test_spectrum_refuses_non_uniform_sampling():
    t = np.cumsum(np.r_[0, np.full(50, 1e-3), np.full(50, 2e-3)])
    with pytest.raises(ValueError, match="not uniformly sampled"):
        spectrum(t, np.sin(t))


def test_cursor_delta_interpolates_and_gives_slope():
    t = np.linspace(0, 1, 11)
    d = cursor_delta(t, 3 * t + 1, 0.25, 0.75)
    assert d.dt_s == pytest.approx(0.5)
    assert d.dvalue == pytest.approx(1.5)
    assert d.slope_per_s == pytest.approx(3)


def test_prominent_peaks_find_a_line_on_a_drifting_spectrum():
    t = np.arange(2048) / 1000.0
    rng = np.random.default_rng(3)
    drift = np.cumsum(rng.normal(0, 0.5, len(t)))  # a random walk: big at low frequencies
    x = drift + 0.3 * np.sin(2 * np.pi * 166.7 * t) + rng.normal(0, 0.01, len(t))
    spec = spectrum(t, x, detrend="constant")
    assert spec.peaks(1)[0][0] < 5.0  # plain maxima: the drift
    (f, amp), *_ = spec.prominent_peaks(1)
    assert abs(f - 166.7) < 1.0 and abs(amp - 0.3) < 0.05
