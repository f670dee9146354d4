"""Orientations, the elements as points, and the vectorised double-precision kernel.

Part of :mod:`chargedesign.checker` (see its docstring for the method).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from chargedesign.body import Design
from chargedesign.checker.constants import (
    BLOCK_PAIRS,
)
from chargedesign.fields import AxisymmetricField
from chargedesign.quadrature import GatheredElements, gather_elements
from chargedesign.validation import check_integer
from chargedesign.vocabulary import (
    FIELD_NAMES,
)


# ----------------------------------------------------------------------- orientations
def sample_orientations(n: int, seed: int = 0) -> np.ndarray:
    """A deterministic, well-spread set of unit vectors gamma.

    The first ``n - n // 2`` (rounded down to even) lie on a Fibonacci sphere
    ``z_i = 1 - (2 i + 1) / n_f`` (an even count never hits the equator gamma3 = 0 exactly,
    where the theorem's singular terms blow up); the rest are uniformly random (seeded).

    Returns
    -------
    ndarray, shape (n, 3)
    """
    check_integer(n, "n_orientations", minimum=1)
    n = int(n)
    n_fib = n - n // 2
    n_fib -= n_fib % 2
    # Deliberately not sampling.fibonacci_sphere: the same spiral, but this rounding order
    # has fixed every check figure since the check was written (the shared sampler's order
    # moves them at round-off, 3e-14 in gamma), so the check keeps its own three lines.
    i = np.arange(n_fib)
    z = 1.0 - (2.0 * i + 1.0) / max(n_fib, 1)
    phi = i * math.pi * (3.0 - math.sqrt(5.0))
    s = np.sqrt(1.0 - z * z)
    fib = np.stack([s * np.cos(phi), s * np.sin(phi), z], axis=1)
    rng = np.random.default_rng(seed)
    rand = rng.standard_normal((n - n_fib, 3))
    rand /= np.linalg.norm(rand, axis=1, keepdims=True)
    return np.concatenate([fib, rand], axis=0)


def rotation_matrices(gammas: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """Rotations R (body to space) with ``R^T e_Z = gamma`` and a random azimuth.

    Rows of R are ``u``, ``gamma x u``, ``gamma`` with ``u`` a random unit vector
    perpendicular to gamma, so ``det R = +1``.

    Returns
    -------
    ndarray, shape (m, 3, 3)
    """
    m = len(gammas)
    trial = rng.standard_normal((m, 3))
    u = trial - np.einsum("ij,ij->i", trial, gammas)[:, None] * gammas
    norm = np.linalg.norm(u, axis=1)
    bad = norm < 1e-6  # vanishingly rare: fall back to a fixed perpendicular axis
    if np.any(bad):
        axis = np.where(np.abs(gammas[bad, :1]) < 0.9, [[1.0, 0.0, 0.0]], [[0.0, 1.0, 0.0]])
        u[bad] = axis - np.einsum("ij,ij->i", axis, gammas[bad])[:, None] * gammas[bad]
        norm[bad] = np.linalg.norm(u[bad], axis=1)
    u /= norm[:, None]
    # a second Gram-Schmidt pass: after the first, u . gamma is only eps * |trial| / |u|
    # (1e-14 when the trial is nearly parallel to gamma), and a rotation that far from
    # orthogonal shears the body by as much, which a cancelling body feels 50-fold
    u -= np.einsum("ij,ij->i", u, gammas)[:, None] * gammas
    u /= np.linalg.norm(u, axis=1, keepdims=True)
    R = np.empty((m, 3, 3))
    R[:, 0] = u
    R[:, 1] = np.cross(gammas, u)
    R[:, 2] = gammas
    return R


# --------------------------------------------------------------------------- elements
def integrand_degree(kind: str, degrees: dict[str, int]) -> int:
    """Polynomial degree (in body coordinates) of every integrand the check uses."""
    if kind == "charge":
        # V and torque of E: Phi_e, r x grad Phi_e (degree L_e); mu and the Lorentz torque:
        # r (r . B), r x ((omega x r) x B) (degree L_m + 1, or 0 without a field).
        lorentz = degrees["magnetic"] + 1 if degrees["magnetic"] else 0
        return max(degrees["electric"], lorentz)
    return max(degrees["gravity"], 2)  # V, torque of gravity; inertia (degree 2)


def collect_elements(
    design: Design, quadrature_order: int | None = None
) -> tuple[GatheredElements, dict[str, int]]:
    """Point elements plus continuous bodies as quadrature nodes (weights in C or kg).

    The degree of exactness of each body's rule is ``density degree + integrand degree``
    (exact for every polynomial integrand of the check) unless ``quadrature_order`` is given.
    Integrand degrees: charges ``max(L_e, L_m + 1)`` (``Phi_e``, ``r x grad Phi_e``;
    ``r (r . B)``, ``r x ((omega x r) x B)``), masses ``max(L_g, 2)`` (gravity; inertia),
    with ``L`` the degree of each field.

    Returns
    -------
    elements : GatheredElements
    degrees : dict[str, int]
        Degree of each field kind (0: no field).
    """
    degrees = {k: AxisymmetricField(design.field(k)).degree for k in FIELD_NAMES}
    integrand = {kind: integrand_degree(kind, degrees) for kind in ("charge", "mass")}
    return gather_elements(design, integrand, quadrature_order), degrees


# ------------------------------------------------------------------------ the kernel
# The check evaluates the zonal harmonics u_k = R^k P_k(Z/R) with its own Cartesian
# recurrences (independent of chargedesign.fields, which differentiates in S = R^2):
#   (k + 1) u_{k+1} = (2k + 1) Z u_k - k S u_{k-1},        u_0 = 1, u_1 = Z
#   d u_k / dZ = k u_{k-1}                                 (at fixed X, Y)
#   d u_k / dX = -X v_{k-1},  v_{k+1} = S v_{k-1} + (2k + 1) u_k,   v_0 = 0, v_1 = 1
#   d v_k / dX = X t_k,       t_{k+1} = S t_{k-1} - (2k - 1) v_{k-1}, t_0 = t_1 = 0
# (v_k = R^(k-1) P_k'(Z/R)). So for Phi = sum f_k u_k, with transverse components X, Y:
#   grad Phi = (-X T, -Y T, D),  D = sum f_k k u_{k-1},  T = sum f_k v_{k-1}
#   Hess: XX = -(T + X^2 W), XY = -X Y W, XZ = -X E, ZZ = sum f_k k (k-1) u_{k-2}
#   with W = sum f_k t_{k-1}, E = sum f_k k v_{k-2} (and YY, YZ alike).
#
# Every temporary comes from a workspace of block-sized buffers that are reused from block
# to block: allocating and freeing them per block lets the C allocator hand the pages back
# to the system and fault them in again, which measured 3 to 5 times slower.


class Workspace:
    """Reusable buffers of shape (rows, n); ``take`` hands out views of the first rows."""

    def __init__(self, rows: int, n: int) -> None:
        self.shape = (rows, n)
        self._free: list[np.ndarray] = []

    def take(self, rows: int) -> np.ndarray:
        base = self._free.pop() if self._free else np.empty(self.shape)
        return base[:rows]

    def give(self, *arrays: Any) -> None:
        """Return buffers (floats and repeats are ignored, so callers may over-give)."""
        for a in arrays:
            if isinstance(a, np.ndarray):
                base = a if a.base is None else a.base
                if base.shape == self.shape and not any(b is base for b in self._free):
                    self._free.append(base)


def product_sum(
    ws: Workspace, rows: int, terms: list[tuple[float, Any, Any]]
) -> np.ndarray | float:
    """``sum_i c_i A_i B_i`` into a workspace buffer (a float when every factor is a float).

    Factors are floats, arrays of shape (rows, n), (n,) or (rows, 1) (broadcast).
    """
    out: np.ndarray | None = None
    tmp: np.ndarray | None = None
    const = 0.0
    for c, a, b in terms:
        a_scalar, b_scalar = isinstance(a, float), isinstance(b, float)
        if a_scalar and b_scalar:
            const += c * a * b
            continue
        if c == 0.0 or (a_scalar and a == 0.0) or (b_scalar and b == 0.0):
            continue
        if out is None:
            target = out = ws.take(rows)
        else:
            if tmp is None:
                tmp = ws.take(rows)
            target = tmp
        if a_scalar or b_scalar:
            arr, scale = (b, c * a) if a_scalar else (a, c * b)
            np.multiply(arr, scale, out=target)
        else:
            np.multiply(a, b, out=target)
            if c != 1.0:
                target *= c
        if target is not out:
            out += target
    ws.give(tmp)
    if out is None:
        return const
    if const != 0.0:
        out += const
    return out


@dataclass
class ZonalSums:
    """Sums of one field at a block of points (workspace buffers or floats)."""

    value: Any = None
    D: Any = None
    T: Any = None
    W: Any = None
    E: Any = None
    ZZ: Any = None


def zonal_sums(
    coeffs: np.ndarray, Z: np.ndarray, S: np.ndarray, order: int, ws: Workspace
) -> tuple[ZonalSums, list[Any]]:
    """Potential (order 0), gradient sums (1) and Hessian sums (2) at points (Z, S = R^2).

    Parameters
    ----------
    coeffs : ndarray, shape (K,)
        Legendre coefficients f_1 .. f_K (trailing zeros removed).
    Z : ndarray, shape (rows, n)
        Axial space coordinate, m.
    S : ndarray, shape (n,)
        Squared distance from O, m^2 (rotation invariant).
    order : int
        Highest derivative wanted.
    ws : Workspace
        Where the buffers come from.

    Returns
    -------
    The sums and the list of buffers to give back to ``ws`` when done.
    """
    rows = Z.shape[0]
    K = len(coeffs)
    f = [0.0, *(float(c) for c in coeffs)]  # f[k] = f_k
    u: list[Any] = [1.0, Z]
    for k in range(1, K):
        u.append(
            product_sum(ws, rows, [((2 * k + 1) / (k + 1), Z, u[k]), (-k / (k + 1), S, u[k - 1])])
        )
    out = ZonalSums()
    out.value = product_sum(ws, rows, [(f[k], u[k], 1.0) for k in range(1, K + 1)])
    scratch: list[Any] = u[2:]
    if order >= 1:
        v: list[Any] = [0.0, 1.0]
        for k in range(1, K - 1):
            v.append(product_sum(ws, rows, [(1.0, S, v[k - 1]), (2.0 * k + 1.0, u[k], 1.0)]))
        out.D = product_sum(ws, rows, [(f[k] * k, u[k - 1], 1.0) for k in range(1, K + 1)])
        out.T = product_sum(ws, rows, [(f[k], v[k - 1], 1.0) for k in range(1, K + 1)])
        scratch += v[2:]
    if order >= 2:
        t: list[Any] = [0.0, 0.0]
        for k in range(1, K - 1):
            t.append(product_sum(ws, rows, [(1.0, S, t[k - 1]), (-(2.0 * k - 1.0), v[k - 1], 1.0)]))
        out.W = product_sum(ws, rows, [(f[k], t[k - 1], 1.0) for k in range(1, K + 1)])
        out.E = product_sum(ws, rows, [(f[k] * k, v[k - 2], 1.0) for k in range(2, K + 1)])
        out.ZZ = product_sum(
            ws, rows, [(f[k] * k * (k - 1), u[k - 2], 1.0) for k in range(2, K + 1)]
        )
        scratch += t[2:]
    ws.give(*scratch)
    return out, [out.value, out.D, out.T, out.W, out.E, out.ZZ]


def rotate_points(
    R: np.ndarray, r: np.ndarray, buffer: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Space components ``X = R r`` of body points: three (m, n) views of ``buffer`` (one GEMM).

    ``buffer`` has shape (3 * rows_max, n).
    """
    m, n = len(R), len(r)
    XR = buffer[: 3 * m]
    np.matmul(R.reshape(3 * m, 3), r.T, out=XR)
    XR3 = XR.reshape(m, 3, n)
    return XR3[:, 0], XR3[:, 1], XR3[:, 2]


def rowwise_dot(a: Any, b: Any, w: np.ndarray | None = None) -> np.ndarray:
    """``sum_n a b (w)`` per row: shape (rows,) (no temporary)."""
    if w is None:
        return np.einsum("mn,mn->m", a, b)
    return np.einsum("mn,mn,n->m", a, b, w)


@dataclass
class RotatedSums:
    """Per-orientation sums over the elements (m rows), SI units.

    ``mu`` (kg m^2/s) and ``gyro`` (N m, Lorentz torque) from the charges; ``energy`` (J)
    and ``torque`` (N m) per potential effect (``electric``, ``gravity``,
    ``magnetization``); ``*_gross`` the per-orientation sums of the elements' absolute
    contributions (the scale of the per-effect route agreement's gate; the pass/fail floors
    use :func:`contribution_sizes`). Vectors are in space axes inside the kernel and in body
    axes once :func:`evaluate_rotated` returns.
    """

    mu: np.ndarray
    gyro: np.ndarray
    mu_gross: np.ndarray
    energy: dict[str, np.ndarray]
    energy_gross: dict[str, np.ndarray]
    torque: dict[str, np.ndarray]
    torque_gross: dict[str, np.ndarray]


POTENTIAL_EFFECTS = ("electric", "gravity", "magnetization")


def zero_rotated_sums(m: int) -> RotatedSums:
    """Rotated sums of ``m`` orientations, every entry zero (to accumulate into)."""
    return RotatedSums(
        mu=np.zeros((m, 3)),
        gyro=np.zeros((m, 3)),
        mu_gross=np.zeros(m),
        energy={k: np.zeros(m) for k in POTENTIAL_EFFECTS},
        energy_gross={k: np.zeros(m) for k in POTENTIAL_EFFECTS},
        torque={k: np.zeros((m, 3)) for k in POTENTIAL_EFFECTS},
        torque_gross={k: np.zeros(m) for k in POTENTIAL_EFFECTS},
    )


def filled_buffer(ws: Workspace, rows: int, value: Any) -> np.ndarray:
    """A (rows, n) buffer holding ``value`` (used when a sum came out as a float)."""
    out = ws.take(rows)
    out[...] = value
    return out


def scalar_potential_block(
    X: tuple[np.ndarray, np.ndarray, np.ndarray],
    S: np.ndarray,
    w: np.ndarray,
    coeffs: np.ndarray,
    name: str,
    out: RotatedSums,
    rows: slice,
    absw: np.ndarray,
    absw_r: np.ndarray,
    ws: Workspace,
) -> None:
    """Energy ``sum w Phi`` and torque ``sum X x (-w grad Phi)`` of charges or masses."""
    x, y, z = X
    m = x.shape[0]
    zs, bufs = zonal_sums(coeffs, z, S, 1, ws)
    value = zs.value if isinstance(zs.value, np.ndarray) else filled_buffer(ws, m, zs.value)
    out.energy[name][rows] = value @ w
    np.abs(value, out=value)
    out.energy_gross[name][rows] = value @ absw
    # grad Phi = (-x T, -y T, D): X x grad Phi = (y (D + z T), -x (D + z T), 0)
    lever = product_sum(ws, m, [(1.0, zs.D, 1.0), (1.0, z, zs.T)])
    lever = lever if isinstance(lever, np.ndarray) else filled_buffer(ws, m, lever)
    out.torque[name][rows, 0] = -rowwise_dot(y, lever, w)
    out.torque[name][rows, 1] = rowwise_dot(x, lever, w)
    np.abs(lever, out=lever)
    out.torque_gross[name][rows] = lever @ absw_r
    ws.give(*bufs, lever, value)


def lorentz_block(
    X: tuple[np.ndarray, np.ndarray, np.ndarray],
    S: np.ndarray,
    q: np.ndarray,
    coeffs: np.ndarray,
    omega_space: np.ndarray,
    out: RotatedSums,
    rows: slice,
    absq_r: np.ndarray,
    ws: Workspace,
) -> None:
    """mu = -sum q (X . B) X and the Lorentz torque sum X x q ((Omega x X) x B)."""
    x, y, z = X
    m = x.shape[0]
    zs, bufs = zonal_sums(coeffs, z, S, 1, ws)
    ps = product_sum
    bx = ps(ws, m, [(1.0, x, zs.T)])  # B = -grad Phi = (x T, y T, -D)
    by = ps(ws, m, [(1.0, y, zs.T)])
    bz = ps(ws, m, [(-1.0, zs.D, 1.0)])
    bx, by, bz = (b if isinstance(b, np.ndarray) else filled_buffer(ws, m, b) for b in (bx, by, bz))
    xb = ps(ws, m, [(1.0, x, bx), (1.0, y, by), (1.0, z, bz)])
    assert isinstance(xb, np.ndarray)
    out.mu[rows, 0] = -rowwise_dot(x, xb, q)
    out.mu[rows, 1] = -rowwise_dot(y, xb, q)
    out.mu[rows, 2] = -rowwise_dot(z, xb, q)
    np.abs(xb, out=xb)
    out.mu_gross[rows] = xb @ absq_r
    ox, oy, oz = (omega_space[:, i, None] for i in range(3))
    vx = ps(ws, m, [(1.0, oy, z), (-1.0, oz, y)])
    vy = ps(ws, m, [(1.0, oz, x), (-1.0, ox, z)])
    vz = ps(ws, m, [(1.0, ox, y), (-1.0, oy, x)])
    fx = ps(ws, m, [(1.0, vy, bz), (-1.0, vz, by)])
    fy = ps(ws, m, [(1.0, vz, bx), (-1.0, vx, bz)])
    fz = ps(ws, m, [(1.0, vx, by), (-1.0, vy, bx)])
    out.gyro[rows, 0] = rowwise_dot(y, fz, q) - rowwise_dot(z, fy, q)
    out.gyro[rows, 1] = rowwise_dot(z, fx, q) - rowwise_dot(x, fz, q)
    out.gyro[rows, 2] = rowwise_dot(x, fy, q) - rowwise_dot(y, fx, q)
    ws.give(*bufs, bx, by, bz, xb, vx, vy, vz, fx, fy, fz)


def dipoles_block(
    X: tuple[np.ndarray, np.ndarray, np.ndarray],
    sig: tuple[np.ndarray, np.ndarray, np.ndarray],
    S: np.ndarray,
    coeffs: np.ndarray,
    out: RotatedSums,
    rows: slice,
    ws: Workspace,
) -> None:
    """Energy ``-sum sigma . B`` and torque ``sum sigma x B + X x grad(sigma . B)``."""
    x, y, z = X
    sx, sy, sz = sig
    m = x.shape[0]
    zs, bufs = zonal_sums(coeffs, z, S, 2, ws)
    ps = product_sum
    bx = ps(ws, m, [(1.0, x, zs.T)])
    by = ps(ws, m, [(1.0, y, zs.T)])
    bz = ps(ws, m, [(-1.0, zs.D, 1.0)])
    energy = ps(ws, m, [(-1.0, sx, bx), (-1.0, sy, by), (-1.0, sz, bz)])
    energy = energy if isinstance(energy, np.ndarray) else filled_buffer(ws, m, energy)
    out.energy["magnetization"][rows] = energy.sum(axis=1)
    np.abs(energy, out=energy)
    out.energy_gross["magnetization"][rows] = energy.sum(axis=1)
    # F = grad(sigma . B) = -H sigma with H the Hessian of Phi.
    xw = ps(ws, m, [(1.0, x, zs.W)])
    yw = ps(ws, m, [(1.0, y, zs.W)])
    hxx = ps(ws, m, [(-1.0, zs.T, 1.0), (-1.0, x, xw)])
    hyy = ps(ws, m, [(-1.0, zs.T, 1.0), (-1.0, y, yw)])
    hxy = ps(ws, m, [(-1.0, x, yw)])
    hxz = ps(ws, m, [(-1.0, x, zs.E)])
    hyz = ps(ws, m, [(-1.0, y, zs.E)])
    hzz = zs.ZZ
    fx = ps(ws, m, [(-1.0, hxx, sx), (-1.0, hxy, sy), (-1.0, hxz, sz)])
    fy = ps(ws, m, [(-1.0, hxy, sx), (-1.0, hyy, sy), (-1.0, hyz, sz)])
    fz = ps(ws, m, [(-1.0, hxz, sx), (-1.0, hyz, sy), (-1.0, hzz, sz)])
    tx = ps(ws, m, [(1.0, sy, bz), (-1.0, sz, by), (1.0, y, fz), (-1.0, z, fy)])
    ty = ps(ws, m, [(1.0, sz, bx), (-1.0, sx, bz), (1.0, z, fx), (-1.0, x, fz)])
    tz = ps(ws, m, [(1.0, sx, by), (-1.0, sy, bx), (1.0, x, fy), (-1.0, y, fx)])
    tx, ty, tz = (t if isinstance(t, np.ndarray) else filled_buffer(ws, m, t) for t in (tx, ty, tz))
    out.torque["magnetization"][rows, 0] = tx.sum(axis=1)
    out.torque["magnetization"][rows, 1] = ty.sum(axis=1)
    out.torque["magnetization"][rows, 2] = tz.sum(axis=1)
    norm = ps(ws, m, [(1.0, tx, tx), (1.0, ty, ty), (1.0, tz, tz)])
    assert isinstance(norm, np.ndarray)
    np.sqrt(norm, out=norm)
    out.torque_gross["magnetization"][rows] = norm.sum(axis=1)
    ws.give(*bufs, bx, by, bz, energy, xw, yw, hxx, hyy, hxy, hxz, hyz)
    ws.give(fx, fy, fz, tx, ty, tz, norm)


def orientation_blocks(m: int, n: int, block_pairs: int) -> tuple[int, list[slice]]:
    """Blocks of the ``m`` orientations of at most ``block_pairs`` element-orientation pairs
    with ``n`` elements (at least one orientation each): the rows per block, the blocks."""
    step = max(1, min(m, block_pairs // max(n, 1)))
    return step, [slice(s, min(m, s + step)) for s in range(0, m, step)]


def to_body_axes(R: np.ndarray, v: np.ndarray) -> np.ndarray:
    """``R^T v`` per orientation: space vectors (m, 3) to body axes."""
    return np.einsum("mci,mc->mi", R, v)


def evaluate_rotated(
    elements: GatheredElements,
    fields: dict[str, tuple[float, ...]],
    R: np.ndarray,
    omegas: np.ndarray,
    *,
    block_pairs: int = BLOCK_PAIRS,
) -> RotatedSums:
    """Rotated-body sums for every orientation, vectors rotated back to body axes.

    Parameters
    ----------
    elements : GatheredElements
        Charges (C), masses (kg), dipoles (A m^2) in body axes (m).
    fields : dict[str, tuple of float]
        Legendre coefficients of ``magnetic``, ``electric``, ``gravity``.
    R : ndarray, shape (m, 3, 3)
        Body-to-space rotations.
    omegas : ndarray, shape (m, 3)
        Angular velocities in body axes, rad/s (for the Lorentz torque).
    block_pairs : int
        Element-orientation pairs per vectorised block.

    Returns
    -------
    RotatedSums
        Every vector in body axes.
    """
    m = len(R)
    sums = zero_rotated_sums(m)
    coeffs = {k: trimmed_legendre(fields.get(k, ())) for k in FIELD_NAMES}
    omega_space = np.einsum("mij,mj->mi", R, omegas)

    r, q = elements.charge_positions, elements.charge_values
    if len(q) and (len(coeffs["magnetic"]) or len(coeffs["electric"])):
        S = np.einsum("ij,ij->i", r, r)
        absq = np.abs(q)
        absq_r = absq * np.sqrt(S)
        step, slices = orientation_blocks(m, len(q), block_pairs)
        ws = Workspace(step, len(q))
        buffer = np.empty((3 * step, len(q)))
        for rows in slices:
            X = rotate_points(R[rows], r, buffer)
            if len(coeffs["magnetic"]):
                lorentz_block(
                    X, S, q, coeffs["magnetic"], omega_space[rows], sums, rows, absq_r, ws
                )
            if len(coeffs["electric"]):
                scalar_potential_block(
                    X, S, q, coeffs["electric"], "electric", sums, rows, absq, absq_r, ws
                )
    r, w = elements.mass_positions, elements.mass_values
    if len(w) and len(coeffs["gravity"]):
        S = np.einsum("ij,ij->i", r, r)
        absw = np.abs(w)
        step, slices = orientation_blocks(m, len(w), block_pairs)
        ws = Workspace(step, len(w))
        buffer = np.empty((3 * step, len(w)))
        for rows in slices:
            X = rotate_points(R[rows], r, buffer)
            scalar_potential_block(
                X, S, w, coeffs["gravity"], "gravity", sums, rows, absw, absw * np.sqrt(S), ws
            )
    r, sigma = elements.dipole_positions, elements.dipole_moments
    if len(sigma) and len(coeffs["magnetic"]):
        S = np.einsum("ij,ij->i", r, r)
        step, slices = orientation_blocks(m, len(sigma), block_pairs)
        ws = Workspace(step, len(sigma))
        buffer = np.empty((3 * step, len(sigma)))
        sig_buffer = np.empty((3 * step, len(sigma)))
        for rows in slices:
            X = rotate_points(R[rows], r, buffer)
            sig = rotate_points(R[rows], sigma, sig_buffer)
            dipoles_block(X, sig, S, coeffs["magnetic"], sums, rows, ws)
    sums.mu = to_body_axes(R, sums.mu)
    sums.gyro = to_body_axes(R, sums.gyro)
    for k in sums.torque:
        sums.torque[k] = to_body_axes(R, sums.torque[k])
    return sums


def trimmed_legendre(legendre: tuple[float, ...]) -> np.ndarray:
    """Coefficients up to the last non-zero one (validated by AxisymmetricField)."""
    field_ = AxisymmetricField(legendre)
    return np.asarray(field_.legendre[: field_.degree], dtype=np.float64)
