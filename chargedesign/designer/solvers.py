"""The solver back ends: HiGHS through scipy, cvxpy (Clarabel, HiGHS, ...), least norm.

Every status is checked here: a proved infeasibility raises :class:`InfeasibleProblem` (the
caller names the cause, :mod:`chargedesign.designer.diagnostics`), any other failure
:class:`chargedesign.errors.SolverError`. Clarabel's tolerances are tightened to 1e-12 (its
defaults bound the objective rather than the equality rows).
"""

from __future__ import annotations

import warnings
from collections.abc import Callable
from typing import Any

import numpy as np

from chargedesign.designer.linear_program import linprog_highs
from chargedesign.errors import SolverError
from chargedesign.scene.design import DesignOptions

#: Clarabel's tolerances (its defaults, 1e-8, bound the objective rather than the rows)
CLARABEL_SETTINGS = {"tol_gap_abs": 1e-12, "tol_gap_rel": 1e-12, "tol_feas": 1e-12}
#: HiGHS tolerances for the linear programs
HIGHS_OPTIONS = {"primal_feasibility_tolerance": 1e-10, "dual_feasibility_tolerance": 1e-10}


class Solution:
    """Scaled solution ``u`` of a problem and how it was found."""

    def __init__(self, u: np.ndarray, solver: str, method: str, status: str = "optimal"):
        self.u = u
        self.solver = solver
        self.method = method
        self.status = status
        self.notes: list[str] = []


class InfeasibleProblem(Exception):
    """A solver proved the (inequality-constrained) problem infeasible; diagnosed by caller."""


def import_cvxpy() -> Any:
    """The cvxpy module (imported lazily: it is slow to import)."""
    import cvxpy as cp

    return cp


def solve_cvxpy(problem: Any, solver: str, where: str, time_limit: float | None = None) -> str:
    """Solve a cvxpy problem, returning its status; raise SolverError on solver failure."""
    cp = import_cvxpy()
    kwargs: dict[str, Any] = {}
    if solver == "CLARABEL":
        kwargs.update(CLARABEL_SETTINGS)
    if solver == "HIGHS" and time_limit is not None:
        kwargs["time_limit"] = time_limit
    try:
        with warnings.catch_warnings():
            # cvxpy warns about inaccurate solutions; the status is checked below instead
            warnings.simplefilter("ignore")
            problem.solve(solver=solver, **kwargs)
    except cp.error.SolverError as exc:
        raise SolverError(f"{where}: solver {solver} failed ({exc})") from exc
    except (ValueError, TypeError) as exc:
        raise SolverError(f"{where}: solver {solver} cannot solve this problem ({exc})") from exc
    return str(problem.status)


def check_cvxpy_status(status: str, where: str, solver: str) -> str:
    """The status if optimal; raise InfeasibleProblem or SolverError otherwise."""
    if status in ("optimal", "optimal_inaccurate"):
        return status
    if status in ("infeasible", "infeasible_inaccurate"):
        raise InfeasibleProblem(where)
    raise SolverError(f"{where}: solver {solver} returned status {status!r}")


def solve_linprog(
    c: np.ndarray,
    A_eq: Any,
    b_eq: np.ndarray,
    bounds: Any,
    where: str,
    A_ub: Any = None,
    b_ub: np.ndarray | None = None,
) -> Any:
    """Solve a linear program with HiGHS; raise InfeasibleProblem or SolverError on failure."""
    res = linprog_highs(
        c, A_ub=A_ub, b_ub=b_ub, A_eq=A_eq, b_eq=b_eq, bounds=bounds, options=HIGHS_OPTIONS
    )
    if res.status == 2:
        raise InfeasibleProblem(where)
    if res.status != 0:
        raise SolverError(f"{where}: HiGHS returned status {res.status} ({res.message})")
    return res


def least_norm_solver(A: np.ndarray) -> Callable[[np.ndarray], np.ndarray]:
    """The minimum-norm solve ``rhs -> x`` of ``A x = rhs`` (A: shape (m, N)), one factor of
    ``A`` for every right-hand side.

    For wide matrices through a QR of ``A^T = Q R``: ``x = Q z`` with ``z`` the least-norm
    solution of the small system ``R^T z = rhs`` (rank-revealing ``lstsq``), since
    ``|x| = |z|``; the QR is made once (the same factor, so the same bits, as a QR per
    solve). (A direct ``lstsq`` on a wide matrix with millions of columns overflows LAPACK's
    workspace size.) Otherwise ``lstsq`` on ``A``.
    """
    if A.shape[1] > 4 * A.shape[0]:
        Q, R = np.linalg.qr(A.T)
        Rt = R.T

        def solve(rhs: np.ndarray) -> np.ndarray:
            return Q @ np.linalg.lstsq(Rt, rhs, rcond=None)[0]

        return solve

    def solve_direct(rhs: np.ndarray) -> np.ndarray:
        return np.linalg.lstsq(A, rhs, rcond=None)[0]

    return solve_direct


def least_norm(
    A: np.ndarray, b: np.ndarray, solve: Callable[[np.ndarray], np.ndarray] | None = None
) -> np.ndarray:
    """Minimum-norm solution of ``A x = b`` (A: shape (m, N)), with one refinement step.

    ``solve``: :func:`least_norm_solver` of ``A`` when the caller has made it (a loop of
    corrections on one matrix factors it once); else it is made here.
    """
    if solve is None:
        solve = least_norm_solver(A)
    x = solve(b)
    return x + solve(b - A @ x)


def solver_name(options: DesignOptions) -> str:
    """The solver option in upper case (``AUTO``, ``HIGHS`` or a cvxpy solver name)."""
    return options.solver.upper()
