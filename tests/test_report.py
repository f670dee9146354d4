"""The report's opening states what a builder must make: the parts' sizes."""

from pathlib import Path

import numpy as np

from chargedesign.design import design_from_scene
from chargedesign.report import render_report
from chargedesign.results import format_length
from chargedesign.scene import load_scene

SMALL = Path(__file__).resolve().parent / "physical" / "small.toml"


def test_part_sizes_are_those_of_the_written_parts():
    design = design_from_scene(load_scene(SMALL), frontier=False).design
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
