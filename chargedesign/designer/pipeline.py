"""The design stages end to end: one source, the whole body, a scene.

For each source: build the nondimensional system (:mod:`~chargedesign.designer.system`),
diagnose it (:mod:`~chargedesign.designer.diagnostics`), solve
(:mod:`~chargedesign.designer.solve`), polish (:mod:`~chargedesign.designer.polish`), verify
the residual and assess the forward accuracy (:mod:`~chargedesign.designer.accuracy`).
:func:`design_body` checks every source's system before solving any and assembles the
:class:`~chargedesign.body.Design`.
"""

from __future__ import annotations

import dataclasses
import time
from dataclasses import dataclass
from typing import Any

import numpy as np

from chargedesign.body import Design
from chargedesign.candidates import CandidateSet, candidates_from_points, candidates_from_table
from chargedesign.designer.accuracy import FORWARD_LIMIT, FORWARD_NOTE, ForwardInputs, length_notes
from chargedesign.designer.diagnostics import diagnose, infeasible_inequalities
from chargedesign.designer.frontier import FrontierResult, find_frontier
from chargedesign.designer.options import DesignOptions, Progress
from chargedesign.designer.physical import design_physical, setup_physical
from chargedesign.designer.polish import polish_weights, support_of
from chargedesign.designer.result import DesignResult, SourceResult, record_provenance
from chargedesign.designer.robust import robust_costs
from chargedesign.designer.solve import solve_problem
from chargedesign.designer.solvers import InfeasibleProblem
from chargedesign.designer.system import (
    UNITS,
    DesignProblem,
    build_problem,
    group_norms,
    relative_residual,
)
from chargedesign.errors import InfeasibleError, InputError, SolverError
from chargedesign.formatting import PLAIN, ROUGH, fmt
from chargedesign.larmor import LarmorReading, body_parameters
from chargedesign.moment_conditions import (
    SOURCES,
    LinearConditions,
    derive_conditions,
    realise_from_scene,
)
from chargedesign.params import Parameters
from chargedesign.physical.realism import K_LAW_KEY, k_law
from chargedesign.scene import Scene
from chargedesign.validation import input_error


def design_source(
    source: str,
    conditions: LinearConditions,
    candidates: CandidateSet,
    options: DesignOptions,
    *,
    progress: Progress | None = None,
    params: Parameters | None = None,
) -> tuple[np.ndarray, SourceResult]:
    """Design one source's weights on the candidates.

    With ``params`` the weights' forward accuracy is assessed as in :func:`design_body`
    (a note when the conditions are met only by cancellation, a refusal beyond
    ``FORWARD_LIMIT``).

    Returns
    -------
    weights : ndarray, shape (n,) or (n, 3)
        SI units (C, A m^2 or kg), on every candidate (zeros off the support).
    result : SourceResult

    Raises
    ------
    InfeasibleError, SolverError
    """
    t0 = time.perf_counter()
    p = build_problem(source, conditions, candidates.points, options)
    p = _with_robust_costs(p, candidates.points, conditions, params, options)
    rank, notes = diagnose(p, candidates.geometry)
    forward = None
    if params is not None:
        realise = options.realise if options.realise is not None else conditions.realise
        forward = ForwardInputs.build(params, conditions, candidates, realise)
    return _design_problem(p, rank, notes, options, t0, progress, forward)


def _with_robust_costs(
    p: DesignProblem,
    points: np.ndarray,
    conditions: LinearConditions,
    params: Parameters | None,
    options: DesignOptions,
) -> DesignProblem:
    """``p`` with the robust objective's costs when its source is designed robustly."""
    if options.objective_for(p.source) != "robust":
        return p
    if params is None:
        raise InputError(f"design.objective: robust {p.source} need the parameters (params=)")
    costs = robust_costs(points, p.source, conditions.fields, params, options.robust_weight)
    return p.with_costs(costs)


def _design_problem(
    p: DesignProblem,
    rank: int,
    notes: list[str],
    options: DesignOptions,
    t0: float,
    progress: Progress | None,
    forward: ForwardInputs | None = None,
) -> tuple[np.ndarray, SourceResult]:
    source = p.source
    objective = options.objective_for(source)
    p.rank = rank
    n_cand = p.n_candidates
    shape = (n_cand, 3) if p.group == 3 else (n_cand,)
    if not np.any(p.b):
        # every condition is homogeneous: no element of this source is needed
        return np.zeros(shape), SourceResult(
            source=source,
            objective=objective,
            objective_value=0.0,
            objective_value_raw=0.0,
            units=UNITS[source],
            solver="none",
            method="all conditions are zero: no elements needed",
            status="optimal",
            n_conditions=len(p.b),
            rank=rank,
            n_candidates=n_cand,
            n_elements=0,
            residual_before=0.0,
            residual_after=0.0,
            seconds=time.perf_counter() - t0,
            notes=notes,
        )
    if progress is not None:
        progress(f"{source}: {objective} problem, {len(p.b)} conditions, {n_cand} candidates")
    try:
        sol = solve_problem(p, objective, options, progress)
    except InfeasibleProblem:
        raise infeasible_inequalities(p, options) from None
    if sol.u is None or not np.all(np.isfinite(sol.u)):
        raise SolverError(f"{source}: solver {sol.solver} returned no finite solution")
    raw = sol.u * p.scale
    before = relative_residual(p.A, raw, p.b)
    u = sol.u
    polish_text = "not polished"
    if options.polish:
        u, polish_text = polish_weights(p, sol.u, options.tolerance)
    weights = u * p.scale
    after = relative_residual(p.A, weights, p.b)
    worst, cancellation = forward.assess(p, weights) if forward is not None else (None, "")
    cancels = worst is not None and worst.forward_error > FORWARD_NOTE
    if after > options.tolerance:
        if options.tolerance < 2 * np.finfo(float).eps:
            raise SolverError(
                f"{source}: relative residual {fmt(after, ROUGH)} exceeds design.tol = "
                f"{fmt(options.tolerance, PLAIN)}, which is below the rounding of double precision "
                f"({fmt(np.finfo(float).eps, ROUGH)}): raise design.tol"
            )
        if cancels:
            # the solver is not at fault: the targets are tiny against what the weights carry
            raise InfeasibleError(
                f"{source}: relative residual {fmt(after, ROUGH)} exceeds design.tol = "
                f"{fmt(options.tolerance, PLAIN)}, most likely because {cancellation} (another "
                "solver will not help)"
            )
        raise SolverError(
            f"{source}: relative residual {fmt(after, ROUGH)} exceeds design.tol = "
            f"{fmt(options.tolerance, PLAIN)} ({sol.solver}, {polish_text}); try another solver"
        )
    if worst is not None and worst.forward_error > FORWARD_LIMIT:
        raise InfeasibleError(
            f"{source}: refused, {cancellation} (beyond {fmt(FORWARD_LIMIT, PLAIN)} the body "
            "realises nothing reliably)"
        )
    if cancels:
        notes.append(f"{source}: {cancellation}")
    if p.nonneg and np.any(weights < 0):
        raise SolverError(f"{source}: a negative mass survived polishing ({fmt(weights.min())} kg)")
    support = support_of(u, p.group, 0.0)
    if sol.status != "optimal" and before > options.tolerance:
        notes.append(
            f"{source}: {sol.solver} reported {sol.status!r} at its tightened tolerances; "
            "the residuals were verified here"
        )
    notes.extend(sol.notes)
    result = SourceResult(
        source=source,
        objective=objective,
        objective_value=_objective_value(weights, p.group, objective, p.cost),
        objective_value_raw=_objective_value(raw, p.group, objective, p.cost),
        units=UNITS[source],
        solver=sol.solver,
        method=f"{sol.method}; {polish_text}",
        status="optimal",
        n_conditions=len(p.b),
        rank=rank,
        n_candidates=n_cand,
        n_elements=len(support),
        residual_before=before,
        residual_after=after,
        seconds=time.perf_counter() - t0,
        notes=notes,
        forward=worst,
    )
    return weights.reshape(shape), result


def _objective_value(
    w: np.ndarray, group: int, objective: str, cost: np.ndarray | None = None
) -> float:
    mags = group_norms(w) if group == 3 else np.abs(w)
    if len(mags) == 0:
        return 0.0
    if objective == "robust" and cost is not None:
        return float(np.sum(cost * mags))
    if objective in ("l1", "robust"):
        return float(np.sum(mags))
    if objective == "l2":
        return float(np.sqrt(np.sum(mags**2)))
    return float(np.max(mags))


def design_body(
    params: Parameters,
    conditions: LinearConditions,
    candidates: CandidateSet | np.ndarray,
    options: DesignOptions | None = None,
    *,
    progress: Progress | None = None,
) -> DesignResult:
    """Design charges, dipoles and masses on candidate points that meet the conditions.

    Parameters
    ----------
    params : Parameters
        The theorem's parameters (SI units).
    conditions : LinearConditions
        From :func:`chargedesign.moment_conditions.derive_conditions`; its ``fields`` are written
        into the design.
    candidates : CandidateSet or ndarray, shape (n, 3)
        Candidate positions in body axes, m.
    options : DesignOptions, optional
    progress : callable, optional
        Called with a short message before each long step.

    Returns
    -------
    DesignResult

    Raises
    ------
    InfeasibleError
        The conditions cannot be met on these candidates (the message names them), or only
        by a cancellation that leaves the body meaningless (estimated forward error above
        ``FORWARD_LIMIT``; the message names the cause and the remedy).
    SolverError
        A solver failed or its polished result misses ``options.tolerance``.

    Notes
    -----
    The design meets ``conditions`` as given. When their default field strengths were chosen
    for an assumed 1 m body (``conditions.length_assumed``) and these candidates call for
    other ones, a note gives them (derive the conditions with ``length=`` the candidates'
    size, as :func:`design_from_scene` does). Every source's delivered weights are assessed
    for cancellation (:func:`forward_accuracy`): above ``FORWARD_NOTE`` the notes say which
    quantity is met only by cancellation, the forward accuracy to expect and the remedy.
    """
    if not isinstance(params, Parameters):
        raise input_error("params", "a chargedesign.params.Parameters", params)
    if not isinstance(conditions, LinearConditions):
        raise input_error(
            "conditions", "a chargedesign.moment_conditions.LinearConditions", conditions
        )
    options = options or DesignOptions()
    cand = (
        candidates if isinstance(candidates, CandidateSet) else candidates_from_points(candidates)
    )
    realise = tuple(conditions.realise) if conditions.realise else ()
    if options.realise is not None:
        if conditions.realise and set(options.realise) != set(conditions.realise):
            raise InputError(
                f"design.realise: the conditions realise {list(conditions.realise)}, the "
                f"options ask for {list(options.realise)}"
            )
        realise = options.realise
    timings: dict[str, float] = {}
    t_start = time.perf_counter()
    sources_present = [s for s in SOURCES if conditions.for_source(s)]
    if options.total_charge not in (None, 0.0) and "charges" not in sources_present:
        raise InputError("design.total_charge: no charges are designed (no charge conditions)")
    if options.n_charges is not None and "charges" not in sources_present:
        raise InputError("design.n_charges: no charges are designed (no charge conditions)")
    if options.total_mass is not None and "masses" not in sources_present:
        raise InputError("design.total_mass: no masses are designed (inertia is not realised)")
    notes = list(cand.notes)
    notes.extend(length_notes(conditions, cand.geometry.size))
    forward = ForwardInputs.build(params, conditions, cand, realise)
    # fail fast: every source's equality system is checked before any solve
    checked = []
    for source in sources_present:
        t0 = time.perf_counter()
        p = build_problem(source, conditions, cand.points, options)
        p = _with_robust_costs(p, cand.points, conditions, params, options)
        rank, source_notes = diagnose(p, cand.geometry)
        checked.append((p, rank, source_notes, time.perf_counter() - t0))
    results: dict[str, SourceResult] = {}
    weights: dict[str, np.ndarray] = {}
    for p, rank, source_notes, setup in checked:
        source = p.source
        t0 = time.perf_counter() - setup
        w, res = _design_problem(p, rank, source_notes, options, t0, progress, forward)
        weights[source] = w
        results[source] = res
        timings[source] = res.seconds
        notes.extend(res.notes)
    timings["total"] = time.perf_counter() - t_start

    def pick(source: str) -> tuple[np.ndarray, np.ndarray]:
        if source not in weights:
            shape = (0, 3) if source == "dipoles" else (0,)
            return np.zeros((0, 3)), np.zeros(shape)
        w = weights[source]
        mags = np.linalg.norm(w, axis=1) if w.ndim == 2 else np.abs(w)
        keep = mags > 0
        return cand.points[keep], w[keep]

    cp_, cv = pick("charges")
    dp, dm = pick("dipoles")
    mp, mv = pick("masses")
    design = Design(
        parameters=params,
        fields={k: tuple(v) for k, v in conditions.fields.items()},
        charge_positions=cp_,
        charge_values=cv,
        mass_positions=mp,
        mass_values=mv,
        dipole_positions=dp,
        dipole_moments=dm,
        realises=list(realise),
    )
    result = DesignResult(
        design=design,
        sources=results,
        candidates=cand,
        options=options,
        conditions=conditions,
        timings=timings,
        notes=notes,
    )
    record_provenance(design, result)
    return result


def design_from_scene(
    scene: Any,
    *,
    progress: Progress | None = None,
    frontier: bool = True,
    **overrides: Any,
) -> DesignResult:
    """Design the body a scene describes: its parameters, fields, ``[body]`` and ``[design]``.

    Parameters
    ----------
    scene : chargedesign.scene.Scene
    progress : callable, optional
    **overrides
        DesignOptions fields that replace the scene's ``[design]`` values (None: keep).

    Returns
    -------
    DesignResult

    The body realises the theorem as its Larmor reading says (``[design] larmor``,
    :func:`larmor_of_scene`): with ``frame`` its elements realise ``n = 0``
    (:func:`chargedesign.larmor.body_parameters`) and ``design.larmor`` records the rate of
    the turning axes. A scene with ``[medium]`` is designed as a physical body
    (:mod:`chargedesign.designer.physical`): carriers, magnets and ballast within every limit,
    accepted as :mod:`chargedesign.designer.acceptance` says; with ``frontier`` the largest rate
    within the limits is then located too (:mod:`chargedesign.designer.frontier`, the report's
    frontier; the physical design itself never calls the frontier).
    """
    if not isinstance(scene, Scene):
        raise input_error("scene", "a chargedesign.scene.Scene", scene)
    t0 = time.perf_counter()
    inputs = _scene_inputs(scene, progress, overrides)
    options, candidates, conditions = inputs.options, inputs.candidates, inputs.conditions
    t2 = time.perf_counter()
    if inputs.spec is not None:
        setup = setup_physical(
            inputs.body_params, conditions, candidates, inputs.spec, options, larmor=inputs.larmor
        )
        result = design_physical(setup, progress=progress)
        if frontier:
            if progress is not None:
                progress("locating the frontier (largest rate within the limits, to 5 %) ...")
            front = find_frontier(setup, rtol=0.05, feasible_rate=1.0, feasible=result.design)
            result.design.frontier = front.to_dict()
            # the budget's K law is judged at the frontier's K_max, known only now
            realism = result.design.realism
            if isinstance(realism, dict) and K_LAW_KEY in realism:
                realism[K_LAW_KEY] = k_law(result.design)
    else:
        result = design_body(inputs.body_params, conditions, candidates, options, progress=progress)
        result.design.parameters = scene.parameters
        result.design.larmor = inputs.larmor
        result.timings = {"setup": t2 - t0, **result.timings}
        result.timings["total"] = time.perf_counter() - t0
        result.design.timings = {k: round(v, 6) for k, v in result.timings.items()}
    result.design.larmor_why = inputs.larmor_why
    if inputs.larmor_note:
        result.notes.append(inputs.larmor_note)
        result.design.notes = [*(result.design.notes or []), inputs.larmor_note]
    if result.design.provenance is not None:
        result.design.provenance["scene"] = scene.source
    return result


@dataclass
class SceneInputs:
    """What a scene gives the design: options, candidates, the conditions of the parameters
    the body realises (``body_params``), the Larmor reading and why it was chosen."""

    options: DesignOptions
    candidates: CandidateSet
    conditions: LinearConditions
    body_params: Parameters
    larmor: LarmorReading
    larmor_why: str
    larmor_note: str
    spec: Any


def larmor_of_scene(
    options: DesignOptions, params: Parameters, physical: bool
) -> tuple[LarmorReading, str, str]:
    """The scene's Larmor reading, why it was chosen, and a note (empty: none).

    ``[design] larmor`` when given; otherwise ``frame`` with ``[medium]`` (n then needs no
    hardware: only K's third moments need charges) and ``charges`` without (the paper's (p6)
    reading, the mathematical case).
    """
    if options.larmor is not None:
        reading = options.larmor
        why = f"[design] larmor = {reading!r}"
    elif physical:
        reading = "frame"
        why = (
            "the default with [medium]: n is a rotation of axes (Larmor), so the body realises "
            "n = 0 and only K's third moments need charges"
        )
    else:
        reading = "charges"
        why = "the default without [medium]: the paper's (p6) reading, second moments of charge"
    note = ""
    if reading == "frame" and params.n == 0:
        note = (
            "design.larmor = 'frame' with n = 0: the turning axes stand still, so the frame "
            "and charges readings give the same body"
        )
    return LarmorReading(reading, params.n), why, note


def _scene_inputs(scene: Any, progress: Progress | None, overrides: dict[str, Any]) -> SceneInputs:
    """A scene's design options, candidate set, Larmor reading and the conditions (derived for
    its size) of the parameters its body realises."""

    given = {k: v for k, v in overrides.items() if v is not None}
    options = dataclasses.replace(scene.design, **given) if given else scene.design
    spec = scene.physical
    larmor, why, note = larmor_of_scene(options, scene.parameters, spec is not None)
    params = body_parameters(scene.parameters, larmor)
    if progress is not None:
        progress("candidates ...")
    body = scene.body.table if scene.body is not None else {}
    candidates = candidates_from_table(body, base_dir=scene.base_dir)
    if progress is not None:
        progress(f"conditions ({len(candidates)} candidates, Larmor reading {larmor.reading}) ...")
    realise = options.realise if options.realise is not None else realise_from_scene(scene)
    size = candidates.geometry.size
    conditions = derive_conditions(params, scene.fields, realise, length=size if size > 0 else None)
    return SceneInputs(options, candidates, conditions, params, larmor, why, note, spec)


def physical_setup_from_scene(scene: Any, **overrides: Any) -> Any:
    """The physical design's setup of a scene with ``[medium]`` (None without one)."""

    inputs = _scene_inputs(scene, None, overrides)
    if inputs.spec is None:
        return None
    return setup_physical(
        inputs.body_params,
        inputs.conditions,
        inputs.candidates,
        inputs.spec,
        inputs.options,
        larmor=inputs.larmor,
    )


def frontier_from_scene(scene: Any, *, progress: Any = None, **overrides: Any) -> FrontierResult:
    """The frontier of a scene with ``[medium]`` (see
    :func:`~chargedesign.designer.frontier.find_frontier`): the pipeline composes the scene's
    physical setup and the frontier, which calls the design (never the other way round)."""
    setup = physical_setup_from_scene(scene, **overrides)
    if setup is None:
        raise InfeasibleError(
            "frontier: the scene has no [medium] table, so nothing limits it (give [medium] "
            "name = vacuum | air | sf6 | oil)"
        )
    return find_frontier(setup, progress=progress)
