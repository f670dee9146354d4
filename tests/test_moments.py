"""Tests of chargedesign.moments against independent definitions: direct loops, a sphere
quadrature built here, scipy's Legendre polynomials and complex spherical harmonics."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation
from scipy.special import eval_legendre, sph_harm_y

from chargedesign.errors import InputError
from chargedesign.moments import (
    cartesian_moment_tensor,
    cartesian_moments,
    dipole_moments,
    moment_key,
    moment_keys,
    monomial_matrix,
    multipole_moments,
    solid_harmonic_index,
    solid_harmonics,
)
from chargedesign.validation import parse_moment_key

RNG_SEED = 7_2024


def _cloud(rng: np.random.Generator, n: int = 30) -> tuple[np.ndarray, np.ndarray]:
    pts = rng.normal(size=(n, 3)) * rng.uniform(0.2, 1.5, size=(n, 1))
    pts[0] = 0.0
    return pts, rng.uniform(-1.0, 1.0, size=n)


# ------------------------------------------------------------------ existing key helpers


def test_key_helpers_unchanged() -> None:
    assert moment_key((2, 0, 1)) == "xxz"
    assert parse_moment_key("xyy") == (1, 2, 0)
    assert moment_keys(2) == ["xx", "xy", "xz", "yy", "yz", "zz"]
    with pytest.raises(InputError):
        parse_moment_key("zx")


# ------------------------------------------------------------------------ Cartesian


@pytest.mark.parametrize("order", [0, 1, 2, 3, 4])
def test_cartesian_tensor_matches_loop_definition(order: int) -> None:
    rng = np.random.default_rng(RNG_SEED + order)
    pts, w = _cloud(rng)
    T = cartesian_moment_tensor(pts, w, order)
    assert T.shape == (3,) * order
    for idx in itertools.product(range(3), repeat=order):
        direct = sum(w[j] * math.prod(pts[j, a] for a in idx) for j in range(len(pts)))
        assert T[idx] == pytest.approx(direct, abs=1e-13 * (1 + abs(direct)))
    # Symmetric under every permutation of its indices.
    for perm in itertools.permutations(range(order)):
        np.testing.assert_allclose(np.transpose(T, perm), T, rtol=0, atol=1e-14)


@pytest.mark.parametrize("order", [0, 1, 2, 3, 4])
def test_cartesian_moments_agree_with_tensor_and_einsum(order: int) -> None:
    rng = np.random.default_rng(RNG_SEED + 10 + order)
    pts, w = _cloud(rng)
    T = cartesian_moment_tensor(pts, w, order)
    moments = cartesian_moments(pts, w, order)
    assert list(moments) == moment_keys(order)
    for key, value in moments.items():
        idx = tuple("xyz".index(ch) for ch in key)
        assert value == pytest.approx(float(T[idx]), abs=1e-13)
    if order == 2:
        np.testing.assert_allclose(np.einsum("j,ja,jb->ab", w, pts, pts), T, atol=1e-14)
    if order == 3:
        np.testing.assert_allclose(np.einsum("j,ja,jb,jc->abc", w, pts, pts, pts), T, atol=1e-14)


@settings(max_examples=25, deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1),
    order=st.integers(0, 4),
)
def test_cartesian_tensor_rotates_as_a_tensor(seed: int, order: int) -> None:
    """Moment tensor of rotated points = rotated tensor (one rotation per index)."""
    rng = np.random.default_rng(seed)
    pts, w = _cloud(rng, 12)
    Q = Rotation.random(random_state=rng).as_matrix()
    T = cartesian_moment_tensor(pts, w, order)
    rotated = T
    for axis in range(order):
        rotated = np.moveaxis(np.tensordot(Q, rotated, axes=([1], [axis])), 0, axis)
    np.testing.assert_allclose(
        cartesian_moment_tensor(pts @ Q.T, w, order), rotated, rtol=0, atol=1e-12
    )


def test_dipole_moments_match_loop_definition() -> None:
    rng = np.random.default_rng(RNG_SEED + 20)
    pts, _ = _cloud(rng, 15)
    sig = rng.normal(size=(15, 3))
    for order in range(4):
        got = dipole_moments(pts, sig, order)
        assert len(got) == 3 * len(moment_keys(order))
        for key in moment_keys(order):
            i, j, k = parse_moment_key(key)
            for c, axis in enumerate("xyz"):
                direct = sum(
                    sig[p, c] * pts[p, 0] ** i * pts[p, 1] ** j * pts[p, 2] ** k
                    for p in range(len(pts))
                )
                assert got[f"{axis}:{key}"] == pytest.approx(direct, abs=1e-13)
    assert dipole_moments(pts, sig, 0)["z:"] == pytest.approx(sig[:, 2].sum(), abs=1e-14)


def test_empty_point_sets() -> None:
    assert cartesian_moments([], [], 2) == dict.fromkeys(moment_keys(2), 0.0)
    assert cartesian_moment_tensor(np.zeros((0, 3)), np.zeros(0), 2).shape == (3, 3)
    assert dipole_moments([], [], 1)["x:y"] == 0.0
    assert multipole_moments([], [], 3).shape == (16,)
    assert solid_harmonics(np.zeros((0, 3)), 2).shape == (0, 9)


# ------------------------------------------------------------------ solid harmonics


def _sphere_rule(n_theta: int, n_phi: int) -> tuple[np.ndarray, np.ndarray]:
    """Gauss-Legendre in cos(theta) x trapezoid in phi: exact for polynomials of degree
    <= 2 n_theta - 1 in cos(theta) and trigonometric degree < n_phi in phi."""
    t, wt = np.polynomial.legendre.leggauss(n_theta)
    phi = 2 * np.pi * np.arange(n_phi) / n_phi
    T, P = np.meshgrid(t, phi, indexing="ij")
    s = np.sqrt(1 - T**2)
    points = np.stack([s * np.cos(P), s * np.sin(P), T], axis=-1).reshape(-1, 3)
    weights = (wt[:, None] * np.full(n_phi, 2 * np.pi / n_phi)[None, :]).reshape(-1)
    return points, weights


def test_orthogonality_on_the_unit_sphere() -> None:
    lmax = 8
    points, weights = _sphere_rule(lmax + 2, 2 * lmax + 3)
    assert weights.sum() == pytest.approx(4 * np.pi, rel=1e-14)
    R = solid_harmonics(points, lmax)
    gram = R.T @ (weights[:, None] * R)
    expected = np.diag([4 * np.pi / (2 * l + 1) for l in range(lmax + 1) for _ in range(2 * l + 1)])
    np.testing.assert_allclose(gram, expected, rtol=0, atol=1e-13)


def test_addition_theorem_against_scipy_legendre() -> None:
    rng = np.random.default_rng(RNG_SEED + 30)
    lmax = 10
    a = rng.normal(size=(40, 3))
    b = rng.normal(size=(40, 3))
    Ra, Rb = solid_harmonics(a, lmax), solid_harmonics(b, lmax)
    na, nb = np.linalg.norm(a, axis=1), np.linalg.norm(b, axis=1)
    cos = np.sum(a * b, axis=1) / (na * nb)
    for l in range(lmax + 1):
        cols = slice(l * l, (l + 1) ** 2)
        lhs = np.sum(Ra[:, cols] * Rb[:, cols], axis=1)
        rhs = (na * nb) ** l * eval_legendre(l, cos)
        # Pointwise: the error scales with |a|^l |b|^l, the size of the terms summed.
        assert np.all(np.abs(lhs - rhs) <= 1e-14 * (l + 1) ** 2 * (na * nb) ** l)


@pytest.mark.parametrize("l", range(7))
def test_against_scipy_complex_spherical_harmonics(l: int) -> None:
    """R_lm from scipy's Y_l^m (which carries the Condon-Shortley phase (-1)^m):
    R_l,m = sqrt(2) (-1)^m Re, R_l,-m = sqrt(2) (-1)^m Im (m > 0), times
    sqrt(4 pi / (2l + 1)) r^l."""
    rng = np.random.default_rng(RNG_SEED + 40 + l)
    pts = rng.normal(size=(50, 3))
    r = np.linalg.norm(pts, axis=1)
    theta = np.arccos(np.clip(pts[:, 2] / r, -1.0, 1.0))
    phi = np.mod(np.arctan2(pts[:, 1], pts[:, 0]), 2 * np.pi)
    scale = np.sqrt(4 * np.pi / (2 * l + 1)) * r**l
    got = solid_harmonics(pts, l)
    for m in range(l + 1):
        Y = sph_harm_y(l, m, theta, phi)
        if m == 0:
            expected = {0: scale * Y.real}
        else:
            sign = (-1) ** m
            expected = {
                m: np.sqrt(2) * sign * scale * Y.real,
                -m: np.sqrt(2) * sign * scale * Y.imag,
            }
        for mm, values in expected.items():
            np.testing.assert_allclose(
                got[:, solid_harmonic_index(l, mm)],
                values,
                rtol=0,
                atol=1e-13 * (1 + np.max(r) ** l),
            )


def test_low_degrees_in_closed_form() -> None:
    rng = np.random.default_rng(RNG_SEED + 50)
    pts = rng.normal(size=(20, 3))
    x, y, z = pts.T
    r2 = x * x + y * y + z * z
    R = solid_harmonics(pts, 3)
    s3 = np.sqrt(3.0)
    closed = {
        (0, 0): np.ones_like(x),
        (1, -1): y,
        (1, 0): z,
        (1, 1): x,
        (2, -2): s3 * x * y,
        (2, -1): s3 * y * z,
        (2, 0): z * z - (x * x + y * y) / 2,
        (2, 1): s3 * x * z,
        (2, 2): s3 / 2 * (x * x - y * y),
        (3, 0): z * (2 * z * z - 3 * (x * x + y * y)) / 2,
        (3, 1): np.sqrt(3 / 8) * x * (4 * z * z - x * x - y * y),
        (3, -1): np.sqrt(3 / 8) * y * (4 * z * z - x * x - y * y),
        (3, 2): np.sqrt(15) / 2 * z * (x * x - y * y),
        (3, -2): np.sqrt(15) * x * y * z,
        (3, 3): np.sqrt(5 / 8) * x * (x * x - 3 * y * y),
        (3, -3): np.sqrt(5 / 8) * y * (3 * x * x - y * y),
    }
    for (l, m), values in closed.items():
        np.testing.assert_allclose(
            R[:, solid_harmonic_index(l, m)], values, rtol=0, atol=1e-13 * (1 + np.max(r2) ** 1.5)
        )


def test_origin_is_regular() -> None:
    R = solid_harmonics(np.zeros((2, 3)), 5)
    expected = np.zeros(36)
    expected[0] = 1.0
    np.testing.assert_array_equal(R, np.stack([expected, expected]))


def test_multipole_trace_relations_with_cartesian_moments() -> None:
    rng = np.random.default_rng(RNG_SEED + 60)
    pts, w = _cloud(rng, 25)
    Q = multipole_moments(pts, w, 3)
    M0 = cartesian_moments(pts, w, 0)
    M1 = cartesian_moments(pts, w, 1)
    M2 = cartesian_moments(pts, w, 2)
    M3 = cartesian_moments(pts, w, 3)
    s3 = np.sqrt(3.0)
    relations = {
        (0, 0): M0[""],
        (1, -1): M1["y"],
        (1, 0): M1["z"],
        (1, 1): M1["x"],
        (2, 0): M2["zz"] - (M2["xx"] + M2["yy"]) / 2,
        (2, 1): s3 * M2["xz"],
        (2, -1): s3 * M2["yz"],
        (2, 2): s3 / 2 * (M2["xx"] - M2["yy"]),
        (2, -2): s3 * M2["xy"],
        (3, 0): M3["zzz"] - 1.5 * (M3["xxz"] + M3["yyz"]),
        (3, 3): np.sqrt(5 / 8) * (M3["xxx"] - 3 * M3["xyy"]),
    }
    for (l, m), value in relations.items():
        assert Q[solid_harmonic_index(l, m)] == pytest.approx(value, abs=1e-13)
    # The trace-free part of the Cartesian tensor carries the l = 2 moments; the trace is
    # the l = 0 moment of |r|^2.
    T = cartesian_moment_tensor(pts, w, 2)
    assert np.trace(T) == pytest.approx(np.sum(w * np.sum(pts**2, axis=1)), abs=1e-13)


def test_multipoles_give_zonal_sums_by_the_addition_theorem() -> None:
    """sum_j w_j u_k(r_j; gamma) = sum_m Q_km R_km(gamma) for unit gamma (how the conditions
    engine turns a degree-k potential into moment conditions)."""
    rng = np.random.default_rng(RNG_SEED + 70)
    pts, w = _cloud(rng, 40)
    lmax = 6
    Q = multipole_moments(pts, w, lmax)
    gammas = rng.normal(size=(8, 3))
    gammas /= np.linalg.norm(gammas, axis=1)[:, None]
    Rg = solid_harmonics(gammas, lmax)
    norms = np.linalg.norm(pts, axis=1)
    for k in range(lmax + 1):
        cos = np.where(norms > 0, (gammas @ pts.T) / np.where(norms > 0, norms, 1.0), 0.0)
        direct = (w * norms**k * eval_legendre(k, cos)).sum(axis=1)
        cols = slice(k * k, (k + 1) ** 2)
        np.testing.assert_allclose(Rg[:, cols] @ Q[cols], direct, rtol=0, atol=1e-12)


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 2**32 - 1))
def test_degree_power_is_rotation_invariant(seed: int) -> None:
    """sum_m Q_lm^2 is unchanged when the points are rotated (the R_l. transform orthogonally)."""
    rng = np.random.default_rng(seed)
    pts, w = _cloud(rng, 10)
    Q = multipole_moments(pts, w, 5)
    Qr = multipole_moments(pts @ Rotation.random(random_state=rng).as_matrix().T, w, 5)
    for l in range(6):
        cols = slice(l * l, (l + 1) ** 2)
        np.testing.assert_allclose(
            np.sum(Qr[cols] ** 2), np.sum(Q[cols] ** 2), rtol=1e-11, atol=1e-12
        )


def test_monomial_matrix_consistent_with_cartesian_moments() -> None:
    rng = np.random.default_rng(RNG_SEED + 80)
    pts, w = _cloud(rng, 10)
    keys = moment_keys(3)
    np.testing.assert_allclose(
        monomial_matrix(pts, keys) @ w, list(cartesian_moments(pts, w, 3).values()), atol=0
    )


# ----------------------------------------------------------------------- bad input


@pytest.mark.parametrize(
    ("call", "name"),
    [
        (lambda: cartesian_moment_tensor(np.ones((3, 2)), np.ones(3), 2), "points"),
        (lambda: cartesian_moment_tensor(np.ones((3, 3)), np.ones(2), 2), "weights"),
        (lambda: cartesian_moment_tensor(np.ones((3, 3)), [1, np.nan, 1], 2), "weights"),
        (lambda: cartesian_moment_tensor(np.ones((3, 3)), np.ones(3), 9), "order"),
        (lambda: cartesian_moment_tensor(np.ones((3, 3)), np.ones(3), -1), "order"),
        (lambda: cartesian_moments(np.ones((3, 3)), np.ones(3), 2.0), "order"),
        (lambda: cartesian_moments(np.ones((3, 3)), np.ones(3), True), "order"),
        (lambda: cartesian_moments([[0, 0, np.inf]], [1.0], 1), "points"),
        (lambda: dipole_moments(np.ones((3, 3)), np.ones((2, 3)), 1), "moments"),
        (lambda: dipole_moments(np.ones((3, 3)), np.ones(3), 1), "moments"),
        (lambda: solid_harmonics(np.ones((3, 3)), -1), "lmax"),
        (lambda: solid_harmonics(np.ones(3), 2), "points"),
        (lambda: multipole_moments(np.ones((3, 3)), np.ones(4), 2), "weights"),
    ],
)
def test_bad_input_names_the_input(call, name: str) -> None:
    with pytest.raises(InputError, match=f"^{name}"):
        call()


def test_a_harmonic_index_out_of_range_is_a_callers_mistake() -> None:
    with pytest.raises(ValueError, match=r"^m: expected an integer in -2\.\.2"):
        solid_harmonic_index(2, 3)
