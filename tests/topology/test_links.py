"""The diagram's links to the atlas and the FLI at one energy."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from chargedesign.simulation import taylor
from chargedesign.topology.compute import TracedBranch
from chargedesign.topology.equations import MomentumMap
from chargedesign.topology.links import critical_motions, linked_pictures


def test_critical_motions_on_a_vertical_line(unit_diagram, unit_params):
    """At h = 1.2 J the line crosses the elliptic top, the hyperbolic curve and k = 0."""
    motions = critical_motions(unit_diagram, 1.2)
    assert sorted(m.type for m in motions) == ["degenerate", "elliptic", "hyperbolic"]
    values = MomentumMap(unit_params).values(np.array([m.state for m in motions]))
    size = np.ptp(np.concatenate([b.hk for b in unit_diagram.branches]), axis=0)
    assert np.allclose(values[:, 0], 1.2, atol=1e-3 * size[0])
    assert np.allclose(values[:, 1], [m.k for m in motions], atol=1e-3 * size[1])
    assert np.allclose(values[:, 3], 0.0, atol=1e-3)


def test_energy_outside_the_diagram_is_refused(unit_diagram):
    with pytest.raises(ValueError, match=r"inside the diagram.s range"):
        linked_pictures(unit_diagram, 50.0)


@pytest.mark.skipif(not taylor.available(), reason="heyoka is not installed")
def test_linked_pictures_small(unit_diagram):
    linked = linked_pictures(
        unit_diagram, 1.2, orbits=3, t_end=30.0, fli_grid=(6, 4), fli_t_end=5.0
    )
    assert len(linked.orbit_k) == 3 and np.all(np.isfinite(linked.orbit_k))
    assert len(linked.critical_orbits) == len(linked.critical) == 3
    assert linked.fli.fli[0].shape == (4, 6)
    assert linked.to_dict()["fli_grid"] == [6, 4]
    assert linked.plot() is not None


def test_a_branch_crossing_the_line_twice_gives_each_crossing_its_own_state():
    """A branch whose energy rises and falls again (a fold) meets h = 1 twice: each critical
    motion is interpolated on its own segment, with that segment's type (not both on the
    first)."""
    hk = np.array([[0.0, 0.0], [2.0, 1.0], [0.0, 2.0]])
    states = np.array([[1.0, 0, 0, 0, 0, 1], [2.0, 0, 0, 0, 0, 1], [3.0, 0, 0, 0, 0, 1]])
    branch = TracedBranch(states, hk, ["elliptic", "degenerate", "hyperbolic"], ("a", "b"))
    motions = critical_motions(SimpleNamespace(branches=[branch]), 1.0)
    assert [m.k for m in motions] == [0.5, 1.5]
    assert [m.state[0] for m in motions] == [1.5, 2.5]
    assert [m.type for m in motions] == ["degenerate", "hyperbolic"]
