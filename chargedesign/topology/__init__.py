"""The shape of the motion: the bifurcation diagram of (H, I4) on ``I3 = 0``.

- :mod:`.equations`: H, I4, I2, I3 from the certified model with exact gradients and
  Hessians (sympy, compiled), the Poisson tensor; lambda = rho = 0 only.
- :mod:`.critical`: the critical equations, seeds, rank-zero points, the exact equator family.
- :mod:`.branches`: pseudo-arclength continuation of the critical families.
- :mod:`.stability`: elliptic or hyperbolic, from the linearised flow's eigenvalues.
- :mod:`.chambers`: tori over a point (h, k), by sampling the level and counting components.
- :mod:`.compute`: the stages, timed, with the structure the theorem's closed form gives.
- :mod:`.case_map`, :mod:`.general`: any polynomial case's momentum map (H, F) on its level,
  and the stages with the structure found from the traced branches; :mod:`.kowalevski`: the
  Appelrot classes.
- :mod:`.diagram`: the one route (any case; the theorem is its catalogue entry, computed at
  unit time scale and n = 0, then mapped exactly: time scale; Larmor: shifted by C n^2) and
  the result (CSV, picture).
- :mod:`.links`: the diagram beside the Poincare atlas and the FLI map at one energy (heyoka).
"""
