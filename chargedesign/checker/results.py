"""What the check reports: quantities, effects, the report and its text.

Part of :mod:`chargedesign.checker` (see its docstring for the method).
"""

from __future__ import annotations

import math
import textwrap
from dataclasses import dataclass, field
from typing import Any

from chargedesign.formatting import AGREEMENT, DIRECTION, ERROR, FLOOR, PLAIN, PRECISE, fmt
from chargedesign.results import Result
from chargedesign.scene.design_realism import induced_text
from chargedesign.vocabulary import VERDICT_STATES

REALISED, NOT_REALISED, _NOT_BUILDABLE, NOT_CHECKED = VERDICT_STATES


# --------------------------------------------------------------------------- results
@dataclass
class QuantityResult:
    """One compared quantity.

    Attributes
    ----------
    name : str
        ``mu``, ``gyroscopic_torque``, ``V``, ``potential_torque`` or ``inertia``.
    rel_err : float
        Largest error over the orientations divided by ``scale`` (see ``basis``).
    abs_err : float
        Largest absolute error (SI units of the quantity).
    scale : float
        The denominator: ``max |x_ref|`` over the orientations (V: the spread of x_ref), or
        the gross contributions when the reference is zero.
    worst_gamma : tuple of float or None
        The orientation of the largest error (None for the inertia).
    claimed : bool
        Whether the design claims it (then it is compared with the tolerance).
    passed : bool or None
        True for status ``pass``, False for ``fail`` and ``unverifiable``, None when not
        claimed (informational).
    status : str
        ``pass``, ``fail``, ``unverifiable`` (the rounding floor of the evaluation exceeds the
        tolerance and the error is not certainly beyond it) or ``info`` (not claimed).
    reason : str or None
        Why a claimed quantity did not pass (one line), else None.
    basis : str
        ``reference`` (rel_err relative to ``max |x_ref|``) or ``gross`` (the reference is
        zero: absolute error relative to the gross contributions).
    gross : float
        Largest (over the orientations) sum of the elements' absolute contributions.
    cancellation : float
        ``gross / max |x_ref|`` (inf for a zero reference): how many times larger the
        cancelling contributions are than the quantity.
    rounding_floor : float
        Attainable accuracy (same units as rel_err) of the evaluation that produced rel_err.
    double_rounding_floor : float
        Attainable accuracy of evaluating this body in double precision (the double kernel,
        ``chargedesign simulate``): ``ROUNDING_FACTOR * EPS * (cancellation + 1)``.
    precision : str
        Arithmetic of the evaluation: ``double`` or ``double-double``.
    """

    name: str
    rel_err: float
    abs_err: float
    scale: float
    worst_gamma: tuple[float, float, float] | None
    claimed: bool
    passed: bool | None
    status: str = "info"
    reason: str | None = None
    basis: str = "reference"
    gross: float = 0.0
    cancellation: float = 0.0
    rounding_floor: float = 0.0
    double_rounding_floor: float = 0.0
    precision: str = "double"

    def to_dict(self) -> dict[str, Any]:
        return {
            "rel_err": self.rel_err,
            "abs_err": self.abs_err,
            "scale": self.scale,
            "worst_gamma": None if self.worst_gamma is None else list(self.worst_gamma),
            "claimed": self.claimed,
            "passed": self.passed,
            "status": self.status,
            "reason": self.reason,
            "basis": self.basis,
            "gross": self.gross,
            # JSON has no infinity: a zero reference has no finite cancellation ratio
            "cancellation": self.cancellation if math.isfinite(self.cancellation) else None,
            "rounding_floor": self.rounding_floor,
            "double_rounding_floor": self.double_rounding_floor,
            "precision": self.precision,
        }


@dataclass
class EffectResult:
    """One physical effect: its size and the agreement of two routes within it.

    Attributes
    ----------
    name : str
        ``lorentz``, ``electric``, ``gravity``, ``magnetization`` or ``inertia``.
    source : str
        ``charges``, ``masses`` or ``dipoles``.
    n_elements : int
        Elements taking part (point elements plus quadrature nodes of continuous bodies).
    active : bool
        True when the effect has both elements and (where it needs one) a non-zero field.
    size : dict[str, float]
        Largest magnitudes over the orientations: ``mu``, ``gyroscopic_torque`` (lorentz);
        ``V_spread`` (max - min of the energy), ``torque`` (electric, gravity,
        magnetization); ``total_mass`` (inertia).
    route_rel_err : float or None
        Relative disagreement of two routes within the effect (informational), or None
        when not computed (inactive, too few orientations for the fit, or an effect whose
        torque cancels so far that its rounding floor exceeds ``NOISE_FLOOR``).
    worst_gamma : tuple of float or None
        Where ``route_rel_err`` occurs.
    """

    name: str
    source: str
    n_elements: int
    active: bool
    size: dict[str, float]
    route_rel_err: float | None = None
    worst_gamma: tuple[float, float, float] | None = None

    def to_dict(self) -> dict[str, Any]:
        return {
            "source": self.source,
            "n_elements": self.n_elements,
            "active": self.active,
            "size": dict(self.size),
            "route_rel_err": self.route_rel_err,
            "worst_gamma": None if self.worst_gamma is None else list(self.worst_gamma),
        }


@dataclass(repr=False)
class CheckReport(Result):
    """Everything :func:`check_design` found.

    Attributes
    ----------
    tol : float
        Relative tolerance of the pass/fail decisions.
    n_orientations : int
        Orientations sampled.
    seed : int
        Seed of the random orientations, azimuths and angular velocities.
    claimed : list[str]
        The design's ``realises``.
    quantities : dict[str, QuantityResult]
        ``mu``, ``gyroscopic_torque``, ``V``, ``potential_torque``, ``inertia``.
    effects : dict[str, EffectResult]
        ``lorentz``, ``electric``, ``gravity``, ``magnetization``, ``inertia``.
    V_offset : float
        The additive constant of the design's V over the theorem's (mean difference), J.
    quadrature : list[dict]
        Per continuous body: kind, shape, degree of exactness used, nodes.
    n_pairs : int
        Element-orientation pairs evaluated.
    notes : list[str]
        Remarks (singular potential terms, nothing claimed, a body verified only in
        double-double, ...).
    precision : str
        Arithmetic of the compared sums: ``double`` or ``double-double``.
    """

    tol: float
    n_orientations: int
    seed: int
    claimed: list[str]
    quantities: dict[str, QuantityResult]
    effects: dict[str, EffectResult]
    V_offset: float
    quadrature: list[dict[str, Any]] = field(default_factory=list)
    n_pairs: int = 0
    notes: list[str] = field(default_factory=list)
    precision: str = "double"
    #: a physical body's limits, recomputed from its elements (None for point elements)
    limits: Any = None
    #: the design's Larmor reading: ``{"reading", "rate", "checked_n"}`` (None: no ``larmor``
    #: key, the charges reading); ``checked_n`` is the n of the theorem compared with
    larmor: dict[str, Any] | None = None

    #: the verdict recomputed from the written parts (:func:`chargedesign.verdict.judge` on
    #: the limits and the realised window recomputed here); None when not asked for
    verdict: dict[str, Any] | None = None
    #: the design's own record (design.json ``verdict``, or what its record gives)
    recorded_verdict: dict[str, Any] | None = None
    #: what the forward check compares with: ``theorem`` or ``case`` (a [case] of (ep))
    reference: str = "theorem"
    #: the induced magnetisation's one figure, recomputed from the written parts
    #: (:func:`chargedesign.physical.budget.induced_magnetisation`); None: not judged
    induced: dict[str, Any] | None = None

    @property
    def parts_within_limits(self) -> bool | None:
        """The limits check for a physical body (every part within its limits, recomputed
        from its elements); None for point elements."""
        return None if self.limits is None else bool(self.limits.parts_within_limits)

    @property
    def buildable(self) -> bool | None:
        """Whether the recomputed verdict calls the parts buildable (``buildable and
        realised`` or ``buildable parts, NOT realised as designed``); None when not checked
        for buildability (point elements, or no verdict computed)."""
        state = (self.verdict or {}).get("state")
        if state is None or state == NOT_CHECKED:
            return None
        return state in (REALISED, NOT_REALISED)

    @property
    def verdict_agrees(self) -> bool | None:
        """The recomputed verdict's state equals the recorded one (None: no verdict)."""
        if self.verdict is None:
            return None
        recorded = (self.recorded_verdict or {}).get("state")
        return recorded == self.verdict["state"]

    @property
    def reproduced(self) -> bool:
        """Every claimed quantity verified within the tolerance: the theorem (or the case)
        reproduced by the written elements."""
        return all(q.passed is not False for q in self.quantities.values())

    @property
    def passed(self) -> bool:
        """True when the theorem is reproduced (:attr:`reproduced`) and a physical body is
        within every limit of its medium and materials (the exit status of ``check``; the
        verdict is :attr:`verdict`)."""
        return self.reproduced and self.parts_within_limits is not False

    @property
    def failures(self) -> list[str]:
        """Names of the claimed quantities that did not pass (``fail`` or ``unverifiable``),
        and ``parts_within_limits`` for a physical body outside its limits."""
        out = [name for name, q in self.quantities.items() if q.passed is False]
        return out + (["parts_within_limits"] if self.parts_within_limits is False else [])

    @property
    def unverifiable(self) -> list[str]:
        """Names of the claimed quantities whose rounding floor exceeds the tolerance."""
        return [name for name, q in self.quantities.items() if q.status == "unverifiable"]

    def to_dict(self) -> dict[str, Any]:
        """JSON mapping: the contract's keys first (``mu_rel_err``, ``V_rel_err``, ...)."""
        out: dict[str, Any] = {}
        for name in ("mu", "V", "inertia", "gyroscopic_torque", "potential_torque"):
            out[f"{name}_rel_err"] = self.quantities[name].rel_err
        out["passed"] = self.passed
        out["tol"] = self.tol
        out["failures"] = self.failures
        out["unverifiable"] = self.unverifiable
        out["reasons"] = {k: q.reason for k, q in self.quantities.items() if q.reason}
        out["precision"] = self.precision
        out["claimed"] = list(self.claimed)
        out["n_orientations"] = self.n_orientations
        out["seed"] = self.seed
        out["n_pairs"] = self.n_pairs
        out["V_offset"] = self.V_offset
        out["quantities"] = {k: v.to_dict() for k, v in self.quantities.items()}
        out["effects"] = {k: v.to_dict() for k, v in self.effects.items()}
        out["quadrature"] = list(self.quadrature)
        out["notes"] = list(self.notes)
        out["reproduced"] = self.reproduced
        out["reference"] = self.reference
        out["parts_within_limits"] = self.parts_within_limits
        out["buildable"] = self.buildable
        if self.verdict is not None:
            out["verdict"] = _public(self.verdict)
            out["recorded_verdict"] = (
                None if self.recorded_verdict is None else _public(self.recorded_verdict)
            )
            out["verdict_agrees"] = self.verdict_agrees
        if self.limits is not None:
            out["limits"] = self.limits.to_dict()
        if self.induced is not None:
            out["induced_magnetisation"] = dict(self.induced)
        if self.larmor is not None:
            out["larmor"] = dict(self.larmor)
        return out

    # result protocol (chargedesign.results): text, compact repr, notebook table
    def _summary(self) -> dict[str, Any]:
        out: dict[str, Any] = {}
        if self.verdict is not None:
            out["verdict"] = self.verdict["state"]
            out["verdict_agrees"] = self.verdict_agrees
        out |= {f"{self.reference}_reproduced": self.reproduced, "tol": self.tol}
        for name in ("mu", "V", "inertia"):
            q = self.quantities.get(name)
            if q is not None:
                out[f"{name}_rel_err"] = q.rel_err
        out["precision"] = self.precision
        out["n_orientations"] = self.n_orientations
        if self.larmor is not None:
            out["larmor"] = self.larmor["reading"]
        if self.parts_within_limits is not None:
            out["parts_within_limits"] = self.parts_within_limits
        if self.failures:
            out["failures"] = list(self.failures)
        return out

    def _text(self) -> str:
        return "\n".join(summary_lines(self))

    def _html_rows(self) -> dict[str, Any]:
        rows = self._summary()
        for name, q in self.quantities.items():
            rows[name] = (
                f"{q.status}: rel_err {fmt(q.rel_err, ERROR)} (floor "
                f"{fmt(q.rounding_floor, FLOOR)})"
            )
        rows.update({f"note {i + 1}": n for i, n in enumerate(self.notes)})
        return rows


def summary_lines(report: CheckReport) -> list[str]:
    """Human-readable lines of a report (the CLI prints them)."""
    lines = [
        f"check: {report.n_orientations} orientations, {report.n_pairs} element-orientation "
        f"pairs, tol {fmt(report.tol, PLAIN)}, evaluated in {report.precision}",
    ]
    if report.larmor is not None:
        lines.append(
            f"larmor reading: {report.larmor['reading']} (rate "
            f"{fmt(report.larmor['rate'], PLAIN)} 1/s); "
            + (
                f"compared with the theorem at n = {fmt(report.larmor['checked_n'], PLAIN)}"
                if report.reference == "theorem"
                else f"compared with the {report.reference}"
            )
        )
    lines += [
        f"{'quantity':<20} {'rel_err':>10} {'floor':>8} {'cancel':>8}  {'status':<10} worst gamma",
    ]
    status = {"info": "info", "pass": "PASS", "fail": "FAIL", "unverifiable": "UNVERIFIED"}
    for name, q in report.quantities.items():
        where = (
            "-"
            if q.worst_gamma is None
            else "(" + ", ".join(f"{fmt(g, DIRECTION)}" for g in q.worst_gamma) + ")"
        )
        cancel = "zero ref" if q.basis == "gross" else fmt(q.cancellation, FLOOR)
        lines.append(
            f"{name:<20} {fmt(q.rel_err, ERROR):>10} {fmt(q.rounding_floor, FLOOR):>8} "
            f"{cancel:>8}  "
            f"{status[q.status]:<10} {where}"
        )
    lines.append(f"{'effect':<14} {'source':<8} {'elements':>8}  size; route agreement")
    for name, e in report.effects.items():
        size = ", ".join(f"{k} {fmt(v, PRECISE)}" for k, v in e.size.items())
        route = (
            ""
            if e.route_rel_err is None
            else f"; routes agree to {fmt(e.route_rel_err, AGREEMENT)}"
        )
        lines.append(f"{name:<14} {e.source:<8} {e.n_elements:>8}  {size}{route}")
    for body in report.quadrature:
        lines.append(
            f"continuous {body['kind']} {body['shape']}: {body['nodes']} nodes, "
            f"exact to degree {body['order']}"
        )
    lines += [f"note: {n}" for n in report.notes]
    lines += [f"{name}: {q.reason}" for name, q in report.quantities.items() if q.reason]
    if report.limits is not None:
        lines.append(str(report.limits))
    if report.induced is not None:
        lines.append(f"{induced_text(report.induced)} (recomputed from the written parts)")
    failed = [name for name, q in report.quantities.items() if q.passed is False]
    lines.append(
        f"{report.reference} reproduced (every claimed quantity within tol)"
        if report.reproduced
        else f"{report.reference} NOT reproduced: " + ", ".join(failed)
    )
    lines += verdict_lines(report)
    return [part for line in lines for part in _wrapped(line)]


def _wrapped(text: str) -> list[str]:
    """Each line of ``text`` wrapped to the terminal's 160 characters."""
    out = []
    for line in text.splitlines():
        out += textwrap.wrap(line, 160, subsequent_indent="  ", break_on_hyphens=False) or [""]
    return out


def _public(verdict: dict[str, Any]) -> dict[str, Any]:
    """The contract's keys of a verdict record (without the report's table rows)."""
    return {k: v for k, v in verdict.items() if k != "rows"}


def verdict_lines(report: CheckReport) -> list[str]:
    """The check's own verdict beside the design's record, and whether they agree."""
    if report.verdict is None:
        return []
    own = report.verdict
    lines = [
        f"verdict (recomputed from the written parts): {own['state']}",
        *(_wrapped(f"  binding: {own['binding']}") if own["state"] != NOT_CHECKED else []),
    ]
    recorded = report.recorded_verdict
    if recorded is None:
        lines.append("recorded verdict: none (design.json has no verdict): cannot compare")
    else:
        agree = "agrees" if report.verdict_agrees else "DISAGREES"
        lines.append(f"recorded verdict (design.json): {recorded['state']}; the check {agree}")
    return lines
