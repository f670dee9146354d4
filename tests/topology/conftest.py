"""One small diagram of the unit-scale case (lighter sampling than the command's), shared."""

from __future__ import annotations

import pytest

from chargedesign.params import Parameters
from chargedesign.topology.chambers import LevelSampling
from chargedesign.topology.compute import DiagramOptions

#: the unit-scale case (examples/scenes/unit_scale.toml)
UNIT = Parameters(C=1.0, c=0.3, d=-0.4, n=0.7, K=0.5, kappa=0.9)
#: fewer seeds and chamber samples than the default: seconds, not tens of seconds
SMALL = DiagramOptions(seeds=200, sampling=LevelSampling(1500, 48), columns=5)


@pytest.fixture(scope="session")
def unit_params():
    return UNIT


@pytest.fixture(scope="session")
def small_options():
    return SMALL


@pytest.fixture(scope="session")
def unit_diagram():
    from chargedesign.topology.diagram import bifurcation_diagram

    return bifurcation_diagram(UNIT, None, SMALL)
