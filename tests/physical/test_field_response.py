"""The applied field acting on the parts' materials: induced magnetisation and eddy currents.

Each figure is checked by a second route: the induced energy against its moment formula for
the paper's field, the eddy torque against a numerical least-dissipation current.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from physical.test_buildable import SMALL, scene_with

from chargedesign.body import Design
from chargedesign.constants import MU_0
from chargedesign.designer import design_from_scene
from chargedesign.designer.pipeline import physical_setup_from_scene
from chargedesign.errors import InputError
from chargedesign.formatting import PRECISE, fmt
from chargedesign.physical.limits import check_limits
from chargedesign.physical.materials import SUSCEPTIBILITY
from chargedesign.physical.realism import (
    FIELD_RESPONSE_KEYS,
    RESPONSE_ORIENTATIONS,
    field_response,
    material_parts,
    typical_rate,
)
from chargedesign.sampling import fibonacci_sphere
from chargedesign.scene import load_scene

A1, A2 = 1.0, 10.0  # T, T/m: Phi = a1 Z + a2 (3 Z^2 - R^2), legendre [a1, 2 a2]


def ballast_design(positions, masses, legendre=(A1, 2 * A2), **ballast) -> Design:
    """A design whose only parts are tungsten ballast spheres (no charges, no magnets)."""
    material = {"name": "tungsten", "density_kg_per_m3": 19250.0, **ballast}
    return Design.from_dict(
        {
            "format": "chargedesign.design/1",
            "parameters": {"C": 2e-5, "n": 2.45e-6, "K": 1.75e-6, "kappa": 1.1025e-11},
            "fields": {"magnetic": {"legendre": list(legendre)}},
            "masses": {"positions": np.asarray(positions).tolist(), "values": list(masses)},
            "realises": ["inertia"],
            "medium": {"name": "vacuum", "breakdown_V_per_m": 1e7, "safety": 0.5},
            "materials": {"ballast": material},
        }
    )


def designed_torque(design: Design) -> float:
    return design.parameters.C * typical_rate(design.parameters) ** 2 / 4.0


def test_induced_energy_matches_the_moment_formula_of_the_papers_field():
    """|B|^2 = a1^2 + 4 a2^2 |r|^2 + 8 a1 a2 (gamma . r) + 12 a2^2 (gamma . r)^2 for a part at r:
    the orientation-dependent energy is -(8 a1 a2 D . gamma + 12 a2^2 gamma^T S gamma) / (2 mu0)
    with D, S the chi-weighted first and second moments of the parts."""
    rng = np.random.default_rng(7)
    positions = rng.uniform(-0.04, 0.04, (9, 3))
    masses = rng.uniform(1e-4, 5e-3, 9)
    design = ballast_design(positions, masses)
    chi = SUSCEPTIBILITY["tungsten"]
    w = chi * masses / 19250.0
    D = w @ positions
    S = (positions * w[:, None]).T @ positions
    g = fibonacci_sphere(RESPONSE_ORIENTATIONS)
    energy = -(8 * A1 * A2 * g @ D + 12 * A2**2 * np.einsum("ki,ij,kj->k", g, S, g)) / (2 * MU_0)
    item = field_response(design)["induced_magnetisation_fraction"]
    assert item["value"] * designed_torque(design) == pytest.approx(np.ptp(energy), rel=1e-9)
    assert item["verdict"] == "NOT negligible"
    assert "ballast tungsten" in item["note"]


def test_centred_isotropic_parts_or_a_uniform_field_make_no_induced_torque():
    """Six equal spheres at +-d on the axes: D = 0 and S isotropic, so the energy is the same
    in every orientation; moved off centre, it is not. A uniform field never turns them."""
    d = 0.02
    axes = np.vstack([np.eye(3), -np.eye(3)]) * d
    lifted = axes + np.array([0.0, 0.0, 1e-3])
    balanced = ballast_design(axes, [1e-3] * 6)
    shifted = ballast_design(lifted, [1e-3] * 6)
    uniform = ballast_design(lifted, [1e-3] * 6, legendre=(A1,))
    value = {
        name: field_response(design)["induced_magnetisation_fraction"]["value"]
        for name, design in [("balanced", balanced), ("shifted", shifted), ("uniform", uniform)]
    }
    # the constant part, -chi v (a1^2 + 4 a2^2 d^2) / (2 mu0), cancels to rounding
    scale = 6 * SUSCEPTIBILITY["tungsten"] * 1e-3 / 19250.0 * (A1**2 + 4 * A2**2 * d**2)
    assert value["balanced"] * designed_torque(balanced) < 1e-14 * scale / (2 * MU_0)
    assert value["shifted"] > 1e6
    assert value["uniform"] * designed_torque(uniform) < 1e-14 * scale / (2 * MU_0)


def _least_dissipation_power(a: float, b: float, sigma: float, omega: float, B: float) -> float:
    """Ohmic power of the current a part carries turning at omega about z in B along x.

    The driving field is v x B = (omega z x r) x B; charges on the surfaces add -grad phi so
    that no current leaves the part. That current is the one of least dissipation among
    E' - grad phi, so phi is fitted by least squares over polynomials up to degree 3 on a
    tensor Gauss quadrature of the ball (or shell) b <= r <= a, exact for these degrees.
    """
    nr, nt, npsi = 12, 16, 32
    x, wr = np.polynomial.legendre.leggauss(nr)
    r = 0.5 * (a - b) * x + 0.5 * (a + b)
    wr = 0.5 * (a - b) * wr * r**2
    ct, wt = np.polynomial.legendre.leggauss(nt)
    psi = 2 * np.pi * np.arange(npsi) / npsi
    R, CT, PSI = np.meshgrid(r, ct, psi, indexing="ij")
    W = (wr[:, None, None] * wt[None, :, None] * np.full(npsi, 2 * np.pi / npsi)).ravel()
    ST = np.sqrt(1 - CT**2)
    pts = np.column_stack(
        [(R * ST * np.cos(PSI)).ravel(), (R * ST * np.sin(PSI)).ravel(), (R * CT).ravel()]
    )
    velocity = np.cross([0.0, 0.0, omega], pts)
    drive = np.cross(velocity, [B, 0.0, 0.0])
    exponents = [
        (i, j, k) for i in range(4) for j in range(4) for k in range(4) if 0 < i + j + k <= 3
    ]
    columns = []
    for i, j, k in exponents:
        grad = np.zeros_like(pts)
        X, Y, Z = pts.T
        if i:
            grad[:, 0] = i * X ** (i - 1) * Y**j * Z**k
        if j:
            grad[:, 1] = j * X**i * Y ** (j - 1) * Z**k
        if k:
            grad[:, 2] = k * X**i * Y**j * Z ** (k - 1)
        columns.append(grad)
    G = np.stack(columns, axis=-1)  # (points, 3, basis)
    sw = np.sqrt(W)[:, None]
    lhs = (G * sw[:, :, None]).reshape(-1, len(exponents))
    rhs = (drive * sw).reshape(-1)
    coef, *_ = np.linalg.lstsq(lhs, rhs, rcond=None)
    current = drive - G @ coef
    return float(sigma * np.sum(W * np.sum(current**2, axis=1)))


@pytest.mark.parametrize("inner", [0.0, 2.5e-3], ids=["solid sphere", "thick shell"])
def test_eddy_torque_matches_the_least_dissipation_current(inner):
    """One aluminium carrier at O in a uniform field: the budget's (2 pi/15) sigma omega B^2
    (a^5 - b^5) against the power of the numerically found current over omega."""
    a, B = 3.0e-3, 1.0
    wall = None if inner == 0.0 else a - inner
    carrier = {"name": "aluminium", "density_kg_per_m3": 2700.0}
    if wall is not None:
        carrier["shell_thickness_m"] = wall
    volume = 4 / 3 * np.pi * (a**3 - inner**3)
    design = Design.from_dict(
        {
            "format": "chargedesign.design/1",
            "parameters": {"C": 2e-5, "n": 2.45e-6},
            "fields": {"magnetic": {"legendre": [B]}},
            "charges": {
                "positions": [[0.0, 0.0, 0.0]],
                "values": [1e-12],
                "radii": [a],
                "masses": [2700.0 * volume],
            },
            "realises": ["mu"],
            "medium": {"name": "vacuum", "breakdown_V_per_m": 1e7, "safety": 0.5},
            "materials": {"carrier": carrier},
        }
    )
    sigma = design.materials["carrier"].get("conductivity_S_per_m", 3.77e7)
    omega = typical_rate(design.parameters)
    numeric = _least_dissipation_power(a, inner, sigma, omega, B) / omega
    item = field_response(design)["eddy_torque_fraction"]
    assert item["value"] * designed_torque(design) == pytest.approx(numeric, rel=1e-9)
    assert numeric == pytest.approx(2 * math.pi / 15 * sigma * omega * B**2 * (a**5 - inner**5))


def test_an_insulating_or_unknown_material_is_said_not_hidden():
    axes = np.vstack([np.eye(3), -np.eye(3)]) * 0.02 + np.array([0.0, 0.0, 1e-3])
    insulating = ballast_design(axes, [1e-3] * 6, conductivity_S_per_m=0.0)
    assert field_response(insulating)["eddy_torque_fraction"]["value"] == 0.0
    custom = Design.from_dict(
        {
            **ballast_design(axes, [1e-3] * 6).to_dict(),
            "materials": {"ballast": {"name": "custom", "density_kg_per_m3": 10000.0}},
        }
    )
    response = field_response(custom)
    for key in FIELD_RESPONSE_KEYS:
        assert response[key]["value"] == 0.0
        assert "not counted" in response[key]["note"] and "ballast custom" in response[key]["note"]


@pytest.fixture(scope="module")
def small_design() -> Design:
    return design_from_scene(load_scene(SMALL), frontier=False).design


def test_every_part_set_is_counted_with_its_material(small_design):
    """Carriers (hollow), magnets with attached ballast, and ballast: one set each."""
    design = small_design
    parts = material_parts(design)
    roles = [p["role"] for p in parts]
    assert roles[0] == "carrier" and "ballast" in roles
    carriers = parts[0]
    assert np.all(carriers["inner"] > 0) and np.all(carriers["inner"] < carriers["outer"])
    total = sum(float(np.sum(p["volumes"])) for p in parts)
    materials = design.materials
    expected = (
        float(np.sum(design.carrier_masses())) / materials["carrier"]["density_kg_per_m3"]
        + float(np.sum(design.magnet_volumes()))
        + float(np.sum(design.mass_values)) / materials["ballast"]["density_kg_per_m3"]
        + float(
            np.sum(
                design.magnet_masses()
                - materials["magnet"]["density_kg_per_m3"] * design.magnet_volumes()
            )
        )
        / materials["ballast"]["density_kg_per_m3"]
    )
    assert total == pytest.approx(expected, rel=1e-12)
    # the check recomputes the same figures from the written elements
    limits = check_limits(design)
    assert limits.field_response == field_response(design)
    assert set(FIELD_RESPONSE_KEYS) <= set(design.realism)
    # its text prints the eddy line; the induced magnetisation is check's one figure (the
    # window's item over the smallest realised term), never this energy under its name
    assert "eddy torque fraction" in str(limits)
    assert "induced magnetisation fraction" not in str(limits)


@pytest.mark.parametrize(
    ("table", "value", "key"),
    [
        ("ballast", {"susceptibility": -1.5}, "ballast.susceptibility"),
        ("carriers", {"conductivity": -1.0}, "carriers.conductivity"),
        ("magnets", {"susceptibility": "0.05"}, "magnets.susceptibility"),
    ],
)
def test_bad_material_response_names_the_key(table, value, key):
    with pytest.raises(InputError, match=key.replace(".", r"\.")):
        physical_setup_from_scene(scene_with(**{table: value}))


def test_a_scene_can_give_its_own_susceptibility_and_conductivity():
    setup = physical_setup_from_scene(
        scene_with(ballast={"material": "tungsten", "susceptibility": 1e-6, "conductivity": 0.0})
    )
    ballast = setup.spec.ballast.to_dict()
    assert ballast["volume_susceptibility"] == 1e-6 and ballast["conductivity_S_per_m"] == 0.0


def test_the_fractions_scale_with_the_rate_as_the_physics_says(small_design):
    """Same parts, the motion s times faster (n, K x s; kappa x s^2): the induced energy is
    unchanged and the eddy torque grows like s while the designed torques grow like s^2, so
    the fractions fall like 1/s^2 and 1/s. The notes name no rate beyond the frontier."""

    def faster(design: Design, s: float) -> Design:
        data = design.to_dict()
        p = data["parameters"]
        for key in ("n", "K"):
            p[key] *= s
        for key in ("kappa", "lambda", "rho"):
            p[key] *= s * s
        return Design.from_dict(data)

    base = field_response(small_design)
    induced = base["induced_magnetisation_fraction"]
    eddy = base["eddy_torque_fraction"]
    scaled = field_response(faster(small_design, 10.0))
    assert scaled["induced_magnetisation_fraction"]["value"] == pytest.approx(
        induced["value"] / 100, rel=1e-12
    )
    assert scaled["eddy_torque_fraction"]["value"] == pytest.approx(eddy["value"] / 10, rel=1e-12)
    for item in (induced, eddy):
        assert "n above" not in item["note"]


def test_the_frontier_reports_the_field_response_of_its_own_body():
    from chargedesign.designer.assembly import build_design, design_at_rate
    from chargedesign.designer.frontier import find_frontier

    setup = physical_setup_from_scene(load_scene(SMALL))
    frontier = find_frontier(setup)
    body = build_design(setup, design_at_rate(setup, frontier.s_max))
    assert frontier.field_response == field_response(body)
    assert frontier.to_dict()["field_response"] == frontier.field_response
    # the text names the body whose response it prints and what each figure is relative to
    text = str(frontier)
    assert f"the body designed at s_max = {fmt(frontier.s_max, PRECISE)}, its" in text
    assert "of its designed torques at its typical rate" in text
