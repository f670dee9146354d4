"""Design problems: weights on candidate points that meet the linear moment conditions.

For each source (charges, dipoles, masses) the conditions engine gives ``A w = b``
(:meth:`chargedesign.conditions.LinearConditions.system`); this module chooses ``w`` on the
candidate points by a convex objective, then polishes it to machine precision:

- charges (free sign, optional ``|q| <= max_charge``, optional total charge, optional number
  of charges): ``l1`` (minimum ``sum |q|``, sparse layouts), ``l2`` (minimum ``sum q^2``,
  smooth), ``linf`` (minimum ``max |q|``);
- dipoles (free vectors): ``l1`` is the group-sparse ``sum |sigma_j|`` (second-order cone),
  ``l2`` the minimum ``sum |sigma_j|^2``, ``linf`` the minimum ``max |sigma_j|``;
- masses (``m >= 0``, optional total mass): ``l1`` minimum total mass (or, with the total
  given, a sparse vertex of the feasible set), ``l2`` minimum ``sum m^2``, ``linf`` minimum
  ``max m``.

The conditions never couple two sources, so the joint problem is the sum of independent
per-source problems and is solved source by source (exactly the same optimum).

Numerics (see docs/design.md):

- every problem is nondimensionalised: each row of ``A`` is divided by its largest entry
  (row equilibration: a row scaled by ``a2 = 1e-9`` or by ``L^4`` for a 5 cm body is as
  accurate as a unit one) and the unknowns by the scale of the scaled right-hand side;
- linear programs (l1, linf, masses) go to HiGHS; on large candidate sets the l1 and mass
  problems (and the group-sparse dipole problem) are solved by column generation: a small
  problem on a working set, all columns priced with its duals, violators added, until none
  is left, which proves optimality for the full set;
- cones and quadratics go to Clarabel through cvxpy with tolerances tightened to 1e-12;
  unconstrained least-norm problems have a closed form (``lstsq``);
- every solver status is checked; residuals are computed here, never taken on trust;
- polishing fixes the support (non-zero weights) and applies the least-norm correction on
  it (``lstsq``, with one refinement step; masses that would turn negative are re-solved by
  NNLS on the support), so the relative residual (defined in :func:`relative_residual`)
  reaches ~1e-16.
"""

from __future__ import annotations

import math
import time
import warnings
from collections.abc import Callable, Mapping, Sequence
from dataclasses import asdict, dataclass, field, replace
from typing import Any

import numpy as np

from chargedesign.body import Design
from chargedesign.candidates import CandidateSet, Geometry, candidates_from_points
from chargedesign.conditions import (
    DEFAULT_STRENGTH_HEADROOM,
    REALISABLE,
    SOURCES,
    LinearCondition,
    LinearConditions,
)
from chargedesign.errors import InfeasibleError, InputError, SolverError
from chargedesign.params import Parameters
from chargedesign.validation import as_finite_float, input_error

OBJECTIVES = ("l1", "l2", "linf")
SPARSITY_METHODS = ("auto", "reweighted", "mip")
UNITS = {"charges": "C", "dipoles": "A m^2", "masses": "kg"}
#: relative residual a polished design must reach (default ``tol`` with polishing)
POLISHED_TOL = 1e-13
#: relative residual accepted from a solver alone (default ``tol`` without polishing)
RAW_TOL = 1e-7
#: column generation is used for l1 / mass / group-sparse problems above this many candidates
CG_MIN_CANDIDATES = 2000
#: Clarabel's tolerances (its defaults, 1e-8, bound the objective rather than the rows)
CLARABEL_SETTINGS = {"tol_gap_abs": 1e-12, "tol_gap_rel": 1e-12, "tol_feas": 1e-12}
#: HiGHS tolerances for the linear programs
HIGHS_OPTIONS = {"primal_feasibility_tolerance": 1e-10, "dual_feasibility_tolerance": 1e-10}
#: a direction of the nondimensional condition matrix with singular value below this
#: fraction of the largest is treated as absent (exact degeneracy up to rounding)
RANK_RTOL = 1e-10
#: weights amplified beyond this factor (relative to a round body) are refused as infeasible
AMPLIFICATION_LIMIT = 1e8
#: ... and beyond this one reported in the notes
AMPLIFICATION_NOTE = 1e3
#: estimated relative forward error (mu, V and their torques evaluated in floating point from
#: the elements) above which a design says its conditions are met only by cancellation (a
#: tenth of the forward check's default tolerance, chargedesign.check.DEFAULT_TOL) ...
FORWARD_NOTE = 1e-10
#: ... and above which it is refused: the body would realise its targets to 1e-4 at best
#: (contributions ~1e12 times the quantity; nothing reliable is left)
FORWARD_LIMIT = 1e-4
#: letters of the Legendre coefficients in messages (fields.electric e4)
_FIELD_LETTER = {"magnetic": "f", "electric": "e", "gravity": "g"}
FIELD_KINDS = ("magnetic", "electric", "gravity")
#: candidates above which the mixed-integer fallback for ``n_charges`` is not attempted
MIP_MAX_CANDIDATES = 5000
#: supports tried by polishing: weights below these fractions of the largest are dropped
POLISH_THRESHOLDS = (1e-6, 1e-9, 1e-12, 0.0)

Progress = Callable[[str], None]


# ============================================================================ options
@dataclass(frozen=True)
class DesignOptions:
    """What to optimise and how.

    Parameters
    ----------
    objective : {"l1", "l2", "linf"}
        Objective for every source (see the module doc); ``objectives`` overrides per source.
    solver : str
        ``"auto"`` (HiGHS for linear programs, Clarabel for cones and quadratics, closed form
        for unconstrained least norm) or a cvxpy solver name (``"CLARABEL"``, ``"HIGHS"``,
        ``"SCS"``, ...), which then solves the full problem through cvxpy.
    max_charge : float, optional
        Bound on every ``|q|``, C.
    total_charge : float, optional
        Required total charge, C.
    n_charges : int, optional
        At most this many charges (reweighted l1, then mixed integer with HiGHS).
    total_mass : float, optional
        Required total mass, kg.
    realise : tuple of str, optional
        What the design claims (default: what the conditions realise).
    polish : bool
        Polish to machine precision on the support.
    tol : float, optional
        Largest accepted relative residual (default 1e-13 polished, 1e-7 unpolished).
    objectives : mapping, optional
        Per-source objective, e.g. ``{"masses": "l2"}``.
    column_generation : bool, optional
        Force column generation on or off (default: on above 2000 candidates, for HiGHS).
    sparsity : {"auto", "reweighted", "mip"}
        How ``n_charges`` is met: reweighted l1 only, mixed integer only, or reweighted l1
        then mixed integer (auto).
    time_limit : float
        Seconds allowed to the mixed-integer solver.
    """

    objective: str = "l1"
    solver: str = "auto"
    max_charge: float | None = None
    total_charge: float | None = None
    n_charges: int | None = None
    total_mass: float | None = None
    realise: tuple[str, ...] | None = None
    polish: bool = True
    tol: float | None = None
    objectives: Mapping[str, str] | None = None
    column_generation: bool | None = None
    sparsity: str = "auto"
    time_limit: float = 60.0

    def __post_init__(self) -> None:
        _check_objective(self.objective, "design.objective")
        if self.objectives is not None:
            if not isinstance(self.objectives, Mapping):
                raise input_error(
                    "design.objectives", "a table source -> objective", self.objectives
                )
            for source, value in self.objectives.items():
                if source not in SOURCES:
                    raise input_error(
                        f"design.objectives.{source}", "one of " + ", ".join(SOURCES), source
                    )
                _check_objective(value, f"design.objectives.{source}")
            object.__setattr__(self, "objectives", dict(self.objectives))
        if not isinstance(self.solver, str) or not self.solver:
            raise input_error(
                "design.solver", "a solver name such as 'auto' or 'CLARABEL'", self.solver
            )
        for name in ("max_charge", "total_mass"):
            value = getattr(self, name)
            if value is not None:
                object.__setattr__(
                    self, name, as_finite_float(value, f"design.{name}", positive=True)
                )
        if self.total_charge is not None:
            object.__setattr__(
                self, "total_charge", as_finite_float(self.total_charge, "design.total_charge")
            )
        if self.n_charges is not None and (
            isinstance(self.n_charges, bool)
            or not isinstance(self.n_charges, (int, np.integer))
            or self.n_charges < 1
        ):
            raise input_error("design.n_charges", "an integer >= 1", self.n_charges)
        if self.realise is not None:
            object.__setattr__(self, "realise", _realise_list(self.realise))
        if not isinstance(self.polish, bool):
            raise input_error("design.polish", "true or false", self.polish)
        if self.tol is not None:
            tol = as_finite_float(self.tol, "design.tol", positive=True)
            if tol >= 1.0:
                raise input_error("design.tol", "a relative residual below 1", self.tol)
            object.__setattr__(self, "tol", tol)
        if self.column_generation is not None and not isinstance(self.column_generation, bool):
            raise input_error("design.column_generation", "true or false", self.column_generation)
        if self.sparsity not in SPARSITY_METHODS:
            raise input_error(
                "design.sparsity", "one of " + ", ".join(SPARSITY_METHODS), self.sparsity
            )
        object.__setattr__(
            self, "time_limit", as_finite_float(self.time_limit, "design.time_limit", positive=True)
        )

    @property
    def tolerance(self) -> float:
        """The residual a delivered design must reach."""
        if self.tol is not None:
            return self.tol
        return POLISHED_TOL if self.polish else RAW_TOL

    def objective_for(self, source: str) -> str:
        if self.objectives and source in self.objectives:
            return self.objectives[source]
        return self.objective

    @classmethod
    def from_table(cls, table: Mapping[str, Any], **overrides: Any) -> DesignOptions:
        """Options from a scene's ``[design]`` table (keys in docs/design.md), then overrides."""
        if not isinstance(table, Mapping):
            raise input_error("design", "a table", table)
        known = {f for f in cls.__dataclass_fields__}
        unknown = sorted(set(table) - known)
        if unknown:
            raise input_error(
                f"design.{unknown[0]}", "one of " + ", ".join(sorted(known)), unknown[0]
            )
        kwargs = dict(table)
        if "realise" in kwargs:
            kwargs["realise"] = _realise_list(kwargs["realise"])
        if "n_charges" in kwargs and isinstance(kwargs["n_charges"], float):
            raise input_error("design.n_charges", "an integer >= 1", kwargs["n_charges"])
        kwargs.update({k: v for k, v in overrides.items() if v is not None})
        return cls(**kwargs)

    def to_dict(self) -> dict[str, Any]:
        out = asdict(self)
        out["realise"] = list(self.realise) if self.realise is not None else None
        out["tolerance"] = self.tolerance
        return out


def _check_objective(value: Any, name: str) -> None:
    if value not in OBJECTIVES:
        raise input_error(name, "one of " + ", ".join(OBJECTIVES), value)


def _realise_list(value: Any) -> tuple[str, ...]:
    """``design.realise``: a list of distinct items among mu, V, inertia (errors name it)."""
    expected = "a list of " + ", ".join(REALISABLE)
    if isinstance(value, str) or not isinstance(value, (list, tuple)):
        raise input_error("design.realise", expected, value)
    for item in value:
        if item not in REALISABLE:
            raise input_error("design.realise", "items among " + ", ".join(REALISABLE), item)
    if len(set(value)) != len(value):
        raise input_error("design.realise", "no repeated items", list(value))
    return tuple(value)


# ============================================================================ results
@dataclass
class SourceResult:
    """Outcome of one source's design problem (SI units).

    ``residual_before`` / ``residual_after``: :func:`relative_residual` of the solver's
    weights and of the delivered (polished) weights. ``forward``: the worst
    :class:`Cancellation` of the delivered weights (None when not assessed).
    """

    source: str
    objective: str
    objective_value: float
    objective_value_raw: float
    units: str
    solver: str
    method: str
    status: str
    n_conditions: int
    rank: int
    n_candidates: int
    n_elements: int
    residual_before: float
    residual_after: float
    seconds: float
    notes: list[str] = field(default_factory=list)
    forward: Cancellation | None = None

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)


@dataclass
class DesignResult:
    """A designed body and how it was obtained.

    Attributes
    ----------
    design : Design
        The body, with provenance in ``design.extra`` (see docs/design.md).
    sources : dict[str, SourceResult]
    candidates : CandidateSet
    options : DesignOptions
    conditions : LinearConditions
    timings : dict[str, float]
        Seconds per stage.
    notes : list of str
    status : str
        ``"optimal"`` (every problem solved and verified).
    """

    design: Design
    sources: dict[str, SourceResult]
    candidates: CandidateSet
    options: DesignOptions
    conditions: LinearConditions
    timings: dict[str, float] = field(default_factory=dict)
    notes: list[str] = field(default_factory=list)
    status: str = "optimal"

    @property
    def residual_before(self) -> float:
        """Largest relative residual of the solvers' weights over the sources."""
        return max((s.residual_before for s in self.sources.values()), default=0.0)

    @property
    def residual_after(self) -> float:
        """Largest relative residual of the delivered weights over the sources."""
        return max((s.residual_after for s in self.sources.values()), default=0.0)

    def summary(self) -> dict[str, Any]:
        """A JSON-ready summary (residuals first)."""
        d = self.design
        return {
            "status": self.status,
            "residuals": {
                "before_polish": {k: s.residual_before for k, s in self.sources.items()},
                "after_polish": {k: s.residual_after for k, s in self.sources.items()},
                "max_after_polish": self.residual_after,
                "tolerance": self.options.tolerance,
            },
            "counts": {
                "candidates": len(self.candidates),
                "charges": len(d.charge_values),
                "dipoles": len(d.dipole_moments),
                "masses": len(d.mass_values),
            },
            "objective": {
                k: {"kind": s.objective, "value": s.objective_value, "units": s.units}
                for k, s in self.sources.items()
            },
            "solver": {k: s.solver for k, s in self.sources.items()},
            "realises": list(d.realises),
            "timings": dict(self.timings),
            "notes": list(self.notes),
        }


# ============================================================================ residuals
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


# ============================================================================ the problem
@dataclass
class _Problem:
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


def _short(text: str, limit: int = 160) -> str:
    first = text.split("; ")[0]
    return first if len(first) <= limit else first[: limit - 3] + "..."


def _build(
    source: str,
    conditions: LinearConditions,
    points: np.ndarray,
    options: DesignOptions,
) -> _Problem:
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
    largest = np.max(np.abs(A), axis=1) if A.shape[1] else np.zeros(len(b))
    row_scale = np.where(largest > 0, 1.0 / np.where(largest > 0, largest, 1.0), 1.0)
    A_s = A * row_scale[:, None]
    b_row = b * row_scale
    scale = float(np.max(np.abs(b_row))) if len(b_row) else 0.0
    if scale == 0.0:
        scale = 1.0
    upper = options.max_charge / scale if source == "charges" and options.max_charge else None
    return _Problem(
        source=source,
        rows=rows,
        labels=labels,
        A=A,
        b=b,
        A_s=A_s,
        b_s=b_row / scale,
        row_scale=row_scale,
        scale=scale,
        group=group,
        upper=upper,
        nonneg=source == "masses",
    )


# ============================================================================ diagnostics
def _natural_row_size(row: LinearCondition, size: float) -> float:
    """What a row gives for unit weight at distance ``size`` (its nondimensional scale)."""
    total = 0.0
    for key, coef in row.coefficients.items():
        letters = key.split(":", 1)[1] if ":" in key else key
        total += abs(coef) * size ** len(letters)
    return total


def diagnose(problem: _Problem, geometry: Geometry) -> tuple[int, list[str]]:
    """Check that ``A w = b`` can be met on the candidates; name what cannot.

    The system is nondimensionalised by what each row gives for unit weight at the body's
    size; directions with singular value below ``RANK_RTOL`` of the largest are absent. A
    right-hand side with a component along an absent direction is infeasible; one that
    needs weights amplified by more than ``AMPLIFICATION_LIMIT`` (a nearly planar or
    degenerate set) is refused as well.

    Returns
    -------
    rank : int
    notes : list of str
        Warnings (ill-conditioning).

    Raises
    ------
    InfeasibleError
        Naming the conditions that cannot be produced, and why.
    """
    source = problem.source
    notes: list[str] = []
    m = len(problem.b)
    if m == 0:
        return 0, notes
    # conditions whose coefficients vanish (e.g. a1 = 0 in a mu condition) but ask for a value
    for i, row in enumerate(problem.rows):
        if all(c == 0 for c in row.coefficients.values()) and row.value != 0:
            raise InfeasibleError(
                f"{source}: condition '{problem.labels[i]}' ({_short(row.provenance)}) asks "
                f"for {row.value:.6g} but all its coefficients are zero: no body meets it"
            )
    size = geometry.size if geometry.size > 0 else 1.0
    natural = np.array([_natural_row_size(r, size) for r in problem.rows])
    natural = np.where(natural > 0, natural, 1.0)
    A_nd = problem.A / natural[:, None]
    b_nd = problem.b / natural
    # SVD through a QR of the tall transpose: A_nd^T = Q R, so A_nd = R^T Q^T and the left
    # singular vectors and values are those of the small (m, m) matrix R^T (several times
    # faster than a direct SVD of a wide matrix with 10^5 columns)
    if A_nd.shape[1] > A_nd.shape[0]:
        R = np.asarray(np.linalg.qr(A_nd.T, mode="r"))
        U, s, _ = np.linalg.svd(R.T)
    else:
        U, s, _ = np.linalg.svd(A_nd, full_matrices=False)
    top = float(s[0]) if len(s) and s[0] > 0 else 0.0
    rank = int(np.sum(s > RANK_RTOL * top)) if top > 0 else 0
    coeffs = U.T @ b_nd
    b_norm = float(np.linalg.norm(b_nd))
    if b_norm == 0.0:
        return rank, notes
    # the left null space: every direction of R^m not spanned by the retained ones
    null_part = b_nd - U[:, :rank] @ coeffs[:rank]
    if float(np.linalg.norm(null_part)) > 1e-8 * b_norm:
        raise InfeasibleError(_cannot_produce(problem, null_part, geometry, exact=True))
    natural_weight = b_norm / top
    worst = 0.0
    worst_dir = None
    for i in range(rank):
        amp = abs(coeffs[i]) / s[i] / natural_weight
        if amp > worst:
            worst, worst_dir = amp, U[:, i]
    if worst > AMPLIFICATION_LIMIT and worst_dir is not None:
        raise InfeasibleError(
            _cannot_produce(problem, worst_dir, geometry, exact=False, amplification=worst)
        )
    if worst > AMPLIFICATION_NOTE and worst_dir is not None:
        involved = _involved(worst_dir)
        names = ", ".join(f"'{problem.labels[i]}'" for i in involved)
        verb = f"conditions {names} are" if len(involved) > 1 else f"condition {names} is"
        notes.append(
            f"{source}: {verb} weakly produced by these candidates: weights "
            f"about {worst:.2g} times larger than a round body of this size needs"
            + (
                f" ({geometry.plane_text()} is nearly all of it)"
                if geometry.thickness_ratio < 1e-2
                else ""
            )
        )
    return rank, notes


# ============================================================================ forward accuracy
@dataclass(frozen=True)
class Cancellation:
    """How far one source's contributions to one quantity cancel (forward accuracy).

    Attributes
    ----------
    source : str
        ``charges``, ``dipoles`` or ``masses``.
    quantity : str
        ``mu`` or ``V``.
    kind : str
        The field the contributions go through: ``magnetic``, ``electric`` or ``gravity``.
    term : str
        The field term the contributions go through: ``a1``, ``a2``, ``fields.magnetic f3``,
        ``fields.electric e4``, ``fields.gravity g1``.
    degree : int
        The term's degree k (``Phi = sum f_k R^k P_k``).
    coefficient : float
        The term's Legendre coefficient f_k (SI units of its field).
    amplification : float
        The sum over the elements of the size of their contributions through the term,
        divided by the size of the quantity (``max |mu|``, or the spread of ``V``, over the
        orientations): 1 for elements that all pull the same way, huge when the quantity is
        met only by cancellation of much larger contributions.
    forward_error : float
        Estimated relative error of the quantity evaluated in floating point from these
        elements (any route: the forward check, the simulation), and of the elements
        themselves as stored: ``eps * amplification * c``, with ``c`` the sum of the absolute
        coefficients of ``P_k`` (the cancellation inside the Cartesian harmonic), times k for
        V (its torque is a derivative).
    largest_weight : float
        Largest ``|q|``, ``|sigma|`` or ``m`` of the source (C, A m^2, kg).
    """

    source: str
    quantity: str
    kind: str
    term: str
    degree: int
    coefficient: float
    amplification: float
    forward_error: float
    largest_weight: float

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)


def _legendre_abs_sum(k: int) -> float:
    """Sum of the absolute power-basis coefficients of ``P_k`` (1, 1, 2, 4, 8.5, ...)."""
    from numpy.polynomial import legendre

    unit = np.zeros(k + 1)
    unit[k] = 1.0
    return float(np.sum(np.abs(legendre.leg2poly(unit))))


def _term_name(kind: str, k: int) -> str:
    """``a1``, ``a2`` (the paper's magnetic coefficients), else ``fields.<kind> <letter>k``."""
    if kind == "magnetic" and k in (1, 2):
        return f"a{k}"
    return f"fields.{kind} {_FIELD_LETTER[kind]}{k}"


def _term_value(kind: str, k: int, coefficient: float) -> str:
    """The term's value as the user writes it (a2 = f2 / 2), with units."""
    if kind == "magnetic" and k == 1:
        return f"a1 = {coefficient:.3g} T"
    if kind == "magnetic" and k == 2:
        return f"a2 = {coefficient / 2:.3g} T/m"
    units = {"magnetic": f"T m^{1 - k}", "electric": f"V m^-{k}", "gravity": f"J/kg m^-{k}"}
    return f"{_term_name(kind, k)} = {coefficient:.3g} {units[kind]}"


#: the field each source feels in each quantity, and how its contributions scale with r:
#: (quantity, field kind, factor(k), power of r(k))
_CONTRIBUTIONS: dict[str, list[tuple[str, str, Callable[[int], int], Callable[[int], int]]]] = {
    # mu = -sum q (r . B) r, r . B_k = -k f_k R^k P_k: |contribution| <= k |f_k| |q| r^(k+1)
    "charges": [
        ("mu", "magnetic", lambda k: k, lambda k: k + 1),
        ("V", "electric", lambda k: 1, lambda k: k),
    ],
    # -sigma . B_k, |B_k| <= k |f_k| r^(k-1)
    "dipoles": [("V", "magnetic", lambda k: k, lambda k: k - 1)],
    "masses": [("V", "gravity", lambda k: 1, lambda k: k)],
}


def quantity_scales(params: Parameters, n_orientations: int = 256) -> dict[str, float]:
    """Sizes of the theorem's mu (``max |mu|``) and V (``max |V - mean V|``) over orientations.

    The forward check compares with the same sizes (chargedesign.check). Evaluated on a
    Fibonacci set of ``n_orientations`` (even: no orientation on gamma3 = 0).
    """
    from chargedesign.candidates import fibonacci_sphere
    from chargedesign.model import evaluators

    gammas = fibonacci_sphere(2 * (n_orientations // 2))
    mu = np.asarray(evaluators.gyroscopic(gammas, params))
    V = np.asarray(evaluators.potential(gammas, params))
    return {
        "mu": float(np.max(np.linalg.norm(mu, axis=1))),
        "V": float(np.max(np.abs(V - V.mean()))),
    }


def source_cancellations(
    source: str,
    positions: np.ndarray,
    weights: np.ndarray,
    fields: Mapping[str, Sequence[float]],
    scales: Mapping[str, float],
    realise: Sequence[str],
) -> list[Cancellation]:
    """The :class:`Cancellation` of one source in every field term it feels.

    Parameters
    ----------
    source : str
    positions : ndarray, shape (n, 3)
        Element positions, m.
    weights : ndarray, shape (n,) or (n, 3)
        Charges (C), masses (kg) or dipole moments (A m^2).
    fields : mapping
        Legendre coefficients per field kind.
    scales : mapping
        Sizes of ``mu`` and ``V`` (:func:`quantity_scales`); a quantity of size 0 is skipped.
    realise : sequence of str
        The quantities the design claims (others are not assessed).
    """
    pts = np.asarray(positions, dtype=float)
    w = np.asarray(weights, dtype=float)
    mags = np.linalg.norm(w, axis=1) if w.ndim == 2 else np.abs(w)
    keep = mags > 0
    if not np.any(keep):
        return []
    mags = mags[keep]
    radii = np.linalg.norm(pts[keep], axis=1)
    largest = float(np.max(mags))
    out = []
    for quantity, kind, factor, power in _CONTRIBUTIONS[source]:
        scale = scales.get(quantity, 0.0)
        if quantity not in realise or not scale > 0:
            continue
        for k, coefficient in enumerate(fields.get(kind, ()), start=1):
            if coefficient == 0:
                continue
            gross = factor(k) * abs(coefficient) * float(np.sum(mags * radii ** power(k)))
            amplification = gross / scale
            evaluation = _legendre_abs_sum(k) * (k if quantity == "V" else 1)
            out.append(
                Cancellation(
                    source=source,
                    quantity=quantity,
                    kind=kind,
                    term=_term_name(kind, k),
                    degree=k,
                    coefficient=float(coefficient),
                    amplification=amplification,
                    forward_error=float(np.finfo(float).eps) * amplification * evaluation,
                    largest_weight=largest,
                )
            )
    return out


def forward_accuracy(design: Design) -> list[Cancellation]:
    """How far a design's contributions to mu and V cancel, per source and field term.

    The elements of a design meet its conditions to ``design.tol`` (a backward error), but a
    quantity that is the small sum of much larger contributions (e.g. charges forced large by
    a weak a1 that must still leave small fourth moments) is only as accurate as
    ``eps`` times that ratio, in any floating-point evaluation. Sorted worst first.
    """
    params = design.parameters
    if params.singular:
        return []  # the theorem's mu and V are not designed for lambda, rho != 0
    scales = quantity_scales(params)
    fields = {kind: design.field(kind) for kind in ("magnetic", "electric", "gravity")}
    blocks = {
        "charges": (design.charge_positions, design.charge_values),
        "dipoles": (design.dipole_positions, design.dipole_moments),
        "masses": (design.mass_positions, design.mass_values),
    }
    out = []
    for source, (positions, weights) in blocks.items():
        out.extend(
            source_cancellations(source, positions, weights, fields, scales, design.realises)
        )
    return sorted(out, key=lambda c: -c.forward_error)


def _row_term(source: str, row: LinearCondition) -> tuple[str, int] | None:
    """The field term (kind, degree) a condition's target was divided by, if any."""
    keys = [k for k in row.coefficients if k]
    if not keys:
        return None
    order = len(keys[0].split(":")[-1])
    text = row.provenance
    if text.startswith("V degree "):
        degree = int(text.split()[2].rstrip(":"))
        return ({"charges": "electric", "dipoles": "magnetic", "masses": "gravity"}[source], degree)
    if source == "charges" and text.startswith("mu"):
        return ("magnetic", order - 1)
    if source == "dipoles":
        return ("magnetic", order + 1)
    if source == "masses" and text.startswith("inertia"):
        return ("inertia", order)
    return None


def _describe_cancellation(
    worst: Cancellation,
    problem: _Problem,
    geometry: Geometry,
    conditions: LinearConditions,
) -> str:
    """What cancels, how much, what sizes the weights, and the remedy (one line, no source).

    The weights are sized by the condition that needs the largest weight from a round body
    of this size (target over what unit weights at distance L give); its field term is the
    driver: strengthening it shrinks every weight, hence the cancellation, in proportion.
    """
    fields = conditions.fields
    origin = conditions.field_origin
    size = geometry.size if geometry.size > 0 else 1.0
    natural = np.array([_natural_row_size(r, size) for r in problem.rows])
    need = np.abs(problem.b) / np.where(natural > 0, natural, np.inf)
    driver_text = ""
    driver = None
    if len(need) and float(np.max(need)) > 0:
        i = int(np.argmax(need))
        driver = _row_term(problem.source, problem.rows[i])
        driver_text = f", sized by condition '{problem.labels[i]}' = {problem.b[i]:.3g}"
        if driver is not None and driver[0] in fields:
            kind, k = driver
            coeffs = fields[kind]
            if 1 <= k <= len(coeffs) and coeffs[k - 1] != 0:
                driver_text += f" through {_term_value(kind, k, coeffs[k - 1])}"
    factor = worst.forward_error / FORWARD_NOTE
    remedy = "its targets differ in scale by this factor"
    involved = [(worst.kind, worst.degree)] + ([driver] if driver is not None else [])
    defaults = [
        _term_name(kind, k)
        for kind, k in involved
        if kind in _FIELD_LETTER
        and f"{kind} {_FIELD_LETTER[kind]}{k}" in conditions.default_strengths
    ]
    if defaults and conditions.length_assumed:
        remedy = (
            f"{defaults[0]} was chosen by default for an assumed 1 m body: derive the "
            f"conditions with length={size:.3g} (the candidates' size)"
        )
    elif (
        worst.kind == "electric"
        and origin.get("electric") == "given"
        and driver != ("electric", worst.degree)
        and worst.amplification > 0
    ):
        # the given strength is too large for these weights: the conditions' own rule
        suggested = 10.0 ** round(
            math.log10(abs(worst.coefficient) * DEFAULT_STRENGTH_HEADROOM / worst.amplification)
        )
        remedy = (
            f"choose {worst.term} ~ {suggested:.0e} V m^-{worst.degree} (or omit "
            "[fields.electric]: the conditions then choose it for the body)"
        )
    elif driver is not None and driver[0] in FIELD_KINDS:
        remedy = f"increase {_term_name(*driver)} at least {factor:.2g}-fold"
    elif driver is not None and driver[0] == "inertia":
        remedy = f"weaken {worst.term} or use a larger body (masses scale like C / L^2)"
    return (
        f"{worst.quantity} is met only by cancellation: the {problem.source}' contributions "
        f"through {worst.term} are {worst.amplification:.2g} times |{worst.quantity}| "
        f"(largest {worst.largest_weight:.3g} {UNITS[problem.source]}{driver_text}); forward "
        f"accuracy ~{worst.forward_error:.1g}: {remedy}"
    )


def _length_notes(conditions: LinearConditions, size: float) -> list[str]:
    """A note when the default strengths were chosen for 1 m and these candidates differ."""
    if not conditions.length_assumed or not size > 0:
        return []
    suited = conditions.for_length(size).default_strengths
    if suited == conditions.default_strengths:
        return []
    changes = ", ".join(
        f"{name} = {conditions.default_strengths.get(name, 0.0):g} (for 1 m) would be {value:g}"
        for name, value in suited.items()
    )
    return [
        "conditions: the default field strengths were chosen for an assumed body length of "
        f"1 m; for these candidates (L = {size:.6g} m) {changes}: derive the conditions with "
        f"length={size:.6g} (design_from_scene does)"
    ]


@dataclass
class _Forward:
    """What the forward-accuracy assessment of one design needs (built by design_body)."""

    conditions: LinearConditions
    scales: dict[str, float]
    realise: tuple[str, ...]
    geometry: Geometry
    points: np.ndarray

    @classmethod
    def build(
        cls,
        params: Parameters,
        conditions: LinearConditions,
        candidates: CandidateSet,
        realise: Sequence[str],
    ) -> _Forward | None:
        if params.singular or not ({"mu", "V"} & set(realise)):
            return None
        return cls(
            conditions=conditions,
            scales=quantity_scales(params),
            realise=tuple(realise),
            geometry=candidates.geometry,
            points=candidates.points,
        )

    def assess(self, p: _Problem, weights: np.ndarray) -> tuple[Cancellation | None, str]:
        """The worst term of one source's weights on the candidates, and (when it exceeds
        ``FORWARD_NOTE``) the sentence that names it."""
        w = weights.reshape(-1, 3) if p.group == 3 else weights
        found = source_cancellations(
            p.source, self.points, w, self.conditions.fields, self.scales, self.realise
        )
        if not found:
            return None, ""
        worst = max(found, key=lambda c: c.forward_error)
        if worst.forward_error <= FORWARD_NOTE:
            return worst, ""
        return worst, _describe_cancellation(worst, p, self.geometry, self.conditions)


def _involved(direction: np.ndarray, limit: int = 4) -> list[int]:
    mags = np.abs(direction)
    order = np.argsort(-mags)
    return [int(i) for i in order[:limit] if mags[i] >= 0.25 * mags[order[0]]]


def _cannot_produce(
    problem: _Problem,
    direction: np.ndarray,
    geometry: Geometry,
    *,
    exact: bool,
    amplification: float = 0.0,
) -> str:
    idx = _involved(direction)
    labels = ", ".join(f"'{problem.labels[i]}'" for i in idx)
    provenance = "; ".join(_short(problem.rows[i].provenance, 120) for i in idx)
    plural = "s" if len(idx) > 1 else ""
    what = f"condition{plural} {labels} of {problem.source} ({provenance})"
    if geometry.dimension < 3:
        where = f"candidates all lie in {geometry.plane_text()}"
    elif geometry.thickness_ratio < 1e-2:
        where = (
            f"candidates are nearly planar (thickness / width {geometry.thickness_ratio:.2g}, "
            f"close to {geometry.plane_text()})"
        )
    else:
        where = "the candidates"
    if exact:
        return f"{where}: they cannot produce the moment{plural} of {what}"
    return (
        f"{where}: they produce the moment{plural} of {what} only with weights "
        f"{amplification:.2g} times larger than a round body of this size needs; "
        "use a thicker candidate region"
    )


# ============================================================================ solvers
class _Solution:
    """Scaled solution ``u`` of a problem and how it was found."""

    def __init__(self, u: np.ndarray, solver: str, method: str, status: str = "optimal"):
        self.u = u
        self.solver = solver
        self.method = method
        self.status = status
        self.notes: list[str] = []


def _cvxpy() -> Any:
    import cvxpy as cp

    return cp


def _solve_cvxpy(problem: Any, solver: str, where: str, time_limit: float | None = None) -> str:
    """Solve a cvxpy problem, returning its status; raise SolverError on solver failure."""
    cp = _cvxpy()
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


def _check_cvxpy_status(status: str, where: str, solver: str) -> str:
    if status in ("optimal", "optimal_inaccurate"):
        return status
    if status in ("infeasible", "infeasible_inaccurate"):
        raise _Infeasible(where)
    raise SolverError(f"{where}: solver {solver} returned status {status!r}")


class _Infeasible(Exception):
    """A solver proved the (inequality-constrained) problem infeasible; diagnosed by caller."""


def _linprog(
    c: np.ndarray,
    A_eq: Any,
    b_eq: np.ndarray,
    bounds: Any,
    where: str,
    A_ub: Any = None,
    b_ub: np.ndarray | None = None,
) -> Any:
    from scipy.optimize import linprog

    res = linprog(
        c,
        A_ub=A_ub,
        b_ub=b_ub,
        A_eq=A_eq,
        b_eq=b_eq,
        bounds=bounds,
        method="highs",
        options=dict(HIGHS_OPTIONS),
    )
    if res.status == 2:
        raise _Infeasible(where)
    if res.status != 0:
        raise SolverError(f"{where}: HiGHS returned status {res.status} ({res.message})")
    return res


def _weights_cost(n: int, costs: np.ndarray | None) -> np.ndarray:
    return np.ones(n) if costs is None else costs


def _l1_lp_full(p: _Problem, costs: np.ndarray | None, support: np.ndarray | None) -> _Solution:
    """min sum c_j |u_j| (or c.u with u >= 0 for masses) by one HiGHS LP."""
    cols = np.arange(p.A_s.shape[1]) if support is None else support
    A = p.A_s[:, cols]
    c = _weights_cost(p.A_s.shape[1], costs)[cols]
    where = f"{p.source}: l1 problem"
    if p.nonneg:
        res = _linprog(c, A, p.b_s, (0, None), where)
        u_cols = res.x
    else:
        ub = p.upper
        res = _linprog(np.concatenate([c, c]), np.hstack([A, -A]), p.b_s, (0, ub), where)
        k = len(cols)
        u_cols = res.x[:k] - res.x[k:]
    u = np.zeros(p.A_s.shape[1])
    u[cols] = u_cols
    return _Solution(u, "HiGHS", f"linear program on {len(cols)} candidates")


def _l1_lp_column_generation(
    p: _Problem, costs: np.ndarray | None, progress: Progress | None
) -> _Solution:
    """min sum c_j |u_j| (charges) or c.u, u >= 0 (masses) by column generation.

    Restricted problems on a working set carry elastic slacks (penalty ``P``), so each is
    feasible; all columns are priced with its duals ``y`` (reduced cost ``c_j -+ a_j . y``)
    and the most negative ones join, until none is negative. Then the restricted optimum is
    optimal for the full set (the duals are feasible for it). If a slack stays non-zero the
    full LP decides (infeasible, or the penalty was too small).
    """
    A, b = p.A_s, p.b_s
    m, n = A.shape
    c = _weights_cost(n, costs)
    penalty = 1e4 * float(np.max(c)) * max(1.0, float(np.max(np.abs(b))))
    # start: the columns that carry the least-norm solution, and a few most correlated
    u_ln = _least_norm(A, b)
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
        res = _linprog(cost, A_eq, b, bounds, f"{p.source}: column generation")
        y = res.eqlin.marginals
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
                full = _l1_lp_full(p, costs, None)
                full.method += " (column generation ended with slack; full LP used)"
                return full
            sol = _Solution(
                u,
                "HiGHS",
                f"column generation: {rounds} rounds, working set {k} of {n} candidates; "
                f"optimality verified (least reduced cost {float(np.min(reduced)):.1e})",
            )
            return sol
        order = violators[np.argsort(reduced[violators])][:step]
        in_work[order] = True
    full = _l1_lp_full(p, costs, None)
    full.method += " (column generation did not converge in 200 rounds; full LP used)"
    return full


def _use_cg(p: _Problem, options: DesignOptions) -> bool:
    if options.column_generation is not None:
        return options.column_generation
    return p.n_candidates > CG_MIN_CANDIDATES


def _solver_name(options: DesignOptions) -> str:
    return options.solver.upper()


def _solve_l1_scalar(
    p: _Problem, options: DesignOptions, costs: np.ndarray | None, progress: Progress | None
) -> _Solution:
    solver = _solver_name(options)
    if solver in ("AUTO", "HIGHS"):
        if _use_cg(p, options):
            return _l1_lp_column_generation(p, costs, progress)
        return _l1_lp_full(p, costs, None)
    cp = _cvxpy()
    n = p.A_s.shape[1]
    u = cp.Variable(n, nonneg=p.nonneg)
    c = _weights_cost(n, costs)
    cons = [p.A_s @ u == p.b_s]
    if p.upper is not None:
        cons.append(cp.abs(u) <= p.upper)
    objective = c @ u if p.nonneg else cp.sum(cp.multiply(c, cp.abs(u)))
    prob = cp.Problem(cp.Minimize(objective), cons)
    where = f"{p.source}: l1 problem"
    status = _check_cvxpy_status(_solve_cvxpy(prob, solver, where), where, solver)
    return _Solution(
        np.asarray(u.value, dtype=float), solver.capitalize(), "cvxpy, full problem", status
    )


def _solve_linf_scalar(p: _Problem, options: DesignOptions) -> _Solution:
    solver = _solver_name(options)
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
        res = _linprog(cost, A_eq.tocsr(), p.b_s, bounds, where, A_ub=A_ub, b_ub=b_ub)
        return _Solution(res.x[:n], "HiGHS", f"linear program on {n} candidates")
    cp = _cvxpy()
    u = cp.Variable(n, nonneg=p.nonneg)
    cons = [p.A_s @ u == p.b_s]
    if p.upper is not None:
        cons.append(cp.abs(u) <= p.upper)
    prob = cp.Problem(cp.Minimize(cp.norm(u, "inf")), cons)
    status = _check_cvxpy_status(_solve_cvxpy(prob, solver, where), where, solver)
    return _Solution(
        np.asarray(u.value, dtype=float), solver.capitalize(), "cvxpy, full problem", status
    )


def _least_norm(A: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Minimum-norm solution of ``A x = b`` (A: shape (m, N)), with one refinement step.

    For wide matrices through a QR of ``A^T = Q R``: ``x = Q z`` with ``z`` the least-norm
    solution of the small system ``R^T z = b`` (rank-revealing ``lstsq``), since ``|x| = |z|``.
    (A direct ``lstsq`` on a wide matrix with millions of columns overflows LAPACK's
    workspace size.)
    """

    def solve(rhs: np.ndarray) -> np.ndarray:
        if A.shape[1] > 4 * A.shape[0]:
            Q, R = np.linalg.qr(A.T)
            return Q @ np.linalg.lstsq(R.T, rhs, rcond=None)[0]
        return np.linalg.lstsq(A, rhs, rcond=None)[0]

    x = solve(b)
    return x + solve(b - A @ x)


def _solve_l2(p: _Problem, options: DesignOptions) -> _Solution:
    solver = _solver_name(options)
    unconstrained = not p.nonneg and p.upper is None
    if unconstrained and solver == "AUTO":
        # the minimum of sum w^2 (or sum |sigma|^2) subject to A w = b is the least-norm solution
        return _Solution(_least_norm(p.A_s, p.b_s), "lstsq", "closed form (least norm)")
    cp = _cvxpy()
    n = p.A_s.shape[1]
    name = "CLARABEL" if solver == "AUTO" else solver
    u = cp.Variable(n, nonneg=p.nonneg)
    cons = [p.A_s @ u == p.b_s]
    if p.upper is not None:
        cons.append(cp.abs(u) <= p.upper)
    prob = cp.Problem(cp.Minimize(cp.sum_squares(u)), cons)
    where = f"{p.source}: l2 problem"
    status = _check_cvxpy_status(_solve_cvxpy(prob, name, where), where, name)
    return _Solution(
        np.asarray(u.value, dtype=float), name.capitalize(), "cvxpy, full problem", status
    )


def _group_norms(u: np.ndarray) -> np.ndarray:
    return np.linalg.norm(u.reshape(-1, 3), axis=1)


def _dipole_cvxpy(
    A: np.ndarray, b: np.ndarray, objective: str, solver: str, where: str, penalty: float = 0.0
) -> tuple[np.ndarray, np.ndarray, str]:
    """Dipole problem on columns ``A`` (m, 3k) via cvxpy: returns (u, dual y, status)."""
    cp = _cvxpy()
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
    status = _check_cvxpy_status(_solve_cvxpy(prob, solver, where), where, solver)
    y = np.asarray(con.dual_value, dtype=float).reshape(-1)
    return np.asarray(u.value, dtype=float), y, status


def _solve_dipoles_cone(
    p: _Problem, options: DesignOptions, progress: Progress | None
) -> _Solution:
    objective = options.objective_for("dipoles")
    solver = _solver_name(options)
    name = "CLARABEL" if solver == "AUTO" else solver
    where = f"dipoles: {objective} problem"
    if objective == "l1" and solver in ("AUTO", "CLARABEL") and _use_cg(p, options):
        return _dipoles_column_generation(p, name, progress)
    try:
        u, _, status = _dipole_cvxpy(p.A_s, p.b_s, objective, name, where)
    except SolverError as exc:
        raise SolverError(
            f"{exc}; the dipoles' {objective} problem is a second-order cone: use solver "
            "'auto' or 'CLARABEL'"
        ) from exc
    return _Solution(u, name.capitalize(), "cvxpy, full problem (second-order cone)", status)


def _dipoles_column_generation(p: _Problem, solver: str, progress: Progress | None) -> _Solution:
    """Group-sparse dipoles by column generation (groups of 3 columns per candidate).

    Dual feasibility of the full problem is ``|A_g^T y| <= 1`` for every candidate g; the
    restricted problem's duals price every group and violators join until none is left.
    """
    A, b = p.A_s, p.b_s
    m = A.shape[0]
    n = A.shape[1] // 3
    blocks = A.reshape(m, n, 3)
    u_ln = _least_norm(A, b)
    k0 = min(n, max(4 * m, 40))
    start = np.argsort(-_group_norms(u_ln))[:k0]
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
        u_w, y, last_status = _dipole_cvxpy(A[:, cols], b, "l1", solver, where, penalty)
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
            return _Solution(
                u,
                solver.capitalize(),
                f"column generation: {rounds} rounds, working set {len(groups)} of {n} "
                f"candidates; optimality verified (largest price outside "
                f"{float(np.max(prices, initial=0.0)):.6f} <= 1)",
                last_status,
            )
        order = violators[np.argsort(-prices[violators])][:step]
        in_work[order] = True
    u, _, status = _dipole_cvxpy(A, b, "l1", solver, "dipoles: l1 problem")
    return _Solution(
        u, solver.capitalize(), "cvxpy, full problem (column generation fallback)", status
    )


# ============================================================================ sparsity
def _reweighted_support(
    p: _Problem, options: DesignOptions, target: int, progress: Progress | None
) -> tuple[np.ndarray, str]:
    """Indices of at most ``target`` charges meeting the conditions (reweighted l1, then MIP)."""
    best: np.ndarray | None = None
    if options.sparsity in ("auto", "reweighted"):
        costs = None
        for iteration in range(1, 11):
            sol = _solve_l1_scalar(p, replace(options, solver="auto"), costs, progress)
            u = sol.u
            top = float(np.max(np.abs(u))) if len(u) else 0.0
            support = np.flatnonzero(np.abs(u) > 1e-9 * top)
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
            f"(up to {options.time_limit:g} s) ..."
        )
    return _mip_support(p, options, target, best)


def _mip_support(
    p: _Problem, options: DesignOptions, target: int, best: np.ndarray | None
) -> tuple[np.ndarray, str]:
    cp = _cvxpy()
    n = p.A_s.shape[1]
    if p.upper is not None:
        big_m = p.upper
        bound_text = f"|q| <= max_charge = {options.max_charge:g} C"
    else:
        ref = _l1_lp_full(p, None, None).u
        big_m = 10.0 * float(np.max(np.abs(ref)))
        bound_text = f"|q| <= {big_m * p.scale:.3g} C (10 x the largest l1 charge; set max_charge)"
    u = cp.Variable(n)
    z = cp.Variable(n, boolean=True)
    prob = cp.Problem(
        cp.Minimize(cp.norm1(u)),
        [p.A_s @ u == p.b_s, cp.abs(u) <= big_m * z, cp.sum(z) <= target],
    )
    where = "charges: mixed-integer sparsity problem"
    status = _solve_cvxpy(prob, "HIGHS", where, time_limit=options.time_limit)
    if status in ("infeasible", "infeasible_inaccurate"):
        raise InfeasibleError(
            f"charges: no design with at most {target} charges exists on these candidates with "
            f"{bound_text} (proved by HiGHS mixed-integer search)"
        )
    if status not in ("optimal", "optimal_inaccurate") or u.value is None:
        found = len(best) if best is not None else "none"
        raise SolverError(
            f"charges: no design with at most {target} charges found within "
            f"design.time_limit = {options.time_limit:g} s (status {status}; the sparsest "
            f"found has {found}); raise n_charges or the time limit"
        )
    values = np.asarray(u.value, dtype=float)
    top = float(np.max(np.abs(values)))
    support = np.flatnonzero(np.abs(values) > 1e-9 * top)
    return support, f"mixed integer (HiGHS): {len(support)} charges with {bound_text}"


# ============================================================================ polishing
def _support_of(u: np.ndarray, group: int, threshold: float) -> np.ndarray:
    mags = _group_norms(u) if group == 3 else np.abs(u)
    top = float(np.max(mags)) if len(mags) else 0.0
    return np.flatnonzero(mags > threshold * top) if top > 0 else np.zeros(0, dtype=int)


def _columns(support: np.ndarray, group: int) -> np.ndarray:
    if group == 1:
        return support
    return (3 * support[:, None] + np.arange(3)).reshape(-1)


def _polish_on(p: _Problem, u: np.ndarray, support: np.ndarray) -> np.ndarray | None:
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
    for _ in range(2):
        values[free] += _least_norm(A_free, rhs - A_free @ values[free])
    if p.nonneg and np.any(values < 0):
        # nonnegative least squares on the support, then the least-norm correction on the
        # masses it keeps positive
        A_sup = p.A_s[:, cols]
        values, _ = nnls(A_sup, p.b_s, maxiter=50 * len(cols) + 100)
        keep = values > 0
        for _ in range(2):
            A_keep = A_sup[:, keep]
            values[keep] += _least_norm(A_keep, p.b_s - A_keep @ values[keep])
        if np.any(values < 0):
            return None
    if p.upper is not None and np.any(np.abs(values) > p.upper * (1.0 + 1e-12)):
        return None
    out = np.zeros_like(u)
    out[cols] = values
    return out


def _extend_support(
    p: _Problem, u: np.ndarray, support: np.ndarray, tol: float
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


def _polish(p: _Problem, u: np.ndarray, tol: float) -> tuple[np.ndarray, str]:
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
        count = len(_support_of(weights, p.group, 0.0))
        return f"least-norm correction on the support ({count} elements; {how})"

    for threshold in POLISH_THRESHOLDS[:-1]:
        cand = _polish_on(p, u, _support_of(u, p.group, threshold))
        if cand is None:
            continue
        if sparse_start is None:
            sparse_start = cand
        res = relative_residual(p.A, cand * p.scale, p.b)
        if res <= tol:
            return cand, describe(cand, f"weights below {threshold:g} of the largest dropped")
        if res < best_res:
            best, best_res = cand, res
            text = describe(cand, f"weights below {threshold:g} of the largest dropped")
    if sparse_start is not None:
        extended = _extend_support(p, sparse_start, _support_of(sparse_start, p.group, 0.0), tol)
        if extended is not None:
            current, added = extended
            return current, describe(
                current, f"{added} added to the solver's support to meet the tolerance"
            )
    cand = _polish_on(p, u, _support_of(u, p.group, 0.0))
    if cand is not None:
        res = relative_residual(p.A, cand * p.scale, p.b)
        if res <= tol or res < best_res:
            return cand, describe(cand, "the solver's full support")
    return best, text


# ============================================================================ one source
def _objective_value(w: np.ndarray, group: int, objective: str) -> float:
    mags = _group_norms(w) if group == 3 else np.abs(w)
    if len(mags) == 0:
        return 0.0
    if objective == "l1":
        return float(np.sum(mags))
    if objective == "l2":
        return float(np.sqrt(np.sum(mags**2)))
    return float(np.max(mags))


def _infeasible_inequalities(p: _Problem, options: DesignOptions) -> InfeasibleError:
    """Name the inequality that makes a (range-feasible) problem infeasible."""
    if p.source == "charges" and p.upper is not None:
        try:
            free = replace(p, upper=None)
            need = float(
                np.max(np.abs(_solve_linf_scalar(free, replace(options, solver="auto")).u))
            )
            return InfeasibleError(
                f"charges: design.max_charge = {options.max_charge:g} C is too small: these "
                f"conditions on these candidates need a largest |q| of at least "
                f"{need * p.scale:.6g} C"
            )
        except _Infeasible:
            pass
    if p.source == "masses":
        if options.total_mass is not None:
            free = _drop_last_row(p)
            try:
                least = _l1_lp_full(free, None, None).u.sum() * free.scale
            except _Infeasible:
                least = None
            if least is not None:
                if options.total_mass < least:
                    return InfeasibleError(
                        f"masses: design.total_mass = {options.total_mass:g} kg is below the "
                        f"least total mass that meets the conditions on these candidates, "
                        f"{least:.6g} kg"
                    )
                return InfeasibleError(
                    f"masses: design.total_mass = {options.total_mass:g} kg is above the largest "
                    "total mass that meets the conditions on these candidates (the least is "
                    f"{least:.6g} kg; add candidates nearer O)"
                )
        idx = _irreducible_rows(p)
        names = ", ".join(f"'{p.labels[i]}' ({_short(p.rows[i].provenance, 100)})" for i in idx)
        return InfeasibleError(
            f"masses: no nonnegative masses on these candidates meet conditions {names} together"
        )
    return InfeasibleError(f"{p.source}: the conditions and bounds cannot be met together")


def _drop_last_row(p: _Problem) -> _Problem:
    A, b = p.A[:-1], p.b[:-1]
    rs = p.row_scale[:-1]
    b_row = b * rs
    scale = float(np.max(np.abs(b_row))) or 1.0
    return replace(
        p,
        rows=p.rows[:-1],
        labels=p.labels[:-1],
        A=A,
        b=b,
        A_s=A * rs[:, None],
        b_s=b_row / scale,
        row_scale=rs,
        scale=scale,
    )


def _irreducible_rows(p: _Problem) -> list[int]:
    """A smallest-by-deletion set of rows with no nonnegative solution (for the message).

    Deletion filter: a row is dropped for good when the others are still infeasible; what
    is left is an irreducible infeasible subsystem (every proper subset is feasible).
    """
    keep = list(range(len(p.b_s)))
    for i in range(len(p.b_s)):
        trial = [j for j in keep if j != i]
        if not trial:
            break
        try:
            _linprog(
                np.zeros(p.A_s.shape[1]), p.A_s[trial], p.b_s[trial], (0, None),
                "masses: infeasibility diagnosis",
            )  # fmt: skip
        except _Infeasible:
            keep = trial
        except SolverError:
            break
    return keep


def design_source(
    source: str,
    conditions: LinearConditions,
    candidates: CandidateSet,
    options: DesignOptions,
    *,
    progress: Progress | None = None,
    params: Parameters | None = None,
) -> tuple[np.ndarray, SourceResult]:
    """Design one source's weights on the candidates.

    With ``params`` the weights' forward accuracy is assessed as in :func:`design_body`
    (a note when the conditions are met only by cancellation, a refusal beyond
    ``FORWARD_LIMIT``).

    Returns
    -------
    weights : ndarray, shape (n,) or (n, 3)
        SI units (C, A m^2 or kg), on every candidate (zeros off the support).
    result : SourceResult

    Raises
    ------
    InfeasibleError, SolverError
    """
    t0 = time.perf_counter()
    p = _build(source, conditions, candidates.points, options)
    rank, notes = diagnose(p, candidates.geometry)
    forward = None
    if params is not None:
        realise = options.realise if options.realise is not None else conditions.realise
        forward = _Forward.build(params, conditions, candidates, realise)
    return _design_problem(p, rank, notes, options, t0, progress, forward)


def _design_problem(
    p: _Problem,
    rank: int,
    notes: list[str],
    options: DesignOptions,
    t0: float,
    progress: Progress | None,
    forward: _Forward | None = None,
) -> tuple[np.ndarray, SourceResult]:
    source = p.source
    objective = options.objective_for(source)
    p.rank = rank
    n_cand = p.n_candidates
    shape = (n_cand, 3) if p.group == 3 else (n_cand,)
    if not np.any(p.b):
        # every condition is homogeneous: no element of this source is needed
        return np.zeros(shape), SourceResult(
            source=source,
            objective=objective,
            objective_value=0.0,
            objective_value_raw=0.0,
            units=UNITS[source],
            solver="none",
            method="all conditions are zero: no elements needed",
            status="optimal",
            n_conditions=len(p.b),
            rank=rank,
            n_candidates=n_cand,
            n_elements=0,
            residual_before=0.0,
            residual_after=0.0,
            seconds=time.perf_counter() - t0,
            notes=notes,
        )
    if progress is not None:
        progress(f"{source}: {objective} problem, {len(p.b)} conditions, {n_cand} candidates")
    try:
        sol = _solve(p, objective, options, progress)
    except _Infeasible:
        raise _infeasible_inequalities(p, options) from None
    if sol.u is None or not np.all(np.isfinite(sol.u)):
        raise SolverError(f"{source}: solver {sol.solver} returned no finite solution")
    raw = sol.u * p.scale
    before = relative_residual(p.A, raw, p.b)
    u = sol.u
    polish_text = "not polished"
    if options.polish:
        u, polish_text = _polish(p, sol.u, options.tolerance)
    weights = u * p.scale
    after = relative_residual(p.A, weights, p.b)
    worst, cancellation = forward.assess(p, weights) if forward is not None else (None, "")
    cancels = worst is not None and worst.forward_error > FORWARD_NOTE
    if after > options.tolerance:
        if options.tolerance < 2 * np.finfo(float).eps:
            raise SolverError(
                f"{source}: relative residual {after:.2g} exceeds design.tol = "
                f"{options.tolerance:g}, which is below the rounding of double precision "
                f"({np.finfo(float).eps:.2g}): raise design.tol"
            )
        if cancels:
            # the solver is not at fault: the targets are tiny against what the weights carry
            raise InfeasibleError(
                f"{source}: relative residual {after:.2g} exceeds design.tol = "
                f"{options.tolerance:g}, most likely because {cancellation} (another solver "
                "will not help)"
            )
        raise SolverError(
            f"{source}: relative residual {after:.2g} exceeds design.tol = "
            f"{options.tolerance:g} ({sol.solver}, {polish_text}); try another solver"
        )
    if worst is not None and worst.forward_error > FORWARD_LIMIT:
        raise InfeasibleError(
            f"{source}: refused, {cancellation} (beyond {FORWARD_LIMIT:g} the body realises "
            "nothing reliably)"
        )
    if cancels:
        notes.append(f"{source}: {cancellation}")
    if p.nonneg and np.any(weights < 0):
        raise SolverError(f"{source}: a negative mass survived polishing ({weights.min():.3g} kg)")
    support = _support_of(u, p.group, 0.0)
    if sol.status != "optimal":
        notes.append(
            f"{source}: {sol.solver} reported {sol.status!r} at its tightened tolerances; "
            "the residuals were verified here"
        )
    notes.extend(sol.notes)
    result = SourceResult(
        source=source,
        objective=objective,
        objective_value=_objective_value(weights, p.group, objective),
        objective_value_raw=_objective_value(raw, p.group, objective),
        units=UNITS[source],
        solver=sol.solver,
        method=f"{sol.method}; {polish_text}",
        status="optimal",
        n_conditions=len(p.b),
        rank=rank,
        n_candidates=n_cand,
        n_elements=len(support),
        residual_before=before,
        residual_after=after,
        seconds=time.perf_counter() - t0,
        notes=notes,
        forward=worst,
    )
    return weights.reshape(shape), result


def _solve(
    p: _Problem, objective: str, options: DesignOptions, progress: Progress | None
) -> _Solution:
    if p.source == "dipoles":
        if objective == "l2":
            return _solve_l2(p, options)
        return _solve_dipoles_cone(p, options, progress)
    if p.source == "charges" and options.n_charges is not None:
        support, how = _reweighted_support(p, options, options.n_charges, progress)
        sub = _restrict(p, support)
        inner = _solve(sub, objective, replace(options, n_charges=None), progress)
        u = np.zeros(p.A_s.shape[1])
        u[support] = inner.u
        sol = _Solution(u, inner.solver, f"{how}; then {inner.method}", inner.status)
        return sol
    if objective == "l1":
        return _solve_l1_scalar(p, options, None, progress)
    if objective == "linf":
        return _solve_linf_scalar(p, options)
    return _solve_l2(p, options)


def _restrict(p: _Problem, support: np.ndarray) -> _Problem:
    return replace(p, A=p.A[:, support], A_s=p.A_s[:, support])


# ============================================================================ the body
def design_body(
    params: Parameters,
    conditions: LinearConditions,
    candidates: CandidateSet | np.ndarray,
    options: DesignOptions | None = None,
    *,
    progress: Progress | None = None,
) -> DesignResult:
    """Design charges, dipoles and masses on candidate points that meet the conditions.

    Parameters
    ----------
    params : Parameters
        The theorem's parameters (SI units).
    conditions : LinearConditions
        From :func:`chargedesign.conditions.derive_conditions`; its ``fields`` are written
        into the design.
    candidates : CandidateSet or ndarray, shape (n, 3)
        Candidate positions in body axes, m.
    options : DesignOptions, optional
    progress : callable, optional
        Called with a short message before each long step.

    Returns
    -------
    DesignResult

    Raises
    ------
    InfeasibleError
        The conditions cannot be met on these candidates (the message names them), or only
        by a cancellation that leaves the body meaningless (estimated forward error above
        ``FORWARD_LIMIT``; the message names the cause and the remedy).
    SolverError
        A solver failed or its polished result misses ``options.tolerance``.

    Notes
    -----
    The design meets ``conditions`` as given. When their default field strengths were chosen
    for an assumed 1 m body (``conditions.length_assumed``) and these candidates call for
    other ones, a note gives them (derive the conditions with ``length=`` the candidates'
    size, as :func:`design_from_scene` does). Every source's delivered weights are assessed
    for cancellation (:func:`forward_accuracy`): above ``FORWARD_NOTE`` the notes say which
    quantity is met only by cancellation, the forward accuracy to expect and the remedy.
    """
    if not isinstance(params, Parameters):
        raise input_error("params", "a chargedesign.params.Parameters", params)
    if not isinstance(conditions, LinearConditions):
        raise input_error("conditions", "a chargedesign.conditions.LinearConditions", conditions)
    options = options or DesignOptions()
    cand = (
        candidates if isinstance(candidates, CandidateSet) else candidates_from_points(candidates)
    )
    realise = tuple(conditions.realise) if conditions.realise else ()
    if options.realise is not None:
        if conditions.realise and set(options.realise) != set(conditions.realise):
            raise InputError(
                f"design.realise: the conditions realise {list(conditions.realise)}, the "
                f"options ask for {list(options.realise)}"
            )
        realise = options.realise
    timings: dict[str, float] = {}
    t_start = time.perf_counter()
    sources_present = [s for s in SOURCES if conditions.for_source(s)]
    if options.total_charge not in (None, 0.0) and "charges" not in sources_present:
        raise InputError("design.total_charge: no charges are designed (no charge conditions)")
    if options.n_charges is not None and "charges" not in sources_present:
        raise InputError("design.n_charges: no charges are designed (no charge conditions)")
    if options.total_mass is not None and "masses" not in sources_present:
        raise InputError("design.total_mass: no masses are designed (inertia is not realised)")
    notes = list(cand.notes)
    notes.extend(_length_notes(conditions, cand.geometry.size))
    forward = _Forward.build(params, conditions, cand, realise)
    # fail fast: every source's equality system is checked before any solve
    checked = []
    for source in sources_present:
        t0 = time.perf_counter()
        p = _build(source, conditions, cand.points, options)
        rank, source_notes = diagnose(p, cand.geometry)
        checked.append((p, rank, source_notes, time.perf_counter() - t0))
    results: dict[str, SourceResult] = {}
    weights: dict[str, np.ndarray] = {}
    for p, rank, source_notes, setup in checked:
        source = p.source
        t0 = time.perf_counter() - setup
        w, res = _design_problem(p, rank, source_notes, options, t0, progress, forward)
        weights[source] = w
        results[source] = res
        timings[source] = res.seconds
        notes.extend(res.notes)
    timings["total"] = time.perf_counter() - t_start

    def pick(source: str) -> tuple[np.ndarray, np.ndarray]:
        if source not in weights:
            shape = (0, 3) if source == "dipoles" else (0,)
            return np.zeros((0, 3)), np.zeros(shape)
        w = weights[source]
        mags = np.linalg.norm(w, axis=1) if w.ndim == 2 else np.abs(w)
        keep = mags > 0
        return cand.points[keep], w[keep]

    cp_, cv = pick("charges")
    dp, dm = pick("dipoles")
    mp, mv = pick("masses")
    design = Design(
        parameters=params,
        fields={k: tuple(v) for k, v in conditions.fields.items()},
        charge_positions=cp_,
        charge_values=cv,
        mass_positions=mp,
        mass_values=mv,
        dipole_positions=dp,
        dipole_moments=dm,
        realises=list(realise),
    )
    result = DesignResult(
        design=design,
        sources=results,
        candidates=cand,
        options=options,
        conditions=conditions,
        timings=timings,
        notes=notes,
    )
    design.extra.update(design_extras(result))
    return result


def design_extras(result: DesignResult) -> dict[str, Any]:
    """Provenance keys written into design.json beside the contract's keys."""
    from chargedesign import __version__

    conditions = result.conditions
    counts = {s: len(conditions.for_source(s)) for s in SOURCES if conditions.for_source(s)}
    out: dict[str, Any] = {
        "units": {
            "positions": "m",
            "charges": "C",
            "masses": "kg",
            "dipoles": "A m^2",
            "fields": "legendre f_k of Phi = sum f_k R^k P_k(Z/R): magnetic T m^(1-k), "
            "electric V m^(-k), gravity J kg^-1 m^(-k)",
        },
        "provenance": {
            "generator": f"chargedesign {__version__}",
            "fields_origin": dict(conditions.field_origin),
            "options": result.options.to_dict(),
        },
        "solver": {
            k: {"solver": s.solver, "method": s.method, "status": s.status}
            for k, s in result.sources.items()
        },
        "objective": {
            k: {
                "kind": s.objective,
                "value": s.objective_value,
                "units": s.units,
                "before_polish": s.objective_value_raw,
            }
            for k, s in result.sources.items()
        },
        "residuals": {
            "definition": "max_i |(A w - b)_i| / (|A_i|_S |w| + |b_i|) over the conditions "
            "of each source (A w = b from the conditions engine, SI units; |.| Euclidean, "
            "|A_i|_S the norm of row i on the support w != 0)",
            "before_polish": {k: s.residual_before for k, s in result.sources.items()},
            "after_polish": {k: s.residual_after for k, s in result.sources.items()},
            "tolerance": result.options.tolerance,
        },
        "forward_accuracy": {
            "definition": "per source, the field term whose contributions cancel most: sum of "
            "the elements' |contributions| through it over the size of mu (max |mu|) or V (its "
            "spread) = amplification; forward_error = eps * amplification * (sum |coefficients| "
            "of P_k, times k for V), the relative error to expect from any floating-point "
            "evaluation",
            "note_above": FORWARD_NOTE,
            "refused_above": FORWARD_LIMIT,
            "worst": {
                k: s.forward.to_dict() for k, s in result.sources.items() if s.forward is not None
            },
        },
        "timings": {k: round(v, 6) for k, v in result.timings.items()},
        "candidates": result.candidates.description,
        "conditions": {
            "counts": counts,
            "ranks": {k: s.rank for k, s in result.sources.items()},
            "notes": list(conditions.notes),
            "list": [c.to_dict() for c in conditions.conditions],
        },
        "notes": list(result.notes),
    }
    if result.candidates.region is not None:
        out["region"] = dict(result.candidates.region)
    return out


def design_from_scene(
    scene: Any,
    *,
    progress: Progress | None = None,
    **overrides: Any,
) -> DesignResult:
    """Design the body a scene describes: its parameters, fields, ``[body]`` and ``[design]``.

    Parameters
    ----------
    scene : chargedesign.scene.Scene
    progress : callable, optional
    **overrides
        DesignOptions fields that replace the scene's ``[design]`` values (None: keep).

    Returns
    -------
    DesignResult
    """
    from pathlib import Path

    from chargedesign.candidates import candidates_from_table
    from chargedesign.conditions import derive_conditions, realise_from_scene
    from chargedesign.scene import Scene

    if not isinstance(scene, Scene):
        raise input_error("scene", "a chargedesign.scene.Scene", scene)
    t0 = time.perf_counter()
    options = DesignOptions.from_table(scene.table("design"), **overrides)
    base_dir = Path(scene.source).parent if scene.source not in ("<default>", "<dict>") else None
    if progress is not None:
        progress("candidates ...")
    candidates = candidates_from_table(scene.table("body"), base_dir=base_dir)
    t1 = time.perf_counter()
    if progress is not None:
        progress(f"conditions ({len(candidates)} candidates) ...")
    realise = options.realise if options.realise is not None else realise_from_scene(scene)
    size = candidates.geometry.size
    conditions = derive_conditions(
        scene.parameters, scene.fields, realise, length=size if size > 0 else None
    )
    t2 = time.perf_counter()
    result = design_body(scene.parameters, conditions, candidates, options, progress=progress)
    result.timings = {"candidates": t1 - t0, "conditions": t2 - t1, **result.timings}
    result.timings["total"] = time.perf_counter() - t0
    result.design.extra["timings"] = {k: round(v, 6) for k, v in result.timings.items()}
    result.design.extra["provenance"]["scene"] = scene.source
    return result


__all__ = [
    "FORWARD_LIMIT",
    "FORWARD_NOTE",
    "OBJECTIVES",
    "Cancellation",
    "DesignOptions",
    "DesignResult",
    "SourceResult",
    "design_body",
    "design_from_scene",
    "design_source",
    "diagnose",
    "forward_accuracy",
    "quantity_scales",
    "relative_residual",
    "source_cancellations",
]
