"""`chargedesign simulate [SCENE_OR_DESIGN]`: motion under the effects the scene calls for.

No argument: the embedded default scene (theorem parameters only: the ``theorem`` effect).
A ``.json`` argument is a design file; anything else is a scene (TOML). Files are written
only with ``--out DIR`` or a scene's ``[output] dir``.
"""

from __future__ import annotations

import argparse
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
        "--poincare", action="store_true", help="record a Poincare section (poincare.png)"
    )
    parser.add_argument("--json", action="store_true", help="print the JSON summary")
    parser.add_argument(
        "--progress",
        action=argparse.BooleanOptionalAction,
        default=None,
        help="progress bar on stderr (default: when stderr is a terminal)",
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
    import json

    from chargedesign.simulate import setup_from_source, simulate

    if args.t_end is not None and not args.t_end > 0:
        raise ChargeDesignError(f"--t-end: expected a duration > 0, got {args.t_end}")
    show_bar = sys.stderr.isatty() if args.progress is None else args.progress
    bar = _ProgressBar() if show_bar else None
    setup = setup_from_source(args.source)
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
            progress=bar,
        )
    finally:
        if bar is not None:
            bar.close()
    # the scene's [output] options; --out wins over its dir
    out_dir = args.out or setup.output.dir
    summary = result.summary()
    if out_dir:
        files = result.write(
            out_dir,
            trajectory=setup.output.trajectory,
            plot=setup.output.plot,
            poincare_axes=setup.output.poincare_axes,
        )
        summary["files"] = [str(f) for f in files]
    if args.json:
        print(json.dumps(summary, indent=2, allow_nan=False))
        return 0
    print(_human(summary))
    return 0


def _human(s: dict) -> str:
    effects = ", ".join(s["effects"]) or "none (torque-free)"
    lines = [
        f"simulated: {effects} ({s['route']} route, {s['method']}, rtol {s['rtol']:g}, "
        f"atol {s['atol']:g})",
        f"t = 0 .. {s['t_reached']:g} s of {s['t_end']:g} s: {s['steps']} steps, "
        f"{s['rhs_evaluations']} evaluations, {s['seconds']:.3g} s",
        f"I4 relative drift {s['I4_rel_drift']:.3g}; I3 max |I3| {s['I3_max']:.3g} J s"
        + (f" (level {s['level']})" if s["level"] else "")
        + f", drift {s['I3_max_dev']:.3g}",
        f"I1 relative drift {s['I1_rel_drift']:.3g}; max ||gamma|^2 - 1| {s['I2_max_dev']:.3g}",
    ]
    for event in s["events"]:
        lines.append(f"event: {event['kind']} at t = {event['t']:.6g} s")
    lines += [f"note: {n}" for n in s["notes"]]
    lines += [f"wrote {f}" for f in s.get("files", [])]
    return "\n".join(lines)
