"""The testbed tests' shared case: the example testbed scene's parameters and a small
``[testbed]`` table with a start (a full sphere holds it: its motion tumbles)."""

from __future__ import annotations

from chargedesign.params import Parameters

#: examples/scenes/testbed.toml's parameters
EXAMPLE = Parameters(C=0.5, c=0.3, d=-0.4, n=0.21, K=0.15, kappa=0.081)
#: a quick table with the paper's start (slowed by 0.3)
SMALL = {
    "platform_mass_kg": 6.0,
    "platform_radius_m": 0.3,
    "bearing": "full_sphere",
    "initial_gamma": [0.36, 0.48, 0.8],
    "initial_p": 0.18,
    "initial_q": -0.12,
    "t_end_s": 0.2,
    "rate_Hz": 20.0,
    "seeds": 1,
}
