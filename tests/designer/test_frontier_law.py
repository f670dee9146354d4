"""A ranking frontier starts its bracket at the masses' rate law (the magnets' conditions are
homogeneous in (sigma, s^2)): on the K = 0 example it closes the same bracket as the
bisection from rates 10x apart, to the tolerance, with fewer designs."""

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


def test_the_law_brackets_what_the_bisection_brackets(fronts):
    law, by_law, by_bisection = fronts
    assert law is not None and by_bisection.s_max < law < by_bisection.s_above * (1 + RTOL)
    for front in (by_law, by_bisection):
        assert front.s_max > 0 and front.s_above / front.s_max <= 1 + RTOL
    # both brackets hold the frontier: they overlap, their ends within the tolerance
    assert by_law.s_max < by_bisection.s_above and by_bisection.s_max < by_law.s_above
    assert abs(math.log(by_law.s_max / by_bisection.s_max)) <= math.log1p(RTOL)
    assert by_law.binding.stage == by_bisection.binding.stage == "magnets"


def test_the_law_needs_fewer_designs(fronts):
    _, by_law, by_bisection = fronts
    assert by_law.evaluations == 2  # one design below the law, one above
    assert by_bisection.evaluations >= 6


def test_the_law_does_not_apply_with_charge_conditions():
    assert masses_rate_law(physical_setup_from_scene(load_scene(SMALL))) is None
