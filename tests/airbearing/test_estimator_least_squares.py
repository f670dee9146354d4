"""The testbed's centre-of-mass estimator (airbearing/loop.Sensing, square-root information
form) against the batch least squares it stands for, solved here by an independent route:
the summed torque-balance rows rebuilt from the equation in Sensing's documentation,
``J d omega + int omega x (J omega + h) + d h = int (M g gamma x (r_c + K gamma) - b omega)``
(trapezoid rule, summed from the start), stacked with the prior and solved by
``numpy.linalg.lstsq``."""

from __future__ import annotations

from itertools import pairwise

import numpy as np

from chargedesign.airbearing.loop import LoopSettings, Sensing

PRIOR_OFFSET, PRIOR_DRAG, PRIOR_COMPLIANCE = 1e-4, 1e-3, 1e-5
#: the upper triangle of K in the estimator's order: the diagonal, then the off-diagonal
PAIRS = [(0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2)]


def _regressor(state: np.ndarray, weight: float) -> np.ndarray:
    """The rows (3, 10) of theta = (r_c, b, K's upper triangle) at one state, from the
    equation: M g gamma x r_c, -b omega, M g gamma x (K gamma)."""
    omega, gamma = state[0:3], state[3:6]
    columns = [weight * np.cross(gamma, e) for e in np.eye(3)] + [-omega]
    for a, b in PAIRS:
        K = np.zeros((3, 3))
        K[a, b] = K[b, a] = 1.0
        columns.append(weight * np.cross(gamma, K @ gamma))
    return np.array(columns).T


def _batch_estimate(states, J, T, weight, noise, prior):
    """argmin sum_k |Y_k - Phi_k theta|^2 / noise^2 + |theta / prior|^2, by lstsq."""
    rows, rhs = [np.diag(1.0 / prior)], [np.zeros(len(prior))]
    Y, Phi = np.zeros(3), np.zeros((3, 10))
    for prev, now in pairwise(states):
        gyro = [np.cross(x[0:3], J @ x[0:3] + x[6:9]) for x in (prev, now)]
        Y = Y + J @ (now[0:3] - prev[0:3]) + 0.5 * T * (gyro[0] + gyro[1]) + now[6:9] - prev[6:9]
        Phi = Phi + 0.5 * T * (_regressor(prev, weight) + _regressor(now, weight))
        rows.append(Phi / noise)
        rhs.append(Y / noise)
    return np.linalg.lstsq(np.vstack(rows), np.concatenate(rhs), rcond=None)[0]


def test_the_estimator_is_the_batch_least_squares_with_its_prior(plant):
    rng = np.random.default_rng(11)
    T, weight, arw = 0.02, 20.0 * 9.80665, 1e-4
    settings = LoopSettings(
        rate_Hz=1 / T,
        delay_s=0.0,
        t_end_s=1.0,
        estimator=True,
        prior_offset_m=PRIOR_OFFSET,
        prior_drag_N_m_s=PRIOR_DRAG,
        prior_compliance_m=PRIOR_COMPLIANCE,
    )
    # arw only sets the rows' weight here: the settings add no noise (noisy is False)
    sensing = Sensing(settings, 1, T, np.zeros((1, 3)), np.full((1, 1), arw), rng, plant, weight)
    states = []
    for k in range(60):
        gamma = rng.normal(size=3)
        state = np.concatenate(
            [rng.normal(size=3), gamma / np.linalg.norm(gamma), rng.normal(size=3)]
        )
        states.append(state)
        sensing.read(state[None, :], k, np.eye(3))
    J = plant.model_inertia
    noise = arw / np.sqrt(T) * float(np.abs(J).max())
    prior = np.array([PRIOR_OFFSET] * 3 + [PRIOR_DRAG] + [PRIOR_COMPLIANCE] * 6)
    expected = _batch_estimate(states, J, T, weight, noise, prior)
    # each unknown to 1e-9 of its prior scale (the estimates are of that order)
    assert np.all(np.abs(sensing.theta[0] - expected) <= 1e-9 * prior)
    # and not trivially: the rows moved the estimate well off the prior's zero
    assert np.max(np.abs(expected) / prior) > 0.1
