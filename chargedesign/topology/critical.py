"""The critical set of F = (H, I4) on ``|gamma| = 1, I3 = 0``: seeds and continuation.

A point is critical when ``a dH + b dI4 + beta dI2 + delta dI3 = 0`` for some ``(a, b) !=
0``. With ``(a, b) = (cos t, sin t)`` (each gradient scaled by a typical size) the unknowns
are ``z = (x, t, beta, delta)`` (9) and the equations are the six components of that sum,
``I2 - 1`` and ``I3`` (8). The solutions form surfaces: each critical periodic orbit is a
circle of solutions (the flow keeps the multipliers), and the circles come in one-parameter
families. Newton steps use the minimum-norm correction (the Jacobian is rank-deficient
along the flow), and continuation steps along the family: the kernel direction orthogonal to
the flow (pseudo-arclength with the step controlled by the image in the (h, k) plane).

Seeds come from random points of the level, corrected by Gauss-Newton in a batch; the
relative equilibria (``b = 0``: isolated) are found by Newton from a grid of the sphere.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from chargedesign.topology.equations import MomentumMap, relative_singular_value

#: Newton converged: scaled residual below this
RESIDUAL_TOL = 1e-11


@dataclass(frozen=True)
class Scales:
    """Typical sizes that make the equations dimensionless: energy (J) and I4 (1/s^4)."""

    energy: float
    quartic: float
    h_low: float
    h_high: float

    def image(self, hk: np.ndarray) -> np.ndarray:
        """(h, k) in units of the diagram's size."""
        return np.asarray(hk) / np.array([self.energy, self.quartic])


def residual_and_jacobian(
    F: MomentumMap, z: np.ndarray, scales: Scales
) -> tuple[np.ndarray, np.ndarray]:
    """The 8 equations at a batch ``z`` (m, 9) and their Jacobian (m, 8, 9)."""
    x, t, beta, delta = z[:, :6], z[:, 6], z[:, 7], z[:, 8]
    grads = F.gradients(x)
    hess = F.hessians(x)
    weights = np.stack([np.cos(t) / scales.energy, np.sin(t) / scales.quartic, beta, delta], axis=1)
    m = z.shape[0]
    E = np.empty((m, 8))
    E[:, :6] = np.einsum("mi,mij->mj", weights, grads)
    values = F.values(x)
    E[:, 6] = values[:, 2] - 1.0
    E[:, 7] = values[:, 3] / F.i3_scale
    J = np.zeros((m, 8, 9))
    J[:, :6, :6] = np.einsum("mi,mijk->mjk", weights, hess)
    J[:, :6, 6] = (
        -np.sin(t)[:, None] * grads[:, 0] / scales.energy
        + np.cos(t)[:, None] * grads[:, 1] / scales.quartic
    )
    J[:, :6, 7] = grads[:, 2]
    J[:, :6, 8] = grads[:, 3]
    J[:, 6, :6] = grads[:, 2]
    J[:, 7, :6] = grads[:, 3] / F.i3_scale
    return E, J


def gauss_newton(
    F: MomentumMap,
    z: np.ndarray,
    scales: Scales,
    iterations: int = 40,
    extra: tuple[np.ndarray, np.ndarray] | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """Minimum-norm Newton corrections of a batch ``z`` (m, 9); returns ``(z, residual)``.

    ``extra = (tau, z_pred)`` adds the pseudo-arclength row ``tau . (z - z_pred) = 0``.
    Each step is clipped to length 0.5 (a guard against wild first steps from far).
    """
    z = z.copy()
    norm = np.full(z.shape[0], np.inf)
    for _ in range(iterations):
        E, J = residual_and_jacobian(F, z, scales)
        if extra is not None:
            tau, z_pred = extra
            E = np.concatenate([E, ((z - z_pred) @ tau)[:, None]], axis=1)
            J = np.concatenate([J, np.broadcast_to(tau, (z.shape[0], 1, 9))], axis=1)
        norm = np.linalg.norm(E, axis=1)
        active = norm > RESIDUAL_TOL
        if not np.any(active):
            break
        step = np.einsum("mij,mj->mi", np.linalg.pinv(J[active], rcond=1e-12), E[active])
        length = np.linalg.norm(step, axis=1, keepdims=True)
        z[active] -= step * np.minimum(1.0, 0.5 / np.maximum(length, 1e-300))
    return z, norm


def plane_basis(F: MomentumMap, gamma: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """For each gamma (m, 3): the kinetic-energy minimiser ``omega0`` on the plane I3 = 0 and
    two directions ``e1, e2`` of the plane, orthonormal for the kinetic energy.

    ``omega0 = -(l . gamma) gamma / (gamma . I gamma)`` (the plane's point nearest the origin
    in the kinetic metric), so ``T(omega0 + u1 e1 + u2 e2) = T(omega0) + u1^2 + u2^2``.
    """
    inertia = F.inertia()
    zeros = np.zeros_like(gamma)
    values = F.values(np.concatenate([zeros, gamma], axis=1))
    l_dot_gamma = values[:, 3]  # I3 at omega = 0
    g_i_g = np.einsum("mi,i,mi->m", gamma, inertia, gamma)
    omega0 = -(l_dot_gamma / g_i_g)[:, None] * gamma
    normal = gamma * inertia  # the plane's normal I gamma
    helper = np.where(np.abs(gamma[:, :1]) < 0.9, [[1.0, 0, 0]], [[0, 1.0, 0]])
    u = np.cross(normal, helper)
    u /= np.sqrt(0.5 * np.einsum("mi,i,mi->m", u, inertia, u))[:, None]
    v = np.cross(normal, u)
    # make v kinetically orthogonal to u, then unit: T(u) = 1/2 u I u = 1
    v -= (np.einsum("mi,i,mi->m", u, inertia, v) / np.einsum("mi,i,mi->m", u, inertia, u))[
        :, None
    ] * u
    v /= np.sqrt(0.5 * np.einsum("mi,i,mi->m", v, inertia, v))[:, None]
    return omega0, u, v


def sphere_points(count: int, rng: np.random.Generator | None = None) -> np.ndarray:
    """``count`` points on the unit sphere: a Fibonacci lattice, or uniform random with rng."""
    if rng is not None:
        g = rng.normal(size=(count, 3))
        return g / np.linalg.norm(g, axis=1, keepdims=True)
    i = np.arange(count) + 0.5
    z = 1.0 - 2.0 * i / count
    phi = np.pi * (1.0 + 5.0**0.5) * i
    s = np.sqrt(1.0 - z * z)
    return np.stack([s * np.cos(phi), s * np.sin(phi), z], axis=1)


def amended_minimum(F: MomentumMap, gamma: np.ndarray) -> np.ndarray:
    """The least energy over each gamma on the level: ``V + T(omega0)``, shape (m,)."""
    omega0, _, _ = plane_basis(F, gamma)
    return F.values(np.concatenate([omega0, gamma], axis=1))[:, 0]


def states_on_level(
    F: MomentumMap, gamma: np.ndarray, energy: np.ndarray, angle: np.ndarray
) -> np.ndarray:
    """States of the level with given gamma (m, 3), energy (m,) and angle on the conic (m,).

    Where the energy is below the minimum over gamma the radius is clipped to 0.
    """
    omega0, e1, e2 = plane_basis(F, gamma)
    base = F.values(np.concatenate([omega0, gamma], axis=1))[:, 0]
    radius = np.sqrt(np.maximum(energy - base, 0.0))
    omega = omega0 + radius[:, None] * (np.cos(angle)[:, None] * e1 + np.sin(angle)[:, None] * e2)
    return np.concatenate([omega, gamma], axis=1)


def random_level_states(
    F: MomentumMap, h_low: float, h_high: float, count: int, rng: np.random.Generator
) -> np.ndarray:
    """``count`` random states of the level (m, 6): gamma uniform on the sphere, the energy
    uniform in ``[h_low, h_high]`` and the angle on the conic uniform (drawn in that order)."""
    gamma = sphere_points(count, rng)
    energy = rng.uniform(h_low, h_high, count)
    return states_on_level(F, gamma, energy, rng.uniform(0, 2 * np.pi, count))


def multipliers(F: MomentumMap, x: np.ndarray, t: np.ndarray, scales: Scales) -> np.ndarray:
    """Least-squares ``(beta, delta)`` for states x (m, 6) and angles t (m,), shape (m, 2)."""
    grads = F.gradients(x)
    target = -(
        np.cos(t)[:, None] * grads[:, 0] / scales.energy
        + np.sin(t)[:, None] * grads[:, 1] / scales.quartic
    )
    A = grads[:, 2:].transpose(0, 2, 1)  # (m, 6, 2)
    return np.einsum("mij,mj->mi", np.linalg.pinv(A), target)


def canonical(z: np.ndarray) -> np.ndarray:
    """The same solution with ``t`` in [0, pi) (``(a, b) -> -(a, b)`` flips beta, delta)."""
    z = z.copy()
    turns = np.floor(z[:, 6] / np.pi)
    odd = (turns % 2) != 0
    z[:, 6] -= turns * np.pi
    z[odd, 7:] *= -1
    return z


@dataclass
class CriticalPoints:
    """Converged solutions ``z`` (m, 9) with their image ``hk`` (m, 2)."""

    z: np.ndarray
    hk: np.ndarray


def critical_seeds(
    F: MomentumMap, scales: Scales, count: int, rng: np.random.Generator
) -> CriticalPoints:
    """Critical points from ``count`` random points of the level inside the energy range."""
    x = random_level_states(F, scales.h_low, scales.h_high, count, rng)
    t = rng.uniform(0, np.pi, count)
    z = np.concatenate([x, t[:, None], multipliers(F, x, t, scales)], axis=1)
    z, residual = gauss_newton(F, z, scales)
    return keep_critical(F, canonical(z), residual, scales)


def keep_critical(
    F: MomentumMap, z: np.ndarray, residual: np.ndarray, scales: Scales
) -> CriticalPoints:
    """The converged, critical solutions inside the energy range (with a 5 % margin)."""
    ok = residual <= 1e3 * RESIDUAL_TOL
    z = z[ok]
    values = F.values(z[:, :6])
    sigma = relative_singular_value(F.gradients(z[:, :6]))
    margin = 0.05 * (scales.h_high - scales.h_low)
    inside = (
        (sigma <= 1e-7)
        & (values[:, 0] >= scales.h_low - margin)
        & (values[:, 0] <= scales.h_high + margin)
    )
    return CriticalPoints(z=z[inside], hk=values[inside][:, :2])


def flow_direction(F: MomentumMap, z: np.ndarray) -> np.ndarray:
    """The flow's velocity lifted to z (multipliers fixed), unit length, shape (9,)."""
    f = np.zeros(9)
    f[:6] = F.velocity(z[:6])
    norm = np.linalg.norm(f)
    return f / norm if norm > 0 else f


def family_tangent(F: MomentumMap, z: np.ndarray, scales: Scales) -> np.ndarray | None:
    """The unit direction along the family at z: the combination of the Jacobian's two
    weakest right singular vectors orthogonal to the flow (None where there is none)."""
    _, J = residual_and_jacobian(F, z[None, :], scales)
    _, _, vt = np.linalg.svd(J[0])
    kernel = vt[-2:]
    coeffs = kernel @ flow_direction(F, z)
    # the combination of the two kernel vectors orthogonal to the flow
    tangent = kernel[0] * coeffs[1] - kernel[1] * coeffs[0]
    norm = np.linalg.norm(tangent)
    if norm < 1e-8:
        return None
    return tangent / norm


def rank_zero(F: MomentumMap, x: np.ndarray, tol: float = 1e-6) -> np.ndarray:
    """True where dH and dI4 both lie in the span of dI2, dI3 (relative equilibria that are
    also critical for I4: the rank-zero points, vertices of the diagram), shape (m,)."""
    grads = F.gradients(np.atleast_2d(x))
    out = np.empty(grads.shape[0], dtype=bool)
    for i, g in enumerate(grads):
        q, _ = np.linalg.qr(g[2:].T)
        rest = g[:2] - (g[:2] @ q) @ q.T
        norms = np.linalg.norm(g[:2], axis=1)
        # a differential that vanishes to round-off (dH at rest, dI4 where xi = 0) passes
        floor = 1e-8 * np.max(np.linalg.norm(g, axis=1))
        out[i] = bool(np.all(np.linalg.norm(rest, axis=1) <= tol * np.maximum(norms, floor)))
    return out


def equilibria(F: MomentumMap, scales: Scales, count: int = 400) -> CriticalPoints:
    """The rank-zero points: Newton with ``(a, b) = (1, 0)`` from ``omega0(gamma)`` over a
    Fibonacci grid of the sphere (relative equilibria have omega parallel to gamma), kept
    when also critical for I4, one per distinct state."""
    gamma = sphere_points(count)
    omega0, _, _ = plane_basis(F, gamma)
    x = np.concatenate([omega0, gamma], axis=1)
    t = np.zeros(count)
    z = np.concatenate([x, t[:, None], multipliers(F, x, t, scales)], axis=1)
    z, residual = gauss_newton(F, z, scales)
    found = keep_critical(F, canonical(z), residual, _all_energies(scales))
    keep = rank_zero(F, found.z[:, :6])
    return distinct(CriticalPoints(found.z[keep], found.hk[keep]))


def _all_energies(scales: Scales) -> Scales:
    return Scales(scales.energy, scales.quartic, -np.inf, np.inf)


def distinct(points: CriticalPoints, tol: float = 1e-6) -> CriticalPoints:
    """One of each group of points whose states agree within ``tol``."""
    chosen: list[int] = []
    for i, z in enumerate(points.z):
        if all(np.linalg.norm(z[:6] - points.z[j, :6]) > tol for j in chosen):
            chosen.append(i)
    return CriticalPoints(points.z[chosen], points.hk[chosen])


def _equator_states(F: MomentumMap, phi: np.ndarray) -> np.ndarray:
    """States of the equator family at rest relative to the Larmor axes (R = 0)."""
    n = F.params.n
    gamma = np.stack([np.cos(phi), np.sin(phi), np.zeros_like(phi)], axis=1)
    omega = np.stack([-n * gamma[:, 0], -n * gamma[:, 1], np.zeros_like(phi)], axis=1)
    return np.concatenate([omega, gamma], axis=1)


def equator_family(F: MomentumMap, scales: Scales, spacing: float) -> CriticalPoints:
    """The exact critical family ``gamma3 = 0, p + n gamma1 = q + n gamma2 = 0``.

    There the complex form of I4, ``xi = (P + iQ)^2 + (c + id) gamma3^2 (kappa + K^2 s
    - i K R)`` with ``P = p + n gamma1`` etc., vanishes with its first differential, so dI4 = 0
    (I4 = |xi|^2 has a degenerate minimum), and I3 = 0 holds for every R: the image is the
    segment k = 0 from the least potential on the equator. Sampled at the equator's lowest
    point, with R from the energy, every ``spacing`` (diagram units) inside the range.
    """
    states = _equator_states(F, np.linspace(0.0, 2 * np.pi, 3601))
    energies = F.values(states)[:, 0]
    best = int(np.argmin(energies))
    low = max(energies[best], scales.h_low)
    if low >= scales.h_high:
        return CriticalPoints(np.zeros((0, 9)), np.zeros((0, 2)))
    count = max(2, int(np.ceil((scales.h_high - low) / scales.energy / spacing)) + 1)
    h = np.linspace(low, scales.h_high, count)
    # on the family H = C n^2 + C r^2 / 2 + V(gamma): r from the energy in closed form
    base = energies[best]
    r = np.sqrt(np.maximum(2.0 * (h - base) / F.params.C, 0.0))
    x = np.tile(states[best], (count, 1))
    x[:, 2] = r
    z = np.concatenate([x, np.full((count, 1), np.pi / 2), np.zeros((count, 2))], axis=1)
    return CriticalPoints(z, F.values(x)[:, :2])


def equator_vertices(F: MomentumMap, scales: Scales) -> CriticalPoints:
    """Rank-zero points on the equator family: the extremes of the energy along the equator
    at R = 0 (golden-section refined), kept when rank zero."""
    from scipy.optimize import minimize_scalar

    phi = np.linspace(0.0, 2 * np.pi, 721)
    energy = F.values(_equator_states(F, phi))[:, 0]
    slope = np.sign(np.diff(energy))
    turns = np.flatnonzero(slope[:-1] != slope[1:]) + 1
    found = []
    for i in turns:
        sign = 1.0 if slope[i - 1] < 0 else -1.0  # minimum: +E, maximum: -E

        def along(angle: float, sign: float = sign) -> float:
            return sign * float(F.values(_equator_states(F, np.array([angle])))[0, 0])

        best = minimize_scalar(
            along, bounds=(phi[i - 1], phi[i + 1]), method="bounded", options={"xatol": 1e-12}
        )
        found.append(best.x)
    if not found:
        return CriticalPoints(np.zeros((0, 9)), np.zeros((0, 2)))
    x = _equator_states(F, np.array(found))
    t = np.zeros(len(x))
    z = np.concatenate([x, t[:, None], multipliers(F, x, t, scales)], axis=1)
    keep = rank_zero(F, x, tol=1e-7)
    return distinct(CriticalPoints(z[keep], F.values(x[keep])[:, :2]))
