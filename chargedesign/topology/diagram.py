"""The bifurcation diagram of a case of (ep), one route: :func:`bifurcation_diagram` takes a
case (the theorem: its catalogue entry) and gives the result (CSV, picture, summary).

- The theorem's entry, (H, I4) on ``I3 = 0``: its closed form (:mod:`.closed_form`) gives
  the structure, and the structure of the equations (Larmor, :mod:`chargedesign.model.larmor`)
  the reading: on the level ``I3 = 0, |gamma| = 1`` the map ``omega = omega0 - n gamma``
  takes the n = 0 system to the n-system with ``H_n = H_0 + C n^2`` and ``I4_n = I4_0``
  exactly. So the stages (:mod:`.compute`) run at n = 0 (and unit time scale) and states and
  energies are mapped; the tests compare with a direct computation at n != 0.
- Any other polynomial case, (H, F) on its level: the same stages with the structure found
  from the traced branches (:mod:`.general`), in the case's units.
"""

from __future__ import annotations

import csv
import io
import os
from collections.abc import Callable
from dataclasses import dataclass, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any, overload

import numpy as np

from chargedesign.errors import InputError, SolverError
from chargedesign.files import atomic_directory, write_text_atomic
from chargedesign.formatting import CELL, FULL, PRECISE, fmt
from chargedesign.params import Parameters
from chargedesign.results import Result, png_html
from chargedesign.scene.bifurcation import (
    check_energy_in_scale,
    check_h_range,
    check_larmor_shift,
    check_not_free_top,
    check_range_width,
    check_regular,
    refuse_inadmissible_range,
)
from chargedesign.topology.closed_form import ClosedForm
from chargedesign.topology.compute import (
    Chamber,
    DiagramOptions,
    RawDiagram,
    TracedBranch,
    Vertex,
    critical_diagram,
    resolve_range,
)
from chargedesign.topology.equations import MomentumMap
from chargedesign.topology.stability import TYPES

if TYPE_CHECKING:
    from chargedesign.scene.case_file import Case
    from chargedesign.topology.general import CaseRaw

#: the CSV's columns (the contract's header)
CSV_COLUMNS = ("h", "k", "branch", "type", "p", "q", "r", "gamma1", "gamma2", "gamma3")
#: the units after h and k in the theorem's text (SI)
SI_UNITS = (" J", " 1/s^4")
#: the colour of each type in the picture
TYPE_COLOURS = {"elliptic": "tab:blue", "hyperbolic": "tab:red", "degenerate": "tab:green"}


def larmor_shift(params: Parameters) -> float:
    """``H_n(omega0 - n gamma) - H_0(omega0) = C n^2`` on ``I3 = 0, |gamma| = 1``, J."""
    return params.C * params.n**2


@dataclass(frozen=True)
class Reading:
    """How the unit n = 0 computation is read at the user's parameters (exact maps).

    Two symmetries of the equations and one change of frame:

    - ``(c, d, K, kappa) -> (t c, t d, K / t, kappa / t)`` changes no term of H, l or I4
      (``c + i d`` enters I4 times ``kappa + K^2 s - i K r``, with s linear in c, d): the
      unit computation has ``c^2 + d^2 = 1`` (``t = 1 / a0``);
    - time scale ``s = max(|K| a0, sqrt(|kappa| a0))``: with ``C = 1``, ``K a0 / s`` and
      ``kappa a0 / s^2`` the equations are those of the parameters read with time in units
      of ``1 / s`` (H is ``C s^2`` times a dimensionless one, I4 ``s^4`` times, omega ``s``
      times);
    - Larmor: ``omega = s omega_unit - n gamma``, ``h = C s^2 h_unit + C n^2``, ``k = s^4
      k_unit``. So n is no parameter of the computation at all.
    """

    params: Parameters
    s: float
    a0: float

    @classmethod
    def of(cls, params: Parameters) -> Reading:
        a0 = float(np.hypot(params.c, params.d))
        s = max(abs(params.K) * a0, (abs(params.kappa) * a0) ** 0.5)
        return cls(params, s if s > 0.0 else 1.0, a0 if a0 > 0.0 else 1.0)

    def unit(self) -> Parameters:
        p, s, a0 = self.params, self.s, self.a0
        return Parameters(
            C=1.0, c=p.c / a0, d=p.d / a0, n=0.0, K=p.K * a0 / s, kappa=p.kappa * a0 / s**2
        )

    def energy(self, h_unit: Any) -> Any:
        return self.params.C * self.s**2 * np.asarray(h_unit) + larmor_shift(self.params)

    def energy_unit(self, h: float) -> float:
        return (h - larmor_shift(self.params)) / (self.params.C * self.s**2)

    def image(self, hk: np.ndarray) -> np.ndarray:
        out = np.array(hk, dtype=float)
        out[..., 0] = self.energy(out[..., 0])
        out[..., 1] *= self.s**4
        return out

    def states(self, x: np.ndarray) -> np.ndarray:
        out = np.array(x, dtype=float)
        out[..., :3] = self.s * out[..., :3] - self.params.n * out[..., 3:]
        return out


def mapped(raw: RawDiagram, reading: Reading) -> RawDiagram:
    """The unit n = 0 diagram ``raw`` read at the user's parameters (:class:`Reading`)."""
    branches = [
        replace(b, states=reading.states(b.states), hk=reading.image(b.hk)) for b in raw.branches
    ]
    vertices = [Vertex(reading.states(v.state), reading.image(v.hk), v.type) for v in raw.vertices]
    chambers = [
        replace(
            c,
            h=float(reading.energy(c.h)),
            k=c.k * reading.s**4,
            width=c.width * reading.params.C * reading.s**2,
        )
        for c in raw.chambers
    ]
    band = raw.admissible.copy()
    band[:, 0] = reading.energy(band[:, 0])
    band[:, 1:] *= reading.s**4
    h_range = (float(reading.energy(raw.h_range[0])), float(reading.energy(raw.h_range[1])))
    return RawDiagram(
        reading.params,
        h_range,
        float(reading.energy(raw.h_min)),
        branches,
        vertices,
        chambers,
        band,
        raw.seconds,
        raw.seeds_found,
    )


@overload
def bifurcation_diagram(
    model: Parameters,
    h_range: tuple[float, float] | None = None,
    options: DiagramOptions | None = None,
    tally: Callable[[int, int], None] | None = None,
    *,
    level: Any = None,
    count: bool = True,
    closed_form: bool = True,
) -> BifurcationDiagram: ...


@overload
def bifurcation_diagram(
    model: Case,
    h_range: tuple[float, float] | None = None,
    options: DiagramOptions | None = None,
    tally: Callable[[int, int], None] | None = None,
    *,
    level: Any = None,
    count: bool = True,
    closed_form: bool = True,
) -> BifurcationDiagram | CaseDiagram: ...


def bifurcation_diagram(
    model: Case | Parameters,
    h_range: tuple[float, float] | None = None,
    options: DiagramOptions | None = None,
    tally: Callable[[int, int], None] | None = None,
    *,
    level: Any = None,
    count: bool = True,
    closed_form: bool = True,
) -> BifurcationDiagram | CaseDiagram:
    """The bifurcation diagram of a case of (ep): the image of ``(H, F)`` on ``|gamma| = 1,
    I3 = level`` with its critical families typed and the tori of each chamber (``count``:
    counted by the flow, the slow stage; ``tally(done, total)`` is told the stages done).

    ``model`` is a :class:`~chargedesign.scene.case_file.Case`, or the theorem's parameters
    (its catalogue entry, :func:`~chargedesign.model.catalogue.theorem_case`, read without
    building it). ``level``: default the case's own level, or 0 for a general claim.

    - The theorem's entry on ``I3 = 0`` (:func:`theorem_reading`; ``closed_form=False`` turns
      the reading off, for cross-checks): its closed form gives the structure, the stages run
      at unit time scale and n = 0, then are mapped exactly (:class:`Reading`: the time scale
      and Larmor's ``H_n = H_0 + C n^2``); ``h_range`` is in J at the parameters, default
      from the least energy on the level to the top of the amended potential plus half its
      span. Returns a :class:`BifurcationDiagram`.
    - Any other polynomial case: the same stages, the structure found from the traced
      branches (:func:`~chargedesign.topology.general.general_diagram`, the case's units).
      Returns a :class:`CaseDiagram`.
    """
    if isinstance(model, Parameters):
        return _theorem_diagram(model, h_range, options, tally, count)
    if level is None:
        level = 0 if model.level is None else model.level
    params = theorem_reading(model, level) if closed_form else None
    if params is not None:
        return _theorem_diagram(params, h_range, options, tally, count)
    from chargedesign.topology.general import general_diagram

    return CaseDiagram(general_diagram(model, level, h_range, options, tally, count))


def theorem_reading(case: Case, level: Any) -> Parameters | None:
    """The theorem's parameters when ``case`` on ``I3 = level`` is the theorem's catalogue
    entry, else None: its inertia, V and l the theorem's at some regular parameters
    (:func:`~chargedesign.model.catalogue.theorem_parameters`), its F the theorem's I4 there
    exactly (on ``|gamma| = 1``), and ``level`` 0 (where I4 is an integral). Parameters the
    theorem's diagram refuses (:func:`check_parameters`: the free top, a Larmor shift that
    swamps the energies) are no reading: such a case keeps the stages of any case."""
    from chargedesign.model.catalogue import theorem_case, theorem_parameters
    from chargedesign.scene.case_file import vanishes_on_sphere

    if level != 0:
        return None
    params = theorem_parameters(case)
    if params is None or params.singular:
        return None
    if not vanishes_on_sphere(case.integral - theorem_case(params).integral):
        return None
    try:
        check_parameters(params)
    except InputError:
        return None
    return params


def _theorem_diagram(
    params: Parameters,
    h_range: tuple[float, float] | None,
    options: DiagramOptions | None,
    tally: Callable[[int, int], None] | None,
    count: bool,
) -> BifurcationDiagram:
    """The theorem's diagram at ``params`` (:func:`bifurcation_diagram`)."""
    reading = Reading.of(params)
    unit_range = check_energy_range(params, h_range)
    raw = critical_diagram(reading.unit(), unit_range, options, tally, count)
    diagram = BifurcationDiagram(mapped(raw, reading))
    if not any(not b.exact for b in diagram.branches):
        lo, hi = diagram.raw.h_range
        raise SolverError(
            f"bifurcation: no critical curve traced in {fmt(lo, CELL)} .. {fmt(hi, CELL)} J"
            " besides k = 0 (the closed form has the parabolas k = ((h - h_j) / C)^2 there):"
            " widen --h-range"
        )
    return diagram


def check_parameters(params: Parameters) -> ClosedForm:
    """Refuse, in one line and before any work, parameters without a diagram: lambda or rho
    != 0, the free top (c = d = 0 or K = kappa = 0) and an n whose Larmor shift swamps the
    energies (the checks of :mod:`chargedesign.scene.bifurcation`). Returns the closed form
    of the branches."""
    check_regular(params.lam, params.rho)
    check_not_free_top(params.c, params.d, params.K, params.kappa)
    closed = ClosedForm.of(params)
    check_larmor_shift(larmor_shift(params), closed.energy_scale)
    return closed


def check_energy_range(
    params: Parameters, h_range: tuple[float, float] | None
) -> tuple[float, float] | None:
    """Refuse parameters without a diagram (:func:`check_parameters`) and an energy range (J,
    at ``params``) without admissible motion, too wide or too narrow for the diagram's
    structure, in one line, before any work; returns the range of the unit computation."""
    closed = check_parameters(params)
    if h_range is None:
        return None
    lo, hi = (float(v) for v in h_range)
    check_h_range(lo, hi)
    reading = Reading.of(params)
    unit = MomentumMap(reading.unit())
    unit_range = (reading.energy_unit(lo), reading.energy_unit(hi))
    try:
        resolve_range(unit, unit_range)
    except ValueError:
        _, low = resolve_range(unit, None)
        refuse_inadmissible_range(lo, hi, float(reading.energy(low)))
    check_range_width(lo, hi, hi - max(lo, closed.h_min), closed.energy_scale)
    require_energy_in_scale(closed, hi, "--h-range")
    return unit_range


def require_energy_in_scale(closed: ClosedForm, h: float, name: str) -> None:
    """Refuse an energy too far above the least energy for the diagram's structure
    (:func:`chargedesign.scene.bifurcation.check_energy_in_scale`)."""
    check_energy_in_scale(name, h, closed.h_min, closed.energy_scale)


def energy_range(params: Parameters, h_range: tuple[float, float] | None) -> tuple[float, float]:
    """The energy range (J, at ``params``) the diagram will cover: ``h_range`` checked and
    raised to the least energy, or the default (see :func:`bifurcation_diagram`)."""
    unit_range = check_energy_range(params, h_range)
    reading = Reading.of(params)
    resolved, _ = resolve_range(MomentumMap(reading.unit()), unit_range)
    return float(reading.energy(resolved[0])), float(reading.energy(resolved[1]))


def vertex_groups(
    vertices: list[Vertex], size: tuple[float, float] = (1.0, 1.0)
) -> dict[tuple[float, float, str], int]:
    """Vertices with the same image (to 1e-9 of ``size``, the diagram's extent in h and k)
    and type (symmetric states), counted; keys are the images rounded to that precision."""
    groups: dict[tuple[float, float, str], int] = {}
    for v in vertices:
        h, k = (round(float(v.hk[i]) / size[i], 9) * size[i] for i in range(2))
        key = (h, k, v.type)
        groups[key] = groups.get(key, 0) + 1
    return groups


def branch_record(b: TracedBranch) -> dict[str, Any]:
    """A traced branch in the JSON summary (its number and name are the caller's)."""
    return {
        "points": len(b.hk),
        "types": {t: b.types.count(t) for t in TYPES if t in b.types},
        "h": [float(b.hk[:, 0].min()), float(b.hk[:, 0].max())],
        "k": [float(b.hk[:, 1].min()), float(b.hk[:, 1].max())],
        "ends": list(b.ends),
        "exact": b.exact,
    }


def branch_line(label: str, item: dict[str, Any], units: tuple[str, str] = ("", "")) -> str:
    """A branch's line of the text from its record (:func:`branch_record`), ``units`` after
    its h and k ranges (``(" J", " 1/s^4")`` for the theorem's SI diagram)."""
    kinds = ", ".join(f"{n} {t}" for t, n in item["types"].items())
    (h0, h1), (k0, k1) = item["h"], item["k"]
    return (
        f"  {label}: {item['points']} points, h {fmt(h0, PRECISE)} .. {fmt(h1, PRECISE)}"
        f"{units[0]}, k {fmt(k0, PRECISE)} .. {fmt(k1, PRECISE)}{units[1]} ({kinds}; ends:"
        f" {', '.join(item['ends'])})"
    )


def vertex_line(
    h: float, k: float, kind: str, states: int, units: tuple[str, str] = ("", ""), note: str = ""
) -> str:
    """A group of vertices' line of the text (:func:`vertex_groups`: its image, type and
    number of states)."""
    return (
        f"  vertex h = {fmt(h, CELL)}{units[0]}, k = {fmt(k, CELL)}{units[1]}: {kind} of the"
        f" energy ({states} states{note})"
    )


def vertex_record(v: Vertex) -> dict[str, Any]:
    """A vertex of the diagram in the JSON summary."""
    return {"h": float(v.hk[0]), "k": float(v.hk[1]), "type": v.type}


def chamber_record(c: Chamber) -> dict[str, Any]:
    """A chamber with its tori count and the evidence of the count, in the JSON summary."""
    return {
        "chamber": c.chamber,
        "h": c.h,
        "k": c.k,
        "tori": c.tori,
        "walls": list(c.walls),
        "evidence": None if c.evidence is None else c.evidence.to_dict(),
    }


def chamber_labels(chambers: list[Chamber]) -> list[Chamber]:
    """One sample per chamber (its widest cell), with the chamber's count: None when its
    cells disagree or one is not resolved (never a count its own samples contradict)."""
    out = []
    for number in sorted({c.chamber for c in chambers}):
        cells = [c for c in chambers if c.chamber == number]
        counts = {c.tori for c in cells}
        widest = max(cells, key=lambda c: c.width)
        out.append(replace(widest, tori=counts.pop() if len(counts) == 1 else None))
    return out


def figure_html(fig: Any, width: int) -> str:
    """A matplotlib figure drawn by Agg as an inline PNG ``width`` pixels wide
    (:func:`~chargedesign.results.png_html`)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    canvas = FigureCanvasAgg(fig)
    canvas.draw()
    return png_html(np.asarray(canvas.buffer_rgba())[..., :3], width)


class DiagramResult(Result):
    """What the theorem's diagram (:class:`BifurcationDiagram`) and a case's
    (:class:`CaseDiagram`) share: ``raw`` with the
    branches, vertices and chambers; the contract's CSV; the files; the chambers' labels."""

    raw: Any

    @property
    def branches(self) -> list[TracedBranch]:
        return self.raw.branches

    def labels(self) -> list[Chamber]:
        """One cell per chamber (its widest), with the chamber's count (None if its cells
        disagree): :func:`chamber_labels`."""
        return chamber_labels(self.raw.chambers)

    def rows(self) -> list[tuple[Any, ...]]:
        """The CSV rows ``h, k, branch, type, p, q, r, gamma1, gamma2, gamma3``."""
        return csv_rows(self.branches)

    def csv_text(self) -> str:
        return csv_table(self.branches)

    def plot(self, axes: Any = None) -> Any:  # pragma: no cover - every diagram overrides it
        raise NotImplementedError

    def _tori_text(self) -> str:
        """The tori per chamber, in words (``unresolved`` for a chamber without a count)."""
        labels = self.labels()
        return ", ".join("unresolved" if c.tori is None else str(c.tori) for c in labels) or "none"

    def _time_line(self) -> str:
        stages = ", ".join(f"{k} {v:.2f} s" for k, v in self.raw.seconds.items())
        return f"  time: {stages}"

    def write(self, out: str | os.PathLike[str]) -> Path:
        """``bifurcation.csv`` and ``bifurcation.png`` into ``out``, together or not at all."""
        target = Path(out)
        with atomic_directory(target) as stage:
            write_text_atomic(stage / "bifurcation.csv", self.csv_text())
            self.plot().savefig(stage / "bifurcation.png", dpi=130)
        return target


@dataclass(repr=False)
class BifurcationDiagram(DiagramResult):
    """The bifurcation diagram: branches (critical families), vertices, chambers.

    ``raw`` holds the arrays (:class:`~chargedesign.topology.compute.RawDiagram`, SI, body
    axes). :meth:`rows` is the CSV table; :meth:`write` writes ``bifurcation.csv`` and
    ``bifurcation.png``; :meth:`plot` draws into matplotlib axes.
    """

    raw: RawDiagram

    def to_dict(self) -> dict[str, Any]:
        raw = self.raw
        return {
            "parameters": raw.params.as_dict(),
            "h_range": list(raw.h_range),
            "h_min": raw.h_min,
            "larmor_shift": larmor_shift(raw.params),
            "time_scale": Reading.of(raw.params).s,
            "branches": [{"branch": i} | branch_record(b) for i, b in enumerate(self.branches)],
            "vertices": [vertex_record(v) for v in raw.vertices],
            "chambers": [chamber_record(c) for c in self.labels()],
            "closed_form": [
                {"type": p.type, "h_j": p.h_j, "from_h": p.start, "name": p.name}
                for p in ClosedForm.of(raw.params).parabolas
            ],
            "seconds": dict(raw.seconds),
            "seeds": raw.seeds_found,
        }

    def _summary(self) -> dict[str, Any]:
        tori = [c.tori for c in self.labels()]
        return {
            "branches": len(self.branches),
            "points": sum(len(b.hk) for b in self.branches),
            "vertices": len(self.raw.vertices),
            "h_range": [float(f"{fmt(v, CELL)}") for v in self.raw.h_range],
            "tori_per_chamber": tori,
        }

    def _text(self) -> str:
        raw = self.raw
        lines = [
            "bifurcation diagram of (H, I4) on I3 = 0, |gamma| = 1",
            f"  energy range {fmt(raw.h_range[0], CELL)} .. {fmt(raw.h_range[1], CELL)} J "
            f"(least energy on the level {fmt(raw.h_min, CELL)} J)",
            f"  computed at n = 0 in time units of 1/w0, w0 = "
            f"{fmt(Reading.of(raw.params).s, CELL)} 1/s, "
            "then mapped exactly (Larmor: h shifted by C n^2 ="
            f" {fmt(larmor_shift(raw.params), CELL)} J)",
        ]
        for item in self.to_dict()["branches"]:
            line = branch_line(f"branch {item['branch']}", item, SI_UNITS)
            lines.append(line + (" exact" if item["exact"] else ""))
        images = [b.hk for b in self.branches]
        extent = np.ptp(np.concatenate(images), axis=0) if images else np.ones(2)
        size = (float(extent[0]) or 1.0, float(extent[1]) or 1.0)
        for (h, k, kind), states in vertex_groups(raw.vertices, size).items():
            # on k = 0 (the equator, w = gamma3 = 0) xi vanishes to second order: the Hessian
            # of I4 = |xi|^2 vanishes, so as singularities of (H, I4) these are degenerate
            note = "" if k != 0.0 else "; degenerate for (H, I4): the Hessian of I4 vanishes"
            lines.append(vertex_line(h, k, kind, states, SI_UNITS, note))
        for p in ClosedForm.of(raw.params).parabolas:
            lines.append(f"  closed form: {p.label}, from h = {fmt(p.start, CELL)} J")
        lines.append(
            f"  chambers: {len(self.labels())} ({len(raw.chambers)} cells between consecutive"
            f" vertex energies, each counted by the flow); tori per chamber: {self._tori_text()}"
        )
        evidence = [c.evidence for c in raw.chambers if c.evidence and c.evidence.plateau]
        if evidence:
            widest = min(e.plateau[1] / e.plateau[0] for e in evidence if e.plateau)
            apart = [e.separation for e in evidence if e.separation is not None]
            lines.append(
                f"  each count holds over join distances spanning a factor {fmt(widest, CELL)} or"
                " more with every sample passed by a trajectory"
                + (f"; the tori's samples at least {fmt(min(apart), CELL)} apart" if apart else "")
            )
        lines.append(self._time_line())
        return "\n".join(lines) + "\n"

    def plot(self, axes: Any = None, root: bool = False) -> Any:
        """The diagram: admissible band, curves by type, vertices, chamber tori counts.

        With ``root`` the vertical axis is ``sqrt(k)``, where every branch is a straight line
        (``C sqrt(k) = |h - h_j|``) and thin chambers open up. Without ``axes`` a figure with
        both panels (k, and sqrt(k)).
        """
        from matplotlib.figure import Figure

        if axes is None:
            fig = Figure(figsize=(13.0, 5.5))
            left, right = fig.subplots(1, 2)
            self.plot(left)
            self.plot(right, root=True)
            return fig
        lift = np.sqrt if root else np.asarray
        raw = self.raw
        draw_diagram(axes, self.branches, raw.vertices, self.labels(), raw.admissible, lift)
        axes.set_xlabel("h = H [J]")
        if root:
            axes.set_ylabel("sqrt(k) = sqrt(I4) [1/s^2]")
            axes.set_title("the same in sqrt(k): branches C sqrt(k) = |h - h_j|", fontsize=10)
        else:
            axes.set_ylabel("k = I4 [1/s^4]")
            title = "Bifurcation diagram on I3 = 0 (numbers: tori per chamber)"
            axes.set_title(title, fontsize=10)
        axes.legend(fontsize=8, loc="upper left")
        return axes.figure

    def _html_picture(self) -> str:
        return figure_html(self.plot(), 420)


@dataclass(repr=False)
class CaseDiagram(DiagramResult):
    """The bifurcation diagram of a case: branches, vertices, cells with their tori."""

    raw: CaseRaw

    def to_dict(self) -> dict[str, Any]:
        raw = self.raw
        return {
            "case": raw.case.name,
            "level": str(raw.level),
            "h_range": list(raw.h_range),
            "h_min": raw.h_min,
            "branches": [
                {"branch": i, "name": raw.names[i]} | branch_record(b)
                for i, b in enumerate(raw.branches)
            ],
            "vertices": [vertex_record(v) for v in raw.vertices],
            "chambers": [chamber_record(c) for c in self.labels()],
            "seconds": dict(raw.seconds),
            "seeds": raw.seeds_found,
        }

    def _summary(self) -> dict[str, Any]:
        return {
            "case": self.raw.case.name,
            "branches": len(self.branches),
            "vertices": len(self.raw.vertices),
            "tori_per_chamber": [c.tori for c in self.labels()],
        }

    def _text(self) -> str:
        raw = self.raw
        lines = [
            f"bifurcation diagram of (H, F) of case {raw.case.name} on I3 = {raw.level},"
            " |gamma| = 1",
            f"  F = {raw.case.texts.get('integral', '')}",
            f"  energy range {fmt(raw.h_range[0], CELL)} .. {fmt(raw.h_range[1], CELL)}"
            f" (least energy on the level {fmt(raw.h_min, CELL)})",
        ]
        lines += [branch_line(item["name"], item) for item in self.to_dict()["branches"]]
        size = (
            raw.h_range[1] - raw.h_range[0],
            float(np.max(np.abs(raw.admissible[:, 1:]), initial=1.0)),
        )
        for (h, k, kind), states in vertex_groups(raw.vertices, size).items():
            lines.append(vertex_line(h, k, kind, states))
        lines.append(
            f"  chambers: {len(self.labels())} ({len(raw.chambers)} cells); tori per chamber:"
            f" {self._tori_text()}"
        )
        lines.append(self._time_line())
        return "\n".join(lines) + "\n"

    def plot(self, axes: Any = None) -> Any:
        """The diagram in (h, k = F): band, branches by type, vertices, tori per chamber."""
        from matplotlib.figure import Figure

        if axes is None:
            axes = Figure(figsize=(7.5, 5.5)).subplots()
        raw = self.raw
        draw_diagram(axes, self.branches, raw.vertices, self.labels(), raw.admissible, clip=False)
        axes.set_xlabel("h = H")
        axes.set_ylabel(f"k = F ({raw.case.texts.get('integral', 'F')})"[:80])
        axes.set_title(
            f"{raw.case.name} on I3 = {raw.level} (numbers: tori per chamber)", fontsize=10
        )
        # each traced branch's Appelrot class on its curve (Kowalevski's case on I3 = 0): the
        # class alone, its formula is in the published normalization, not these axes' units
        for branch, name in zip(raw.branches, raw.names, strict=True):
            if name.startswith("Appelrot") and len(branch.hk):
                h, k = branch.hk[int(0.75 * (len(branch.hk) - 1))]
                axes.annotate(
                    name.split(":")[0],
                    (h, k),
                    xytext=(4, 4),
                    textcoords="offset points",
                    fontsize=8,
                    color="0.2",
                )
        axes.legend(fontsize=8, loc="upper left")
        return axes.figure


def draw_diagram(
    axes: Any,
    branches: list[TracedBranch],
    vertices: list[Vertex],
    labels: list[Chamber],
    band: np.ndarray,
    lift: Any = np.asarray,
    clip: bool = True,
) -> None:
    """Admissible band, curves coloured by type, vertices and each chamber's tori count into
    ``axes`` (``lift`` maps k to the vertical axis; ``clip``: k drawn at least 0)."""
    if len(band):
        axes.fill_between(
            band[:, 0],
            lift(band[:, 1]),
            lift(band[:, 2]),
            color="0.9",
            label="admissible (F^-1 not empty)",
        )
    drawn = set()
    for b in branches:
        kinds = np.array(b.types)
        for kind in TYPES:
            mask = kinds == kind
            if not np.any(mask):
                continue
            hk = np.where(mask[:, None], b.hk, np.nan)
            axes.plot(
                hk[:, 0],
                lift(np.maximum(hk[:, 1], 0.0) if clip else hk[:, 1]),
                color=TYPE_COLOURS[kind],
                lw=1.6,
                label=kind if kind not in drawn else None,
            )
            drawn.add(kind)
    for v in vertices:
        k = max(float(v.hk[1]), 0.0) if clip else float(v.hk[1])
        axes.plot(v.hk[0], lift(k), "ko", ms=4)
    for c in labels:
        axes.annotate(
            "?" if c.tori is None else str(c.tori),
            (c.h, float(lift(c.k))),
            ha="center",
            va="center",
            fontsize=9,
            weight="bold",
        )


def csv_rows(branches: list[TracedBranch]) -> list[tuple[Any, ...]]:
    """The CSV rows ``h, k, branch, type, p, q, r, gamma1, gamma2, gamma3``."""
    out = []
    for index, b in enumerate(branches):
        for hk, kind, x in zip(b.hk, b.types, b.states, strict=True):
            out.append((float(hk[0]), float(hk[1]), index, kind, *map(float, x)))
    return out


def csv_table(branches: list[TracedBranch]) -> str:
    """The branches as the contract's CSV (:data:`CSV_COLUMNS`)."""
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(CSV_COLUMNS)
    for row in csv_rows(branches):
        writer.writerow([f"{fmt(v, FULL)}" if isinstance(v, float) else v for v in row])
    return buffer.getvalue()
