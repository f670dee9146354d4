"""Comparisons with the theorem, rounding floors, verdicts and check_design.

Part of :mod:`chargedesign.checker` (see its docstring for the method).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from chargedesign.body import Design
from chargedesign.checker.accurate import (
    evaluate_accurate,
)
from chargedesign.checker.constants import (
    ACCURATE_FRACTION,
    BLOCK_PAIRS,
    DEFAULT_ORIENTATIONS,
    DEFAULT_TOL,
    EPS,
    NOISE_FLOOR,
    QUANTITY_CLAIMS,
    ROUNDING_FACTOR,
)
from chargedesign.checker.double_double import (
    DD_UNIT,
)
from chargedesign.checker.inertia import whole_inertia_check
from chargedesign.checker.kernel import (
    RotatedSums,
    collect_elements,
    evaluate_rotated,
    rotation_matrices,
    sample_orientations,
    trimmed_legendre,
)
from chargedesign.checker.results import (
    CheckReport,
    EffectResult,
    QuantityResult,
)
from chargedesign.errors import InputError, SolverError
from chargedesign.formatting import AGREEMENT, FLOOR, ORDER_SCI, PLAIN, ROUGH, fmt
from chargedesign.model import evaluators
from chargedesign.moments import moment_keys, monomial_matrix
from chargedesign.physical.budget import induced_magnetisation, window_at_design
from chargedesign.physical.limits import LimitsReport, check_limits
from chargedesign.quadrature import GatheredElements
from chargedesign.results import json_ready
from chargedesign.scene.design_realism import WindowAtDesign
from chargedesign.scene.keys import KEY
from chargedesign.validation import (
    as_finite_float,
    check_choice,
    check_instance,
    check_integer,
    parse_moment_key,
)
from chargedesign.verdict import judge, not_checked, recorded_verdict
from chargedesign.vocabulary import (
    CHECK_EFFECTS,
    FIELD_NAMES,
    PRECISIONS,
)


# ------------------------------------------------------------------------ comparisons
def worst_orientation(gammas: np.ndarray, err: np.ndarray) -> tuple[float, float, float]:
    """The orientation gamma (a 3-tuple) where ``err`` is largest."""
    i = int(np.argmax(err))
    return (float(gammas[i, 0]), float(gammas[i, 1]), float(gammas[i, 2]))


def orientation_norms(a: np.ndarray) -> np.ndarray:
    """|a| per orientation: absolute values (m,) or Euclidean norms of rows (m, 3)."""
    return np.abs(a) if a.ndim == 1 else np.linalg.norm(a, axis=1)


def relative_error(
    x: np.ndarray, ref: np.ndarray, gross: float, gammas: np.ndarray
) -> tuple[float, float, float, str, tuple[float, float, float]]:
    """(rel_err, abs_err, scale, basis, worst gamma) of per-orientation vectors or scalars.

    The scale is ``max |ref|`` (basis ``reference``); for a reference that is zero at every
    orientation, the gross contributions (basis ``gross``: absolute error relative to the
    size of the terms that had to cancel to zero).
    """
    err = orientation_norms(x - ref)
    abs_err = float(err.max(initial=0.0))
    scale = float(orientation_norms(ref).max(initial=0.0))
    basis = "reference"
    if scale == 0.0:
        basis, scale = "gross", gross
    if scale > 0.0:
        rel = abs_err / scale
    else:  # no reference and no contributions: nothing to compare
        rel = 0.0 if abs_err == 0.0 else math.inf
    return rel, abs_err, scale, basis, worst_orientation(gammas, err)


def field_bounds(coeffs: np.ndarray, radii: np.ndarray) -> tuple[np.ndarray, ...]:
    """Bounds at distance r from O of |Phi|, |grad Phi| and |Hessian Phi| of a field.

    ``sum |f_k| r^k``, ``sum k |f_k| r^(k-1)``, ``sum k (k - 1) |f_k| r^(k-2)``: the sizes
    of the terms an element's evaluation adds up (the field may be far smaller there).

    Returns
    -------
    three ndarrays, shape (n,)
    """
    value, grad, hess = (np.zeros(len(radii)) for _ in range(3))
    for k, f in enumerate(np.abs(np.asarray(coeffs, dtype=float)), start=1):
        if f == 0.0:
            continue
        value += f * radii**k
        grad += k * f * radii ** (k - 1)
        if k >= 2:
            hess += k * (k - 1) * f * radii ** (k - 2)
    return value, grad, hess


def contribution_sizes(
    elements: GatheredElements, fields: Mapping[str, Sequence[float]]
) -> dict[str, float]:
    """Sum over the elements of the size of their contributions to each compared quantity.

    The size of one contribution is its bound through every field term (:func:`field_bounds`):
    ``|q| r^2 |grad Phi_m|`` for mu (and the Lorentz torque per unit |omega|), ``|q| |Phi_e| +
    m |Phi_g| + |sigma| |grad Phi_m|`` for V, ``|q| r |grad Phi_e| + m r |grad Phi_g| +
    |sigma| (|grad Phi_m| + r |Hess Phi_m|)`` for the potential torque. It is what a
    floating-point evaluation of each element rounds against, whatever the orientation, so
    ``size / max |x_ref|`` is the cancellation that sets the rounding floor.

    Returns
    -------
    dict with ``mu`` (kg m^2/s), ``gyroscopic_torque`` (per rad/s, N m s), ``V`` (J),
    ``potential_torque`` (N m).
    """
    coeffs = {k: trimmed_legendre(tuple(fields.get(k, ()))) for k in FIELD_NAMES}
    rq = np.linalg.norm(elements.charge_positions, axis=1)
    rm = np.linalg.norm(elements.mass_positions, axis=1)
    rd = np.linalg.norm(elements.dipole_positions, axis=1)
    q = np.abs(elements.charge_values)
    m = np.abs(elements.mass_values)
    s = np.linalg.norm(elements.dipole_moments, axis=1)
    _, grad_mq, _ = field_bounds(coeffs["magnetic"], rq)
    value_e, grad_e, _ = field_bounds(coeffs["electric"], rq)
    value_g, grad_g, _ = field_bounds(coeffs["gravity"], rm)
    _, grad_md, hess_md = field_bounds(coeffs["magnetic"], rd)
    mu = float(q @ (rq**2 * grad_mq))
    return {
        "mu": mu,
        "gyroscopic_torque": mu,
        "V": float(q @ value_e + m @ value_g + s @ grad_md),
        "potential_torque": float(
            q @ (rq * grad_e) + m @ (rm * grad_g) + s @ (grad_md + rd * hess_md)
        ),
    }


def cancellation_factor(gross: float, ref_scale: float) -> float:
    """``gross / max |x_ref|``: inf for a zero reference, 0 without contributions."""
    if ref_scale > 0.0:
        return gross / ref_scale
    return math.inf if gross > 0.0 else 0.0


def rounding_floor(cancellation: float, unit: float, basis: str = "reference") -> float:
    """Attainable relative accuracy of a sum whose contributions cancel ``cancellation``-fold.

    ``ROUNDING_FACTOR * (unit * cancellation + EPS)``: each element's contribution is
    evaluated with a relative error of a few ``unit`` (the rotation, the recurrences, the
    products), so the sum is uncertain by a few ``unit * gross``; the result is finally
    rounded to double (``EPS``). With basis ``gross`` (a zero reference, rel_err measured
    against the gross) it is ``ROUNDING_FACTOR * unit``. ``unit``: :data:`EPS` for double,
    :data:`DD_UNIT` for double-double.
    """
    if basis == "gross":
        return ROUNDING_FACTOR * unit
    return ROUNDING_FACTOR * (unit * cancellation + EPS)


def quantity_verdict(
    rel: float, floor: float, tol: float, cancellation: float, basis: str, precision: str
) -> tuple[str, str | None]:
    """(status, reason) of a claimed quantity.

    ``fail`` when the error is beyond the tolerance by more than the rounding floor (certainly
    wrong), ``unverifiable`` when the floor itself exceeds the tolerance (the evaluation cannot
    tell), ``pass`` when within the tolerance, ``fail`` otherwise.
    """
    failed = (
        "fail",
        f"error {fmt(rel, AGREEMENT)} exceeds tol {fmt(tol, PLAIN)} (rounding floor"
        f" {fmt(floor, FLOOR)})",
    )
    if not rel <= tol + floor:  # also catches an infinite error
        return failed
    if floor > tol:
        if basis == "gross":
            size = "the reference is zero and the gross contributions round"
        else:
            size = f"contributions cancel to 1 part in {fmt(cancellation, ROUGH)}"
        return "unverifiable", (
            f"cannot be verified at tol {fmt(tol, PLAIN)}: {size} (rounding floor"
            f" {fmt(floor, FLOOR)} in "
            f"{precision}; error seen {fmt(rel, FLOOR)})"
        )
    if rel <= tol:
        return "pass", None
    return failed


def fitted_torque(gammas: np.ndarray, energy: np.ndarray, degree: int) -> np.ndarray | None:
    """``gamma x grad p`` of the least-squares polynomial p (degree <= ``degree``) of energy.

    The fit uses an evenly strided subset of the orientations (four per monomial: the
    polynomial is determined by any well-spread sample); the torque is evaluated at all.
    Returns None when there are too few orientations for a well-determined fit.
    """
    keys = [k for order in range(degree + 1) for k in moment_keys(order)]
    if len(gammas) < 2 * len(keys):
        return None
    subset = np.unique(np.linspace(0, len(gammas) - 1, 4 * len(keys)).astype(int))
    basis = monomial_matrix(gammas[subset], keys).T
    # the monomials are dependent on the sphere (|gamma| = 1): lstsq returns the minimum-norm
    # fit, whose tangential gradient (all the torque uses) is unique.
    coef, *_ = np.linalg.lstsq(basis, energy[subset], rcond=None)
    grad = np.zeros_like(gammas)
    for axis in range(3):
        lowered, factors = [], []
        for c, key in zip(coef, keys, strict=True):
            exps = list(parse_moment_key(key))
            if exps[axis]:
                factors.append(c * exps[axis])
                exps[axis] -= 1
                lowered.append("x" * exps[0] + "y" * exps[1] + "z" * exps[2])
        if lowered:
            grad[:, axis] = np.asarray(factors) @ monomial_matrix(gammas, lowered)
    return np.cross(gammas, grad)


def theorem_reference(params: Any, gammas: np.ndarray) -> dict[str, np.ndarray]:
    """The theorem's mu, V and grad V at the sampled orientations (must all be finite)."""
    ref = {
        "mu": np.asarray(evaluators.gyroscopic(gammas, params), dtype=float),
        "V": np.asarray(evaluators.potential(gammas, params), dtype=float),
        "dV": np.asarray(evaluators.potential_gradient(gammas, params), dtype=float),
    }
    for name, value in ref.items():
        if not np.all(np.isfinite(value)):
            raise SolverError(f"theorem: {name} is not finite at some sampled orientation")
    return ref


def check_design(
    design: Design,
    *,
    n_orientations: int = DEFAULT_ORIENTATIONS,
    tol: float = DEFAULT_TOL,
    seed: int = 0,
    quadrature_order: int | None = None,
    block_pairs: int = BLOCK_PAIRS,
    precision: str = "auto",
    verdict: bool = True,
) -> CheckReport:
    """Recompute mu, V, the torques and the inertia of a design and compare with the theorem.

    Parameters
    ----------
    design : Design
        Point charges (C), masses (kg), dipoles (A m^2) and continuous bodies in body axes.
    n_orientations : int
        Orientations gamma sampled (half Fibonacci sphere, half random).
    tol : float
        Relative tolerance (> 0) for the quantities the design claims (``realises``).
    seed : int
        Seed of the random orientations, azimuths and angular velocities (rad/s, unit-normal
        components).
    quadrature_order : int, optional
        Degree of exactness of the continuous bodies' rules; default: exact for the check.
    block_pairs : int
        Element-orientation pairs per vectorised block (memory vs speed).
    precision : str
        ``auto`` (default): double precision, and double-double where a claimed quantity's
        contributions cancel so far that double rounding could decide it (its double
        rounding floor above ``ACCURATE_FRACTION * tol``); ``double`` or ``double-double``
        to force one.
    verdict : bool
        Recompute the verdict from the written parts too (default; the design's own
        acceptance, which has just judged them, passes False): the limits and the realised
        window's items at the body's rate, judged by :func:`chargedesign.verdict.judge`, beside
        the design's record (``verdict_agrees``).

    Returns
    -------
    CheckReport
        The reference is the theorem with the body's own parameters
        (:attr:`~chargedesign.body.Design.body_parameters`): n = 0 for a ``frame`` reading
        (``design.larmor``), whose n is the rate of the turning axes, not a field effect.
        A claimed quantity passes when its error is within ``tol``; it is ``unverifiable``
        (and fails) when the rounding floor of the evaluation exceeds ``tol``. A physical
        body (with ``medium``) also has its limits recomputed from its elements
        (:func:`chargedesign.physical.limits.check_limits`): the report passes only when
        its parts are within their limits too.
    """
    tol = validate_check_options(design, tol, seed, quadrature_order, block_pairs, precision)
    gammas = sample_orientations(n_orientations, seed)
    rng = np.random.default_rng([int(seed), 1])
    R = rotation_matrices(gammas, rng)
    omegas = rng.standard_normal((len(gammas), 3))
    elements, degrees = collect_elements(design, quadrature_order)
    fields = {k: design.field(k) for k in FIELD_NAMES}
    sums = evaluate_rotated(elements, fields, R, omegas, block_pairs=block_pairs)
    # a frame body realises the theorem with n = 0 (its n is the rate of the turning axes)
    params = design.body_parameters
    case = _case_functions(design)  # a case of (ep) (design.json "case"): its own reference
    ref = theorem_reference(params, gammas) if case is None else case.reference(gammas)
    claimed = set(design.realises)
    for name, arr in [("mu", sums.mu), ("gyroscopic torque", sums.gyro)]:
        if not np.all(np.isfinite(arr)):
            raise SolverError(f"check: the design's {name} is not finite (overflow?)")
    refs = reference_quantities(ref, gammas, omegas)
    plan = rounding_plan(elements, fields, omegas, refs)
    accurate = use_double_double(precision, claimed, plan, tol)
    evaluated = evaluate_quantities(elements, fields, gammas, omegas, sums, accurate, block_pairs)
    notes: list[str] = []
    quantities = compare_quantities(evaluated, refs, plan, gammas, claimed, tol, notes)
    # the whole inertia: the points, every part's own and the holder's (checker.inertia)
    inertia, inertia_gross, compared = whole_inertia_check(design, elements)
    if compared:
        notes.append(_inertia_note(compared))
    quantities["inertia"] = inertia_result(
        inertia, inertia_gross, params, claimed, tol, None if case is None else case.inertia
    )
    effects = effect_results(
        elements, degrees, gammas, omegas, evaluated.sums, inertia, evaluated.unit
    )
    notes.extend(design_notes(design, params, claimed))
    n_pairs = len(gammas) * (
        len(elements.charge_values) + len(elements.mass_values) + len(elements.dipole_moments)
    )
    limits = check_limits(design) if design.medium else None
    return CheckReport(
        tol=tol,
        n_orientations=len(gammas),
        seed=int(seed),
        claimed=list(design.realises),
        quantities=quantities,
        effects=effects,
        V_offset=evaluated.energy_mean - float(ref["V"].mean()),
        quadrature=elements.quadrature,
        n_pairs=n_pairs,
        notes=notes,
        precision=evaluated.precision,
        limits=limits,
        larmor=larmor_summary(design, params),
        verdict=recomputed_verdict(design, limits) if verdict else None,
        recorded_verdict=_recorded(design) if verdict else None,
        reference="theorem" if case is None else "case",
        induced=(
            induced_magnetisation(design, parts_ok=limits.parts_within_limits)
            if verdict and limits is not None
            else None
        ),
    )


def recomputed_verdict(design: Design, limits: LimitsReport | None) -> dict[str, Any]:
    """The verdict from the written parts alone: the limits recomputed
    (:func:`~chargedesign.physical.limits.check_limits`), the magnets against their continuum
    size and the realised window's items at the body's rate
    (:func:`~chargedesign.physical.budget.window_at_design`), judged as the design's record is
    (:func:`chargedesign.verdict.judge`); the design's realism record is not read."""
    if design.medium is None or limits is None:
        return not_checked()
    window = window_at_design(design, parts_ok=limits.parts_within_limits)
    return judge(
        design,
        limits=limits.to_dict(),
        magnets=limits.magnet_continuum,
        window=None if window is None else WindowAtDesign.from_dict(json_ready(window)),
    )


def _recorded(design: Design) -> dict[str, Any] | None:
    """The design's verdict record (or, for a file written before it, what its record gives;
    None when that record is incomplete)."""
    try:
        return recorded_verdict(design)
    except InputError:
        return None


def _case_functions(design: Design) -> Any:
    """The numeric functions of the case a design.json carries, read in the body's own axes
    (:func:`~chargedesign.model.case_numeric.body_case`: the frame reading's elements realise
    the case at n = 0); None: the theorem's."""
    if "case" not in design.further_keys:
        return None
    from chargedesign.model.case_numeric import design_case_functions  # sympy: a case only

    return design_case_functions(design.further_keys["case"], design.larmor, design.time_rate)


def validate_check_options(
    design: Any,
    tol: Any,
    seed: Any,
    quadrature_order: Any,
    block_pairs: Any,
    precision: Any,
) -> float:
    """Refuse bad arguments of :func:`check_design` (one line each); the tolerance as a float."""
    check_instance(design, Design, "design", "a Design")
    tol = as_finite_float(tol, "tol", positive=True)
    check_integer(seed, "seed", minimum=0)
    check_integer(quadrature_order, "quadrature_order", minimum=0, none_allowed=True)
    check_integer(block_pairs, "block_pairs", minimum=1)
    check_choice(precision, PRECISIONS, "precision")
    return tol


def reference_quantities(
    ref: Mapping[str, np.ndarray], gammas: np.ndarray, omegas: np.ndarray
) -> dict[str, np.ndarray]:
    """The theorem's mu, gyroscopic torque, centred V and potential torque per orientation."""
    return {
        "mu": ref["mu"],
        "gyroscopic_torque": np.cross(ref["mu"], omegas),
        "V": ref["V"] - ref["V"].mean(),  # V is defined up to a constant
        "potential_torque": np.cross(gammas, ref["dV"]),
    }


@dataclass(frozen=True)
class RoundingPlan:
    """Per compared quantity: gross contributions, cancellation, basis and double floor."""

    gross: dict[str, float]
    cancellation: dict[str, float]
    basis: dict[str, str]
    double_floor: dict[str, float]


def rounding_plan(
    elements: GatheredElements,
    fields: Mapping[str, Sequence[float]],
    omegas: np.ndarray,
    refs: Mapping[str, np.ndarray],
) -> RoundingPlan:
    """How far each quantity's contributions cancel, and so its rounding floor in double."""
    sizes = contribution_sizes(elements, fields)
    omega_norm = np.linalg.norm(omegas, axis=1)
    gross = dict(sizes)
    gross["gyroscopic_torque"] = sizes["gyroscopic_torque"] * float(omega_norm.max(initial=0.0))
    ref_scale = {k: float(orientation_norms(v).max(initial=0.0)) for k, v in refs.items()}
    cancellation = {k: cancellation_factor(gross[k], ref_scale[k]) for k in refs}
    basis = {k: "reference" if ref_scale[k] > 0.0 else "gross" for k in refs}
    double_floor = {k: rounding_floor(cancellation[k], EPS, basis[k]) for k in refs}
    return RoundingPlan(gross, cancellation, basis, double_floor)


def use_double_double(precision: str, claimed: set[str], plan: RoundingPlan, tol: float) -> bool:
    """Whether to sum in double-double: forced, or (``auto``) where double rounding could
    decide a claimed quantity."""
    if precision == "auto":
        return any(
            QUANTITY_CLAIMS[k] in claimed and plan.double_floor[k] > ACCURATE_FRACTION * tol
            for k in plan.double_floor
        )
    return precision == "double-double"


@dataclass(frozen=True)
class EvaluatedQuantities:
    """The design's compared quantities in the arithmetic used, with the sums behind them."""

    sums: RotatedSums
    values: dict[str, np.ndarray]
    energy_mean: float
    precision: str
    unit: float


def evaluate_quantities(
    elements: GatheredElements,
    fields: dict[str, tuple[float, ...]],
    gammas: np.ndarray,
    omegas: np.ndarray,
    sums: RotatedSums,
    accurate: bool,
    block_pairs: int,
) -> EvaluatedQuantities:
    """mu, gyroscopic torque, centred V and potential torque of the design, in double or
    (``accurate``) double-double; raises SolverError on a non-finite value."""
    used = sums
    if accurate:
        acc = evaluate_accurate(elements, fields, gammas, omegas, block_pairs=block_pairs)
        used = RotatedSums(
            mu=acc.mu,
            gyro=acc.gyro,
            mu_gross=sums.mu_gross,
            energy=acc.energy,
            energy_gross=sums.energy_gross,
            torque=acc.torque,
            torque_gross=sums.torque_gross,
        )
        energy_centered, energy_mean = acc.energy_centered, acc.energy_mean
    else:
        energy = np.sum(list(sums.energy.values()), axis=0)
        energy_mean = float(energy.mean())
        energy_centered = energy - energy_mean
    used_precision = "double-double" if accurate else "double"
    values = {
        "mu": used.mu,
        "gyroscopic_torque": used.gyro,
        "V": energy_centered,
        "potential_torque": np.sum(list(used.torque.values()), axis=0),
    }
    for name, value in values.items():
        if not np.all(np.isfinite(value)):
            raise SolverError(
                f"check: the design's {name} is not finite in {used_precision} (overflow?)"
            )
    return EvaluatedQuantities(
        sums=used,
        values=values,
        energy_mean=energy_mean,
        precision=used_precision,
        unit=DD_UNIT if accurate else EPS,
    )


def quantity_result(
    name: str,
    compared: tuple[float, float, float, str, Any],
    gross_size: float,
    cancel: float,
    floors: tuple[float, float],
    arithmetic: str,
    claimed: set[str],
    tol: float,
) -> QuantityResult:
    """The verdict on one compared quantity (``info`` when the design does not claim it).

    ``compared``: (rel_err, abs_err, scale, basis, worst gamma) from :func:`relative_error`;
    ``floors``: (rounding floor in the arithmetic used, rounding floor in double).
    """
    rel, abs_err, scale, basis, worst = compared
    is_claimed = QUANTITY_CLAIMS[name] in claimed
    status, reason = (
        quantity_verdict(rel, floors[0], tol, cancel, basis, arithmetic)
        if is_claimed
        else ("info", None)
    )
    return QuantityResult(
        name=name,
        rel_err=rel,
        abs_err=abs_err,
        scale=scale,
        worst_gamma=worst,
        claimed=is_claimed,
        passed=None if status == "info" else status == "pass",
        status=status,
        reason=reason,
        basis=basis,
        gross=gross_size,
        cancellation=cancel,
        rounding_floor=floors[0],
        double_rounding_floor=floors[1],
        precision=arithmetic,
    )


def compare_quantities(
    evaluated: EvaluatedQuantities,
    refs: Mapping[str, np.ndarray],
    plan: RoundingPlan,
    gammas: np.ndarray,
    claimed: set[str],
    tol: float,
    notes: list[str],
) -> dict[str, QuantityResult]:
    """Verdicts on mu, the gyroscopic torque, V and the potential torque; appends to ``notes``
    the quantities only double-double could verify."""
    quantities: dict[str, QuantityResult] = {}
    accurate = evaluated.precision == "double-double"
    for name in ("mu", "gyroscopic_torque", "V", "potential_torque"):
        gross, cancel = plan.gross[name], plan.cancellation[name]
        compared = relative_error(evaluated.values[name], refs[name], gross, gammas)
        floors = (
            rounding_floor(cancel, evaluated.unit, plan.basis[name]),
            plan.double_floor[name],
        )
        result = quantity_result(
            name, compared, gross, cancel, floors, evaluated.precision, claimed, tol
        )
        quantities[name] = result
        if accurate and result.claimed and floors[1] > tol and result.status == "pass":
            notes.append(
                f"{name}: verified in double-double; its contributions cancel to 1 part in "
                f"{fmt(cancel, ROUGH)}, so any double-precision evaluation of this body "
                f"(e.g. chargedesign simulate) has a rounding floor of ~{fmt(floors[1], ORDER_SCI)}"
            )
    return quantities


def inertia_result(
    inertia: np.ndarray,
    inertia_gross: float,
    params: Any,
    claimed: set[str],
    tol: float,
    reference: np.ndarray | None = None,
) -> QuantityResult:
    """The inertia tensor (summed in double-double, gross ``sum m |r|^2``) against
    diag(2C, 2C, C), or a case's ``reference``."""
    inertia_ref = np.diag([2.0 * params.C, 2.0 * params.C, params.C])
    inertia_ref = inertia_ref if reference is None else reference
    scale = float(np.abs(inertia_ref).max())
    inertia_abs = float(np.abs(inertia - inertia_ref).max())
    inertia_cancel = inertia_gross / scale
    return quantity_result(
        "inertia",
        (inertia_abs / scale, inertia_abs, scale, "reference", None),
        inertia_gross,
        inertia_cancel,
        (rounding_floor(inertia_cancel, DD_UNIT), rounding_floor(inertia_cancel, EPS)),
        "double-double",
        claimed,
        tol,
    )


def _inertia_note(compared: dict[str, Any]) -> str:
    """How the recomputed whole inertia compares with design.json's record."""
    return (
        "inertia: recomputed from the written parts (points, each part's own "
        f"{fmt(compared['parts_own_kg_m2'])} kg m^2"
        + (", the holder less its bores" if compared["holder"] else ", no holder")
        + f"); design.json's inertia.total_kg_m2 agrees to "
        f"{fmt(compared['recorded_vs_recomputed'], ORDER_SCI)} relative"
    )


def design_notes(design: Design, params: Any, claimed: set[str]) -> list[str]:
    """Notes on what the design cannot realise, claims nothing, or reads in turning axes."""
    notes = []
    if params.singular:
        notes.append(
            "lambda/rho terms of V are singular on gamma3 = 0: charges, masses and dipoles "
            "cannot realise them"
        )
    if not claimed:
        notes.append("the design claims nothing (realises is empty): all results informational")
    if design.larmor is not None and design.larmor.is_frame:
        notes.append(
            f"frame reading: elements checked against the theorem with n = 0; "
            f"n = {fmt(design.larmor.rate, PLAIN)} 1/s is the rate of the turning axes (the motion "
            "read in them is the theorem's with n)"
        )
    return notes


def larmor_summary(design: Design, params: Any) -> dict[str, Any] | None:
    """The design's Larmor reading and rate, and the n it was checked with (None without)."""
    if design.larmor is None:
        return None
    return {
        "reading": design.larmor.reading,
        "rate": design.larmor.rate,
        "checked_n": params.n,
    }


def _resolved(size: float, gross: float, unit: float) -> bool:
    """Whether an effect of ``size`` stands above the rounding of its ``gross`` contributions."""
    return size > 0.0 and rounding_floor(gross / size, unit) <= NOISE_FLOOR


def _lorentz_result(
    count: int, active: bool, gammas: np.ndarray, omegas: np.ndarray, sums: RotatedSums, unit: float
) -> EffectResult:
    """Lorentz: the force route (sum r x q (v x B)) against the design's own mu x omega."""
    size = {
        "mu": float(np.linalg.norm(sums.mu, axis=1).max(initial=0.0)),
        "gyroscopic_torque": float(np.linalg.norm(sums.gyro, axis=1).max(initial=0.0)),
    }
    route: float | None = None
    worst = None
    gross = float((sums.mu_gross * np.linalg.norm(omegas, axis=1)).max(initial=0.0))
    if active and _resolved(size["gyroscopic_torque"], gross, unit):
        route, _, _, _, worst = relative_error(sums.gyro, np.cross(sums.mu, omegas), gross, gammas)
    return EffectResult("lorentz", "charges", count, active, size, route, worst)


def _field_effect_result(
    name: str, count: int, degree: int, gammas: np.ndarray, sums: RotatedSums, unit: float
) -> EffectResult:
    """A potential's effect: its energy's spread and torque, the torque against the fitted
    gradient of the energy."""
    source = CHECK_EFFECTS[name][0]
    active = count > 0 and degree > 0
    e = sums.energy[name]
    t = sums.torque[name]
    size = {
        "V_spread": float(e.max(initial=0.0) - e.min(initial=0.0)) if len(e) else 0.0,
        "torque": float(np.linalg.norm(t, axis=1).max(initial=0.0)),
    }
    route, worst = None, None
    gross = float(sums.torque_gross[name].max(initial=0.0))
    # an effect that cancels to rounding (e.g. masses centred at O in uniform gravity)
    # has no torque to compare: its route agreement would only measure rounding
    if active and _resolved(size["torque"], gross, unit):
        fitted = fitted_torque(gammas, e, degree)
        if fitted is not None:
            route, _, _, _, worst = relative_error(t, fitted, gross, gammas)
    return EffectResult(name, source, count, active, size, route, worst)


def effect_results(
    elements: GatheredElements,
    degrees: dict[str, int],
    gammas: np.ndarray,
    omegas: np.ndarray,
    sums: RotatedSums,
    inertia: np.ndarray,
    unit: float,
) -> dict[str, EffectResult]:
    """Per-effect sizes and route agreement; ``unit``: unit roundoff of the sums (the route
    agreement is skipped where the effect cancels so far that rounding would dominate it)."""
    counts = {
        "charges": len(elements.charge_values),
        "masses": len(elements.mass_values),
        "dipoles": len(elements.dipole_moments),
    }
    out: dict[str, EffectResult] = {}
    active = counts["charges"] > 0 and degrees["magnetic"] > 0
    out["lorentz"] = _lorentz_result(counts["charges"], active, gammas, omegas, sums, unit)
    for name in ("electric", "gravity", "magnetization"):
        source, field_name = CHECK_EFFECTS[name]
        assert field_name is not None
        count, degree = counts[source], degrees[field_name]
        out[name] = _field_effect_result(name, count, degree, gammas, sums, unit)
    out["inertia"] = EffectResult(
        "inertia",
        "masses",
        counts["masses"],
        counts["masses"] > 0,
        {KEY.total_mass: float(elements.mass_values.sum()), "trace": float(np.trace(inertia))},
    )
    return out
