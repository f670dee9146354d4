"""The frontier scan: the law it fits is measured, not assumed, and it states only what it
measured (no size extrapolation). The real scan takes minutes (bench / `frontier --scan`);
here its plumbing runs on a stand-in frontier with a known law, and the fit on exact data."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pytest

from chargedesign.designer import frontier_scan
from chargedesign.designer.frontier_scan import ELEMENTARY_CHARGE, fit_power_law, scan_frontier
from chargedesign.physical.materials import BREAKDOWN_V_PER_M, CARRIER_DENSITY
from chargedesign.scene import load_scene

SMALL = Path(__file__).parent / "small.toml"


@dataclass
class _Binding:
    stage: str = "charges"

    def text(self, medium: str) -> str:
        return "stand-in"


@dataclass
class _Front:
    s_max: float
    K_max: float
    n_max: float | None
    larmor: str
    smallest_charge: float
    binding: _Binding = field(default_factory=_Binding)
    seconds: float = 0.0
    field_response: dict = field(default_factory=dict)


def _law_frontier(exponents):
    """A frontier following K_max = E^e a2^b L^l rho^r exactly, read off each variant scene."""

    def fake(scene, **_):
        E = scene.tables["medium"]["name"]
        a2 = scene.fields["magnetic"][1] / 2
        L = scene.tables["body"]["radius"] / 0.05
        rho = CARRIER_DENSITY[scene.tables.get("carriers", {}).get("material", "aluminium")]
        k = (
            BREAKDOWN_V_PER_M[E] ** exponents["E"]
            * a2 ** exponents["field"]
            * L ** exponents["L"]
            * rho ** exponents["rho"]
        )
        return _Front(1.0, k, None, "frame", 3 * ELEMENTARY_CHARGE)

    return fake


def test_the_scan_measures_the_law_of_its_frontiers(monkeypatch):
    law = {"E": 1.0, "field": 1.0, "L": 0.0, "rho": -1.0}
    monkeypatch.setattr(frontier_scan, "frontier_from_scene", _law_frontier(law))
    scan = scan_frontier(load_scene(SMALL))  # small.toml has [medium]: the frame reading
    assert scan.larmor == "frame" and scan.target == "K_max" and scan.field_name == "a2"
    assert len(scan.rows) == 11 and not scan.failures
    for key, value in law.items():
        assert scan.exponents[key] == pytest.approx(value, abs=1e-9)
    assert scan.rms_fit_error < 1e-12 and scan.worst_fit_error < 1e-12
    # the field case varies a2 (half the scene's 10 T/m), the sizes scale the body
    assert {r["a2"] for r in scan.rows} == {10.0, 5.0}
    assert {r["size_factor"] for r in scan.rows} == {0.5, 1.0, 2.0}
    text = str(scan)
    assert "K_max ~ E_breakdown^1 a2^1 L^" in text and "fit residual: rms" in text
    assert "negligible" not in text and "extrapolated along" not in text
    assert all(r["smallest_carrier_charge_e"] == pytest.approx(3.0) for r in scan.rows)


def test_the_scan_reports_a_law_that_is_not_the_expected_one(monkeypatch):
    """A frontier that falls with size gives its own exponent, not the expected 0."""
    law = {"E": 1.0, "field": 0.5, "L": -1.0, "rho": -1.0}
    monkeypatch.setattr(frontier_scan, "frontier_from_scene", _law_frontier(law))
    scan = scan_frontier(load_scene(SMALL))
    assert scan.exponents["L"] == pytest.approx(-1.0, abs=1e-9)
    assert scan.exponents["field"] == pytest.approx(0.5, abs=1e-9)
    assert scan.expected["L"] == 0.0


def test_the_fit_residual_measures_scatter():
    rng = np.random.default_rng(1)
    rows = []
    for E in (1e6, 3e6, 1e7):
        for f in (0.5, 1.0, 2.0):
            rows.append(
                {
                    "breakdown_V_per_m": E,
                    "a2": 10.0,
                    "size_factor": f,
                    "carrier_density": 2700.0,
                    "K_max": 1e-12 * E * math.exp(0.01 * rng.standard_normal()),
                }
            )
    rows.append({**rows[0], "a2": 5.0, "K_max": rows[0]["K_max"] / 2})
    rows.append({**rows[0], "carrier_density": 8960.0, "K_max": rows[0]["K_max"] * 2700 / 8960})
    exponents, worst, rms = fit_power_law(rows, "K_max", "a2")
    assert exponents["E"] == pytest.approx(1.0, abs=0.02)
    assert 0.001 < rms < 0.02 and worst < 0.05


def test_the_response_laws_stay_within_the_measured_sizes():
    rows = [
        {
            "case": "size",
            "medium": "air",
            "size_factor": f,
            "induced_magnetisation_fraction": 1e9 * f**2,
            "eddy_torque_fraction": 1e6 * f,
        }
        for f in (0.5, 1.0, 2.0)
    ]
    laws = frontier_scan.response_laws(rows)
    assert laws["induced_magnetisation_fraction"]["size_exponent"] == pytest.approx(2.0)
    assert laws["eddy_torque_fraction"]["measured_size_factors"] == [0.5, 2.0]
    assert all("negligible_below_size_factor" not in law for law in laws.values())
