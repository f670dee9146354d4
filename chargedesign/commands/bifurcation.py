"""`chargedesign bifurcation [SCENE] [--h-range LO HI] [--out DIR]`: the shape of the motion.

The critical set of the momentum map (H, I4) on the level ``I3 = 0, |gamma| = 1`` of the
scene's parameters, its image (the bifurcation diagram) with the stability type of each
branch, and the number of Liouville tori in each chamber. Writes ``DIR/bifurcation.csv``
(``h, k, branch, type, p, q, r, gamma1, gamma2, gamma3``; consecutive rows of a branch are
neighbours along it) and ``DIR/bifurcation.png`` (default DIR ``out/``). With ``--at H``
also ``DIR/bifurcation_at.png``: the diagram with the line h = H beside the Poincare atlas
on I3 = 0 (the orbits on critical values of k marked) and the FLI map at 64 x 48 (heyoka;
about a minute). With ``--tori H K`` only the number of tori of the level H = h, I4 = k is
printed (``{"h": h, "k": k, "tori": n}`` with ``--json``; 0 for an empty level; a critical
value refused in one line naming its branch), nothing written. lambda or rho != 0 is refused
(see docs/bifurcation.md).

A scene with a ``[case]`` table (or a bare case file) draws that case's diagram of (H, F)
on ``I3 = --level`` (default: the case's own level, or 0 for a general claim), with the same
files; a conditional case asked for another level, a singular case and a case given by
``mu`` alone are refused in one line (docs/workbench.md). Both go through the one route,
:func:`~chargedesign.topology.diagram.bifurcation_diagram`: a case that is the theorem's
catalogue entry on I3 = 0 gets the theorem's diagram.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from fractions import Fraction
from typing import TYPE_CHECKING, Any

from chargedesign.commands.progress import Progress
from chargedesign.errors import InputError
from chargedesign.files import atomic_directory, check_outputs
from chargedesign.formatting import CELL, PLAIN, fmt
from chargedesign.scene import load_scene
from chargedesign.topology.compute import STAGES
from chargedesign.topology.diagram import BifurcationDiagram, bifurcation_diagram, energy_range
from chargedesign.topology.links import linked_pictures
from chargedesign.topology.tori import tori_at
from chargedesign.validation import exact_decimal

if TYPE_CHECKING:
    from chargedesign.params import Parameters
    from chargedesign.scene.case_file import Case


def run(args: argparse.Namespace) -> int:
    if args.tori is not None:
        return _tori(args)
    check_outputs(
        [("--out", args.out, True)],
        inputs=[args.scene],
        writes=("bifurcation.csv", "bifurcation.png", "bifurcation_at.png"),
    )
    scene = load_scene(args.scene)
    h_range = None if args.h_range is None else (args.h_range[0], args.h_range[1])
    model: Case | Parameters
    level: Fraction | None = None
    if "case" in scene.tables:
        assert scene.case is not None
        model = scene.case
        if args.at is not None:
            raise InputError("--at: the atlas is drawn for the theorem's scenes only, not a [case]")
        level = case_level(model, args.level)
    else:
        model = scene.parameters
        if args.level is not None:
            raise InputError("--level: for a [case] scene; the theorem's diagram is on I3 = 0")
    if args.at is not None:
        lo, hi = energy_range(scene.parameters, h_range)
        if not lo < args.at < hi:
            raise InputError(
                f"--at: expected an energy inside {fmt(lo, CELL)} .. {fmt(hi, CELL)} J, got"
                f" {fmt(args.at, PLAIN)}"
            )
    # the diagram's stages (STAGES), the --at atlas and the files, against their total
    total = len(STAGES) + (args.at is not None) + 1
    with _stage_progress(args.quiet, total) as tally:
        diagram = bifurcation_diagram(model, h_range, tally=tally, level=level)
        linked = None
        if args.at is not None:
            assert isinstance(diagram, BifurcationDiagram)
            linked = linked_pictures(diagram, args.at, orbits=20, t_end=200.0, fli_t_end=10.0)
            if tally is not None:
                tally(total - 1, total)
        # every file or none; a picture at another energy from an earlier run is not kept
        stale = () if linked is not None else ("bifurcation_at.png",)
        with atomic_directory(args.out, drop=stale) as stage:
            diagram.write(args.out)
            if linked is not None:
                linked.plot().savefig(stage / "bifurcation_at.png", dpi=90)
        if tally is not None:
            tally(total, total)
    if args.json:
        print(diagram.to_json())
    else:
        print(str(diagram), end="")
        if linked is not None:
            print(str(linked), end="")
        names = ["bifurcation.csv", "bifurcation.png"] + (["bifurcation_at.png"] if linked else [])
        print("wrote " + ", ".join(f"{args.out}/{name}" for name in names))
    return 0


@contextmanager
def _stage_progress(quiet: bool, total: int) -> Iterator[Callable[[int, int], None] | None]:
    """``tally(done, _)`` for the diagram's stages (None with ``--quiet``), its
    :class:`~chargedesign.commands.progress.Progress` started when the energy range's stage
    ends: the route's refusals (a case without a diagram, an energy range without motion or
    scale) come before it, so their one line is all a refused run says."""
    if quiet:
        yield None
        return
    checked = STAGES.index("energy range") + 1
    bar: Progress | None = None

    def tally(done: int, _: int) -> None:
        nonlocal bar
        if done < checked:
            return
        if bar is None:
            bar = Progress("bifurcation", unit="stages")
            bar.say("bifurcation: critical set, continuation, chambers ...")
        bar.update(done, total)

    try:
        yield tally
    finally:
        if bar is not None:
            bar.close()


def case_level(case: Any, text: str | None) -> Fraction:
    """The I3 level of a case's diagram: ``--level`` read exactly (a number or a fraction;
    never through sympy), which a conditional case allows only at its own level."""
    if text is None:
        return Fraction(0) if case.level is None else Fraction(str(case.level))
    level = exact_decimal(text, "--level", fraction=True)  # its size checked on the text
    if case.level is not None and level != Fraction(str(case.level)):
        raise InputError(
            f"--level: case {case.name}'s integral holds on I3 = {case.level} only, not on"
            f" I3 = {level}"
        )
    return level


def _tori(args: argparse.Namespace) -> int:
    """``--tori H K``: the count at one point, nothing written."""
    if args.at is not None or args.h_range is not None:
        raise InputError("--tori: counts one level; --at and --h-range do not apply with it")
    scene = load_scene(args.scene)
    if "case" in scene.tables:
        raise InputError(
            f"{scene.source}: --tori counts the theorem's levels; a [case] scene's diagram"
            " gives each chamber's tori (run without --tori)"
        )
    if not args.quiet:
        print("bifurcation: counting tori by the flow ...", file=sys.stderr, flush=True)
    count = tori_at(scene.parameters, args.tori[0], args.tori[1])
    print(count.to_json() if args.json else str(count).rstrip("\n"))
    return 0
