"""One small diagram of the unit-scale case (lighter sampling than the command's), shared."""

from __future__ import annotations

import pytest
from topology_cases import GENERIC
from unit_scene import UNIT_PARAMETERS as UNIT

from chargedesign.topology.chambers import FlowCounting, LevelSampling
from chargedesign.topology.compute import DiagramOptions

#: the unit-scale case (examples/scenes/unit_scale.toml)
#: fewer seeds and level samples than the default: seconds, not tens of seconds
SMALL = DiagramOptions(
    seeds=200, counting=FlowCounting(sampling=LevelSampling(800, 32), t_end=150.0, samples=5000)
)


@pytest.fixture(scope="session")
def unit_params():
    return UNIT


@pytest.fixture(scope="session")
def small_options():
    return SMALL


@pytest.fixture(scope="session")
def generic_diagram():
    from chargedesign.topology.diagram import bifurcation_diagram

    return bifurcation_diagram(GENERIC, None, SMALL)


@pytest.fixture(scope="session")
def unit_diagram():
    from chargedesign.topology.diagram import bifurcation_diagram

    return bifurcation_diagram(UNIT, None, SMALL)
