"""The realised window: the rates at which every parasitic is below a fraction of each term.

Time rescaling (``n, K -> s n, s K``; ``kappa, lambda, rho -> s^2 (...)``) is the same motion ``s``
times faster. A body designed at a rate ``s_ref`` tells how each parasitic and each designed term
grows with ``x = s / s_ref``, exactly for a body of the same parts (carriers and ballast of the
same volume, charges ``~ x``, magnets' moments and volumes ``~ x^2``, the same field):

==========================  =================================================  ===============
item                        parasitic                                          over the terms
==========================  =================================================  ===============
each realised term of V, mu  range over orientations (V), ``|omega| |mu|``      ``x^2``
induced magnetisation        range of ``-sum chi v |B|^2 / 2 mu0``: magnets      per set: ``x^0``
                             ``x^2``, other parts ``x^0``                        or ``x^-2``
eddy currents                ``(2 pi/15) sigma omega |L|^2 a^5``: ``x`` times    ``x^(7/3)``,
                             ``a^5``, magnets' ``a^5 ~ x^(10/3)``                ``x^-1``
gravity on the balance       ``M g delta`` (``delta`` = 0.1 um, sourced)         ``x^-2``
drag in the medium           ``8 pi mu R^3 omega``                               ``x^-1``
radiation                    Larmor power over ``omega``: ``q^2 omega^3``        ``x^3``
self-field                   ``mu0 q omega / 4 pi r`` over the applied ``|B|``    ``x^2``
relativistic                 ``(v / c)^2``                                       ``x^2``
coils' harmonics             the magnets' energy in the coils' degree >= 3      ``x^0``
                             terms (charges: the field's relative error)
==========================  =================================================  ===============

"The terms" are the rows of the realisability map
(:func:`chargedesign.physical.realism.realisability_map`) that this body's parts realise: each
must be ``1 / fraction`` times the parasitic (a small term swamped by a parasitic is not
realised however large the others are), so each parasitic is compared with the smallest.

:func:`window_model` builds these laws from one body; :func:`solve_window` finds the interval
of rates in ``[s_floor, s_ceiling]`` where every item is below the fraction (each item is a sum
of powers of ``x``, convex in ``log x``, so its admissible rates are one interval) and what
binds at each end. The designer confirms the window with bodies designed at its ends
(:mod:`chargedesign.designer.frontier`).
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from chargedesign.constants import STANDARD_GRAVITY
from chargedesign.fields import AxisymmetricField, zonal_block, zonal_first_from_terms, zonal_sums
from chargedesign.formatting import CELL, PLAIN, ROUGH, fmt
from chargedesign.physical.coils import COIL_RADII, HARMONIC_SHARE, Apparatus, apparatus_at
from chargedesign.physical.drag import cup_drag
from chargedesign.physical.field_bounds import field_magnitude_max
from chargedesign.physical.materials import BUILDER_BALANCE_M
from chargedesign.physical.parasitics import (
    FACTOR_CACHE_SIZE,
    RESPONSE_ORIENTATIONS,
    array_key,
    balance_torque,
    eddy_torques_by_set,
    holder_eddy_torque,
    induced_energies_by_set,
    laminar_drag,
    larmor_power,
    reynolds,
    self_field,
    speed_over_c,
)
from chargedesign.physical.realism import (
    material_parts,
    model_scales,
    realisability_map,
    region_radius,
)
from chargedesign.physical.state_of_the_art import BEARINGS
from chargedesign.results import Result
from chargedesign.sampling import fibonacci_sphere
from chargedesign.scene.design_realism import parasitic_text
from chargedesign.scene.keys import KEY, declared, default_of

#: the default fraction of each designed term every parasitic must stay below
REALISED_FRACTION = 1e-3
#: the growth of a magnet's ``a^5`` with its moment ``~ x^2``: volume ``~ x^2``, so ``x^(10/3)``
MAGNET_RADIUS5_EXPONENT = 10.0 / 3.0
#: grid of rates (in log s) on which the window's ends are bracketed before bisection
GRID_POINTS = 801
#: how far below the ceiling the window is looked for, when no lower limit is known
FLOOR_SPAN = 1e12
#: the support: the theorem's motion turns the body every way about O, so only a bearing with
#: every attitude free holds it (state_of_the_art.BEARINGS: the testbed's full sphere)
SUPPORT_BEARING = "full_sphere"


@dataclass
class Parasitic:
    """One item of the window: its ratio to the smallest realised term as a function of
    ``x = s / s_ref`` (``ratio(x)``, vectorised) and the law, in words."""

    key: str
    label: str
    law: str
    ratio: Any

    def at(self, x: float) -> float:
        return float(np.asarray(self.ratio(np.array([x])))[0])


@dataclass
class WindowModel:
    """The window's items built from one body designed at ``s_ref``."""

    s_ref: float
    fraction: float
    term_key: str
    term_size: float
    items: list[Parasitic]
    apparatus: Apparatus | None
    gravity: float
    notes: list[str] = field(default_factory=list)
    #: the fixed point O (:func:`support_of`), None when not estimated
    support: dict[str, Any] | None = None

    def ratios(self, s: float) -> dict[str, float]:
        """Every item's ratio to the smallest realised term at rate ``s``."""
        return {p.key: p.at(s / self.s_ref) for p in self.items}


def _smallest_term(design: Any) -> tuple[str, float]:
    """The realised term of V or mu with the smallest size (N m): the one a parasitic swamps
    first. Terms the turning axes realise (frame reading) need no parts and are not counted."""
    rows = [
        r
        for r in realisability_map(design)
        if r["frontier_size_N_m"] is not None and math.isfinite(r["size_N_m"]) and r["size_N_m"] > 0
    ]
    if not rows:
        scales = model_scales(design)
        if scales.terms:  # a general case: its own smallest realised term
            key = min(scales.terms, key=scales.terms.__getitem__)
            return key, scales.terms[key]
        return "typical", scales.torque
    row = min(rows, key=lambda r: r["size_N_m"])
    return row["key"], float(row["size_N_m"])


def _set_exponents(parts: list[dict[str, Any]], magnet: float, other: float) -> np.ndarray:
    return np.array([magnet if p["role"] == "magnet" else other for p in parts])


def _induced_item(design: Any, parts: list[dict[str, Any]], legendre, term: float) -> Parasitic:
    energies = induced_energies_by_set(legendre, parts)  # (sets, orientations)
    power = _set_exponents(parts, 2.0, 0.0)

    def ratio(x: np.ndarray) -> np.ndarray:
        x = np.asarray(x, dtype=float)
        scaled = np.einsum("sk,ms->mk", energies, x[:, None] ** power[None, :])
        return np.ptp(scaled, axis=1) / (term * x**2)

    return Parasitic(
        "induced",
        "induced magnetisation",
        "range of -chi v |B|^2 / 2 mu0 over orientations: the magnets' ~ s^2 like the terms, "
        "the other parts' fixed (over the terms ~ 1/s^2)",
        ratio,
    )


def _eddy_item(design: Any, parts: list[dict[str, Any]], legendre, term: float) -> Parasitic:
    rate = model_scales(design).rate
    torques = eddy_torques_by_set(legendre, parts, rate)
    holder = holder_eddy_torque(legendre, getattr(design, "holder", None), rate)
    power = _set_exponents(parts, 1.0 + MAGNET_RADIUS5_EXPONENT, 1.0)

    def ratio(x: np.ndarray) -> np.ndarray:
        x = np.asarray(x, dtype=float)
        return ((x[:, None] ** power[None, :]) @ torques + x * holder) / (term * x**2)

    return Parasitic(
        "eddy",
        "eddy currents",
        "(2 pi / 15) sigma |omega| max|L|^2 a^5 (dB/dt = L omega: the rotation in B and the "
        "motion through the gradient): ~ s for fixed parts, s^(13/3) for the magnets",
        ratio,
    )


def _power_item(key: str, label: str, law: str, value: float, exponent: float) -> Parasitic:
    def ratio(x: np.ndarray) -> np.ndarray:
        return value * np.asarray(x, dtype=float) ** exponent

    return Parasitic(key, label, law, ratio)


def _charge_items(design: Any, term: float, applied: float) -> list[Parasitic]:
    """Radiation, self-field and v/c of the charges (none without charges)."""
    q = np.asarray(design.charge_values, dtype=float)
    rate = model_scales(design).rate
    positions, _ = design.all_masses()
    r_max = float(np.max(np.linalg.norm(positions, axis=1), initial=0.0))
    items = [
        _power_item(
            "relativistic",
            "relativistic corrections",
            "(v / c)^2 of the fastest part, ~ s^2",
            speed_over_c(rate, r_max) ** 2,
            2.0,
        )
    ]
    if not len(q):
        return items
    radii = np.linalg.norm(design.charge_positions, axis=1)
    power = larmor_power(q, radii, rate)
    items.append(
        _power_item(
            "radiation",
            "radiation",
            "Larmor power of the charges over |omega|: q^2 omega^3 ~ s^5 (over the terms s^3)",
            power / rate / term,
            3.0,
        )
    )
    if applied > 0:
        b_self = self_field(q, radii, rate)
        items.append(
            _power_item(
                "self_field",
                "self-field",
                "the moving charges' field mu0 q omega / (4 pi r) over the applied |B|: ~ s^2",
                b_self / applied,
                2.0,
            )
        )
    return items


def turned_about_axis(gammas: np.ndarray, axis: int, angle: float) -> np.ndarray:
    """``gammas`` (n, 3) turned by ``angle`` about body axis ``axis`` (unit vectors stay unit)."""
    i, j = [k for k in range(3) if k != axis]
    out = gammas.copy()
    c, s = math.cos(angle), math.sin(angle)
    out[:, i] = c * gammas[:, i] - s * gammas[:, j]
    out[:, j] = s * gammas[:, i] + c * gammas[:, j]
    return out


#: angle of the central differences of the magnets' energy over orientations, rad
TORQUE_STEP = 1e-4


def _magnets_error(
    positions_bytes: bytes, moments_bytes: bytes, apparatus: Apparatus, term: float
) -> float:
    """Largest torque over orientations of the magnets (positions, moments as float64 bytes;
    empty: none) in the coils' degree >= 3 terms (energy ``m . grad Phi_error``,
    differentiated by turning gamma), over the smallest realised term (its range; the largest
    torque of a degree-2 term of V is its range)."""
    if not moments_bytes:
        return 0.0
    return magnets_torque(apparatus.error_legendre, positions_bytes, moments_bytes) / term


#: magnets per block of the (orientations, magnets) arrays of :func:`magnets_torque`
MAGNETS_BLOCK = 256
#: largest memory of a body's recorded zonal terms (:func:`torque_terms`), bytes; beyond it
#: each field runs the recurrence itself
TORQUE_TERMS_BYTES = 1 << 27


def _turns() -> list[np.ndarray]:
    """The orientations the torque's central differences turn to: about each body axis by
    -+ :data:`TORQUE_STEP` (in the order of the slopes: axis 0 +, axis 0 -, axis 1 + ...)."""
    gammas = fibonacci_sphere(RESPONSE_ORIENTATIONS)
    return [
        turned_about_axis(gammas, k, sign * TORQUE_STEP) for k in range(3) for sign in (1.0, -1.0)
    ]


@functools.lru_cache(maxsize=1)  # the body whose coil sizes are being tried
def torque_terms(positions_bytes: bytes, moments_bytes: bytes, degrees: int):
    """A body's magnets at every turned orientation, the field-free part of their energy:
    per turn and block of magnets ``(Z, g . m, r . m, terms)`` with ``terms`` the zonal
    recurrence's terms (:func:`chargedesign.fields.zonal_first_from_terms`) to ``degrees``.
    The coils' sizes tried for one body (:func:`_coil_item`) share them."""
    positions = np.frombuffer(positions_bytes).reshape(-1, 3)
    moments = np.frombuffer(moments_bytes).reshape(-1, 3)
    zero = np.zeros(degrees)
    out = []
    for g in _turns():
        blocks = []
        for start in range(0, len(positions), MAGNETS_BLOCK):
            r = positions[start : start + MAGNETS_BLOCK]
            m = moments[start : start + MAGNETS_BLOCK]
            s = np.einsum("ij,ij->i", r, r)
            Z = g @ r.T
            terms: list[tuple[np.ndarray, np.ndarray]] = []
            zonal_block(zero, Z, s, 1, False, record=terms)
            blocks.append((Z, g @ m.T, np.einsum("ij,ij->i", r, m), terms))
        out.append(blocks)
    return out


@functools.lru_cache(maxsize=FACTOR_CACHE_SIZE)
def magnets_torque(legendre: tuple[float, ...], positions_bytes: bytes, moments_bytes: bytes):
    """The largest torque over orientations of magnets (positions, moments as float64 bytes)
    in the field ``legendre``, N m: central differences of their energy ``m . grad Phi`` over
    turns of gamma by :data:`TORQUE_STEP` about each body axis. Rate-free for the field and
    the parts: computed once per body and coil size (the window at a body's own rate and the
    verdict's check ask for the same). The zonal recurrence at the turned orientations does
    not depend on the field: it runs once per body (:func:`torque_terms`) when its terms fit
    in :data:`TORQUE_TERMS_BYTES`, with the same sums (the same bits) as
    :func:`magnets_torque_direct`."""
    error = AxisymmetricField(legendre)
    coeffs = np.asarray(error.legendre[: error.degree], dtype=np.float64)
    n_magnets = len(positions_bytes) // 24
    size = 6 * RESPONSE_ORIENTATIONS * n_magnets * 2 * len(legendre) * 8
    if size > TORQUE_TERMS_BYTES:
        return magnets_torque_direct(coeffs, positions_bytes, moments_bytes)
    turns = torque_terms(positions_bytes, moments_bytes, len(legendre))

    def energy(blocks) -> np.ndarray:
        out = np.zeros(RESPONSE_ORIENTATIONS)
        for Z, gm, rm, terms in blocks:
            d = zonal_first_from_terms(coeffs, Z, terms)
            out += np.einsum("nk,nk->n", d["Z"], gm)
            out += (2.0 * d["S"]) @ rm
        return out

    slopes = [
        (energy(turns[2 * k]) - energy(turns[2 * k + 1])) / (2 * TORQUE_STEP) for k in range(3)
    ]
    return float(np.max(np.linalg.norm(slopes, axis=0)))


def magnets_torque_direct(coeffs: np.ndarray, positions_bytes: bytes, moments_bytes: bytes):
    """:func:`magnets_torque` with the recurrence run for this field (``coeffs``)."""
    positions = np.frombuffer(positions_bytes).reshape(-1, 3)
    moments = np.frombuffer(moments_bytes).reshape(-1, 3)
    gammas = fibonacci_sphere(RESPONSE_ORIENTATIONS)

    def energy(g: np.ndarray) -> np.ndarray:
        # -m . B with B = -grad Phi = -(Phi_Z gamma + 2 Phi_S r) in body axes
        out = np.zeros(len(g))
        for start in range(0, len(positions), MAGNETS_BLOCK):
            r = positions[start : start + MAGNETS_BLOCK]
            m = moments[start : start + MAGNETS_BLOCK]
            s = np.einsum("ij,ij->i", r, r)
            d = zonal_sums(coeffs, g @ r.T, s, 1, want_value=False)
            out += np.einsum("nk,nk->n", d["Z"], g @ m.T)
            out += (2.0 * d["S"]) @ np.einsum("ij,ij->i", r, m)
        return out

    slopes = [
        (
            energy(turned_about_axis(gammas, k, TORQUE_STEP))
            - energy(turned_about_axis(gammas, k, -TORQUE_STEP))
        )
        / (2 * TORQUE_STEP)
        for k in range(3)
    ]
    return float(np.max(np.linalg.norm(slopes, axis=0)))


def _coil_item(design: Any, legendre, region: float, term: float, fraction: float):
    """The coil pairs' harmonic error acting on the magnets (element by element) and, with
    charges, the field's relative error over the region (their mu terms err by as much).
    The coils are the smallest of :data:`~chargedesign.physical.coils.COIL_RADII` that keep
    it below HARMONIC_SHARE of the fraction."""
    a1 = legendre[0] if legendre else 0.0
    a2 = legendre[1] / 2.0 if len(legendre) > 1 else 0.0
    if a1 == 0.0 and a2 == 0.0:
        return None, None
    moments = np.asarray(design.dipole_moments, dtype=float)
    value, apparatus = coil_search(
        a1,
        a2,
        region,
        term,
        HARMONIC_SHARE * fraction,
        array_key(design.dipole_positions, 3) if len(moments) else b"",
        array_key(moments, 3) if len(moments) else b"",
        bool(len(design.charge_values)),
    )
    item = _power_item(
        "coil_harmonics",
        "coils' harmonic error",
        "the coil pairs' degree >= 3 terms: their largest torque on the magnets (and the "
        "field's relative error for charges), like the terms ~ s^2",
        value,
        0.0,
    )
    # the cached apparatus stays as found: each window gets its own lists
    return item, replace(apparatus, pairs=list(apparatus.pairs), notes=list(apparatus.notes))


@functools.lru_cache(maxsize=FACTOR_CACHE_SIZE)
def coil_search(
    a1: float,
    a2: float,
    region: float,
    term: float,
    wanted: float,
    positions_bytes: bytes,
    moments_bytes: bytes,
    charged: bool,
) -> tuple[float, Apparatus]:
    """The coil search of :func:`_coil_item` on hashable content (the magnets as float64
    bytes, empty without magnets): the harmonic error of the first coil size that meets
    ``wanted`` (the largest tried when none does) and its apparatus. Every stage that builds
    one body's window (its budget, map, verdict, record) asks for the same, so the sizes are
    tried once per body (each try is two field bounds and a torque over 2000 orientations)."""
    apparatus, value = None, math.inf
    for factor in COIL_RADII:
        apparatus = apparatus_at(a1, a2, factor * region, region, wanted)
        value = _magnets_error(positions_bytes, moments_bytes, apparatus, term)
        if charged:
            value = max(value, apparatus.harmonic_error)
        if value < wanted:
            break
    assert apparatus is not None
    return value, apparatus


def support_of(region: float, rate: float, term: float) -> dict[str, Any]:
    """The fixed point O the motion needs, as the testbed builds it: a full-sphere air bearing
    (the body inside a ball of the body region's radius floating in a cup), and its cup's
    air-film drag ``b |omega|`` (``b`` the testbed's Couette film, ``physical.drag.
    cup_drag``, at its default film) at the typical rate, over the smallest realised term.
    Stated beside the window, not one of its items (``in_window`` False): the drag falls
    like ``1/s`` over the terms and, for the bodies the search finds, sits far above the
    fraction at every rate below the frontier.
    """
    gap = default_of("testbed", KEY.bearing_gap_m)
    drag = cup_drag(region, gap)
    style = BEARINGS[SUPPORT_BEARING]
    return {
        "bearing": SUPPORT_BEARING,
        KEY.tilt_limit_deg: style.tilt_limit_deg,
        "load_kg": style.load_kg,
        "source": style.source,
        "ball_radius_m": region,
        "film_gap_m": gap,
        KEY.drag_N_m_s: drag,
        "drag_source": declared("testbed", KEY.drag_N_m_s).source
        + "; the film: "
        + declared("testbed", KEY.bearing_gap_m).source,
        "drag_torque_N_m": drag * rate,
        "drag_over_term": drag * rate / term,
        "needs": "a gas at the film (an air bearing does not run in vacuum)",
        "in_window": False,
    }


@dataclass(frozen=True)
class BearingSupport:
    """The support :func:`support_of` writes (design.json's ``window_at_design.support``),
    read back for the report: its bearing, its air film's drag and the sources they cite."""

    bearing: str
    tilt_limit_deg: float
    ball_radius_m: float
    film_gap_m: float
    drag_N_m_s: float
    drag_torque_N_m: float
    drag_over_term: float
    needs: str
    #: the bearing's and the drag's sources ("" when not written)
    source: str
    drag_source: str

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> BearingSupport:
        return cls(
            bearing=data["bearing"],
            tilt_limit_deg=data[KEY.tilt_limit_deg],
            ball_radius_m=data["ball_radius_m"],
            film_gap_m=data["film_gap_m"],
            drag_N_m_s=data[KEY.drag_N_m_s],
            drag_torque_N_m=data["drag_torque_N_m"],
            drag_over_term=data["drag_over_term"],
            needs=data["needs"],
            source=data.get("source") or "",
            drag_source=data.get("drag_source") or "",
        )


def window_model(
    design: Any,
    s_ref: float,
    *,
    fraction: float = REALISED_FRACTION,
    gravity: float = STANDARD_GRAVITY,
) -> WindowModel:
    """The window's items, from ``design`` (the body designed at rate ``s_ref``).

    Parameters
    ----------
    design : Design
        A physical body (``medium`` and ``materials``).
    s_ref : float
        Its time rate (the scene's rates times ``s_ref``).
    fraction : float
        Each parasitic must stay below this fraction of every realised term.
    gravity : float
        The gravity its balance acts in, m/s^2 (1 g: a lab on Earth; 0: free fall).
    """
    legendre = tuple(design.field("magnetic"))
    key, term = _smallest_term(design)
    parts = material_parts(design)
    _, masses = design.all_masses()
    region = region_radius(design)
    rate = model_scales(design).rate
    items: list[Parasitic] = []
    if legendre:
        items += [
            _induced_item(design, parts, legendre, term),
            _eddy_item(design, parts, legendre, term),
        ]
    if gravity > 0:
        items.append(
            _power_item(
                "gravity",
                f"gravity on the balance ({fmt(gravity / STANDARD_GRAVITY, ROUGH)} g, "
                f"{fmt(BUILDER_BALANCE_M, PLAIN)} m)",
                "M g delta with the builder's balance delta: fixed (over the terms ~ 1/s^2)",
                balance_torque(float(np.sum(masses)), gravity) / term,
                -2.0,
            )
        )
    gas = design.medium.gas_properties if design.medium is not None else None
    notes = []
    if gas is not None and gas[1] > 0:
        drag = laminar_drag(gas[1], region, rate)
        re = reynolds(gas[0], gas[1], region, rate)
        if re > 1.0:
            notes.append(
                f"drag: the laminar estimate 8 pi mu R^3 omega holds for Re << 1; here Re = "
                f"{fmt(re, ROUGH)}, where it is a lower bound"
            )
        items.append(
            _power_item(
                "drag",
                f"drag in {design.medium.name}",
                "8 pi mu R^3 |omega| (laminar): ~ s (over the terms ~ 1/s)",
                drag / term,
                -1.0,
            )
        )
    applied = float(field_magnitude_max(legendre, np.array([region]))[0]) if legendre else 0.0
    items += _charge_items(design, term, applied)
    coil, apparatus = _coil_item(design, legendre, region, term, fraction)
    if coil is not None:
        items.append(coil)
    if gas is None and design.medium is not None:
        notes.append(f"drag not estimated: medium {design.medium.name!r} names no gas")
    # recorded, not yet an item: counted, it empties the K = 0 example's window (its film's
    # drag is 3e2 x the fraction at the design's rate); the choice of support is open
    support = support_of(region, rate, term)
    return WindowModel(s_ref, fraction, key, term, items, apparatus, gravity, notes, support)


@dataclass(repr=False)
class RealisedWindow(Result):
    """The rates ``[s_low, s_high]`` (multiples of the scene's rates, like ``s_max``) at which
    the design is accepted and every parasitic is below ``fraction`` of each realised term.

    ``binding_low`` / ``binding_high``: what ends the window below and above (for an empty
    window: the parasitic that dominates at the best rate, and the upper limit);
    ``missing``: for an empty window, the factor by which the best rate misses the fraction
    (its worst ratio over the fraction); ``margins``: each item's ratio over the fraction at
    the window's geometric middle (the best rate when empty); ``confirmed``: the bodies
    designed at rates of the window and what their parts measure.
    """

    s_low: float | None
    s_high: float | None
    binding_low: str
    binding_high: str
    fraction: float
    s_best: float
    missing: float
    term_key: str
    margins: dict[str, float]
    laws: dict[str, str]
    confirmed: list[dict[str, Any]] = field(default_factory=list)
    apparatus: dict[str, Any] | None = None
    notes: list[str] = field(default_factory=list)
    why: str = ""
    #: the support of the body at s_max (:func:`support_of`; ``design`` writes its own body's)
    support: dict[str, Any] | None = None
    #: each parasitic over the fraction for the body designed at the scene's own rate (s = 1;
    #: written by ``design``, whose ``apparatus`` is then that body's too)
    at_design: dict[str, float] | None = None
    #: the laws on the grid of rates: ``{"s": rates, label: ratio over the fraction, ...}``
    #: (for the picture; not in ``to_dict``)
    curves: dict[str, np.ndarray] = field(default_factory=dict)
    #: the laws of the body designed and accepted last at each end (``"low"``, ``"high"``: a
    #: :class:`WindowModel`), the laws that end was solved from (for the picture; not in
    #: ``to_dict``)
    end_laws: dict[str, Any] = field(default_factory=dict)

    @property
    def empty(self) -> bool:
        return self.s_low is None

    def set_end(self, low: bool, rate: float, binding: str) -> None:
        """Move the low (``low``) or high end of the window to ``rate``, bound by ``binding``."""
        if low:
            self.s_low, self.binding_low = rate, binding
        else:
            self.s_high, self.binding_high = rate, binding

    @property
    def width(self) -> float:
        """``s_high / s_low`` (0 when empty)."""
        if self.s_low is None or self.s_high is None:
            return 0.0
        return self.s_high / self.s_low

    def to_dict(self) -> dict[str, Any]:
        return {
            "s_low": self.s_low,
            "s_high": self.s_high,
            "binding_low": self.binding_low,
            "binding_high": self.binding_high,
            "empty": self.empty,
            "fraction": self.fraction,
            "s_best": self.s_best,
            "missing_factor": (
                self.missing if self.empty and math.isfinite(self.missing) else None
            ),
            "smallest_term": self.term_key,
            "margins": dict(self.margins),
            "laws": dict(self.laws),
            "confirmed": list(self.confirmed),
            "apparatus": self.apparatus,
            "support": self.support,
            "notes": list(self.notes),
            "why": self.why,
            **({"at_design": dict(self.at_design)} if self.at_design is not None else {}),
        }

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> RealisedWindow:
        """A window as :meth:`to_dict` (design.json's ``frontier.realised``) or a ``[case]``
        record (its ends, bindings, fraction and notes) writes it.

        What is not recorded stays empty (the curves, the end laws; a case's margins and
        laws); a missing factor written as null (not empty, or unbounded) is read as infinite,
        a best rate not recorded as NaN."""
        missing, best = data.get("missing_factor"), data.get("s_best")
        return cls(
            s_low=data.get("s_low"),
            s_high=data.get("s_high"),
            binding_low=data.get("binding_low", ""),
            binding_high=data.get("binding_high", ""),
            fraction=data["fraction"],
            s_best=math.nan if best is None else best,
            missing=math.inf if missing is None else missing,
            term_key=data.get("smallest_term") or "",
            margins=dict(data.get("margins") or {}),
            laws=dict(data.get("laws") or {}),
            confirmed=list(data.get("confirmed") or []),
            apparatus=data.get("apparatus"),
            notes=list(data.get("notes") or []),
            why=data.get("why") or "",
            support=data.get("support"),
            at_design=data.get("at_design"),
        )

    def _summary(self) -> dict[str, Any]:
        return {"s_low": self.s_low, "s_high": self.s_high, "empty": self.empty}

    def _text(self) -> str:
        if self.empty:
            head = (
                f"realised window: EMPTY (every parasitic below {fmt(self.fraction, PLAIN)} of "
                f"each realised term at no rate): {self.why}\n"
            )
        else:
            head = (
                f"realised window: s = {fmt(self.s_low, CELL)} to {fmt(self.s_high, CELL)} "
                f"(x {fmt(self.width, ROUGH)}), every parasitic below "
                f"{fmt(self.fraction, PLAIN)} of each realised term\n"
                f"  low end: {self.binding_low}\n  high end: {self.binding_high}\n"
            )
        where = "the best rate" if self.empty else "the window's middle"
        # each parasitic's figure (of the smallest realised term, at the named rate), as the
        # verdict and the induced magnetisation's one figure state theirs; margins stay over
        # the fraction in to_dict
        margins = ", ".join(
            f"{k} {fmt(v * self.fraction, ROUGH)}"
            for k, v in sorted(self.margins.items(), key=lambda kv: -kv[1])
        )
        lines = [
            head,
            f"  parasitics of the smallest realised term ({self.term_key}) at {where} s = "
            f"{fmt(self.s_best, ROUGH)} (limit {fmt(self.fraction, PLAIN)}): {margins}\n",
        ]
        lines += [f"  note: {n}\n" for n in self.notes]
        if self.support:
            lines.append(
                f"  support (stated, not counted): {self.support['bearing']} air bearing, its "
                f"film's drag {parasitic_text(self.support['drag_over_term'], self.term_key, 1.0)} "
                f"(limit {fmt(self.fraction, PLAIN)}; the body the window was drawn from, at its "
                "own rate)\n"
            )
        for c in self.confirmed:
            lines.append(
                f"  designed at s = {fmt(c['s'], CELL)}: "
                + (
                    f"worst {c['worst']} "
                    f"{parasitic_text(c['measured'] * self.fraction, self.term_key, c['s'])} "
                    f"(law: {fmt(c['predicted'] * self.fraction, ROUGH)})"
                    if c.get("accepted")
                    else f"refused ({c.get('refused')})"
                )
                + "\n"
            )
        return "".join(lines)


def _max_ratio(model: WindowModel, s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The worst item's ratio over the fraction at each rate, and which item it is."""
    x = s / model.s_ref
    table = np.array([np.asarray(p.ratio(x), dtype=float) for p in model.items]).reshape(
        len(model.items), len(s)
    )
    table = table / model.fraction
    return table.max(axis=0), table.argmax(axis=0)


def _edge(model: WindowModel, inside: float, outside: float) -> float:
    """Bisection in log s between an admissible rate and an inadmissible one (rtol 1e-9)."""
    for _ in range(100):
        if abs(math.log(outside / inside)) < 1e-9:
            break
        mid = math.sqrt(inside * outside)
        if _max_ratio(model, np.array([mid]))[0][0] <= 1.0:
            inside = mid
        else:
            outside = mid
    return inside


def _item_text(model: WindowModel, index: int, s: float) -> str:
    item = model.items[index]
    ratio = item.at(s / model.s_ref)
    return f"{item.label} ({fmt(ratio, ROUGH)} of the {model.term_key} term; {item.law})"


def _curves(model: WindowModel, rates: np.ndarray) -> dict[str, np.ndarray]:
    out = {"s": rates}
    for item in model.items:
        out[item.label] = np.asarray(item.ratio(rates / model.s_ref), dtype=float) / model.fraction
    return out


def plot_window(window: RealisedWindow, s_max: float, ax: Any = None) -> Any:
    """Each parasitic over the fraction against the rate (log-log), the fraction at 1, the
    realised window shaded and ``s_max`` marked; returns the axes."""
    import matplotlib.pyplot as plt

    if ax is None:
        _, ax = plt.subplots(figsize=(7.5, 4.6))
    rates = window.curves.get("s")
    curves = []
    if rates is not None:
        for label, values in window.curves.items():
            if label != "s" and np.any(values > 0):
                curves += ax.plot(rates, np.where(values > 0, values, np.nan), label=label)
    ax.axhline(1.0, color="k", lw=1.0, ls="--", label=f"the fraction ({fmt(window.fraction)})")
    if s_max > 0:
        ax.axvline(s_max, color="0.4", lw=1.0, ls=":", label="s_max (the frontier)")
    if not window.empty:
        ax.axvspan(window.s_low, window.s_high, color="tab:green", alpha=0.15, label="realised")
    ax.set_xscale("log")
    ax.set_yscale("log")
    low = window.s_low if window.s_low is not None else window.s_best
    if rates is not None and low and s_max > 0:
        ax.set_xlim(max(float(rates[0]), min(low, s_max) / 1e3), s_max * 1.5)
    ax.set_ylim(bottom=max(ax.get_ylim()[0], 1e-12))
    ax.set_xlabel("time rate s (x the scene's rates)")
    ax.set_ylabel("parasitic / (fraction x smallest realised term)")
    ax.set_title(
        "realised window: "
        + ("EMPTY" if window.empty else f"x {fmt(window.width)}")
        + " (the laws of the body at s_max)"
    )
    # the legend names only the curves drawn inside the axes (one below the floor is not)
    (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()
    for line in curves:
        x, y = np.asarray(line.get_xdata(), float), np.asarray(line.get_ydata(), float)
        if not np.any((x >= x0) & (x <= x1) & (y >= y0) & (y <= y1)):
            line.set_label(f"_{line.get_label()}")  # matplotlib leaves "_" labels out
    ax.legend(fontsize=7, loc="best")
    return ax


def solve_window(
    model: WindowModel,
    s_floor: float,
    s_ceiling: float,
    *,
    floor_text: str,
    ceiling_text: str,
) -> RealisedWindow:
    """The window in ``[s_floor, s_ceiling]`` (the design's own limits, with what sets them).

    ``s_floor`` 0 means no lower limit is known: the rates down to ``s_ceiling / 1e12``.
    """
    top = s_ceiling
    bottom = s_floor if s_floor > 0 else s_ceiling / FLOOR_SPAN
    if not model.items:
        rates = np.array([bottom, top])
        worst, which = np.zeros(2), np.zeros(2, dtype=int)
    else:
        rates = np.geomspace(bottom, top, GRID_POINTS)
        worst, which = _max_ratio(model, rates)
    ok = worst <= 1.0
    best = int(np.argmin(worst))
    laws = {p.key: p.law for p in model.items}
    apparatus = model.apparatus.to_dict() if model.apparatus is not None else None
    if not np.any(ok):
        s_best = float(rates[best])
        margins = model.ratios(s_best)
        falling = int(which[best])
        return RealisedWindow(
            None,
            None,
            _item_text(model, falling, s_best) if model.items else floor_text,
            ceiling_text,
            model.fraction,
            s_best,
            float(worst[best]),
            model.term_key,
            {k: v / model.fraction for k, v in margins.items()},
            laws,
            apparatus=apparatus,
            support=model.support,
            notes=list(model.notes),
            curves=_curves(model, rates),
        )
    first = int(np.argmax(ok))
    last = len(ok) - 1 - int(np.argmax(ok[::-1]))
    if first == 0:
        s_low, low_text = float(rates[0]), floor_text
    else:
        s_low = _edge(model, float(rates[first]), float(rates[first - 1]))
        low_text = _item_text(model, int(which[first - 1]), float(rates[first - 1]))
    if last == len(ok) - 1:
        s_high, high_text = float(rates[-1]), ceiling_text
    else:
        s_high = _edge(model, float(rates[last]), float(rates[last + 1]))
        high_text = _item_text(model, int(which[last + 1]), float(rates[last + 1]))
    middle = math.sqrt(s_low * s_high)
    margins = {k: v / model.fraction for k, v in model.ratios(middle).items()}
    return RealisedWindow(
        s_low,
        s_high,
        low_text,
        high_text,
        model.fraction,
        middle,
        float(np.max(list(margins.values()), initial=0.0)),
        model.term_key,
        margins,
        laws,
        apparatus=apparatus,
        support=model.support,
        notes=list(model.notes),
        curves=_curves(model, rates),
    )


# --- a case of (ep) (the workbench) -----------------------------------------------------------


def case_window_model(
    design: Any,
    budget: dict[str, Any],
    *,
    fraction: float = REALISED_FRACTION,
) -> WindowModel:
    """The window's items for a case body of point elements, from its realism budget
    (:func:`chargedesign.physical.realism.case_realism_budget`, at the rate ``s = 1``).

    A case rescaled in time (``V -> s^2 V``, ``l -> s l``) keeps its motions ``s`` times
    faster; its elements follow with charges ``~ s`` (mu) and the fields and weights of V
    ``~ s^2``. The items then scale over the terms as in :func:`window_model`: radiation
    ``s^3``, self-field and ``(v / c)^2`` ``s^2``, gravity on the balance ``s^-2``. A case
    whose V is realised by masses in gravity cannot be rescaled (g is fixed): the caller
    keeps only ``s = 1`` (:func:`case_realised_window`).
    """
    exponents = {"radiation": 3.0, "self_field": 2.0, "relativistic": 2.0, "gravity_balance": -2.0}
    laws = {
        "radiation": "Larmor power of the charges over |omega|: over the terms ~ s^3",
        "self_field": "mu0 q omega / (4 pi r) over the applied |B|: ~ s^2",
        "relativistic": "(v / c)^2 of the fastest element: ~ s^2",
        "gravity_balance": "M g delta over the terms: ~ 1/s^2",
    }
    items = [
        _power_item(
            key, key.replace("_", " "), laws[key], float(item["value"] or 0.0), exponents[key]
        )
        for key, item in budget["items"].items()
        if item["value"]
    ]
    return WindowModel(
        1.0,
        fraction,
        str(budget["term_key"]),
        float(budget["term_N_m"]),
        items,
        None,
        STANDARD_GRAVITY,
    )


def case_realised_window(
    design: Any,
    budget: dict[str, Any],
    *,
    fraction: float = REALISED_FRACTION,
    span: float = 1e6,
) -> RealisedWindow:
    """The rates ``s`` (multiples of the budget's typical rate) in ``[1/span, span]`` where
    every item of :func:`case_window_model` is below ``fraction`` of the smallest term. With
    masses in a gravity field that realise V (``design.fields["gravity"]`` non-zero) the rate
    is fixed: the window is ``[1, 1]`` when every item is below the fraction there, else empty.
    """
    model = case_window_model(design, budget, fraction=fraction)
    gravity_fixed = any(design.field("gravity"))
    if gravity_fixed:
        window = solve_window(
            model, 1.0, 1.0, floor_text="the rate g fixes", ceiling_text="the rate g fixes"
        )
        window.notes.append(
            "V is realised by masses in gravity: g fixes the case's rate (s = 1 only)"
        )
        return window
    return solve_window(
        model,
        1.0 / span,
        span,
        floor_text=f"the searched range (s >= {1.0 / span:g})",
        ceiling_text=f"the searched range (s <= {span:g})",
    )
