"""Design options: what to optimise and how (``DesignOptions``), validated.

The keys of a scene's ``[design]`` table (docs/design.md) and the default tolerances a
delivered design must reach.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import asdict, dataclass
from typing import Any

from chargedesign.scene.keys import KEY, check_value, declared, default_of, key_names
from chargedesign.validation import as_finite_float, check_keys, input_error
from chargedesign.vocabulary import OBJECTIVES as OBJECTIVES
from chargedesign.vocabulary import REALISABLE, SOURCES

SPARSITY_METHODS: tuple[str, ...] = tuple(declared("design", "sparsity").schema["enum"])
#: relative residual a polished design must reach (default ``tol`` with polishing)
POLISHED_TOL = 1e-13
#: relative residual accepted from a solver alone (default ``tol`` without polishing)
RAW_TOL = 1e-7
Progress = Callable[[str], None]


@dataclass(frozen=True)
class DesignOptions:
    """What to optimise and how.

    Parameters
    ----------
    objective : {"l1", "l2", "linf", "robust"}
        Objective for every source (see the module doc); ``objectives`` overrides per source.
        ``"robust"`` minimises ``sum_j c_j |w_j|`` (``||sigma_j||`` for dipoles), ``c_j`` the
        first-order placement sensitivity of a unit element at candidate j
        (:func:`chargedesign.sensitivity.sensitivity_weights`): the body that tolerates the
        largest placement errors.
    robust_weight : float
        With ``"robust"``: the cost of candidate j is ``(1 - beta) + beta c_j / mean(c)``,
        ``beta`` in [0, 1]; 0 is plain l1 (sparsity), 1 (default) pure sensitivity.
    solver : str
        ``"auto"`` (HiGHS for linear programs, Clarabel for cones and quadratics, closed form
        for unconstrained least norm) or a cvxpy solver name (``"CLARABEL"``, ``"HIGHS"``,
        ``"SCS"``, ...), which then solves the full problem through cvxpy.
    max_charge : float, optional
        Bound on every ``|q|``, C.
    total_charge : float, optional
        Required total charge, C.
    n_charges : int, optional
        At most this many charges (reweighted l1, then mixed integer with HiGHS).
    total_mass : float, optional
        Required total mass, kg.
    realise : tuple of str, optional
        What the design claims (default: what the conditions realise).
    polish : bool
        Polish to machine precision on the support.
    tol : float, optional
        Largest accepted relative residual (default 1e-13 polished, 1e-7 unpolished).
    objectives : mapping, optional
        Per-source objective, e.g. ``{"masses": "l2"}``.
    column_generation : bool, optional
        Force column generation on or off (default: on above 2000 candidates, for HiGHS).
    sparsity : {"auto", "reweighted", "mip"}
        How ``n_charges`` is met: reweighted l1 only, mixed integer only, or reweighted l1
        then mixed integer (auto).
    time_limit : float
        Seconds allowed to the mixed-integer solver.
    larmor : {"charges", "frame"}, optional
        How the theorem's n is realised (:mod:`chargedesign.larmor`): ``charges``, the paper's
        (p6) second moments of charge; ``frame``, a body realising n = 0 whose motion, read in
        axes turning at n about Z, is the theorem's. Default (None): ``charges`` for a scene
        without ``[medium]``, ``frame`` with one.
    realised_fraction : float
        The realised window (:mod:`chargedesign.physical.window`): every parasitic below
        this fraction of each realised term (default 1e-3).
    realised_gravity : float
        Gravity on the builder's balance in the realised window, m/s^2 (default 1 g).
    """

    objective: str = default_of("design", "objective")
    solver: str = default_of("design", "solver")
    max_charge: float | None = None
    total_charge: float | None = None
    n_charges: int | None = None
    total_mass: float | None = None
    realise: tuple[str, ...] | None = None
    polish: bool = default_of("design", "polish")
    tol: float | None = None
    objectives: Mapping[str, str] | None = None
    column_generation: bool | None = None
    sparsity: str = default_of("design", "sparsity")
    time_limit: float = default_of("design", KEY.time_limit)
    robust_weight: float = default_of("design", KEY.robust_weight)
    larmor: str | None = None
    realised_fraction: float = default_of("design", KEY.realised_fraction)
    realised_gravity: float = default_of("design", KEY.realised_gravity)

    def __post_init__(self) -> None:
        for name in (KEY.realised_fraction, KEY.realised_gravity):
            object.__setattr__(self, name, check_value("design", name, getattr(self, name)))
        self._check_objectives()
        self._check_amounts()
        self._check_solve_options()
        self._check_robust_weight()

    def _check_objectives(self) -> None:
        """The objective(s), the Larmor reading and the solver's name."""
        check_value("design", "objective", self.objective)
        if self.larmor is not None:
            check_value("design", "larmor", self.larmor)
        if self.objectives is not None:
            if not isinstance(self.objectives, Mapping):
                raise input_error(
                    "design.objectives", "a table source -> objective", self.objectives
                )
            for source, value in self.objectives.items():
                if source not in SOURCES:
                    raise input_error(
                        f"design.objectives.{source}", "one of " + ", ".join(SOURCES), source
                    )
                check_value("design", "objective", value, f"design.objectives.{source}")
            object.__setattr__(self, "objectives", dict(self.objectives))
        if not isinstance(self.solver, str) or not self.solver:
            raise input_error(
                "design.solver", "a solver name such as 'auto' or 'CLARABEL'", self.solver
            )

    def _check_amounts(self) -> None:
        """Largest charge, totals, number of charges and the realised terms."""
        for name in (KEY.max_charge, KEY.total_mass, KEY.total_charge):
            value = getattr(self, name)
            if value is not None:
                object.__setattr__(self, name, check_value("design", name, value))
        if self.n_charges is not None:
            check_value("design", KEY.n_charges, self.n_charges)
        if self.realise is not None:
            object.__setattr__(self, "realise", _realise_list(self.realise))

    def _check_solve_options(self) -> None:
        """Polish, tolerance, column generation, sparsity method and time limit."""
        check_value("design", "polish", self.polish)
        if self.tol is not None:
            tol = as_finite_float(self.tol, "design.tol", positive=True)
            if tol >= 1.0:
                raise input_error("design.tol", "a relative residual below 1", self.tol)
            object.__setattr__(self, "tol", tol)
        if self.column_generation is not None:
            check_value("design", KEY.column_generation, self.column_generation)
        check_value("design", "sparsity", self.sparsity)
        object.__setattr__(
            self, KEY.time_limit, check_value("design", KEY.time_limit, self.time_limit)
        )

    def _check_robust_weight(self) -> None:
        """The robust objective's weight in [0, 1], only with the robust objective."""
        beta = check_value("design", KEY.robust_weight, self.robust_weight)
        object.__setattr__(self, KEY.robust_weight, beta)
        if beta != 1.0 and not self.robust:
            # a weight that would change nothing: the user meant the robust objective
            raise input_error(
                "design.robust_weight",
                "to be used with objective = 'robust' (set design.objective or "
                "design.objectives too)",
                self.robust_weight,
            )

    @property
    def robust(self) -> bool:
        """Whether any source is designed with the robust objective."""
        return "robust" in (self.objective, *(self.objectives or {}).values())

    @property
    def tolerance(self) -> float:
        """The residual a delivered design must reach."""
        if self.tol is not None:
            return self.tol
        return POLISHED_TOL if self.polish else RAW_TOL

    def objective_for(self, source: str) -> str:
        if self.objectives and source in self.objectives:
            return self.objectives[source]
        return self.objective

    @classmethod
    def from_table(cls, table: Mapping[str, Any], **overrides: Any) -> DesignOptions:
        """Options from a scene's ``[design]`` table (keys in docs/design.md), then overrides."""
        if not isinstance(table, Mapping):
            raise input_error("design", "a table", table)
        check_keys(table, sorted(key_names("design")), "design")
        kwargs = dict(table)
        if "realise" in kwargs:
            kwargs["realise"] = _realise_list(kwargs["realise"])
        if KEY.n_charges in kwargs and isinstance(kwargs[KEY.n_charges], float):
            raise input_error("design.n_charges", "an integer >= 1", kwargs[KEY.n_charges])
        kwargs.update({k: v for k, v in overrides.items() if v is not None})
        return cls(**kwargs)

    def to_dict(self) -> dict[str, Any]:
        out = asdict(self)
        out["realise"] = list(self.realise) if self.realise is not None else None
        out["tolerance"] = self.tolerance
        return out


def _realise_list(value: Any) -> tuple[str, ...]:
    """``design.realise``: a list of distinct items among mu, V, inertia (errors name it)."""
    expected = "a list of " + ", ".join(REALISABLE)
    if isinstance(value, str) or not isinstance(value, (list, tuple)):
        raise input_error("design.realise", expected, value)
    for item in value:
        if item not in REALISABLE:
            raise input_error("design.realise", "items among " + ", ".join(REALISABLE), item)
    if len(set(value)) != len(value):
        raise input_error("design.realise", "no repeated items", list(value))
    return tuple(value)
