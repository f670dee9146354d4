"""The wheels: sized for the largest need over the planned motions, and saturated at their
momentum limit inside the sampled loop."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from unit_scene import UNIT_PARAMETERS as UNIT

from chargedesign.airbearing.bearing import fitting_starts
from chargedesign.airbearing.dynamics import Plant
from chargedesign.airbearing.loop import (
    Actuator,
    LoopSettings,
    continuous_loop,
    run_loop,
)
from chargedesign.airbearing.wheels import (
    planned_needs,
    wheel_axes,
    wheel_limits,
)
from chargedesign.scene.testbed import TestbedOptions

T_END = 3.0
SAMPLES = 601


def _wheel_peaks(plant: Plant, start: np.ndarray) -> tuple[float, float]:
    """One motion's largest |momentum| and |torque| of a wheel of the orthogonal array,
    read from the ideal loop's wheel momentum h (body axes = the wheels' axes) and its
    time derivative along the loop."""
    _, states = continuous_loop(plant, start, T_END, SAMPLES)
    rates = plant.ideal_rates(states)
    return float(np.abs(states[:, 6:9]).max()), float(np.abs(rates[:, 6:9]).max())


def test_wheels_are_sized_for_the_largest_planned_need(plant: Plant, x0: np.ndarray) -> None:
    near, _ = fitting_starts(UNIT, [9.0, 27.0, 18.0])  # planned near the stable equilibrium
    starts = np.vstack([near, x0])
    planned = planned_needs(plant, starts, wheel_axes("orthogonal", 54.7), T_END, SAMPLES)
    peaks = np.array([_wheel_peaks(plant, s) for s in starts])
    torque, momentum, _ = wheel_limits(planned, TestbedOptions(wheel_margin=1.5))
    assert momentum == pytest.approx(1.5 * peaks[:, 0].max(), rel=1e-12)
    assert torque == pytest.approx(1.5 * peaks[:, 1].max(), rel=1e-12)
    assert planned.momentum_motion == int(np.argmax(peaks[:, 0]))
    assert planned.torque_motion == int(np.argmax(peaks[:, 1]))
    assert (peaks.max(axis=0) > peaks[0]).all()  # other motions need more than the first
    for motion in planned.motions:  # the conserved angular momentum still bounds each
        assert motion.momentum_norm <= motion.momentum_bound


def test_a_wheel_at_its_momentum_limit_delivers_no_torque_beyond_it() -> None:
    settings = LoopSettings(rate_Hz=100.0, delay_s=0.0, t_end_s=1.0, max_momentum=1.0)
    actuator = Actuator(settings)
    body = np.array([[0.5, -0.5, 0.5]])
    at_limit = np.array([[1.0, -1.0, -1.0]])  # wheels 1, 2 at the limit, wheel 3 opposite
    _, tau = actuator.apply(body, at_limit, 0.01)
    assert tau[0, 0] == 0.0 and tau[0, 1] == 0.0  # would push further: clipped
    assert tau[0, 2] == 0.5  # pulls back from the limit: unchanged
    _, near = actuator.apply(body, np.array([[0.998, 0.0, 0.0]]), 0.01)
    assert near[0, 0] == pytest.approx(0.2)  # only the room left over the hold
    _, free = actuator.apply(body, np.zeros((1, 3)), 0.01)
    assert np.array_equal(free, body)


def test_the_loop_saturates_the_wheel_momentum(plant: Plant, x0: np.ndarray) -> None:
    free = LoopSettings(rate_Hz=100.0, delay_s=2e-3, t_end_s=T_END)
    unlimited = run_loop(plant, x0, free)
    limit = 0.5 * float(unlimited.wheel_momentum_max[0])
    limited = run_loop(plant, x0, replace(free, max_momentum=limit))
    assert float(limited.wheel_momentum_max[0]) <= limit * (1 + 1e-12)
    assert float(limited.wheel_momentum_max[0]) > 0.99 * limit  # it reached the limit
    assert limited.I4_drift[0] > 10 * unlimited.I4_drift[0]  # and the motion suffered
