"""`chargedesign check DESIGN`: JSON keys, human output, exit codes 0 / 1 / 2."""

from __future__ import annotations

import copy
import json
from pathlib import Path

import numpy as np
import pytest
from test_check import sound_design

from chargedesign.body import Design, write_design
from chargedesign.cli import main


@pytest.fixture(scope="module")
def designs(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    root = tmp_path_factory.mktemp("designs")
    sound, _ = sound_design()
    broken: Design = copy.deepcopy(sound)
    broken.charge_values[0] *= -1.0
    paths = {"sound": root / "sound.json", "broken": root / "broken.json"}
    write_design(sound, paths["sound"])
    write_design(broken, paths["broken"])
    return paths


def test_json_output_and_exit_zero(designs: dict[str, Path], capsys) -> None:
    code = main(
        ["check", str(designs["sound"]), "--json", "--orientations", "200", "--tol", "1e-11"]
    )
    assert code == 0
    data = json.loads(capsys.readouterr().out)
    assert list(data)[:3] == ["mu_rel_err", "V_rel_err", "inertia_rel_err"]
    for key in ("gyroscopic_torque_rel_err", "potential_torque_rel_err"):
        assert data[key] <= 1e-11
    assert data["passed"] is True and data["tol"] == 1e-11 and data["n_orientations"] == 200
    assert data["quantities"]["mu"]["claimed"] is True
    assert len(data["quantities"]["V"]["worst_gamma"]) == 3


def test_failed_check_exits_one_and_names_the_failures(designs: dict[str, Path], capsys) -> None:
    assert main(["check", str(designs["broken"]), "--orientations", "100"]) == 1
    out = capsys.readouterr().out
    assert "theorem NOT reproduced: mu" in out and "FAILED" not in out
    assert main(["check", str(designs["broken"]), "--json", "--orientations", "100"]) == 1
    data = json.loads(capsys.readouterr().out)
    assert data["passed"] is False and "mu" in data["failures"]
    assert data["mu_rel_err"] > 1e-6


def test_human_output(designs: dict[str, Path], capsys) -> None:
    assert main(["check", str(designs["sound"]), "--orientations", "100"]) == 0
    out = capsys.readouterr().out
    assert "theorem reproduced" in out and "PASSED" not in out
    assert out.strip().endswith("the check agrees")
    assert "verdict (recomputed from the written parts): not checked for buildability" in out
    for word in ("mu", "gyroscopic_torque", "potential_torque", "lorentz", "magnetization"):
        assert word in out


def test_loose_tolerance_lets_the_broken_design_pass(designs: dict[str, Path], capsys) -> None:
    assert main(["check", str(designs["broken"]), "--tol", "10", "--orientations", "50"]) == 0


@pytest.mark.parametrize(
    "extra",
    [
        ["--tol", "0"],
        ["--tol=-1e-9"],
        ["--tol", "nan"],
        ["--orientations", "0"],
        ["--seed=-3"],
        ["--quadrature-order=-1"],
        ["--precision", "quad"],
    ],
)
def test_bad_options_exit_two(designs: dict[str, Path], extra: list[str], capsys) -> None:
    assert main(["check", str(designs["sound"]), *extra]) == 2
    err = capsys.readouterr().err
    assert err.startswith("chargedesign check: error:") and len(err.strip().splitlines()) == 1


def test_bad_files_exit_two(tmp_path: Path, capsys) -> None:
    assert main(["check", str(tmp_path / "missing.json")]) == 2
    bad = tmp_path / "bad.json"
    bad.write_text("{not json")
    assert main(["check", str(bad)]) == 2
    wrong = tmp_path / "wrong.json"
    wrong.write_text(json.dumps({"parameters": {"C": 1.0}, "charges": {"positions": [[0, 0]]}}))
    assert main(["check", str(wrong)]) == 2
    body = tmp_path / "body.json"
    body.write_text(
        json.dumps({"parameters": {"C": 1.0}, "continuous": [{"kind": "charge", "shape": "cone"}]})
    )
    assert main(["check", str(body)]) == 2
    err = capsys.readouterr().err
    assert err.count("chargedesign check: error:") == 4


def test_continuous_design_file(tmp_path: Path, capsys) -> None:
    design, _ = sound_design(shell_charge=0.5, ball_inertia=0.2)
    path = tmp_path / "continuous.json"
    write_design(design, path)
    assert "continuous" in json.loads(path.read_text())
    assert main(["check", str(path), "--json", "--orientations", "100", "--tol", "1e-12"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert {b["shape"] for b in data["quadrature"]} == {"shell", "ball"}
    # an explicit too-low quadrature order breaks mu (the shell's r (r.B) r needs degree 3)
    assert main(["check", str(path), "--quadrature-order", "0", "--orientations", "50"]) == 1
    assert np.isfinite(data["V_offset"])


def test_cli_defaults_mirror_the_library() -> None:
    from chargedesign import checker as check
    from chargedesign.commands import arguments as command

    assert command.DEFAULT_TOL == check.DEFAULT_TOL
    assert command.DEFAULT_ORIENTATIONS == check.DEFAULT_ORIENTATIONS
    assert command.PRECISIONS == check.PRECISIONS


@pytest.fixture(scope="module")
def cancelling_path(tmp_path_factory: pytest.TempPathFactory) -> Path:
    from test_check import with_cancelling_stencils

    sound, _ = sound_design()
    path = tmp_path_factory.mktemp("cancelling") / "cancelling.json"
    write_design(with_cancelling_stencils(sound), path)
    return path


def test_cancelling_design_is_verified_by_default(cancelling_path: Path, capsys) -> None:
    assert main(["check", str(cancelling_path), "--orientations", "100"]) == 0
    out = capsys.readouterr().out
    assert "evaluated in double-double" in out and "theorem reproduced" in out
    assert "note: mu: verified in double-double" in out


def test_unverifiable_quantities_exit_one_with_the_reason(cancelling_path: Path, capsys) -> None:
    args = ["check", str(cancelling_path), "--orientations", "100", "--precision", "double"]
    assert main(args) == 1
    out = capsys.readouterr().out
    assert "UNVERIFIED" in out
    assert "mu: cannot be verified at tol 1e-09: contributions cancel to 1 part in" in out
    assert "theorem NOT reproduced: mu" in out
    assert main([*args, "--json"]) == 1
    data = json.loads(capsys.readouterr().out)
    assert list(data)[:3] == ["mu_rel_err", "V_rel_err", "inertia_rel_err"]
    assert data["passed"] is False and data["precision"] == "double"
    assert data["unverifiable"] == ["mu", "gyroscopic_torque", "V", "potential_torque"]
    assert data["failures"] == data["unverifiable"]
    for name in data["unverifiable"]:
        assert data["quantities"][name]["status"] == "unverifiable"
        assert data["reasons"][name].startswith("cannot be verified at tol 1e-09")
