"""Pseudo-arclength continuation of the critical families and their image in (h, k).

Each seed is followed both ways along its family (see :mod:`.critical`); a step is accepted
when Newton converges and the image moves at most ``max_image_step`` (in units of the
diagram's size) and turns at most ``max_turn`` radians, so the polyline through the image
points stays close to the curve. A branch ends where the energy leaves the range, where
the step shrinks below ``min_step`` (an end or a branch point: a relative equilibrium, a
tangency), where the image closes on itself, or after ``max_points``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from chargedesign.topology.critical import (
    CriticalPoints,
    Scales,
    canonical,
    family_tangent,
    gauss_newton,
    keep_critical,
)
from chargedesign.topology.equations import MomentumMap


@dataclass(frozen=True)
class ContinuationSettings:
    """Step control of the continuation (steps in the 9 unknowns, image in diagram units)."""

    first_step: float = 0.02
    min_step: float = 1e-5
    max_step: float = 0.1
    max_image_step: float = 0.02
    max_turn: float = 0.1
    max_points: int = 4000


@dataclass
class Branch:
    """One traced family: solutions ``z`` (m, 9) in order along it, image ``hk`` (m, 2),
    and why each end stopped."""

    z: np.ndarray
    hk: np.ndarray
    ends: tuple[str, str]


def _turn(a: np.ndarray, b: np.ndarray) -> float:
    na, nb = np.linalg.norm(a), np.linalg.norm(b)
    if na == 0 or nb == 0:
        return 0.0
    return float(np.arccos(np.clip(a @ b / (na * nb), -1.0, 1.0)))


def _step(
    F: MomentumMap, z: np.ndarray, tangent: np.ndarray, ds: float, scales: Scales
) -> tuple[np.ndarray, np.ndarray] | None:
    """One predictor-corrector step; the new (z, hk) or None when Newton fails."""
    pred = z + ds * tangent
    new, residual = gauss_newton(F, pred[None, :], scales, iterations=8, extra=(tangent, pred))
    kept = keep_critical(F, canonical(new), residual, _wide(scales))
    if len(kept.z) == 0:
        return None
    return kept.z[0], kept.hk[0]


def _wide(scales: Scales) -> Scales:
    """The same scales with an energy range wide enough never to cut a step."""
    width = scales.h_high - scales.h_low
    return Scales(scales.energy, scales.quartic, scales.h_low - width, scales.h_high + width)


def _inside(hk: np.ndarray, scales: Scales) -> bool:
    return bool(scales.h_low <= hk[0] <= scales.h_high)


def _land_on_bound(
    F: MomentumMap,
    z: np.ndarray,
    hk: np.ndarray,
    tangent: np.ndarray,
    ds: float,
    h_out: float,
    scales: Scales,
) -> tuple[np.ndarray, np.ndarray] | None:
    """The point of the family where h equals the range's bound crossed by the step ``ds``
    from ``(z, hk)`` (whose end has energy ``h_out``): secant iterations on the step."""
    bound = scales.h_high if h_out > scales.h_high else scales.h_low
    a, fa, b, fb = 0.0, hk[0] - bound, ds, h_out - bound
    best = None
    for _ in range(8):
        if fb == fa:
            break
        c = b - fb * (b - a) / (fb - fa)
        result = _step(F, z, tangent, c, scales)
        if result is None:
            break
        best = result
        a, fa, b, fb = b, fb, c, result[1][0] - bound
        if abs(fb) <= 1e-12 * scales.energy:
            break
    return best


def follow(
    F: MomentumMap,
    z0: np.ndarray,
    hk0: np.ndarray,
    direction: float,
    scales: Scales,
    settings: ContinuationSettings,
) -> tuple[list[np.ndarray], list[np.ndarray], str]:
    """Points after ``z0`` along one direction of its family, and why it stopped."""
    zs, hks = [z0], [hk0]
    tangent = family_tangent(F, z0, scales)
    if tangent is None:
        return zs, hks, "no family direction"
    tangent = direction * tangent
    ds = settings.first_step
    while len(zs) < settings.max_points:
        if ds < settings.min_step:
            return zs, hks, "end"
        result = _step(F, zs[-1], tangent, ds, scales)
        if result is None:
            ds *= 0.5
            continue
        z, hk = result
        move = scales.image(hk - hks[-1])
        previous = scales.image(hks[-1] - hks[-2]) if len(hks) > 1 else move
        if np.linalg.norm(move) > settings.max_image_step or _turn(move, previous) > (
            settings.max_turn
        ):
            ds *= 0.5
            continue
        if not _inside(hk, scales):
            landed = _land_on_bound(F, zs[-1], hks[-1], tangent, ds, float(hk[0]), scales)
            if landed is not None:
                zs.append(landed[0])
                hks.append(landed[1])
            return zs, hks, "energy range"
        new_tangent = family_tangent(F, z, scales)
        if new_tangent is None:
            return zs, hks, "end"
        tangent = new_tangent if new_tangent @ tangent >= 0 else -new_tangent
        zs.append(z)
        hks.append(hk)
        if len(hks) > 20 and np.linalg.norm(scales.image(hk - hk0)) < 0.5 * (
            settings.max_image_step
        ):
            return zs, hks, "closed"
        ds = min(ds * 1.5, settings.max_step)
    return zs, hks, "max points"


def trace_branch(
    F: MomentumMap,
    z0: np.ndarray,
    hk0: np.ndarray,
    scales: Scales,
    settings: ContinuationSettings,
) -> Branch:
    """The family through ``z0``, both ways, as one ordered branch."""
    back_z, back_hk, back_end = follow(F, z0, hk0, -1.0, scales, settings)
    if back_end == "closed":
        return Branch(np.array(back_z), np.array(back_hk), ("closed", "closed"))
    fwd_z, fwd_hk, fwd_end = follow(F, z0, hk0, 1.0, scales, settings)
    z = np.array(back_z[::-1] + fwd_z[1:])
    hk = np.array(back_hk[::-1] + fwd_hk[1:])
    return Branch(z, hk, (back_end, fwd_end))


def distance_to_branch(hk: np.ndarray, branch: Branch, scales: Scales) -> float:
    """Distance (diagram units) from an image point to a branch's image polyline."""
    pts = scales.image(branch.hk)
    q = scales.image(hk)
    if len(pts) == 1:
        return float(np.linalg.norm(pts[0] - q))
    a, b = pts[:-1], pts[1:]
    ab = b - a
    length2 = np.maximum(np.einsum("ij,ij->i", ab, ab), 1e-300)
    s = np.clip(np.einsum("ij,ij->i", q - a, ab) / length2, 0.0, 1.0)
    return float(np.min(np.linalg.norm(a + s[:, None] * ab - q, axis=1)))


def trace_all(
    F: MomentumMap,
    seeds: CriticalPoints,
    scales: Scales,
    settings: ContinuationSettings,
    covered: float = 0.004,
) -> list[Branch]:
    """Branches through the seeds; a seed whose image already lies on a traced branch (within
    ``covered`` diagram units) with the same ratio ``a : b`` is skipped."""
    branches: list[Branch] = []
    order = np.argsort(seeds.hk[:, 0])
    for i in order:
        z0, hk0 = seeds.z[i], seeds.hk[i]
        if any(
            distance_to_branch(hk0, b, scales) < covered and _same_ratio(z0, b) for b in branches
        ):
            continue
        branches.append(trace_branch(F, z0, hk0, scales, settings))
    return branches


def _same_ratio(z0: np.ndarray, branch: Branch) -> bool:
    """True when the seed's angle t is near one of the branch's (mod pi)."""
    diff = np.abs(branch.z[:, 6] - z0[6]) % np.pi
    return bool(np.min(np.minimum(diff, np.pi - diff)) < 0.05)
