"""The direct force route's fast kernel: element by element, one evaluation in a few microseconds.

The fields are evaluated at every element's rotated position on every call. In body axes the
point ``r`` sits at ``X = R r`` with ``Z = X . e_Z = r . gamma`` and ``S = |X|^2 = |r|^2``;
``S`` does not depend on the attitude, so each field quantity an element needs is, at that
element, a polynomial in ``Z`` whose coefficients depend on the element only
(:func:`chargedesign.fields.zonal_z_coefficients`, the zonal recurrence run on coefficient
arrays). Those coefficients, the charges, masses and dipole moments are fixed at construction;
a call computes ``Z_i = r_i . gamma`` for every element, the field quantities at every element
(Horner's rule, all elements in one numpy pass) and sums the element torques.

Forces and couples per element, in body axes (``grad Phi = Phi_Z gamma + 2 Phi_S r``,
``B = -grad Phi_m``, ``Phi_Z`` at fixed ``S``)::

    electric, gravity   F = -w grad Phi              r x F = -w Phi_Z (r x gamma)
    induced             U = -w |grad Phi|^2 / (2 mu0) = -w G(Z) / (2 mu0), D += U'(Z) r
    lorentz             F = q (omega x r) x B        r x F = -q (r . B) (r x omega)
    magnetization       F = grad(sigma . B) = -H sigma, couple sigma x B
                        r x F + sigma x B = -(Phi_Z sigma + e r) x gamma,
                        e = Phi_ZZ (gamma . sigma) + 2 Phi_ZS (r . sigma)

(``r x r = 0``; in the dipole's torque the ``Phi_S`` terms ``-2 Phi_S (sigma x r)`` of the
couple and ``-2 Phi_S (r x sigma)`` of the force cancel). The total is written as the reduced
route's ``gamma x D + M x omega`` with, summed over the elements::

    D = sum_{charges, masses} w Phi_Z r + sum_{dipoles} (Phi_Z sigma + e r)
    M = sum_{charges} -q (r . B) r = sum_{charges} q (Z Phi_Z + 2 S Phi_S) r

but every term is an element's own field value at its own position for the current gamma,
not a moment of the body: the cost is linear in the number of elements.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np

from chargedesign.constants import MU_0
from chargedesign.fields import zonal_z_coefficients
from chargedesign.simulation.body import Body

#: columns of a row's output vector: D (3), M (3), and T (3 x 3, row-major) with D += T gamma
_D, _M, _T = slice(0, 3), slice(3, 6), slice(6, 15)

#: the physical effects the kernel computes
KERNEL_EFFECTS = ("lorentz", "electric", "magnetization", "gravity", "induced")


class DirectKernel:
    """Element torques of a body's physical effects, for one or many states.

    Each *row* is one field quantity at one element: a polynomial in ``Z`` (coefficients
    fixed by the element's ``S`` and weight) times a fixed vector added to ``D``, ``M`` or
    the matrix ``T`` (``D += T gamma``).

    Parameters
    ----------
    body : Body
        Elements and fields (already validated by :class:`~chargedesign.simulation.body.Body`).
    effects : sequence of str
        Physical effects among :data:`KERNEL_EFFECTS`.
    """

    def __init__(self, body: Body, effects: Sequence[str]) -> None:
        positions: list[np.ndarray] = []
        polys: list[np.ndarray] = []
        vectors: list[np.ndarray] = []

        def add(pts: np.ndarray, poly: np.ndarray, vec: np.ndarray) -> None:
            keep = np.any(poly != 0.0, axis=1) & np.any(vec != 0.0, axis=1)
            positions.append(pts[keep])
            polys.append(poly[keep])
            vectors.append(vec[keep])

        def rows(n: int, where: slice, values: np.ndarray) -> np.ndarray:
            out = np.zeros((n, 15))
            out[:, where] = values
            return out

        for name in effects:
            if name not in KERNEL_EFFECTS:
                raise ValueError(f"effects: {name!r} is not a physical effect")
            if name in ("electric", "gravity"):
                pts, w = (
                    (body.charge_positions, body.charge_values)
                    if name == "electric"
                    else (body.mass_positions, body.mass_values)
                )
                c = _coefficients(body, name, pts, 1)
                add(pts, w[:, None] * c["Z"], rows(len(pts), _D, pts))
            elif name == "lorentz":
                pts, q = body.charge_positions, body.charge_values
                S = np.einsum("ij,ij->i", pts, pts)
                c = _coefficients(body, "magnetic", pts, 1)
                # -r . B = r . grad Phi = Z Phi_Z + 2 S Phi_S
                r_dot_grad = _times_z(c["Z"])
                r_dot_grad[:, :-1] += 2.0 * S[:, None] * c["S"]
                add(pts, q[:, None] * r_dot_grad, rows(len(pts), _M, pts))
            elif name == "induced":
                # U = -w G(Z) / (2 mu0), G = |grad Phi|^2 = Phi_Z^2 + 4 Z Phi_Z Phi_S + 4 S Phi_S^2
                # at the part's S: D = dU/dgamma = -w G'(Z) r / (2 mu0)
                pts, w = body.part_positions, body.part_susceptances
                S = np.einsum("ij,ij->i", pts, pts)
                c = _coefficients(body, "magnetic", pts, 1)
                pz, ps = c["Z"], c["S"]
                g = _times_z(_product(pz, ps)) * 4.0
                g = _add(g, _product(pz, pz))
                g = _add(g, 4.0 * S[:, None] * _product(ps, ps))
                slope = g[:, 1:] * np.arange(1, g.shape[1])
                add(pts, -w[:, None] / (2.0 * MU_0) * slope, rows(len(pts), _D, pts))
            else:  # magnetization
                pts, sig = body.dipole_positions, body.dipole_moments
                c = _coefficients(body, "magnetic", pts, 2)
                r_dot_sigma = np.einsum("ij,ij->i", pts, sig)
                add(pts, c["Z"], rows(len(pts), _D, sig))
                add(pts, 2.0 * r_dot_sigma[:, None] * c["ZS"], rows(len(pts), _D, pts))
                r_sigma = np.einsum("ia,ib->iab", pts, sig).reshape(-1, 9)
                add(pts, c["ZZ"], rows(len(pts), _T, r_sigma))
        width = max((p.shape[1] for p in polys), default=1)
        #: element position per row, ndarray shape (J, 3)
        self.positions = np.ascontiguousarray(
            np.concatenate(positions) if positions else np.zeros((0, 3))
        )
        # coefficient of Z^a of every row in row a (contiguous for Horner's rule)
        padded = [np.pad(p, ((0, 0), (0, width - p.shape[1]))) for p in polys]
        stacked = np.concatenate(padded) if padded else np.zeros((0, width))
        # trailing zero coefficients (f_k = 0 at the top, zero derivatives) cost Horner steps
        nonzero = np.flatnonzero(np.any(stacked != 0.0, axis=0))
        stacked = stacked[:, : (int(nonzero[-1]) + 1 if len(nonzero) else 1)]
        self.coefficients = np.ascontiguousarray(stacked.T)  # (width, J)
        self.vectors = np.ascontiguousarray(
            np.concatenate(vectors) if vectors else np.zeros((0, 15))
        )
        self.has_matrix = bool(np.any(self.vectors[:, _T] != 0.0))

    @property
    def rows(self) -> int:
        """Number of (element, field quantity) rows evaluated per call."""
        return len(self.positions)

    def row_values(self, gamma: np.ndarray) -> np.ndarray:
        """Every row's field quantity at the rotated element, ndarray (m, J) for gamma (m, 3)."""
        Z = gamma @ self.positions.T
        return _horner(self.coefficients, Z)

    def terms(self, gamma: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``D`` and ``M`` (torque ``gamma x D + M x omega``), each ndarray shape (m, 3)."""
        out = self.row_values(gamma) @ self.vectors  # (m, 15)
        D = out[:, _D].copy()
        if self.has_matrix:
            D += np.einsum("mab,mb->ma", out[:, _T].reshape(-1, 3, 3), gamma)
        return D, out[:, _M]

    def torque(self, omega: np.ndarray, gamma: np.ndarray) -> np.ndarray:
        """Torque about O in body axes (N m), ndarray shape (m, 3).

        Parameters
        ----------
        omega : ndarray, shape (m, 3)
            Angular velocities in body axes, 1/s.
        gamma : ndarray, shape (m, 3)
            Unit vectors of space Z in body axes.
        """
        D, M = self.terms(gamma)
        return cross(gamma, D) + cross(M, omega)

    def scalar_function(self) -> Callable[[float, float, float], list[float]]:
        """``(g1, g2, g3) -> [D1, D2, D3, M1, M2, M3]`` for one state, in Python floats.

        The fast path of a single trajectory: one matrix-vector product for the ``Z`` of every
        row, Horner's rule in place on arrays of the rows, one product with the row vectors.
        """
        P = self.positions
        coeffs = list(self.coefficients[::-1])  # highest power first
        top, rest = coeffs[0], coeffs[1:]
        V = self.vectors
        dot = np.dot
        has_matrix = self.has_matrix

        def terms(g1: float, g2: float, g3: float) -> list[float]:
            Z = dot(P, (g1, g2, g3))
            if rest:
                v = top * Z
                v += rest[0]
                for c in rest[1:]:
                    v *= Z
                    v += c
            else:
                v = top
            out = dot(v, V).tolist()
            if has_matrix:
                t = out[6:]
                out[0] += t[0] * g1 + t[1] * g2 + t[2] * g3
                out[1] += t[3] * g1 + t[4] * g2 + t[5] * g3
                out[2] += t[6] * g1 + t[7] * g2 + t[8] * g3
            return out[:6]

        return terms


def _coefficients(body: Body, kind: str, pts: np.ndarray, order: int) -> dict[str, np.ndarray]:
    field = body.field(kind)
    S = np.einsum("ij,ij->i", pts, pts)
    return zonal_z_coefficients(np.asarray(field.legendre, dtype=np.float64), S, order)


def _product(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Row by row, the coefficients of the product of two polynomials in Z."""
    out = np.zeros((a.shape[0], a.shape[1] + b.shape[1] - 1))
    for i in range(a.shape[1]):
        out[:, i : i + b.shape[1]] += a[:, i : i + 1] * b
    return out


def _add(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Row by row, the coefficients of the sum of two polynomials in Z."""
    width = max(a.shape[1], b.shape[1])
    return np.pad(a, ((0, 0), (0, width - a.shape[1]))) + np.pad(
        b, ((0, 0), (0, width - b.shape[1]))
    )


def _times_z(c: np.ndarray) -> np.ndarray:
    """Coefficients of ``Z p(Z)`` from those of ``p`` (one more column)."""
    out = np.zeros((c.shape[0], c.shape[1] + 1))
    out[:, 1:] = c
    return out


def _horner(coefficients: np.ndarray, Z: np.ndarray) -> np.ndarray:
    """``sum_a coefficients[a] Z^a`` by Horner's rule; coefficients (width, J), Z (..., J)."""
    v = np.broadcast_to(coefficients[-1], Z.shape).copy()
    for c in coefficients[-2::-1]:
        v *= Z
        v += c
    return v


def cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Row-wise cross product of (..., 3) arrays, components written out (faster than np.cross);
    the one of the numpy routes (the simulation's system and this kernel, the tolerance ensemble,
    the testbed)."""
    out = np.empty(np.broadcast_shapes(a.shape, b.shape))
    out[..., 0] = a[..., 1] * b[..., 2] - a[..., 2] * b[..., 1]
    out[..., 1] = a[..., 2] * b[..., 0] - a[..., 0] * b[..., 2]
    out[..., 2] = a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]
    return out
