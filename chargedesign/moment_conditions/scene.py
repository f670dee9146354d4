"""The conditions of a scene: its parameters, fields, ``[design] realise`` and body size."""

from __future__ import annotations

from typing import Any

from chargedesign.candidates import candidates_from_table
from chargedesign.errors import ChargeDesignError
from chargedesign.formatting import PLAIN, fmt
from chargedesign.moment_conditions.constants import DEFAULT_LENGTH, REALISABLE
from chargedesign.moment_conditions.derive import derive_conditions, validate_realise
from chargedesign.moment_conditions.types import LinearConditions
from chargedesign.scene import Scene
from chargedesign.validation import input_error


def realise_from_scene(scene: Scene) -> tuple[str, ...]:
    """The ``[design] realise`` list of a scene (default: all of mu, V, inertia), validated."""
    value = scene.design.realise
    return validate_realise(list(REALISABLE if value is None else value), "design.realise")


def scene_length(scene: Scene) -> tuple[float | None, str]:
    """The body length scale of a scene (m): the largest distance of a candidate from O.

    The candidates of the scene's ``[body]`` table are built as the design stage builds them
    (:func:`chargedesign.candidates.candidates_from_table`), so the conditions command and
    the design choose the same default strengths. A scene with no usable ``[body]`` gives
    ``(None, reason)``: the conditions do not validate the body (the design does).
    """

    table = scene.body.table if scene.body is not None else {}
    if not table:
        return None, "the scene has no [body]"
    try:
        size = candidates_from_table(table, base_dir=scene.base_dir).geometry.size
    except ChargeDesignError as exc:
        return None, f"[body] not usable ({exc})"
    if not size > 0:
        return None, "the candidates all sit at O"
    return size, ""


def conditions_for_scene(
    scene: Scene, *, exact: bool = False, parameters: Any = None
) -> LinearConditions:
    """:func:`derive_conditions` for a scene's parameters, fields and ``[design] realise``.

    Default field strengths are chosen for the size of the scene's body
    (:func:`scene_length`), as :func:`chargedesign.designer.design_from_scene` does.
    ``parameters``: the parameters the body realises when they are not the scene's (the
    ``frame`` Larmor reading's n = 0; ``chargedesign conditions`` passes the design's).
    """

    if not isinstance(scene, Scene):
        raise input_error("scene", "a chargedesign.scene.Scene", scene)
    realise = realise_from_scene(scene)
    length, why = scene_length(scene)
    params = scene.parameters if parameters is None else parameters
    result = derive_conditions(params, scene.fields, realise, exact=exact, length=length)
    if result.length_assumed and why:
        result.notes.append(f"body length {fmt(DEFAULT_LENGTH, PLAIN)} m assumed: {why}")
    return result
