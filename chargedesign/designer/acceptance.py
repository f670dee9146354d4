"""What a designed body must pass before it is delivered: one acceptance for design and frontier.

``chargedesign design`` writes a body only when it passes (in this order):

1. the limits check (physical bodies: :func:`chargedesign.physical.limits.check_limits`, run
   by :func:`chargedesign.designer.assembly.design_physical`);
2. the balance (a physical body under gravity, :func:`balance_bound`): gravity acts on the
   whole mass, so the centre of mass must sit at O within a distance the forward check's
   tolerance allows against the designed torques. The designed torques scale like ``s^2``
   (``s`` the time rate), gravity's imbalance does not: the balance bounds the rate from
   below, twice. Double precision holds the centre of mass to about one unit of roundoff of
   the body's mass-weighted size (``BALANCE_ULPS``): below the rate where the check would need
   a finer balance, the check cannot confirm the body. And a builder balances a platform to
   about ``BUILDER_BALANCE_M``: below the rate where that balance leaves gravity a torque
   above ``BUILDER_TORQUE_FRACTION`` of the designed ones, the body cannot be built as
   designed. The lower bound is the larger of the two;
3. the forward check (:func:`forward_acceptance`, :func:`chargedesign.checker.check_design`
   with its default tolerance, against the parameters the elements realise:
   ``n = 0`` for the ``frame`` Larmor reading).

The frontier (:mod:`chargedesign.designer.frontier`) applies the same three, so a rate it
reports is one ``design`` accepts.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from chargedesign.body import Design
from chargedesign.checker import (
    DEFAULT_ORIENTATIONS,
    DEFAULT_TOL,
    check_design,
    sample_orientations,
    theorem_reference,
)
from chargedesign.constants import STANDARD_GRAVITY
from chargedesign.errors import ChargeDesignError
from chargedesign.formatting import PLAIN, ROUGH, fmt
from chargedesign.physical.materials import BUILDER_BALANCE_M
from chargedesign.physical.realism import general_case_functions
from chargedesign.validation import MAX_MAGNITUDE

#: the balance double precision holds, in units of roundoff of the body's mass-weighted size
#: ``sum m |r| / M`` (the polished masses put the centre of mass 0.3 of it from O on the
#: 2 cm test body in SF6: tests/physical/test_frontier_acceptance.py)
BALANCE_ULPS = 1.0
#: gravity's torque from the builder's balance may be at most this fraction of the designed
#: torques (the realism budget's "negligible": a parasitic below 1e-3 of them)
BUILDER_TORQUE_FRACTION = 1e-3


def body_check(design: Design, **kwargs: Any) -> Any:
    """The forward check of the elements against the parameters they realise.

    :func:`chargedesign.checker.check_design` on the design with ``parameters`` replaced by
    :attr:`Design.body_parameters` (``n = 0`` for the ``frame`` Larmor reading; unchanged
    for ``charges``).
    """
    body = (
        design
        if design.larmor_reading == "charges"
        else replace(design, parameters=design.body_parameters)
    )
    return check_design(body, verdict=False, **kwargs)  # the verdict: judged at acceptance


def _check_magnitudes(design: Design) -> None:
    """Every element's values and positions within the supported range ``MAX_MAGNITUDE``."""
    values = [
        np.abs(getattr(design, name))
        for name in ("charge_values", "mass_values", "dipole_moments", "charge_positions")
    ]
    largest = max((float(v.max()) for v in values if v.size), default=0.0)
    if not np.isfinite(largest) or largest > MAX_MAGNITUDE:
        raise ChargeDesignError(
            f"the body needs an element of size {fmt(largest)} (SI), outside the "
            f"supported range |x| <= {fmt(MAX_MAGNITUDE, PLAIN)}: the requested total is too large"
            " or "
            "the scale is outside the range; rescale the units. Nothing was written"
        )


def failed_quantities(report: Any) -> str:
    """The forward check's failing quantities and their relative errors, in one line."""
    return ", ".join(
        f"{name} {fmt(q.rel_err, ROUGH)}"
        for name, q in report.quantities.items()
        if name in report.failures
    )


def forward_acceptance(design: Design, *, totals_requested: bool = False) -> None:
    """The design command's forward check: raises one line when the body misses the theorem.

    Parameters
    ----------
    design : Design
    totals_requested : bool
        Whether a total charge or mass was requested (named as a possible cause).

    Raises
    ------
    ChargeDesignError
        Elements outside the supported range, a check that could not run, or a body that
        misses the theorem (the failing quantities and their errors).
    """
    _check_magnitudes(design)
    try:
        report = body_check(design)
    except ChargeDesignError as exc:
        raise ChargeDesignError(
            f"the forward check of the body failed ({exc}); nothing was written"
        ) from exc
    if report.passed:
        return
    errors = failed_quantities(report)
    causes = []
    if totals_requested:
        causes.append("the requested total (--total-charge/--total-mass) may be too large")
    causes.append(
        "the scale may be outside the supported range or the forward accuracy "
        "insufficient (rescale the units toward 1)"
    )
    raise ChargeDesignError(
        f"the body misses the theorem in the forward check ({errors or 'failed'} "
        f"against tol {fmt(report.tol, PLAIN)}); {'; '.join(causes)}. Nothing was written "
        "(--no-forward-check writes it anyway)"
    )


@dataclass(frozen=True)
class BalanceBound:
    """How finely a body under gravity must be balanced at its rate, and the rate bound.

    Attributes
    ----------
    gravity : float
        The uniform part ``|f_1|`` of the gravity field, m/s^2.
    mass : float
        The body's mass, kg.
    needed : float
        The centre-of-mass distance from O whose gravity torque (and energy range) is the
        check's tolerance times the designed ones at this rate, m.
    held : float
        The balance double precision holds for this body (``BALANCE_ULPS`` roundoff of its
        mass-weighted size), m.
    tol : float
        The forward check's relative tolerance.
    rate : float
        The body's time rate ``s`` (design.json ``time_rate``).
    """

    gravity: float
    mass: float
    needed: float
    held: float
    tol: float
    rate: float

    @property
    def check_rate(self) -> float:
        """The lowest time rate whose balance the check can confirm (the designed torques go
        as ``s^2``; the mass is taken as this body's)."""
        return self.rate * math.sqrt(self.held / self.needed) if self.needed > 0 else math.inf

    @property
    def builder_needed(self) -> float:
        """The centre-of-mass distance whose gravity torque is ``BUILDER_TORQUE_FRACTION`` of
        the designed torques at this rate, m."""
        return BUILDER_TORQUE_FRACTION * self.needed / self.tol

    @property
    def builder_rate(self) -> float:
        """The lowest rate at which a builder's balance (``BUILDER_BALANCE_M``) leaves gravity
        below ``BUILDER_TORQUE_FRACTION`` of the designed torques."""
        need = self.builder_needed
        return self.rate * math.sqrt(BUILDER_BALANCE_M / need) if need > 0 else math.inf

    @property
    def lowest_rate(self) -> float:
        """The lowest rate the body is accepted at: checkable and buildable."""
        return max(self.check_rate, self.builder_rate)

    @property
    def confirmed(self) -> bool:
        return self.needed >= self.held and self.builder_needed >= BUILDER_BALANCE_M

    def text(self) -> str:
        """One line: what the balance asks at this rate and what holds."""
        g = _gravity_text(self.gravity)
        if self.builder_needed < BUILDER_BALANCE_M:
            return (
                f"under {g} the centre of mass must sit within {fmt(self.builder_needed)} m of O "
                f"for gravity to stay below {fmt(BUILDER_TORQUE_FRACTION, PLAIN)} of the designed"
                " torques, "
                f"finer than the {fmt(BUILDER_BALANCE_M, PLAIN)} m a builder balances to"
            )
        return (
            f"under {g} the centre of mass must sit within {fmt(self.needed)} m of O (the "
            f"check's tolerance {fmt(self.tol, PLAIN)} of the designed torques), and double"
            " precision "
            f"holds this body's balance only to {fmt(self.held)} m"
        )

    def to_dict(self) -> dict[str, Any]:
        return {
            "gravity_m_per_s2": self.gravity,
            "mass_kg": self.mass,
            "centre_of_mass_within_m": self.needed,
            "balance_held_m": self.held,
            "check_tolerance": self.tol,
            "lowest_rate": self.lowest_rate if math.isfinite(self.lowest_rate) else None,
            "check_lowest_rate": self.check_rate if math.isfinite(self.check_rate) else None,
            "builder_balance_m": BUILDER_BALANCE_M,
            "builder_torque_fraction": BUILDER_TORQUE_FRACTION,
            "builder_centre_of_mass_within_m": self.builder_needed,
            "builder_lowest_rate": self.builder_rate if math.isfinite(self.builder_rate) else None,
        }


def _gravity_text(g: float) -> str:
    ratio = g / STANDARD_GRAVITY
    return f"{fmt(ratio)} g" if abs(ratio - 1) > 0.01 else "1 g"


def balance_bound(design: Design, tol: float | None = None) -> BalanceBound | None:
    """The balance a body under uniform gravity needs at its rate (None without gravity).

    Parameters
    ----------
    design : Design
        With ``design.time_rate`` (1 when absent) and a ``gravity`` field.
    tol : float, optional
        The forward check's tolerance (default: the check's).

    Notes
    -----
    A centre-of-mass offset ``delta`` adds ``M g gamma . delta`` to V and ``M g gamma x
    delta`` to the potential torque; the check accepts neither beyond ``tol`` times the
    designed spread of V or the largest designed potential torque over its orientations
    (:func:`chargedesign.checker.theorem_reference` of the body's parameters; a general
    case's own V, :func:`chargedesign.physical.realism.general_case_functions`). Only the
    uniform part of gravity is counted: it is the one that does not vanish at O.
    """
    coeffs = design.field("gravity")
    g = abs(float(coeffs[0])) if coeffs else 0.0
    if g == 0.0:
        return None
    tol = DEFAULT_TOL if tol is None else tol
    positions, masses = design.all_masses()
    mass = float(np.sum(masses))
    if not mass > 0:
        return None
    size = float(np.sum(masses * np.linalg.norm(positions, axis=1))) / mass
    gammas = sample_orientations(DEFAULT_ORIENTATIONS, 0)
    functions = general_case_functions(design)  # a general case: its own V
    ref = (
        theorem_reference(design.body_parameters, gammas)
        if functions is None
        else functions.reference(gammas)
    )
    spread = float(np.max(np.abs(ref["V"] - ref["V"].mean())))
    torque = float(np.max(np.linalg.norm(np.cross(gammas, ref["dV"]), axis=1)))
    designed = min(x for x in (spread, torque, math.inf) if x > 0) if spread or torque else 0.0
    needed = tol * designed / (mass * g) if math.isfinite(designed) else 0.0
    held = BALANCE_ULPS * float(np.finfo(float).eps) * size
    rate = 1.0 if design.time_rate is None else float(design.time_rate)
    return BalanceBound(g, mass, needed, held, tol, rate)
