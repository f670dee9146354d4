"""The bifurcation command's refusals, on plain numbers (the boundary: issue 33 item 2).

The diagram's kernels (:mod:`chargedesign.topology`) compute the figures a refusal rests on
(the energy spread, the least energy, the Larmor shift) and call these checks, which raise
the one-line :class:`~chargedesign.errors.InputError` the user sees.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import NoReturn

from chargedesign.errors import InputError
from chargedesign.formatting import CELL, PLAIN, fmt

#: the Larmor shift C n^2 may be at most this many times the spread of the critical energies
#: (beyond it the diagram's energies differ only in their last digits)
MAX_SHIFT_OVER_SPREAD = 1e10
#: an energy range may be at most this many times the spread of the critical energies wide
#: (the continuation's steps are a fiftieth of the range: beyond it the structure is lost)
MAX_RANGE_OVER_SPREAD = 1e3
#: and at least this fraction of it
MIN_RANGE_OVER_SPREAD = 1e-6


def check_regular(lam: float, rho: float) -> None:
    """Refuse lambda or rho != 0: the singular terms blow up on the level I3 = 0."""
    if lam != 0.0 or rho != 0.0:
        raise InputError(
            "parameters: the bifurcation diagram needs lambda = rho = 0 (the singular terms "
            f"blow up on gamma3 = 0, which the level I3 = 0 crosses); got lambda = "
            f"{fmt(lam, PLAIN)}, rho = {fmt(rho, PLAIN)}"
        )


def check_not_free_top(c: float, d: float, K: float, kappa: float) -> None:
    """Refuse c = d = 0 or K = kappa = 0: a free symmetric top, every level critical."""
    if math.hypot(c, d) == 0.0 or (K == 0.0 and kappa == 0.0):
        raise InputError(
            "parameters: no bifurcation diagram with c = d = 0 or K = kappa = 0: the potential"
            " and the extra terms of I4 vanish (a free symmetric top, I4 = |p + i q|^4 after"
            f" Larmor, every level critical); got c = {fmt(c, PLAIN)}, d ="
            f" {fmt(d, PLAIN)}, K = {fmt(K, PLAIN)}, kappa ="
            f" {fmt(kappa, PLAIN)}"
        )


def check_larmor_shift(shift: float, spread: float) -> None:
    """Refuse a Larmor shift ``C n^2`` (J) that swamps the ``spread`` of the critical energies."""
    if not (math.isfinite(spread) and spread > 0.0) or shift > MAX_SHIFT_OVER_SPREAD * spread:
        raise InputError(
            f"parameters.n: the Larmor shift C n^2 = {fmt(shift, CELL)} J is over"
            f" {fmt(MAX_SHIFT_OVER_SPREAD, CELL)} times the spread of the critical energies"
            f" ({fmt(spread, CELL)} J): the diagram's energies would differ only in their last"
            " digits; it is the diagram of n = 0 shifted by C n^2, so compute it with n = 0"
        )


def check_h_range(lo: float, hi: float) -> None:
    """``--h-range``: two finite energies LO < HI."""
    if not (math.isfinite(lo) and math.isfinite(hi)) or lo >= hi:
        raise InputError(
            f"--h-range: expected two finite energies LO < HI, got {fmt(lo, PLAIN)}"
            f" {fmt(hi, PLAIN)}"
        )


def refuse_inadmissible_range(lo: float, hi: float, least: float) -> NoReturn:
    """``--h-range`` below the ``least`` energy (J) on I3 = 0: no motion to draw."""
    raise InputError(
        f"--h-range: no admissible motion for energies {fmt(lo, PLAIN)} .. {fmt(hi, PLAIN)} J:"
        " on I3 = 0 the "
        f"energy is at least {fmt(least, CELL)} J"
    )


def check_range_width(lo: float, hi: float, width: float, spread: float) -> None:
    """Refuse an admissible ``width`` (J) of ``lo .. hi`` too narrow against the ``spread``."""
    if width < MIN_RANGE_OVER_SPREAD * spread:
        raise InputError(
            f"--h-range: the admissible part of {fmt(lo, PLAIN)} .. {fmt(hi, PLAIN)} J is"
            f" {fmt(width, CELL)} J wide, under {fmt(MIN_RANGE_OVER_SPREAD, CELL)} of the"
            f" spread of the critical energies ({fmt(spread, CELL)} J): too narrow to resolve"
        )


def check_energy_in_scale(name: str, h: float, h_min: float, spread: float) -> None:
    """Refuse an energy ``h`` more than :data:`MAX_RANGE_OVER_SPREAD` spreads of the critical
    energies above the least energy ``h_min`` (the diagram's structure is lost at that scale,
    and the motion is so fast there that a count by the flow would not end)."""
    if h - h_min > MAX_RANGE_OVER_SPREAD * spread:
        raise InputError(
            f"{name}: energy {fmt(h, PLAIN)} J is over {fmt(MAX_RANGE_OVER_SPREAD, CELL)} times"
            f" the spread of the critical energies ({fmt(spread, CELL)} J) above the least"
            f" energy {fmt(h_min, CELL)} J: the diagram's structure is not resolved there;"
            f" give energies up to {fmt(h_min + MAX_RANGE_OVER_SPREAD * spread, CELL)} J"
        )


def check_tori_point(h: float, k: float) -> None:
    """``--tori H K``: two finite numbers."""
    if not (math.isfinite(h) and math.isfinite(k)):
        raise InputError(f"--tori: expected two finite numbers H K, got {h} {k}")


def check_regular_value(h: float, k: float, branch: str | None) -> None:
    """Refuse a critical value ``(h, k)``: on the named ``branch`` (None: a regular value)."""
    if branch is not None:
        raise InputError(
            f"--tori: (h, k) = ({fmt(h, PLAIN)}, {fmt(k, PLAIN)}) is a critical value, on the"
            f" {branch}: the level is not a union of tori"
        )


def refuse_unresolved_chamber(
    h: float, k: float, best: tuple[float, float], counts: Sequence[int], deltas: Sequence[float]
) -> NoReturn:
    """The chamber of ``(h, k)`` whose count no factor 2 of join distances supports, at its
    thickest point ``best``: the ``counts`` found at each join distance of ``deltas``."""
    pairs = zip(counts, deltas, strict=True)
    found = ", ".join(f"{c} at {fmt(d, CELL)}" for c, d in pairs)
    raise InputError(
        f"--tori: the chamber of ({fmt(h, PLAIN)}, {fmt(k, PLAIN)}) is not resolved: at its"
        f" thickest point ({fmt(best[0], CELL)}, {fmt(best[1], CELL)}) no count holds over a"
        " factor 2 of join distances with every sample covered"
        f" ({found or 'no sample found'})"
    )


def refuse_no_chamber(h: float, k: float) -> NoReturn:
    """A regular value inside the admissible region that no chamber holds (rounding at a wall)."""
    raise InputError(f"--tori: ({fmt(h, PLAIN)}, {fmt(k, PLAIN)}) lies in no chamber")
