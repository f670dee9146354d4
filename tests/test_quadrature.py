"""Quadrature of continuous bodies: exactness at the stated degree (against closed-form
integrals of monomials), sharpness of that degree, geometric convergence beyond it, the
density and body formats, and validation."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
import sympy as sp

from chargedesign.body import Design, read_design, write_design
from chargedesign.errors import InputError
from chargedesign.moments import monomial_matrix
from chargedesign.params import Parameters
from chargedesign.quadrature import (
    ContinuousBody,
    Density,
    geometric_rule,
    quadrature_points,
    required_order,
    rule_sizes,
)

ONE = Density("uniform", 1.0)


# --------------------------------------------------------- closed-form monomial integrals
def _sphere_monomial(i: int, j: int, k: int) -> float:
    """int over the unit sphere of u^i v^w w^k dS (zero unless all even)."""
    if i % 2 or j % 2 or k % 2:
        return 0.0
    a, b, c = (i + 1) / 2, (j + 1) / 2, (k + 1) / 2
    return 2.0 * math.gamma(a) * math.gamma(b) * math.gamma(c) / math.gamma(a + b + c)


def _disk_monomial(i: int, j: int) -> float:
    """int over the unit disk of s^i t^j dA."""
    if i % 2 or j % 2:
        return 0.0
    a, b = (i + 1) / 2, (j + 1) / 2
    return 2.0 * math.gamma(a) * math.gamma(b) / math.gamma(a + b) / (i + j + 2)


def _segment(a: int, lo: float, hi: float) -> float:
    return (hi ** (a + 1) - lo ** (a + 1)) / (a + 1)


def _binomial_terms(a: int, c: float, rho: float) -> list[tuple[int, float]]:
    """(c + rho u)^a = sum_i coef_i u^i."""
    return [(i, math.comb(a, i) * c ** (a - i) * rho**i) for i in range(a + 1)]


def exact_monomial(body: ContinuousBody, exps: tuple[int, int, int]) -> float:
    """int over the body of x^a y^b z^c (body coordinates), unit density, closed form."""
    a, b, c = exps
    cx, cy, cz = body.center
    if body.shape == "box":
        hx, hy, hz = body.half_size
        return (
            _segment(a, cx - hx, cx + hx)
            * _segment(b, cy - hy, cy + hy)
            * _segment(c, cz - hz, cz + hz)
        )
    rho = float(body.radius)
    if body.shape in ("ball", "shell"):
        total = 0.0
        for (i, ci), (j, cj), (k, ck) in itertools.product(
            _binomial_terms(a, cx, rho), _binomial_terms(b, cy, rho), _binomial_terms(c, cz, rho)
        ):
            s = _sphere_monomial(i, j, k)
            if body.shape == "ball":
                total += ci * cj * ck * s * rho**3 / (i + j + k + 3)
            else:
                total += ci * cj * ck * s * rho**2
        return total
    h = float(body.height)
    disk = sum(
        ci * cj * _disk_monomial(i, j) * rho**2
        for (i, ci), (j, cj) in itertools.product(
            _binomial_terms(a, cx, rho), _binomial_terms(b, cy, rho)
        )
    )
    return disk * _segment(c, cz - h / 2, cz + h / 2)


def monomials_up_to(d: int) -> list[tuple[int, int, int]]:
    return [(a, b, c) for a in range(d + 1) for b in range(d + 1 - a) for c in range(d + 1 - a - b)]


def _key(exps: tuple[int, int, int]) -> str:
    return "x" * exps[0] + "y" * exps[1] + "z" * exps[2]


BODIES = {
    "box": ContinuousBody("charge", "box", [0.1, -0.2, 0.3], ONE, half_size=[0.5, 0.7, 0.4]),
    "ball": ContinuousBody("charge", "ball", [0.2, 0.1, -0.3], ONE, radius=0.6),
    "shell": ContinuousBody("charge", "shell", [-0.1, 0.25, 0.2], ONE, radius=0.8),
    "cylinder": ContinuousBody("mass", "cylinder", [0.15, -0.1, 0.05], ONE, radius=0.5, height=1.3),
}


# ------------------------------------------------------------------------------- tests
def test_closed_forms_agree_with_sympy() -> None:
    """The closed forms used below against sympy's integration (ball, cylinder, shell)."""
    r, th, ph, z = sp.symbols("r theta phi z", nonnegative=True)
    x_s = r * sp.sin(th) * sp.cos(ph)
    y_s = r * sp.sin(th) * sp.sin(ph)
    z_s = r * sp.cos(th)
    ball = ContinuousBody("charge", "ball", [0.0, 0.0, 0.0], ONE, radius=1.0)
    shell = ContinuousBody("charge", "shell", [0.0, 0.0, 0.0], ONE, radius=1.0)
    for exps in [(2, 0, 0), (2, 2, 0), (0, 0, 4), (2, 2, 2)]:
        f = x_s ** exps[0] * y_s ** exps[1] * z_s ** exps[2]
        on_sphere = sp.integrate(f.subs(r, 1) * sp.sin(th), (ph, 0, 2 * sp.pi), (th, 0, sp.pi))
        in_ball = sp.integrate(on_sphere * r ** (sum(exps) + 2), (r, 0, 1))
        assert float(on_sphere) == pytest.approx(exact_monomial(shell, exps), rel=1e-14)
        assert float(in_ball) == pytest.approx(exact_monomial(ball, exps), rel=1e-14)
    cyl = ContinuousBody("mass", "cylinder", [0.0, 0.0, 0.0], ONE, radius=1.0, height=2.0)
    f = (r * sp.cos(ph)) ** 2 * (r * sp.sin(ph)) ** 2 * z**2 * r
    value = sp.integrate(f, (ph, 0, 2 * sp.pi), (r, 0, 1), (z, -1, 1))
    assert float(value) == pytest.approx(exact_monomial(cyl, (2, 2, 2)), rel=1e-14)


@pytest.mark.parametrize("shape", list(BODIES))
@pytest.mark.parametrize("order", [0, 1, 2, 3, 4, 5, 6, 8])
def test_exact_for_every_monomial_up_to_the_stated_degree(shape: str, order: int) -> None:
    body = BODIES[shape]
    pts, w = geometric_rule(body, order)
    exps_list = monomials_up_to(order)
    values = monomial_matrix(pts, [_key(e) for e in exps_list]) @ w
    for exps, value in zip(exps_list, values, strict=True):
        exact = exact_monomial(body, exps)
        # absolute scale: the integral of |monomial| is at most measure * (max |coordinate|)^deg
        scale = body.measure * (np.abs(body.center).max() + body.extent) ** sum(exps)
        assert abs(value - exact) <= 2e-14 * scale, (shape, order, exps, value, exact)


@pytest.mark.parametrize("shape", list(BODIES))
@pytest.mark.parametrize("order", [1, 2, 3, 4, 6])
def test_stated_degree_is_sharp(shape: str, order: int) -> None:
    """z^e with e the first even power above ``order`` is not integrated exactly."""
    body = ContinuousBody.from_dict({**BODIES[shape].to_dict(), "center": [0.0, 0.0, 0.0]})
    e = order + 1 if order % 2 else order + 2
    pts, w = geometric_rule(body, order)
    value = w @ pts[:, 2] ** e
    exact = exact_monomial(body, (0, 0, e))
    assert abs(value - exact) > 1e-6 * abs(exact)


def test_node_counts_match_rule_sizes_and_weights_sum_to_measure() -> None:
    for shape, body in BODIES.items():
        for order in (0, 3, 7):
            pts, w = geometric_rule(body, order)
            assert len(pts) == len(w) == math.prod(rule_sizes(shape, order).values())
            assert np.all(w > 0)
            assert w.sum() == pytest.approx(body.measure, rel=1e-14)


def test_geometric_convergence_beyond_the_degree() -> None:
    """Analytic integrand exp(x) on the unit ball: the error drops by more than 100x per
    four degrees (Gauss rules converge geometrically), down to rounding."""
    ball = ContinuousBody("mass", "ball", [0.0, 0.0, 0.0], ONE, radius=1.0)
    exact = 4.0 * math.pi / math.e
    errors = []
    for order in (3, 7, 11):
        pts, w = geometric_rule(ball, order)
        errors.append(abs(w @ np.exp(pts[:, 0]) - exact) / exact)
    assert errors[0] > 1e-6
    assert errors[1] < errors[0] / 100 and errors[2] < errors[1] / 100
    pts, w = geometric_rule(ball, 21)
    assert abs(w @ np.exp(pts[:, 0]) - exact) / exact < 1e-14


def _exps(key: str) -> tuple[int, int, int]:
    return (key.count("x"), key.count("y"), key.count("z"))


def _plus(a: tuple[int, int, int], b: tuple[int, int, int]) -> tuple[int, int, int]:
    return (a[0] + b[0], a[1] + b[1], a[2] + b[2])


def test_polynomial_density_moments_are_exact_at_the_required_order() -> None:
    """Density 0.5 + 2 x z - 3 y^2 on a box: its moments up to order 3, quadrature at
    ``required_order(body, 3)`` against the closed forms."""
    coeffs = {"": 0.5, "xz": 2.0, "yy": -3.0}
    density = Density("polynomial", coefficients=coeffs)
    body = ContinuousBody("charge", "box", [0.1, 0.2, -0.1], density, half_size=[0.3, 0.4, 0.5])
    order = required_order(body, 3)
    assert order == 5

    def exact(exps: tuple[int, int, int]) -> float:
        return sum(c * exact_monomial(body, _plus(_exps(k), exps)) for k, c in coeffs.items())

    pts, q = quadrature_points(body, order)
    for exps in monomials_up_to(3):
        value = monomial_matrix(pts, [_key(exps)])[0] @ q
        assert value == pytest.approx(exact(exps), rel=1e-13, abs=1e-15)
    # two degrees less is not exact for the highest moments
    pts, q = quadrature_points(body, order - 2)
    value = monomial_matrix(pts, ["yyyz"])[0] @ q
    assert abs(value - exact((0, 3, 1))) > 1e-9 * abs(exact((0, 3, 1)))


def test_density_evaluation_and_degree() -> None:
    d = Density("polynomial", coefficients={"": 1.0, "xxz": 2.0, "y": -1.0})
    pts = np.array([[1.0, 2.0, 3.0], [0.5, -1.0, 0.0]])
    expected = 1.0 + 2.0 * pts[:, 0] ** 2 * pts[:, 2] - pts[:, 1]
    assert np.array_equal(d.evaluate(pts), expected)
    assert d.degree == 3
    assert Density("uniform", 2.5).degree == 0
    assert np.array_equal(Density("uniform", 2.5).evaluate(pts), [2.5, 2.5])


def test_uniform_shell_total_charge_and_mass_ball_inertia() -> None:
    shell = ContinuousBody("charge", "shell", [0.0, 0.0, 0.0], Density("uniform", 0.3), radius=2.0)
    _, q = quadrature_points(shell, 0)
    assert q.sum() == pytest.approx(0.3 * 4 * math.pi * 4.0, rel=1e-15)
    ball = ContinuousBody("mass", "ball", [0.0, 0.0, 0.0], Density("uniform", 2.0), radius=0.5)
    pts, m = quadrature_points(ball, 2)
    mass = 2.0 * 4 / 3 * math.pi * 0.125
    inertia = np.einsum("n,n->", m, (pts**2).sum(1)) * np.eye(3) - np.einsum(
        "n,ni,nj->ij", m, pts, pts
    )
    np.testing.assert_allclose(inertia, 0.4 * mass * 0.25 * np.eye(3), rtol=1e-14, atol=1e-16)


def test_dict_round_trip_and_design_json(tmp_path) -> None:
    bodies = [
        {
            "kind": "charge",
            "shape": "shell",
            "radius": 0.5,
            "center": [0.0, 0.0, 0.1],
            "density": {"type": "uniform", "value": 1e-3},
        },
        {
            "kind": "mass",
            "shape": "box",
            "half_size": [0.1, 0.2, 0.3],
            "center": [0.0, 0.0, 0.0],
            "density": {"type": "polynomial", "coefficients": {"": 2.0, "zz": 1.0}},
        },
        {
            "kind": "mass",
            "shape": "cylinder",
            "radius": 0.2,
            "height": 0.4,
            "center": [0.0, 0.0, 0.0],
            "density": {"type": "uniform", "value": 7.8},
        },
    ]
    for raw in bodies:
        assert ContinuousBody.from_dict(raw).to_dict() == raw
    design = Design(parameters=Parameters(), continuous=bodies)
    assert all(isinstance(b, ContinuousBody) for b in design.continuous)
    path = tmp_path / "design.json"
    write_design(design, path)
    again = read_design(path)
    assert [b.to_dict() for b in again.continuous] == bodies
    assert "continuous" not in Design(parameters=Parameters()).to_dict()
    cube = ContinuousBody.from_dict({**bodies[1], "half_size": 0.25})
    assert np.array_equal(cube.half_size, [0.25, 0.25, 0.25])


@pytest.mark.parametrize(
    ("raw", "fragment"),
    [
        ({"kind": "charge", "shape": "cone", "radius": 1.0}, "shape"),
        ({"kind": "spin", "shape": "ball", "radius": 1.0}, "kind"),
        ({"kind": "charge", "shape": "ball"}, "radius"),
        ({"kind": "charge", "shape": "ball", "radius": -1.0}, "radius"),
        ({"kind": "charge", "shape": "ball", "radius": 1.0, "height": 2.0}, "height"),
        ({"kind": "charge", "shape": "cylinder", "radius": 1.0}, "height"),
        ({"kind": "charge", "shape": "box", "half_size": [1.0, 0.0, 1.0]}, "half_size"),
        ({"kind": "charge", "shape": "box", "half_size": [1.0, 1.0]}, "half_size"),
        ({"kind": "mass", "shape": "ball", "radius": 1.0, "value": 1.0}, "value"),
        ({"kind": "charge", "shape": "ball", "radius": 1.0, "center": [0, 0]}, "center"),
    ],
)
def test_bad_bodies_are_rejected(raw: dict, fragment: str) -> None:
    raw = {"density": {"type": "uniform", "value": 1.0}, **raw}
    with pytest.raises(InputError, match=fragment):
        ContinuousBody.from_dict(raw)


@pytest.mark.parametrize(
    ("density", "fragment"),
    [
        ({"type": "gaussian"}, "type"),
        ({"type": "uniform"}, "value"),
        ({"type": "uniform", "value": float("nan")}, "value"),
        ({"type": "polynomial", "coefficients": {"zx": 1.0}}, "moment key"),
        ({"type": "polynomial", "coefficients": [1.0]}, "coefficients"),
    ],
)
def test_bad_densities_are_rejected(density: dict, fragment: str) -> None:
    raw = {"kind": "charge", "shape": "ball", "radius": 1.0, "density": density}
    with pytest.raises(InputError, match=fragment):
        ContinuousBody.from_dict(raw)


def test_negative_mass_density_and_bad_order_are_rejected() -> None:
    negative = {"type": "uniform", "value": -1.0}
    with pytest.raises(InputError, match=r"mass density >= 0, got -1\.0"):
        ContinuousBody.from_dict(
            {"kind": "mass", "shape": "ball", "radius": 1.0, "density": negative}
        )
    body = ContinuousBody(
        "mass", "ball", [0, 0, 0], Density("polynomial", coefficients={"z": 1.0}), radius=1.0
    )
    with pytest.raises(InputError, match="mass density"):
        quadrature_points(body, 3)
    # a rule's order is the caller's (the command line checks its option's range): a
    # programming error, not an input error
    for order, error in ((-1, ValueError), (2.5, TypeError), (True, TypeError)):
        with pytest.raises(error, match="order") as info:
            geometric_rule(BODIES["ball"], order)  # type: ignore[arg-type]
        assert not isinstance(info.value, InputError)
    with pytest.raises(InputError, match="continuous"):
        Design(parameters=Parameters(), continuous=[{"kind": "charge"}])
