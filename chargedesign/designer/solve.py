"""Which problem solves a source: objective, full problem or column generation, sparsity.

:func:`solve_problem` dispatches one source's scaled problem by its objective; with
``n_charges`` the charges' support is first searched by reweighted l1 and then, if needed,
by a mixed-integer program (HiGHS), and the objective is solved on that support.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from chargedesign.designer.column_generation import (
    dipoles_column_generation,
    l1_lp_column_generation,
    use_column_generation,
)
from chargedesign.designer.polish import support_of
from chargedesign.designer.problems import (
    dipole_cvxpy,
    l1_cvxpy,
    l1_lp_full,
    solve_l2,
    solve_linf_scalar,
)
from chargedesign.designer.solvers import Solution, import_cvxpy, solve_cvxpy, solver_name
from chargedesign.designer.system import DesignProblem, restrict_problem
from chargedesign.errors import InfeasibleError, SolverError
from chargedesign.formatting import PLAIN, fmt
from chargedesign.scene.design import DesignOptions, Progress

#: candidates above which the mixed-integer fallback for ``n_charges`` is not attempted
MIP_MAX_CANDIDATES = 5000


def solve_problem(
    p: DesignProblem, objective: str, options: DesignOptions, progress: Progress | None
) -> Solution:
    """Solve one source's problem for ``objective``, choosing the method for its source."""
    if p.source == "dipoles":
        if objective == "l2":
            return solve_l2(p, options)
        if objective == "robust":
            return _solve_dipoles_weighted(p, options, progress)
        return _solve_dipoles_cone(p, options, progress)
    if p.source == "charges" and options.n_charges is not None:
        support, how = _reweighted_support(p, options, options.n_charges, progress)
        sub = restrict_problem(p, support)
        inner = solve_problem(sub, objective, replace(options, n_charges=None), progress)
        u = np.zeros(p.A_s.shape[1])
        u[support] = inner.u
        sol = Solution(u, inner.solver, f"{how}; then {inner.method}", inner.status)
        return sol
    if objective == "l1":
        return _solve_l1_scalar(p, options, None, progress)
    if objective == "robust":
        return _solve_l1_scalar(p, options, _costs(p), progress)
    if objective == "linf":
        return solve_linf_scalar(p, options)
    return solve_l2(p, options)


def _solve_l1_scalar(
    p: DesignProblem, options: DesignOptions, costs: np.ndarray | None, progress: Progress | None
) -> Solution:
    solver = solver_name(options)
    if solver in ("AUTO", "HIGHS"):
        if use_column_generation(p, options):
            return l1_lp_column_generation(p, costs, progress)
        return l1_lp_full(p, costs, None)
    return l1_cvxpy(p, costs, solver)


def _solve_dipoles_cone(
    p: DesignProblem, options: DesignOptions, progress: Progress | None
) -> Solution:
    objective = options.objective_for("dipoles")
    solver = solver_name(options)
    name = "CLARABEL" if solver == "AUTO" else solver
    where = f"dipoles: {objective} problem"
    if objective == "l1" and solver in ("AUTO", "CLARABEL") and use_column_generation(p, options):
        return dipoles_column_generation(p, name, progress)
    try:
        u, _, status = dipole_cvxpy(p.A_s, p.b_s, objective, name, where)
    except SolverError as exc:
        raise SolverError(
            f"{exc}; the dipoles' {objective} problem is a second-order cone: use solver "
            "'auto' or 'CLARABEL'"
        ) from exc
    return Solution(u, name.capitalize(), "cvxpy, full problem (second-order cone)", status)


def _costs(p: DesignProblem) -> np.ndarray:
    if p.cost is None:
        raise SolverError(f"{p.source}: the robust objective's costs were not computed")
    return p.cost


def _solve_dipoles_weighted(
    p: DesignProblem, options: DesignOptions, progress: Progress | None
) -> Solution:
    """min sum_j cost_j ||sigma_j||: the l1 cone problem in the columns ``v_j = cost_j sigma_j``."""
    cols = np.repeat(_costs(p), 3)
    scaled = replace(p, A=p.A / cols, A_s=p.A_s / cols, cost=None)
    # the plain l1 cone problem in the scaled columns (the weight is already in the costs)
    as_l1 = replace(
        options,
        objective="l1",
        objectives={**(options.objectives or {}), "dipoles": "l1"},
        robust_weight=1.0,
    )
    sol = _solve_dipoles_cone(scaled, as_l1, progress)
    sol.u = sol.u / cols
    sol.method += " (robust: columns scaled by their costs)"
    return sol


def _reweighted_support(
    p: DesignProblem, options: DesignOptions, target: int, progress: Progress | None
) -> tuple[np.ndarray, str]:
    """Indices of at most ``target`` charges meeting the conditions (reweighted l1, then MIP)."""
    best: np.ndarray | None = None
    if options.sparsity in ("auto", "reweighted"):
        costs = None
        for iteration in range(1, 11):
            sol = _solve_l1_scalar(p, replace(options, solver="auto"), costs, progress)
            u = sol.u
            top = float(np.max(np.abs(u))) if len(u) else 0.0
            support = support_of(u, 1, 1e-9)
            if best is None or len(support) < len(best):
                best = support
            if len(support) <= target:
                return support, f"reweighted l1: {iteration} iterations, {len(support)} charges"
            eps = 1e-3 * top
            costs = 1.0 / (np.abs(u) + eps)
            costs /= float(np.min(costs))
    if options.sparsity == "reweighted" or (
        options.sparsity == "auto" and p.n_candidates > MIP_MAX_CANDIDATES
    ):
        # not a proof of infeasibility (a heuristic failed to find one): a solver failure
        raise SolverError(
            f"charges: no design with at most {target} charges found (reweighted l1 reached "
            f"{len(best) if best is not None else 'none'}); raise design.n_charges"
            + (
                f" or use fewer than {MIP_MAX_CANDIDATES} candidates for the mixed-integer search"
                if p.n_candidates > MIP_MAX_CANDIDATES
                else ""
            )
        )
    if progress is not None:
        progress(
            f"charges: mixed-integer search for at most {target} charges "
            f"(up to {fmt(options.time_limit, PLAIN)} s) ..."
        )
    return _mip_support(p, options, target, best)


def _mip_support(
    p: DesignProblem, options: DesignOptions, target: int, best: np.ndarray | None
) -> tuple[np.ndarray, str]:
    cp = import_cvxpy()
    n = p.A_s.shape[1]
    if p.upper is not None:
        big_m = p.upper
        bound_text = f"|q| <= max_charge = {fmt(options.max_charge, PLAIN)} C"
    else:
        ref = l1_lp_full(p, None, None).u
        big_m = 10.0 * float(np.max(np.abs(ref)))
        bound_text = f"|q| <= {fmt(big_m * p.scale)} C (10 x the largest l1 charge; set max_charge)"
    u = cp.Variable(n)
    z = cp.Variable(n, boolean=True)
    prob = cp.Problem(
        cp.Minimize(cp.norm1(u)),
        [p.A_s @ u == p.b_s, cp.abs(u) <= big_m * z, cp.sum(z) <= target],
    )
    where = "charges: mixed-integer sparsity problem"
    status = solve_cvxpy(prob, "HIGHS", where, time_limit=options.time_limit)
    if status in ("infeasible", "infeasible_inaccurate"):
        raise InfeasibleError(
            f"charges: no design with at most {target} charges exists on these candidates with "
            f"{bound_text} (proved by HiGHS mixed-integer search)"
        )
    if status not in ("optimal", "optimal_inaccurate") or u.value is None:
        found = len(best) if best is not None else "none"
        raise SolverError(
            f"charges: no design with at most {target} charges found within "
            f"design.time_limit = {fmt(options.time_limit, PLAIN)} s (status {status}; the sparsest"
            " "
            f"found has {found}); raise n_charges or the time limit"
        )
    support = support_of(np.asarray(u.value, dtype=float), 1, 1e-9)
    return support, f"mixed integer (HiGHS): {len(support)} charges with {bound_text}"
