"""`chargedesign tolerance DESIGN`: how precisely each element must be made, and what errors do.

Without error options: the exact first-order sensitivity (tolerance per element for
``--target``, most influential first). With ``--position``, ``--charge``, ``--dipole`` or
``--mass``: also a Monte Carlo of perturbed bodies (errors at one standard deviation,
Gaussian): the distribution of the mu, V and inertia errors, the I4 drift of each perturbed
body over ``--t-end`` (one batch simulation) and the linear-response prediction beside it.

Error syntax: a number with an optional unit, or a percentage. ``--position 20um`` (also
``m``, ``mm``, ``um``/``µm``, ``nm``; a bare number is m), ``--position 0.1%`` (of each
element's distance from O); ``--charge 1e-6`` (C) or ``--charge 1%``; ``--dipole`` (A m^2 per
component, or % of |sigma|); ``--mass`` (kg or %). See docs/tolerance.md.

Material properties (physical designs): ``--chi-relative``, ``--density-relative``,
``--magnetisation-relative`` (relative errors, one draw per material; default: the scene's
``[tolerance]`` values the design records) add the induced-magnetisation parasitic they
leave, by the exact first-order sensitivity and by a Monte Carlo, and the chi accuracy needed.
"""

from __future__ import annotations

import argparse
from collections.abc import Sequence
from typing import Any

import numpy as np

from chargedesign.body import read_design, write_design
from chargedesign.commands.progress import progress_bar
from chargedesign.errors import InputError
from chargedesign.files import atomic_directory, check_outputs
from chargedesign.formatting import EXACT, PLAIN, fmt
from chargedesign.limits import MAX_PERIODS
from chargedesign.limits import MAX_TOLERANCE_LEVELS as MAX_LEVELS
from chargedesign.sensitivity import check_theorem_design
from chargedesign.tolerancing import (
    ErrorModel,
    MonteCarloResult,
    material_errors_with,
    monte_carlo,
    plot_drift,
    tolerance_report,
    with_tolerance,
)
from chargedesign.validation import check_error_spreads, check_periods


def check_error_scale(model: Any, levels: Sequence[float], design: Any) -> None:
    """The largest error a Monte Carlo draws (a spread times the largest level) no larger than
    what it perturbs: a position error within the body's extent (the farthest element from
    O), an absolute charge, dipole or mass error within the largest element of its kind, a
    relative one at most 100 %. Past that the perturbed bodies are no longer the design: on a
    1 m body ``--position 10`` (or ``1um`` at ``--levels 1e31``) ran past 60 s with no end
    (0.5 m: 14 s).

    Parameters
    ----------
    model : chargedesign.tolerancing.ErrorModel
    levels : sequence of float
        The scale factors of the errors (``--levels``).
    design : chargedesign.body.Design
        Its element arrays: positions (m), charges (C), dipole moments (A m^2), masses (kg).
    """
    top = max(levels, default=1.0)

    def largest(array: Any, rows: bool = False) -> float:
        a = np.asarray(array, dtype=float)
        if a.size == 0:
            return 0.0
        return float(np.max(np.linalg.norm(a, axis=1) if rows else np.abs(a)))

    sizes = {
        "position": max(
            largest(design.charge_positions, True),
            largest(design.dipole_positions, True),
            largest(design.mass_positions, True),
        ),
        "charge": largest(design.charge_values),
        "dipole": largest(design.dipole_moments, True),
        "mass": largest(design.mass_values),
    }
    units = {"position": "m", "charge": "C", "dipole": "A m^2", "mass": "kg"}
    for name, size in sizes.items():
        spread = getattr(model, name)
        drawn = spread.value * top
        if drawn == 0.0:
            continue
        if spread.relative and drawn > 1.0:
            raise InputError(
                f"--{name}: {fmt(100 * spread.value, PLAIN)}% times the largest level"
                f" {fmt(top, PLAIN)} is "
                f"{fmt(100 * drawn, PLAIN)}%, past 100 %: give a smaller error or smaller --levels"
            )
        if not spread.relative and drawn > size:
            what = "the body's extent" if name == "position" else f"the largest {name}"
            raise InputError(
                f"--{name}: {fmt(spread.value, PLAIN)} {units[name]} times the largest level"
                f" {fmt(top, PLAIN)} "
                f"is {fmt(drawn, PLAIN)} {units[name]}, more than {what} ({fmt(size, PLAIN)}"
                f" {units[name]}): the "
                "perturbed bodies would not be this design; give a smaller error or smaller "
                "--levels"
            )


def run(args: argparse.Namespace) -> int:
    import json
    import math

    check_outputs([("--out", args.out, True)], inputs=[args.design], writes=TOLERANCE_FILES)
    # --target, --samples, --t-end: their ranges are checked by the command line before this
    # runs (chargedesign.limits.OPTION_RANGES, shown in --help)
    try:
        levels = [float(x) for x in args.levels.split(",") if x.strip()]
    except ValueError:
        raise InputError(
            f"--levels: expected numbers separated by commas, got {args.levels!r}"
        ) from None
    if not 1 <= len(levels) <= MAX_LEVELS or any(not (x > 0 and math.isfinite(x)) for x in levels):
        raise InputError(
            f"--levels: expected 1 to {MAX_LEVELS} positive factors, got {args.levels!r}"
        )
    model = ErrorModel.parse(args.position, args.charge, args.dipole, args.mass)
    check_error_spreads(model)
    design = read_design(args.design)
    check_theorem_design(design, args.design)  # before the spreads are weighed against it
    check_error_scale(model, levels, design)
    if not model.is_zero and not args.no_simulate:
        check_periods(args.t_end, design.parameters, None, MAX_PERIODS, "--t-end")
    materials = material_errors_with(
        design,
        "--",
        chi_relative=args.chi_relative,
        density_relative=args.density_relative,
        magnetisation_relative=args.magnetisation_relative,
    )
    result: object
    if model.is_zero:
        result = tolerance_report(
            design, args.target, material_errors=materials, material_samples=args.samples
        )
    else:
        # the Monte-Carlo bodies counted against their total, with the time left
        with progress_bar("tolerance", "bodies", args.quiet) as bar:
            result = monte_carlo(
                design,
                model,
                samples=args.samples,
                drift_samples=0 if args.no_simulate else args.samples,
                t_end=args.t_end,
                levels=levels,
                seed=args.seed,
                target=args.target,
                material_errors=materials,
                tally=None if bar is None else bar.update,
            )
    data = result.to_dict()
    if args.out:
        _write(args.out, result, data, design)
    if args.json:
        print(json.dumps(data, indent=2, allow_nan=False))
    else:
        print(str(result))
    return 0


#: every file the tolerance command may write into --out
TOLERANCE_FILES = (
    "tolerance.json",
    "design.json",
    "errors.csv",
    "drift.csv",
    "drift_over_time.csv",
    "drift.png",
)


def _write(out: str, result: Any, data: dict, design: Any) -> None:
    import csv
    import io
    import json

    report = result.report if isinstance(result, MonteCarloResult) else result
    with atomic_directory(out) as stage:
        (stage / "tolerance.json").write_text(json.dumps(data, indent=2, allow_nan=False) + "\n")
        if report is not None:
            # the design with its per-element tolerances under the key "tolerance"
            write_design(with_tolerance(design, report), stage / "design.json")
        if not isinstance(result, MonteCarloResult):
            return
        buf = io.StringIO()
        w = csv.writer(buf)
        w.writerow(["sample", *(f"{q}_{k}" for q in result.errors for k in ("mc", "linear"))])
        for i in range(result.n):
            w.writerow(
                [i]
                + [
                    fmt(result.errors[q][k][i], EXACT)
                    for q in result.errors
                    for k in ("monte_carlo", "linear")
                ]
            )
        (stage / "errors.csv").write_text(buf.getvalue())
        if result.drift_mc.size:
            buf = io.StringIO()
            w = csv.writer(buf)
            w.writerow(["level", "body", "I4_rel_drift_mc", "I4_rel_drift_linear"])
            for i, level in enumerate(result.levels):
                for b in range(result.drift_mc.shape[1]):
                    w.writerow(
                        [
                            fmt(level, PLAIN),
                            b,
                            fmt(result.drift_mc[i, b], EXACT),
                            fmt(result.drift_linear[i, b], EXACT),
                        ]
                    )
            (stage / "drift.csv").write_text(buf.getvalue())
            buf = io.StringIO()
            w = csv.writer(buf)
            w.writerow(["t", "I4_rel_drift_median", "I4_rel_drift_p90"])
            for t, a, b in zip(
                result.drift_times,
                result.drift_median_over_time,
                result.drift_p90_over_time,
                strict=True,
            ):
                w.writerow([fmt(t, EXACT), fmt(a, EXACT), fmt(b, EXACT)])
            (stage / "drift_over_time.csv").write_text(buf.getvalue())
            import matplotlib

            matplotlib.use("Agg")
            import matplotlib.pyplot as plt

            fig, ax = plt.subplots(figsize=(6, 4.5))
            plot_drift(result, ax=ax)
            fig.tight_layout()
            fig.savefig(stage / "drift.png", dpi=110)
            plt.close(fig)
