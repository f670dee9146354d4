"""The theorem as a symbolic model (sympy is the source of truth).

- :mod:`.case`: symbols, V, l, mu (derived from l), inertia, the integrals I1..I4.
- :mod:`.equations`: Euler-Poisson equations derived from the general form.
- :mod:`.certificate`: exact proof that I1, I3 are integrals and I4 is one on I3 = 0.
- :mod:`.larmor`: exact proof that the n-system is the n = 0 system read in axes turning at
  n about Z (Larmor's theorem): equations, I3 level, I4 map, Lagrangian, energy.
- :mod:`.printed`: the paper's printed formulas, transcribed only to be audited.
- :mod:`.audit`: printed versus derived, term by term on |gamma| = 1.
- :mod:`.evaluators`: compiled numeric evaluators, vectorised over states.
"""
