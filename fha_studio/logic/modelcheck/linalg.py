"""The linear algebra of the model check's selection (step 3): AR whitening, least squares, BIC and
contiguous-block cross-validation (selection.py says why each)."""

from __future__ import annotations

import itertools
import math

import numpy as np

CV_BLOCKS = 5
MAX_AR_ORDER = 12


def fit_ar(e: np.ndarray, max_order: int = MAX_AR_ORDER) -> np.ndarray:
    """AR coefficients phi (e[t] ~ sum phi_k e[t-k]) by Yule-Walker (Levinson-Durbin), order by BIC."""
    n = len(e)
    top = max(0, min(max_order, n // 10))
    x = e - np.mean(e)
    r = np.array([float(x[: n - k] @ x[k:]) / n for k in range(top + 1)])
    if r[0] <= 0:
        return np.empty(0)
    best_bic, best = n * math.log(r[0]), np.empty(0)
    phi = np.empty(0)
    err = r[0]
    for p in range(1, top + 1):
        k = (r[p] - float(phi @ r[p - 1 : 0 : -1])) / err if p > 1 else r[1] / err
        phi = np.concatenate([phi - k * phi[::-1], [k]]) if p > 1 else np.array([k])
        err *= max(1.0 - k * k, 1e-12)
        value = n * math.log(max(err, 1e-300)) + p * math.log(n)
        if value < best_bic:
            best_bic, best = value, phi.copy()
    return best


def whiten(x: np.ndarray, phi: np.ndarray) -> np.ndarray:
    """Apply the AR whitening filter w[t] = x[t] - sum phi_k x[t-k] (drops the first p samples)."""
    p = len(phi)
    if p == 0:
        return x
    out = x[p:].copy()
    for k in range(p):
        out = out - phi[k] * x[p - k - 1 : len(x) - k - 1]
    return out


def gram(x: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """x'x and x'y of a tall, narrow design without BLAS: OpenBLAS threads even these small
    products (a 2500 x 17 x'x already), and on a loaded machine its waiting threads spin: a
    2500 x 19 Gram matrix took 37 ms of CPU that way against 0.5 ms by einsum (measured here)."""
    return np.einsum("ij,ik->jk", x, x), np.einsum("ij,i->j", x, y)


def solve_normal(g: np.ndarray, b: np.ndarray, rcond: float = 1e-10) -> np.ndarray:
    """pinv(g) @ b for a symmetric g, as numpy.linalg.pinv(g, rcond, hermitian=True) computes it
    (eigenvalues below rcond x the largest magnitude dropped), without its wrappers' cost: these
    fits are a dozen columns wide and numerous."""
    w, v = np.linalg.eigh(g)
    magnitude = np.abs(w)
    inv = np.divide(1.0, w, out=np.zeros_like(w), where=magnitude > rcond * magnitude.max())
    return v @ (inv * (b @ v))


def _scaled(g: np.ndarray, xty: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The normal equations of the columns scaled to unit norm (the scale, from the diagonal)."""
    scale = np.sqrt(np.diag(g))
    scale[scale == 0] = 1.0
    return g / np.outer(scale, scale), xty / scale, scale


def ols(y: np.ndarray, x: np.ndarray) -> tuple[np.ndarray, float]:
    """Least squares (normal equations on scaled columns, pseudo-inverse): coefficients and RSS."""
    if x.shape[1] == 0:
        return np.empty(0), float(y @ y)
    gs, xtys, scale = _scaled(*gram(x, y))
    beta = solve_normal(gs, xtys) / scale
    r = y - x @ beta
    return beta, float(r @ r)


class Beside:
    """Least squares of y on [x, c] for many c beside one x, by projection: x's normal equations
    are solved once, and each c costs the products with it (x'c, c'c, c'y) and a solve as wide as
    c, not the whole Gram matrix and its eigenvectors again. The coefficients of c and the residual
    are those ``ols(y, [x, c])`` gives while [x, c] has full rank (a shape search or a frequency scan
    tries a few dozen columns beside the same model)."""

    def __init__(self, y: np.ndarray, x: np.ndarray, rcond: float = 1e-10):
        self.y, self.x, self.rcond = y, x, rcond
        if x.shape[1]:
            gs, xtys, scale = _scaled(*gram(x, y))
            w, v = np.linalg.eigh(gs)
            magnitude = np.abs(w)
            inv = np.divide(1.0, w, out=np.zeros_like(w), where=magnitude > rcond * magnitude.max())
            # pinv(x'x) through the scaled columns: x pinv x' is the projection onto x's columns
            self._pinv = (v * inv) @ v.T / np.outer(scale, scale)
            self.beta_x = self._pinv @ (xtys * scale)
            self.y_rest = y - x @ self.beta_x
        else:
            self._pinv = np.zeros((0, 0))
            self.y_rest = y

    def fit(self, c: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The coefficients of the columns c beside x, and the residual y - [x, c] beta."""
        c_rest = c - self.x @ (self._pinv @ np.einsum("ij,ik->jk", self.x, c)) if self.x.shape[1] else c
        beta = solve_normal_scaled(*gram(c_rest, self.y_rest), rcond=self.rcond)
        return beta, self.y_rest - c_rest @ beta


def solve_normal_scaled(g: np.ndarray, b: np.ndarray, rcond: float = 1e-10) -> np.ndarray:
    """The normal equations g beta = b solved on unit-norm columns (pseudo-inverse), as ols does."""
    gs, bs, scale = _scaled(g, b)
    return solve_normal(gs, bs, rcond) / scale


def bic(rss: float, n: int, k: int) -> float:
    """Bayesian information criterion of a Gaussian least-squares fit."""
    return n * math.log(max(rss / n, 1e-300)) + k * math.log(n)


def block_edges(n: int, blocks: int = CV_BLOCKS) -> list[tuple[int, int]]:
    """Contiguous blocks covering 0..n."""
    cuts = np.linspace(0, n, blocks + 1).round().astype(int)
    return [(int(a), int(b)) for a, b in itertools.pairwise(cuts)]


def fold_betas(y: np.ndarray, x: np.ndarray, edges: list[tuple[int, int]]) -> list[np.ndarray]:
    """Least-squares coefficients with each block [a, b) left out, in turn.

    The normal equations of a fold are the whole record's minus the left-out block's, so the
    record is multiplied out once, block by block, not once per fold (the cost stays linear in its
    length).
    """
    blocks = [gram(x[a:b], y[a:b]) for a, b in edges]
    if edges and edges[0][0] == 0 and edges[-1][1] == len(y) and all(
        b == a2 for (_, b), (a2, _) in itertools.pairwise(edges)
    ):  # the blocks cover the record: its products are theirs summed
        g_all, xty = sum(g for g, _ in blocks), sum(v for _, v in blocks)
    else:
        g_all, xty = gram(x, y)
    scale = np.sqrt(np.diag(g_all))
    scale[scale == 0] = 1.0
    outer = np.outer(scale, scale)
    out = []
    for g_block, xty_block in blocks:
        beta = solve_normal((g_all - g_block) / outer, (xty - xty_block) / scale)
        out.append(beta / scale)
    return out


def block_cv(y: np.ndarray, x: np.ndarray, blocks: int = CV_BLOCKS) -> tuple[float, np.ndarray]:
    """Held-out RMS and the held-out prediction: each block predicted from a fit on the others."""
    n = len(y)
    pred = np.zeros(n)
    if x.shape[1]:
        edges = block_edges(n, blocks)
        for (a, b), beta in zip(edges, fold_betas(y, x, edges), strict=True):
            pred[a:b] = x[a:b] @ beta
    r = y - pred
    return float(np.sqrt(np.mean(r**2))), pred
