"""The simulated body: an element set in body axes plus the fields and parameters it feels.

What the effects act on (:mod:`chargedesign.simulation.system`) and what the direct route's
kernel (:mod:`chargedesign.simulation.direct`) reads; both import it from here, below them.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from chargedesign.body import FIELD_KINDS
from chargedesign.elements import ElementSet
from chargedesign.fields import AxisymmetricField
from chargedesign.formatting import fmt
from chargedesign.params import Parameters
from chargedesign.physical.holder import whole_inertia
from chargedesign.physical.parasitics import eddy_weights
from chargedesign.physical.realism import material_parts
from chargedesign.quadrature import gather_elements

__all__ = ["Body"]


@dataclass(repr=False)
class Body(ElementSet):
    """What the effects act on: an element set in body axes plus fields and parameters.

    The masses of carriers and magnets are gathered into the ballast arrays
    (:meth:`~chargedesign.elements.ElementSet.point_elements`) when a body is built from a
    design, so gravity and the inertia see the whole mass.

    Attributes
    ----------
    parameters : Parameters
        The theorem's parameters; ``C`` fixes the inertia ``diag(2C, 2C, C)`` (kg m^2).
    fields : dict[str, tuple[float, ...]]
        Legendre coefficients per field kind.
    charge_positions, charge_values, dipole_positions, dipole_moments, mass_positions,
    mass_values
        The elements (keyword arguments; see :class:`~chargedesign.elements.ElementSet`).
    notes : list of str
        What was done to build the body (continuous parts turned into quadrature nodes, ...).
    """

    parameters: Parameters
    fields: dict[str, tuple[float, ...]] = field(default_factory=dict)
    has_elements: bool | None = None
    notes: list[str] = field(default_factory=list)
    #: centres of the parts whose material the magnetic field magnetises (m, body axes), and
    #: their ``chi v`` (m^3): the ``induced`` effect (from a physical design's materials)
    part_positions: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    part_susceptances: np.ndarray = field(default_factory=lambda: np.zeros(0))
    #: centres of the conducting parts (m, body axes) and their ``sigma (a^5 - b^5)``
    #: (S m^4): the ``eddy`` effect (:func:`~chargedesign.physical.parasitics.eddy_torque`)
    conductor_positions: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    conductor_weights: np.ndarray = field(default_factory=lambda: np.zeros(0))
    #: the inertia beyond the point masses (kg m^2, (3, 3)): every part's own and the
    #: holder's (chargedesign.physical.holder.whole_inertia, recomputed from the parts)
    parts_inertia: np.ndarray = field(default_factory=lambda: np.zeros((3, 3)))

    def source_count(self, source: str) -> int:
        """Number of non-zero elements of a source; ``parts``: parts with a susceptibility."""
        if source == "parts":
            return int(np.count_nonzero(self.part_susceptances))
        if source == "conductors":
            return int(np.count_nonzero(self.conductor_weights))
        return super().source_count(source)

    def __post_init__(self) -> None:
        super().__post_init__()
        if not isinstance(self.parameters, Parameters):
            raise TypeError(f"parameters: expected a Parameters, got {self.parameters!r}")
        fields_out: dict[str, tuple[float, ...]] = {}
        for kind, coeffs in dict(self.fields).items():
            # a scene's and a design's fields are checked where they are read
            assert kind in FIELD_KINDS, kind
            fields_out[kind] = AxisymmetricField(tuple(coeffs)).legendre
        self.fields = fields_out
        if self.has_elements is None:
            # a body is what has elements; bare parameters are the reduced model only
            self.has_elements = self.n_elements > 0

    @classmethod
    def from_design(cls, design: Any, fields: dict[str, tuple[float, ...]] | None = None) -> Body:
        """A :class:`~chargedesign.body.Design` (fields of ``fields`` replace the design's).

        The body's parameters are the design's :attr:`~chargedesign.body.Design.body_parameters`:
        n = 0 for a ``frame`` reading (its motion is read in turning axes afterwards).

        Carriers' and magnets' masses join the ballast. Continuous charge and mass bodies of
        the design become quadrature nodes exact for the fields' degree (+1 for the Lorentz
        terms), so both force routes stay exact.
        """
        merged = dict(design.fields)
        merged.update(fields or {})
        degree = max((len(v) for v in merged.values()), default=0) + 1
        gathered = gather_elements(design, degree)
        notes = [
            f"continuous[{i}] ({b['kind']} {b['shape']}): {b['nodes']} quadrature nodes, "
            f"exact to degree {b['order']}"
            for i, b in enumerate(gathered.quadrature)
        ]
        part_positions, part_susceptances = np.zeros((0, 3)), np.zeros(0)
        conductor_positions, conductor_weights = np.zeros((0, 3)), np.zeros(0)
        parts_inertia = np.zeros((3, 3))
        if getattr(design, "medium", None) is not None:
            whole = whole_inertia(design)
            own = np.asarray(whole["total_kg_m2"]) - np.asarray(whole["points_kg_m2"])
            if getattr(design, "inertia", None) is not None:
                parts_inertia = own
            else:  # a file designed with point masses: simulated as it was designed
                notes.append(
                    "design.json has no whole-inertia record (designed with point masses): "
                    f"the parts' own inertia ({fmt(float(own[2, 2]))} kg m^2 on each axis) is "
                    "left out"
                )
            every_part = material_parts(design)
            conductor_positions, conductor_weights = eddy_weights(every_part)
            parts = [p for p in every_part if p["chi"] is not None]
            if parts:
                part_positions = np.concatenate([p["centres"] for p in parts])
                part_susceptances = np.concatenate([p["chi"] * p["volumes"] for p in parts])
        # a frame body's elements realise the theorem with n = 0 (n is a rotation of axes)
        parameters = getattr(design, "body_parameters", design.parameters)
        return cls(
            parameters=parameters,
            fields=merged,
            charge_positions=gathered.charge_positions,
            charge_values=gathered.charge_values,
            mass_positions=gathered.mass_positions,
            mass_values=gathered.mass_values,
            dipole_positions=gathered.dipole_positions,
            dipole_moments=gathered.dipole_moments,
            has_elements=True,
            notes=notes,
            part_positions=part_positions,
            part_susceptances=part_susceptances,
            conductor_positions=conductor_positions,
            conductor_weights=conductor_weights,
            parts_inertia=parts_inertia,
        )

    def field(self, kind: str) -> AxisymmetricField:
        return AxisymmetricField(tuple(self.fields.get(kind, ())))
