"""The model check's shortcuts compute what the plain way computes (to rounding), and its choices
do not depend on rounding (see benchmarks/modelcheck_speed.py for what they save)."""

from __future__ import annotations

import numpy as np
import pytest

from fha_studio.logic.modelcheck.candidates import CANDIDATES, TORQUE, ChannelContext
from fha_studio.logic.modelcheck.linalg import Beside, block_edges, fold_betas, ols, solve_normal
from fha_studio.logic.modelcheck.selection import ChannelSelector, _first_lowest
from fha_studio.logic.modelcheck.signals import build_signals, make_filter


@pytest.mark.parametrize("window", [11, 13, 57, 111])
@pytest.mark.parametrize("step", [1, 2, 3, 8, 9])
def test_smoothing_at_every_step_th_sample_equals_the_full_smoothing_there(window, step):
    x = np.random.default_rng(window + step).standard_normal(3001).cumsum()
    f = make_filter(window, 1e-3)
    full = f.apply(x)
    every = f.apply_every(x, step)
    assert every.shape == full[::step].shape
    assert np.max(np.abs(every - full[::step])) <= 1e-12 * np.max(np.abs(full))


def test_the_normal_equations_are_solved_as_the_pseudo_inverse_solves_them():
    rng = np.random.default_rng(5)
    x = rng.standard_normal((400, 5)) * [1.0, 1e3, 1e-3, 5.0, 1.0]
    y = rng.standard_normal(400)
    for design in (x, np.column_stack([x, 2.0 * x[:, 0]])):  # full rank, then rank-deficient
        g, b = design.T @ design, design.T @ y
        expected = np.linalg.pinv(g, rcond=1e-10, hermitian=True) @ b
        assert np.allclose(solve_normal(g, b), expected, rtol=1e-9, atol=1e-12 * np.max(np.abs(expected)))


def test_columns_fitted_beside_a_model_get_what_the_whole_least_squares_gives():
    # a shape search and a frequency scan fit one candidate's columns beside the same model by
    # projection: its coefficients and the residual are the whole fit's (columns of very different
    # scales, and a model with a column twice over, whose pseudo-inverse drops the repeat)
    rng = np.random.default_rng(7)
    t = np.linspace(0.0, 10.0, 2500)
    x = np.column_stack([np.ones_like(t), np.sign(np.sin(t)), 1e3 * np.sin(0.3 * t), 1e-3 * t])
    y = x @ [0.5, 2.0, 1e-3, 40.0] + 0.3 * np.sin(7.7 * t + 1.0) + 0.1 * rng.standard_normal(len(t))
    for model in (x, np.column_stack([x, 2.0 * x[:, 1]]), x[:, :0]):
        beside = Beside(y, model)
        for cycles in (7.7, 3.1, 12.0):
            c = np.column_stack([np.sin(cycles * t), 100.0 * np.cos(cycles * t)])
            expected, _ = ols(y, np.column_stack([model, c]))
            beta, residual = beside.fit(c)
            assert np.allclose(beta, expected[-2:], rtol=1e-8, atol=1e-12)
            whole = np.column_stack([model, c])
            assert np.allclose(residual, y - whole @ expected, rtol=0, atol=1e-9 * np.max(np.abs(y)))


def test_folds_summed_from_their_blocks_equal_the_folds_of_the_whole_record():
    rng = np.random.default_rng(3)
    x = rng.standard_normal((1000, 4)) * [1.0, 1e3, 1e-3, 1.0]
    y = x @ [1.0, 2.0, 3.0, 4.0] + rng.standard_normal(1000)
    edges = block_edges(len(y), 5)
    for (a, b), beta in zip(edges, fold_betas(y, x, edges), strict=True):
        keep = np.r_[0:a, b : len(y)]
        expected, _ = ols(y[keep], x[keep])
        assert np.allclose(beta, expected, rtol=1e-9)
    # blocks that do not cover the record (a held-out gap) use the whole record's products
    gapped = [(0, 100), (300, 500)]
    for (a, b), beta in zip(gapped, fold_betas(y, x, gapped), strict=True):
        keep = np.r_[0:a, b : len(y)]
        assert np.allclose(beta, ols(y[keep], x[keep])[0], rtol=1e-9)


def test_searched_columns_built_at_the_fitted_rows_equal_the_full_columns_there():
    t = np.arange(0.0, 6.0, 1e-3)
    pos = 0.8 * np.sin(1.3 * t) + 0.2 * np.sin(4.1 * t)
    sig = build_signals(t, pos, np.sin(3.0 * t), kt_nm_per_a=20.0, inertia_kgm2=1.0, ratio=50.0, window=41)
    ctx = ChannelContext(sig, TORQUE, nominal_inertia_kgm2=1.0)
    n = len(sig.t_s)
    index = np.arange(0, n, 7)
    selector = ChannelSelector(ctx, np.zeros(len(index)), (), index, 0.1, "N m")
    assert selector._decimated is not None  # the rows are every 7th: the short path is taken
    for cid, shape in (("torque_ripple", (2.3,)), ("stribeck_friction", (0.05,))):
        cand = CANDIDATES[cid]
        assert cand.decimates
        full = cand.build(ctx, shape)[index]
        assert np.max(np.abs(selector.cols(cand, shape) - full)) <= 1e-12 * np.max(np.abs(full))


def test_scores_equal_to_rounding_are_a_tie_settled_by_order():
    # friction by direction spans the columns of Coulomb friction + an offset: their BIC gains agree
    # to rounding, and the first candidate must win whichever rounds lower
    scores = [("load_torque_offset", -382.84), ("asymmetric_friction", -382.84 * (1 + 1e-13)), ("x", -1.0)]
    assert _first_lowest(scores, lambda s: s[1])[0] == "load_torque_offset"
    assert _first_lowest(scores[1:], lambda s: s[1])[0] == "asymmetric_friction"
    assert _first_lowest([("a", -1.0), ("b", -2.0)], lambda s: s[1])[0] == "b"
