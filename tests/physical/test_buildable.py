"""Buildable bodies: limits recomputed independently, all mass sets, the frontier, bad input."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from chargedesign.body import Design, read_design
from chargedesign.cli import main
from chargedesign.constants import COULOMB, EPSILON_0
from chargedesign.designer.assembly import design_physical
from chargedesign.designer.charges import charge_program, design_charges
from chargedesign.designer.frontier import find_frontier
from chargedesign.designer.pipeline import physical_setup_from_scene
from chargedesign.errors import InputError
from chargedesign.physical.bom import bom_csv, bom_rows
from chargedesign.physical.coulomb import coulomb_field
from chargedesign.physical.holder import design_parts
from chargedesign.physical.limits import (
    carrier_surface_fields,
    check_limits,
)
from chargedesign.sampling import fibonacci_sphere
from chargedesign.scene import load_scene, scene_from_dict

HERE = Path(__file__).parent
SMALL = HERE / "small.toml"


@pytest.fixture(scope="module")
def setup():
    return physical_setup_from_scene(load_scene(SMALL))


@pytest.fixture(scope="module")
def frontier(setup):
    return find_frontier(setup)


@pytest.fixture(scope="module")
def result(setup, frontier):
    """Designed near the frontier, where the surface fields bind."""
    return design_physical(setup, scale=0.95 * frontier.s_max)


def dense_surface_max(design: Design, samples: int = 20000) -> np.ndarray:
    """Brute force: the largest |E| on each carrier sphere, far denser than the design's."""
    dirs = fibonacci_sphere(samples)
    out = []
    for c, a in zip(design.charge_positions, design.carrier_radii(), strict=True):
        pts = c + a * dirs
        d = pts[:, None, :] - design.charge_positions[None, :, :]
        e = COULOMB * np.einsum(
            "pnk,pn->pk", d, design.charge_values / np.linalg.norm(d, axis=2) ** 3
        )
        out.append(np.linalg.norm(e, axis=1).max())
    return np.array(out)


def test_every_surface_field_is_below_the_safe_field(result):
    design = result.design
    dense = dense_surface_max(design)
    safe = design.medium.safety * design.medium.breakdown
    assert np.all(dense <= safe), dense.max() / safe
    # near the frontier the design works at its limit: the largest carrier is within 1 %
    assert dense.max() > 0.99 * safe


def test_the_limits_check_finds_the_dense_maximum_on_random_bodies():
    rng = np.random.default_rng(3)
    for _ in range(5):
        # carriers as a design places them: on a lattice 4 radii apart, jittered
        grid = np.stack(np.meshgrid(*[np.arange(3)] * 3), axis=-1).reshape(-1, 3)
        pos = (grid[rng.choice(27, 12, replace=False)] + rng.uniform(-0.2, 0.2, (12, 3))) * 0.01
        q = rng.normal(0, 1e-9, 12)
        radii = np.full(12, 0.002)
        fields, _ = carrier_surface_fields(pos, q, radii, ())
        brute = np.array(
            [
                np.linalg.norm(
                    coulomb_field(pos, q, pos[i] + 0.002 * fibonacci_sphere(20000)), axis=1
                ).max()
                for i in range(12)
            ]
        )
        # the check never under-reports by more than the brute force's own sampling error
        assert np.all(fields >= brute * (1 - 1e-5))
        assert np.all(fields <= brute * (1 + 1e-3))


def test_own_field_of_a_lone_carrier_is_coulomb():
    fields, _ = carrier_surface_fields(np.zeros((1, 3)), np.array([1e-9]), np.array([0.01]), ())
    assert fields[0] == pytest.approx(1e-9 / (4 * math.pi * EPSILON_0 * 1e-4), rel=1e-12)


def test_all_three_mass_sets_give_the_inertia_and_centre(result, setup):
    design = result.design
    assert len(design.charge_values) and np.all(design.carrier_masses() > 0)
    assert np.all(design.magnet_masses() >= 7500 * design.magnet_volumes())
    r, m = design.all_masses()
    C = setup.params.C
    # the point masses plus every part's own inertia (spheres; the carriers hollow shells)
    own = float(np.sum(design_parts(design).own_inertia()))
    assert own > 1e-4 * C
    A = np.sum(m * (r[:, 1] ** 2 + r[:, 2] ** 2)) + own
    B = np.sum(m * (r[:, 0] ** 2 + r[:, 2] ** 2)) + own
    Cz = np.sum(m * (r[:, 0] ** 2 + r[:, 1] ** 2)) + own
    scale = np.sum(m * np.sum(r**2, axis=1))
    for value, target in ((A, 2 * C), (B, 2 * C), (Cz, C)):
        assert abs(value - target) <= 1e-12 * scale
    for i, j in ((0, 1), (0, 2), (1, 2)):
        assert abs(np.sum(m * r[:, i] * r[:, j])) <= 1e-12 * scale
    total = np.asarray(design.inertia["total_kg_m2"])
    assert np.allclose(total, np.diag([2 * C, 2 * C, C]), rtol=0, atol=1e-12 * scale)
    # the carriers alone are a real share of the body: leaving them out breaks the inertia
    ballast_only = np.sum(design.mass_values * np.sum(design.mass_positions[:, :2] ** 2, axis=1))
    assert abs(ballast_only - C) > 1e-6 * C


def test_design_passes_its_forward_check_and_the_limits_check(result):
    from chargedesign.designer.acceptance import body_check

    # small.toml has [medium]: the frame reading, checked against n = 0
    assert result.design.larmor.reading == "frame"
    report = body_check(result.design)
    assert report.passed, str(report)
    limits = check_limits(result.design)
    assert limits.parts_within_limits and not limits.violations


def test_design_json_round_trip_keeps_every_part(result, tmp_path):
    from chargedesign.body import write_design

    write_design(result.design, tmp_path / "d.json")
    again = read_design(tmp_path / "d.json")
    data = json.loads((tmp_path / "d.json").read_text())
    assert {"radii", "masses"} <= set(data["charges"]) and {"volumes", "masses"} <= set(
        data["dipoles"]
    )
    assert data["medium"]["name"] == "air" and data["medium"]["breakdown_V_per_m"] == 3e6
    assert again.total_mass == pytest.approx(result.design.total_mass, rel=1e-15)
    assert check_limits(again).parts_within_limits


def test_bill_of_materials_lists_every_part(result):
    design = result.design
    rows = bom_rows(design)
    assert len(rows) == design.n_elements
    assert sum(r["mass_kg"] for r in rows) == pytest.approx(design.total_mass, rel=1e-13)
    text = bom_csv(design)
    assert text.splitlines()[0].startswith("part,kind,x_m")
    assert len(text.splitlines()) == design.n_elements + 1


def test_frontier_brackets_the_buildable(setup, frontier):
    """Design accepts 0.98 s_max (limits and forward check) and refuses 1.02 s_max in one
    line naming the binding limit (small.toml, the frame reading)."""
    from chargedesign.designer.acceptance import forward_acceptance
    from chargedesign.errors import InfeasibleError

    assert frontier.s_max > 1.0  # the scene's own rate is buildable
    assert frontier.binding.stage in ("charges", "masses", "magnets", "fields")
    forward_acceptance(design_physical(setup, scale=0.98 * frontier.s_max).design)
    with pytest.raises(InfeasibleError) as info:
        forward_acceptance(design_physical(setup, scale=1.02 * frontier.s_max).design)
    text = str(info.value)
    assert text and "\n" not in text and "time rate s =" in text
    assert "charge at" in text or "inertia" in text or "ballast" in text or "magnet" in text
    # the frame reading: n is free (a rotation of axes), the frontier is K's
    assert frontier.larmor == "frame" and frontier.n_max is None
    assert frontier.K_max == pytest.approx(frontier.s_max * 0.7e-7)
    assert math.isinf(frontier.period)


def test_the_necessary_bound_is_an_upper_bound(setup, frontier):
    assert frontier.s_necessary >= frontier.s_max


def test_frontier_scales_with_the_breakdown_field(frontier):
    """Where breakdown binds, n_max is linear in the safe field (the scaling law)."""
    data = scene_with(medium={"name": "air", "safety": 0.25})
    half = find_frontier(physical_setup_from_scene(data))
    assert half.s_max / frontier.s_max == pytest.approx(0.5, rel=0.03)


def test_constraint_generation_equals_the_full_cvxpy_program_when_no_limit_binds(setup):
    """At a small rate no carrier is near its limit: the LP path and the full program agree."""
    import cvxpy as cp

    s = 0.05
    fast = design_charges(setup, s)
    program = charge_program(setup, s, samples=12)
    program.problem.solve(solver=cp.CLARABEL)
    full = float(np.sum(np.abs(program.q.value))) * program.charge_scale
    assert fast.cones == 0
    assert float(np.sum(np.abs(fast.charges))) == pytest.approx(full, rel=1e-6)


def test_beyond_the_frontier_the_design_fails_with_one_line(setup, frontier):
    with pytest.raises(Exception) as info:
        design_physical(setup, scale=2 * frontier.s_max)
    text = str(info.value)
    assert "\n" not in text
    assert "time rate s =" in text and "vacuum or a medium with a higher breakdown" in text


def scene_with(**tables):
    import tomllib

    data = tomllib.loads(SMALL.read_text())
    for key, value in tables.items():
        data[key] = value
    return scene_from_dict(data, "<test>")


@pytest.mark.parametrize(
    ("tables", "key"),
    [
        ({"medium": {"name": "helium"}}, "medium.name"),
        ({"medium": {"breakdown": -1.0}}, "medium.breakdown"),
        ({"medium": {"breakdown": 0.0}}, "medium.breakdown"),
        ({"medium": {"name": "air", "safety": 1.5}}, "medium.safety"),
        ({"medium": {"name": "air", "safety": 0.0}}, "medium.safety"),
        ({"medium": {"name": "air"}, "carriers": {"density": -2.0}}, "carriers.density"),
        ({"medium": {"name": "air"}, "ballast": {"density": -2.0}}, "ballast.density"),
        ({"medium": {"name": "air"}, "magnets": {"material": "unobtainium"}}, "magnets.material"),
        (
            {
                "medium": {"name": "air"},
                "body": {
                    "shape": "ball",
                    "radius": 0.05,
                    "spacing": 0.0167,
                    "carrier_radius": 0.0084,
                },
            },
            "body.carrier_radius",
        ),
    ],
)
def test_bad_physical_input_names_the_key(tables, key):
    with pytest.raises(InputError, match=key.replace(".", r"\.")):
        physical_setup_from_scene(scene_with(**tables))


def test_a_field_limit_the_fixed_field_exceeds_is_refused():
    import tomllib

    data = tomllib.loads(SMALL.read_text())
    data["fields"]["magnetic"]["max"] = 1.0
    with pytest.raises(InputError, match=r"fields\.magnetic\.max"):
        physical_setup_from_scene(scene_from_dict(data, "<test>"))


def test_cli_bad_medium_is_one_line_and_writes_nothing(tmp_path, capsys):
    scene = tmp_path / "bad.toml"
    scene.write_text(SMALL.read_text().replace('name = "air"', 'name = "helium"'))
    out = tmp_path / "out"
    # in-process: the command's exit code and stderr (an escaping exception fails the test)
    code = main(["design", str(scene), "--out", str(out), "--quiet"])
    err = capsys.readouterr().err
    assert code == 2
    assert err.strip().count("\n") == 0 and "medium.name" in err
    assert not out.exists()


def test_cli_frontier_json_has_the_contract_keys(capsys):
    code = main(["frontier", str(SMALL), "--json", "--quiet"])
    captured = capsys.readouterr()
    assert code == 0, captured.err
    data = json.loads(captured.out)
    assert {"s_max", "n_max", "K_max", "larmor", "binding"} <= set(data)
    # small.toml has [medium]: the frame reading, where n is free and K binds
    assert data["larmor"] == "frame" and data["n_max"] is None and data["n_free"] is True
    assert data["K_max"] == pytest.approx(data["s_max"] * 0.7e-7)


def test_the_embedded_default_is_buildable():
    """`make demo`'s body: an independent recheck of every limit, and the forward check."""
    from chargedesign.designer import design_from_scene
    from chargedesign.designer.acceptance import body_check

    design = design_from_scene(load_scene(None), frontier=False).design
    assert design.medium is not None and design.medium.name == "vacuum"
    assert design.larmor.reading == "frame" and design.larmor.rate == 2.45e-6
    assert check_limits(design).parts_within_limits
    assert body_check(design).passed
    assert design.realism["v_over_c"]["verdict"] == "negligible"
    # ... but the applied field acts on its tungsten and aluminium far more than the designed
    # charges and magnets do (docs/buildable.md, "The applied field acts on every part")
    realism = design.realism
    assert realism["induced_magnetisation_fraction"]["value"] > 1e10
    assert realism["eddy_torque_fraction"]["value"] > 1e6
    from chargedesign.report import render_report

    # three states (docs/buildable.md): its magnets are below the continuum size (not
    # buildable as specified), and were they larger the parts would not be realised
    text = render_report(design)
    assert text.splitlines()[2].startswith("**Verdict: NOT buildable**")
    (row,) = [x for x in text.splitlines() if x.startswith("| buildable parts, NOT realised")]
    assert "induced magnetisation" in row
