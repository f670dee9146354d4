"""`check` of a physical body recomputes its limits from the written elements."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from chargedesign.body import read_design, write_design
from chargedesign.checker import check_design
from chargedesign.cli import main
from chargedesign.designer import design_from_scene
from chargedesign.physical.limits import carrier_surface_fields
from chargedesign.scene import load_scene

SMALL = Path(__file__).resolve().parents[1] / "physical" / "small.toml"


@pytest.fixture(scope="module")
def design():
    return design_from_scene(load_scene(SMALL), frontier=False).design


def test_a_buildable_body_passes_with_its_limits(design, tmp_path):
    report = check_design(design, n_orientations=60)
    assert report.parts_within_limits is True and report.passed
    data = report.to_dict()
    assert data["parts_within_limits"] is True
    assert data["verdict"]["state"] == design.verdict["state"] and data["verdict_agrees"]
    top = float(
        np.max(
            carrier_surface_fields(
                design.charge_positions,
                design.charge_values,
                design.carrier_radii(),
                design.field("electric"),
            )[0]
        )
    )
    assert data["limits"]["largest_surface_field_V_per_m"] == pytest.approx(top, rel=1e-12)
    assert "parts within their limits (recomputed from the elements)" in str(report)
    assert "theorem reproduced" in str(report) and "PASSED" not in str(report)


def test_a_body_beyond_its_limits_fails_the_check_and_the_cli(design, tmp_path, capsys):
    """Charges x100: the surface fields too, beyond the safe field of air (the frame body's
    carriers sit at a few % of it; the quantities then fail too; the report names both)."""
    path = tmp_path / "design.json"
    write_design(design, path)
    data = json.loads(path.read_text())
    data["charges"]["values"] = [100 * q for q in data["charges"]["values"]]
    path.write_text(json.dumps(data))
    report = check_design(read_design(path), n_orientations=60)
    assert report.parts_within_limits is False and not report.passed
    assert report.buildable is False and report.verdict["state"] == "NOT buildable"
    assert "parts_within_limits" in report.failures
    assert report.limits.violations and "surface field" in report.limits.violations[0]
    assert main(["check", str(path), "--orientations", "60", "--json"]) == 1
    printed = json.loads(capsys.readouterr().out)
    assert printed["parts_within_limits"] is False and printed["passed"] is False
    assert printed["verdict"]["state"] == "NOT buildable"
    assert printed["verdict_agrees"] is (design.verdict["state"] == "NOT buildable")


def test_point_elements_have_no_buildability(design):
    from chargedesign.body import Design

    points = Design(
        parameters=design.parameters,
        fields=design.fields,
        charge_positions=design.charge_positions,
        charge_values=design.charge_values,
        realises=[],
    )
    report = check_design(points, n_orientations=20)
    assert report.parts_within_limits is None and "limits" not in report.to_dict()
    assert report.buildable is None
    assert report.verdict["state"] == "not checked for buildability"
