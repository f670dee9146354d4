"""The release on I3 = 0 in a named chamber and its tolerance (flight/release.py)."""

from __future__ import annotations

import numpy as np
import pytest

from chargedesign.flight.release import (
    release_start,
    release_tolerance,
    turns_of,
)
from chargedesign.params import Parameters
from chargedesign.physical.support import MIN_TURNS
from chargedesign.report import flight_lines
from chargedesign.topology.chambers import propagate
from chargedesign.topology.closed_form import ClosedForm
from chargedesign.topology.equations import MomentumMap

#: the drop example's parameters (examples/scenes/chaplygin_drop.toml)
DROP = Parameters(C=1.5e-6, c=0.3, d=-0.4, n=0.0, K=0.0, kappa=64.0)
FLIGHT = 8.8


@pytest.fixture(scope="module")
def start():
    return release_start(DROP, FLIGHT)


def test_the_start_lies_on_its_level_in_its_named_chamber(start):
    H, I4, I2, I3 = MomentumMap(DROP).values(start.state[None, :])[0]
    assert I2 == pytest.approx(1.0, abs=1e-14)
    assert abs(I3) <= 1e-12 * DROP.C * np.linalg.norm(start.state[:3])
    assert H == pytest.approx(start.h, rel=1e-9)
    assert I4 == pytest.approx(start.k, rel=1e-2)  # a secant root on the sampled conic
    cells = ClosedForm.of(DROP).cells(start.energy_range[0] - 1.0, start.energy_range[1] + 1.0)
    assert any(c.walls == start.walls and c.chamber == start.chamber for c in cells)
    # between its walls at its energy
    walls = dict((name, value) for value, name in ClosedForm.of(DROP).walls(start.h))
    low, high = walls[start.walls[0]], walls[start.walls[1]]
    assert low < I4 < high
    assert start.name.startswith(f"chamber {start.chamber}: between ")


def test_the_start_turns_at_least_five_times_in_the_flight(start):
    assert start.turns >= MIN_TURNS
    times, states, _ = propagate(DROP, start.state[None, :], FLIGHT, 2000)
    assert turns_of(times, states)[0] == pytest.approx(start.turns, rel=1e-3)


def test_a_slow_body_is_refused_in_words():
    slow = Parameters(C=1.5e-6, c=0.3, d=-0.4, kappa=1e-4)
    with pytest.raises(ValueError, match="too slow for the flight"):
        release_start(slow, 1.0)


def test_the_tolerance_grows_with_the_release_error_and_the_exact_release_holds(start):
    tol = release_tolerance(DROP, start, errors=(1e-4, 1e-3, 1e-2), directions=4, seed=3)
    assert tol.nominal_drift < 1e-10  # the exact release keeps I4 (no projection)
    assert tol.drifts[0] < tol.drifts[1] < tol.drifts[2]
    # small errors: the drift is linear in the error (the ratio of decades about 10)
    assert 4.0 < tol.drifts[1] / tol.drifts[0] < 25.0
    # I3 follows the error: an omega error epsilon |omega| gives I3 of order epsilon C |omega|
    assert 0.1 * 1e-3 < tol.i3_relative[1] < 3 * 1e-3
    assert tol.largest_error == pytest.approx(1e-3 / tol.slope)
    assert tol.largest_error < 1e-2  # the release must be accurate to better than 1 %
    assert "release tolerance" in str(tol) and set(tol.to_dict()) >= {"slope", "I4_drifts"}


def test_the_report_s_flight_section_renders_the_record():
    assert flight_lines(None) == []
    record = {
        "style": "free_fall",
        "facility": "drop_tower_catapult",
        "microgravity_s": 9.3,
        "state": "included",
        "items": [
            {"name": "turns_in_flight", "value": 22.0, "limit": 5.0, "unit": "", "met": True}
        ],
        "notes": ["a note"],
        "flight": {"lines": ["release: ..."]},
    }
    lines = flight_lines(record)
    assert lines[:3] == ["", "## Flight", ""]
    assert "support: free_fall (drop_tower_catapult, 9.3 s of microgravity): included" in lines
    assert "- turns_in_flight: 22 (limit 5): met" in lines
    assert lines[-2:] == ["- a note", "- release: ..."]
