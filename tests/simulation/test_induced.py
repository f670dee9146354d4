"""The ``induced`` effect: the parts' own materials magnetised by the applied field.

Three routes give its torque (moment polynomials, the direct kernel, element by element with
the field's Hessian) and a fourth its energy (the realism budget's point evaluation); a run
shows it conserves the energy while it breaks I4, which the designed effects keep.
"""

from __future__ import annotations

import numpy as np
import pytest
from physical.test_buildable import SMALL

from chargedesign.body import Design
from chargedesign.designer import design_from_scene
from chargedesign.physical.realism import RESPONSE_ORIENTATIONS, field_response, typical_rate
from chargedesign.sampling import fibonacci_sphere
from chargedesign.scene import load_scene
from chargedesign.simulation.api import simulate
from chargedesign.simulation.system import (
    Body,
    RigidBodySystem,
    attitude_from_gamma,
    direct_terms,
    select_effects,
)


@pytest.fixture(scope="module")
def design() -> Design:
    return design_from_scene(load_scene(SMALL), frontier=False).design


@pytest.fixture(scope="module")
def body(design) -> Body:
    return Body.from_design(design)


def test_the_parts_are_every_carrier_magnet_and_ballast(body, design):
    counts = len(design.charge_values) + len(design.dipole_moments) + len(design.mass_values)
    assert counts <= body.source_count("parts") <= counts + len(design.dipole_moments)
    assert np.all(body.part_susceptances > 0)  # aluminium, NdFeB, tungsten: paramagnetic


def test_three_routes_give_the_same_torque_and_energy(body):
    rng = np.random.default_rng(3)
    gamma = rng.normal(size=(7, 3))
    gamma /= np.linalg.norm(gamma, axis=1)[:, None]
    omega = rng.normal(size=(7, 3)) * 1e-6
    rotation = np.array([attitude_from_gamma(g, 0.4) for g in gamma])
    reduced = RigidBodySystem(body, ["induced"], route="reduced")
    kernel = RigidBodySystem(body, ["induced"], route="direct")
    torque, energy, _ = direct_terms(body, "induced", omega, rotation)
    scale = float(np.max(np.abs(torque)))
    assert scale > 0
    assert np.max(np.abs(reduced.torque(omega, gamma) - torque)) <= 1e-13 * scale
    assert np.max(np.abs(kernel.torque(omega, gamma) - torque)) <= 1e-13 * scale
    assert np.max(np.abs(reduced.energy(gamma) - energy)) <= 1e-13 * np.max(np.abs(energy))


def test_its_energy_range_is_the_realism_budgets(body, design):
    gammas = fibonacci_sphere(RESPONSE_ORIENTATIONS)
    energy = RigidBodySystem(body, ["induced"], route="reduced").energy(gammas)
    torque = design.parameters.C * typical_rate(design.parameters) ** 2 / 4
    budget = field_response(design)["induced_magnetisation_fraction"]["value"] * torque
    assert np.ptp(energy) == pytest.approx(budget, rel=1e-10)


def test_it_is_asked_for_by_name():
    body = Body.from_design(design_from_scene(load_scene(SMALL), frontier=False).design)
    effects, notes = select_effects(body, None)
    assert "induced" not in effects and any(n.startswith("induced:") for n in notes)
    effects, _ = select_effects(body, ["lorentz", "induced"])
    assert effects == ["lorentz", "induced"]


def test_it_conserves_the_energy_and_breaks_i4(design):
    """Over 100 s the designed effects keep I4 at round-off; with the parts' magnetisation
    the energy is still conserved (a potential) but I4 changes by its own size."""
    designed = ["lorentz", "electric", "magnetization"]
    kept = simulate(design, effects=designed, t_end=100.0, samples=50)
    broken = simulate(design, effects=[*designed, "induced"], t_end=100.0, samples=50)
    assert kept.to_dict()["I4_rel_drift"] < 1e-12
    assert broken.to_dict()["I1_rel_drift"] < 1e-12
    assert broken.to_dict()["I4_rel_drift"] > 1e-2
