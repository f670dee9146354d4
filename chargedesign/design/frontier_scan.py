"""The frontier over size, medium, field and density, and the scaling law it follows.

Bodies are scaled geometrically (radius, spacing, carrier radius and shell wall times ``f``;
``C`` times ``f^5``, the same materials), the medium and the uniform field ``a1`` and the
carriers' density are varied. Where the carriers' breakdown binds, the charges' second
moments are about ``N a^2 eps0 E_safe L^2`` and ``C ~ rho L^5``, so

    n_max  ~  eps0 E_safe a1 / (rho L)     (exponents 1 in E, 1 in a1, -1 in L)

:func:`scan_frontier` measures the exponents by least squares over the sweep and reports
how far each point lies from the fitted law.

At each frontier it also records how strongly the applied field acts on the parts' own
materials (:func:`chargedesign.physical.realism.field_response`). The induced-magnetisation
energy does not depend on the rate and the designed torques go as ``n^2``, so at the frontier
it falls like ``1 / n_max^2 ~ L^2``; the eddy torque, ``~ n``, like ``1 / n_max ~ L``. The
fitted size exponents give the size below which each would be negligible.
"""

from __future__ import annotations

import copy
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from chargedesign.design.frontier import frontier_from_scene
from chargedesign.physical.materials import BREAKDOWN_V_PER_M, CARRIER_DENSITY
from chargedesign.physical.realism import FIELD_RESPONSE_KEYS, RESPONSE_FRACTION
from chargedesign.results import Result

SIZE_FACTORS = (0.5, 1.0, 2.0)
MEDIA = ("air", "sf6", "vacuum")
#: the uniform field a1 of the field case, relative to the scene's (weaker: a stronger a1 puts
#: the magnets beyond what they withstand)
FIELD_FACTOR = 0.5
DENSE_CARRIER = "copper"


@dataclass(repr=False)
class ScanResult(Result):
    """The frontier over size, medium, field and carrier density, and the fitted law."""

    rows: list[dict[str, Any]]
    exponents: dict[str, float]
    expected: dict[str, float]
    worst_fit_error: float
    law: str
    failures: list[str] = field(default_factory=list)
    #: per field-response item: its size exponent at the frontier and the size factor below
    #: which it is negligible, per medium
    response_laws: dict[str, dict[str, Any]] = field(default_factory=dict)

    def to_dict(self) -> dict[str, Any]:
        return {
            "rows": self.rows,
            "exponents": self.exponents,
            "expected_exponents": self.expected,
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
        lines = [
            "frontier scan: n_max (1/s) by size factor, medium, field a1 and carrier density",
            f"{'size':>6} {'medium':>8} {'a1 T':>6} {'carrier':>10} {'n_max':>11} {'binding':>9}",
        ]
        for r in self.rows:
            lines.append(
                f"{r['size_factor']:>6g} {r['medium']:>8} {r['a1']:>6g} {r['carrier']:>10} "
                f"{r['n_max']:>11.4g} {r['binding_stage']:>9}"
            )
        lines.append(f"law: {self.law}")
        lines.append(f"worst relative deviation from the fitted law: {self.worst_fit_error:.3g}")
        for key, law in self.response_laws.items():
            sizes = ", ".join(
                f"{medium} f < {f:.3g}" for medium, f in law["negligible_below_size_factor"].items()
            )
            head = f"{key.replace('_', ' ')} at the frontier ~ L^{law['size_exponent']:.3g}"
            lines.append(
                f"{head}: negligible ({RESPONSE_FRACTION:g}) only for bodies {sizes} times "
                "this one (extrapolated along the fitted law)"
                if sizes
                else f"{head}: it does not fall as the body shrinks"
            )
        lines.extend(f"failed: {f}" for f in self.failures)
        return "\n".join(lines) + "\n"


def _scene_dict(scene: Any) -> dict[str, Any]:
    """The mapping a scene was read from (parameters, fields with limits, tables)."""
    from chargedesign.params import Parameters

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


def _variant(
    base: dict[str, Any], f: float, medium: str, a1_factor: float, carrier: str | None
) -> dict[str, Any]:
    data = copy.deepcopy(base)
    body = data.setdefault("body", {})
    for key in ("radius", "spacing", "carrier_radius", "height"):
        if key in body:
            body[key] = body[key] * f
    data["parameters"]["C"] = data["parameters"].get("C", 1.0) * f**5
    carriers = data.setdefault("carriers", {})
    if "shell_thickness" in carriers:
        carriers["shell_thickness"] = carriers["shell_thickness"] * f
    else:
        from chargedesign.physical.spec import DEFAULT_SHELL_THICKNESS

        carriers["shell_thickness"] = DEFAULT_SHELL_THICKNESS * f
    if carrier is not None:
        carriers.pop("density", None)
        carriers["material"] = carrier
    med = data.setdefault("medium", {})
    med.pop("breakdown", None)
    med["name"] = medium
    mag = data["fields"].get("magnetic", {})
    if "legendre" in mag:
        coeffs = list(mag["legendre"])
        coeffs[0] = coeffs[0] * a1_factor
        mag["legendre"] = coeffs
        if "max" in mag:
            # the gradient term grows with the body: the apparatus' limit grows with it
            mag["max"] = mag["max"] * max(1.0, a1_factor) * max(1.0, f)
    return data


def scan_frontier(
    scene: Any,
    *,
    size_factors: tuple[float, ...] = SIZE_FACTORS,
    media: tuple[str, ...] = MEDIA,
    progress: Any = None,
) -> ScanResult:
    """Frontiers over size x medium, plus a stronger field and denser carriers (see module)."""
    from chargedesign.scene import scene_from_dict

    base = _scene_dict(scene)
    base_carrier = base.get("carriers", {}).get("material", "aluminium")
    a1 = float(scene.fields.get("magnetic", (1.0,))[0]) if scene.fields.get("magnetic") else 1.0
    cases: list[tuple[float, str, float, str | None]] = [
        (f, m, 1.0, None) for m in media for f in size_factors
    ]
    cases.append((1.0, media[0], FIELD_FACTOR, None))
    cases.append((1.0, media[0], 1.0, DENSE_CARRIER))
    rows: list[dict[str, Any]] = []
    failures: list[str] = []
    for i, (f, medium, a1f, carrier) in enumerate(cases):
        data = _variant(base, f, medium, a1f, carrier)
        if progress is not None:
            progress(
                f"[{i + 1}/{len(cases)}] size x{f:g}, {medium}, a1 x{a1f:g}, "
                f"{carrier or base_carrier}"
            )
        try:
            result = frontier_from_scene(scene_from_dict(data, f"{scene.source} (scan {i})"))
        except Exception as exc:  # one failing point is recorded, the scan goes on
            failures.append(f"size x{f:g} {medium}, a1 x{a1f:g}, {carrier or base_carrier}: {exc}")
            continue
        name = carrier or base_carrier
        rows.append(
            {
                # "size": the size x medium grid; "field" and "carrier": the one-off variations
                "case": "field" if a1f != 1.0 else "carrier" if carrier else "size",
                "size_factor": f,
                "medium": medium,
                "breakdown_V_per_m": BREAKDOWN_V_PER_M[medium],
                "a1": a1 * a1f,
                "carrier": name,
                "carrier_density": CARRIER_DENSITY.get(name, float("nan")),
                "s_max": result.s_max,
                "n_max": result.n_max,
                "binding_stage": result.binding.stage,
                "binding": result.binding.text(medium),
                "seconds": result.seconds,
                **{
                    key: _response_value(result.field_response.get(key))
                    for key in FIELD_RESPONSE_KEYS
                },
            }
        )
    exponents, worst, expected = _fit(rows)
    law = (
        "n_max ~ E_breakdown^{E:.3g} a1^{B:.3g} L^{L:.3g} rho_carrier^{rho:.3g} "
        "(breakdown-bound estimate: E^1 a1^1 L^-1, rho^-1 when the carriers' mass dominates)"
    ).format(**{k: v for k, v in exponents.items()})
    return ScanResult(rows, exponents, expected, worst, law, failures, _response_laws(rows))


def _response_value(item: dict[str, Any] | None) -> float:
    if not item or item.get("value") is None:
        return math.nan
    return float(item["value"])


def _response_laws(rows: list[dict[str, Any]]) -> dict[str, dict[str, Any]]:
    """Size exponent of each field-response fraction at the frontier (base field and carrier),
    and per medium the size factor at which it would fall to ``RESPONSE_FRACTION``."""
    laws: dict[str, dict[str, Any]] = {}
    for key in FIELD_RESPONSE_KEYS:
        sized = [r for r in rows if r["case"] == "size" and math.isfinite(r[key]) and r[key] > 0]
        media = sorted({r["medium"] for r in sized})
        if len({r["size_factor"] for r in sized}) < 2:
            continue
        # one slope in log size, one intercept per medium
        X = np.array(
            [[math.log(r["size_factor"])] + [float(r["medium"] == m) for m in media] for r in sized]
        )
        coef, *_ = np.linalg.lstsq(X, np.log([r[key] for r in sized]), rcond=None)
        slope = float(coef[0])
        below = (
            {
                m: math.exp((math.log(RESPONSE_FRACTION) - coef[1 + i]) / slope)
                for i, m in enumerate(media)
            }
            if slope > 0
            else {}  # it does not fall as the body shrinks
        )
        laws[key] = {"size_exponent": slope, "negligible_below_size_factor": below}
    return laws


def _fit(rows: list[dict[str, Any]]) -> tuple[dict[str, float], float, dict[str, float]]:
    expected = {"E": 1.0, "B": 1.0, "L": -1.0, "rho": -1.0}
    good = [r for r in rows if r["n_max"] > 0]
    if len(good) < 5:
        return {k: math.nan for k in expected}, math.nan, expected
    X = np.array(
        [
            [
                1.0,
                math.log(r["breakdown_V_per_m"]),
                math.log(r["a1"]),
                math.log(r["size_factor"]),
                math.log(r["carrier_density"]),
            ]
            for r in good
        ]
    )
    y = np.log([r["n_max"] for r in good])
    # a quantity the scan did not vary (e.g. its field case failed) has no exponent
    varied = [0] + [j for j in range(1, X.shape[1]) if np.ptp(X[:, j]) > 0]
    coef = np.full(X.shape[1], math.nan)
    coef[varied], *_ = np.linalg.lstsq(X[:, varied], y, rcond=None)
    worst = float(np.max(np.abs(np.exp(X[:, varied] @ coef[varied] - y) - 1.0)))
    return dict(zip(("E", "B", "L", "rho"), map(float, coef[1:]), strict=True)), worst, expected


def plot_scan(scan: ScanResult, ax: Any = None) -> Any:
    """n_max against size, log-log, one line per medium; returns the axes."""
    import matplotlib.pyplot as plt

    if ax is None:
        _, ax = plt.subplots(figsize=(6, 4.2))
    media = sorted({r["medium"] for r in scan.rows})
    for medium in media:
        pts = sorted(
            (r["size_factor"], r["n_max"])
            for r in scan.rows
            if r["medium"] == medium and r["case"] == "size"
        )
        if pts:
            x, y = zip(*pts, strict=True)
            ax.loglog(x, y, "o-", label=medium)
    ax.set_xlabel("body size factor f (radius, spacing, carriers x f; C x f^5)")
    ax.set_ylabel("n_max (1/s)")
    ax.set_title("frontier of the buildable")
    ax.legend(title="medium")
    ax.grid(True, which="both", alpha=0.3)
    return ax


def plot_field_response(scan: ScanResult, ax: Any = None) -> Any:
    """The field's action on the parts at the frontier against size, log-log, with the fitted
    laws extended (dotted) to where each falls to the negligible fraction; returns the axes."""
    import matplotlib.pyplot as plt

    if ax is None:
        _, ax = plt.subplots(figsize=(6, 4.2))
    styles = {FIELD_RESPONSE_KEYS[0]: "-", FIELD_RESPONSE_KEYS[1]: "--"}
    names = {FIELD_RESPONSE_KEYS[0]: "induced magnetisation", FIELD_RESPONSE_KEYS[1]: "eddy"}
    colours: dict[str, Any] = {}
    smallest = 0.5
    for key in FIELD_RESPONSE_KEYS:
        law = scan.response_laws.get(key)
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
            below = law["negligible_below_size_factor"].get(medium) if law else None
            if law and below:
                # the fitted law through this medium's smallest point, down to the crossing
                xs = np.geomspace(below, x[0], 50)
                fitted = y[0] * (xs / x[0]) ** law["size_exponent"]
                ax.loglog(xs, fitted, ":", color=line.get_color())
                smallest = min(smallest, below)
    ax.axhline(RESPONSE_FRACTION, color="k", lw=0.8)
    ax.text(smallest, RESPONSE_FRACTION * 2, f"negligible below {RESPONSE_FRACTION:g}", fontsize=8)
    ax.set_xlabel("body size factor f (dotted: the fitted law extended)")
    ax.set_ylabel("torque from the parts' materials / designed torques")
    ax.set_title("the applied field acting on the parts, at n_max")
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

    from chargedesign.files import atomic_directory, write_text_atomic

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
