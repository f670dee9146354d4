"""The linear response of I4 (balance, drag, inertia) against the simulated loop."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from unit_scene import UNIT_INERTIA as TARGET
from unit_scene import UNIT_PARAMETERS as UNIT

from chargedesign.airbearing.balance import sensitivity
from chargedesign.airbearing.dynamics import Plant
from chargedesign.airbearing.loop import LoopSettings, initial_state, run_loop
from chargedesign.airbearing.wheels import wheel_axes, wheel_needs

T_END, RATE, MASS = 2.0, 200.0, 20.0


@pytest.fixture(scope="module")
def setup() -> tuple:
    plant = Plant(UNIT, TARGET, TARGET)
    x0 = initial_state(UNIT, np.array([0.36, 0.48, 0.8]), 0.6, -0.4)
    needs = wheel_needs(
        plant, x0, wheel_axes("orthogonal", 54.7), T_END, samples=int(T_END * RATE) + 1
    )
    return plant, x0, sensitivity(plant, needs.times, needs.states, MASS)


def _loop(plant: Plant, x0: np.ndarray, **changes: object) -> float:
    settings = LoopSettings(rate_Hz=RATE, delay_s=0.0, t_end_s=T_END, command="predictive")
    return float(run_loop(plant, x0, replace(settings, **changes)).I4_drift[0])


def test_imbalance_drift_is_the_linear_response(setup: tuple) -> None:
    plant, x0, sens = setup
    size = 1e-5
    simulated = _loop(
        plant, x0, imbalance_m=size, imbalance_direction=(1.0, 0.0, 0.0), total_mass_kg=MASS
    )
    predicted = size * np.abs(sens.imbalance[:, 0]).max()
    assert abs(simulated - predicted) < 0.05 * predicted


def test_drag_drift_is_the_linear_response(setup: tuple) -> None:
    plant, x0, sens = setup
    b = 1e-3
    simulated = _loop(plant, x0, drag_N_m_s=b)
    predicted = b * sens.drag_per_unit
    assert abs(simulated - predicted) < 0.05 * predicted


def test_unknown_inertia_error_is_the_linear_response(setup: tuple) -> None:
    """A platform whose A - B differs from the controller's model by 1e-3 kg m^2."""
    _, x0, sens = setup
    dJ = np.diag([0.5e-3, -0.5e-3, 0.0])
    wrong = Plant(UNIT, TARGET + dJ, TARGET)
    simulated = _loop(wrong, x0)
    predicted = sens.inertia_drift(dJ)
    assert abs(simulated - predicted) < 0.05 * predicted


def test_drag_fed_forward_is_cancelled(setup: tuple) -> None:
    plant, x0, _ = setup
    quiet = _loop(plant, x0)
    dragged = _loop(plant, x0, drag_N_m_s=1e-3)
    cancelled = _loop(plant, x0, drag_N_m_s=1e-3, drag_feedforward_N_m_s=1e-3)
    assert dragged > 100 * quiet
    assert cancelled < 2 * quiet  # what is left is the loop's own drift and O(b T)
