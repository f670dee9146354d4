"""Physical design, assembled: both stages at one rate, the body they make, its acceptance.

:func:`design_physical` is the stage's entry point: the charges
(:mod:`chargedesign.designer.charges`) and masses (:mod:`chargedesign.designer.masses`) at the
requested rate, the body built from them, checked forward and accepted, or refused naming the
binding limit.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from chargedesign.body import Design
from chargedesign.designer.acceptance import balance_bound
from chargedesign.designer.charges import ChargeSolution, design_charges
from chargedesign.designer.masses import MassSolution, design_masses
from chargedesign.designer.physical_setup import (
    DESIGN_MARGIN,
    Binding,
    PhysicalInfeasible,
    PhysicalSetup,
)
from chargedesign.designer.result import DesignResult, SourceResult, record_provenance
from chargedesign.designer.robust import weighted_norm
from chargedesign.designer.system import UNITS
from chargedesign.errors import InfeasibleError, SolverError
from chargedesign.formatting import PRECISE, fmt
from chargedesign.larmor import LarmorReading
from chargedesign.params import Parameters
from chargedesign.physical.budget import realism_record
from chargedesign.physical.holder import design_parts, holder_for, whole_inertia
from chargedesign.physical.limits import (
    check_limits,
)
from chargedesign.physical.materials import Material
from chargedesign.scene.design import Progress


# --------------------------------------------------------------------------- assembling
@dataclass
class PhysicalOutcome:
    charges: ChargeSolution
    masses: MassSolution
    scale: float
    seconds: float


def design_at_rate(setup: PhysicalSetup, s: float) -> PhysicalOutcome:
    """Both stages at time rate ``s``; raises PhysicalInfeasible naming the binding limit."""
    t0 = time.perf_counter()
    charges = design_charges(setup, s)
    masses = design_masses(setup, s, charges.sites)
    return PhysicalOutcome(charges, masses, s, time.perf_counter() - t0)


def scaled_parameters(params: Parameters, s: float) -> Parameters:
    """The theorem's parameters at time rate ``s`` (n, K x s; kappa, lambda, rho x s^2)."""
    return replace(
        params,
        n=params.n * s,
        K=params.K * s,
        kappa=params.kappa * s * s,
        lam=params.lam * s * s,
        rho=params.rho * s * s,
    )


def build_design(setup: PhysicalSetup, outcome: PhysicalOutcome) -> Design:
    """The Design of an outcome: carriers, magnets (with any attached ballast), ballast."""
    s = outcome.scale
    spec = setup.spec
    ch, ms = outcome.charges, outcome.masses
    magnets = np.linalg.norm(ms.moments, axis=1) > 0
    M = spec.magnet.magnetisation or 1.0
    fields = {k: tuple(v) for k, v in setup.conditions.fields.items()}
    if "electric" in fields:
        fields["electric"] = tuple(s * x for x in fields["electric"])
    larmor = setup.larmor
    design = Design(
        parameters=scaled_parameters(setup.theorem_params, s),
        fields=fields,
        charge_positions=setup.points[ch.sites],
        charge_values=ch.charges,
        charge_radii=np.full(len(ch.sites), setup.carrier_radius),
        charge_masses=np.full(len(ch.sites), setup.carrier_mass),
        dipole_positions=setup.points[ms.sites[magnets]],
        dipole_moments=ms.moments[magnets],
        dipole_volumes=np.linalg.norm(ms.moments[magnets], axis=1) / M,
        dipole_masses=ms.site_masses[magnets],
        mass_positions=setup.points[ms.sites[~magnets]],
        mass_values=ms.site_masses[~magnets],
        mass_materials=(
            [spec.ballasts[j].name for j in ms.materials[~magnets]]
            if ms.materials is not None
            else None
        ),
        realises=list(setup.options.realise or setup.conditions.realise),
        medium=spec.medium.to_dict(),
        materials=spec.materials_dict(),
        larmor=None if larmor is None else LarmorReading(larmor.reading, larmor.rate * s),
    )
    design.field_limits = dict(spec.field_limits)
    design.time_rate = s
    if setup.model_record is not None:
        # a general case: the record is the case at rate 1 and the body realises it at rate
        # s (design.time_rate): every reader rescales it (model.case_numeric.body_case)
        design.further_keys["case"] = dict(setup.model_record)
    whole_record(design, spec.holder, ms)
    if spec.material_errors:
        design.material_errors = dict(spec.material_errors)
    return design


def whole_record(design: Design, material: Material | None, masses: MassSolution) -> None:
    """Write the holder (of ``material``, at the radius the design converged to; none without
    a material) and the whole inertia about O into ``design``."""
    holder = None
    if material is not None:
        holder = holder_for(material, design_parts(design), masses.holder_radius)
        design.holder = holder.record()
    design.inertia = whole_inertia(design, holder)
    if masses.convergence is not None:
        design.inertia["convergence"] = masses.convergence.to_dict()


def source_results(setup: PhysicalSetup, outcome: PhysicalOutcome) -> dict[str, SourceResult]:
    """The per-source outcomes in the form the report and summary read: each designed
    source's objective value, method, residual and element count."""
    ch, ms = outcome.charges, outcome.masses
    dipoles = int(np.count_nonzero(np.linalg.norm(ms.moments, axis=1)))
    parts = {  # source: (weights, sites, method, residual, element count)
        "charges": (ch.charges, ch.sites, ch.method, ch.residual, len(ch.sites)),
        "dipoles": (ms.moments, ms.sites, ms.method, ms.residual_dipoles, dipoles),
        "masses": (ms.site_masses, ms.sites, ms.method, ms.residual_masses, len(ms.sites)),
    }
    out = {}
    for source, (weights, sites, method, residual, count) in parts.items():
        A, b = setup.systems[source]
        if not len(b):
            continue
        value = weighted_norm(weights, setup.cost(source)[sites])
        out[source] = SourceResult(
            source=source,
            objective=setup.options.objective_for(source),
            objective_value=value,
            objective_value_raw=value,
            units=UNITS[source],
            solver="HiGHS+Clarabel" if source == "charges" else "Clarabel",
            method=method,
            status="optimal",
            n_conditions=len(b),
            rank=int(np.linalg.matrix_rank(A)) if A.size else 0,
            n_candidates=len(setup.points),
            n_elements=count,
            residual_before=residual,
            residual_after=residual,
            seconds=outcome.seconds,
        )
    return out


def design_physical(
    setup: PhysicalSetup,
    *,
    scale: float = 1.0,
    progress: Progress | None = None,
) -> DesignResult:
    """Design the physical body at time rate ``scale`` (1: the scene's parameters).

    The body is accepted as :mod:`chargedesign.designer.acceptance` says: its limits are
    checked again from the written parts and, under gravity, its balance; the realism budget
    (:func:`chargedesign.physical.budget.realism_record`) is written into
    ``design.realism``. The design never locates the frontier (the frontier calls
    the design): :func:`chargedesign.designer.pipeline.design_from_scene` adds it.

    A rate beyond what the limits allow raises :class:`~chargedesign.errors.InfeasibleError`
    with the binding element and limit, in one line.
    """
    t0 = time.perf_counter()
    if progress is not None:
        progress(
            f"physical design: {len(setup.points)} candidate sites, medium {setup.spec.medium.name}"
        )
    try:
        design, outcome, limits = accept_at_rate(setup, scale)
    except PhysicalInfeasible as exc:
        raise InfeasibleError(beyond_message(setup, exc.binding, scale)) from None
    result = DesignResult(
        design=design,
        sources=source_results(setup, outcome),
        candidates=setup.candidates,
        options=setup.options,
        conditions=setup.conditions,
        timings={"physical": time.perf_counter() - t0},
        notes=[],
    )
    record_provenance(design, result)
    design.buildability = limits.to_dict()
    design.realism = realism_record(design, limits.field_response)
    design.physical_design = {
        "carrier_radius_m": setup.carrier_radius,
        "carrier_mass_kg": setup.carrier_mass,
        "constraint_generation_rounds": outcome.charges.rounds,
        "surface_cones": outcome.charges.cones,
        "design_margin": DESIGN_MARGIN,
    }
    return result


_FURTHER = {
    "charges": "vacuum or a medium with a higher breakdown, more or larger carriers, a stronger "
    "magnetic field (a2 for K, a1 for n in the charges reading), or a smaller, lighter body "
    "reaches further",
    "fields": "a larger fields.electric.max reaches further",
    "masses": "lighter carriers (thinner shells, a lighter material, fewer) or a larger C "
    "reach further",
    "magnets": "a stronger magnet material, a larger gradient a2 or larger cells reach further",
    "balance": "a faster rate, a heavier designed potential or less gravity reaches it",
}


def beyond_message(setup: PhysicalSetup, binding: Binding, s: float) -> str:
    """One line: what fails at rate ``s`` and what would reach further (no frontier search:
    ``chargedesign frontier`` gives the largest rate)."""
    return (
        f"{binding.text(setup.spec.medium.name)} at time rate s = {fmt(s, PRECISE)}; "
        f"{_FURTHER.get(binding.stage, 'see docs/buildable.md')} (chargedesign frontier "
        "finds the largest rate)"
    )


def accept_at_rate(setup: PhysicalSetup, s: float) -> tuple[Design, PhysicalOutcome, Any]:
    """The body at rate ``s`` with the design's acceptance before the forward check: both
    stages, the limits recomputed from the written parts, and the balance under gravity.

    Returns
    -------
    design : Design
    outcome : PhysicalOutcome
    limits : chargedesign.physical.limits.LimitsReport

    Raises
    ------
    PhysicalInfeasible
        Naming the binding limit (stage ``balance`` when the check cannot confirm the
        balance gravity asks at this rate).
    SolverError
        The body fails its own limits check.
    """
    outcome = design_at_rate(setup, s)
    design = build_design(setup, outcome)
    limits = check_limits(design)
    if not limits.parts_within_limits:
        raise SolverError("physical design failed its own limits check: " + limits.violations[0])
    balance = balance_bound(design)
    if balance is not None:
        design.balance = balance.to_dict()
        if not balance.confirmed:
            raise PhysicalInfeasible(
                Binding(
                    "balance",
                    f"{balance.text()}; rates are accepted from s ="
                    f" {fmt(balance.lowest_rate, PRECISE)} up",
                    "centre of mass",
                    balance.held / balance.needed if balance.needed > 0 else math.inf,
                )
            )
    return design, outcome, limits
