"""Kowalevski's bifurcation set on the zero area level, by Appelrot class.

Kharlamov (1983, J. Appl. Math. Mech. 47) and Bolsinov-Richter-Fomenko (2000, Sbornik Math.
191) write the Kowalevski top as ``H = w1^2 + w2^2 + w3^2 / 2 - a1`` and
``K = (w1^2 - w2^2 + a1)^2 + (2 w1 w2 + a2)^2`` with the area constant ``g``. On ``g = 0``
the critical values lie on

- ``k = 0`` (``h >= 0``): Appelrot class I, Delone's motions (``xi = 0``, where K vanishes
  to second order);
- ``k = (h - g^2)^2 = h^2`` (``h >= -1``): class II;
- ``k = 1`` (``h >= -1``) and ``k = 1 + h^2`` (``h >= 0``): classes III and IV, which on
  g = 0 lie on these two curves (the tool does not tell the two classes apart on them, and
  names them together).

The first two are the published forms at ``g = 0`` (as the issue quotes them). The last two
were not found in a text the project could read: they are the rank-one values this package
finds on the level (Gauss-Newton on the rank-drop equations from random states), fitted by
these exact forms, which hold to 7.6e-12 on every traced point; they are not proven
symbolically here. The tests check both ways: every traced point on one of the four curves,
every curve traced over the energy range.

The catalogue writes the case as ``H = C (p^2 + q^2 + r^2 / 2 + a gamma1)`` with
``F = (p^2 - q^2 - a gamma1)^2 + (2 p q - a gamma2)^2``. With ``p = sqrt(a) w1`` (time read in
units of ``1 / sqrt(a)``) and the body turned by pi about its axis (``gamma1, gamma2 = -a1,
-a2``, ``p, q = -w1, -w2``, which keeps every product) these are ``H = C a H_BRF`` and
``F = a^2 K_BRF`` exactly (a test checks it with sympy). So a point ``(h, k)`` of the case is
``(h / (C a), k / a^2)`` in the published normalization.
"""

from __future__ import annotations

import numpy as np
import sympy as sp

from chargedesign.model.case import GAMMA, g1, g2, p, q
from chargedesign.scene.case_file import Case

#: the curves on g = 0: (name, F(h, k) vanishing on it, least h), published normalization
CURVES: tuple[tuple[str, str, float], ...] = (
    ("Appelrot I (Delone): k = 0", "k", 0.0),
    ("Appelrot II: k = (h - g^2)^2", "k - h**2", -1.0),
    ("Appelrot III/IV: k = 1", "k - 1", -1.0),
    ("Appelrot III/IV: k = 1 + h^2", "k - 1 - h**2", 0.0),
)

#: a traced point lies on a curve when |F(h, k)| is below this (published normalization)
ON_CURVE = 1e-6


def curve_value(index: int, h: np.ndarray, k: np.ndarray) -> np.ndarray:
    """The left side of curve ``index`` at published ``(h, k)``."""
    return {
        0: lambda: k,
        1: lambda: k - h**2,
        2: lambda: k - 1.0,
        3: lambda: k - 1.0 - h**2,
    }[index]()


def curve_points(index: int, h: np.ndarray) -> np.ndarray:
    """``k`` on curve ``index`` at published energies ``h`` (every curve is ``k - f(h) = 0``)."""
    return -np.asarray(curve_value(index, np.asarray(h, float), np.zeros_like(h, dtype=float)))


def kowalevski_constants(case: Case) -> tuple[float, float] | None:
    """``(C, a)`` when ``case`` is Kowalevski's top as the catalogue writes it (inertia
    ``(2C, 2C, C)``, ``l = 0``, ``V = C a gamma1``, ``F`` the Kowalevski integral), else None."""
    A, B, C = case.inertia
    if not (A == B == 2 * C) or case.l is None or any(e != 0 for e in case.l):
        return None
    a = sp.simplify(case.V / (C * g1))
    if a.free_symbols or a == 0:
        return None
    target = (p**2 - q**2 - a * g1) ** 2 + (2 * p * q - a * g2) ** 2
    if sp.expand(case.integral - target) != 0 or set(case.V.free_symbols) - set(GAMMA):
        return None
    return float(C), float(a)


def appelrot_class(hk: np.ndarray, C: float, a: float) -> str | None:
    """The name of the curve on which every point of a traced branch ``hk`` (m, 2) lies
    (case units), or None."""
    h, k = hk[:, 0] / (C * a), hk[:, 1] / a**2
    for index, (name, _, _) in enumerate(CURVES):
        if np.all(np.abs(curve_value(index, h, k)) <= ON_CURVE * np.maximum(1.0, np.abs(k))):
            return name
    return None
