"""The report's opening states what a builder must make: the parts' sizes."""

import re
from pathlib import Path

import numpy as np

from chargedesign.body import Design
from chargedesign.designer import design_from_scene
from chargedesign.report import render_report
from chargedesign.results import design_text, format_length
from chargedesign.scene import load_scene

SMALL = Path(__file__).resolve().parent / "physical" / "small.toml"


def test_part_sizes_are_those_of_the_written_parts():
    result = design_from_scene(load_scene(SMALL), frontier=False)
    design = result.design
    # the physical record: named fields, read through by the result
    assert result.limits is design.buildability and result.limits["buildable"] is True
    assert result.realism is design.realism and result.realism
    assert result.time_rate == design.time_rate == 1.0
    assert result.frontier is None and "frontier" not in design.to_dict()
    (line,) = [x for x in render_report(design).splitlines() if x.startswith("- Part sizes:")]
    radius = design.carrier_radii()[0]
    assert f"{len(design.charge_values)} carriers of radius {format_length(radius)}" in line
    edges = np.cbrt(design.magnet_volumes())
    assert f"{len(edges)} magnets of {format_length(edges.min())} to " in line
    assert f"to {format_length(edges.max())} across" in line


def test_lengths_read_in_the_unit_that_fits():
    assert format_length(3.125e-3) == "3.12 mm"
    assert format_length(1.2e-8) == "12 nm"
    assert format_length(2.0) == "2 m"
    assert format_length(float("inf")) == "any"


def test_realism_notes_with_bars_stay_in_their_table_cell():
    """`|B|` and `|omega|` in a note would split the Markdown row into more cells."""
    design = Design.from_dict(
        {
            "format": "chargedesign.design/1",
            "parameters": {"C": 1.0, "n": 0.7},
            "masses": {"positions": [[0.1, 0.0, 0.0]], "values": [1.0]},
            "realises": ["inertia"],
            "medium": {"name": "vacuum", "breakdown_V_per_m": 1e7, "safety": 0.5},
            "materials": {"ballast": {"name": "tungsten", "density_kg_per_m3": 19250.0}},
        }
    )
    design.realism = {
        "x": {"value": 1.0, "unit": "", "verdict": "negligible", "note": "at |omega| in |B|"}
    }
    rows = [line for line in render_report(design).splitlines() if line.startswith("| x |")]
    assert len(rows) == 1
    cells = re.split(r"(?<!\\)\|", rows[0])[1:-1]
    assert len(cells) == 4 and "\\|omega\\|" in cells[3]


def test_the_verdict_rests_on_the_k_law_and_the_report_carries_the_map():
    """No size extrapolated from a fit (no "18 nm", no "negligible below"); the verdict's
    ratio is the K law's for this body, and the map has a row per term of V and mu whose
    sizes are the map function's."""
    from chargedesign.physical.realism import k_law, realisability_map

    design = design_from_scene(load_scene(SMALL), frontier=False).design
    text = render_report(design)
    for stale in ("18 nm", "negligible below", "size below which", "n above"):
        assert stale not in text
    law = k_law(design)
    (line,) = [x for x in text.splitlines() if x.startswith("- Induced magnetisation at the K")]
    assert f"{law['ratio']:.3g} times the designed K torques" in line
    assert "field evaporation" in text.split("## ")[0] or "evaporates" in text.split("## ")[0]
    table = text.split("## Realisability map")[1].split("\n## ")[0]
    rows = [x for x in table.splitlines() if x.startswith("| ") and not x.startswith("| term")]
    computed = realisability_map(design)
    assert len(rows) == len(computed) == 8
    for row, line in zip(computed, rows, strict=True):
        assert line.startswith(f"| {row['term']}: ")
        assert f"| {row['size_N_m']:.3g} |" in line
    # another body, other numbers: ten times the parts' susceptibilities
    data = design.to_dict()
    for material in data["materials"].values():
        material["volume_susceptibility"] *= 10
    other = render_report(Design.from_dict(data))
    assert f"{10 * law['ratio']:.3g} times the designed K torques" in other
    assert f"element by element {10 * law['ratio_elements']:.3g}" in other


def test_a_design_prints_its_figures_and_the_result_its_report():
    design = Design.from_dict(
        {
            "parameters": {"C": 1.0, "n": 0.7},
            "masses": {"positions": [[0.1, 0.0, 0.0]], "values": [1.0]},
            "realises": ["inertia"],
        }
    )
    text = str(design)
    assert text == design_text(design)
    assert text.splitlines()[0] == "Design:" and "masses" in text and "C=1 n=0.7" in text
    assert "Design report" in render_report(design)
