"""The magnets' torque in the coils' error field from the body's recorded zonal terms
(one recurrence per body) against the recurrence run for each field: the same bits."""

import numpy as np

from chargedesign.fields import zonal_block, zonal_first_from_terms, zonal_sums
from chargedesign.physical import window
from chargedesign.physical.coils import COIL_RADII, apparatus_at
from chargedesign.physical.parasitics import array_key


def test_zonal_sums_from_recorded_terms_are_the_recurrence():
    rng = np.random.default_rng(5)
    Z = rng.normal(size=(300, 7))
    s = np.einsum("ij,ij->j", Z[:3], Z[:3]) + 1.0  # a squared radius per column
    terms: list = []
    zonal_block(np.zeros(12), Z, s, 1, False, record=terms)
    assert len(terms) == 12
    for coeffs in (rng.normal(size=12), np.r_[0.0, 0.0, rng.normal(size=6)], np.zeros(0)):
        direct = zonal_sums(coeffs, Z, s, 1, want_value=False)
        again = zonal_first_from_terms(coeffs, Z, terms)
        for key in ("Z", "S"):
            np.testing.assert_array_equal(again[key], direct[key])


def test_magnets_torque_from_terms_is_the_direct_one():
    rng = np.random.default_rng(9)
    positions = rng.normal(scale=0.02, size=(9, 3))
    moments = rng.normal(scale=0.1, size=(9, 3))
    keys = array_key(positions, 3), array_key(moments, 3)
    window.torque_terms.cache_clear()
    for factor in COIL_RADII[:4]:  # the coil sizes one body tries, one recurrence for all
        apparatus = apparatus_at(1e-3, 2e-2, factor * 0.05, 0.05, 1e-4)
        legendre = tuple(float(f) for f in apparatus.error_legendre)
        window.magnets_torque.cache_clear()
        fast = window.magnets_torque(legendre, *keys)
        error = window.AxisymmetricField(legendre)
        coeffs = np.asarray(error.legendre[: error.degree], dtype=np.float64)
        assert fast == window.magnets_torque_direct(coeffs, *keys)  # the same bits
        assert fast > 0
    assert window.torque_terms.cache_info().misses == 1
