"""Polynomials in gamma built from moment contractions: the reduced force route.

Every field is an axisymmetric harmonic polynomial ``Phi = sum_k f_k u_k(Z, S)`` with
``Z = r . gamma`` and ``S = |r|^2`` in body axes (see :mod:`chargedesign.fields`). Summed over
the elements of a body, each static quantity is a polynomial in gamma whose coefficients are
Cartesian moments of the body contracted with the field's coefficients:

    sum_i w_i Z_i^a S_i^j = sum_{|e| = a} (a! / e!) gamma^e  sum_i w_i S_i^j r_i^e.

The polynomial in gamma is the natural extension off the unit sphere (S does not depend on
gamma), so its gradient gives the potential torque ``gamma x dV/dgamma`` exactly; for
polynomial fields the route is exact, not an approximation.
"""

from __future__ import annotations

from collections import defaultdict
from math import factorial

import numpy as np

from chargedesign.moments import moment_key, monomial_matrix

#: a polynomial in (Z, S): {(a, j): coefficient of Z^a S^j}
ZSPoly = dict[tuple[int, int], float]
#: a polynomial in gamma: {(e1, e2, e3): coefficient of gamma1^e1 gamma2^e2 gamma3^e3}
GammaPoly = dict[tuple[int, int, int], float]


def zonal_polynomials(degree: int) -> list[ZSPoly]:
    """``u_0 .. u_degree`` with ``u_k = R^k P_k(Z/R)`` as polynomials in Z and S = R^2.

    Uses ``(k + 1) u_{k+1} = (2k + 1) Z u_k - k S u_{k-1}``, ``u_0 = 1``, ``u_1 = Z``.
    """
    polys: list[ZSPoly] = [{(0, 0): 1.0}, {(1, 0): 1.0}]
    for k in range(1, degree):
        nxt: ZSPoly = defaultdict(float)
        for (a, j), c in polys[k].items():
            nxt[(a + 1, j)] += (2 * k + 1) / (k + 1) * c
        for (a, j), c in polys[k - 1].items():
            nxt[(a, j + 1)] -= k / (k + 1) * c
        polys.append(dict(nxt))
    return polys[: degree + 1]


def field_polynomial(legendre: tuple[float, ...]) -> ZSPoly:
    """``Phi = sum_k f_k u_k`` as a polynomial in Z and S."""
    out: ZSPoly = defaultdict(float)
    for k, u in enumerate(zonal_polynomials(len(legendre)), start=0):
        if k == 0:
            continue
        f = legendre[k - 1]
        if f != 0.0:
            for key, c in u.items():
                out[key] += f * c
    return dict(out)


def flux_polynomial(legendre: tuple[float, ...]) -> ZSPoly:
    """The flux function ``psi = -(S - Z^2) sum_k f_k v_k / (k + 1)`` (natural gauge).

    ``v_k = R^(k-1) P_k'(Z/R)``: ``v_0 = 0``, ``v_1 = 1``, ``v_{k+1} = S v_{k-1} + (2k+1) u_k``.
    ``sum_i q_i psi_i`` is the charges' share of the canonical angular momentum about Z.
    """
    K = len(legendre)
    us = zonal_polynomials(max(K, 1))
    vs: list[ZSPoly] = [{}, {(0, 0): 1.0}]
    for k in range(1, K):
        nxt: ZSPoly = defaultdict(float)
        for (a, j), c in vs[k - 1].items():
            nxt[(a, j + 1)] += c
        for key, c in us[k].items():
            nxt[key] += (2 * k + 1) * c
        vs.append(dict(nxt))
    g: ZSPoly = defaultdict(float)
    for k in range(1, K + 1):
        f = legendre[k - 1]
        if f != 0.0:
            for key, c in vs[k].items():
                g[key] += f / (k + 1) * c
    out: ZSPoly = defaultdict(float)
    for (a, j), c in g.items():
        out[(a, j + 1)] -= c
        out[(a + 2, j)] += c
    return dict(out)


def derivative_z(poly: ZSPoly) -> ZSPoly:
    """``d/dZ`` of a polynomial in Z and S."""
    return {(a - 1, j): a * c for (a, j), c in poly.items() if a > 0}


def derivative_s(poly: ZSPoly) -> ZSPoly:
    """``d/dS`` of a polynomial in Z and S (at fixed Z)."""
    return {(a, j - 1): j * c for (a, j), c in poly.items() if j > 0}


def multiply(p: ZSPoly, q: ZSPoly) -> ZSPoly:
    """The product of two polynomials in Z and S."""
    out: ZSPoly = defaultdict(float)
    for (a, j), c in p.items():
        for (b, k), d in q.items():
            out[(a + b, j + k)] += c * d
    return dict(out)


def gradient_squared(legendre: tuple[float, ...]) -> ZSPoly:
    """``|grad Phi|^2 = Phi_Z^2 + 4 Z Phi_Z Phi_S + 4 S Phi_S^2`` as a polynomial in Z and S
    (``grad Phi = Phi_Z e_Z + 2 Phi_S X``)."""
    phi = field_polynomial(legendre)
    pz, ps = derivative_z(phi), derivative_s(phi)
    out: ZSPoly = defaultdict(float)
    for key, c in multiply(pz, pz).items():
        out[key] += c
    for (a, j), c in multiply(pz, ps).items():
        out[(a + 1, j)] += 4.0 * c
    for (a, j), c in multiply(ps, ps).items():
        out[(a, j + 1)] += 4.0 * c
    return dict(out)


def _compositions(order: int) -> list[tuple[int, int, int]]:
    out = []
    for i in range(order, -1, -1):
        for j in range(order - i, -1, -1):
            out.append((i, j, order - i - j))
    return out


def _multinomial(e: tuple[int, int, int]) -> float:
    return factorial(sum(e)) / (factorial(e[0]) * factorial(e[1]) * factorial(e[2]))


def contract(
    poly: ZSPoly,
    points: np.ndarray,
    weights: np.ndarray,
    shift: tuple[int, int, int] = (0, 0, 0),
) -> GammaPoly:
    """``sum_i w_i r_i^shift P(r_i . gamma, |r_i|^2)`` as a polynomial in gamma.

    Parameters
    ----------
    poly : dict
        The polynomial ``P`` in Z and S.
    points : ndarray, shape (n, 3)
        Body positions in m.
    weights : ndarray, shape (n,)
        Element weights (charges, masses, ...).
    shift : tuple of int
        Extra monomial ``r^shift`` of each element (e.g. ``(1, 0, 0)`` for the x component of
        ``sum w P r``).
    """
    out: GammaPoly = defaultdict(float)
    if len(points) == 0:
        return {}
    S = np.einsum("ij,ij->i", points, points)
    for (a, j), c in poly.items():
        if c == 0.0:
            continue
        exps = _compositions(a)
        keys = [moment_key((e[0] + shift[0], e[1] + shift[1], e[2] + shift[2])) for e in exps]
        moments = monomial_matrix(points, keys) @ (weights * S**j)
        for e, m in zip(exps, moments, strict=True):
            out[e] += c * _multinomial(e) * float(m)
    return dict(out)


def add_into(target: GammaPoly, poly: GammaPoly, scale: float = 1.0) -> None:
    """``target += scale * poly`` in place."""
    for key, c in poly.items():
        target[key] = target.get(key, 0.0) + scale * c


def times_gamma(poly: GammaPoly, axis: int) -> GammaPoly:
    """``gamma_axis * poly``."""
    out: GammaPoly = {}
    for e, c in poly.items():
        key = (e[0] + (axis == 0), e[1] + (axis == 1), e[2] + (axis == 2))
        out[key] = out.get(key, 0.0) + c
    return out


def gamma_gradient(poly: GammaPoly) -> list[GammaPoly]:
    """The three partial derivatives ``d poly / d gamma_l``."""
    grads: list[GammaPoly] = [{}, {}, {}]
    for e, c in poly.items():
        for axis in range(3):
            if e[axis] > 0:
                key = (e[0] - (axis == 0), e[1] - (axis == 1), e[2] - (axis == 2))
                g = grads[axis]
                g[key] = g.get(key, 0.0) + e[axis] * c
    return grads


class PolynomialBank:
    """Several polynomials in gamma on one monomial basis, evaluated with one matrix product.

    Parameters
    ----------
    polys : list of dict
        Polynomials in gamma (``{(e1, e2, e3): coefficient}``).
    """

    def __init__(self, polys: list[GammaPoly]) -> None:
        exps = sorted({e for p in polys for e in p}) or [(0, 0, 0)]
        self.exponents = np.array(exps, dtype=np.intp).reshape(-1, 3)
        self.degree = int(self.exponents.sum(axis=1).max())
        index = {e: i for i, e in enumerate(exps)}
        self.coefficients = np.zeros((len(exps), len(polys)))
        for col, p in enumerate(polys):
            for e, c in p.items():
                self.coefficients[index[e], col] = c
        self._exps = [tuple(int(x) for x in e) for e in self.exponents]

    def monomials(self, g1: float, g2: float, g3: float) -> list[float]:
        """The basis monomials at one gamma, as Python floats (the single-state hot path)."""
        p1, p2, p3 = [1.0], [1.0], [1.0]
        for _ in range(self.degree):
            p1.append(p1[-1] * g1)
            p2.append(p2[-1] * g2)
            p3.append(p3[-1] * g3)
        return [p1[i] * p2[j] * p3[k] for i, j, k in self._exps]

    def __call__(self, gammas: np.ndarray) -> np.ndarray:
        """Values at ``gammas``, ndarray shape (m, 3) -> ndarray shape (m, len(polys))."""
        return monomial_values(gammas, self.exponents, self.degree) @ self.coefficients


def monomial_values(gammas: np.ndarray, exponents: np.ndarray, degree: int) -> np.ndarray:
    """The monomials ``gamma^e`` of the rows ``e`` of ``exponents`` (K, 3), all of degree
    <= ``degree``, at ``gammas`` (m, 3): ndarray shape (m, K)."""
    m = gammas.shape[0]
    powers = np.empty((m, degree + 1, 3))
    powers[:, 0, :] = 1.0
    for d in range(1, degree + 1):
        np.multiply(powers[:, d - 1, :], gammas, out=powers[:, d, :])
    e = exponents
    return powers[:, e[:, 0], 0] * powers[:, e[:, 1], 1] * powers[:, e[:, 2], 2]
