"""A scene's ``[body]`` region designed when a run first needs its elements.

:func:`design_pending` runs :func:`chargedesign.designer.design_from_scene` with the scene's
``[design]`` once per :class:`~chargedesign.simulation.setup.SimulationSetup`; a run whose
effects are only ``theorem`` (:func:`needs_elements` false) does not design it.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence

from chargedesign.errors import InfeasibleError
from chargedesign.formatting import ROUGH, fmt
from chargedesign.simulation.setup import SimulationSetup, body_counts
from chargedesign.simulation.system import (
    EFFECTS,
    Body,
)


def needs_elements(effects: Sequence[str] | None) -> bool:
    """True unless the effects asked for are only the theorem's reduced model."""
    if effects is None:
        return True
    return any(name != "theorem" for name in effects if name in EFFECTS)


def design_pending(
    setup: SimulationSetup, progress: Callable[[str], None] | None = None
) -> SimulationSetup:
    """Design the body of a setup whose scene gives a ``[body]`` region (once; in place).

    Runs :func:`chargedesign.designer.design_from_scene` with the scene's ``[design]`` table and
    replaces ``setup.body`` by the designed elements in the scene's fields (each kind the
    scene gives replaces the design's). Does nothing when nothing is pending.

    Parameters
    ----------
    setup : SimulationSetup
    progress : callable, optional
        ``progress(message)`` with the designer's stages.

    Returns
    -------
    SimulationSetup
        The same setup, designed.

    Raises
    ------
    InfeasibleError
        The scene's targets cannot be realised in its region (the message says how to
        simulate the reduced model instead).
    InputError, SolverError
        As :func:`~chargedesign.designer.design_from_scene`.
    """
    scene = setup.design_scene
    if scene is None:
        return setup
    # here, not at import: the designer loads scipy.sparse and scipy.linalg (about 0.4 s of
    # CPU), which a run of a written design.json never calls (tests/test_startup.py)
    from chargedesign.designer import design_from_scene

    t0 = time.perf_counter()
    try:
        result = design_from_scene(scene, progress=progress, frontier=False)
    except InfeasibleError as exc:
        raise InfeasibleError(
            f"{exc} (to simulate the theorem's reduced model instead: effects = ['theorem'])"
        ) from exc
    seconds = time.perf_counter() - t0
    design = result.design
    body = Body.from_design(design, dict(scene.fields))
    summary = result.summary()
    residuals = summary["residuals"]
    shape = str(scene.body.table.get("shape"))
    counts = body_counts(body)
    setup.body = body
    setup.design = design
    setup.design_scene = None
    setup.body_info = {
        "designed_from_scene": True,
        "origin": f"designed from the scene's [body] (shape = {shape!r})",
        "counts": counts,
        "shape": shape,
        "candidates": len(result.candidates),
        "residuals": {
            "max_after_polish": residuals["max_after_polish"],
            "tolerance": residuals["tolerance"],
            "after_polish": dict(residuals["after_polish"]),
            "before_polish": dict(residuals["before_polish"]),
        },
        "realises": list(design.realises),
        "fields": {kind: list(coeffs) for kind, coeffs in body.fields.items()},
        "design_seconds": seconds,
    }
    setup.notes.append(
        f"body designed from the scene's [body] ({shape}, {len(result.candidates)} "
        f"candidates): {counts['charges']} charges, {counts['dipoles']} dipoles, "
        f"{counts['masses']} masses; largest relative residual "
        f"{fmt(residuals['max_after_polish'], ROUGH)} (tolerance"
        f" {fmt(residuals['tolerance'], ROUGH)}); "
        f"realises {', '.join(design.realises) or 'nothing'}"
    )
    missing = [k for k in ("mu", "V", "inertia") if k not in design.realises]
    if missing:
        setup.notes.append(
            f"the design does not realise {', '.join(missing)}: I4 is the theorem's integral "
            "only for a body that realises mu, V and inertia"
        )
    setup.notes += [f"design: {note}" for note in result.notes]
    setup.notes += body.notes
    return setup
