"""[design] larmor = charges | frame: the default, what each reading designs, bad input."""

from __future__ import annotations

import tomllib
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from chargedesign.checker import check_design
from chargedesign.designer import design_from_scene
from chargedesign.designer.acceptance import body_check
from chargedesign.designer.options import DesignOptions
from chargedesign.errors import InputError
from chargedesign.scene import scene_from_dict

UNIT = Path(__file__).parents[2] / "examples" / "scenes" / "unit_scale.toml"


def unit(**design):
    data = tomllib.loads(UNIT.read_text())
    data["body"]["spacing"] = 0.34  # a coarse ball: fast
    data["design"].update(design)
    return scene_from_dict(data, "<unit>")


def test_the_mathematical_case_defaults_to_charges_and_is_unchanged():
    result = design_from_scene(unit())
    design = result.design
    assert design.larmor.reading == "charges" and design.larmor.rate == 0.7
    assert design.parameters.n == 0.7 and design.body_parameters == design.parameters
    assert "without [medium]" in design.larmor_why
    # the same body as the explicit charges reading
    again = design_from_scene(unit(larmor="charges")).design
    np.testing.assert_array_equal(design.charge_values, again.charge_values)
    assert check_design(design).passed
    # (p6): the second moments of charge carry n, xx = yy = zz / 3 = -C n / a1
    q, r = design.charge_values, design.charge_positions
    assert np.sum(q * r[:, 0] ** 2) == pytest.approx(-0.7, rel=1e-12)
    assert np.sum(q * r[:, 2] ** 2) == pytest.approx(-2.1, rel=1e-12)


def test_frame_realises_n_zero_and_reads_n_in_turning_axes():
    design = design_from_scene(unit(larmor="frame")).design
    assert design.larmor.reading == "frame" and design.larmor.rate == 0.7
    assert design.parameters.n == 0.7 and design.body_parameters.n == 0.0
    assert body_check(design).passed
    # against the theorem with n (the charges reading's claim) its mu misses
    claimed_n = check_design(replace(design, larmor=None))
    assert not claimed_n.passed and claimed_n.quantities["mu"].rel_err > 0.1
    # no second moments of charge for n: xx = zz = 0 (K's third moments remain)
    q, r = design.charge_values, design.charge_positions
    scale = np.sum(np.abs(q) * np.sum(r**2, axis=1))
    assert abs(np.sum(q * r[:, 0] ** 2)) < 1e-12 * scale
    assert abs(np.sum(q * r[:, 2] ** 2)) < 1e-12 * scale
    assert np.sum(q * r[:, 0] ** 2 * r[:, 2]) == pytest.approx(
        -1.0 * 0.5 * -0.4 / (6 * 0.5), rel=1e-10
    )


def test_unknown_larmor_is_one_line_naming_the_key():
    with pytest.raises(InputError, match=r"^design\.larmor: expected one of charges, frame"):
        design_from_scene(unit(larmor="rotating"))
    with pytest.raises(InputError, match=r"design\.larmor"):
        DesignOptions(larmor="Frame")


def test_frame_with_n_zero_is_a_note_not_an_error():
    data = tomllib.loads(UNIT.read_text())
    data["body"]["spacing"] = 0.34
    data["parameters"]["n"] = 0.0
    data["design"]["larmor"] = "frame"
    result = design_from_scene(scene_from_dict(data, "<unit n=0>"))
    notes = result.design.notes
    assert any("n = 0" in note and "same body" in note for note in notes)
    assert result.design.larmor.reading == "frame" and result.design.larmor.rate == 0.0
    assert body_check(result.design).passed
