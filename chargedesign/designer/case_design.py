"""``chargedesign design CASE_SCENE.toml``: a scene's ``[case]`` designed as point masses.

A case whose ``l`` is zero and whose ``V`` is a polynomial of degree at most 2 in gamma (the
heavy tops: Euler, Lagrange, Kowalevski, Goriachev-Chaplygin; Clebsch in a gravity gradient)
is realised by masses in gravity (:func:`chargedesign.designer.case_masses.design_case_masses`).
This module takes the scene's ``[body]`` region as candidates and its ``[fields.gravity]``
uniform part as g, refuses in one line what masses cannot realise (before any work), runs the
case's exact certificate, and returns the body as a :class:`~chargedesign.body.Design` whose
design.json carries the case (``case``: :func:`chargedesign.model.case_numeric.case_record`)
so that ``check`` and ``simulate`` compare with the case's own V, inertia and integral.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from chargedesign.body import Design
from chargedesign.candidates import candidates_from_table
from chargedesign.designer.case_elements import (
    TORQUE_SAMPLES,
    CaseElementBody,
    design_case_elements,
)
from chargedesign.designer.case_masses import CaseMassBody, design_case_masses, mass_conditions
from chargedesign.errors import InfeasibleError, InputError
from chargedesign.model.case_file import CaseCertificate, certify_case
from chargedesign.model.case_numeric import case_functions, case_record
from chargedesign.moment_conditions import LinearConditions, scene_length
from chargedesign.moment_conditions.case import derive_case_conditions
from chargedesign.params import Parameters
from chargedesign.physical.realism import case_realism_budget
from chargedesign.physical.window import case_realised_window
from chargedesign.results import Result
from chargedesign.scene import Scene, case_refusals


def case_gravity(scene: Scene) -> float:
    """The uniform gravity g (m/s^2) a case scene designs in: ``[fields.gravity]``'s first
    Legendre coefficient, else standard gravity. A gravity gradient is derived from the case
    (:func:`chargedesign.designer.case_masses.gradient_strength`), so a scene may not give one;
    electric and magnetic fields act on no mass and are refused."""
    return case_refusals.case_gravity(scene.fields)


def case_conditions(scene: Scene) -> LinearConditions:
    """The linear conditions of a scene's ``[case]``: the masses' in gravity when masses
    alone realise it, else the charges', dipoles' and masses' of the conditions engine (one-line
    refusal of what no supported field realises): what ``chargedesign conditions CASE_SCENE``
    prints."""
    if scene.case is None:
        raise ValueError(f"{scene.source}: no [case] table")  # callers route [case] scenes only
    if masses_realise(scene):
        return mass_conditions(scene.case, case_gravity(scene))
    given = {kind: tuple(v) for kind, v in scene.fields.items()}
    length, _ = scene_length(scene)
    return derive_case_conditions(scene.case, given or None, length=length)


def realism_lines(design: Design) -> list[str]:
    """The report's lines of a case design's realism budget and realised window (none when
    the record has neither)."""
    record = design.further_keys["case"]
    budget, window = record.get("realism"), record.get("realised")
    if budget and budget["term_key"] is None:
        return ["- realism: the case realises no force (V and mu constant): no term to hold"]
    if not budget or not window:
        return []
    items = ", ".join(
        f"{key} {item['value']:.1e} ({item['verdict']})"
        for key, item in budget["items"].items()
        if item["value"] is not None
    )
    span = (
        "empty"
        if window["s_low"] is None
        else f"s = {window['s_low']:.3g} .. {window['s_high']:.3g}"
    )
    return [
        f"- realism at the typical rate {budget['rate_rad_s']:.3g} rad/s, over the smallest "
        f"term ({budget['term_key']}, {budget['term_N_m']:.3g} N m): {items}",
        f"- realised window (each parasitic below {window['fraction']:g} of it): {span}; "
        f"below: {window['binding_low']}; above: {window['binding_high']}",
    ]


@dataclass(repr=False)
class CaseBodyResult(Result):
    """A body designed for a case of (ep), with its certificate: what the two kinds of case
    body (masses; charges, dipoles and masses) share."""

    design: Design
    body: Any
    certificate: CaseCertificate

    def to_dict(self) -> dict[str, Any]:
        return {
            "case": self.design.further_keys["case"],
            "body": self.body.to_dict(),
            "realises": list(self.design.realises),
        }

    def _summary(self) -> dict[str, Any]:
        return {
            "case": self.body.name,
            "integral_holds": self.certificate.holds,
            **{k: v for k, v in self.body._summary().items() if k != "name"},
        }


@dataclass(repr=False)
class CaseDesignResult(CaseBodyResult):
    """A case of (ep) designed as point masses, with its certificate.

    Attributes
    ----------
    design : Design
        The body (design.json: masses, ``fields.gravity``, ``realises`` V and inertia, and the
        ``case`` record).
    body : CaseMassBody
        The masses with the inertia and linear potential recomputed from them.
    certificate : CaseCertificate
        The exact certificate of the case's claimed integral.
    """

    design: Design
    body: CaseMassBody
    certificate: CaseCertificate

    def _text(self) -> str:
        body = self.body
        gravity = ", ".join(f"{x:g}" for x in body.gravity)
        certificate = self.certificate
        verdict = "holds" if certificate.holds else "does NOT hold"
        diagonal = ", ".join(f"{x:.10g}" for x in np.diag(body.inertia))
        product = float(np.max(np.abs(body.inertia - np.diag(np.diag(body.inertia)))))
        linear = ", ".join(f"{x:.10g}" for x in body.potential)
        level = "general" if certificate.level == "general" else f"on I3 = {certificate.level}"
        lines = [
            f"# Case {body.name}: a body of point masses",
            "",
            f"Realises the case's V (up to a constant) and its inertia about O, as "
            f"{len(body.masses)} masses ({body.masses.sum():.6g} kg in all) in gravity "
            f"legendre = [{gravity}].",
            "",
            f"- inertia recomputed from the masses: diag({diagonal}) kg m^2, largest product "
            f"{product:.1e}; relative error {body.inertia_rel_err:.1e}",
            f"- f1 M x_cm = ({linear}) J, the case's linear part of V; relative error "
            f"{body.potential_err:.1e}",
            f"- the claimed integral {verdict} exactly ({level}; independent: "
            f"{'yes' if certificate.independent else 'NO'}; {certificate.seconds:.2f} s)",
            "- not realised: nothing else is claimed (l = 0: no gyroscopic forces are needed)",
            *realism_lines(self.design),
        ]
        return "\n".join(lines) + "\n"


def record_realism(design: Design, case: Any) -> None:
    """Add the realism budget and the realised window of a case body (point elements, at the
    case's typical rate) to its design.json ``case`` record (``realism``, ``realised``)."""
    budget = case_realism_budget(design, case_functions(case))
    design.further_keys["case"]["realism"] = budget
    if budget["term_key"] is None:
        design.further_keys["case"]["realised"] = None
        return
    window = case_realised_window(design, budget)
    design.further_keys["case"]["realised"] = {
        "s_low": window.s_low,
        "s_high": window.s_high,
        "binding_low": window.binding_low,
        "binding_high": window.binding_high,
        "fraction": window.fraction,
        "notes": list(window.notes),
    }


def _count(number: int, one: str, many: str | None = None) -> str:
    return f"{number} {one if number == 1 else many or one + 's'}"


def masses_realise(scene: Scene) -> bool:
    """Whether masses in gravity alone realise the scene's case (l = 0, V of degree <= 2 with
    its quadratic part the inertia's, only ``[fields.gravity]`` given): the masses' path.
    Any other case goes to charges, dipoles and masses (:func:`design_case_elements_scene`)."""
    if scene.case is None:
        return False
    try:
        mass_conditions(scene.case, case_gravity(scene))
    except InputError:
        return False
    except InfeasibleError:
        return True  # the masses' own refusal (a broken triangle inequality) is the reason
    return True


def _region_candidates(scene: Scene) -> Any:
    case_refusals.require_region(scene.source, scene.region is not None, "elements")
    assert scene.region is not None
    return candidates_from_table(scene.region.table, base_dir=scene.base_dir)


@dataclass(repr=False)
class CaseElementsResult(CaseBodyResult):
    """A case of (ep) designed as charges, dipoles and masses, with its certificate."""

    design: Design
    body: CaseElementBody
    certificate: CaseCertificate

    def _text(self) -> str:
        body = self.body
        certificate = self.certificate
        verdict = "holds" if certificate.holds else "does NOT hold"
        level = "general" if certificate.level == "general" else f"on I3 = {certificate.level}"
        fields = "; ".join(
            f"{kind} legendre = [{', '.join(f'{x:g}' for x in v)}]"
            for kind, v in body.fields.items()
        )
        diagonal = ", ".join(f"{x:.10g}" for x in np.diag(body.inertia))
        lines = [
            f"# Case {body.name}: a body of charges, dipoles and masses",
            "",
            f"Realises the case's {', '.join(self.design.realises)} as "
            f"{_count(len(body.charge_values), 'charge')}, "
            f"{_count(len(body.dipole_moments), 'dipole')} and "
            f"{_count(len(body.mass_values), 'mass', 'masses')} in the fields: "
            f"{fields or 'none'}.",
            "",
            f"- inertia recomputed from the masses: diag({diagonal}) kg m^2; relative error "
            f"{body.inertia_rel_err:.1e}",
            f"- torque of every element in its field against the case's gamma x dV/dgamma - "
            f"omega x mu at {TORQUE_SAMPLES} states: relative error {body.torque_rel_err:.1e}",
            f"- the claimed integral {verdict} exactly ({level}; independent: "
            f"{'yes' if certificate.independent else 'NO'}; {certificate.seconds:.2f} s)",
            f"- the charges' l . gamma is the case's plus {body.level_offset:.6g} kg m^2/s "
            f"(a constant: spread {body.level_spread:.1e})"
            + (
                f"; the case's level I3 = {certificate.level} is the body's I3 = "
                f"{float(certificate.level) + body.level_offset:.6g}"
                if certificate.level != "general"
                else ""
            ),
            *realism_lines(self.design),
            "",
            "Choices of the conditions engine:",
            "",
            *[f"- {note}" for note in body.conditions.notes],
        ]
        return "\n".join(lines) + "\n"


def design_case_elements_scene(scene: Scene, say: Callable[[str], None]) -> CaseElementsResult:
    """A scene's case that masses alone do not realise, as charges, dipoles and masses in the
    scene's fields (given) and the fields the conditions engine derives (one-line refusal of a
    singular term, a degree above 4, a constant mu, before any design work)."""
    case = scene.case
    if case is None:
        raise ValueError(f"{scene.source}: no [case] table to design")  # callers route cases only
    given = {kind: tuple(v) for kind, v in scene.fields.items()}
    candidates = _region_candidates(scene)
    length = float(np.max(np.linalg.norm(candidates.points, axis=1)))
    # the refusals (singular, degree, constant mu, fields) come here, before any work
    conditions = derive_case_conditions(case, given or None, length=length)
    say(f"certificate of the case {case.name} (exact) ...")
    certificate = certify_case(case)
    say(f"charges, dipoles and masses on {len(candidates)} candidates ...")
    body = design_case_elements(case, candidates, given, scene.design, conditions=conditions)
    design = Design(
        parameters=Parameters.from_mapping({"C": float(case.inertia[2])}, "case.inertia[2]"),
        fields=body.fields,
        charge_positions=body.charge_positions,
        charge_values=body.charge_values,
        dipole_positions=body.dipole_positions,
        dipole_moments=body.dipole_moments,
        mass_positions=body.mass_positions,
        mass_values=body.mass_values,
        realises=list(body.conditions.realise),
        notes=list(body.conditions.notes),
        residuals={
            "inertia_rel_err": body.inertia_rel_err,
            "torque_rel_err": body.torque_rel_err,
        },
        further_keys={"case": case_record(scene.tables["case"], case, certificate)},
    )
    design.further_keys["case"]["level_offset"] = body.level_offset
    design.further_keys["case"]["level_spread"] = body.level_spread
    record_realism(design, case)
    return CaseElementsResult(design=design, body=body, certificate=certificate)


def design_case_scene(
    scene: Scene, progress: Callable[[str], None] | None = None
) -> CaseDesignResult | CaseElementsResult:
    """Design the ``[case]`` of ``scene`` as point masses on its ``[body]`` region.

    Raises
    ------
    InputError
        The scene has no ``[case]`` or no ``[body]`` region, or the case is not one masses in
        gravity realise (non-zero l, singular terms, degree > 2 in gamma, a quadratic V not of
        the inertia's second moments): one line with the reason, before any work.
    InfeasibleError, SolverError
    """
    say = progress or (lambda message: None)
    case = scene.case
    if case is None:
        raise ValueError(f"{scene.source}: no [case] table to design")  # callers route cases only
    if not masses_realise(scene):
        return design_case_elements_scene(scene, say)
    g = case_gravity(scene)
    mass_conditions(case, g)  # refuses what masses cannot realise, before any work
    case_refusals.require_region(scene.source, scene.region is not None, "masses")
    assert scene.region is not None
    candidates = candidates_from_table(scene.region.table, base_dir=scene.base_dir)
    say(f"certificate of the case {case.name} (exact) ...")
    certificate = certify_case(case)
    say(f"masses on {len(candidates)} candidates ...")
    body = design_case_masses(case, candidates, g, scene.design)
    notes = [
        f"case {case.name}: masses in gravity legendre = {list(body.gravity)} realise V (up to "
        "a constant) and the inertia diag(" + ", ".join(str(m) for m in case.inertia) + ")",
    ]
    design = Design(
        # design.json needs the theorem's parameters; a case's body is compared with the case
        # (the record below), C is the case's third moment
        parameters=Parameters.from_mapping({"C": float(case.inertia[2])}, "case.inertia[2]"),
        fields={"gravity": body.gravity},
        mass_positions=body.positions,
        mass_values=body.masses,
        realises=["V", "inertia"],
        notes=notes,
        residuals={
            "inertia_rel_err": body.inertia_rel_err,
            "potential_linear_rel_err": body.potential_err,
        },
        further_keys={"case": case_record(scene.tables["case"], case, certificate)},
    )
    record_realism(design, case)
    return CaseDesignResult(design=design, body=body, certificate=certificate)


__all__ = [
    "CaseDesignResult",
    "CaseElementsResult",
    "case_conditions",
    "case_gravity",
    "design_case_elements_scene",
    "design_case_scene",
    "masses_realise",
    "realism_lines",
    "record_realism",
]
