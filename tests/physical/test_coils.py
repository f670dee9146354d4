"""The field apparatus: circular loops by Biot-Savart, against the closed form on the axis, a
direct quadrature of the Biot-Savart integral off it, and the Legendre series."""

from __future__ import annotations

import math

import numpy as np
import pytest

from chargedesign.constants import MU_0
from chargedesign.fields import AxisymmetricField
from chargedesign.physical.coils import (
    COPPER_RESISTIVITY,
    CoilPair,
    apparatus_at,
    design_apparatus,
    loop_axis_field,
    loop_field,
    loop_legendre,
)

RADIUS, HEIGHT, CURRENT = 0.3, 0.12, 7.0


def biot_savart_quadrature(points: np.ndarray, segments: int = 4096) -> np.ndarray:
    """``B = mu0 I / (4 pi) sum dl x (x - l) / |x - l|^3`` over a polygon of the loop (the
    midpoint rule of a periodic integrand: exponentially accurate)."""
    phi = (np.arange(segments) + 0.5) * 2 * np.pi / segments
    wire = np.column_stack([RADIUS * np.cos(phi), RADIUS * np.sin(phi), np.full(segments, HEIGHT)])
    dl = np.column_stack([-np.sin(phi), np.cos(phi), np.zeros(segments)]) * (
        RADIUS * 2 * np.pi / segments
    )
    sep = points[:, None, :] - wire[None, :, :]
    dist3 = np.linalg.norm(sep, axis=2) ** 3
    return MU_0 * CURRENT / (4 * np.pi) * np.sum(np.cross(dl[None], sep) / dist3[..., None], axis=1)


def test_on_the_axis_the_elliptic_form_is_the_closed_form():
    z = np.linspace(-1.0, 1.0, 41)
    points = np.column_stack([np.zeros_like(z), np.zeros_like(z), z])
    b = loop_field(points, RADIUS, HEIGHT, CURRENT)
    np.testing.assert_allclose(b[:, 2], loop_axis_field(z, RADIUS, HEIGHT, CURRENT), rtol=1e-13)
    assert np.all(b[:, :2] == 0.0)
    # the centre of a loop: mu0 I / (2 a)
    centre = loop_axis_field(HEIGHT, RADIUS, HEIGHT, CURRENT)
    assert centre == pytest.approx(MU_0 * CURRENT / (2 * RADIUS), rel=1e-15)


def test_off_the_axis_the_elliptic_form_is_the_biot_savart_integral():
    rng = np.random.default_rng(3)
    points = rng.uniform(-0.5, 0.5, size=(30, 3))
    direct = biot_savart_quadrature(points)
    np.testing.assert_allclose(
        loop_field(points, RADIUS, HEIGHT, CURRENT), direct, rtol=1e-9, atol=1e-12 * MU_0
    )


def test_inside_the_sphere_through_the_loop_the_field_is_its_legendre_series():
    rng = np.random.default_rng(4)
    points = rng.normal(size=(40, 3))
    points *= 0.1 / np.linalg.norm(points, axis=1)[:, None]  # r = 0.1, D = 0.323
    series = AxisymmetricField(loop_legendre(RADIUS, HEIGHT, CURRENT, 30))
    np.testing.assert_allclose(
        -series.gradient(points), loop_field(points, RADIUS, HEIGHT, CURRENT), rtol=1e-12
    )


def test_helmholtz_and_maxwell_pairs_cancel_their_next_term():
    helmholtz = CoilPair("helmholtz", 0.5, 0.5, 100.0, 2.0).legendre()
    maxwell = CoilPair("maxwell", 0.5, math.sqrt(3) * 0.5, 100.0, 2.0).legendre()
    # Helmholtz: odd degrees only, no degree 3; Maxwell: even degrees only, no degree 4
    assert abs(helmholtz[2]) < 1e-13 * abs(helmholtz[0])
    assert np.all(np.abs(helmholtz[1::2]) < 1e-13 * abs(helmholtz[0]))
    assert abs(maxwell[3]) < 1e-13 * abs(maxwell[1])
    assert np.all(np.abs(maxwell[0::2]) < 1e-13 * abs(maxwell[1]))
    # the textbook Helmholtz field at the centre: (4/5)^(3/2) mu0 N I / a
    b0 = -helmholtz[0]
    assert b0 == pytest.approx((4 / 5) ** 1.5 * MU_0 * 200.0 / 0.5, rel=1e-13)


def test_the_apparatus_makes_the_papers_field_and_states_its_cost():
    a1, a2, region = 0.01, 0.05, 0.1
    apparatus = apparatus_at(a1, a2, 0.6, region, 1e-3)
    total = np.sum([p.legendre() for p in apparatus.pairs], axis=0)
    assert total[0] == pytest.approx(a1, rel=1e-12)
    assert total[1] == pytest.approx(2 * a2, rel=1e-12)
    np.testing.assert_allclose(apparatus.error_legendre[2:], total[2:], rtol=0, atol=0)
    pair = apparatus.pairs[1]
    # ohmic power of the copper: rho (2 coils x 2 pi a N) I^2 / A
    length = 2 * 2 * math.pi * pair.radius * pair.turns
    assert pair.power_W == pytest.approx(COPPER_RESISTIVITY * length * pair.current**2 / 1e-6)


def test_larger_coils_make_a_smaller_harmonic_error():
    small = apparatus_at(0.0, 0.05, 0.3, 0.1, 1e-3).harmonic_error
    large = apparatus_at(0.0, 0.05, 0.6, 0.1, 1e-3).harmonic_error
    # Maxwell pair: the first error term is degree 6, |B_error| / |B| ~ (r / a)^4
    assert large / small == pytest.approx(2.0**-4, rel=0.1)
    chosen = design_apparatus(0.0, 0.05, 0.1, 1e-4)
    assert chosen.harmonic_error < 1e-4
