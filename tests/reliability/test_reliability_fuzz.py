"""Hypothesis-driven mutations of scenes and design.json files (issue 15).

Every case ends in exit 0 (and then a body that passes ``check``) or exit 1 (a check that
fails, said in its report) or a one-line error (exit 2) with no traceback; the output folder
is unchanged unless the run succeeded.
"""

from __future__ import annotations

import copy
import json
import tomllib
from pathlib import Path
from typing import Any

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from reliability_support import SMALL_DESIGN, SMALL_SCENE, assert_clean_error, run_cli, snapshot

#: values a hostile or careless file may hold where a number (or anything) is expected
WEIRD = st.one_of(
    st.booleans(),
    st.none(),
    st.just(float("nan")),
    st.just(float("inf")),
    st.floats(allow_nan=False, allow_infinity=False),
    st.sampled_from([0, -1, 10**309, 10**20, 1e-320, 1e300, -1e-308, 2**63]),
    st.text(max_size=8),
    st.lists(st.floats(-10, 10), max_size=4),
    st.just([[True, 0.0, 0.0]]),
    st.just({"x": 1}),
)


def _paths(data: Any, prefix: tuple = ()) -> list[tuple]:
    out = [prefix] if prefix else []
    if isinstance(data, dict):
        for key, value in data.items():
            out += _paths(value, (*prefix, key))
    elif isinstance(data, list) and data and not isinstance(data[0], (int, float)):
        for i, value in enumerate(data):
            out += _paths(value, (*prefix, i))
    return out


def _set(data: Any, path: tuple, value: Any) -> None:
    for key in path[:-1]:
        data = data[key]
    data[path[-1]] = value


def _toml_value(value: Any) -> str:
    if value is None:
        return '"none"'
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        if value != value:
            return "nan"
        if value in (float("inf"), float("-inf")):
            return "inf" if value > 0 else "-inf"
        return repr(value)
    if isinstance(value, int):
        return str(value)
    if isinstance(value, str):
        return json.dumps(value)
    if isinstance(value, list):
        return "[" + ", ".join(_toml_value(v) for v in value) + "]"
    if isinstance(value, dict):
        return "{" + ", ".join(f"{k} = {_toml_value(v)}" for k, v in value.items()) + "}"
    raise TypeError(value)


def _toml(data: dict[str, Any]) -> str:
    lines = []
    for name, table in data.items():
        sub = {k: v for k, v in table.items() if isinstance(v, dict) and name == "fields"}
        plain = {k: v for k, v in table.items() if k not in sub}
        lines.append(f"[{name}]")
        lines += [f"{k} = {_toml_value(v)}" for k, v in plain.items()]
        for key, inner in sub.items():
            lines.append(f"[{name}.{key}]")
            lines += [f"{k} = {_toml_value(v)}" for k, v in inner.items()]
    return "\n".join(lines) + "\n"


SCENE = tomllib.loads(SMALL_SCENE)
SCENE_PATHS = [p for p in _paths(SCENE) if len(p) >= 2 and p[-1] != "magnetic"]
DESIGN_PATHS = _paths(SMALL_DESIGN)


@settings(
    max_examples=20,
    deadline=None,
    suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow],
)
@given(
    path=st.sampled_from(SCENE_PATHS),
    value=WEIRD,
    extra=st.sampled_from([None, ("body", "extra_key"), ("parameters", "mystery")]),
)
def test_mutated_scenes_end_cleanly_in_conditions(tmp_path_factory, capsys, path, value, extra):
    folder = tmp_path_factory.mktemp("scene")
    data = copy.deepcopy(SCENE)
    _set(data, path, value)
    if extra is not None and isinstance(data.get(extra[0]), dict):
        data[extra[0]][extra[1]] = 1.0
    scene = folder / "scene.toml"
    scene.write_text(_toml(data))
    code, _, err = run_cli(["conditions", str(scene)], capsys)
    if code != 0:
        assert_clean_error(code, err, "conditions")


@settings(
    max_examples=4,
    deadline=None,
    suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow],
)
@given(path=st.sampled_from(SCENE_PATHS), value=WEIRD)
def test_mutated_scenes_design_a_checked_body_or_fail_cleanly(
    tmp_path_factory, capsys, path, value
):
    folder = tmp_path_factory.mktemp("design")
    data = copy.deepcopy(SCENE)
    _set(data, path, value)
    scene = folder / "scene.toml"
    scene.write_text(_toml(data))
    out = folder / "out"
    out.mkdir()
    (out / "design.json").write_text("{}")
    before = snapshot(out)
    code, _, err = run_cli(
        ["design", str(scene), "--out", str(out), "--quiet", "--no-picture"], capsys
    )
    if code == 0:
        check, _, check_err = run_cli(["check", str(out / "design.json")], capsys)
        assert check == 0, check_err
    else:
        assert_clean_error(code, err, "design")
        assert snapshot(out) == before


@settings(
    max_examples=20,
    deadline=None,
    suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow],
)
@given(
    path=st.sampled_from(DESIGN_PATHS),
    value=WEIRD,
    command=st.sampled_from(["check", "export", "simulate"]),
)
def test_mutated_design_files_end_cleanly(tmp_path_factory, capsys, path, value, command):
    folder: Path = tmp_path_factory.mktemp("dj")
    data = copy.deepcopy(SMALL_DESIGN)
    _set(data, path, value)
    design = folder / "design.json"
    try:
        design.write_text(json.dumps(data))
    except ValueError:  # a value json cannot write: write its nearest text
        design.write_text(json.dumps(data, default=str))
    out = folder / "out"
    argv = {
        "check": ["check", str(design), "--orientations", "20"],
        "export": ["export", str(design), "--out", str(folder / "e.csv")],
        "simulate": [
            "simulate",
            str(design),
            "--t-end",
            "0.5",
            "--samples",
            "5",
            "--no-progress",
            "--out",
            str(out),
        ],
    }[command]
    code, _, err = run_cli(argv, capsys)
    if code == 2:
        assert_clean_error(code, err, command)
        assert not out.exists() and not (folder / "e.csv").exists()
    else:
        assert code in (0, 1), err
