"""The parts as spheres made block by block (``parts_from_arrays``) and their moments
(``monomial_moments``) against the part-by-part formulas they replaced: the same bits."""

import math

import numpy as np

from chargedesign.physical.holder import (
    direction_mean,
    monomial_moments,
    parts_from_arrays,
)
from chargedesign.physical.materials import sphere_radius

_FOUR_PI = 4.0 * math.pi


def _old_parts(carriers, magnets, ballast):
    """The part-by-part loop before the blocks were made at once: (centres, masses, layers)."""
    centres, masses, layers = [], [], []
    pos, mass, radii, wall = carriers
    for i in range(len(mass)):
        centres.append(np.asarray(pos[i], float))
        masses.append(float(mass[i]))
        outer = float(radii[i])
        inner = max(outer - wall, 0.0) if wall is not None else 0.0
        volume = _FOUR_PI / 3.0 * (outer**3 - inner**3)
        layers.append([(float(mass[i]) / volume if volume > 0 else 0.0, inner, outer)])
    pos, mass, volume, density, attached = magnets
    for i in range(len(mass)):
        centres.append(np.asarray(pos[i], float))
        masses.append(float(mass[i]))
        core = float(sphere_radius(float(volume[i])))
        extra = max(float(mass[i]) - density * float(volume[i]), 0.0)
        block = [(density, 0.0, core)]
        if extra > 0 and attached > 0:
            block.append(
                (attached, core, float(sphere_radius(float(volume[i]) + extra / attached)))
            )
        layers.append(block)
    pos, mass, rho = ballast
    for i in range(len(mass)):
        centres.append(np.asarray(pos[i], float))
        masses.append(float(mass[i]))
        if not math.isfinite(rho[i]):
            layers.append([])
            continue
        layers.append([(float(rho[i]), 0.0, float(sphere_radius(mass[i] / rho[i])))])
    return np.array(centres).reshape(-1, 3), np.array(masses), layers


def _old_moments(keys, centres, radial, masses):
    from chargedesign.validation import parse_moment_key

    exps = [parse_moment_key(k) for k in keys]
    top = max(sum(e) for e in exps)
    radial_by_n = {n: (masses if n == 0 else radial(n)) for n in range(0, top + 1, 2)}
    out = np.zeros((len(keys), len(centres)))
    for a, (i, j, k) in enumerate(exps):
        for p in range(0, i + 1, 2):
            for q in range(0, j + 1, 2):
                for r in range(0, k + 1, 2):
                    coef = math.comb(i, p) * math.comb(j, q) * math.comb(k, r)
                    coef *= direction_mean(p, q, r)
                    out[a] += (
                        coef
                        * radial_by_n[p + q + r]
                        * centres[:, 0] ** (i - p)
                        * centres[:, 1] ** (j - q)
                        * centres[:, 2] ** (k - r)
                    )
    return out


def test_parts_and_moments_are_the_part_by_part_formulas():
    rng = np.random.default_rng(11)
    carriers = (
        rng.normal(size=(4, 3)),
        rng.uniform(1e-4, 1e-3, 4),
        rng.uniform(1e-3, 2e-3, 4),
        2e-4,
    )
    volume = rng.uniform(1e-9, 1e-8, 5)
    magnet_mass = 7500.0 * volume * np.array([1.0, 1.5, 0.9, 3.0, 1.0])
    magnets = (rng.normal(size=(5, 3)), magnet_mass, volume, 7500.0, 19300.0)
    rho = np.array([19300.0, np.inf, 11340.0, 8900.0])
    ballast = (rng.normal(size=(4, 3)), rng.uniform(1e-4, 1e-2, 4), rho)
    parts = parts_from_arrays(carriers=carriers, magnets=magnets, ballast=ballast)
    centres, masses, layers = _old_parts(carriers, magnets, ballast)
    np.testing.assert_array_equal(parts.centres, centres)
    np.testing.assert_array_equal(parts.masses, masses)
    assert parts.layers == layers  # the same floats, layer by layer
    assert parts.names[4] == "magnet 0" and parts.names[-1] == "ballast 3"
    keys = ["", "xx", "xy", "yyzz", "xxxz", "yyyy", "xxyyzz", "zzzzzz", "xyyzzz"]
    np.testing.assert_array_equal(
        monomial_moments(keys, parts.centres, parts.radial_moments, parts.masses),
        _old_moments(keys, centres, parts.radial_moments, masses),
    )
