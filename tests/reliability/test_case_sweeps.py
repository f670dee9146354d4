"""A sweep over a ``[case]`` scene runs the case (issue 43 item 4): with the Kowalevski
example as the scene and a grid on ``case.V``, ``case.parameters.a`` or ``body.spacing``,
``sweep --executor serial`` exited 0 and every point's design.json was the theorem's default
body (C = 1, three masses, no case record), because the sweep's ``design`` took the
theorem's route only. Every point's case is now read by the case loader before any point
runs, and a point ``design`` would refuse (a degree-5 V) is refused with its values."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from case_scene import case_scene
from reliability_support import refused, run_cli


def _sweep(folder: Path, grid: str) -> Path:
    case_scene(folder, "scene.toml")
    path = folder / "case.sweep"
    path.write_text(f'command = "design"\nscene = "scene.toml"\n[grid]\n{grid}\n')
    return path


@pytest.mark.parametrize(
    ("grid", "check"),
    [
        ('"case.parameters.a" = [2.0, 3.0]', lambda table, i: table["parameters"]["a"] == 2.0 + i),
        ('"case.V" = ["C*a*gamma1", "2*C*a*gamma1"]', lambda table, i: "gamma1" in table["V"]),
        ('"body.spacing" = [0.125, 0.25]', lambda table, i: table["parameters"]["C"] == 0.3),
    ],
)
def test_a_sweep_of_design_over_a_case_scene_writes_case_designs(
    grid: str, check, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    sweep = _sweep(tmp_path, grid)
    out = tmp_path / "out"
    code, _, err = run_cli(["sweep", str(sweep), "--out", str(out), "--executor", "serial"], capsys)
    assert code == 0, err
    for i in range(2):
        point = out / "points" / f"p{i:04d}"
        result = json.loads((point / "result.json").read_text())
        assert result["status"] == "ok", result
        design = json.loads((point / "design.json").read_text())
        assert "case" in design, design.keys()
        assert design["parameters"]["C"] == pytest.approx(0.3)
        assert check(design["case"]["table"], i)


@pytest.mark.parametrize(
    ("grid", "said"),
    [
        ('"case.V" = ["C*a*gamma1", "C*a*gamma1**5"]', "of degree 5 in gamma"),
        ('"case.V" = ["C*a*gamma1", "C*a*gamma1/z"]', "not a state variable"),
        ('"case.V" = ["C*a*gamma1", "1e99999999*gamma1"]', "exponent"),
        ('"case.parameters.a" = [2.5, "0e99999999"]', "case.parameters.a"),
    ],
)
def test_a_case_point_design_refuses_is_refused_before_any_point_runs(
    grid: str, said: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    sweep = _sweep(tmp_path, grid)
    argv = ["sweep", str(sweep), "--out", str(tmp_path / "out"), "--executor", "serial"]
    line = refused(argv, "sweep", capsys, tmp_path)
    assert said in line, line  # the point (or the swept key) named, before any point ran
