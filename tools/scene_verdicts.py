"""Which scenes are accepted and which refused, and with what one-line error: a corpus that
walks every key of the scene schema with a fixed set of probe values, so that a change of the
scene's validators can be held against the behaviour before it.

    python tools/scene_verdicts.py OUT.json

Each probe is one key of the schema (``table.key``, or ``fields.<kind>.key``) set to one
probe value in one base scene (the embedded default, a physical region scene and a theorem
scene with [simulation] and [initial]), written as a TOML file and read with
:func:`chargedesign.scene.load_scene`, exactly as every command reads a scene. The verdict is
``"accepted"`` or the error's text; anything else that escapes is recorded as a crash
(``"CRASH <type>: <text>"``). An accepted scene with a ``[body]`` region also has its
candidate points built (:func:`chargedesign.candidates.candidates_from_table`, as the
design stage does): the verdict then adds their count and a hash of their coordinates, or
the error that refused them. :mod:`tools.compare_outputs` runs it into each snapshot.
"""

from __future__ import annotations

import json
import sys
import tempfile
import tomllib
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]

#: probe values: numbers at and across the usual bounds, wrong types, lists and tables
PROBES: tuple[Any, ...] = (
    0,
    1,
    -1,
    0.5,
    1.0,
    2,
    1e-30,
    1e31,
    7.5,
    True,
    "x",
    "",
    "auto",
    [1.0, 2.0, 3.0],
    [1.0, 2.0],
    [],
    ["x"],
    {"a": 1},
)

THEOREM = """\
[parameters]
C = 1.0
c = 0.3
d = -0.4
n = 0.7
K = 0.5
kappa = 0.9

[fields.magnetic]
a1 = 1.0
a2 = 0.5

[simulation]
t_end = 1.0
samples = 11

[initial]
gamma = [0.6, 0.0, 0.8]
omega = [0.1, 0.2, 0.0]

[output]
dir = "out"
"""


def _bases() -> dict[str, dict[str, Any]]:
    from chargedesign.scene import default_scene_text

    small = tomllib.loads((ROOT / "tests/physical/small.toml").read_text("utf-8"))
    return {
        "default": tomllib.loads(default_scene_text()),
        "small": small,
        "theorem": tomllib.loads(THEOREM),
    }


def _keys() -> list[tuple[str, ...]]:
    """Every key path of the scene schema's tables (fields by kind), with enum values."""
    from chargedesign.schemas import schema

    out: list[tuple[str, ...]] = []
    for table, spec in schema("scene")["properties"].items():
        for key, sub in spec.get("properties", {}).items():
            if table == "fields":
                out += [(table, key, inner) for inner in sub.get("properties", {})]
            else:
                out.append((table, key))
        out.append((table, "no_such_key"))
    return out


def _enums(path: tuple[str, ...]) -> list[Any]:
    from chargedesign.schemas import schema

    node: Any = schema("scene")
    for part in path:
        node = node.get("properties", {}).get(part, {})
    values = list(node.get("enum", []))
    items = node.get("items", {})
    if isinstance(items, dict) and "enum" in items:
        values += [[v] for v in items["enum"]]
    return values


def _toml_value(value: Any) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, (int, float, str)):
        return json.dumps(value)
    if isinstance(value, list):
        return "[" + ", ".join(_toml_value(v) for v in value) + "]"
    return "{" + ", ".join(f"{k} = {_toml_value(v)}" for k, v in value.items()) + "}"


def _toml(data: dict[str, Any]) -> str:
    """A scene mapping as TOML: one table per scene table, ``[fields.<kind>]`` per field."""
    chunks = []
    for table, value in data.items():
        inner = value if table == "fields" and isinstance(value, dict) else {table: value}
        for name, body in inner.items():
            head = f"[fields.{name}]" if table == "fields" else f"[{name}]"
            if not isinstance(body, dict):
                chunks.append(f"{name} = {_toml_value(body)}")
                continue
            lines = [f"{k} = {_toml_value(v)}" for k, v in body.items()]
            chunks.append("\n".join([head, *lines]))
    return "\n\n".join(chunks) + "\n"


def _set(data: dict[str, Any], path: tuple[str, ...], value: Any) -> dict[str, Any]:
    out = json.loads(json.dumps(data))
    node = out
    for part in path[:-1]:
        child = node.get(part)
        if not isinstance(child, dict):
            child = node[part] = {}
        node = child
    node[path[-1]] = value
    return out


def _candidates(scene: Any) -> str:
    """``"; <n> candidates <hash>"`` for a scene with a [body] region (or the refusal)."""
    import hashlib

    from chargedesign.candidates import candidates_from_table
    from chargedesign.errors import InputError

    if scene.region is None:
        return ""
    try:
        found = candidates_from_table(scene.region.table, base_dir=scene.base_dir)
    except InputError as exc:
        return f"; candidates refused: {exc}"
    digest = hashlib.sha256(found.points.tobytes()).hexdigest()[:16]
    return f"; {len(found.points)} candidates {digest}"


def verdicts() -> dict[str, str]:
    from chargedesign.errors import InputError
    from chargedesign.scene import load_scene

    out: dict[str, str] = {}
    with tempfile.TemporaryDirectory() as tmp:
        scene_file = Path(tmp) / "scene.toml"
        for base_name, base in _bases().items():
            for path in _keys():
                for value in (*PROBES, *_enums(path)):
                    name = f"{base_name} {'.'.join(path)} = {_toml_value(value)}"
                    scene_file.write_text(_toml(_set(base, path, value)), "utf-8")
                    try:
                        scene = load_scene(scene_file)
                        out[name] = "accepted" + _candidates(scene)
                    except InputError as exc:
                        out[name] = str(exc).replace(tmp, "{tmp}")
                    except Exception as exc:  # recorded as a crash, not hidden
                        out[name] = f"CRASH {type(exc).__name__}: {exc}".replace(tmp, "{tmp}")
    return out


def main(argv: list[str] | None = None) -> int:
    args = sys.argv[1:] if argv is None else argv
    if len(args) != 1:
        print(__doc__.splitlines()[0] + "\nusage: scene_verdicts.py OUT.json", file=sys.stderr)
        return 2
    result = verdicts()
    Path(args[0]).write_text(json.dumps(result, indent=1, sort_keys=True) + "\n", "utf-8")
    refused = sum(not v.startswith("accepted") for v in result.values())
    print(
        f"{len(result)} probes: {len(result) - refused} accepted, {refused} refused",
        file=sys.stderr,
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
