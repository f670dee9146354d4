"""The momentum map ``(H, F)`` of any case of (ep) on the level ``|gamma| = 1, I3 = g``.

A case file (:mod:`chargedesign.model.case_file`) gives the inertia, ``V``, ``l`` and a
claimed integral ``F``. Its energy ``H = 1/2 omega I omega + V``, ``F``, ``I2 = |gamma|^2`` and
``I3 - g = (I omega + l) . gamma - g`` are the case's own sympy objects (built by the
whitelisted parser: no text reaches sympy), differentiated by sympy and compiled once per
map. :class:`CaseMomentumMap` has the interface of the theorem's
:class:`~chargedesign.topology.equations.MomentumMap`, so the critical equations, the
continuation, the stability types and the flow counting of this package run on it
unchanged; only the theorem's closed forms (:mod:`.closed_form`) and its exact equator family
do not apply.

The map is defined for polynomial cases with ``l`` given (the Poisson tensor needs the
vector potential); :func:`diagram_refusal` says why another case has no diagram here.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
import sympy as sp

from chargedesign.model.case import GAMMA, STATE_SYMBOLS
from chargedesign.model.case_file import case_equations
from chargedesign.model.case_numeric import lambdified, singular_factors
from chargedesign.scene.case_file import Case
from chargedesign.simulation.integrate import Symbolic, solve
from chargedesign.topology.equations import MomentumMap, lie_poisson_tensor


def diagram_refusal(case: Case) -> str | None:
    """Why ``case`` has no diagram here (None: it has one): a singular case (a denominator
    in V, l or F; the set named) or one given by ``mu`` without ``l``."""
    singular = singular_factors(
        [case.V, case.integral, *(case.l if case.l is not None else case.mu)]
    )
    if singular:
        return (
            f"case {case.name}: no bifurcation diagram for a singular case (its expressions"
            f" blow up on {', '.join(singular)}; the level's compact sampling and the flow need"
            " a polynomial V, l and F)"
        )
    if case.l is None:
        return (
            f"case {case.name}: no bifurcation diagram for a case given by mu without l (the"
            " stability types need the Poisson tensor of m = I omega + l)"
        )
    return None


class CaseMomentumMap(MomentumMap):
    """``H, F, I2, I3 - level`` of one case with their exact derivatives.

    Every method takes states of shape (m, 6) (``p, q, r, gamma1, gamma2, gamma3``). The
    second column is the case's integral ``F`` (the theorem's I4 in
    :class:`~chargedesign.topology.equations.MomentumMap`).
    """

    def __init__(self, case: Case, level: Any = 0) -> None:
        refusal = diagram_refusal(case)
        if refusal is not None:
            raise ValueError(refusal)
        assert case.l is not None
        self.case = case
        self.level = sp.Rational(str(level))  # exact: an int, Fraction or Rational's text
        functions = [case.I1, case.integral, sum(g**2 for g in GAMMA), case.I3 - self.level]
        gradients = [[sp.diff(e, x) for x in STATE_SYMBOLS] for e in functions]
        hessians = [sp.hessian(e, STATE_SYMBOLS).tolist() for e in functions]
        self._functions = {
            (order, module): lambdified(outputs, STATE_SYMBOLS, module, cse=True)
            for order, outputs in enumerate((functions, gradients, hessians))
            for module in ("numpy", "math")
        }
        #: no parameters after the state: the case's numbers are in its expressions
        self.pt = ()
        equations = tuple(case_equations(case))
        self._velocity = lambdified(list(equations), STATE_SYMBOLS, "math", cse=True)
        self._velocity_batch = lambdified(list(equations), STATE_SYMBOLS, cse=True)
        #: the equations as the integrator service's Taylor method takes them
        self.symbolic = Symbolic(tuple(STATE_SYMBOLS), equations)
        self._l = lambdified(list(case.l), STATE_SYMBOLS, "math", cse=True)
        self._dl = lambdified(case.l.jacobian(GAMMA).tolist(), STATE_SYMBOLS, "math", cse=True)
        self._inertia = np.array([float(m) for m in case.inertia])
        #: the flow counting's unit of time (s): its t_end is read in these units
        self.time_unit = 1.0

    def _compiled(self, order: int, module: str) -> Callable[..., Any]:
        return self._functions[order, module]

    def inertia(self) -> np.ndarray:
        """``(A, B, C)``."""
        return self._inertia

    @property
    def i3_scale(self) -> float:
        return float(np.max(self._inertia))

    def velocity(self, x: np.ndarray) -> np.ndarray:
        return np.array(self._velocity(*np.asarray(x, dtype=float).tolist()), dtype=float)

    def velocities(self, x: np.ndarray) -> np.ndarray:
        """The right-hand side at a batch of states (m, 6) -> (m, 6)."""
        out: np.ndarray = self._velocity_batch(*np.atleast_2d(x).T)
        return out

    def poisson(self, x: np.ndarray) -> np.ndarray:
        """The Poisson tensor in ``(omega, gamma)`` (as
        :func:`~chargedesign.topology.equations.poisson_tensor`, with the case's l)."""
        omega, gamma = x[:3], x[3:]
        dl = np.array(self._dl(*x.tolist()), dtype=float)
        m = self._inertia * omega + np.array(self._l(*x.tolist()), dtype=float)
        return lie_poisson_tensor(m, gamma, self._inertia, dl)


def case_trajectories(
    F: CaseMomentumMap, starts: np.ndarray, t_end: float, samples: int
) -> np.ndarray:
    """States along the case's flow from ``starts`` (m, 6) at ``samples`` times in
    ``[0, t_end]``: (m, samples, 6). The integrator service on the case's own equations
    (``gamma' = gamma x omega``): heyoka's Taylor method at machine precision on their sympy
    form, as the theorem's flow counting; without heyoka one DOP853 run of the stacked system
    (rtol 1e-10)."""
    m = len(starts)
    solution = solve(
        lambda _t, y: F.velocities(y),
        np.asarray(starts, float).reshape(m, 6),
        (0.0, t_end),
        t_eval=np.linspace(0.0, t_end, samples),
        method="taylor",
        symbolic=F.symbolic,
        rtol=1e-10,
        atol=1e-12,
        what=f"case {F.case.name}: the flow counting's trajectories",
    )
    return solution.y.transpose(1, 0, 2)
