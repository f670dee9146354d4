"""The in-loop surface-field kernel of the physical design against the limits check's own."""

import numpy as np

from chargedesign.designer.physical import _coulomb_field_gemm
from chargedesign.physical.limits import coulomb_field, fibonacci_directions, local_cap, local_caps


def test_the_matrix_product_field_equals_the_direct_sum_on_random_bodies():
    rng = np.random.default_rng(7)
    for n, scale, radius in ((150, 0.05, 0.003), (40, 1.0, 0.06), (3, 1e-3, 1e-5)):
        sources = rng.uniform(-scale, scale, (n, 3))
        charges = rng.normal(size=n) * 1e-9
        points = (sources[:, None, :] + radius * fibonacci_directions(60)[None]).reshape(-1, 3)
        direct = coulomb_field(sources, charges, points)
        fast = _coulomb_field_gemm(sources, charges, points)
        rel = np.linalg.norm(fast - direct, axis=1) / np.linalg.norm(direct, axis=1)
        assert rel.max() < 1e-10


def test_caps_are_unit_vectors_within_the_angle_filling_it():
    rng = np.random.default_rng(1)
    directions = rng.normal(size=(20, 3))
    directions[0] = [1.0, 0.0, 0.0]  # the other helper axis
    caps = local_caps(directions, 0.2)
    assert caps.shape == (20, 49, 3)
    for d, cap in zip(directions, caps, strict=True):
        unit = d / np.linalg.norm(d)
        np.testing.assert_allclose(cap[0], unit, rtol=0, atol=1e-15)  # the centre itself
        np.testing.assert_allclose(np.linalg.norm(cap, axis=1), 1.0, rtol=0, atol=1e-15)
        angles = np.arccos(np.clip(cap @ unit, -1, 1))
        assert angles.max() <= 0.2 + 1e-12 and angles.max() > 0.9 * 0.2  # reaches the rim
    assert local_cap(directions[3], 0.2).shape == (49, 3)
