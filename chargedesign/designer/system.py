"""One source's system ``A w = b`` on the candidates, nondimensionalised, and its residual.

The conditions engine gives ``A w = b`` per source
(:meth:`chargedesign.moment_conditions.LinearConditions.system`); :func:`build_problem` adds the
design's
own rows (total charge, total mass) and equilibrates: each row is divided by its largest
entry and the unknowns by the scale of the scaled right-hand side (``w = scale * u``), so a
row scaled by ``a2 = 1e-9`` or by ``L^4`` for a 5 cm body is as accurate as a unit one.
:func:`relative_residual` is the backward error every stage is judged by. The physical
stages' programs scale their rows with :func:`row_scaled` and meet their equalities to
rounding with :func:`polish_equal`.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from chargedesign.designer.solvers import least_norm, least_norm_solver
from chargedesign.moment_conditions import LinearCondition, LinearConditions
from chargedesign.scene.design import DesignOptions

UNITS = {"charges": "C", "dipoles": "A m^2", "masses": "kg"}


def relative_residual(A: np.ndarray, w: np.ndarray, b: np.ndarray) -> float:
    """Largest relative residual of ``A w = b`` over the rows (a row-wise backward error).

    ``max_i |(A w - b)_i| / (|A_i|_S |w| + |b_i|)``, where ``|w|`` is the Euclidean norm of
    the weights and ``|A_i|_S`` that of row i restricted to the support (the columns with
    ``w_j != 0``); 0 for a row with zero denominator. By Cauchy-Schwarz ``|A_i w| <=
    |A_i|_S |w|``, so the ratio is the error relative to what the row can produce from these
    weights; it is invariant under row scaling and under a common scaling of ``w`` and ``b``,
    is ~1e-16 when the only error is rounding, and 1 when a row is not met at all. (The
    componentwise form ``sum_j |A_ij| |w_j|`` in the denominator is not used: rows whose
    exact terms all vanish, e.g. ``sum sigma_z = 0`` with every ``sigma_z = 0``, would turn
    rounding of the other rows into an O(1) ratio.)

    Parameters
    ----------
    A : ndarray, shape (m, N)
    w : ndarray, shape (N,)
    b : ndarray, shape (m,)
    """
    if A.shape[0] == 0:
        return 0.0
    support = w != 0
    numerator = np.abs(A @ w - b)
    row_norms = np.linalg.norm(A[:, support], axis=1)
    denominator = row_norms * float(np.linalg.norm(w)) + np.abs(b)
    ratio = np.divide(numerator, denominator, out=np.zeros_like(numerator), where=denominator > 0)
    return float(np.max(ratio))


@dataclass
class DesignProblem:
    """One source's system, nondimensionalised: ``A_s u = b_s`` with ``w = scale * u``."""

    source: str
    rows: list[LinearCondition]  # the conditions, then any extra rows (total charge / mass)
    labels: list[str]
    A: np.ndarray  # SI system, shape (m, N)
    b: np.ndarray
    A_s: np.ndarray  # row-equilibrated
    b_s: np.ndarray
    row_scale: np.ndarray
    scale: float  # w = scale * u
    group: int  # 1 (scalar weights) or 3 (dipole vectors)
    upper: float | None  # bound on |u| (charges) in scaled units
    nonneg: bool
    rank: int = 0
    cost: np.ndarray | None = None  # per-candidate cost of the robust objective

    def with_costs(self, cost: np.ndarray) -> DesignProblem:
        """This problem with per-candidate objective costs (robust objective)."""
        return replace(self, cost=np.asarray(cost, dtype=float))

    @property
    def n_candidates(self) -> int:
        return self.A.shape[1] // self.group


def condition_label(row: LinearCondition) -> str:
    """A short name for a condition: its moment key, or its combination of keys."""
    if len(row.coefficients) == 1:
        return next(iter(row.coefficients))
    terms = [f"{coef:+g} {key}" for key, coef in row.coefficients.items()]
    text = " ".join(terms[:4]) + (" ..." if len(terms) > 4 else "")
    return text.lstrip("+")


def _equilibrate(A: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
    """Row equilibration and the unknowns' scale: ``(A_s, b_s, row_scale, scale)``.

    Each row of ``A`` (shape (m, N)) is divided by its largest entry (zero rows are kept),
    the unknowns by the largest scaled right-hand side (1 when it is zero), so that
    ``A_s u = b_s`` with ``w = scale * u``.
    """
    largest = np.max(np.abs(A), axis=1) if A.shape[1] else np.zeros(len(b))
    row_scale = np.where(largest > 0, 1.0 / np.where(largest > 0, largest, 1.0), 1.0)
    b_row = b * row_scale
    scale = float(np.max(np.abs(b_row))) if len(b_row) else 0.0
    if scale == 0.0:
        scale = 1.0
    return A * row_scale[:, None], b_row / scale, row_scale, scale


def build_problem(
    source: str,
    conditions: LinearConditions,
    points: np.ndarray,
    options: DesignOptions,
) -> DesignProblem:
    """One source's nondimensionalised problem: its conditions at the candidate points."""
    rows = list(conditions.for_source(source))
    A, b = conditions.system(source, points)
    labels = [condition_label(r) for r in rows]
    group = 3 if source == "dipoles" else 1
    extra_rows: list[tuple[np.ndarray, float, str, str]] = []
    if source == "charges" and options.total_charge is not None:
        extra_rows.append((np.ones(A.shape[1]), options.total_charge, "total", "total charge"))
    if source == "masses" and options.total_mass is not None:
        extra_rows.append((np.ones(A.shape[1]), options.total_mass, "total", "total mass"))
    for vec, value, key, prov in extra_rows:
        A = np.vstack([A, vec])
        b = np.append(b, value)
        labels.append(key)
        rows.append(LinearCondition(source, {"": 1.0}, value, f"design: {prov}"))
    A_s, b_s, row_scale, scale = _equilibrate(A, b)
    upper = options.max_charge / scale if source == "charges" and options.max_charge else None
    return DesignProblem(
        source=source,
        rows=rows,
        labels=labels,
        A=A,
        b=b,
        A_s=A_s,
        b_s=b_s,
        row_scale=row_scale,
        scale=scale,
        group=group,
        upper=upper,
        nonneg=source == "masses",
    )


def drop_last_row(p: DesignProblem) -> DesignProblem:
    """The problem without its last row (the design's total mass), equilibrated anew."""
    A, b = p.A[:-1], p.b[:-1]
    A_s, b_s, row_scale, scale = _equilibrate(A, b)
    return replace(
        p,
        rows=p.rows[:-1],
        labels=p.labels[:-1],
        A=A,
        b=b,
        A_s=A_s,
        b_s=b_s,
        row_scale=row_scale,
        scale=scale,
    )


def restrict_problem(p: DesignProblem, support: np.ndarray) -> DesignProblem:
    """The problem restricted to the candidate columns in ``support``."""
    cost = None if p.cost is None else p.cost[support]
    return replace(p, A=p.A[:, support], A_s=p.A_s[:, support], cost=cost)


def natural_row_size(row: LinearCondition, size: float) -> float:
    """What a row gives for unit weight at distance ``size`` (its nondimensional scale)."""
    total = 0.0
    for key, coef in row.coefficients.items():
        letters = key.split(":", 1)[1] if ":" in key else key
        total += abs(coef) * size ** len(letters)
    return total


def group_norms(u: np.ndarray) -> np.ndarray:
    """Euclidean norms of consecutive groups of three weights (one per dipole)."""
    return np.linalg.norm(u.reshape(-1, 3), axis=1)


def row_scaled(A: np.ndarray, b: np.ndarray, col_scale: float) -> tuple[np.ndarray, np.ndarray]:
    """Rows divided by their largest entry (columns in units of ``col_scale``)."""
    As = A * col_scale
    top = np.max(np.abs(As), axis=1) if As.shape[1] else np.ones(len(b))
    top = np.where(top > 0, top, 1.0)
    return As / top[:, None], b / top


def polish_equal(A: np.ndarray, b: np.ndarray, w: np.ndarray, cols: np.ndarray) -> np.ndarray:
    """Least-norm correction of ``w`` on ``cols`` so that ``A w = b`` to rounding."""
    out = w.copy()
    if len(cols) == 0:
        return out
    top = np.max(np.abs(A[:, cols]), axis=1)
    top = np.where(top > 0, top, 1.0)
    As = A[:, cols] / top[:, None]
    solve = least_norm_solver(As)  # one factor for the three corrections
    for _ in range(3):
        out[cols] += least_norm(As, (b - A @ out) / top, solve)
    return out
