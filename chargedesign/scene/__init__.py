"""The one input boundary: a scene file (TOML) becomes a typed :class:`Scene`.

- :mod:`.keys`: every key declared once (type and range, unit, default and its source, doc):
  validation (:func:`~.keys.check_value`), the JSON Schema, the docs' tables, the typed
  options' defaults and the command-line options that set a key follow from it;
- :mod:`.medium`: the :class:`Medium` (scene ``[medium]`` and design.json's ``medium``);
- :mod:`.design`: ``[design]`` (:class:`DesignOptions`);
- :mod:`.tables`: ``[body]`` (a region, read into a :class:`~.tables.RegionSpec`, or a
  reference) and ``[tolerance]``;
- :mod:`.physical`: ``[medium]``, ``[carriers]``, ``[magnets]``, ``[ballast]``
  (:class:`PhysicalSpec`);
- :mod:`.simulation`: ``[simulation]``, ``[output]``, ``[initial]``;
- :mod:`.design_materials`: design.json's ``materials``;
- :mod:`.sweep_file`: a sweep file's own structure (its points are checked by
  :mod:`chargedesign.sweeps.spec`);
- :mod:`.load`: :func:`load_scene`, :func:`scene_from_dict` and the :class:`Scene`.

The names below are loaded on first use (PEP 562, as the package's top level): importing
:mod:`.keys` alone (the command line's parser, so ``--help`` and the commands that read no
scene) then runs none of :mod:`.load`'s imports (the readers, the tables' parsers).
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

#: public name -> the module that defines it
_LAZY = {
    **dict.fromkeys(
        (
            "KNOWN_TABLES",
            "Scene",
            "check_output_dir",
            "default_scene_text",
            "load_scene",
            "parse_field",
            "scene_from_dict",
            "validate_tables",
            "validated",
        ),
        "chargedesign.scene.load",
    ),
    "Medium": "chargedesign.scene.medium",
    "BodyReference": "chargedesign.scene.tables",
    "BodyRegion": "chargedesign.scene.tables",
}

__all__ = [
    "KNOWN_TABLES",
    "BodyReference",
    "BodyRegion",
    "Medium",
    "Scene",
    "check_output_dir",
    "default_scene_text",
    "load_scene",
    "parse_field",
    "scene_from_dict",
    "validate_tables",
    "validated",
]


def __getattr__(name: str) -> Any:
    try:
        module_name = _LAZY[name]
    except KeyError:
        raise AttributeError(f"module 'chargedesign.scene' has no attribute {name!r}") from None
    value = getattr(importlib.import_module(module_name), name)
    globals()[name] = value  # later look-ups skip __getattr__
    return value


if TYPE_CHECKING:  # pragma: no cover - for type checkers and IDEs
    from chargedesign.scene.load import (
        KNOWN_TABLES,
        Scene,
        check_output_dir,
        default_scene_text,
        load_scene,
        parse_field,
        scene_from_dict,
        validate_tables,
        validated,
    )
    from chargedesign.scene.medium import Medium
    from chargedesign.scene.tables import BodyReference, BodyRegion
