"""The records of a :class:`~chargedesign.body.Design` the report renders, read once into
typed records (:class:`ReportRecords`), so :mod:`chargedesign.report` reads attributes, not
keys.

Each record reads one block design.json writes: the design stage's provenance (candidates,
forward accuracy, objective, solver and residuals), the frontier, the tolerancing, the
buildability, the materials, a ``[case]`` record, and a physical body's realism budget (its
items, the size-free K law, the part sizes, the realisability map, the support at the
design's rate). A key an older design.json does not write reads as the default the report
prints for it (``?``, empty, None). The realised window is the frontier's own
:class:`~chargedesign.physical.window.RealisedWindow` and the support the window's
:class:`~chargedesign.physical.window.BearingSupport`, each read by its ``from_dict``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from chargedesign.body import Design
from chargedesign.physical.window import BearingSupport, RealisedWindow
from chargedesign.scene.design_realism import (
    FIELD_RESPONSE_KEYS,
    INDUCED_KEY,
    RealismRecord,
)
from chargedesign.verdict import recorded_window


@dataclass(frozen=True)
class Candidates:
    """The candidate places the design chose from (design.json ``candidates``)."""

    #: how many (``?`` when not written)
    count: Any
    #: their spacing, m (the written spacing, else the geometry's; None: neither is written)
    spacing: float | None
    #: every figure but the count and the geometry, as written (the report lists them)
    figures: dict[str, Any]

    @classmethod
    def read(cls, design: Design) -> Candidates | None:
        """The candidates of ``design`` (None: not written)."""
        data = design.candidates
        return cls.from_dict(data) if isinstance(data, dict) else None

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> Candidates:
        written = (data.get("spacing"), (data.get("geometry") or {}).get("spacing_m"))
        spacing = next((float(v) for v in written if isinstance(v, (int, float)) and v > 0), None)
        figures = {k: v for k, v in data.items() if k not in ("geometry", "n")}
        return cls(count=data.get("n", "?"), spacing=spacing, figures=figures)


@dataclass(frozen=True)
class Cancellation:
    """A source's estimated forward accuracy where its contributions cancel most
    (design.json ``forward_accuracy.worst``)."""

    forward_error: float
    quantity: str
    term: str
    amplification: float

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> Cancellation:
        return cls(**{name: data[name] for name in cls.__dataclass_fields__})


@dataclass(frozen=True)
class Objective:
    """What a source minimised (design.json ``objective``)."""

    kind: Any = "?"
    value: Any = "?"
    units: Any = ""

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> Objective:
        return cls(data.get("kind", "?"), data.get("value", "?"), data.get("units", ""))


@dataclass(frozen=True)
class Solver:
    """The solver a source's problem ran on, and its method (design.json ``solver``)."""

    name: Any = "?"
    method: Any = ""

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> Solver:
        return cls(data.get("solver", "?"), data.get("method", ""))


@dataclass(frozen=True)
class Problems:
    """The design's problems: objective and solver per source, the relative residuals before
    and after polish, their definition and tolerance (design.json ``objective``, ``solver``,
    ``residuals``)."""

    objective: dict[str, Objective]
    solver: dict[str, Solver]
    before_polish: dict[str, Any]
    after_polish: dict[str, Any]
    #: None: not written
    definition: str | None
    tolerance: Any

    @property
    def largest_residual(self) -> float | None:
        """The largest relative residual after polish (None: none written)."""
        numbers = (v for v in self.after_polish.values() if isinstance(v, (int, float)))
        return max(numbers, default=None)

    @classmethod
    def read(cls, design: Design) -> Problems | None:
        """The problems of ``design`` (None: neither an objective nor residuals written)."""
        objective, residuals = design.objective or {}, design.residuals or {}
        if not (objective or residuals):
            return None
        return cls(
            objective={k: Objective.from_dict(v or {}) for k, v in objective.items()},
            solver={k: Solver.from_dict(v or {}) for k, v in (design.solver or {}).items()},
            before_polish=dict(residuals.get("before_polish") or {}),
            after_polish=dict(residuals.get("after_polish") or {}),
            definition=residuals.get("definition"),
            tolerance=residuals.get("tolerance", "?"),
        )


@dataclass(frozen=True)
class CaseChecks:
    """The elements recomputed against a ``[case]`` (its record's ``checks``)."""

    inertia_rel_err: float
    torque_rel_err: float
    level_offset: float

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> CaseChecks:
        return cls(data["inertia_rel_err"], data["torque_rel_err"], data["level_offset"])


@dataclass(frozen=True)
class CaseRealism:
    """A ``[case]``'s realism budget (its record's ``realism``): the typical rate, the
    smallest term it holds (None: the case realises no force) and each item's figure."""

    term_key: str | None
    rate_rad_s: float | None
    term_N_m: float | None
    #: (value, verdict) of every item with a value, by key, in the budget's order
    items: dict[str, tuple[float, str]]

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> CaseRealism:
        return cls(
            term_key=data["term_key"],
            rate_rad_s=data.get("rate_rad_s"),
            term_N_m=data.get("term_N_m"),
            items={
                key: (item["value"], item["verdict"])
                for key, item in (data.get("items") or {}).items()
                if item["value"] is not None
            },
        )


@dataclass(frozen=True)
class CaseRecord:
    """A ``[case]`` scene's record (design.json ``case``): the case, its certificate, the
    checks of the elements against it, its realism budget and realised window."""

    name: Any
    #: ``general``, or the value of I3 the integral holds on
    level: Any
    inertia: tuple[float, ...]
    holds: bool
    independent: bool
    checks: CaseChecks | None
    realism: CaseRealism | None
    window: RealisedWindow | None

    @classmethod
    def read(cls, design: Design) -> CaseRecord | None:
        """The case record of ``design`` (None: not a ``[case]`` scene)."""
        data = design.further_keys.get("case")
        if not isinstance(data, dict):
            return None
        certificate = data.get("certificate") or {}
        checks, realism, realised = data.get("checks"), data.get("realism"), data.get("realised")
        return cls(
            name=data.get("name"),
            level=data.get("level"),
            inertia=tuple(data.get("inertia", [])),
            holds=bool(certificate.get("holds")),
            independent=bool(certificate.get("independent")),
            checks=CaseChecks.from_dict(checks) if checks else None,
            realism=CaseRealism.from_dict(realism) if realism else None,
            window=recorded_window(realised),
        )


@dataclass(frozen=True)
class Frontier:
    """The frontier the design recorded (design.json ``frontier``): K_max, n_max and its
    period (None: not written), what binds, the Larmor reading."""

    K_max: float | None
    n_max: float | None
    period_s: float | None
    binding: Any
    larmor: str

    @classmethod
    def read(cls, data: dict[str, Any] | None) -> Frontier | None:
        """The recorded frontier (None: none recorded)."""
        if not data:
            return None
        return cls(
            K_max=data.get("K_max"),
            n_max=data.get("n_max"),
            period_s=data.get("period_s"),
            binding=data.get("binding"),
            larmor=data.get("larmor", "charges"),
        )


@dataclass(frozen=True)
class Placement:
    """The element whose placement tolerance binds (design.json ``tolerance``)."""

    element: str
    position_tol_m_min: float
    binding: str
    target: float | None

    @classmethod
    def read(cls, data: dict[str, Any] | None) -> Placement | None:
        """The binding element (None: no tolerancing recorded, or nothing binds)."""
        data = data or {}
        top = (data.get("elements") or [None])[0]
        if not (top and top.get("binding")):
            return None
        return cls(top["element"], top["position_tol_m_min"], top["binding"], data.get("target"))


@dataclass(frozen=True)
class Limits:
    """The buildability checks of the written parts (design.json ``buildability``)."""

    #: the largest surface field over the medium's breakdown at the scene's rate (0: unwritten)
    surface_field_fraction: float
    violations: tuple[str, ...]

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> Limits:
        return cls(
            surface_field_fraction=data.get("largest_surface_field_fraction_of_breakdown", 0),
            violations=tuple(data.get("violations", [])),
        )


@dataclass(frozen=True)
class Materials:
    """The names of the carriers' and the magnets' materials (``?``: not written)."""

    carrier: str
    magnet: str

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> Materials:
        return cls(
            carrier=data.get("carrier", {}).get("name", "?"),
            magnet=data.get("magnet", {}).get("name", "?"),
        )


@dataclass(frozen=True)
class BudgetItem:
    """An item of the realism budget: its figure (None: unbounded), unit, verdict and note;
    the induced magnetisation's one figure also names its term and rate."""

    value: float | None
    unit: str
    verdict: Any
    note: Any
    term: str | None = None
    s: float | None = None

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> BudgetItem:
        return cls(
            value=data.get("value"),
            unit=data.get("unit", ""),
            verdict=data.get("verdict"),
            note=data.get("note"),
            term=data.get("term"),
            s=data.get("s"),
        )


@dataclass(frozen=True)
class Budget:
    """The realism budget's scalars and items (design.json ``realism`` less its figure
    blocks), in the order written."""

    typical_rate_1_per_s: float
    period_s: float
    designed_torque_N_m: float
    items: dict[str, BudgetItem]

    @property
    def balance_1g(self) -> BudgetItem | None:
        """The centre of mass's offset from O the balance allows under 1 g (None: unwritten)."""
        return self.items.get("balance_offset_1g_m")

    @property
    def balance_microgravity(self) -> BudgetItem | None:
        """The same under 1e-6 g (None: unwritten)."""
        return self.items.get("balance_offset_microgravity_m")

    @property
    def table(self) -> dict[str, BudgetItem]:
        """The items of the budget's table: the induced magnetisation once, as its one figure
        (:data:`INDUCED_KEY`) when written, not also the field response's input to it."""
        return {
            k: v
            for k, v in self.items.items()
            if k != FIELD_RESPONSE_KEYS[0] or INDUCED_KEY not in self.items
        }

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> Budget:
        return cls(
            typical_rate_1_per_s=data.get("typical_rate_1_per_s", 0),
            period_s=data.get("period_s", 0),
            designed_torque_N_m=data.get("designed_torque_N_m", 0),
            items={k: BudgetItem.from_dict(v) for k, v in data.items() if isinstance(v, dict)},
        )


@dataclass(frozen=True)
class KLaw:
    """The size-free K law's item of the realism budget
    (:func:`chargedesign.physical.realism.k_law_item`): the verdict on the parts' materials
    at the K frontier and the figures its lines print."""

    #: the figure the verdict rests on (element by element, else the law's; None: unwritten)
    value: float | None
    #: the law's own ratio 6 (chi/rho) / (mu0 G^2)
    ratio: float
    verdict: str
    larmor_reading: str
    cancelled_by_design: bool
    ratio_elements: float | None
    ratio_without_cancellation: float | None
    chi_over_rho_m3_per_kg: float | None
    G_C_m_per_kg: float
    K_max_1_per_s: float
    K_max_source: str
    a2_T_per_m: float
    chi_relative_needed: float | None
    metrology_chi_relative: float | None
    surface_field_V_per_m: float
    parity_surface_field_V_per_m: float
    parity_chi_over_rho_m3_per_kg: float | None
    field_evaporation_V_per_m: float
    atomic_field_V_per_m: float
    eddy_ratio: float | None
    conductivity_needed_S_per_m: float | None
    conductivity_needed_for: str | None
    conductivity_now_S_per_m: float | None
    insulators_S_per_m: dict[str, float]
    one_charge_carrier_radius_m: float
    smallest_similar_body_radius_m: float | None

    @classmethod
    def read(cls, data: dict[str, Any]) -> KLaw | None:
        """The K law's item (None: the law does not apply, its item is empty)."""
        if not data:
            return None
        return cls(
            value=data.get("value"),
            ratio=data["ratio"],
            verdict=data["verdict"],
            larmor_reading=data["larmor_reading"],
            cancelled_by_design=bool(data.get("cancelled_by_design")),
            ratio_elements=data.get("ratio_elements"),
            ratio_without_cancellation=data.get("ratio_without_cancellation"),
            chi_over_rho_m3_per_kg=data.get("chi_over_rho_m3_per_kg"),
            G_C_m_per_kg=data["G_C_m_per_kg"],
            K_max_1_per_s=data["K_max_1_per_s"],
            K_max_source=data["K_max_source"],
            a2_T_per_m=data["a2_T_per_m"],
            chi_relative_needed=data.get("chi_relative_needed"),
            metrology_chi_relative=data.get("metrology_chi_relative"),
            surface_field_V_per_m=data["surface_field_V_per_m"],
            parity_surface_field_V_per_m=data["parity_surface_field_V_per_m"],
            parity_chi_over_rho_m3_per_kg=data.get("parity_chi_over_rho_m3_per_kg"),
            field_evaporation_V_per_m=data["field_evaporation_V_per_m"],
            atomic_field_V_per_m=data["atomic_field_V_per_m"],
            eddy_ratio=data.get("eddy_ratio"),
            conductivity_needed_S_per_m=data.get("conductivity_needed_S_per_m"),
            conductivity_needed_for=data.get("conductivity_needed_for"),
            conductivity_now_S_per_m=data.get("conductivity_now_S_per_m"),
            insulators_S_per_m=dict(data.get("insulators_S_per_m") or {}),
            one_charge_carrier_radius_m=data["one_charge_carrier_radius_m"],
            smallest_similar_body_radius_m=data.get("smallest_similar_body_radius_m"),
        )


@dataclass(frozen=True)
class PartSpan:
    """How many parts of a kind and their smallest and largest size, m (a carrier's and a
    ballast sphere's radius)."""

    count: int
    smallest_m: float
    largest_m: float

    @classmethod
    def read(cls, data: dict[str, Any] | None) -> PartSpan | None:
        """The kind's sizes (None: the body has none of it)."""
        if not data:
            return None
        return cls(data["count"], data["smallest_m"], data["largest_m"])


@dataclass(frozen=True)
class MagnetSpan(PartSpan):
    """The magnets' sizes (their edges, m) against their continuum size
    (:func:`chargedesign.physical.realism.magnet_continuum`): ``below`` of them are under
    ``continuum_size_m``."""

    below: int
    continuum_size_m: float

    @classmethod
    def read(cls, data: dict[str, Any] | None) -> MagnetSpan | None:
        if not data:
            return None
        return cls(**{name: data[name] for name in cls.__dataclass_fields__})


@dataclass(frozen=True)
class PartSizes:
    """The budget's ``part_sizes``: carriers, magnets and ballast (None: none of the kind)."""

    carriers: PartSpan | None
    magnets: MagnetSpan | None
    ballast: PartSpan | None

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> PartSizes:
        return cls(
            carriers=PartSpan.read(data.get("carriers")),
            magnets=MagnetSpan.read(data.get("magnets")),
            ballast=PartSpan.read(data.get("ballast")),
        )


@dataclass(frozen=True)
class MapRow:
    """A row of the realisability map (:func:`chargedesign.physical.realism.realisability_map`
    with the induced columns of :func:`chargedesign.physical.budget.map_figures`; a size
    written as null is unbounded)."""

    term: str
    expression: str
    where: str
    mechanisms: str
    here: str
    size_N_m: float | None
    induced_over_term: float | None
    eddy_over_term: float | None
    frontier_size_N_m: float | None
    frontier_induced_over_term: float | None
    frontier_eddy_over_term: float | None

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> MapRow:
        return cls(**{name: data[name] for name in cls.__dataclass_fields__})


@dataclass(frozen=True)
class PhysicalRecords:
    """A physical body's realism budget, typed: the record as read
    (:class:`~chargedesign.scene.design_realism.RealismRecord`: its window at the design's
    rate, the induced magnetisation's figure) and its items and figures."""

    realism: RealismRecord
    budget: Budget
    #: the field response items (induced magnetisation, eddy currents), when written
    response: dict[str, BudgetItem]
    law: KLaw | None
    part_sizes: PartSizes
    realisability_map: tuple[MapRow, ...]
    #: the support at the design's rate (None: not written, or the body is not buildable)
    support: BearingSupport | None

    @classmethod
    def read(cls, design: Design) -> PhysicalRecords:
        record = RealismRecord.read(design.realism)
        budget = Budget.from_dict(record.budget)
        window = record.window
        support = window.support if window is not None else None
        return cls(
            realism=record,
            budget=budget,
            response={k: budget.items[k] for k in FIELD_RESPONSE_KEYS if k in budget.items},
            law=KLaw.read(record.law),
            part_sizes=PartSizes.from_dict(record.part_sizes),
            realisability_map=tuple(MapRow.from_dict(row) for row in record.realisability_map),
            support=BearingSupport.from_dict(support) if support else None,
        )


@dataclass(frozen=True)
class ReportRecords:
    """Every record of a design the report renders, read once (:meth:`read`)."""

    #: where each field's coefficients came from, by kind (design.json ``fields_origin``)
    fields_origin: dict[str, str]
    candidates: Candidates | None
    #: the forward accuracy where each source's contributions cancel most, by source
    cancellations: dict[str, Cancellation]
    problems: Problems | None
    case: CaseRecord | None
    frontier: Frontier | None
    placement: Placement | None
    limits: Limits
    materials: Materials
    #: a physical body's (one with a medium) realism budget; None for point elements
    physical: PhysicalRecords | None

    @classmethod
    def read(cls, design: Design) -> ReportRecords:
        worst = (design.forward_accuracy or {}).get("worst") or {}
        return cls(
            fields_origin=dict((design.provenance or {}).get("fields_origin") or {}),
            candidates=Candidates.read(design),
            cancellations={k: Cancellation.from_dict(v) for k, v in worst.items()},
            problems=Problems.read(design),
            case=CaseRecord.read(design),
            frontier=Frontier.read(design.frontier),
            placement=Placement.read(design.tolerance),
            limits=Limits.from_dict(design.buildability or {}),
            materials=Materials.from_dict(design.materials or {}),
            physical=PhysicalRecords.read(design) if design.medium is not None else None,
        )
