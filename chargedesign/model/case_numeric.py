"""A case of (ep) as numeric functions, and its record in design.json.

The checker compares a case's body with the case's own ``V``, ``dV/dgamma``, ``mu`` and
inertia, and the simulation monitors the case's own integral ``F``. Both need numbers from
the case's expressions: they are the sympy objects the whitelisted parser built
(:mod:`chargedesign.model.expressions`), turned into NumPy functions by ``sympy.lambdify``
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
from chargedesign.model.case import GAMMA
from chargedesign.model.case_file import STATE, Case, CaseCertificate, case_from_table


def _vectorised(expr: sp.Expr, symbols: tuple[sp.Symbol, ...]) -> Callable[..., np.ndarray]:
    """``expr`` of ``symbols`` as a NumPy function broadcasting over its arguments' shape."""
    function = sp.lambdify(symbols, expr, modules="numpy")

    def evaluate(*columns: np.ndarray) -> np.ndarray:
        return np.broadcast_to(np.asarray(function(*columns), dtype=float), columns[0].shape)

    return evaluate


@dataclass(frozen=True)
class CaseFunctions:
    """A case's V, grad V, mu and F as NumPy functions (SI: the case's numbers are read in
    J, kg m^2 and 1/s)."""

    case: Case
    _V: Callable[..., np.ndarray]
    _dV: tuple[Callable[..., np.ndarray], ...]
    _mu: tuple[Callable[..., np.ndarray], ...]
    _F: Callable[..., np.ndarray]

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
        _V=_vectorised(case.V, GAMMA_SYMBOLS),
        _dV=tuple(_vectorised(sp.diff(case.V, x), GAMMA_SYMBOLS) for x in GAMMA_SYMBOLS),
        _mu=tuple(_vectorised(m, GAMMA_SYMBOLS) for m in case.mu),
        _F=_vectorised(case.integral, STATE),
    )


GAMMA_SYMBOLS: tuple[sp.Symbol, ...] = tuple(GAMMA)


def case_record(
    table: Mapping[str, Any], case: Case, certificate: CaseCertificate | None
) -> dict[str, Any]:
    """design.json's ``case``: the ``[case]`` table as written (``table``, to rebuild the
    case), its name, inertia (kg m^2), V, integral, level and the certificate's verdict."""
    verdict = None
    if certificate is not None:
        exact = certificate.to_dict()["case"]
        verdict = {
            k: exact[k]
            for k in ("holds", "independent", "holds_for_all_parameters", "singular", "seconds")
        }
    return {
        "name": case.name,
        "inertia": [float(m) for m in case.inertia],
        "V": sp.sstr(case.V),
        "integral": sp.sstr(case.integral),
        "level": "general" if case.level is None else str(case.level),
        "certificate": verdict,
        "table": dict(table),
    }


def case_from_record(record: Any, where: str = "design.case") -> Case:
    """The case of a design.json ``case`` record, validated again from its ``table``."""
    if not isinstance(record, Mapping) or not isinstance(record.get("table"), Mapping):
        raise InputError(f"{where}: expected an object with the [case] table under 'table'")
    return case_from_table(record["table"], f"{where}.table")


def design_case_functions(record: Any) -> CaseFunctions:
    """The numeric functions of a design.json ``case`` record (:func:`case_from_record`)."""
    return case_functions(case_from_record(record))


def simulated_case_functions(record: Any) -> CaseFunctions:
    """:func:`design_case_functions` for a run: the simulation's body model has the theorem's
    inertia diag(2C, 2C, C), so a case of another inertia is refused in one line (its motion
    would be of the wrong body, and its integral's drift meaningless)."""
    functions = design_case_functions(record)
    A, B, C = functions.case.inertia
    if not A == B == 2 * C:
        raise InputError(
            f"case {functions.case.name}: inertia diag({A}, {B}, {C}) is not diag(2C, 2C, C); "
            "simulate moves bodies of the theorem's inertia only (design and check take it)"
        )
    return functions


__all__ = [
    "CaseFunctions",
    "case_from_record",
    "case_functions",
    "case_record",
    "design_case_functions",
    "simulated_case_functions",
]
