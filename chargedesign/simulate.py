"""Simulate the motion of a designed body (or of the theorem's reduced model).

The default integrator is ``taylor`` (heyoka; DOP853 with a note where heyoka is missing).
Only the effects a scene calls for are computed: ``lorentz`` (charges in the magnetic field),
``electric`` (charges in the electric field), ``magnetization`` (point dipoles in the magnetic
field), ``gravity`` (masses) and ``theorem`` (V and mu of the theorem, lambda and rho
allowed). See docs/simulate.md.

>>> from chargedesign.simulate import simulate
>>> result = simulate(None, t_end=1.0)   # the default scene: its body, designed on the fly
>>> sorted(result.summary())[:3]
['I1_rel_drift', 'I2_max_dev', 'I3_max']
"""

from __future__ import annotations

from chargedesign.simulation.api import (
    DEFAULT_INITIAL,
    OutputOptions,
    SimulationOptions,
    SimulationSetup,
    design_pending,
    initial_state,
    parse_initial,
    parse_output_options,
    parse_simulation_options,
    prepare,
    setup_from_scene,
    setup_from_source,
    simulate,
    simulate_batch,
    with_level,
)
from chargedesign.simulation.chaos import (
    FLIMap,
    PoincareAtlas,
    fast_lyapunov_indicator,
    fli_map,
    lyapunov_exponent,
    poincare_atlas,
)
from chargedesign.simulation.ensemble import EnsembleResult, simulate_ensemble
from chargedesign.simulation.integrate import METHODS, STATE_NAMES, Integration, integrate
from chargedesign.simulation.monitors import MONITORS
from chargedesign.simulation.result import SimulationResult, plot_integrals, plot_poincare
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
    "integrate",
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

# `chargedesign.simulate(...)` calls chargedesign.api.simulate (the module stays a module)
from chargedesign.api import make_callable

make_callable(__name__)
