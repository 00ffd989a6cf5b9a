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
    """x'x and x'y of a tall, narrow design without BLAS: a multi-threaded BLAS spends more CPU
    starting and spinning its threads than these few thousand x a dozen products take."""
    return np.einsum("ij,ik->jk", x, x), np.einsum("ij,i->j", x, y)


def ols(y: np.ndarray, x: np.ndarray) -> tuple[np.ndarray, float]:
    """Least squares (normal equations on scaled columns, pseudo-inverse): coefficients and RSS."""
    if x.shape[1] == 0:
        return np.empty(0), float(y @ y)
    scale = np.sqrt(np.sum(x * x, axis=0))
    scale[scale == 0] = 1.0
    xs = x / scale
    g, xty = gram(xs, y)
    beta = (np.linalg.pinv(g, rcond=1e-10, hermitian=True) @ xty) / scale
    r = y - x @ beta
    return beta, float(r @ r)


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
    record is multiplied out once, not once per fold (the cost stays linear in its length).
    """
    scale = np.sqrt(np.sum(x * x, axis=0))
    scale[scale == 0] = 1.0
    xs = x / scale
    g_all, xty = gram(xs, y)
    out = []
    for a, b in edges:
        g_block, xty_block = gram(xs[a:b], y[a:b])
        beta = np.linalg.pinv(g_all - g_block, rcond=1e-10, hermitian=True) @ (xty - xty_block)
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
