"""The cones' kernel rows kept between constraint-generation rounds (``ConeRows``) against the
plain kernel of each round (``coulomb_kernel`` on the round's sources and points): the same
bits, so the cone programs and every answer downstream are unchanged."""

from __future__ import annotations

import math
import tomllib
from pathlib import Path

import numpy as np
import pytest

from chargedesign.constants import COULOMB, EPSILON_0
from chargedesign.designer.charges import ConeRows, socp_charges
from chargedesign.designer.cone_program import ConeProgram
from chargedesign.designer.frontier_probes import minmax_charges
from chargedesign.designer.pipeline import physical_setup_from_scene
from chargedesign.physical.coulomb import coulomb_kernel
from chargedesign.scene import scene_from_dict

SMALL = Path(__file__).parents[1] / "physical" / "small.toml"


@pytest.fixture(scope="module")
def setup():
    return physical_setup_from_scene(scene_from_dict(tomllib.loads(SMALL.read_text()), "<t>"))


def _surface_points(sources, a, n, seed):
    rng = np.random.default_rng(seed)
    picks = rng.integers(0, len(sources), n)
    dirs = rng.standard_normal((n, 3))
    dirs /= np.linalg.norm(dirs, axis=1)[:, None]
    return sources[picks] + a * dirs


def test_kept_rows_equal_the_plain_kernel_bit_for_bit():
    rng = np.random.default_rng(3)
    sources = rng.uniform(-0.05, 0.05, (40, 3))
    rows = ConeRows(sources)
    first = _surface_points(sources, 0.004, 30, 1)
    more = _surface_points(sources, 0.004, 20, 2)
    scale = COULOMB * 1.7e-11 / 4.9e6
    np.testing.assert_array_equal(rows.of(first, scale), coulomb_kernel(sources, first, scale))
    # a later round: kept points (in another order) with new ones, another scale
    later = np.concatenate([first[::-2], more])
    np.testing.assert_array_equal(
        rows.of(later, 2.5 * scale), coulomb_kernel(sources, later, 2.5 * scale)
    )
    assert len(rows.rows) == len(first) + len(more)  # each point computed once
    # a subset of the sources (a working set): its own rows, then kept for it
    cols = np.sort(rng.choice(len(sources), 25, replace=False))
    for points in (later, first):
        np.testing.assert_array_equal(
            rows.of(points, scale, cols), coulomb_kernel(sources[cols], points, scale)
        )
    assert len(rows.rows) == len(first) + len(more)


def _captured(monkeypatch):
    """The cone programs the routes build, captured as they are solved."""
    seen = []
    original = ConeProgram.solve

    def capture(self, *args, **kwargs):
        seen.append(self)
        return original(self, *args, **kwargs)

    monkeypatch.setattr(ConeProgram, "solve", capture)
    return seen


def test_the_minmax_rounds_build_the_plain_programs(setup, monkeypatch):
    """Rounds of the minmax's cones through one ConeRows: each program's cone rows are the
    plain kernel of that round's points, and its answer that of a fresh route."""
    seen = _captured(monkeypatch)
    a = setup.carrier_radius
    k = len(setup.points)
    limit = setup.surface_limit
    qs = 4 * math.pi * EPSILON_0 * a**2 * limit
    points = _surface_points(setup.points, a, 30, 4)
    rows = ConeRows(setup.points)
    for cones in (list(points[:10]), list(points[5:20]), list(points[::3]) + list(points[20:])):
        kept = minmax_charges(setup, cones, rows)
        plain = coulomb_kernel(setup.points, np.array(cones), COULOMB * qs / limit)
        np.testing.assert_array_equal(-seen[-1].G_soc[:, 1:, :k], plain)
        fresh = minmax_charges(setup, cones)
        assert kept is not None and fresh is not None
        assert kept[0] == fresh[0]
        np.testing.assert_array_equal(kept[1], fresh[1])


def test_the_design_cone_rounds_build_the_plain_programs(setup, monkeypatch):
    """The design's cone rounds on a working set, then on every usable candidate (the
    rows kept over all candidates, each program taking its columns)."""
    seen = _captured(monkeypatch)
    s = 1.0
    caps = setup.charge_caps(s)
    usable = np.flatnonzero(caps > 0)
    limit = setup.surface_limit
    points = _surface_points(setup.points[usable], setup.carrier_radius, 12, 5)
    cones = [(int(usable[0]), p) for p in points]
    rows = ConeRows(setup.points)
    for chosen in (usable[::2], usable):
        socp_charges(setup, chosen, s, cones, caps, rows)
        qs = float(np.max(caps[chosen]))
        plain = coulomb_kernel(setup.points[chosen], points, COULOMB * qs / limit)
        np.testing.assert_array_equal(-seen[-1].G_soc[:, 1:, : len(chosen)], plain)
