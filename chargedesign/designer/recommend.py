"""The recommended scene: the choice of field, materials, size and medium with the widest
realised window (:mod:`chargedesign.physical.window`).

The search is coordinate-wise over the choices a builder makes (each dimension in turn, every
value of it with the others held, the best kept; a second pass when the first changed
anything), every point a frontier with its window (``frontier_from_scene``):

- the field: ``a1 = 0`` (the frame reading needs no uniform field: its n is a rotation of
  axes) and the gradient ``a2`` times :data:`A2_FACTORS`;
- the magnets: every grade of :data:`~chargedesign.physical.materials.MAGNET_DATA`;
- the ballast: every material of :data:`~chargedesign.physical.materials.BALLAST_DENSITY`
  (metals and the insulating, low-chi ceramics and glass);
- the size: the body scaled by :data:`SIZE_FACTORS` (``C x f^5``, the parts' sizes x f);
- the medium: :data:`MEDIA`.

A choice is better when its window is wider (``s_high / s_low``); among empty windows, when
its best rate misses the fraction by less. The choices are ranked by frontiers located to
:data:`RANK_RTOL` without the checks around their bracket (a ranking needs no more: the
windows of the choices differ by factors; without charge conditions the bracket is found from
the masses' rate law, :func:`~chargedesign.designer.frontier.masses_rate_law`: 2 to 4
designs instead of 8); the best one is then located once more as
``chargedesign frontier`` locates it (to :data:`~chargedesign.designer.frontier.FRONTIER_RTOL`,
its bracket checked), and that frontier's window is the one reported and written.

Similar bodies share their designs (:class:`~chargedesign.designer.masses.SimilarBodies`): a
body ``4^k`` times the size of another of the same materials in the same field has, at
``2^-k`` times the rate, the other's magnets-and-masses program, and its design is the other's
scaled, to the bit. So a ranked frontier starts its scan at ``2^-k`` (:func:`similar_class`:
the sizes 1 and 4, 0.5 and 2 are one class, as are the media and the magnet grades of equal
figures) and takes its class's designs where the class made them (the K = 0 example: 124 of
409 designs). The recommended scene runs at the window's geometric middle (n, K x s; kappa,
lambda, rho x s^2; the simulated time / s).
"""

from __future__ import annotations

import copy
import json
import math
import time
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

from chargedesign.designer.frontier import FRONTIER_RTOL, WindowOptions, find_frontier
from chargedesign.designer.frontier_scan import scene_dict, scene_variant
from chargedesign.designer.masses import similar_bodies
from chargedesign.designer.pipeline import NO_MEDIUM, physical_setup_from_scene
from chargedesign.errors import ChargeDesignError, InfeasibleError
from chargedesign.files import write_text_atomic
from chargedesign.formatting import CELL, PLAIN, ROUGH, fmt
from chargedesign.physical.materials import BALLAST_DENSITY, MAGNET_DATA
from chargedesign.physical.window import RealisedWindow
from chargedesign.results import Result
from chargedesign.scene import scene_from_dict
from chargedesign.scene.keys import KEY

#: the gradient a2 tried, relative to the scene's
A2_FACTORS = (0.03, 0.1, 0.3, 1.0, 3.0)
#: the body's size tried, relative to the scene's
SIZE_FACTORS = (0.5, 1.0, 2.0, 4.0)
MEDIA = ("vacuum", "air", "sf6")
#: passes of the coordinate search (the second only when the first changed something)
PASSES = 2
#: the frontier's tolerance while the choices are ranked (the best is located to
#: FRONTIER_RTOL after)
RANK_RTOL = 0.05
#: rank by frontiers whose bracket comes from the masses' rate law where it applies (8 designs
#: a frontier become 2 to 4, and the K = 0 example's search 98 -> 53 s of CPU). Off: the design
#: is not monotone in the rate near some frontiers (the alumina-ballast body is refused at
#: s = 7.4989 and accepted at 7.58-8.35), and there the law ranks that choice above the one
#: the bisection leads to, whose located window is wider (the K = 0 example: x 36 against
#: x 118, docs/benchmarks.md); the better answer is kept until the design is monotone
RANK_LAW = False
#: the order in which the tables are written
TABLE_ORDER = (
    "parameters",
    "fields",
    "medium",
    "carriers",
    "magnets",
    "ballast",
    "body",
    "design",
    "simulation",
)


@dataclass(frozen=True)
class Choice:
    """One point of the search (None: the scene's own)."""

    a1_zero: bool = False
    a2_factor: float = 1.0
    magnets: str | None = None
    ballast: str | None = None
    size: float = 1.0
    medium: str | None = None

    def apply(self, base: dict[str, Any]) -> dict[str, Any]:
        """The scene mapping of this choice (``base`` unchanged)."""
        medium = self.medium or base.get("medium", {}).get("name", "vacuum")
        data = scene_variant(base, self.size, medium, 1.0, None) if self.size != 1.0 else None
        data = copy.deepcopy(base) if data is None else data
        if self.medium is not None:
            med = data.setdefault("medium", {})
            med.pop("breakdown", None)
            med["name"] = self.medium
        magnetic = data.get("fields", {}).get("magnetic", {})
        coeffs = list(magnetic.get("legendre", []))
        if coeffs:
            if self.a1_zero:
                coeffs[0] = 0.0
            if len(coeffs) > 1:
                coeffs[1] *= self.a2_factor
            magnetic["legendre"] = coeffs
        if self.magnets is not None:
            data["magnets"] = {"material": self.magnets}
        if self.ballast is not None:
            data["ballast"] = {"material": self.ballast}
        return data


@dataclass
class Evaluation:
    """A choice, its frontier's ``s_max`` and its realised window (None: refused, ``error``)."""

    choice: Choice
    s_max: float = 0.0
    window: RealisedWindow | None = None
    error: str = ""

    @property
    def score(self) -> tuple[int, float]:
        """Wider windows first; among empty ones, the smaller missing factor."""
        if self.window is None:
            return (0, -math.inf)
        if not self.window.empty:
            return (1, math.log(self.window.width))
        return (0, -math.log(self.window.missing) if self.window.missing > 0 else -math.inf)

    def text(self) -> str:
        if self.window is None:
            return f"refused ({self.error})"
        if self.window.empty:
            return f"empty, misses the fraction by {fmt(self.window.missing, ROUGH)}"
        return (
            f"s = {fmt(self.window.s_low, CELL)} to {fmt(self.window.s_high, CELL)} "
            f"(x {fmt(self.window.width, ROUGH)})"
        )


def _changes(base: dict[str, Any], choice: Choice, rate: float) -> list[str]:
    """Every change of the recommended scene from the input, in words."""
    out = []
    coeffs = list(base.get("fields", {}).get("magnetic", {}).get("legendre", []))
    if choice.a1_zero and coeffs and coeffs[0] != 0.0:
        out.append(f"[fields.magnetic] a1: {fmt(coeffs[0])} -> 0 T (no uniform field needed)")
    if choice.a2_factor != 1.0 and len(coeffs) > 1:
        a2 = coeffs[1] / 2.0
        out.append(
            f"[fields.magnetic] a2: {fmt(a2)} -> {fmt(a2 * choice.a2_factor)} T/m "
            f"(x {fmt(choice.a2_factor, PLAIN)})"
        )
    for table, chosen in (("magnets", choice.magnets), ("ballast", choice.ballast)):
        if chosen is not None:
            before = base.get(table, {}).get("material", "?")
            out.append(f"[{table}] material: {before} -> {chosen}")
    if choice.size != 1.0:
        out.append(
            f"[body] size x {fmt(choice.size, PLAIN)} (radius, spacing, carriers; C x "
            f"{fmt(choice.size**5, PLAIN)})"
        )
    if choice.medium is not None:
        before = base.get("medium", {}).get("name", "?")
        out.append(f"[medium] name: {before} -> {choice.medium}")
    if rate != 1.0:
        out.append(
            f"[parameters] the rate s = {fmt(rate, CELL)}: n, K x s; kappa, lambda, rho x s^2 "
            "(the window's geometric middle); [simulation] t_end / s"
        )
    return out


def scene_at_rate(data: dict[str, Any], s: float) -> dict[str, Any]:
    """The scene mapping at time rate ``s`` (the same motion s times faster)."""
    out = copy.deepcopy(data)
    params = out.get("parameters", {})
    for key in ("n", "K"):
        if key in params:
            params[key] = params[key] * s
    for key in ("kappa", "lambda", "rho"):
        if key in params:
            params[key] = params[key] * s**2
    simulation = out.get("simulation", {})
    if KEY.t_end in simulation:
        simulation[KEY.t_end] = simulation[KEY.t_end] / s
    return out


def _value(value: Any) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int | float):
        return repr(value) if isinstance(value, int) else repr(float(value))
    if isinstance(value, str):
        return json.dumps(value)
    if isinstance(value, list | tuple):
        return "[" + ", ".join(_value(v) for v in value) + "]"
    raise TypeError(f"recommend: cannot write {value!r} as TOML")


def _table(name: str, table: dict[str, Any]) -> list[str]:
    lines = [f"[{name}]"]
    subtables = []
    for key, value in table.items():
        if isinstance(value, dict):
            subtables.append((f"{name}.{key}", value))
        else:
            lines.append(f"{key} = {_value(value)}")
    for sub, value in subtables:
        lines += ["", *_table(sub, value)]
    return lines if len(lines) > 1 or not subtables else lines[1:]


def toml_text(data: dict[str, Any], comments: list[str]) -> str:
    """A scene mapping as TOML (tables of numbers, strings and lists), ``comments`` on top."""
    lines = [f"# {c}" if c else "#" for c in comments]
    keys = [k for k in TABLE_ORDER if k in data] + [k for k in data if k not in TABLE_ORDER]
    for key in keys:
        lines += ["", *_table(key, data[key])]
    return "\n".join(lines) + "\n"


@dataclass(repr=False)
class Recommendation(Result):
    """The search's best choice, its window, and the scene that realises it."""

    source: str
    base: Evaluation
    best: Evaluation
    searched: dict[str, list[Any]]
    evaluations: int
    seconds: float
    changes: list[str]
    scene: dict[str, Any]
    rate: float
    history: list[tuple[str, str]] = field(default_factory=list)
    #: the magnets-and-masses designs taken from a similar body's and made
    #: (:class:`~chargedesign.designer.masses.SimilarBodies`)
    sharing: tuple[int, int] = (0, 0)

    def comments(self) -> list[str]:
        window = self.best.window
        lines = [
            f"Recommended by `chargedesign frontier {self.source} --recommend`: the choice with "
            "the widest realised window",
            "(every parasitic below the fraction of each realised term; docs/buildable.md).",
            f"Input: {self.base.text()}. Recommended: {self.best.text()}.",
            "Changes from the input:",
            *[f"  - {c}" for c in self.changes],
        ]
        if not self.changes:
            lines.append("  - none: the input is the best choice searched")
        if window is not None and not window.empty:
            assert window.s_low is not None and window.s_high is not None
            lines += [
                f"Window margins at this rate: down to x {fmt(self.rate / window.s_low, ROUGH)} "
                f"slower ({window.binding_low.split(' (')[0]}), up to x "
                f"{fmt(window.s_high / self.rate, ROUGH)} faster "
                f"({window.binding_high.split(': ')[0]}).",
                "Parasitics over the fraction here: "
                + ", ".join(f"{k} {fmt(v, ROUGH)}" for k, v in window.margins.items()),
            ]
        lines.append("Searched: " + "; ".join(f"{k} {v}" for k, v in self.searched.items()))
        return lines

    def write(self, path: Path) -> None:
        write_text_atomic(path, toml_text(self.scene, self.comments()))

    def to_dict(self) -> dict[str, Any]:
        def evaluation(e: Evaluation) -> dict[str, Any]:
            return {
                "choice": e.choice.__dict__,
                "s_max": e.s_max,
                "realised": e.window.to_dict() if e.window is not None else None,
                "error": e.error or None,
            }

        return {
            "base": evaluation(self.base),
            "best": evaluation(self.best),
            "changes": list(self.changes),
            "rate": self.rate,
            "searched": {k: list(v) for k, v in self.searched.items()},
            "evaluations": self.evaluations,
            "seconds": self.seconds,
        }

    def _summary(self) -> dict[str, Any]:
        return {"best": self.best.text(), "evaluations": self.evaluations}

    def _text(self) -> str:
        lines = [
            f"input: {self.base.text()}",
            f"recommended: {self.best.text()}",
            *[f"  change: {c}" for c in self.changes],
        ]
        window = self.best.window
        if window is not None and window.empty and window.why:
            lines.append(f"why: {window.why}")
        lines += [
            "searched: " + "; ".join(f"{k} {v}" for k, v in self.searched.items()),
            f"({self.evaluations} frontiers with windows, {self.seconds:.1f} s)",
            self.answer(),
        ]
        return "\n".join(lines) + "\n"

    def answer(self) -> str:
        """One line that answers the search: which choice realises the theorem within the
        fraction, over which rates; or that none searched does, and by how much the closest
        misses."""
        window = self.best.window
        if window is None:
            return f"answer: every choice searched was refused ({self.best.error})"
        what = "; ".join(self.changes) if self.changes else "the input scene as it is"
        if window.empty:
            return (
                f"answer: no choice searched is realised within the fraction; the closest "
                f"({what}) misses it by x {fmt(window.missing, ROUGH)}"
            )
        return (
            f"answer: realised for s = {fmt(window.s_low, CELL)} to {fmt(window.s_high, CELL)} "
            f"(x {fmt(window.width, ROUGH)}) with {what}; the scene written runs at s = "
            f"{fmt(self.rate, CELL)}"
        )


def _dimensions(base: dict[str, Any]) -> dict[str, tuple[Any, ...]]:
    """The values each choice takes (a dimension the scene cannot use is left out)."""
    coeffs = list(base.get("fields", {}).get("magnetic", {}).get("legendre", []))
    dims: dict[str, tuple[Any, ...]] = {}
    reading = base.get("design", {}).get("larmor", "frame")
    if coeffs and coeffs[0] != 0.0 and reading == "frame":
        dims["a1_zero"] = (False, True)
    if len(coeffs) > 1 and coeffs[1] != 0.0:
        dims["a2_factor"] = A2_FACTORS
    if coeffs:
        dims["magnets"] = tuple(MAGNET_DATA)
    dims["ballast"] = tuple(BALLAST_DENSITY)
    dims["size"] = SIZE_FACTORS
    dims["medium"] = MEDIA
    return dims


def recommend(
    scene: Any, options: WindowOptions, *, progress: Any = None, tally: Any = None
) -> Recommendation:
    """The choice with the widest realised window (see the module doc) and its scene.

    ``progress(message)`` is told each probe's outcome; ``tally(done, total)`` counts the
    probes (frontiers with windows) against the most the search can make.
    """
    t0 = time.perf_counter()
    base = scene_dict(scene)
    dims = _dimensions(base)
    total = probes_at_most(dims)
    cache: dict[Choice, Evaluation] = {}
    history: list[tuple[str, str]] = []
    made = [0]

    def frontier_of(choice: Choice, ranked: bool) -> Evaluation:
        made[0] += 1
        try:
            data = choice.apply(base)
            setup = physical_setup_from_scene(
                scene_from_dict(data, f"{scene.source} (recommend {made[0]})")
            )
            if setup is None:
                raise InfeasibleError(NO_MEDIUM)
            key, ratio = similar_class(choice)
            shared.add(setup, key, ratio)
            front = find_frontier(
                setup,
                window=options,
                rtol=RANK_RTOL if ranked else FRONTIER_RTOL,
                checks=not ranked,
                law=RANK_LAW and ranked,
                # a ranked frontier follows its class's path (the located one, frontier's own)
                start=1.0 / math.sqrt(ratio) if ranked else 1.0,
            )
            found = Evaluation(choice, front.s_max, front.realised)
        except ChargeDesignError as exc:
            found = Evaluation(choice, error=str(exc))
        history.append((repr(choice), found.text()))
        if progress is not None:
            what = "probe" if ranked else "the best choice located"
            progress(f"{what} {made[0]} of at most {total}: {_choice_text(choice)}: {found.text()}")
        if tally is not None:
            tally(made[0], total)
        return found

    def evaluate(choice: Choice) -> Evaluation:
        if choice not in cache:
            cache[choice] = frontier_of(choice, ranked=True)
        return cache[choice]

    with similar_bodies() as shared:
        first = evaluate(Choice())
        best = first
        for _ in range(PASSES):
            before = best.choice
            for name, values in dims.items():
                for value in values:
                    trial = evaluate(replace(best.choice, **{name: _normalised(name, value, base)}))
                    if trial.score > best.score:
                        best = trial
            if best.choice == before:
                break
        located = frontier_of(best.choice, ranked=False)
        sharing = (shared.shared, shared.designed)
    if located.window is not None or best.window is None:
        best = located
        if best.choice == first.choice:
            first = located
    if tally is not None:
        tally(made[0], made[0])  # the search ended: every probe it makes is made
    window = best.window
    rate = window.s_best if window is not None and not window.empty else 1.0
    scene_out = scene_at_rate(best.choice.apply(base), rate)
    return Recommendation(
        source=str(scene.source),
        base=first,
        best=best,
        searched={k: list(v) for k, v in dims.items()},
        evaluations=made[0],
        seconds=time.perf_counter() - t0,
        changes=_changes(base, best.choice, rate),
        scene=scene_out,
        rate=rate,
        history=history,
        sharing=sharing,
    )


def similar_class(choice: Choice) -> tuple[Choice, float]:
    """The class of similar bodies a choice's body belongs to, and its size over the class's
    body (a power of 4: :class:`~chargedesign.designer.masses.SimilarBodies`). The medium and
    the magnets' grade are left out: the magnets-and-masses design reads the carriers the
    charges leave and the magnet material's figures (not its name), which the sharing
    compares (ndfeb-eh is ndfeb with a higher coercivity: the same body where no cell's
    field demagnetises either)."""
    k = math.floor(math.log(choice.size, 4) + 0.5) if choice.size > 0 else 0
    ratio = 4.0**k
    return replace(choice, size=choice.size / ratio, medium=None, magnets=None), ratio


def probes_at_most(dims: dict[str, tuple[Any, ...]]) -> int:
    """The most probes the coordinate search makes: the input, then every value of every
    dimension in each pass (a repeated choice is not probed again), then the best choice
    located to the frontier's tolerance."""
    return 2 + PASSES * sum(len(values) for values in dims.values())


def _normalised(name: str, value: Any, base: dict[str, Any]) -> Any:
    """The scene's own value of a material or medium is the choice ``None`` (no change)."""
    own = {
        "magnets": base.get("magnets", {}).get("material"),
        "ballast": base.get("ballast", {}).get("material"),
        "medium": base.get("medium", {}).get("name"),
    }
    return None if name in own and value == own[name] else value


def _choice_text(choice: Choice) -> str:
    parts = [
        f"{k}={v}"
        for k, v in choice.__dict__.items()
        if v is True or (v is not None and v is not False and v != 1.0) or k == "size"
    ]
    return ", ".join(parts)
