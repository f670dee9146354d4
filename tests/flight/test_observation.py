"""The cameras' reconstruction of I4(t) and the control release (flight/observation.py)."""

from __future__ import annotations

import numpy as np
import pytest

from chargedesign.flight.observation import (
    Cameras,
    default_markers,
    fit_attitudes,
    fit_states,
    noisy_track,
    observe,
)
from chargedesign.flight.release import release_start
from chargedesign.params import Parameters
from chargedesign.simulation.system import quaternion_rotation, theorem_i4
from chargedesign.topology.chambers import propagate

DROP = Parameters(C=1.5e-6, c=0.3, d=-0.4, n=0.0, K=0.0, kappa=64.0)
FLIGHT = 8.8


@pytest.fixture(scope="module")
def start():
    return release_start(DROP, FLIGHT)


@pytest.fixture(scope="module")
def track(start):
    times, states, quats = propagate(DROP, start.state[None, :], FLIGHT, 1761)
    return times, states[0], quaternion_rotation(quats[0])


def test_kabsch_recovers_the_attitude_from_noise_free_markers(track):
    _, _, rotations = track
    markers = default_markers(0.03)
    silent = Cameras(noise_across_m=0.0, noise_along_m=0.0)
    seen = noisy_track(rotations, markers, silent, np.random.default_rng(0))
    assert np.max(np.abs(fit_attitudes(seen, markers) - rotations)) < 1e-12


def test_the_noise_is_anisotropic_along_the_line_of_sight(track):
    _, _, rotations = track
    markers = default_markers(0.03)
    cameras = Cameras()
    seen = noisy_track(rotations, markers, cameras, np.random.default_rng(1))
    error = seen - np.einsum("tij,kj->tki", rotations, markers)
    assert np.std(error[..., 0]) == pytest.approx(cameras.noise_along_m, rel=0.02)
    assert np.std(error[..., 1]) == pytest.approx(cameras.noise_across_m, rel=0.02)


def test_windowed_fits_give_i4_to_the_fit_s_own_error_without_noise(track):
    times, states, rotations = track
    mids, fitted = fit_states(times, rotations)
    at = states[[int(np.argmin(np.abs(times - t))) for t in mids]]
    truth = theorem_i4(at, DROP)
    assert np.max(np.abs(theorem_i4(fitted, DROP) - truth)) / abs(truth[0]) < 5e-2
    # the fit's model error (a polynomial in time over 0.2 s, some 3 rad of rotation)
    assert np.max(np.abs(fitted[:, 3:] - at[:, 3:])) < 5e-3
    assert np.max(np.abs(fitted[:, :3] - at[:, :3])) < 3e-2 * np.max(np.abs(at[:, :3]))


def test_the_control_is_told_apart_from_the_integrable_release(start):
    seen = observe(DROP, start, 0.034, seeds=8, seed=11)
    assert seen.relative_sigma < 0.1  # a few per cent per window, at the sourced noise
    assert seen.control_truth > 3 * seen.relative_sigma / np.sqrt(len(seen.times))
    assert seen.z > 5.0 and seen.detected >= 0.9
    record = seen.to_dict()
    assert record["cameras"]["frame_rate_Hz"] == 200.0 and "sigma apart" in str(seen)
