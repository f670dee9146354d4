"""Issue 22's rules on the options and tables added after it (an outside review): design.json's
``larmor`` key, ``tolerance --chi-relative/--density-relative/--magnetisation-relative``.

Each refusal is one error line, no traceback, nothing written and the inputs unchanged.
"""

from __future__ import annotations

import json
import os
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

#: every command that reads a design.json (the error comes from the one reader, before the work)
READERS = [
    ["check", "j.json"],
    ["export", "j.json", "--format", "csv", "--out", "o.csv"],
    ["simulate", "j.json", "--t-end", "1", "--no-progress"],
    ["tolerance", "j.json"],
]


@pytest.fixture
def work(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.chdir(tmp_path)
    return tmp_path


@pytest.mark.parametrize("argv", READERS, ids=lambda a: a[0])
@pytest.mark.parametrize(
    ("larmor", "named"),
    [
        # a rate other than parameters.n (0.7): silently ignored by a charges body (check,
        # export, simulate, tolerance exited 0), and a frame body's axes turned at it
        ({"reading": "charges", "rate": 5.0}, "differs from parameters.n = 0.7"),
        ({"reading": "frame", "rate": 123.0}, "differs from parameters.n = 0.7"),
        # outside n's own range: check exited 1, export and tolerance 0, simulate failed in
        # the integrator ("stopped near t = nan")
        ({"reading": "frame", "rate": 1e200}, "1e-08 <= |x| <= 1e+08"),
    ],
)
def test_larmor_rate_is_the_theorems_n(
    argv: list[str], larmor: dict[str, object], named: str, work: Path, capsys
) -> None:
    design_json(work, "j.json", larmor=larmor)
    line = refused(argv, argv[0], capsys, work)
    assert "larmor.rate" in line and named in line, line


def test_a_larmor_rate_equal_to_n_is_read(work: Path, capsys) -> None:
    """The refusal is of the mismatch only: the same file with rate = n passes check."""
    design_json(work, "j.json", larmor={"reading": "charges", "rate": 0.7})
    code, out, err = run_cli(["check", "j.json"], capsys)
    assert code == 0 and not err, err
    assert "larmor reading: charges (rate 0.7 1/s)" in out


@pytest.mark.parametrize(
    "option", ["--chi-relative", "--density-relative", "--magnetisation-relative"]
)
@pytest.mark.parametrize("value", ["1", "-0.5", "nan", "1e400"])
def test_material_error_options_have_their_range(
    option: str, value: str, work: Path, capsys
) -> None:
    design = work / "design.json"
    design.write_text(json.dumps(SMALL_DESIGN))
    line = refused(
        ["tolerance", "design.json", option, value, "--out", "o"], "tolerance", capsys, work
    )
    assert option in line, line
    assert "[0, 1)" in line or "finite" in line, line


# ------------------------------------------------------------------ sweeps (outside review)


def _sweep(folder: Path, body: str, scene: str = THEOREM_SCENE) -> None:
    (folder / "t.toml").write_text(scene)
    (folder / "x.sweep").write_text('scene = "t.toml"\n' + body)


@pytest.mark.parametrize("out", [".", ".."])
def test_a_sweep_never_fills_the_working_directory(out: str, work: Path, capsys) -> None:
    """sweep fills its folder point by point (no one swap), so the boundary check itself
    refuses the working directory: `sweep x.sweep --out .` wrote points/ beside the inputs."""
    (work / "sub").mkdir()
    _sweep(work / "sub", 'command = "simulate"\n[grid]\n"simulation.t_end" = [1.0]\n')
    os.chdir(work / "sub")
    line = refused(["sweep", "x.sweep", "--out", out, "--quiet"], "sweep", capsys, work)
    assert "working directory" in line, line


@pytest.mark.parametrize(
    ("body", "named"),
    [
        # the second point's motion is 1.5e7 periods: it ran unbounded after p0000 had written
        ('command = "simulate"\n[grid]\n"simulation.t_end" = [1.0, 1e8]\n', "p0001"),
        (
            'command = "simulate"\n[grid]\n"simulation.samples" = [11]\n[options]\nt_end = 1e30\n',
            "options.t_end",
        ),
    ],
)
def test_a_sweep_caps_each_points_motion_before_any_runs(
    body: str, named: str, work: Path, capsys
) -> None:
    _sweep(work, body)
    line = refused(["sweep", "x.sweep", "--out", "o", "--quiet"], "sweep", capsys, work)
    assert named in line and "MAX_PERIODS" in line, line


@pytest.mark.parametrize(
    ("options", "named"),
    [
        ('position = "1e31"', "options.position: 1e+31 is outside"),  # failed as its point ran
        ('position = "100000%"', "options.position: expected a relative error of at most 100%"),
        ('position = "20parsec"', "options.position"),
        ("samples = 1000000000", "options.samples: expected a value in [1, 2000]"),  # accepted
        ("target = 2.0", "options.target: expected a value in (0, 1)"),
        ('position = "1um"\nt_end = 1e30', "options.t_end"),  # the drift's periods
        # the materials' errors, as tolerance --chi-relative ... takes them
        ("chi_relative = 2.0", "options.chi_relative: expected a value in [0, 1)"),
        ('density_relative = "5%"', "options.density_relative: expected a real number"),
        # SMALL_SCENE has no [medium]: no materials to perturb
        ("magnetisation_relative = 1e-3", "options.magnetisation_relative: material errors need"),
    ],
)
def test_a_sweeps_tolerance_options_are_checked_before_any_point(
    options: str, named: str, work: Path, capsys
) -> None:
    _sweep(
        work,
        f'command = "tolerance"\n[grid]\n"body.spacing" = [0.34]\n[options]\n{options}\n',
        SMALL_SCENE,
    )
    line = refused(["sweep", "x.sweep", "--out", "o", "--quiet"], "sweep", capsys, work)
    assert named in line, line


# ------------------------------------------------------------------ tolerance's work, materials


@pytest.mark.parametrize(
    ("argv", "named"),
    [
        # SMALL_DESIGN's farthest element is 1 m from O; 10 m (and 1um at 1e31) ran unbounded
        (["--position", "10"], "more than the body's extent (1 m)"),
        (["--position", "1um", "--levels", "1e31"], "largest level 1e+31"),
        (["--position", "60%", "--levels", "1,2"], "120%, past 100 %"),
        (["--charge", "1"], "more than the largest charge (0.8 C)"),
        (["--mass", "0.2"], "more than the largest mass (0.1 kg)"),
    ],
)
def test_tolerance_errors_stay_within_what_they_perturb(
    argv: list[str], named: str, work: Path, capsys
) -> None:
    (work / "design.json").write_text(json.dumps(SMALL_DESIGN))
    line = refused(["tolerance", "design.json", *argv, "--out", "o"], "tolerance", capsys, work)
    assert named in line, line


@pytest.mark.parametrize("argv", READERS, ids=lambda a: a[0])
@pytest.mark.parametrize(
    ("recorded", "named"),
    [
        ({"chi_relative": 2}, "material_errors.chi_relative: expected a relative error in [0, 1)"),
        ({"chi_relative": "5%"}, "material_errors.chi_relative: expected a real number"),
        ({"bogus": 0.1}, "material_errors.bogus"),
        ([0.1], "material_errors: expected a table"),
    ],
)
def test_recorded_material_errors_are_read_by_every_reader(
    argv: list[str], recorded: object, named: str, work: Path, capsys
) -> None:
    """design.json's material_errors (the scene's [tolerance]): check passed a file whose
    chi_relative was 2 or a string; only tolerance read it."""
    data = json.loads(json.dumps(SMALL_DESIGN))
    data["material_errors"] = recorded
    (work / "j.json").write_text(json.dumps(data))
    line = refused(argv, argv[0], capsys, work)
    assert named in line, line
