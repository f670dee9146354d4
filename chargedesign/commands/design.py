"""`chargedesign design [SCENE] [--out DIR]`: design the body and write it with its report.

Writes ``DIR/design.json``, ``DIR/report.md``, ``DIR/design.png`` (and ``DIR/bom.csv`` for a
physical body, a scene with ``[medium]``) together: they are
staged in a temporary directory and moved in only when all three exist, so a failed run
(infeasible targets, solver failure, or a failed picture) leaves earlier outputs untouched.
A failed picture fails the command (exit 2, one line naming the cause): the three files
describe one body and a stale picture beside a new design would mislead; ``--no-picture``
skips the picture deliberately (and removes an earlier ``design.png`` from DIR).

A scene with ``[case]`` (any case of (ep), docs/workbench.md) takes the same route, stage
for stage (:func:`chargedesign.designer.design_from_scene`, the same options, the same checks
before any work, the same files and ``--json`` shape), checked forward against the case's own
V and inertia; what no supported field realises is refused in one line. The tolerances are
measured against the theorem's mu, V and inertia: a case not of the theorem's form records
them as not applicable, with the reason (design.json ``tolerance``, ``--json``
``not_applicable``), never skipped in silence.

Before anything is written the body is checked forward (``chargedesign.checker``, the check
command's default tolerance and orientations, against the parameters the elements realise:
n = 0 for the ``frame`` Larmor reading): a body that misses the theorem is refused
with one line naming the cause (too large a requested total, a scale outside the supported
range, or insufficient forward accuracy), and DIR stays as it was (docs/reliability.md).
The ``linf`` objective (a dense problem) is capped at ``MAX_LINF_CANDIDATES`` candidates;
``--max-linf-candidates`` raises the cap.
"""

from __future__ import annotations

import argparse
from collections.abc import Callable
from typing import Any

from chargedesign.body import Design, write_design
from chargedesign.candidates import candidates_from_table
from chargedesign.commands.progress import Stages, progress_bar
from chargedesign.designer import design_from_scene
from chargedesign.designer.acceptance import forward_acceptance
from chargedesign.errors import ChargeDesignError, InputError
from chargedesign.files import atomic_directory, check_outputs, write_text_atomic
from chargedesign.flight.record import add_flight
from chargedesign.limits import MAX_LINF_CANDIDATES
from chargedesign.physical.bom import bom_csv
from chargedesign.report import plausibility, render_report, render_summary
from chargedesign.scene import load_scene
from chargedesign.sensitivity import check_theorem_design
from chargedesign.tolerancing import tolerance_report

#: the stages a design counts on stderr: candidates, conditions, the program, the frontier (a
#: physical body), the forward check, the tolerances, the picture, the files written
DESIGN_STAGES = 8


def run(args: argparse.Namespace) -> int:
    # before any work: the folder can be written and holds none of the inputs
    check_outputs([("--out", args.out, True)], inputs=[args.scene], writes=DESIGN_FILES)
    # each stage's message, and the stages counted against their total with the time left
    with progress_bar("design", "stages", args.quiet) as bar:
        stages = Stages(bar, DESIGN_STAGES)
        code = _run(args, stages)
        stages.end()
        return code


def _run(args: argparse.Namespace, progress: Callable[[str], None]) -> int:
    """One route for every scene, the theorem's and any ``[case]``: the same checks, design,
    forward check, files and printed summary. A stage that needs the theorem's form (the
    tolerances: :func:`_tolerance_stage`) is recorded as not applicable, with its reason, for
    a case of another form (design.json and ``--json`` ``not_applicable``)."""
    import json
    from pathlib import Path

    scene = load_scene(args.scene)
    _check_degenerate(scene)
    _check_linf_cap(scene, args)
    result = design_from_scene(scene, progress=progress, **_design_options(args))
    design = result.design
    if not args.no_forward_check:
        progress(
            "forward check ..."
            if scene.case is None
            else "forward check against the case's V and inertia ..."
        )
        _forward_check(design, args)
    not_applicable = _tolerance_stage(design, progress)
    add_flight(design)  # free fall: the release, its tolerance, the cameras (docs/flight.md)
    out = Path(args.out)
    # the body's whole record (a [case] scene's certificate verdict), made before it is written
    design = result.recorded_design(progress)
    files, report = _write(design, out, result.candidates.region, args.no_picture, progress)
    if args.json:
        summary = result.summary()
        summary = {
            "residuals": summary.pop("residuals"),
            "out": str(out),
            "files": files,
            **summary,
            "plausibility": plausibility(design),
            **({"not_applicable": not_applicable} if not_applicable else {}),
        }
        print(json.dumps(summary, indent=2, allow_nan=False))
    elif args.verbose:
        print(report, end="")
    else:
        print(render_summary(design, report=str(out / "report.md")), end="")
    return 0


def _tolerance_stage(design: Design, progress: Callable[[str], None]) -> dict[str, str]:
    """The tolerances of every element (design.json ``tolerance``), measured against the
    theorem's mu, V and inertia: a case not of the theorem's form has none to be measured
    against (:func:`chargedesign.sensitivity.check_theorem_design` says why), so its
    ``tolerance`` records ``applicable: false`` and the reason, and the reason is returned
    (``{"tolerance": reason}``, the summary's ``not_applicable``). A continuous body has no
    elements to place (no record, as before)."""
    if design.continuous:
        return {}
    try:
        check_theorem_design(design, "design")
    except InputError as exc:
        reason = str(exc)
        progress(f"tolerances: not applicable ({reason})")
        design.tolerance = {"applicable": False, "reason": reason}
        return {"tolerance": reason}
    progress("tolerances (exact first-order sensitivity of every element) ...")
    design.tolerance = tolerance_report(design).to_dict()
    return {}


def _write(
    design: Any, out: Any, region: Any, no_picture: bool, progress: Callable[[str], None]
) -> tuple[list[str], str]:
    """design.json, report.md, bom.csv (a physical body) and design.png written together
    into ``out`` (one swap). A file this body does not have (the picture
    with ``--no-picture``, the bill of materials of a point body) is dropped from ``out``: an
    earlier body's beside this design.json would mislead. Returns the names and the report."""
    physical = design.medium is not None
    files = (
        ["design.json", "report.md"]
        + (["bom.csv"] if physical else [])
        + ([] if no_picture else ["design.png"])
    )
    report = render_report(design, picture=None if no_picture else "design.png")
    stale = out / "design.png"
    had_picture = no_picture and stale.exists()
    drop = tuple(name for name in ("design.png", "bom.csv") if name not in files)
    with atomic_directory(out, drop=drop) as stage:
        write_design(design, stage / "design.json")
        write_text_atomic(stage / "report.md", report)
        if physical:
            write_text_atomic(stage / "bom.csv", bom_csv(design))
        if not no_picture:
            progress("rendering design.png ...")
            _render(design, stage / "design.png", region)
    if had_picture:
        progress(f"removed the earlier {stale} (--no-picture)")
    progress(f"wrote {', '.join(str(out / f) for f in files)}")
    return files, report


def _design_options(args: argparse.Namespace) -> dict[str, Any]:
    """The command line's [design] options (None: the scene's), for every route."""
    return {
        "objective": args.objective,
        "robust_weight": args.robust_weight,
        "solver": args.solver,
        "n_charges": args.n_charges,
        "max_charge": args.max_charge,
        "total_charge": args.total_charge,
        "total_mass": args.total_mass,
        "polish": False if args.no_polish else None,
    }


#: every file the design command may write into its folder
DESIGN_FILES = ("design.json", "report.md", "bom.csv", "design.png")


def _check_degenerate(scene: object) -> None:
    """A request that would design nothing is refused (``[design] realise = []``)."""

    if scene.design.realise == ():  # type: ignore[attr-defined]
        raise InputError(
            "design.realise: empty, the body would realise nothing; name at least one of mu, "
            "V, inertia (or drop the key for all the scene calls for)"
        )


def _check_linf_cap(scene: object, args: argparse.Namespace) -> None:
    """Refuse an linf design on more candidates than the cap (before the dense solve)."""

    objective = args.objective or scene.design.objective  # type: ignore[attr-defined]
    if objective != "linf":
        return
    cap = MAX_LINF_CANDIDATES if args.max_linf_candidates is None else args.max_linf_candidates
    body = scene.body.table if scene.body is not None else {}  # type: ignore[attr-defined]
    n = len(candidates_from_table(body, base_dir=scene.base_dir))  # type: ignore[attr-defined]
    if n > cap:
        raise InputError(
            f"the linf objective on {n} candidates exceeds the cap of {cap} (a dense "
            "problem: time and memory grow fast); use l1, a coarser [body] spacing, or "
            "--max-linf-candidates N"
        )


def _forward_check(design: object, args: argparse.Namespace) -> None:
    """The check command's verdict on the body before it is written; one line if it fails
    (:func:`chargedesign.designer.acceptance.forward_acceptance`, the frontier's too)."""

    forward_acceptance(
        design,  # type: ignore[arg-type]
        totals_requested=args.total_charge is not None or args.total_mass is not None,
    )


def _render(design: object, path: object, region: object) -> None:
    """Render the picture; any failure becomes a one-line ChargeDesignError (nothing written)."""
    try:
        from chargedesign.viz import render_screenshot, too_many_elements

        if problem := too_many_elements(design):  # type: ignore[arg-type]
            raise InputError(problem)  # the one line, as the picture's kernel no longer raises it
        render_screenshot(design, path, region=region)  # type: ignore[arg-type]
    except ChargeDesignError as exc:
        raise ChargeDesignError(
            f"rendering design.png failed ({exc}); nothing was written (--no-picture skips it)"
        ) from exc
    except Exception as exc:  # VTK/OpenGL failures come as many types
        raise ChargeDesignError(
            f"rendering design.png failed ({type(exc).__name__}: {exc}); nothing was written "
            "(--no-picture skips the picture)"
        ) from exc
