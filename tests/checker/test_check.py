"""The forward check: a sound design passes at 1e-12; deliberately broken designs fail in the
quantity they break and only there; the rotated-body kernel agrees with independent routes
(a per-orientation loop over chargedesign.fields, the paper's moment formula (p5)); continuous
bodies go through the same route."""

from __future__ import annotations

import copy
import json
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from unit_scene import UNIT_PARAMETERS as PARAMS
from unit_scene import UNIT_SCENE

from chargedesign.bench.check import bench_design, naive_sums, stencil_points
from chargedesign.body import Design
from chargedesign.checker import (
    CheckReport,
    check_design,
    collect_elements,
    evaluate_rotated,
    rotation_matrices,
    sample_orientations,
)
from chargedesign.errors import InputError
from chargedesign.fields import AxisymmetricField
from chargedesign.params import Parameters
from chargedesign.quadrature import ContinuousBody, Density, quadrature_points

A1, A2 = 1.0, 0.5  # the paper's Phi = a1 Z + a2 (3 Z^2 - R^2): legendre [a1, 2 a2]
MAGNETIC = (A1, 2 * A2)
# With the paper's (p6) the charges' third moments are fixed by mu; in a degree-3 electric
# field they produce the cubic term (15 e3 / (12 a2)) C K gamma3 f of V, and the theorem's is
# -n K C gamma3 f: hence e3 = -0.8 a2 n. The other coefficients are free.
ELECTRIC = (0.3, 0.5, -0.8 * A2 * PARAMS.n, 0.6)
GRAVITY = (9.81,)
QUANTITIES = ("mu", "gyroscopic_torque", "V", "potential_torque", "inertia")


def theorem(gammas: np.ndarray, P: Parameters) -> tuple[np.ndarray, np.ndarray]:
    """V and mu of the theorem, transcribed from the paper's (pot) and (muu) (lambda = rho = 0)."""
    g1, g2, g3 = gammas.T
    C, c, d, n, K, kappa = P.C, P.c, P.d, P.n, P.K, P.kappa
    f = d * (g2**2 - g1**2) + 2 * c * g1 * g2
    V = C * (
        kappa * (2 * d * g1 * g2 + c * (g1**2 - g2**2))
        + 0.5 * n**2 * g3**2
        - n * K * g3 * f
        + K**2
        * (
            2 * c * d * g1 * g2 * (g1**2 - g2**2)
            + d**2 / 2 * (g3**4 + 4 * g1**2 * g2**2)
            - c**2 * (g3**2 * (g1**2 + g2**2) + 2 * g1**2 * g2**2)
        )
    )
    mu = C * np.stack(
        [
            2 * K * g3 * (c * g2 - d * g1) - n * g1,
            2 * K * g3 * (d * g2 + c * g1) - n * g2,
            K * f - 3 * n * g3,
        ],
        axis=1,
    )
    return V, mu


def _in_ball(rng: np.random.Generator, n: int, lo: float = 0.3) -> np.ndarray:
    v = rng.standard_normal((n, 3))
    v /= np.linalg.norm(v, axis=1, keepdims=True)
    return v * rng.uniform(lo, 1.0, (n, 1))


def sound_design(
    *,
    gravity: tuple[float, ...] = GRAVITY,
    shell_charge: float = 0.0,
    shell_radius: float = 0.9,
    ball_inertia: float = 0.0,
    seed: int = 1,
) -> tuple[Design, float]:
    """A design realising mu, V and the inertia, built by collocation (not by the check).

    Charges at random positions and dipoles at random positions solve, in the least-squares
    sense, mu_design(gamma) = mu(gamma) and V_design(gamma) = V(gamma) + const at 80 random
    orientations, with the body-axes field formulas of chargedesign.fields. Six masses on
    the axes give diag(2C, 2C, C) (their centre is O, so uniform gravity adds nothing).

    ``shell_charge``: a uniform charged shell (total charge Q, radius a) is added as a
    continuous body; by symmetry its mu is a1 Q a^2 / 3 gamma and its V is zero (mean-value
    property), so the point charges realise mu minus that. ``ball_inertia``: a uniform mass
    ball with inertia J 1 is added; the point masses supply the rest.

    Returns the design and the relative residual of the collocation.
    """
    rng = np.random.default_rng(seed)
    rq, rd = _in_ball(rng, 60), _in_ball(rng, 8)
    g = rng.standard_normal((80, 3))
    g /= np.linalg.norm(g, axis=1, keepdims=True)
    M = len(g)
    fm, fe = AxisymmetricField(MAGNETIC), AxisymmetricField(ELECTRIC)
    B = -fm.gradient_body(rq, g)
    rB = np.einsum("mnc,nc->mn", B, rq)
    A_mu = -(rB[:, :, None] * rq[None, :, :]).transpose(0, 2, 1).reshape(3 * M, -1)
    A_vq = fe.potential_body(rq, g)
    A_vd = fm.gradient_body(rd, g).reshape(M, -1)  # -sigma . B = sigma . grad Phi_m
    V, mu = theorem(g, PARAMS)
    mu = mu - A1 * shell_charge * shell_radius**2 / 3.0 * g
    A = np.block(
        [
            [A_mu, np.zeros((3 * M, 3 * len(rd) + 1))],
            [A_vq, A_vd, -np.ones((M, 1))],
        ]
    )
    b = np.concatenate([mu.reshape(-1), V])
    x, *_ = np.linalg.lstsq(A, b, rcond=None)
    residual = float(np.abs(A @ x - b).max() / np.abs(b).max())
    C, J = PARAMS.C, ball_inertia
    a, bz = math.sqrt((C - J) / 4.0), math.sqrt((3.0 * C - J) / 4.0)  # 2 a^2 = (C - J) / 2
    masses = [[a, 0, 0], [-a, 0, 0], [0, a, 0], [0, -a, 0], [0, 0, bz], [0, 0, -bz]]
    continuous = []
    if shell_charge:
        sigma = shell_charge / (4.0 * math.pi * shell_radius**2)
        continuous.append(
            {
                "kind": "charge",
                "shape": "shell",
                "radius": shell_radius,
                "center": [0.0, 0.0, 0.0],
                "density": {"type": "uniform", "value": sigma},
            }
        )
    if ball_inertia:
        radius = 0.5
        mass = J / (0.4 * radius**2)
        continuous.append(
            {
                "kind": "mass",
                "shape": "ball",
                "radius": radius,
                "center": [0.0, 0.0, 0.0],
                "density": {"type": "uniform", "value": mass / (4.0 / 3.0 * math.pi * radius**3)},
            }
        )
    fields = {"magnetic": MAGNETIC, "electric": ELECTRIC}
    if gravity:
        fields["gravity"] = gravity
    design = Design(
        parameters=PARAMS,
        fields=fields,
        charge_positions=rq,
        charge_values=x[: len(rq)],
        mass_positions=masses,
        mass_values=np.ones(6),
        dipole_positions=rd,
        dipole_moments=x[len(rq) : len(rq) + 3 * len(rd)].reshape(-1, 3),
        realises=["mu", "V", "inertia"],
        continuous=continuous,
    )
    return design, residual


@pytest.fixture(scope="module")
def sound() -> Design:
    design, residual = sound_design()
    assert residual < 1e-13
    return design


def _rotation(axis: np.ndarray, angle: float) -> np.ndarray:
    a = axis / np.linalg.norm(axis)
    K = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
    return np.eye(3) + math.sin(angle) * K + (1 - math.cos(angle)) * K @ K


# ------------------------------------------------------------------- sound and broken
def test_sound_design_passes_at_1e_12(sound: Design) -> None:
    report = check_design(sound, n_orientations=400, tol=1e-12)
    assert report.passed, report.to_dict()
    for name in QUANTITIES:
        q = report.quantities[name]
        assert q.claimed and q.passed
        assert q.rel_err <= 1e-12
    for name in ("lorentz", "electric", "magnetization"):
        effect = report.effects[name]
        assert effect.active and effect.route_rel_err is not None
        assert effect.route_rel_err <= 1e-12
    assert report.effects["gravity"].size["V_spread"] < 1e-12  # masses centred at O
    assert report.n_pairs == 400 * (60 + 6 + 8)


def _charge_moved(d: Design) -> None:
    size = np.linalg.norm(d.charge_positions, axis=1).max()
    d.charge_positions[3] += 1e-3 * size * np.array([0.6, 0.0, 0.8])


def _charge_flipped(d: Design) -> None:
    d.charge_values[int(np.argmax(np.abs(d.charge_values)))] *= -1.0


def _dipole_rotated(d: Design) -> None:
    d.dipole_moments[0] = _rotation(np.array([1.0, 2.0, 0.5]), 1e-3) @ d.dipole_moments[0]


def _mass_moved(d: Design) -> None:
    d.mass_positions[0] += 1e-3 * np.array([0.0, 0.3, 0.4])


BROKEN = {
    "charge moved": (_charge_moved, {"mu", "gyroscopic_torque", "V", "potential_torque"}),
    "charge sign flipped": (_charge_flipped, {"mu", "gyroscopic_torque", "V", "potential_torque"}),
    "dipole rotated": (_dipole_rotated, {"V", "potential_torque"}),
    "mass moved": (_mass_moved, {"inertia", "V", "potential_torque"}),
}


@pytest.mark.parametrize("name", list(BROKEN))
def test_broken_design_fails_exactly_where_physics_says(sound: Design, name: str) -> None:
    breaker, broken = BROKEN[name]
    design = copy.deepcopy(sound)
    breaker(design)
    report = check_design(design, n_orientations=300)
    assert not report.passed
    assert set(report.failures) == broken
    for quantity in QUANTITIES:
        rel = report.quantities[quantity].rel_err
        if quantity in broken:
            assert rel > 1e-7, (quantity, rel)
        else:
            assert rel <= 1e-12, (quantity, rel)
    worst = report.quantities[sorted(broken)[0]].worst_gamma
    assert worst is not None and math.isclose(float(np.linalg.norm(worst)), 1.0, rel_tol=1e-12)


def test_moved_mass_without_gravity_breaks_only_the_inertia() -> None:
    design, _ = sound_design(gravity=())
    _mass_moved(design)
    report = check_design(design, n_orientations=200)
    assert report.failures == ["inertia"]
    assert report.quantities["V"].rel_err <= 1e-12
    assert not report.effects["gravity"].active


def test_only_claimed_quantities_decide(sound: Design) -> None:
    design = copy.deepcopy(sound)
    _charge_flipped(design)
    design.realises = ["inertia"]
    report = check_design(design, n_orientations=100)
    assert report.passed
    assert report.quantities["mu"].passed is None and report.quantities["mu"].rel_err > 1e-6
    assert report.quantities["inertia"].passed is True
    design.realises = []
    assert check_design(design, n_orientations=50).notes


def test_gyroscopic_torque_is_mu_cross_omega_not_omega_cross_mu(sound: Design) -> None:
    """Euler-Poisson: I omega' = (omega I + mu) x omega + gamma x dV/dgamma."""
    gammas = sample_orientations(50)
    rng = np.random.default_rng(5)
    R = rotation_matrices(gammas, rng)
    omegas = rng.standard_normal((50, 3))
    elements, _ = collect_elements(sound)
    sums = evaluate_rotated(elements, sound.fields, R, omegas)
    _, mu = theorem(gammas, PARAMS)
    np.testing.assert_allclose(sums.gyro, np.cross(mu, omegas), rtol=0, atol=1e-13)
    assert np.abs(sums.gyro - np.cross(omegas, mu)).max() > 1.0


def test_report_json_contract_keys_first(sound: Design) -> None:
    report = check_design(sound, n_orientations=60, tol=1e-10)
    data = json.loads(json.dumps(report.to_dict(), allow_nan=False))
    assert list(data)[:3] == ["mu_rel_err", "V_rel_err", "inertia_rel_err"]
    for key in ("gyroscopic_torque_rel_err", "potential_torque_rel_err", "passed", "tol"):
        assert key in data
    assert data["tol"] == 1e-10 and data["passed"] is True
    assert set(data["effects"]) == {"lorentz", "electric", "gravity", "magnetization", "inertia"}
    assert data["effects"]["electric"]["source"] == "charges"
    assert isinstance(report, CheckReport)


# ------------------------------------------------------------------ independent routes
HIGH_DEGREE_FIELDS = {
    "magnetic": (0.4, -0.7, 0.5, 0.3, -0.2),
    "electric": (0.1, 0.0, 0.6, -0.4, 0.25, 0.1),
    "gravity": (9.81, 0.0, -0.5),
}


@pytest.mark.parametrize("high_degree", [False, True])
def test_kernel_matches_a_loop_over_the_fields_module(high_degree: bool) -> None:
    """Two implementations of the harmonic fields (own recurrences vs chargedesign.fields)."""
    design = bench_design(70, 9, 11, seed=3)
    if high_degree:
        design.fields = dict(HIGH_DEGREE_FIELDS)
    gammas = sample_orientations(40, seed=2)
    rng = np.random.default_rng(4)
    R = rotation_matrices(gammas, rng)
    omegas = rng.standard_normal((40, 3))
    elements, _ = collect_elements(design)
    sums = evaluate_rotated(elements, design.fields, R, omegas, block_pairs=256)
    ref = naive_sums(design, R, omegas)
    for got, want in [
        (sums.mu, ref["mu"]),
        (sums.gyro, ref["gyro"]),
        (sum(sums.torque.values()), ref["torque"]),
        (sum(sums.energy.values()), ref["energy"]),
    ]:
        np.testing.assert_allclose(got, want, rtol=0, atol=1e-13 * np.abs(want).max())


def _p5(moment: dict[str, float], gammas: np.ndarray) -> np.ndarray:
    """The paper's (p5): mu in terms of second and third moments for [a1, 2 a2]."""
    I = moment
    g1, g2, g3 = gammas.T
    rows = []
    for a in "xyz":

        def m(*letters: str, a: str = a) -> float:
            return I["".join(sorted(a + "".join(letters)))]

        rows.append(
            -2 * A2 * (m("x", "x") + m("y", "y") + m("z", "z"))
            + A1 * (m("x") * g1 + m("y") * g2 + m("z") * g3)
            + 6
            * A2
            * (
                m("x", "x") * g1**2
                + m("y", "y") * g2**2
                + m("z", "z") * g3**2
                + 2 * m("x", "y") * g1 * g2
                + 2 * m("x", "z") * g1 * g3
                + 2 * m("y", "z") * g2 * g3
            )
        )
    return np.stack(rows, axis=1)


def _moments(points: np.ndarray, weights: np.ndarray) -> dict[str, float]:
    out = {}
    for order in (2, 3):
        for i in range(order + 1):
            for j in range(order + 1 - i):
                k = order - i - j
                key = "x" * i + "y" * j + "z" * k
                out[key] = float(
                    weights @ (points[:, 0] ** i * points[:, 1] ** j * points[:, 2] ** k)
                )
    return out


def test_mu_matches_the_papers_moment_formula() -> None:
    rng = np.random.default_rng(11)
    r, q = _in_ball(rng, 50, lo=0.0), rng.standard_normal(50)
    design = Design(
        parameters=PARAMS, fields={"magnetic": MAGNETIC}, charge_positions=r, charge_values=q
    )
    gammas = sample_orientations(30)
    R = rotation_matrices(gammas, rng)
    elements, _ = collect_elements(design)
    sums = evaluate_rotated(elements, design.fields, R, np.zeros((30, 3)))
    want = _p5(_moments(r, q), gammas)
    np.testing.assert_allclose(sums.mu, want, rtol=0, atol=1e-13 * np.abs(want).max())


@settings(max_examples=20, deadline=None)
@given(
    gamma=st.tuples(*[st.floats(-1, 1, allow_nan=False)] * 3).filter(
        lambda g: 0.1 < math.hypot(*g)
    ),
    seed=st.integers(0, 2**16),
)
def test_results_do_not_depend_on_the_azimuth_about_the_field_axis(
    gamma: tuple[float, float, float], seed: int
) -> None:
    design = bench_design(20, 5, 4, seed=7)
    g = np.array(gamma) / np.linalg.norm(gamma)
    gammas = np.stack([g, g])
    R = np.concatenate(
        [
            rotation_matrices(gammas[:1], np.random.default_rng(seed)),
            rotation_matrices(gammas[1:], np.random.default_rng(seed + 1)),
        ]
    )
    assert np.allclose(R[0, 2], R[1, 2]) and not np.allclose(R[0, 0], R[1, 0])
    omega = np.array([[0.3, -1.1, 0.7]] * 2)
    elements, _ = collect_elements(design)
    sums = evaluate_rotated(elements, design.fields, R, omega)
    for arr in [sums.mu, sums.gyro, *sums.torque.values(), *sums.energy.values()]:
        assert np.allclose(arr[0], arr[1], rtol=1e-12, atol=1e-12 * (1 + np.abs(arr).max()))


# ------------------------------------------------------------------- continuous bodies
def test_continuous_shell_and_ball_through_the_same_route() -> None:
    design, residual = sound_design(shell_charge=0.7, ball_inertia=0.3)
    assert residual < 1e-13
    report = check_design(design, n_orientations=300, tol=1e-12)
    assert report.passed, report.to_dict()
    kinds = {(b["kind"], b["shape"]) for b in report.quadrature}
    assert kinds == {("charge", "shell"), ("mass", "ball")}
    shell_info = next(b for b in report.quadrature if b["shape"] == "shell")
    assert shell_info["order"] == len(ELECTRIC)  # max(L_e, L_m + 1) = 4, uniform density
    # the shell's charge off by one part in a thousand breaks mu (not V: its V is zero)
    broken = copy.deepcopy(design)
    shell = broken.continuous[0]
    broken.continuous[0] = ContinuousBody(
        "charge",
        "shell",
        shell.center,
        Density("uniform", shell.density.value * 1.001),
        radius=shell.radius,
    )
    report = check_design(broken, n_orientations=200)
    assert set(report.failures) == {"mu", "gyroscopic_torque"}
    assert report.quantities["V"].rel_err <= 1e-12


def test_polynomial_density_box_agrees_with_closed_form_moments() -> None:
    """mu of a charged box with a polynomial density: check route (quadrature, rotated body)
    against the paper's (p5) with exact moments (closed forms from test_quadrature)."""
    from test_quadrature import exact_monomial

    coeffs = {"": 0.2, "x": 1.0, "yz": -2.0, "xxz": 0.5}
    body = ContinuousBody(
        "charge",
        "box",
        [0.1, -0.2, 0.3],
        Density("polynomial", coefficients=coeffs),
        half_size=[0.4, 0.3, 0.5],
    )
    design = Design(parameters=PARAMS, fields={"magnetic": MAGNETIC}, continuous=[body])
    moments = {}
    for key in _moments(np.zeros((1, 3)), np.zeros(1)):
        moments[key] = sum(
            c
            * exact_monomial(
                body,
                (
                    key.count("x") + k.count("x"),
                    key.count("y") + k.count("y"),
                    key.count("z") + k.count("z"),
                ),
            )
            for k, c in coeffs.items()
        )
    gammas = sample_orientations(40)
    R = rotation_matrices(gammas, np.random.default_rng(0))
    elements, _ = collect_elements(design)
    assert elements.quadrature[0]["order"] == 3 + 3  # density degree + (L_m + 1)
    sums = evaluate_rotated(elements, design.fields, R, np.zeros((40, 3)))
    want = _p5(moments, gammas)
    np.testing.assert_allclose(sums.mu, want, rtol=0, atol=1e-13 * np.abs(want).max())
    # an explicit lower order is honoured and is no longer exact
    low, _ = collect_elements(design, quadrature_order=2)
    sums_low = evaluate_rotated(low, design.fields, R, np.zeros((40, 3)))
    assert np.abs(sums_low.mu - want).max() > 1e-8


def test_continuous_masses_count_in_the_inertia() -> None:
    ball = ContinuousBody("mass", "ball", [0, 0, 0], Density("uniform", 3.0), radius=0.5)
    design = Design(parameters=Parameters(C=0.4 * ball.measure * 3.0 * 0.25 / 2), continuous=[ball])
    design.realises = ["inertia"]
    report = check_design(design, n_orientations=20)
    # a uniform ball has I = 2/5 M a^2 about every axis: diag(2C, 2C, C) fails by C / 2C
    assert report.quantities["inertia"].rel_err == pytest.approx(0.5, rel=1e-12)
    _, w = quadrature_points(ball, 2)
    assert report.effects["inertia"].n_elements == len(w)


# ------------------------------------------------------------------------------ inputs
def test_orientations_are_unit_deterministic_and_avoid_the_equator() -> None:
    g = sample_orientations(101, seed=3)
    assert g.shape == (101, 3)
    np.testing.assert_allclose(np.linalg.norm(g, axis=1), 1.0, rtol=0, atol=1e-15)
    assert np.all(g[:, 2] != 0.0)
    assert np.array_equal(g, sample_orientations(101, seed=3))
    assert not np.array_equal(g, sample_orientations(101, seed=4))
    R = rotation_matrices(g, np.random.default_rng(0))
    np.testing.assert_allclose(
        np.einsum("mij,mkj->mik", R, R), np.broadcast_to(np.eye(3), R.shape), atol=1e-14
    )
    np.testing.assert_allclose(np.linalg.det(R), 1.0, atol=1e-14)
    np.testing.assert_allclose(R[:, 2], g, atol=0)


@pytest.mark.parametrize(
    ("kwargs", "fragment"),
    [
        ({"tol": 0.0}, "tol"),
        ({"tol": float("nan")}, "tol"),
        ({"n_orientations": 0}, "n_orientations"),
        ({"n_orientations": 2.5}, "n_orientations"),
        ({"seed": "a"}, "seed"),
        ({"seed": -1}, "seed"),
    ],
)
def test_bad_arguments_are_rejected(sound: Design, kwargs: dict, fragment: str) -> None:
    with pytest.raises(InputError, match=fragment):
        check_design(sound, **kwargs)


def test_not_a_design_is_rejected() -> None:
    with pytest.raises(InputError, match="design"):
        check_design({"charges": []})  # type: ignore[arg-type]


def test_singular_parameters_are_reported(sound: Design) -> None:
    design = copy.deepcopy(sound)
    design.parameters = PARAMS.replace(lam=0.1)
    report = check_design(design, n_orientations=40)
    assert "V" in report.failures
    assert any("singular" in note for note in report.notes)


def test_a_design_from_the_default_scene_passes() -> None:
    """End to end: chargedesign.designer's answer for the embedded scene, checked here."""
    from chargedesign.designer import design_from_scene
    from chargedesign.scene import load_scene

    design = design_from_scene(load_scene(UNIT_SCENE)).design
    report = check_design(design, n_orientations=500, tol=1e-10)
    assert report.passed, report.to_dict()
    assert set(report.claimed) == {"mu", "V", "inertia"}


# ------------------------------------------------------- cancellation and rounding floor
#: finite-difference stencil: the fifth difference of a polynomial of degree <= 4 is zero


def with_cancelling_stencils(design: Design, weight: float = 2.0**30, seed: int = 0) -> Design:
    """The design plus huge charges and dipoles whose contributions cancel exactly.

    Each stencil is six collinear elements at ``p + j h`` (j = 0..5) with weights
    ``weight (-1)^j C(5, j)``: their sum of any polynomial of degree <= 4 in r is zero, and
    every integrand of the check is one (charges: mu and the Lorentz torque degree
    L_m + 1 = 3, V and its torque degree L_e = 4; dipoles: degree L_m - 1 = 1). p and h are
    multiples of 2^-10 and the weights powers of two times integers: exact doubles, so the
    body's mu, V and torques are exactly the design's, while the contributions are ~1e10
    times larger.
    """
    points_arr, values_arr = stencil_points(weight, seed)
    out = copy.deepcopy(design)
    out.charge_positions = np.concatenate([design.charge_positions, points_arr])
    out.charge_values = np.concatenate([design.charge_values, values_arr])
    axis = np.array([0.5, -0.25, 0.75])  # exact products with the weights
    out.dipole_positions = np.concatenate([design.dipole_positions, points_arr[::-1]])
    out.dipole_moments = np.concatenate([design.dipole_moments, np.outer(values_arr, axis)])
    return out


CLAIMED_SUMS = ("mu", "gyroscopic_torque", "V", "potential_torque")


@pytest.fixture(scope="module")
def cancelling(sound: Design) -> Design:
    return with_cancelling_stencils(sound)


def test_sound_cancelling_body_is_verified_in_double_double(cancelling: Design) -> None:
    report = check_design(cancelling, n_orientations=200, tol=1e-12)
    assert report.precision == "double-double"
    assert report.passed, report.to_dict()
    for name in QUANTITIES:
        assert report.quantities[name].status == "pass"
        assert report.quantities[name].rel_err <= 1e-12, name
    for name in CLAIMED_SUMS:
        q = report.quantities[name]
        assert q.cancellation > 1e9 and q.double_rounding_floor > 1e-6, name
        assert q.rounding_floor <= 1e-14
    assert any("double-precision evaluation" in note for note in report.notes)


def test_sound_cancelling_body_is_unverifiable_in_double(cancelling: Design) -> None:
    """Double rounding (~eps * 1e10) hides everything below 1e-6: never a pass."""
    report = check_design(cancelling, n_orientations=200, tol=1e-9, precision="double")
    assert not report.passed and report.precision == "double"
    assert report.unverifiable == list(CLAIMED_SUMS)
    for name in CLAIMED_SUMS:
        q = report.quantities[name]
        assert q.status == "unverifiable" and q.passed is False
        assert q.reason is not None
        assert q.reason.startswith("cannot be verified at tol 1e-09: contributions cancel")
        assert q.rounding_floor > 1e-6
    data = json.loads(json.dumps(report.to_dict(), allow_nan=False))
    assert data["passed"] is False and data["unverifiable"] == list(CLAIMED_SUMS)
    assert data["quantities"]["mu"]["status"] == "unverifiable"
    assert "cancel to 1 part in" in data["reasons"]["V"]
    assert data["inertia_rel_err"] <= 1e-15 and data["quantities"]["inertia"]["passed"] is True


def test_cancelling_body_with_a_1e_7_error_fails_at_1e_9(sound: Design, cancelling: Design) -> None:
    """The charges that carry mu off by 1e-7: the old noise floor (1e-6 of the gross
    contributions in the denominator) called this 1e-10 and passed it."""
    broken = copy.deepcopy(cancelling)
    broken.charge_values[: len(sound.charge_values)] *= 1.0 + 1e-7
    report = check_design(broken, n_orientations=200, tol=1e-9)
    for name in ("mu", "gyroscopic_torque"):
        q = report.quantities[name]
        assert q.status == "fail" and q.passed is False, name
        assert q.rel_err == pytest.approx(1e-7, rel=1e-4), name
    assert {"mu", "gyroscopic_torque"} <= set(report.failures)
    # what the old definition made of it, from the same double-precision sums
    gammas = sample_orientations(200)
    rng = np.random.default_rng(3)
    sums = evaluate_rotated(
        collect_elements(broken)[0],
        broken.fields,
        rotation_matrices(gammas, rng),
        np.zeros((200, 3)),
    )
    _, mu_ref = theorem(gammas, PARAMS)
    size = np.linalg.norm(mu_ref, axis=1).max()
    old = np.linalg.norm(sums.mu - mu_ref, axis=1).max() / max(size, 1e-6 * sums.mu_gross.max())
    assert old < 1e-9


def _weak_field_least_squares_body(a1: float) -> Design:
    """Charges on a ball meeting the mu conditions for the field [a1, 1] by least squares:
    a weak a1 forces charges ~1/a1 whose contributions cancel (test_stability's route)."""
    from chargedesign.candidates import candidates_from_table
    from chargedesign.moment_conditions import derive_conditions

    conditions = derive_conditions(PARAMS, {"magnetic": (a1, 1.0)}, ("mu",))
    points = candidates_from_table({"shape": "ball", "radius": 1.0, "spacing": 0.5}).points
    A, b = conditions.system("charges", points)
    row = np.max(np.abs(A), axis=1)
    row = np.where(row > 0, row, 1.0)
    q = np.linalg.lstsq(A / row[:, None], b / row, rcond=None)[0]
    return Design(
        parameters=PARAMS,
        fields={"magnetic": (a1, 1.0)},
        charge_positions=points,
        charge_values=q,
        realises=["mu"],
    )


def _mu_50_digits(design: Design, gamma: tuple[float, float, float]) -> list[float]:
    """mu = -sum q (r . B) r in 50-digit arithmetic for Phi = a1 Z + a2 (3 Z^2 - R^2)."""
    import mpmath as mp

    with mp.workdps(50):
        a1, f2 = (mp.mpf(float(c)) for c in design.fields["magnetic"])
        a2 = f2 / 2
        g = [mp.mpf(float(c)) for c in gamma]
        norm = mp.sqrt(sum(c * c for c in g))
        g = [c / norm for c in g]
        mu = [mp.mpf(0)] * 3
        for r, q in zip(design.charge_positions, design.charge_values, strict=True):
            x = [mp.mpf(float(c)) for c in r]
            Z = sum(a * b for a, b in zip(g, x, strict=True))
            S = sum(c * c for c in x)
            r_dot_B = -(a1 * Z + a2 * (6 * Z * Z - 2 * S))  # B = -grad Phi
            mu = [m - mp.mpf(float(q)) * r_dot_B * c for m, c in zip(mu, x, strict=True)]
        return [float(c) for c in mu]


def test_weak_field_body_reports_its_true_error() -> None:
    """a1 = 1e-6: contributions 3e6 times mu. The error figure is the body's own (50-digit
    arithmetic agrees), a 1e-7 error fails, and double alone could not tell."""
    from chargedesign.model import evaluators

    design = _weak_field_least_squares_body(1e-6)
    report = check_design(design, n_orientations=200, tol=1e-9)
    q = report.quantities["mu"]
    assert q.precision == "double-double" and q.cancellation > 1e6
    assert q.double_rounding_floor > 1e-9 > q.rounding_floor
    assert q.worst_gamma is not None
    want = np.array(_mu_50_digits(design, q.worst_gamma))
    ref = np.asarray(evaluators.gyroscopic(np.array([q.worst_gamma]), PARAMS))[0]
    assert q.abs_err == pytest.approx(float(np.linalg.norm(want - ref)), rel=1e-4)
    assert q.status == ("pass" if q.rel_err <= 1e-9 else "fail")
    broken = copy.deepcopy(design)
    broken.charge_values *= 1.0 + 1e-7
    q = check_design(broken, n_orientations=200, tol=1e-9).quantities["mu"]
    assert q.status == "fail" and q.rel_err == pytest.approx(1e-7, abs=2e-9)
    q = check_design(design, n_orientations=200, tol=1e-9, precision="double").quantities["mu"]
    assert q.status == "unverifiable"


def test_rounding_floor_bounds_the_double_error(sound: Design, cancelling: Design) -> None:
    """The floor the check states for double precision holds against double-double."""
    from chargedesign.checker import EPS, contribution_sizes, evaluate_accurate, rounding_floor

    bodies = [sound, cancelling, _weak_field_least_squares_body(1e-7), bench_design(80, 9, 11)]
    bodies[-1].fields = dict(HIGH_DEGREE_FIELDS)
    for body in bodies:
        gammas = sample_orientations(300, seed=5)
        rng = np.random.default_rng(6)
        R = rotation_matrices(gammas, rng)
        omegas = rng.standard_normal((300, 3))
        elements, _ = collect_elements(body)
        fast = evaluate_rotated(elements, body.fields, R, omegas)
        exact = evaluate_accurate(elements, body.fields, gammas, omegas)
        sizes = contribution_sizes(elements, body.fields)
        energy = sum(fast.energy.values())
        pairs = {
            "mu": (fast.mu, exact.mu, sizes["mu"]),
            "gyroscopic_torque": (
                fast.gyro,
                exact.gyro,
                sizes["gyroscopic_torque"] * np.linalg.norm(omegas, axis=1).max(),
            ),
            "V": (energy - energy.mean(), exact.energy_centered, sizes["V"]),
            "potential_torque": (
                sum(fast.torque.values()),
                sum(exact.torque.values()),
                sizes["potential_torque"],
            ),
        }
        for name, (got, want, gross) in pairs.items():
            if gross == 0.0:  # nothing contributes (no such field): both exactly zero
                assert not np.any(got) and not np.any(want), name
                continue
            scale = np.abs(want).max() if want.ndim == 1 else np.linalg.norm(want, axis=1).max()
            err = (
                np.abs(got - want).max()
                if got.ndim == 1
                else np.linalg.norm(got - want, axis=1).max()
            )
            assert err <= rounding_floor(gross / scale, EPS) * scale, (name, err / scale)


def test_rounding_floor_bounds_the_double_double_error(sound: Design) -> None:
    """Stencils of weight 2^70 (cancellation ~1e21) add exactly nothing: the double-double
    sums must equal the body's own to within the double-double floor."""
    from chargedesign.checker import DD_UNIT, contribution_sizes, evaluate_accurate, rounding_floor

    gammas = sample_orientations(100, seed=7)
    omegas = np.random.default_rng(8).standard_normal((100, 3))
    huge = with_cancelling_stencils(sound, weight=2.0**70)
    elements, _ = collect_elements(huge)
    truth = evaluate_accurate(collect_elements(sound)[0], sound.fields, gammas, omegas)
    got = evaluate_accurate(elements, sound.fields, gammas, omegas)
    sizes = contribution_sizes(elements, sound.fields)
    for name, x, want in [
        ("mu", got.mu, truth.mu),
        ("V", got.energy_centered, truth.energy_centered),
        ("potential_torque", sum(got.torque.values()), sum(truth.torque.values())),
    ]:
        scale = np.abs(want).max() if want.ndim == 1 else np.linalg.norm(want, axis=1).max()
        err = np.abs(x - want).max() if x.ndim == 1 else np.linalg.norm(x - want, axis=1).max()
        cancellation = sizes[name] / scale
        assert cancellation > 1e20
        assert 0.0 < err <= rounding_floor(cancellation, DD_UNIT) * scale, (name, err / scale)


@pytest.mark.parametrize("precision", ["double-double", "longdouble"])
def test_accurate_kernel_matches_the_loop_over_the_fields_module(precision: str) -> None:
    """The body-axes extended-precision route against chargedesign.fields (space axes)."""
    from chargedesign.checker import evaluate_accurate

    design = bench_design(70, 9, 11, seed=3)
    design.fields = dict(HIGH_DEGREE_FIELDS)
    gammas = sample_orientations(40, seed=2)
    rng = np.random.default_rng(4)
    R = rotation_matrices(gammas, rng)
    omegas = rng.standard_normal((40, 3))
    elements, _ = collect_elements(design)
    sums = evaluate_accurate(elements, design.fields, gammas, omegas, precision=precision)
    ref = naive_sums(design, R, omegas)
    energy = ref["energy"] - ref["energy"].mean()
    for got, want in [
        (sums.mu, ref["mu"]),
        (sums.gyro, ref["gyro"]),
        (sum(sums.torque.values()), ref["torque"]),
        (sums.energy_centered, energy),
        (sum(sums.energy.values()), ref["energy"]),
    ]:
        np.testing.assert_allclose(got, want, rtol=0, atol=1e-13 * np.abs(want).max())
    assert sums.energy_mean == pytest.approx(ref["energy"].mean(), rel=1e-13)


def test_zero_reference_is_measured_against_the_gross_contributions() -> None:
    """n = K = 0: the theorem's mu is zero; rel_err is the absolute error over the gross."""
    params = Parameters(C=1.0, c=0.3, d=-0.4, kappa=0.9)
    empty = Design(parameters=params, fields={"magnetic": MAGNETIC}, realises=["mu"])
    body = with_cancelling_stencils(empty)
    report = check_design(body, n_orientations=60, tol=1e-12)
    q = report.quantities["mu"]
    assert q.basis == "gross" and q.cancellation == math.inf and q.passed
    assert report.precision == "double"  # measured against the gross, double suffices
    assert q.scale == q.gross > 1e9 and q.rel_err <= 1e-15
    assert json.loads(json.dumps(report.to_dict()))["quantities"]["mu"]["cancellation"] is None
    body.charge_positions[0] += [1e-3, 0.0, 0.0]
    q = check_design(body, n_orientations=60, tol=1e-12).quantities["mu"]
    assert q.status == "fail" and q.basis == "gross" and q.rel_err > 1e-6


def test_tolerance_below_the_rounding_floor_is_not_a_pass(sound: Design) -> None:
    """Even double-double ends in a double: 16 eps is the least floor, so tol 1e-16 fails
    every quantity, as unverifiable unless its error is certainly beyond the tolerance."""
    report = check_design(sound, n_orientations=60, tol=1e-16)
    assert not report.passed and "inertia" in report.unverifiable
    for name in QUANTITIES:
        q = report.quantities[name]
        assert q.rounding_floor > 1e-16 and q.reason is not None
        if q.rel_err <= 1e-16 + q.rounding_floor:
            assert q.status == "unverifiable", (name, q.rel_err, q.rounding_floor)
            assert q.reason.startswith("cannot be verified at tol 1e-16")
        else:
            assert q.status == "fail" and q.reason.startswith("error")


def test_bad_precision_is_rejected(sound: Design) -> None:
    with pytest.raises(InputError, match="precision"):
        check_design(sound, precision="quad")
