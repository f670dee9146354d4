"""The Coulomb field's forms against each other, and the sphere sampler they are checked on."""

import math

import numpy as np
import pytest

from chargedesign.constants import COULOMB, EPSILON_0
from chargedesign.physical.coulomb import (
    coulomb_field,
    coulomb_field_gemm,
    coulomb_kernel,
    point_charge_field,
)
from chargedesign.sampling import GOLDEN_ANGLE, fibonacci_sphere


def test_the_matrix_product_field_equals_the_direct_sum_on_random_bodies():
    rng = np.random.default_rng(7)
    for n, scale, radius in ((150, 0.05, 0.003), (40, 1.0, 0.06), (3, 1e-3, 1e-5)):
        sources = rng.uniform(-scale, scale, (n, 3))
        charges = rng.normal(size=n) * 1e-9
        points = (sources[:, None, :] + radius * fibonacci_sphere(60)[None]).reshape(-1, 3)
        direct = coulomb_field(sources, charges, points)
        fast = coulomb_field_gemm(sources, charges, points)
        rel = np.linalg.norm(fast - direct, axis=1) / np.linalg.norm(direct, axis=1)
        assert rel.max() < 1e-10


def test_the_kernel_times_the_charges_is_the_direct_sum():
    """The cone programs' rows (field per unit charge) applied to charges give the field."""
    rng = np.random.default_rng(11)
    sources = rng.uniform(-0.05, 0.05, (80, 3))
    charges = rng.normal(size=80) * 1e-9
    points = (sources[:20, None, :] + 0.003 * fibonacci_sphere(30)[None]).reshape(-1, 3)
    direct = coulomb_field(sources, charges, points)
    kernel = coulomb_kernel(sources, points)
    assert kernel.shape == (len(points), 3, len(sources))
    rel = np.linalg.norm(kernel @ charges - direct, axis=1) / np.linalg.norm(direct, axis=1)
    assert rel.max() < 1e-12
    # a scale is the program's units in one product
    np.testing.assert_allclose(coulomb_kernel(sources, points, 2.0), kernel * 2.0 / COULOMB)


def test_one_charge_gives_the_inverse_square_field_along_the_separation():
    source = np.array([[0.01, -0.02, 0.03]])
    q = -3e-9
    points = source + 0.25 * fibonacci_sphere(7)
    for kernel in (coulomb_field, coulomb_field_gemm):
        e = kernel(source, np.array([q]), points)
        np.testing.assert_allclose(
            np.linalg.norm(e, axis=1), point_charge_field(q, 0.25), rtol=1e-12
        )
        # a negative charge's field points at it
        np.testing.assert_allclose(
            e / np.linalg.norm(e, axis=1)[:, None], (source - points) / 0.25, atol=1e-12
        )
    assert point_charge_field(q, 0.25) == pytest.approx(
        3e-9 / (4 * math.pi * EPSILON_0 * 0.0625), rel=1e-15
    )


def test_the_sphere_sampler_gives_equal_area_unit_vectors_on_the_golden_spiral():
    n = 101
    u = fibonacci_sphere(n)
    np.testing.assert_allclose(np.linalg.norm(u, axis=1), 1.0, atol=1e-15)
    np.testing.assert_allclose(u[:, 2], 1.0 - (2.0 * np.arange(n) + 1.0) / n, atol=1e-15)
    # nearly uniform: the mean of the unit vectors is small
    assert np.linalg.norm(u.mean(axis=0)) < 1e-2
    # the phase turns every point by the same angle about z
    v = fibonacci_sphere(n, phase=0.0)
    turn = np.arctan2(u[:, 1], u[:, 0]) - np.arctan2(v[:, 1], v[:, 0])
    np.testing.assert_allclose(np.mod(turn, 2 * np.pi), 0.5 * GOLDEN_ANGLE, atol=1e-9)
