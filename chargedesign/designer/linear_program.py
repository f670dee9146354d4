"""Linear programs by HiGHS through its own Python module, ``highspy``.

The same solver as ``scipy.optimize.linprog(method="highs")``, with the same options (dual
simplex, presolve) and the same check of the answer (bounds and constraints to
``10 sqrt(1e-9)``), without importing ``scipy.optimize``: that import (with the
``scipy.spatial`` it pulls in) cost the frontier command 0.2-0.35 s of CPU at its start,
for the few LPs it solves (docs/benchmarks.md, "Linear programs without scipy.optimize").
HiGHS in ``highspy`` is the release cvxpy installs; scipy bundles its own build, so a
degenerate LP may stop at another optimal vertex (the design's tests compare the answers).

:func:`linprog_highs` takes ``linprog``'s arguments and returns its status codes: 0 optimal,
1 iteration or time limit, 2 infeasible, 3 unbounded, 4 numerical trouble.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import highspy
import numpy as np
from highspy._core import _Highs
from scipy import sparse

# linprog's check of an "optimal" answer: bounds and rows to sqrt(tol) * 10, tol = 1e-9
_ANSWER_TOLERANCE = 10.0 * np.sqrt(1e-9)

_STATUS = {
    highspy.HighsModelStatus.kOptimal: 0,
    highspy.HighsModelStatus.kTimeLimit: 1,
    highspy.HighsModelStatus.kIterationLimit: 1,
    highspy.HighsModelStatus.kInfeasible: 2,
    highspy.HighsModelStatus.kModelError: 2,
    highspy.HighsModelStatus.kUnbounded: 3,
}


@dataclass(frozen=True)
class LinearProgramResult:
    """What the callers read of an LP: ``status`` (linprog's codes), ``x`` (None unless
    optimal), the equality rows' duals ``eq_duals`` (linprog's ``eqlin.marginals``) and
    HiGHS' message."""

    status: int
    x: np.ndarray | None
    eq_duals: np.ndarray | None
    message: str


def _bounds(bounds: Any, n: int) -> tuple[np.ndarray, np.ndarray]:
    """linprog's bounds (one pair for all, each side a number or an array per variable; a
    pair per variable; or an (n, 2) array; None is unbounded) as lower and upper arrays."""
    if isinstance(bounds, tuple) and len(bounds) == 2 and not isinstance(bounds[0], tuple):
        lo, hi = bounds
        lower = np.broadcast_to(-np.inf if lo is None else np.asarray(lo, dtype=float), (n,))
        upper = np.broadcast_to(np.inf if hi is None else np.asarray(hi, dtype=float), (n,))
        return lower.copy(), upper.copy()
    table = np.array(
        [[-np.inf if lo is None else lo, np.inf if hi is None else hi] for lo, hi in bounds],
        dtype=float,
    ).reshape(n, 2)
    return table[:, 0].copy(), table[:, 1].copy()


def _columns(A: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The matrix in compressed columns: starts, row indices and values."""
    if hasattr(A, "tocsc"):  # a scipy sparse matrix
        csc = A.tocsc()
        csc.sort_indices()
        return csc.indptr, csc.indices, csc.data
    dense = np.asarray(A, dtype=float)
    cols, rows = np.nonzero(dense.T)  # column-major order, rows ascending in each column
    starts = np.zeros(dense.shape[1] + 1, dtype=np.int64)
    np.cumsum(np.bincount(cols, minlength=dense.shape[1]), out=starts[1:])
    return starts, rows, dense.T[cols, rows]


def _stack(A_ub: Any, A_eq: Any, n: int) -> Any:
    """The inequality rows above the equality rows (dense, or sparse if either is)."""
    parts = [A for A in (A_ub, A_eq) if A is not None]
    if not parts:
        return np.zeros((0, n))
    if len(parts) == 1:
        return parts[0]
    if any(hasattr(A, "tocsc") for A in parts):
        return sparse.vstack([sparse.csc_array(A) for A in parts], format="csc")
    return np.vstack([np.asarray(A, dtype=float) for A in parts])


def linprog_highs(
    c: np.ndarray,
    A_ub: Any = None,
    b_ub: np.ndarray | None = None,
    A_eq: Any = None,
    b_eq: np.ndarray | None = None,
    bounds: Any = (0.0, None),
    options: dict[str, float] | None = None,
) -> LinearProgramResult:
    """``min c x`` with ``A_ub x <= b_ub``, ``A_eq x = b_eq`` and the bounds, by HiGHS."""
    cost = np.asarray(c, dtype=float)
    n = len(cost)
    upper_rows = np.zeros(0) if b_ub is None else np.asarray(b_ub, dtype=float)
    equal_rows = np.zeros(0) if b_eq is None else np.asarray(b_eq, dtype=float)
    lower, upper = _bounds(bounds, n)
    A = _stack(A_ub, A_eq, n)
    starts, rows, values = _columns(A)

    lp = highspy.HighsLp()
    lp.num_col_ = n
    lp.num_row_ = len(upper_rows) + len(equal_rows)
    lp.col_cost_ = cost
    lp.col_lower_ = lower
    lp.col_upper_ = upper
    lp.row_lower_ = np.concatenate([np.full(len(upper_rows), -np.inf), equal_rows])
    lp.row_upper_ = np.concatenate([upper_rows, equal_rows])
    lp.a_matrix_.format_ = highspy.MatrixFormat.kColwise
    lp.a_matrix_.num_col_ = n
    lp.a_matrix_.num_row_ = lp.num_row_
    lp.a_matrix_.start_ = starts
    lp.a_matrix_.index_ = rows
    lp.a_matrix_.value_ = values

    # the plain binding (highspy exports it as _Highs): the Python class `Highs` turns on its
    # callbacks, and its first construction prints HiGHS' banner on stdout before any option
    # can silence it, which would break a command's --json
    highs = _Highs()
    highs.setOptionValue("output_flag", False)
    highs.setOptionValue("presolve", "on")
    highs.setOptionValue("simplex_strategy", 1)  # dual simplex, as linprog asks
    for key, value in (options or {}).items():
        highs.setOptionValue(key, value)
    highs.passModel(lp)
    highs.run()
    model_status = highs.getModelStatus()
    message = highs.modelStatusToString(model_status)
    status = _STATUS.get(model_status, 4)
    if status != 0:
        return LinearProgramResult(status, None, None, message)
    solution = highs.getSolution()
    x = np.array(solution.col_value)
    duals = np.array(solution.row_dual)[len(upper_rows) :]
    row_values = np.array(solution.row_value)
    tol = _ANSWER_TOLERANCE
    answer_holds = (
        np.all(np.isfinite(x))
        and np.all((x >= lower - tol) & (x <= upper + tol))
        and np.all(row_values[: len(upper_rows)] <= upper_rows + tol)
        and np.all(np.abs(row_values[len(upper_rows) :] - equal_rows) <= tol)
    )
    if not answer_holds:
        return LinearProgramResult(
            4, None, None, f"{message}, but the answer misses its constraints by over {tol:.2g}"
        )
    return LinearProgramResult(0, x, duals, message)
