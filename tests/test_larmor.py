"""The Larmor reading a design records, and the turning-axes map of states."""

from __future__ import annotations

import numpy as np
import pytest

from chargedesign.body import Design
from chargedesign.errors import InputError
from chargedesign.larmor import LarmorReading, from_turning_axes, to_turning_axes
from chargedesign.params import Parameters

PARAMS = Parameters(C=1.0, c=0.3, d=-0.4, n=0.7, K=0.5, kappa=0.9)


def test_design_json_round_trips_the_reading_and_the_frame_body_realises_n_zero() -> None:
    design = Design(parameters=PARAMS, larmor={"reading": "frame", "rate": 0.7})
    data = design.to_dict()
    assert data["larmor"] == {"reading": "frame", "rate": 0.7}
    again = Design.from_dict(data)
    assert again.larmor == LarmorReading("frame", 0.7)
    assert again.body_parameters.n == 0.0 and again.parameters.n == 0.7
    assert again.body_parameters.K == PARAMS.K


def test_a_file_without_the_key_is_the_charges_reading() -> None:
    design = Design(parameters=PARAMS)
    assert design.larmor is None and design.larmor_reading == "charges"
    assert "larmor" not in design.to_dict()
    assert design.body_parameters == PARAMS


@pytest.mark.parametrize(
    "value, match",
    [
        ({"reading": "gauge", "rate": 0.7}, "larmor.reading"),
        ({"reading": "frame"}, "reading, rate"),
        ({"reading": "frame", "rate": "fast"}, "larmor.rate"),
        ("frame", "reading, rate"),
    ],
)
def test_a_bad_reading_is_one_line_naming_the_key(value: object, match: str) -> None:
    with pytest.raises(InputError, match=match):
        Design.from_dict({"parameters": PARAMS.as_dict(), "larmor": value})


def test_the_turning_axes_map_shifts_omega_by_n_gamma_and_inverts() -> None:
    rng = np.random.default_rng(1)
    states = rng.normal(size=(5, 6))
    turned = to_turning_axes(states, 0.7)
    np.testing.assert_array_equal(turned[:, 3:], states[:, 3:])
    np.testing.assert_allclose(turned[:, :3], states[:, :3] - 0.7 * states[:, 3:], rtol=0, atol=0)
    np.testing.assert_allclose(from_turning_axes(turned, 0.7), states, rtol=0, atol=1e-15)
