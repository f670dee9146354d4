"""The workbench at the top level: ``cd.verify_case``, ``cd.catalogue`` and ``cd.design`` of a
scene with ``[case]``, each a result of the one protocol (to_dict, str, repr, HTML)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

import chargedesign as cd
from chargedesign.results import REPR_LIMIT

KOWALEVSKI = {
    "name": "kowalevski-api",
    "inertia": [2, 2, 1],
    "V": "a*gamma1",
    "integral": "(p**2 - q**2 - a*gamma1)**2 + (2*p*q - a*gamma2)**2",
    "parameters": {"a": 0.5},
}


def _protocol(result: object) -> dict:
    data = json.loads(json.dumps(result.to_dict(), allow_nan=False))  # type: ignore[attr-defined]
    text = str(result)
    assert text and text != repr(result)
    assert "\n" not in repr(result) and len(repr(result)) <= REPR_LIMIT
    assert result._repr_html_().startswith("<")  # type: ignore[attr-defined]
    return data


def test_verify_case_of_a_mapping_and_a_refuted_claim() -> None:
    certificate = cd.verify_case({"case": KOWALEVSKI})
    assert isinstance(certificate, cd.CaseCertificate)
    assert certificate.holds and certificate.independent
    assert _protocol(certificate)["case"]["name"] == "kowalevski-api"
    wrong = dict(KOWALEVSKI, integral="(p**2 - q**2 - 2*a*gamma1)**2 + (2*p*q - a*gamma2)**2")
    refuted = cd.verify_case(wrong)
    assert not refuted.holds and refuted.counterexample is not None
    with pytest.raises(cd.InputError, match="verify_case: expected"):
        cd.verify_case(3)


def test_catalogue_certifies_every_case() -> None:
    report = cd.catalogue()
    assert isinstance(report, cd.CatalogueReport) and report.holds
    names = [case["name"] for case in _protocol(report)["cases"]]
    assert {"kowalevski", "lagrange", "clebsch", "yehia-elmandouh"} <= set(names)


def test_design_of_a_case_scene_is_masses_checked_and_simulated(tmp_path: Path) -> None:
    scene = {"case": KOWALEVSKI, "body": {"shape": "ball", "radius": 0.5, "spacing": 0.125}}
    result = cd.design(scene)
    assert isinstance(result, cd.DesignResult) and result.certificate.holds
    data = _protocol(result)
    assert data["realises"] == ["V", "inertia"] and data["design"]["case"]["certificate"]["holds"]
    residuals = result.design.residuals
    assert residuals["inertia_rel_err"] <= 1e-12 and residuals["torque_rel_err"] <= 1e-12
    assert cd.check(result, n_orientations=40).passed
    motion = cd.simulate(result, t_end=2.0)
    assert motion.summary()["F_rel_drift"] <= 1e-12
    # the one route honours the design options of a case scene too
    l2 = cd.design(scene, objective="l2")
    assert l2.design.provenance["options"]["objective"] == "l2"


def test_bifurcation_of_a_case_scene_is_the_commands_diagram(tmp_path: Path) -> None:
    """``cd.bifurcation`` of a ``[case]`` scene draws its case, not the theorem at the
    scene's stand-in parameters: the same rows as the command's bifurcation.csv."""
    from chargedesign.cli import main

    scene = Path(__file__).parents[2] / "examples" / "scenes" / "kowalevski_case.toml"
    diagram = cd.bifurcation(str(scene))
    assert isinstance(diagram, cd.CaseDiagram)
    assert _protocol(diagram)["case"] == "kowalevski-example"
    assert main(["bifurcation", str(scene), "--out", str(tmp_path), "--quiet"]) == 0
    assert diagram.csv_text() == (tmp_path / "bifurcation.csv").read_text()
