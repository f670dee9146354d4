"""Bodies of masses for the catalogue's heavy tops (designer/case_masses.py): the inertia and
the potential recomputed here from the designed masses, by plain sums."""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp

from chargedesign.candidates import ball_points
from chargedesign.constants import STANDARD_GRAVITY
from chargedesign.designer.case_masses import design_case_masses, mass_conditions
from chargedesign.errors import InfeasibleError, InputError
from chargedesign.model.case import GAMMA
from chargedesign.model.case_file import case_from_table
from chargedesign.model.catalogue import catalogue_case, entry_table

TIGHT = 1e-12


def _recomputed(positions: np.ndarray, masses: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    inertia = np.zeros((3, 3))
    for x, m in zip(positions, masses, strict=True):
        inertia += m * (np.dot(x, x) * np.eye(3) - np.outer(x, x))
    return inertia, STANDARD_GRAVITY * (masses[:, None] * positions).sum(axis=0)


@pytest.mark.parametrize("name", ["kowalevski", "lagrange", "goriachev-chaplygin"])
def test_a_heavy_top_becomes_masses_with_its_inertia_and_potential(name: str) -> None:
    case = catalogue_case(name)
    body = design_case_masses(case, ball_points(1.0, 0.25))
    assert np.all(body.masses > 0)
    inertia, linear = _recomputed(body.positions, body.masses)
    target = np.diag([float(m) for m in case.inertia])
    scale = float(np.max(target))
    assert np.max(np.abs(inertia - target)) <= TIGHT * scale  # products zero too
    # the body's V = g sum m (x . gamma) equals the case's V (up to its constant) exactly at
    # random points of the sphere
    rng = np.random.default_rng(7)
    for gamma in rng.normal(size=(5, 3)):
        gamma /= np.linalg.norm(gamma)
        case_v = float(case.V.xreplace(dict(zip(GAMMA, gamma, strict=True))))
        v_zero = float(case.V.xreplace(dict.fromkeys(GAMMA, 0)))
        assert linear @ gamma + v_zero == pytest.approx(case_v, rel=TIGHT, abs=TIGHT * scale)


def test_kowalevski_masses_centre_of_mass_on_the_first_axis() -> None:
    case = catalogue_case("kowalevski")
    body = design_case_masses(case, ball_points(1.0, 0.25))
    C, a = float(case.parameters["C"]), float(case.parameters["a"])
    centre = (body.masses[:, None] * body.positions).sum(axis=0) / body.masses.sum()
    assert STANDARD_GRAVITY * body.masses.sum() * centre[0] == pytest.approx(C * a, rel=TIGHT)
    assert abs(centre[1]) <= TIGHT and abs(centre[2]) <= TIGHT


@pytest.mark.parametrize(
    ("entry", "reason"),
    [
        ("yehia_gyrostat.toml", "l is not zero"),
        ("goriachev.toml", "singular"),
        ("clebsch.toml", "degree 2"),
    ],
)
def test_cases_masses_cannot_realise_are_refused_in_one_line(entry: str, reason: str) -> None:
    case = case_from_table(entry_table({"file": entry}))
    with pytest.raises(InputError) as exc:
        mass_conditions(case)
    assert "\n" not in str(exc.value) and reason in str(exc.value)


def test_an_inertia_no_masses_have_is_infeasible() -> None:
    table = entry_table({"file": "euler.toml", "parameters": {"A1": 3, "A2": 1, "A3": 1}})
    with pytest.raises(InfeasibleError, match="triangle inequality"):
        mass_conditions(case_from_table(table))


def test_the_conditions_are_exact_fractions_of_the_case() -> None:
    case = catalogue_case("kowalevski")
    conditions = mass_conditions(case, g=2.0)
    fixed = conditions.fixed_moments("masses")
    C, a = case.parameters["C"], case.parameters["a"]
    assert fixed["x"] == float(C * a / 2) and fixed["y"] == 0.0 and fixed["z"] == 0.0
    assert fixed["xx"] == fixed["yy"] == float(C / 2) and fixed["zz"] == float(3 * C / 2)
    assert sp.Rational(str(fixed["zz"])) == 3 * C / 2
