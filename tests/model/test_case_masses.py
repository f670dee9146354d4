"""Bodies of masses for the catalogue's heavy tops (the conditions of designer/case_masses.py,
designed by the one design program): the inertia and the potential recomputed here from the
designed masses, by plain sums."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pytest
import sympy as sp
from scipy.integrate import solve_ivp

from chargedesign.candidates import ball_points
from chargedesign.constants import STANDARD_GRAVITY
from chargedesign.designer.case_masses import gradient_strength, mass_conditions
from chargedesign.designer.pipeline import design_body
from chargedesign.errors import InfeasibleError, InputError
from chargedesign.fields import zonal_sums
from chargedesign.model.case import GAMMA, OMEGA
from chargedesign.model.catalogue import catalogue_case, entry_table
from chargedesign.params import Parameters
from chargedesign.scene.case_file import Case, case_from_table

TIGHT = 1e-12


@dataclass
class MassBody:
    positions: np.ndarray
    masses: np.ndarray
    gravity: tuple[float, ...]


def design_case_masses(case: Case, points: np.ndarray) -> MassBody:
    """The case's masses in gravity on ``points`` by the one design program."""
    conditions = mass_conditions(case)
    params = Parameters(C=float(case.inertia[2]))
    design = design_body(params, conditions, points, forward=False).design
    return MassBody(design.mass_positions, design.mass_values, design.fields["gravity"])


def _inertia(positions: np.ndarray, masses: np.ndarray) -> np.ndarray:
    inertia = np.zeros((3, 3))
    for x, m in zip(positions, masses, strict=True):
        inertia += m * (np.dot(x, x) * np.eye(3) - np.outer(x, x))
    return inertia


def _body_potential(body: MassBody, gamma: np.ndarray) -> float:
    """sum m Phi_g(x) with the project's field evaluator (Z = x . gamma, S = |x|^2)."""
    Z = body.positions @ gamma
    S = np.einsum("ij,ij->i", body.positions, body.positions)
    phi = zonal_sums(np.asarray(body.gravity), Z, S, 0)[""]
    return float(body.masses @ phi)


@pytest.mark.parametrize("name", ["kowalevski", "lagrange", "goriachev-chaplygin", "clebsch"])
def test_a_case_becomes_masses_with_its_inertia_and_potential(name: str) -> None:
    case = catalogue_case(name)
    body = design_case_masses(case, ball_points(1.0, 0.25))
    assert np.all(body.masses > 0)
    target = np.diag([float(m) for m in case.inertia])
    scale = float(np.max(target))
    assert np.max(np.abs(_inertia(body.positions, body.masses) - target)) <= TIGHT * scale
    # the body's V in its gravity field equals the case's V up to one constant on the sphere
    rng = np.random.default_rng(7)
    differences = []
    for gamma in rng.normal(size=(6, 3)):
        gamma /= np.linalg.norm(gamma)
        case_v = float(case.V.xreplace(dict(zip(GAMMA, gamma, strict=True))))
        differences.append(_body_potential(body, gamma) - case_v)
    assert np.ptp(differences) <= TIGHT * scale * max(1.0, *map(abs, body.gravity))


def test_clebsch_is_a_body_in_a_gravity_gradient() -> None:
    """V = eps/2 (A1 g1^2 + A2 g2^2 + A3 g3^2) with the inertia's own second moments needs
    f2 = -eps/3 and no uniform part."""
    case = catalogue_case("clebsch")
    assert gradient_strength(case) == -case.parameters["eps"] / 3
    assert design_case_masses(case, ball_points(1.0, 0.25)).gravity[0] == 0.0


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
        ("steklov_lyapunov.toml", "l is not zero"),
    ],
)
def test_cases_masses_cannot_realise_are_refused_in_one_line(entry: str, reason: str) -> None:
    case = case_from_table(entry_table({"file": entry}))
    with pytest.raises(InputError) as exc:
        mass_conditions(case)
    assert "\n" not in str(exc.value) and reason in str(exc.value)


def test_a_quadratic_v_that_is_not_the_inertias_is_refused() -> None:
    """Chaplygin's V (the theorem's limit) is quadratic but not the inertia's second moments."""
    with pytest.raises(InputError, match="not the inertia's second moments"):
        mass_conditions(catalogue_case("chaplygin"))
    table = entry_table({"file": "kowalevski.toml"}) | {"V": "gamma1**3"}
    with pytest.raises(InputError, match="degree 3"):
        mass_conditions(case_from_table(table))


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


@pytest.mark.parametrize("name", ["kowalevski", "clebsch"])
def test_the_designed_masses_move_with_the_cases_integral(name: str) -> None:
    """Element-level route: the torque from each designed mass in its gravity field
    (gamma x sum m Phi_Z(x . gamma) x), the inertia summed from the masses, integrated by
    DOP853; the case's own F (from its case file) stays constant."""
    case = catalogue_case(name)
    body = design_case_masses(case, ball_points(1.0, 0.25))
    inertia = _inertia(body.positions, body.masses)
    f = np.zeros(2)
    f[: len(body.gravity)] = body.gravity

    def rhs(_: float, y: np.ndarray) -> np.ndarray:
        omega, gamma = y[:3], y[3:]
        Z = body.positions @ gamma
        gradient = (body.masses * (f[0] + 3 * f[1] * Z)) @ body.positions
        torque = np.cross(gamma, gradient)
        omega_dot = np.linalg.solve(inertia, torque - np.cross(omega, inertia @ omega))
        return np.concatenate([omega_dot, np.cross(gamma, omega)])

    integral = sp.lambdify([*OMEGA, *GAMMA], case.integral, "numpy")
    start = np.array([0.3, -0.2, 0.5, 0.6, 0.0, 0.8])
    run = solve_ivp(
        rhs, (0.0, 20.0), start, method="DOP853", rtol=1e-12, atol=1e-12, dense_output=True
    )
    assert run.success
    values = np.array([integral(*run.sol(t)) for t in np.linspace(0.0, 20.0, 41)])
    assert np.ptp(values) <= 1e-9 * max(1.0, abs(values[0]))
    # the motion is not trivial: gamma moves
    assert np.ptp(run.y[3]) > 0.1
