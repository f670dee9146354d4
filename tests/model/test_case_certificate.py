"""The exact certificate of any case (model/case_file.py), checked by independent routes:
counterexamples re-evaluated by plain sympy differentiation, the theorem entered as a case
file against the hand-built model, and claims that must fail."""

from __future__ import annotations

from typing import Any

import pytest
import sympy as sp

from chargedesign.errors import InputError
from chargedesign.model.case import GAMMA, OMEGA, symbolic_case
from chargedesign.model.case_file import case_equations, certify_case
from chargedesign.model.catalogue import catalogue_case, entry_table
from chargedesign.model.certificate import certify
from chargedesign.model.equations import equations_of_motion, euler_poisson
from chargedesign.scene.case_file import Case, case_from_table, read_case

STATE = (*OMEGA, *GAMMA)

KOWALEVSKI: dict[str, Any] = {
    "name": "kowalevski",
    "inertia": [2.0, 2.0, 1.0],
    "V": "g*gamma1",
    "l": ["0", "0", "0"],
    "integral": "(p**2 - q**2 - g*gamma1)**2 + (2*p*q - g*gamma2)**2",
    "level": "general",
    "parameters": {"g": 1.0},
}


def _derivative_by_sympy(case: Case, values: dict[sp.Symbol, Any]) -> sp.Rational:
    """dF/dt at a state by plain sympy: the chain rule on the case's (ep) right-hand sides."""
    rhs = case_equations(case)
    total = sum(sp.diff(case.integral, x) * rhs[i] for i, x in enumerate(STATE))
    return sp.Rational(total.xreplace(values))


def _state(certificate_state: dict[str, str]) -> dict[sp.Symbol, Any]:
    by_name = {str(s): s for s in STATE}
    return {by_name[k]: sp.Rational(v) for k, v in certificate_state.items()}


def test_kowalevski_holds_and_is_independent() -> None:
    result = certify_case(case_from_table(KOWALEVSKI))
    assert result.holds and result.independent and result.counterexample is None
    assert all(result.checks.values())
    data = result.to_dict()["case"]
    assert {"name", "holds", "level", "independent", "counterexample"} <= set(data)
    assert data["level"] == "general"


def test_a_false_claim_gives_an_exact_counterexample_that_sympy_confirms() -> None:
    wrong = dict(KOWALEVSKI, integral="(p**2 - q**2 + g*gamma1)**2 + (2*p*q - g*gamma2)**2")
    case = case_from_table(wrong)
    result = certify_case(case)
    assert not result.holds and not result.checks["F_conserved"]
    ce = result.counterexample
    assert ce is not None
    values = _state(ce["state"])
    assert sum(values[x] ** 2 for x in GAMMA) == 1  # exactly on the sphere
    assert ce["gamma_norm_squared"] == "1"
    value = _derivative_by_sympy(case, values)
    assert value != 0 and value == sp.Rational(ce["dF_dt"])
    assert ce["dF_dt_float"] == pytest.approx(float(value), rel=1e-15)


def test_a_conditional_claim_on_the_wrong_level_fails_on_that_level() -> None:
    table = entry_table({"file": "goriachev_chaplygin.toml"})
    assert certify_case(case_from_table(table)).holds
    wrong = dict(table, level="1/3")
    case = case_from_table(wrong)
    result = certify_case(case)
    assert not result.holds
    ce = result.counterexample
    assert ce is not None and sp.Rational(ce["I3"]) == sp.Rational(1, 3)
    values = _state(ce["state"])
    assert sp.Rational(case.I3.xreplace(values)) == sp.Rational(1, 3)
    assert _derivative_by_sympy(case, values) == sp.Rational(ce["dF_dt"]) != 0
    assert result.to_dict()["case"]["level"] == pytest.approx(1 / 3)


@pytest.mark.parametrize(
    "integral", ["p**2 + q**2 + r**2/2 + g*gamma1", "(2*p*gamma1 + 2*q*gamma2 + r*gamma3)**2"]
)
def test_a_conserved_function_of_the_known_integrals_is_not_independent(integral: str) -> None:
    """H (here with inertia 2, 2, 1) and I3^2 are conserved: the claim holds, rank < 4."""
    result = certify_case(case_from_table(dict(KOWALEVSKI, integral=integral)))
    assert result.holds and not result.independent
    assert result.checks["independent"] is False


def test_the_equations_conserve_h_and_i3_for_a_rational_case() -> None:
    result = certify_case(case_from_table(entry_table({"file": "goriachev.toml"})))
    assert result.checks["H_conserved"] and result.checks["I3_conserved"]
    assert result.checks["witness"]
    assert "gamma3 = 0" in result.singular


def test_the_theorems_lambda_and_another_name_give_the_same_case() -> None:
    """The theorem's file names lambda as [parameters] does (a keyword, read under an alias);
    renamed lam, the case is the same."""
    table = entry_table({"file": "yehia_elmandouh.toml"})
    renamed = dict(table)
    renamed["V"] = table["V"].replace("lambda/", "lam/")
    renamed["integral"] = table["integral"].replace("lambda*", "lam*")
    parameters = dict(table["parameters"])
    parameters["lam"] = parameters.pop("lambda")
    renamed["parameters"] = parameters
    assert "lambda" not in renamed["V"] + renamed["integral"]
    case, original = case_from_table(renamed), case_from_table(table)
    assert sp.expand(sp.together(case.V - original.V)) == 0
    assert sp.expand(sp.together(case.integral - original.integral)) == 0
    assert certify_case(case).holds


def test_mu_given_instead_of_l() -> None:
    """Joukovsky's gyrostat with mu = k (a constant l gives mu = l by (mu))."""
    table = entry_table({"file": "joukovsky.toml"})
    with_mu = {k: v for k, v in table.items() if k != "l"}
    with_mu["mu"] = table["l"]
    case = case_from_table(with_mu)
    by_l = case_from_table(table)
    assert sp.simplify(case.mu - by_l.mu) == sp.zeros(3, 1)
    assert sp.expand(case.I3 - by_l.I3) == 0
    result = certify_case(case)
    assert result.holds and result.independent


# ------------------------------------------- the theorem as a case file against the model

PARAMETER_SETS = [
    {"C": 1.5, "c": 0.3, "d": -0.4, "n": 0.7, "K": 0.5, "kappa": 0.9, "lambda": 0.1, "rho": 0.2},
    {"C": "2/3", "c": -1.25, "d": 2, "n": -0.3, "K": 1.5, "kappa": -0.4, "lambda": 0, "rho": 0.05},
]


def _theorem_table(parameters: dict[str, Any]) -> dict[str, Any]:
    return entry_table({"file": "yehia_elmandouh.toml", "parameters": parameters})


def _model_values(parameters: dict[str, Any]) -> dict[sp.Symbol, sp.Rational]:
    model = symbolic_case()
    symbols = {str(s): s for s in model.V.free_symbols | model.I4.free_symbols}
    return {symbols[k]: sp.Rational(str(v)) for k, v in parameters.items()}


@pytest.mark.parametrize("parameters", PARAMETER_SETS)
def test_the_theorem_as_a_case_file_has_the_models_equations(parameters: dict[str, Any]) -> None:
    case = case_from_table(_theorem_table(parameters))
    values = _model_values(parameters)
    model_rhs = equations_of_motion().xreplace(values)
    difference = (case_equations(case) - model_rhs).applyfunc(lambda e: sp.expand(sp.together(e)))
    assert difference == sp.zeros(6, 1)
    model = symbolic_case()
    assert sp.expand(sp.together(case.integral - model.I4.xreplace(values))) == 0
    assert sp.expand(case.I3 - model.I3.xreplace(values)) == 0


@pytest.mark.parametrize("parameters", PARAMETER_SETS)
def test_the_theorem_as_a_case_file_gives_the_models_certificate(
    parameters: dict[str, Any],
) -> None:
    result = certify_case(case_from_table(_theorem_table(parameters)))
    model = certify("general")
    assert result.holds == model.holds is True
    assert result.independent == model.checks["I4_independent"] is True
    # with every non-zero parameter free, the case file's certificate is the model's symbolic
    # one (parameter set 1 has lambda = 0: the model's case with lambda zeroed holds too)
    assert result.holds_for_all_parameters is True
    assert result.checks["witness_for_all_parameters"]


@pytest.mark.parametrize(
    ("entry", "model_case"), [("chaplygin", "chaplygin"), ("yehia2003", "yehia2003")]
)
def test_the_theorems_limits_hold_for_all_parameters_as_in_the_model(
    entry: str, model_case: str
) -> None:
    result = certify_case(catalogue_case(entry))
    assert result.holds_for_all_parameters is certify(model_case).holds is True


def test_a_claim_true_only_at_the_files_values_is_not_true_for_all_parameters() -> None:
    """Clebsch's V written with its own numbers j_i = eps A_i: true at these values, false with
    the j_i free (Clebsch's condition ties them to the inertia)."""
    table = entry_table({"file": "clebsch.toml"})
    eps, moments = sp.Rational(2, 5), (3, 2, 1)
    table["V"] = "j1/2*gamma1**2 + j2/2*gamma2**2 + j3/2*gamma3**2"
    table["parameters"] = dict(table["parameters"])
    table["parameters"].update({f"j{i + 1}": str(eps * m) for i, m in enumerate(moments)})
    result = certify_case(case_from_table(table))
    assert result.holds and result.independent
    assert result.holds_for_all_parameters is False
    assert "only at these values" in str(result)


def test_a_case_without_parameters_has_no_all_parameters_verdict() -> None:
    table = dict(KOWALEVSKI, V="gamma1", integral=KOWALEVSKI["integral"].replace("g*", ""))
    table.pop("parameters")
    result = certify_case(case_from_table(table))
    assert result.holds and result.holds_for_all_parameters is None


@pytest.mark.parametrize("parameters", PARAMETER_SETS)
def test_off_the_zero_level_the_case_file_and_the_model_agree_on_df_dt(
    parameters: dict[str, Any],
) -> None:
    """On I3 = 1 the claim fails; dI4/dt at the counterexample equals the model's value there
    (the model's own derived equations, :func:`euler_poisson` on its V and mu)."""
    case = case_from_table(dict(_theorem_table(parameters), level=1))
    result = certify_case(case)
    assert not result.holds
    ce = result.counterexample
    assert ce is not None
    values = _state(ce["state"]) | _model_values(parameters)
    model = symbolic_case()
    rhs = euler_poisson(model.inertia, model.V, model.mu)
    d_i4 = sum(sp.diff(model.I4, x) * rhs[i] for i, x in enumerate(STATE))
    assert sp.Rational(d_i4.xreplace(values)) == sp.Rational(ce["dF_dt"]) != 0
    assert sp.Rational(model.I3.xreplace(values)) == 1


# --------------------------------------------------------------------- one-line refusals


@pytest.mark.parametrize(
    ("change", "named"),
    [
        ({"inertia": [2.0, -2.0, 1.0]}, "case.inertia[1]: expected a moment of inertia > 0"),
        ({"inertia": [2.0, 2.0]}, "case.inertia: expected a list"),
        ({"V": "p*gamma1"}, "case.V: depends on p"),
        ({"l": ["0", "0"]}, "case.l: expected a list of 3"),
        ({"mu": ["0", "0", "0"]}, "case: give l or mu, not both"),
        ({"level": "high"}, "case.level: the name `high`"),
        ({"level": ""}, "case.level"),
        ({"integral": "1/(gamma1**2 + gamma2**2 + gamma3**2 - 1)"}, "vanishes on the whole sphere"),
        ({"parameters": {"None": 1.0}}, "case.parameters.None: 'None' is a Python constant"),
        ({"parameters": {"g": "p"}}, "case.parameters.g"),
        ({"parameters": {"g": float("nan")}}, "case.parameters.g"),
        ({"colour": "red"}, "case.colour"),
        ({"name": ""}, "case.name"),
    ],
)
def test_a_bad_case_table_is_refused_in_one_line(change: dict[str, Any], named: str) -> None:
    with pytest.raises(InputError) as exc:
        case_from_table(dict(KOWALEVSKI, **change))
    assert "\n" not in str(exc.value) and named in str(exc.value)


def test_a_mu_of_no_mu_form_and_a_conditional_mu_are_refused() -> None:
    table = {k: v for k, v in KOWALEVSKI.items() if k != "l"}
    with pytest.raises(InputError, match="not of the form"):
        case_from_table(dict(table, mu=["gamma2", "0", "0"]))
    with pytest.raises(InputError, match="needs l"):
        case_from_table(dict(table, mu=["0", "0", "0"], level=0))


def test_read_case_refuses_a_file_without_case_or_with_parameters(tmp_path: Any) -> None:
    plain = tmp_path / "scene.toml"
    plain.write_text("[parameters]\nC = 1.0\n")
    with pytest.raises(InputError, match=r"no \[case\] table"):
        read_case(plain)
    both = tmp_path / "both.toml"
    both.write_text('[parameters]\nC = 1.0\n[case]\nname = "x"\n')
    with pytest.raises(InputError, match="together"):
        read_case(both)


@pytest.mark.parametrize(
    "change",
    [
        {"inertia": ["a", 1, 1]},
        {"inertia": [True, 1, 1]},
        {"inertia": [[1], 1, 1]},
        {"l": [1, 2, {"x": 1}]},
        {"l": "0"},
        {"V": 3},
        {"V": ["gamma1"]},
        {"integral": None},
        {"level": [0]},
        {"level": True},
        {"parameters": {"g": [1]}},
        {"parameters": {"g": {"x": 1}}},
        {"parameters": ["g"]},
        {"parameters": {"g": 1e40}},
        {"parameters": {f"x{i}": 1 for i in range(40)}},
        {"source": 3},
        {"name": 7},
    ],
)
def test_wrong_types_in_a_case_table_are_one_line_errors(change: dict[str, Any]) -> None:
    with pytest.raises(InputError) as exc:
        case_from_table(dict(KOWALEVSKI, **change))
    assert "\n" not in str(exc.value) and str(exc.value).startswith("case")


def test_a_claim_too_large_to_certify_is_refused_before_the_work() -> None:
    """Whitelisted but huge: the theorem's I4 times (1 + p + q + r)^2 (about 76 s of work)."""
    table = entry_table({"file": "yehia_elmandouh.toml"})
    table["integral"] = f"({table['integral']})*(1 + p + q + r)**2"
    with pytest.raises(InputError) as exc:
        certify_case(case_from_table(table))
    assert "\n" not in str(exc.value) and "work on integral is estimated" in str(exc.value)
    huge_v = dict(KOWALEVSKI, V="(gamma1 + gamma2 + gamma3 + 1)**12")
    with pytest.raises(InputError, match=r"work( on H)? is estimated"):  # by its expansion first
        certify_case(case_from_table(huge_v))
    with_mu = {k: v for k, v in KOWALEVSKI.items() if k != "l"}
    with pytest.raises(InputError, match="give l instead"):
        case_from_table(dict(with_mu, mu=["gamma1**9", "0", "0"]))
