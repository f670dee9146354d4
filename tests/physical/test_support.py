"""The support the K = 0 body needs (a fixed point O with every attitude free): the testbed's
full-sphere air bearing, recorded in design.json and the report with its air film's drag."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from chargedesign.designer import design_from_scene
from chargedesign.physical.drag import AIR_VISCOSITY
from chargedesign.physical.realism import typical_rate
from chargedesign.physical.state_of_the_art import BEARINGS, FULL_SPHERE
from chargedesign.physical.window import REALISED_FRACTION, support_of, window_model
from chargedesign.report import render_report
from chargedesign.scene import load_scene
from chargedesign.scene.testbed import TestbedOptions

CHAPLYGIN = Path(__file__).resolve().parents[2] / "examples" / "scenes" / "chaplygin_magnetic.toml"


def test_its_drag_is_the_couette_shear_of_the_cup_film():
    """Independent route: the film's shear stress eta omega R sin(theta) / h over the cup
    (polar angle 0 to its half-angle, from the coverage in state_of_the_art), integrated by
    Gauss-Legendre quadrature: torque = int (eta omega R sin / h) (R sin) R^2 sin dtheta dphi."""
    radius, rate, term = 0.05, 16.0, 1.3e-3
    support = support_of(radius, rate, term)
    gap = TestbedOptions().bearing_gap_m
    half_angle = math.acos(1.0 - FULL_SPHERE["cup_coverage_sr"].value / (2.0 * math.pi))
    x, w = np.polynomial.legendre.leggauss(40)
    theta = half_angle * (x + 1) / 2
    shear = AIR_VISCOSITY * rate * radius * np.sin(theta) / gap
    torque = 2 * math.pi * half_angle / 2 * np.sum(w * shear * radius**3 * np.sin(theta) ** 2)
    assert support["drag_torque_N_m"] == pytest.approx(torque, rel=1e-12)
    assert support["drag_over_term"] == pytest.approx(torque / term, rel=1e-12)
    assert support["bearing"] == "full_sphere"
    assert support["tilt_limit_deg"] == BEARINGS["full_sphere"].tilt_limit_deg == 180.0
    assert support["in_window"] is False


def test_the_k0_example_records_its_support_and_the_report_states_it():
    design = design_from_scene(load_scene(CHAPLYGIN)).design
    written = design.frontier["realised"]["support"]
    model = window_model(design, 1.0)
    assert written == model.support
    region = design.buildability["region_radius_m"]
    assert written["ball_radius_m"] == region
    rate = typical_rate(design.parameters)
    assert written["drag_torque_N_m"] == pytest.approx(written["drag_N_m_s"] * rate, rel=1e-14)
    # the film's drag is far above the fraction for this 5 cm body at 2.5 turns a second
    assert written["drag_over_term"] / REALISED_FRACTION > 100
    text = render_report(design)
    assert "- Support: a full_sphere air bearing" in text
    assert "NOT counted in the verdict" in text
