"""The design's in-loop surface check against a brute-force reference: the direct Coulomb sum
at every sample point of every carrier and at the refinement cap around its largest."""

from __future__ import annotations

import tomllib
from pathlib import Path

import numpy as np
import pytest

from chargedesign.designer.charges import LOOP_SURFACE_SAMPLES, surface_check
from chargedesign.designer.pipeline import physical_setup_from_scene
from chargedesign.physical.coulomb import coulomb_field, point_charge_field
from chargedesign.physical.limits import local_caps, sample_spacing
from chargedesign.sampling import fibonacci_sphere
from chargedesign.scene import scene_from_dict

SMALL = Path(__file__).parents[1] / "physical" / "small.toml"


@pytest.fixture(scope="module")
def setup():
    return physical_setup_from_scene(scene_from_dict(tomllib.loads(SMALL.read_text()), "<t>"))


def _brute_force(setup, positions, q, s, samples):
    """Every sample point by the direct sum over the charges, then the cap around the
    largest (the check's definition, written out point by point)."""
    a = setup.carrier_radius
    dirs = fibonacci_sphere(samples)

    def magnitudes(points):
        e = np.linalg.norm(coulomb_field(positions, q, points), axis=1)
        return e + setup.external_max(np.linalg.norm(points, axis=1), s)

    ratios, worst = [], []
    for c in positions:
        e = magnitudes(c + a * dirs)
        cap = c + a * local_caps(dirs[np.argmax(e)][None], 1.5 * sample_spacing(samples))[0]
        e_cap = magnitudes(cap)
        ratios.append(max(e_cap.max(), e.max()) / setup.safe_field)
        worst.append(cap[np.argmax(e_cap)])
    return np.array(ratios), np.array(worst)


@pytest.mark.parametrize("count", [93, 40, 2])
def test_the_surface_check_equals_the_brute_force_reference(setup, count):
    """On candidates (the kept geometry) and off them (the direct route): ratios to 1e-12,
    the same worst points."""
    rng = np.random.default_rng(count)
    sites = np.sort(rng.choice(len(setup.points), min(count, len(setup.points)), replace=False))
    q = rng.normal(size=len(sites)) * 1e-11
    for positions in (setup.points[sites], setup.points[sites] + 1e-4):
        ratios, worst = surface_check(setup, positions, q, 2.0, LOOP_SURFACE_SAMPLES)
        ref_ratios, ref_worst = _brute_force(setup, positions, q, 2.0, LOOP_SURFACE_SAMPLES)
        np.testing.assert_allclose(ratios, ref_ratios, rtol=1e-12, atol=0)
        np.testing.assert_array_equal(worst, ref_worst)


def test_one_carrier_alone_has_its_own_field(setup):
    """Its own field is uniform on its sphere (every sample ties): q / (4 pi eps0 a^2) (at
    s = 0, without the applied field)."""
    q = np.array([3e-11])
    ratios, _ = surface_check(setup, setup.points[:1], q, 0.0, LOOP_SURFACE_SAMPLES)
    own = point_charge_field(q[0], setup.carrier_radius) / setup.safe_field
    np.testing.assert_allclose(ratios, [own], rtol=1e-14)


def test_no_carriers_no_ratios(setup):
    ratios, worst = surface_check(setup, np.zeros((0, 3)), np.zeros(0), 1.0, 50)
    assert ratios.shape == (0,) and worst.shape == (0, 3)
