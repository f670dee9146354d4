"""The unit case's testbed plant and its start on I3 = 0, shared by the loop's and the
wheels' tests."""

from __future__ import annotations

import numpy as np
import pytest
from unit_scene import UNIT_INERTIA, UNIT_PARAMETERS

from chargedesign.airbearing.dynamics import Plant
from chargedesign.airbearing.loop import initial_state


@pytest.fixture(scope="module")
def plant() -> Plant:
    """The platform built exactly to the Kowalevski inertia (model and truth alike)."""
    return Plant(UNIT_PARAMETERS, UNIT_INERTIA, UNIT_INERTIA)


@pytest.fixture(scope="module")
def x0() -> np.ndarray:
    """A start on I3 = 0: gamma = (0.36, 0.48, 0.8), p = 0.6, q = -0.4."""
    return initial_state(UNIT_PARAMETERS, np.array([0.36, 0.48, 0.8]), 0.6, -0.4)
