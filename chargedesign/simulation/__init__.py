"""Rigid-body simulation of designed bodies and of the theorem's reduced model.

Public entry: :mod:`chargedesign.simulate` (re-exports :func:`.api.simulate` and friends).

- :mod:`.polynomials`: polynomials in gamma from moment contractions (the reduced route).
- :mod:`.system`: the body, its effects, torques by the direct and reduced routes.
- :mod:`.integrate`: solve_ivp and Gauss-Legendre integration, events, batching.
- :mod:`.result`: the result, drift monitors, output files and plots.
- :mod:`.api`: scenes' simulation tables and :func:`simulate`.
"""
