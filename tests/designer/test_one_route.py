"""One model, one design route: a ``[case]`` scene takes the theorem's program.

Independent entries of the same physics: the theorem's scene (``[parameters]``) and the same
theorem written by hand as a ``[case]`` (its V and l as plain numbers, or with the theorem's
parameters) with the same ``[fields]``, ``[medium]``, ``[magnets]``, ``[ballast]`` and
``[body]``: the same parts (counts, positions to 1e-9 relative, masses) and the same verdict.
"""

from __future__ import annotations

import tomllib
from pathlib import Path

import numpy as np
import pytest
import sympy as sp

import chargedesign as cd
from chargedesign.errors import InputError
from chargedesign.model.catalogue import theorem_case
from chargedesign.params import Parameters
from chargedesign.report import render_report
from chargedesign.scene import scene_from_dict

EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "scenes"

#: the K = 0 example's theorem (C = 2e-5, c = 0.3, d = -0.4, n = K = 0, kappa = 64) by hand:
#: V = C kappa (2 d g1 g2 + c (g1^2 - g2^2)), l = 0, I4 = F1^2 + F2^2 on I3 = 0
CHAPLYGIN_CASE = {
    "name": "chaplygin by hand",
    "inertia": ["4.0e-5", "4.0e-5", "2.0e-5"],
    "V": "-1.024e-3*gamma1*gamma2 + 3.84e-4*(gamma1**2 - gamma2**2)",
    "l": ["0", "0", "0"],
    "integral": "(p**2 - q**2 + 19.2*gamma3**2)**2 + (2*p*q - 25.6*gamma3**2)**2",
    "level": 0,
}

#: the unit-scale theorem (C = 1, c = 0.3, d = -0.4, n = 0.7, K = 0.5, kappa = 0.9) by hand
UNIT_CASE = {
    "name": "unit scale by hand",
    "inertia": [2, 2, 1],
    "V": (
        "0.9*(-0.8*gamma1*gamma2 + 0.3*(gamma1**2 - gamma2**2)) + 0.245*gamma3**2"
        " - 0.35*gamma3*(-0.4*(gamma2**2 - gamma1**2) + 0.6*gamma1*gamma2)"
        " + 0.25*(-0.24*gamma1*gamma2*(gamma1**2 - gamma2**2)"
        " + 0.08*(gamma3**4 + 4*gamma1**2*gamma2**2)"
        " - 0.09*(gamma3**2*(gamma1**2 + gamma2**2) + 2*gamma1**2*gamma2**2))"
    ),
    "l": [
        "1.4*gamma1",
        "1.4*gamma2",
        "0.7*gamma3 + 0.5*(-0.4*(gamma2**2 - gamma1**2) + 0.6*gamma1*gamma2)",
    ],
    # the theorem's I4 at these parameters, on I3 = 0 (its printed text, from the catalogue)
    "integral": sp.sstr(
        theorem_case(Parameters(C=1.0, c=0.3, d=-0.4, n=0.7, K=0.5, kappa=0.9)).integral
    ),
    "level": 0,
}


def _twin(path: Path, case: dict) -> tuple[object, object]:
    data = tomllib.loads(path.read_text("utf-8"))
    theorem = scene_from_dict(data, str(path))
    tables = {k: v for k, v in data.items() if k not in ("parameters", "simulation")}
    return theorem, scene_from_dict({**tables, "case": case}, f"{path} as a case")


def _twin_file(path: Path, case: dict, out: Path) -> Path:
    """The ``[case]`` twin of a theorem scene as a file: its tables but ``[parameters]`` and
    ``[simulation]``, then ``[case]`` (strings, numbers and their lists written as JSON, which
    TOML reads the same)."""
    import json

    kept, skipping = [], False
    for line in path.read_text("utf-8").splitlines():
        if line.strip().startswith("["):
            skipping = line.split("#")[0].strip() in ("[parameters]", "[simulation]")
        if not skipping:
            kept.append(line)
    kept += ["", "[case]", *(f"{key} = {json.dumps(value)}" for key, value in case.items())]
    out.write_text("\n".join(kept) + "\n", "utf-8")
    return out


def _verdict(design) -> str:
    """The report's verdict line (its state and what it rests on)."""
    return next(line for line in render_report(design).splitlines() if "Verdict" in line)


def _same_parts(a, b) -> None:
    for positions, values in (
        ("charge_positions", "charge_values"),
        ("dipole_positions", "dipole_moments"),
        ("mass_positions", "mass_values"),
    ):
        pa, pb = getattr(a, positions), getattr(b, positions)
        assert pa.shape == pb.shape, positions
        scale = max(float(np.max(np.abs(pa), initial=0.0)), 1e-300)
        assert np.allclose(pa, pb, rtol=0, atol=1e-9 * scale), positions
        va, vb = getattr(a, values), getattr(b, values)
        top = max(float(np.max(np.abs(va), initial=0.0)), 1e-300)
        assert np.allclose(va, vb, rtol=0, atol=1e-9 * top), values
    for extra in ("charge_masses", "charge_radii", "dipole_masses", "dipole_volumes"):
        xa, xb = getattr(a, extra, None), getattr(b, extra, None)
        if xa is None or xb is None:
            assert xa is None and xb is None, extra
            continue
        assert np.allclose(xa, xb, rtol=1e-9, atol=0), extra


def test_the_k0_example_as_a_case_gets_the_theorems_parts_and_verdict() -> None:
    theorem_scene, case_scene = _twin(EXAMPLES / "chaplygin_magnetic.toml", CHAPLYGIN_CASE)
    theorem = cd.design(theorem_scene)
    case = cd.design(case_scene)
    assert case.design.medium is not None and case.design.dipole_moments.shape[0] > 0
    _same_parts(theorem.design, case.design)
    assert case.design.parameters == theorem.design.parameters
    assert _verdict(case.design) == _verdict(theorem.design)
    assert case.design.frontier["s_max"] == pytest.approx(theorem.design.frontier["s_max"])
    assert case.certificate is not None and case.certificate.holds
    assert case.design.further_keys["case"]["name"] == "chaplygin by hand"
    # the theorem's scene is the catalogue's case at its parameters, certified the same way;
    # its design.json keeps the parameters as its record (no case key)
    assert theorem.certificate.name == "yehia-elmandouh" and theorem.certificate.holds
    assert theorem.certificate.independent and theorem.certificate.holds_for_all_parameters is None
    assert "case" not in theorem.design.further_keys


def test_the_unit_scale_scene_and_its_case_twin_give_the_same_body() -> None:
    theorem_scene, case_scene = _twin(EXAMPLES / "unit_scale.toml", UNIT_CASE)
    theorem = cd.design(theorem_scene)
    case = cd.design(case_scene)
    assert type(case) is type(theorem)
    _same_parts(theorem.design, case.design)
    assert case.design.parameters == theorem.design.parameters
    assert case.design.realises == theorem.design.realises
    assert case.design.forward_accuracy == theorem.design.forward_accuracy
    assert case.certificate is not None and case.certificate.holds
    # one record step: the same exact certificate of the same model, at the same numbers
    mine, twin = theorem.certificate.to_dict()["case"], case.certificate.to_dict()["case"]
    for key in ("holds", "independent", "holds_for_all_parameters", "level", "counterexample"):
        assert mine[key] == twin[key], key


def test_design_takes_a_case_scene_from_its_path(tmp_path: Path) -> None:
    text = (EXAMPLES / "kowalevski_case.toml").read_text("utf-8")
    path = tmp_path / "kowalevski.toml"
    path.write_text(text, "utf-8")
    result = cd.design(str(path))
    assert isinstance(result, cd.DesignResult)
    assert result.certificate.holds and len(result.design.mass_values) > 0


@pytest.mark.parametrize(
    ("argv", "option"),
    [
        (["--max-charge", "1e-15"], "max_charge"),
        (["--total-mass", "1.0"], "total_mass"),
        (["--solver", "SCS"], "solver"),
        (["--no-polish"], "polish"),
    ],
)
def test_an_option_the_physical_program_does_not_read_is_refused_in_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], argv: list[str], option: str
) -> None:
    """The default scene has [medium]: before any work, one line naming the option and the
    route, exit 2, nothing written (it was silently ignored: 1.87e-9 C under a 1e-15 cap)."""
    from chargedesign.cli import main

    out = tmp_path / "out"
    assert main(["design", "--out", str(out), "--quiet", *argv]) == 2
    err = capsys.readouterr().err.strip()
    assert f"design.{option}: not available with [medium]" in err and "\n" not in err
    assert not out.exists()


def test_the_tolerance_of_a_physical_scene_is_refused_through_the_api() -> None:
    with pytest.raises(InputError, match=r"design\.tol: not available with \[medium\]"):
        cd.design(EXAMPLES / "chaplygin_magnetic.toml", tol=1e-9)


def test_the_command_line_options_reach_a_case_scene(tmp_path: Path) -> None:
    """The case's point route reads the same options as the theorem's (it dropped them)."""
    import json

    from chargedesign.cli import main

    out = tmp_path / "out"
    scene = str(EXAMPLES / "kowalevski_case.toml")
    argv = ["design", scene, "--out", str(out), "--quiet", "--no-picture", "--objective", "l2"]
    assert main(argv) == 0
    data = json.loads((out / "design.json").read_text("utf-8"))
    assert data["provenance"]["options"]["objective"] == "l2"
    assert data["case"]["certificate"]["holds"] is True


def _default_as_a_case() -> tuple[object, object]:
    """The default scene (n != 0, [medium], frame reading) and its twin: the theorem at the
    default parameters as a hand-written ``[case]`` (exact text of the catalogue's entry)."""
    from chargedesign.scene.load import default_scene_text

    data = tomllib.loads(default_scene_text())
    given = data["parameters"]
    params = Parameters(**{("lam" if k == "lambda" else k): v for k, v in given.items()})
    case = theorem_case(params)
    table = {
        "name": "default by hand",
        "inertia": [sp.sstr(x) for x in case.inertia],
        "V": sp.sstr(case.V),
        "l": [sp.sstr(x) for x in case.l],
        "integral": sp.sstr(case.integral),
        "level": 0,
    }
    tables = {k: v for k, v in data.items() if k not in ("parameters", "simulation")}
    theorem = scene_from_dict(data, "default")
    return theorem, scene_from_dict({**tables, "case": table}, "default as a case")


def test_a_case_of_the_theorems_form_with_n_is_checked_in_its_bodys_own_axes() -> None:
    """With [medium] the frame reading builds the n = 0 body; the forward check compares it
    with the case read in axes turning at -n (``case_numeric.body_case``), not with the case's
    own n (the body missed it by mu 1, V 0.32 and the design was refused)."""
    from chargedesign.checker import check_design
    from chargedesign.designer.pipeline import design_from_scene

    theorem_scene, case_scene = _default_as_a_case()
    theorem = design_from_scene(theorem_scene, frontier=False).design
    case = design_from_scene(case_scene, frontier=False).design
    assert case.larmor.is_frame and case.larmor.rate == theorem.larmor.rate > 0
    _same_parts(theorem, case)
    report = check_design(case)
    assert report.reference == "case" and report.passed, report.failures
    assert report.verdict["state"] == theorem.verdict["state"] == case.verdict["state"]


def test_the_body_case_of_a_frame_reading_is_the_theorem_at_n_zero() -> None:
    """Exact: the default theorem's case read in axes turning at -n is its n = 0 case (V up
    to a constant on the sphere, the same l)."""
    from dataclasses import replace

    from chargedesign.model.frame import frame_reading

    params = Parameters(C=2.0e-5, c=0.3, d=-0.4, n=2.45e-6, K=1.75e-6, kappa=1.1025e-11)
    read = frame_reading(theorem_case(params), -params.n)
    plain = theorem_case(replace(params, n=0.0))
    from chargedesign.model.case import GAMMA

    g1, g2, g3 = GAMMA
    _, difference = sp.reduced(sp.expand(read.V - plain.V), [g1**2 + g2**2 + g3**2 - 1])
    assert difference.free_symbols == set()
    assert all(sp.expand(a - b) == 0 for a, b in zip(read.l, plain.l, strict=True))


def test_a_model_is_certified_once_per_process() -> None:
    """The theorem's scene as a case (the catalogue's entry at its parameters, at their values:
    no "for all parameters" step, as its twin written in numbers has none) is certified once:
    a second design of the same model reuses the exact certificate."""
    from chargedesign.designer.case_design import model_certificate, theorem_model

    params = Parameters(C=2e-5, c=0.3, d=-0.4, kappa=64.0)
    case = theorem_model(params)
    assert case.free == {} and case.parameters["kappa"] == 64
    first = model_certificate(case)
    assert first.holds and first.holds_for_all_parameters is None
    assert model_certificate(theorem_model(params)) is first


def test_a_theorem_scene_whose_case_the_catalogue_refuses_keeps_its_body() -> None:
    """c = 1e-35 is a valid theorem parameter and outside a case file's range (1e-30): the
    record step notes that the certificate was not made, and raises nothing."""
    from chargedesign.body import Design
    from chargedesign.designer.case_design import theorem_certificate

    params = Parameters(C=1.0, c=1e-35, d=0.5, kappa=1.0)
    design = Design(params, charge_positions=[[0.1, 0.0, 0.0]], charge_values=[1.0])
    assert theorem_certificate(design, params) is None
    assert any("certificate was not made" in note and "1e-35" in note for note in design.notes)
    assert "case" not in design.further_keys


def _fields(certificate) -> dict:
    """The certificate's record without its seconds."""
    record = certificate.to_dict()["case"]
    record.pop("seconds")
    return record


def test_the_theorem_scenes_certificate_is_made_when_first_read() -> None:
    """The theorem's scene defers its certificate (no output of design or frontier prints it):
    read, it is the one route's (record_case of the catalogue's case at the parameters), field
    for field; the deferred result pickles (a sweep's process pool) and is read there too."""
    import pickle

    from chargedesign.designer.case_design import theorem_model
    from chargedesign.model.case_file import certify_case

    scene = scene_from_dict(
        tomllib.loads((EXAMPLES / "unit_scale.toml").read_text("utf-8")), "unit_scale"
    )
    result = cd.design(scene)
    assert result.certificate_of is not None  # not made by the design
    copy = pickle.loads(pickle.dumps(result))
    fresh = certify_case(theorem_model(scene.parameters))
    assert _fields(result.certificate) == _fields(fresh)
    assert result.certificate_of is None and result.certificate is result.certificate
    assert _fields(copy.certificate) == _fields(fresh)


def test_a_refused_theorem_case_notes_it_when_its_certificate_is_read() -> None:
    """A scene's reader refuses c = 1e-35 as a case file's does; a scene made in code with it
    designs, and reading its certificate gives None and the record step's note."""
    import dataclasses

    data = tomllib.loads((EXAMPLES / "unit_scale.toml").read_text("utf-8"))
    scene = scene_from_dict(data, "unit_scale")
    params = dataclasses.replace(scene.parameters, c=1e-35)
    result = cd.design(dataclasses.replace(scene, parameters=params))
    assert not any("certificate was not made" in note for note in result.design.notes or [])
    assert result.certificate is None
    assert any("certificate was not made" in n and "1e-35" in n for n in result.design.notes)


def test_a_case_scenes_certificate_is_deferred_and_written_into_its_record() -> None:
    """A ``[case]`` scene defers its certificate as the theorem's scene does: the design
    leaves the case record's verdict None; reading the certificate (or the body through
    ``recorded_design``, as every writer takes it) writes the verdict there, the one that
    record_case then case_certificate make, key order kept."""
    import copy
    import pickle

    from chargedesign.designer.case_design import case_certificate, record_case

    theorem_scene, case_scene = _twin(EXAMPLES / "unit_scale.toml", UNIT_CASE)
    deferred = cd.design(case_scene)
    assert deferred.certificate_of is not None and deferred.certificate_recorded
    assert deferred.design.further_keys["case"]["certificate"] is None
    copied = pickle.loads(pickle.dumps(deferred))  # a sweep's process pool
    body = copied.recorded_design()
    assert copied.certificate_of is None and body.further_keys["case"]["certificate"]["holds"]
    design = copy.deepcopy(deferred.design)
    design.further_keys.pop("case")
    table, case = case_scene.tables["case"], case_scene.case
    record_case(design, case, table, theorem_scene.parameters)
    assert design.further_keys["case"]["certificate"] is None
    certificate = case_certificate(design, case)
    assert _fields(certificate) == _fields(copied.certificate)
    made, recorded = design.further_keys["case"], body.further_keys["case"]
    assert list(made) == list(recorded)  # design.json's key order kept
    for record in (made, recorded):
        record["certificate"].pop("seconds")
    assert made == recorded


def test_every_writer_of_a_case_body_writes_its_certificate(tmp_path: Path) -> None:
    """The design command, a sweep's design and the API's ``to_dict`` make the deferred
    certificate before they write: design.json's ``case.certificate`` holds."""
    import json

    from chargedesign.cli import main
    from chargedesign.sweeps.registry import run_design

    _, case_scene = _twin(EXAMPLES / "unit_scale.toml", UNIT_CASE)
    path = _twin_file(EXAMPLES / "unit_scale.toml", UNIT_CASE, tmp_path / "case.toml")
    out = tmp_path / "out"
    assert main(["design", str(path), "--out", str(out), "--no-picture", "--quiet"]) == 0
    written = json.loads((tmp_path / "out" / "design.json").read_text("utf-8"))
    assert written["case"]["certificate"]["holds"]
    assert "holds exactly" in (tmp_path / "out" / "report.md").read_text("utf-8")
    point = tmp_path / "point"
    point.mkdir()
    run_design(case_scene, point)
    swept = json.loads((point / "design.json").read_text("utf-8"))
    assert swept["case"]["certificate"]["holds"]
    assert cd.design(case_scene).to_dict()["design"]["case"]["certificate"]["holds"]
