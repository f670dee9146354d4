"""The theorem as a case of (ep): the catalogue's entry built from its parameters.

Independent routes: the theorem's own conditions engine (``derive_conditions``) and the
general case engine (``derive_case_conditions``) on ``theorem_case(p)`` give the same rows.
They differ in two places only, both stated here: the float reading (the theorem reads each
parameter's binary value, a case its decimal text: the values differ in the last bits), and
a case whose mu is zero (n = K = 0), where the theorem keeps its charges' homogeneous mu
rows (every moment zero: no charges) and the case engine does not ask for charges at all.
"""

from __future__ import annotations

import math

import pytest
import sympy as sp

from chargedesign.model.catalogue import theorem_case, theorem_parameters
from chargedesign.moment_conditions import derive_conditions
from chargedesign.moment_conditions.case import derive_case_conditions
from chargedesign.params import Parameters
from chargedesign.scene.case_file import case_from_table

SETS = [
    (Parameters(C=1.0, c=0.3, d=-0.4, n=0.7, K=0.5, kappa=0.9), {"magnetic": (1.0, 1.0)}, 1.0),
    (
        Parameters(C=1.0, c=0.3, d=-0.4, n=0.7, K=0.5, kappa=0.9),
        {"magnetic": (1.0, 1.0), "gravity": (9.81,)},
        1.0,
    ),
    (Parameters(C=1.5, c=0.2, d=0.5, n=-1.3, K=2.0, kappa=-0.4), None, 0.5),
    (
        Parameters(C=2.0e-5, c=0.3, d=-0.4, n=0.4, K=0.0, kappa=64.0),
        {"magnetic": (1.0, 0.06)},
        0.05,
    ),
]


def _rows(conditions) -> list:
    return sorted(
        (c.source, tuple(sorted(c.coefficients.items())), c.value) for c in conditions.conditions
    )


@pytest.mark.parametrize(("params", "fields", "length"), SETS)
def test_the_theorems_case_gives_its_conditions_row_for_row(params, fields, length) -> None:
    theorem = derive_conditions(params, fields, length=length)
    case = derive_case_conditions(theorem_case(params), fields, length=length)
    a, b = _rows(theorem), _rows(case)
    assert len(a) == len(b) > 20
    assert [row[:2] for row in a] == [row[:2] for row in b]
    scale = max(abs(row[2]) for row in a)
    for (_, _, x), (_, _, y) in zip(a, b, strict=True):
        # the binary value of a float against its decimal text: the last bits only
        assert math.isclose(x, y, rel_tol=1e-15, abs_tol=4e-16 * scale)
    assert case.realise == theorem.realise
    assert case.field_origin == theorem.field_origin
    for kind, coeffs in theorem.fields.items():
        assert case.fields[kind] == pytest.approx(coeffs, rel=1e-15, abs=1e-16)
    # read as decimals by both, the rows are the same exactly
    exact = derive_conditions(params, fields, exact=True, length=length)
    assert _rows(exact) == b


def test_a_zero_mu_drops_the_theorems_homogeneous_charge_rows() -> None:
    """n = K = 0: mu = 0. The theorem keeps 10 charges' rows (every third moment zero), the
    case engine none; the other rows are the same, and so is the body (no charges)."""
    params = Parameters(C=2.0e-5, c=0.3, d=-0.4, n=0.0, K=0.0, kappa=64.0)
    fields = {"magnetic": (0.0, 0.06)}
    theorem = derive_conditions(params, fields, exact=True, length=0.05)
    case = derive_case_conditions(theorem_case(params), fields, length=0.05)
    charges = [row for row in _rows(theorem) if row[0] == "charges"]
    assert charges and all(row[2] == 0.0 for row in charges)
    assert [row for row in _rows(theorem) if row[0] != "charges"] == _rows(case)
    assert theorem.realise == ("mu", "V", "inertia")
    assert case.realise == ("V", "inertia")


@pytest.mark.parametrize(("params", "fields", "length"), SETS)
def test_the_theorems_parameters_are_read_back(params, fields, length) -> None:
    assert theorem_parameters(theorem_case(params)) == params


def test_a_hand_written_theorem_case_is_read_with_the_papers_normalisation() -> None:
    """Written as plain numbers, V and l fix K (c, d) and kappa (c, d): the reading takes
    c^2 + d^2 = 1/4 (the paper's c = 0.3, d = -0.4) and K >= 0."""
    given = Parameters(C=1.0, c=0.6, d=-0.8, n=0.7, K=0.25, kappa=0.45)
    case = theorem_case(given)
    table = {
        "name": "by hand",
        "inertia": [2, 2, 1],
        "V": sp.sstr(case.V),
        "l": [sp.sstr(x) for x in case.l],
        "integral": "r",
    }
    read = theorem_parameters(case_from_table(table))
    assert read == Parameters(C=1.0, c=0.3, d=-0.4, n=0.7, K=0.5, kappa=0.9)


@pytest.mark.parametrize(
    "table",
    [
        {"name": "kowalevski", "inertia": [2, 2, 1], "V": "gamma1", "integral": "r"},
        {"name": "lagrange", "inertia": [2, 2, 1], "V": "gamma3", "integral": "r"},
        {"name": "other inertia", "inertia": [3, 2, 1], "V": "gamma1*gamma2", "integral": "r"},
        {
            "name": "quartic off the form",
            "inertia": [2, 2, 1],
            "V": "gamma1**4",
            "integral": "r",
        },
    ],
)
def test_other_cases_are_not_the_theorems(table) -> None:
    assert theorem_parameters(case_from_table(table)) is None
