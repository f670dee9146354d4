"""The testbed's loop against independent routes: the theorem's own equations, the
conserved angular momentum, and the order of the sampled commands."""

from __future__ import annotations

import math

import numpy as np
import pytest
from unit_scene import UNIT_INERTIA as TARGET
from unit_scene import UNIT_PARAMETERS as UNIT

from chargedesign.airbearing.dynamics import Plant
from chargedesign.airbearing.loop import (
    LoopSettings,
    continuous_loop,
    invariants,
    run_loop,
)
from chargedesign.airbearing.wheels import wheel_axes, wheel_needs
from chargedesign.errors import SolverError
from chargedesign.model import evaluators
from chargedesign.simulation.integrate import solve


def test_initial_state_is_on_I3_zero(x0: np.ndarray) -> None:
    I3, _ = invariants(x0[None], UNIT)
    assert abs(I3[0]) < 1e-14


def test_ideal_continuous_loop_is_the_theorem(plant: Plant, x0: np.ndarray) -> None:
    """The wheels' command makes the platform's motion the theorem's reduced model's
    (integrated separately, from the derived Euler-Poisson equations) to 1e-10."""
    _, loop = continuous_loop(plant, x0, 5.0, 201)
    theorem = solve(
        evaluators.rhs_function(UNIT),
        x0[:6],
        (0.0, 5.0),
        t_eval=np.linspace(0.0, 5.0, 201),
        method="DOP853",
        rtol=1e-12,
        atol=1e-12,
    ).y
    assert np.abs(loop[:, :6] - theorem).max() < 1e-10
    assert np.abs(loop[:, 6:9]).max() > 0.1  # the wheels do work


def test_wheel_momentum_stays_within_the_bound(plant: Plant, x0: np.ndarray) -> None:
    needs = wheel_needs(plant, x0, wheel_axes("orthogonal", 54.7), 10.0, samples=501)
    assert needs.momentum_norm <= needs.momentum_bound
    # the bound's reason: |J omega + h| (the total angular momentum) is constant
    total = needs.states[:, 0:3] @ TARGET + needs.states[:, 6:9]
    norms = np.linalg.norm(total, axis=1)
    assert np.ptp(norms) < 1e-9 * norms[0]


def test_pyramid_wheels_share_the_same_body_torque(plant: Plant, x0: np.ndarray) -> None:
    axes = wheel_axes("pyramid", math.degrees(math.acos(1 / math.sqrt(3))))
    assert np.allclose(np.linalg.norm(axes, axis=1), 1.0)
    settings = LoopSettings(rate_Hz=100.0, delay_s=0.0, t_end_s=0.5, wheel_axes=axes)
    ortho = LoopSettings(rate_Hz=100.0, delay_s=0.0, t_end_s=0.5)
    a, b = run_loop(plant, x0, settings), run_loop(plant, x0, ortho)
    assert abs(a.I4_drift[0] - b.I4_drift[0]) < 1e-9 * b.I4_drift[0]


def _drift(plant: Plant, x0: np.ndarray, rate: float, command: str) -> float:
    settings = LoopSettings(rate_Hz=rate, delay_s=0.0, t_end_s=2.0, command=command)
    return float(run_loop(plant, x0, settings).I4_drift[0])


def test_zoh_drift_falls_like_the_control_period(plant: Plant, x0: np.ndarray) -> None:
    """Measured order of the plain zero-order hold: 1 (drift proportional to T)."""
    slow, fast = _drift(plant, x0, 50.0, "zoh"), _drift(plant, x0, 200.0, "zoh")
    order = math.log(slow / fast) / math.log(4.0)
    assert 0.9 < order < 1.1


def test_predictive_drift_falls_like_the_period_squared(plant: Plant, x0: np.ndarray) -> None:
    """The model's average over the coming interval: order 2, and far below the ZOH's."""
    slow, fast = _drift(plant, x0, 50.0, "predictive"), _drift(plant, x0, 200.0, "predictive")
    order = math.log(slow / fast) / math.log(4.0)
    assert 1.8 < order < 2.2
    assert slow < 0.05 * _drift(plant, x0, 50.0, "zoh")


def test_noise_free_loop_agrees_with_adaptive_dop853(plant: Plant, x0: np.ndarray) -> None:
    """The fixed-step plant between samples against scipy's adaptive DOP853 of the same
    held torques (one interval): the fixed steps lose nothing at this size."""
    from scipy.integrate import solve_ivp

    x = np.zeros((1, 9))
    x[0, :6] = x0
    u = plant.command(x)
    T = 0.02
    adaptive = solve_ivp(
        lambda _t, y: plant.rates(y[None], u, None)[0],
        (0, T),
        x[0],
        method="DOP853",
        rtol=1e-13,
        atol=1e-13,
    ).y[:, -1]
    fixed = solve(
        lambda _t, y: plant.rates(y, u, None),
        x,
        (0.0, T),
        method="fixed-DOP853",
        max_step=0.05 / 1.5,
    ).end[0]
    assert np.abs(fixed - adaptive).max() < 1e-12


def test_noise_and_disturbances_raise_the_drift(plant: Plant, x0: np.ndarray) -> None:
    quiet = LoopSettings(rate_Hz=100.0, delay_s=0.0, t_end_s=1.0, command="predictive")
    noisy = LoopSettings(
        rate_Hz=100.0,
        delay_s=0.0,
        t_end_s=1.0,
        command="predictive",
        gyro_arw=1e-4,
        gyro_bias=1e-4,
        attitude_noise=1e-4,
        imbalance_m=1e-5,
        drag_N_m_s=1e-4,
        total_mass_kg=20.0,
    )
    a = run_loop(plant, x0, quiet)
    b = run_loop(plant, x0, noisy, runs=3, seed=5)
    c = run_loop(plant, x0, noisy, runs=3, seed=5)
    assert (b.I4_drift > 10 * a.I4_drift[0]).all()
    assert np.array_equal(b.I4_drift, c.I4_drift)  # one seed, one ensemble


def test_a_diverging_loop_is_one_line(plant: Plant, x0: np.ndarray) -> None:
    wild = LoopSettings(rate_Hz=5.0, delay_s=0.0, t_end_s=20.0, command="zoh", gyro_arw=50.0)
    with pytest.raises(SolverError, match="diverged"):
        run_loop(plant, x0, wild)
