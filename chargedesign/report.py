"""The short human report of a design (``report.md`` beside ``design.json``).

Everything is read from the :class:`~chargedesign.body.Design` and the provenance keys the
design stage writes into it (``residuals``, ``forward_accuracy``, ``objective``, ``solver``,
``timings``, ``candidates``, ``notes``), so a report can be regenerated from a design.json
file.

The plausibility section answers the first question a physicist asks: could this body be
built? A point charge q makes the field ``q / (4 pi eps0 s^2)`` at the distance s of its
neighbours (the candidate spacing); air breaks down near 3 MV/m. A magnetic dipole sigma is
compared with a neodymium magnet (magnetisation about 1e6 A/m), which needs the volume
``sigma / M``.
"""

from __future__ import annotations

import math
import textwrap
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np

from chargedesign.body import Design
from chargedesign.formatting import ORDER, ORDER_SCI, PLAIN, PRECISE, ROUGH, fmt, fmt_length
from chargedesign.physical.bom import bom_rows, bom_totals

# the plausibility figures: the Coulomb field and the material data of the physical design
from chargedesign.physical.coulomb import point_charge_field as charge_field
from chargedesign.physical.limits import CHECK_SURFACE_SAMPLES, within_limits
from chargedesign.physical.materials import BREAKDOWN_V_PER_M, MAGNET_DATA, ballast_label
from chargedesign.physical.sources import cited_keys, sources_table_lines, table_cell
from chargedesign.physical.support import support_lines
from chargedesign.physical.window import BearingSupport, RealisedWindow
from chargedesign.report_records import (
    BudgetItem,
    Cancellation,
    Candidates,
    CaseRecord,
    Frontier,
    KLaw,
    MagnetSpan,
    MapRow,
    Materials,
    Objective,
    PartSizes,
    PartSpan,
    PhysicalRecords,
    Placement,
    ReportRecords,
    Solver,
)
from chargedesign.scene.design_realism import (
    FIELD_RESPONSE_KEYS,
    INDUCED_KEY,
    INDUCED_NAME,
    RESPONSE_FRACTION,
    RealismRecord,
    WindowAtDesign,
    induced_text,
    parasitic_text,
)
from chargedesign.scene.medium import Medium
from chargedesign.verdict import (
    realised_window,
    recorded_verdict,
    verdict_state_line,
    verdict_table,
    verdict_text_table,
)


def _spacing(design: Design, candidates: Candidates | None) -> float | None:
    """The candidates' spacing, else the distance from the largest charge to its nearest."""
    if candidates is not None and candidates.spacing is not None:
        return candidates.spacing
    pts = design.charge_positions
    if len(pts) >= 2:
        i = int(np.argmax(np.abs(design.charge_values)))
        d = np.linalg.norm(pts - pts[i], axis=1)
        d = d[d > 0]
        if len(d):
            return float(d.min())
    return None


@dataclass(frozen=True)
class Plausibility:
    """Figures that say whether the body could be built (SI units); None for the kinds of
    element the design has not (and the field, when no spacing is known)."""

    largest_charge_C: float | None = None
    spacing_m: float | None = None
    field_V_per_m: float | None = None
    field_over_air_breakdown: float | None = None
    largest_dipole_Am2: float | None = None
    ndfeb_volume_m3: float | None = None
    total_mass_kg: float | None = None
    largest_mass_kg: float | None = None

    @classmethod
    def of(cls, design: Design, candidates: Candidates | None) -> Plausibility:
        """The figures of ``design``, whose charges sit on ``candidates`` (when written)."""
        figures: dict[str, float] = {}
        if len(design.charge_values):
            q = float(np.max(np.abs(design.charge_values)))
            s = _spacing(design, candidates)
            figures["largest_charge_C"] = q
            if s is not None:
                field = charge_field(q, s)
                figures |= {
                    "spacing_m": s,
                    "field_V_per_m": field,
                    "field_over_air_breakdown": field / BREAKDOWN_V_PER_M["air"],
                }
        if len(design.dipole_moments):
            sigma = float(np.max(np.linalg.norm(design.dipole_moments, axis=1)))
            figures |= {
                "largest_dipole_Am2": sigma,
                "ndfeb_volume_m3": sigma / MAGNET_DATA["ndfeb"][0],
            }
        if len(design.mass_values):
            figures |= {
                "total_mass_kg": float(np.sum(design.mass_values)),
                "largest_mass_kg": float(np.max(design.mass_values)),
            }
        return cls(**figures)

    def to_dict(self) -> dict[str, float]:
        """The figures the design has (the keys of the others absent)."""
        return {k: v for k, v in asdict(self).items() if v is not None}


def plausibility(design: Design) -> dict[str, Any]:
    """Figures that say whether the body could be built (SI units).

    Returns
    -------
    dict
        ``largest_charge_C``, ``spacing_m``, ``field_V_per_m``, ``field_over_air_breakdown``;
        ``largest_dipole_Am2``, ``ndfeb_volume_m3``; ``total_mass_kg``, ``largest_mass_kg``
        (keys present only for the kinds of element the design has).
    """
    return Plausibility.of(design, Candidates.read(design)).to_dict()


def _fmt(value: Any) -> str:
    if isinstance(value, float):
        return fmt(value, PRECISE)
    return str(value)


def _plausibility_lines(figures: Plausibility) -> list[str]:
    lines = []
    q, field = figures.largest_charge_C, figures.field_V_per_m
    ratio = figures.field_over_air_breakdown
    if field is not None and ratio is not None:
        verdict = (
            f"{fmt(ratio, ROUGH)} times the breakdown field of air (~3 MV/m): not buildable as "
            "point charges in air. The charges scale like C n / (a1 L^2) and C K / (a2 L^3) for a "
            "body of size L, their field like q / s^2: a larger body, stronger magnetic "
            "fields or a smaller C bring it down"
            if ratio > 1
            else f"{fmt(ratio, ROUGH)} of the breakdown field of air (~3 MV/m): below breakdown"
        )
        lines.append(
            f"- Largest charge {fmt(q, PRECISE)} C; at the candidate "
            f"spacing s = {fmt(figures.spacing_m, PRECISE)} m it makes q / (4 pi eps0 s^2) = "
            f"{fmt(field)} V/m, {verdict}."
        )
    elif q is not None:
        lines.append(f"- Largest charge {fmt(q, PRECISE)} C.")
    volume = figures.ndfeb_volume_m3
    if volume is not None:
        side = volume ** (1.0 / 3.0)
        lines.append(
            f"- Largest dipole {fmt(figures.largest_dipole_Am2, PRECISE)} A m^2: a NdFeB magnet "
            f"(M ~ 1e6 A/m) of {fmt(volume * 1e6)} cm^3 (a cube of side {fmt(side * 100)} cm)."
        )
    if figures.total_mass_kg is not None:
        lines.append(
            f"- Total mass {fmt(figures.total_mass_kg, PRECISE)} kg, largest mass "
            f"{fmt(figures.largest_mass_kg, PRECISE)} kg."
        )
    return lines


def _scene_lines(design: Design, records: ReportRecords) -> list[str]:
    """The model (the theorem's parameters, or a general case's own inertia and V: its
    recorded parameters are placeholders), fields, realised terms and candidates, one line
    each."""
    case = design.general_case
    if case is not None:
        inertia = ", ".join(fmt(float(x), PLAIN) for x in case.get("inertia", ()))
        name, potential = case.get("name"), case.get("V")
        lines = [f"Case: {name}: inertia diag({inertia}) kg m^2, V = {potential} J."]
    else:
        params = design.parameters.as_dict()
        lines = [
            "Parameters: "
            + ", ".join(f"{k} = {fmt(v, PLAIN)}" for k, v in params.items())
            + " (SI units)."
        ]
    origin = records.fields_origin
    field_parts = []
    for kind in ("magnetic", "electric", "gravity"):
        coeffs = design.field(kind)
        if coeffs:
            tag = f" ({origin[kind]})" if kind in origin else ""
            field_parts.append(
                f"{kind} legendre [{', '.join(f'{fmt(c, PLAIN)}' for c in coeffs)}]{tag}"
            )
    lines.append("Fields: " + ("; ".join(field_parts) if field_parts else "none") + ".")
    lines.append(
        "Realises: " + (", ".join(design.realises) if design.realises else "nothing") + "."
    )
    cand = records.candidates
    if cand is not None:
        keys = [f"{k} = {_fmt(v)}" for k, v in cand.figures.items()]
        lines.append(f"Candidates: {cand.count} points ({', '.join(keys)}).")
    return lines


def _element_lines(design: Design) -> list[str]:
    """The elements' table: count, sum of magnitudes, largest and net per source."""
    lines = ["", "## Elements", ""]
    lines.append("| source | count | sum of magnitudes | largest | net |")
    lines.append("|---|---|---|---|---|")
    q = design.charge_values
    if len(q):
        lines.append(
            f"| charges | {len(q)} | {fmt(np.sum(np.abs(q)), PRECISE)} C | "
            f"{fmt(np.max(np.abs(q)), PRECISE)} C | "
            f"{fmt(np.sum(q), PRECISE)} C |"
        )
    sig = design.dipole_moments
    if len(sig):
        norms = np.linalg.norm(sig, axis=1)
        lines.append(
            f"| dipoles | {len(sig)} | {fmt(np.sum(norms), PRECISE)} A m^2 | "
            f"{fmt(np.max(norms), PRECISE)} A m^2 | "
            f"{fmt(np.linalg.norm(np.sum(sig, axis=0)), PRECISE)} A m^2 |"
        )
    m = design.mass_values
    if len(m):
        lines.append(
            f"| masses | {len(m)} | {fmt(np.sum(m), PRECISE)} kg | {fmt(np.max(m), PRECISE)} kg "
            f"| {fmt(np.sum(m), PRECISE)} kg |"
        )
    if not (len(q) or len(sig) or len(m)):
        lines.append("| (none) | 0 | | | |")
    return lines


def _forward_accuracy_lines(cancellations: dict[str, Cancellation]) -> list[str]:
    """The estimated forward accuracy of the sources whose contributions cancel most."""
    if not cancellations:
        return []
    parts = [
        f"{source} ~{fmt(w.forward_error, ORDER)} ({w.quantity} through {w.term}: "
        f"contributions {fmt(w.amplification, ROUGH)} times |{w.quantity}|)"
        for source, w in cancellations.items()
    ]
    return [
        "",
        "Forward accuracy (estimated relative error of mu and V evaluated in floating "
        "point from these elements; the contributions that cancel most): " + "; ".join(parts) + ".",
    ]


def _problem_lines(records: ReportRecords) -> list[str]:
    """The problems' table (objective, solver, residuals), forward accuracy and methods."""
    problems = records.problems
    if problems is None:
        return []
    lines = ["", "## Problems and residuals", ""]
    lines.append("| source | objective | value | solver | residual before | after polish |")
    lines.append("|---|---|---|---|---|---|")
    before, after = problems.before_polish, problems.after_polish
    for source in ("charges", "dipoles", "masses"):
        if source not in problems.objective and source not in after:
            continue
        obj = problems.objective.get(source) or Objective()
        sol = problems.solver.get(source) or Solver()
        lines.append(
            f"| {source} | {obj.kind} | {_fmt(obj.value)} {obj.units} | {sol.name} | "
            f"{_fmt(before.get(source, '?'))} | {_fmt(after.get(source, '?'))} |"
        )
    if problems.definition is not None:
        lines += [
            "",
            f"Relative residual: {problems.definition}; required <= {_fmt(problems.tolerance)}.",
        ]
    lines += _forward_accuracy_lines(records.cancellations)
    methods = [f"- {k}: {v.method}" for k, v in problems.solver.items() if v.method]
    if methods:
        lines += ["", "Methods:", "", *methods]
    return lines


def render_report(
    design: Design, *, title: str = "Design report", picture: str | None = None
) -> str:
    """The human report of a design as Markdown.

    Parameters
    ----------
    design : Design
        A designed body; its provenance keys (as written by :mod:`chargedesign.designer`)
        are used when present.
    title : str
    picture : str, optional
        File name of a picture to show under the title (e.g. ``design.png``).
    """
    lines = [f"# {title}", ""]
    # the design's records, read once (a physical body's figures as its realism budget
    # recorded them)
    records = ReportRecords.read(design)
    physical = records.physical
    # the summary first (the recorded verdict, what binds, the headline figures), then the
    # detail they rest on, in sections
    summary, detail = _verdict_lines(design, records)
    lines += summary
    if picture:
        lines += [f"![the designed body]({picture})", ""]
    if detail:
        lines += ["## Detail", "", *detail, ""]
    lines += _scene_lines(design, records)
    lines += _case_lines(design, records.case)
    lines += _element_lines(design)
    lines += _problem_lines(records)
    timings = design.timings or {}
    if timings:
        lines += [
            "",
            "Timings: " + ", ".join(f"{k} {fmt(v)} s" for k, v in timings.items()) + ".",
        ]
    if physical is not None:  # the bill of materials and the realism budget
        lines += _bom_lines(design, records.materials) + _realism_lines(physical)
    lines += flight_lines(design.support)
    figures = (
        Plausibility.of(design, records.candidates) if design.medium is None else Plausibility()
    )
    if figures != Plausibility():
        lines += ["", "## Could it be built?", "", *_plausibility_lines(figures)]
    notes = list(design.notes or [])
    if notes:
        lines += ["", "## Notes", "", *[f"- {n}" for n in notes]]
    # one sources section at the end: the support's sources and every key cited above, each
    # with its checked status from the sources table (inline: only the key)
    text, keys = cited_keys("\n".join(lines))
    support, more = cited_keys("\n".join(_sources_lines(physical)))
    keys += [key for key in more if key not in keys]
    if support or keys:
        section = ["", "## Sources", *(support.split("\n") if support else [])]
        text += "\n" + "\n".join(section + sources_table_lines(keys))
    return text + "\n"


def _case_lines(design: Design, case: CaseRecord | None) -> list[str]:
    """A ``[case]`` scene's record (design.json ``case``): the case, its certificate, the
    checks of the elements against it, its realism budget and window (none: the theorem's)."""
    if case is None:
        return []
    level = "general" if case.level == "general" else f"on I3 = {case.level}"
    verdict = "holds" if case.holds else "does NOT hold"
    independent = "yes" if case.independent else "NO"
    lines = [
        "",
        f"Realises the case's {', '.join(design.realises)}: case {case.name}, "
        f"inertia diag({', '.join(f'{m:.10g}' for m in case.inertia)}) kg m^2.",
        f"- the claimed integral {verdict} exactly ({level}; independent: {independent})",
    ]
    checks = case.checks
    if checks is not None:
        lines.append(
            f"- recomputed from the elements: inertia relative error "
            f"{checks.inertia_rel_err:.1e}; torque of every element in its field against the "
            f"case's gamma x dV/dgamma - omega x mu: relative error {checks.torque_rel_err:.1e}"
            f"; the charges' l . gamma is the case's plus {checks.level_offset:.6g} kg m^2/s"
        )
    budget, window = case.realism, case.window
    if budget is not None and budget.term_key is None:
        lines.append("- realism: the case realises no force (V and mu constant): no term to hold")
    elif budget is not None and window is not None:
        items = ", ".join(
            f"{key} {value:.1e} ({verdict})" for key, (value, verdict) in budget.items.items()
        )
        span = "empty" if window.empty else f"s = {window.s_low:.3g} .. {window.s_high:.3g}"
        lines += [
            f"- realism at the typical rate {budget.rate_rad_s:.3g} rad/s, over the smallest "
            f"term ({budget.term_key}, {budget.term_N_m:.3g} N m): {items}",
            f"- realised window (each parasitic below {window.fraction:g} of it): {span}; "
            f"below: {window.binding_low}; above: {window.binding_high}",
        ]
    return lines


def flight_lines(support: dict[str, Any] | None) -> list[str]:
    """The "Flight" section: the support's items and, in free fall, the release, its
    tolerance and what the cameras would show (``design.support``, docs/flight.md)."""
    if not support:
        return []
    flight = support.get("flight") or {}
    lines = [f"- {x}" for x in flight.get("lines", [])]
    return ["", "## Flight", "", *support_lines(support), *lines]


#: the terminal's widest line and longest summary (``chargedesign design`` without --verbose)
TERMINAL_WIDTH = 160
SUMMARY_LINES = 40


def _wrapped(text: str) -> list[str]:
    """One paragraph wrapped to :data:`TERMINAL_WIDTH` characters (continuation lines
    indented)."""
    return textwrap.wrap(
        " ".join(text.split()), TERMINAL_WIDTH, subsequent_indent="  ", break_on_hyphens=False
    ) or [""]


def wrapped_text(text: str, width: int = TERMINAL_WIDTH) -> str:
    """``text`` with every line wrapped to ``width`` characters (for a terminal)."""
    lines = [
        part
        for line in text.splitlines()
        for part in (
            textwrap.wrap(line, width, subsequent_indent="  ", break_on_hyphens=False)
            if len(line) > width
            else [line]
        )
    ]
    return "\n".join(lines) + ("\n" if text.endswith("\n") else "")


def render_summary(design: Design, *, report: str | None = None) -> str:
    """The short text of a design for a terminal: the recorded verdict as a table, then the
    main figures; at most :data:`SUMMARY_LINES` lines of at most :data:`TERMINAL_WIDTH`
    characters (the full report: :func:`render_report`, report.md).

    Parameters
    ----------
    design : Design
    report : str, optional
        Where the full report is (e.g. ``out/report.md``), named in the last line.
    """
    verdict = recorded_verdict(design)
    medium = design.medium
    where = f" in {medium.name}" if isinstance(medium, Medium) else ""
    lines = [f"Verdict: {verdict_state_line(verdict)}{where}", ""]
    lines += verdict_text_table(verdict) if verdict.get("rows") else _wrapped(verdict["binding"])
    lines.append("")
    body: list[str] = []
    records = ReportRecords.read(design)
    for line in _scene_lines(design, records)[:3]:
        body += _wrapped(line)
    counts = [
        f"{len(design.charge_values)} charges" if len(design.charge_values) else "",
        f"{len(design.dipole_moments)} magnets" if len(design.dipole_moments) else "",
        f"{len(design.mass_values)} ballast masses" if len(design.mass_values) else "",
    ]
    residual = records.problems.largest_residual if records.problems is not None else None
    body += _wrapped(
        "Elements: "
        + (", ".join(c for c in counts if c) or "none")
        + (f"; largest relative residual {fmt(residual, PRECISE)}" if residual is not None else "")
        + "."
    )
    window = realised_window(design)
    physical = records.physical
    if physical is not None and physical.realism.induced:
        body += _wrapped(f"{induced_text(physical.realism.induced)}.")
    if window is not None and window.empty and window.why:
        law = physical.law if physical is not None else None
        body += _wrapped(f"Why no rate is realised: {_why_empty(window, law)}.")
    elif window is not None:
        body += _wrapped(
            f"Realised window: s = {fmt(window.s_low, ROUGH)} to "
            f"{fmt(window.s_high, ROUGH)} x the scene's rates."
        )
    for line in _frontier_lines(design, records.frontier):
        body += _wrapped(line.removeprefix("- "))
    room = SUMMARY_LINES - len(lines) - 2
    if len(body) > room:
        body = [*body[: room - 1], "  ..."]
    lines += body
    tail = f"Full report: {report}" if report else "Full report: chargedesign.report.render_report"
    lines += ["", tail + " (--verbose prints it)."]
    return "\n".join(line[:TERMINAL_WIDTH] for line in lines) + "\n"


def _larmor_lines(design: Design) -> list[str]:
    """Which Larmor reading realises n, and why (design.json ``larmor``, ``larmor_why``)."""
    if design.larmor is None:
        return []
    why = design.larmor_why
    how = (
        f"the elements realise n = 0; the motion read in axes turning at "
        f"{fmt(design.larmor.rate, PRECISE)} 1/s about Z is the theorem's"
        if design.larmor.is_frame
        else "second moments of charge realise n (the paper's (p6))"
    )
    return [f"- Larmor reading: {design.larmor.reading}: {how}" + (f" ({why})." if why else ".")]


def _verdict_table(
    design: Design, record: RealismRecord
) -> tuple[dict[str, Any], list[str], WindowAtDesign | None]:
    """The recorded verdict (:func:`chargedesign.verdict.recorded_verdict`: design.json's
    ``verdict``), its short table, and the realised window at the design's rate it read."""
    verdict = recorded_verdict(design)
    window = record.window if within_limits(design.buildability) else None
    return verdict, verdict_table(verdict), window


def _best_rate_text(window: RealisedWindow) -> str | None:
    """The worst parasitic at the empty window's best rate, with its reference and rate (the
    window's laws, drawn from the body designed at s_max); None when not recorded."""
    best, missing, fraction = window.s_best, window.missing, window.fraction
    if not (math.isfinite(best) and math.isfinite(missing) and fraction):
        return None
    worst = str(window.binding_low).split(" (")[0] or "the worst parasitic"
    return (
        f"at the best rate the worst parasitic ({worst}) is "
        f"{parasitic_text(missing * fraction, window.term_key or '?', best)} by the window's "
        "laws (the body designed at s_max)"
    )


def _why_empty(window: RealisedWindow, law: KLaw | None) -> str:
    """Why no rate is realised: the K law where it applies (the realism budget's
    ``k_law_induced_ratio``: a law of matter at the K frontier, named as the law, the same
    number as its line below and the budget's table), then the worst parasitic at the best
    rate with its reference and rate; else the frontier's own words."""
    if law is None or law.value is None:
        return str(window.why)
    text = (
        "the K term cannot be realised by ordinary matter: the K law (below) is "
        f"{fmt(law.value)} x the designed K torques C K_max^2 at the K frontier, for any "
        "size and a2"
    )
    best = _best_rate_text(window)
    return text + (f"; {best}" if best else "")


def _apparatus_lines(window: WindowAtDesign | None) -> list[str]:
    """The coil pairs that make the field, with their harmonic error."""
    if window is None or window.apparatus_summary is None:
        return []
    return ["- Field apparatus: " + window.apparatus_summary + "."]


def _support_lines(window: WindowAtDesign | None, support: BearingSupport | None) -> list[str]:
    """The fixed point O (the window's ``support``) and its air film's drag."""
    if window is None or support is None:
        return []
    return [
        f"- Support: a {support.bearing} air bearing (tilt {fmt(support.tilt_limit_deg)} "
        f"deg: every attitude free), ball radius {fmt(support.ball_radius_m)} m in a "
        f"cup, film {fmt(support.film_gap_m)} m: drag {fmt(support.drag_N_m_s)} "
        f"N m s, {fmt(support.drag_torque_N_m)} N m at the typical rate = "
        f"{parasitic_text(support.drag_over_term, window.term_key, 1.0)} (limit "
        f"{fmt(window.fraction, PLAIN)}), NOT counted in the verdict or the realised window "
        f"above; it needs "
        f"{support.needs} (its sources: Sources, below)."
    ]


def _top_level_parts(text: str) -> list[str]:
    """``text`` split at its ``;`` outside parentheses (one source each)."""
    parts, depth, start = [], 0, 0
    for i, ch in enumerate(text):
        depth += {"(": 1, ")": -1}.get(ch, 0)
        if ch == ";" and depth == 0:
            parts.append(text[start:i])
            start = i + 1
    parts.append(text[start:])
    return [p.strip() for p in parts if p.strip()]


def _sources_lines(physical: PhysicalRecords | None) -> list[str]:
    """The report's sources in one section at its end, each with its checked status as the
    source says it (``[unverified ...]``); the figures above cite them, never inline."""
    support = physical.support if physical is not None else None
    if support is None:
        return []
    cited = [
        part for text in (support.source, support.drag_source) for part in _top_level_parts(text)
    ]
    if not cited:
        return []
    return ["", "The support's figures (air film and cup drag):", "", *[f"- {p}" for p in cited]]


def _frontier_lines(design: Design, frontier: Frontier | None) -> list[str]:
    """The frontier of K and the time rate n against the frontier's n_max."""
    lines = []
    n = design.parameters.n
    if frontier is not None and frontier.K_max is not None:
        lines.append(
            f"- Frontier of K ({frontier.larmor} reading): K = "
            f"{fmt(design.parameters.K, PRECISE)} 1/s, "
            f"K_max = {fmt(frontier.K_max, PRECISE)} 1/s."
        )
    if frontier is not None:
        n_max, period = frontier.n_max, frontier.period_s
        lines.append(
            f"- Time rate: n = {fmt(n, PRECISE)} 1/s; the frontier "
            f"n_max = {fmt(n_max, PRECISE)} 1/s (period 2 pi / n_max = {fmt(period, PRECISE)} s; "
            f"binding: {frontier.binding})."
            if n_max is not None and period is not None
            else f"- Time rate: n = {fmt(n, PRECISE)} 1/s."
        )
    return lines


def _placement_lines(placement: Placement | None) -> list[str]:
    """The element whose placement tolerance binds, when tolerancing was recorded."""
    if placement is None:
        return []
    return [
        f"- Placement: {placement.element} dominates: within "
        f"+-{fmt(placement.position_tol_m_min)} m it keeps the relative error of "
        f"{placement.binding} below {fmt(placement.target, PLAIN)}."
    ]


def _verdict_lines(design: Design, records: ReportRecords) -> tuple[list[str], list[str]]:
    """The report's opening and its detail: the summary (the recorded verdict, its table of
    what binds, the headline figures, each with what it is relative to and at which rate) and
    the detail the summary rests on (the lines of the section ``Detail``)."""
    physical = records.physical
    if design.medium is None or physical is None:
        summary = [
            "**Verdict: not checked for buildability** (the scene has no [medium]: point "
            "elements, the mathematical case).",
            *_larmor_lines(design),
            "",
        ]
        return summary, []
    record = physical.realism
    medium = design.medium
    assert isinstance(medium, Medium)  # Design reads design.json's mapping into a Medium
    response = physical.response
    law = physical.law if response else None
    verdict, table, window_now = _verdict_table(design, record)
    window = realised_window(design)
    summary = [
        f"**Verdict: {verdict_state_line(verdict)}** in {medium.name} (breakdown "
        f"{fmt(medium.breakdown)} V/m, safety {fmt(medium.safety, PLAIN)}).",
        "",
        *table,
        "",
        "Headline figures (the detail below):",
        "",
    ]
    detail = []
    if record.induced:
        summary.append(f"- {induced_text(record.induced)}.")
    if window is not None and window.empty and window.why:
        best = _best_rate_text(window)
        summary.append(
            "- Realised window: empty (no rate realises the body"
            + (f"; {best})." if best else ").")
        )
        detail.append(f"- Why no rate is realised: {_why_empty(window, law)}.")
    elif window is not None:
        summary.append(
            f"- Realised window: s = {fmt(window.s_low, ROUGH)} to "
            f"{fmt(window.s_high, ROUGH)} x the scene's rates, every parasitic below "
            f"{fmt(window.fraction, PLAIN)} of each realised term (low end: "
            f"{window.binding_low.split(' (')[0]}; high end: "
            f"{window.binding_high.split(': ')[0]})."
        )
    summary.append(
        "- Largest surface field: "
        f"{fmt(records.limits.surface_field_fraction, PRECISE)} of "
        f"breakdown at the scene's rate (s = 1; recomputed from the written parts at "
        f"{CHECK_SURFACE_SAMPLES} points per carrier and around the largest)."
    )
    bal, micro = physical.budget.balance_1g, physical.budget.balance_microgravity
    if bal is not None:
        summary.append(
            f"- Balance: the centre of mass within {fmt(bal.value)} m of O under 1 g "
            f"({bal.verdict}), {fmt(micro.value if micro is not None else 0)} m under 1e-6 g, "
            "for a gravity torque below 1e-3 of the designed torques at s = 1."
        )
    detail += [*_apparatus_lines(window_now), *_support_lines(window_now, physical.support)]
    detail += _larmor_lines(design)
    detail += _frontier_lines(design, records.frontier)
    detail += (
        _k_law_lines(law, physical.part_sizes.magnets)
        if law is not None
        else _response_lines(response, bool(record.induced))
    )
    detail += _part_size_lines(physical.part_sizes)
    detail += _placement_lines(records.placement)
    for v in records.limits.violations:
        detail.append(f"- Limit broken: {v}")
    return [*summary, ""], detail


def _response_lines(response: dict[str, BudgetItem], induced: bool) -> list[str]:
    """The field response at the designed rate (a body without the K law's figures); the
    induced magnetisation only when its one figure is not recorded (an older design.json)."""
    lines = []
    for key, item in response.items():
        if key == FIELD_RESPONSE_KEYS[0] and induced:  # its one figure, in the summary
            continue
        value = item.value
        title = "Induced magnetisation" if key.startswith("induced") else "Eddy currents"
        lines.append(
            f"- {title}: {'inf' if value is None else fmt(value)} of the designed torques "
            f"({item.verdict}): {item.note}."
        )
    return lines


def _k_law_tail(law: KLaw) -> str:
    """The K law's closing words: size-free, and which reading needs Lorentz charges."""
    return (
        ". For a similar body it is the same at any size and any a2, and falls like "
        "1/E_surface^2. Only K needs Lorentz charges when n is read as turning axes (this "
        f"body: the {law.larmor_reading} reading"
        + (
            ", whose charges also carry n, so its K frontier is lower)."
            if law.larmor_reading == "charges"
            else ")."
        )
    )


def _k_law_induced_line(law: KLaw) -> str:
    """Induced magnetisation at the K frontier: cancelled by the design, or by the law."""
    tail = _k_law_tail(law)
    if law.cancelled_by_design:
        return (
            "- The K law (ordinary matter's induced-magnetisation energy range at the K "
            "frontier): cancelled by the design's chi-weighted "
            f"moments to {fmt(law.ratio_elements)} of the designed K torques C K_max^2 "
            f"({law.verdict}, element by element); the same matter without the "
            f"cancellation gives {fmt(law.ratio_without_cancellation)} by the size-free law "
            f"6 (chi/rho) / (mu0 G^2) (G = K_max / a2 = {fmt(law.G_C_m_per_kg)} C m/kg, "
            f"K_max = {fmt(law.K_max_1_per_s)} 1/s from {law.K_max_source}, a2 = "
            f"{fmt(law.a2_T_per_m)} T/m). The cancellation holds only if each material's "
            f"susceptibility is known to {fmt(law.chi_relative_needed, ROUGH)} relative; "
            f"susceptibility metrology reaches about "
            f"{fmt(law.metrology_chi_relative, ORDER_SCI)}" + tail
        )
    value = law.ratio if law.value is None else law.value
    how = (
        "element by element"
        if law.ratio_elements is not None and value == law.ratio_elements
        else "by the law"
    )
    return (
        f"- The K law (ordinary matter's induced-magnetisation energy range at the K frontier, "
        f"not the {INDUCED_NAME} figure above): {fmt(value)} x the designed K "
        f"torques C K_max^2 ({law.verdict}; {how}, the budget's k_law_induced_ratio). The "
        f"size-free law 6 (chi/rho) / (mu0 G^2) estimates it at {fmt(law.ratio)} "
        f"with the parts' chi/rho = {fmt(law.chi_over_rho_m3_per_kg)} m^3/kg "
        f"(mass-weighted) and G = K_max / a2 = {fmt(law.G_C_m_per_kg)} C m/kg (K_max = "
        f"{fmt(law.K_max_1_per_s)} 1/s from {law.K_max_source}, a2 = "
        f"{fmt(law.a2_T_per_m)} T/m)" + tail
    )


def _k_law_parity_line(law: KLaw) -> str:
    """What parity with the designed torques would need: fields, or materials."""
    parity, surface = law.parity_surface_field_V_per_m, law.surface_field_V_per_m
    evaporation, atomic = law.field_evaporation_V_per_m, law.atomic_field_V_per_m
    return (
        f"- Parity would need G {fmt(parity / surface)} times larger: "
        f"carrier surface fields of {fmt(parity)} V/m instead of "
        f"{fmt(surface)} V/m, "
        f"{fmt(parity / evaporation)} times the field that evaporates "
        f"metal surfaces (~{fmt(evaporation, ORDER)} V/m "
        "[limits.field_evaporation.tungsten]) and "
        f"{fmt(parity / atomic)} times the atomic field "
        f"e / (4 pi eps0 a0^2) = {fmt(atomic)} V/m; or parts with "
        f"chi/rho = {fmt(law.parity_chi_over_rho_m3_per_kg)} m^3/kg."
    )


def _k_law_size_line(law: KLaw, magnets: MagnetSpan | None, smallest: float) -> str:
    """The sizes the law holds for: one elementary charge per carrier, continuum magnets."""
    line = (
        "- Size: the law holds for similar bodies while each carrier at the safe field "
        "holds at least one elementary charge, i.e. carriers of radius "
        f"{fmt_length(law.one_charge_carrier_radius_m)} and more: a body of radius "
        f"{fmt_length(smallest)} and more. Within that range the ratio changes with "
        "size only through the surface field the medium holds (as 1/E^2; the breakdown "
        "field used is that of mm to cm gaps)."
    )
    if magnets is not None:
        where = "already below it" if magnets.below else "above it"
        line += (
            " The parts must stay continuum parts too, which bounds the size first where "
            f"the magnets are small: a magnet at least "
            f"{fmt_length(magnets.continuum_size_m)} across; this body's smallest "
            f"is {fmt_length(magnets.smallest_m)}, {where}."
        )
    return line


def _k_law_lines(law: KLaw, magnets: MagnetSpan | None) -> list[str]:
    """The verdict on the parts' materials by the size-free K law, with its numbers."""
    lines = [_k_law_induced_line(law)]
    if law.ratio > 0:
        lines.append(_k_law_parity_line(law))
    eddy, sigma = law.eddy_ratio, law.conductivity_needed_S_per_m
    if eddy is not None and sigma is not None:
        insulators = ", ".join(
            f"{k} ~{fmt(v, ORDER_SCI)}" for k, v in law.insulators_S_per_m.items()
        )
        lines.append(
            f"- Eddy currents (a choice of material): at the K frontier {fmt(eddy)} times the "
            f"designed K torques with these conductors; below "
            f"{fmt(RESPONSE_FRACTION, PLAIN)} of them needs conductivities under {fmt(sigma)} "
            f"S/m (now {law.conductivity_needed_for}, "
            f"{fmt(law.conductivity_now_S_per_m)} S/m), which insulating parts reach "
            f"({insulators} S/m)."
        )
    smallest = law.smallest_similar_body_radius_m
    if smallest is not None:
        lines.append(_k_law_size_line(law, magnets, smallest))
    return lines


def _part_size_lines(sizes: PartSizes) -> list[str]:
    """How large each kind of part is (the budget's ``part_sizes``): what a builder must make
    (the magnets' size is the cube root of their material's volume)."""

    def span(kind: PartSpan) -> str:
        lo, hi = kind.smallest_m, kind.largest_m
        return fmt_length(lo) if lo == hi else f"{fmt_length(lo)} to {fmt_length(hi)}"

    parts = []
    carriers = sizes.carriers
    if carriers is not None:
        parts.append(f"{carriers.count} carriers of radius {span(carriers)}")
    continuum = sizes.magnets
    if continuum is not None:
        magnets = f"{continuum.count} magnets of {span(continuum)} across"
        if continuum.below:
            magnets += (
                f" ({continuum.below} of them below the "
                f"{fmt_length(continuum.continuum_size_m)} a ferromagnet needs to be a "
                "continuum magnet: single-domain nanoparticles with a reduced surface "
                "magnetisation, whose moment and coercivity are not the data sheet's, those of "
                "micrometre-grained sintered parts; not buildable as specified)"
            )
        parts.append(magnets)
    ballast = sizes.ballast
    if ballast is not None:
        parts.append(f"{ballast.count} ballast spheres of radius {span(ballast)}")
    return [f"- Part sizes: {'; '.join(parts)}."] if parts else []


def _bom_lines(design: Design, materials: Materials) -> list[str]:
    """The bill of materials: totals, the fields the apparatus makes, the first 20 parts."""
    totals = bom_totals(design)
    lines = ["", "## Bill of materials", ""]
    lines.append(
        f"Carriers: {totals['carriers']} spheres of {materials.carrier} "
        f"({fmt(totals['mass_carriers_kg'], PRECISE)} kg); magnets: {totals['magnets']} of "
        f"{materials.magnet} ({fmt(totals['magnet_volume_m3'], PRECISE)} "
        f"m^3, {fmt(totals['mass_magnets_kg'], PRECISE)} kg with attached ballast); ballast: "
        f"{totals['ballast']} pieces of {ballast_label(design.materials)} "
        f"({fmt(totals['mass_ballast_kg'], PRECISE)} kg). Total mass "
        f"{fmt(totals['mass_total_kg'], PRECISE)} kg; "
        f"net charge {fmt(totals['charge_net_C'], PRECISE)} C."
    )
    maxima = totals["field_maxima_over_body"]
    if maxima:
        lines.append(
            "The apparatus must make, over the body region: "
            + ", ".join(
                f"{k} {fmt(v, PRECISE)} "
                f"{'T' if k == 'magnetic' else 'V/m' if k == 'electric' else 'm/s^2'}"
                for k, v in maxima.items()
            )
            + " (largest magnitude)."
        )
    rows = bom_rows(design)
    lines += ["", "| part | kind | position (m) | size | material | charge / moment | mass (kg) |"]
    lines.append("|---|---|---|---|---|---|---|")
    for r in rows[:20]:
        value = (
            f"{fmt(r['charge_C'], PRECISE)} C"
            if r["kind"] == "carrier"
            else f"({fmt(r['moment_x_A_m2'])}, {fmt(r['moment_y_A_m2'])}, "
            f"{fmt(r['moment_z_A_m2'])}) A m^2"
            if r["kind"] == "magnet"
            else ""
        )
        lines.append(
            f"| {r['part']} | {r['kind']} | ({fmt(r['x_m'], PRECISE)}, {fmt(r['y_m'], PRECISE)}, "
            f"{fmt(r['z_m'], PRECISE)}) | "
            f"{fmt(r['size'])} {r['size_unit']} | {r['material']} | {value} | "
            f"{fmt(r['mass_kg'], PRECISE)} |"
        )
    if len(rows) > 20:
        lines.append(f"| ... | {len(rows) - 20} more parts in bom.csv | | | | | |")
    return lines


def _realism_lines(physical: PhysicalRecords) -> list[str]:
    """The realism budget as recorded (its items, the field response and the K law among
    them) and the realisability map."""
    budget = physical.budget
    lines = ["", "## Realism budget", ""]
    lines.append(
        f"Typical motion: |omega| = {fmt(budget.typical_rate_1_per_s, PRECISE)} "
        f"1/s, period {fmt(budget.period_s, PRECISE)} s, designed torques ~"
        f"{fmt(budget.designed_torque_N_m)} N m."
    )
    lines += ["", "| effect | value | verdict | what |", "|---|---|---|---|"]
    for key, item in budget.table.items():
        amount = item.value
        shown = f"{fmt(amount)} {item.unit}" if amount is not None else "inf"
        if key == INDUCED_KEY:
            assert item.term is not None and item.s is not None  # the one figure's reference
            shown = parasitic_text(amount, item.term, item.s)
        lines.append(f"| {key} | {shown} | {item.verdict} | {table_cell(item.note)} |")
    lines += _map_lines(physical.realisability_map)
    return lines


def _map_lines(rows: tuple[MapRow, ...]) -> list[str]:
    """The realisability map, as the budget records it (``realisability_map``)."""

    def num(x: float | None) -> str:
        return "" if x is None else fmt(x)

    if not rows:  # a general case: no term of the theorem's
        return [
            "",
            "## Realisability map",
            "",
            "Not applicable: the map splits the theorem's V and mu by their parameters; this "
            "body realises a case not of the theorem's form, sized by its own terms (the "
            "smallest realised term above).",
        ]
    lines = [
        "",
        "## Realisability map",
        "",
        "Each term of V and mu, what can realise it, what this body uses, its size (the range "
        "of a V term over orientations; the gyroscopic torque |omega| max|mu term| of a mu "
        "term at the typical motion) here and at the K frontier (every term scales like the "
        "rate squared), and the parts' induced-magnetisation energy range and eddy torque over "
        "it (the induced energy by the window's law: the magnets' grows like the terms, the "
        "other parts' does not; over the smallest realised term at s = 1 it is the induced "
        "magnetisation's one figure above; the eddy torque grows like the rate). Computed "
        "from this body by `chargedesign.physical.realism.realisability_map`, the induced "
        "columns by `chargedesign.physical.budget.map_figures`.",
        "",
        "| term | in | mechanisms | this body | size here (N m) | induced / term "
        "| eddy / term | size at the K frontier (N m) | induced / term | eddy / term |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for row in rows:
        # an unbounded size (a singular term that is present) is recorded as null
        size = "inf" if row.size_N_m is None else fmt(row.size_N_m)
        lines.append(
            f"| {row.term}: `{row.expression}` | {row.where} | "
            f"{table_cell(row.mechanisms)} | {table_cell(row.here)} | "
            f"{size} | {num(row.induced_over_term)} | "
            f"{num(row.eddy_over_term)} | {num(row.frontier_size_N_m)} | "
            f"{num(row.frontier_induced_over_term)} | {num(row.frontier_eddy_over_term)} |"
        )
    return lines
