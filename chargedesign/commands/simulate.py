"""`chargedesign simulate [SCENE_OR_DESIGN]`: motion under the effects the scene calls for.

No argument: the embedded default scene, whose ``[body]`` region is designed on the fly and
simulated from its own elements (lorentz, electric, magnetization, gravity) on the level
``I3 = 0``; ``--off-level I3`` starts off it. A scene with a ``[body] shape`` is designed the
same way unless its effects are only ``theorem`` (the reduced model). A ``.json`` argument is a
design file; anything else is a scene (TOML). Files are written only with ``--out DIR`` or a
scene's ``[output] dir`` (plus ``design.json`` of a body designed here).
"""

from __future__ import annotations

import argparse
import math
import sys
import time

from chargedesign.errors import ChargeDesignError

EFFECT_NAMES = ("lorentz", "electric", "magnetization", "gravity", "theorem")


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "source",
        nargs="?",
        default=None,
        metavar="SCENE_OR_DESIGN",
        help="scene (.toml) or design (.json); default: the embedded default scene",
    )
    parser.add_argument("--t-end", type=float, default=None, metavar="T", help="duration, s")
    parser.add_argument(
        "--effects",
        nargs="+",
        choices=EFFECT_NAMES,
        default=None,
        help="effects to compute (default: the scene's, else all with a source)",
    )
    parser.add_argument("--out", default=None, metavar="DIR", help="write outputs into DIR")
    parser.add_argument("--route", choices=("reduced", "direct"), default=None)
    parser.add_argument(
        "--method", default=None, help="DOP853 (default), RK45, ..., gauss-legendre"
    )
    parser.add_argument("--rtol", type=float, default=None)
    parser.add_argument("--atol", type=float, default=None)
    parser.add_argument("--step", type=float, default=None, help="gauss-legendre step, s")
    parser.add_argument("--samples", type=int, default=None, help="output samples")
    parser.add_argument(
        "--off-level",
        type=float,
        default=None,
        metavar="I3",
        help="start on the level I3 = value (J s) instead of the scene's (default: I3 = 0); "
        "same gamma, p, q, r solved from it: the theorem's I4 is then not conserved",
    )
    parser.add_argument(
        "--poincare", action="store_true", help="record a Poincare section (poincare.png)"
    )
    parser.add_argument("--json", action="store_true", help="print the JSON summary")
    parser.add_argument(
        "--progress",
        action=argparse.BooleanOptionalAction,
        default=None,
        help="progress bar on stderr (default: when stderr is a terminal); --no-progress also "
        "silences the 'designing body ...' lines",
    )


class _ProgressBar:
    """A one-line bar on stderr, drawn only once a run has lasted a second."""

    def __init__(self) -> None:
        self.start = time.perf_counter()
        self.drawn = False
        self.last = -1

    def __call__(self, fraction: float) -> None:
        elapsed = time.perf_counter() - self.start
        percent = int(100 * fraction)
        if elapsed < 1.0 or percent == self.last:
            return
        self.last = percent
        bar = "#" * (percent // 4) + "-" * (25 - percent // 4)
        print(f"\rsimulate [{bar}] {percent:3d}% {elapsed:6.1f} s", end="", file=sys.stderr)
        self.drawn = True

    def close(self) -> None:
        if self.drawn:
            print(file=sys.stderr)


def run(args: argparse.Namespace) -> int:
    import contextlib
    import json
    from pathlib import Path

    from chargedesign.body import write_design
    from chargedesign.files import atomic_directory
    from chargedesign.simulate import setup_from_source, simulate

    if args.t_end is not None and not args.t_end > 0:
        raise ChargeDesignError(f"--t-end: expected a duration > 0, got {args.t_end}")
    if args.off_level is not None and not math.isfinite(args.off_level):
        raise ChargeDesignError(f"--off-level: expected a finite I3 in J s, got {args.off_level}")
    show_bar = sys.stderr.isatty() if args.progress is None else args.progress
    bar = _ProgressBar() if show_bar else None
    setup = setup_from_source(args.source)
    designing = setup.design_scene is not None

    def design_progress(message: str) -> None:
        if args.progress is not False:
            print(f"designing body: {message}", file=sys.stderr, flush=True)

    try:
        result = simulate(
            setup,
            effects=args.effects,
            t_end=args.t_end,
            rtol=args.rtol,
            atol=args.atol,
            method=args.method,
            step=args.step,
            samples=args.samples,
            route=args.route,
            poincare=True if args.poincare else None,
            level=args.off_level,
            progress=bar,
            design_progress=design_progress,
        )
    finally:
        if bar is not None:
            bar.close()
    if designing and result.body and result.body.get("designed_from_scene"):
        if args.progress is not False:
            c = result.body["counts"]
            print(
                f"designed body: {c['charges']} charges, {c['dipoles']} dipoles, "
                f"{c['masses']} masses in {result.body['design_seconds']:.2f} s",
                file=sys.stderr,
                flush=True,
            )
    # the scene's [output] options; --out wins over its dir
    out_dir = args.out or setup.output.dir
    # one transaction: design.json and the run's files change together (chargedesign.files)
    with atomic_directory(out_dir) if out_dir else contextlib.nullcontext():
        if out_dir and result.body and result.body.get("designed_from_scene"):
            # the body designed here, beside its motion (chargedesign show/check read it)
            design_path = Path(out_dir) / "design.json"
            if Path(out_dir).exists() and not Path(out_dir).is_dir():
                raise ChargeDesignError(f"{out_dir}: expected an output directory, it is a file")
            write_design(setup.design, design_path)
            result.body["design_file"] = str(design_path)
        summary = result.summary()
        if out_dir:
            files = result.write(
                out_dir,
                trajectory=setup.output.trajectory,
                plot=setup.output.plot,
                poincare_axes=setup.output.poincare_axes,
            )
            summary["files"] = [str(f) for f in files]
            if "design_file" in summary.get("body", {}):
                summary["files"].append(summary["body"]["design_file"])
    if args.json:
        print(json.dumps(summary, indent=2, allow_nan=False))
        return 0
    print(_human(summary))
    return 0


def _human(s: dict) -> str:
    effects = ", ".join(s["effects"]) or "none (torque-free)"
    body = s.get("body") or {}
    lines = [
        f"simulated: {effects} ({s['route']} route, {s['method']}, rtol {s['rtol']:g}, "
        f"atol {s['atol']:g})",
    ]
    if body.get("designed_from_scene"):
        c = body["counts"]
        lines.append(
            f"body: designed from the scene's [body] ({body['shape']}, {body['candidates']} "
            f"candidates): {c['charges']} charges, {c['dipoles']} dipoles, {c['masses']} masses, "
            f"residual {body['residuals']['max_after_polish']:.2g}"
        )
    lines += [
        f"t = 0 .. {s['t_reached']:g} s of {s['t_end']:g} s: {s['steps']} steps, "
        f"{s['rhs_evaluations']} evaluations, {s['seconds']:.3g} s",
        f"I4 relative drift {s['I4_rel_drift']:.3g}; I3 max |I3| {s['I3_max']:.3g} J s"
        + (f" (level {s['level']})" if s["level"] else "")
        + f", drift {s['I3_max_dev']:.3g}",
        f"I1 relative drift {s['I1_rel_drift']:.3g}; max ||gamma|^2 - 1| {s['I2_max_dev']:.3g}",
    ]
    for event in s["events"]:
        lines.append(f"event: {event['kind']} at t = {event['t']:.6g} s")
    realises_theorem = {"mu", "V", "inertia"} <= set(body.get("realises", ()))
    if s["level"] == "I3=0" and (s["effects"] == ["theorem"] or realises_theorem):
        # a level of the order of C omega with omega ~ 1/s
        example = 0.5 * float(s["parameters"].get("C", 1.0))
        lines.append(
            f"on I3 = 0 the theorem's I4 is an integral; --off-level {example:g} starts off "
            "the level"
        )
    elif s["level"] is not None and s["level"] != "I3=0" and realises_theorem:
        lines.append(
            f"{s['level'].replace('=', ' = ')} is off the theorem's level I3 = 0: I4 is no "
            "integral there, I1 and I3 are"
        )
    notes = s["notes"]
    if body.get("designed_from_scene"):
        # already said on the body line
        notes = [n for n in notes if not n.startswith("body designed from the scene's")]
    lines += [f"note: {n}" for n in notes]
    lines += [f"wrote {f}" for f in s.get("files", [])]
    return "\n".join(lines)
