"""The largest applied field over orientations: the screened route against the recurrence at
every angle (the route it replaced), to the last bit."""

from __future__ import annotations

import numpy as np
import pytest

from chargedesign.fields import AxisymmetricField
from chargedesign.physical import field_bounds
from chargedesign.physical.field_bounds import ANGLE_SAMPLES, RadialBound, field_magnitude_max


def _every_angle(legendre, radii):
    """The reference: the recurrence at every polar angle of every radius, the largest plus
    the largest second difference."""
    fld = AxisymmetricField(tuple(legendre))
    theta = np.linspace(0.0, np.pi, ANGLE_SAMPLES)
    unit = np.column_stack([np.sin(theta), np.zeros_like(theta), np.cos(theta)])
    out = []
    for r in np.asarray(radii, dtype=float):
        mag = np.linalg.norm(fld.gradient(r * unit), axis=1)
        out.append(mag.max() + np.abs(np.diff(mag, 2)).max())
    return np.array(out)


FIELDS = [
    (0.0, 0.0, 0.0, 0.1),  # the default scene's electric field
    (1.0, 20.0),  # its magnetic field
    (0.0, 2.0),  # zero at the centre
    (1.0,),  # uniform: every angle ties
    (0.0, 0.0, 7.1e-15, -3.9e-13, -1807.9, -26841.8, 125267.7, 294925.8, -2622779.5),
]


@pytest.mark.parametrize("legendre", FIELDS)
def test_the_screen_gives_the_recurrences_largest_field_to_the_bit(legendre):
    radii = np.concatenate([np.linspace(0.0, 0.06, 97), [0.3, 1.7]])
    np.testing.assert_array_equal(
        field_magnitude_max(legendre, radii), _every_angle(legendre, radii)
    )


def test_random_fields_and_radii_to_the_bit():
    rng = np.random.default_rng(5)
    for _ in range(6):
        legendre = tuple(rng.normal(size=int(rng.integers(1, 9))))
        radii = rng.uniform(0.0, 2.0, 40)
        np.testing.assert_array_equal(
            field_magnitude_max(legendre, radii), _every_angle(legendre, radii)
        )


def test_few_radii_take_the_recurrence_and_shapes_are_kept():
    legendre = (1.0, 20.0)
    few = np.array([[0.01, 0.02], [0.03, 0.04]])
    assert few.size <= field_bounds.DIRECT_RADII
    got = field_magnitude_max(legendre, few)
    assert got.shape == few.shape
    np.testing.assert_array_equal(got.reshape(-1), _every_angle(legendre, few.reshape(-1)))
    assert field_magnitude_max((0.0, 0.0), np.ones(3)).tolist() == [0.0, 0.0, 0.0]
    assert field_magnitude_max(legendre, np.zeros(0)).shape == (0,)


def test_the_radial_bound_is_an_upper_bound_and_nondecreasing():
    bound = RadialBound((0.0, 0.0, 0.0, 0.1), 0.05)
    assert np.all(np.diff(bound.values) >= 0.0)
    r = np.linspace(0.0, 0.05, 33)
    assert np.all(bound(r) >= field_magnitude_max((0.0, 0.0, 0.0, 0.1), r))


def test_field_reach_is_each_field_bound_once_and_agrees_with_itself():
    """A setup's reach: the region maxima are the reference at the region, the electric
    grid's last value is that same maximum to the last bit (the setup's rate bound reads it),
    and the magnetic field is bounded at the radii asked for, none else."""
    fields = {"electric": FIELDS[0], "magnetic": FIELDS[1], "gravity": ()}
    region = 0.037
    radii = np.array([0.0, 0.01, 0.02, region])
    reach = field_bounds.field_reach(fields, region, magnetic_radii=radii)
    assert set(reach.maxima) == {"electric", "magnetic"}  # an empty field is left out
    for kind in ("electric", "magnetic"):
        assert reach.maxima[kind] == _every_angle(fields[kind], [region])[0]
    assert reach.electric_grid[-1] == region
    assert len(reach.electric_grid) == field_bounds.REGION_GRID_RADII
    assert reach.electric_values[-1] == reach.maxima["electric"]
    np.testing.assert_array_equal(reach.magnetic_at, _every_angle(fields["magnetic"], radii))
    bare = field_bounds.field_reach({"magnetic": FIELDS[1]}, region)
    assert bare.magnetic_at is None
    assert not np.any(bare.electric_values)
