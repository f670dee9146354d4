"""The convex problems of one source on the whole candidate set, per objective.

- ``l1``: minimum ``sum c_j |u_j|`` (charges; masses: ``c . u`` with ``u >= 0``) as one
  HiGHS linear program, or through cvxpy for another solver;
- ``linf``: minimum ``max |u_j|`` as a linear program (HiGHS) or through cvxpy;
- ``l2``: minimum ``sum u_j^2``: the least-norm closed form when unconstrained, else a
  quadratic program (Clarabel);
- dipoles: the group norms ``|sigma_j|`` (second-order cone, cvxpy).

Large ``l1`` problems are solved by column generation
(:mod:`chargedesign.designer.column_generation`), which falls back on these.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from chargedesign.designer.solvers import (
    Solution,
    check_cvxpy_status,
    import_cvxpy,
    least_norm,
    solve_cvxpy,
    solve_linprog,
    solver_name,
)
from chargedesign.designer.system import DesignProblem
from chargedesign.scene.design import DesignOptions


def weights_cost(n: int, costs: np.ndarray | None) -> np.ndarray:
    """The per-weight costs of the l1 objective (ones when none are given)."""
    return np.ones(n) if costs is None else costs


def l1_lp_full(p: DesignProblem, costs: np.ndarray | None, support: np.ndarray | None) -> Solution:
    """min sum c_j |u_j| (or c.u with u >= 0 for masses) by one HiGHS LP."""
    cols = np.arange(p.A_s.shape[1]) if support is None else support
    A = p.A_s[:, cols]
    c = weights_cost(p.A_s.shape[1], costs)[cols]
    where = f"{p.source}: l1 problem"
    if p.nonneg:
        res = solve_linprog(c, A, p.b_s, (0, None), where)
        u_cols = res.x
    else:
        ub = p.upper
        res = solve_linprog(np.concatenate([c, c]), np.hstack([A, -A]), p.b_s, (0, ub), where)
        k = len(cols)
        u_cols = res.x[:k] - res.x[k:]
    u = np.zeros(p.A_s.shape[1])
    u[cols] = u_cols
    return Solution(u, "HiGHS", f"linear program on {len(cols)} candidates")


def _scalar_cvxpy(
    p: DesignProblem, objective: Callable[[Any], Any], solver: str, where: str
) -> Solution:
    """Minimise ``objective(u)`` through cvxpy subject to ``A_s u = b_s``, ``u >= 0`` for
    masses and ``|u| <= upper`` under a charge bound (the full problem)."""
    cp = import_cvxpy()
    u = cp.Variable(p.A_s.shape[1], nonneg=p.nonneg)
    cons = [p.A_s @ u == p.b_s]
    if p.upper is not None:
        cons.append(cp.abs(u) <= p.upper)
    prob = cp.Problem(cp.Minimize(objective(u)), cons)
    status = check_cvxpy_status(solve_cvxpy(prob, solver, where), where, solver)
    return Solution(
        np.asarray(u.value, dtype=float), solver.capitalize(), "cvxpy, full problem", status
    )


def l1_cvxpy(p: DesignProblem, costs: np.ndarray | None, solver: str) -> Solution:
    """min sum c_j |u_j| (or c.u with u >= 0 for masses) through cvxpy with ``solver``."""
    cp = import_cvxpy()
    c = weights_cost(p.A_s.shape[1], costs)

    def objective(u: Any) -> Any:
        return c @ u if p.nonneg else cp.sum(cp.multiply(c, cp.abs(u)))

    return _scalar_cvxpy(p, objective, solver, f"{p.source}: l1 problem")


def solve_linf_scalar(p: DesignProblem, options: DesignOptions) -> Solution:
    """min max_j |u_j| (charges) or max_j u_j, u >= 0 (masses), by HiGHS or cvxpy."""
    solver = solver_name(options)
    n = p.A_s.shape[1]
    where = f"{p.source}: linf problem"
    if solver in ("AUTO", "HIGHS"):
        from scipy import sparse

        # variables (u, t): minimise t with -t <= u_j <= t (masses: 0 <= u_j <= t)
        eye = sparse.identity(n, format="csr")
        ones = sparse.csr_matrix(np.ones((n, 1)))
        bounds: Sequence[tuple[float | None, float | None]]
        if p.nonneg:
            A_ub = sparse.hstack([eye, -ones], format="csr")
            b_ub = np.zeros(n)
            bounds = [(0.0, None)] * n + [(0.0, None)]
        else:
            A_ub = sparse.vstack(
                [sparse.hstack([eye, -ones]), sparse.hstack([-eye, -ones])], format="csr"
            )
            b_ub = np.zeros(2 * n)
            bounds = [(None, None)] * n + [(0.0, p.upper)]
        A_eq = sparse.hstack([sparse.csr_matrix(p.A_s), sparse.csr_matrix((len(p.b_s), 1))])
        cost = np.zeros(n + 1)
        cost[-1] = 1.0
        res = solve_linprog(cost, A_eq.tocsr(), p.b_s, bounds, where, A_ub=A_ub, b_ub=b_ub)
        return Solution(res.x[:n], "HiGHS", f"linear program on {n} candidates")
    cp = import_cvxpy()
    return _scalar_cvxpy(p, lambda u: cp.norm(u, "inf"), solver, where)


def solve_l2(p: DesignProblem, options: DesignOptions) -> Solution:
    """min sum u_j^2 subject to the conditions: closed form when unconstrained, else cvxpy."""
    solver = solver_name(options)
    unconstrained = not p.nonneg and p.upper is None
    if unconstrained and solver == "AUTO":
        # the minimum of sum w^2 (or sum |sigma|^2) subject to A w = b is the least-norm solution
        return Solution(least_norm(p.A_s, p.b_s), "lstsq", "closed form (least norm)")
    cp = import_cvxpy()
    name = "CLARABEL" if solver == "AUTO" else solver
    return _scalar_cvxpy(p, lambda u: cp.sum_squares(u), name, f"{p.source}: l2 problem")


def dipole_cvxpy(
    A: np.ndarray, b: np.ndarray, objective: str, solver: str, where: str, penalty: float = 0.0
) -> tuple[np.ndarray, np.ndarray, str]:
    """Dipole problem on columns ``A`` (m, 3k) via cvxpy: returns (u, dual y, status)."""
    cp = import_cvxpy()
    k = A.shape[1] // 3
    u = cp.Variable(3 * k)
    vectors = cp.reshape(u, (k, 3), order="C")
    norms = cp.norm(vectors, 2, axis=1)
    goal = cp.sum(norms) if objective == "l1" else cp.max(norms)
    if penalty > 0:
        slack = cp.Variable(len(b))
        con = A @ u + slack == b
        goal = goal + penalty * cp.norm1(slack)
    else:
        con = A @ u == b
    prob = cp.Problem(cp.Minimize(goal), [con])
    status = check_cvxpy_status(solve_cvxpy(prob, solver, where), where, solver)
    y = np.asarray(con.dual_value, dtype=float).reshape(-1)
    return np.asarray(u.value, dtype=float), y, status
