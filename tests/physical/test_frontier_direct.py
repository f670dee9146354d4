"""The charges' limit on the rate computed directly (one minmax of the carriers' surface
field) against the frontier's bisection, the design's charges stage and the limits check's
own field kernel."""

from __future__ import annotations

import numpy as np
import pytest

# the frontier's acceptance tests' bodies (pytest puts this folder on the path)
from test_frontier_acceptance import CASES, setup_of, small

from chargedesign.designer.charges import design_charges
from chargedesign.designer.frontier import FRONTIER_RTOL, find_frontier
from chargedesign.designer.frontier_probes import MINMAX_GAP, charges_rate_limit
from chargedesign.designer.physical_setup import PhysicalInfeasible
from chargedesign.physical.limits import carrier_surface_fields

#: the small body in SF6 (frame reading), where the carriers' surface field binds
CHARGES_BIND = CASES["small in SF6, frame"]


@pytest.fixture(scope="module")
def sf6():
    setup = setup_of(CHARGES_BIND)
    return setup, charges_rate_limit(setup)


@pytest.fixture(scope="module")
def bisected(sf6):
    return find_frontier(sf6[0], direct=False)


def test_the_charges_limit_lies_in_the_bisection_bracket(sf6, bisected):
    _, limit = sf6
    assert bisected.binding.stage == "charges"
    assert limit.stage == "charges" and limit.gap <= MINMAX_GAP
    # an upper bound on every rate the design accepts, and reached within the bracket
    assert bisected.s_max <= limit.rate <= bisected.s_above


def test_the_direct_frontier_agrees_with_the_bisection_in_fewer_designs(sf6, bisected):
    setup, limit = sf6
    direct = find_frontier(setup)
    assert direct.s_charges == pytest.approx(limit.rate, rel=FRONTIER_RTOL / 10)
    assert direct.s_above == direct.s_charges
    assert direct.s_above / direct.s_max <= 1 + FRONTIER_RTOL
    assert abs(direct.s_max / bisected.s_max - 1) <= FRONTIER_RTOL
    assert direct.binding.stage == "charges" and direct.binding.proved
    assert direct.binding.element.startswith("charge at")
    assert direct.evaluations < bisected.evaluations


@pytest.mark.parametrize("body", ["sf6", "small"])
def test_just_above_the_limit_the_charges_stage_refuses(sf6, body):
    if body == "sf6":
        setup, limit = sf6
    else:
        setup = setup_of(small())
        limit = charges_rate_limit(setup)
    with pytest.raises(PhysicalInfeasible) as info:
        design_charges(setup, 1.001 * limit.rate)
    assert info.value.binding.stage == "charges"
    # and just below it the stage finds charges
    charges = design_charges(setup, limit.rate / (1 + FRONTIER_RTOL / 4))
    assert len(charges.sites) > 0


def test_the_limit_charges_reach_the_safe_field_by_the_limits_check_kernel(sf6):
    """At rate/(1 + gap) the minmax's charges meet the conditions with the largest surface
    field at the design's limit E_safe (1 - DESIGN_MARGIN), by the independent kernel of
    the limits check (400 samples per carrier, its own refinement)."""
    setup, limit = sf6
    s = limit.rate / (1 + limit.gap)
    q = s * limit.charges
    A, b = setup.systems["charges"]
    full = np.zeros(len(setup.points))
    full[limit.sites] = q
    np.testing.assert_allclose(A @ full, s * b, rtol=0, atol=1e-7 * np.abs(s * b).max())
    radii = np.full(len(q), setup.carrier_radius)
    fields, _ = carrier_surface_fields(setup.points[limit.sites], q, radii, setup.electric, 400)
    top = float(np.max(fields)) / setup.surface_limit
    assert 1 - 2e-3 <= top <= 1 + 2e-3
    # the worst carrier named is the one the kernel finds at the top (within the gap)
    worst = fields[list(limit.sites).index(limit.worst_site)]
    assert worst >= float(np.max(fields)) * (1 - 2e-3)
