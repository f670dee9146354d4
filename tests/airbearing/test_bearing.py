"""The bearing as an outside checker reads it from testbed.json: every planned motion's largest
tilt (recomputed by another integrator and a longer horizon), the keep-out cone (every part
clear, by the contract's formula), the requirements' own numbers and the verdict's rule."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.spatial import cKDTree
from testbed_scene import EXAMPLE, SMALL

from chargedesign.airbearing.bearing import (
    TORUS_JOIN,
    best_axis,
    clear_of_cone,
    fitting_starts,
    keep_out,
)
from chargedesign.airbearing.run import build_testbed
from chargedesign.cli import main
from chargedesign.errors import InputError
from chargedesign.model import evaluators
from chargedesign.params import Parameters
from chargedesign.physical.limits import close_pairs
from chargedesign.scene.testbed import TestbedOptions

TINY = [
    "t_end_s = 0.4",
    "rate_Hz = 20.0",
    "seeds = 2",
    "requirement_rates_Hz = [20.0]",
    "requirement_seeds = 1",
]
SCENE = Path(__file__).resolve().parents[2] / "examples" / "scenes" / "testbed.toml"


def _scene(tmp: Path, extra: list[str]) -> Path:
    head, table = SCENE.read_text().split("\n[testbed]\n")
    keep = [
        line
        for line in table.splitlines()
        if line.split("=")[0].strip() not in {x.split("=")[0].strip() for x in extra}
    ]
    path = tmp / "scene.toml"
    path.write_text(head + "\n[testbed]\n" + "\n".join(keep + extra) + "\n")
    return path


@pytest.fixture(scope="module")
def written(tmp_path_factory: pytest.TempPathFactory) -> dict:
    tmp = tmp_path_factory.mktemp("bearing")
    out = tmp / "out"
    assert main(["testbed", str(_scene(tmp, TINY)), "--out", str(out), "--quiet"]) == 0
    return json.loads((out / "testbed.json").read_text())


def _largest_tilt(params: Parameters, start: list[float], horizon: float, u: np.ndarray) -> float:
    """LSODA (not the tool's DOP853), sampled every 0.05 s, the peaks refined by a parabola."""
    sol = solve_ivp(
        evaluators.rhs_function(params),
        (0.0, horizon),
        np.array(start),
        method="LSODA",
        rtol=1e-11,
        atol=1e-12,
        dense_output=True,
    )
    assert sol.success
    t = np.arange(0.0, horizon, 0.05)
    tilt = np.degrees(np.arccos(np.clip(sol.sol(t)[3:6].T @ u, -1.0, 1.0)))
    return float(tilt.max())


def test_planned_tilts_agree_with_an_independent_integration(written: dict) -> None:
    params = Parameters(**{k: v for k, v in written["parameters"].items() if k != "lambda"})
    u = np.array(written["bearing"]["pedestal_axis"])
    limit = written["bearing"]["tilt_limit_deg"]
    for motion in written["results"]["planned_motions"]:
        horizon = motion["horizon_s"]
        mine = _largest_tilt(params, motion["initial_state"], horizon, u)
        assert abs(mine - motion["tilt_max_deg"]) <= 0.5
        # a longer horizon does not raise it past the checker's half degree
        assert _largest_tilt(params, motion["initial_state"], 2.0 * horizon, u) <= (
            motion["tilt_max_deg"] + 0.5
        )
        assert motion["tilt_max_deg"] <= limit


def test_no_part_enters_the_keep_out_cone(written: dict) -> None:
    cone = written["bearing"]["keep_out"]
    axis = np.array(cone["axis"])
    parts = [
        (np.array(written["ballast"]["positions"]), np.array(written["ballast"]["radii"])),
        (np.array(written["wheels"]["positions"]), np.array(written["wheels"]["radii"])),
    ]
    for centres, radii in parts:
        dist = np.linalg.norm(centres, axis=1)
        angle = np.degrees(np.arccos(centres @ axis / dist)) - np.degrees(np.arcsin(radii / dist))
        assert (angle >= cone["half_angle_deg"] - 1e-9).all()
        assert (dist + radii <= written["platform"]["radius_m"] + 1e-12).all()
    # the keep-out axis is the pedestal's side: opposite the pedestal axis
    assert np.allclose(axis, -np.array(written["bearing"]["pedestal_axis"]), atol=1e-12)


def test_requirements_marked_met_are_met_by_their_numbers(written: dict) -> None:
    reqs = written["state_of_the_art"]
    assert {r["name"] for r in reqs} >= {
        "bearing_tilt_deg",
        "bearing_load_kg",
        "wheel_torque_N_m",
        "wheel_momentum_N_m_s",
        "centre_of_mass_offset_m",
        "bearing_drag_N_m_s",
        "nominal_I4_drift",
    }
    for r in reqs:
        assert r["source"]
        if r["met"]:
            assert (
                (r["best"] <= r["required"])
                if r["kind"] == "tolerance"
                else (r["required"] <= r["best"])
            )
    median = written["results"]["nominal"]["I4_relative_drift_median"]
    buildable = all(r["met"] for r in reqs) and median <= written["results"]["target_I4_drift"]
    assert written["verdict"]["buildable"] is buildable
    if not buildable:
        assert written["verdict"]["line"].startswith(
            "NOT buildable: " + written["verdict"]["binding"]
        )


def test_the_cone_formula_on_a_sphere_touching_it() -> None:
    """A sphere whose rim lies exactly on the cone's surface is clear; nudged in, it is not."""
    cone = keep_out(np.array([0.0, 0.0, 1.0]), 30.0, 0.05, 0.0)
    assert cone is not None and cone.half_angle_deg == 30.0
    d, a = 0.2, 0.02
    angle = math.radians(180.0 - 30.0) - math.asin(a / d)  # from +z: the cone is about -z
    centre = d * np.array([math.sin(angle), 0.0, math.cos(angle)])
    assert clear_of_cone(np.array([centre * (1 + 1e-12)]), np.array([a * (1 - 1e-9)]), cone)[0]
    assert not clear_of_cone(np.array([centre]), np.array([a * 1.01]), cone)[0]


def test_best_axis_is_the_centre_of_the_smallest_cap() -> None:
    """Points on a circle of 20 deg about an axis: the best axis is that axis, 20 deg."""
    axis = np.array([1.0, 2.0, 2.0]) / 3.0
    e1 = np.cross(axis, [0.0, 0.0, 1.0])
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(axis, e1)
    phi = np.linspace(0.0, 2.0 * np.pi, 721)
    a = math.radians(20.0)
    pts = math.cos(a) * axis + math.sin(a) * (np.outer(np.cos(phi), e1) + np.outer(np.sin(phi), e2))
    u = best_axis([pts])
    assert np.degrees(np.arccos(np.clip(u @ axis, -1, 1))) < 1e-3


def test_fitting_starts_are_on_I3_zero_at_the_asked_tilt() -> None:
    starts, gamma_e = fitting_starts(EXAMPLE, [10.0, 20.0])
    values = evaluators.integrals(starts, EXAMPLE)
    assert np.abs(values[:, 2]).max() < 1e-14  # I3
    tilts = np.degrees(np.arccos(starts[:, 3:6] @ gamma_e))
    assert np.allclose(tilts, [10.0, 20.0], atol=1e-9)


def test_a_start_beyond_the_tilt_limit_is_refused_with_the_tilt_and_a_start_that_fits() -> None:
    opts = TestbedOptions.from_table({**SMALL, "bearing": "tabletop"})
    with pytest.raises(InputError) as info:
        build_testbed(EXAMPLE, opts, with_requirements=False)
    text = str(info.value)
    assert "\n" not in text
    assert "deg of tilt" in text and "allows 30 deg" in text and "initial_gamma = [" in text


def test_the_tilt_map_agrees_with_the_integrated_planned_motions(written: dict) -> None:
    """The planned motions lie next to the elliptic periodic orbits that bound each energy's
    I4: the map's top cells (the level sampled, split into tori, the best-hosted one's
    largest tilt), read at each motion's energy, give the tilt its integration needs within
    the sampling grid's resolution (4 deg)."""
    params = Parameters(**{k: v for k, v in written["parameters"].items() if k != "lambda"})
    m = written["bearing"]["tilt_map"]
    assert m["limit_deg"] == written["bearing"]["tilt_limit_deg"]
    h = np.array(m["h_J"])
    tilt = np.array([[np.nan if v is None else v for v in row] for row in m["tilt_max_deg"]])
    top = np.nanmax(tilt[:, -3:], axis=1)
    for motion in written["results"]["planned_motions"]:
        H = evaluators.integrals(np.array(motion["initial_state"]), params)[0]
        assert h[0] - (h[1] - h[0]) <= H <= h[-1]
        assert abs(np.interp(H, h, top) - motion["tilt_max_deg"]) < 4.0


def test_the_tori_are_joined_by_every_pair_of_points_at_most_the_join_apart() -> None:
    """The tilt map splits a level's points into tori by :func:`close_pairs` (once a kd-tree's
    ``query_pairs``): on scaled states (omega in a cube, gamma on the sphere) with pairs planted
    exactly at the join and one rounding step beyond it, the pairs are those of the whole
    distance matrix with ``<=`` (the tie in, the next one out), in lexicographic order, and the
    kd-tree's set."""
    rng = np.random.default_rng(39)
    gamma = rng.normal(size=(600, 3))
    points = np.concatenate(
        [rng.uniform(-1, 1, (600, 3)), gamma / np.linalg.norm(gamma, axis=1, keepdims=True)], axis=1
    )
    join = TORUS_JOIN * 2.0**-4  # a grid spacing that keeps the planted distances exact
    tie = np.array([0.5, 0.0, 0.0, 0.0, 0.0, 1.0])
    at = tie.copy()
    at[0] += join  # exactly the join from the tie
    beyond = np.array([0.5, 0.5, 0.0, 0.0, 0.0, 1.0])
    past = beyond.copy()
    past[1] = np.nextafter(0.5 + join, 1.0)  # the least float farther than the join
    points = np.concatenate([points, [tie, at, beyond, past]])
    d2 = np.sum((points[:, None] - points[None]) ** 2, axis=2)
    i, j = np.nonzero(np.triu(d2 <= join * join, k=1))
    n = len(points)
    assert d2[n - 4, n - 3] == join * join and d2[n - 2, n - 1] > join * join
    pairs = close_pairs(points, join)
    assert np.array_equal(pairs, np.stack([i, j], axis=1))
    assert [n - 4, n - 3] in pairs.tolist() and [n - 2, n - 1] not in pairs.tolist()
    assert {tuple(p) for p in cKDTree(points).query_pairs(join, output_type="ndarray")} == {
        tuple(p) for p in pairs
    }


def test_a_full_sphere_holds_a_tumbling_start_and_reports_its_own_limits() -> None:
    result = build_testbed(EXAMPLE, TestbedOptions.from_table(SMALL), with_requirements=False)
    bearing = result.to_dict()["bearing"]
    assert bearing["style"] == "full_sphere" and bearing["keep_out"] is None
    assert bearing["tilt_limit_deg"] == 180.0
    assert result.plan is not None and result.plan.motions[0].tilt_max_deg > 90.0  # it tumbles
    ball = bearing["full_sphere"]
    assert ball["ball_diameter_m"] == 2 * SMALL["platform_radius_m"]
    # the cup's film lies under the whole ball: its drag is the one the loop carries
    assert result.to_dict()["disturbances"]["drag_N_m_s"] == ball["air_film_drag_N_m_s"]
    half = math.radians(ball["cup_half_angle_deg"])
    assert ball["cup_coverage_sr"] == pytest.approx(2 * math.pi * (1 - math.cos(half)), rel=1e-12)


def test_the_zoh_figure_agrees_with_an_independent_loop(written: dict) -> None:
    """testbed.json's zoh_noise_free drift recomputed from its own numbers: the command
    ``-J f - omega x (J omega + h)`` (f from the theorem's equations) sampled every period,
    acting ``delay_s`` later, the plant by adaptive LSODA between switches."""
    params = Parameters(**{k: v for k, v in written["parameters"].items() if k != "lambda"})
    J = np.array(written["inertia_total_kg_m2"])
    Jinv = np.linalg.inv(J)
    rate, delay = written["control"]["rate_Hz"], written["control"]["delay_s"]
    T = 1.0 / rate
    steps = round(written["results"]["t_simulated_s"] * rate)
    rhs = evaluators.rhs_function(params)

    def command(y: np.ndarray) -> np.ndarray:
        omega, h = y[0:3], y[6:9]
        f = rhs(0.0, y[0:6])[0:3]
        return -J @ f - np.cross(omega, J @ omega + h)

    def plant(torque: np.ndarray) -> object:
        def f(_t: float, y: np.ndarray) -> np.ndarray:
            omega, gamma, h = y[0:3], y[3:6], y[6:9]
            domega = Jinv @ (-np.cross(omega, J @ omega + h) - torque)
            return np.concatenate([domega, np.cross(gamma, omega), torque])

        return f

    y = np.concatenate([written["results"]["initial_state"], np.zeros(3)])
    held = command(y)
    i4 = [evaluators.integrals(y[0:6], params)[3]]
    for _ in range(steps):
        new = command(y)
        for torque, dt in ((held, delay), (new, T - delay)):
            sol = solve_ivp(plant(torque), (0.0, dt), y, method="LSODA", rtol=1e-12, atol=1e-14)
            y = sol.y[:, -1]
        held = new
        i4.append(evaluators.integrals(y[0:6], params)[3])
    i4 = np.array(i4)
    mine = float(np.abs(i4 - i4[0]).max() / abs(i4[0]))
    theirs = written["results"]["zoh_noise_free"]["I4_relative_drift"]
    assert mine / 1.05 <= theirs <= 1.05 * mine
