"""Scenes: TOML files with the contract's keys, parsed once into a typed :class:`Scene`.

Every table is parsed and checked when the scene is loaded (one-line errors naming the key):
``[parameters]``, ``[fields.*]``, ``[medium]`` with ``[carriers]``, ``[magnets]``,
``[ballast]`` (the physical spec), ``[body]`` (a region, or the body to simulate),
``[design]``, ``[simulation]``, ``[initial]``, ``[output]``, ``[tolerance]``,
``[testbed]`` and ``[case]`` (any case of (ep) instead of ``[parameters]``). The stages
take these objects; :attr:`Scene.tables` keeps the raw tables only for sweeps, which apply a
grid of dotted keys to them and parse again.
"""

from __future__ import annotations

import os
import tomllib
from dataclasses import dataclass, field
from functools import cached_property
from importlib import resources
from pathlib import Path
from typing import TYPE_CHECKING, Any

from chargedesign.errors import InputError
from chargedesign.params import Parameters
from chargedesign.readers import read_toml_file
from chargedesign.scene.design import DesignOptions
from chargedesign.scene.keys import check_value, default_of, key_names
from chargedesign.scene.medium import Medium
from chargedesign.scene.physical import PhysicalSpec, spec_from_tables
from chargedesign.scene.simulation import (
    OutputOptions,
    SimulationOptions,
    parse_initial,
    parse_output_options,
    parse_simulation_options,
)
from chargedesign.scene.support import SupportOptions
from chargedesign.scene.tables import (
    BodyReference,
    BodyRegion,
    RegionSpec,
    body_from_table,
    region_from_table,
)
from chargedesign.scene.testbed import TestbedOptions
from chargedesign.validation import (
    as_array,
    check_field_degree,
    check_keys,
    check_parameters_range,
    check_tree,
    input_error,
)
from chargedesign.vocabulary import FIELD_KINDS, SCENE_TABLES

if TYPE_CHECKING:
    from chargedesign.scene.case_file import Case

#: characters no portable file name holds (Windows forbids them; '\\' is a separator there)
_NOT_PORTABLE = '<>:"\\|?*'
#: the one list of scene tables (the vocabulary's; the schema is built from it too)
KNOWN_TABLES = SCENE_TABLES


@dataclass
class Scene:
    """A parsed, validated scene.

    Attributes
    ----------
    parameters : Parameters
    fields : dict[str, tuple[float, ...]]
        Legendre coefficients of each field the scene gives (``a1``/``a2`` are converted to
        ``[a1, 2 a2]``). A kind that is absent is for the conditions engine to derive.
    field_limits : dict[str, float]
        ``max`` of each field table: the largest |B| (T), |E| (V/m) or |g| (m/s^2) the
        apparatus makes over the body region.
    Parsed tables (each parsed once, when first read; :func:`load_scene` reads them all):

    physical : PhysicalSpec or None
        ``[medium]``, ``[carriers]``, ``[magnets]``, ``[ballast]``, ``[body] carrier_radius``
        and ``[tolerance]`` (None: no ``[medium]``, the mathematical case).
    body : BodyRegion, BodyReference or None
        ``[body]``: a region to design in, or the body to simulate.
    design : DesignOptions
        ``[design]``.
    simulation, output : SimulationOptions, OutputOptions
        ``[simulation]``, ``[output]`` (:mod:`chargedesign.simulation`).
    initial : dict or None
        ``[initial]`` as :func:`chargedesign.simulation.parse_initial` normalises it (None:
        the scene has none).
    tables : dict
        The raw TOML tables, for sweeps (a grid of dotted keys applied, then parsed again).
    source : str
        Where the scene came from (a path, or ``<default>``).
    """

    parameters: Parameters
    fields: dict[str, tuple[float, ...]] = field(default_factory=dict)
    tables: dict[str, Any] = field(default_factory=dict)
    source: str = "<default>"
    field_limits: dict[str, float] = field(default_factory=dict)

    # Each table is parsed once, when first read: load_scene reads them all at load (every
    # error before any work); a scene built from a mapping raises a table's error where the
    # table is first used, as stages always did.
    @cached_property
    def design(self) -> DesignOptions:
        return DesignOptions.from_table(self.tables.get("design", {}))

    @cached_property
    def physical(self) -> PhysicalSpec | None:
        return spec_from_tables(self.tables, self.field_limits)

    @cached_property
    def body(self) -> BodyRegion | BodyReference | None:
        return body_from_table(self.tables.get("body"))

    @cached_property
    def simulation(self) -> SimulationOptions:
        return parse_simulation_options(self.tables.get("simulation", {}))

    @cached_property
    def output(self) -> OutputOptions:
        return parse_output_options(self.tables.get("output", {}))

    @cached_property
    def initial(self) -> dict[str, Any] | None:
        if "initial" not in self.tables:
            return None
        return parse_initial(self.tables["initial"], "initial", self.base_dir)

    @cached_property
    def case(self) -> Case | None:
        """``[case]``: any case of (ep) with its claimed integral (None: the theorem's
        ``[parameters]``), validated by :func:`chargedesign.scene.case_file.case_from_table`."""
        if "case" not in self.tables:
            return None
        # sympy loads only for a scene that carries a case
        from chargedesign.scene.case_file import case_from_table

        return case_from_table(self.tables["case"], "case")

    @cached_property
    def testbed(self) -> TestbedOptions:
        """``[testbed]``: the air-bearing platform (defaults where the scene has none)."""
        return TestbedOptions.from_table(self.tables.get("testbed"))

    @cached_property
    def support(self) -> SupportOptions:
        """``[support]``: how the body is held (docs/flight.md; the air bearing when absent)."""
        return SupportOptions.from_table(self.tables.get("support"))

    @property
    def medium(self) -> Medium | None:
        """``[medium]`` (None: the mathematical case, point elements)."""
        return self.physical.medium if self.physical is not None else None

    @property
    def carriers(self) -> Any:
        """The carriers' material (``[carriers]``), None without ``[medium]``."""
        return self.physical.carrier if self.physical is not None else None

    @property
    def magnets(self) -> Any:
        """The magnets' material (``[magnets]``), None without ``[medium]``."""
        return self.physical.magnet if self.physical is not None else None

    @property
    def ballast(self) -> Any:
        """The ballast materials (``[ballast]``), empty without ``[medium]``."""
        if self.physical is None:
            return ()
        return self.physical.ballasts or (self.physical.ballast,)

    @property
    def tolerance(self) -> dict[str, float]:
        """``[tolerance]``: the materials' relative errors (empty: none given)."""
        return dict(self.physical.material_errors) if self.physical is not None else {}

    @property
    def region(self) -> BodyRegion | None:
        """The ``[body]`` region to design in (None: the body is a reference, or absent)."""
        return self.body if isinstance(self.body, BodyRegion) else None

    def region_spec(self) -> RegionSpec:
        """The checked values of the ``[body]`` region the design places elements in (read
        once, :meth:`BodyRegion.spec`). A scene without such a region is refused in one line:
        a ``[case]`` scene's names the scene; any other's is the line
        :func:`~chargedesign.scene.tables.region_from_table` gives an absent ``[body]`` or one
        that names a body to simulate."""
        if self.region is not None:
            return self.region.spec()
        if "case" in self.tables:
            raise InputError(
                f"{self.source}: a [case] scene needs a [body] region (shape, size) to place "
                "the elements in"
            )
        return region_from_table(self.body.table if self.body is not None else {})

    @property
    def base_dir(self) -> Path | None:
        """The folder relative paths of the scene are read from (None: not from a file)."""
        return None if self.source.startswith("<") else Path(self.source).parent

    def table(self, name: str) -> dict[str, Any]:
        """One raw table (empty dict when the scene has none)."""
        value = self.tables.get(name, {})
        return value if isinstance(value, dict) else {}


def parse_field(spec: Any, where: str) -> tuple[float, ...]:
    """A field table: either the paper's ``a1``/``a2`` (magnetic) or ``legendre = [...]``."""
    if not isinstance(spec, dict):
        raise input_error(where, "a table", spec)
    check_keys(spec, key_names("fields"), where)
    if "legendre" in spec:
        if "a1" in spec or "a2" in spec:
            raise InputError(f"{where}: give either legendre or a1/a2, not both")
        value = spec["legendre"]
        if isinstance(value, list) and not value:
            return ()
        check_field_degree(value, f"{where}.legendre")
        return tuple(float(x) for x in as_array(value, f"{where}.legendre", (None,)))
    a1 = check_value("fields", "a1", spec.get("a1", default_of("fields", "a1")), f"{where}.a1")
    a2 = check_value("fields", "a2", spec.get("a2", default_of("fields", "a2")), f"{where}.a2")
    return (a1, 2.0 * a2)


def scene_from_dict(data: dict[str, Any], source: str = "<dict>") -> Scene:
    """Validate a scene mapping (as read from TOML)."""
    if not isinstance(data, dict):
        raise input_error(source, "a table of scene keys", data)
    unknown = sorted(set(data) - set(KNOWN_TABLES))
    if unknown:
        raise input_error(
            f"{source}: key {unknown[0]}", "one of " + ", ".join(KNOWN_TABLES), unknown[0]
        )
    # the theorem's numbers: real, finite, inside the supported range (a file's other tables
    # are checked as a whole by load_scene; every table by its owner in validate_tables, which
    # load_scene and every sweep point call; a mapping's tables by the stages that own them)
    if "case" in data and "parameters" in data:
        raise InputError(
            f"{source}: [parameters] and [case] together (a scene carries the theorem's "
            "[parameters] or a [case] of (ep) instead, not both)"
        )
    _precheck(data)
    check_tree({k: data[k] for k in ("parameters", "fields") if k in data}, "")
    check_output_dir(data.get("output"))
    params = Parameters.from_mapping(data.get("parameters", {}), "parameters")
    fields_in = data.get("fields", {})
    if not isinstance(fields_in, dict):
        raise input_error("fields", "a table", fields_in)
    fields_out: dict[str, tuple[float, ...]] = {}
    limits: dict[str, float] = {}
    for kind, spec in fields_in.items():
        if kind not in FIELD_KINDS:
            raise input_error(f"fields.{kind}", "one of " + ", ".join(FIELD_KINDS), kind)
        if isinstance(spec, dict) and "max" in spec:
            limits[kind] = check_value("fields", "max", spec["max"], f"fields.{kind}.max")
            spec = {k: v for k, v in spec.items() if k != "max"}
            if not spec:
                continue  # a limit only: the field itself is for the engine to derive
        fields_out[kind] = parse_field(spec, f"fields.{kind}")
    tables = {k: v for k, v in data.items() if k not in ("parameters", "fields")}
    for name, value in tables.items():
        if not isinstance(value, dict):
            raise input_error(name, "a table", value)
    return Scene(
        parameters=params, fields=fields_out, tables=tables, source=source, field_limits=limits
    )


def _precheck(data: dict[str, Any]) -> None:
    """What must be refused before the rest of a scene is looked at: a field longer than the
    engine's degree (a 300 000-term list is not walked) and the theorem's parameters against
    their own ranges (a 40-digit n is named against 1e-8..1e8, not the generic range)."""
    fields_in = data.get("fields")
    if isinstance(fields_in, dict):
        for kind, spec in fields_in.items():
            if isinstance(spec, dict) and "legendre" in spec:
                check_field_degree(spec["legendre"], f"fields.{kind}.legendre")
    check_parameters_range(data.get("parameters"), "parameters")


def validate_tables(scene: Scene) -> None:
    """Every table of a scene parsed (once) by its type, in a fixed order: a key or value no
    stage would accept is refused by every command that reads the scene (one line naming the
    key), not only by the command that uses the table."""
    for name in (
        "design",
        "physical",
        "body",
        "simulation",
        "output",
        "initial",
        "testbed",
        "case",
        "support",
    ):
        getattr(scene, name)


def check_output_dir(table: Any, where: str = "output.dir") -> None:
    """A scene may write only below the working directory: ``[output] dir`` is a relative
    path without ``..`` (``--out DIR`` on the command line may name any folder)."""
    if not isinstance(table, dict) or "dir" not in table:
        return
    raw = table["dir"]
    if not isinstance(raw, str) or not raw:
        raise input_error(where, "a directory path", raw)
    bad = next((ch for ch in raw if ord(ch) < 32 or ord(ch) == 127 or ch in _NOT_PORTABLE), None)
    if bad is not None:
        raise InputError(
            f"{where}: {bad!r} is not a portable file-name character (no control characters "
            f"or any of {_NOT_PORTABLE}), got {raw!r}"
        )
    if any(part != part.rstrip(" .") for part in raw.split("/") if part not in (".", "")):
        raise InputError(f"{where}: a folder name may not end in a space or dot, got {raw!r}")
    path = Path(raw)
    if path.is_absolute() or raw.startswith("~") or ".." in path.parts or "\x00" in raw:
        raise InputError(
            f"{where}: a scene may write only inside the working directory (a relative path "
            f"without '..'), got {raw!r}; give --out DIR on the command line to write elsewhere"
        )


def default_scene_text() -> str:
    return resources.files("chargedesign").joinpath("data/default_scene.toml").read_text("utf-8")


def load_scene(path: str | os.PathLike[str] | None = None) -> Scene:
    """Load a scene file, or the embedded default scene when ``path`` is None."""
    if path is None:
        return validated(scene_from_dict(tomllib.loads(default_scene_text()), "<default>"))
    p = Path(path)
    data = read_toml_file(p, "scene file")
    # every number of the file: real, finite, inside the supported range, named by its key
    _precheck(data)
    check_tree(data, "")
    return validated(scene_from_dict(data, str(p)))


def validated(scene: Scene) -> Scene:
    """``scene`` after :func:`validate_tables` (the whole file, whatever the command)."""
    validate_tables(scene)
    return scene
