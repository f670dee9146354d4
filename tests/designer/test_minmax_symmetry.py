"""The charges' minmax on the symmetric charges (one unknown per orbit of candidates) against
the whole program with the cones at every image of the points: the same optimum, as the
averaging argument of :class:`~chargedesign.designer.frontier_probes.ChargeSymmetry` says.
"""

from __future__ import annotations

import tomllib

import numpy as np
import pytest

from chargedesign.designer.charge_symmetry import charge_symmetry
from chargedesign.designer.charges import ConeRows
from chargedesign.designer.frontier_probes import charges_rate_limit, minmax_charges
from chargedesign.designer.pipeline import physical_setup_from_scene
from chargedesign.scene import scene_from_dict
from chargedesign.scene.load import default_scene_text


@pytest.fixture(scope="module")
def setup():
    """The default body (257 candidates)."""
    return physical_setup_from_scene(scene_from_dict(tomllib.loads(default_scene_text()), "<t>"))


@pytest.fixture(scope="module")
def symmetry(setup):
    found = setup.symmetry
    assert found is not None
    return found


def test_every_map_carries_the_candidates_and_the_conditions_onto_themselves(setup, symmetry):
    A, b = setup.systems["charges"]
    assert symmetry.order == 4  # the default body: z half-turns and the quarter-turn with z flip
    rng = np.random.default_rng(1)
    u = np.linalg.lstsq(A, b, rcond=None)[0]
    _, _, vt = np.linalg.svd(A)
    u = u + vt[-3:].T @ rng.normal(size=3) * np.abs(u).max()  # another solution
    for R, sigma in zip(symmetry.maps, symmetry.signs, strict=True):
        np.testing.assert_allclose(np.abs(R), np.abs(R).round())  # a signed permutation
        image = setup.points @ R.T
        distance = np.linalg.norm(image[:, None, :] - setup.points[None, :, :], axis=2)
        pi = np.argmin(distance, axis=1)
        assert np.max(distance[np.arange(len(pi)), pi]) < 1e-12
        moved = np.zeros_like(u)
        moved[pi] = sigma * u
        np.testing.assert_allclose(A @ moved, b, rtol=0, atol=1e-9 * np.abs(b).max())


def test_the_basis_spans_the_symmetric_charges(setup, symmetry):
    B = symmetry.basis
    np.testing.assert_allclose(B.T @ B, np.eye(B.shape[1]), atol=1e-12)
    for R, sigma in zip(symmetry.maps, symmetry.signs, strict=True):
        image = setup.points @ R.T
        pi = np.argmin(np.linalg.norm(image[:, None] - setup.points[None], axis=2), axis=1)
        moved = np.zeros_like(B)
        moved[pi] = sigma * B
        np.testing.assert_allclose(moved, B, atol=1e-15)  # each column is its own image
    assert np.all(symmetry.orbit[symmetry.reps] == np.arange(B.shape[1]))


def test_the_symmetric_minmax_is_the_whole_one_with_the_cones_at_every_image(setup, symmetry):
    """At points on a few carriers, and the whole program with the cones at all their
    images: the same t (the symmetric charges reach the optimum) and charges on each orbit
    constant up to the signs."""
    rng = np.random.default_rng(2)
    a = setup.carrier_radius
    sites = rng.choice(len(setup.points), 12, replace=False)
    dirs = rng.normal(size=(12, 3))
    dirs /= np.linalg.norm(dirs, axis=1, keepdims=True)
    points = setup.points[sites] + a * dirs
    images = np.concatenate([points @ R.T for R in symmetry.maps])
    rows = ConeRows(setup.points)
    reduced = minmax_charges(setup, list(points), rows, symmetry)
    whole = minmax_charges(setup, list(images), rows)
    assert reduced is not None and whole is not None
    assert reduced[0] == pytest.approx(whole[0], rel=1e-7)
    u = reduced[1]
    np.testing.assert_allclose(
        symmetry.basis @ (symmetry.basis.T @ u), u, atol=1e-12 * abs(u).max()
    )


def test_the_charges_limit_records_the_symmetry(setup, symmetry):
    limit = charges_rate_limit(setup)
    assert limit.symmetry == symmetry.order
    assert limit.stage == "charges" and limit.rounds > 1


def test_the_setup_finds_the_symmetry_once_from_the_charges_conditions(setup, symmetry):
    A, b = setup.systems["charges"]
    again = charge_symmetry(A, b, setup.points)
    assert again is not None and setup.symmetry is symmetry  # cached: one search per setup
    for name in ("maps", "signs", "basis", "reps", "orbit"):
        assert np.array_equal(getattr(again, name), getattr(symmetry, name))
