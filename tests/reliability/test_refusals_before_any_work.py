"""Refusals before any work (first asked for in issue 22): outputs never destroy inputs and
are checked before the work, every command validates the whole file it reads, checks never
pass what they should not, degenerate requests and out-of-range options are refused, work is
capped before it starts, sweeps are validated point by point before any runs.

Every case asserts one error line (no traceback), nothing written and the inputs unchanged
(or, for a cap, the refusal and the option that raises it).
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
from pathlib import Path

import pytest
from reliability_support import (
    SMALL_DESIGN,
    SMALL_SCENE,
    THEOREM_SCENE,
    design_json,
    refused,
    run_cli,
)


@pytest.fixture
def work(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.chdir(tmp_path)
    return tmp_path


# ------------------------------------------------------------------ outputs and inputs


def test_an_output_never_replaces_an_input_directly_or_through_a_path(work: Path, capsys) -> None:
    design = design_json(work)
    (work / "sub").mkdir()
    os.link(design, work / "hard.csv")
    cases = [
        ["export", "design.json", "--format", "csv", "--out", "design.json"],
        ["export", "design.json", "--format", "csv", "--out", "sub/../design.json"],
        ["export", "design.json", "--format", "csv", "--out", str(design.resolve())],
        ["export", "design.json", "--format", "csv", "--out", "hard.csv"],  # a hard link
    ]
    for argv in cases:
        line = refused(argv, "export", capsys, work)
        assert "input" in line, line


def test_a_folder_output_never_holds_an_input_under_a_name_it_writes(work: Path, capsys) -> None:
    (work / "res").mkdir()
    design = design_json(work / "res")  # res/design.json: tolerance and simulate write that name
    line = refused(["tolerance", str(design), "--out", "res"], "tolerance", capsys, work)
    assert "input" in line
    line = refused(
        ["simulate", str(design), "--out", "res", "--no-progress"], "simulate", capsys, work
    )
    assert "input" in line
    scene = work / "s.toml"
    scene.write_text(SMALL_SCENE)
    link = work / "res" / "report.md"
    link.symlink_to(scene)  # a link inside the folder to the scene
    assert "--out" in refused(["design", "s.toml", "--out", "res"], "design", capsys, work)


def _no_work(monkeypatch: pytest.MonkeyPatch) -> None:
    """Make every expensive stage fail loudly: the refusal must come before it."""

    def boom(*args: object, **kwargs: object) -> None:
        raise AssertionError("the work started before the output was checked")

    # the names the commands call (each command module imports its stages at the top)
    import chargedesign.commands.design as design_command
    import chargedesign.commands.frontier as frontier_command
    import chargedesign.commands.simulate as simulate_command

    monkeypatch.setattr(design_command, "design_from_scene", boom)
    monkeypatch.setattr(simulate_command, "simulate", boom)
    monkeypatch.setattr(frontier_command, "scan_frontier", boom)


@pytest.mark.parametrize(
    "argv",
    [
        ["design", "--out", "/proc/chargedesign-x"],
        ["design", "--out", "/sys/chargedesign-x/y"],
        ["design", "--out", "afile"],  # an existing regular file where a folder goes
        ["design", "--out", "afile/sub"],  # below a file
        ["simulate", "--out", "/proc/chargedesign-x"],
        ["simulate", "--atlas", "--out", "/proc/chargedesign-x"],
        ["frontier", "--scan", "--out", "/proc/chargedesign-x"],
        ["show", "design.json", "--animate", "t.npz", "--out", "/proc/chargedesign-x.gif"],
        ["show", "design.json", "--screenshot", "/proc/chargedesign-x.png"],
        ["tolerance", "design.json", "--out", "/proc/chargedesign-x"],
        ["bench", "--only", "fields", "--out", "/proc/chargedesign-x"],
        ["sweep", "sw.toml", "--out", "/proc/chargedesign-x"],
    ],
    ids=lambda a: " ".join(a[:3]),
)
def test_outputs_are_checked_before_any_work(
    argv: list[str], work: Path, capsys, monkeypatch: pytest.MonkeyPatch
) -> None:
    design_json(work)
    (work / "afile").write_text("keep")
    (work / "t.npz").write_bytes(b"")
    (work / "sw.toml").write_text('command = "design"\n[grid]\n"parameters.n" = [0.5]\n')
    _no_work(monkeypatch)
    line = refused(argv, argv[0], capsys, work)
    assert "--out" in line or "--screenshot" in line, line


def test_an_immutable_folder_is_refused_before_the_work(
    work: Path, capsys, monkeypatch: pytest.MonkeyPatch
) -> None:
    out = work / "frozen"
    out.mkdir()
    if shutil.which("chattr") is None:
        pytest.skip("needs chattr")
    if subprocess.run(["chattr", "+i", str(out)], capture_output=True).returncode != 0:
        pytest.skip("this file system has no immutable flag")
    try:
        _no_work(monkeypatch)
        assert "--out" in refused(["design", "--out", "frozen"], "design", capsys, work)
    finally:
        subprocess.run(["chattr", "-i", str(out)], check=False)


def test_a_second_simulate_leaves_only_its_own_files(work: Path, capsys) -> None:
    scene = work / "th.toml"
    scene.write_text(THEOREM_SCENE + "\n[output]\nplot = true\n")
    code, _, err = run_cli(["simulate", "th.toml", "--out", "run", "--no-progress"], capsys)
    assert code == 0, err
    assert (work / "run" / "integrals.png").is_file()
    (work / "run" / "mine.txt").write_text("the user's own file stays")
    scene.write_text(THEOREM_SCENE + "\n[output]\nplot = false\n")
    code, _, err = run_cli(["simulate", "th.toml", "--out", "run", "--no-progress"], capsys)
    assert code == 0, err
    names = {p.name for p in (work / "run").iterdir()}
    assert names == {"summary.json", "trajectory.npz", "trajectory.csv", "mine.txt"}, names


# ------------------------------------------------------------------ whole-file validation


@pytest.mark.parametrize(
    "table",
    [
        "[medium]\nname = 'air'\nbogus = 1",
        "[medium]\nname = 'air'\n[carriers]\nbogus = 1",
        "[medium]\nname = 'air'\n[magnets]\nbogus = 1",
        "[medium]\nname = 'air'\n[ballast]\nbogus = 1",
        "[simulation]\nbogus = 1",
        "[initial]\ngamma = [0, 0, 1]\nomega = [0, 0, 1]\nbogus = 1",
        "[output]\nbogus = 1",
        "[design]\nbogus = 1",
        "[body]\nshape = 'ball'\nradius = 1.0\nspacing = 0.34\nbogus = 1",
    ],
    ids=[
        "medium",
        "carriers",
        "magnets",
        "ballast",
        "simulation",
        "initial",
        "output",
        "design",
        "body",
    ],
)
@pytest.mark.parametrize("command", ["conditions", "design", "frontier", "simulate"])
def test_every_command_refuses_an_unknown_key_in_any_table(
    table: str, command: str, work: Path, capsys, monkeypatch: pytest.MonkeyPatch
) -> None:
    base = SMALL_SCENE.split("[body]")[0]
    (work / "s.toml").write_text(base + "\n" + table + "\n")
    _no_work(monkeypatch)
    argv = [command, "s.toml"] + (["--no-progress"] if command == "simulate" else [])
    line = refused(argv, command, capsys, work)
    assert ".bogus" in line, line


def test_check_refuses_unknown_keys_and_kinds_of_a_design_field(work: Path, capsys) -> None:
    fields = {"magnetic": {"legendre": [1.0, 1.0], "bogus": 1}}
    design_json(work, fields=fields)
    assert "fields.magnetic.bogus" in refused(["check", "design.json"], "check", capsys, work)
    design_json(work, fields={"magentic": {"legendre": [1.0]}})
    assert "fields.magentic" in refused(["check", "design.json"], "check", capsys, work)


def test_the_scene_schema_lists_what_the_medium_validator_reads() -> None:
    from chargedesign.scene.keys import key_names
    from chargedesign.schemas import scene_schema

    medium = scene_schema()["properties"]["medium"]
    assert set(medium["properties"]) == set(key_names("medium"))
    assert medium["additionalProperties"] is False


# ------------------------------------------------------------------ no false pass


def test_check_needs_realises_to_give_a_verdict(work: Path, capsys) -> None:
    data = json.loads(json.dumps(SMALL_DESIGN))
    del data["realises"]
    data["charges"]["values"] = [-0.8 * 1.01]  # tampered
    (work / "design.json").write_text(json.dumps(data))
    assert "realises" in refused(["check", "design.json"], "check", capsys, work)


@pytest.mark.parametrize("command", ["check", "export", "simulate"])
def test_a_physical_design_without_materials_is_refused(
    command: str, work: Path, capsys, monkeypatch: pytest.MonkeyPatch
) -> None:
    medium = {"name": "air", "breakdown_V_per_m": 3e6, "safety": 0.5}
    for materials in ([], {}):
        design_json(work, medium=medium, materials=materials)
        argv = {
            "check": ["check", "design.json"],
            "export": ["export", "design.json", "--out", "x.csv"],
            "simulate": ["simulate", "design.json", "--no-progress"],
        }[command]
        assert "materials" in refused(argv, command, capsys, work)


# ------------------------------------------------------------------ degenerate requests


def test_a_design_that_realises_nothing_is_refused(work: Path, capsys) -> None:
    (work / "s.toml").write_text(SMALL_SCENE + "\n[design]\nrealise = []\n")
    assert "design.realise" in refused(["design", "s.toml", "--out", "o"], "design", capsys, work)


def test_no_command_is_one_error_line(capsys) -> None:
    code, _, err = run_cli([], capsys)
    assert code == 2
    errors = [line for line in err.splitlines() if "error:" in line]
    assert len(errors) == 1 and "give a command" in errors[0], err


def test_free_motion_is_said_in_the_output(work: Path, capsys) -> None:
    (work / "s.toml").write_text(THEOREM_SCENE.replace('["theorem"]', "[]"))
    code, out, err = run_cli(["simulate", "s.toml", "--no-progress"], capsys)
    assert code == 0, err
    assert "torque-free" in out


# ------------------------------------------------------------------ ranges of options


@pytest.mark.parametrize(
    "argv, option",
    [
        (["design", "--n-charges", "1000000000"], "--n-charges"),
        (["design", "--max-linf-candidates", "-1"], "--max-linf-candidates"),
        (["design", "--max-linf-candidates", "0"], "--max-linf-candidates"),
        (["check", "design.json", "--quadrature-order", "-1"], "--quadrature-order"),
        (["check", "design.json", "--quadrature-order", "65"], "--quadrature-order"),
        (["simulate", "--rtol", "10"], "--rtol"),
        (["simulate", "--atol", "1e10"], "--atol"),
        (["tolerance", "design.json", "--position", "100000%"], "--position"),
        (["tolerance", "design.json", "--position", "1e31"], "--position"),
        (["tolerance", "design.json", "--target", "2"], "--target"),
        (["tolerance", "design.json", "--seed", "-1"], "--seed"),
        (["tolerance", "design.json", "--position", "1%", "--t-end", "1e29"], "--t-end"),
        (["show", "design.json", "--frames", "0"], "--frames"),
    ],
    ids=lambda a: " ".join(a) if isinstance(a, list) else a,
)
def test_out_of_range_options_are_refused(
    argv: list[str], option: str, work: Path, capsys, monkeypatch: pytest.MonkeyPatch
) -> None:
    design_json(work, realises=["inertia"])
    _no_work(monkeypatch)
    line = refused(argv, argv[0], capsys, work)
    assert option in line, line


def test_help_states_every_range_that_is_checked() -> None:
    from chargedesign.cli import build_parser
    from chargedesign.limits import OPTION_RANGES

    parser = build_parser()
    sub = next(a for a in parser._actions if a.dest == "command")
    for command, ranges in OPTION_RANGES.items():
        actions = {a.dest: a for a in sub.choices[command]._actions}
        for dest, bounds in ranges.items():
            assert dest in actions, (command, dest)
            assert f"[range {bounds.text()}]" in (actions[dest].help or ""), (command, dest)


# ------------------------------------------------------------------ caps on work


def test_caps_name_the_option_that_raises_them(work: Path, capsys) -> None:
    line = refused(["simulate", "--t-end", "1e13", "--no-progress"], "simulate", capsys, work)
    assert "--max-periods" in line and "periods" in line
    line = refused(["simulate", "--t-end", "1e30", "--no-progress"], "simulate", capsys, work)
    assert "--max-periods" in line
    line = refused(["simulate", "--atlas", "--orbits", "1000000"], "simulate", capsys, work)
    assert "--orbits" in line
    grid = ", ".join(str(0.1 + 0.01 * i) for i in range(100))
    (work / "big.toml").write_text(
        f'command = "design"\n[grid]\n"parameters.n" = [{grid}]\n"parameters.K" = [{grid}]\n'
        f'"parameters.kappa" = [{grid}]\n'
    )
    line = refused(["sweep", "big.toml", "--out", "o"], "sweep", capsys, work)
    assert "--max-points" in line
    line = refused(
        ["sweep", "big.toml", "--out", "o", "--workers", "100000"], "sweep", capsys, work
    )
    assert "--workers" in line


def test_a_long_legendre_list_is_refused_by_its_degree_first(work: Path, capsys) -> None:
    terms = ", ".join(["0.5"] * 300_000)
    (work / "s.toml").write_text(
        f"[parameters]\nC = 1.0\n[fields.magnetic]\nlegendre = [{terms}]\n"
    )
    line = refused(["conditions", "s.toml"], "conditions", capsys, work)
    assert "degree" in line and "300000" in line


def test_a_design_json_of_too_many_elements_is_refused_by_its_count(work: Path, capsys) -> None:
    from chargedesign.limits import MAX_DESIGN_ELEMENTS

    n = MAX_DESIGN_ELEMENTS + 1
    text = (
        '{"format": "chargedesign.design/1", "parameters": {"C": 1.0}, "realises": [], '
        '"charges": {"positions": ['
        + ",".join(["[0,0,1]"] * n)
        + '], "values": ['
        + ",".join(["1"] * n)
        + "]}}"
    )
    (work / "design.json").write_text(text)
    line = refused(["check", "design.json"], "check", capsys, work)
    assert "MAX_DESIGN_ELEMENTS" in line


def test_a_parameter_is_reported_against_its_own_range(work: Path, capsys) -> None:
    (work / "s.toml").write_text("[parameters]\nC = 1.0\nn = " + "1" * 40 + "\n")
    line = refused(["conditions", "s.toml"], "conditions", capsys, work)
    assert "parameters.n" in line and "1e-08" in line and "1e+08" in line


# ------------------------------------------------------------------ sweeps


@pytest.mark.parametrize(
    "command, grid, word",
    [
        ("design", '"body.radius" = [1.0, nan]', "finite"),
        ("design", '"body.radius" = [1.0, "x"]', "body.radius"),
        ("design", '"body.radius" = [1.0, 1e200]', "range"),
        ("design", '"body.radius" = [1.0, -1.0]', "body.radius"),
        ("simulate", '"body.bogus" = [1.0]', "body.bogus"),
        ("check", '"simulation.bogus" = [1]', "simulation.bogus"),
    ],
)
def test_every_point_of_a_sweep_is_validated_before_any_runs(
    command: str, grid: str, word: str, work: Path, capsys
) -> None:
    (work / "scene.toml").write_text(SMALL_SCENE)
    (work / "sw.toml").write_text(f'scene = "scene.toml"\ncommand = "{command}"\n[grid]\n{grid}\n')
    line = refused(
        ["sweep", "sw.toml", "--out", "o", "--executor", "serial"], "sweep", capsys, work
    )
    assert word in line, line


def test_a_point_that_fails_only_in_combination_is_found_before_the_run(work: Path, capsys) -> None:
    (work / "scene.toml").write_text(
        SMALL_SCENE.replace("radius = 1.0", "radius = 0.1").replace("0.34", "0.034")
    )
    # each value passes alone against the base scene (radius 1.0 with spacing 0.034, spacing
    # 0.005 with radius 0.1), but radius 1.0 with spacing 0.005 gives too many candidates
    (work / "sw.toml").write_text(
        'scene = "scene.toml"\ncommand = "design"\n[grid]\n"body.radius" = [0.1, 1.0]\n'
        '"body.spacing" = [0.034, 0.005]\n'
    )
    line = refused(
        ["sweep", "sw.toml", "--out", "o", "--executor", "serial"], "sweep", capsys, work
    )
    assert "point p" in line, line


def test_sweep_options_are_bound_to_the_command(work: Path, capsys) -> None:
    (work / "sw.toml").write_text(
        'command = "tolerance"\n[grid]\n"parameters.n" = [0.5]\n[options]\nbogus = 1\n'
    )
    line = refused(["sweep", "sw.toml", "--out", "o"], "sweep", capsys, work)
    assert "bogus" in line


@pytest.mark.parametrize("name", ["a\nb", "a\x07b", "a:b", "a|b", "out ", "out."])
def test_output_dir_names_must_be_portable(name: str, work: Path, capsys) -> None:
    (work / "s.toml").write_text(THEOREM_SCENE + f"\n[output]\ndir = {json.dumps(name)}\n")
    line = refused(["simulate", "s.toml", "--no-progress"], "simulate", capsys, work)
    assert "output.dir" in line


def test_docs_list_every_option_range() -> None:
    from chargedesign.limits import OPTION_RANGES

    text = (Path(__file__).parents[2] / "docs" / "reliability.md").read_text()
    for command, ranges in OPTION_RANGES.items():
        for dest, bounds in ranges.items():
            row = f"| `{command}` | `--{dest.replace('_', '-')}` | {bounds.text()} |"
            assert row in text, row


def test_tolerance_without_simulation_prints_no_nan_table(work: Path, capsys) -> None:
    design = Path(__file__).parents[1] / "tolerancing" / "data" / "default_design.json"
    argv = ["tolerance", str(design), "--position", "1%", "--no-simulate", "--samples", "20"]
    code, out, err = run_cli(argv, capsys)
    assert code == 0, err
    assert "nan" not in out and "warning" not in err.lower(), (out, err)
    assert "not simulated" in out


def test_simulate_always_hands_the_integrator_a_callback(
    work: Path, capsys, monkeypatch: pytest.MonkeyPatch
) -> None:
    """SIGINT is raised in Python code: the integrator must come back to Python every step,
    also without a progress bar (--no-progress), or heyoka runs on for seconds (33.8 s
    measured; 0.24 s with the callback)."""
    import chargedesign.commands.simulate as simulate_command

    seen: dict[str, object] = {}

    class Stop(Exception):
        pass

    def capture(*args: object, **kwargs: object) -> None:
        seen.update(kwargs)
        raise Stop

    monkeypatch.setattr(simulate_command, "simulate", capture)
    (work / "s.toml").write_text(THEOREM_SCENE)
    with pytest.raises(Stop):
        run_cli(["simulate", "s.toml", "--no-progress"], capsys)
    assert callable(seen["progress"])
