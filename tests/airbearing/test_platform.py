"""Platform and ballast: the inertia recomputed from the written parts, and the fit."""

from __future__ import annotations

import math

import numpy as np
import pytest

from chargedesign.airbearing.platform import Platform, design_ballast
from chargedesign.physical.materials import BALLAST_DENSITY
from chargedesign.scene.testbed import TestbedOptions

C = 0.5


@pytest.fixture(scope="module")
def built() -> tuple[TestbedOptions, Platform, object]:
    opts = TestbedOptions.from_table({"platform_mass_kg": 6.0, "platform_radius_m": 0.3})
    platform = Platform.from_options(opts)
    return opts, platform, design_ballast(platform, C, opts)


def _inertia_from_parts(positions, masses, radii) -> np.ndarray:
    """Independent route: one part at a time, parallel-axis theorem for a solid sphere."""
    total = np.zeros((3, 3))
    for r, m, a in zip(positions, masses, radii, strict=True):
        own = 0.4 * m * a * a
        for i in range(3):
            for j in range(3):
                total[i, j] += m * ((r @ r if i == j else 0.0) - r[i] * r[j])
            total[i, i] += own
    return total


def test_ballast_inertia_equals_the_target(built) -> None:
    _opts, platform, ballast = built
    inertia = platform.inertia + _inertia_from_parts(
        ballast.positions, ballast.masses, ballast.radii
    )
    target = np.diag([2 * C, 2 * C, C])
    assert np.abs(inertia - target).max() < 1e-12 * 2 * C


def test_ballast_centre_of_mass_at_O(built) -> None:
    _opts, platform, ballast = built
    moment = platform.mass_kg * platform.com + (ballast.masses[:, None] * ballast.positions).sum(0)
    assert np.abs(moment).max() < 1e-12 * platform.mass_kg * platform.radius_m


def test_parts_are_real_spheres_inside_the_envelope(built) -> None:
    opts, platform, ballast = built
    density = BALLAST_DENSITY[opts.ballast_material]
    volume = 4.0 / 3.0 * math.pi * ballast.radii**3
    assert np.allclose(volume * density, ballast.masses, rtol=1e-12)
    r = np.linalg.norm(ballast.positions, axis=1)
    assert (r + ballast.radii <= platform.radius_m).all()
    assert (r - ballast.radii >= opts.bearing_radius_m).all()
    gaps = np.linalg.norm(ballast.positions[:, None] - ballast.positions[None], axis=-1)
    sums = ballast.radii[:, None] + ballast.radii[None]
    off = ~np.eye(len(r), dtype=bool)
    assert (gaps[off] >= sums[off]).all()


def test_full_sphere_shell_platform_is_the_whole_sphere() -> None:
    opts = TestbedOptions.from_table({"platform_mass_kg": 3.0, "bearing": "full_sphere"})
    p = Platform.from_options(opts)
    R = 0.25
    assert np.allclose(p.inertia, 2.0 / 3.0 * 3.0 * R * R * np.eye(3), rtol=1e-14)
    assert np.allclose(p.com, 0.0, atol=1e-15)
