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

from chargedesign.bench.check import bench_design, naive_sums
from chargedesign.body import Design
from chargedesign.check import (
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
PARAMS = Parameters(C=1.0, c=0.3, d=-0.4, n=0.7, K=0.5, kappa=0.9)
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
    """End to end: chargedesign.design's answer for the embedded scene, checked here."""
    from chargedesign.design import design_from_scene
    from chargedesign.scene import load_scene

    design = design_from_scene(load_scene()).design
    report = check_design(design, n_orientations=500, tol=1e-10)
    assert report.passed, report.to_dict()
    assert set(report.claimed) == {"mu", "V", "inertia"}
