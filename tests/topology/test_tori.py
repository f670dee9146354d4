"""Tori counted by the flow: the generic case the sampler got wrong, every chamber once (thin
ones too), kappa < 0, and n as no parameter of the count (Larmor)."""

from __future__ import annotations

import pytest
from topology_cases import GENERIC
from unit_scene import UNIT_PARAMETERS as UNIT

from chargedesign.errors import InputError
from chargedesign.topology.chambers import count_by_flow
from chargedesign.topology.closed_form import ClosedForm
from chargedesign.topology.diagram import bifurcation_diagram, chamber_labels
from chargedesign.topology.equations import MomentumMap
from chargedesign.topology.tori import tori_at

#: (h, k, tori) in its chambers; the old sampler said 1 and 2 at the first two
GENERIC_LEVELS = [(0.5235, 7e-5, 2), (0.5082, 0.00063, 4), (0.5388, 0.00357, 4)]


@pytest.mark.parametrize(("h", "k", "tori"), GENERIC_LEVELS)
def test_generic_counts_by_the_flow(h, k, tori):
    count = tori_at(GENERIC, h, k)
    assert count.tori == tori
    assert count.at_point is not None and count.at_point.tori == tori
    evidence = count.middle
    assert evidence is not None and evidence.plateau is not None
    # the count holds over a factor of at least 2 of join distances, every sample covered,
    # and the tori's samples lie farther apart than the largest join distance
    assert evidence.plateau[1] >= 2 * evidence.plateau[0]
    assert evidence.separation is not None and evidence.separation > evidence.plateau[1]


def test_the_count_has_no_n_in_it(small_options):
    """Counted directly at n = 0.7 in SI (no unit reading, no Larmor map) and through the
    reading at n = 0: the same numbers of tori (the Larmor map is a change of frame)."""
    h, k, tori = GENERIC_LEVELS[1]
    light = small_options.counting
    direct = count_by_flow(MomentumMap(GENERIC), h, k, light)
    assert direct.tori == tori
    shifted = GENERIC.replace(n=0.0)
    assert tori_at(shifted, h - GENERIC.C * GENERIC.n**2, k, light).tori == tori


def test_every_chamber_counted_and_labelled_once(generic_diagram):
    cells = generic_diagram.raw.chambers
    labels = chamber_labels(cells)
    assert [c.chamber for c in labels] == sorted({c.chamber for c in cells})
    assert all(c.tori is not None for c in cells)
    for label in labels:  # the cells of a chamber agree
        assert {c.tori for c in cells if c.chamber == label.chamber} == {label.tori}
    assert sorted({c.tori for c in labels}) == [2, 4]
    # the thin bottom chamber (below 2e-3 of the k scale at its middle: the old sampler
    # skipped it) has its sample and its 4 tori
    closed = ClosedForm.of(GENERIC)
    k_scale = closed.upper(generic_diagram.raw.h_range[1])
    bottom = [c for c in cells if c.h < closed.parabolas[1].start]
    assert len(bottom) == 1
    assert closed.upper(bottom[0].h) < 2e-3 * k_scale and bottom[0].tori == 4


def test_chaplygin_chambers_labelled_once(small_options):
    """K = n = 0: two traced families share one image for 0 < h < a; the chambers come from
    the closed form, so each of the three is labelled once."""
    chaplygin = UNIT.replace(K=0.0, n=0.0)
    diagram = bifurcation_diagram(chaplygin, None, small_options)
    labels = chamber_labels(diagram.raw.chambers)
    assert len(labels) == 3
    assert len({(round(c.h, 9), round(c.k, 12)) for c in labels}) == 3
    assert all(c.tori == 2 for c in labels)


def test_kappa_negative(small_options):
    """kappa < 0 (the other shape: |kappa| > K^2 a0): the boundary sits at s = +a0, and the
    counts through the reading agree with a direct count at n != 0."""
    params = UNIT.replace(kappa=-0.9)
    closed = ClosedForm.of(params)
    assert closed.parabolas[0].s > 0 and closed.parabolas[0].type == "elliptic"
    hyperbolic = closed.parabolas[1]
    for h, lower in ((hyperbolic.start + 0.3, True), (hyperbolic.h_j + 0.2, False)):
        walls = [value for value, _ in closed.walls(h)]
        k = 0.5 * (walls[1] + walls[2]) if not lower else 0.25 * walls[1]
        through = tori_at(params, h, k, small_options.counting).tori
        direct = count_by_flow(MomentumMap(params), h, k, small_options.counting).tori
        assert through == direct == 2


def test_outside_the_bounds_is_empty_and_a_branch_is_refused():
    closed = ClosedForm.of(GENERIC)
    assert tori_at(GENERIC, closed.h_min - 0.01, 1e-6).tori == 0
    assert tori_at(GENERIC, 0.55, 1.001 * closed.upper(0.55)).tori == 0
    with pytest.raises(InputError, match="critical value, on the hyperbolic") as error:
        tori_at(GENERIC, 0.55, float(closed.parabolas[2].k(0.55)))
    assert "\n" not in str(error.value)
    with pytest.raises(InputError, match="critical value, on the degenerate k = 0"):
        tori_at(GENERIC, 0.55, 0.0)


def test_a_level_near_a_branch_takes_its_chambers_count(small_options):
    """Just above a hyperbolic arc (1e-7 of k) the tori nearly touch; the count is the
    chamber's, counted at its thickest point, and the text says what the point itself gave."""
    closed = ClosedForm.of(GENERIC)
    h = 0.55
    k = float(closed.parabolas[2].k(h)) * (1 + 1e-7)
    near = tori_at(GENERIC, h, k, small_options.counting)
    walls = [value for value, _ in closed.walls(h)]
    above = min(v for v in walls if v > k)
    middle = tori_at(GENERIC, h, 0.5 * (k + above), small_options.counting)
    assert near.tori == middle.tori
    assert near.best == middle.best
    assert "chamber's thickest point" in str(near)
