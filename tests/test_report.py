"""The report's opening states what a builder must make: the parts' sizes."""

import math
import re
from pathlib import Path

import numpy as np
import pytest

from chargedesign.body import Design
from chargedesign.designer import design_from_scene
from chargedesign.errors import InputError
from chargedesign.formatting import fmt_length
from chargedesign.physical.budget import realism_record
from chargedesign.report import render_report
from chargedesign.results import design_text
from chargedesign.scene import load_scene

SMALL = Path(__file__).resolve().parent / "physical" / "small.toml"


def test_part_sizes_are_those_of_the_written_parts():
    result = design_from_scene(load_scene(SMALL), frontier=False)
    design = result.design
    # the physical record: named fields, read through by the result
    assert result.limits is design.buildability and result.limits["parts_within_limits"] is True
    assert result.realism is design.realism and result.realism
    assert result.time_rate == design.time_rate == 1.0
    assert result.frontier is None and "frontier" not in design.to_dict()
    (line,) = [x for x in render_report(design).splitlines() if x.startswith("- Part sizes:")]
    radius = design.carrier_radii()[0]
    assert f"{len(design.charge_values)} carriers of radius {fmt_length(radius)}" in line
    edges = np.cbrt(design.magnet_volumes())
    assert f"{len(edges)} magnets of {fmt_length(edges.min())} to " in line
    assert f"to {fmt_length(edges.max())} across" in line


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
        "x": {"value": 1.0, "unit": "", "verdict": "negligible", "note": "at |omega| in |B|"},
        "part_sizes": {},
        "realisability_map": [],
        "window_at_design": None,
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
    (line,) = [x for x in text.splitlines() if x.startswith("- The K law (")]
    # the law's figure, the budget's, and the formula's estimate beside it
    assert f"{law['value']:.3g} x the designed K torques" in line
    assert f"estimates it at {law['ratio']:.3g}" in line
    detail = text.split("## Detail")[1].split("\n## ")[0]  # the detail after the summary
    assert "field evaporation" in detail or "evaporates" in detail
    table = text.split("## Realisability map")[1].split("\n## ")[0]
    rows = [x for x in table.splitlines() if x.startswith("| ") and not x.startswith("| term")]
    computed = realisability_map(design)
    assert len(rows) == len(computed) == 8
    for row, line in zip(computed, rows, strict=True):
        assert line.startswith(f"| {row['term']}: ")
        assert f"| {row['size_N_m']:.3g} |" in line
    # another body, other numbers: ten times the parts' susceptibilities (its budget
    # recomputed: the report renders the record)
    data = design.to_dict()
    for material in data["materials"].values():
        material["volume_susceptibility"] *= 10
    edited = Design.from_dict(data)
    edited.realism = realism_record(edited)
    other = render_report(edited)
    assert f"estimates it at {10 * law['ratio']:.3g}" in other
    assert f"{10 * law['ratio_elements']:.3g} x the designed K torques" in other


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


def _small_design() -> Design:
    return design_from_scene(load_scene(SMALL), frontier=False).design


def test_the_recorded_figures_equal_a_fresh_recomputation(tmp_path):
    """Every figure the report prints is in design.json's ``realism``; each equals the same
    figure recomputed from the written parts (the realism and window functions, and the
    part sizes from the elements by hand), also after the frontier moves K_max."""
    from chargedesign.body import read_design, write_design
    from chargedesign.physical.budget import judge_at_frontier, map_figures
    from chargedesign.physical.realism import field_response, k_law, realisability_map
    from chargedesign.physical.window import window_model
    from chargedesign.results import json_ready

    design = _small_design()
    realism = design.realism
    for key, item in field_response(design).items():
        assert realism[key] == item
    assert realism["k_law_induced_ratio"] == k_law(design)
    # the map's rows, their induced columns from the one figure's function (physical.budget)
    assert realism["realisability_map"] == json_ready(map_figures(design))
    rows = {r["key"]: r for r in realisability_map(design)}
    for row in realism["realisability_map"]:
        if row["induced_over_term"] is not None:  # the same energy at the design's rate
            assert row["induced_over_term"] == pytest.approx(
                rows[row["key"]]["induced_over_term"], rel=1e-9
            )
    figure = realism["induced_magnetisation"]
    smallest = next(r for r in realism["realisability_map"] if r["key"] == figure["term"])
    assert smallest["induced_over_term"] == pytest.approx(figure["value"], rel=1e-12)
    # the part sizes by hand: carrier radii, magnet cube edges, ballast sphere radii
    sizes = realism["part_sizes"]
    radii = np.asarray(design.charge_radii)
    assert sizes["carriers"] == {
        "count": len(radii),
        "smallest_m": radii.min(),
        "largest_m": radii.max(),
    }
    edges = np.cbrt(np.asarray(design.dipole_volumes))
    assert sizes["magnets"]["count"] == len(edges) == 12
    assert sizes["magnets"]["smallest_m"] == pytest.approx(edges.min(), rel=1e-15)
    assert sizes["magnets"]["largest_m"] == pytest.approx(edges.max(), rel=1e-15)
    density = design.materials["ballast"]["density_kg_per_m3"]
    balls = (3.0 * np.asarray(design.mass_values) / (4.0 * np.pi * density)) ** (1.0 / 3.0)
    assert sizes["ballast"]["count"] == len(balls) > 0
    assert sizes["ballast"]["smallest_m"] == pytest.approx(balls.min(), rel=1e-14)
    assert sizes["ballast"]["largest_m"] == pytest.approx(balls.max(), rel=1e-14)
    # the window's items at the design's rate
    model = window_model(design, 1.0)
    window = realism["window_at_design"]
    assert window["fraction"] == model.fraction and window["term_key"] == model.term_key
    ratios = model.ratios(1.0)
    assert [i["key"] for i in window["items"]] == list(ratios)
    for item in window["items"]:
        assert item["over_fraction"] == pytest.approx(
            ratios[item["key"]] / model.fraction, rel=1e-14
        )
    assert window["support"] == json_ready(model.support)
    assert window["apparatus"] == json_ready(model.apparatus.to_dict())
    # a frontier known later: the K law and the map's frontier columns follow its K_max
    design.frontier = {"K_max": 3.0 * abs(design.parameters.K)}
    before = realism["realisability_map"]
    judge_at_frontier(design)
    assert design.realism["k_law_induced_ratio"] == k_law(design)
    after = design.realism["realisability_map"]
    assert after == json_ready(map_figures(design)) and after != before
    # ... and the window at the design's rate, not recomputed, is still a fresh one's
    model = window_model(design, 1.0)
    ratios = model.ratios(1.0)
    kept = design.realism["window_at_design"]
    assert model.term_key == kept["term_key"] and list(ratios) == [i["key"] for i in kept["items"]]
    for item in kept["items"]:
        expected = ratios[item["key"]] / model.fraction
        assert item["over_fraction"] == pytest.approx(expected, rel=1e-14)
    # the report renders the same from memory and from the written file
    write_design(design, tmp_path / "design.json")
    assert render_report(read_design(tmp_path / "design.json")) == render_report(design)


def test_an_older_design_json_without_the_figures_is_one_line():
    """A design.json written before the budget recorded the report's figures: one line
    naming the missing block, no traceback, no report from half a record."""
    data = _small_design().to_dict()
    for key in ("part_sizes", "realisability_map", "window_at_design"):
        del data["realism"][key]
    with pytest.raises(InputError) as caught:
        render_report(Design.from_dict(data))
    assert str(caught.value) == (
        "design realism.part_sizes: missing (a design.json written before the realism budget "
        "recorded the report's figures): design the scene again with `chargedesign design` to "
        "render its report"
    )
    # without [medium] (the mathematical case) nothing of the budget is needed
    del data["medium"], data["realism"]
    data.pop("buildability", None)
    assert "not checked for buildability" in render_report(Design.from_dict(data))


def test_the_report_imports_no_computation_of_the_budget():
    """report.py renders: it imports neither the realism budget's computations nor the
    window's (nor the module that assembles them); it reads the typed record."""
    import ast

    import chargedesign.report as report

    tree = ast.parse(Path(report.__file__).read_text())
    imported = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and node.module:
            imported.add(node.module)
            imported |= {f"{node.module}.{alias.name}" for alias in node.names}
        elif isinstance(node, ast.Import):
            imported |= {alias.name for alias in node.names}
    # the realised window and its support are read back as the window's own record types
    # (RealisedWindow.from_dict, BearingSupport.from_dict): the names of the window's module
    # allowed
    window = {m for m in imported if m.startswith("chargedesign.physical.window")}
    assert window <= {
        "chargedesign.physical.window",
        "chargedesign.physical.window.RealisedWindow",
        "chargedesign.physical.window.BearingSupport",
    }
    imported -= window
    computing = {
        "chargedesign.physical.realism",
        "chargedesign.physical.window",
        "chargedesign.physical.budget",
        "chargedesign.physical.coils",
        "chargedesign.physical.field_bounds",
    }
    assert not imported & computing
    assert not {m for m in imported if m.startswith(tuple(f"{c}." for c in computing))}
    assert "chargedesign.scene.design_realism.RealismRecord" in imported
    # the materials module serves the mathematical case's plausibility constants and a label
    materials = {
        m.rsplit(".", 1)[1] for m in imported if m.startswith("chargedesign.physical.materials.")
    }
    assert materials == {"BREAKDOWN_V_PER_M", "MAGNET_DATA", "ballast_label"}


def test_citations_are_keys_inline_and_the_sources_section_says_their_status():
    """Inline a figure is cited by its key alone; the sources section lists each key once with
    its checked status from the sources table (unverified ones say so there, not inline)."""
    from chargedesign.physical.sources import cited_keys, rows, sources_table_lines

    table = {row.key: row for row in rows()}
    unchecked = next(row for row in table.values() if not row.checked)
    checked = next(row for row in table.values() if row.checked)
    text = (
        f"a figure [{unchecked.key}, unverified], again [{unchecked.key}, unverified], "
        f"a checked one [{checked.key}] and a mark [unverified (from memory)]"
    )
    out, keys = cited_keys(text)
    assert "unverified" not in out and out.count(f"[{unchecked.key}]") == 2
    assert keys == [unchecked.key, checked.key, "unchecked"]
    lines = sources_table_lines(keys)
    (row_u,) = [x for x in lines if x.startswith(f"| {unchecked.key} |")]
    (row_c,) = [x for x in lines if x.startswith(f"| {checked.key} |")]
    assert row_u.endswith("| no (unverified) |") and row_c.endswith("| yes |")
    assert any(x.startswith("| unchecked |") and x.endswith("| no |") for x in lines)
    assert sources_table_lines([]) == []


@pytest.mark.parametrize("s_low", [None, 0.13])
def test_the_recorded_window_reads_back_as_the_frontier_s_record(s_low):
    """design.json's ``frontier.realised`` is read back as the frontier's RealisedWindow
    (the one type the report and the verdict render): its ``to_dict`` is the record written,
    through JSON, for an empty window (a missing factor) and a window with a range."""
    import json

    from chargedesign.physical.window import RealisedWindow
    from chargedesign.verdict import realised_window

    window = RealisedWindow(
        s_low=s_low,
        s_high=None if s_low is None else 4.8,
        binding_low="eddy torque (of the K2 term)",
        binding_high="limits: surface field",
        fraction=1e-3,
        s_best=0.5,
        missing=37.0,
        term_key="K2",
        margins={"eddy": 2.0},
        laws={"eddy": "s^1"},
        notes=["a note"],
        why="no rate" if s_low is None else "",
        support={"bearing": "cup"},
        at_design={"eddy": 3.0},
    )
    written = json.loads(json.dumps(window.to_dict()))
    design = Design.from_dict({"parameters": {"C": 1.0}, "frontier": {"realised": written}})
    read = realised_window(design)
    assert isinstance(read, RealisedWindow)
    assert read.to_dict() == written
    assert RealisedWindow.from_dict(written).to_dict() == written
    assert read.empty == (s_low is None)
    assert read.missing == (37.0 if s_low is None else math.inf)
    assert realised_window(Design.from_dict({"parameters": {"C": 1.0}})) is None


def test_a_case_record_s_window_reads_back_with_what_it_keeps():
    """A ``[case]`` record keeps its window's ends, bindings, fraction and notes: read back as
    the same RealisedWindow, the rest empty."""
    from chargedesign.verdict import recorded_window

    kept = {"s_low": 0.2, "s_high": 3.0, "binding_low": "a", "binding_high": "b"}
    window = recorded_window({**kept, "fraction": 1e-3, "notes": ["n"]})
    assert window is not None and not window.empty
    assert {k: getattr(window, k) for k in kept} == kept
    assert (window.fraction, window.notes, window.margins) == (1e-3, ["n"], {})
    assert window.missing == math.inf
    assert recorded_window(None) is None and recorded_window({}) is None
    assert recorded_window({**kept, "s_low": None, "fraction": 1e-3}).empty
