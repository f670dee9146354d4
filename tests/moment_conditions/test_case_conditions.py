"""The conditions engine opened to a case's polynomial V and mu (derive_case_conditions).

Independent routes: the theorem entered as a case file gives exactly the theorem's own
conditions; each catalogue case that cannot be realised is refused in one line naming the
term; the charges' mu and V recomputed from a designed body's elements element by element
give the case's Euler-Poisson torque (tests/designer/test_case_elements.py)."""

from __future__ import annotations

import tomllib
from pathlib import Path

import pytest

import chargedesign
from chargedesign.errors import InfeasibleError
from chargedesign.moment_conditions import derive_conditions
from chargedesign.moment_conditions.case import case_target, derive_case_conditions
from chargedesign.params import Parameters
from chargedesign.scene.case_file import case_from_table, read_case

CASES = Path(chargedesign.__file__).parent / "data" / "cases"


def _theorem_table(**overrides: float) -> dict:
    table = tomllib.loads((CASES / "yehia_elmandouh.toml").read_text("utf-8"))["case"]
    table["parameters"] = dict(table["parameters"], **{"lambda": 0, "rho": 0}, **overrides)
    return table


def _exact_rows(conditions) -> list:
    return sorted(
        (c.source, tuple(sorted(c.exact_coefficients.items())), c.exact_value)
        for c in conditions.conditions
    )


@pytest.mark.parametrize("overrides", [{}, {"c": 0.2, "d": 0.5, "n": -1.3, "K": 2, "kappa": -0.4}])
def test_the_theorem_as_a_case_gives_the_theorems_conditions_exactly(overrides: dict) -> None:
    table = _theorem_table(**overrides)
    p = table["parameters"]
    params = Parameters(C=p["C"], c=p["c"], d=p["d"], n=p["n"], K=p["K"], kappa=p["kappa"])
    theorem = derive_conditions(params, exact=True, length=0.5)
    case = derive_case_conditions(case_from_table(table), length=0.5)
    assert case.fields == theorem.fields
    assert _exact_rows(case) == _exact_rows(theorem)
    assert len(case.conditions) > 30  # mu, the three degrees of V and the inertia


def test_a_case_projection_is_exact_on_the_sphere() -> None:
    """Each harmonic coefficient times its harmonic, summed, is V again on |gamma| = 1."""
    import sympy as sp

    from chargedesign.model.case import GAMMA
    from chargedesign.moment_conditions.harmonics import real_solid_harmonics

    table = {
        "name": "quartic",
        "inertia": [2, 2, 1],
        "V": "gamma1**4 - 3*gamma2*gamma3**2 + gamma1*gamma2 + 2*gamma3",
        "integral": "r",
    }
    case = case_from_table(table)
    target = case_target(case)
    total = sp.Integer(0)
    for k in range(target.v_degree + 1):
        for h in real_solid_harmonics(k):
            value = target.v.get(h.label, 0)
            poly = sum(
                sp.Rational(c.numerator, c.denominator)
                * GAMMA[0] ** a
                * GAMMA[1] ** b
                * GAMMA[2] ** e
                for (a, b, e), c in h.poly.items()
            )
            total += sp.Rational(value.numerator, value.denominator) * poly
    difference = sp.expand((total - case.V).subs(GAMMA[2] ** 2, 1 - GAMMA[0] ** 2 - GAMMA[1] ** 2))
    difference = sp.expand(difference.subs(GAMMA[2] ** 2, 1 - GAMMA[0] ** 2 - GAMMA[1] ** 2))
    # a constant (degree 0) is dropped from V on purpose; the rest must vanish
    assert difference.free_symbols == set()


@pytest.mark.parametrize(
    ("file", "reason"),
    [
        ("goriachev.toml", "singular term"),
        ("joukovsky.toml", "gyrostat's rotor"),
        ("yehia_gyrostat.toml", "gyrostat's rotor"),
        ("yehia_elmandouh.toml", "singular term"),
    ],
)
def test_what_no_field_realises_is_refused_in_one_line(file: str, reason: str) -> None:
    with pytest.raises(InfeasibleError) as info:
        derive_case_conditions(read_case(CASES / file))
    assert reason in str(info.value) and "\n" not in str(info.value)


def test_a_degree_above_the_bound_is_refused_naming_the_term() -> None:
    table = {"name": "quintic", "inertia": [2, 2, 1], "V": "gamma1**5", "integral": "r"}
    with pytest.raises(InfeasibleError, match="gamma1\\*\\*5 of degree 5"):
        derive_case_conditions(case_from_table(table))


def test_masses_cases_give_the_masses_conditions() -> None:
    """Kowalevski: first moments a / g and the inertia's second moments; Clebsch: the gradient
    -eps/3 that the masses' route (case_masses) derives."""
    from chargedesign.designer.case_masses import mass_conditions

    for file in ("kowalevski.toml", "clebsch.toml", "lagrange.toml"):
        case = read_case(CASES / file)
        general = derive_case_conditions(case)
        masses = mass_conditions(case)
        assert general.fields["gravity"] == pytest.approx(masses.fields["gravity"], rel=1e-15)
        fixed, expected = general.fixed_moments("masses"), masses.fixed_moments("masses")
        for key, value in expected.items():
            assert fixed.get(key, 0.0) == pytest.approx(value, rel=1e-15, abs=1e-300)
        assert not general.for_source("charges")


def test_steklov_lyapunov_mu_needs_charges_in_a_uniform_field() -> None:
    """mu = (2K - tr K) gamma for l = K gamma: the charges' second moments are mu's matrix
    over a1 (derived a1 = 1 T)."""
    case = read_case(CASES / "steklov_lyapunov.toml")
    conditions = derive_case_conditions(case)
    assert conditions.fields["magnetic"][0] == 1.0
    fixed = conditions.fixed_moments("charges")
    # mu = (-4/15 g1, 2/5 g2, 4/5 g3) = a1 sum q (r . gamma) r: I_xx = -4/15, ...
    assert fixed["xx"] == pytest.approx(-4 / 15, rel=1e-15)
    assert fixed["yy"] == pytest.approx(2 / 5, rel=1e-15)
    assert fixed["zz"] == pytest.approx(4 / 5, rel=1e-15)
    assert fixed["xy"] == fixed["xz"] == fixed["yz"] == 0.0


def test_the_conditions_command_prints_a_case_scenes_conditions(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``chargedesign conditions`` of a Steklov-Lyapunov scene: the charges' second moments
    (JSON), the derived magnetic field, and a quadratic V without a magnetic quadrupole given
    is refused naming the degree (the charges' quadrupole, fixed by mu, does not give it)."""
    import json

    from chargedesign.cli import main

    scene = tmp_path / "steklov.toml"
    body = '\n[body]\nshape = "ball"\nradius = 0.5\nspacing = 0.125\n'
    scene.write_text((CASES / "steklov_lyapunov.toml").read_text("utf-8") + body, "utf-8")
    assert main(["conditions", str(scene), "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["charges"]["xx"] == pytest.approx(-4 / 15, rel=1e-15)
    assert data["fields"]["magnetic"] == {"legendre": [1.0, 1.0], "origin": "derived"}
    assert data["dipoles"]  # V's quadratic part: dipoles in the quadrupole
    uniform = scene.read_text("utf-8") + "\n[fields.magnetic]\nlegendre = [1.0]\n"
    scene.write_text(uniform, "utf-8")
    assert main(["conditions", str(scene)]) == 2
    error = capsys.readouterr().err.strip()
    assert "V degree 2" in error and "\n" not in error
