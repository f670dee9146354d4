"""The ``eddy`` effect: the conducting parts' eddy currents, a damping torque ``-D(gamma) omega``.

Run on the K = 0 example body (its NdFeB magnets conduct; its fused-silica ballast hardly):
the energy the dissipative run loses is the dissipation integrated along the conservative run
(two integrations of different equations), and its rate is the one the realism budget's eddy
ratio (the window's law at the design's rate) predicts, to the estimate's own accuracy.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from chargedesign.designer import design_from_scene
from chargedesign.physical.realism import FIELD_RESPONSE_KEYS, field_response, typical_rate
from chargedesign.scene import load_scene
from chargedesign.simulation.api import simulate
from chargedesign.simulation.system import Body, RigidBodySystem, select_effects

CHAPLYGIN = Path(__file__).resolve().parents[2] / "examples" / "scenes" / "chaplygin_magnetic.toml"
T_END = 4.0  # s: about 3 turns of the default start's motion


@pytest.fixture(scope="module")
def design():
    return design_from_scene(load_scene(CHAPLYGIN), frontier=False).design


@pytest.fixture(scope="module")
def runs(design):
    """The run with the eddy torque (scipy) and the conservative one (taylor, dense samples)."""
    dissipative = simulate(design, effects=["magnetization", "eddy"], t_end=T_END, axes="inertial")
    conservative = simulate(
        design, effects=["magnetization"], t_end=T_END, samples=8001, axes="inertial"
    )
    return dissipative, conservative


def test_it_is_asked_for_by_name_and_runs_on_scipy(design, runs):
    body = Body.from_design(design)
    assert body.source_count("conductors") == len(body.conductor_weights) > 0
    effects, _ = select_effects(body, None)
    assert "eddy" not in effects
    dissipative, conservative = runs
    assert dissipative.method == "DOP853" and conservative.method == "taylor"
    assert any("instead of taylor" in note for note in dissipative.notes)


def test_its_energy_loss_is_the_dissipation_along_the_motion(design, runs):
    dissipative, conservative = runs
    body = Body.from_design(design)
    system = RigidBodySystem(body, ["magnetization", "eddy"])
    omega, gamma = conservative.omega, conservative.gamma
    eddy = system.torque(omega, gamma) - RigidBodySystem(body, ["magnetization"]).torque(
        omega, gamma
    )
    power = np.einsum("ij,ij->i", eddy, omega)
    assert np.all(power <= 0.0)
    dissipated = np.trapezoid(power, conservative.times)
    lost = dissipative.integrals[-1, 0] - dissipative.integrals[0, 0]
    # first order in the damping (1e-7 of the energy), trapezoid on 8000 samples
    assert lost == pytest.approx(dissipated, rel=1e-4)
    assert conservative.to_dict()["I1_rel_drift"] < 1e-12


def test_i4_drift_is_the_windows_eddy_ratio(design, runs):
    """The budget's eddy ratio f (torque over C w^2 / 4 at the typical rate w, each part's
    largest |dB/dt| / |omega|: its spin in B and its motion through the gradient) bounds the
    power f (C w^2 / 4) <|omega|^2> / w; the run's is 0.52 of it (1.17 of the spin alone). The
    I4 the magnets keep to 1e-14 then drifts by the dissipation, below the window's
    fraction."""
    dissipative, conservative = runs
    fraction = field_response(design)[FIELD_RESPONSE_KEYS[1]]["value"]
    rate = typical_rate(design.parameters)
    C = design.parameters.C
    mean_square = np.mean(np.sum(conservative.omega**2, axis=1))
    predicted = fraction * C * rate**2 / 4.0 * mean_square / rate
    measured = -(dissipative.integrals[-1, 0] - dissipative.integrals[0, 0]) / T_END
    assert 0.3 < measured / predicted <= 1.0
    i4 = dissipative.to_dict()["I4_rel_drift"]
    assert i4 > 1e6 * conservative.to_dict()["I4_rel_drift"]
    assert i4 < 1e-3


def test_the_routes_and_integrators_lose_the_same_energy(design):
    """The eddy torque on the reduced and the direct force route, integrated by DOP853 and by
    the fixed-step Gauss-Legendre method: one energy loss."""
    losses = []
    for kwargs in ({}, {"route": "direct"}, {"method": "gauss-legendre", "step": 0.005}):
        run = simulate(design, effects=["magnetization", "eddy"], t_end=0.5, **kwargs)
        losses.append(run.integrals[-1, 0] - run.integrals[0, 0])
    assert losses[0] < 0
    np.testing.assert_allclose(losses[1:], losses[0], rtol=2e-3)
