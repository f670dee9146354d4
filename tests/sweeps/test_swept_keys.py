"""A sweep's keys resolved once to their declarations, and the file's checks at the boundary
(chargedesign.scene.sweep_file): each refusal is the line the scene loader itself gives for
the same scene (an independent route: the loader run on the scene the value makes)."""

from __future__ import annotations

import copy
import json
import tomllib
from pathlib import Path
from typing import Any

import pytest

import chargedesign as cd
from chargedesign.errors import InputError
from chargedesign.scene.keys import DECLARED, declared
from chargedesign.scene.load import default_scene_text, scene_from_dict, validated
from chargedesign.scene.sweep_file import (
    builtin_command,
    check_executor,
    check_sweep_out,
    resolve_sweep_key,
    scene_with,
)
from chargedesign.sweeps import make_executor, sweep_from_dict
from chargedesign.tolerancing.common import sample_count

THEOREM = {
    "parameters": {"C": 1.0, "c": 0.3, "d": -0.4, "n": 0.7, "K": 0.5, "kappa": 0.9},
    "simulation": {"effects": ["theorem"], "t_end": 1.0, "samples": 11},
    "output": {"trajectory": False, "plot": False},
}
BAD_VALUES = ("x", True, -1e9, 1e25, 0, [1.0, 2.0])


def _loader_line(data: dict[str, Any], source: str) -> str | None:
    """The scene loader's own line for a scene (None: accepted)."""
    try:
        validated(scene_from_dict(copy.deepcopy(data), source))
    except InputError as exc:
        return str(exc)
    return None


@pytest.fixture(scope="module")
def theorem_scene(tmp_path_factory: pytest.TempPathFactory) -> Path:
    path = tmp_path_factory.mktemp("scene") / "theorem.toml"
    lines = []
    for table, values in THEOREM.items():
        lines.append(f"[{table}]")
        lines += [
            f"{k} = {json.dumps(v).lower() if isinstance(v, bool) else json.dumps(v)}"
            for k, v in values.items()
        ]
    path.write_text("\n".join(lines) + "\n")
    return path


def test_a_key_resolves_to_its_declaration() -> None:
    key = resolve_sweep_key("design.max_charge", "s.toml")
    assert (key.table, key.name, key.declaration) == (
        "design",
        "max_charge",
        declared("design", "max_charge"),
    )
    field = resolve_sweep_key("fields.magnetic.a1", "s.toml")
    assert (field.table, field.name, field.declaration) == (
        "fields",
        "a1",
        declared("fields", "a1"),
    )
    # a whole table, a deeper key or an undeclared name has no declaration of its own
    assert resolve_sweep_key("fields.magnetic", "s.toml").declaration is None
    assert resolve_sweep_key("body.charges.values", "s.toml").declaration is None
    assert resolve_sweep_key("design.no_such_key", "s.toml").declaration is None


@pytest.mark.parametrize(
    ("key", "line"),
    [
        ("n", "s.toml: grid key 'n': expected a dotted scene key such as body.radius"),
        ("design.", "s.toml: grid key 'design.': expected a dotted scene key such as body.radius"),
        ("colours.n", "s.toml: unknown scene key 'colours.n' (scene tables: "),
    ],
)
def test_a_key_that_names_no_scene_key_is_refused(key: str, line: str) -> None:
    with pytest.raises(InputError) as info:
        resolve_sweep_key(key, "s.toml")
    assert str(info.value).startswith(line)


PLAIN_KEYS = [
    (table, key.name)
    for table in ("design", "simulation", "output")
    for key in DECLARED[table]
    if "enum" in key.schema or key.schema.get("type") in ("number", "integer", "boolean")
]


@pytest.mark.parametrize(("table", "name"), PLAIN_KEYS)
def test_a_declared_keys_refusal_is_the_loaders_line(
    table: str, name: str, theorem_scene: Path
) -> None:
    """Every plain key of the tables checked by their declarations, with values of the wrong
    type and out of range: the sweep refuses exactly when the loader refuses the scene the
    value makes, with the loader's line after the key's name."""
    base = tomllib.loads(theorem_scene.read_text())
    refused = 0
    for value in BAD_VALUES:
        path = f"{table}.{name}"
        data = {"scene": str(theorem_scene), "command": "simulate", "grid": {path: [value]}}
        expected = _loader_line(scene_with(base, {path: value}), str(theorem_scene))
        try:
            sweep_from_dict(data, "s.toml")
            got = None
        except InputError as exc:
            got = str(exc)
        if expected is None:
            # the loader accepts the scene: a refusal, if any, comes later (the point's work)
            assert got is None or "scene key" not in got
        else:
            refused += 1
            assert got == f"s.toml: scene key {path!r}: {expected}"
    assert refused >= 1  # each key refuses at least one of the bad values


def test_an_invalid_base_scene_is_reported_as_the_loader_reports_it(tmp_path: Path) -> None:
    """A base scene that fails in a table the loader reads first keeps its own line, even
    when the swept value is itself bad (the declaration is not asked first)."""
    data = copy.deepcopy(THEOREM)
    data["parameters"]["n"] = -5e300
    scene = tmp_path / "bad.toml"
    scene.write_text(
        "[parameters]\nC = 1.0\nc = 0.3\nd = -0.4\nn = -5e300\nK = 0.5\nkappa = 0.9\n"
        "[simulation]\neffects = ['theorem']\n"
    )
    sweep = {"scene": str(scene), "command": "simulate", "grid": {"simulation.rtol": [-1.0]}}
    with pytest.raises(InputError) as info:
        sweep_from_dict(sweep, "s.toml")
    base = tomllib.loads(scene.read_text())
    expected = _loader_line(scene_with(base, {"simulation.rtol": -1.0}), str(scene))
    assert expected is not None and expected.startswith("parameters.n")
    assert str(info.value) == f"s.toml: scene key 'simulation.rtol': {expected}"


def test_the_default_scene_is_valid_for_the_declaration_route() -> None:
    # the route that asks the declaration first needs a valid base: the default is one
    assert _loader_line(tomllib.loads(default_scene_text()), "<default>") is None


def test_the_run_options_are_checked_at_the_boundary(tmp_path: Path) -> None:
    with pytest.raises(InputError, match=r"^--executor: expected one of process, dask, serial"):
        check_executor("threads", None)
    for workers in (0, True, 1.5):
        with pytest.raises(InputError, match=r"^--workers: expected an integer >= 1"):
            make_executor("serial", workers=workers)
    assert check_executor("serial", 3) == 3
    afile = tmp_path / "afile"
    afile.write_text("x")
    with pytest.raises(InputError, match="expected an output directory, it is a file"):
        check_sweep_out(afile, [], "simulate", False)
    out = tmp_path / "out"
    out.mkdir()
    points = [{"point": "p0000", "keys": {"parameters.n": 0.5}}]
    (out / "sweep.json").write_text(json.dumps({"points": points, "command": "simulate"}))
    with pytest.raises(InputError, match="holds an earlier sweep; pass --resume"):
        check_sweep_out(out, points, "simulate", False)
    with pytest.raises(InputError, match="--resume: the sweep file's points or command differ"):
        check_sweep_out(out, points, "design", True)
    check_sweep_out(out, points, "simulate", True)  # the same sweep: resumed


def test_a_command_name_is_compared_never_imported() -> None:
    assert builtin_command("simulate", ("design", "simulate")) == "simulate"
    with pytest.raises(InputError, match=r"^command 'os:system': not a built-in command"):
        builtin_command("os:system", ("design", "simulate"))


def test_the_notebook_entry_points_refuse_a_wrong_kind_in_one_line() -> None:
    cases = [
        (
            lambda: cd.design(3.5),
            "design: expected a scene, a path, a mapping, Parameters or None, got float",
        ),
        (
            lambda: cd.check(3.5),
            "check: expected a Design, a DesignResult, a design.json path or mapping, got float",
        ),
        (
            lambda: cd.verify_case(3.5),
            "verify_case: expected a case file path, a [case] mapping or a Case, got float",
        ),
    ]
    for call, line in cases:
        with pytest.raises(InputError) as info:
            call()
        assert str(info.value) == line
    spec = sweep_from_dict({"command": "simulate", "scene": None, "grid": {"parameters.n": [0.5]}})
    with pytest.raises(InputError) as info:
        cd.sweep(spec, "unused", command=lambda scene, out: {})
    assert str(info.value) == "command=: give it with a sweep file, not with a parsed SweepSpec"


def test_sample_counts_are_checked_at_the_boundary() -> None:
    assert sample_count(200, "samples", 1) == 200
    for value in (True, 0, 2001, 2.0):
        with pytest.raises(InputError, match=r"^samples: expected an integer in 1\.\.2000"):
            sample_count(value, "samples", 1)
