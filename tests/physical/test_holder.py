"""The whole inertia and the holder: the parts as spheres, the holder's bores, the design's
fixed point, the outside-style recomputation, and the eddy law with the motion through the
gradient."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from chargedesign.checker.inertia import holder_inertia, own_inertia
from chargedesign.designer.assembly import design_physical
from chargedesign.designer.pipeline import physical_setup_from_scene
from chargedesign.errors import InfeasibleError, InputError
from chargedesign.fields import AxisymmetricField
from chargedesign.physical.holder import (
    Holder,
    design_parts,
    holder_material,
    monomial_moments,
    parts_from_arrays,
    point_inertia,
    whole_inertia,
)
from chargedesign.physical.parasitics import (
    eddy_rate_squared,
    eddy_torque,
    eddy_torques_by_set,
    holder_eddy_torque,
)
from chargedesign.scene import load_scene, scene_from_dict

HERE = Path(__file__).parent
HELD = HERE / "holder.toml"


@pytest.fixture(scope="module")
def held():
    return design_physical(physical_setup_from_scene(load_scene(HELD))).design


def test_a_sphere_has_the_moments_of_its_mass_spread_about_its_centre():
    rng = np.random.default_rng(3)
    c = np.array([0.01, -0.02, 0.03])
    a, rho = 0.004, 2200.0
    parts = parts_from_arrays(ballast=(c[None], np.array([rho * 4 / 3 * math.pi * a**3]), [rho]))
    m = parts.masses[0]
    # Monte Carlo of the uniform ball against the exact expansion, to its own noise
    n = 400_000
    pts = rng.uniform(-a, a, (n, 3))
    pts = c + pts[np.sum(pts**2, axis=1) <= a * a]
    keys = ["", "x", "xx", "xy", "zz", "xxz", "xxzz", "zzzz"]
    exact = monomial_moments(keys, parts.centres, parts.radial_moments, parts.masses)[:, 0]
    exps = [(k.count("x"), k.count("y"), k.count("z")) for k in keys]
    mc = [m * np.mean(pts[:, 0] ** i * pts[:, 1] ** j * pts[:, 2] ** k) for i, j, k in exps]
    np.testing.assert_allclose(exact, mc, rtol=2e-2)
    assert parts.own_inertia()[0] == pytest.approx(0.4 * m * a * a, rel=1e-14)


def test_the_holder_is_a_sphere_less_its_bores():
    parts = parts_from_arrays(
        ballast=(np.array([[0.02, 0, 0], [0, 0, -0.03]]), np.array([1e-3, 2e-3]), [19250.0] * 2)
    )
    holder = Holder("peek", 1320.0, 0.04, parts.centres, parts.outer, parts.names, -9e-6, 1e-14)
    sphere = 0.4 * 1320.0 * 4 / 3 * math.pi * 0.04**5
    bores = 1320.0 * 4 / 3 * math.pi * parts.outer**3
    expected = (
        sphere * np.eye(3)
        - point_inertia(parts.centres, bores)
        - float(np.sum(0.4 * bores * parts.outer**2)) * np.eye(3)
    )
    np.testing.assert_allclose(holder.inertia(), expected, rtol=1e-14)
    # not isotropic: the bores carry the contrast
    assert abs(holder.inertia()[0, 0] - holder.inertia()[2, 2]) > 1e-3 * sphere * 1e-3
    assert holder.volume == pytest.approx(4 / 3 * math.pi * (0.04**3 - np.sum(parts.outer**3)))
    assert holder.mass == pytest.approx(1320.0 * holder.volume)
    # the checker's own formula gives the same
    np.testing.assert_allclose(holder_inertia(holder.record())[0], holder.inertia(), rtol=1e-13)


def test_the_held_design_meets_the_whole_inertia(held):
    C = held.parameters.C
    record = held.inertia
    total = np.asarray(record["total_kg_m2"])
    np.testing.assert_allclose(total, np.diag([2 * C, 2 * C, C]), rtol=0, atol=1e-12 * C)
    parts = (
        np.asarray(record["points_kg_m2"])
        + np.asarray(record["parts_own_kg_m2"])
        + np.asarray(record["holder_kg_m2"])
    )
    np.testing.assert_allclose(parts, total, rtol=0, atol=1e-15 * C)
    # the point masses alone are far from it: the parts' own inertia and the holder count
    assert abs(np.asarray(record["points_kg_m2"])[0, 0] / C - 2.0) > 1e-2
    assert record["convergence"]["last_change_relative"] <= 1e-15
    # the recomputation from the written parts agrees (the checker's formulas)
    points = point_inertia(*held.all_masses())
    again = points + own_inertia(held) * np.eye(3) + holder_inertia(held.holder)[0]
    np.testing.assert_allclose(again, total, rtol=0, atol=1e-12 * C)
    np.testing.assert_allclose(
        np.asarray(whole_inertia(held)["total_kg_m2"]), total, rtol=0, atol=1e-15 * C
    )


def test_the_holder_encloses_every_bore_with_its_wall(held):
    holder = held.holder
    assert holder["material"] == "pmi-foam"
    assert holder["density_kg_per_m3"] == holder_material("pmi-foam").density
    parts = design_parts(held)
    assert [b["part"] for b in holder["bores"]] == parts.names
    reach = np.linalg.norm(parts.centres, axis=1) + parts.outer
    assert np.all(reach + holder["wall_m"] <= holder["radius_m"] + 1e-15)
    assert holder["radius_m"] < float(np.max(reach)) + holder["wall_m"] + 1e-4 + 1e-12
    assert holder["mass_kg"] == pytest.approx(holder["density_kg_per_m3"] * holder["volume_m3"])


def _scene(holder: dict) -> dict:
    import tomllib

    data = tomllib.loads(HELD.read_text())
    data["holder"] = holder
    return data


def test_a_holder_as_dense_as_the_ballast_is_refused_by_name():
    scene = scene_from_dict(_scene({"material": "tungsten"}))
    with pytest.raises(InfeasibleError, match=r"holder\.material: a tungsten holder"):
        design_physical(physical_setup_from_scene(scene))


def test_an_unknown_holder_material_is_one_line():
    with pytest.raises(InputError, match=r"holder\.material: expected one of pmi-foam"):
        scene = scene_from_dict(_scene({"material": "unobtainium"}))
        physical_setup_from_scene(scene)


def test_the_eddy_estimate_counts_the_motion_through_the_gradient():
    # a pure gradient (a1 = 0): on the equator at r, |B| = 2 a2 r... the motion through the
    # gradient adds as much again, so max |dB/dt|^2 / omega^2 is 9/4 of max |B|^2 there
    legendre = (0.0, 0.06)
    centre = np.array([[0.05, 0.0, 0.0]])
    from chargedesign.physical.field_bounds import field_magnitude_max

    b2 = field_magnitude_max(legendre, np.array([0.05]))[0] ** 2
    assert eddy_rate_squared(legendre, centre)[0] / b2 == pytest.approx(2.25, rel=1e-3)
    # a uniform field: the rotation alone
    assert eddy_rate_squared((1.0,), centre)[0] == pytest.approx(1.0, rel=1e-12)


def test_the_estimate_bounds_the_simulated_eddy_power():
    """The simulated torque (eddy_torque) dissipates (2 pi / 15) sigma a^5 |dB/dt|^2 with the
    gradient motion in dB/dt; the estimate takes its largest value."""
    legendre = (0.3, 0.4)
    fld = AxisymmetricField(legendre)
    rng = np.random.default_rng(5)
    centres = np.array([[0.03, -0.01, 0.02]])
    gammas = rng.standard_normal((64, 3))
    gammas /= np.linalg.norm(gammas, axis=1)[:, None]
    omega = rng.standard_normal((64, 3))
    tau = eddy_torque(legendre, centres, np.array([1.0]), omega, gammas)
    power = -np.einsum("ij,ij->i", tau, omega)
    b0 = -fld.gradient_body(centres, gammas)[:, 0]
    g = -fld.hessian_body(centres, gammas)[:, 0]
    bdot = np.einsum("mij,mj->mi", g, np.cross(omega, centres[0])) - np.cross(omega, b0)
    np.testing.assert_allclose(power, 2 * np.pi / 15 * np.sum(bdot**2, axis=1), rtol=1e-10)
    part = {"sigma": 1.0, "outer": np.array([1.0]), "inner": np.array([0.0]), "centres": centres}
    rate = float(np.max(np.linalg.norm(omega, axis=1)))
    estimate = eddy_torques_by_set(legendre, [part], rate)[0]
    assert np.all(power / np.linalg.norm(omega, axis=1) <= estimate * (1 + 1e-3))


def test_a_conducting_holder_counts_its_eddy_currents():
    holder = {"radius_m": 0.05, "conductivity_S_per_m": 3.77e7}
    tau = holder_eddy_torque((0.0, 0.06), holder, 10.0)
    g = float(
        np.linalg.norm(
            AxisymmetricField((0.0, 0.06)).hessian_body(
                np.zeros((1, 3)), np.array([[0.0, 0.0, 1.0]])
            )[0, 0],
            ord=2,
        )
    )
    assert tau == pytest.approx(4 * math.pi * 3.77e7 * 10.0 * g**2 * 0.05**7 / 7, rel=1e-12)
    assert holder_eddy_torque((0.0, 0.06), {"radius_m": 0.05}, 10.0) == 0.0
