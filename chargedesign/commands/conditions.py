"""`chargedesign conditions [SCENE]`: the linear conditions on moments a body must meet."""

from __future__ import annotations

import argparse
from typing import Any

PREFIX = {"charges": "I", "dipoles": "S", "masses": "M"}
PROVENANCE_WIDTH = 120


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "scene", nargs="?", default=None, help="scene file (TOML); default: the embedded scene"
    )
    parser.add_argument("--json", action="store_true", help="print JSON")
    parser.add_argument(
        "--exact",
        action="store_true",
        help="read the inputs as the decimals they print as and report exact rational values",
    )


def _moment_name(source: str, key: str) -> str:
    """``I_xxz`` (charges), ``M_xx`` (masses), ``S_z:x`` = sum sigma_z x (dipoles)."""
    key = key.rstrip(":")
    return f"{PREFIX[source]}_{key}" if key else PREFIX[source]


def _number(value: float) -> str:
    return f"{value:.12g}"


def _lhs(source: str, coefficients: dict[str, float]) -> str:
    terms = []
    for key, coef in coefficients.items():
        name = _moment_name(source, key)
        if coef == 1.0:
            terms.append(f"+ {name}")
        elif coef == -1.0:
            terms.append(f"- {name}")
        else:
            sign = "-" if coef < 0 else "+"
            terms.append(f"{sign} {_number(abs(coef))} {name}")
    text = " ".join(terms)
    return text[2:] if text.startswith("+ ") else "-" + text[2:]


def _short(provenance: str) -> str:
    parts = provenance.split("; ")
    text = parts[0] + (f" (+{len(parts) - 1} more)" if len(parts) > 1 else "")
    return text if len(text) <= PROVENANCE_WIDTH else text[: PROVENANCE_WIDTH - 3] + "..."


def _human(result: Any, scene_source: str) -> str:
    from chargedesign.conditions import SOURCES

    lines = [f"conditions for {scene_source} (realise {', '.join(result.realise) or 'nothing'})"]
    lines.append("fields (legendre coefficients of Phi = sum_k f_k R^k P_k(Z/R)):")
    for kind, origin in result.field_origin.items():
        coeffs = ", ".join(_number(v) for v in result.fields.get(kind, ()))
        lines.append(f"  {kind:<9} [{coeffs}]  ({origin})")
    for source in SOURCES:
        rows = result.for_source(source)
        if not rows and source not in _present(result):
            continue
        lines.append("")
        lines.append(f"{source}: {len(rows)} condition{'s' if len(rows) != 1 else ''}")
        for row in rows:
            value = row.exact_value or _number(row.value)
            key = row.single_key
            if key is not None and row.coefficients[key] == 1.0:
                equation = f"{_moment_name(source, key)} = {value}"
            else:
                equation = f"{_lhs(source, row.coefficients)} = {value}"
            lines.append(f"  {equation}")
            lines.append(f"      <- {_short(row.provenance)}")
    if result.notes:
        lines.append("")
        lines.append("notes:")
        lines += [f"  - {note}" for note in result.notes]
    return "\n".join(lines)


def _present(result: Any) -> set[str]:
    present = set()
    if "mu" in result.realise or "V" in result.realise:
        present.add("charges")
    if "V" in result.realise:
        present.add("dipoles")
    if "inertia" in result.realise:
        present.add("masses")
    return present


def _validate_other_tables(scene: Any) -> None:
    """Every command knows every key: unknown [body] keys and the [design] table get the
    design command's one-line errors (bad [body] values stay a note: the conditions only
    take the body's length from it)."""
    from chargedesign.candidates import check_body_keys
    from chargedesign.design import DesignOptions

    DesignOptions.from_table(scene.table("design"))
    body = scene.table("body")
    if "shape" in body:  # a region (without a shape, [body] may be simulate's inline body)
        check_body_keys(body)


def run(args: argparse.Namespace) -> int:
    import json

    from chargedesign.conditions import conditions_for_scene
    from chargedesign.scene import load_scene

    scene = load_scene(args.scene)
    _validate_other_tables(scene)
    result = conditions_for_scene(scene, exact=args.exact)
    if args.json:
        out = result.to_dict()
        out["scene"] = scene.source
        out["parameters"] = scene.parameters.as_dict()
        print(json.dumps(out, indent=2))
    else:
        print(_human(result, scene.source))
    return 0
