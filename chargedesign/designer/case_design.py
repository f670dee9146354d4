"""A scene's ``[case]`` on the one design route: its conditions and its record.

Every scene takes :func:`chargedesign.designer.pipeline.design_from_scene`. A case of the
theorem's form (:func:`chargedesign.model.catalogue.theorem_parameters`) takes the theorem's
conditions and program unchanged (points, or real parts with ``[medium]``). Any other case
takes its own conditions here (:func:`case_conditions`: masses in gravity when they alone
realise it, else the conditions engine's charges, dipoles and masses) and the same point
design. This module then records the case (:func:`record_case`): its exact certificate, the
design.json ``case`` record (so that ``check`` and ``simulate`` compare with the case's own V,
inertia and integral), the checks of a point body's elements against the case, and for a
general case its realism budget and realised window at the case's typical rate.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

from chargedesign.body import Design
from chargedesign.designer.case_elements import case_checks
from chargedesign.designer.case_masses import mass_conditions
from chargedesign.designer.result import DesignResult
from chargedesign.errors import InputError
from chargedesign.model.case_file import CaseCertificate, certify_case
from chargedesign.model.case_numeric import case_functions, case_record
from chargedesign.moment_conditions import LinearConditions, scene_length
from chargedesign.moment_conditions.case import derive_case_conditions
from chargedesign.params import Parameters
from chargedesign.physical.realism import case_realism_budget
from chargedesign.physical.window import case_realised_window
from chargedesign.scene import Scene, case_refusals

#: the one result of a design: a case scene's carries its ``certificate``
CaseDesignResult = DesignResult
CaseElementsResult = DesignResult


def case_conditions(scene: Scene, length: float | None = None) -> LinearConditions:
    """The linear conditions of a scene's ``[case]`` (:func:`conditions_of_case`; ``length``
    None: the scene's own, from its ``[body]``): what ``chargedesign conditions CASE_SCENE``
    prints."""
    if scene.case is None:
        raise ValueError(f"{scene.source}: no [case] table")  # callers route [case] scenes only
    masses = _masses_conditions(scene.case, scene.fields)
    if masses is not None:
        return masses
    if length is None:
        length, _ = scene_length(scene)
    return _engine_conditions(scene.case, scene.fields, length)


def conditions_of_case(
    case: Any, fields: Mapping[str, Sequence[float]], length: float | None
) -> LinearConditions:
    """The linear conditions of a case with the scene's fields (as the scene read them once):
    the masses' in gravity when masses alone realise it (l = 0, V of degree <= 2 with its
    quadratic part the inertia's, only ``[fields.gravity]`` given), else the charges',
    dipoles' and masses' of the conditions engine (one-line refusal of what no supported field
    realises)."""
    masses = _masses_conditions(case, fields)
    return masses if masses is not None else _engine_conditions(case, fields, length)


def _masses_conditions(case: Any, fields: Mapping[str, Sequence[float]]) -> LinearConditions | None:
    """The masses' conditions in the scene's uniform gravity (None: masses alone do not
    realise the case); the masses' own refusal (a broken triangle inequality) is raised."""
    try:
        return mass_conditions(case, case_refusals.case_gravity(fields))
    except InputError:
        return None


def _engine_conditions(
    case: Any, fields: Mapping[str, Sequence[float]], length: float | None
) -> LinearConditions:
    """The conditions engine's charges, dipoles and masses of a case."""
    given = {kind: tuple(v) for kind, v in fields.items()}
    return derive_case_conditions(case, given or None, length=length)


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


def record_case(
    design: Design,
    case: Any,
    table: Mapping[str, Any] | None,
    theorem: Parameters | None,
) -> CaseCertificate:
    """Record a case scene's body: the case's exact certificate and design.json ``case``
    (the table as written, to rebuild the case); for a general case (``theorem`` None: not
    of the theorem's form) also the checks of its point body's elements against the case
    (``case.checks``; also in ``residuals``) and its realism budget and realised window at
    the case's typical rate (``case.realism``, ``case.realised``). A case of the theorem's
    form has the theorem's body and records: its forward accuracy, and with ``[medium]`` its
    limits, realism budget and window. Returns the certificate."""
    certificate = certify_case(case)
    design.further_keys["case"] = case_record(table or {}, case, certificate)
    if design.medium is not None or theorem is not None:
        # the theorem's body: its own forward accuracy, limits, realism budget and window
        # (as the theorem's scene has them) say the rest
        return certificate
    checks = case_checks(case, design)
    record = design.further_keys["case"]
    record["checks"] = checks
    record["level_offset"] = checks["level_offset"]
    record["level_spread"] = checks["level_spread"]
    design.residuals = {
        **(design.residuals or {}),
        "inertia_rel_err": checks["inertia_rel_err"],
        "torque_rel_err": checks["torque_rel_err"],
    }
    record_realism(design, case)
    return certificate


__all__ = [
    "CaseDesignResult",
    "CaseElementsResult",
    "case_conditions",
    "conditions_of_case",
    "record_case",
    "record_realism",
]
