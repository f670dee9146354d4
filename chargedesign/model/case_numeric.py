"""A case of (ep) as numeric functions, and its record in design.json.

The checker compares a case's body with the case's own ``V``, ``dV/dgamma``, ``mu`` and
inertia, and the simulation monitors the case's own integral ``F``. Both need numbers from
the case's expressions: they are the sympy objects the whitelisted parser built
(:mod:`chargedesign.scene.expressions`), turned into NumPy functions by ``sympy.lambdify``
(no text from a file reaches ``eval``: the printed code is sympy's own, of a tree whose
leaves are the state's names and rationals).

The design.json record (``case``) keeps the ``[case]`` table as written, so the case is
rebuilt through the same validation (:func:`case_from_record`), with the certificate's
verdict beside it.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np
import sympy as sp

from chargedesign.errors import InputError
from chargedesign.model.case import GAMMA, OMEGA
from chargedesign.model.case_file import STATE, CaseCertificate
from chargedesign.model.frame import frame_reading, time_rescaled
from chargedesign.scene.case_file import Case, case_from_table


def lambdified(
    outputs: Any, symbols: tuple[sp.Symbol, ...], module: str = "numpy", cse: bool = False
) -> Callable[..., Any]:
    """``outputs`` (one sympy expression or nested lists of them) of ``symbols`` compiled by
    ``sympy.lambdify``: the house's one wrapper of it for numbers at run time.

    ``module="numpy"``: the function takes columns of shape (n,) first (further arguments,
    e.g. parameters, may be floats) and returns one float array of shape (n, ...): constant
    entries broadcast, nested lists stacked along the axes after the first. ``module="math"``:
    Python floats in, nested lists out (one state, far less overhead). ``cse``: common
    subexpressions eliminated (worth it for gradients and Hessians).
    """
    function = sp.lambdify(symbols, outputs, modules=module, cse=cse)
    if module != "numpy":
        return function

    def evaluate(*columns: Any) -> np.ndarray:
        return _stacked(function(*columns), len(columns[0]))

    return evaluate


def _stacked(out: Any, m: int) -> np.ndarray:
    """Nested lists of scalars or (m,) arrays from a lambdified function, as one array (m, ...)."""
    if isinstance(out, (list, tuple)):
        return np.stack([_stacked(v, m) for v in out], axis=1)
    return np.broadcast_to(np.asarray(out, dtype=float), (m,))


@dataclass(frozen=True)
class CaseFunctions:
    """A case's V, grad V, mu and F as NumPy functions (SI: the case's numbers are read in
    J, kg m^2 and 1/s)."""

    case: Case
    _V: Callable[..., np.ndarray]
    _dV: tuple[Callable[..., np.ndarray], ...]
    _mu: tuple[Callable[..., np.ndarray], ...]
    _F: Callable[..., np.ndarray]
    _l_dot_gamma: Callable[..., np.ndarray]
    _terms: Callable[[float, float, float], Any]

    @property
    def inertia(self) -> np.ndarray:
        """``diag(A, B, C)``, kg m^2."""
        return np.diag([float(m) for m in self.case.inertia])

    def potential(self, gammas: np.ndarray) -> np.ndarray:
        """``V`` at each row of ``gammas`` (shape (n, 3)) -> (n,)."""
        g = np.asarray(gammas, dtype=float)
        return self._V(g[:, 0], g[:, 1], g[:, 2])

    def potential_gradient(self, gammas: np.ndarray) -> np.ndarray:
        """``dV/dgamma`` at each row -> (n, 3)."""
        g = np.asarray(gammas, dtype=float)
        return np.stack([f(g[:, 0], g[:, 1], g[:, 2]) for f in self._dV], axis=1)

    def gyroscopic(self, gammas: np.ndarray) -> np.ndarray:
        """``mu`` at each row -> (n, 3)."""
        g = np.asarray(gammas, dtype=float)
        return np.stack([f(g[:, 0], g[:, 1], g[:, 2]) for f in self._mu], axis=1)

    def momentum(self, gammas: np.ndarray) -> np.ndarray:
        """``l . gamma`` at each row (the gamma part of I3, J s) -> (n,)."""
        g = np.asarray(gammas, dtype=float)
        return self._l_dot_gamma(g[:, 0], g[:, 1], g[:, 2])

    def scalar_terms(self) -> Callable[[float, float, float], Any]:
        """``(g1, g2, g3) -> (dV/dg1, dV/dg2, dV/dg3, mu1, mu2, mu3)`` in Python floats."""
        return self._terms

    def integral(self, states: np.ndarray) -> np.ndarray:
        """The claimed ``F`` at each state ``[p, q, r, gamma1, gamma2, gamma3]`` -> (n,)."""
        x = np.atleast_2d(np.asarray(states, dtype=float))
        return self._F(*(x[:, k] for k in range(6)))

    def reference(self, gammas: np.ndarray) -> dict[str, np.ndarray]:
        """What the checker compares a body with: ``mu``, ``V`` and ``dV`` per orientation."""
        return {
            "mu": self.gyroscopic(gammas),
            "V": self.potential(gammas),
            "dV": self.potential_gradient(gammas),
        }


def case_functions(case: Case) -> CaseFunctions:
    """The numeric functions of ``case`` (its parameters substituted)."""
    return CaseFunctions(
        case=case,
        _V=lambdified(case.V, GAMMA_SYMBOLS),
        _dV=tuple(lambdified(sp.diff(case.V, x), GAMMA_SYMBOLS) for x in GAMMA_SYMBOLS),
        _mu=tuple(lambdified(m, GAMMA_SYMBOLS) for m in case.mu),
        _F=lambdified(case.integral, STATE),
        _l_dot_gamma=lambdified(case.l_dot_gamma, GAMMA_SYMBOLS),
        _terms=lambdified(
            [*(sp.diff(case.V, x) for x in GAMMA_SYMBOLS), *case.mu], GAMMA_SYMBOLS, "math"
        ),
    )


GAMMA_SYMBOLS: tuple[sp.Symbol, ...] = tuple(GAMMA)


def lagrangian_torque(case: Any) -> sp.Matrix:
    """``N(omega, gamma)`` (3, 1) of a :class:`~chargedesign.scene.case_file.Case`, each
    entry expanded, derived from the case's Lagrangian.

    ``L = 1/2 omega . I omega + l(gamma) . omega - V(gamma)`` with ``gamma`` carried by the body
    (``gamma' = gamma x omega``). The Euler-Poincare equations with an advected vector give

        d/dt (dL/domega) = dL/domega x omega + dL/dgamma x gamma,

    ``dL/domega = I omega + l`` and ``dL/dgamma = grad(l . omega) - grad V`` (gradients in
    gamma, omega held). With ``dl/dt = J gamma'`` (``J = dl/dgamma``) the torque of
    ``I omega' = (I omega) x omega + N`` is

        N = l x omega + dL/dgamma x gamma - J (gamma x omega),

    linear in omega: ``gamma x grad V + mu x omega`` with the paper's (mu). A case given by
    ``mu`` (no ``l``) takes ``N = gamma x grad V + mu x omega`` as written. The simulation's
    Taylor route integrates this torque (:mod:`chargedesign.simulation.taylor`); its NumPy route
    evaluates ``gamma x grad V + mu x omega`` from the case's ``mu``
    (:mod:`chargedesign.model.case_numeric`), so the two routes start from different forms.
    """
    grad_V = sp.Matrix([sp.diff(case.V, x) for x in GAMMA])
    if case.l is None:
        return (GAMMA.cross(grad_V) + case.mu.cross(OMEGA)).applyfunc(sp.expand)
    l_vec = sp.Matrix(case.l)
    l_dot_omega = l_vec.dot(OMEGA)
    dL_dgamma = sp.Matrix([sp.diff(l_dot_omega, x) for x in GAMMA]) - grad_V
    J = l_vec.jacobian(GAMMA)
    gamma_dot = GAMMA.cross(OMEGA)
    torque = l_vec.cross(OMEGA) + dL_dgamma.cross(GAMMA) - J * gamma_dot
    return torque.applyfunc(sp.expand)


#: the keys of a certificate that design.json's ``case.certificate`` keeps
VERDICT_KEYS = ("holds", "independent", "holds_for_all_parameters", "singular", "seconds")


def certificate_verdict(certificate: CaseCertificate) -> dict[str, Any]:
    """design.json's ``case.certificate``: the certificate's verdict (:data:`VERDICT_KEYS`)."""
    exact = certificate.to_dict()["case"]
    return {k: exact[k] for k in VERDICT_KEYS}


def case_record(
    table: Mapping[str, Any], case: Case, certificate: CaseCertificate | None
) -> dict[str, Any]:
    """design.json's ``case``: the ``[case]`` table as written (``table``, to rebuild the
    case), its name, inertia (kg m^2), V, integral, level and the certificate's verdict
    (None until the certificate is made: :func:`certificate_verdict`)."""
    return {
        "name": case.name,
        "inertia": [float(m) for m in case.inertia],
        "V": sp.sstr(case.V),
        "integral": sp.sstr(case.integral),
        "level": "general" if case.level is None else str(case.level),
        "certificate": None if certificate is None else certificate_verdict(certificate),
        "table": dict(table),
    }


def case_from_record(record: Any, where: str = "design.case") -> Case:
    """The case of a design.json ``case`` record, validated again from its ``table``."""
    if not isinstance(record, Mapping) or not isinstance(record.get("table"), Mapping):
        raise InputError(f"{where}: expected an object with the [case] table under 'table'")
    return case_from_table(record["table"], f"{where}.table")


def body_case(record: Any, larmor: Any = None, time_rate: float | None = None) -> Case:
    """The case a body's own elements realise, of a design.json ``case`` record.

    A body designed at time rate ``s`` (``design.time_rate``; None or 1: the record's own)
    realises the record's case at that rate (:func:`chargedesign.model.frame.time_rescaled`:
    ``s^2 V``, ``s l``; the frontier's bodies). With the ``frame`` Larmor reading at rate n
    (``design.larmor``, already at the body's rate) the elements realise the case read in axes
    turning at ``-n`` (:func:`chargedesign.model.frame.frame_reading`; for the theorem that is
    its n = 0 case, up to a constant on the sphere): the record's case is what the body does in
    axes turning at n. Otherwise the record's case itself."""
    case = case_from_record(record)
    if time_rate is not None and time_rate != 1.0:
        case = time_rescaled(case, time_rate)
    if larmor is not None and larmor.is_frame and larmor.rate != 0.0:
        return frame_reading(case, -larmor.rate)
    return case


def design_case_functions(
    record: Any, larmor: Any = None, time_rate: float | None = None
) -> CaseFunctions:
    """The numeric functions of the case a design's elements realise (:func:`body_case`)."""
    return case_functions(body_case(record, larmor, time_rate))


def simulated_case_functions(
    record: Any, larmor: Any = None, time_rate: float | None = None
) -> CaseFunctions:
    """:func:`design_case_functions` for a run (:func:`simulated_functions`)."""
    return simulated_functions(body_case(record, larmor, time_rate))


def singular_factors(expressions: Any) -> list[str]:
    """``"<factor> = 0"`` for each factor of a denominator of ``expressions`` that depends on
    the state (the case's numbers substituted), sorted: where the case's numbers blow up."""
    found = set()
    for expr in expressions:
        denominator = sp.fraction(sp.together(expr))[1]
        for factor, _ in sp.factor_list(denominator)[1]:
            if factor.free_symbols & set(STATE):
                found.add(f"{sp.sstr(factor)} = 0")
    return sorted(found)


def simulated_functions(case: Case) -> CaseFunctions:
    """:func:`case_functions` for a run: a case with singular terms (a denominator in gamma, as
    Goriachev's ``1/gamma3^2``) is refused in one line: the integrators take polynomial
    torques (its terms are infinite on the zero set the message names)."""
    where = singular_factors([case.V, *(case.l if case.l is not None else case.mu)])
    if where:
        raise InputError(
            f"case {case.name}: singular where {'; '.join(where)}; simulate moves cases whose V "
            "and l (or mu) are polynomials in gamma (verify certifies the others)"
        )
    return case_functions(case)


__all__ = [
    "VERDICT_KEYS",
    "CaseFunctions",
    "body_case",
    "case_from_record",
    "case_functions",
    "case_record",
    "certificate_verdict",
    "design_case_functions",
    "lagrangian_torque",
    "lambdified",
    "simulated_case_functions",
    "simulated_functions",
    "singular_factors",
]
