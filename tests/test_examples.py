"""The examples run: every examples/*.py script, every example scene (TOML).

Each script runs in a subprocess in a temporary directory (``MPLBACKEND=Agg``, output
directory given as the first argument and as ``$CHARGEDESIGN_OUT``); it must exit 0 and print
its key lines, whose numbers are checked against what the script claims. Every
``examples/**/*.toml`` must load with :func:`load_scene` and go through
``chargedesign conditions``; scenes with a ``[body] shape`` go through ``chargedesign design``
and ``chargedesign check`` too.
"""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

from chargedesign.cli import main
from chargedesign.scene import load_scene

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"
SCRIPTS = sorted(EXAMPLES.glob("*.py"))
SCENES = sorted(EXAMPLES.rglob("*.toml"))
PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


def number(pattern: str, text: str) -> float:
    """The float captured by ``pattern`` (one group) in ``text``; fails when absent."""
    match = re.search(pattern, text)
    assert match, f"no line matching {pattern!r} in:\n{text}"
    return float(match.group(1))


def is_png(path: Path) -> bool:
    return path.is_file() and path.read_bytes()[:8] == PNG_MAGIC


def check_verify_theorem(out: str, out_dir: Path) -> None:
    for case in ("general", "yehia2003", "goriachev", "chaplygin"):
        assert re.search(rf"^certificate {case}\s+holds \(6/6", out, re.M), case
    for name in ("mu_from_l", "eom_r", "eom_gamma", "I4", "p6"):
        assert re.search(rf"^printed {name}\s+agrees$", out, re.M), name
    assert re.search(r"^printed I3\s+differs by -2\*C\*n$", out, re.M)
    assert number(r"dI4/dt = \S+ ~ (\S+)", out) != 0.0


def check_design_default_body(out: str, out_dir: Path) -> None:
    assert number(r"residual after polish: (\S+)", out) <= 1e-13
    for name in ("mu", "V", "inertia"):
        assert number(rf"check {name}\s+rel_err (\S+)", out) <= 1e-9, name
    assert "check: theorem reproduced" in out
    design = json.loads((out_dir / "design.json").read_text())
    assert design["format"] == "chargedesign.design/1"
    assert design["realises"] == ["mu", "V", "inertia"]
    assert is_png(out_dir / "design.png")


def check_conservation_on_level(out: str, out_dir: Path) -> None:
    assert number(r"on the level I3 = 0: I4 relative drift (\S+),", out) <= 1e-9
    assert number(r"off the level I3 = 0\.5: I4 relative drift (\S+),", out) >= 1e-2
    assert number(r"reduced model at t = \S+ s: state gap (\S+)", out) <= 1e-9
    assert "(lorentz, electric, magnetization, gravity)" in out
    assert is_png(out_dir / "I4_drift.png")


def check_infeasible_design(out: str, out_dir: Path) -> None:
    assert out.count("  infeasible: ") == 3
    assert len(re.findall(r"fixed with .*: designed: .*residual (\S+)", out)) == 3
    assert "a2 = 0 while K = 0.5 != 0" in out
    assert "candidates all lie in the plane z = 0" in out
    assert "design.max_charge = 0.05 C is too small" in out


def check_simulate_designed_body(out: str, out_dir: Path) -> None:
    assert number(r"I3=0 +effects .*: I4 rel drift (\S+),", out) <= 1e-9
    assert number(r"I3=0\.5 +effects .*: I4 rel drift (\S+),", out) >= 1e-2
    assert number(r"direct route, t = 5 s: I4 rel drift (\S+)", out) <= 1e-9
    assert (out_dir / "design.json").is_file()


def check_simulate_theorem(out: str, out_dir: Path) -> None:
    assert number(r"DOP853 +I4 rel drift (\S+)", out) <= 1e-9
    assert number(r"gauss-legendre +I4 rel drift (\S+)", out) <= 1e-9
    assert re.search(r"event singular_plane at t = \S+ s, gamma3 = 0\.0100", out)


#: what each script must print (and write); a script without an entry must print something
EXPECTED: dict[str, Callable[[str, Path], None]] = {
    "verify_theorem.py": check_verify_theorem,
    "design_default_body.py": check_design_default_body,
    "conservation_on_level.py": check_conservation_on_level,
    "infeasible_design.py": check_infeasible_design,
    "simulate_designed_body.py": check_simulate_designed_body,
    "simulate_theorem.py": check_simulate_theorem,
}


def test_the_expected_examples_exist() -> None:
    names = {p.name for p in SCRIPTS}
    mine = {"verify_theorem.py", "design_default_body.py", "conservation_on_level.py"}
    assert mine <= names
    assert {"si_scale.toml", "yehia2003.toml"} <= {p.name for p in SCENES}


@pytest.mark.parametrize("script", SCRIPTS, ids=[p.name for p in SCRIPTS])
def test_example_script_runs(script: Path, tmp_path: Path) -> None:
    out_dir = tmp_path / "out"
    env = {**os.environ, "MPLBACKEND": "Agg", "CHARGEDESIGN_OUT": str(out_dir)}
    proc = subprocess.run(
        [sys.executable, str(script), str(out_dir)],
        cwd=tmp_path,
        env=env,
        capture_output=True,
        text=True,
        timeout=300,
        check=False,
    )
    assert proc.returncode == 0, f"exit {proc.returncode}\n{proc.stdout}\n{proc.stderr}"
    assert "Traceback" not in proc.stderr, proc.stderr
    check = EXPECTED.get(script.name)
    if check is None:
        assert proc.stdout.strip(), f"{script.name} printed nothing"
    else:
        check(proc.stdout, out_dir)


@pytest.mark.parametrize("scene", SCENES, ids=[str(p.relative_to(EXAMPLES)) for p in SCENES])
def test_example_scene_loads_and_gives_conditions(scene: Path, capsys) -> None:
    loaded = load_scene(scene)
    assert loaded.source == str(scene)
    code = main(["conditions", str(scene), "--json"])
    captured = capsys.readouterr()
    if loaded.parameters.singular:
        # lambda, rho != 0: no body realises them; the reduced simulation accepts them
        assert code == 2
        (line,) = captured.err.splitlines()
        assert "singular on gamma3 = 0" in line
        return
    assert code == 0, captured.err
    result = json.loads(captured.out)
    assert set(result) >= {"charges", "dipoles", "masses", "fields", "notes"}
    if loaded.case is not None:  # a [case] scene: its conditions are the case's
        assert result["case"] == loaded.case.name and result["conditions"]
    else:
        assert result["parameters"] == loaded.parameters.as_dict()


DESIGN_SCENES = [p for p in SCENES if "shape" in load_scene(p).table("body")]


@pytest.mark.parametrize(
    "scene", DESIGN_SCENES, ids=[str(p.relative_to(EXAMPLES)) for p in DESIGN_SCENES]
)
def test_example_design_scene_is_designed_and_checked(scene: Path, tmp_path: Path, capsys):
    out_dir = tmp_path / "out"
    code = main(["design", str(scene), "--out", str(out_dir), "--no-picture", "--quiet", "--json"])
    captured = capsys.readouterr()
    assert code == 0, captured.err
    summary = json.loads(captured.out)
    if "case" in summary:  # a [case] scene: a body of the case, its claim certified
        assert summary["case"]["certificate"]["holds"] is True
    else:
        assert summary["residuals"]["max_after_polish"] <= summary["residuals"]["tolerance"]
    code = main(["check", str(out_dir / "design.json"), "--json"])
    captured = capsys.readouterr()
    assert code == 0, captured.out
    report = json.loads(captured.out)
    assert report["passed"] and report["failures"] == []
    if scene.name == "thin_slab.toml":
        assert any("nearly planar" in note for note in summary["notes"]), summary["notes"]
    if scene.name == "chaplygin_drop.toml":  # free fall: its support is counted and passes
        written = json.loads((out_dir / "design.json").read_text())
        support = written["support"]
        assert support["style"] == "free_fall" and support["state"] == "included"
        assert support["turns"] >= 5 and support["flight"]["release"]["turns"] >= 5
        assert "## Flight" in (out_dir / "report.md").read_text()
        assert written["verdict"]["state"] == "buildable and realised"
        assert written["verdict"]["support"] == {"style": "free_fall", "state": "included"}
        total = whole_inertia_from_parts(written)
        C = written["parameters"]["C"]
        assert np.max(np.abs(total - np.diag([2 * C, 2 * C, C]))) <= 1e-9 * C
        assert np.max(np.abs(total - np.array(written["inertia"]["total_kg_m2"]))) <= 1e-9 * C


def whole_inertia_from_parts(written: dict) -> np.ndarray:
    """The body's inertia about O recomputed from design.json alone, by its own formulas (not
    the package's): each part a concentric sphere at its position (a ballast sphere of its
    density; a magnet's core of its volume with the rest of its mass as a ballast shell), every
    part's own (8 pi / 15) sum rho (r_out^5 - r_in^5) and its point term m (|c|^2 I - c c^T),
    and the holder: a solid sphere about O less a sphere of holder material at each bore."""
    materials, eye = written["materials"], np.eye(3)
    rho_ballast = materials["ballast"]["density_kg_per_m3"]
    rho_magnet = materials["magnet"]["density_kg_per_m3"]
    assert not written.get("charges", {}).get("values"), "a K = 0 body has no charges"

    def point(mass: float, c: np.ndarray) -> np.ndarray:
        return mass * (c @ c * eye - np.outer(c, c))

    def ball(rho: float, r_in: float, r_out: float) -> float:
        return 8 * np.pi / 15 * rho * (r_out**5 - r_in**5)

    total = np.zeros((3, 3))
    dipoles, masses = written["dipoles"], written["masses"]
    for c, v, m in zip(dipoles["positions"], dipoles["volumes"], dipoles["masses"], strict=True):
        core = (3 * v / (4 * np.pi)) ** (1 / 3)
        outer = (3 * (v + (m - rho_magnet * v) / rho_ballast) / (4 * np.pi)) ** (1 / 3)
        own = ball(rho_magnet, 0.0, core) + ball(rho_ballast, core, outer)
        total += point(m, np.array(c)) + own * eye
    for c, m in zip(masses["positions"], masses["values"], strict=True):
        radius = (3 * m / (4 * np.pi * rho_ballast)) ** (1 / 3)
        total += point(m, np.array(c)) + ball(rho_ballast, 0.0, radius) * eye
    holder = written["holder"]
    rho_holder = holder["density_kg_per_m3"]
    total += ball(rho_holder, 0.0, holder["radius_m"]) * eye
    for bore in holder["bores"]:
        a, c = bore["radius_m"], np.array(bore["position"])
        total -= point(rho_holder * 4 / 3 * np.pi * a**3, c) + ball(rho_holder, 0.0, a) * eye
    return total


# ------------------------------------------------------------------ the user guide
GUIDE = ROOT / "docs" / "guide.md"


def code_blocks(language: str) -> list[str]:
    return re.findall(rf"^```{language}\n(.*?)^```$", GUIDE.read_text(), re.M | re.S)


def test_guide_python_snippets_run(tmp_path: Path) -> None:
    """The guide's Python snippets, in order, from a directory that looks like the repo root."""
    (tmp_path / "examples").symlink_to(EXAMPLES)
    blocks = code_blocks("python")
    assert len(blocks) >= 6
    proc = subprocess.run(
        [sys.executable, "-c", "\n".join(blocks)],
        cwd=tmp_path,
        env={**os.environ, "MPLBACKEND": "Agg"},
        capture_output=True,
        text=True,
        timeout=300,
        check=False,
    )
    assert proc.returncode == 0, proc.stderr
    assert "a2 = 0 while K = 0.5 != 0" in proc.stdout
    out = tmp_path / "out" / "si_scale"
    assert (out / "design.json").is_file() and (out / "design.vtp").is_file()
    assert is_png(out / "design.png") and is_png(out / "on_level" / "integrals.png")


def test_guide_toml_blocks_are_valid_scenes() -> None:
    """Every TOML block of the guide is a scene whose tables pass their own validation."""
    import tomllib

    from chargedesign.candidates import candidates_from_table
    from chargedesign.designer import DesignOptions
    from chargedesign.moment_conditions import conditions_for_scene
    from chargedesign.scene import scene_from_dict
    from chargedesign.simulation import (
        parse_initial,
        parse_output_options,
        parse_simulation_options,
    )

    blocks = code_blocks("toml")
    assert len(blocks) == 2
    tables: set[str] = set()
    for block in blocks:
        data = tomllib.loads(block)
        scene = scene_from_dict(data, "<guide>")
        tables |= set(data)
        if "shape" in scene.table("body"):
            assert len(candidates_from_table(scene.table("body"))) > 0
        if "design" in scene.tables:
            DesignOptions.from_table(scene.table("design"))
            assert conditions_for_scene(scene).realise == ("mu", "V", "inertia")
        if "simulation" in scene.tables:
            parse_simulation_options(scene.table("simulation"))
        if "initial" in scene.tables:
            parse_initial(scene.table("initial"))
        if "output" in scene.tables:
            parse_output_options(scene.table("output"))
    assert tables == {"parameters", "fields", "body", "design", "simulation", "initial", "output"}


SWEEPS = sorted(EXAMPLES.glob("sweeps/*.sweep"))


@pytest.mark.parametrize("sweep", SWEEPS, ids=[p.name for p in SWEEPS])
def test_example_sweep_runs_every_point(sweep: Path, tmp_path: Path, capsys) -> None:
    """Every shipped sweep runs and each of its points succeeds (design_spacing.sweep once
    reported 4 failed: a 0.25 m spacing on the 5 cm default body)."""
    out = tmp_path / "sweep"
    code = main(["sweep", str(sweep), "--out", str(out), "--executor", "serial", "--quiet"])
    captured = capsys.readouterr()
    assert code == 0, captured.err + captured.out
    rows = (out / "summary.csv").read_text().splitlines()
    header = rows[0].split(",")
    status = header.index("status")
    assert len(rows) > 1 and all(r.split(",")[status] == "ok" for r in rows[1:]), rows


def test_a_sweep_whose_spacing_exceeds_the_body_is_refused_before_any_point(
    tmp_path: Path, capsys
) -> None:
    """The reason is knowable before the work: each point's scene goes through the loader and
    its candidates first."""
    sweep = tmp_path / "coarse.sweep"
    sweep.write_text('command = "check"\n[grid]\n"body.spacing" = [0.0125, 0.25]\n')
    out = tmp_path / "sweep"
    code = main(["sweep", str(sweep), "--out", str(out), "--executor", "serial", "--quiet"])
    err = capsys.readouterr().err
    assert code == 2 and not out.exists(), err
    assert "point p0001 (body.spacing = 0.25)" in err and "body.spacing = 0.25 m on a ball" in err
