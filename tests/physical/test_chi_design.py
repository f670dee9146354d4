"""Designing the induced magnetisation: ballast of opposite susceptibilities (issue 20, item 5).

The induced energy ``-chi v |B|^2 / (2 mu0)`` of the parts is linear in their volumes, like
gravity in the masses: the mass program's ballast stage makes its orientation-dependent part
vanish. Checked by routes independent of the design: the realism budget's own field
evaluation (:func:`field_response`, |B|^2 of the field at each part) and the chi-weighted
moments recomputed from the written parts; the freedom the theorem leaves (the sectoral part
along (c, d) only shifts kappa) is proven exactly with sympy from the package's model.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
import sympy as sp
from physical.test_buildable import scene_with

from chargedesign.body import Design
from chargedesign.constants import MU_0
from chargedesign.designer import design_from_scene
from chargedesign.designer.pipeline import physical_setup_from_scene
from chargedesign.errors import InputError
from chargedesign.model.case import (
    GAMMA,
    OMEGA,
    C,
    K,
    c,
    d,
    g1,
    g2,
    g3,
    kappa,
    lam,
    n,
    p,
    q,
    r,
    rho,
    symbolic_case,
)
from chargedesign.physical.bom import bom_rows
from chargedesign.physical.induced import induced_rows
from chargedesign.physical.limits import check_limits
from chargedesign.physical.materials import SUSCEPTIBILITY
from chargedesign.physical.realism import field_response, material_parts, typical_rate
from chargedesign.report import render_report
from chargedesign.schemas import validate

A1, A2 = 1.0, 10.0  # the small scene's field: T, T/m
CHI_BALLAST = {"ballast": {"material": ["tungsten", "bismuth"]}}


@pytest.fixture(scope="module")
def chi_design() -> Design:
    return design_from_scene(scene_with(**CHI_BALLAST), frontier=False).design


@pytest.fixture(scope="module")
def plain_design() -> Design:
    return design_from_scene(scene_with(), frontier=False).design


def designed_torque(design: Design) -> float:
    return design.parameters.C * typical_rate(design.parameters) ** 2 / 4.0


def gross_induced(design: Design) -> float:
    """sum |chi v| max_gamma |B|^2 / (2 mu0) over the parts (J): what cancels, part by part.

    ``|B|^2 <= a1^2 + 8 |a1 a2| |x| + 16 a2^2 |x|^2`` for a part at distance |x| from O.
    """
    total = 0.0
    for part in material_parts(design):
        rad = np.linalg.norm(part["centres"], axis=1)
        b2 = A1**2 + 8 * abs(A1 * A2) * rad + 16 * A2**2 * rad**2
        total += float(np.sum(abs(part["chi"]) * part["volumes"] * b2)) / (2 * MU_0)
    return total


def test_the_chi_designed_body_has_its_induced_range_at_round_off(chi_design, plain_design):
    """The induced energy's range over 2000 orientations (recomputed by field_response from
    the written parts) is within 1000 ulps of the gross energy that cancels; the same scene
    with tungsten alone leaves it 1e14 times the designed torques."""
    torque = designed_torque(chi_design)
    induced = field_response(chi_design)["induced_magnetisation_fraction"]["value"]
    gross = gross_induced(chi_design)
    assert gross / torque > 1e13  # the cancellation is a real one
    assert induced * torque <= 1e3 * np.finfo(float).eps * gross
    plain = field_response(plain_design)["induced_magnetisation_fraction"]["value"]
    assert plain > 1e13 and induced < 1e-13 * plain
    assert check_limits(chi_design).parts_within_limits


def test_the_chi_weighted_moments_of_the_written_parts_vanish(chi_design):
    """D = sum chi v x and the trace-free part of S = sum chi v x x^T, summed from the parts
    as the realism budget sees them (carriers, magnets, both ballast materials)."""
    rows = np.zeros(8)
    scale = np.zeros(8)
    for part in material_parts(chi_design):
        w = part["chi"] * part["volumes"]
        R = induced_rows((A1, 2 * A2), part["centres"])
        rows += R @ w
        scale += np.abs(R) @ np.abs(w)
    assert np.all(np.abs(rows) <= 1e-13 * scale.max())
    names = {part["name"] for part in material_parts(chi_design) if part["role"] == "ballast"}
    assert names == {"tungsten", "bismuth"}


def test_per_part_materials_round_trip_and_reach_the_bill_of_materials(chi_design):
    data = chi_design.to_dict()
    validate(json.loads(json.dumps(data)), "design")
    assert [m["name"] for m in data["materials"]["ballast"]] == ["tungsten", "bismuth"]
    assert len(data["masses"]["material"]) == len(data["masses"]["values"])
    again = Design.from_dict(data)
    assert again.mass_materials == chi_design.mass_materials
    rows = [row for row in bom_rows(again) if row["kind"] == "ballast"]
    assert [row["material"] for row in rows] == chi_design.mass_materials
    for row in rows:  # each part's volume from its own material's density
        rho = 19250.0 if row["material"] == "tungsten" else 9780.0
        assert row["size"] == pytest.approx(row["mass_kg"] / rho, rel=1e-15)


# ---------------------------------------------------------------- what the theorem allows
def _rates(V: sp.Expr) -> list[sp.Expr]:
    """(omega', gamma') of ``omega' I + omega x (omega I + mu) = gamma x dV/dgamma``."""
    case = symbolic_case()
    grad = sp.Matrix([sp.diff(V, x) for x in GAMMA])
    torque = GAMMA.cross(grad) - OMEGA.cross(case.inertia * OMEGA + case.mu)
    return [torque[i] / case.inertia[i, i] for i in range(3)] + list(GAMMA.cross(OMEGA))


def _dI4_dt(V: sp.Expr, I4: sp.Expr, values: dict) -> sp.Expr:
    """dI4/dt along the equations of potential V at a rational state on I3 = 0, |gamma| = 1."""
    case = symbolic_case()
    state = dict(values)
    state[r] = sp.solve(case.I3.subs(state), r)[0]
    rates = [e.subs(state) for e in _rates(V)]
    grad = [sp.diff(I4, x).subs(state) for x in (*OMEGA, *GAMMA)]
    return sp.nsimplify(sum(a * b for a, b in zip(grad, rates, strict=True)))


POINTS = [
    {
        g1: sp.Rational(2, 7),
        g2: sp.Rational(3, 7),
        g3: sp.Rational(6, 7),
        p: sp.Rational(1, 3),
        q: sp.Rational(-2, 5),
    },
    {
        g1: sp.Rational(-1, 3),
        g2: sp.Rational(2, 3),
        g3: sp.Rational(2, 3),
        p: sp.Rational(3, 4),
        q: sp.Rational(1, 6),
    },
]
PARAMS = {
    C: sp.Rational(3, 2),
    c: sp.Rational(1, 3),
    d: sp.Rational(-2, 5),
    n: sp.Rational(5, 7),
    K: sp.Rational(1, 2),
    kappa: sp.Rational(4, 9),
    lam: sp.Rational(1, 5),
    rho: sp.Rational(2, 11),
}


def test_the_sectoral_part_along_c_d_only_shifts_kappa():
    """Adding ``e (c (g1^2 - g2^2) + 2 d g1 g2)`` to V is kappa -> kappa + e / C identically
    (mu, the inertia and I3 hold no kappa), so I4 with the shifted kappa stays an integral:
    dI4/dt = 0 exactly at rational states of I3 = 0. The other sectoral term, the zonal
    gamma3^2 term, a gamma1 (D . gamma) and a gamma1 gamma3 (tesseral) term each make dI4/dt
    nonzero, for I4 with any
    kappa (dI4/dt is affine in kappa and has no common zero at the two states)."""
    case = symbolic_case()
    e = sp.Symbol("e")
    along = c * (g1**2 - g2**2) + 2 * d * g1 * g2
    assert sp.expand(case.V + e * along - case.V.subs(kappa, kappa + e / C)) == 0
    assert all(sp.diff(x, kappa) == 0 for x in (*case.mu, case.I3))
    eps = sp.Rational(3, 13)
    shifted = case.I4.subs(kappa, kappa + eps / C)
    for point in POINTS:
        values = {**PARAMS, **point}
        assert _dI4_dt((case.V + eps * along).subs(PARAMS), shifted.subs(PARAMS), values) == 0
        assert _dI4_dt(case.V.subs(PARAMS), case.I4.subs(PARAMS), values) == 0
    k = sp.Symbol("k")
    others = {
        "other sectoral": d * (g1**2 - g2**2) - 2 * c * g1 * g2,
        "zonal": g3**2,
        "D . gamma": g1,
        "tesseral": g1 * g3,
    }
    for name, term in others.items():
        V = (case.V + eps * term).subs(PARAMS)
        I4 = case.I4.subs({**{x: v for x, v in PARAMS.items() if x is not kappa}, kappa: k})
        rates = [_dI4_dt(V.subs(kappa, PARAMS[kappa]), I4, {**PARAMS, **pt}) for pt in POINTS]
        zeros = [set(sp.solve(x, k)) if x.has(k) else (set() if x != 0 else None) for x in rates]
        assert all(z is not None for z in zeros), name
        assert not set.intersection(*zeros), name


# ---------------------------------------------------------------- bad input
@pytest.mark.parametrize(
    ("ballast", "key", "words"),
    [
        ({"material": ["tungsten", "aluminium"]}, "ballast.material", "diamagnetic"),
        ({"material": ["tungsten", "unobtainium"]}, "ballast.material", "unobtainium"),
        ({"material": ["tungsten", "bismuth"], "density": 9000.0}, "ballast.density", "list"),
        ({"material": ["tungsten", "tungsten"]}, "ballast.material", "distinct"),
        ({"material": []}, "ballast.material", "list"),
    ],
)
def test_bad_ballast_lists_are_one_line_naming_the_key(ballast, key, words):
    with pytest.raises(InputError, match=key.replace(".", r"\.")) as info:
        physical_setup_from_scene(scene_with(ballast=ballast))
    assert "\n" not in str(info.value) and words in str(info.value)


def test_a_design_file_with_several_ballast_materials_names_each_part(chi_design):
    data = chi_design.to_dict()
    del data["masses"]["material"]
    with pytest.raises(InputError, match=r"masses\.material"):
        Design.from_dict(data)
    data["masses"]["material"] = ["lead"] * len(data["masses"]["values"])
    with pytest.raises(InputError, match=r"masses\.material"):
        Design.from_dict(data)


def test_a_custom_material_without_susceptibility_is_named():
    """The cancellation needs every part's chi: a custom carrier density has none."""
    scene = scene_with(**CHI_BALLAST, carriers={"density": 2500.0})
    with pytest.raises(InputError, match=r"carriers\.susceptibility") as info:
        design_from_scene(scene, frontier=False)
    assert "\n" not in str(info.value)


def test_bismuth_and_copper_are_diamagnetic_as_the_crc_molar_values_say():
    """chi_SI = 4 pi chi_mol rho / M (cgs chi_mol, cm^3/mol; rho g/cm^3; M g/mol)."""
    assert SUSCEPTIBILITY["bismuth"] == pytest.approx(
        4 * math.pi * -280.1e-6 * 9.78 / 208.98, rel=1e-3
    )
    assert SUSCEPTIBILITY["copper"] == pytest.approx(
        4 * math.pi * -5.46e-6 * 8.96 / 63.546, rel=5e-3
    )


def test_the_verdict_rests_on_the_measured_cancellation_and_names_the_chi_accuracy(
    chi_design: Design, plain_design: Design
) -> None:
    """A chi-designed body is judged by what its written parts measure, not by the law for
    undesigned matter; the report says how precisely chi must be known for the cancellation."""
    from chargedesign.physical.materials import SUSCEPTIBILITY_METROLOGY
    from chargedesign.physical.realism import RESPONSE_FRACTION, k_law

    law = k_law(chi_design)
    from chargedesign.physical.realism import CANCELLED

    assert law["cancelled_by_design"]
    # (this body is judged at its own K: the fixture locates no frontier)
    gross = law["ratio_without_cancellation"]
    assert law["ratio_measured"] == law["ratio_elements"] < CANCELLED * gross
    report = render_report(chi_design)
    expected = "negligible" if law["ratio_measured"] < RESPONSE_FRACTION else "NOT negligible"
    assert law["verdict"] == expected
    # the budget row shows the number its verdict rests on, not the undesigned matter's law
    assert law["value"] == law["ratio_measured"]
    (row,) = [x for x in report.splitlines() if x.startswith("| k_law_induced_ratio |")]
    assert row.startswith(f"| k_law_induced_ratio | {law['ratio_measured']:.3g} ")
    # the uncancelled figure counts every part's |chi|: above the signed mixture's law
    assert law["ratio_without_cancellation"] > law["ratio"] > 1e6
    assert law["chi_relative_needed"] == pytest.approx(
        RESPONSE_FRACTION / law["ratio_without_cancellation"], rel=1e-12
    )
    assert law["chi_relative_needed"] < SUSCEPTIBILITY_METROLOGY
    assert "cancelled by the design's chi-weighted moments" in report
    assert f"known to {law['chi_relative_needed']:.2g} relative" in report
    # one material only: no cancellation, the law and the elements agree on NOT negligible
    plain = k_law(plain_design)
    assert not plain["cancelled_by_design"] and plain["verdict"] == "NOT negligible"
    assert plain["ratio_measured"] == plain["ratio_elements"]
