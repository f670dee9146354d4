"""The surface samplers of the physical design (the caps around a carrier's worst point)."""

import numpy as np

from chargedesign.physical.limits import local_caps


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
