"""Polishing to machine precision: the least-norm correction on a fixed support.

The support (non-zero weights) of the solver's answer is kept and the least-norm
correction applied on it (``lstsq`` with one refinement step); masses that would turn
negative are re-solved by NNLS on the support. The relative residual
(:func:`chargedesign.designer.system.relative_residual`) then reaches ~1e-16.
"""

from __future__ import annotations

import numpy as np

from chargedesign.designer.solvers import least_norm, least_norm_solver
from chargedesign.designer.system import DesignProblem, group_norms, relative_residual
from chargedesign.formatting import PLAIN, fmt

#: supports tried by polishing: weights below these fractions of the largest are dropped
POLISH_THRESHOLDS = (1e-6, 1e-9, 1e-12, 0.0)


def support_of(u: np.ndarray, group: int, threshold: float) -> np.ndarray:
    """Indices of the candidates (groups of ``group`` weights) above ``threshold`` x the largest."""
    mags = group_norms(u) if group == 3 else np.abs(u)
    top = float(np.max(mags)) if len(mags) else 0.0
    return np.flatnonzero(mags > threshold * top) if top > 0 else np.zeros(0, dtype=int)


def _columns(support: np.ndarray, group: int) -> np.ndarray:
    if group == 1:
        return support
    return (3 * support[:, None] + np.arange(3)).reshape(-1)


def _polish_on(p: DesignProblem, u: np.ndarray, support: np.ndarray) -> np.ndarray | None:
    """Least-norm correction of ``u`` on ``support`` (candidate indices); None if it breaks
    a constraint (a bound, or a mass that cannot stay nonnegative)."""
    from scipy.optimize import nnls

    if len(support) == 0:
        return None
    cols = _columns(support, p.group)
    values = u[cols].copy()
    fixed = np.zeros(len(cols), dtype=bool)
    if p.upper is not None:
        # charges at the bound stay exactly at it; the rest absorb the correction
        fixed = np.abs(values) >= p.upper * (1.0 - 1e-9)
        values[fixed] = np.sign(values[fixed]) * p.upper
    free = ~fixed
    if not np.any(free):
        return None
    A_free = p.A_s[:, cols[free]]
    rhs = p.b_s - p.A_s[:, cols[fixed]] @ values[fixed]
    solve = least_norm_solver(A_free)  # one factor for both corrections
    for _ in range(2):
        values[free] += least_norm(A_free, rhs - A_free @ values[free], solve)
    if p.nonneg and np.any(values < 0):
        # nonnegative least squares on the support, then the least-norm correction on the
        # masses it keeps positive
        A_sup = p.A_s[:, cols]
        values, _ = nnls(A_sup, p.b_s, maxiter=50 * len(cols) + 100)
        keep = values > 0
        A_keep = A_sup[:, keep]
        solve = least_norm_solver(A_keep)
        for _ in range(2):
            values[keep] += least_norm(A_keep, p.b_s - A_keep @ values[keep], solve)
        if np.any(values < 0):
            return None
    if p.upper is not None and np.any(np.abs(values) > p.upper * (1.0 + 1e-12)):
        return None
    out = np.zeros_like(u)
    out[cols] = values
    return out


def _extend_support(
    p: DesignProblem, u: np.ndarray, support: np.ndarray, tol: float
) -> tuple[np.ndarray, int] | None:
    """Add candidates one at a time (most correlated with the residual) until ``tol`` is met.

    Needed when the solver's support misses an element whose exact weight is below its
    feasibility tolerance (targets whose terms differ by many orders of magnitude).
    """
    current = u
    chosen = set(int(i) for i in support)
    m = len(p.b_s)
    n = p.n_candidates
    blocks = p.A_s.reshape(m, n, p.group)
    col_norms = np.sqrt(np.einsum("mnk,mnk->n", blocks, blocks))
    col_norms = np.where(col_norms > 0, col_norms, np.inf)
    for added in range(1, m + 1):
        r = p.b_s - p.A_s @ current
        corr = np.einsum("mnk,m->nk", blocks, r)
        if p.nonneg:
            price = np.maximum(corr[:, 0], 0.0) / col_norms
        else:
            price = np.linalg.norm(corr, axis=1) / col_norms
        price[list(chosen)] = -1.0
        best = int(np.argmax(price))
        if price[best] <= 0:
            return None
        chosen.add(best)
        polished = _polish_on(p, current, np.array(sorted(chosen)))
        if polished is None:
            return None
        current = polished
        if relative_residual(p.A, current * p.scale, p.b) <= tol:
            return current, added
    return None


def polish_weights(p: DesignProblem, u: np.ndarray, tol: float) -> tuple[np.ndarray, str]:
    """Polish ``u`` (scaled) on its support.

    1. Supports from the sparsest (weights below 1e-6 of the largest dropped) to 1e-12: the
       first whose polished residual meets ``tol`` wins (dropping solver noise and reaching
       machine precision at once).
    2. Else candidates are added to the sparsest support one at a time
       (:func:`_extend_support`): the solver may have left out an element whose exact
       weight is below its feasibility tolerance.
    3. Else the solver's full support. If nothing meets ``tol`` the smallest residual is
       kept (the caller then refuses it).
    """
    best = u
    best_res = relative_residual(p.A, u * p.scale, p.b)
    text = "polishing did not improve the residual"
    sparse_start: np.ndarray | None = None

    def describe(weights: np.ndarray, how: str) -> str:
        count = len(support_of(weights, p.group, 0.0))
        return f"least-norm correction on the support ({count} elements; {how})"

    for threshold in POLISH_THRESHOLDS[:-1]:
        cand = _polish_on(p, u, support_of(u, p.group, threshold))
        if cand is None:
            continue
        if sparse_start is None:
            sparse_start = cand
        res = relative_residual(p.A, cand * p.scale, p.b)
        if res <= tol:
            return cand, describe(
                cand, f"weights below {fmt(threshold, PLAIN)} of the largest dropped"
            )
        if res < best_res:
            best, best_res = cand, res
            text = describe(cand, f"weights below {fmt(threshold, PLAIN)} of the largest dropped")
    if sparse_start is not None:
        extended = _extend_support(p, sparse_start, support_of(sparse_start, p.group, 0.0), tol)
        if extended is not None:
            current, added = extended
            return current, describe(
                current, f"{added} added to the solver's support to meet the tolerance"
            )
    cand = _polish_on(p, u, support_of(u, p.group, 0.0))
    if cand is not None:
        res = relative_residual(p.A, cand * p.scale, p.b)
        if res <= tol or res < best_res:
            return cand, describe(cand, "the solver's full support")
    return best, text
