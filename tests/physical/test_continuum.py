"""Magnets below the continuum size are flagged, not silently accepted.

The magnet data (remanence, coercivity) are those of bulk sintered magnets. The small test
body's magnets come out about 2 nm across: single-domain nanoparticles, not the continuum
magnets the design assumes. The report's verdict, its part sizes and the limits check say so;
the limits themselves (fields, overlaps, demagnetisation) are unchanged.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from chargedesign.body import Design
from chargedesign.designer import design_from_scene
from chargedesign.physical.budget import realism_record
from chargedesign.physical.limits import check_limits
from chargedesign.physical.materials import MAGNET_CONTINUUM_SIZE
from chargedesign.physical.realism import magnet_continuum
from chargedesign.report import render_report
from chargedesign.scene import load_scene
from chargedesign.verdict import verdict_record

SMALL = Path(__file__).parent / "small.toml"


@pytest.fixture(scope="module")
def small_design() -> Design:
    return design_from_scene(load_scene(SMALL), frontier=False).design


def with_edges(design: Design, edges: np.ndarray) -> Design:
    """The same design with magnets of the given cube edges, m (volumes edited only; its
    realism budget and verdict recomputed, as the report renders the record)."""
    data = design.to_dict()
    data["dipoles"]["volumes"] = [float(e) ** 3 for e in edges]
    edited = Design.from_dict(data)
    edited.realism = realism_record(edited)
    edited.verdict = verdict_record(edited)
    return edited


def test_the_small_bodys_magnets_are_nanoparticles(small_design):
    edges = np.cbrt(small_design.magnet_volumes())
    # |m| / M from the written moments: the second route to the magnets' size
    moments = np.linalg.norm(small_design.dipole_moments, axis=1)
    magnetisation = small_design.materials["magnet"]["remanent_magnetisation_A_per_m"]
    np.testing.assert_allclose(edges, np.cbrt(moments / magnetisation), rtol=1e-12)
    found = magnet_continuum(small_design)
    assert edges.max() < 3e-9  # about 2 nm: the case the flag is for
    assert found["below"] == found["count"] == len(edges) == 12
    assert found["smallest_m"] == edges.min() and found["largest_m"] == edges.max()
    assert found["continuum_size_m"] == MAGNET_CONTINUUM_SIZE == 20e-9
    assert found["material"] == "ndfeb-eh"


def test_only_the_magnets_below_the_size_are_counted(small_design):
    edges = np.array([5e-9, 19.9e-9, 20.1e-9, 40e-9] * 3)
    found = magnet_continuum(with_edges(small_design, edges))
    assert found["below"] == 6 and found["count"] == 12
    assert found["smallest_m"] == pytest.approx(5e-9, rel=1e-12)
    assert found["largest_m"] == pytest.approx(40e-9, rel=1e-12)


def test_a_body_without_magnets_has_nothing_to_flag(small_design):
    data = small_design.to_dict()
    del data["dipoles"]
    data["realises"] = [r for r in data["realises"] if r != "V"]
    assert magnet_continuum(Design.from_dict(data)) == {}


def test_the_report_says_the_parts_are_not_buildable_as_specified(small_design):
    text = render_report(small_design)
    verdict = next(x for x in text.splitlines() if x.startswith("**Verdict:"))
    assert verdict.startswith("**Verdict: NOT buildable**")
    (row,) = [x for x in text.splitlines() if x.startswith("| NOT buildable |")]
    assert "12 of its magnets are smaller than the 20 nm continuum size" in row
    (sizes,) = [x for x in text.splitlines() if x.startswith("- Part sizes:")]
    assert "(12 of them below the 20 nm a ferromagnet needs" in sizes
    (size,) = [x for x in text.splitlines() if x.startswith("- Size:")]
    assert "this body's smallest is 2.24 nm, already below it" in size
    # no claim that size is free below the sizes the breakdown data hold for
    assert "no size changes" not in size and "only through the surface field" in size
    # the same body with magnets of 30 nm: no flag, the verdict of the limits and the budget
    large = render_report(with_edges(small_design, np.full(12, 30e-9)))
    verdict = next(x for x in large.splitlines() if x.startswith("**Verdict:"))
    opening = large.split("\n## Elements")[0]  # the summary and its detail
    assert "continuum size" not in opening.split("- Part sizes")[0]
    assert verdict.startswith("**Verdict: buildable parts, NOT realised as designed**")
    assert "below the 20 nm" not in large and "30 nm, above it" in large


def test_the_limits_check_flags_them_without_a_broken_limit(small_design):
    limits = check_limits(small_design)
    assert limits.parts_within_limits and not limits.violations
    assert limits.to_dict()["magnet_continuum"]["below"] == 12
    assert "magnets below the continuum size: 12 of 12" in str(limits)
    large = check_limits(with_edges(small_design, np.full(12, 30e-9)))
    assert large.to_dict()["magnet_continuum"]["below"] == 0
    assert "continuum" not in str(large)
