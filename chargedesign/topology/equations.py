"""Exact equations of the momentum map F = (H, I4) on the level ``|gamma| = 1, I3 = 0``.

Everything comes from the certified model (:mod:`chargedesign.model.case`): the integrals
``H = I1``, ``I4``, ``I2 = |gamma|^2`` and ``I3``; their gradients and Hessians are derived
by sympy and compiled once (lambdify with common-subexpression elimination). No user text
reaches sympy: the parameters enter the compiled functions as numbers.

Only the regular case is compiled (lambda = rho = 0 substituted): the singular terms are
refused before any work (:func:`chargedesign.scene.bifurcation.check_regular`, which the
command runs first, through :func:`~.diagram.check_parameters`).
"""

from __future__ import annotations

from collections.abc import Callable
from functools import cache
from typing import Any

import numpy as np

from chargedesign.model.evaluators import angular_potential, parameter_tuple, rhs
from chargedesign.params import Parameters
from chargedesign.scene.bifurcation import check_regular


def _expressions() -> list[Any]:

    from chargedesign.model.case import lam, rho, symbolic_case

    case = symbolic_case()
    regular = {lam: 0, rho: 0}
    return [e.xreplace(regular) for e in (case.I1, case.I4, case.I2, case.I3)]


@cache
def _compiled(order: int, module: str = "numpy") -> Callable[..., Any]:
    """The compiled values (order 0), gradients (1) or Hessians (2) of the four functions;
    ``module`` "numpy" (batches) or "math" (one state: far less overhead)."""
    import sympy as sp

    from chargedesign.model.case import PARAMETER_SYMBOLS, STATE_SYMBOLS
    from chargedesign.model.case_numeric import lambdified

    expressions = _expressions()
    if order == 0:
        outputs: list[Any] = expressions
    elif order == 1:
        outputs = [[sp.diff(e, x) for x in STATE_SYMBOLS] for e in expressions]
    else:
        outputs = [sp.hessian(e, STATE_SYMBOLS).tolist() for e in expressions]
    return lambdified(outputs, STATE_SYMBOLS + PARAMETER_SYMBOLS, module, cse=True)


class MomentumMap:
    """``H, I4, I2, I3`` of one parameter set with their exact derivatives.

    Every method takes states of shape (m, 6) (``p, q, r, gamma1, gamma2, gamma3``; SI).
    """

    def __init__(self, params: Parameters) -> None:
        check_regular(params.lam, params.rho)
        self.params = params
        self.pt: tuple[float, ...] = parameter_tuple(params)

    def _compiled(self, order: int, module: str) -> Callable[..., Any]:
        """The compiled function of ``order`` (values 0, gradients 1, Hessians 2); its
        arguments after the state are :attr:`pt`."""
        return _compiled(order, module)

    def _evaluate(self, order: int, x: np.ndarray) -> np.ndarray:
        x = np.atleast_2d(np.asarray(x, dtype=float))
        if x.shape[0] == 1:
            return np.array([self._compiled(order, "math")(*x[0].tolist(), *self.pt)], float)
        out: np.ndarray = self._compiled(order, "numpy")(*x.T, *self.pt)
        return out

    def values(self, x: np.ndarray) -> np.ndarray:
        """Shape (m, 4): ``H (J), I4 (1/s^4), I2, I3 (kg m^2/s)`` (a case's map: ``H, F, I2,
        I3 - level``)."""
        return self._evaluate(0, x)

    def gradients(self, x: np.ndarray) -> np.ndarray:
        """Shape (m, 4, 6): the rows dH, dI4, dI2, dI3."""
        return self._evaluate(1, x)

    def hessians(self, x: np.ndarray) -> np.ndarray:
        """Shape (m, 4, 6, 6)."""
        return self._evaluate(2, x)

    def inertia(self) -> np.ndarray:
        """``diag(2C, 2C, C)``."""
        C = self.params.C
        return np.array([2 * C, 2 * C, C])

    @property
    def i3_scale(self) -> float:
        """The size of I3 the critical equations divide it by (kg m^2 / s per 1/s)."""
        return float(self.params.C)

    def velocity(self, x: np.ndarray) -> np.ndarray:
        """The flow's right-hand side at one state x (6,)."""
        return np.asarray(rhs(x, self.params), dtype=float)

    def poisson(self, x: np.ndarray) -> np.ndarray:
        """The Poisson tensor at one state x (6,) (:func:`poisson_tensor`)."""
        return poisson_tensor(self, x)


def relative_singular_value(gradients: np.ndarray) -> np.ndarray:
    """Smallest over largest singular value of the 4x6 Jacobian with unit rows, shape (m,).

    Zero exactly where dH, dI4, dI2, dI3 are linearly dependent (the critical set). A row
    below ``1e-9`` of the largest (a differential that vanishes, as dI4 on the equator
    family) is a zero row: dependent by itself.
    """
    g = np.asarray(gradients, dtype=float).reshape(-1, 4, 6)
    norms = np.linalg.norm(g, axis=2, keepdims=True)
    vanishing = norms <= 1e-9 * np.max(norms, axis=1, keepdims=True)
    scaled = np.where(vanishing, 0.0, g / np.where(vanishing, 1.0, norms))
    s = np.linalg.svd(scaled, compute_uv=False)
    return s[:, -1] / s[:, 0]


@cache
def _compiled_angular_potential_jacobian() -> Callable[..., Any]:
    """``dl/dgamma`` (3x3) of the model's vector potential, compiled."""
    from chargedesign.model.case import GAMMA, PARAMETER_SYMBOLS, symbolic_case
    from chargedesign.model.case_numeric import lambdified

    jac = symbolic_case().l.jacobian(GAMMA).tolist()
    return lambdified(jac, tuple(GAMMA) + PARAMETER_SYMBOLS, "math", cse=True)


def _hat(v: np.ndarray) -> np.ndarray:
    """The matrix of ``u -> v x u``."""
    return np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])


def poisson_tensor(F: MomentumMap, x: np.ndarray) -> np.ndarray:
    """The Poisson tensor of the flow in the state variables ``(omega, gamma)``, shape (6, 6).

    With the momentum ``m = I omega + l(gamma)`` the equations are Lie-Poisson on e(3)*:
    ``m' = m x dH/dm + gamma x dH/dgamma``, ``gamma' = gamma x dH/dm`` (the Euler-Poincare
    form the Larmor certificate proves). Read in ``(omega, gamma)`` with ``P = d(omega,
    gamma)/d(m, gamma)`` the tensor is ``P Pi P^T``; ``tensor @ dH`` is the model's
    right-hand side (tested).
    """
    omega, gamma = x[:3], x[3:]
    inertia = F.inertia()
    dl = np.array(_compiled_angular_potential_jacobian()(*gamma.tolist(), *F.pt), dtype=float)
    m = inertia * omega + np.asarray(angular_potential(gamma, F.params), dtype=float)
    return lie_poisson_tensor(m, gamma, inertia, dl)


def lie_poisson_tensor(
    m: np.ndarray, gamma: np.ndarray, inertia: np.ndarray, dl: np.ndarray
) -> np.ndarray:
    """``P Pi P^T``: the Lie-Poisson tensor of e(3)* at ``(m, gamma)`` read in ``(omega,
    gamma)`` through ``m = I omega + l(gamma)`` (``dl = dl/dgamma``), shape (6, 6)."""
    pi = np.zeros((6, 6))
    pi[:3, :3] = _hat(m)
    pi[:3, 3:] = _hat(gamma)
    pi[3:, :3] = _hat(gamma)
    P = np.zeros((6, 6))
    P[:3, :3] = np.diag(1.0 / inertia)
    P[:3, 3:] = -dl / inertia[:, None]
    P[3:, 3:] = np.eye(3)
    return P @ pi @ P.T
