"""Step 3 of the model check: name the effect(s) that explain a residual, without naming noise.

The criterion (each gate must pass for an effect to be named):

1. Whitened BIC. Residuals of a closed-loop axis (and of any smoothed signal) are strongly
   autocorrelated, so an information criterion on raw samples would count thousands of
   "independent" samples and name noise. The residual of the current model is fitted with an
   autoregressive model AR(p) (p by BIC, up to linalg.MAX_AR_ORDER); the residual and every regressor are
   passed through the same whitening filter, and the BIC of the whitened least-squares fit must
   fall by at least BIC_MIN (10: "very strong" evidence) when the effect is added.
2. Contiguous-block cross-validation: the record is cut into linalg.CV_BLOCKS contiguous blocks (never
   shuffled samples: neighbouring samples are nearly copies of each other); each block is predicted
   from a fit on the others. The held-out RMS must fall.
3. Practical significance: the effect's size (its typical magnitude in N m or arcsec) must exceed a
   floor, so that a statistically clear but practically irrelevant (or noise-level) term is not
   named. It must also have the physical sign (friction opposes motion, a spring winds up under load).
4. Statistical significance of the size itself: it must stand MIN_SIGMAS (3) delete-one-block
   jackknife sigmas above zero (an effect whose size the data does not pin down is not named).
5. Look-elsewhere, for searched shapes (cycles per motor turn): the grid and the refinement pick
   the largest of many noise peaks, which the BIC gate (one frequency) does not know about. The size
   must be MIN_OFF_SHAPE_RATIO x the median size the same sinusoid reaches, next to the chosen one,
   at quarter-cycle frequencies nobody claims. Found on a scope trace of the simulated drive: its
   loops see whole encoder pulses, so the current carries coloured servo noise that a frequency
   search over ~25 motor turns turned into a 0.8-0.9 N m "torque ripple".

Parameters are estimated by ordinary least squares on the (unwhitened) residual: whitening
emphasises the highest frequencies, where the rigid-body and timing approximations are weakest,
so it serves the criterion only (the BIC of the least-squares fit on whitened data).
Uncertainties come from a delete-one-block jackknife over JACKKNIFE_BLOCKS contiguous blocks,
which stays honest under autocorrelation. The shape of a candidate (cycles per motor turn, the
number of wind-up regions) is chosen by contiguous-block CV.

Forward selection (best whitened-BIC gain first), the nominal parameters (the total inertia) first,
then a backward pass. Shape parameters (cycles per motor turn) are picked on a grid and refined by
least squares; the final fit refines all parameters together (scipy.optimize.least_squares).
"""

from __future__ import annotations

import copy
import math
from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
from scipy.optimize import least_squares

from fha_studio.logic.modelcheck.candidates import (
    QUANTISED_PULSES_PER_PERIOD,
    Candidate,
    ChannelContext,
    Param,
)
from fha_studio.logic.modelcheck.linalg import (
    Beside,
    bic,
    block_cv,
    block_edges,
    fit_ar,
    fold_betas,
    ols,
    whiten,
)

BIC_MIN = 10.0
CV_MIN_GAIN = 0.005  # the held-out RMS must fall by at least 0.5 %
MAX_EFFECTS = 4
JACKKNIFE_BLOCKS = 10
MIN_SIGMAS = 3.0  # a named effect's size must stand this many jackknife sigmas above zero
# A searched shape (cycles per motor turn) picks the largest of many noise peaks (look-elsewhere): its
# size must stand this many times above the median size the same fit finds at frequencies nobody
# claims. Pure noise reaches ~3-4x (the largest of a few hundred peaks); real ripple 150x and more.
MIN_OFF_SHAPE_RATIO = 6.0
MASKED_CV_FACTOR = 3.0  # a look-alike the record cannot rule out fits within this factor of the chosen
OFF_SHAPE_GAP = 0.45  # off-shape frequencies keep this far (cycles per turn) from the chosen one
# a searched shape's refinement stops when a step moves it by less than this share: 4e-5 cycles per
# turn at 4, a fiftieth of what a record of 500 motor turns resolves (with scipy's default, 1e-8, a
# sixth of the evaluations crept on below it), and the final fit refines it again
SHAPE_XTOL = 1e-5


# Two scores this close (relative) are a tie, settled by the candidates' order: candidates that span
# the same columns (friction by direction = Coulomb friction + an offset) score alike up to rounding,
# and the choice between them must not depend on the order of a sum.
TIE_RELATIVE = 1e-9


def _first_lowest(items: list[Any], key: Callable[[Any], float]) -> Any:
    """The first item whose key is the lowest, or within TIE_RELATIVE of it."""
    lowest = min(key(item) for item in items)
    tolerance = TIE_RELATIVE * abs(lowest) if math.isfinite(lowest) else 0.0
    return next(item for item in items if key(item) <= lowest + tolerance)


# ----------------------------------------------------------------------------------- data types


@dataclass
class Term:
    """One candidate in a model, with its shape (e.g. cycles per motor turn)."""

    cand: Candidate
    shape: tuple[float, ...]
    cols: np.ndarray  # decimated columns (n, n_linear)

    @property
    def id(self) -> str:
        return self.cand.id


@dataclass
class Trial:
    """One candidate tried at one selection step (for the GUI's table of each step)."""

    id: str
    shape: tuple[float, ...]
    delta_bic: float
    cv_rms_before: float
    cv_rms_after: float
    size: float
    physical: bool
    accepted: bool
    reason: str
    noise_peak: bool = False  # a searched shape that does not stand above its neighbours (look-elsewhere)
    # gates failed: "evidence", "held_out", "floor", "precision", "creep", "noise_peak", "sign"
    failed: tuple[str, ...] = ()


@dataclass
class SelectionStep:
    """One forward (or backward) selection step."""

    kind: str  # "nominal", "forward", "backward"
    ar_order: int
    trials: list[Trial]
    chosen: str | None


@dataclass
class FittedTerm:
    """A named effect with its contract parameters."""

    id: str
    channel: str
    label: str
    params: list[Param]
    size: float
    shape: tuple[float, ...]
    beta: np.ndarray
    contribution: np.ndarray  # its part of the fitted residual (decimated samples)


# --------------------------------------------------------------------------------------- engine


class ChannelSelector:
    """Forward/backward selection on one channel's residual (decimated samples)."""

    def __init__(
        self,
        ctx: ChannelContext,
        y: np.ndarray,
        candidates: tuple[Candidate, ...],
        index: np.ndarray,
        floor: float,
        unit: str,
        base: np.ndarray | None = None,
    ):
        self.ctx = ctx
        self.y = y
        self.index = index  # decimation: rows of the analysis-rate arrays used
        self.floor = floor
        self.unit = unit
        self.base = base if base is not None else np.empty((len(y), 0))
        self.candidates = [c for c in candidates if not (c.needs_ratio and ctx.sig.ratio is None)]
        self.n = len(y)
        self._cols_cache: dict[tuple[str, tuple[float, ...]], np.ndarray] = {}
        # the rows are every step-th sample of the valid part: a candidate that decimates builds
        # only those (its searched shapes are rebuilt at every trial)
        n_valid = len(ctx.sig.t_s)
        step = int(index[1] - index[0]) if len(index) > 1 else 0
        evenly = step > 0 and np.array_equal(index, np.arange(0, n_valid, step))
        self._decimated = replace(ctx, rows_step=step) if evenly else None
        # detection limits by (candidate, the terms beside it with their shapes): substitutes() and
        # the report ask for the same ones
        self._limit_cache: dict[tuple[object, ...], tuple[float, tuple[float, ...]]] = {}
        # held-out RMS by the terms' columns: every candidate of a selection step is weighed against
        # the same model, and the model a step chose is the next step's (the value keeps the columns,
        # so their ids stay theirs while cached)
        self._cv_cache: dict[tuple[int, ...], tuple[list[np.ndarray], float]] = {}
        # trials by (candidate, the terms with their shapes, the one it replaces): the selection's
        # forward steps and substitutes() try some of the same candidates beside the same model
        self._trial_cache: dict[tuple[object, ...], tuple[Trial, tuple[float, ...], np.ndarray]] = {}

    # --- columns
    def cols(self, cand: Candidate, shape: tuple[float, ...]) -> np.ndarray:
        key = (cand.id, tuple(round(s, 9) for s in shape))
        if key not in self._cols_cache:
            if cand.decimates and self._decimated is not None:
                self._cols_cache[key] = np.asarray(cand.build(self._decimated, shape), dtype=float)
            else:
                full = cand.build(self.ctx, shape)
                self._cols_cache[key] = np.asarray(full, dtype=float)[self.index]
        return self._cols_cache[key]

    def design(self, terms: list[Term]) -> np.ndarray:
        parts = [self.base] + [t.cols for t in terms]
        return np.column_stack(parts) if sum(p.shape[1] for p in parts) else np.empty((self.n, 0))

    def cv_rms(self, terms: list[Term]) -> float:
        """Held-out RMS (block_cv) of the model of ``terms``."""
        key = tuple(id(t.cols) for t in terms)
        if key not in self._cv_cache:
            self._cv_cache[key] = ([t.cols for t in terms], block_cv(self.y, self.design(terms))[0])
        return self._cv_cache[key][1]

    def residual(self, terms: list[Term]) -> np.ndarray:
        x = self.design(terms)
        beta, _ = ols(self.y, x)
        return self.y - x @ beta if x.shape[1] else self.y.copy()

    # --- scoring
    def _ar_for(self, x: np.ndarray) -> np.ndarray:
        """AR whitening estimated on the residual of the model with columns x (the alternative)."""
        return self._fit_and_ar(x)[1]

    def _fit_and_ar(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The least-squares coefficients of the columns x, and the AR whitening of their residual."""
        beta, _ = ols(self.y, x)
        return beta, fit_ar(self.y - x @ beta if x.shape[1] else self.y)

    def _wrss(self, x: np.ndarray, phi: np.ndarray) -> tuple[np.ndarray, float, int]:
        """The criterion's fit: least squares on the whitened residual and columns (GLS); its RSS."""
        yw = whiten(self.y, phi)
        xw = whiten(x, phi) if x.shape[1] else np.empty((len(yw), 0))
        beta, rss = ols(yw, xw)
        return beta, rss, len(yw)

    def score(self, terms: list[Term], phi: np.ndarray) -> float:
        x = self.design(terms)
        _, rss, nw = self._wrss(x, phi)
        return bic(rss, nw, x.shape[1])

    def best_shape(self, cand: Candidate, terms: list[Term]) -> tuple[float, ...]:
        if len(cand.shape_grid) == 1 and not cand.shape_refine:
            return cand.shape_grid[0]
        # the same candidate beside the same terms (shapes included) is asked for again by the
        # look-alike and detection-limit steps: one search each
        key = ("shape", cand.id, *((t.id, t.shape) for t in terms))
        if key not in self._limit_cache:
            self._limit_cache[key] = (0.0, self._best_shape(cand, terms))
        return self._limit_cache[key][1]

    def _best_shape(self, cand: Candidate, terms: list[Term]) -> tuple[float, ...]:
        x0 = self.design(terms)
        # shapes by contiguous-block CV: honest for shapes of different dimension (wind-up regions),
        # and it does not weigh the highest frequencies as whitening does
        scores = [
            block_cv(self.y, np.column_stack([x0, self.cols(cand, shape)]))[0] for shape in cand.shape_grid
        ]
        shape = cand.shape_grid[int(np.argmin(scores))]
        if not cand.shape_refine:
            return shape

        beside = Beside(self.y, x0)

        def resid(s):
            return beside.fit(self.cols(cand, (float(s[0]),)))[1]

        try:
            sol = least_squares(
                resid, [shape[0]], bounds=cand.shape_bounds(shape), diff_step=1e-4, max_nfev=30,
                xtol=SHAPE_XTOL,
            )
            return (float(sol.x[0]),)
        except (ValueError, np.linalg.LinAlgError):  # pragma: no cover - degenerate data
            return shape

    def try_add(self, cand: Candidate, terms: list[Term], replace: Term | None = None) -> tuple[Trial, Term]:
        """Score cand added to terms: whitened BIC gain (AR from the larger model), block CV, size.

        replace: a chosen term cand extends (a refinement, e.g. friction by direction for Coulomb
        friction): cand takes its place and must beat the model that holds it.
        """
        key = (cand.id, *((t.id, t.shape, t is replace) for t in terms))
        if key not in self._trial_cache:
            trial, term = self._try_add(cand, terms, replace)
            self._trial_cache[key] = (trial, term.shape, term.cols)
        trial, shape, cols = self._trial_cache[key]
        # new objects each time: final_fit() refines the chosen terms' shapes in place
        return copy.copy(trial), Term(cand, shape, cols)

    def _try_add(self, cand: Candidate, terms: list[Term], replace: Term | None) -> tuple[Trial, Term]:
        kept = [t for t in terms if t is not replace]
        shape = self.best_shape(cand, kept)
        term = Term(cand, shape, self.cols(cand, shape))
        x0 = self.design(terms)
        x1 = self.design([*kept, term])
        beta1, phi = self._fit_and_ar(x1)  # size and sign from the plain least-squares estimate
        _, rss1, nw = self._wrss(x1, phi)
        _, rss0, _ = self._wrss(x0, phi)
        bic0, bic1 = bic(rss0, nw, x0.shape[1]), bic(rss1, nw, x1.shape[1])
        cv0 = self.cv_rms(terms)
        cv1 = self.cv_rms([*kept, term])
        beta_c = beta1[-term.cols.shape[1] :]
        size = float(cand.size(beta_c, self.ctx))
        physical = self._physical(cand, beta_c)
        reasons = []
        failed: list[str] = []  # the gates it failed, by name (for plain words in the GUI)
        if bic1 - bic0 > -BIC_MIN:
            reasons.append(f"whitened BIC gain {bic0 - bic1:.1f} < {BIC_MIN:g}")
            failed.append("evidence")
        if cv1 > cv0 * (1.0 - CV_MIN_GAIN):
            reasons.append("held-out RMS does not fall")
            failed.append("held_out")
        if size < self.floor:
            reasons.append(f"size {size:.3g} {self.unit} below the floor {self.floor:.3g}")
            failed.append("floor")
        sigma = self.size_sigma(cand, x1, term.cols.shape[1])
        if size < MIN_SIGMAS * sigma:
            reasons.append(f"size {size:.3g} {self.unit} within {MIN_SIGMAS:g} sigma ({sigma:.3g}) of zero")
            failed.append("precision")
        if cand.beyond_creep is not None and size >= self.floor and not failed:
            creep_only = self._creep_only(cand, kept, shape)
            if creep_only:
                reasons.append(creep_only)
                failed.append("creep")
        noise_peak = False
        if cand.look_elsewhere and size >= self.floor:
            off = self.off_shape_size(cand, x1, shape)
            noise_peak = size < MIN_OFF_SHAPE_RATIO * off
            if noise_peak:
                reasons.append(
                    f"size {size:.3g} {self.unit} not {MIN_OFF_SHAPE_RATIO:g}x above the median {off:.3g} "
                    "found at other frequencies (a noise peak)"
                )
        if not physical:
            reasons.append("unphysical sign")
            failed.append("sign")
        trial = Trial(
            cand.id,
            shape,
            bic1 - bic0,
            cv0,
            cv1,
            size,
            bool(physical),
            not reasons,
            "; ".join(reasons) or "named",
            noise_peak,
            tuple(failed + (["noise_peak"] if noise_peak else [])),
        )
        return trial, term

    def _creep_only(self, cand: Candidate, kept: list[Term], shape: tuple[float, ...]) -> str:
        """Why cand at shape is seen only while the motor creeps ("" when it stands beyond that):
        its size without the creep must pass the floor and stand MIN_SIGMAS jackknife sigmas."""
        assert cand.beyond_creep is not None
        if cand.decimates and self._decimated is not None:
            cols = np.asarray(cand.beyond_creep(self._decimated, shape), dtype=float)
        else:
            cols = np.asarray(cand.beyond_creep(self.ctx, shape), dtype=float)[self.index]
        x = np.column_stack([self.design(kept), cols])
        beta, _ = ols(self.y, x)
        k = cols.shape[1]
        size = float(cand.size(beta[-k:], self.ctx))
        sigma = self.size_sigma(cand, x, k)
        if size >= self.floor and size >= MIN_SIGMAS * sigma:
            return ""
        return (
            f"without the creep into a target (under {QUANTISED_PULSES_PER_PERIOD:g} encoder pulses per "
            f"servo period) its size is {size:.3g} ± {sigma:.3g} {self.unit}: the creep alone shows it"
        )

    def size_sigma(self, cand: Candidate, x: np.ndarray, k: int) -> float:
        """Delete-one-block jackknife sigma of cand's size (its last k columns of x, shape held)."""
        edges = block_edges(self.n, JACKKNIFE_BLOCKS)
        sizes = [float(cand.size(bj[-k:], self.ctx)) for bj in fold_betas(self.y, x, edges)]
        vals = np.array(sizes)
        g = len(vals)
        return math.sqrt((g - 1) / g * float(np.sum((vals - vals.mean()) ** 2)))

    def off_shape_size(self, cand: Candidate, x1: np.ndarray, shape: tuple[float, ...]) -> float:
        """Median size of a second cand fitted next to x1 (which holds cand at shape) at quarter-cycle
        frequencies away from shape: the size noise alone reaches at a frequency nobody claims.

        Fitted next to the chosen term, so a real effect's leakage (dwells at one motor angle) is
        not counted as noise.
        """
        grid = [c for (c,) in cand.shape_grid]
        offs = np.arange(0.25, max(grid) + 0.76, 0.25)
        offs = offs[(np.abs(offs - shape[0]) >= OFF_SHAPE_GAP) & (np.abs(offs - np.round(offs)) > 0.1)]
        beside = Beside(self.y, x1)
        sizes = [float(cand.size(beside.fit(self.cols(cand, (float(c),)))[0], self.ctx)) for c in offs]
        return float(np.median(sizes)) if sizes else 0.0

    @staticmethod
    def _physical(cand: Candidate, beta: np.ndarray) -> bool:
        if cand.all_positive:
            return bool(np.all(beta >= 0.0) and np.any(beta > 0.0))
        if cand.sign == 0:
            return True
        # cumulative: every region of a piecewise term (wind-up slopes) must keep the sign
        return bool(np.all(np.sign(np.cumsum(beta)) == cand.sign))

    # --- selection
    def select(self, nominal_first: tuple[str, ...] = ()) -> tuple[list[Term], list[SelectionStep]]:
        terms: list[Term] = []
        steps: list[SelectionStep] = []
        # re-fit the nominal parameters before blaming a missing effect
        for cid in nominal_first:
            cand = next((c for c in self.candidates if c.id == cid), None)
            if cand is None:
                continue
            trial, term = self.try_add(cand, terms)
            steps.append(
                SelectionStep(
                    "nominal",
                    len(self._ar_for(self.design([*terms, term]))),
                    [trial],
                    cid if trial.accepted else None,
                )
            )
            if trial.accepted:
                terms.append(term)
        while len(terms) < MAX_EFFECTS:
            phi = fit_ar(self.residual(terms))
            in_model = [t.id for t in terms]
            tried: list[tuple[Trial, Term, Term | None]] = []
            for cand in self.candidates:
                if cand.id in in_model:
                    continue
                # a refinement of a chosen term is tried in its place, never beside it
                replaced = next((t for t in terms if t.id in cand.extends), None)
                if (cand.extends and replaced is None) or cand.only_as_alternative:
                    continue
                tried.append((*self.try_add(cand, terms, replaced), replaced))
            good = [trial for trial in tried if trial[0].accepted]
            best = _first_lowest(good, lambda p: p[0].delta_bic) if good else None
            chosen = best[0].id if best else None
            steps.append(SelectionStep("forward", len(phi), [tr for tr, _, _ in tried], chosen))
            if best is None:
                break
            terms = [t for t in terms if t is not best[2]] + [best[1]]
        # backward: drop a term the others have made redundant
        changed = True
        while changed and len(terms) > 1:
            changed = False
            phi = self._ar_for(self.design(terms))
            full = self.score(terms, phi)
            cv_full = self.cv_rms(terms)
            trials: list[Trial] = []
            for term in terms:
                rest = [t for t in terms if t is not term]
                drop_bic = self.score(rest, phi)
                cv_rest = self.cv_rms(rest)
                keep = drop_bic - full >= BIC_MIN and cv_full < cv_rest * (1.0 - CV_MIN_GAIN)
                trials.append(
                    Trial(
                        term.id,
                        term.shape,
                        full - drop_bic,
                        cv_rest,
                        cv_full,
                        0.0,
                        True,
                        keep,
                        "kept" if keep else "redundant given the others",
                    )
                )
            weakest = _first_lowest(trials, lambda tr: -tr.delta_bic if not tr.accepted else math.inf)
            if not weakest.accepted:
                terms = [t for t in terms if t.id != weakest.id]
                steps.append(SelectionStep("backward", len(phi), trials, weakest.id))
                changed = True
        return terms, steps

    # --- final fit with uncertainty
    def _fit_all(
        self, terms: list[Term], rows: np.ndarray | None, start: np.ndarray | None = None, max_nfev: int = 50
    ) -> tuple[np.ndarray, dict[int, tuple[float, ...]]]:
        """All coefficients (base, then terms) and refined shapes, on rows (None = all)."""
        shaped = [i for i, t in enumerate(terms) if t.cand.shape_refine]
        sel = slice(None) if rows is None else rows
        y = self.y[sel]

        def design_for(shapes):
            cols = [self.base[sel]]
            for i, t in enumerate(terms):
                cols.append(self.cols(t.cand, shapes[i])[sel] if i in shaped else t.cols[sel])
            return np.column_stack(cols) if sum(c.shape[1] for c in cols) else np.empty((len(y), 0))

        shapes0 = {i: terms[i].shape for i in shaped}
        x = design_for(shapes0)
        beta0, _ = ols(y, x)
        if not shaped:
            return beta0, {}
        n_lin = x.shape[1]

        def shapes_of(p) -> dict[int, tuple[float, ...]]:
            return {i: (float(p[j]),) for j, i in enumerate(shaped)}

        # the shapes refined with the coefficients solved linearly at each step (variable
        # projection): the same optimum, and a Jacobian of the shapes alone (its SVD, not one over
        # every coefficient, is what a step costs)
        def resid(p):
            xs = design_for(shapes_of(p))
            b, _ = ols(y, xs)
            return y - xs @ b

        s0 = start[n_lin:] if start is not None else [terms[i].shape[0] for i in shaped]
        sol = least_squares(resid, s0, diff_step=1e-6, x_scale="jac", max_nfev=max_nfev)
        shapes = shapes_of(sol.x)
        beta, _ = ols(y, design_for(shapes))
        return beta, shapes

    def final_fit(self, terms: list[Term]) -> tuple[list[FittedTerm], np.ndarray, np.ndarray, int]:
        """Refine every parameter together (least squares); uncertainties by block jackknife."""
        beta, shapes = self._fit_all(terms, None)
        shaped = sorted(shapes)
        nb = self.base.shape[1]
        for i, shape in shapes.items():
            terms[i].shape = shape
            terms[i].cols = self.cols(terms[i].cand, shape)
        x = self.design(terms)
        full_params = self._term_values(terms, beta)
        # delete-one-block jackknife of every reported number
        start = np.concatenate([beta, [shapes[i][0] for i in shaped]])
        reps = []
        for a, b in block_edges(self.n, JACKKNIFE_BLOCKS):
            rows = np.ones(self.n, bool)
            rows[a:b] = False
            bj, sj = self._fit_all(terms, rows, start=start, max_nfev=10)
            saved = [(t.shape, t.cols) for t in terms]
            for i, shape in sj.items():
                terms[i].shape, terms[i].cols = shape, self.cols(terms[i].cand, shape)
            reps.append(self._term_values(terms, bj))
            for t, (sh, co) in zip(terms, saved, strict=True):
                t.shape, t.cols = sh, co
        g = len(reps)
        fitted_terms = []
        col = nb
        for ti, t in enumerate(terms):
            k = t.cols.shape[1]
            b_t = beta[col : col + k]
            params = []
            for pi, prm in enumerate(full_params[ti]):
                vals = np.array([r[ti][pi].value for r in reps])
                if prm.name == "phase_deg":  # wrap around the full-data value
                    vals = prm.value + (vals - prm.value + 180.0) % 360.0 - 180.0
                var = (g - 1) / g * float(np.sum((vals - vals.mean()) ** 2))
                params.append(Param(prm.name, prm.value, math.sqrt(var), prm.unit))
            fitted_terms.append(
                FittedTerm(
                    t.id,
                    t.cand.channel,
                    t.cand.label,
                    params,
                    float(t.cand.size(b_t, self.ctx)),
                    t.shape,
                    b_t,
                    x[:, col : col + k] @ b_t,
                )
            )
            col += k
        fitted = x @ beta if x.shape[1] else np.zeros(self.n)
        phi = fit_ar(self.y - fitted)
        return fitted_terms, fitted, beta[:nb], len(phi)

    def _term_values(self, terms: list[Term], beta: np.ndarray) -> list[list[Param]]:
        out = []
        col = self.base.shape[1]
        none = np.zeros((0, 0))
        for t in terms:
            k = t.cols.shape[1]
            out.append(t.cand.to_params(beta[col : col + k], np.zeros((k, k)), t.shape, none, self.ctx))
            col += k
        return out

    def _look_alike_sets(
        self, terms: list[Term], phi: np.ndarray, full: float, fit_full: np.ndarray
    ) -> list[tuple[str, str, float, dict[str, float]]]:
        """A chosen effect against the set of effects that together look like it (a candidate's
        look_alikes), both ways: (chosen ids, alternative ids, BIC difference), ids joined by " + "."""
        by_id = {c.id: c for c in self.candidates}
        chosen = {t.id for t in terms}
        out: list[tuple[str, str, float, dict[str, float]]] = []
        for cand in self.candidates:
            for combo in cand.look_alikes:
                if not all(i in by_id for i in combo):
                    continue
                if cand.id in chosen and not set(combo) <= chosen:
                    rest = [t for t in terms if t.id != cand.id and t.id not in combo]
                    alt_terms = list(rest)
                    for i in combo:
                        member = by_id[i]
                        shape = self.best_shape(member, alt_terms)
                        alt_terms.append(Term(member, shape, self.cols(member, shape)))
                    pair = (cand.id, " + ".join(combo))
                elif set(combo) <= chosen and cand.id not in chosen:
                    rest = [t for t in terms if t.id not in combo]
                    trial, alt = self.try_add(cand, rest)
                    if not (trial.physical and trial.size >= self.floor):
                        continue
                    alt_terms = [*rest, alt]
                    pair = (" + ".join(combo), cand.id)
                else:
                    continue
                x_alt = self.design(alt_terms)
                b_alt, _ = ols(self.y, x_alt)
                differ = float(np.sqrt(np.mean((x_alt @ b_alt - fit_full) ** 2)))
                alt_bic = self.score(alt_terms, phi)
                if abs(alt_bic - full) < BIC_MIN or differ < 0.5 * self.floor:
                    out.append((*pair, alt_bic - full, {}))
        return out

    def _term_sizes(self, terms: list[Term], beta: np.ndarray) -> list[float]:
        """Each term's size (channel unit) from the coefficients of the whole design (base first)."""
        out = []
        col = self.base.shape[1]
        for t in terms:
            k = t.cols.shape[1]
            out.append(float(t.cand.size(beta[col : col + k], self.ctx)))
            col += k
        return out

    # --- after selection
    def detection_limit(self, terms: list[Term], cand: Candidate) -> tuple[float, tuple[float, ...]]:
        """Smallest size of cand this record would have revealed next to terms (channel unit).

        The jackknife spread of cand's coefficient(s) when fitted next to the chosen terms, times
        the whitened-BIC gate's own threshold sqrt(BIC_MIN + k ln n), never below the floor. A shape
        that is not a searched frequency (a Stribeck speed) is the one that fits best next to terms.
        """
        key = (cand.id, *((t.id, t.shape) for t in terms))
        if key not in self._limit_cache:
            self._limit_cache[key] = self._detection_limit(terms, cand)
        return self._limit_cache[key]

    def _detection_limit(self, terms: list[Term], cand: Candidate) -> tuple[float, tuple[float, ...]]:
        shape = (
            self.best_shape(cand, terms)
            if cand.shape_refine and not cand.look_elsewhere
            else cand.shape_grid[0]
        )
        x = np.column_stack([self.design(terms), self.cols(cand, shape)])
        k = x.shape[1] - self.design(terms).shape[1]
        reps = [bj[-k:] for bj in fold_betas(self.y, x, block_edges(self.n, JACKKNIFE_BLOCKS))]
        reps_arr = np.array(reps)
        g = len(reps)
        var = (g - 1) / g * np.sum((reps_arr - reps_arr.mean(axis=0)) ** 2, axis=0)
        sigma = math.sqrt(float(np.mean(var)))
        unit_size = cand.size(np.full(k, 1.0 / math.sqrt(k)) if k > 1 else np.ones(1), self.ctx)
        z = math.sqrt(BIC_MIN + k * math.log(self.n))
        limit = max(self.floor, z * sigma * unit_size, MIN_SIGMAS * sigma * unit_size)
        if cand.look_elsewhere:  # the look-elsewhere gate of try_add
            limit = max(limit, MIN_OFF_SHAPE_RATIO * self.off_shape_size(cand, x, shape))
        return limit, shape

    def substitutes(self, terms: list[Term]) -> list[tuple[str, str, float, dict[str, float]]]:
        """(chosen, alternative, BIC difference, the alternative's parameters) for alternatives that
        explain the data as well.

        An alternative (swapped in for one chosen term, physical, above the floor and lowering the
        held-out RMS; its own precision gates do not matter: a look-alike is as uncertain as the
        term it could replace) is not separable
        when the whitened BIC does not prefer the chosen set by BIC_MIN, or when the two fits differ
        by less than the practical floor anywhere it matters (RMS of their difference): the data
        then cannot tell which is the cause, however precise it is.
        """
        if not terms:
            return []
        x_full = self.design(terms)
        phi = self._ar_for(x_full)
        full = self.score(terms, phi)
        beta, _ = ols(self.y, x_full)
        fit_full = x_full @ beta
        out = []
        chosen = {t.id for t in terms}
        sizes = self._term_sizes(terms, beta)
        cv_full = self.cv_rms(terms)
        hidden = {c.id: self.detection_limit(terms, c)[0] for c in self.candidates if c.id not in chosen}
        for term, size in zip(terms, sizes, strict=True):
            rest = [t for t in terms if t is not term]
            for cand in self.candidates:
                if (
                    cand.id in chosen
                    or cand.extends
                    or term.id in cand.extends
                    or cand.id in term.cand.extends
                ):
                    continue  # a refinement replaces only its base, and the whitened BIC chose between them
                trial, alt = self.try_add(cand, rest)
                if not (
                    trial.physical
                    and not trial.noise_peak
                    and trial.size >= self.floor
                    and trial.cv_rms_after < trial.cv_rms_before
                ):
                    continue
                x_alt = self.design([*rest, alt])
                alt_bic = self.score([*rest, alt], phi)
                b_alt, _ = ols(self.y, x_alt)
                differ = float(np.sqrt(np.mean((x_alt @ b_alt - fit_full) ** 2)))
                # below what the record can show: next to the chosen terms, an effect of this kind as
                # large as the chosen one would not have been seen, so the data cannot tell them apart
                # (and it must explain the data nearly as well: within MASKED_CV_FACTOR of the held-out RMS)
                masked = hidden[cand.id] > size and trial.cv_rms_after <= MASKED_CV_FACTOR * cv_full
                if alt_bic - full < BIC_MIN or differ < 0.5 * self.floor or masked:
                    k = alt.cols.shape[1]
                    none = np.zeros((0, 0))
                    alt_params = cand.to_params(b_alt[-k:], np.zeros((k, k)), alt.shape, none, self.ctx)
                    out.append((term.id, cand.id, alt_bic - full, {q.name: q.value for q in alt_params}))
        out.extend(self._look_alike_sets(terms, phi, full, fit_full))
        return out
