"""A sweep file read at the boundary: its keys, the command it names, the base scene,
``chunk``, ``options``, the ``[grid]`` lists and the ``[random]`` specs, the number of points
(counted before any is built) and the points themselves, each a mapping of dotted scene keys
to values applied to the base scene's tables (:func:`scene_with`). One-line errors name the
key.

Each swept key is resolved once to its place in the scene and its declaration
(:func:`resolve_sweep_key`, :mod:`chargedesign.scene.keys`); a value is checked by that
declaration (:func:`check_swept_value`, the same one line the scene's owner gives), then the
whole scene it makes by the scene loader itself (cross-key rules: one function, not a copy).
The checks that need the stages (a point's candidates, solver, motion) are passed in by
:mod:`chargedesign.sweeps.spec` as functions; their errors are named here, by key or point.
The output directory of a run is checked here too (:func:`check_sweep_out`).
"""

from __future__ import annotations

import copy
import inspect
import json
import math
import os
import tomllib
from collections.abc import Callable, Iterator, Mapping
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from chargedesign.errors import InputError
from chargedesign.formatting import fmt
from chargedesign.limits import MAX_SWEEP_POINTS, OPTION_RANGES
from chargedesign.readers import read_toml_file
from chargedesign.scene.keys import Key, check_value, declared, key_names
from chargedesign.scene.load import (
    KNOWN_TABLES,
    Scene,
    default_scene_text,
    scene_from_dict,
    validated,
)
from chargedesign.validation import check_tree
from chargedesign.vocabulary import SWEEP_EXECUTORS

SWEEP_KEYS = ("scene", "command", "chunk", "grid", "random", "options")
RANDOM_KINDS = ("uniform", "log_uniform", "choice")


def set_dotted(data: dict[str, Any], key: str, value: Any) -> None:
    """``data["a"]["b"]["c"] = value`` for ``key = "a.b.c"`` (tables created as needed)."""
    parts = key.split(".")
    node = data
    for part in parts[:-1]:
        child = node.get(part)
        if child is None:
            child = node[part] = {}
        if not isinstance(child, dict):
            raise InputError(f"grid key {key!r}: {part!r} is a value, not a table, in the scene")
        node = child
    node[parts[-1]] = value


def scene_with(base: Mapping[str, Any], point: Mapping[str, Any]) -> dict[str, Any]:
    data = copy.deepcopy(dict(base))
    for key, value in point.items():
        set_dotted(data, key, value)
    return data


def random_values(key: str, spec: Any, n: int, rng: np.random.Generator, source: str) -> list:
    where = f"{source}: random key {key!r}"
    if not isinstance(spec, dict) or len(spec) != 1 or next(iter(spec)) not in RANDOM_KINDS:
        raise InputError(
            f"{where}: expected one of {{uniform = [lo, hi]}}, "
            "{log_uniform = [lo, hi]}, {choice = [...]}"
        )
    kind, arg = next(iter(spec.items()))
    if not isinstance(arg, list) or not arg:
        raise InputError(f"{where}: {kind} needs a non-empty list")
    if kind == "choice":
        idx = rng.integers(0, len(arg), n)
        return [arg[int(i)] for i in idx]
    if (
        len(arg) != 2
        or not all(isinstance(x, (int, float)) and not isinstance(x, bool) for x in arg)
        or not all(math.isfinite(x) for x in arg)
        or not arg[0] < arg[1]
    ):
        raise InputError(f"{where}: {kind} needs [lo, hi] with lo < hi")
    lo, hi = float(arg[0]), float(arg[1])
    if kind == "uniform":
        return [float(x) for x in rng.uniform(lo, hi, n)]
    if lo <= 0.0:
        raise InputError(f"{where}: log_uniform needs lo > 0")
    return [float(x) for x in np.exp(rng.uniform(math.log(lo), math.log(hi), n))]


def check_point_value(value: Any, where: str) -> None:
    """A swept value: a number within the input range (no nan, no 1e200), a string, a
    boolean, or a list or table of those (chargedesign.validation.check_tree)."""

    check_tree(value, where)


def check_sweep_keys(data: Any, source: str) -> None:
    """A table of known sweep keys."""
    if not isinstance(data, Mapping):
        raise InputError(f"{source}: expected a table of sweep keys")
    unknown = sorted(set(data) - set(SWEEP_KEYS))
    if unknown:
        raise InputError(
            f"{source}: unknown sweep key {unknown[0]!r} (expected {', '.join(SWEEP_KEYS)})"
        )


def base_scene(
    data: Mapping[str, Any], source: str, base_dir: Path | None
) -> tuple[dict[str, Any], str]:
    """The base scene's TOML mapping and its source (a path, or ``<default>``)."""

    scene_value = data.get("scene")
    if scene_value is None:
        return tomllib.loads(default_scene_text()), "<default>"
    if not isinstance(scene_value, str) or not scene_value:
        raise InputError(f"{source}: scene: expected a path to a scene file, got {scene_value!r}")
    path = Path(scene_value)
    if not path.is_absolute() and base_dir is not None:
        path = base_dir / path
    try:
        # missing, special files, size, encoding and depth: one line each
        scene_data = read_toml_file(path, "scene file")
    except InputError as exc:
        raise InputError(f"{source}: scene: {exc}") from None
    return scene_data, str(path)


def sweep_tables(data: Mapping[str, Any], source: str) -> tuple[int, dict, dict, dict | None]:
    """The ``chunk``, ``options``, ``grid`` and ``random`` entries, of the right types."""
    chunk = data.get("chunk", 0)
    if isinstance(chunk, bool) or not isinstance(chunk, int) or chunk < 0:
        raise InputError(f"{source}: chunk: expected an integer >= 0, got {chunk!r}")
    options = data.get("options", {})
    if not isinstance(options, dict):
        raise InputError(f"{source}: options: expected a table")
    grid = data.get("grid", {})
    if not isinstance(grid, dict):
        raise InputError(f"{source}: grid: expected a table of dotted scene keys")
    random = data.get("random")
    if random is not None and not isinstance(random, dict):
        raise InputError(f"{source}: random: expected a table")
    return chunk, options, grid, random


def grid_lists(grid: Mapping[str, Any], source: str) -> tuple[list[str], list[list[Any]]]:
    """The grid's keys and their (non-empty) lists of values."""
    keys: list[str] = []
    value_lists: list[list[Any]] = []
    for key, values in grid.items():
        if not isinstance(values, list):
            raise InputError(f"{source}: grid key {key!r}: expected a list of values")
        if not values:
            raise InputError(f"{source}: grid key {key!r}: empty list of values (empty grid)")
        keys.append(key)
        value_lists.append(values)
    return keys, value_lists


def random_table(
    random: Mapping[str, Any] | None, grid: Mapping[str, Any], source: str
) -> tuple[dict[str, Any], int, int]:
    """The ``[random]`` table's sampled keys, number of samples and seed (none: no keys)."""
    if random is None:
        return {}, 0, 0
    n_random = random.get("samples", 0)
    seed = random.get("seed", 0)
    if isinstance(n_random, bool) or not isinstance(n_random, int) or n_random < 1:
        raise InputError(f"{source}: random.samples: expected an integer >= 1, got {n_random!r}")
    if isinstance(seed, bool) or not isinstance(seed, int) or seed < 0:
        raise InputError(f"{source}: random.seed: expected an integer >= 0, got {seed!r}")
    random_keys = {k: v for k, v in random.items() if k not in ("samples", "seed")}
    if not random_keys:
        raise InputError(f"{source}: random: no keys to sample (empty random sample)")
    for key in random_keys:
        if key in grid:
            raise InputError(f"{source}: random key {key!r} is also a grid key")
    return random_keys, n_random, seed


def check_point_count(
    keys: list[str],
    value_lists: list[list[Any]],
    random_keys: Mapping[str, Any],
    n_random: int,
    max_points: int | None,
    source: str,
) -> None:
    """Some keys to sweep, and the points (grid points times draws) within the cap."""
    if not keys and not random_keys:
        raise InputError(f"{source}: grid: empty grid (give at least one dotted key with values)")
    count = math.prod(len(v) for v in value_lists) * (n_random if random_keys else 1)
    cap = MAX_SWEEP_POINTS if max_points is None else max_points
    if count > cap:
        raise InputError(
            f"{source}: {fmt(count)} points exceed the cap of {cap} "
            "(chargedesign.limits.MAX_SWEEP_POINTS); --max-points N raises it"
        )


def random_points(
    grid_points: list[dict[str, Any]],
    random_keys: Mapping[str, Any],
    n_random: int,
    rng: np.random.Generator,
    source: str,
) -> list[dict[str, Any]]:
    """``n_random`` draws of the random keys at every grid point (drawn per grid point)."""
    points: list[dict[str, Any]] = []
    for gp in grid_points:
        draws = {k: random_values(k, v, n_random, rng, source) for k, v in random_keys.items()}
        for i in range(n_random):
            p = dict(gp)
            p.update({k: draws[k][i] for k in random_keys})
            points.append(p)
    return points


# ------------------------------------------------------------------ swept keys, typed
@dataclass(frozen=True)
class SweptKey:
    """A swept dotted key resolved once: its table, its name in the table ("" when the key
    is deeper, or a whole table such as ``fields.magnetic``) and its declaration
    (:mod:`chargedesign.scene.keys`; None when it has none of its own)."""

    path: str
    table: str
    name: str
    declaration: Key | None

    def check(self, value: Any) -> None:
        """``value`` checked by the declaration alone (a number's type and range, an
        integer, a switch, a choice): the one line the table's owner gives for it.
        Keys without such a declaration are left to the whole scene's check."""
        key = self.declaration
        if key is None or not _checked_alone(self.table, key):
            return
        check_value(self.table, key.name, value, self.path)


#: tables whose owners check each plain key by its declaration first, named by its dotted
#: path, and the keys among them whose owners give their own words (``design.tol``: "a number
#: > 0", then "a relative residual below 1"). The others are checked by the whole scene alone,
#: as before (measured on a corpus of sweep files): ``[parameters]`` names "parameter n"; a
#: field's a1/a2 give way to a legendre conflict; ``[initial]`` needs gamma first; ``[body]``
#: refuses a key of another shape first; the physical tables need ``[medium]`` first and add
#: units or their own words; ``[case]`` and ``[testbed]`` parse their tables whole.
_CHECKED_ALONE = ("design", "simulation", "output")
_OWN_WORDS = ("design.tol",)


def _checked_alone(table: str, key: Key) -> bool:
    """A key whose value its owner checks by its declaration before anything else: a plain
    number, integer, switch or choice, in a table read key by key."""
    if table not in _CHECKED_ALONE or f"{table}.{key.name}" in _OWN_WORDS:
        return False
    spec = key.schema
    return "enum" in spec or spec.get("type") in ("number", "integer", "boolean")


def resolve_sweep_key(key: str, source: str) -> SweptKey:
    """A grid or random key as a :class:`SweptKey` (one line for a key that is not a dotted
    scene key, or names no scene table)."""
    parts = key.split(".")
    if len(parts) < 2 or not all(parts):
        raise InputError(
            f"{source}: grid key {key!r}: expected a dotted scene key such as body.radius"
        )
    if parts[0] not in KNOWN_TABLES:
        raise InputError(
            f"{source}: unknown scene key {key!r} (scene tables: {', '.join(KNOWN_TABLES)})"
        )
    table, rest = parts[0], parts[1:]
    if table == "fields":
        rest = rest[1:]  # fields.<kind>.<key>
    name = rest[0] if len(rest) == 1 else ""
    declaration = declared(table, name) if name in key_names(table) else None
    return SweptKey(key, table, name, declaration)


def base_is_valid(data: Mapping[str, Any], scene_source: str) -> bool:
    """Whether the base scene alone is accepted by the loader: only then is a swept value
    checked by its declaration first (a base scene's own error, in a table the loader reads
    before the key's, is reported as it always was)."""
    try:
        validated(scene_from_dict(copy.deepcopy(dict(data)), scene_source))
    except (InputError, TypeError, ValueError):
        return False
    return True


def check_scene_key(
    key: SweptKey,
    value: Any,
    data: Mapping[str, Any],
    source: str,
    scene_source: str,
    stage_check: Callable[[Scene], None] | None = None,
    *,
    by_declaration: bool = True,
) -> None:
    """``value`` of ``key`` alone on the base scene: by its declaration
    (``by_declaration``: the base scene is valid), then the whole scene by the loader (every
    table by its owner: cross-key rules), then ``stage_check`` (a region's candidates). One
    line naming the key."""
    # a dotted key through a value of the scene is refused as it is (its own one line)
    applied = scene_with(data, {key.path: value})
    try:
        if by_declaration:
            key.check(value)
        scene = validated(scene_from_dict(applied, scene_source))
        if stage_check is not None:
            stage_check(scene)
    except (InputError, TypeError, ValueError) as exc:
        raise InputError(f"{source}: scene key {key.path!r}: {exc}") from None


def point_scene(base: Mapping[str, Any], point: Mapping[str, Any], scene_source: str) -> Scene:
    """The scene of one point, validated as the loader validates a scene file
    (:func:`chargedesign.scene.load.validated`)."""
    return validated(scene_from_dict(scene_with(base, point), scene_source))


def check_points(
    points: list[dict[str, Any]], source: str, check: Callable[[dict[str, Any]], None]
) -> None:
    """Every point before any runs: its values (the input range), then ``check(point)``
    (its whole scene and the stages' work). One line naming the point and its values."""
    width = max(4, len(str(max(len(points) - 1, 0))))
    for i, point in enumerate(points):
        try:
            check_point_value(point, f"point p{i:0{width}d}")
            check(point)
        except (InputError, TypeError, ValueError) as exc:
            values = ", ".join(f"{k} = {v!r}" for k, v in point.items())
            raise InputError(f"{source}: point p{i:0{width}d} ({values}): {exc}") from None


# ------------------------------------------------------------------ command and options
def check_command_name(command: Any, names: Any, where: str) -> None:
    """One-line error unless ``command`` is one of ``names`` (the built-in commands).

    Nothing is imported or called: a name from a file is compared with the names, and
    anything else (``module:function`` included) is refused.
    """
    if isinstance(command, str) and command in names:
        return
    hint = ""
    if isinstance(command, str) and ":" in command:
        hint = (
            "; a sweep file never names code to run: pass your own function from Python, "
            "cd.sweep(file, out, command=function)"
        )
    raise InputError(
        f"{where}: unknown command {command!r} (expected one of {', '.join(names)}){hint}"
    )


def builtin_command(command: Any, names: Any) -> str:
    """``command`` when it is one of ``names`` (a built-in command; never imported)."""
    if isinstance(command, str) and command in names:
        return command
    raise InputError(
        f"command {command!r}: not a built-in command (expected one of {', '.join(names)})"
    )


def check_no_command_with_spec(command: Any) -> None:
    """``command=`` goes with a sweep file; a parsed sweep already holds its command."""
    if command is not None:
        raise InputError("command=: give it with a sweep file, not with a parsed SweepSpec")


def chosen_command(data: Mapping[str, Any], source: str, command: Any, names: Any) -> Any:
    """The command run at every point: the function passed from Python, or the file's
    named built-in command."""
    if command is not None:
        if not callable(command):
            raise InputError(f"command=: expected a function, got {type(command).__name__}")
        if "command" in data:
            raise InputError(
                f"{source}: names command {data['command']!r} and a function was passed as "
                "command=: give one of them"
            )
        return command
    if "command" not in data:
        raise InputError(f"{source}: missing key 'command'")
    check_command_name(data["command"], names, f"{source}: command")
    return data["command"]


def check_option_names(
    function: Callable[..., Any], options: Mapping[str, Any], source: str
) -> None:
    """``[options]``: values within the input range and names ``function`` takes (its
    signature)."""
    check_point_value(dict(options), f"{source}: options")
    try:
        inspect.signature(function).bind(None, None, **options)
    except TypeError as exc:
        raise InputError(f"{source}: options: {exc}") from None
    except ValueError:  # pragma: no cover - a callable without a signature
        return


def check_option_ranges(command: str, options: Mapping[str, Any], prefix: str) -> None:
    """A built-in command's numeric options within the ranges its command-line options have
    (:data:`chargedesign.limits.OPTION_RANGES`)."""
    ranges = OPTION_RANGES.get(command, {})
    for name, value in options.items():
        bounds = ranges.get(name)
        if bounds is None or isinstance(value, bool) or not isinstance(value, (int, float)):
            continue
        if not bounds.holds(value):
            raise InputError(f"{prefix}{name}: expected a value in {bounds.text()}, got {value!r}")


@contextmanager
def named_as_option(prefix: str) -> Iterator[None]:
    """An error of a command-line option's parser (``--position: ...``) named as the sweep
    file's option (``options.position: ...``)."""
    try:
        yield
    except InputError as exc:
        raise InputError(f"{prefix}{str(exc).removeprefix('--')}") from None


# ------------------------------------------------------------------ the run's options
def check_executor(kind: str, workers: Any) -> int:
    """``--executor`` among the executors and ``--workers`` an integer >= 1 (None: the
    CPUs, at most 8). The number of workers."""
    if kind not in SWEEP_EXECUTORS:
        raise InputError(f"--executor: expected one of {', '.join(SWEEP_EXECUTORS)}, got {kind!r}")
    n = workers if workers is not None else max(1, min(os.cpu_count() or 1, 8))
    if isinstance(n, bool) or not isinstance(n, int) or n < 1:
        raise InputError(f"--workers: expected an integer >= 1, got {workers!r}")
    return n


def check_sweep_out(out: Path, points: Any, command: str, resume: bool) -> None:
    """``out`` is a directory, new, or (``resume``) holding the same sweep: its
    ``sweep.json`` lists the same ``points`` and ``command``."""
    if out.exists() and not out.is_dir():
        raise InputError(f"{out}: expected an output directory, it is a file")
    plan_path = out / "sweep.json"
    if not plan_path.exists():
        return
    try:
        old = json.loads(plan_path.read_text(encoding="utf-8"))
    except (OSError, json.JSONDecodeError):
        old = None
    same = old is not None and old.get("points") == json.loads(json.dumps(points))
    if not resume:
        raise InputError(
            f"{out}: holds an earlier sweep; pass --resume to complete it or choose another --out"
        )
    if not same or old.get("command") != command:
        raise InputError(
            f"{out}: --resume: the sweep file's points or command differ from the sweep "
            "started there"
        )
