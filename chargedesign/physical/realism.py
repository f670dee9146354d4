"""The realism budget: what the idealised theorem leaves out, for a designed body.

The theorem assumes rigid point charges whose only effect is the static Lorentz force in the
applied field. For a typical motion of the designed body this module estimates (numbers and
verdicts, never hidden):

- ``v/c`` of the fastest element (relativistic corrections ~ (v/c)^2);
- Larmor radiation of the charges (incoherent sum, an upper bound) against the kinetic
  energy: a damping time, in periods;
- the magnetic field the moving charges make at O against the applied field;
- the centre-of-mass offset whose gravity torque is 1e-3 of the designed torques, under 1 g
  and under 1e-6 g (how precisely the body must be balanced);
- the viscous drag torque of the medium on the body's enveloping sphere (laminar estimate,
  ``8 pi mu R^3 omega``) against the designed torques.

The typical motion: ``|omega| = 2 max(|n|, |K|, sqrt|kappa|, sqrt|lambda|, sqrt|rho|)``, the
rate the theorem's terms set; the designed torques: ``C omega^2 / 4``.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from chargedesign.physical.materials import EPSILON_0, GAS_PROPERTIES, LIGHT_SPEED, MU_0

G_EARTH = 9.80665
MICROGRAVITY = 1e-6 * G_EARTH
#: a torque this fraction of the designed torques is what "balanced" tolerates
BALANCE_FRACTION = 1e-3


def _verdict(value: float, negligible_below: float) -> str:
    return "negligible" if value < negligible_below else "NOT negligible"


def realism_budget(design: Any) -> dict[str, Any]:
    """The budget of :mod:`this module <chargedesign.physical.realism>` as a JSON-ready dict."""
    p = design.parameters
    rate = 2.0 * max(
        abs(p.n), abs(p.K), math.sqrt(abs(p.kappa)), math.sqrt(abs(p.lam)), math.sqrt(abs(p.rho))
    )
    if rate == 0:
        return {"note": "the theorem's terms vanish: no typical motion to estimate"}
    positions, masses = design.all_masses()
    radii = np.linalg.norm(design.charge_positions, axis=1)
    all_r = np.linalg.norm(positions, axis=1)
    r_max = float(np.max(all_r, initial=0.0))
    q = design.charge_values
    period = 2 * math.pi / rate
    kinetic = p.C * rate**2  # ~ (1/2) omega . I omega with I ~ 2C
    torque = p.C * rate**2 / 4.0
    v_over_c = rate * r_max / LIGHT_SPEED
    larmor = float(np.sum(q**2 * (rate**2 * radii) ** 2)) / (
        6 * math.pi * EPSILON_0 * LIGHT_SPEED**3
    )
    damping_time = kinetic / larmor if larmor > 0 else math.inf
    damping_periods = damping_time / period
    with np.errstate(divide="ignore"):
        b_self = (
            MU_0
            / (4 * math.pi)
            * float(np.sum(np.abs(q) * rate / np.where(radii > 0, radii, np.inf)))
        )
    applied = abs(design.field("magnetic")[0]) if design.field("magnetic") else 0.0
    total_mass = float(np.sum(masses))
    offset_1g = BALANCE_FRACTION * torque / (total_mass * G_EARTH) if total_mass > 0 else math.inf
    offset_micro = (
        BALANCE_FRACTION * torque / (total_mass * MICROGRAVITY) if total_mass > 0 else math.inf
    )
    medium = (design.medium or {}).get("name", "vacuum")
    rho_gas, viscosity = GAS_PROPERTIES.get(medium, (0.0, 0.0))
    envelope = float(design.extra.get("buildability", {}).get("region_radius_m", r_max))
    drag = 8 * math.pi * viscosity * envelope**3 * rate
    reynolds = rho_gas * rate * envelope**2 / viscosity if viscosity > 0 else 0.0

    def item(value: float, unit: str, verdict: str, note: str) -> dict[str, Any]:
        return {
            "value": value if math.isfinite(value) else None,
            "unit": unit,
            "verdict": verdict,
            "note": note,
        }

    return {
        "typical_rate_1_per_s": rate,
        "period_s": period,
        "designed_torque_N_m": torque,
        "v_over_c": item(
            v_over_c, "", _verdict(v_over_c, 1e-6), "fastest element at |omega| r_max"
        ),
        "radiation_damping_periods": item(
            damping_periods,
            "periods",
            "negligible" if damping_periods > 1e6 else "NOT negligible",
            "kinetic energy over the Larmor power of the charges (incoherent upper bound)",
        ),
        "self_field_fraction": item(
            b_self / applied if applied > 0 else math.inf,
            "",
            _verdict(b_self / applied if applied > 0 else math.inf, 1e-6),
            "field of the moving charges at O over the applied a1",
        ),
        "balance_offset_1g_m": item(
            offset_1g,
            "m",
            "achievable" if offset_1g > 1e-7 else "NOT achievable on Earth (below 0.1 um)",
            "centre-of-mass offset whose gravity torque is 1e-3 of the designed torques, 1 g",
        ),
        "balance_offset_microgravity_m": item(
            offset_micro,
            "m",
            "achievable" if offset_micro > 1e-7 else "NOT achievable (below 0.1 um)",
            "the same under 1e-6 g",
        ),
        "drag_torque_fraction": item(
            drag / torque,
            "",
            _verdict(drag / torque, 1e-3),
            f"laminar drag of {medium} on the enveloping sphere (Re = {reynolds:.3g}) over the "
            "designed torques",
        ),
    }
