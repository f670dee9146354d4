"""The catalogue of the paper's integrable cases, each a case file certified exactly.

The entries live in ``chargedesign/data/cases/catalogue.toml``: each names a case file of
that folder (``[case]`` tables, :mod:`chargedesign.model.case_file`), with optional parameter
overrides (the theorem's limits are its own file with parameters set to zero), a name and a
source. :func:`certify_catalogue` runs :func:`chargedesign.model.case_file.certify_case` on
each (what ``chargedesign catalogue`` prints).
"""

from __future__ import annotations

import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from functools import lru_cache
from importlib import resources
from typing import Any

import sympy as sp

from chargedesign.model import case as model
from chargedesign.model.case_file import CaseCertificate, certify_case
from chargedesign.params import Parameters
from chargedesign.readers import loads_toml
from chargedesign.results import Result
from chargedesign.scene.case_file import (
    Case,
    case_from_table,
    sphere_remainder,
    vanishes_on_sphere,
)
from chargedesign.validation import check_keys

#: the keys of one catalogue entry
ENTRY_KEYS = ("file", "name", "source", "parameters")


def _data_text(name: str) -> str:
    return resources.files("chargedesign").joinpath("data", "cases", name).read_text("utf-8")


def catalogue_entries() -> list[dict[str, Any]]:
    """The entries of ``data/cases/catalogue.toml`` (file, and optional name, source,
    parameters)."""
    data = loads_toml(_data_text("catalogue.toml"), "data/cases/catalogue.toml")
    entries = data.get("entry", [])
    for i, entry in enumerate(entries):
        check_keys(entry, ENTRY_KEYS, f"catalogue.entry[{i}]")
    return list(entries)


def entry_table(entry: Mapping[str, Any]) -> dict[str, Any]:
    """The ``[case]`` table of an entry: its file's, with the entry's overrides applied."""
    name = entry["file"]
    table = dict(loads_toml(_data_text(name), f"data/cases/{name}")["case"])
    parameters = dict(table.get("parameters", {}))
    for key, value in entry.get("parameters", {}).items():
        if key not in parameters:
            raise ValueError(f"catalogue: {name} has no parameter {key!r} to override")
        parameters[key] = value
    table["parameters"] = parameters
    for key in ("name", "source"):
        if key in entry:
            table[key] = entry[key]
    return table


def catalogue_cases() -> list[Case]:
    """Every case of the catalogue, validated."""
    return [case_from_table(entry_table(e), f"case {e['file']}") for e in catalogue_entries()]


def catalogue_case(name: str) -> Case:
    """One case of the catalogue by its name."""
    for entry in catalogue_entries():
        table = entry_table(entry)
        if table["name"] == name:
            return case_from_table(table, f"case {entry['file']}")
    names = ", ".join(entry_table(e)["name"] for e in catalogue_entries())
    raise ValueError(f"catalogue: no case named {name!r} (the cases: {names})")


#: the catalogue's file of the theorem (Yehia & Elmandouh): V, l and I4 as the paper states them
THEOREM_FILE = "yehia_elmandouh.toml"
#: the name of the theorem's case built from a scene's parameters
THEOREM_NAME = "yehia-elmandouh"


def theorem_case(params: Parameters) -> Case:
    """The theorem as a case of (ep): the catalogue's entry with ``params`` as its parameters.

    Each float is read as the decimal it prints as (``0.3 -> 3/10``, as a case file reads
    it), so the case's V, l, inertia and I4 are exact; ``case.parameters`` holds them. The
    conditions engine gives it the theorem's own conditions
    (:func:`chargedesign.moment_conditions.case.derive_case_conditions`; the two agree row for
    row, tests/model/test_theorem_case.py).
    """
    table = entry_table({"file": THEOREM_FILE, "parameters": params.as_dict()})
    table["name"] = THEOREM_NAME
    return case_from_table(table, f"case {THEOREM_FILE}")


def theorem_parameters(case: Case) -> Parameters | None:
    """The theorem's parameters of a case of the theorem's form, or None for any other case.

    A case is the theorem's when its inertia is ``(2C, 2C, C)`` and its V and l are, on
    ``|gamma| = 1``, the theorem's with lambda = rho = 0 for some ``(c, d, n, K, kappa)``
    (exact rationals). V and l fix ``n``, ``K (c, d)`` and ``kappa (c, d)`` only (the theorem
    is unchanged under ``(c, d, K, kappa) -> (t c, t d, K / t, kappa / t)``), so:

    - a case whose ``parameters`` name the theorem's and give its V and l exactly (the
      catalogue's entry, :func:`theorem_case`) is read with those parameters;
    - any other is read with the paper's ``c^2 + d^2 = 1/4`` and ``K >= 0`` (``kappa >= 0``
      when K = 0).

    The physical design reads of these parameters what a general case does not give: the
    typical rate of the realism budget, the K law and the Larmor rate n.
    """
    A, B, C = case.inertia
    if not (A == B == 2 * C) or case.l is None:
        return None
    given = _given_theorem_parameters(case)
    if given is not None:
        return given
    products = _theorem_products(case)
    if products is None:
        return None
    n, Kc, Kd, kc, kd = products
    if Kc != 0 or Kd != 0:
        K = 2 * sp.sqrt(Kc**2 + Kd**2)
        c, d = Kc / K, Kd / K
        if kc * Kd != kd * Kc:
            return None  # kappa (c, d) not along K (c, d): not the theorem's V
        kappa = kc / c if c != 0 else kd / d
    elif kc != 0 or kd != 0:
        K = sp.Integer(0)
        kappa = 2 * sp.sqrt(kc**2 + kd**2)
        c, d = kc / kappa, kd / kappa
    else:
        K = kappa = c = d = sp.Integer(0)
    return Parameters(
        C=float(C), c=float(c), d=float(d), n=float(n), K=float(K), kappa=float(kappa)
    )


def _given_theorem_parameters(case: Case) -> Parameters | None:
    """The case's own ``parameters`` when they are the theorem's and give its V and l."""
    names = set(Parameters().as_dict())
    if not case.parameters or not set(case.parameters) <= names:
        return None
    values = {k: float(v) for k, v in case.parameters.items()}
    params = Parameters.from_mapping(values, f"case {case.name}.parameters")
    if params.singular:
        return None
    theorem = theorem_case(params)
    assert theorem.l is not None and case.l is not None
    same = (
        tuple(theorem.inertia) == tuple(case.inertia)
        and vanishes_on_sphere(theorem.V - case.V)
        and all(vanishes_on_sphere(a - b) for a, b in zip(theorem.l, case.l, strict=True))
    )
    return params if same else None


def _sphere_coefficients(expr: sp.Expr, constant: bool) -> list[sp.Expr]:
    """The coefficients of ``expr``'s normal form on ``|gamma| = 1``
    (:func:`~chargedesign.scene.case_file.sphere_remainder`; its constant term too when
    ``constant``): all zero iff ``expr`` vanishes on the sphere (up to a constant)."""
    return [c for m, c in sphere_remainder(expr).terms() if constant or any(m)]


@lru_cache(maxsize=1)
def _theorem_in_products() -> tuple[tuple[sp.Expr, ...], sp.Expr, tuple[sp.Symbol, ...]]:
    """The theorem's l and V (:func:`chargedesign.model.case.symbolic_case`, the claim's one
    statement in code) with lambda = rho = 0, divided by C and written in the products
    ``(n, K c, K d, kappa c, kappa d)``, which they are linear in (each c or d of the K terms
    comes with one K, each of the kappa term with kappa): ``(l, V, products)``."""
    theorem = model.symbolic_case()
    Kc, Kd, kc, kd = sp.symbols("Kc Kd kc kd")
    plain = {model.C: 1, model.lam: 0, model.rho: 0}
    V = sp.expand(theorem.V.xreplace(plain))
    V_kappa = V.coeff(model.kappa)
    in_K = {model.c: Kc / model.K, model.d: Kd / model.K}
    V = sp.expand((V - model.kappa * V_kappa).xreplace(in_K)) + sp.expand(
        V_kappa.xreplace({model.c: kc, model.d: kd})
    )
    l_vec = tuple(sp.expand(x.xreplace(plain).xreplace(in_K)) for x in theorem.l)
    assert not (V.free_symbols | set().union(*(x.free_symbols for x in l_vec))) & {
        model.c,
        model.d,
        model.K,
        model.kappa,
    }
    return l_vec, V, (model.n, Kc, Kd, kc, kd)


def _theorem_products(case: Case) -> tuple[sp.Expr, ...] | None:
    """``(n, K c, K d, kappa c, kappa d)`` whose theorem V and l are the case's on the
    sphere (exact), or None (no such: the case is not the theorem's)."""
    assert case.l is not None
    C = case.inertia[2]
    l_unit, V_unit, (n, Kc, Kd, kc, kd) = _theorem_in_products()
    l_theorem = [C * x for x in l_unit]
    V_theorem = C * V_unit
    try:
        l_rows = [
            c
            for a, b in zip(l_theorem, case.l, strict=True)
            for c in _sphere_coefficients(a - b, True)
        ]
        l_solutions = list(sp.linsolve(l_rows, [n, Kc, Kd]))
        if len(l_solutions) != 1 or any(s.free_symbols for s in l_solutions[0]):
            return None
        first = dict(zip((n, Kc, Kd), l_solutions[0], strict=True))
        v_rows = _sphere_coefficients(V_theorem.subs(first) - case.V, False)
        v_solutions = list(sp.linsolve(v_rows, [kc, kd]))
    except (sp.PolynomialError, sp.polys.polyerrors.PolificationFailed):
        return None  # a singular (rational) V or l: not the theorem's polynomial form
    if len(v_solutions) != 1 or any(s.free_symbols for s in v_solutions[0]):
        return None
    return (*l_solutions[0], *v_solutions[0])


@dataclass(repr=False)
class CatalogueReport(Result):
    """The certificate of every catalogue case (``chargedesign catalogue``).

    Attributes
    ----------
    certificates : list of CaseCertificate
    seconds : float
        Wall time of the whole catalogue.
    """

    certificates: Sequence[CaseCertificate]
    seconds: float

    @property
    def holds(self) -> bool:
        """Every claim holds and every integral is independent."""
        return all(c.holds and c.independent for c in self.certificates)

    def to_dict(self) -> dict[str, Any]:
        return {
            "cases": [c.to_dict()["case"] for c in self.certificates],
            "holds": self.holds,
            "seconds": self.seconds,
        }

    def _summary(self) -> dict[str, Any]:
        return {
            "cases": len(self.certificates),
            "certified": sum(c.holds and c.independent for c in self.certificates),
            "holds": self.holds,
            "seconds": self.seconds,
        }

    def _text(self) -> str:
        width = max((len(c.name) for c in self.certificates), default=4)
        lines = [
            "Catalogue of the paper's cases: exact certificates (rational arithmetic)",
            "",
            f"  {'case':<{width}}  {'level':<8} {'holds':<6} {'indep.':<7} {'all par.':<9} "
            f"{'seconds':<8} source",
        ]
        for c in self.certificates:
            level = "general" if c.level == "general" else f"I3 = {c.level}"
            for_all = {True: "yes", False: "NO", None: "-"}[c.holds_for_all_parameters]
            lines.append(
                f"  {c.name:<{width}}  {level:<8} {'yes' if c.holds else 'NO':<6} "
                f"{'yes' if c.independent else 'NO':<7} {for_all:<9} {c.seconds:<8.3f} {c.source}"
            )
        certified = sum(c.holds and c.independent for c in self.certificates)
        lines += [
            "",
            f"  {certified}/{len(self.certificates)} certified in {self.seconds:.2f} s "
            "(holds at the files' values, independent; 'all par.': for all values of the "
            "non-zero parameters)",
        ]
        return "\n".join(lines)


def certify_catalogue() -> CatalogueReport:
    """Certify every case of the catalogue."""
    start = time.perf_counter()
    certificates = [certify_case(case) for case in catalogue_cases()]
    return CatalogueReport(certificates, time.perf_counter() - start)


__all__ = [
    "CatalogueReport",
    "catalogue_case",
    "catalogue_cases",
    "catalogue_entries",
    "certify_catalogue",
    "entry_table",
    "theorem_case",
    "theorem_parameters",
]
