"""A scene's ``[case]`` on the one design route: its conditions and its record.

Every scene takes :func:`chargedesign.designer.pipeline.design_from_scene`. A case of the
theorem's form (:func:`chargedesign.model.catalogue.theorem_parameters`) takes the theorem's
conditions and program unchanged (points, or real parts with ``[medium]``). Any other case
takes its own conditions here (:func:`case_conditions`: masses in gravity when they alone
realise it, else the conditions engine's charges, dipoles and masses) and the same point
design. This module then records the model of every scene (:func:`record_case`): the theorem's
scene is the catalogue's case built from its parameters (:func:`theorem_model`), so every body
carries the exact certificate of the model it realises, at the body's own numbers; a ``[case]``
scene adds the design.json ``case`` record (so that ``check`` and ``simulate`` compare with the
case's own V, inertia and integral), the checks of a point body's elements against the case,
and for a general case its realism budget and realised window at the case's typical rate.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from typing import Any

from chargedesign.body import Design
from chargedesign.designer.case_elements import case_checks
from chargedesign.designer.case_masses import mass_conditions
from chargedesign.designer.result import DesignResult
from chargedesign.errors import InputError
from chargedesign.model.case_file import CaseCertificate, certify_case
from chargedesign.model.case_numeric import case_functions, case_record, certificate_verdict
from chargedesign.model.catalogue import THEOREM_NAME, theorem_case
from chargedesign.moment_conditions import LinearConditions, scene_length
from chargedesign.moment_conditions.case import derive_case_conditions
from chargedesign.params import Parameters
from chargedesign.physical.realism import case_realism_budget
from chargedesign.physical.window import case_realised_window
from chargedesign.scene import Scene, case_refusals
from chargedesign.scene.case_file import Case

#: the one result of a design: a case scene's carries its ``certificate``
CaseDesignResult = DesignResult


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


#: certificates already made in this process, by the case's exact content (a sweep or a test
#: session designs the same model many times; the certificate is exact, so it is reused)
_CERTIFIED: dict[tuple[Any, ...], CaseCertificate] = {}
#: most certificates kept
MAX_CERTIFIED = 16


def theorem_model(params: Parameters) -> Case:
    """The theorem's scene as a case of (ep): the catalogue's entry built from the scene's
    parameters (:func:`chargedesign.model.catalogue.theorem_case`), at their values: its
    certificate is the claim at the body's own numbers, as its ``[case]`` twin's is (the
    theorem for all parameters is ``chargedesign verify``'s)."""
    return theorem_case(params).at_values()


def model_certificate(case: Case) -> CaseCertificate:
    """The exact certificate of ``case`` (:func:`chargedesign.model.case_file.certify_case`),
    made once per process for the same exact case."""
    key = (
        case.name,
        tuple(case.inertia),
        case.V,
        None if case.l is None else tuple(case.l),
        tuple(case.mu),
        case.integral,
        case.level,
        bool(case.free),
    )
    certificate = _CERTIFIED.get(key)
    if certificate is None:
        certificate = certify_case(case)
        if len(_CERTIFIED) >= MAX_CERTIFIED:
            _CERTIFIED.pop(next(iter(_CERTIFIED)))
        _CERTIFIED[key] = certificate
    return certificate


def theorem_certificate(
    design: Design, theorem: Parameters, progress: Callable[[str], None] | None = None
) -> CaseCertificate | None:
    """The theorem's scene's certificate (:func:`theorem_model`); design.json's parameters are
    its record (they rebuild the case). The theorem's scene whose case the catalogue's bounds
    refuse (a parameter outside the supported range of a case file, or a certificate beyond its
    work limit) keeps its body: the certificate is None and a note says why (the theorem holds
    for all parameters: ``chargedesign verify``)."""
    if progress is not None:
        progress(f"certificate of the case {THEOREM_NAME} (exact) ...")
    try:
        return model_certificate(theorem_model(theorem))
    except InputError as exc:
        design.notes = [*(design.notes or []), f"the model's exact certificate was not made: {exc}"]
        return None


def case_certificate(
    design: Design, case: Case, progress: Callable[[str], None] | None = None
) -> CaseCertificate:
    """A ``[case]`` scene's certificate (:func:`model_certificate`), its verdict written into
    the body's design.json ``case`` record (``case.certificate``): the ``[case]`` scene's
    :func:`theorem_certificate`, one call that can be made when the certificate is read."""
    if progress is not None:
        progress(f"certificate of the case {case.name} (exact) ...")
    certificate = model_certificate(case)
    record = design.further_keys.get("case")
    if isinstance(record, dict):
        record["certificate"] = certificate_verdict(certificate)
    return certificate


def record_case(
    design: Design, case: Any, table: Mapping[str, Any] | None, theorem: Parameters | None
) -> None:
    """Record the model a ``[case]`` scene's body realises: with ``table`` (the ``[case]`` as
    written) design.json ``case`` (to rebuild the case), its ``certificate`` None until
    :func:`case_certificate` makes it (the pipeline defers it, as the theorem's scene's
    :func:`theorem_certificate`). For a general case (``theorem`` None: not of the theorem's
    form) also the checks of its point body's elements against the case (``case.checks``;
    also in ``residuals``) and its realism budget and realised window at the case's typical
    rate (``case.realism``, ``case.realised``). A case of the theorem's form has the theorem's
    body and records: its forward accuracy, and with ``[medium]`` its limits, realism budget
    and window."""
    if table is not None and "case" not in design.further_keys:
        # a general case's physical body carries it already, made once by its setup
        design.further_keys["case"] = case_record(table, case, None)
    if table is None or design.medium is not None or theorem is not None:
        # the theorem's body: its own forward accuracy, limits, realism budget and window
        # (as the theorem's scene has them) say the rest; a general case's real parts: the
        # forward check against the case (every part's own inertia counted, as `check`
        # does), its limits and its physical realism budget (at the case's own rate)
        return
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


__all__ = [
    "CaseDesignResult",
    "case_certificate",
    "case_conditions",
    "conditions_of_case",
    "model_certificate",
    "record_case",
    "record_realism",
    "theorem_certificate",
    "theorem_model",
]
