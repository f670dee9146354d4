"""bifurcation: no empty answer with exit 0 (issue 32). Energy ranges far wider or narrower
than the diagram's structure, degenerate parameters, an n whose Larmor shift swamps the
energies: each a one-line refusal before any work; a huge c gives a real diagram, with the
chambers it cannot resolve said so."""

from __future__ import annotations

from pathlib import Path

import pytest
from reliability_support import refused, run_cli

UNIT_PARAMETERS = {"C": 1.0, "c": 0.3, "d": -0.4, "n": 0.7, "K": 0.5, "kappa": 0.9}


def _scene(folder: Path, **changes: float) -> str:
    values = {**UNIT_PARAMETERS, **changes}
    lines = ["[parameters]"] + [f"{key} = {value!r}" for key, value in values.items()]
    path = folder / "scene.toml"
    path.write_text("\n".join(lines) + "\n")
    return str(path)


@pytest.mark.parametrize(("lo", "hi"), [("0", "1e30"), ("1e29", "1e30"), ("0.06", "0.0600001")])
def test_energy_range_out_of_scale_is_refused_before_the_work(tmp_path, capsys, lo, hi):
    scene = _scene(tmp_path)
    out = tmp_path / "out"
    argv = ["bifurcation", scene, "--h-range", lo, hi, "--out", str(out)]
    line = refused(argv, "bifurcation", capsys, tmp_path)
    assert "--h-range" in line and "spread of the critical energies" in line
    assert not out.exists()


def test_tori_at_an_energy_out_of_scale_is_refused(tmp_path, capsys):
    """The embedded SI scene's energies are about 1e-17 J: a count at 1 J (inside the bound
    k <= ((h - h_min)/C)^2) would integrate motions 1e8 times too fast; refused at once."""
    line = refused(["bifurcation", "--tori", "1", "1"], "bifurcation", capsys, tmp_path)
    assert "--tori: energy 1 J is over" in line


@pytest.mark.parametrize(
    "changes",
    [
        {"c": 0.0, "d": 0.0, "n": 0.0, "K": 0.0, "kappa": 0.0},  # every parameter zero but C
        {"c": 0.0, "d": 0.0, "K": 0.0, "kappa": 0.0},  # the same with n
        {"c": 0.0, "d": 0.0},
        {"K": 0.0, "kappa": 0.0},
    ],
)
def test_degenerate_parameters_are_refused(tmp_path, capsys, changes):
    scene = _scene(tmp_path, **changes)
    line = refused(
        ["bifurcation", scene, "--out", str(tmp_path / "out")], "bifurcation", capsys, tmp_path
    )
    assert "no bifurcation diagram with c = d = 0 or K = kappa = 0" in line


def test_n_whose_shift_swamps_the_energies_is_refused(tmp_path, capsys):
    scene = _scene(tmp_path, n=1e8)
    line = refused(
        ["bifurcation", scene, "--out", str(tmp_path / "out")], "bifurcation", capsys, tmp_path
    )
    assert "parameters.n" in line and "C n^2" in line


def test_tori_refusals_name_the_cause(tmp_path, capsys):
    scene = _scene(tmp_path, n=1e8)
    line = refused(["bifurcation", scene, "--tori", "1e16", "0.1"], "bifurcation", capsys, tmp_path)
    assert "parameters.n" in line
    scene = _scene(tmp_path)
    line = refused(["bifurcation", scene, "--tori", "0.96", "0"], "bifurcation", capsys, tmp_path)
    assert "critical value" in line and "degenerate k = 0" in line


def test_tori_json_is_the_contract(tmp_path, capsys):
    import json

    scene = _scene(tmp_path)
    code, out, _ = run_cli(["bifurcation", scene, "--tori", "0.2", "0.5", "--json"], capsys)
    assert code == 0
    assert json.loads(out) == {"h": 0.2, "k": 0.5, "tori": 0}  # above ((h - h_min)/C)^2


def test_huge_c_gives_branches_and_says_what_it_cannot_count():
    """c = 1e8 is the unit case's diagram rescaled ((c, d, K, kappa) -> (t c, t d, K/t,
    kappa/t) changes no term): real branches on the closed form, and chambers thinner than
    the counting resolves are printed as unresolved, not as a count (lighter options than
    the command's: the same stages)."""
    from chargedesign.params import Parameters
    from chargedesign.topology.chambers import FlowCounting, LevelSampling
    from chargedesign.topology.compute import DiagramOptions
    from chargedesign.topology.diagram import bifurcation_diagram

    params = Parameters(**{**UNIT_PARAMETERS, "c": 1e8})
    light = FlowCounting(sampling=LevelSampling(800, 32), t_end=150.0, samples=5000)
    diagram = bifurcation_diagram(params, None, DiagramOptions(seeds=150, counting=light))
    text = str(diagram)
    kinds = {kind for branch in diagram.branches for kind in branch.types}
    assert {"elliptic", "hyperbolic"} <= kinds
    assert sum(len(branch.hk) for branch in diagram.branches) > 100
    assert "unresolved" in text
