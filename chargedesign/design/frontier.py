"""The frontier of the buildable: the largest time rate a body realises within every limit.

Time rescaling ``n, K -> s n, s K`` and ``kappa, lambda, rho -> s^2 (...)`` is the same motion
``s`` times faster (:func:`chargedesign.design.physical.scaled_parameters`). The charges grow
like ``s`` (and the surface fields with them), the magnets like ``s^2``; the carriers, whose
number grows with ``s``, weigh on the inertia. :func:`find_frontier` brackets the largest
feasible ``s``:

1. an upper bound from one LP: the largest ``s`` for which charges meet their conditions with
   every carrier's own surface field within the safe field (a necessary condition);
2. bisection in ``log s`` over the full two-stage feasibility problems
   (:func:`~chargedesign.design.physical.design_at_rate`) to ``rtol``.

The binding limit is the one that fails just above ``s_max``.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from chargedesign.design.physical import (
    Binding,
    PhysicalInfeasible,
    PhysicalOutcome,
    PhysicalSetup,
    build_design,
    design_at_rate,
)
from chargedesign.errors import InfeasibleError, SolverError
from chargedesign.results import Result

#: relative width of the final bracket [s_max, s_above]
FRONTIER_RTOL = 1e-2
#: after bisection, rates (1 + rtol)^k above the bracket that must fail too
UPWARD_STEPS = (1, 2, 4)
UPWARD_RESTARTS = 3
#: how far below the necessary bound a feasible rate is searched for
LOWEST_RATE_FRACTION = 1e-9


@dataclass(repr=False)
class FrontierResult(Result):
    """Where the buildable stops for one scene.

    Attributes
    ----------
    s_max : float
        Largest time rate the body realises within every limit (0: none).
    n_max : float
        ``s_max * n``, 1/s.
    period : float
        ``2 pi / n_max``, s (inf when n_max = 0).
    binding : Binding
        What fails just above ``s_max``.
    s_necessary : float
        The charges' own-field upper bound on s.
    field_response : dict
        The applied field acting on the parts' materials of the body designed at ``s_max``
        (:func:`chargedesign.physical.realism.field_response`): induced magnetisation and
        eddy torques as fractions of the designed torques.
    """

    s_max: float
    n: float
    binding: Binding
    s_necessary: float
    s_above: float
    evaluations: int
    seconds: float
    medium: str
    history: list[tuple[float, bool]] = field(default_factory=list)
    field_response: dict[str, Any] = field(default_factory=dict)

    @property
    def n_max(self) -> float:
        return self.s_max * self.n

    @property
    def period(self) -> float:
        return 2 * math.pi / self.n_max if self.n_max > 0 else math.inf

    def to_dict(self) -> dict[str, Any]:
        return {
            "s_max": self.s_max,
            "n_max": self.n_max,
            "period_s": self.period if math.isfinite(self.period) else None,
            "binding": self.binding.text(self.medium),
            "binding_detail": self.binding.to_dict(),
            "s_above": self.s_above,
            "s_necessary": self.s_necessary,
            "medium": self.medium,
            "evaluations": self.evaluations,
            "seconds": self.seconds,
            "field_response": dict(self.field_response),
        }

    def _summary(self) -> dict[str, Any]:
        return {
            "s_max": self.s_max,
            "n_max": self.n_max,
            "binding": self.binding.stage,
            "medium": self.medium,
            "evaluations": self.evaluations,
            "seconds": self.seconds,
        }

    def _text(self) -> str:
        period = f"{self.period:.4g} s" if math.isfinite(self.period) else "none"
        return (
            f"frontier: s_max = {self.s_max:.4g} (n_max = {self.n_max:.4g} 1/s, period "
            f"2 pi / n_max = {period}) in {self.medium}\n"
            f"binding: {self.binding.text(self.medium)}\n"
            + "".join(
                f"at n_max, {key.replace('_', ' ')}: {_value_text(item)} of the designed "
                f"torques ({item['verdict']})\n"
                for key, item in self.field_response.items()
            )
            + f"({self.evaluations} feasibility problems, {self.seconds:.2f} s)\n"
        )


def _value_text(item: dict[str, Any]) -> str:
    value = item.get("value")
    return "inf" if value is None else f"{value:.3g}"


def necessary_rate(setup: PhysicalSetup) -> float:
    """Largest s with charges meeting ``A q = s b`` and ``|q_i| <= c0_i - s c1_i`` (one LP)."""
    from scipy.optimize import linprog

    A, b = setup.systems["charges"]
    bound = setup.field_bound(1.0)
    if not np.any(b):
        return bound
    c0 = setup.charge_caps(0.0)
    c1 = c0 - setup.charge_caps(1.0)  # the external field's share per unit rate
    qs = float(np.max(c0))
    top = np.max(np.abs(A), axis=1) * qs
    top = np.where(top > 0, top, 1.0)
    As = A * qs / top[:, None]
    bs = b / top
    n = A.shape[1]
    # variables (q+, q-, s); maximise s
    cost = np.zeros(2 * n + 1)
    cost[-1] = -1.0
    A_eq = np.hstack([As, -As, -bs[:, None]])
    A_ub = np.hstack([np.eye(n), np.eye(n), (c1 / qs)[:, None]])
    res = linprog(
        cost,
        A_ub=A_ub,
        b_ub=c0 / qs,
        A_eq=A_eq,
        b_eq=np.zeros(len(b)),
        bounds=[(0, None)] * (2 * n) + [(0, min(bound, 1e300))],
        method="highs",
    )
    if res.status == 3:  # unbounded: the charges' conditions are homogeneous
        return bound
    if res.status != 0 or res.x is None:
        raise SolverError(f"frontier: HiGHS failed on the necessary-rate LP ({res.message})")
    return float(res.x[-1])


def _feasible(setup: PhysicalSetup, s: float) -> tuple[PhysicalOutcome | None, Binding | None]:
    try:
        return design_at_rate(setup, s), None
    except PhysicalInfeasible as exc:
        return None, exc.binding


def _response_at(setup: PhysicalSetup, outcome: PhysicalOutcome | None) -> dict[str, Any]:
    """The field response of the body designed at the frontier (empty when none)."""
    from chargedesign.physical.realism import field_response

    return {} if outcome is None else field_response(build_design(setup, outcome))


def find_frontier(
    setup: PhysicalSetup,
    *,
    rtol: float = FRONTIER_RTOL,
    progress: Any = None,
    feasible_rate: float | None = None,
    feasible_outcome: PhysicalOutcome | None = None,
) -> FrontierResult:
    """The largest time rate within every limit, and the limit that binds above it.

    ``feasible_rate``: a rate already known to be feasible (e.g. the one just designed),
    which starts the bracket and saves the search for a feasible point; ``feasible_outcome``
    its body, which then need not be designed again if the frontier ends there. The bracket
    ``[s_max, s_above]`` ends narrower than ``1 + rtol``.
    """
    t0 = time.perf_counter()
    s_nec = necessary_rate(setup)
    history: list[tuple[float, bool]] = []
    medium = setup.spec.medium.name

    # the body at the highest feasible rate probed (its field response is reported)
    best: dict[float, PhysicalOutcome] = {}
    if feasible_rate is not None and feasible_outcome is not None:
        best[feasible_rate] = feasible_outcome

    def probe(s: float) -> tuple[bool, Binding | None]:
        outcome, binding = _feasible(setup, s)
        ok = outcome is not None
        if outcome is not None and all(s > known for known in best):
            best.clear()
            best[s] = outcome
        history.append((s, ok))
        if progress is not None:
            progress(f"s = {s:.6g}: {'feasible' if ok else 'infeasible'}")
        return ok, binding

    if not s_nec > 0:
        none_binding = Binding(
            "charges",
            f"the external electric field alone exceeds the safe field of {medium}",
            "fields.electric",
        )
        return FrontierResult(0.0, setup.params.n, none_binding, 0.0, 0.0, 0, 0.0, medium)
    # the necessary bound itself: just above it the own-field LP is infeasible
    upper_binding = Binding(
        "charges",
        f"the carriers' own surface fields reach the safe field of {medium} "
        f"({setup.safe_field:.3g} V/m)",
        "the carriers",
    )
    if math.isfinite(setup.field_bound(1.0)) and s_nec >= setup.field_bound(1.0) * (1 - 1e-12):
        upper_binding = Binding(
            "fields",
            f"fields.electric.max ({setup.spec.field_limits.get('electric'):g} V/m) over the "
            "body region",
            "fields.electric",
        )
    hi = s_nec * (1 + rtol)
    hi_binding: Binding | None = upper_binding
    ok, binding = probe(s_nec)
    if ok:
        lo = s_nec
    else:
        hi, hi_binding = s_nec, binding
        lo = feasible_rate if feasible_rate is not None and feasible_rate < s_nec else 0.0
        s = s_nec
        while lo == 0.0 and s > s_nec * LOWEST_RATE_FRACTION:
            s *= 0.1
            ok, binding = probe(s)
            if ok:
                lo = s
                break
            hi, hi_binding = s, binding
        if lo == 0.0:
            assert hi_binding is not None
            return FrontierResult(
                0.0,
                setup.params.n,
                hi_binding,
                s_nec,
                hi,
                len(history),
                time.perf_counter() - t0,
                medium,
                history,
            )
        for _ in range(UPWARD_RESTARTS + 1):
            while hi / lo > 1 + rtol:
                mid = math.sqrt(lo * hi)
                ok, binding = probe(mid)
                if ok:
                    lo = mid
                else:
                    hi, hi_binding = mid, binding
            # the heuristic feasibility (LP rounds, then cones) is not exactly monotone in s:
            # rates a little above the bracket are tried, and a success reopens it
            above = [hi * (1 + rtol) ** k for k in UPWARD_STEPS if hi * (1 + rtol) ** k < s_nec]
            found = None
            for s_up in above:
                ok, binding = probe(s_up)
                if ok:
                    found = s_up
                    break
            if found is None:
                break
            lo = found
            hi = min(s_nec, found * (1 + rtol) ** 4)
            hi_binding = upper_binding
            ok, binding = probe(hi)
            if ok:
                lo = hi
                break
            hi_binding = binding
    assert hi_binding is not None
    outcome = best.get(lo)
    if outcome is None:  # the feasible rate given by the caller was not probed here
        outcome = _feasible(setup, lo)[0]
    return FrontierResult(
        s_max=lo,
        n=setup.params.n,
        binding=hi_binding,
        s_necessary=s_nec,
        s_above=hi,
        evaluations=len(history),
        seconds=time.perf_counter() - t0,
        medium=medium,
        history=history,
        field_response=_response_at(setup, outcome),
    )


_FURTHER = {
    "charges": "vacuum or a medium with a higher breakdown, more or larger carriers, a stronger "
    "magnetic field a1, or a smaller, lighter body reaches further",
    "fields": "a larger fields.electric.max reaches further",
    "masses": "lighter carriers (thinner shells, a lighter material, fewer) or a larger C "
    "reach further",
    "magnets": "a stronger magnet material, a larger gradient a2 or larger cells reach further",
}


def beyond_frontier_message(
    setup: PhysicalSetup, binding: Binding, frontier: FrontierResult, s: float
) -> str:
    """One line: what fails at rate ``s``, how far the body reaches, what would reach further."""
    reach = (
        f"this body reaches at most n = {frontier.n_max:.3g} 1/s (s_max = "
        f"{frontier.s_max:.3g} of the requested rate)"
        if frontier.s_max > 0
        else "this body realises no rate within the limits"
    )
    return (
        f"{binding.text(setup.spec.medium.name)}; {reach}; "
        f"{_FURTHER.get(frontier.binding.stage, 'see docs/buildable.md')}"
    )


def frontier_from_scene(scene: Any, *, progress: Any = None, **overrides: Any) -> FrontierResult:
    """The frontier of a scene with ``[medium]`` (see :func:`find_frontier`)."""
    from chargedesign.design.pipeline import physical_setup_from_scene

    setup = physical_setup_from_scene(scene, **overrides)
    if setup is None:
        raise InfeasibleError(
            "frontier: the scene has no [medium] table, so nothing limits it (give [medium] "
            "name = vacuum | air | sf6 | oil)"
        )
    return find_frontier(setup, progress=progress)
