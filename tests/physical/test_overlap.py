"""Parts do not overlap: the limits check finds every pair of part spheres closer than their
radii, by :func:`chargedesign.physical.limits.close_pairs` (numpy; it replaced a kd-tree so
that the check command loads no scipy)."""

from __future__ import annotations

import numpy as np
import pytest
from physical.test_buildable import SMALL

from chargedesign.body import Design
from chargedesign.designer import design_from_scene
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


def test_close_pairs_of_one_centre_is_empty():
    assert close_pairs(np.zeros((1, 3)), 1.0).shape == (0, 2)


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
