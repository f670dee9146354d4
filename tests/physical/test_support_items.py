"""The supports' items (physical/support.py): free fall, orbit, electrostatic, air bearing.

The free-fall body is examples/scenes/chaplygin_drop.toml (the K = 0 body, 3 cm, in the
catapult). Physics tests compare independent routes: the net force on the magnets by
Biot-Savart central differences against the coils' Legendre series (its Hessian, exact);
the free-molecular drag by quadrature over the sphere; the coils' room from their turns.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import ClassVar

import numpy as np
import pytest

from chargedesign.constants import STANDARD_GRAVITY
from chargedesign.designer import design_from_scene
from chargedesign.fields import AxisymmetricField
from chargedesign.physical.coils import CoilPair
from chargedesign.physical.support import (
    FIGURES,
    MIN_TURNS,
    coil_room,
    field_on_parts,
    figure,
    free_molecular_torque,
    scene_window_gravity,
    support_record,
    tidal_torque,
    window_gravity,
)
from chargedesign.physical.window import window_model
from chargedesign.scene import load_scene, scene_from_dict
from chargedesign.scene.support import SupportOptions

DROP = Path(__file__).resolve().parents[2] / "examples" / "scenes" / "chaplygin_drop.toml"
ITEM_KEYS = {"name", "value", "limit", "unit", "met", "source", "checked"}


@pytest.fixture(scope="module")
def drop_design():
    return design_from_scene(load_scene(DROP), frontier=False).design


def test_every_figure_names_its_source_and_only_read_ones_are_checked():
    for key, fig in FIGURES.items():
        assert fig.source and fig.locator and fig.what, key
        assert math.isfinite(fig.value), key
        if "from memory" in fig.locator or "not sourced" in fig.source:
            assert fig.checked is False, key
    assert figure("drop_tower.catapult_time_s") == 9.3
    assert figure("drop_tower.drop_time_s") == 4.74
    assert FIGURES["drop_tower.residual_g"].checked


def test_free_fall_and_orbit_set_the_windows_gravity_to_their_residual():
    assert window_gravity(SupportOptions("free_fall", "drop_tower_drop", True), 9.8) == (
        pytest.approx(1e-6 * STANDARD_GRAVITY, rel=1e-15)
    )
    assert window_gravity(SupportOptions("orbit", None, True), 9.8) == pytest.approx(
        figure("orbit.residual_g") * STANDARD_GRAVITY
    )
    assert window_gravity(SupportOptions("air_bearing", None, True), 9.8) == 9.8
    assert window_gravity(SupportOptions(), 3.0) == 3.0
    free = scene_from_dict({"support": {"style": "free_fall"}})
    assert scene_window_gravity(free) == pytest.approx(1e-6 * STANDARD_GRAVITY)
    given = scene_from_dict(
        {"support": {"style": "free_fall"}, "design": {"realised_gravity": 1.0}}
    )
    assert scene_window_gravity(given) == 1.0  # the scene's own [design] key wins


def test_the_drop_body_s_record_has_the_contract_keys_and_is_included(drop_design):
    record = drop_design.support
    assert {"style", "facility", "microgravity_s", "residual_g", "turns", "net_force_N"} <= set(
        record
    )
    assert record["style"] == "free_fall" and record["facility"] == "drop_tower_catapult"
    assert record["microgravity_s"] == 9.3 and record["residual_g"] == 1e-6
    for item in record["items"]:
        assert set(item) == ITEM_KEYS, item
        assert isinstance(item["met"], bool)
    assert record["state"] == ("included" if all(i["met"] for i in record["items"]) else "open")
    assert record["state"] == "included"
    assert record["turns"] >= MIN_TURNS
    # the net force moves the body less than the clearance the residual acceleration and the
    # release velocity leave, over the flight; each magnet alone feels some 1e3 times more
    force = next(i for i in record["items"] if i["name"] == "net_force_N")
    assert force["value"] == record["net_force_N"] <= force["limit"]
    model = window_model(drop_design, 1.0, gravity=0.0)
    pairs = list(model.apparatus.pairs)
    magnets = np.asarray(drop_design.dipole_moments), np.asarray(drop_design.dipole_positions)
    single = np.linalg.norm(_series_force(pairs, magnets[1][:1], magnets[0][:1], np.zeros(3)))
    assert record["net_force_N"] < 3e-3 * single


def _series_force(pairs, positions, moments, offset):
    """Net force on point dipoles from the coils' Legendre series: grad (m . B) = -Hess Phi m."""
    series = AxisymmetricField(np.sum([p.legendre() for p in pairs], axis=0))
    hess = series.hessian(positions + offset)
    return -np.einsum("nij,nj->i", hess, moments)


def test_the_net_force_by_biot_savart_matches_the_coils_series(drop_design):
    """Independent routes: central differences of the loops' closed-form field against the
    Hessian of their exact Legendre series (degree 12), at an offset of 3 mm."""
    model = window_model(drop_design, 1.0, gravity=0.0)
    pairs = list(model.apparatus.pairs)
    offset = np.array([0.0, 0.0, 3e-3])
    moments = np.asarray(drop_design.dipole_moments)
    positions = np.asarray(drop_design.dipole_positions)
    found = field_on_parts(drop_design, pairs, offset, count=1)  # the identity rotation
    expected = np.linalg.norm(_series_force(pairs, positions, moments, offset))
    assert found.net_force_dipoles_N == pytest.approx(expected, rel=1e-4)
    # each magnet alone feels G m, some 1e6 times more: the sum cancels (zero net dipole)
    single = np.linalg.norm(_series_force(pairs, positions[:1], moments[:1], offset))
    assert found.net_force_dipoles_N < 1e-3 * single
    centred = field_on_parts(drop_design, pairs, np.zeros(3), count=8)
    assert centred.net_force_dipoles_N < 1e-9 * single
    assert centred.dipole_sum < 1e-12 * centred.dipole_magnitudes


def test_a_lone_dipole_feels_the_gradient():
    """One dipole m e_z at a Maxwell pair's centre: Biot-Savart differences give the series'
    force, ``|F| = |d^2 Phi / dz^2| m = 2 |f2| m`` (``Phi = f2 R^2 P2``)."""
    pair = CoilPair("maxwell", 0.2, math.sqrt(3.0) * 0.2, 100.0, 2.0)

    class OneMagnet:  # the attributes field_on_parts reads, no materials
        dipole_positions = np.zeros((1, 3))
        dipole_moments = np.array([[0.0, 0.0, 0.01]])
        materials: ClassVar[dict] = {}
        charge_values = dipole_volumes = mass_values = np.zeros(0)

        def field(self, kind):
            return ()

        def magnet_volumes(self):
            return np.zeros(1)

    found = field_on_parts(OneMagnet(), [pair], np.zeros(3), count=1)
    assert found.net_force_N == pytest.approx(2 * abs(pair.legendre()[1]) * 0.01, rel=1e-6)


def test_free_molecular_drag_by_quadrature():
    """Momentum flux of the molecules leaving the sphere, integrated over it: each carries
    m omega R sin(theta) tangentially at the rate n cbar / 4 per unit area."""
    p, R, w = 2.0, 0.03, 16.0
    m, T = figure("gas.air_molecular_mass_kg"), figure("gas.temperature_K")
    k_B = 1.380649e-23
    n = p / (k_B * T)
    cbar = math.sqrt(8 * k_B * T / (math.pi * m))
    x, weights = np.polynomial.legendre.leggauss(60)
    theta = math.pi * (x + 1) / 2
    integrand = n * cbar / 4 * m * w * R * np.sin(theta) * R * np.sin(theta)
    torque = 2 * math.pi * math.pi / 2 * np.sum(weights * integrand * R**2 * np.sin(theta))
    assert free_molecular_torque(p, R, w) == pytest.approx(torque, rel=1e-10)


def test_tidal_torque_of_the_theorem_inertia():
    # (3 GM / r^3) |u x I u| is largest at 45 degrees from the symmetry axis: 3/2 (A - C) rate^2
    C, rate2 = 2e-6, 1.5e-6
    inertia = np.diag([2 * C, 2 * C, C])
    angles = np.linspace(0, math.pi / 2, 2001)
    u = np.stack([np.sin(angles), 0 * angles, np.cos(angles)], 1)
    largest = np.max(np.linalg.norm(3 * rate2 * np.cross(u, u @ inertia), axis=1))
    assert tidal_torque(rate2, C) == pytest.approx(largest, rel=1e-6)


def test_the_5cm_body_s_coils_do_not_fit_the_capsule():
    """The chaplygin_magnetic example's Maxwell pair (0.337 m, 8480 turns of 1 mm^2): 0.86 m
    across its windings, more than the capsule's 0.8 m."""
    pair = CoilPair("maxwell", 0.3374875, 0.5845455, 8480.08, -2.0)
    diameter, length, copper = coil_room([pair])
    side = math.sqrt(8480.08e-6)
    assert diameter == pytest.approx(2 * (0.3374875 + side))
    assert diameter > figure("drop_tower.capsule_diameter_m")
    assert length == pytest.approx(0.5845455 + side)
    assert copper == pytest.approx(2 * 2 * math.pi * 0.3374875 * 8480.08e-6 * 8960.0)


def test_the_other_supports_items(drop_design):
    air = support_record(drop_design, SupportOptions("air_bearing", None, True))
    names = {i["name"]: i for i in air["items"]}
    assert not names["gas_at_the_film"]["met"]  # the body sits in vacuum
    assert not names["film_drag_over_term"]["met"] and air["state"] == "open"
    electro = support_record(drop_design, SupportOptions("electrostatic", None, True))
    spin = next(i for i in electro["items"] if i["name"] == "spin_down_drag_over_term")
    assert "gpb.spin_down_years_min" in spin["source"] and spin["checked"]
    orbit = support_record(drop_design, SupportOptions("orbit", None, True))
    assert orbit["turns"] is None and orbit["residual_g"] == figure("orbit.residual_g")
    tidal = next(i for i in orbit["items"] if i["name"] == "gravity_gradient_torque_over_term")
    assert tidal["met"] and tidal["checked"] is False  # the orbit's figures are not sourced
