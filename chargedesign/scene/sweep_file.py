"""A sweep file read at the boundary: its keys, the base scene it names, ``chunk``,
``options``, the ``[grid]`` lists and the ``[random]`` specs, the number of points (counted
before any is built) and the points themselves, each a mapping of dotted scene keys to
values applied to the base scene's tables (:func:`scene_with`). One-line errors name the key.

What a point's values mean for the stages (its whole scene, its candidates, its work) is
checked by :mod:`chargedesign.sweeps.spec`.
"""

from __future__ import annotations

import copy
import math
import tomllib
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from chargedesign.errors import InputError
from chargedesign.formatting import fmt
from chargedesign.limits import MAX_SWEEP_POINTS
from chargedesign.readers import read_toml_file
from chargedesign.scene.load import default_scene_text
from chargedesign.validation import check_tree

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
