"""A ranking frontier finds its bracket from the masses' rate law (the magnets' conditions are
homogeneous in (sigma, s^2)): on the K = 0 example, where the design's outcome is monotone in
the rate, it ends in the bisection's own bracket (the same s_max, to the bit, and the same
binding) with 2 designs instead of 8."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from chargedesign.designer.frontier import find_frontier, masses_rate_law
from chargedesign.designer.pipeline import physical_setup_from_scene
from chargedesign.scene import load_scene

ROOT = Path(__file__).parents[2]
CHAPLYGIN = ROOT / "examples" / "scenes" / "chaplygin_magnetic.toml"
SMALL = ROOT / "tests" / "physical" / "small.toml"
RTOL = 0.05


@pytest.fixture(scope="module")
def fronts():
    setup = physical_setup_from_scene(load_scene(CHAPLYGIN))
    by_law = find_frontier(setup, rtol=RTOL, checks=False, law=True)
    setup = physical_setup_from_scene(load_scene(CHAPLYGIN))
    by_bisection = find_frontier(setup, rtol=RTOL, checks=False, law=False)
    return masses_rate_law(setup), by_law, by_bisection


def test_the_law_ends_in_the_bisections_bracket(fronts):
    law, by_law, by_bisection = fronts
    assert law is not None and abs(math.log(law / by_bisection.s_max)) < math.log1p(RTOL)
    assert by_law.s_max == by_bisection.s_max and by_law.s_above == by_bisection.s_above
    assert by_law.binding.text("vacuum") == by_bisection.binding.text("vacuum")
    assert by_law.binding.stage == "magnets"
    assert by_law.realised is None and by_bisection.realised is None


def test_the_law_needs_fewer_designs(fronts):
    _, by_law, by_bisection = fronts
    assert by_law.evaluations == 2  # one design below the law, one above
    assert by_bisection.evaluations >= 6


def test_the_law_does_not_apply_with_charge_conditions():
    assert masses_rate_law(physical_setup_from_scene(load_scene(SMALL))) is None
