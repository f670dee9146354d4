"""The accurate evaluation: the kernel's sums in double-double.

Part of :mod:`chargedesign.checker` (see its docstring for the method).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from chargedesign.checker.constants import (
    BLOCK_PAIRS,
)
from chargedesign.checker.double_double import (
    DoubleDouble,
    sum_last_axis,
    to_float_array,
)
from chargedesign.checker.kernel import (
    POTENTIAL_EFFECTS,
    orientation_blocks,
    trimmed_legendre,
)
from chargedesign.quadrature import GatheredElements
from chargedesign.vocabulary import (
    FIELD_NAMES,
)


@dataclass
class AccurateZonalSums:
    """value, gradient sums (D, T) and Hessian sums (W, E, ZZ) of one field (see the kernel
    notes above), in the accurate arithmetic; floats where a sum has no element term."""

    value: Any
    D: Any
    T: Any
    W: Any = 0.0
    E: Any = 0.0
    ZZ: Any = 0.0


def zonal_sums_accurate(
    coeffs: np.ndarray, Z: Any, S: Any, order: int, lift: Callable[[Any], Any]
) -> AccurateZonalSums:
    """The recurrences of the kernel notes in the accurate arithmetic (integer factors exact:
    every ``(2k + 1) / (k + 1)`` is a multiplication and a division, not a rounded ratio)."""
    K = len(coeffs)
    f = [lift(0.0), *(lift(float(c)) for c in coeffs)]
    u: list[Any] = [1.0, Z]
    for k in range(1, K):
        u.append(((2 * k + 1) * (Z * u[k]) - k * (S * u[k - 1])) / float(k + 1))
    value: Any = 0.0
    D: Any = 0.0
    T: Any = 0.0
    v: list[Any] = [0.0, 1.0]
    for k in range(1, K - 1):
        v.append(S * v[k - 1] + (2 * k + 1) * u[k])
    for k in range(1, K + 1):
        if coeffs[k - 1] == 0.0:
            continue
        value = value + f[k] * u[k]
        D = D + (f[k] * k) * u[k - 1]
        T = T + f[k] * v[k - 1]
    out = AccurateZonalSums(value, D, T)
    if order >= 2:
        t: list[Any] = [0.0, 0.0]
        for k in range(1, K - 1):
            t.append(S * t[k - 1] - (2 * k - 1) * v[k - 1])
        for k in range(1, K + 1):
            if coeffs[k - 1] == 0.0:
                continue
            out.W = out.W + f[k] * t[k - 1]
            if k >= 2:
                out.E = out.E + (f[k] * k) * v[k - 2]
                out.ZZ = out.ZZ + (f[k] * (k * (k - 1))) * u[k - 2]
    return out


@dataclass
class AccurateSums:
    """Per-orientation sums of :func:`evaluate_accurate` (body axes, SI units), each
    correctly rounded to double from the accurate arithmetic.

    ``energy_centered`` is the total energy minus its mean over the orientations, both
    formed in the accurate arithmetic (an orientation-independent part of the energy, however
    large, then costs no accuracy); ``energy_mean`` is that mean (J).
    """

    mu: np.ndarray
    gyro: np.ndarray
    energy: dict[str, np.ndarray]
    energy_centered: np.ndarray
    energy_mean: float
    torque: dict[str, np.ndarray]
    precision: str


def cross_components(a: tuple[Any, Any, Any], b: tuple[Any, Any, Any]) -> tuple[Any, Any, Any]:
    """Cross product ``a x b`` of two vectors given as component triples (any arithmetic)."""
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def arithmetic_lift(precision: str) -> Callable[[Any], Any]:
    """The map from doubles into the accurate arithmetic named by ``precision``."""
    if precision == "double-double":
        return DoubleDouble
    if precision == "longdouble":
        return lambda x: np.asarray(x, dtype=np.longdouble)
    raise ValueError(f"precision: expected 'double-double' or 'longdouble', got {precision!r}")


class AccurateAccumulator:
    """The per-orientation sums of :func:`evaluate_accurate`, accumulated block by block in
    the accurate arithmetic (``lift``), in body axes."""

    def __init__(
        self,
        gammas: np.ndarray,
        omegas: np.ndarray,
        lift: Callable[[Any], Any],
        block_pairs: int,
    ) -> None:
        self.gammas, self.omegas, self.lift = gammas, omegas, lift
        self.block_pairs = block_pairs
        m = len(gammas)
        self.mu = [lift(np.zeros(m)) for _ in range(3)]
        self.gyro = [lift(np.zeros(m)) for _ in range(3)]
        self.energy = {k: lift(np.zeros(m)) for k in POTENTIAL_EFFECTS}
        self.torque = {k: [lift(np.zeros(m)) for _ in range(3)] for k in POTENTIAL_EFFECTS}

    def unit_gammas(self, rows: slice) -> tuple[Any, Any, Any]:
        """gamma normalised in the accurate arithmetic, for the orientations ``rows``."""
        # 1 / |g| = 1 - delta / 2 + 3 delta^2 / 8 + O(delta^3), delta = |g|^2 - 1 ~ 1e-16
        gammas = self.gammas
        g = [self.lift(gammas[rows, i]) for i in range(3)]
        delta = g[0] * gammas[rows, 0] + g[1] * gammas[rows, 1] + g[2] * gammas[rows, 2] - 1.0
        scale = 1.0 - delta * 0.5 + (delta * delta) * 0.375
        return g[0] * scale, g[1] * scale, g[2] * scale

    @staticmethod
    def add_rows(target: Any, rows: slice, value: Any) -> None:
        """``target[rows] += value`` in either arithmetic."""
        if isinstance(target, DoubleDouble):
            block = target[rows] + value
            target.hi[rows], target.lo[rows] = block.hi, block.lo
        else:
            target[rows] = target[rows] + value

    def geometry(self, r: np.ndarray, rows: slice) -> tuple[Any, ...]:
        """(gamma columns, r components, Z = gamma . r, S = |r|^2, t = r - Z gamma)."""
        g = self.unit_gammas(rows)
        gc = tuple(gi[:, None] for gi in g)
        x, y, z = r[:, 0], r[:, 1], r[:, 2]
        Z = gc[0] * x + gc[1] * y + gc[2] * z
        S = self.lift(x) * x + self.lift(y) * y + self.lift(z) * z
        t = (x - Z * gc[0], y - Z * gc[1], z - Z * gc[2])
        return gc, (x, y, z), Z, S, t

    def blocks(self, n: int) -> list[slice]:
        """Orientation blocks of at most ``block_pairs`` pairs with ``n`` elements."""
        return orientation_blocks(len(self.gammas), n, self.block_pairs)[1]

    def add_potential(self, name: str, r: np.ndarray, w: np.ndarray, c: np.ndarray) -> None:
        """Energy and torque of weights ``w`` at ``r`` in the zonal potential ``c``."""
        for rows in self.blocks(len(w)):
            gc, xyz, Z, S, _ = self.geometry(r, rows)
            h = zonal_sums_accurate(c, Z, S, 1, self.lift)
            self.add_rows(self.energy[name], rows, sum_last_axis(h.value * w))
            # X x (-w grad Phi) = -w (D + Z T) (r x gamma)
            lever = (h.D + Z * h.T) * (-w)
            for i, arm in enumerate(cross_components(xyz, gc)):
                self.add_rows(self.torque[name][i], rows, sum_last_axis(lever * arm))

    def add_lorentz(self, r: np.ndarray, q: np.ndarray, c: np.ndarray) -> None:
        """mu and the Lorentz torque of charges ``q`` at ``r`` in the magnetic field ``c``."""
        for rows in self.blocks(len(q)):
            gc, xyz, Z, S, t = self.geometry(r, rows)
            h = zonal_sums_accurate(c, Z, S, 1, self.lift)
            B = tuple(t[i] * h.T - h.D * gc[i] for i in range(3))
            qrB = (B[0] * xyz[0] + B[1] * xyz[1] + B[2] * xyz[2]) * q
            for i in range(3):
                self.add_rows(self.mu[i], rows, -sum_last_axis(qrB * xyz[i]))
            om = tuple(self.lift(self.omegas[rows, i])[:, None] for i in range(3))
            v = cross_components(om, xyz)  # omega x r
            force = tuple(fi * q for fi in cross_components(v, B))  # q v x B
            for i, ti in enumerate(cross_components(xyz, force)):
                self.add_rows(self.gyro[i], rows, sum_last_axis(ti))

    def add_dipoles(self, r: np.ndarray, sigma: np.ndarray, c: np.ndarray) -> None:
        """Energy and torque (spin and lever) of dipoles ``sigma`` at ``r`` in the field ``c``."""
        s = (sigma[:, 0], sigma[:, 1], sigma[:, 2])
        for rows in self.blocks(len(sigma)):
            gc, xyz, Z, S, t = self.geometry(r, rows)
            h = zonal_sums_accurate(c, Z, S, 2, self.lift)
            B = tuple(t[i] * h.T - h.D * gc[i] for i in range(3))
            self.add_rows(
                self.energy["magnetization"],
                rows,
                -sum_last_axis(B[0] * s[0] + B[1] * s[1] + B[2] * s[2]),
            )
            sg = gc[0] * s[0] + gc[1] * s[1] + gc[2] * s[2]
            st = t[0] * s[0] + t[1] * s[1] + t[2] * s[2]
            # F = grad(sigma . B) = -H sigma,
            # H = -T (1 - g g^T) - W t t^T - E (t g^T + g t^T) + ZZ g g^T
            force = tuple(
                h.T * (s[i] - gc[i] * sg)
                + h.W * (t[i] * st)
                + h.E * (t[i] * sg + gc[i] * st)
                - h.ZZ * (gc[i] * sg)
                for i in range(3)
            )
            spin = cross_components(s, B)
            lever = cross_components(xyz, force)
            for i in range(3):
                self.add_rows(
                    self.torque["magnetization"][i], rows, sum_last_axis(spin[i] + lever[i])
                )

    def result(self, precision: str) -> AccurateSums:
        """The sums rounded to double, with the energy centred in the accurate arithmetic."""
        energy, m = self.energy, len(self.gammas)
        total = energy["electric"] + energy["gravity"] + energy["magnetization"]
        if isinstance(total, DoubleDouble):
            mean = sum_last_axis(total) / float(m)
        else:
            mean = np.mean(total)
        return AccurateSums(
            mu=np.stack([to_float_array(c) for c in self.mu], axis=1),
            gyro=np.stack([to_float_array(c) for c in self.gyro], axis=1),
            energy={k: to_float_array(v) for k, v in energy.items()},
            energy_centered=to_float_array(total - mean),
            energy_mean=float(to_float_array(mean)),
            torque={
                k: np.stack([to_float_array(c) for c in v], axis=1) for k, v in self.torque.items()
            },
            precision=precision,
        )


def evaluate_accurate(
    elements: GatheredElements,
    fields: dict[str, tuple[float, ...]],
    gammas: np.ndarray,
    omegas: np.ndarray,
    *,
    precision: str = "double-double",
    block_pairs: int = BLOCK_PAIRS,
) -> AccurateSums:
    """mu, the Lorentz torque, the energies and the torques in extended precision.

    The same quantities as :func:`evaluate_rotated`, from the same recurrences, evaluated
    in body axes (``Z = gamma . r``, transverse part ``t = r - Z gamma``, ``grad Phi =
    -T t + D gamma``) in double-double arithmetic (about 32 digits) or ``np.longdouble``
    (``precision="longdouble"``; 19 digits on x86-64). The inputs (positions, weights, field
    coefficients, gamma, omega) are exact doubles; gamma is normalised in the accurate
    arithmetic, so the harmonics are harmonic to its precision (a double gamma is unit only
    to 1e-16, which a body whose contributions cancel would otherwise feel).

    Parameters
    ----------
    elements : GatheredElements
    fields : dict[str, tuple of float]
    gammas : ndarray, shape (m, 3)
        Near-unit vectors (|gamma| = 1 to 1e-12).
    omegas : ndarray, shape (m, 3)
        Angular velocities in body axes, rad/s.
    precision : str
        ``double-double`` or ``longdouble``.
    block_pairs : int
        Element-orientation pairs per vectorised block.

    Returns
    -------
    AccurateSums
    """
    lift = arithmetic_lift(precision)
    gammas = np.asarray(gammas, dtype=np.float64)
    if np.abs(np.einsum("ij,ij->i", gammas, gammas) - 1.0).max(initial=0.0) > 1e-12:
        raise ValueError("gammas: expected unit vectors (to 1e-12)")
    coeffs = {k: trimmed_legendre(fields.get(k, ())) for k in FIELD_NAMES}
    acc = AccurateAccumulator(gammas, omegas, lift, block_pairs)
    r, q = elements.charge_positions, elements.charge_values
    if len(q) and len(coeffs["magnetic"]):
        acc.add_lorentz(r, q, coeffs["magnetic"])
    if len(q) and len(coeffs["electric"]):
        acc.add_potential("electric", r, q, coeffs["electric"])
    r, w = elements.mass_positions, elements.mass_values
    if len(w) and len(coeffs["gravity"]):
        acc.add_potential("gravity", r, w, coeffs["gravity"])
    r, sigma = elements.dipole_positions, elements.dipole_moments
    if len(sigma) and len(coeffs["magnetic"]):
        acc.add_dipoles(r, sigma, coeffs["magnetic"])
    return acc.result(precision)
