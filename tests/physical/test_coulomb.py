"""The Coulomb field's forms against each other, and the sphere sampler they are checked on."""

import math

import numpy as np
import pytest

from chargedesign.constants import COULOMB, EPSILON_0
from chargedesign.physical import coulomb
from chargedesign.physical.coulomb import (
    SphereKernel,
    coulomb_field,
    coulomb_field_gemm,
    coulomb_kernel,
    point_charge_field,
    sphere_fields,
    sphere_kernel,
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


def _direct_on_spheres(centres, charges, radii, directions):
    """The reference: the direct sum at the points themselves, shape (k, m, 3)."""
    points = centres[:, None, :] + np.asarray(radii)[:, None, None] * directions
    return coulomb_field(centres, charges, points.reshape(-1, 3)).reshape(points.shape)


def test_the_sphere_fields_equal_the_direct_sum_on_random_bodies():
    """Summed in each carrier's coordinates: the direct sum's figures to 1e-12 (measured
    2e-14), shared directions, each carrier's own, and one radius per carrier."""
    rng = np.random.default_rng(3)
    for n, scale, radius in ((120, 0.05, 0.003), (30, 1.0, 0.06), (3, 1e-3, 1e-5)):
        centres = rng.uniform(-scale, scale, (n, 3))
        charges = rng.normal(size=n) * 1e-9
        radii = radius * rng.uniform(0.5, 1.0, n)
        shared = fibonacci_sphere(80)
        own = fibonacci_sphere(25)[None] * np.ones((n, 1, 1))
        own = own @ np.linalg.qr(rng.normal(size=(3, 3)))[0]  # each turned the same way
        for directions in (shared, own):
            got = sphere_fields(centres, charges, radii, directions)
            ref = _direct_on_spheres(centres, charges, radii, directions)
            rel = np.linalg.norm(got - ref, axis=2) / np.linalg.norm(ref, axis=2)
            assert rel.max() < 1e-12


def test_a_carriers_own_field_on_its_sphere_is_radial_and_exact():
    centre = np.array([[0.3, -0.2, 0.1]])  # far from the origin: no loss to its size
    q, a = 2e-9, 1e-4
    dirs = fibonacci_sphere(40)
    e = sphere_fields(centre, np.array([q]), np.array([a]), dirs)[0]
    np.testing.assert_allclose(np.linalg.norm(e, axis=1), point_charge_field(q, a), rtol=1e-14)
    np.testing.assert_allclose(e / np.linalg.norm(e, axis=1)[:, None], dirs, atol=1e-14)


def test_the_kept_geometry_gives_the_sphere_fields_of_any_subset():
    rng = np.random.default_rng(9)
    centres = rng.uniform(-0.05, 0.05, (60, 3))
    dirs = fibonacci_sphere(50)
    kernel = sphere_kernel(centres, 0.002, dirs)
    assert isinstance(kernel, SphereKernel)
    assert sphere_kernel(centres.copy(), 0.002, dirs) is kernel  # kept per content
    for rows in (np.arange(60), np.sort(rng.choice(60, 17, replace=False))):
        charges = rng.normal(size=len(rows)) * 1e-9
        assert np.array_equal(kernel.rows_of(centres[rows]), rows)
        got = kernel.fields(rows, charges)
        ref = _direct_on_spheres(centres[rows], charges, np.full(len(rows), 0.002), dirs)
        rel = np.linalg.norm(got - ref, axis=2) / np.linalg.norm(ref, axis=2)
        assert rel.max() < 1e-12
        np.testing.assert_array_equal(
            kernel.distances[rows],
            np.linalg.norm(centres[rows][:, None, :] + 0.002 * dirs[None], axis=2),
        )
    assert kernel.rows_of(centres[:3] + 1e-9) is None  # not the candidates: sum directly


def test_the_geometry_is_not_kept_beyond_its_budget(monkeypatch):
    monkeypatch.setattr(coulomb, "SPHERE_KERNEL_ELEMENTS", 10 * 10 * 5)
    centres = np.random.default_rng(2).uniform(-1, 1, (11, 3))
    assert sphere_kernel(centres, 0.01, fibonacci_sphere(5)) is None
    assert sphere_kernel(centres[:10], 0.01, fibonacci_sphere(5)) is not None
