"""The frontier of the buildable: the largest time rate a body realises within every limit.

Time rescaling ``n, K -> s n, s K`` and ``kappa, lambda, rho -> s^2 (...)`` is the same motion
``s`` times faster (:func:`chargedesign.designer.assembly.scaled_parameters`). The charges grow
like ``s`` (and the surface fields with them), the magnets like ``s^2``; the carriers, whose
number grows with ``s``, weigh on the inertia. What the charges carry depends on the Larmor
reading (:mod:`chargedesign.larmor`): with ``charges`` (the paper's (p6)) their second
moments realise n and their third moments K, so the frontier is ``n_max``; with ``frame``
the body realises ``n = 0`` (any n is a rotation of axes), only K's third moments need
charges, and the frontier is ``K_max`` (with kappa's magnets and the masses).

:func:`find_frontier` brackets the largest ``s`` the design accepts
(:mod:`chargedesign.designer.acceptance`: both stages, the limits recomputed from the parts,
the balance under gravity and the forward check):

1. an upper bound from one LP: the largest ``s`` for which charges meet their conditions with
   every carrier's own surface field within the safe field (a necessary condition; without
   charge conditions, rates 10x apart up to the first refused);
2. the charges' limit computed directly
   (:func:`~chargedesign.designer.frontier_probes.charges_rate_limit`): the charges' conditions
   ``A q = s b`` and their surface fields are homogeneous in ``(q, s)``, so with ``q = s u``
   the largest rate the charges allow is ``s_c = E_lim / t*``,
   ``t* = min_u max_x |E(u)(x)| + E_ext`` subject to ``A u = b``: one SOCP, solved by the
   design's constraint generation. No charges exist above ``s_c`` (a proved refusal, never
   designed); the design at ``s_c (1 - rtol / 4)``, then at ``s_c / (1 + rtol)``, closes the
   bracket when accepted (measured: the default body in 1 design instead of 11, the small body
   in SF6 in 1 instead of 11);
3. otherwise (the masses, the balance or the acceptance bind below ``s_c``) bisection in
   ``log s`` over the full acceptance to ``rtol``, below the lowest rate refused. A frontier
   only ranked (``checks=False``) on a body without charge conditions follows that
   bisection's path with the outcomes the masses' rate law predicts
   (:func:`masses_rate_law`: the magnets' conditions are homogeneous in ``(sigma, s^2)``, one
   SOCP) and designs only the cell it ends in (the K = 0 example: 2 designs instead of 8,
   the same bracket).

A refusal the charges' stage proves (:attr:`~chargedesign.designer.physical_setup.Binding.proved`:
the own-field LP, or the surface cones on every usable carrier, infeasible; or the rate above
``s_c``) holds at every faster rate, so the checks above the bracket that guard against the
heuristic's non-monotonicity skip the rates above a proved refusal.

The binding limit is the one that fails just above ``s_max``. Under gravity the balance
bounds the rate from below (the designed torques go as ``s^2``, gravity's imbalance does not):
the frontier reports that lowest rate ``s_min``, and fails in one line when it lies above
``s_max`` ("no buildable rate: ...").
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from chargedesign.body import Design
from chargedesign.constants import STANDARD_GRAVITY
from chargedesign.designer.acceptance import (
    BUILDER_BALANCE_M,
    balance_bound,
    body_check,
    failed_quantities,
)
from chargedesign.designer.assembly import build_design, design_at_rate
from chargedesign.designer.charges import charge_support, lp_charges
from chargedesign.designer.cone_program import ConeProgram
from chargedesign.designer.frontier_probes import ChargesLimit, charges_rate_limit
from chargedesign.designer.linear_program import linprog_highs
from chargedesign.designer.masses import design_masses, mass_data
from chargedesign.designer.physical_setup import Binding, PhysicalInfeasible, PhysicalSetup
from chargedesign.designer.whole_inertia import WholeTerms
from chargedesign.errors import ChargeDesignError, InfeasibleError, SolverError
from chargedesign.files import atomic_directory
from chargedesign.formatting import CELL, PLAIN, PRECISE, fmt
from chargedesign.physical.limits import check_limits
from chargedesign.physical.realism import field_response, k_law
from chargedesign.physical.window import (
    REALISED_FRACTION,
    RealisedWindow,
    WindowModel,
    plot_window,
    solve_window,
    window_model,
)
from chargedesign.results import Result
from chargedesign.scene.design_realism import induced_text, parasitic_text

#: relative width of the final bracket [s_max, s_above]
FRONTIER_RTOL = 1e-2
#: after bisection, rates (1 + rtol)^k above the bracket that must fail too
UPWARD_STEPS = (1, 2, 4)
UPWARD_RESTARTS = 3
#: how far below the necessary bound a feasible rate is searched for
LOWEST_RATE_FRACTION = 1e-9
#: without charge conditions (no necessary bound): rates 10x apart are tried up to this
HIGHEST_RATE = 1e15
#: rates below s_max tried when the forward check or the limits check refuses the body there
ACCEPT_RETRIES = 3
#: the charges' minmax (:func:`~chargedesign.designer.frontier_probes.charges_rate_limit`)
#: closes its gap to this fraction of the frontier's rtol
CHARGES_GAP_FRACTION = 0.1
#: with the charges' limit s_c known, the rates designed first: s_c (1 - rtol / 4), then
#: s_c / (1 + rtol) (None)
DIRECT_STEPS = (0.25, None)
#: a ranking frontier (``checks=False``) without charge conditions finds its bracket from the
#: masses' rate law (:func:`masses_rate_law`, :func:`_law_bracket`); after this many designed
#: ends that contradict the law's prediction the search without the law decides
LAW_ROUNDS = 12
#: the rates of the bisection's path within this factor of the cell it ends in are designed
#: too, not predicted (the design's outcome is not always monotone in the rate). With 1.15
#: ``--recommend`` on the K = 0 example recommends what the bisection alone does, at its
#: cost (393 designs against 406; 1.0: 163, docs/benchmarks.md)
LAW_VERIFY = 1.0
#: at most this many bodies bring ``s_min`` down to the balance of the body designed there
#: (:func:`_lowest_balanced_rate`)
S_MIN_ROUNDS = 6


@dataclass(repr=False)
class FrontierResult(Result):
    """Where the buildable stops for one scene.

    Attributes
    ----------
    s_max : float
        Largest time rate the body realises within every limit and the design accepts
        (0: none).
    n : float
        The theorem's n at rate 1, 1/s.
    K : float
        The theorem's K at rate 1, 1/s.
    larmor : str
        The Larmor reading (``charges`` or ``frame``).
    n_max : float or None
        ``s_max * n`` for ``charges``; None for ``frame``, where n is free (a rotation of
        axes: the body realises n = 0, so any n reads its motion in turning axes).
    K_max : float
        ``s_max * K``, 1/s: the largest K the body realises.
    period : float
        ``2 pi / n_max``, s (inf when n_max is 0 or None).
    binding : Binding
        What fails just above ``s_max``.
    s_necessary : float
        The charges' own-field upper bound on s (inf without charge conditions).
    s_charges : float or None
        The largest rate the charges allow, from their minmax
        (:func:`~chargedesign.designer.frontier_probes.charges_rate_limit`; an upper bound on
        ``s_max``: no charges exist above it); None when not computed.
    s_min : float
        Under gravity, the lowest rate whose balance the forward check confirms (0 without
        gravity); ``balance`` gives the numbers at ``s_max``.
    field_response : dict
        The applied field acting on the parts' materials of the body designed at ``s_max``
        (:func:`chargedesign.physical.realism.field_response`): induced magnetisation and
        eddy torques as fractions of the designed torques.
    smallest_charge : float
        The smallest carrier charge of that body, C.
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
    K: float = 0.0
    larmor: str = "charges"
    s_min: float = 0.0
    balance: dict[str, Any] = field(default_factory=dict)
    #: the smallest |q| of the body designed at s_max, C (0: no charges)
    smallest_charge: float = 0.0
    s_charges: float | None = None
    #: the realised window (:mod:`chargedesign.physical.window`); None when not computed
    realised: RealisedWindow | None = None
    #: the K law's item (:func:`chargedesign.physical.realism.k_law`): the induced
    #: magnetisation at the K frontier over the designed K torques C K_max^2, the one figure
    #: of that effect the frontier prints (empty: the law does not apply)
    k_law: dict[str, Any] = field(default_factory=dict)
    #: whose parts the K law's figure measures
    k_law_body: str = ""
    #: the induced magnetisation's one figure of the body at the scene's rate
    #: (:func:`chargedesign.physical.budget.induced_magnetisation`, as design.json's
    #: ``realism.induced_magnetisation``; empty: no such body)
    induced: dict[str, Any] = field(default_factory=dict)
    #: a general case's name (None: the theorem's body, whose n and K the rate scales)
    case: str | None = None

    @property
    def n_free(self) -> bool:
        return self.larmor == "frame"

    @property
    def n_max(self) -> float | None:
        return None if self.n_free else self.s_max * self.n

    @property
    def K_max(self) -> float:
        return self.s_max * self.K

    @property
    def period(self) -> float:
        n_max = self.n_max
        return 2 * math.pi / n_max if n_max is not None and n_max > 0 else math.inf

    def to_dict(self) -> dict[str, Any]:
        return {
            "s_max": self.s_max,
            "n_max": self.n_max,
            "K_max": self.K_max,
            "larmor": self.larmor,
            "n_free": self.n_free,
            "period_s": self.period if math.isfinite(self.period) else None,
            "binding": self.binding.text(self.medium),
            "binding_detail": self.binding.to_dict(),
            "s_above": self.s_above,
            "s_necessary": self.s_necessary if math.isfinite(self.s_necessary) else None,
            "s_charges": (
                self.s_charges
                if self.s_charges is not None and math.isfinite(self.s_charges)
                else None
            ),
            "s_min": self.s_min,
            "balance": dict(self.balance),
            "medium": self.medium,
            "evaluations": self.evaluations,
            "seconds": self.seconds,
            "field_response": dict(self.field_response),
            "smallest_charge_C": self.smallest_charge,
            "k_law_induced_ratio": self._k_law_figure(),
            "induced_magnetisation": dict(self.induced) or None,
            **({"realised": self.realised.to_dict()} if self.realised is not None else {}),
            **({"case": self.case} if self.case is not None else {}),
        }

    def _k_law_figure(self) -> dict[str, Any] | None:
        """The K law's one figure: its value, verdict and whose parts it measures (None: the
        law does not apply)."""
        if not self.k_law or self.k_law.get("value") is None:
            return None
        return {
            "name": "the K law",
            "value": self.k_law["value"],
            "of": "the designed K torques C K_max^2 at the K frontier",
            "verdict": self.k_law.get("verdict"),
            "body": self.k_law_body,
        }

    def _summary(self) -> dict[str, Any]:
        return {
            "s_max": self.s_max,
            "K_max": self.K_max,
            "n_max": self.n_max,
            "larmor": self.larmor,
            "binding": self.binding.stage,
            "medium": self.medium,
            "evaluations": self.evaluations,
            "seconds": self.seconds,
        }

    def _text(self) -> str:
        if self.case is not None:
            rate = f"the case {self.case} at time rate s: V x s^2, l x s"
        elif self.n_free:
            rate = (
                f"K_max = {fmt(self.K_max, PRECISE)} 1/s; n is free: the frame reading realises n ="
                " 0 "
                "and any n reads the motion in axes turning at n"
            )
        else:
            period = f"{fmt(self.period, PRECISE)} s" if math.isfinite(self.period) else "none"
            rate = (
                f"n_max = {fmt(self.n_max or 0.0, PRECISE)} 1/s, period 2 pi / n_max = {period}, "
                f"K_max = {fmt(self.K_max, PRECISE)} 1/s"
            )
        lines = [
            f"frontier ({self.larmor} reading): s_max = {fmt(self.s_max, PRECISE)} ({rate}) in "
            f"{self.medium}\n",
            f"binding: {self.binding.text(self.medium)}\n",
        ]
        if self.balance:
            lines.append(
                "balance: under gravity the rate must stay above s_min ="
                f" {fmt(self.s_min, PRECISE)} "
                f"(at s_max the centre of mass must sit within "
                f"{fmt(self.balance['builder_centre_of_mass_within_m'])} m of O for gravity to "
                f"stay below {fmt(self.balance['builder_torque_fraction'], PLAIN)} of the designed "
                f"torques, a builder balancing to {fmt(BUILDER_BALANCE_M, PLAIN)} m; and within "
                f"{fmt(self.balance['centre_of_mass_within_m'])} m for the check's tolerance "
                f"{fmt(self.balance['check_tolerance'], PLAIN)})\n"
            )
        if self.induced:
            # the induced magnetisation's one figure (design.json's, the report's, the verdict's)
            lines.append(f"{induced_text(self.induced)}; the body at the scene's rate\n")
        figure = self._k_law_figure()
        if figure is not None:
            # a law of matter at the K frontier, named as the law (not the figure above)
            lines.append(
                f"the K law (ordinary matter's induced-magnetisation energy range at the K "
                f"frontier, any size and a2): {fmt(figure['value'])} x the designed K torques "
                f"C K_max^2 ({figure['verdict']}; {figure['body']})\n"
            )
        lines += [
            f"the body designed at s_max = {fmt(self.s_max, PRECISE)}, its "
            f"{key.replace('_', ' ')}: {_value_text(item)} of its designed torques at its "
            f"typical rate ({item['verdict']})\n"
            for key, item in self.field_response.items()
            if not key.startswith("induced")  # the induced magnetisation: its one figure
        ]
        if self.realised is not None:
            lines.append(str(self.realised))
        lines.append(f"({self.evaluations} feasibility problems, {self.seconds:.2f} s)\n")
        return "".join(lines)


def _value_text(item: dict[str, Any]) -> str:
    value = item.get("value")
    return "inf" if value is None else f"{fmt(value)}"


def necessary_rate(setup: PhysicalSetup) -> float:
    """Largest s with charges meeting ``A q = s b`` and ``|q_i| <= c0_i - s c1_i`` (one LP)."""
    A, b = setup.systems["charges"]
    bound = setup.rate_bound
    if not np.any(b):
        return bound
    c0 = setup.rest_caps
    c1 = setup.caps_per_rate  # the external field's share per unit rate
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
    res = linprog_highs(
        cost,
        A_ub=A_ub,
        b_ub=c0 / qs,
        A_eq=A_eq,
        b_eq=np.zeros(len(b)),
        bounds=[(0, None)] * (2 * n) + [(0, min(bound, 1e300))],
    )
    if res.status == 3:  # unbounded: the charges' conditions are homogeneous
        return bound
    if res.status != 0 or res.x is None:
        raise SolverError(f"frontier: HiGHS failed on the necessary-rate LP ({res.message})")
    return float(res.x[-1])


def _charges_limit(setup: PhysicalSetup, rtol: float) -> ChargesLimit | None:
    """The charges' limit on the rate, or None when it does not apply (no charge conditions,
    no charges at all, or the minmax's rounds ran out: the bisection alone then)."""
    try:
        limit = charges_rate_limit(setup, gap=CHARGES_GAP_FRACTION * rtol)
    except SolverError:
        return None
    return limit if limit.stage != "none" and 0 < limit.rate < math.inf else None


def _masses_refuse(setup: PhysicalSetup, s: float) -> bool:
    """Whether the magnets-and-masses stage refuses rate ``s`` around the carriers of the
    charges' own-field LP (a cheap guess of the design's carriers; it only orders the
    frontier's probes, never decides one)."""
    A, b = setup.systems["charges"]
    q = lp_charges(A, s * b, setup.charge_caps(s), setup.cost("charges"))
    if q is None:
        return False
    try:
        design_masses(setup, s, charge_support(q))
    except PhysicalInfeasible:
        return True  # the magnets or the masses
    except SolverError:
        return False  # the design will say
    return False


def masses_rate_law(setup: PhysicalSetup) -> float | None:
    """The largest rate the magnets and the ballast allow by their scaling law, for a body
    without charge conditions (None: the law does not apply or has no answer).

    The magnets' conditions ``A_d sigma = s^2 b_d`` are homogeneous in ``(sigma, s^2)``; the
    masses' ``A_m w = b_m`` do not depend on the rate; a magnet weighs at least its volume and
    magnet plus ballast fit in the cell (:func:`~chargedesign.designer.masses.mass_data`, the
    design's own program). So the largest ``t = s^2`` with ``A_d sigma = t b_d`` and the rest
    is one convex program (an SOCP in ``(w, |sigma|, sigma, t)``, Clarabel). The parts' own
    inertia enters at its first estimate (the design's fixed point moves it a little), so the
    rate it gives is where the frontier's bracket starts, never the frontier itself.
    """
    _, b_charges = setup.systems["charges"]
    _, bd = setup.systems["dipoles"]
    if np.any(b_charges) or not np.any(bd) or setup.spec.designs_induced:
        return None
    terms = WholeTerms(setup, np.zeros(0, dtype=int))
    kappa = terms.kappa(setup.spec.ballast.density)
    if kappa <= 0:
        return None
    data = mass_data(setup, 1.0, np.zeros(0, dtype=int), terms.initial(), kappa)
    k = len(data.sites)
    free = np.flatnonzero(~data.blocked)
    kf = len(free)
    if kf == 0:
        return None
    n = k + 4 * kf + 1  # (w, |sigma| bounds, sigma, t)
    tau, sig, t = k, k + kf, n - 1
    md, mm = len(data.bds), len(data.bms)
    sig_cols = (3 * free[:, None] + np.arange(3)).reshape(-1)
    A = np.zeros((md + mm, n))
    A[:md, sig : sig + 3 * kf] = data.Ads[:, sig_cols]
    A[:md, t] = -data.bds
    A[md:, :k] = data.Ams
    b = np.concatenate([np.zeros(md), data.bms])
    rows = np.arange(k)
    G = np.zeros((2 * k + 1, n))
    G[rows, rows] = -1.0  # -w + alpha |sigma| <= 0
    G[free, tau + np.arange(kf)] = data.alpha
    G[k + rows, rows] = data.gamma  # gamma w + beta |sigma| <= 1
    G[k + free, tau + np.arange(kf)] = data.beta[free]
    G[2 * k, t] = -1.0  # t >= 0
    h = np.concatenate([np.zeros(k), np.ones(k), [0.0]])
    G_soc = np.zeros((kf, 4, n))  # (|sigma|, sigma) in Q4 on every free site
    G_soc[np.arange(kf), 0, tau + np.arange(kf)] = -1.0
    for j in range(3):
        G_soc[np.arange(kf), 1 + j, sig + 3 * np.arange(kf) + j] = -1.0
    cost = np.zeros(n)
    cost[t] = -1.0
    program = ConeProgram(
        cost, A, b, G, h, G_soc, np.zeros((kf, 4)), "frontier: the masses' rate law"
    )
    try:
        x = program.solve_clarabel()
    except SolverError:
        return None
    if x is None or not x[t] > 0 or not np.isfinite(x[t]):
        return None
    return math.sqrt(float(x[t]))


def _limit_binding(setup: PhysicalSetup, limit: ChargesLimit) -> Binding:
    """What refuses every rate above the charges' limit (proved: no charges exist there)."""
    if limit.stage == "fields":
        return Binding(
            "fields",
            f"fields.electric.max ({fmt(setup.spec.field_limits.get('electric'), PLAIN)} V/m) over"
            " the "
            "body region",
            "fields.electric",
            1.0,
            proved=True,
        )
    medium = setup.spec.medium
    return Binding(
        "charges",
        f"no charges meet the conditions above s = {fmt(limit.rate, CELL)} with every carrier's "
        f"surface field within the safe field of {medium.name} ({fmt(setup.safe_field)} V/m): "
        "at the best charges the carriers' fields add up to it here",
        f"charge at {np.array2string(setup.points[limit.worst_site], precision=4)} m",
        1.0,
        proved=True,
    )


def _probe_body(setup: PhysicalSetup, s: float) -> tuple[Design | None, Binding | None]:
    """The body at rate ``s`` and what refuses it among the design's per-rate limits: both
    stages (:func:`~chargedesign.designer.assembly.design_at_rate`) and the balance under
    gravity (a ``balance`` binding, with the body, means ``s`` is too slow)."""
    try:
        design = build_design(setup, design_at_rate(setup, s))
    except PhysicalInfeasible as exc:
        return None, exc.binding
    except SolverError as exc:
        # one rate's design failing (e.g. a polish that leaves a magnet lighter than its
        # volume) refuses that rate; it does not end the search
        return None, Binding("design", str(exc), "design")
    balance = balance_bound(design)
    if balance is None:
        return design, None
    design.balance = balance.to_dict()
    if balance.confirmed:
        return design, None
    return design, Binding("balance", balance.text(), "centre of mass")


def _balance_fails(design: Design, s: float) -> bool:
    balance = design.balance or {}
    return bool(balance) and not float(balance.get("lowest_rate") or math.inf) <= s


def _accept_body(design: Design, responses: dict[int, Any] | None = None) -> Binding | None:
    """The rest of the design's acceptance on a body whose limits and balance hold: the
    limits recomputed from the written parts and the forward check (None: accepted).

    The forward check recomputes the limits of a physical body itself (they do not depend on
    the parameters it compares with), so they are read from its report, not computed twice;
    they speak first, as in ``design``."""
    try:
        report = body_check(design)
    except ChargeDesignError as exc:
        limits = check_limits(design)
        if not limits.parts_within_limits:
            return Binding("limits", limits.violations[0], "limits check")
        return Binding("forward", f"the forward check could not run ({exc})", "check")
    limits = report.limits if report.limits is not None else check_limits(design)
    if responses is not None and limits.field_response:
        # the limits check's field response of this body (the frontier reports it: not twice)
        responses[id(design)] = (design, limits.field_response)
    if not limits.parts_within_limits:
        return Binding("limits", limits.violations[0], "limits check")
    if report.passed:
        return None
    errors = failed_quantities(report)
    return Binding(
        "forward",
        f"the body misses the theorem in the forward check ({errors} against tol"
        f" {fmt(report.tol, PLAIN)})",
        "forward check",
    )


def _response_at(design: Design | None, responses: dict[int, Any]) -> dict[str, Any]:
    """The field response of the body designed at the frontier (empty when none; the one its
    acceptance computed when it has)."""
    if design is None:
        return {}
    known = responses.get(id(design))
    if known is not None and known[0] is design:
        return dict(known[1])
    return field_response(design)


def no_buildable_rate(balance: dict[str, Any], s_max: float, K_max: float) -> str:
    """The one line of a frontier whose balance bound lies above its largest rate."""
    g = balance["gravity_m_per_s2"] / STANDARD_GRAVITY
    gravity = "1 g" if abs(g - 1) <= 0.01 else f"{fmt(g)} g"
    return (
        f"no buildable rate: under {gravity} the centre of mass must sit within "
        f"{fmt(balance['builder_centre_of_mass_within_m'])} m of O at s_max = {fmt(s_max, PRECISE)}"
        " "
        f"(K_max = {fmt(K_max)} 1/s) for gravity to stay below "
        f"{fmt(balance['builder_torque_fraction'], PLAIN)} of the designed torques (a builder"
        " balances "
        f"to about {fmt(balance['builder_balance_m'], PLAIN)} m), and within "
        f"{fmt(balance['centre_of_mass_within_m'])} m for the forward check's tolerance "
        f"{fmt(balance['check_tolerance'], PLAIN)} (double precision holds "
        f"{fmt(balance['balance_held_m'])} m); rates are accepted from s = "
        f"{fmt(balance['lowest_rate'], PRECISE)}, above s_max"
    )


@dataclass
class _Search:
    """The state of one frontier search: every rate designed, the bodies kept, the lowest
    rate whose refusal is proved, and the bracket ``[lo, hi]`` with what refuses ``hi``."""

    setup: PhysicalSetup
    rtol: float
    progress: Any
    s_nec: float
    t0: float
    s_lp: float = 0.0  # reported: the own-field LP's bound
    s_charges: float | None = None
    history: list[tuple[float, bool]] = field(default_factory=list)
    #: the body at the highest rate probed whose limits hold (its field response and balance
    #: are reported)
    best: dict[float, Design] = field(default_factory=dict)
    #: the lowest rate whose refusal is proved (Binding.proved: a relaxation of the limits is
    #: infeasible there, so at every faster rate too): faster rates are refused unprobed
    proved: list[tuple[float, Binding]] = field(default_factory=list)
    lo: float = 0.0
    hi: float = 0.0
    hi_binding: Binding | None = None
    upper_binding: Binding | None = None
    accepted_at: float | None = None
    #: the lowest rate refused by the direct steps, and why
    first: tuple[float, Binding] | None = None
    #: the checks around the bracket after bisection (False: a frontier only ranked)
    checks: bool = True
    #: what each rate designed gave (a rate is designed once; the caller's accepted rate
    #: is known without a design)
    outcomes: dict[float, tuple[bool, Binding | None]] = field(default_factory=dict)
    #: the field response each accepted body's limits check computed (by the body's id,
    #: with the body: an id is only unique while its object lives)
    responses: dict[int, Any] = field(default_factory=dict)
    #: the first rate of the scan without charge conditions (rates 10x apart from it)
    start: float = 1.0

    def probe(self, s: float) -> tuple[bool, Binding | None]:
        """Design at rate ``s`` (unless a proved refusal covers it, or the rate was designed
        already: every rate is designed once): accepted, and why not."""
        known = self.outcomes.get(s)
        if known is not None:
            if all(x != s for x, _ in self.history):
                self.history.append((s, known[0]))
            return known
        if self.proved and s >= self.proved[0][0]:
            self._say(
                f"s = {fmt(s, CELL)}: infeasible (proved at s = {fmt(self.proved[0][0], CELL)})"
            )
            return False, self.proved[0][1]
        design, binding = _probe_body(self.setup, s)
        if design is None and binding is not None and binding.proved:
            self.proved[:] = [(s, binding)]
        # only the balance fails: the limits hold and the rate is too slow, not too fast (the
        # upper search goes on; s_min decides below)
        ok = design is not None
        if design is not None and all(s > known for known in self.best):
            self.best.clear()
            self.best[s] = design
        self.history.append((s, ok))
        self.outcomes[s] = (ok, binding)
        self._say(f"s = {fmt(s, CELL)}: {'feasible' if ok else 'infeasible'}")
        return ok, binding

    def _say(self, text: str) -> None:
        if self.progress is not None:
            self.progress(text)

    def result(
        self, lo: float, hi: float, binding: Binding, design: Design | None
    ) -> FrontierResult:
        theorem = self.setup.theorem_params
        return FrontierResult(
            s_max=lo,
            n=theorem.n,
            binding=binding,
            s_necessary=self.s_lp,
            s_above=hi,
            evaluations=len(self.history),
            seconds=time.perf_counter() - self.t0,
            medium=self.setup.spec.medium.name,
            history=self.history,
            field_response=_response_at(design, self.responses),
            K=theorem.K,
            larmor=_reading(self.setup),
            case=None if self.setup.model_record is None else self.setup.model_record["name"],
            smallest_charge=(
                float(np.min(np.abs(design.charge_values)))
                if design is not None and len(design.charge_values)
                else 0.0
            ),
            s_charges=self.s_charges,
        )


def _reading(setup: PhysicalSetup) -> str:
    return setup.larmor.reading if setup.larmor is not None else "charges"


def _necessary_binding(setup: PhysicalSetup, s_nec: float) -> Binding:
    """What refuses rates just above the necessary bound: the own-field LP, or the
    apparatus' electric field when it sets that bound."""
    medium = setup.spec.medium.name
    if math.isfinite(setup.rate_bound) and s_nec >= setup.rate_bound * (1 - 1e-12):
        return Binding(
            "fields",
            f"fields.electric.max ({fmt(setup.spec.field_limits.get('electric'), PLAIN)} V/m) over"
            " the "
            "body region",
            "fields.electric",
        )
    return Binding(
        "charges",
        f"the carriers' own surface fields reach the safe field of {medium} "
        f"({fmt(setup.safe_field)} V/m)",
        "the carriers",
    )


def _direct_steps(search: _Search, limit: ChargesLimit) -> None:
    """The charges' limit computed directly: no charges exist above it (a proved refusal),
    and when the charges bind, designs just below it close the bracket."""
    setup, rtol = search.setup, search.rtol
    search.s_charges = limit.rate
    top_binding = _limit_binding(setup, limit)
    search.proved[:] = [(limit.rate, top_binding)]
    search.s_nec = min(search.s_nec, limit.rate)
    search.upper_binding = search.hi_binding = top_binding
    search.hi = limit.rate
    # near s_c the design's cone rounds are its dearest: when the masses already fail there
    # around the carriers of the charges' first LP, the bisection starts below instead
    steps = () if _masses_refuse(setup, limit.rate / (1 + rtol)) else DIRECT_STEPS
    for step in steps:
        s_try = limit.rate / (1 + rtol) if step is None else limit.rate * (1 - step * rtol)
        ok, binding = search.probe(s_try)
        design_try = search.best.get(s_try) if ok else None
        if design_try is not None:
            # the balance, if it fails, speaks below (too slow); else the acceptance
            refused = (
                None
                if _balance_fails(design_try, s_try)
                else _accept_body(design_try, search.responses)
            )
            if refused is None:
                search.accepted_at = search.lo = s_try
                return
            binding = refused
        assert binding is not None
        search.hi, search.hi_binding = s_try, binding
        search.first = (s_try, binding)
        if binding.stage != "charges":
            return  # the masses, the balance or the acceptance bind lower: bisect below


def _scan_decades(search: _Search, feasible_rate: float | None) -> None:
    """No charge conditions (frame with K = 0): rates 10x apart up to the first refused."""
    s = feasible_rate or search.start
    search.s_nec = HIGHEST_RATE
    while s < HIGHEST_RATE:
        ok, binding = search.probe(s)
        if not ok:
            search.s_nec, search.upper_binding = s, binding or search.upper_binding
            break
        s *= 10.0
    search.hi_binding = search.upper_binding


def _lowest_feasible(search: _Search, feasible_rate: float | None) -> None:
    """A feasible rate below ``hi``: the caller's, else rates 10x apart downwards (``lo``
    stays 0 when none is found above LOWEST_RATE_FRACTION of the necessary bound)."""
    hi = search.hi
    search.lo = feasible_rate if feasible_rate is not None and feasible_rate < hi else 0.0
    s = hi
    while search.lo == 0.0 and s > search.s_nec * LOWEST_RATE_FRACTION:
        s *= 0.1
        ok, binding = search.probe(s)
        if ok:
            search.lo = s
            return
        search.hi, search.hi_binding = s, binding


def _bisection_path(search: _Search, ok: Any) -> tuple[float, float]:
    """The bracket ``[lo, hi]`` the search without the law (:func:`_scan_decades`,
    :func:`_search_bracket`, :func:`_lowest_feasible`, :func:`_bisect`) ends in when rate
    ``s`` is accepted iff ``ok(s)``: the same rates, in the same floating point (lo = 0: none
    accepted)."""
    rtol = search.rtol
    s, s_nec = search.start, HIGHEST_RATE
    while s < HIGHEST_RATE:
        if not ok(s):
            s_nec = s
            break
        s *= 10.0
    if ok(s_nec):
        return s_nec, s_nec * (1 + rtol)
    lo, hi, s = 0.0, s_nec, s_nec
    while lo == 0.0 and s > s_nec * LOWEST_RATE_FRACTION:
        s *= 0.1
        if ok(s):
            lo = s
        else:
            hi = s
    if lo == 0.0:
        return 0.0, hi
    while hi / lo > 1 + rtol:
        mid = math.sqrt(lo * hi)
        if ok(mid):
            lo = mid
        else:
            hi = mid
    return lo, hi


def _law_bracket(search: _Search, law: float) -> bool:
    """The bisection's own bracket, found from the masses' rate law (:func:`masses_rate_law`).

    The search without the law visits rates 10x apart, then bisects in ``log s``; it ends in
    the one cell of its grid where the design passes from accepted to refused. Here that
    path is followed with the outcomes the law predicts (accepted up to ``x``, the law at
    first) and only the cell it ends in is designed: accepted below, refused above, the
    bracket is the bisection's, so ``s_max``, its body and the binding are those the search
    without the law finds wherever the design's outcome is monotone in the rate (the rates of
    the path within :data:`LAW_VERIFY` of that cell are designed too). When a designed rate
    contradicts the prediction, ``x`` moves past it (by steps doubling in ``log s``) and the
    path is followed again, every rate designed keeping its outcome.
    After LAW_ROUNDS contradictions the search without the law decides (False: no rate
    accepted).
    """
    x, factor = law, 1 + search.rtol
    visited: list[float] = []

    def predicted(s: float) -> bool:
        visited.append(s)
        known = search.outcomes.get(s)
        return known[0] if known is not None else s <= x

    for _ in range(LAW_ROUNDS):
        visited.clear()
        lo, hi = _bisection_path(search, predicted)
        if lo == 0.0:
            break
        near = [r for r in visited if lo / LAW_VERIFY <= r <= hi * LAW_VERIFY]
        todo = [r for r in dict.fromkeys([lo, hi, *near]) if r not in search.outcomes]
        if not todo:
            known = search.outcomes[hi]
            search.lo, search.hi, search.hi_binding = lo, hi, known[1]
            return True
        for r in todo:
            ok = search.probe(r)[0]
            if ok != (r <= x):  # the prediction was wrong there: move it past r
                x, factor = (r * factor, factor * factor) if ok else (r / factor, factor * factor)
                break
    return _search_bracket(search, None)


def _bisect(search: _Search) -> None:
    """Bisection in ``log s`` until ``hi / lo <= 1 + rtol``."""
    while search.hi / search.lo > 1 + search.rtol:
        mid = math.sqrt(search.lo * search.hi)
        ok, binding = search.probe(mid)
        if ok:
            search.lo = mid
        else:
            search.hi, search.hi_binding = mid, binding


def _rates_above(search: _Search) -> list[float]:
    """Rates above the bracket the design must refuse: ``(1 + 2 rtol) lo`` and
    ``(1 + rtol)^k hi`` below the necessary bound (those within rtol / 4 of one already
    listed tell nothing new)."""
    above = [search.lo * (1 + 2 * search.rtol)]
    for k in UPWARD_STEPS:
        s_up = search.hi * (1 + search.rtol) ** k
        if s_up < search.s_nec and all(abs(s_up / x - 1) > search.rtol / 4 for x in above):
            above.append(s_up)
    return above


def _bisect_with_restarts(search: _Search) -> None:
    """Bisection, then the checks around the bracket.

    The heuristic feasibility (LP rounds, then cones; the carriers the masses must balance)
    is not exactly monotone in s: rates a little above the bracket, and (1 + 2 rtol) s_max,
    which design must refuse, are tried, and a success reopens the bracket; (1 - 2 rtol)
    s_max, which design must accept, is tried too.
    """
    rtol = search.rtol
    if not search.checks:
        _bisect(search)  # a ranking frontier (recommend): the bracket alone
        return
    for _ in range(UPWARD_RESTARTS + 1):
        _bisect(search)
        found = next((s_up for s_up in _rates_above(search) if search.probe(s_up)[0]), None)
        if found is not None:
            search.lo = found
            search.hi = min(search.s_nec, found * (1 + rtol) ** 4)
            search.hi_binding = search.upper_binding
            ok, binding = search.probe(search.hi)
            if ok:
                search.lo = search.hi
                return
            search.hi_binding = binding
            continue
        below = search.lo * (1 - 2 * rtol)
        ok, binding = search.probe(below)
        if ok:
            return
        # refused just below: the frontier lies under it
        search.hi, search.hi_binding = below, binding
        feasible_below = [x for x, good in search.history if good and x < below]
        if not feasible_below:
            return
        search.lo = max(feasible_below)


def _accept_lowest(search: _Search) -> Design | None:
    """The rest of the design's acceptance (limits recomputed from the parts, forward check)
    at the rate reported. It does not depend on the rate but through the balance, so it runs
    once, and a refusal moves the frontier down to the next rate probed feasible."""
    design = search.best.get(search.lo)
    for _ in range(ACCEPT_RETRIES):
        if design is None:
            # the rate given by the caller was not probed here
            design, _ = _probe_body(search.setup, search.lo)
        if design is None or _balance_fails(design, search.lo):
            return design  # the balance speaks below
        refused = (
            None if search.lo == search.accepted_at else _accept_body(design, search.responses)
        )
        if refused is None:
            return design
        search.hi, search.hi_binding = search.lo, refused
        lower_rates = [x for x, good in search.history if good and x < search.lo]
        search.lo = max(lower_rates, default=0.0)
        design = None
        if search.lo == 0.0:
            return None
    search.lo = 0.0
    return None


def _search_bracket(search: _Search, feasible_rate: float | None) -> bool:
    """Close the bracket below the direct steps (False: no feasible rate was found)."""
    if search.accepted_at is not None:
        return True
    if not math.isfinite(search.s_nec):
        _scan_decades(search, feasible_rate)
    checked = (False, None) if search.first is not None else search.probe(search.s_nec)
    if checked[0]:
        search.hi = search.s_nec * (1 + search.rtol)
        search.lo = search.s_nec
        return True
    search.hi, search.hi_binding = (
        search.first if search.first is not None else (search.s_nec, checked[1])
    )
    _lowest_feasible(search, feasible_rate)
    if search.lo == 0.0:
        return False
    _bisect_with_restarts(search)
    return True


def find_frontier(
    setup: PhysicalSetup,
    *,
    rtol: float = FRONTIER_RTOL,
    progress: Any = None,
    feasible_rate: float | None = None,
    feasible: Design | None = None,
    direct: bool | None = None,
    window: WindowOptions | None = None,
    checks: bool = True,
    law: bool | None = None,
    start: float = 1.0,
) -> FrontierResult:
    """The largest time rate the design accepts, and the limit that binds above it.

    ``checks``: after bisection, design the rates just above and below the bracket that
    guard against the heuristic's non-monotonicity (False: the bracket alone, for a frontier
    only ranked against others, as :func:`~chargedesign.designer.recommend.recommend` ranks
    its choices before it locates the best one with them).

    ``feasible_rate``: a rate already known to be accepted (e.g. the one just designed),
    which starts the bracket and saves the search for a feasible point; ``feasible`` its
    body, which then need not be designed again if the frontier ends there. The bracket
    ``[s_max, s_above]`` ends narrower than ``1 + rtol``. ``direct``: bracket the frontier
    from the charges' limit first (see the module doc; False: the bisection alone). By
    default it is used for the ``frame`` reading, where the charges bind (the default body:
    1 design instead of 11); the ``charges`` reading's carriers weigh on the masses, which
    bind first on the default body, and the design near the charges' limit cost more than
    the bisection saved (49 s against 22 s, docs/benchmarks.md).

    ``law``: on a body without charge conditions, start the bracket at the masses' rate law
    (:func:`masses_rate_law`; the K = 0 example: 2 designs instead of 8 at rtol 0.05) instead
    of rates 10x apart and bisection from them. The bracket found is as narrow, but its end
    ``s_max`` is another point of it. By default (None) used for a frontier only ranked
    (``checks=False``), so ``chargedesign frontier`` keeps its s_max.

    ``start``: without charge conditions, the first rate of the scan 10x apart (the bracket
    lies on the grid ``start 10^(j / 2^k)``). A body ``4^k`` times the size of another (the
    same materials) has the other's masses program at twice the rate (:class:`~chargedesign.
    designer.masses.SimilarBodies`): started at ``2^-k``, its frontier follows the other's
    path and shares its designs (:func:`~chargedesign.designer.recommend.recommend`).

    Raises
    ------
    InfeasibleError
        Under gravity, when the balance the check can confirm needs a rate above ``s_max``
        ("no buildable rate: ...").
    """
    t0 = time.perf_counter()
    search = _Search(
        setup, rtol, progress, s_nec=necessary_rate(setup), t0=t0, checks=checks, start=start
    )
    search.s_lp = search.s_nec
    if direct is None:
        direct = _reading(setup) == "frame"
    if feasible_rate is not None and feasible is not None:
        search.best[feasible_rate] = feasible
        search.outcomes[feasible_rate] = (True, None)
    if not search.s_nec > 0:
        front = search.result(0.0, 0.0, _external_field_binding(setup), None)
        if window is not None:
            front.realised = realised_window(search, front, None, window)
        return front
    search.upper_binding = search.hi_binding = _necessary_binding(setup, search.s_nec)
    limit = _charges_limit(setup, rtol) if direct and math.isfinite(search.s_nec) else None
    if limit is not None:
        _direct_steps(search, limit)
    if law is None:
        law = not checks
    law_rate = (
        masses_rate_law(setup)
        if law and feasible_rate is None and math.isinf(search.s_nec)
        else None
    )
    found = (
        _law_bracket(search, law_rate)
        if law_rate is not None
        else _search_bracket(search, feasible_rate)
    )
    if not found:
        assert search.hi_binding is not None
        front = search.result(0.0, search.hi, search.hi_binding, None)
        if window is not None:
            front.realised = realised_window(search, front, None, window)
        return front
    assert search.hi_binding is not None
    design = _accept_lowest(search)
    front = search.result(search.lo, search.hi, search.hi_binding, design)
    if design is not None:
        front.k_law = k_law(design, front.field_response)
        front.k_law_body = f"the body designed at s_max = {fmt(front.s_max, PRECISE)}"
    _record_balance(front, design, search.lo)
    if front.s_min > 0 and math.isfinite(front.s_min):
        front.s_min = _lowest_balanced_rate(setup, front.s_min, rtol)
    if window is not None:
        front.realised = realised_window(search, front, design, window)
        front.seconds = time.perf_counter() - t0
    return front


def _external_field_binding(setup: PhysicalSetup) -> Binding:
    """No rate at all: the external electric field alone exceeds the safe field."""
    return Binding(
        "charges",
        f"the external electric field alone exceeds the safe field of {setup.spec.medium.name}",
        "fields.electric",
    )


def _record_balance(front: FrontierResult, design: Design | None, s_max: float) -> None:
    """The balance under gravity and the lowest buildable rate; refused above ``s_max``."""
    balance = (design.balance if design is not None else None) or {}
    if balance:
        front.balance = dict(balance)
        front.s_min = float(balance.get("lowest_rate") or math.inf)
        if not front.s_min <= s_max:
            raise InfeasibleError(no_buildable_rate(balance, s_max, front.K_max))


def _lowest_balanced_rate(setup: PhysicalSetup, s: float, rtol: float) -> float:
    """The lowest rate whose own body the balance accepts, from ``s``: the bound the body at
    ``s_max`` gives takes that body's mass, and a body designed at a lower rate is lighter
    (its magnets and their ballast go as ``s^2``), so ``s <- lowest_rate(body(s))`` while it
    falls by more than ``rtol``, each rate kept only when its own body is accepted there."""
    best = s
    for _ in range(S_MIN_ROUNDS):
        body, binding = _probe_body(setup, s)
        if body is None or binding is not None:
            break
        best = s
        lower = float((body.balance or {}).get("lowest_rate") or math.inf)
        if not lower < s * (1.0 - rtol):
            break
        s = lower
    return best


@dataclass(frozen=True)
class WindowOptions:
    """How the realised window is found: each parasitic below ``fraction`` of every realised
    term, gravity ``gravity`` (m/s^2: 1 g for a lab on Earth, 0 in free fall)."""

    fraction: float = REALISED_FRACTION
    gravity: float = STANDARD_GRAVITY

    def __post_init__(self) -> None:
        # the scene's [design] keys and the command line's ranges (limits.OPTION_RANGES)
        # check both before the run: out of range here is a caller's mistake
        if not 0 < self.fraction < 1:
            raise ValueError(f"fraction: expected a number between 0 and 1, got {self.fraction}")
        if not 0 <= self.gravity < math.inf:
            raise ValueError(f"gravity: expected a number >= 0 (m/s^2), got {self.gravity}")


#: bodies designed to confirm a window: at most this many corrections of an end
CONFIRM_STEPS = 3


def _measured(
    search: _Search, s: float, options: WindowOptions
) -> tuple[dict[str, Any], WindowModel | None]:
    """A body designed at ``s`` and accepted, what its own parts measure there (the window's
    laws are not used: the independent route), and the laws of that body."""
    design, binding = _probe_body(search.setup, s)
    if design is not None and binding is None:
        binding = _accept_body(design)
    if design is None or binding is not None:
        assert binding is not None
        medium = search.setup.spec.medium.name
        return {"s": s, "accepted": False, "refused": binding.text(medium)}, None
    model = window_model(design, s, fraction=options.fraction, gravity=options.gravity)
    ratios = model.ratios(s)
    worst = max(ratios, key=lambda k: ratios[k]) if ratios else "none"
    entry = {
        "s": s,
        "accepted": True,
        "worst": worst,
        "measured": ratios.get(worst, 0.0) / options.fraction,
        "ratios": {k: v / options.fraction for k, v in ratios.items()},
    }
    return entry, model


def _confirm_end(
    search: _Search,
    window: RealisedWindow,
    model: WindowModel,
    low: bool,
    options: WindowOptions,
    front: FrontierResult,
) -> list[dict[str, Any]]:
    """Design at one end of the window and let that body's own laws move the end (the laws
    of the body at s_max assume the other parts fixed; the body designed near the end knows
    better). An end whose body is refused or measures a parasitic above the fraction moves
    back inwards. At most CONFIRM_STEPS bodies."""
    out: list[dict[str, Any]] = []
    confirmed: tuple[float, str] | None = None
    for _ in range(CONFIRM_STEPS):
        assert window.s_low is not None and window.s_high is not None
        s = window.s_low if low else window.s_high
        if not low and s == search.lo:
            return out  # the frontier's own body, accepted there
        entry, local = _measured(search, s, options)
        entry["predicted"] = max(model.ratios(s).values(), default=0.0) / options.fraction
        out.append(entry)
        if entry["accepted"] and entry["measured"] <= 1.0:
            confirmed = (s, window.binding_low if low else window.binding_high)
            assert local is not None
            window.end_laws["low" if low else "high"] = local  # the picture draws these laws
            again = solve_window(
                local,
                front.s_min if low else s,
                s if low else front.s_max,
                floor_text=window.binding_low,
                ceiling_text=window.binding_high,
            )
            end = again.s_low if low else again.s_high
            if again.empty or end is None or abs(math.log(end / s)) < math.log1p(search.rtol):
                return out
            window.set_end(low, end, again.binding_low if low else again.binding_high)
            continue
        if confirmed is not None:
            # the body's own laws overreached: back to the rate confirmed
            window.set_end(low, *confirmed)
            return out
        step = (window.s_high / window.s_low) ** 0.25
        if step < 1 + search.rtol:
            window.s_low = window.s_high = None
            return out
        reason = (
            f"the design refuses s = {fmt(s, CELL)} ({entry['refused']})"
            if not entry["accepted"]
            else f"the body designed at s = {fmt(s, CELL)} measures {entry['worst']} "
            f"{parasitic_text(entry['measured'] * options.fraction, window.term_key, s)}"
        )
        window.set_end(low, s * step if low else s / step, reason)
    if confirmed is not None:
        # the last end proposed was not designed: keep the last one confirmed
        window.set_end(low, *confirmed)
    return out


def _why_empty(window: RealisedWindow, law: dict[str, Any] | None) -> str:
    """One line: why no rate realises the body (with the K law's one figure where it
    applies: ``law``, the :func:`~chargedesign.physical.realism.k_law` item; None: no body)."""
    if law is None:
        return "no rate is buildable: " + window.binding_high
    worst = window.missing * window.fraction
    head = (
        f"at the best rate the worst parasitic ({window.binding_low.split(' (')[0]}) is "
        f"{parasitic_text(worst if math.isfinite(worst) else None, window.term_key, window.s_best)}"
        " by the window's laws"
    )
    if not law or law.get("value") is None:
        return head
    return (
        f"the K term cannot be realised by ordinary matter: the K law is {fmt(law['value'])} x "
        f"the designed K torques C K_max^2 at the K frontier, for any size and a2 (the "
        f"size-free law 6 (chi/rho) / (mu0 G^2), G = K_max / a2 = {fmt(law['G_C_m_per_kg'])} "
        f"C m/kg; design.json's realism k_law_induced_ratio); {head}"
    )


def restate_k_law(front: FrontierResult, law: dict[str, Any], body: str) -> None:
    """Give the frontier the K law's figure of ``body`` (the body ``design`` records, judged
    at this frontier's K_max), so the frontier, its window's why-line, the report and the
    budget print one number for the induced magnetisation."""
    front.k_law, front.k_law_body = dict(law), body
    if front.realised is not None and front.realised.empty and front.realised.why:
        if not front.realised.why.startswith("no rate is buildable"):
            front.realised.why = _why_empty(front.realised, law)


def realised_window(
    search: _Search, front: FrontierResult, design: Design | None, options: WindowOptions
) -> RealisedWindow:
    """The realised window below the frontier (:mod:`chargedesign.physical.window`): the laws
    of the body at ``s_max``, then bodies designed at the window's ends confirm it (an end
    whose body is refused or measures a parasitic above the fraction moves inwards)."""
    medium = search.setup.spec.medium.name
    ceiling_text = "the frontier s_max: " + front.binding.text(medium)
    if design is None or front.s_max <= 0:
        window = RealisedWindow(
            None,
            None,
            "no buildable rate",
            ceiling_text,
            options.fraction,
            0.0,
            math.inf,
            "none",
            {},
            {},
        )
        window.why = _why_empty(window, None)
        return window
    search._say("realised window ...")
    model = window_model(design, front.s_max, fraction=options.fraction, gravity=options.gravity)
    floor_text = (
        f"the balance the forward check confirms (s_min = {fmt(front.s_min, CELL)})"
        if front.s_min > 0
        else "no parasitic binds down to s_max / 1e12"
    )
    window = solve_window(
        model, front.s_min, front.s_max, floor_text=floor_text, ceiling_text=ceiling_text
    )
    if not window.empty:
        window.confirmed += _confirm_end(search, window, model, True, options, front)
        if not window.empty:
            window.confirmed += _confirm_end(search, window, model, False, options, front)
    if window.empty:
        window.why = _why_empty(window, front.k_law)
    else:
        assert window.s_low is not None and window.s_high is not None
        window.s_best = math.sqrt(window.s_low * window.s_high)
        window.margins = {k: v / options.fraction for k, v in model.ratios(window.s_best).items()}
    return window


def write_window_picture(front: FrontierResult, out: Any) -> None:
    """``out/realised_window.png``: the window's laws against the rate (atomic directory)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    assert front.realised is not None
    with atomic_directory(out) as stage:
        fig = window_figure(front.realised, front.s_max)
        fig.savefig(stage / "realised_window.png", dpi=120)
        plt.close(fig)


def window_figure(window: RealisedWindow, s_max: float) -> Any:
    """The realised window's picture (a matplotlib Figure): the laws each end is solved from.

    The window's ends come from the laws of the bodies designed and accepted at each end
    (``window.end_laws``; the body at ``s_max`` where no end body was designed), so below the
    window's geometric middle the curves are the low end body's laws and above it the high
    end body's: each shaded end is where a drawn curve crosses 1 (or a limit drawn as a line:
    the frontier ``s_max``). A dotted line marks where the drawn laws pass from one body to
    the other.
    """
    import dataclasses

    import matplotlib.pyplot as plt

    rates = window.curves.get("s")
    curves = dict(window.curves)
    switch = None
    whose = {"low": "the body at s_max", "high": "the body at s_max"}
    if rates is not None and not window.empty and window.end_laws:
        assert window.s_low is not None and window.s_high is not None
        switch = math.sqrt(window.s_low * window.s_high)
        for side, part in (("low", rates < switch), ("high", rates >= switch)):
            model = window.end_laws.get(side)
            if model is None:
                continue  # this side's end was solved from the laws of the body at s_max
            whose[side] = f"the body designed at s = {fmt(model.s_ref)}"
            own = {
                item.label: np.asarray(item.ratio(rates / model.s_ref), float) / model.fraction
                for item in model.items
            }
            for label in (set(curves) - {"s"}) | set(own):
                values = np.array(curves.get(label, np.zeros_like(rates)), dtype=float)
                values[part] = own.get(label, np.zeros_like(rates))[part]
                curves[label] = values
    fig, ax = plt.subplots(figsize=(7.5, 4.8))
    plot_window(dataclasses.replace(window, curves=curves), s_max, ax=ax)
    for line in ax.get_lines():
        if str(line.get_label()).lstrip("_") in curves:
            line.set_gid("law")  # a drawn law (the tests read the picture's own curves)
    if switch is not None:
        ax.axvline(switch, color="0.6", lw=0.8, ls="-.", label="the laws pass to the other body")
        ax.legend(fontsize=7, loc="best")
        head = ax.get_title().replace(" (the laws of the body at s_max)", "")
        ax.set_title(
            f"{head}\nlaws below s = {fmt(switch)}: {whose['low']}; above: {whose['high']}",
            fontsize=10,
        )
    fig.tight_layout()
    return fig
