"""A ``[case]`` not of the theorem's form, with ``[medium]``: real parts on the one program.

The physical program designs carriers, magnets and ballast for any linear conditions; what it
read of the theorem was the body's typical rate and torque (its budgets, window and support)
and the designed V the balance is held against. A general case's body reads its own
(:func:`chargedesign.physical.realism.model_scales`, :func:`~chargedesign.physical.realism.
general_case_functions`). Checked here by independent routes: the typical rate against its
closed form, the written body against ``chargedesign check`` (which recomputes every part's
inertia, the limits and the verdict from design.json), and the refusals before the work.
"""

from __future__ import annotations

import json
import math
import tomllib
from pathlib import Path

import numpy as np
import pytest

import chargedesign as cd
from chargedesign.cli import main
from chargedesign.designer.assembly import design_physical
from chargedesign.designer.pipeline import physical_setup_from_scene
from chargedesign.errors import InputError
from chargedesign.physical.realism import model_scales, typical_rate
from chargedesign.scene import load_scene, scene_from_dict

EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "scenes"
AXISYMMETRIC = EXAMPLES / "axisymmetric_case.toml"


def _scene_data(name: str) -> dict:
    return tomllib.loads((EXAMPLES / name).read_text("utf-8"))


def _design_and_check(path: Path, out: Path, capsys: pytest.CaptureFixture[str]) -> dict:
    """``chargedesign design`` then ``chargedesign check --json`` of what it wrote."""
    assert main(["design", str(path), "--out", str(out), "--no-picture", "--quiet"]) == 0
    capsys.readouterr()
    assert main(["check", str(out / "design.json"), "--json"]) == 0
    return json.loads(capsys.readouterr().out)


def test_the_axisymmetric_top_is_built_of_magnets_and_ballast_and_checked_from_its_files(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    report = _design_and_check(AXISYMMETRIC, tmp_path / "out", capsys)
    # the check compares with the case itself, every part's own inertia counted
    assert report["reference"] == "case" and report["reproduced"]
    for key in ("V_rel_err", "potential_torque_rel_err", "inertia_rel_err"):
        assert report[key] <= 1e-12, key
    assert report["buildable"] and report["parts_within_limits"] and report["verdict_agrees"]
    written = json.loads((tmp_path / "out" / "design.json").read_text("utf-8"))
    assert written["case"]["certificate"]["holds"]
    assert written["verdict"]["state"] == "buildable and realised"
    assert len(written["dipoles"]["moments"]) > 0  # the magnets realise V's degree 2
    assert written["frontier"]["s_max"] > 1.0  # located as for the theorem's scenes


def test_its_typical_rate_is_the_cases_own_closed_form() -> None:
    """V = C k gamma3^2: |gamma x dV/dgamma| = 2 C k |gamma3| sqrt(1 - gamma3^2), largest C k at
    45 degrees, so the typical rate sqrt(T_V / C) is sqrt(k); the theorem's formula would read
    the recorded parameters (C only) and give 0."""
    result = cd.design(str(AXISYMMETRIC))
    k = _scene_data("axisymmetric_case.toml")["case"]["parameters"]["k"]
    scales = model_scales(result.design)
    assert typical_rate(result.design.parameters) == 0.0
    assert scales.rate == pytest.approx(math.sqrt(k), rel=1e-4)
    assert result.design.realism["typical_rate_1_per_s"] == scales.rate
    assert scales.C == pytest.approx(2.0e-5, rel=1e-15)


def test_the_kowalevski_top_with_medium_is_a_heavy_top_of_ballast(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """V = C a gamma1 by masses in the laboratory's g: the centre of mass on the x axis. The
    typical rate is sqrt(a) (|gamma x e1| is at most 1); the check recomputes the body."""
    data = _scene_data("kowalevski_case.toml")
    data["medium"] = {"name": "vacuum"}
    result = cd.design(scene_from_dict(data, "<kowalevski with medium>"))
    design = result.design
    a = data["case"]["parameters"]["a"]
    assert model_scales(design).rate == pytest.approx(math.sqrt(a), rel=1e-4)
    positions, masses = design.all_masses()
    centre = masses @ positions / masses.sum()
    g = 9.80665
    # V = M g x_cm gamma1 = C a gamma1 (the case's own V, to the polish's round-off)
    assert masses.sum() * g * centre[0] == pytest.approx(0.3 * a, rel=1e-9)
    assert np.allclose(centre[1:], 0.0, atol=1e-12)
    path = tmp_path / "kowalevski.toml"
    path.write_text(
        (EXAMPLES / "kowalevski_case.toml").read_text("utf-8") + '\n[medium]\nname = "vacuum"\n',
        "utf-8",
    )
    report = _design_and_check(path, tmp_path / "out", capsys)
    assert report["reference"] == "case" and report["reproduced"] and report["verdict_agrees"]
    # its masses realise V: the physical program scales the carriers' and magnets' conditions
    # with the rate, not the masses', so its frontier is refused in one line (and noted)
    assert any(n.startswith("frontier not located: the masses realise") for n in design.notes)
    with pytest.raises(InputError, match=r"frontier: the masses realise part of this case's V"):
        cd.frontier(scene_from_dict(data, "<kowalevski with medium>"))


def test_the_frontier_and_window_of_a_general_case_and_a_body_at_another_rate(
    capsys: pytest.CaptureFixture[str],
) -> None:
    """The frontier scales the case by its time rate (s^2 V, s l: model.frame.time_rescaled).
    A body designed at s = 4, checked by `check` against the case at its recorded rate,
    reproduces it; read at rate 1 (its time rate dropped) its V is s^2 times the case's."""
    frontier = cd.design(str(AXISYMMETRIC)).design.frontier
    front = cd.frontier(str(AXISYMMETRIC))
    assert front.s_max == frontier["s_max"] > 1.0
    assert front.to_dict()["case"] == "axisymmetric magnetic top"
    assert "the case axisymmetric magnetic top at time rate s: V x s^2" in str(front)
    window = frontier["realised"]
    # the scene's own body is accepted and realised at s = 1 (its verdict), so its window
    # holds s = 1: s_min is the balance of the body designed there, not the heavier s_max
    # body's (which alone gave 1.77)
    assert 0.0 < window["s_low"] < 1.0 < window["s_high"] <= frontier["s_max"]
    assert window["s_low"] >= frontier["s_min"] > 0.0
    scene = load_scene(AXISYMMETRIC)
    # the body designed at s_min is accepted there (design_physical raises otherwise), by its
    # own balance bound
    lowest = design_physical(physical_setup_from_scene(scene), scale=frontier["s_min"]).design
    assert lowest.balance["lowest_rate"] <= frontier["s_min"]
    s = 4.0  # inside the window
    body = design_physical(physical_setup_from_scene(scene), scale=s).design
    assert body.time_rate == s
    report = cd.check(body)
    assert report.reference == "case" and report.reproduced
    assert report.to_dict()["V_rel_err"] <= 1e-12
    body.time_rate = None  # the same parts read as the case at rate 1
    missed = cd.check(body).to_dict()["V_rel_err"]
    assert missed == pytest.approx(s**2 - 1.0, rel=1e-9)  # V is s^2 the rate-1 case's
    assert main(["frontier", str(AXISYMMETRIC), "--recommend", "x.toml"]) != 0
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "--recommend vary the theorem's [parameters]" in err


def test_a_gravity_gradient_the_conditions_would_derive_is_refused_before_the_work() -> None:
    """Without [fields.gravity] the engine realises V's degree 2 by masses in a derived gravity
    gradient (1.33 1/s^2 here); real parts feel their site's uniform g only."""
    data = _scene_data("axisymmetric_case.toml")
    del data["fields"]["gravity"]
    with pytest.raises(InputError, match=r"gravity gradient .* derived\): a site.s gravity"):
        cd.design(scene_from_dict(data, "<no gravity given>"))


def test_a_derived_g_where_the_support_has_none_is_refused() -> None:
    """The Kowalevski top's masses need the laboratory's g; in free fall there is none."""
    data = _scene_data("kowalevski_case.toml")
    data["medium"] = {"name": "vacuum"}
    data["support"] = {"style": "free_fall", "facility": "drop_tower_catapult"}
    with pytest.raises(InputError, match="but the support's is"):
        cd.design(scene_from_dict(data, "<kowalevski in free fall>"))
