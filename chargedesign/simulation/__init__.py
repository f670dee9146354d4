"""Rigid-body simulation of designed bodies and of the theorem's reduced model.

Public entry: :mod:`chargedesign.simulate` (re-exports :func:`.api.simulate` and friends).

- :mod:`.polynomials`: polynomials in gamma from moment contractions (the reduced route).
- :mod:`.system`: the body, its effects, torques by the direct and reduced routes.
- :mod:`.integrate`: the methods (taylor by default), events, batching.
- :mod:`.taylor`: the heyoka back end (equations as heyoka expressions, compiled once).
- :mod:`.monitors`: the integral registry and what a run reports.
- :mod:`.ensemble`: sets of initial states.
- :mod:`.chaos`: Poincare atlases and the fast Lyapunov indicator.
- :mod:`.result`: the result, drift monitors, output files and plots.
- :mod:`.api`: scenes' simulation tables and :func:`simulate`.
"""
