import json

import numpy as np
import pytest
from unit_scene import UNIT_SCENE

from chargedesign.body import read_design
from chargedesign.cli import main
from chargedesign.moment_conditions import derive_conditions

SI_SCENE = """
[parameters]
C = 1e-4
c = 0.3
d = -0.4
n = 0.7
K = 0.5
kappa = 0.9

[fields.magnetic]
a1 = 1.0
a2 = 1e-3

[fields.gravity]
legendre = [9.81]

[body]
shape = "cylinder"
radius = 0.05
height = 0.1
spacing = 0.0125

[design]
realise = ["mu", "V", "inertia"]
objective = "l1"
"""


def moments_of(positions, weights, letters):
    """sum_j w_j prod r_j[letter]: einsum-free, one factor at a time."""
    terms = np.array(weights, dtype=float).copy()
    for ch in letters:
        terms = terms * positions[:, "xyz".index(ch)]
    return float(np.sum(terms))


def check_written_design(path, rtol=1e-12):
    """Recompute every condition from design.json's own positions and values."""
    design = read_design(path)
    conditions = derive_conditions(design.parameters, design.fields, design.realises)
    for cond in conditions.conditions:
        lhs, scale = 0.0, abs(cond.value)
        for key, coef in cond.coefficients.items():
            if cond.source == "dipoles":
                comp, letters = key.split(":")
                pos, w = design.dipole_positions, design.dipole_moments[:, "xyz".index(comp)]
                wn = np.linalg.norm(design.dipole_moments)
            elif cond.source == "charges":
                letters, pos, w = key, design.charge_positions, design.charge_values
                wn = np.linalg.norm(w)
            else:
                letters, pos, w = key, design.mass_positions, design.mass_values
                wn = np.linalg.norm(w)
            lhs += coef * moments_of(pos, w, letters)
            mono = np.ones(len(pos))
            for ch in letters:
                mono = mono * pos[:, "xyz".index(ch)]
            scale += abs(coef) * np.linalg.norm(mono) * wn
        assert abs(lhs - cond.value) <= rtol * scale, cond
    r, m = design.mass_positions, design.mass_values
    inertia = np.einsum("j,jk->", m, r * r) * np.eye(3) - np.einsum("j,ja,jb->ab", m, r, r)
    C = design.parameters.C
    assert np.allclose(inertia, np.diag([2 * C, 2 * C, C]), rtol=0, atol=1e-12 * C)
    assert np.all(m >= 0)
    return design


def snapshot(directory):
    return {p.name: p.read_bytes() for p in sorted(directory.iterdir())}


def test_default_design_writes_design_report_and_picture(tmp_path, capsys):
    import imageio.v3 as iio

    out = tmp_path / "out"
    assert main(["design", str(UNIT_SCENE), "--out", str(out)]) == 0
    captured = capsys.readouterr()
    assert sorted(p.name for p in out.iterdir()) == ["design.json", "design.png", "report.md"]
    # the terminal: the verdict and a short summary; the report is in report.md
    assert captured.out.startswith("Verdict: not checked for buildability")
    assert f"Full report: {out / 'report.md'}" in captured.out
    assert len(captured.out.splitlines()) <= 40
    assert "design: charges:" in captured.err  # progress on stderr
    report = (out / "report.md").read_text()
    assert "breakdown field of air" in report
    assert "![the designed body](design.png)" in report
    design = check_written_design(out / "design.json")
    assert design.realises == ["mu", "V", "inertia"]
    image = iio.imread(out / "design.png")
    assert image.shape[:2] == (768, 1024)
    # no staging directory left beside the output
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]


def test_json_summary_and_si_scene(tmp_path, capsys):
    scene = tmp_path / "si.toml"
    scene.write_text(SI_SCENE)
    out = tmp_path / "si_out"
    code = main(["design", str(scene), "--out", str(out), "--json", "--no-picture", "--quiet"])
    assert code == 0
    captured = capsys.readouterr()
    summary = json.loads(captured.out)
    assert next(iter(summary)) == "residuals"
    assert summary["residuals"]["max_after_polish"] <= 1e-13
    assert summary["files"] == ["design.json", "report.md"]
    assert summary["counts"]["candidates"] > 100
    assert summary["plausibility"]["field_V_per_m"] > 0
    assert captured.err == ""
    design = check_written_design(out / "design.json")
    assert design.candidates["shape"] == "cylinder"
    assert design.residuals["after_polish"]["charges"] <= 1e-13


def test_objective_override(tmp_path, capsys):
    out = tmp_path / "o"
    assert (
        main(
            [
                "design",
                str(UNIT_SCENE),
                "--out",
                str(out),
                "--objective",
                "l2",
                "--no-picture",
                "--quiet",
            ]
        )
        == 0
    )
    capsys.readouterr()
    design = read_design(out / "design.json")
    assert design.objective["charges"]["kind"] == "l2"
    check_written_design(out / "design.json")


PLANAR = """
[parameters]
C = 1.0
n = 0.7
K = 0.5
c = 0.3

[fields.magnetic]
a1 = 1.0
a2 = 0.5

[body]
shape = "box"
half_size = [1.0, 1.0, 0.1]
spacing = 0.25
"""


@pytest.mark.parametrize(
    ("scene_text", "fragments"),
    [
        (PLANAR, ["candidates all lie in the plane z = 0", "'zz'"]),
        (PLANAR.replace("a1 = 1.0", "a1 = 0.0"), ["a1 = 0", "n = 0.7"]),
    ],
)
def test_infeasible_scenes_fail_in_one_line_and_write_nothing(
    tmp_path, capsys, scene_text, fragments
):
    scene = tmp_path / "bad.toml"
    scene.write_text(scene_text)
    out = tmp_path / "out"
    out.mkdir()
    (out / "design.json").write_text('{"old": true}\n')
    (out / "keep.txt").write_text("mine\n")
    before = snapshot(out)
    code = main(["design", str(scene), "--out", str(out), "--quiet"])
    captured = capsys.readouterr()
    assert code == 2
    assert captured.out == ""
    lines = captured.err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("chargedesign design: error: ")
    for fragment in fragments:
        assert fragment in lines[0]
    assert snapshot(out) == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bad.toml", "out"]


def test_infeasible_scene_does_not_create_the_directory(tmp_path, capsys):
    scene = tmp_path / "bad.toml"
    scene.write_text(PLANAR)
    out = tmp_path / "never"
    assert main(["design", str(scene), "--out", str(out), "--quiet"]) == 2
    capsys.readouterr()
    assert not out.exists()


def test_failed_picture_fails_the_command_and_keeps_earlier_outputs(tmp_path, capsys, monkeypatch):
    import chargedesign.viz

    out = tmp_path / "out"
    assert main(["design", str(UNIT_SCENE), "--out", str(out), "--no-picture", "--quiet"]) == 0
    before = snapshot(out)

    def broken(*args, **kwargs):
        raise RuntimeError("no OpenGL context")

    monkeypatch.setattr(chargedesign.viz, "render_screenshot", broken)
    code = main(["design", str(UNIT_SCENE), "--out", str(out), "--objective", "l2", "--quiet"])
    captured = capsys.readouterr()
    assert code == 2
    assert "rendering design.png failed (RuntimeError: no OpenGL context)" in captured.err
    assert len(captured.err.strip().splitlines()) == 1
    assert snapshot(out) == before


def test_no_picture_removes_a_stale_picture(tmp_path, capsys):
    out = tmp_path / "out"
    out.mkdir()
    (out / "design.png").write_bytes(b"old picture")
    assert main(["design", str(UNIT_SCENE), "--out", str(out), "--no-picture"]) == 0
    captured = capsys.readouterr()
    assert not (out / "design.png").exists()
    assert "removed the earlier" in captured.err
    assert "![the designed body]" not in (out / "report.md").read_text()


def test_bad_scene_key_is_named(tmp_path, capsys):
    scene = tmp_path / "s.toml"
    scene.write_text('[body]\nshape = "ball"\nradius = 1.0\nspacing = -1\n')
    assert main(["design", str(scene), "--out", str(tmp_path / "o"), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert "body.spacing: expected a number > 0, got -1" in err


def test_bad_realise_is_named_design_realise(tmp_path, capsys):
    scene = tmp_path / "s.toml"
    scene.write_text('[parameters]\nn = 0.5\n[design]\nrealise = ["mu", "B"]\n')
    assert main(["design", str(scene), "--out", str(tmp_path / "o"), "--quiet"]) == 2
    (line,) = capsys.readouterr().err.strip().splitlines()
    assert line.startswith("chargedesign design: error: design.realise: expected items among")


def test_scene_without_body_table_names_the_missing_table(tmp_path, capsys):
    scene = tmp_path / "nobody.toml"
    scene.write_text("[parameters]\nn = 0.5\n")
    out_dir = tmp_path / "out"
    code = main(["design", str(scene), "--out", str(out_dir)])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2
    assert "no [body] table" in err[-1]
    assert not out_dir.exists()


def test_verbose_prints_the_report_the_default_a_short_summary(tmp_path, capsys):
    out = tmp_path / "out"
    args = ["design", str(UNIT_SCENE), "--out", str(out), "--no-picture", "--quiet"]
    assert main([*args, "--verbose"]) == 0
    assert capsys.readouterr().out == (out / "report.md").read_text()
    assert main(args) == 0
    short = capsys.readouterr().out
    assert short.splitlines()[0] == "Verdict: not checked for buildability"
    assert len(short.splitlines()) <= 40 and max(len(x) for x in short.splitlines()) <= 160


def _twin_of(theorem_scene, out):
    """The ``[case]`` twin of a theorem scene (tools/shared_functions.py ``write_twin``)."""
    import importlib.util
    from pathlib import Path

    path = Path(__file__).resolve().parents[2] / "tools" / "shared_functions.py"
    spec = importlib.util.spec_from_file_location("shared_functions", path)
    assert spec is not None and spec.loader is not None
    tool = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(tool)
    return tool.write_twin(theorem_scene, out)


def _design_json(tmp_path, capsys, scene, name):
    """``design SCENE --json``: the printed summary and the written design.json."""
    out = tmp_path / name
    assert main(["design", str(scene), "--out", str(out), "--json", "--no-picture", "--quiet"]) == 0
    summary = json.loads(capsys.readouterr().out)
    return summary, json.loads((out / "design.json").read_text("utf-8"))


def test_a_case_twin_takes_the_theorem_scene_route(tmp_path, capsys):
    """unit_scale entered as a [case] of the theorem's form: the same summary (shape and
    figures) and the same design.json, tolerances included, beside its ``case`` record."""
    twin = _twin_of(UNIT_SCENE, tmp_path / "twin.toml")
    theorem, theorem_record = _design_json(tmp_path, capsys, UNIT_SCENE, "theorem")
    case, case_record = _design_json(tmp_path, capsys, twin, "twin")
    for summary in (theorem, case):
        del summary["timings"], summary["out"]
    assert list(case) == list(theorem)
    assert case == theorem
    assert "not_applicable" not in case
    assert case_record["tolerance"]["elements"]
    assert case_record["tolerance"] == theorem_record["tolerance"]
    assert case_record["case"]["name"] == "unit_scale as a case"
    assert sorted(set(case_record) - set(theorem_record)) == ["case"]


def test_a_case_of_another_form_records_its_tolerance_not_applicable(tmp_path, capsys):
    """The Kowalevski case: the theorem's summary shape, and the tolerance stage (measured
    against the theorem's mu, V and inertia) recorded as not applicable, with the reason."""
    scene = UNIT_SCENE.parent / "kowalevski_case.toml"
    summary, record = _design_json(tmp_path, capsys, scene, "kow")
    assert next(iter(summary)) == "residuals"
    assert summary["plausibility"]["total_mass_kg"] > 0
    reason = summary["not_applicable"]["tolerance"]
    assert "not of a case of another form (kowalevski-example" in reason
    assert record["tolerance"] == {"applicable": False, "reason": reason}


def test_a_case_scene_takes_the_degenerate_and_linf_checks(tmp_path, capsys):
    """The checks before any work apply to a [case] scene as to the theorem's."""
    text = (UNIT_SCENE.parent / "kowalevski_case.toml").read_text("utf-8")
    empty = tmp_path / "empty.toml"
    empty.write_text(text + "\n[design]\nrealise = []\n", "utf-8")
    assert main(["design", str(empty), "--out", str(tmp_path / "e"), "--quiet"]) == 2
    assert "design.realise: empty" in capsys.readouterr().err
    args = ["--objective", "linf", "--max-linf-candidates", "3", "--quiet"]
    scene = UNIT_SCENE.parent / "kowalevski_case.toml"
    assert main(["design", str(scene), "--out", str(tmp_path / "l"), *args]) == 2
    assert "exceeds the cap of 3" in capsys.readouterr().err
    assert not (tmp_path / "e").exists() and not (tmp_path / "l").exists()
