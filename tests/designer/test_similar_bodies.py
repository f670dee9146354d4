"""Similar bodies share their magnets-and-masses designs: a body 4 times the size (radius,
spacing x 4, C x 4^5) of the same materials in the same field has, at half the rate, the
other's program, and its design is the other's with masses and moments x 64, to the bit. Within
``similar_bodies`` a member takes such a design instead of making it; a ranked frontier started
at 1/2 follows the smaller body's path and designs nothing new."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from chargedesign.designer.frontier import find_frontier
from chargedesign.designer.frontier_scan import scene_dict
from chargedesign.designer.masses import SimilarBodies, design_masses, similar_bodies
from chargedesign.designer.physical_setup import PhysicalInfeasible
from chargedesign.designer.pipeline import physical_setup_from_scene
from chargedesign.designer.recommend import Choice, similar_class
from chargedesign.errors import SolverError
from chargedesign.scene import load_scene, scene_from_dict

ROOT = Path(__file__).parents[2]
CHAPLYGIN = ROOT / "examples" / "scenes" / "chaplygin_magnetic.toml"
NONE = np.zeros(0, dtype=int)


@pytest.fixture(scope="module")
def base():
    return scene_dict(load_scene(CHAPLYGIN))


def setup_of(base, choice):
    return physical_setup_from_scene(scene_from_dict(choice.apply(base), "similar"))


def outcome(setup, s):
    try:
        return design_masses(setup, s, NONE)
    except (PhysicalInfeasible, SolverError) as exc:
        return exc


def same(small, large, factor=64.0):
    """The large body's design is the small one's x 64 (masses, moments), bit for bit."""
    if isinstance(small, Exception):
        assert type(large) is type(small)
        return
    assert not isinstance(large, Exception)
    assert np.array_equal(small.sites, large.sites)
    assert np.array_equal(small.moments * factor, large.moments)
    assert np.array_equal(small.site_masses * factor, large.site_masses)
    assert small.residual_masses == large.residual_masses


@pytest.mark.parametrize("s", [0.5, 2.0, 4.0, 8.0])
def test_four_times_the_size_at_half_the_rate_is_the_same_design(base, s):
    small = setup_of(base, Choice())
    large = setup_of(base, Choice(size=4.0))
    same(outcome(small, s), outcome(large, s / 2))


def test_members_share_and_others_do_not(base):
    own = outcome(setup_of(base, Choice(size=4.0)), 1.0)
    small, large = setup_of(base, Choice()), setup_of(base, Choice(size=4.0))
    other = setup_of(base, Choice(size=4.0, ballast="zirconia"))
    with similar_bodies() as shared:
        for choice, setup in ((Choice(), small), (Choice(size=4.0), large)):
            shared.add(setup, *similar_class(choice))
        made = outcome(small, 2.0)
        taken = outcome(large, 1.0)
        assert (shared.shared, shared.designed) == (1, 1)
        outcome(other, 1.0)  # not a member: its own design
        assert (shared.shared, shared.designed) == (1, 1)
        # a member of the class by its key whose magnets differ makes its own design
        smco = Choice(size=4.0, magnets="smco")
        assert similar_class(smco) == similar_class(Choice(size=4.0))
        member = setup_of(base, smco)
        shared.add(member, *similar_class(smco))
        outcome(member, 1.0)
        assert (shared.shared, shared.designed) == (1, 2)
    same(made, taken)
    same(own, taken, 1.0)  # the design taken is the one the body makes itself
    assert similar_class(Choice(size=2.0)) == (Choice(size=0.5), 4.0)
    with pytest.raises(ValueError, match="power of 4"):
        SimilarBodies().add(small, "key", 2.0)


def test_a_ranked_frontier_follows_its_class(base):
    with similar_bodies() as shared:
        fronts = []
        for choice in (Choice(), Choice(size=4.0)):
            setup = setup_of(base, choice)
            key, ratio = similar_class(choice)
            shared.add(setup, key, ratio)
            fronts.append(
                find_frontier(setup, rtol=0.05, checks=False, law=False, start=ratio**-0.5)
            )
            if len(fronts) == 1:
                designed = shared.designed
    small, large = fronts
    assert large.s_max == small.s_max / 2 and large.s_above == small.s_above / 2
    assert shared.designed == designed and shared.shared == small.evaluations
    assert large.binding.text("vacuum") == small.binding.text("vacuum")
