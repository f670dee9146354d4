"""What a design returns: per-source outcomes, the body, and its design.json provenance."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import asdict, dataclass, field
from typing import Any

from chargedesign.body import Design
from chargedesign.candidates import CandidateSet
from chargedesign.designer.accuracy import FORWARD_LIMIT, FORWARD_NOTE, Cancellation
from chargedesign.formatting import PLAIN, fmt
from chargedesign.moment_conditions import SOURCES, LinearConditions
from chargedesign.report import render_summary
from chargedesign.results import Result
from chargedesign.scene.design import DesignOptions
from chargedesign.verdict import recorded_verdict
from chargedesign.version import __version__


@dataclass
class SourceResult:
    """Outcome of one source's design problem (SI units).

    ``residual_before`` / ``residual_after``: :func:`relative_residual` of the solver's
    weights and of the delivered (polished) weights. ``forward``: the worst
    :class:`Cancellation` of the delivered weights (None when not assessed).
    """

    source: str
    objective: str
    objective_value: float
    objective_value_raw: float
    units: str
    solver: str
    method: str
    status: str
    n_conditions: int
    rank: int
    n_candidates: int
    n_elements: int
    residual_before: float
    residual_after: float
    seconds: float
    notes: list[str] = field(default_factory=list)
    forward: Cancellation | None = None

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)


@dataclass(repr=False)
class DesignResult(Result):
    """A designed body and how it was obtained.

    Attributes
    ----------
    design : Design
        The body, with its record (provenance, residuals, limits, realism, frontier, ...) in
        named attributes (:data:`chargedesign.body.RECORD_KEYS`; see docs/design.md).
    sources : dict[str, SourceResult]
    candidates : CandidateSet
    options : DesignOptions
    conditions : LinearConditions
    timings : dict[str, float]
        Seconds per stage.
    notes : list of str
    status : str
        ``"optimal"`` (every problem solved and verified).
    certificate : CaseCertificate or None
        The exact certificate of the model the body realises, at the body's own numbers
        (:func:`chargedesign.model.case_file.certify_case`): a ``[case]`` scene's claimed
        integral, or the theorem's I4 for the theorem's scene (the catalogue's case built from
        its parameters); None for a body designed outside a scene (``design_body``). A scene's
        is made when first read (``certificate_of``): it costs sympy and about a second, and
        the design itself never reads it.
    certificate_of : callable or None
        Makes the certificate when it is first read (then None); takes ``progress=``.
    certificate_recorded : bool
        The deferred certificate writes into the body's record (a ``[case]`` scene's verdict,
        design.json ``case.certificate``): :meth:`recorded_design` makes it before the body
        is written. The theorem's scene's is not written (its ``parameters`` rebuild the case).
    """

    design: Design
    sources: dict[str, SourceResult]
    candidates: CandidateSet
    options: DesignOptions
    conditions: LinearConditions
    timings: dict[str, float] = field(default_factory=dict)
    notes: list[str] = field(default_factory=list)
    status: str = "optimal"
    _certificate: Any = field(default=None, repr=False)
    certificate_of: Callable[..., Any] | None = field(default=None, repr=False, compare=False)
    certificate_recorded: bool = field(default=False, repr=False, compare=False)

    @property
    def certificate(self) -> Any:
        """The exact certificate of the body's model (made now when it was deferred)."""
        return self._made_certificate(None)

    @certificate.setter
    def certificate(self, value: Any) -> None:
        self._certificate, self.certificate_of = value, None

    def _made_certificate(self, progress: Callable[[str], None] | None) -> Any:
        if self.certificate_of is not None:
            self._certificate, self.certificate_of = self.certificate_of(progress=progress), None
        return self._certificate

    def recorded_design(self, progress: Callable[[str], None] | None = None) -> Design:
        """The body with every record its files carry: a deferred certificate that its
        record holds (:attr:`certificate_recorded`) is made first. Every writer of the body
        (design.json, the report, a sweep's or simulation's files, :meth:`to_dict`)
        takes it from here, so that no written file lacks the certificate."""
        if self.certificate_recorded:
            self._made_certificate(progress)
        return self.design

    @property
    def limits(self) -> dict[str, Any] | None:
        """The limits report of a physical body (design.json ``buildability``), or None."""
        return self.design.buildability

    @property
    def realism(self) -> dict[str, Any] | None:
        """The realism budget of a physical body (design.json ``realism``), or None."""
        return self.design.realism

    @property
    def frontier(self) -> dict[str, Any] | None:
        """The largest rate within the limits (design.json ``frontier``), or None."""
        return self.design.frontier

    @property
    def tolerance(self) -> dict[str, Any] | None:
        """The tolerance report (design.json ``tolerance``), or None."""
        return self.design.tolerance

    @property
    def time_rate(self) -> float | None:
        """The physical design's time rate s (design.json ``time_rate``), or None."""
        return self.design.time_rate

    @property
    def larmor_why(self) -> str | None:
        """Why the body's Larmor reading was chosen (design.json ``larmor_why``), or None."""
        return self.design.larmor_why

    @property
    def residual_before(self) -> float:
        """Largest relative residual of the solvers' weights over the sources."""
        return max((s.residual_before for s in self.sources.values()), default=0.0)

    @property
    def residual_after(self) -> float:
        """Largest relative residual of the delivered weights over the sources."""
        return max((s.residual_after for s in self.sources.values()), default=0.0)

    def summary(self) -> dict[str, Any]:
        """A JSON-ready summary (residuals first)."""
        d = self.design
        return {
            "status": self.status,
            "verdict": recorded_verdict(d),
            "residuals": {
                "before_polish": {k: s.residual_before for k, s in self.sources.items()},
                "after_polish": {k: s.residual_after for k, s in self.sources.items()},
                "max_after_polish": self.residual_after,
                "tolerance": self.options.tolerance,
            },
            "counts": {
                "candidates": len(self.candidates),
                "charges": len(d.charge_values),
                "dipoles": len(d.dipole_moments),
                "masses": len(d.mass_values),
            },
            "objective": {
                k: {"kind": s.objective, "value": s.objective_value, "units": s.units}
                for k, s in self.sources.items()
            },
            "solver": {k: s.solver for k, s in self.sources.items()},
            "realises": list(d.realises),
            "timings": dict(self.timings),
            "notes": list(self.notes),
        }

    # result protocol (chargedesign.results)
    def to_dict(self) -> dict[str, Any]:
        """JSON-ready: :meth:`summary` plus the body's design.json mapping under ``design``."""
        return {**self.summary(), "design": self.recorded_design().to_dict()}

    def _summary(self) -> dict[str, Any]:
        d = self.design
        verdict = recorded_verdict(d)
        return {
            "verdict": verdict["state"],
            "status": self.status,
            "charges": len(d.charge_values),
            "dipoles": len(d.dipole_moments),
            "masses": len(d.mass_values),
            "candidates": len(self.candidates),
            "residual": self.residual_after,
            "realises": list(d.realises),
        }

    def _text(self) -> str:
        """The verdict and a short summary (the full report:
        :func:`chargedesign.report.render_report`)."""
        return render_summary(self.design)

    def _html_rows(self) -> dict[str, Any]:
        rows = self._summary()
        verdict = recorded_verdict(self.design)
        if verdict.get("binding") and verdict["binding"] != "-":
            rows["binding"] = verdict["binding"]
        if verdict.get("change") and verdict["change"] != "-":
            rows["what would change it"] = verdict["change"]
        rows["parameters"] = ", ".join(
            f"{k} = {fmt(v, PLAIN)}" for k, v in self.design.parameters.as_dict().items()
        )
        rows.update({f"note {i + 1}": n for i, n in enumerate(self.notes)})
        return rows

    def _html_picture(self) -> str:
        return self.design._html_picture()


def record_provenance(design: Design, result: DesignResult) -> None:
    """Set the design's provenance record (:func:`design_extras`) from how it was obtained."""
    for key, value in design_extras(result).items():
        setattr(design, key, value)


def _units_record() -> dict[str, str]:
    """design.json's ``units``: the SI units of every quantity written."""
    return {
        "positions": "m",
        "charges": "C",
        "masses": "kg",
        "dipoles": "A m^2",
        "fields": "legendre f_k of Phi = sum f_k R^k P_k(Z/R): magnetic T m^(1-k), "
        "electric V m^(-k), gravity J kg^-1 m^(-k)",
    }


def _residuals_record(result: DesignResult) -> dict[str, Any]:
    """design.json's ``residuals``: their definition, per source before and after polish."""
    return {
        "definition": "max_i |(A w - b)_i| / (|A_i|_S |w| + |b_i|) over the conditions "
        "of each source (A w = b from the conditions engine, SI units; |.| Euclidean, "
        "|A_i|_S the norm of row i on the support w != 0)",
        "before_polish": {k: s.residual_before for k, s in result.sources.items()},
        "after_polish": {k: s.residual_after for k, s in result.sources.items()},
        "tolerance": result.options.tolerance,
    }


def _forward_accuracy_record(result: DesignResult) -> dict[str, Any]:
    """design.json's ``forward_accuracy``: its definition, thresholds, the worst per source."""
    return {
        "definition": "per source, the field term whose contributions cancel most: sum of "
        "the elements' |contributions| through it over the size of mu (max |mu|) or V (its "
        "spread) = amplification; forward_error = eps * amplification * (sum |coefficients| "
        "of P_k, times k for V), the relative error to expect from any floating-point "
        "evaluation",
        "note_above": FORWARD_NOTE,
        "refused_above": FORWARD_LIMIT,
        "worst": {
            k: s.forward.to_dict() for k, s in result.sources.items() if s.forward is not None
        },
    }


def design_extras(result: DesignResult) -> dict[str, Any]:
    """The provenance record written into design.json beside the contract's keys (units,
    provenance, solver, objective, residuals, forward_accuracy, timings, candidates,
    conditions, notes, region: :class:`~chargedesign.body.Design` attributes)."""
    conditions = result.conditions
    counts = {s: len(conditions.for_source(s)) for s in SOURCES if conditions.for_source(s)}
    out: dict[str, Any] = {
        "units": _units_record(),
        "provenance": {
            "generator": f"chargedesign {__version__}",
            "fields_origin": dict(conditions.field_origin),
            "options": result.options.to_dict(),
        },
        "solver": {
            k: {"solver": s.solver, "method": s.method, "status": s.status}
            for k, s in result.sources.items()
        },
        "objective": {
            k: {
                "kind": s.objective,
                "value": s.objective_value,
                "units": s.units,
                "before_polish": s.objective_value_raw,
            }
            for k, s in result.sources.items()
        },
        "residuals": _residuals_record(result),
        "forward_accuracy": _forward_accuracy_record(result),
        "timings": {k: round(v, 6) for k, v in result.timings.items()},
        "candidates": result.candidates.description,
        "conditions": {
            "counts": counts,
            "ranks": {k: s.rank for k, s in result.sources.items()},
            "notes": list(conditions.notes),
            "list": [c.to_dict() for c in conditions.conditions],
        },
        "notes": list(result.notes),
    }
    if result.candidates.region is not None:
        out["region"] = dict(result.candidates.region)
    return out
