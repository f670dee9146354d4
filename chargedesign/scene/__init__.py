"""The one input boundary: a scene file (TOML) becomes a typed :class:`Scene`.

- :mod:`.keys`: every table's keys, declared once (validators and the JSON Schema read them);
- :mod:`.medium`: the :class:`Medium` (scene ``[medium]`` and design.json's ``medium``);
- :mod:`.design`: ``[design]`` (:class:`DesignOptions`);
- :mod:`.tables`: ``[body]`` (a region or a reference) and ``[tolerance]``;
- :mod:`.physical`: ``[medium]``, ``[carriers]``, ``[magnets]``, ``[ballast]``
  (:class:`PhysicalSpec`);
- :mod:`.load`: :func:`load_scene`, :func:`scene_from_dict` and the :class:`Scene`.
"""

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
