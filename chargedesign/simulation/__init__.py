"""Rigid-body simulation of designed bodies and of the theorem's reduced model.

The package re-exports :func:`.api.simulate` and friends (``cd.simulate`` is
:func:`chargedesign.api.simulate`).

- :mod:`.polynomials`: polynomials in gamma from moment contractions (the reduced route).
- :mod:`.system`: the body, its effects, torques by the direct and reduced routes.
- :mod:`.integrate`: the methods (taylor by default), events, batching.
- :mod:`.taylor`: the heyoka back end (equations as heyoka expressions, compiled once).
- :mod:`.monitors`: the integral registry and what a run reports.
- :mod:`.ensemble`: sets of initial states and batches.
- :mod:`.chaos`: Poincare atlases and the fast Lyapunov indicator.
- :mod:`.result`: the result, drift monitors, output files and plots.
- :mod:`.setup`: a run's setup from a scene, a design or parameters; a scene's ``[body]``
  region designed when a run needs it.
- :mod:`.api`: :func:`simulate` (the entry point).
"""

from __future__ import annotations

# No name re-exported here may equal a submodule's (``integrate`` the function would hide
# ``chargedesign.simulation.integrate`` the module): import the function from its module.
from chargedesign.scene.simulation import (
    DEFAULT_INITIAL,
    OutputOptions,
    SimulationOptions,
    parse_initial,
    parse_output_options,
    parse_simulation_options,
    with_level,
)
from chargedesign.simulation.api import initial_state, prepare, simulate
from chargedesign.simulation.chaos import (
    FLIMap,
    PoincareAtlas,
    fast_lyapunov_indicator,
    fli_map,
    lyapunov_exponent,
    poincare_atlas,
)
from chargedesign.simulation.ensemble import EnsembleResult, simulate_batch, simulate_ensemble
from chargedesign.simulation.integrate import METHODS, STATE_NAMES, Integration
from chargedesign.simulation.monitors import MONITORS
from chargedesign.simulation.result import SimulationResult, plot_integrals, plot_poincare
from chargedesign.simulation.setup import (
    SimulationSetup,
    design_pending,
    setup_from_scene,
    setup_from_source,
)
from chargedesign.simulation.system import (
    EFFECTS,
    ROUTES,
    Body,
    RigidBodySystem,
    attitude_from_gamma,
    body_mass_points,
    direct_terms,
    quaternion_gamma,
    quaternion_rotation,
    reduced_polynomials,
    rotation_quaternion,
    select_effects,
)

__all__ = [
    "DEFAULT_INITIAL",
    "EFFECTS",
    "METHODS",
    "MONITORS",
    "ROUTES",
    "STATE_NAMES",
    "Body",
    "EnsembleResult",
    "FLIMap",
    "Integration",
    "OutputOptions",
    "PoincareAtlas",
    "RigidBodySystem",
    "SimulationOptions",
    "SimulationResult",
    "SimulationSetup",
    "attitude_from_gamma",
    "body_mass_points",
    "design_pending",
    "direct_terms",
    "fast_lyapunov_indicator",
    "fli_map",
    "initial_state",
    "lyapunov_exponent",
    "parse_initial",
    "parse_output_options",
    "parse_simulation_options",
    "plot_integrals",
    "plot_poincare",
    "poincare_atlas",
    "prepare",
    "quaternion_gamma",
    "quaternion_rotation",
    "reduced_polynomials",
    "rotation_quaternion",
    "select_effects",
    "setup_from_scene",
    "setup_from_source",
    "simulate",
    "simulate_batch",
    "simulate_ensemble",
    "with_level",
]
