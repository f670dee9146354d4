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
import functools
import time
from dataclasses import dataclass
from typing import Any

import numpy as np

from chargedesign.body import Design
from chargedesign.candidates import CandidateSet, candidates_from_points, candidates_from_region
from chargedesign.designer.accuracy import FORWARD_LIMIT, FORWARD_NOTE, ForwardInputs, length_notes
from chargedesign.designer.assembly import design_physical
from chargedesign.designer.diagnostics import diagnose, infeasible_inequalities
from chargedesign.designer.frontier import (
    FRONTIER_RTOL,
    FrontierResult,
    WindowOptions,
    find_frontier,
    restate_k_law,
)
from chargedesign.designer.physical_setup import setup_physical
from chargedesign.designer.polish import polish_weights, support_of
from chargedesign.designer.result import DesignResult, SourceResult, record_provenance
from chargedesign.designer.robust import robust_costs
from chargedesign.designer.solve import solve_problem
from chargedesign.designer.solvers import InfeasibleProblem, Solution
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
from chargedesign.limits import MAX_FRONTIER_CANDIDATES
from chargedesign.moment_conditions import (
    SOURCES,
    LinearConditions,
    derive_conditions,
)
from chargedesign.params import Parameters
from chargedesign.physical.budget import judge_at_frontier
from chargedesign.physical.support import scene_window_gravity, support_record
from chargedesign.physical.window import window_model
from chargedesign.scene import Scene
from chargedesign.scene.design import DesignOptions, Progress
from chargedesign.scene.design_realism import INDUCED_KEY, K_LAW_KEY
from chargedesign.validation import check_instance
from chargedesign.verdict import verdict_record
from chargedesign.vocabulary import REALISABLE

#: the frontier of a scene without ``[medium]``
NO_MEDIUM = (
    "frontier: the scene has no [medium] table, so nothing limits it (give [medium] "
    "name = vacuum | air | sf6 | oil)"
)


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
    if params is None:  # a robust objective is costed at the theorem's parameters
        raise InputError(f"design.objective: robust {p.source} need the parameters (params=)")
    costs = robust_costs(points, p.source, conditions.fields, params, options.robust_weight)
    return p.with_costs(costs)


def _no_elements_result(
    p: DesignProblem, objective: str, rank: int, notes: list[str], t0: float
) -> SourceResult:
    """The result of a source whose conditions are all homogeneous: no element needed."""
    return SourceResult(
        source=p.source,
        objective=objective,
        objective_value=0.0,
        objective_value_raw=0.0,
        units=UNITS[p.source],
        solver="none",
        method="all conditions are zero: no elements needed",
        status="optimal",
        n_conditions=len(p.b),
        rank=rank,
        n_candidates=p.n_candidates,
        n_elements=0,
        residual_before=0.0,
        residual_after=0.0,
        seconds=time.perf_counter() - t0,
        notes=notes,
    )


def _check_residual(
    source: str,
    after: float,
    options: DesignOptions,
    solver_text: str,
    cancels: bool,
    cancellation: str,
) -> None:
    """Refuse a polished solution whose residual exceeds ``design.tol``, naming the cause."""
    if not after > options.tolerance:
        return
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
        f"{fmt(options.tolerance, PLAIN)} ({solver_text}); try another solver"
    )


def _solved(
    p: DesignProblem, objective: str, options: DesignOptions, progress: Progress | None
) -> Solution:
    """The solver's solution, finite (infeasible inequalities named)."""
    try:
        sol = solve_problem(p, objective, options, progress)
    except InfeasibleProblem:
        raise infeasible_inequalities(p, options) from None
    if sol.u is None or not np.all(np.isfinite(sol.u)):
        raise SolverError(f"{p.source}: solver {sol.solver} returned no finite solution")
    return sol


def _polished(p: DesignProblem, u: np.ndarray, options: DesignOptions) -> tuple[np.ndarray, str]:
    """The polished solution (when ``options.polish``) and how it was polished."""
    if options.polish:
        return polish_weights(p, u, options.tolerance)
    return u, "not polished"


def _status_notes(source: str, sol: Solution, before: float, options: DesignOptions) -> list[str]:
    """A solver's non-optimal status whose residual was verified here, and its own notes."""
    notes = []
    if sol.status != "optimal" and before > options.tolerance:
        notes.append(
            f"{source}: {sol.solver} reported {sol.status!r} at its tightened tolerances; "
            "the residuals were verified here"
        )
    return notes + list(sol.notes)


def _delivery_notes(
    p: DesignProblem, weights: np.ndarray, worst: Any, cancellation: str, cancels: bool
) -> list[str]:
    """Refuse weights met only by a cancellation beyond ``FORWARD_LIMIT``, or negative masses;
    the note of a cancellation beyond ``FORWARD_NOTE``."""
    source = p.source
    if worst is not None and worst.forward_error > FORWARD_LIMIT:
        raise InfeasibleError(
            f"{source}: refused, {cancellation} (beyond {fmt(FORWARD_LIMIT, PLAIN)} the body "
            "realises nothing reliably)"
        )
    if p.nonneg and np.any(weights < 0):
        raise SolverError(f"{source}: a negative mass survived polishing ({fmt(weights.min())} kg)")
    return [f"{source}: {cancellation}"] if cancels else []


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
        return np.zeros(shape), _no_elements_result(p, objective, rank, notes, t0)
    if progress is not None:
        progress(f"{source}: {objective} problem, {len(p.b)} conditions, {n_cand} candidates")
    sol = _solved(p, objective, options, progress)
    raw = sol.u * p.scale
    before = relative_residual(p.A, raw, p.b)
    u, polish_text = _polished(p, sol.u, options)
    weights = u * p.scale
    after = relative_residual(p.A, weights, p.b)
    worst, cancellation = forward.assess(p, weights) if forward is not None else (None, "")
    cancels = worst is not None and worst.forward_error > FORWARD_NOTE
    _check_residual(source, after, options, f"{sol.solver}, {polish_text}", cancels, cancellation)
    notes.extend(_delivery_notes(p, weights, worst, cancellation, cancels))
    notes.extend(_status_notes(source, sol, before, options))
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
        n_elements=len(support_of(u, p.group, 0.0)),
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


def _check_design_inputs(params: Any, conditions: Any) -> None:
    """Parameters and linear conditions, of their types."""
    check_instance(params, Parameters, "params", "a chargedesign.params.Parameters")
    check_instance(
        conditions,
        LinearConditions,
        "conditions",
        "a chargedesign.moment_conditions.LinearConditions",
    )


def _realised(conditions: LinearConditions, options: DesignOptions) -> tuple[str, ...]:
    """The inertia terms realised: the conditions', unless the options name (the same) ones."""
    realise = tuple(conditions.realise) if conditions.realise else ()
    if options.realise is not None:
        if conditions.realise and set(options.realise) != set(conditions.realise):
            raise InputError(
                f"design.realise: the conditions realise {list(conditions.realise)}, the "
                f"options ask for {list(options.realise)}"
            )
        realise = options.realise
    return realise


def _sources_present(conditions: LinearConditions, options: DesignOptions) -> list[str]:
    """The sources the conditions ask for; options about charges or masses need them."""
    sources_present = [s for s in SOURCES if conditions.for_source(s)]
    # a [design] total or count for a source the conditions do not design is refused
    if options.total_charge not in (None, 0.0) and "charges" not in sources_present:
        raise InputError("design.total_charge: no charges are designed (no charge conditions)")
    if options.n_charges is not None and "charges" not in sources_present:
        raise InputError("design.n_charges: no charges are designed (no charge conditions)")
    if options.total_mass is not None and "masses" not in sources_present:
        raise InputError("design.total_mass: no masses are designed (inertia is not realised)")
    return sources_present


def _checked_problems(
    sources_present: list[str],
    params: Parameters,
    conditions: LinearConditions,
    cand: CandidateSet,
    options: DesignOptions,
) -> list[tuple[DesignProblem, int, list[str], float]]:
    """Every source's problem, its rank, its notes and its setup time, before any solve."""
    checked = []
    for source in sources_present:
        t0 = time.perf_counter()
        p = build_problem(source, conditions, cand.points, options)
        p = _with_robust_costs(p, cand.points, conditions, params, options)
        rank, source_notes = diagnose(p, cand.geometry)
        checked.append((p, rank, source_notes, time.perf_counter() - t0))
    return checked


def _solve_sources(
    checked: list[tuple[DesignProblem, int, list[str], float]],
    options: DesignOptions,
    progress: Progress | None,
    forward: ForwardInputs | None,
    timings: dict[str, float],
    notes: list[str],
) -> tuple[dict[str, np.ndarray], dict[str, SourceResult]]:
    """Solve every checked problem: its weights and result; its time and notes are added."""
    results: dict[str, SourceResult] = {}
    weights: dict[str, np.ndarray] = {}
    for p, rank, source_notes, setup in checked:
        t0 = time.perf_counter() - setup
        w, res = _design_problem(p, rank, source_notes, options, t0, progress, forward)
        weights[p.source] = w
        results[p.source] = res
        timings[p.source] = res.seconds
        notes.extend(res.notes)
    return weights, results


def _nonzero_elements(
    weights: dict[str, np.ndarray], source: str, points: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """The positions and weights of a source's non-zero elements (empty when not designed)."""
    if source not in weights:
        shape = (0, 3) if source == "dipoles" else (0,)
        return np.zeros((0, 3)), np.zeros(shape)
    w = weights[source]
    mags = np.linalg.norm(w, axis=1) if w.ndim == 2 else np.abs(w)
    keep = mags > 0
    return points[keep], w[keep]


def _design_of(
    params: Parameters,
    conditions: LinearConditions,
    weights: dict[str, np.ndarray],
    points: np.ndarray,
    realise: tuple[str, ...],
) -> Design:
    """The design of the solved sources' non-zero elements."""
    cp_, cv = _nonzero_elements(weights, "charges", points)
    dp, dm = _nonzero_elements(weights, "dipoles", points)
    mp, mv = _nonzero_elements(weights, "masses", points)
    return Design(
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


def design_body(
    params: Parameters,
    conditions: LinearConditions,
    candidates: CandidateSet | np.ndarray,
    options: DesignOptions | None = None,
    *,
    progress: Progress | None = None,
    forward: bool = True,
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
    forward : bool
        Assess the forward accuracy against the theorem's mu and V at ``params`` (False for
        a case not of the theorem's form: its own scales are not the theorem's).

    Raises
    ------
    InfeasibleError
        The conditions cannot be met on these candidates (the message names them), or only
        by a cancellation beyond ``FORWARD_LIMIT`` (the message names cause and remedy).
    SolverError
        A solver fails, or its polished result misses ``options.tolerance``.

    Notes
    -----
    When the conditions' default field strengths were chosen for an assumed 1 m body
    (``conditions.length_assumed``), a note gives the ones these candidates call for. Above
    ``FORWARD_NOTE`` (:func:`forward_accuracy`) the notes say which quantity is met only by
    cancellation, the forward accuracy to expect and the remedy.
    """
    _check_design_inputs(params, conditions)
    options = options or DesignOptions()
    cand = (
        candidates if isinstance(candidates, CandidateSet) else candidates_from_points(candidates)
    )
    realise = _realised(conditions, options)
    timings: dict[str, float] = {}
    t_start = time.perf_counter()
    sources_present = _sources_present(conditions, options)
    notes = [*cand.notes, *length_notes(conditions, cand.geometry.size)]
    assess = ForwardInputs.build(params, conditions, cand, realise) if forward else None
    # fail fast: every source's equality system is checked before any solve
    checked = _checked_problems(sources_present, params, conditions, cand, options)
    weights, results = _solve_sources(checked, options, progress, assess, timings, notes)
    timings["total"] = time.perf_counter() - t_start
    design = _design_of(params, conditions, weights, cand.points, realise)
    return _recorded_result(design, results, cand, options, conditions, timings, notes)


def _recorded_result(
    design: Design,
    results: dict[str, SourceResult],
    cand: CandidateSet,
    options: DesignOptions,
    conditions: LinearConditions,
    timings: dict[str, float],
    notes: list[str],
) -> DesignResult:
    """The design's result, its provenance recorded in the design."""
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
    """Design the body a scene describes: its model, fields, ``[body]`` and ``[design]``.

    Parameters
    ----------
    scene : chargedesign.scene.Scene
        Its model is the theorem's ``[parameters]`` or a ``[case]`` of (ep)
        (:func:`scene_model`); both take the same program below.
    progress : callable, optional
    **overrides
        DesignOptions fields that replace the scene's ``[design]`` values (None: keep).

    Notes
    -----
    The body realises the theorem as its Larmor reading says (``[design] larmor``,
    :func:`larmor_of_scene`): with ``frame`` its elements realise ``n = 0``
    (:func:`chargedesign.larmor.body_parameters`) and ``design.larmor`` records the rate of
    the turning axes. A scene with ``[medium]`` is designed as a physical body
    (:mod:`chargedesign.designer.assembly`): carriers, magnets and ballast within every limit,
    accepted as :mod:`chargedesign.designer.acceptance` says; with ``frontier`` the largest rate
    within the limits is then located too (:mod:`chargedesign.designer.frontier`, the report's
    frontier; the physical design itself never calls the frontier). Every result carries the
    exact certificate of its model (``result.certificate``; the theorem's scene: the
    catalogue's case at its parameters); a ``[case]`` scene's body also carries the case
    (design.json ``case``: ``check`` and ``simulate`` compare with it)."""
    check_instance(scene, Scene, "scene", "a chargedesign.scene.Scene")
    t0 = time.perf_counter()
    inputs = _scene_inputs(scene, progress, overrides)
    if inputs.spec is not None:
        fixed = _rate_fixed(inputs)
        result, _ = _physical_design(
            inputs, inputs.physical_setup(), progress, frontier and fixed is None
        )
        if frontier and fixed is not None:
            result.design.notes = [*(result.design.notes or []), f"frontier not located: {fixed}"]
        return _finish_scene_design(scene, inputs, result, progress)
    t2 = time.perf_counter()
    result = design_body(
        inputs.body_params,
        inputs.conditions,
        inputs.candidates,
        inputs.options,
        progress=progress,
        forward=inputs.model.theorem is not None,
    )
    result.design.parameters = inputs.model.parameters
    result.design.larmor = inputs.larmor
    result.timings = {"setup": t2 - t0, **result.timings}
    result.timings["total"] = time.perf_counter() - t0
    result.design.timings = {k: round(v, 6) for k, v in result.timings.items()}
    return _finish_scene_design(scene, inputs, result, progress)


def design_and_frontier_from_scene(
    scene: Any, *, progress: Progress | None = None, **overrides: Any
) -> tuple[DesignResult | None, FrontierResult]:
    """The body a scene with ``[medium]`` designs at its own rate and its frontier, from one
    physical setup and one derivation of the conditions (what ``chargedesign frontier``
    prints): the body is the one :func:`design_from_scene` records (its frontier, K law and
    verdict judged the same way, once). When the scene's own rate is not accepted the body is
    None and the frontier is located alone, on the same setup. ``overrides`` as in
    :func:`design_from_scene` (``realised_fraction``, ``realised_gravity``: the window's)."""
    check_instance(scene, Scene, "scene", "a chargedesign.scene.Scene")
    if scene.physical is None:
        raise InfeasibleError(NO_MEDIUM)
    inputs = _scene_inputs(scene, progress, overrides)
    _check_rate_family(scene, inputs)
    too_many = frontier_too_large(inputs.candidates)
    if too_many is not None:
        raise InputError(f"frontier: {too_many}")  # before the work: it would not end
    setup = inputs.physical_setup()
    try:
        result = design_physical(setup, progress=progress)
    except (InfeasibleError, SolverError) as exc:
        if progress is not None:
            progress(f"the scene's own rate is not accepted ({exc}): the frontier alone")
        return None, find_frontier(setup, progress=progress, window=_window_options(inputs))
    result, front = _physical_design(inputs, setup, progress, True, result)
    assert front is not None
    return _finish_scene_design(scene, inputs, result, progress), front


def _finish_scene_design(
    scene: Any, inputs: SceneInputs, result: DesignResult, progress: Progress | None
) -> DesignResult:
    """What every scene's body records after its design: the support, the Larmor reading's
    why, the case, the provenance and the verdict (judged once)."""
    if inputs.spec is not None and scene.support.given:
        # how the body is held, counted (physical/support.py)
        result.design.support = support_record(
            result.design, scene.support, fraction=inputs.options.realised_fraction
        )
    result.design.larmor_why = inputs.larmor_why
    if inputs.larmor_note:
        result.notes.append(inputs.larmor_note)
        result.design.notes = [*(result.design.notes or []), inputs.larmor_note]
    if result.design.provenance is not None:
        result.design.provenance["scene"] = scene.source
    _record_case(result, inputs.model)  # every model, the theorem's too
    result.design.verdict = verdict_record(result.design)  # judged once, rendered everywhere
    return result


def _record_case(result: DesignResult, model: SceneModel) -> None:
    """Every scene's body: its model's record and the exact certificate of its model, deferred
    the same way for every scene (:func:`scene_certificate`, made when ``result.certificate``
    is first read). The theorem's scene's model is the catalogue's case built from its
    parameters; design.json's parameters are its record, so nothing is written now. A
    ``[case]`` scene's body gets its case record now (and for a general case the checks of its
    elements against the case's own V, mu and inertia, its realism budget and window:
    :func:`chargedesign.designer.case_design.record_case`); the certificate's verdict is
    written into that record when it is made (``result.certificate_recorded``: every writer
    makes it first, :meth:`~chargedesign.designer.result.DesignResult.recorded_design`).

    The certificate costs sympy and about 1.7 s of CPU, and nothing the design decides reads
    it: ``frontier`` and a theorem scene's ``design`` never make it. A refusal of the
    theorem's case (the note of
    :func:`chargedesign.designer.case_design.theorem_certificate`) goes into ``design.notes``
    when it is read (a scene's parameters are all within a case file's range: the scene's
    reader checks them as the case's parser does)."""
    if model.case is not None:
        from chargedesign.designer.case_design import record_case  # sympy: a case scene only

        record_case(result.design, model.case, model.table, model.theorem)
    result.certificate_of = functools.partial(scene_certificate, result.design, model)
    result.certificate_recorded = model.case is not None


def scene_certificate(design: Design, model: SceneModel, progress: Progress | None = None) -> Any:
    """The exact certificate of the model a scene's body realises (a ``[case]`` scene's
    :func:`chargedesign.designer.case_design.case_certificate`, its verdict written into the
    body's ``case`` record; the theorem's scene's
    :func:`chargedesign.designer.case_design.theorem_certificate`, None and a note in
    ``design.notes`` when the case is refused), imported when made: it loads sympy."""
    from chargedesign.designer import case_design  # sympy

    if model.case is not None:
        return case_design.case_certificate(design, model.case, progress)
    assert model.theorem is not None  # a scene's model is its [case] or its [parameters]
    return case_design.theorem_certificate(design, model.theorem, progress)


@dataclass
class SceneModel:
    """The model a scene's body realises: the theorem's ``[parameters]`` or a ``[case]``.

    ``case`` is the scene's ``[case]`` (None: the theorem's scene, whose conditions come from
    the theorem's own engine and whose case is the catalogue's, built from its parameters when
    the body is recorded: :func:`chargedesign.designer.case_design.theorem_model`); ``theorem``
    the theorem's parameters (the scene's, or those a case of the theorem's form carries:
    :func:`chargedesign.model.catalogue.theorem_parameters`; None: a general case); ``table``
    the ``[case]`` table as written (None: the theorem's scene).
    """

    case: Any
    theorem: Parameters | None
    table: dict[str, Any] | None = None

    @property
    def parameters(self) -> Parameters:
        """The parameters design.json records: the theorem's, or a general case's C."""
        if self.theorem is not None:
            return self.theorem
        return Parameters.from_mapping({"C": float(self.case.inertia[2])}, "case.inertia[2]")


def scene_model(scene: Any) -> SceneModel:
    """The scene's model (:class:`SceneModel`)."""
    if "case" not in scene.tables:
        return SceneModel(case=None, theorem=scene.parameters)
    from chargedesign.model.catalogue import theorem_parameters  # sympy: a case scene only

    case = scene.case
    return SceneModel(case=case, theorem=theorem_parameters(case), table=scene.tables["case"])


def _window_options(inputs: SceneInputs) -> WindowOptions:
    """The realised window's options of a scene's inputs (its ``[design]`` keys, the support's
    gravity, any override)."""
    return WindowOptions(inputs.options.realised_fraction, inputs.options.realised_gravity)


def _physical_design(
    inputs: SceneInputs,
    setup: Any,
    progress: Progress | None,
    frontier: bool,
    result: DesignResult | None = None,
) -> tuple[DesignResult, FrontierResult | None]:
    """The physical body a scene with ``[medium]`` describes (``result``: already designed on
    ``setup``), with its frontier when asked: located once, on the same setup, and reused for
    the realised window, the K law, the report and the verdict."""
    result = design_physical(setup, progress=progress) if result is None else result
    if not frontier:
        return result, None
    too_many = frontier_too_large(inputs.candidates)
    if too_many is not None:
        # the body stands without it: said in the report's notes and on the terminal
        result.design.notes = [*(result.design.notes or []), f"frontier not located: {too_many}"]
        if progress is not None:
            progress(f"frontier not located: {too_many}")
        return result, None
    if progress is not None:
        progress(
            f"locating the frontier (largest rate within the limits, to "
            f"{fmt(100 * FRONTIER_RTOL, PLAIN)} %) ..."
        )
    design = result.design
    front = find_frontier(
        setup,
        progress=progress,
        feasible_rate=1.0,
        feasible=design,
        window=_window_options(inputs),
    )
    if front.realised is not None:
        # the apparatus and the parasitics of this body at its own rate (the window's are
        # those of the body at s_max)
        _record_at_design(front, design, inputs.options.realised_gravity)
    design.frontier = front.to_dict()
    # the budget's K law and the report's figures are judged at the frontier's K_max
    judge_at_frontier(design)
    realism = design.realism if isinstance(design.realism, dict) else {}
    # the induced magnetisation's one figure: this body's (design.json's, the verdict's)
    front.induced = dict(realism.get(INDUCED_KEY) or {})
    if realism.get(K_LAW_KEY):
        # the K law's one figure: this body's, judged at K_max (the report's and the budget's)
        restate_k_law(front, realism[K_LAW_KEY], "the body at the scene's rate (s = 1)")
    design.frontier = front.to_dict()
    return result, front


def frontier_too_large(candidates: CandidateSet) -> str | None:
    """Why a body of these candidates has no frontier located (None: it can have one): above
    :data:`~chargedesign.limits.MAX_FRONTIER_CANDIDATES`, with the spacing that would fit."""
    count = len(candidates)
    if count <= MAX_FRONTIER_CANDIDATES:
        return None
    spacing = candidates.description.get("spacing")
    fits = ""
    if isinstance(spacing, (int, float)) and spacing > 0:
        # the count goes like spacing^-3 in a region of fixed size
        wider = float(spacing) * (count / MAX_FRONTIER_CANDIDATES) ** (1 / 3)
        fits = f"; a [body] spacing of about {fmt(wider, ROUGH)} m keeps it within"
    return (
        f"{count:,} candidates is above the {MAX_FRONTIER_CANDIDATES:,} a frontier takes (its "
        f"charges' minmax is a cone program dense in every candidate){fits}"
    )


def _record_at_design(front: FrontierResult, design: Design, gravity: float) -> None:
    """The realised window's apparatus, support and parasitics at the design's own rate (the
    window laws of the body at s = 1, at the window's gravity; cheap: the rate-free factors
    are computed once per body, physical/parasitics.py)."""
    assert front.realised is not None
    own = window_model(design, 1.0, gravity=gravity)
    front.realised.apparatus = own.apparatus.to_dict() if own.apparatus else None
    front.realised.support = own.support
    front.realised.at_design = {k: v / own.fraction for k, v in own.ratios(1.0).items()}


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
    model: SceneModel

    def physical_setup(self) -> Any:
        """The physical design's setup of these inputs (they must carry a ``[medium]``); a
        general case's setup carries its design.json ``case`` record (its budgets read it)."""
        model_record = None
        if self.model.theorem is None:
            from chargedesign.model.case_numeric import case_record  # sympy: a case only

            model_record = case_record(self.model.table or {}, self.model.case, None)
        return setup_physical(
            self.body_params,
            self.conditions,
            self.candidates,
            self.spec,
            self.options,
            larmor=self.larmor,
            model_record=model_record,
        )


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


#: objectives of the physical design (l2 and linf are not built for the cones and cells)
PHYSICAL_OBJECTIVES = ("l1", "robust")


#: [design] options the physical program does not read: each is refused with [medium] (the
#: carriers' own-field limits bound every charge, the parts' materials fix the masses, and the
#: program's own solvers and equality polish reach its accuracy)
PHYSICAL_REFUSED = {
    "max_charge": "the carriers' own-field limits bound every |q|",
    "total_mass": "the parts' materials and sizes fix the masses",
    "solver": "the physical program runs its own linear and cone solvers",
    "polish": "the physical program always polishes its equalities",
    "tol": "the physical program is accepted by its limits and the forward check",
}


def check_physical_options(options: DesignOptions) -> None:
    """The ``[design]`` options a physical design (a scene with ``[medium]``) takes, refused in
    one line naming the one it does not, once, before any design work: an option the program
    would not read (:data:`PHYSICAL_REFUSED`), an objective outside
    :data:`PHYSICAL_OBJECTIVES`, inertia not realised, a charge total or count."""
    default = DesignOptions()
    for name, reason in PHYSICAL_REFUSED.items():
        value = getattr(options, name)
        if value != getattr(default, name):
            raise InputError(
                f"design.{name}: not available with [medium] ({reason}); drop it, or drop "
                "[medium] for point elements"
            )
    for source in ("charges", "dipoles", "masses"):
        objective = options.objective_for(source)
        if objective not in PHYSICAL_OBJECTIVES:
            raise InputError(
                f"design.objective: {objective!r} for {source} is not "
                "available with [medium] (expected " + " or ".join(PHYSICAL_OBJECTIVES) + ")"
            )
    # the conditions realise what the options name (all three when they name none)
    if "inertia" not in (options.realise if options.realise is not None else REALISABLE):
        raise InputError(
            "design.realise: a physical design realises the inertia (every part has mass)"
        )
    if options.total_charge is not None or options.n_charges is not None:
        raise InputError(
            "design.total_charge / n_charges: not available with [medium] (the carriers' "
            "limits decide the charges)"
        )


def _scene_inputs(
    scene: Scene, progress: Progress | None, overrides: dict[str, Any]
) -> SceneInputs:
    """A scene's design options, candidate set, Larmor reading and the conditions (derived for
    its size) of the model its body realises."""

    given = {k: v for k, v in overrides.items() if v is not None}
    if "realised_gravity" not in given:  # the support decides (free fall: residual g)
        given["realised_gravity"] = scene_window_gravity(scene)
    options = dataclasses.replace(scene.design, **given)  # the overrides checked once
    spec = scene.physical
    if spec is not None:
        check_physical_options(options)  # once, before any work
    model = scene_model(scene)
    if model.theorem is not None:
        larmor, why, note = larmor_of_scene(options, model.theorem, spec is not None)
        params = body_parameters(model.theorem, larmor)
    else:
        larmor, why, note = _general_case_reading(scene, options, spec)
        params = model.parameters
    if progress is not None:
        progress("candidates ...")
    # the [body] region as the scene read it (its keys checked once, its values once)
    candidates = candidates_from_region(scene.region_spec(), base_dir=scene.base_dir)
    if progress is not None:
        progress(f"conditions ({len(candidates)} candidates, Larmor reading {larmor.reading}) ...")
    # the options are the scene's [design] read once (with the overrides): all three by default
    realise = options.realise if options.realise is not None else REALISABLE
    size = candidates.geometry.size
    length = size if size > 0 else None
    if model.theorem is not None:
        conditions = derive_conditions(params, scene.fields, realise, length=length)
    else:
        from chargedesign.designer.case_design import conditions_of_case  # sympy: a case only

        conditions = conditions_of_case(model.case, scene.fields, length)
        if spec is not None:
            _check_site_gravity(scene, conditions, options.realised_gravity)
    return SceneInputs(options, candidates, conditions, params, larmor, why, note, spec, model)


def _check_site_gravity(scene: Any, conditions: LinearConditions, site_g: float) -> None:
    """Refuse, in one line, real parts of a general case whose conditions put masses in a
    gravity no site has: the engine derives gravity when masses realise V (uniform standard g
    for V's degree 1, a gradient for its degree 2), but real parts feel their site's uniform
    gravity only (``site_g``: the support's, or ``[design] realised_gravity``)."""
    if conditions.field_origin.get("gravity") != "derived":
        return
    legendre = tuple(conditions.fields.get("gravity", ()))
    if any(x != 0.0 for x in legendre[1:]):
        raise InputError(
            f"{scene.source}: [medium] with a [case] whose V the conditions realise by masses "
            f"in a gravity gradient (fields.gravity legendre [{', '.join(map(fmt, legendre))}], "
            "derived): a site's gravity is uniform; give [fields.gravity] a1 (the site's g) "
            "and [fields.magnetic] a2, so that magnets realise V's degree 2, or drop [medium] "
            "for point elements"
        )
    if legendre and not np.isclose(legendre[0], site_g, rtol=1e-12, atol=0.0):
        raise InputError(
            f"{scene.source}: [medium] with a [case] whose V the conditions realise by masses "
            f"in gravity {fmt(legendre[0])} m/s^2 (derived), but the support's is "
            f"{fmt(site_g)} m/s^2; give [fields.gravity] a1, or a support where the masses "
            "feel that gravity"
        )


def _general_case_reading(
    scene: Any, options: DesignOptions, spec: Any
) -> tuple[LarmorReading, str, str]:
    """A case not of the theorem's form: its elements realise its own V and l (the charges
    reading), refused in one line where the route still needs the theorem's parameters. With
    ``[medium]`` its parts are designed as the theorem's are, at any time rate s (the case's
    ``s^2 V``, ``s l``: :func:`chargedesign.model.frame.time_rescaled`), and its budgets,
    window and balance read the case's own V, mu and typical rate
    (:func:`chargedesign.physical.realism.model_scales`)."""
    if options.larmor == "frame":
        raise InputError(
            "design.larmor: 'frame' reads the theorem's n as turning axes; a [case] not of the "
            "theorem's form has no n (use 'charges' or drop the key)"
        )
    why = "a [case] not of the theorem's form: its elements realise its own V and l"
    return LarmorReading("charges", 0.0), why, ""


def physical_setup_from_scene(scene: Any, **overrides: Any) -> Any:
    """The physical design's setup of a scene with ``[medium]`` (None without one)."""
    inputs = _scene_inputs(scene, None, overrides)
    if inputs.spec is None:
        return None
    return inputs.physical_setup()


def frontier_from_scene(
    scene: Any,
    *,
    progress: Any = None,
    window: Any = None,
    rtol: float = FRONTIER_RTOL,
    checks: bool = True,
    law: bool | None = None,
    **overrides: Any,
) -> FrontierResult:
    """The frontier of a scene with ``[medium]`` (see
    :func:`~chargedesign.designer.frontier.find_frontier`): the pipeline composes the scene's
    physical setup and the frontier, which calls the design (never the other way round).
    ``window``: :class:`~chargedesign.designer.frontier.WindowOptions` to find the realised
    window too (None: not); ``rtol``, ``checks``, ``law`` as there. The scene is read once,
    into typed inputs (:class:`SceneInputs`); the setup and the frontier take those."""
    if scene.physical is None:
        raise InfeasibleError(NO_MEDIUM)
    inputs = _scene_inputs(scene, None, overrides)
    _check_rate_family(scene, inputs)
    setup = inputs.physical_setup()
    return find_frontier(setup, progress=progress, window=window, rtol=rtol, checks=checks, law=law)


def _rate_fixed(inputs: SceneInputs) -> str | None:
    """Why the frontier cannot scale this body with the rate (None: it can). The physical
    program scales the carriers' and the magnets' right-hand sides with the rate (``s`` and
    ``s^2``) but not the masses' (theirs is the inertia, which does not scale), so a general
    case whose masses realise part of its V in gravity (a heavy top: V of degree 1) has its
    body at rate 1 only."""
    if inputs.model.theorem is not None:
        return None
    for row in inputs.conditions.conditions:
        if row.source == "masses" and row.provenance.startswith("V") and row.value != 0.0:
            return (
                f"the masses realise part of this case's V in gravity ({row.provenance}), and "
                "the frontier scales the carriers' and the magnets' conditions with the rate, "
                "not the masses' (theirs is the inertia): its body is designed at its own rate"
            )
    return None


def _check_rate_family(scene: Any, inputs: SceneInputs) -> None:
    """Refuse the frontier of a body the rate cannot scale (:func:`_rate_fixed`), in one line
    before the setup's work."""
    fixed = _rate_fixed(inputs)
    if fixed is not None:
        raise InputError(f"{scene.source}: frontier: {fixed}")
