"""Each file kind the tool writes is refused by the commands meant for another, in one line
naming both kinds (``sim/summary.json is a simulation summary, not a design.json``), exit 2,
nothing written. ``simulate testbed.json`` and ``simulate summary.json`` once ran a
torque-free motion and exited 0; ``show testbed.json --screenshot`` wrote an empty picture;
``check summary.json`` said "missing key 'realises'"."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest
from reliability_support import SMALL_DESIGN, refused, run_cli

from chargedesign.readers import FILE_KINDS, csv_kind, json_kind, sniff_kind

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def files(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """One file of each kind: a real simulation summary and trajectory (a fast theorem run),
    the shipped scene, case and sweep files, and the others' documented shapes."""
    folder = tmp_path_factory.mktemp("kinds")
    scene = folder / "scene.toml"
    shutil.copy(ROOT / "examples/sweeps/theorem_scene.toml", scene)
    text = scene.read_text().replace("trajectory = false", "trajectory = true")
    scene.write_text(text)
    from chargedesign.cli import main

    assert main(["simulate", str(scene), "--out", str(folder / "sim"), "--no-progress"]) == 0
    shutil.copy(ROOT / "examples/scenes/kowalevski_case.toml", folder / "case.toml")
    shutil.copy(ROOT / "examples/sweeps/theorem_t_end.sweep", folder / "t_end.sweep")
    (folder / "design.json").write_text(json.dumps(SMALL_DESIGN))
    testbed = {
        "parameters": {"C": 0.5},
        "platform": {"mass_kg": 12.0, "com_m": [0, 0, 0]},
        "ballast": {"positions": [], "masses": []},
        "wheels": {"max_torque_N_m": 0.1},
        "control": {"rate_Hz": 200.0},
    }
    (folder / "testbed.json").write_text(json.dumps(testbed))
    (folder / "bifurcation.csv").write_text(
        "h,k,branch,type,p,q,r,gamma1,gamma2,gamma3\n0.1,0.01,0,elliptic,0,0,0,0,0,1\n"
    )
    (folder / "summary.csv").write_text("point,simulation.t_end,status,seconds\np0000,10,ok,1\n")
    (folder / "sweep.json").write_text(
        json.dumps({"format": "chargedesign.sweep/1", "points": [], "command": "simulate"})
    )
    return folder


def test_each_kind_is_recognised(files: Path) -> None:
    kinds = {
        "design.json": "design",
        "testbed.json": "testbed",
        "sim/summary.json": "simulation",
        "sim/trajectory.csv": "trajectory",
        "bifurcation.csv": "bifurcation",
        "summary.csv": "sweep",
        "sweep.json": "sweep",
        "scene.toml": "scene",
        "case.toml": "case",
        "t_end.sweep": "sweep_file",
    }
    for name, kind in kinds.items():
        assert sniff_kind(files / name) == kind, name
        assert kind in FILE_KINDS
    assert json_kind([1, 2]) is None and csv_kind("a,b") is None


WRONG_FOR_A_DESIGN = [
    ("sim/summary.json", "a simulation summary"),
    ("testbed.json", "a testbed.json"),
    ("sweep.json", "a sweep summary"),
    ("scene.toml", "a scene (TOML)"),
    ("case.toml", "a case file (TOML)"),
]


@pytest.mark.parametrize(("name", "kind"), WRONG_FOR_A_DESIGN)
@pytest.mark.parametrize(
    "argv",
    [
        ["check"],
        ["tolerance"],
        ["show", "--screenshot", "x.png"],
        ["export", "--format", "csv", "--out", "x.csv"],
    ],
    ids=["check", "tolerance", "show", "export"],
)
def test_commands_meant_for_a_design_refuse_other_kinds(
    files: Path, name: str, kind: str, argv: list[str], capsys, monkeypatch
) -> None:
    monkeypatch.chdir(files)
    command = argv[0]
    line = refused([command, name, *argv[1:]], command, capsys, files)
    assert f"{name} is {kind}, not a design.json" in line, line


@pytest.mark.parametrize(
    ("name", "message"),
    [
        ("sim/summary.json", "sim/summary.json is a simulation summary, not a design.json"),
        ("testbed.json", "testbed.json is a testbed.json, not a design.json"),
        ("sim/trajectory.csv", "sim/trajectory.csv is a trajectory.csv, not a scene (TOML)"),
        ("bifurcation.csv", "bifurcation.csv is a bifurcation csv, not a scene (TOML)"),
        ("t_end.sweep", "t_end.sweep is a sweep file, not a scene (TOML)"),
    ],
)
def test_simulate_refuses_what_is_no_scene_or_design(
    files: Path, name: str, message: str, capsys, monkeypatch
) -> None:
    monkeypatch.chdir(files)
    line = refused(["simulate", name, "--no-progress"], "simulate", capsys, files)
    assert message in line, line


@pytest.mark.parametrize("name", ["sim/trajectory.csv", "bifurcation.csv", "summary.csv"])
def test_show_and_export_refuse_a_csv_of_another_kind(
    files: Path, name: str, capsys, monkeypatch
) -> None:
    monkeypatch.chdir(files)
    kind = FILE_KINDS[sniff_kind(files / name) or ""]
    for argv in (["show", name, "--screenshot", "x.png"], ["export", name, "--out", "x.json"]):
        line = refused(argv, argv[0], capsys, files)
        assert f"{name} is {kind}, not a design export (csv)" in line, line


def test_the_right_kinds_still_read(files: Path, capsys, monkeypatch) -> None:
    monkeypatch.chdir(files)
    code, _, err = run_cli(["export", "design.json", "--format", "csv", "--out", "d.csv"], capsys)
    assert code == 0, err
    code, _, err = run_cli(["export", "d.csv", "--format", "json", "--out", "d2.json"], capsys)
    assert code == 0, err
