"""The catalogue of parasitic laws: what the idealised theorem leaves out, as pure functions.

Each law takes the body's figures (charges, radii, rates, masses, parts as spheres, the
applied field) and returns the parasitic's size in SI units. The realism budget
(:mod:`chargedesign.physical.realism`), the realised window (:mod:`chargedesign.physical.
window`) and a case's budget all call these and nothing else for the physics:

=========================  ===========================================================
law                        what it gives
=========================  ===========================================================
:func:`speed_over_c`       ``|omega| r_max / c`` of the fastest element (corrections ~ its square)
:func:`larmor_power`       the charges' Larmor power, incoherent (an upper bound), W
:func:`self_field`         the moving charges' field at O, ``mu0 |q| omega / (4 pi r)``, T
:func:`balance_torque`     gravity on a balance off by ``delta``: ``M g delta``, N m
:func:`balance_offset`     the offset whose gravity torque is a fraction of a torque, m
:func:`laminar_drag`       ``8 pi mu R^3 omega`` on the enveloping sphere, N m
:func:`reynolds`           ``rho omega R^2 / mu`` of that flow
induced magnetisation      :func:`induced_energies_by_set`: ``-chi v |B|^2 / (2 mu0)`` per
                           part set and orientation, J
eddy currents              :func:`eddy_torques_by_set` (the estimate) and :func:`eddy_torque`
                           (the torque a simulation applies), N m
=========================  ===========================================================
"""

from __future__ import annotations

import functools
import math
from typing import Any

import numpy as np

from chargedesign.constants import EPSILON_0, LIGHT_SPEED, MU_0
from chargedesign.fields import AxisymmetricField, zonal_sums
from chargedesign.physical.materials import BUILDER_BALANCE_M
from chargedesign.sampling import fibonacci_sphere

#: orientations (a Fibonacci sphere) at which the induced-magnetisation energy is evaluated
RESPONSE_ORIENTATIONS = 2000
#: how many bodies' rate-free factors (the field at the parts over the orientations, for one
#: field and one set of part centres or part sets) are kept: the stages that judge one body
#: (its limits, budget, map, window, the frontier's probes) compute each once
FACTOR_CACHE_SIZE = 128
#: part centres per block of the eddy factor's (orientations, centres) arrays
EDDY_BLOCK = 256


def speed_over_c(rate: float, r_max: float) -> float:
    """``|omega| r_max / c`` of the fastest element."""
    return rate * r_max / LIGHT_SPEED


def larmor_power(charges: np.ndarray, radii: np.ndarray, rate: float) -> float:
    """``sum q^2 (omega^2 r)^2 / (6 pi eps0 c^3)``: the charges turning at ``rate`` about an
    axis at distances ``radii`` radiate at most this (incoherent sum), W."""
    q = np.asarray(charges, dtype=float)
    r = np.asarray(radii, dtype=float)
    return float(np.sum(q**2 * (rate**2 * r) ** 2)) / (6 * math.pi * EPSILON_0 * LIGHT_SPEED**3)


def self_field(charges: np.ndarray, radii: np.ndarray, rate: float) -> float:
    """``mu0 / (4 pi) sum |q| omega / r``: the field the moving charges make at O, T (a charge
    at O moves not and adds nothing)."""
    q = np.asarray(charges, dtype=float)
    r = np.asarray(radii, dtype=float)
    return MU_0 / (4 * math.pi) * float(np.sum(np.abs(q) * rate / np.where(r > 0, r, np.inf)))


def balance_torque(mass: float, gravity: float, offset: float = BUILDER_BALANCE_M) -> float:
    """``M g delta``: gravity's torque on a body whose centre of mass is ``offset`` off O."""
    return mass * gravity * offset


def balance_offset(torque: float, mass: float, gravity: float) -> float:
    """The offset of the centre of mass whose gravity torque is ``torque`` (inf: no mass)."""
    return torque / (mass * gravity) if mass > 0 else math.inf


def laminar_drag(viscosity: float, radius: float, rate: float) -> float:
    """``8 pi mu R^3 omega``: the laminar drag on a sphere turning in a viscous medium, N m."""
    return 8 * math.pi * viscosity * radius**3 * rate


def reynolds(density: float, viscosity: float, radius: float, rate: float) -> float:
    """``rho omega R^2 / mu`` of the flow round the turning sphere (0 in vacuum)."""
    return density * rate * radius**2 / viscosity if viscosity > 0 else 0.0


def induced_energies_by_set(legendre: tuple[float, ...], parts: list[dict[str, Any]]) -> np.ndarray:
    """``-sum chi v |B|^2 / (2 mu0)`` of each part set at each orientation (J), (sets, n).

    The field is axisymmetric, so a part at body position r sees the field at the point of
    polar coordinates (|r|, gamma . r): ``|B|^2`` there, for gamma on a Fibonacci sphere.
    For fields of degree <= 2 (the paper's) ``|B|^2`` is quadratic, and its mean over a
    sphere or shell of material differs from its value at the centre by an orientation-free
    constant, so the parts may be taken as points.

    It does not depend on the rate: computed once per field and part sets (their ``chi``,
    centres and volumes; :data:`FACTOR_CACHE_SIZE` kept), a fresh copy returned each call.
    """
    key = tuple(
        (
            None if part["chi"] is None else float(part["chi"]),
            array_key(part["centres"], 3),
            array_key(part["volumes"], 1),
        )
        for part in parts
    )
    return _induced_energies(_field_key(legendre), key).copy()


@functools.lru_cache(maxsize=FACTOR_CACHE_SIZE)
def _induced_energies(
    legendre: tuple[float, ...], sets: tuple[tuple[float | None, bytes, bytes], ...]
) -> np.ndarray:
    """:func:`induced_energies_by_set` on hashable content (the arrays as float64 bytes)."""
    fld = AxisymmetricField(legendre)
    gammas = fibonacci_sphere(RESPONSE_ORIENTATIONS)
    out = np.zeros((len(sets), len(gammas)))
    for k, (chi, centres_bytes, volumes_bytes) in enumerate(sets):
        if chi is None or fld.is_zero:
            continue
        all_centres = np.frombuffer(centres_bytes).reshape(-1, 3)
        volumes = np.frombuffer(volumes_bytes)
        energy = out[k]
        for start in range(0, len(volumes), 64):
            centres = all_centres[start : start + 64]
            weights = chi * volumes[start : start + 64]
            z = centres @ gammas.T  # (k, orientations)
            rho = np.sqrt(np.maximum(np.sum(centres**2, axis=1)[:, None] - z**2, 0.0))
            points = np.stack([rho, np.zeros_like(rho), z], axis=-1).reshape(-1, 3)
            b2 = np.sum(fld.gradient(points) ** 2, axis=1).reshape(z.shape)
            energy -= weights @ b2 / (2.0 * MU_0)
    out.flags.writeable = False
    return out


def _field_key(legendre: Any) -> tuple[float, ...]:
    return tuple(float(f) for f in legendre)


def array_key(values: Any, width: int) -> bytes:
    """The float64 bytes of an array (rows of ``width``): a hashable key of its content, for
    the caches of rate-free factors (``np.frombuffer(key).reshape(-1, width)`` reads it back)."""
    return np.ascontiguousarray(np.asarray(values, dtype=np.float64).reshape(-1, width)).tobytes()


def eddy_rate_squared(legendre: tuple[float, ...], centres: np.ndarray) -> np.ndarray:
    """``max |dB/dt|^2 / |omega|^2`` over orientations and directions of omega at each part
    centre (T^2), (k,).

    In body axes a part at ``c`` moving at ``v = omega x c`` through the field sees
    ``dB/dt = R^T (v . grad) B - omega x B = L omega`` with ``L = [B0]x - G [c]x`` (``B0`` and
    ``G`` the field and its gradient at the part, body axes): its largest value over the
    directions of omega is the spectral norm of L, maximised here over
    :data:`RESPONSE_ORIENTATIONS` orientations. Without the gradient it is ``max |B|^2``.

    The field is axisymmetric, so the normal ``e`` of the plane of ``c`` and gamma is an
    eigenvector of ``G`` (the field is even in the distance from that plane), and ``B0``,
    ``c``, ``G (c x e)`` lie in the plane: ``L = u e^T + e w^T`` with ``u = L e`` and
    ``w = L^T e`` both in the plane, so the singular values of L are ``|u|``, ``|w|`` and 0.
    With ``Phi(Z, S)`` (``Z = c . gamma``, ``S = |c|^2``, ``rho^2 = S - Z^2``; the partial
    derivatives of :func:`chargedesign.fields.zonal_sums`) they are ``|w| = |Phi_Z|`` (the
    part turning in B) and ``|u|^2 = (Phi_Z + 2 rho^2 Phi_ZS)^2 + rho^2 (Phi_ZZ + 2 Z
    Phi_ZS)^2`` (with its motion through the gradient): the spectral norm without an SVD
    (tests/physical/test_parasitics_once.py checks it against ``np.linalg.norm(L, 2)``).

    It does not depend on the rate: computed once per field and set of centres
    (:data:`FACTOR_CACHE_SIZE` kept), a fresh copy returned each call.
    """
    return _eddy_rate_squared(_field_key(legendre), array_key(centres, 3)).copy()


@functools.lru_cache(maxsize=FACTOR_CACHE_SIZE)
def _eddy_rate_squared(legendre: tuple[float, ...], centres_bytes: bytes) -> np.ndarray:
    """:func:`eddy_rate_squared` on hashable content (the centres as float64 bytes)."""
    fld = AxisymmetricField(legendre)
    centres = np.frombuffer(centres_bytes).reshape(-1, 3)
    out = np.zeros(len(centres))
    if not fld.is_zero and len(centres):
        coeffs = np.asarray(fld.legendre[: fld.degree], dtype=np.float64)
        gammas = fibonacci_sphere(RESPONSE_ORIENTATIONS)
        for start in range(0, len(centres), EDDY_BLOCK):
            c = centres[start : start + EDDY_BLOCK]
            s = np.einsum("ij,ij->i", c, c)
            z = gammas @ c.T  # (orientations, k)
            rho2 = np.maximum(s[None, :] - z * z, 0.0)
            d = zonal_sums(coeffs, z, s, 2, want_value=False)
            turning = d["Z"] ** 2
            moving = (d["Z"] + 2.0 * rho2 * d["ZS"]) ** 2 + rho2 * (
                d["ZZ"] + 2.0 * z * d["ZS"]
            ) ** 2
            out[start : start + EDDY_BLOCK] = np.max(np.maximum(turning, moving), axis=0)
    out.flags.writeable = False
    return out


def eddy_coefficients_by_set(
    legendre: tuple[float, ...], parts: list[dict[str, Any]]
) -> np.ndarray:
    """The eddy-current torque of each part set per unit rate (N m s): the rate-free factor
    ``(2 pi / 15) sum sigma max|L|^2 (a^5 - b^5)`` of :func:`eddy_torques_by_set` (0 for a
    set of unknown conductivity, or without a field)."""
    out = np.zeros(len(parts))
    if not legendre:
        return out
    for k, part in enumerate(parts):
        if part["sigma"] is None:
            continue
        b2 = eddy_rate_squared(tuple(legendre), part["centres"])
        out[k] = float(np.sum(2.0 * np.pi / 15.0 * b2 * _eddy_weight(part)))
    return out


def eddy_torques_by_set(legendre: tuple[float, ...], parts: list[dict[str, Any]], rate: float):
    """Eddy-current torque of each part set turning at ``rate`` through the field (N m).

    A conducting sphere (radius a, a shell: ``a^5 - b^5``; skin depth much larger than the
    part) in a field changing uniformly at ``dB/dt`` carries ``E = -(dB/dt) x rho / 2`` and
    dissipates ``(2 pi / 15) sigma |dB/dt|^2 a^5``; over ``|omega|`` that is the damping
    torque ``(2 pi / 15) sigma |omega| max|L|^2 a^5`` (:func:`eddy_rate_squared`: the part's
    rotation in B and its motion through the gradient). Spinning in a uniform B this is the
    slow-rotation limit of the rotating sphere (:func:`eddy_torque`, whose dissipated power
    it bounds from above). Dropped: the current quadratic in rho, ``(a / |c|)^2`` smaller.
    Linear in the rate: ``rate`` times :func:`eddy_coefficients_by_set`.
    """
    return rate * eddy_coefficients_by_set(legendre, parts)


def holder_eddy_torque(legendre: tuple[float, ...], holder: dict[str, Any] | None, rate: float):
    """An upper bound of the eddy torque on a conducting holder (a sphere of radius R about
    O), N m: with ``v x B = (omega x rho) x (B0 + G rho)`` the dissipated power is at most
    ``sigma int |v x B|^2`` (the current is the projection of ``sigma v x B`` on the
    divergence-free fields), so ``tau <= 4 pi sigma |omega| (B0^2 R^5 / 5 + B0 G R^6 / 3 +
    G^2 R^7 / 7)`` with ``B0 = |B(O)|`` and ``G`` the largest singular value of the gradient
    at O. 0 without a holder or its conductivity; the bores are not subtracted (a bound)."""
    if not holder or not legendre or not holder.get("conductivity_S_per_m"):
        return 0.0
    fld = AxisymmetricField(tuple(legendre))
    if fld.is_zero:
        return 0.0
    origin = np.zeros((1, 3))
    axis = np.array([[0.0, 0.0, 1.0]])
    b0 = float(np.linalg.norm(fld.gradient_body(origin, axis)[0, 0]))
    g = float(np.linalg.norm(fld.hessian_body(origin, axis)[0, 0], ord=2))
    r = float(holder["radius_m"])
    sigma = float(holder["conductivity_S_per_m"])
    return 4 * math.pi * sigma * rate * (b0**2 * r**5 / 5 + b0 * g * r**6 / 3 + g**2 * r**7 / 7)


def _eddy_weight(part: dict[str, Any]) -> np.ndarray:
    """``sigma (a^5 - b^5)`` of each sphere or shell of a part set, S m^4."""
    return part["sigma"] * (part["outer"] ** 5 - part["inner"] ** 5)


def eddy_weights(parts: list[dict[str, Any]]) -> tuple[np.ndarray, np.ndarray]:
    """The conducting parts as spheres: centres (k, 3) and ``sigma (a^5 - b^5)`` (k,) (S m^4).

    The eddy torque of a sphere or shell is this weight times the field's terms
    (:func:`eddy_torques_by_set`, :func:`eddy_torque`); parts of no or zero conductivity are
    left out.
    """
    conducting = [p for p in parts if p["sigma"]]
    if not conducting:
        return np.zeros((0, 3)), np.zeros(0)
    centres = np.concatenate([p["centres"] for p in conducting])
    weights = np.concatenate([_eddy_weight(p) for p in conducting])
    return centres, weights


def eddy_torque(
    legendre: tuple[float, ...],
    centres: np.ndarray,
    weights: np.ndarray,
    omega: np.ndarray,
    gammas: np.ndarray,
) -> np.ndarray:
    """Eddy-current torque about O on conducting spheres turning with the body (N m, body axes).

    Each sphere (centre ``c``, weight ``sigma (a^5 - b^5)``, :func:`eddy_weights`) moves at
    ``v = omega x (c + rho)`` through ``B(c + rho) = B0 + G rho`` (``B0 = -grad Phi(c)``,
    ``G = -Hess Phi(c)``, the field linear over the part). The uniform part of ``v x B``
    drives no current (surface charges cancel it); of the part linear in ``rho``,
    ``M rho = (omega x c) x (G rho) + (omega x rho) x B0``, the symmetric part is a gradient
    cancelled by charges and the antisymmetric part ``w x rho`` drives ``J = sigma w x rho``
    (divergence-free, tangent to every sphere about c: it meets the boundary condition as it
    is). With ``int rho rho^T dV = (4 pi / 15)(a^5 - b^5) 1`` the torque is
    ``sigma (4 pi / 15)(a^5 - b^5) (w x B0 + c x G w)`` (``tr G = 0``), linear in omega:
    ``tau = -D(gamma) omega``. Spinning about its centre in a uniform B (``w = omega x B0 /
    2``) this is ``-(2 pi / 15) sigma a^5 B0 x (omega x B0)``: the slow-rotation limit of
    the rotating sphere (H. Hertz, "On induction in rotating spheres", 1880, *Miscellaneous
    Papers* ch. II; the current ``(sigma / 2) rho x (B0 x omega)`` is derived above and
    checked by quadrature in tests/physical/test_eddy.py), whose magnitude
    :func:`eddy_torques_by_set` estimates. Dropped: terms
    ``(a / |c|)^2`` smaller (the current of the part quadratic in rho), and skin effects
    (slow rotation: skin depth much larger than the part).

    Parameters
    ----------
    legendre : tuple of float
        The magnetic field's Legendre coefficients.
    centres : ndarray, shape (k, 3)
        Sphere centres in body axes, m.
    weights : ndarray, shape (k,)
        ``sigma (a^5 - b^5)`` per sphere, S m^4.
    omega, gammas : ndarray, shape (m, 3)
        Angular velocities (1/s) and the field axis, in body axes.

    Returns
    -------
    ndarray, shape (m, 3)
    """
    omega = np.asarray(omega, dtype=float)
    out = np.zeros_like(omega)
    fld = AxisymmetricField(tuple(legendre))
    if not len(weights) or fld.is_zero:
        return out
    c = np.asarray(centres, dtype=float)[None]  # (1, k, 3)
    b0 = -fld.gradient_body(centres, gammas)  # (m, k, 3)
    g = -fld.hessian_body(centres, gammas)  # (m, k, 3, 3)
    w_ = omega[:, None, :]
    u = np.cross(w_, c)  # (m, k, 3): the part centre's velocity
    # M = [u]x G - [B0]x [omega]x, and w the axial vector of its antisymmetric part
    m_mat = np.einsum("...ij,...jk->...ik", _skew(u), g) - np.einsum(
        "...ij,...jk->...ik", _skew(b0), _skew(np.broadcast_to(w_, u.shape))
    )
    w = 0.5 * np.stack(
        [
            m_mat[..., 2, 1] - m_mat[..., 1, 2],
            m_mat[..., 0, 2] - m_mat[..., 2, 0],
            m_mat[..., 1, 0] - m_mat[..., 0, 1],
        ],
        axis=-1,
    )
    per_part = np.cross(w, b0) + np.cross(c, np.einsum("...ij,...j->...i", g, w))
    return (4.0 * np.pi / 15.0) * np.einsum("mki,k->mi", per_part, np.asarray(weights, float))


def _skew(v: np.ndarray) -> np.ndarray:
    """The cross-product matrices ``[v]x`` of (..., 3) vectors, shape (..., 3, 3)."""
    out = np.zeros((*v.shape, 3))
    out[..., 0, 1], out[..., 0, 2] = -v[..., 2], v[..., 1]
    out[..., 1, 0], out[..., 1, 2] = v[..., 2], -v[..., 0]
    out[..., 2, 0], out[..., 2, 1] = -v[..., 1], v[..., 0]
    return out
