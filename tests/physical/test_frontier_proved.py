"""A refusal the charges' stage proves holds at every faster rate, and the frontier that skips
the rates above it finds what the frontier designing every rate finds."""

from __future__ import annotations

import tomllib
from pathlib import Path

import numpy as np
import pytest

from chargedesign.designer.charges import design_charges
from chargedesign.designer.frontier import find_frontier
from chargedesign.designer.physical_setup import Binding, PhysicalInfeasible
from chargedesign.designer.pipeline import physical_setup_from_scene
from chargedesign.physical.limits import carrier_surface_fields
from chargedesign.scene import scene_from_dict

SMALL = Path(__file__).parent / "small.toml"


@pytest.fixture(scope="module")
def setup():
    return physical_setup_from_scene(scene_from_dict(tomllib.loads(SMALL.read_text()), "<t>"))


@pytest.fixture(scope="module")
def frontier(setup):
    # the bisection alone (the charges' limit computed directly proves its refusal without
    # the design's: test_frontier_direct.py)
    return find_frontier(setup, direct=False)


def _refusal(setup, s):
    try:
        design_charges(setup, s)
    except PhysicalInfeasible as exc:
        return exc.binding
    return None


def test_faster_rates_than_a_proved_refusal_are_refused_by_design_too(setup, frontier):
    """The heuristic's own verdicts (every round, no proof used) above a proved refusal."""
    factors = (1.0, 1.02, 1.05, 1.2, 2.0, 10.0)
    refusals = [_refusal(setup, frontier.s_above * f) for f in factors]
    proved = [i for i, b in enumerate(refusals) if b is not None and b.proved]
    assert proved, "no proved refusal above the frontier: the test would assert nothing"
    assert all(refusals[i] is not None for i in range(proved[0], len(factors)))


def test_feasible_charges_scale_down_with_the_rate(setup, frontier):
    """The premise of the proof: charges feasible at s, times s'/s, meet the conditions at
    s' < s with every surface field lower (by the limits check's own kernel)."""
    s = frontier.s_max
    charges = design_charges(setup, s)
    A, b = setup.systems["charges"]
    radii = np.full(len(charges.sites), setup.carrier_radius)
    positions = setup.points[charges.sites]
    at_s, _ = carrier_surface_fields(positions, charges.charges, radii, setup.electric, 400)
    for ratio in (0.5, 0.9):
        q = charges.charges * ratio
        full = np.zeros(len(setup.points))
        full[charges.sites] = q
        np.testing.assert_allclose(A @ full, ratio * s * b, rtol=0, atol=1e-9 * np.abs(b).max() * s)
        slower, _ = carrier_surface_fields(positions, q, radii, setup.electric, 400)
        assert np.all(slower <= at_s * (1 + 1e-12))
        assert np.all(np.abs(q) <= setup.charge_caps(ratio * s)[charges.sites] * (1 + 1e-12))


def test_skipping_the_rates_above_a_proved_refusal_changes_nothing(setup, frontier, monkeypatch):
    """Against the same frontier with every proof withdrawn (every rate designed)."""
    original = PhysicalInfeasible.__init__

    def unproved(self, binding):
        original(self, Binding(**{**binding.__dict__, "proved": False}))

    monkeypatch.setattr(PhysicalInfeasible, "__init__", unproved)
    plain = find_frontier(setup, direct=False)
    assert plain.s_max == frontier.s_max and plain.s_above == frontier.s_above
    assert plain.binding.to_dict() == frontier.binding.to_dict()
    # this body's upward checks include rates above a proved refusal (12 designs against 14)
    assert frontier.evaluations < plain.evaluations
    designed = {s for s, _ in frontier.history}
    assert designed <= {s for s, _ in plain.history}
