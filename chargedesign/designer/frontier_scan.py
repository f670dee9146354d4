"""The frontier over size, medium, field and density, and the scaling law it measures.

Bodies are scaled geometrically (radius, spacing, carrier radius and shell wall times ``f``;
``C`` times ``f^5``, the same materials), the medium, one coefficient of the magnetic field
and the carriers' density are varied. What binds depends on the Larmor reading
(:mod:`chargedesign.larmor`):

- ``frame`` (the default with ``[medium]``): the body realises n = 0 and only K's third
  moments need charges, ``6 a2 I_xxz = -C K d``. Where the carriers' breakdown binds,
  ``I_xxz ~ N a^2 eps0 E_safe L^3`` and ``C ~ rho L^5`` (``rho`` the body's density), so
  the expected law is

      K_max  ~  eps0 E_safe a2 / rho      (exponents 1 in E, 1 in a2, 0 in L)

  independent of size for similar bodies; the field case varies ``a2``.
- ``charges`` (the paper's (p6)): the second moments ``-C n / a1`` bind first, so

      n_max  ~  eps0 E_safe a1 / (rho L)  (exponents 1 in E, 1 in a1, -1 in L)

  and the field case varies ``a1``.

Scaled bodies keep their density (``C x f^5``); the carrier case changes the carriers'
material at fixed ``C``, whose exponent is 0 unless the carriers' mass binds.

:func:`scan_frontier` measures the exponents by least squares over the sweep (it does not
assume them) and reports each point's deviation from the fitted law and the fit's residual.

At each frontier it also records the measured fractions of the applied field's action on
the parts' own materials (:func:`chargedesign.physical.realism.field_response`) and the
smallest carrier charge in elementary charges: a statement about size stays within the
measured sizes, and a carrier holds at least one elementary charge. (No extrapolation of
the fractions beyond the sizes measured.)
"""

from __future__ import annotations

import copy
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from chargedesign.constants import ELEMENTARY_CHARGE
from chargedesign.designer.pipeline import frontier_from_scene, physical_setup_from_scene
from chargedesign.files import atomic_directory, write_text_atomic
from chargedesign.formatting import PLAIN, PRECISE, fmt
from chargedesign.params import Parameters
from chargedesign.physical.materials import BREAKDOWN_V_PER_M, CARRIER_DENSITY
from chargedesign.physical.realism import FIELD_RESPONSE_KEYS, RESPONSE_FRACTION
from chargedesign.results import Result
from chargedesign.scene import scene_from_dict
from chargedesign.scene.keys import KEY
from chargedesign.scene.physical import DEFAULT_SHELL_THICKNESS

SIZE_FACTORS = (0.5, 1.0, 2.0)
MEDIA = ("air", "sf6", "vacuum")
#: the field coefficient of the field case (a2 for frame, a1 for charges), relative to the
#: scene's (weaker: a stronger field puts the magnets beyond what they withstand)
FIELD_FACTOR = 0.5
DENSE_CARRIER = "copper"
#: expected exponents of the law each reading fits (module doc) where breakdown binds; the
#: scan varies the carriers' density at fixed C (the body's density rho = C / L^5 stays
#: fixed as the body is scaled), so the carriers' density enters only where their mass binds
EXPECTED = {
    "frame": {"E": 1.0, "field": 1.0, "L": 0.0, "rho": 0.0},
    "charges": {"E": 1.0, "field": 1.0, "L": -1.0, "rho": 0.0},
}


@dataclass(repr=False)
class ScanResult(Result):
    """The frontier over size, medium, field and carrier density, and the fitted law.

    ``target`` is ``K_max`` (frame reading) or ``n_max`` (charges); ``exponents`` its fitted
    exponents in the breakdown field ``E``, the varied field coefficient (``a2`` or ``a1``),
    the size ``L`` and the carriers' density ``rho``; ``rms_fit_error`` and
    ``worst_fit_error`` the residual of the fit in log space (rms) and the largest relative
    deviation of a point from the fitted law.
    """

    rows: list[dict[str, Any]]
    exponents: dict[str, float]
    expected: dict[str, float]
    worst_fit_error: float
    law: str
    failures: list[str] = field(default_factory=list)
    #: per field-response item: its size exponent over the measured sizes (no extrapolation)
    response_laws: dict[str, dict[str, Any]] = field(default_factory=dict)
    larmor: str = "frame"
    target: str = "K_max"
    field_name: str = "a2"
    rms_fit_error: float = math.nan

    def to_dict(self) -> dict[str, Any]:
        return {
            "rows": self.rows,
            "larmor": self.larmor,
            "target": self.target,
            "field": self.field_name,
            "exponents": self.exponents,
            "expected_exponents": self.expected,
            "rms_log_fit_error": self.rms_fit_error,
            "worst_relative_fit_error": self.worst_fit_error,
            "law": self.law,
            "failures": self.failures,
            "field_response_laws": self.response_laws,
        }

    def _summary(self) -> dict[str, Any]:
        return {
            "points": len(self.rows),
            "law": self.law,
            "worst_relative_fit_error": self.worst_fit_error,
            "failures": len(self.failures),
        }

    def _text(self) -> str:
        t = self.target
        lines = [
            f"frontier scan ({self.larmor} reading): {t} (1/s) by size factor, medium, field "
            f"{self.field_name} and carrier density",
            f"{'size':>6} {'medium':>8} {self.field_name + ' T':>7} {'carrier':>10} {t:>11} "
            f"{'binding':>9} {'min |q|/e':>10}",
        ]
        for r in self.rows:
            lines.append(
                f"{fmt(r['size_factor'], PLAIN):>6} {r['medium']:>8}"
                f" {fmt(r[self.field_name], PLAIN):>7} "
                f"{r['carrier']:>10} {fmt(r[t], PRECISE):>11} {r['binding_stage']:>9} "
                f"{fmt(r['smallest_carrier_charge_e']):>10}"
            )
        lines.append(f"law: {self.law}")
        lines.append(
            f"fit residual: rms {fmt(self.rms_fit_error)} in log {t}; worst relative deviation "
            f"{fmt(self.worst_fit_error)}"
        )
        for key, law in self.response_laws.items():
            lo, hi = law["measured_size_factors"]
            lines.append(
                f"{key.replace('_', ' ')} at the frontier ~ L^{fmt(law['size_exponent'])} over "
                f"the measured sizes f = {fmt(lo, PLAIN)} .. {fmt(hi, PLAIN)} (fractions per point"
                " in the rows; "
                "not extrapolated)"
            )
        lines.extend(f"failed: {f}" for f in self.failures)
        return "\n".join(lines) + "\n"


def scene_dict(scene: Any) -> dict[str, Any]:
    """The mapping a scene was read from (parameters, fields with limits, tables)."""

    params = scene.parameters.as_dict() if isinstance(scene.parameters, Parameters) else {}
    fields: dict[str, Any] = {}
    for kind, coeffs in scene.fields.items():
        fields[kind] = {"legendre": list(coeffs)}
    for kind, limit in scene.field_limits.items():
        fields.setdefault(kind, {})["max"] = limit
    out = copy.deepcopy(scene.tables)
    out["parameters"] = params
    out["fields"] = fields
    return out


def scene_variant(
    base: dict[str, Any],
    f: float,
    medium: str,
    field_factor: float,
    carrier: str | None,
    field_index: int = 0,
) -> dict[str, Any]:
    """A scan point: size ``f``, ``medium``, the magnetic Legendre coefficient
    ``field_index`` (0: a1, 1: 2 a2) times ``field_factor``, carrier material."""
    data = copy.deepcopy(base)
    body = data.setdefault("body", {})
    for key in ("radius", "spacing", KEY.carrier_radius, "height"):
        if key in body:
            body[key] = body[key] * f
    data["parameters"]["C"] = data["parameters"].get("C", 1.0) * f**5
    carriers = data.setdefault("carriers", {})
    if KEY.shell_thickness in carriers:
        carriers[KEY.shell_thickness] = carriers[KEY.shell_thickness] * f
    else:
        carriers[KEY.shell_thickness] = DEFAULT_SHELL_THICKNESS * f
    if carrier is not None:
        carriers.pop("density", None)
        carriers["material"] = carrier
    med = data.setdefault("medium", {})
    med.pop("breakdown", None)
    med["name"] = medium
    mag = data["fields"].get("magnetic", {})
    if "legendre" in mag:
        coeffs = list(mag["legendre"])
        if field_index < len(coeffs):
            coeffs[field_index] = coeffs[field_index] * field_factor
        mag["legendre"] = coeffs
        if "max" in mag:
            # the gradient term grows with the body: the apparatus' limit grows with it
            mag["max"] = mag["max"] * max(1.0, field_factor) * max(1.0, f)
    return data


def scan_frontier(
    scene: Any,
    *,
    size_factors: tuple[float, ...] = SIZE_FACTORS,
    media: tuple[str, ...] = MEDIA,
    progress: Any = None,
) -> ScanResult:
    """Frontiers over size x medium, plus a weaker field and denser carriers (see module)."""

    base = scene_dict(scene)
    base_carrier = base.get("carriers", {}).get("material", "aluminium")
    setup = physical_setup_from_scene(scene)
    reading = setup.larmor.reading if setup is not None and setup.larmor else "charges"
    frame = reading == "frame"
    target, field_name, index = ("K_max", "a2", 1) if frame else ("n_max", "a1", 0)
    magnetic = scene.fields.get("magnetic", ())
    # legendre [a1, 2 a2]
    base_field = float(magnetic[index]) / (2.0 if frame else 1.0) if len(magnetic) > index else 1.0
    cases: list[tuple[float, str, float, str | None]] = [
        (f, m, 1.0, None) for m in media for f in size_factors
    ]
    cases.append((1.0, media[0], FIELD_FACTOR, None))
    cases.append((1.0, media[0], 1.0, DENSE_CARRIER))
    rows: list[dict[str, Any]] = []
    failures: list[str] = []
    for i, (f, medium, ff, carrier) in enumerate(cases):
        data = scene_variant(base, f, medium, ff, carrier, index)
        if progress is not None:
            progress(
                f"[{i + 1}/{len(cases)}] size x{fmt(f, PLAIN)}, {medium}, {field_name}"
                f" x{fmt(ff, PLAIN)}, "
                f"{carrier or base_carrier}"
            )
        try:
            result = frontier_from_scene(scene_from_dict(data, f"{scene.source} (scan {i})"))
        except Exception as exc:  # one failing point is recorded, the scan goes on
            failures.append(
                f"size x{fmt(f, PLAIN)} {medium}, {field_name} x{fmt(ff, PLAIN)},"
                f" {carrier or base_carrier}: {exc}"
            )
            continue
        name = carrier or base_carrier
        rows.append(
            {
                # "size": the size x medium grid; "field" and "carrier": the one-off variations
                "case": "field" if ff != 1.0 else "carrier" if carrier else "size",
                "size_factor": f,
                "medium": medium,
                "breakdown_V_per_m": BREAKDOWN_V_PER_M[medium],
                field_name: base_field * ff,
                "carrier": name,
                "carrier_density": CARRIER_DENSITY.get(name, float("nan")),
                "larmor": result.larmor,
                "s_max": result.s_max,
                "n_max": result.n_max if result.n_max is not None else math.nan,
                "K_max": result.K_max,
                "binding_stage": result.binding.stage,
                "binding": result.binding.text(medium),
                "smallest_carrier_charge_e": result.smallest_charge / ELEMENTARY_CHARGE,
                "seconds": result.seconds,
                **{
                    key: _response_value(result.field_response.get(key))
                    for key in FIELD_RESPONSE_KEYS
                },
            }
        )
    exponents, worst, rms = fit_power_law(rows, target, field_name)
    expected = EXPECTED[reading]
    if frame:
        law = (
            f"K_max ~ E_breakdown^{fmt(exponents['E'])} a2^{fmt(exponents['field'])}"
            f" L^{fmt(exponents['L'])} rho_carrier^{fmt(exponents['rho'])} "
            "(expected eps0 E a2 / rho_body: E^1 a2^1 L^0, independent of size; "
            "rho_carrier^0 unless the carriers' mass binds)"
        )
    else:
        law = (
            f"n_max ~ E_breakdown^{fmt(exponents['E'])} a1^{fmt(exponents['field'])}"
            f" L^{fmt(exponents['L'])} rho_carrier^{fmt(exponents['rho'])} "
            "(expected eps0 E a1 / (rho_body L): E^1 a1^1 L^-1; rho_carrier^0 unless the "
            "carriers' mass binds)"
        )
    return ScanResult(
        rows,
        exponents,
        expected,
        worst,
        law,
        failures,
        response_laws(rows),
        larmor=reading,
        target=target,
        field_name=field_name,
        rms_fit_error=rms,
    )


def _response_value(item: dict[str, Any] | None) -> float:
    if not item or item.get("value") is None:
        return math.nan
    return float(item["value"])


def response_laws(rows: list[dict[str, Any]]) -> dict[str, dict[str, Any]]:
    """Size exponent of each field-response fraction at the frontier (base field and
    carrier, one intercept per medium) over the measured sizes only."""
    laws: dict[str, dict[str, Any]] = {}
    for key in FIELD_RESPONSE_KEYS:
        sized = [r for r in rows if r["case"] == "size" and math.isfinite(r[key]) and r[key] > 0]
        media = sorted({r["medium"] for r in sized})
        sizes = sorted({r["size_factor"] for r in sized})
        if len(sizes) < 2:
            continue
        X = np.array(
            [[math.log(r["size_factor"])] + [float(r["medium"] == m) for m in media] for r in sized]
        )
        coef, *_ = np.linalg.lstsq(X, np.log([r[key] for r in sized]), rcond=None)
        laws[key] = {
            "size_exponent": float(coef[0]),
            "measured_size_factors": [sizes[0], sizes[-1]],
            "negligible_fraction": RESPONSE_FRACTION,
        }
    return laws


def fit_power_law(
    rows: list[dict[str, Any]], target: str, field_name: str
) -> tuple[dict[str, float], float, float]:
    """Exponents of ``target`` in E, the field, L and rho by least squares in logs, the worst
    relative deviation and the rms log residual (NaN with fewer than 5 points)."""
    names = ("E", "field", "L", "rho")
    good = [r for r in rows if math.isfinite(r[target]) and r[target] > 0]
    if len(good) < 5:
        return {k: math.nan for k in names}, math.nan, math.nan
    X = np.array(
        [
            [
                1.0,
                math.log(r["breakdown_V_per_m"]),
                math.log(r[field_name]),
                math.log(r["size_factor"]),
                math.log(r["carrier_density"]),
            ]
            for r in good
        ]
    )
    y = np.log([r[target] for r in good])
    # a quantity the scan did not vary (e.g. its field case failed) has no exponent
    varied = [0] + [j for j in range(1, X.shape[1]) if np.ptp(X[:, j]) > 0]
    coef = np.full(X.shape[1], math.nan)
    coef[varied], *_ = np.linalg.lstsq(X[:, varied], y, rcond=None)
    residual = X[:, varied] @ coef[varied] - y
    worst = float(np.max(np.abs(np.exp(residual) - 1.0)))
    rms = float(np.sqrt(np.mean(residual**2)))
    return dict(zip(names, map(float, coef[1:]), strict=True)), worst, rms


def plot_scan(scan: ScanResult, ax: Any = None) -> Any:
    """The fitted quantity (K_max or n_max) against size, log-log, one line per medium."""
    import matplotlib.pyplot as plt

    if ax is None:
        _, ax = plt.subplots(figsize=(6, 4.2))
    media = sorted({r["medium"] for r in scan.rows})
    for medium in media:
        pts = sorted(
            (r["size_factor"], r[scan.target])
            for r in scan.rows
            if r["medium"] == medium and r["case"] == "size"
        )
        if pts:
            x, y = zip(*pts, strict=True)
            ax.loglog(x, y, "o-", label=medium)
    ax.set_xlabel("body size factor f (radius, spacing, carriers x f; C x f^5)")
    ax.set_ylabel(f"{scan.target} (1/s)")
    ax.set_title(f"frontier of the buildable ({scan.larmor} reading)")
    ax.legend(title="medium")
    ax.grid(True, which="both", alpha=0.3)
    return ax


def plot_field_response(scan: ScanResult, ax: Any = None) -> Any:
    """The measured field response of the parts at the frontier against size, log-log (the
    measured points only); returns the axes."""
    import matplotlib.pyplot as plt

    if ax is None:
        _, ax = plt.subplots(figsize=(6, 4.2))
    styles = {FIELD_RESPONSE_KEYS[0]: "-", FIELD_RESPONSE_KEYS[1]: "--"}
    names = {FIELD_RESPONSE_KEYS[0]: "induced magnetisation", FIELD_RESPONSE_KEYS[1]: "eddy"}
    colours: dict[str, Any] = {}
    for key in FIELD_RESPONSE_KEYS:
        for medium in sorted({r["medium"] for r in scan.rows}):
            pts = sorted(
                (r["size_factor"], r[key])
                for r in scan.rows
                if r["medium"] == medium
                and r["case"] == "size"
                and math.isfinite(r[key])
                and r[key] > 0
            )
            if not pts:
                continue
            x, y = zip(*pts, strict=True)
            (line,) = ax.loglog(
                x, y, "o" + styles[key], color=colours.get(medium), label=f"{names[key]}, {medium}"
            )
            colours.setdefault(medium, line.get_color())
    ax.axhline(RESPONSE_FRACTION, color="k", lw=0.8)
    ax.set_xlabel("body size factor f (measured points only)")
    ax.set_ylabel("torque from the parts' materials / designed torques")
    ax.set_title("the applied field acting on the parts, at the frontier")
    ax.legend(fontsize=7)
    ax.grid(True, which="both", alpha=0.3)
    return ax


def write_scan(scan: ScanResult, out: Path) -> None:
    """frontier_scan.csv and frontier_scan.png into ``out``, together or not at all."""
    import csv
    import io

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    buffer = io.StringIO()
    if scan.rows:
        writer = csv.DictWriter(buffer, fieldnames=list(scan.rows[0]))
        writer.writeheader()
        writer.writerows(scan.rows)
    with atomic_directory(out) as stage:
        write_text_atomic(stage / "frontier_scan.csv", buffer.getvalue())
        fig, (left, right) = plt.subplots(1, 2, figsize=(12, 4.4))
        plot_scan(scan, ax=left)
        plot_field_response(scan, ax=right)
        fig.tight_layout()
        fig.savefig(stage / "frontier_scan.png", dpi=120)
        plt.close(fig)
