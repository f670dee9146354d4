"""Column generation for large candidate sets (l1 charges and masses, group-sparse dipoles).

A small problem on a working set is solved, every candidate is priced with its duals, the
violators join, until none is left: that proves the restricted optimum optimal for the whole
set. Used above :data:`CG_MIN_CANDIDATES` candidates (or when forced by the options); if a
round ends with slack the full problem (:mod:`chargedesign.designer.problems`) decides.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from chargedesign.designer.problems import dipole_cvxpy, l1_lp_full, weights_cost
from chargedesign.designer.solvers import Solution, least_norm, solve_linprog
from chargedesign.designer.system import DesignProblem, group_norms
from chargedesign.formatting import FLOOR, fmt
from chargedesign.scene.design import DesignOptions, Progress

#: column generation is used for l1 / mass / group-sparse problems above this many candidates
CG_MIN_CANDIDATES = 2000


def use_column_generation(p: DesignProblem, options: DesignOptions) -> bool:
    """Whether to solve the problem by column generation (the option, or by its size)."""
    if options.column_generation is not None:
        return options.column_generation
    return p.n_candidates > CG_MIN_CANDIDATES


def l1_lp_column_generation(
    p: DesignProblem, costs: np.ndarray | None, progress: Progress | None
) -> Solution:
    """min sum c_j |u_j| (charges) or c.u, u >= 0 (masses) by column generation.

    Restricted problems on a working set carry elastic slacks (penalty ``P``), so each is
    feasible; all columns are priced with its duals ``y`` (reduced cost ``c_j -+ a_j . y``)
    and the most negative ones join, until none is negative. Then the restricted optimum is
    optimal for the full set (the duals are feasible for it). If a slack stays non-zero the
    full LP decides (infeasible, or the penalty was too small).
    """
    A, b = p.A_s, p.b_s
    m, n = A.shape
    c = weights_cost(n, costs)
    penalty = 1e4 * float(np.max(c)) * max(1.0, float(np.max(np.abs(b))))
    # start: the columns that carry the least-norm solution, and a few most correlated
    u_ln = least_norm(A, b)
    k0 = min(n, max(4 * m, 60))
    start = np.argsort(-np.abs(u_ln))[:k0]
    corr = np.argsort(-np.abs(A.T @ b))[:k0]
    work = np.unique(np.concatenate([start, corr]))
    in_work = np.zeros(n, dtype=bool)
    in_work[work] = True
    step = max(2 * m, 40)
    price_tol = 1e-9
    eye = np.eye(m)
    rounds = 0
    for rounds in range(1, 201):
        cols = np.flatnonzero(in_work)
        k = len(cols)
        Aw = A[:, cols]
        bounds: Sequence[tuple[float | None, float | None]]
        if p.nonneg:
            A_eq = np.hstack([Aw, eye, -eye])
            cost = np.concatenate([c[cols], np.full(2 * m, penalty)])
            bounds = [(0.0, None)] * (k + 2 * m)
        else:
            A_eq = np.hstack([Aw, -Aw, eye, -eye])
            cost = np.concatenate([c[cols], c[cols], np.full(2 * m, penalty)])
            bounds = [(0.0, p.upper)] * (2 * k) + [(0.0, None)] * (2 * m)
        res = solve_linprog(cost, A_eq, b, bounds, f"{p.source}: column generation")
        y = res.eq_duals
        ay = A.T @ y
        if p.nonneg:
            reduced = c - ay
        else:
            reduced = c - np.abs(ay)
        reduced[in_work] = 0.0
        violators = np.flatnonzero(reduced < -price_tol)
        if progress is not None and rounds % 5 == 0:
            progress(f"{p.source}: column generation round {rounds}, working set {k}")
        if len(violators) == 0:
            x = res.x
            slack = float(np.sum(x[-2 * m :]))
            u = np.zeros(n)
            u[cols] = x[:k] if p.nonneg else x[:k] - x[k : 2 * k]
            if slack > 1e-9 * max(1.0, float(np.max(np.abs(b)))):
                # slack left: infeasible, or the penalty was too small; the full LP decides
                full = l1_lp_full(p, costs, None)
                full.method += " (column generation ended with slack; full LP used)"
                return full
            sol = Solution(
                u,
                "HiGHS",
                f"column generation: {rounds} rounds, working set {k} of {n} candidates; "
                f"optimality verified (least reduced cost {fmt(float(np.min(reduced)), FLOOR)})",
            )
            return sol
        order = violators[np.argsort(reduced[violators])][:step]
        in_work[order] = True
    full = l1_lp_full(p, costs, None)
    full.method += " (column generation did not converge in 200 rounds; full LP used)"
    return full


def dipoles_column_generation(p: DesignProblem, solver: str, progress: Progress | None) -> Solution:
    """Group-sparse dipoles by column generation (groups of 3 columns per candidate).

    Dual feasibility of the full problem is ``|A_g^T y| <= 1`` for every candidate g; the
    restricted problem's duals price every group and violators join until none is left.
    """
    A, b = p.A_s, p.b_s
    m = A.shape[0]
    n = A.shape[1] // 3
    blocks = A.reshape(m, n, 3)
    u_ln = least_norm(A, b)
    k0 = min(n, max(4 * m, 40))
    start = np.argsort(-group_norms(u_ln))[:k0]
    in_work = np.zeros(n, dtype=bool)
    in_work[start] = True
    penalty = 1e4 * max(1.0, float(np.max(np.abs(b))))
    step = max(2 * m, 20)
    where = "dipoles: column generation"
    last_status = "optimal"
    rounds = 0
    for rounds in range(1, 101):
        groups = np.flatnonzero(in_work)
        cols = (3 * groups[:, None] + np.arange(3)).reshape(-1)
        u_w, y, last_status = dipole_cvxpy(A[:, cols], b, "l1", solver, where, penalty)
        prices = np.linalg.norm(np.einsum("mgk,m->gk", blocks, y), axis=1)
        prices[in_work] = 0.0
        violators = np.flatnonzero(prices > 1.0 + 1e-7)
        if progress is not None and rounds % 3 == 0:
            progress(f"dipoles: column generation round {rounds}, working set {len(groups)}")
        if len(violators) == 0:
            u = np.zeros(3 * n)
            u[cols] = u_w
            residual = float(np.max(np.abs(A @ u - b)))
            if residual > 1e-6 * max(1.0, float(np.max(np.abs(b)))):
                break  # slack left: let the full problem decide
            return Solution(
                u,
                solver.capitalize(),
                f"column generation: {rounds} rounds, working set {len(groups)} of {n} "
                f"candidates; optimality verified (largest price outside "
                f"{float(np.max(prices, initial=0.0)):.6f} <= 1)",
                last_status,
            )
        order = violators[np.argsort(-prices[violators])][:step]
        in_work[order] = True
    u, _, status = dipole_cvxpy(A, b, "l1", solver, "dipoles: l1 problem")
    return Solution(
        u, solver.capitalize(), "cvxpy, full problem (column generation fallback)", status
    )
