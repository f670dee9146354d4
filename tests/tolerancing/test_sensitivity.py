"""Exact first-order sensitivity: the derivatives against central finite differences."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from chargedesign.body import read_design
from chargedesign.sensitivity import QUANTITIES, jacobians, sensitivity_weights
from chargedesign.tolerancing import ErrorModel, parse_spread, tolerance_report

DESIGN = Path(__file__).parent / "data" / "default_design.json"


@pytest.fixture(scope="module")
def design():
    return read_design(DESIGN)


def _quantities(design, gammas):
    """mu, centred V and inertia of a design by an independent route: the simulation's
    direct terms (space axes, rotated bodies) for V, the contract's formula for mu."""
    from chargedesign.fields import AxisymmetricField
    from chargedesign.simulation.system import attitude_from_gamma

    R = np.array([attitude_from_gamma(g) for g in gammas])
    fm = AxisymmetricField(design.field("magnetic"))
    fe = AxisymmetricField(design.field("electric"))
    fg = AxisymmetricField(design.field("gravity"))
    mu = np.zeros((len(gammas), 3))
    V = np.zeros(len(gammas))
    for k, Rk in enumerate(R):
        X = design.charge_positions @ Rk.T
        B_body = -(fm.gradient(X) @ Rk)  # R^T B
        mu[k] = -np.einsum(
            "n,n,ni->i",
            design.charge_values,
            np.einsum("ni,ni->n", design.charge_positions, B_body),
            design.charge_positions,
        )
        V[k] = design.charge_values @ fe.potential(X)
        V[k] += design.mass_values @ fg.potential(design.mass_positions @ Rk.T)
        Xd = design.dipole_positions @ Rk.T
        sig = design.dipole_moments @ Rk.T
        V[k] += np.einsum("ki,ki->", sig, fm.gradient(Xd))
    r, m = design.mass_positions, design.mass_values
    inertia = np.eye(3) * (m @ np.einsum("ij,ij->i", r, r)) - np.einsum("n,ni,nj->ij", m, r, r)
    return {"mu": mu, "V": V - V.mean(), "inertia": inertia.reshape(1, 9)}


def _shifted(design, kind, index, what, axis, h):
    from chargedesign.body import Design

    arrays = {
        "charge_positions": design.charge_positions.copy(),
        "charge_values": design.charge_values.copy(),
        "dipole_positions": design.dipole_positions.copy(),
        "dipole_moments": design.dipole_moments.copy(),
        "mass_positions": design.mass_positions.copy(),
        "mass_values": design.mass_values.copy(),
    }
    name = {
        ("charge", "position"): "charge_positions",
        ("charge", "value"): "charge_values",
        ("dipole", "position"): "dipole_positions",
        ("dipole", "value"): "dipole_moments",
        ("mass", "position"): "mass_positions",
        ("mass", "value"): "mass_values",
    }[(kind, what)]
    a = arrays[name]
    if a.ndim == 1:
        a[index] += h
    else:
        a[index, axis] += h
    return Design(parameters=design.parameters, fields=dict(design.fields), **arrays)


@pytest.mark.parametrize("what", ["position", "value"])
def test_derivatives_match_finite_differences(design, what):
    from chargedesign.checker import sample_orientations

    gammas = sample_orientations(12, 3)
    jac = jacobians(design, gammas)
    picks = [0, 7, 25, 27, len(jac.labels) - 1]  # charges, dipoles, a mass
    h = 1e-5
    for j in picks:
        kind, index = jac.labels[j]
        width = 3 if (what == "position" or kind == "dipole") else 1
        for axis in range(width):
            plus = _quantities(_shifted(design, kind, index, what, axis, h), gammas)
            minus = _quantities(_shifted(design, kind, index, what, axis, -h), gammas)
            block = jac.position if what == "position" else jac.value
            for q in QUANTITIES:
                fd = (plus[q] - minus[q]).reshape(-1) / (2 * h)
                exact = block[q][j][..., axis].reshape(-1)
                scale = max(np.abs(exact).max(), np.abs(fd).max(), 1e-12)
                assert np.abs(fd - exact).max() <= 1e-6 * scale, (kind, index, what, axis, q)


def test_report_orders_elements_and_is_json_ready(design):
    report = tolerance_report(design, 1e-4, n_orientations=100)
    tols = [e["position_tol_m_min"] for e in report.elements]
    assert tols == sorted(tols)
    assert len(report.elements) == design.n_elements
    data = json.loads(json.dumps(report.to_dict(), allow_nan=False))
    head = data["headline"]
    assert head.startswith(report.elements[0]["element"] + " dominates: place it within ±")
    assert "below 1e-04" in head
    assert max(report.nominal.values()) < 1e-9  # the design realises the theorem


def test_displacement_by_the_tolerance_keeps_the_error_below_target(design):
    from chargedesign.tolerancing import error_distribution

    target = 1e-6
    report = tolerance_report(design, target, n_orientations=100)
    top = report.elements[0]
    # move only the dominant element, by its tolerance in random directions
    rng = np.random.default_rng(1)
    kind, index = top["kind"], top["index"]
    worst = 0.0
    for _ in range(20):
        d = rng.standard_normal(3)
        d *= top["position_tol_m_min"] / np.linalg.norm(d)
        moved = design
        for axis in range(3):
            moved = _shifted(moved, kind, index, "position", axis, d[axis])
        out = error_distribution(moved, ErrorModel(), 1, n_orientations=100)
        worst = max(worst, out[top["binding"]]["monte_carlo"][0])
    assert worst <= target * 1.01
    assert worst >= target * 0.2  # the bound is not loose by orders of magnitude


def test_robust_weights_agree_with_the_report(design):
    report = tolerance_report(design, 1e-4, n_orientations=100)
    c = sensitivity_weights(
        design.charge_positions, "charges", design.fields, design.parameters, n_orientations=100
    )
    for e in report.elements:
        if e["kind"] == "charge":
            q = abs(design.charge_values[e["index"]])
            assert c[e["index"]] * q == pytest.approx(1e-4 / e["position_tol_m_min"], rel=1e-9)
    cd = sensitivity_weights(design.dipole_positions, "dipoles", design.fields, design.parameters)
    assert cd.shape == (len(design.dipole_moments),) and np.all(cd > 0)


def test_spread_syntax():
    assert parse_spread("20um", "--position", True).value == pytest.approx(2e-5)
    assert parse_spread("20 µm", "--position", True).value == pytest.approx(2e-5)
    assert parse_spread("0.02mm", "--position", True).value == pytest.approx(2e-5)
    s = parse_spread("1%", "--charge")
    assert s.relative and s.value == pytest.approx(0.01)
    assert parse_spread("1e-6", "--charge").value == 1e-6
    from chargedesign.errors import InputError

    for bad in ("5 furlong", "-1um", "abc", "1 mm"):
        with pytest.raises(InputError, match="--"):
            parse_spread(bad, "--charge" if bad == "1 mm" else "--position", bad != "1 mm")
