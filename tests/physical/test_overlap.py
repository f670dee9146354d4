"""Parts do not overlap: the limits check finds every pair of part spheres closer than their
radii, by :func:`chargedesign.physical.limits.close_pairs` (numpy blocks for a body's parts,
so that the check command loads no scipy; scipy's KD-tree for the testbed's larger sets)."""

from __future__ import annotations

import numpy as np
import pytest
from physical.test_buildable import SMALL

from chargedesign.body import Design
from chargedesign.designer import design_from_scene
from chargedesign.physical import limits
from chargedesign.physical.limits import check_limits, close_pairs, part_radii
from chargedesign.scene import load_scene


@pytest.mark.parametrize("n", [2, 3, 40, 700])
@pytest.mark.parametrize("reach", [0.05, 0.6, 10.0])
def test_close_pairs_are_every_pair_within_reach_in_order(n, reach):
    rng = np.random.default_rng(n)
    centres = rng.normal(size=(n, 3))
    # the whole distance matrix: an independent route
    d = np.linalg.norm(centres[:, None] - centres[None], axis=2)
    i, j = np.nonzero(np.triu(d <= reach, k=1))
    assert np.array_equal(close_pairs(centres, reach), np.stack([i, j], axis=1))


@pytest.mark.parametrize("shift", [0.0, 1e4])
@pytest.mark.parametrize("n", [200, 300])  # either side of PAIRS_BY_BLOCKS_MAX
def test_close_pairs_keep_a_pair_exactly_at_reach_far_from_the_origin(shift, n, monkeypatch):
    # a quarter-metre lattice: many distances are exactly the reach, in any dimension; the
    # numpy blocks and the KD-tree find the same pairs, ties included
    rng = np.random.default_rng(7)
    for dim in (1, 3, 6):
        centres = np.round(rng.normal(size=(n, dim))) / 4 + shift
        d2 = np.sum((centres[:, None] - centres[None]) ** 2, axis=2)
        i, j = np.nonzero(np.triu(d2 <= 0.25**2, k=1))
        assert np.any(d2[i, j] == 0.25**2)
        expected = np.stack([i, j], axis=1)
        assert np.array_equal(close_pairs(centres, 0.25), expected)
        for largest in (0, 10**6):  # every set to the tree, every set to the blocks
            monkeypatch.setattr(limits, "PAIRS_BY_BLOCKS_MAX", largest)
            assert np.array_equal(close_pairs(centres, 0.25), expected)
        monkeypatch.undo()


def test_close_pairs_of_one_centre_is_empty():
    assert close_pairs(np.zeros((1, 3)), 1.0).shape == (0, 2)
    assert close_pairs(np.zeros((0, 3)), 1.0).shape == (0, 2)


@pytest.mark.parametrize("n", [60, 400])  # either side of PAIRS_BY_BLOCKS_MAX
def test_overlapping_pairs_are_the_spheres_closer_than_their_radii(n):
    """The limits check's parts and the testbed's ballast: against the whole distance matrix,
    strictly closer than ``r_i + r_j`` (touching is no overlap), with their overlaps, and a
    slack of the distance forgiven."""
    rng = np.random.default_rng(n)
    centres = rng.uniform(-0.5, 0.5, size=(n, 3))
    radii = rng.uniform(0.05, 0.15, size=n)
    # two spheres touching exactly, away from the rest: no overlap
    centres[:2], radii[:2] = [[2.0, 2.0, 2.0], [2.25, 2.0, 2.0]], 0.125
    d = np.linalg.norm(centres[:, None] - centres[None], axis=2)
    gap = d - radii[:, None] - radii[None]
    i, j = np.nonzero(np.triu(gap < 0, k=1))
    pairs, overlaps = limits.overlapping_pairs(centres, radii)
    assert len(i) > 0 and np.array_equal(pairs, np.stack([i, j], axis=1))
    np.testing.assert_array_equal(overlaps, -gap[i, j])
    assert [0, 1] not in pairs.tolist()
    forgiven, _ = limits.overlapping_pairs(centres, radii, slack=0.1)
    i, j = np.nonzero(np.triu(gap < -0.1 * d, k=1))
    assert len(i) < len(pairs) and np.array_equal(forgiven, np.stack([i, j], axis=1))
    assert limits.overlapping_pairs(centres[:1], radii[:1])[0].shape == (0, 2)


@pytest.fixture(scope="module")
def small_design() -> Design:
    return design_from_scene(load_scene(SMALL), frontier=False).design


def test_the_check_names_two_parts_moved_onto_each_other(small_design):
    assert not any("overlap" in v for v in check_limits(small_design).violations)
    data = small_design.to_dict()
    positions = np.asarray(data["charges"]["positions"], dtype=float)
    _, radii = part_radii(small_design)
    # the third carrier beside the second, closer than their radii
    positions[2] = positions[1] + [0.5 * (radii[1] + radii[2]), 0.0, 0.0]
    data["charges"]["positions"] = positions.tolist()
    violations = check_limits(Design.from_dict(data)).violations
    (line,) = [v for v in violations if "overlap" in v]
    assert line.startswith("parts 1 and 2 overlap")
