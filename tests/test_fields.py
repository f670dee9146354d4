"""Tests of chargedesign.fields against independent routes: sympy's exact derivatives of the
Legendre form, finite differences, rotations between body and space axes, harmonicity."""

from __future__ import annotations

import functools

import numpy as np
import pytest
import sympy as sp
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from chargedesign.errors import InputError
from chargedesign.fields import AxisymmetricField

RNG_SEED = 20240611
XS, YS, ZS = sp.symbols("X Y Z", real=True)
zs, ss = sp.symbols("z s", positive=True)


def _homogenise(poly_in_t: sp.Expr, k: int, z: sp.Expr, s: sp.Expr) -> sp.Expr:
    """R^k p(Z/R) for a polynomial p of degree <= k and parity k: sum_j c_j z^j s^((k-j)/2)."""
    t = sp.Symbol("t")
    coeffs = sp.Poly(poly_in_t, t).all_coeffs()[::-1]
    terms = [c * z**j * s ** ((k - j) // 2) for j, c in enumerate(coeffs) if c != 0]
    assert all((k - j) % 2 == 0 for j, c in enumerate(coeffs) if c != 0)
    return sp.expand(sum(terms, sp.Integer(0)))


@functools.cache
def _solid_harmonic_xyz(k: int) -> sp.Expr:
    """R^k P_k(Z/R) as an expanded polynomial in X, Y, Z (from sympy's Legendre P_k)."""
    return _homogenise(sp.legendre(k, sp.Symbol("t")), k, ZS, XS**2 + YS**2 + ZS**2)


@functools.cache
def _solid_harmonic_zs(k: int) -> sp.Expr:
    """R^k P_k(Z/R) as a polynomial in z = Z and s = R^2."""
    return _homogenise(sp.legendre(k, sp.Symbol("t")), k, zs, ss)


def _reference(coeffs: tuple[float, ...]):
    """Lambdified exact potential, gradient, Hessian, vector potential (space axes)."""
    phi = sum(
        (sp.Float(f, 30) * _solid_harmonic_xyz(k) for k, f in enumerate(coeffs, 1)),
        sp.Integer(0),
    )
    v = [XS, YS, ZS]
    grad = [sp.diff(phi, a) for a in v]
    hess = [[sp.diff(g, b) for b in v] for g in grad]
    f_pot = sp.lambdify(v, phi, "numpy")
    f_grad = sp.lambdify(v, grad, "numpy")
    f_hess = sp.lambdify(v, hess, "numpy")

    def pot(P):
        return np.broadcast_to(f_pot(*P.T), (len(P),)).astype(float)

    def gradient(P):
        return np.stack([np.broadcast_to(c, (len(P),)) for c in f_grad(*P.T)], axis=1)

    def hessian(P):
        rows = f_hess(*P.T)
        return np.stack(
            [np.stack([np.broadcast_to(c, (len(P),)) for c in row], axis=1) for row in rows],
            axis=1,
        )

    return pot, gradient, hessian


def _random_coeffs(rng: np.random.Generator, degree: int) -> tuple[float, ...]:
    return tuple(float(x) for x in rng.uniform(-1.5, 1.5, size=degree))


def _points(rng: np.random.Generator, n: int = 40) -> np.ndarray:
    pts = rng.normal(size=(n, 3)) * rng.uniform(0.1, 2.0, size=(n, 1))
    pts[0] = 0.0  # the origin
    pts[1] = [0.0, 0.0, 1.3]  # on the axis
    pts[2] = [0.7, -0.4, 0.0]  # in the equatorial plane
    return pts


def _rotations(rng: np.random.Generator, m: int) -> np.ndarray:
    """Body-to-space rotation matrices, shape (m, 3, 3)."""
    return Rotation.random(m, random_state=np.random.default_rng(rng.integers(2**32))).as_matrix()


@pytest.mark.parametrize("degree", [1, 2, 3, 4, 5, 6])
def test_space_axes_match_sympy(degree: int) -> None:
    rng = np.random.default_rng(RNG_SEED + degree)
    coeffs = _random_coeffs(rng, degree)
    field = AxisymmetricField(coeffs)
    pot, grad, hess = _reference(coeffs)
    P = _points(rng)
    scale = 1.0 + np.max(np.linalg.norm(P, axis=1)) ** degree
    np.testing.assert_allclose(field.potential(P), pot(P), rtol=0, atol=1e-13 * scale * degree)
    np.testing.assert_allclose(field.gradient(P), grad(P), rtol=0, atol=1e-13 * scale * degree)
    np.testing.assert_allclose(field.hessian(P), hess(P), rtol=0, atol=1e-13 * scale * degree)


@pytest.mark.parametrize("degree", [1, 2, 4, 6])
def test_gamma_derivative_matches_sympy(degree: int) -> None:
    """dPhi/dgamma = dPhi/dz(z = r.gamma, s = |r|^2) r, from sympy's polynomial in (z, s)."""
    rng = np.random.default_rng(RNG_SEED + 10 * degree)
    coeffs = _random_coeffs(rng, degree)
    phi = sum(
        (sp.Float(f, 30) * _solid_harmonic_zs(k) for k, f in enumerate(coeffs, 1)), sp.Integer(0)
    )
    dphi_dz = sp.lambdify([zs, ss], sp.diff(phi, zs), "numpy")
    r = _points(rng, 12)
    gammas = _rotations(rng, 5)[:, 2, :]
    Z = gammas @ r.T
    S = np.broadcast_to(np.sum(r * r, axis=1), Z.shape)
    expected = np.broadcast_to(dphi_dz(Z, S), Z.shape)[:, :, None] * r[None]
    got = AxisymmetricField(coeffs).gamma_derivative(r, gammas)
    assert got.shape == (5, 12, 3)
    np.testing.assert_allclose(got, expected, rtol=0, atol=1e-12 * 3.0**degree)


def test_gamma_derivative_tangential_part_by_finite_differences() -> None:
    """Along curves on the unit sphere, d/dt Phi(r; gamma(t)) = dPhi/dgamma . gamma'(t)."""
    rng = np.random.default_rng(RNG_SEED + 1)
    field = AxisymmetricField(_random_coeffs(rng, 5))
    r = _points(rng, 15)
    gamma = _rotations(rng, 1)[0, 2, :]
    direction = np.cross(gamma, rng.normal(size=3))
    direction /= np.linalg.norm(direction)
    h = 1e-4

    def on_sphere(t: float) -> np.ndarray:
        return (np.cos(t) * gamma + np.sin(t) * direction)[None]

    # 4th-order central difference in t; gamma'(0) = direction.
    fd = (
        -field.potential_body(r, on_sphere(2 * h))
        + 8 * field.potential_body(r, on_sphere(h))
        - 8 * field.potential_body(r, on_sphere(-h))
        + field.potential_body(r, on_sphere(-2 * h))
    ) / (12 * h)
    exact = field.gamma_derivative(r, gamma[None]) @ direction
    np.testing.assert_allclose(exact, fd, rtol=0, atol=1e-9)


@pytest.mark.parametrize("degree", [2, 3, 5, 6, 8])
def test_harmonic(degree: int) -> None:
    rng = np.random.default_rng(RNG_SEED + 100 + degree)
    field = AxisymmetricField(_random_coeffs(rng, degree))
    P = _points(rng, 200)
    H = field.hessian(P)
    trace = np.trace(H, axis1=1, axis2=2)
    size = np.linalg.norm(H, axis=(1, 2))
    assert np.all(np.abs(trace) <= 1e-13 * (size + 1e-300) * degree)
    np.testing.assert_array_equal(H, np.swapaxes(H, 1, 2))
    gammas = _rotations(rng, 4)[:, 2, :]
    Hb = field.hessian_body(P[:20], gammas)
    trace_b = np.trace(Hb, axis1=2, axis2=3)
    assert np.all(np.abs(trace_b) <= 1e-13 * (np.linalg.norm(Hb, axis=(2, 3)) + 1e-300) * degree)


def test_gradient_and_hessian_by_finite_differences() -> None:
    rng = np.random.default_rng(RNG_SEED + 2)
    field = AxisymmetricField(_random_coeffs(rng, 6))
    P = _points(rng, 30)
    h = 1e-3
    fd_grad = np.empty_like(P)
    fd_hess = np.empty((len(P), 3, 3))
    for c in range(3):
        e = np.zeros(3)
        e[c] = h
        # 4th-order central differences.
        fd_grad[:, c] = (
            -field.potential(P + 2 * e)
            + 8 * field.potential(P + e)
            - 8 * field.potential(P - e)
            + field.potential(P - 2 * e)
        ) / (12 * h)
        fd_hess[:, :, c] = (
            -field.gradient(P + 2 * e)
            + 8 * field.gradient(P + e)
            - 8 * field.gradient(P - e)
            + field.gradient(P - 2 * e)
        ) / (12 * h)
    scale = 1.0 + np.max(np.linalg.norm(P, axis=1)) ** 6
    np.testing.assert_allclose(field.gradient(P), fd_grad, rtol=0, atol=1e-9 * scale)
    np.testing.assert_allclose(field.hessian(P), fd_hess, rtol=0, atol=1e-9 * scale)


@pytest.mark.parametrize("degree", [1, 2, 3, 6])
def test_body_axes_match_rotated_space_axes(degree: int) -> None:
    rng = np.random.default_rng(RNG_SEED + 200 + degree)
    field = AxisymmetricField(_random_coeffs(rng, degree))
    r = _points(rng, 25)
    Rs = _rotations(rng, 7)
    gammas = Rs[:, 2, :]  # R^T e_Z is the third row of R
    X = np.einsum("mab,nb->mna", Rs, r)  # X = R r
    tol = 1e-13 * (1.0 + np.max(np.linalg.norm(r, axis=1)) ** degree) * degree
    pot = np.stack([field.potential(x) for x in X])
    grad = np.einsum("mba,mnb->mna", Rs, np.stack([field.gradient(x) for x in X]))
    hess = np.einsum("mba,mnbc,mcd->mnad", Rs, np.stack([field.hessian(x) for x in X]), Rs)
    psi = np.stack([field.flux_function(x) for x in X])
    vec = np.einsum("mba,mnb->mna", Rs, np.stack([field.vector_potential(x) for x in X]))
    np.testing.assert_allclose(field.potential_body(r, gammas), pot, rtol=0, atol=tol)
    np.testing.assert_allclose(field.gradient_body(r, gammas), grad, rtol=0, atol=tol)
    np.testing.assert_allclose(field.hessian_body(r, gammas), hess, rtol=0, atol=tol)
    np.testing.assert_allclose(field.flux_function_body(r, gammas), psi, rtol=0, atol=tol)
    np.testing.assert_allclose(field.vector_potential_body(r, gammas), vec, rtol=0, atol=tol)


@settings(max_examples=30, deadline=None)
@given(
    coeffs=st.lists(st.floats(-2.0, 2.0), min_size=1, max_size=5),
    quat=st.lists(st.floats(-1.0, 1.0), min_size=4, max_size=4).filter(
        lambda q: sum(x * x for x in q) > 0.1
    ),
    point=st.lists(st.floats(-2.0, 2.0), min_size=3, max_size=3),
)
def test_body_space_consistency_property(
    coeffs: list[float], quat: list[float], point: list[float]
) -> None:
    field = AxisymmetricField(coeffs)
    R = Rotation.from_quat(quat).as_matrix()
    r = np.array([point])
    X = r @ R.T
    scale = 1e-12 * (1.0 + 2.0**5) * 4
    np.testing.assert_allclose(
        field.potential_body(r, R[2][None])[0], field.potential(X), rtol=0, atol=scale
    )
    np.testing.assert_allclose(
        field.gradient_body(r, R[2][None])[0], field.gradient(X) @ R, rtol=0, atol=scale
    )


def test_paper_field() -> None:
    a1, a2 = 0.7, -0.45
    field = AxisymmetricField.from_paper(a1, a2)
    assert field.legendre == (a1, 2 * a2)
    rng = np.random.default_rng(RNG_SEED + 3)
    P = _points(rng)
    X, Y, Z = P.T
    np.testing.assert_allclose(
        field.potential(P), a1 * Z + a2 * (3 * Z**2 - (X**2 + Y**2 + Z**2)), rtol=0, atol=1e-14
    )
    B = -field.gradient(P)
    np.testing.assert_allclose(
        B, np.stack([2 * a2 * X, 2 * a2 * Y, -a1 - 4 * a2 * Z], axis=1), rtol=0, atol=1e-14
    )


@pytest.mark.parametrize("degree", [1, 2, 3, 4, 5, 6])
def test_vector_potential_curl_is_field_exactly(degree: int) -> None:
    """Symbolic: A = -g (e_Z x X), g = sum f_k R^(k-1) P_k'(Z/R) / (k+1), has curl A = -grad Phi;
    and the code's A equals that expression."""
    rng = np.random.default_rng(RNG_SEED + 300 + degree)
    coeffs = _random_coeffs(rng, degree)
    fr = [sp.Rational(round(f * 1000), 1000) for f in coeffs]  # exact rationals
    t = sp.Symbol("t")
    rsq = XS**2 + YS**2 + ZS**2
    g = sum(
        (
            f / (k + 1) * _homogenise(sp.diff(sp.legendre(k, t), t), k - 1, ZS, rsq)
            for k, f in enumerate(fr, 1)
        ),
        sp.Integer(0),
    )
    A = [g * YS, -g * XS, sp.Integer(0)]
    phi = sum((f * _solid_harmonic_xyz(k) for k, f in enumerate(fr, 1)), sp.Integer(0))
    curl = [
        sp.diff(A[2], YS) - sp.diff(A[1], ZS),
        sp.diff(A[0], ZS) - sp.diff(A[2], XS),
        sp.diff(A[1], XS) - sp.diff(A[0], YS),
    ]
    B = [-sp.diff(phi, v) for v in (XS, YS, ZS)]
    assert all(sp.expand(c - b) == 0 for c, b in zip(curl, B, strict=True))
    # Divergence-free gauge.
    assert sp.expand(sp.diff(A[0], XS) + sp.diff(A[1], YS)) == 0
    field = AxisymmetricField(tuple(float(f) for f in fr))
    P = _points(rng, 20)
    A_ref = sp.lambdify([XS, YS, ZS], A, "numpy")(*P.T)
    A_ref = np.stack([np.broadcast_to(c, (len(P),)) for c in A_ref], axis=1)
    np.testing.assert_allclose(field.vector_potential(P), A_ref, rtol=0, atol=1e-13 * 3**degree)


def test_vector_potential_curl_by_finite_differences() -> None:
    rng = np.random.default_rng(RNG_SEED + 4)
    field = AxisymmetricField(_random_coeffs(rng, 6))
    P = _points(rng, 30)
    h = 1e-3
    jac = np.empty((len(P), 3, 3))  # jac[:, i, c] = dA_i/dX_c
    for c in range(3):
        e = np.zeros(3)
        e[c] = h
        jac[:, :, c] = (
            -field.vector_potential(P + 2 * e)
            + 8 * field.vector_potential(P + e)
            - 8 * field.vector_potential(P - e)
            + field.vector_potential(P - 2 * e)
        ) / (12 * h)
    curl = np.stack(
        [jac[:, 2, 1] - jac[:, 1, 2], jac[:, 0, 2] - jac[:, 2, 0], jac[:, 1, 0] - jac[:, 0, 1]],
        axis=1,
    )
    scale = 1.0 + np.max(np.linalg.norm(P, axis=1)) ** 6
    np.testing.assert_allclose(curl, -field.gradient(P), rtol=0, atol=1e-9 * scale)


def test_flux_function_is_rho_times_azimuthal_potential() -> None:
    """psi = rho A_phi = (X x A)_Z; psi vanishes on the axis; B_Z = (1/rho) dpsi/drho."""
    rng = np.random.default_rng(RNG_SEED + 5)
    field = AxisymmetricField(_random_coeffs(rng, 5))
    P = _points(rng, 30)
    A = field.vector_potential(P)
    psi = field.flux_function(P)
    np.testing.assert_allclose(psi, P[:, 0] * A[:, 1] - P[:, 1] * A[:, 0], rtol=0, atol=1e-13)
    axis = np.array([[0.0, 0.0, z] for z in (-1.5, 0.0, 0.4, 2.0)])
    np.testing.assert_array_equal(field.flux_function(axis), 0.0)
    # Flux through the disc of radius rho at height Z is 2 pi psi (Stokes).
    rho, z = 0.8, 0.3
    nodes, wts = np.polynomial.legendre.leggauss(20)
    radii = 0.5 * rho * (nodes + 1.0)
    Bz = -field.gradient(np.stack([radii, 0 * radii, z + 0 * radii], axis=1))[:, 2]
    flux = np.sum(0.5 * rho * wts * 2 * np.pi * radii * Bz)
    np.testing.assert_allclose(
        2 * np.pi * field.flux_function(np.array([[rho, 0.0, z]]))[0], flux, rtol=1e-13
    )


def test_uniform_field_flux_function() -> None:
    """B = -b e_Z (Phi = b Z): psi = -b rho^2 / 2, A = (b Y / 2, -b X / 2, 0)."""
    b = 1.7
    field = AxisymmetricField((b,))
    P = np.array([[0.3, -0.2, 0.5], [1.0, 2.0, -3.0]])
    np.testing.assert_allclose(
        field.flux_function(P), -b * (P[:, 0] ** 2 + P[:, 1] ** 2) / 2, rtol=1e-15
    )
    np.testing.assert_allclose(
        field.vector_potential(P),
        np.stack([b * P[:, 1] / 2, -b * P[:, 0] / 2, 0 * P[:, 0]], axis=1),
        rtol=1e-15,
    )


def test_origin_is_regular() -> None:
    f1, f2, f3 = 0.4, -1.1, 0.9
    field = AxisymmetricField((f1, f2, f3))
    origin = np.zeros((1, 3))
    assert field.potential(origin)[0] == 0.0
    np.testing.assert_array_equal(field.gradient(origin)[0], [0.0, 0.0, f1])
    np.testing.assert_allclose(field.hessian(origin)[0], f2 * np.diag([-1.0, -1.0, 2.0]))
    np.testing.assert_array_equal(field.flux_function(origin), [0.0])
    np.testing.assert_array_equal(field.vector_potential(origin), np.zeros((1, 3)))
    gammas = np.array([[0.0, 0.0, 1.0], [0.6, 0.0, 0.8]])
    np.testing.assert_array_equal(field.gradient_body(origin, gammas)[:, 0], f1 * gammas)
    assert np.all(np.isfinite(field.hessian_body(origin, gammas)))


def test_degree_zero_field_and_shapes() -> None:
    assert AxisymmetricField(()).is_zero
    assert AxisymmetricField((0.0, 0.0)).is_zero
    assert AxisymmetricField((0.0, 0.0)).degree == 0
    assert AxisymmetricField([1.0, 0.0, 2.0, 0.0]).degree == 3
    assert not AxisymmetricField([0.0, 1e-30]).is_zero
    field = AxisymmetricField(())
    r = np.ones((4, 3))
    gammas = np.array([[0.0, 0.0, 1.0]] * 2)
    assert field.potential(r).shape == (4,)
    assert field.gradient(r).shape == (4, 3)
    assert field.hessian(r).shape == (4, 3, 3)
    assert field.potential_body(r, gammas).shape == (2, 4)
    assert field.gradient_body(r, gammas).shape == (2, 4, 3)
    assert field.hessian_body(r, gammas).shape == (2, 4, 3, 3)
    assert field.gamma_derivative(r, gammas).shape == (2, 4, 3)
    assert field.flux_function_body(r, gammas).shape == (2, 4)
    assert not np.any(field.gradient_body(r, gammas))
    empty = np.zeros((0, 3))
    one = AxisymmetricField((1.0, 2.0))
    assert one.gradient_body(empty, gammas).shape == (2, 0, 3)
    assert one.gradient_body(r, np.zeros((0, 3))).shape == (0, 4, 3)


def test_trailing_zero_coefficients_do_not_change_values() -> None:
    rng = np.random.default_rng(RNG_SEED + 6)
    P = _points(rng, 10)
    a = AxisymmetricField((0.3, -0.5))
    b = AxisymmetricField((0.3, -0.5, 0.0, 0.0))
    np.testing.assert_array_equal(a.hessian(P), b.hessian(P))
    assert a != b  # the stored coefficients differ; the field does not


@pytest.mark.parametrize(
    ("make", "name"),
    [
        (lambda: AxisymmetricField((1.0, float("nan"))), "legendre"),
        (lambda: AxisymmetricField((1.0, float("inf"))), "legendre"),
        (lambda: AxisymmetricField([[1.0, 2.0]]), "legendre"),
        (lambda: AxisymmetricField(("a",)), "legendre"),
        (lambda: AxisymmetricField.from_paper(float("nan"), 1.0), "a1"),
        (lambda: AxisymmetricField.from_paper(1.0, "x"), "a2"),
        (lambda: AxisymmetricField((1.0,)).potential(np.ones((3, 2))), "points"),
        (lambda: AxisymmetricField((1.0,)).gradient([[0.0, np.nan, 1.0]]), "points"),
        (lambda: AxisymmetricField((1.0,)).hessian(np.ones(3)), "points"),
        (
            lambda: AxisymmetricField((1.0,)).gradient_body(np.ones((2, 3)), [[0.0, 0.0, 1.1]]),
            "gammas",
        ),
        (
            lambda: AxisymmetricField((1.0,)).potential_body(
                np.ones((2, 3)), [[0.0, 0.0, 1.0 + 2e-9]]
            ),
            "gammas",
        ),
        (lambda: AxisymmetricField((1.0,)).potential_body(np.ones((2, 3)), [0, 0, 1]), "gammas"),
        (
            lambda: AxisymmetricField((1.0,)).gamma_derivative(
                np.ones((2, 3)), [[0.0, np.inf, 1.0]]
            ),
            "gammas",
        ),
        (
            lambda: AxisymmetricField((1.0,)).flux_function_body(np.ones((2, 4)), [[0, 0, 1.0]]),
            "points",
        ),
    ],
)
def test_bad_input_names_the_input(make, name: str) -> None:
    with pytest.raises(InputError, match=f"^{name}"):
        make()


def test_nearly_unit_gamma_is_accepted_as_given() -> None:
    field = AxisymmetricField((1.0,))
    gamma = np.array([[0.0, 0.0, 1.0 + 5e-10]])
    out = field.potential_body(np.array([[0.0, 0.0, 1.0]]), gamma)
    assert out[0, 0] == gamma[0, 2]  # used as given, not renormalised


@pytest.mark.parametrize("block", [1, 5, 7, 64])
def test_blocked_evaluation_matches_one_block(monkeypatch, block: int) -> None:
    """Cache-sized blocks (rows and columns) reproduce a single whole-array evaluation."""
    import chargedesign.fields as fields_module

    rng = np.random.default_rng(RNG_SEED + 7)
    field = AxisymmetricField(_random_coeffs(rng, 4))
    r = _points(rng, 23)
    gammas = _rotations(rng, 9)[:, 2, :]
    names = ["potential_body", "gradient_body", "hessian_body", "gamma_derivative"]
    names += ["flux_function_body", "vector_potential_body"]
    whole = {nm: getattr(field, nm)(r, gammas) for nm in names}
    monkeypatch.setattr(fields_module, "_BLOCK_ELEMENTS", block)
    for nm in names:
        # Z = G @ r.T may round differently by block shape (BLAS kernels): a few ulps.
        scale = np.max(np.abs(whole[nm]))
        np.testing.assert_allclose(
            getattr(field, nm)(r, gammas), whole[nm], rtol=0, atol=1e-14 * scale, err_msg=nm
        )


def test_benchmark_quick_run_reports_a_table() -> None:
    from chargedesign.bench.fields import run

    (table,) = run(quick=True)
    assert [row[0] for row in table.rows] == [1, 2, 4, 6]
    assert all(len(row) == len(table.columns) for row in table.rows)
    assert all(np.isfinite(v) and v > 0 for row in table.rows for v in row[1:])
