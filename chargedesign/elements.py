"""The one element type: charges on carriers, magnets and ballast masses, in body axes.

:class:`ElementSet` is shared by the design (:class:`~chargedesign.body.Design` is an element
set plus its targets), the forward check, the simulation's
:class:`~chargedesign.simulation.system.Body`, the pictures and the exports. Arrays are
validated once here; errors name the design.json key (``charges.values``, ...).

Physical elements (design.json keys added by the contract; absent keys mean massless points):

- a charge ``q`` sits on a carrier sphere of radius ``charge_radii`` (m) with mass
  ``charge_masses`` (kg);
- a dipole ``sigma`` is a magnet of volume ``dipole_volumes`` (m^3) and mass ``dipole_masses``
  (kg);
- ``mass_positions`` / ``mass_values`` are the ballast; with several ballast materials
  ``mass_materials`` names each part's material (design.json ``masses.material``).

The body's mass distribution is all three mass sets together (:meth:`ElementSet.all_masses`).
"""

from __future__ import annotations

from dataclasses import dataclass, field, fields
from typing import Any

import numpy as np

from chargedesign.results import compact_repr
from chargedesign.validation import as_points, as_weights, check_instance, check_keys, input_error

#: the design.json block of each source and its keys, in the order they are written
BLOCKS = {
    "charges": ("positions", "values", "radii", "masses"),
    "dipoles": ("positions", "moments", "volumes", "masses"),
    "masses": ("positions", "values", "material"),
}


def _points() -> np.ndarray:
    return np.zeros((0, 3))


def _weights() -> np.ndarray:
    return np.zeros(0)


@dataclass(kw_only=True, repr=False)
class ElementSet:
    """Charges, dipoles and ballast masses in body axes (SI units).

    Attributes
    ----------
    charge_positions : ndarray, shape (n, 3)
        Carrier centres, m.
    charge_values : ndarray, shape (n,)
        Charges, C.
    charge_radii : ndarray, shape (n,), optional
        Carrier sphere radii, m (0 or None: point charges).
    charge_masses : ndarray, shape (n,), optional
        Carrier masses, kg (>= 0; None: massless).
    dipole_positions : ndarray, shape (k, 3)
        Magnet centres, m.
    dipole_moments : ndarray, shape (k, 3)
        Magnetic moments in body axes, A m^2.
    dipole_volumes : ndarray, shape (k,), optional
        Magnet volumes, m^3 (0 or None: point dipoles).
    dipole_masses : ndarray, shape (k,), optional
        Magnet masses, kg (>= 0; None: massless).
    mass_positions : ndarray, shape (m, 3)
        Ballast positions, m.
    mass_values : ndarray, shape (m,)
        Ballast masses, kg (>= 0).
    mass_materials : list of str, optional
        The material name of each ballast part (None: the one ballast material).
    """

    charge_positions: np.ndarray = field(default_factory=_points)
    charge_values: np.ndarray = field(default_factory=_weights)
    charge_radii: np.ndarray | None = None
    charge_masses: np.ndarray | None = None
    dipole_positions: np.ndarray = field(default_factory=_points)
    dipole_moments: np.ndarray = field(default_factory=_points)
    dipole_volumes: np.ndarray | None = None
    dipole_masses: np.ndarray | None = None
    mass_positions: np.ndarray = field(default_factory=_points)
    mass_values: np.ndarray = field(default_factory=_weights)
    mass_materials: list[str] | None = None

    def __post_init__(self) -> None:
        self.charge_positions = as_points(self.charge_positions, "charges.positions")
        n = len(self.charge_positions)
        self.charge_values = as_weights(self.charge_values, "charges.values", n)
        self.charge_radii = _nonneg(self.charge_radii, "charges.radii", n)
        self.charge_masses = _nonneg(self.charge_masses, "charges.masses", n)
        self.dipole_positions = as_points(self.dipole_positions, "dipoles.positions")
        k = len(self.dipole_positions)
        self.dipole_moments = as_points(self.dipole_moments, "dipoles.moments", k)
        self.dipole_volumes = _nonneg(self.dipole_volumes, "dipoles.volumes", k)
        self.dipole_masses = _nonneg(self.dipole_masses, "dipoles.masses", k)
        self.mass_positions = as_points(self.mass_positions, "masses.positions")
        # a ballast mass needs its value: unlike sizes, values are not optional per element
        values = self.mass_values
        if values is None and not len(self.mass_positions):
            values = np.zeros(0)
        self.mass_values = as_nonnegative_weights(values, "masses.values", len(self.mass_positions))
        if self.mass_materials is not None:
            self.mass_materials = check_names(
                self.mass_materials, len(self.mass_values), "masses.material"
            )

    # ------------------------------------------------------------------ sizes and masses
    def carrier_radii(self) -> np.ndarray:
        """Carrier radii, m, shape (n,) (zeros for point charges)."""
        return _or_zeros(self.charge_radii, len(self.charge_values))

    def carrier_masses(self) -> np.ndarray:
        """Carrier masses, kg, shape (n,)."""
        return _or_zeros(self.charge_masses, len(self.charge_values))

    def magnet_volumes(self) -> np.ndarray:
        """Magnet volumes, m^3, shape (k,)."""
        return _or_zeros(self.dipole_volumes, len(self.dipole_moments))

    def magnet_masses(self) -> np.ndarray:
        """Magnet masses, kg, shape (k,)."""
        return _or_zeros(self.dipole_masses, len(self.dipole_moments))

    @property
    def n_elements(self) -> int:
        return len(self.charge_values) + len(self.dipole_moments) + len(self.mass_values)

    @property
    def is_physical(self) -> bool:
        """True when any element has a size or a mass of its own (not a bare point)."""
        arrays = (self.charge_radii, self.charge_masses, self.dipole_volumes, self.dipole_masses)
        return any(a is not None and bool(np.any(a)) for a in arrays)

    def source_count(self, source: str) -> int:
        """Number of non-zero elements of ``charges``, ``masses`` or ``dipoles``."""
        values = {
            "charges": self.charge_values,
            "masses": self.mass_values,
            "dipoles": self.dipole_moments,
        }[source]
        if len(values) == 0:
            return 0
        return int(np.count_nonzero(values.reshape(len(values), -1).any(axis=1)))

    def all_masses(self) -> tuple[np.ndarray, np.ndarray]:
        """Every mass of the body: carriers, magnets and ballast.

        Returns
        -------
        positions : ndarray, shape (n + k + m, 3)
            m, body axes.
        masses : ndarray, shape (n + k + m,)
            kg.
        """
        positions = np.concatenate(
            [self.charge_positions, self.dipole_positions, self.mass_positions]
        )
        masses = np.concatenate([self.carrier_masses(), self.magnet_masses(), self.mass_values])
        return positions, masses

    @property
    def total_mass(self) -> float:
        """Mass of the whole body (carriers, magnets and ballast), kg."""
        return float(np.sum(self.all_masses()[1]))

    def point_elements(self) -> ElementSet:
        """The same body with every mass gathered into the ballast arrays.

        What the physics of mass sees (inertia, gravity): carriers' and magnets' masses sit at
        their centres (massless ones are left out). Charges and dipoles keep their values;
        sizes and own masses are dropped.
        """
        carrier_masses, magnet_masses = self.carrier_masses(), self.magnet_masses()
        carried = carrier_masses > 0
        magnets = magnet_masses > 0
        return ElementSet(
            charge_positions=self.charge_positions,
            charge_values=self.charge_values,
            dipole_positions=self.dipole_positions,
            dipole_moments=self.dipole_moments,
            mass_positions=np.concatenate(
                [
                    self.mass_positions,
                    self.charge_positions[carried],
                    self.dipole_positions[magnets],
                ]
            ),
            mass_values=np.concatenate(
                [self.mass_values, carrier_masses[carried], magnet_masses[magnets]]
            ),
        )

    def __repr__(self) -> str:
        """Counts and total mass, not the arrays (a body can hold thousands of elements)."""
        items: dict[str, Any] = {
            "charges": len(self.charge_values),
            "dipoles": len(self.dipole_moments),
            "masses": len(self.mass_values),
            "total_mass_kg": self.total_mass,
        }
        parameters = getattr(self, "parameters", None)
        if parameters is not None:
            items["n"] = parameters.n
        return compact_repr(type(self).__name__, items)

    def element_arrays(self) -> dict[str, Any]:
        """The element fields of this set by name (to build another element type from it)."""
        return {f.name: getattr(self, f.name) for f in fields(ElementSet)}

    # ------------------------------------------------------------------ design.json blocks
    def blocks(self) -> dict[str, dict[str, list[Any]]]:
        """The ``charges``, ``dipoles`` and ``masses`` blocks of design.json.

        Sizes and element masses are written only when the set is physical, so files of point
        designs stay as they were.
        """
        physical = self.is_physical
        charges: dict[str, list[Any]] = {
            "positions": self.charge_positions.tolist(),
            "values": self.charge_values.tolist(),
        }
        dipoles: dict[str, list[Any]] = {
            "positions": self.dipole_positions.tolist(),
            "moments": self.dipole_moments.tolist(),
        }
        if physical:
            charges["radii"] = self.carrier_radii().tolist()
            charges["masses"] = self.carrier_masses().tolist()
            dipoles["volumes"] = self.magnet_volumes().tolist()
            dipoles["masses"] = self.magnet_masses().tolist()
        masses: dict[str, list[Any]] = {
            "positions": self.mass_positions.tolist(),
            "values": self.mass_values.tolist(),
        }
        if self.mass_materials is not None:
            masses["material"] = list(self.mass_materials)
        return {"charges": charges, "masses": masses, "dipoles": dipoles}

    @staticmethod
    def arrays_from_blocks(data: dict[str, Any], where: str = "design") -> dict[str, Any]:
        """Element arguments from design.json blocks (unknown keys in a block are refused)."""
        names = {
            "charges": ("charge_positions", "charge_values", "charge_radii", "charge_masses"),
            "dipoles": ("dipole_positions", "dipole_moments", "dipole_volumes", "dipole_masses"),
            "masses": ("mass_positions", "mass_values", "mass_materials"),
        }
        out: dict[str, Any] = {}
        for block, keys in BLOCKS.items():
            b = data.get(block) or {}
            check_instance(b, dict, f"{where}.{block}", "an object")
            check_keys(b, keys, f"{where}.{block}")
            for key, name in zip(keys, names[block], strict=True):
                if key in b:
                    out[name] = b[key]
                elif key in ("positions", "values", "moments"):
                    out[name] = []
        return out


def _nonneg(value: Any, name: str, n: int) -> np.ndarray | None:
    """An optional per-element array of sizes or masses: None when absent, >= 0 otherwise."""
    if value is None:
        return None
    return as_nonnegative_weights(value, name, n)


def _or_zeros(value: np.ndarray | None, n: int) -> np.ndarray:
    return np.zeros(n) if value is None else value


def check_names(value: Any, n: int, name: str) -> list[str]:
    """A list (or tuple) of ``n`` strings, as a list; else one line naming ``name``."""
    if (
        not isinstance(value, (list, tuple))
        or len(value) != n
        or not all(isinstance(x, str) for x in value)
    ):
        raise input_error(name, f"{n} material names", value)
    return list(value)


def as_nonnegative_weights(value: Any, name: str, n: int | None = None) -> np.ndarray:
    """:func:`as_weights`, every one >= 0 (sizes, masses)."""
    arr = as_weights(value, name, n)
    if np.any(arr < 0):
        raise input_error(name, "nonnegative numbers", float(arr.min()))
    return arr
