"""Integral monitors: which quantities are integrals of a run, their values and drifts.

A monitor has a name, a function of the trajectory ``(omega, gamma) -> values`` and a rule
saying when the body's effects and parameters make it an integral (and why not, otherwise).
The summary reports the drift of every monitor the user asked for (``[simulation] monitors =
[...]`` or ``simulate(..., monitors=[...])``, names or Python callables) and of every monitor
that is an integral of the run; for the others it gives the reason it reports nothing.

Registry (:data:`MONITORS`):

``energy``
    ``1/2 omega . I omega + V`` (J); always an integral (static fields, Lorentz forces do no
    work). Drift relative to the largest kinetic energy.
``gamma_norm``
    ``|gamma|^2`` (1 by construction from the quaternion).
``I3``
    ``(I omega) . gamma + L(gamma)`` (J s), the momentum about the fields' axis; always an
    integral (axisymmetric fields). Drift absolute (J s).
``I4``
    The theorem's quartic integral with the body's parameters; an integral on ``I3 = 0`` for
    the theorem's reduced model or a body that realises mu, V and inertia.
``kowalevski``
    ``|(p + i q)^2 - (a1 + i a2)(gamma1 + i gamma2) / C|^2`` for ``V = a1 gamma1 + a2 gamma2``
    (a centre of the linear potential in the equator), no gyroscopic terms, inertia
    diag(2C, 2C, C): Kowalevski's case.
``lagrange``
    ``r`` (1/s) when A = B, V depends on gamma3 only and no gyroscopic term acts (Lagrange's
    top).
``F``
    The claimed integral of the case of (ep) a design realises (design.json ``case``) or a
    case scene's reduced model, evaluated from the case's parsed expressions; an integral of
    the case's motion (on the case's level for a conditional claim).
``goriachev_chaplygin``
    Needs A = B = 4C: reported as not an integral (a case of that inertia monitors its F).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from chargedesign.formatting import PLAIN, fmt
from chargedesign.scene.simulation import parse_monitors as parse_monitors
from chargedesign.validation import input_error

#: relative size below which a polynomial coefficient counts as zero
_ZERO = 1e-12


@dataclass(frozen=True)
class Context:
    """What decides whether a monitor is an integral of a run.

    Attributes
    ----------
    system : RigidBodySystem
    level : float or None
        ``I3(0)`` when the run starts on a level given by the user, else None.
    I3_start : float
        ``I3`` at the first sample (J s).
    realises : tuple of str
        What the simulated design claims (``mu``, ``V``, ``inertia``); empty for none.
    axes_rate : float
        Rate (1/s) of the axes the states are read in (0: inertial; a frame body's n:
        turning axes, where the integrals are the theorem's with that n).
    """

    system: Any
    level: float | None
    I3_start: float
    I3_scale: float
    realises: tuple[str, ...] = ()
    axes_rate: float = 0.0
    #: the numeric functions of the case of (ep) the design realises (None: the theorem's)
    case: Any = None


@dataclass(frozen=True)
class Monitor:
    """One monitored quantity.

    Attributes
    ----------
    name : str
    unit : str
    description : str
    values : callable
        ``values(context, omega (T, 3), gamma (T, 3), integrals (T, 4)) -> ndarray (T,)``.
    integral : callable
        ``integral(context) -> (bool, reason)``: whether the quantity is an integral here.
    scale : str
        ``relative`` (to ``|X(0)|``), ``kinetic`` (to the largest kinetic energy),
        ``absolute``.
    """

    name: str
    unit: str
    description: str
    values: Callable[..., np.ndarray]
    integral: Callable[[Context], tuple[bool, str]]
    scale: str = "relative"


def _linear_potential(system: Any) -> tuple[np.ndarray, str] | None:
    """``a`` with ``V = a . gamma`` (+ const) and no gyroscopic term, else None and why."""
    if "theorem" in system.effects:
        return None
    if not system.physical:
        return np.zeros(3), ""
    bank = system.polynomial_bank
    coef = bank.coefficients
    exps = bank.exponents
    degree = exps.sum(axis=1)
    scale = float(np.max(np.abs(coef[:, 0]))) or 1.0
    if np.any(np.abs(coef[degree > 1, 0]) > _ZERO * scale):
        return None
    mu_scale = float(np.max(np.abs(coef[:, 4:7]))) if coef.shape[1] > 6 else 0.0
    if mu_scale > _ZERO * max(scale, 1.0):
        return None
    a = np.zeros(3)
    for row, e in zip(coef, exps, strict=True):
        if int(e.sum()) == 1:
            a[int(np.argmax(e))] = row[0]
    return a, ""


def _always(_: Context) -> tuple[bool, str]:
    return True, ""


def _i4_integral(ctx: Context) -> tuple[bool, str]:
    system = ctx.system
    if system.case is not None and "theorem" in system.effects:
        return False, (
            f"I4 is the theorem's integral; this is the reduced model of the case "
            f"{system.case.case.name} (its own integral is F)"
        )
    if ctx.case is not None:
        return False, (
            f"I4 is the theorem's integral; this body realises the case {ctx.case.case.name}"
            " (its own integral is F)"
        )
    theorem_only = system.effects == ["theorem"]
    realised = {"mu", "V", "inertia"} <= set(ctx.realises) and "theorem" not in system.effects
    if not (theorem_only or realised):
        if "theorem" in system.effects:
            why = "the theorem effect acts together with physical effects"
        elif ctx.realises:
            missing = sorted({"mu", "V", "inertia"} - set(ctx.realises))
            why = f"the design does not realise {', '.join(missing) or 'the full set'}"
        else:
            why = "the body is not a design that realises the theorem's mu, V and inertia"
        return False, f"I4 is no integral: {why}"
    if abs(ctx.I3_start) > 1e-9 * ctx.I3_scale:
        return False, f"I4 is no integral off the level I3 = 0 (I3(0) = {fmt(ctx.I3_start)} J s)"
    return True, ""


def _turning(ctx: Context, name: str) -> tuple[bool, str] | None:
    """Not an integral in turning axes: the Coriolis term of the axes acts on the body."""
    if ctx.axes_rate == 0.0:
        return None
    return False, (
        f"{name} is no integral in axes turning at {fmt(ctx.axes_rate, PLAIN)} 1/s (their Coriolis"
        " and "
        "centrifugal terms act); simulate with axes = 'inertial'"
    )


def _kowalevski_integral(ctx: Context) -> tuple[bool, str]:
    turning = _turning(ctx, "Kowalevski's integral")
    if turning is not None:
        return turning
    A, B, C = ctx.system.inertia_diagonal()
    if not A == B == 2.0 * C:
        return False, "Kowalevski's integral needs the inertia diag(2C, 2C, C)"
    lin = _linear_potential(ctx.system)
    if lin is None:
        return False, (
            "Kowalevski's integral needs V linear in gamma and no gyroscopic terms "
            "(e.g. masses in uniform gravity only)"
        )
    a = lin[0]
    if abs(a[2]) > _ZERO * (float(np.max(np.abs(a))) or 1.0):
        return False, "Kowalevski's integral needs the centre of V in the equator (a3 = 0)"
    return True, ""


def _lagrange_integral(ctx: Context) -> tuple[bool, str]:
    turning = _turning(ctx, "Lagrange's integral r")
    if turning is not None:
        return turning
    system = ctx.system
    A, B, _ = system.inertia_diagonal()
    if A != B:
        return False, "Lagrange's integral r needs A = B"
    if "theorem" in system.effects:
        return False, "Lagrange's integral r needs V(gamma3) and no gyroscopic terms"
    if not system.physical:
        return True, ""
    bank = system.polynomial_bank
    coef = bank.coefficients
    exps = bank.exponents
    off_axis = (exps[:, 0] + exps[:, 1]) > 0
    scale = float(np.max(np.abs(coef[:, 0]))) or 1.0
    if np.any(np.abs(coef[off_axis, 0]) > _ZERO * scale) or np.any(
        np.abs(coef[:, 4:7]) > _ZERO * max(scale, 1.0)
    ):
        return False, "Lagrange's integral r needs V(gamma3) and no gyroscopic terms"
    return True, ""


def _kowalevski_values(ctx: Context, omega: np.ndarray, gamma: np.ndarray, _: Any) -> np.ndarray:
    lin = _linear_potential(ctx.system)
    a = lin[0] if lin is not None else np.zeros(3)
    C = ctx.system.C
    z = (omega[:, 0] + 1j * omega[:, 1]) ** 2
    w = (a[0] + 1j * a[1]) * (gamma[:, 0] + 1j * gamma[:, 1]) / C
    return np.abs(z - w) ** 2


def _case_integral(ctx: Context) -> tuple[bool, str]:
    """The claimed integral F of the design's case: an integral of the body's own motion
    (l = 0: masses in gravity), on the case's level when its claim is conditional."""
    if ctx.case is None:
        return False, "F is the integral of a case of (ep): the body is no case design"
    turning = _turning(ctx, "the case's integral F")
    if turning is not None:
        return turning
    system = ctx.system
    if "theorem" in system.effects and (system.case is None or system.physical):
        return False, "F is no integral when the theorem effect acts"
    level = ctx.case.case.level
    if level is not None and abs(ctx.I3_start - float(level)) > 1e-9 * ctx.I3_scale:
        return False, f"F is claimed on I3 = {level} only (I3(0) = {fmt(ctx.I3_start)} J s)"
    return True, ""


def _case_values(ctx: Context, omega: np.ndarray, gamma: np.ndarray, _: Any) -> np.ndarray:
    if ctx.case is None:
        return np.full(len(omega), np.nan)
    return np.asarray(ctx.case.integral(np.column_stack([omega, gamma])), dtype=float)


MONITORS: dict[str, Monitor] = {
    "energy": Monitor(
        "energy", "J", "1/2 omega . I omega + V", lambda c, o, g, i: i[:, 0], _always, "kinetic"
    ),
    "gamma_norm": Monitor(
        "gamma_norm", "", "|gamma|^2", lambda c, o, g, i: i[:, 1], _always, "relative"
    ),
    "I3": Monitor(
        "I3", "J s", "(I omega) . gamma + L(gamma)", lambda c, o, g, i: i[:, 2], _always, "absolute"
    ),
    "I4": Monitor(
        "I4", "1/s^4", "the theorem's quartic integral", lambda c, o, g, i: i[:, 3], _i4_integral
    ),
    "kowalevski": Monitor(
        "kowalevski",
        "1/s^4",
        "|(p + i q)^2 - (a1 + i a2)(gamma1 + i gamma2) / C|^2",
        _kowalevski_values,
        _kowalevski_integral,
    ),
    "lagrange": Monitor(
        "lagrange", "1/s", "r", lambda c, o, g, i: o[:, 2].copy(), _lagrange_integral, "relative"
    ),
    "F": Monitor(
        "F", "", "the claimed integral of the design's case of (ep)", _case_values, _case_integral
    ),
    "goriachev_chaplygin": Monitor(
        "goriachev_chaplygin",
        "",
        "needs A = B = 4C",
        lambda c, o, g, i: np.full(len(o), np.nan),
        lambda c: (
            False,
            "the Goriachev-Chaplygin case needs A = B = 4C; this body has A = B = 2C"
            if not c.system.general_inertia
            else "the Goriachev-Chaplygin case is a [case] of (ep): monitor its F",
        ),
    ),
}


def _drift(values: np.ndarray, scale: str, kinetic: float) -> float:
    d = float(np.max(np.abs(values - values[0])))
    if scale == "kinetic":
        return d / (kinetic if kinetic > 0.0 else 1.0)
    if scale == "relative":
        v0 = abs(float(values[0]))
        return d / (v0 if v0 > 0.0 else 1.0)
    return d


def evaluate(
    ctx: Context,
    omega: np.ndarray,
    gamma: np.ndarray,
    integrals: np.ndarray,
    kinetic: np.ndarray,
    requested: Sequence[Any] | None,
) -> dict[str, dict[str, Any]]:
    """Monitors of a run: ``{name: {"integral", "requested", "drift" | "reason", ...}}``.

    Every registry monitor appears: with ``drift`` when it is an integral or was requested,
    otherwise with ``drift`` None and the ``reason``. Callables appear under their
    ``__name__`` with their drift relative to ``|X(0)|``.
    """
    asked = list(requested or [])
    kin = float(np.max(kinetic)) if len(kinetic) else 0.0
    out: dict[str, dict[str, Any]] = {}
    for name, mon in MONITORS.items():
        is_integral, reason = mon.integral(ctx)
        entry: dict[str, Any] = {"integral": is_integral, "requested": name in asked}
        if is_integral or name in asked:
            values = mon.values(ctx, omega, gamma, integrals)
            if np.all(np.isfinite(values)):
                entry["drift"] = _drift(values, mon.scale, kin)
                entry["initial"] = float(values[0])
                entry["scale"] = mon.scale
            else:
                entry["drift"] = None
        else:
            entry["drift"] = None
        if reason:
            entry["reason"] = reason
        out[name] = entry
    for item in asked:
        if callable(item):
            name = getattr(item, "__name__", "callable")
            values = np.asarray(item(omega, gamma), dtype=float).reshape(-1)
            if values.shape != (len(omega),):
                raise input_error(
                    f"monitors.{name}", f"an array of {len(omega)} values", values.shape
                )
            out[name] = {
                "integral": None,
                "requested": True,
                "drift": _drift(values, "relative", kin),
                "initial": float(values[0]),
                "scale": "relative",
            }
    return out
