"""A body above MAX_FRONTIER_CANDIDATES: ``design`` writes it without its frontier and says
why (the report's notes, the terminal), and ``frontier`` refuses the scene in one line before
the physical design (its charges' minmax would not end)."""

from __future__ import annotations

from pathlib import Path

import pytest

import chargedesign.designer.pipeline as pipeline
from chargedesign.candidates import candidates_from_points
from chargedesign.errors import InputError
from chargedesign.scene import load_scene

SMALL = Path(__file__).resolve().parents[1] / "physical" / "small.toml"


def test_the_reason_names_the_count_the_cap_and_a_spacing_that_fits(monkeypatch):
    points = [[0.01 * i, 0.0, 0.0] for i in range(-6, 7)]
    candidates = candidates_from_points(points)
    assert pipeline.frontier_too_large(candidates) is None  # 13 <= 1,000
    monkeypatch.setattr(pipeline, "MAX_FRONTIER_CANDIDATES", 5)
    why = pipeline.frontier_too_large(candidates)
    assert why is not None and why.startswith("13 candidates is above the 5 ")
    candidates.description["spacing"] = 0.01
    why = pipeline.frontier_too_large(candidates)
    # 13 / 5 candidates at spacing^-3: (13 / 5)^(1/3) = 1.375 times wider
    assert why is not None and "spacing of about 0.014 m keeps it within" in why


def test_design_writes_the_body_without_its_frontier_and_frontier_refuses(monkeypatch):
    scene = load_scene(SMALL)
    monkeypatch.setattr(pipeline, "MAX_FRONTIER_CANDIDATES", 10)
    said: list[str] = []
    result = pipeline.design_from_scene(scene, progress=said.append)
    assert result.design.frontier is None
    notes = [n for n in result.design.notes or [] if n.startswith("frontier not located: ")]
    assert len(notes) == 1 and "above the 10 a frontier takes" in notes[0]
    assert any(line == notes[0] for line in said)
    with pytest.raises(InputError, match=r"^frontier: \d+ candidates is above the 10 ") as info:
        pipeline.design_and_frontier_from_scene(scene)
    assert "\n" not in str(info.value)
