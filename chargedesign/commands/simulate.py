"""`chargedesign simulate [SCENE_OR_DESIGN]`: motion under the effects the scene calls for.

No argument: the embedded default scene, whose ``[body]`` region is designed on the fly and
simulated from its own elements (lorentz, electric, magnetization, gravity) on the level
``I3 = 0``; ``--off-level I3`` starts off it. A scene with a ``[body] shape`` is designed the
same way unless its effects are only ``theorem`` (the reduced model). A ``.json`` argument is a
design file; anything else is a scene (TOML). Files are written only with ``--out DIR`` or a
scene's ``[output] dir`` (plus ``design.json`` of a body designed here).

The default integrator is ``taylor`` (heyoka; DOP853 with a note where heyoka is missing). A
scene whose ``[initial]`` gives ``states`` or ``file`` runs them all as an ensemble
(``summary.json`` and ``ensemble.csv``). ``--atlas`` draws the Poincare atlas (orbits on one
energy level on and off I3 = 0, ``atlas.png`` and ``atlas.csv``); ``--fli`` adds the fast
Lyapunov indicator map (``fli.png``).
"""

from __future__ import annotations

import argparse
import sys
from typing import Any

from chargedesign.body import write_design
from chargedesign.commands.progress import Progress
from chargedesign.errors import ChargeDesignError, InputError
from chargedesign.files import atomic_directory, check_outputs
from chargedesign.formatting import CELL, PLAIN, fmt
from chargedesign.limits import MAX_PERIODS
from chargedesign.scene.keys import KEY
from chargedesign.simulation import (
    SimulationSetup,
    fli_map,
    poincare_atlas,
    prepare,
    setup_from_source,
    simulate,
    simulate_ensemble,
)
from chargedesign.simulation.result import summary_text
from chargedesign.validation import check_periods
from chargedesign.vocabulary import SIMULATION_AXES

#: orbits per level of --atlas when --orbits is not given
ATLAS_ORBITS = 50


def run(args: argparse.Namespace) -> int:
    import contextlib
    import json
    from pathlib import Path

    for option, given, what in (
        ("--orbits", args.orbits is not None, "the Poincare atlas's orbits per level"),
        ("--fli", args.fli, "the fast Lyapunov indicator map beside the atlas"),
    ):
        if given and not args.atlas:  # an option that needs its companion is refused without it
            raise InputError(f"{option}: sets {what}; give --atlas too")
    # --t-end, --off-level, --orbits: their ranges are checked by the command line before
    # this runs (chargedesign.limits.OPTION_RANGES, shown in --help)
    if args.axes is not None and args.axes not in SIMULATION_AXES:
        raise ChargeDesignError(
            f"--axes: expected one of {', '.join(SIMULATION_AXES)}, got {args.axes!r}"
        )
    _check_out(args, None)
    setup = setup_from_source(args.source)
    _check_out(args, setup)
    _check_work(args, setup)
    designing = setup.design_scene is not None
    if args.atlas:
        return _atlas(args, setup)
    # the run's progress on stderr: a bar on a terminal, a line every few seconds without one
    # (--no-progress: none; the default simulate once ran 596 s saying nothing); closed on
    # every path below (its heartbeat is a thread)
    bar = Progress("simulate") if args.progress is not False else None
    if isinstance(setup.initial, dict) and "states" in setup.initial:
        return _ensemble(args, setup, bar)

    def design_progress(message: str) -> None:
        if args.progress is not False:
            print(f"designing body: {message}", file=sys.stderr, flush=True)

    try:
        result = simulate(
            setup,
            **_options(args),
            poincare=True if args.poincare else None,
            level=args.off_level,
            # always a callback: the integrator returns to Python every step, so SIGINT stops
            # the run at once (without one, heyoka ran on in C++ for seconds)
            progress=bar if bar is not None else _interruptible,
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
    # the folder holds exactly this run's files: an earlier run's others are dropped
    with atomic_directory(out_dir, drop=SIMULATE_FILES) if out_dir else contextlib.nullcontext():
        if out_dir and result.body and result.body.get("designed_from_scene"):
            # the body designed here, beside its motion (chargedesign show/check read it)
            design_path = Path(out_dir) / "design.json"
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
    print(summary_text(summary))
    return 0


def _interruptible(fraction: float) -> None:
    """A progress callback that draws nothing: the integrator's steps return to Python, where a
    pending SIGINT is raised."""


#: every file simulate may write into its folder (a run drops the earlier run's others)
SIMULATE_FILES = (
    "design.json",
    "summary.json",
    "trajectory.npz",
    "trajectory.csv",
    "integrals.png",
    "poincare.png",
    "ensemble.csv",
    "atlas.png",
    "atlas.csv",
    "fli.png",
)


def _check_out(args: argparse.Namespace, setup: SimulationSetup | None) -> None:
    """The output folder, before any work (chargedesign.files.check_outputs): ``--out`` (or
    the atlas's default) before the source is read; a scene's ``[output] dir`` after."""

    inputs = [args.source]
    if setup is None:
        out = args.out or ("out/atlas" if args.atlas else None)
        check_outputs([("--out", out, True)], inputs=inputs, writes=SIMULATE_FILES)
        return
    import os

    origin = setup.body_info.get("origin")  # a scene's body.design file
    if isinstance(origin, str) and os.path.isfile(origin):
        inputs.append(origin)
    if args.out is None and not args.atlas:
        check_outputs(
            [("output.dir", setup.output.dir, True)],
            inputs=inputs,
            writes=SIMULATE_FILES,
        )
    elif args.out is not None:
        check_outputs([("--out", args.out, True)], inputs=inputs, writes=SIMULATE_FILES)


def _check_work(args: argparse.Namespace, setup: SimulationSetup) -> None:
    """The work a run asks for, estimated before it starts (chargedesign.limits): periods of
    the body's fastest rate over t_end (``effects = []``, a free motion, is said by the run's
    notes: "no effect acts: torque-free motion")."""

    options = setup.options
    if args.atlas:
        t_end, option = args.t_end or 500.0, "--t-end"
    elif args.t_end is not None:
        t_end, option = args.t_end, "--t-end"
    else:
        t_end, option = options.t_end, "simulation.t_end"
    cap = MAX_PERIODS if args.max_periods is None else args.max_periods
    check_periods(
        t_end,
        setup.body.parameters,
        setup.initial,
        cap,
        option,
        "--max-periods N",
    )


def _options(args: argparse.Namespace) -> dict:
    """The run's options from the command line (None: the scene's), for one run and an
    ensemble alike."""
    return {
        "effects": args.effects,
        KEY.t_end: args.t_end,
        "rtol": args.rtol,
        "atol": args.atol,
        "method": args.method,
        "step": args.step,
        "samples": args.samples,
        "route": args.route,
        "tol": args.tol,
        "monitors": args.monitors,
        "axes": args.axes,
    }


def _ensemble(args: argparse.Namespace, setup: SimulationSetup, bar: Progress | None) -> int:
    import json

    try:
        result = simulate_ensemble(setup, progress=bar, **_options(args))
    finally:
        if bar is not None:
            bar.close()
    summary = result.summary()
    out_dir = args.out or setup.output.dir
    if out_dir:
        summary["files"] = [str(f) for f in result.write(out_dir)]
    if args.json:
        print(json.dumps(summary, indent=2, allow_nan=False))
    else:
        print(str(result))
        for f in summary.get("files", []):
            print(f"wrote {f}")
    return 0


def _atlas(args: argparse.Namespace, setup: SimulationSetup) -> int:
    import json
    from pathlib import Path

    from matplotlib.backends.backend_agg import FigureCanvasAgg

    orbits = ATLAS_ORBITS if args.orbits is None else args.orbits
    system, _, _, _, _ = prepare(setup, effects=args.effects, route=args.route)
    out = Path(args.out or "out/atlas")
    off = args.off_level if args.off_level is not None else 0.5 * system.C
    if off == 0.0:
        raise ChargeDesignError("--off-level: the atlas needs a level other than I3 = 0")
    t_end = args.t_end or 500.0
    atlas = poincare_atlas(system, off_level=off, orbits=orbits, t_end=t_end)
    fmap = fli_map(system, off_level=off, t_end=min(t_end, 100.0)) if args.fli else None
    # everything is computed first; the folder then changes in one swap (all or nothing)
    with atomic_directory(out) as stage:
        fig = atlas.plot()
        FigureCanvasAgg(fig)
        fig.savefig(stage / "atlas.png", dpi=110)
        atlas.write_csv(stage / "atlas.csv")
        if fmap is not None:
            fig = fmap.plot()
            FigureCanvasAgg(fig)
            fig.savefig(stage / "fli.png", dpi=110)
    files = [str(out / "atlas.png"), str(out / "atlas.csv")]
    summary: dict[str, Any] = {
        "energy": atlas.energy,
        "levels": list(atlas.levels),
        "orbits": orbits,
        KEY.t_end: t_end,
        "points": [sum(len(p) for p in level) for level in atlas.points],
        "seconds": atlas.seconds,
        "effects": list(system.effects),
    }
    if fmap is not None:
        files.append(str(out / "fli.png"))
        summary["fli_median"] = [float(_nanmedian(f)) for f in fmap.fli]
        summary["fli_seconds"] = fmap.seconds
    summary["files"] = files
    if args.json:
        print(json.dumps(summary, indent=2, allow_nan=False))
        return 0
    print(
        f"Poincare atlas: {orbits} orbits per level at energy {fmt(atlas.energy, CELL)} J, "
        f"I3 = {fmt(atlas.levels[0], PLAIN)} and {fmt(atlas.levels[1], PLAIN)} J s, t = "
        f"{fmt(t_end, PLAIN)} s: "
        f"{summary['points'][0]} and {summary['points'][1]} section points in "
        f"{fmt(atlas.seconds)} s"
    )
    if args.fli:
        m0, m1 = summary["fli_median"]
        print(
            f"FLI median on I3 = 0: {fmt(m0)}; off the level: {fmt(m1)} "
            f"({fmt(summary['fli_seconds'])} s)"
        )
    print("\n".join(f"wrote {f}" for f in files))
    return 0


def _nanmedian(values: object) -> float:
    import numpy as np

    arr = np.asarray(values, dtype=float)
    return float(np.nanmedian(arr)) if np.any(np.isfinite(arr)) else float("nan")
