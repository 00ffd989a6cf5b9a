"""The closed loop of a recording without current, as a linear model of its following error.

A bench capture of an HA-655 gives the command and the encoder position, no current. The loop that
ran (docs/physics.md, "Servo": speed command = Kp (cmd - pos) + FF cmd', current = Kv (e + integral
(e) / Tv), e = speed command - the speed the drive measures) and the rigid plant J a = Kt i - d
give, in Laplace terms,

    pos = Gc(s) cmd - H(s) d,   Gc = g (Tv s + 1)(lag s + 1)(FF s + Kp) / D(s),
    H = Tv s (lag s + 1) / D(s),   D(s) = J Tv s^3 (lag s + 1) + g (Tv s + 1)(Kp (lag s + 1) + s),

g = Kt Kv on the declared inertia J, ``lag`` the first-order lag of the drive's speed detection (a
filter, a period's difference), and the command taken up to 2 ms early (``lead``: the drive samples
the command and the encoder at its own instants, which the recording's common time stamps do not
show; a lead reads as FF + Kp lead, so it is bounded to what a servo period can make).

The loop is identified by *output error*: the position the model gives for the recorded command
against the measured one (``RecordedLoop.fit``, least squares over the loop's parameters, the
disturbance columns and the start's free response solved linearly at every step). The tempting
alternative, the loop's torque written from the measured signals (equation error), multiplies every
timing detail of the drive (its servo period, its speed detection's lag, the integration rule) by
the loop's gains: on the simulated drive's default loop (Kp 40 1/s, 60 Hz speed loop) a 0.1 ms
difference already shows as 2 N m, and the fit then prefers a wrong loop that explains the
acceleration as the following error's derivative. In the following error those details stay as
small as they are.

What the disturbance d does is H (a band-pass: the speed loop's integral holds whatever is constant,
so H(0) = 0) applied to it. A candidate effect's columns are passed through H and scaled by
1 / max |H| (``through_loop``): the channel (``oe_channel``) stays in N m, a disturbance at the
loop's most sensitive frequency keeping its size, every other one shown smaller; the effects'
coefficients stay in N m. While the command pushes an axis that friction holds, the axis takes the
torque the loop winds up (``RecordedLoop.stick_torque``), not a friction column's level.

Not in the model, and why: viscous friction. The speed detection's lag reads as less inertia and a
negative viscous friction (g lag / Tv); a free viscous column trades off against g and the lag
(tried on the simulated drive: with one, g came out 1.8 x too large and every torque with it;
without it, within 1 %). Nor with the lag held at the simulated drive's detection (0.33 ms): each
0.1 ms off moves the drag by g x 0.1 ms / Tv, the lag at which nothing hidden reads as no drag
ranges over 0.27-0.41 ms from axis to axis, and with 50 % feed-forward the drag trades off against
Kp, FF and g (docs/physics.md). A coast after an alarm shows it, with the loop out of the
picture (coast.py).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from functools import lru_cache

import numpy as np
from scipy import signal as sps
from scipy.optimize import least_squares

from fha_studio.logic.modelcheck.candidates import Candidate
from fha_studio.logic.modelcheck.linalg import ols
from fha_studio.logic.modelcheck.signals import ARCSEC_PER_RAD, Signals

#: the parameters' bounds: position gain (1/s), feed-forward, speed loop bandwidth g / J (Hz), Tv (s),
#: the lag of the drive's speed detection (ms)
KP_RANGE = (0.3, 3000.0)
FF_RANGE = (-0.5, 1.5)
SPEED_BANDWIDTH_RANGE_HZ = (0.5, 3000.0)
TV_RANGE_S = (0.0005, 5.0)
LAG_RANGE_S = (0.0, 0.005)
#: how much earlier than recorded the drive may act on the command (s): its sampling of the command
#: and the encoder within a servo period, which a recording's common time stamps do not show
LEAD_RANGE_S = (-0.002, 0.002)
#: starting points tried (each one evaluated once; the best few refined): feed-forward, speed loop
#: bandwidth (Hz) and Tv in units of 1 / (2 pi bandwidth)
START_FF = (0.0, 0.6, 0.95)
START_BANDWIDTH_HZ = (15.0, 50.0, 150.0)
START_TV_PERIODS = (2.0, 6.0)
START_LAG_MS = 0.3
REFINED_STARTS = 2
#: evaluations of one fit at most (Levenberg-Marquardt counts its Jacobian's among them)
FIT_MAX_EVALUATIONS = 150
#: evaluations of the second stage (every parameter, from the first stage's loop)
SECOND_STAGE_EVALUATIONS = 140
#: beyond a parameter's range, the residual grows by this much per unit of its distance (arcsec):
#: the unbounded Levenberg-Marquardt steps back inside (a bounded method's SVDs cost more)
PENALTY = 1e3
#: the fit stops when no parameter changes by more than this share (0.1 %: well inside what it is
#: known to)
FIT_XTOL = 1e-3
#: the loop's order with its speed lag: the free response's columns
FREE_COLUMNS = 4
#: LoopParams.vector()'s length: the first columns of oe_channel's base
N_PARAMS = 6
#: a free response has died out after this many of the loop's slowest time constants (e^-14)
FREE_DECAY = 14.0


@lru_cache(maxsize=16)
def _tustin_basis(order: int, dt: float) -> np.ndarray:
    """Row k: K^k (z - 1)^k (z + 1)^(order - k), K = 2 / dt, in descending powers of z: s^k under
    the bilinear transform, times (z + 1)^order."""
    k2 = 2.0 / dt
    rows = []
    for k in range(order + 1):
        row = np.array([k2**k])
        for _ in range(k):
            row = np.convolve(row, [1.0, -1.0])
        for _ in range(order - k):
            row = np.convolve(row, [1.0, 1.0])
        rows.append(row)
    return np.array(rows)


def tustin(num, den, dt: float) -> tuple[np.ndarray, np.ndarray]:
    """The bilinear (Tustin) transform of N(s) / D(s) (descending powers), normalised; the same as
    scipy.signal.bilinear, without its polynomial objects (a hundred times faster)."""
    num = np.atleast_1d(np.asarray(num, dtype=float))
    den = np.atleast_1d(np.asarray(den, dtype=float))
    order = max(len(num), len(den)) - 1
    basis = _tustin_basis(order, dt)
    b = num[::-1] @ basis[: len(num)]
    a = den[::-1] @ basis[: len(den)]
    return b / a[0], a / a[0]


def bounds(inertia_kgm2: float) -> tuple[np.ndarray, np.ndarray]:
    """The searched range of LoopParams.vector()."""
    g_lo, g_hi = (2.0 * math.pi * f * inertia_kgm2 for f in SPEED_BANDWIDTH_RANGE_HZ)
    lo = [KP_RANGE[0], FF_RANGE[0], g_lo, TV_RANGE_S[0], LAG_RANGE_S[0], LEAD_RANGE_S[0]]
    hi = [KP_RANGE[1], FF_RANGE[1], g_hi, TV_RANGE_S[1], LAG_RANGE_S[1], LEAD_RANGE_S[1]]
    return LoopParams(*lo).vector(), LoopParams(*hi).vector()


@dataclass(frozen=True)
class LoopParams:
    """Kp (1/s), FF, g = Kt Kv (N m s/rad, resting on the declared inertia), Tv (s), the lag of the
    speed the loop sees (s: a first-order lag, the drive's speed detection) and how much earlier
    than recorded the drive acts on the command (s). The lead trades off against FF (a lead d
    reads as FF + Kp d): it is bounded to what a servo period can make."""

    kp: float
    ff: float
    g: float
    tv: float
    lag: float = LAG_RANGE_S[0]
    lead: float = 0.0

    def vector(self) -> np.ndarray:
        return np.array(
            [math.log(self.kp), self.ff, math.log(self.g), math.log(self.tv), 1e3 * self.lag, 1e3 * self.lead]
        )

    @classmethod
    def from_vector(cls, p: np.ndarray) -> LoopParams:
        return cls(
            math.exp(p[0]), float(p[1]), math.exp(p[2]), math.exp(p[3]), float(p[4]) / 1e3, float(p[5]) / 1e3
        )

    def inside(self, inertia_kgm2: float) -> bool:
        """Every parameter within the searched range, none at its edge (the lag may be nil)."""
        lo, hi = bounds(inertia_kgm2)
        v = self.vector()
        margin = 1e-3 * (hi - lo)
        return bool(np.all(v[:4] > lo[:4] + margin[:4]) and np.all(v < hi - margin))

    def moved(self, other: LoopParams, share: float = 0.05) -> bool:
        """Whether other differs by more than ``share`` in a gain or Tv (or 0.05 in FF, 0.05 ms in
        the lag)."""
        d = np.abs(self.vector() - other.vector())
        return bool(
            d[0] > share
            or d[2] > share
            or d[3] > share
            or d[1] > 0.05
            or abs(self.lag - other.lag) > 5e-5
            or abs(self.lead - other.lead) > 5e-5
        )


#: the loop model explains the following error when it leaves at most this share of its RMS
EXPLAINED_SHARE = 0.2


@dataclass(frozen=True)
class LoopFit:
    params: LoopParams
    rms_arcsec: float  # what the loop model leaves of the following error
    following_error_rms_arcsec: float  # the following error itself (what there was to explain)
    coefficients: np.ndarray = field(default_factory=lambda: np.zeros(0))  # the disturbances' (N m)

    @property
    def explains(self) -> bool:
        return self.rms_arcsec <= EXPLAINED_SHARE * self.following_error_rms_arcsec


class RecordedLoop:
    """The recording's command and position (smoothed like the analysis) and the loop's responses."""

    def __init__(
        self,
        sig: Signals,
        inertia_kgm2: float,
        known_nm: np.ndarray | None = None,
        rows: np.ndarray | slice = slice(None),
    ):
        assert sig.cmd_pos_rad is not None
        f = sig.filt
        self.sig = sig
        self.j = inertia_kgm2
        self.dt = f.dt_s
        ref = float(sig.cmd_pos_rad[0])
        self.cmd = f.apply(sig.cmd_pos_rad - ref)
        self.pos = f.apply(sig.raw_pos_rad - ref)
        self.n = len(self.cmd)
        # a measured disturbance (an output torque sensor's, N m): it acts with its own size
        self.known = known_nm
        # the rows the fit compares (the smoothed signals decimated: they carry no more)
        self.rows = rows
        self._impulse = np.zeros(self.n)
        self._impulse[0] = 1.0
        # what the loop's torque is made of, for the spans where friction holds the axis
        self.pushed = pushed_standstills(sig)
        eps = sig.cmd_pos_rad - sig.raw_pos_rad
        self._eps = f.apply(eps)
        self._int_eps = f.apply(np.concatenate([[0.0], np.cumsum(0.5 * (eps[1:] + eps[:-1]))]) * f.dt_s)
        self._cmd_speed = f.apply(np.gradient(sig.cmd_pos_rad, f.dt_s))
        self._speed = sig.speed_f_rad_s

    # ---- the responses
    def _den(self, p: LoopParams) -> np.ndarray:
        # J Tv s^3 (lag s + 1) + g (Tv s + 1)(Kp (lag s + 1) + s)
        # (descending powers, written out: numpy's polynomial helpers cost more than the filtering)
        j, g, tv, kp, lag = self.j, p.g, p.tv, p.kp, p.lag
        # J Tv lag s^4 + J Tv s^3 + g Tv (Kp lag + 1) s^2 + g (Tv Kp + Kp lag + 1) s + g Kp
        den = [j * tv * lag, j * tv, g * tv * (kp * lag + 1.0), g * (tv * kp + kp * lag + 1.0), g * kp]
        return np.array(den)

    def _num_command(self, p: LoopParams) -> np.ndarray:
        # g (Tv s + 1)(lag s + 1)(FF s + Kp)
        return p.g * np.convolve(np.convolve([p.tv, 1.0], [p.lag, 1.0]), [p.ff, p.kp])

    def _num_disturbance(self, p: LoopParams) -> np.ndarray:
        return np.array([p.tv * p.lag, p.tv, 0.0])

    def _discrete(self, num, den) -> tuple[np.ndarray, np.ndarray]:
        return tustin(num, den, self.dt)

    def command_response(self, p: LoopParams) -> np.ndarray:
        """The position the loop gives for the recorded command (rad), from rest, the command
        taken ``p.lead`` earlier (to first order: the lead times the response to its speed)."""
        num = self._num_command(p)
        b, a = self._discrete(np.polyadd(num, p.lead * np.append(num, 0.0)), self._den(p))
        return sps.lfilter(b, a, self.cmd)

    def nuisance(self, p: LoopParams) -> np.ndarray:
        """The loop's own motion from the state at the first sample: fitted with every model,
        never an effect of the axis."""
        return self.free_responses(p)

    def response(self, p: LoopParams) -> np.ndarray:
        """The position the loop gives for the recorded command and the measured disturbance, with
        the torque that holds a stuck axis (stick_torque)."""
        x = self.command_response(p)
        known = self.stick_torque(p)
        if self.known is not None:
            known = known + self.known
        if self.known is not None or self.pushed:
            x = x - self.disturbance_response(p, known)
        return x

    def stick_torque(self, p: LoopParams) -> np.ndarray:
        """While the command pushes an axis that stands (friction holds it: ``pushed``), the axis
        takes whatever torque the loop winds up, not the friction of the direction it last slid:
        the loop's torque change since the standstill began, g (e(t) - e(t0) + integral(e) / Tv),
        e = Kp eps + FF cmd' - speed, read from the recording (over a short span the integral does
        not drift). The friction columns keep the last direction's level there; this is the rest."""
        out = np.zeros(self.n)
        if not self.pushed:
            return out
        e = p.kp * self._eps + p.ff * self._cmd_speed - self._speed
        # the integral of e: Kp integral(eps) + FF cmd - pos
        integral = p.kp * self._int_eps + p.ff * self.cmd - self.pos
        for a, b in self.pushed:
            out[a:b] = p.g * ((e[a:b] - e[a]) + (integral[a:b] - integral[a]) / p.tv)
        return out

    def disturbance_response(self, p: LoopParams, cols: np.ndarray) -> np.ndarray:
        """H applied to disturbance columns (N m): how much each one holds the position back (rad)."""
        b, a = self._discrete(self._num_disturbance(p), self._den(p))
        return sps.lfilter(b, a, cols, axis=0)

    def free_responses(self, p: LoopParams) -> np.ndarray:
        """The loop's own motion from any state at the first sample (FREE_COLUMNS columns), over
        as long as it lasts (FREE_DECAY of its slowest time constant)."""
        den = self._den(p)
        roots = np.roots(den)
        slowest = float(np.min(np.abs(roots.real))) if roots.size else 1.0
        length = min(self.n, int(FREE_DECAY / max(slowest, 1e-9) / self.dt) + 2)
        cols = np.zeros((self.n, FREE_COLUMNS))
        for k in range(len(den) - 1):
            b, a = self._discrete([1.0] + [0.0] * k, den)
            cols[:length, k] = sps.lfilter(b, a, self._impulse[:length])
        return cols

    def disturbance_scale(self, p: LoopParams) -> float:
        """max |H(j w)| (rad per N m): the following error a disturbance makes at most, per N m."""
        w = np.logspace(-1.0, math.log10(math.pi / self.dt), 300)
        _, h = sps.freqs(self._num_disturbance(p), self._den(p), w)
        return float(np.max(np.abs(h)))

    # ---- the fit
    def residual(self, p: LoopParams, disturbances: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The following error the loop model leaves (rad, on the fit's rows), its disturbance
        coefficients (N m) and start solved linearly, and those coefficients."""
        r = self.rows
        y = (self.pos - self.response(p))[r]
        x = np.column_stack([-self.disturbance_response(p, disturbances), self.nuisance(p)])[r]
        beta, _ = ols(y, x)
        return y - x @ beta, beta

    def fit(self, disturbances: np.ndarray, start: LoopParams | None = None) -> LoopFit:
        """The loop that explains the following error best, with ``disturbances`` (columns, N m)
        beside it; from ``start`` or from a grid of loops a drive may run.

        In two stages: the gains and Tv with the lag and the lead held (unbounded Levenberg-
        Marquardt on log gains: a few times fewer evaluations than a bounded method), then every
        parameter from there, held within its range by a penalty (the lag and the lead are the
        weakest directions)."""
        starts = [start] if start is not None else self._starts(disturbances)
        lo, hi = bounds(self.j)

        def resid(v: np.ndarray) -> np.ndarray:
            return self.residual(LoopParams.from_vector(v), disturbances)[0] * ARCSEC_PER_RAD

        best: tuple[float, LoopParams] | None = None
        for s in starts:
            v0 = np.clip(s.vector(), lo, hi)
            held = v0[4:]
            try:
                first = least_squares(
                    lambda v, held=held: resid(np.concatenate([np.clip(v, lo[:4], hi[:4]), held])),
                    v0[:4],
                    method="lm",
                    x_scale="jac",
                    diff_step=1e-4,
                    xtol=FIT_XTOL,
                    max_nfev=FIT_MAX_EVALUATIONS,
                )
                v1 = np.clip(np.concatenate([first.x, held]), lo, hi)
                sol = least_squares(
                    lambda v: np.concatenate([resid(np.clip(v, lo, hi)), PENALTY * (v - np.clip(v, lo, hi))]),
                    v1,
                    method="lm",
                    x_scale="jac",
                    diff_step=1e-4,
                    xtol=FIT_XTOL,
                    max_nfev=SECOND_STAGE_EVALUATIONS,
                )
            except (ValueError, np.linalg.LinAlgError):  # pragma: no cover - degenerate data
                continue
            p = LoopParams.from_vector(np.clip(sol.x, lo, hi))
            cost = float(np.sqrt(np.mean(resid(p.vector()) ** 2)))
            if best is None or cost < best[0]:
                best = (cost, p)
            if LoopFit(p, cost, self._following_error_rms()).explains:
                break  # the best start already explains it: the next one would cost as much again
        if best is None:  # pragma: no cover - every start failed
            best = (math.inf, starts[0])
        _, beta = self.residual(best[1], disturbances)
        k = disturbances.shape[1]
        return LoopFit(best[1], best[0], self._following_error_rms(), beta[:k])

    def with_torque(self, torque_nm: np.ndarray) -> RecordedLoop:
        """The same recording with ``torque_nm`` (analysis rate) acting on the axis beside what is
        measured: a model whose effects are fixed."""
        known = torque_nm if self.known is None else self.known + torque_nm
        return RecordedLoop(self.sig, self.j, known, self.rows)

    def simulate(self, p: LoopParams) -> np.ndarray:
        """The position (rad, analysis rate, relative to the first command) the loop gives, its
        start fitted to the recording's."""
        x = self.response(p)
        free = self.free_responses(p)
        beta, _ = ols((self.pos - x)[self.rows], free[self.rows])
        return x + free @ beta

    def _following_error_rms(self) -> float:
        eps = (self.cmd - self.pos)[self.rows] * ARCSEC_PER_RAD
        return float(np.sqrt(np.mean((eps - np.mean(eps)) ** 2)))

    def _starts(self, disturbances: np.ndarray) -> list[LoopParams]:
        """The best few of a grid of loops, the position gain of each from the following error at
        steady speed, which is (1 - FF) x speed / Kp whatever the speed loop (its integral holds
        the load)."""
        ratio = self._lag_per_speed()
        grid = []
        for ff in START_FF:
            kp = (1.0 - ff) / ratio if ratio > 0 else 0.0
            for f in START_BANDWIDTH_HZ:
                w = 2.0 * math.pi * f
                kp_f = min(max(kp if kp > 0 else w / 5.0, KP_RANGE[0]), KP_RANGE[1])
                for periods in START_TV_PERIODS:
                    grid.append(LoopParams(kp_f, ff, w * self.j, periods / w, START_LAG_MS / 1000.0))
        scored = sorted(
            grid, key=lambda p: float(np.sum(self.residual(p, disturbances)[0] ** 2))
        )
        return scored[:REFINED_STARTS]

    def _lag_per_speed(self) -> float:
        """Following error per speed (s) while the command runs at a steady speed."""
        v = np.gradient(self.cmd, self.dt)
        a = np.gradient(v, self.dt)
        moving = np.abs(v) > 0.2 * np.max(np.abs(v)) if len(v) else np.zeros(0, bool)
        steady = moving & (np.abs(a) < 0.05 * max(float(np.max(np.abs(a))), 1e-12))
        if np.count_nonzero(steady) < 10:
            return 0.0
        eps = self.cmd - self.pos
        return float(np.sum(eps[steady] * v[steady]) / np.sum(v[steady] ** 2))


def pushed_standstills(sig: Signals) -> list[tuple[int, int]]:
    """The spans (analysis-rate rows) where the command moves but the axis stands: friction holds
    it while the loop winds its torque up (a start, above all a reversal)."""
    assert sig.cmd_pos_rad is not None
    f = sig.filt
    threshold = 3.0 * max(sig.pos_noise_rad, 1e-9) / (f.window * f.dt_s)
    still = np.abs(sig.speed_rad_s) <= threshold
    pushed = still & (np.abs(f.speed(sig.cmd_pos_rad)) > threshold)
    edges = np.flatnonzero(np.diff(np.concatenate([[0], pushed.astype(np.int8), [0]])))
    return [(int(a), int(b)) for a, b in zip(edges[::2], edges[1::2], strict=True)]


def through_loop(cands: tuple[Candidate, ...], model: RecordedLoop, p: LoopParams) -> tuple[Candidate, ...]:
    """The candidates with their columns passed through H and scaled by 1 / max |H| (N m), with
    the sign of a torque that holds the position back."""
    scale = 1.0 / model.disturbance_scale(p)

    def wrap(c: Candidate) -> Candidate:
        def build(ctx, shape, _build=c.build):
            return -scale * model.disturbance_response(p, np.asarray(_build(ctx, shape), dtype=float))

        # the loop's response needs the whole record: never built at the fitted rows only
        return replace(c, build=build, decimates=False)

    return tuple(wrap(c) for c in cands)


def oe_channel(
    model: RecordedLoop, p: LoopParams, index: np.ndarray
) -> tuple[np.ndarray, np.ndarray, float]:
    """The following error the loop leaves, scaled to N m (1 / max |H|), at the analysis rate; the
    nuisance columns on the decimated rows (the loop's own parameters linearised, so that they are
    fitted with the effects, then RecordedLoop.nuisance); and the scale (N m per rad)."""
    scale = 1.0 / model.disturbance_scale(p)
    y = (model.pos - model.response(p)) * scale
    v = p.vector()
    jac = []
    for i in range(N_PARAMS):
        step = 1e-3
        up, down = v.copy(), v.copy()
        up[i] += step
        down[i] -= step
        d = model.response(LoopParams.from_vector(up)) - model.response(LoopParams.from_vector(down))
        jac.append(d / (2.0 * step) * scale)
    base = np.column_stack([np.column_stack(jac), model.nuisance(p) * scale])
    return y, base[index], scale
