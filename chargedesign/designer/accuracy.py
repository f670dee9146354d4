"""Forward accuracy: how far a source's contributions to mu and V cancel.

The elements of a design meet its conditions to ``design.tol`` (a backward error), but a
quantity that is the small sum of much larger contributions is only as accurate as ``eps``
times that ratio in any floating-point evaluation. :func:`forward_accuracy` measures it for
a design; during the design (:class:`ForwardInputs`) a source whose estimated forward error
exceeds :data:`FORWARD_NOTE` gets a note naming the cause and the remedy, and beyond
:data:`FORWARD_LIMIT` it is refused.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np

from chargedesign.body import Design
from chargedesign.candidates import CandidateSet, Geometry, fibonacci_sphere
from chargedesign.designer.system import UNITS, DesignProblem, natural_row_size
from chargedesign.formatting import CELL, ORDER, ORDER_SCI, PLAIN, ROUGH, fmt
from chargedesign.model import evaluators
from chargedesign.moment_conditions import (
    DEFAULT_STRENGTH_HEADROOM,
    FIELD_KINDS,
    FIELD_LETTERS,
    SOURCE_FIELD,
    LinearCondition,
    LinearConditions,
)
from chargedesign.params import Parameters

#: estimated relative forward error (mu, V and their torques evaluated in floating point from
#: the elements) above which a design says its conditions are met only by cancellation (a
#: tenth of the forward check's default tolerance, chargedesign.checker.DEFAULT_TOL) ...
FORWARD_NOTE = 1e-10
#: ... and above which it is refused: the body would realise its targets to 1e-4 at best
#: (contributions ~1e12 times the quantity; nothing reliable is left)
FORWARD_LIMIT = 1e-4


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
    return f"fields.{kind} {FIELD_LETTERS[kind]}{k}"


def _term_value(kind: str, k: int, coefficient: float) -> str:
    """The term's value as the user writes it (a2 = f2 / 2), with units."""
    if kind == "magnetic" and k == 1:
        return f"a1 = {fmt(coefficient)} T"
    if kind == "magnetic" and k == 2:
        return f"a2 = {fmt(coefficient / 2)} T/m"
    units = {"magnetic": f"T m^{1 - k}", "electric": f"V m^-{k}", "gravity": f"J/kg m^-{k}"}
    return f"{_term_name(kind, k)} = {fmt(coefficient)} {units[kind]}"


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

    The forward check compares with the same sizes (chargedesign.checker). Evaluated on a
    Fibonacci set of ``n_orientations`` (even: no orientation on gamma3 = 0).
    """

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
            out.append(
                _cancellation(source, quantity, kind, k, coefficient, gross / scale, largest)
            )
    return out


def _cancellation(
    source: str,
    quantity: str,
    kind: str,
    k: int,
    coefficient: float,
    amplification: float,
    largest: float,
) -> Cancellation:
    """The cancellation through one field term, its forward error from its amplification."""
    evaluation = _legendre_abs_sum(k) * (k if quantity == "V" else 1)
    return Cancellation(
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
    fields = {kind: design.field(kind) for kind in FIELD_KINDS}
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
        return (SOURCE_FIELD[source], degree)
    if source == "charges" and text.startswith("mu"):
        return ("magnetic", order - 1)
    if source == "dipoles":
        return ("magnetic", order + 1)
    if source == "masses" and text.startswith("inertia"):
        return ("inertia", order)
    return None


def _describe_cancellation(
    worst: Cancellation,
    problem: DesignProblem,
    geometry: Geometry,
    conditions: LinearConditions,
) -> str:
    """What cancels, how much, what sizes the weights, and the remedy (one line, no source).

    The weights are sized by the condition that needs the largest weight from a round body
    of this size (target over what unit weights at distance L give); its field term is the
    driver: strengthening it shrinks every weight, hence the cancellation, in proportion.
    """
    size = geometry.size if geometry.size > 0 else 1.0
    driver, driver_text = _weight_driver(problem, size, conditions.fields)
    remedy = _cancellation_remedy(worst, driver, conditions, size)
    return (
        f"{worst.quantity} is met only by cancellation: the {problem.source}' contributions "
        f"through {worst.term} are {fmt(worst.amplification, ROUGH)} times |{worst.quantity}| "
        f"(largest {fmt(worst.largest_weight)} {UNITS[problem.source]}{driver_text}); forward "
        f"accuracy ~{fmt(worst.forward_error, ORDER)}: {remedy}"
    )


def _weight_driver(
    problem: DesignProblem, size: float, fields: Mapping[str, Sequence[float]]
) -> tuple[tuple[str, int] | None, str]:
    """The field term of the condition needing the largest weight from a round body of this
    size, and its words (empty when no condition needs a weight)."""
    natural = np.array([natural_row_size(r, size) for r in problem.rows])
    need = np.abs(problem.b) / np.where(natural > 0, natural, np.inf)
    driver_text = ""
    driver = None
    if len(need) and float(np.max(need)) > 0:
        i = int(np.argmax(need))
        driver = _row_term(problem.source, problem.rows[i])
        driver_text = f", sized by condition '{problem.labels[i]}' = {fmt(problem.b[i])}"
        if driver is not None and driver[0] in fields:
            kind, k = driver
            coeffs = fields[kind]
            if 1 <= k <= len(coeffs) and coeffs[k - 1] != 0:
                driver_text += f" through {_term_value(kind, k, coeffs[k - 1])}"
    return driver, driver_text


def _cancellation_remedy(
    worst: Cancellation,
    driver: tuple[str, int] | None,
    conditions: LinearConditions,
    size: float,
) -> str:
    """The remedy of a cancellation: default strengths, a given electric field, the driver."""
    origin = conditions.field_origin
    factor = worst.forward_error / FORWARD_NOTE
    remedy = "its targets differ in scale by this factor"
    involved = [(worst.kind, worst.degree)] + ([driver] if driver is not None else [])
    defaults = [
        _term_name(kind, k)
        for kind, k in involved
        if kind in FIELD_LETTERS
        and f"{kind} {FIELD_LETTERS[kind]}{k}" in conditions.default_strengths
    ]
    if defaults and conditions.length_assumed:
        remedy = (
            f"{defaults[0]} was chosen by default for an assumed 1 m body: derive the "
            f"conditions with length={fmt(size)} (the candidates' size)"
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
            f"choose {worst.term} ~ {fmt(suggested, ORDER_SCI)} V m^-{worst.degree} (or omit "
            "[fields.electric]: the conditions then choose it for the body)"
        )
    elif driver is not None and driver[0] in FIELD_KINDS:
        remedy = f"increase {_term_name(*driver)} at least {fmt(factor, ROUGH)}-fold"
    elif driver is not None and driver[0] == "inertia":
        remedy = f"weaken {worst.term} or use a larger body (masses scale like C / L^2)"
    return remedy


def length_notes(conditions: LinearConditions, size: float) -> list[str]:
    """A note when the default strengths were chosen for 1 m and these candidates differ."""
    if not conditions.length_assumed or not size > 0:
        return []
    suited = conditions.for_length(size).default_strengths
    if suited == conditions.default_strengths:
        return []
    changes = ", ".join(
        f"{name} = {fmt(conditions.default_strengths.get(name, 0.0), PLAIN)} (for 1 m) would be"
        f" {fmt(value, PLAIN)}"
        for name, value in suited.items()
    )
    return [
        "conditions: the default field strengths were chosen for an assumed body length of "
        f"1 m; for these candidates (L = {fmt(size, CELL)} m) {changes}: derive the conditions with"
        " "
        f"length={fmt(size, CELL)} (design_from_scene does)"
    ]


@dataclass
class ForwardInputs:
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
    ) -> ForwardInputs | None:
        if params.singular or not ({"mu", "V"} & set(realise)):
            return None
        return cls(
            conditions=conditions,
            scales=quantity_scales(params),
            realise=tuple(realise),
            geometry=candidates.geometry,
            points=candidates.points,
        )

    def assess(self, p: DesignProblem, weights: np.ndarray) -> tuple[Cancellation | None, str]:
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
