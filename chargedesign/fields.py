"""Axisymmetric harmonic fields: potentials, gradients, Hessians and the magnetic flux function.

Every external field is an axisymmetric harmonic polynomial about the space axis Z,

    Phi(X) = sum_{k>=1} f_k u_k(X),   u_k(X) = R^k P_k(Z / R),   R = |X|,

stored as ``legendre = (f_1, f_2, ...)`` (see CONTRACT.md). ``u_k`` is a polynomial in ``Z``
and ``S = R^2``; it is evaluated by the three-term recurrence

    (k + 1) u_{k+1} = (2k + 1) Z u_k - k S u_{k-1},   u_0 = 1,  u_1 = Z,

which has no singularity at R = 0. The partial derivatives of ``u_k(Z, S)`` (``Phi_Z`` at fixed
S, ``Phi_S`` at fixed Z, and second derivatives) follow exactly by differentiating the
recurrence term by term; first-order ``Phi_Z`` uses the Cartesian identity
``(d/dZ)_{X,Y} u_k = k u_{k-1}``, i.e. ``Phi_Z = sum_k k f_k u_{k-1} - 2 Z Phi_S``.
With ``Phi = Phi(Z, S)``:

    grad Phi = Phi_Z e_Z + 2 Phi_S X,
    Hess Phi = Phi_ZZ e_Z e_Z^T + 2 Phi_ZS (e_Z X^T + X e_Z^T) + 4 Phi_SS X X^T + 2 Phi_S I.

In body axes a point ``r`` sits at ``X = R r`` with ``R^T e_Z = gamma``, so ``Z = r . gamma``
and ``S = |r|^2``: the same formulas hold with ``e_Z -> gamma`` and ``X -> r``.

Magnetic vector potential (natural axisymmetric gauge): for ``B = -grad Phi``,
``A = -g(Z, S) (e_Z x X)`` with ``g = sum_k f_k v_k / (k + 1)``, ``v_k = R^(k-1) P_k'(Z/R)``,
``v_0 = 0``, ``v_1 = 1``, ``v_{k+1} = S v_{k-1} + (2k + 1) u_k``. The Stokes flux function is
``psi = rho A_phi = -rho^2 g``, ``rho^2 = S - Z^2``. See docs/fields-and-moments.md.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from chargedesign.formatting import PLAIN, fmt
from chargedesign.validation import as_array, as_finite_float, as_points, input_error

#: points per block of :func:`zonal_sums` (8192 doubles: 64 kB an array, the recurrence's dozen
#: in cache; measured 2-3x faster than one block of 5e5 points)
ZONAL_BLOCK = 1 << 13


def zonal_sums(
    coeffs: np.ndarray, Z: np.ndarray, S: np.ndarray, order: int, *, want_value: bool = True
) -> dict[str, np.ndarray]:
    """Sums ``sum_k f_k d(u_k)`` of the zonal solid harmonics and their partial derivatives.

    ``u_k`` is taken as a function of ``Z`` and ``S = R^2``; ``"Z"`` is ``dPhi/dZ`` at fixed
    ``S`` (not the Cartesian ``d/dZ`` at fixed X, Y, which is ``Phi_Z + 2 Z Phi_S``).

    Parameters
    ----------
    coeffs : ndarray, shape (K,)
        ``f_1 .. f_K``.
    Z : ndarray, any shape
        The axial coordinate.
    S : ndarray, broadcastable to ``Z``
        The squared radius ``R^2``.
    order : int
        0: value only; 1: also ``Phi_Z``, ``Phi_S``; 2: also ``Phi_ZZ``, ``Phi_ZS``, ``Phi_SS``.
    want_value : bool
        Whether to accumulate ``Phi`` itself when ``order >= 1``.

    Returns
    -------
    dict of ndarray with the broadcast shape of ``Z`` and ``S`` (keys ``""``, ``"Z"``,
    ``"S"``, ``"ZZ"``, ``"ZS"``, ``"SS"`` as requested).
    """
    shape = np.broadcast_shapes(Z.shape, S.shape)
    size = int(np.prod(shape))
    if size <= ZONAL_BLOCK:
        return zonal_block(coeffs, Z, S, order, want_value)
    # elementwise: blocks of the flattened points, so the recurrence's arrays stay in cache
    # (the same operations on every point, so the same bits)
    z = np.broadcast_to(Z, shape).reshape(-1)
    s = np.broadcast_to(S, shape).reshape(-1)
    out: dict[str, np.ndarray] = {}
    for start in range(0, size, ZONAL_BLOCK):
        part = zonal_block(
            coeffs,
            z[start : start + ZONAL_BLOCK],
            s[start : start + ZONAL_BLOCK],
            order,
            want_value,
        )
        for nm, values in part.items():
            out.setdefault(nm, np.empty(size))[start : start + len(values)] = values
    return {nm: values.reshape(shape) for nm, values in out.items()}


def zonal_block(
    coeffs: np.ndarray,
    Z: np.ndarray,
    S: np.ndarray,
    order: int,
    want_value: bool,
    record: list[tuple[np.ndarray, np.ndarray]] | None = None,
) -> dict[str, np.ndarray]:
    """:func:`zonal_sums` on one block of points (``Z`` and ``S`` broadcastable).

    ``record`` (order 1 only): a list that gets, for each k = 1..K, copies of the terms the
    sums take at that k, ``(u_{k-1}, u_k,S)``; they do not depend on ``coeffs`` (see
    :func:`zonal_first_from_terms`, which sums them again for other coefficients).
    """
    shape = np.broadcast_shapes(Z.shape, S.shape)
    names = [""] if (want_value or order == 0) else []
    names += ["Z", "S"] if order >= 1 else []
    names += ["ZZ", "ZS", "SS"] if order >= 2 else []
    out = {nm: np.zeros(shape) for nm in names}
    K = len(coeffs)
    if K == 0:
        return out
    # The recurrence below runs in place on recycled buffers, every product and sum the same
    # IEEE operation as the plain expression in its comment (so the same bits): ``S`` and
    # ``b S`` keep their own (broadcast) shape, ``a Z`` is formed once per k.
    Zb = np.broadcast_to(Z, shape)
    Sf = np.asarray(S, dtype=np.float64)
    # Running (k-1, k) values of u_k and its derivatives. u_0 = 1, u_1 = Z; every derivative
    # of u_0 vanishes, and of u_1 only d/dZ (= 1).
    zero = np.zeros(shape)
    prev: dict[str, np.ndarray] = {"": np.ones(shape)}
    cur: dict[str, np.ndarray] = {"": Zb.astype(np.float64, copy=True)}
    if order >= 1:
        prev |= {"S": zero}
        cur |= {"S": zero}
    if order >= 2:
        prev |= {"Z": zero, "ZZ": zero, "ZS": zero, "SS": zero}
        cur |= {"Z": np.ones(shape), "ZZ": zero, "ZS": zero, "SS": zero}
    # At order 1, Phi_Z comes from the Cartesian identity d u_k / dZ|_{X,Y} = k u_{k-1}:
    # Phi_Z|_S = sum_k f_k k u_{k-1} - 2 Z Phi_S (cheaper than a recurrence of its own).
    cartesian_z = np.zeros(shape) if order == 1 else None
    tmp = np.empty(shape)
    a_z = np.empty(shape)
    made: list[dict[str, np.ndarray]] = []  # the buffers the loop made (the others are shared)
    spare: dict[str, np.ndarray] | None = None  # made, and free to reuse
    for k in range(1, K + 1):
        f = float(coeffs[k - 1])
        if record is not None:
            record.append((prev[""].copy(), np.broadcast_to(cur["S"], shape).copy()))
        if f != 0.0:
            if "" in out:
                out[""] += np.multiply(cur[""], f, out=tmp)  # f * u_k
            if cartesian_z is not None:
                cartesian_z += np.multiply(prev[""], f * k, out=tmp)  # (f k) * u_{k-1}
            for nm in ("S", "Z", "ZZ", "ZS", "SS"):
                if nm in out and nm in cur:
                    out[nm] += np.multiply(cur[nm], f, out=tmp)
        if k == K:
            break
        a, b = (2 * k + 1) / (k + 1), k / (k + 1)
        b_s = b * Sf
        np.multiply(Zb, a, out=a_z)  # a * Z
        if spare is None:
            spare = {nm: np.empty(shape) for nm in cur}
            made.append(spare)
        nxt = spare
        # (k+1) u_{k+1} = (2k+1) Z u_k - k S u_{k-1}, differentiated term by term.
        # u: a Z u_k - b S u_{k-1}
        np.multiply(a_z, cur[""], out=nxt[""])
        nxt[""] -= np.multiply(b_s, prev[""], out=tmp)
        if order >= 1:
            # S: a Z u_k,S - b (u_{k-1} + S u_{k-1},S)
            np.multiply(a_z, cur["S"], out=nxt["S"])
            np.multiply(Sf, prev["S"], out=tmp)
            tmp += prev[""]
            tmp *= b
            nxt["S"] -= tmp
        if order >= 2:
            # Z: a (u_k + Z u_k,Z) - b S u_{k-1},Z
            nz = nxt["Z"]
            np.multiply(Zb, cur["Z"], out=nz)
            nz += cur[""]
            nz *= a
            nz -= np.multiply(b_s, prev["Z"], out=tmp)
            # ZZ: a (2 u_k,Z + Z u_k,ZZ) - b S u_{k-1},ZZ
            nzz = nxt["ZZ"]
            np.multiply(Zb, cur["ZZ"], out=nzz)
            nzz += np.multiply(cur["Z"], 2.0, out=tmp)
            nzz *= a
            nzz -= np.multiply(b_s, prev["ZZ"], out=tmp)
            # ZS: a (u_k,S + Z u_k,ZS) - b (u_{k-1},Z + S u_{k-1},ZS)
            nzs = nxt["ZS"]
            np.multiply(Zb, cur["ZS"], out=nzs)
            nzs += cur["S"]
            nzs *= a
            np.multiply(Sf, prev["ZS"], out=tmp)
            tmp += prev["Z"]
            tmp *= b
            nzs -= tmp
            # SS: a Z u_k,SS - b (2 u_{k-1},S + S u_{k-1},SS)
            nss = nxt["SS"]
            np.multiply(a_z, cur["SS"], out=nss)
            np.multiply(Sf, prev["SS"], out=tmp)
            tmp += np.multiply(prev["S"], 2.0, out=a_z)  # a_z is formed again next k
            tmp *= b
            nss -= tmp
        # the buffers of u_{k-1} are free once u_{k+1} is formed, if the loop made them
        spare = prev if any(prev is m for m in made) else None
        prev, cur = cur, nxt
    if cartesian_z is not None:
        out["Z"] = cartesian_z - 2.0 * Zb * out["S"]
    return out


def zonal_first_from_terms(
    coeffs: np.ndarray, Z: np.ndarray, terms: list[tuple[np.ndarray, np.ndarray]]
) -> dict[str, np.ndarray]:
    """``Phi_Z`` and ``Phi_S`` (:func:`zonal_sums` at order 1, no value) from the terms
    :func:`zonal_block` recorded at these points (``terms``, for at least ``len(coeffs)``
    degrees): the same sums in the same order, so the same bits, without the recurrence.
    A body's magnets in many fields (the coils' sizes) run the recurrence once."""
    shape = terms[0][0].shape if terms else np.shape(Z)
    out = {"Z": np.zeros(shape), "S": np.zeros(shape)}
    K = len(coeffs)
    if K == 0:
        return out
    if K > len(terms):
        raise ValueError(f"{K} degrees asked of terms recorded for {len(terms)}")
    cartesian_z = np.zeros(shape)
    tmp = np.empty(shape)
    for k in range(1, K + 1):
        f = float(coeffs[k - 1])
        if f != 0.0:
            u_prev, u_s = terms[k - 1]
            cartesian_z += np.multiply(u_prev, f * k, out=tmp)  # (f k) * u_{k-1}
            out["S"] += np.multiply(u_s, f, out=tmp)
    out["Z"] = cartesian_z - 2.0 * np.broadcast_to(Z, shape) * out["S"]
    return out


@dataclass(frozen=True)
class AxisymmetricField:
    """An axisymmetric harmonic potential ``Phi = sum_k f_k R^k P_k(Z/R)`` about the space Z axis.

    Parameters
    ----------
    legendre : sequence of float, length K
        ``(f_1, ..., f_K)``; ``f_k`` in the potential's unit per m^k (e.g. T m / m^k for a
        magnetic scalar potential, V / m^k for an electric one, J/kg / m^k for gravity).

    Notes
    -----
    Space-axes methods take ``points``, ``ndarray, shape (n, 3)``, positions X in m.
    Body-axes methods take body positions ``r``, shape (n, 3), and orientations ``gammas``,
    shape (m, 3) (unit vectors: the space Z axis in body axes) and return arrays with the
    orientation index first, shape (m, n, ...).
    """

    legendre: tuple[float, ...] = ()

    def __post_init__(self) -> None:
        value: Any = self.legendre
        if isinstance(value, (list, tuple)) and len(value) == 0:
            coeffs: tuple[float, ...] = ()
        else:
            coeffs = tuple(float(x) for x in as_array(value, "legendre", (None,)))
        object.__setattr__(self, "legendre", coeffs)

    @classmethod
    def from_paper(cls, a1: float, a2: float) -> AxisymmetricField:
        """The paper's ``Phi = a1 Z + a2 (3 Z^2 - R^2)``, i.e. ``legendre = (a1, 2 a2)``."""
        return cls((as_finite_float(a1, "a1"), 2.0 * as_finite_float(a2, "a2")))

    @property
    def degree(self) -> int:
        """Highest k with ``f_k != 0`` (0 for the zero field)."""
        nonzero = [k for k, f in enumerate(self.legendre, start=1) if f != 0.0]
        return nonzero[-1] if nonzero else 0

    @property
    def is_zero(self) -> bool:
        """True when every coefficient is zero (a property, not a method)."""
        return self.degree == 0

    @property
    def _coeffs(self) -> np.ndarray:
        return np.asarray(self.legendre[: self.degree], dtype=np.float64)

    # ----------------------------------------------------------------- space axes
    def potential(self, points: Any) -> np.ndarray:
        """``Phi(X)``, ``ndarray, shape (n,)``, for space-axes ``points`` (n, 3) in m."""
        X = as_points(points, "points")
        return zonal_sums(self._coeffs, X[:, 2], np.einsum("ij,ij->i", X, X), 0)[""]

    def gradient(self, points: Any) -> np.ndarray:
        """``grad Phi(X)``, ``ndarray, shape (n, 3)`` (magnetic: ``B = -gradient``)."""
        X = as_points(points, "points")
        d = zonal_sums(self._coeffs, X[:, 2], np.einsum("ij,ij->i", X, X), 1, want_value=False)
        out = (2.0 * d["S"])[:, None] * X
        out[:, 2] += d["Z"]
        return out

    def hessian(self, points: Any) -> np.ndarray:
        """Hessian of Phi, ``ndarray, shape (n, 3, 3)`` (symmetric, trace zero)."""
        X = as_points(points, "points")
        ez = np.array([[0.0, 0.0, 1.0]])
        S = np.einsum("ij,ij->i", X, X)
        return _hessian_from_sums(self._coeffs, X[None, :, 2], S, ez, X)[0]

    def flux_function(self, points: Any) -> np.ndarray:
        """Stokes flux function ``psi = rho A_phi``, ``ndarray, shape (n,)`` (units of Phi m)."""
        X = as_points(points, "points")
        S = np.einsum("ij,ij->i", X, X)
        Z = X[:, 2]
        return -(S - Z * Z) * _flux_sum(self._coeffs, Z, S)

    def vector_potential(self, points: Any) -> np.ndarray:
        """Vector potential ``A = (psi / rho^2) (e_Z x X)``, ``ndarray, shape (n, 3)``.

        ``curl A = -grad Phi`` (the magnetic field when Phi is the magnetic scalar potential);
        ``A`` is a polynomial, regular on the axis.
        """
        X = as_points(points, "points")
        g = _flux_sum(self._coeffs, X[:, 2], np.einsum("ij,ij->i", X, X))
        out = np.zeros_like(X)
        out[:, 0] = g * X[:, 1]
        out[:, 1] = -g * X[:, 0]
        return out

    # ------------------------------------------------------------------ body axes
    def potential_body(self, points: Any, gammas: Any) -> np.ndarray:
        """``Phi(R r)`` for body ``points`` (n, 3) at orientations ``gammas`` (m, 3).

        Returns
        -------
        ndarray, shape (m, n)
        """
        coeffs = self._coeffs

        def block(Z: np.ndarray, G: np.ndarray, r: np.ndarray, S: np.ndarray) -> np.ndarray:
            return zonal_sums(coeffs, Z, S, 0)[""]

        return _blockwise(points, gammas, (), block)

    def gradient_body(self, points: Any, gammas: Any) -> np.ndarray:
        """Gradient w.r.t. body coordinates, ``R^T grad Phi(R r)``, ``ndarray, shape (m, n, 3)``.

        For a magnetic potential the field in body axes is ``B_body = -gradient_body``.
        """
        coeffs = self._coeffs

        def block(Z: np.ndarray, G: np.ndarray, r: np.ndarray, S: np.ndarray) -> np.ndarray:
            d = zonal_sums(coeffs, Z, S, 1, want_value=False)
            return _combine(d["Z"], G, 2.0 * d["S"], r)

        return _blockwise(points, gammas, (3,), block)

    def hessian_body(self, points: Any, gammas: Any) -> np.ndarray:
        """Hessian w.r.t. body coordinates, ``R^T H(R r) R``, ``ndarray, shape (m, n, 3, 3)``."""
        coeffs = self._coeffs

        def block(Z: np.ndarray, G: np.ndarray, r: np.ndarray, S: np.ndarray) -> np.ndarray:
            return _hessian_from_sums(coeffs, Z, S, G, r)

        return _blockwise(points, gammas, (3, 3), block)

    def gamma_derivative(self, points: Any, gammas: Any) -> np.ndarray:
        """``dPhi/dgamma = Phi_Z r`` with Phi written in ``Z = r . gamma`` and ``|r|^2``.

        ``Phi_Z`` is the partial derivative at fixed ``|r|^2``. Only the part tangent to the
        unit sphere is intrinsic; the potential torque ``gamma x dV/dgamma`` uses only that part.

        Returns
        -------
        ndarray, shape (m, n, 3)
        """
        coeffs = self._coeffs

        def block(Z: np.ndarray, G: np.ndarray, r: np.ndarray, S: np.ndarray) -> np.ndarray:
            d = zonal_sums(coeffs, Z, S, 1, want_value=False)
            return d["Z"][:, :, None] * r[None, :, :]

        return _blockwise(points, gammas, (3,), block)

    def flux_function_body(self, points: Any, gammas: Any) -> np.ndarray:
        """Flux function ``psi = rho A_phi`` at body ``points`` (n, 3), ``gammas`` (m, 3).

        ``sum_j q_j psi_j`` is the charges' magnetic contribution to the canonical angular
        momentum about the space Z axis (``X x A`` has Z component ``psi``).

        Returns
        -------
        ndarray, shape (m, n)
        """
        coeffs = self._coeffs

        def block(Z: np.ndarray, G: np.ndarray, r: np.ndarray, S: np.ndarray) -> np.ndarray:
            return -(S[None, :] - Z * Z) * _flux_sum(coeffs, Z, S)

        return _blockwise(points, gammas, (), block)

    def vector_potential_body(self, points: Any, gammas: Any) -> np.ndarray:
        """``R^T A(R r) = -g (gamma x r)``, ``ndarray, shape (m, n, 3)``."""
        coeffs = self._coeffs

        def block(Z: np.ndarray, G: np.ndarray, r: np.ndarray, S: np.ndarray) -> np.ndarray:
            g = _flux_sum(coeffs, Z, S)
            cross = np.cross(G[:, None, :], r[None, :, :])
            return -g[:, :, None] * cross

        return _blockwise(points, gammas, (3,), block)


#: Elements per block of (orientation, point) pairs: blocks that stay in cache run the
#: recurrences several times faster than whole (m, n) arrays (see docs/fields-and-moments.md).
_BLOCK_ELEMENTS = 1 << 15


def _blockwise(
    points: Any,
    gammas: Any,
    trailing: tuple[int, ...],
    block: Any,
) -> np.ndarray:
    """Evaluate ``block(Z, G, r, S)`` on cache-sized blocks of the (m, n) pairs.

    ``Z = G @ r.T`` (block, shape (mb, nb)), ``S = |r|^2`` (nb,); ``block`` returns shape
    ``(mb, nb) + trailing``; the result has shape ``(m, n) + trailing``.
    """
    r, G = as_points(points, "points"), as_unit_vectors(gammas, "gammas")
    m, n = len(G), len(r)
    out = np.empty((m, n, *trailing))
    if m == 0 or n == 0:
        return out
    S = np.einsum("ij,ij->i", r, r)
    cols = min(n, _BLOCK_ELEMENTS)
    rows = max(1, _BLOCK_ELEMENTS // cols)
    for j0 in range(0, n, cols):
        rj, Sj = r[j0 : j0 + cols], S[j0 : j0 + cols]
        for i0 in range(0, m, rows):
            Gi = G[i0 : i0 + rows]
            out[i0 : i0 + rows, j0 : j0 + cols] = block(Gi @ rj.T, Gi, rj, Sj)
    return out


def _combine(a: np.ndarray, G: np.ndarray, b: np.ndarray, r: np.ndarray) -> np.ndarray:
    """``out[i, j] = a[i, j] G[i] + b[i, j] r[j]``, shape (m, n, 3)."""
    m, n = a.shape
    out = np.empty((m, n, 3))
    for c in range(3):
        np.multiply(a, G[:, c, None], out=out[:, :, c])
        out[:, :, c] += b * r[None, :, c]
    return out


def _hessian_from_sums(
    coeffs: np.ndarray, Z: np.ndarray, S: np.ndarray, G: np.ndarray, pts: np.ndarray
) -> np.ndarray:
    """Hessian ``(m, n, 3, 3)`` at points ``pts`` (n, 3) for axis vectors ``G`` (m, 3).

    ``Z = G @ pts.T`` (m, n) and ``S = |pts|^2`` (n,).
    """
    d = zonal_sums(coeffs, Z, S, 2, want_value=False)
    gg = G[:, None, :, None] * G[:, None, None, :]  # (m, 1, 3, 3)
    gr = G[:, None, :, None] * pts[None, :, None, :]  # (m, n, 3, 3)
    rr = pts[:, :, None] * pts[:, None, :]  # (n, 3, 3)
    H = d["ZZ"][:, :, None, None] * gg
    H += (2.0 * d["ZS"])[:, :, None, None] * (gr + np.swapaxes(gr, 2, 3))
    H += (4.0 * d["SS"])[:, :, None, None] * rr[None]
    H += (2.0 * d["S"])[:, :, None, None] * np.eye(3)
    return H


def _flux_sum(coeffs: np.ndarray, Z: np.ndarray, S: np.ndarray) -> np.ndarray:
    """``g = sum_k f_k v_k / (k + 1)`` with ``v_k = R^(k-1) P_k'(Z/R)`` (polynomial).

    ``v_0 = 0``, ``v_1 = 1``, ``v_{k+1} = S v_{k-1} + (2k + 1) u_k`` (from
    ``P'_{k+1} = P'_{k-1} + (2k + 1) P_k``), evaluated alongside the recurrence for ``u_k``.
    """
    shape = np.broadcast_shapes(Z.shape, S.shape)
    out = np.zeros(shape)
    K = len(coeffs)
    if K == 0:
        return out
    u_prev: np.ndarray | float = 1.0
    u: np.ndarray = np.broadcast_to(Z, shape).astype(np.float64)
    v_prev: np.ndarray | float = 0.0
    v: np.ndarray | float = 1.0
    for k in range(1, K + 1):
        f = float(coeffs[k - 1])
        if f != 0.0:
            out += (f / (k + 1)) * v
        if k == K:
            break
        v_next = S * v_prev + (2 * k + 1) * u
        u_next = ((2 * k + 1) * Z * u - k * S * u_prev) / (k + 1)
        v_prev, v = v, v_next
        u_prev, u = u, u_next
    return out


def zonal_z_coefficients(coeffs: np.ndarray, S: np.ndarray, order: int) -> dict[str, np.ndarray]:
    """The sums of :func:`zonal_sums` as polynomials in ``Z``, one per value of ``S``.

    At a fixed ``S = |r|^2`` (a point of a body: turning the body changes ``Z = r . gamma``,
    not ``S``) each ``u_k`` is a polynomial of degree k in ``Z``. The recurrence
    ``(k + 1) u_{k+1} = (2k + 1) Z u_k - k S u_{k-1}`` and its ``S``-derivatives are run on
    the coefficient arrays (multiplying by ``Z`` shifts the coefficients); ``Z``-derivatives
    at fixed ``S`` are derivatives of these polynomials. Internal fast path for evaluations
    at one orientation (no validation): ``Phi_*(Z_i, S_i) = sum_a out[*][i, a] Z_i^a``.

    Parameters
    ----------
    coeffs : ndarray, shape (K,)
        ``f_1 .. f_K``.
    S : ndarray, shape (n,)
        Squared radii of the points, m^2.
    order : int
        0: ``""``; 1: also ``"Z"``, ``"S"``; 2: also ``"ZZ"``, ``"ZS"``, ``"SS"``.

    Returns
    -------
    dict of ndarray, shape (n, K + 1)
        Coefficient of ``Z^a`` in column ``a`` (same keys and meaning as :func:`zonal_sums`).
    """
    S = np.asarray(S, dtype=np.float64)
    n, K = len(S), len(coeffs)
    width = K + 1
    Sc = S[:, None]

    def zeros() -> np.ndarray:
        return np.zeros((n, width))

    def times_z(c: np.ndarray) -> np.ndarray:
        out = zeros()
        out[:, 1:] = c[:, :-1]
        return out

    def d_dz(c: np.ndarray) -> np.ndarray:
        out = zeros()
        out[:, :-1] = c[:, 1:] * np.arange(1, width)
        return out

    total = {"": zeros(), "S": zeros(), "SS": zeros()}
    # u_0 = 1, u_1 = Z; their S-derivatives vanish
    u_prev, u = zeros(), zeros()
    u_prev[:, 0] = 1.0
    if K >= 1:
        u[:, 1] = 1.0
    s_prev, s, ss_prev, ss = zeros(), zeros(), zeros(), zeros()
    for k in range(1, K + 1):
        f = float(coeffs[k - 1])
        if f != 0.0:
            total[""] += f * u
            total["S"] += f * s
            total["SS"] += f * ss
        if k == K:
            break
        a, b = (2 * k + 1) / (k + 1), k / (k + 1)
        nxt = a * times_z(u) - b * Sc * u_prev
        nxt_s = a * times_z(s) - b * (u_prev + Sc * s_prev)
        nxt_ss = a * times_z(ss) - b * (2.0 * s_prev + Sc * ss_prev)
        u_prev, u = u, nxt
        s_prev, s = s, nxt_s
        ss_prev, ss = ss, nxt_ss
    out = {"": total[""]}
    if order >= 1:
        out["Z"] = d_dz(total[""])
        out["S"] = total["S"]
    if order >= 2:
        out["ZZ"] = d_dz(out["Z"])
        out["ZS"] = d_dz(total["S"])
        out["SS"] = total["SS"]
    return out


#: Largest accepted | |gamma| - 1 | for body-axes evaluations.
GAMMA_UNIT_TOLERANCE = 1e-9


def as_unit_vectors(value: Any, name: str = "gammas") -> np.ndarray:
    """Unit vectors as ``ndarray, shape (m, 3)``, rejecting norms off 1 by more than 1e-9.

    The vectors are used as given (not renormalised), so that every body-axes quantity is
    the same polynomial in gamma that its derivatives describe.
    """
    arr = as_array(value, name, (None, 3))
    if len(arr):
        worst = float(np.max(np.abs(np.sqrt(np.einsum("ij,ij->i", arr, arr)) - 1.0)))
        if worst > GAMMA_UNIT_TOLERANCE:
            raise input_error(
                name, f"unit vectors (| |gamma| - 1 | <= {fmt(GAMMA_UNIT_TOLERANCE, PLAIN)})", arr
            )
    return arr
