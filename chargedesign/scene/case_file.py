"""A ``[case]`` table (a case file, or a scene's ``[case]``) read into a typed :class:`Case`,
every refusal made here, before any certificate work.

The case holds the file's values exactly: the inertia, ``V``, ``l`` (``mu`` follows by the
paper's (mu), :func:`mu_from_l`) or ``mu`` itself, the claimed integral and its level, every
expression parsed by the whitelisted parser (:mod:`chargedesign.scene.expressions`) with the
parameters substituted (and, for the certificate's "for all parameters" step, with the
non-zero parameters kept as symbols). The equations and the exact certificate on the typed
case are the model's: :mod:`chargedesign.model.case_file`.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from fractions import Fraction
from typing import Any

import sympy as sp

from chargedesign.errors import InputError
from chargedesign.readers import read_toml_file
from chargedesign.scene.expressions import (
    g1,
    g2,
    g3,
    p,
    parameter_name_error,
    parameter_symbol,
    parse_bounded,
    q,
    r,
)
from chargedesign.validation import check_input_number, check_keys, input_error
from chargedesign.vocabulary import CASE_KEYS

#: most declared parameters of one case
MAX_PARAMETERS = 32
#: highest degree of a mu given without l (I3's gamma part is then found by an ansatz)
MAX_MU_DEGREE = 8
#: largest denominator (terms) factored to say where a case is singular
MAX_FACTORED_TERMS = 200
OMEGA = sp.Matrix([p, q, r])
GAMMA = sp.Matrix([g1, g2, g3])
_SPHERE = sp.Poly(g1**2 + g2**2 + g3**2 - 1, g1, g2, g3, p, q, r)


def mu_from_l(l_vec: sp.Matrix) -> sp.Matrix:
    """The paper's formula (mu): ``mu = d(l . gamma)/dgamma - (div_gamma l) gamma`` (what a
    case file's ``l`` means; :mod:`chargedesign.model.case` derives the theorem's mu by it)."""
    lg = l_vec.dot(GAMMA)
    grad = sp.Matrix([sp.diff(lg, x) for x in GAMMA])
    div = sum(sp.diff(l_vec[i], GAMMA[i]) for i in range(3))
    return (grad - div * GAMMA).applyfunc(sp.expand)


@dataclass(frozen=True)
class Case:
    """A case of (ep) with its claim, every expression exact (parameters substituted).

    Attributes
    ----------
    name : str
    inertia : tuple of sympy.Rational, shape (3,)
        ``A, B, C`` (principal moments at O, each > 0).
    V : sympy.Expr
        Potential, a function of gamma.
    l : sympy.Matrix or None
        Vector potential (None when the file gives ``mu``).
    mu : sympy.Matrix, shape (3, 1)
        Gyroscopic vector (from ``l`` by (mu), or as given).
    integral : sympy.Expr
        The claimed integral ``F``.
    level : sympy.Rational or None
        The I3 level of a conditional claim; None for a general one.
    parameters : dict of str to sympy.Rational
    texts : dict of str to str
        The expressions as written (V, l or mu, integral), for reports.
    source, note : str
        Where the case comes from, and a remark (both optional).
    """

    name: str
    inertia: tuple[sp.Rational, sp.Rational, sp.Rational]
    V: sp.Expr
    l: sp.Matrix | None
    mu: sp.Matrix
    integral: sp.Expr
    level: sp.Rational | None
    parameters: dict[str, sp.Rational] = field(default_factory=dict)
    texts: dict[str, Any] = field(default_factory=dict)
    source: str = ""
    note: str = ""
    free: dict[str, Any] = field(default_factory=dict, compare=False)

    def at_values(self) -> Case:
        """The same case without its free-parameter form: its certificate is then the claim
        at the parameters' values only (as a case written with plain numbers), its
        ``holds_for_all_parameters`` None."""
        return replace(self, free={})

    def with_free_parameters(self) -> Case | None:
        """The same case with every non-zero parameter kept as a symbol (zero ones stay 0:
        they switch terms off), or None when no parameter is free."""
        if not self.free:
            return None
        forms = ("inertia", "V", "l", "mu", "integral", "level")
        return replace(self, free={}, **{name: self.free[name] for name in forms})

    @property
    def I1(self) -> sp.Expr:
        """Jacobi's integral ``1/2 omega I omega + V``."""
        return (
            sp.Rational(1, 2)
            * sum((m * w**2 for m, w in zip(self.inertia, OMEGA, strict=True)), start=sp.Integer(0))
            + self.V
        )

    @property
    def l_dot_gamma(self) -> sp.Expr:
        """``l . gamma`` (with ``mu`` given: an ``f`` with ``gamma x (mu - grad f) = 0``)."""
        if self.l is not None:
            return self.l.dot(GAMMA)
        return potential_of_mu(self.mu, "case.mu")

    @property
    def I3(self) -> sp.Expr:
        """The cyclic integral ``(I omega + l) . gamma``."""
        momentum = sum(
            (m * w * x for m, w, x in zip(self.inertia, OMEGA, GAMMA, strict=True)),
            start=sp.Integer(0),
        )
        return momentum + self.l_dot_gamma

    def singular(self) -> list[str]:
        """Where the case's expressions are singular: ``"<factor> = 0"`` for each factor of
        a denominator of V, l (or mu) and F, and of r solved from the level."""
        parts = [self.V, self.integral, *(self.l if self.l is not None else self.mu)]
        factors: set[sp.Expr] = set()
        for expr in parts:
            _, denominator = sp.fraction(sp.together(expr))
            if len(sp.Add.make_args(sp.expand(denominator))) > MAX_FACTORED_TERMS:
                factors.add(denominator)  # factoring a large one costs more than it tells
                continue
            factors |= {f for f, _ in sp.factor_list(denominator)[1]}
        found = sorted(f"{sp.sstr(f)} = 0" for f in factors)
        if self.level is not None:
            found.append("gamma3 = 0 (r from the level I3 = const)")
        return found


def _expression(
    value: Any,
    where: str,
    names: Mapping[str, sp.Symbol] | None,
    known: Mapping[str, sp.Rational] | None,
    sizes: dict[str, int] | None,
) -> sp.Expr:
    """An expression of the file, parsed with its bounds (``known``: the parameters' values);
    the bound on its expanded terms goes into ``sizes[where]``."""
    parsed = parse_bounded(value, where, names, known)
    if sizes is not None:
        sizes[where] = parsed.terms
    return parsed.expression


def _exact_number(
    value: Any,
    where: str,
    names: Mapping[str, sp.Symbol] | None = None,
    known: Mapping[str, sp.Rational] | None = None,
    sizes: dict[str, int] | None = None,
) -> Any:
    """A number of the file as an exact rational: an int, a float as its decimal text
    (``0.1 -> 1/10``), or a string expression of numbers (and ``names``, ``known`` their
    values for the bound on its coefficients; the bound on its expanded terms goes into
    ``sizes[where]``)."""
    if isinstance(value, str):
        return _expression(value, where, names, known, sizes)
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise input_error(where, "a number or an expression in a string", value)
    check_input_number(value, where)
    exact = Fraction(repr(value)) if isinstance(value, float) else Fraction(value)
    return sp.Rational(exact.numerator, exact.denominator)


_UNDEFINED = (sp.zoo, sp.nan, sp.oo, -sp.oo)


def _defined(written: sp.Expr, value: sp.Expr, values: Mapping[sp.Symbol, Any], at: str) -> Any:
    """``value`` (``written`` with the parameters' ``values`` substituted) when no term of it
    became infinite or undefined; else one line naming the key and the parameters whose
    values make a denominator vanish (sympy's ``zoo``, ``nan`` never reach the user)."""
    if not value.has(*_UNDEFINED):
        return value
    culprits = sorted(
        str(symbol)
        for symbol in written.free_symbols & set(values)
        if written.xreplace({symbol: values[symbol]}).has(*_UNDEFINED)
    )
    if not culprits:  # only together (1/(a - b) with a = b): the denominator's parameters
        denominators = {sp.denom(term) for term in sp.preorder_traversal(written)}
        used = set().union(*(d.free_symbols for d in denominators)) & set(values)
        culprits = sorted(str(symbol) for symbol in used or written.free_symbols & set(values))
    given = ", ".join(f"{name} = {values[parameter_symbol(name)]}" for name in culprits)
    raise InputError(
        f"{at}: becomes infinite or undefined with {given} (a denominator vanishes at "
        f"{'these values' if len(culprits) > 1 else 'this value'})"
    )


def _constant(expr: sp.Expr, where: str) -> sp.Rational:
    if not isinstance(expr, sp.Rational):
        raise input_error(where, "a number (it may use only the declared parameters)", str(expr))
    return expr


def _only_gamma(expr: sp.Expr, where: str) -> sp.Expr:
    moving = sorted(str(s) for s in expr.free_symbols & {p, q, r})
    if moving:
        raise InputError(f"{where}: depends on {moving[0]} (V, l and mu are functions of gamma)")
    return expr


def _vector(
    value: Any,
    where: str,
    names: Mapping[str, sp.Symbol],
    known: Mapping[str, sp.Rational],
    sizes: dict[str, int],
) -> list[sp.Expr]:
    if not isinstance(value, list) or len(value) != 3:
        raise input_error(where, "a list of 3 expressions", value)
    return [
        _only_gamma(_exact_number(item, f"{where}[{i}]", names, known, sizes), f"{where}[{i}]")
        for i, item in enumerate(value)
    ]


def _parameters(table: Any, where: str) -> tuple[dict[str, sp.Symbol], dict[sp.Symbol, Any]]:
    if table is None:
        return {}, {}
    if not isinstance(table, Mapping):
        raise input_error(where, "a table of name = number", table)
    if len(table) > MAX_PARAMETERS:
        raise input_error(where, f"at most {MAX_PARAMETERS} parameters", f"{len(table)}")
    symbols: dict[str, sp.Symbol] = {}
    values: dict[sp.Symbol, Any] = {}
    for name, value in table.items():
        reason = parameter_name_error(name)
        if reason:
            raise InputError(f"{where}.{name}: {reason}")
        symbol = parameter_symbol(name)
        symbols[name] = symbol
        values[symbol] = _constant(_exact_number(value, f"{where}.{name}"), f"{where}.{name}")
    return symbols, values


def sphere_remainder(expr: sp.Expr) -> sp.Poly:
    """The normal form of the polynomial ``expr`` on ``|gamma| = 1``: its remainder by
    ``|gamma|^2 - 1``, monic in gamma1 (so of degree <= 1 in gamma1), as a polynomial in the
    state ``gamma1 gamma2 gamma3 p q r`` whose coefficients may hold other symbols (the
    sphere normal form of :func:`chargedesign.model.certificate.sphere_normal_form`, for a
    sympy expression). It is zero iff ``expr`` vanishes on the whole sphere.

    Raises
    ------
    sympy.PolynomialError
        ``expr`` is not a polynomial in the state (a denominator in gamma).
    """
    return sp.Poly(sp.expand(expr), g1, g2, g3, p, q, r).rem(_SPHERE)


def vanishes_on_sphere(expr: sp.Expr) -> bool:
    """Whether the polynomial ``expr`` (in the state) vanishes on the whole unit sphere
    (:func:`sphere_remainder` is zero)."""
    return bool(sphere_remainder(expr).is_zero)


def _not_on_whole_sphere(expr: sp.Expr, where: str) -> None:
    """Refuse an expression whose denominator vanishes on the whole unit sphere."""
    _, denominator = sp.fraction(sp.together(expr))
    if vanishes_on_sphere(denominator):
        raise InputError(f"{where}: its denominator vanishes on the whole sphere |gamma| = 1")


def case_from_table(table: Any, where: str = "case") -> Case:
    """Validate a ``[case]`` table (see docs/contract.md) into a :class:`Case`.

    Raises
    ------
    InputError
        One line naming the key and the reason, before any certificate work.
    """
    if not isinstance(table, Mapping):
        raise input_error(where, "a table", table)
    check_keys(table, CASE_KEYS, where)
    for key in ("name", "inertia", "V", "integral"):
        if key not in table:
            raise InputError(f"{where}.{key}: missing (a case needs name, inertia, V, integral)")
    name = table["name"]
    if not isinstance(name, str) or not name.strip() or len(name) > 80:
        raise input_error(f"{where}.name", "a name of 1 to 80 characters", name)
    texts: dict[str, Any] = {}
    names, values = _parameters(table.get("parameters"), f"{where}.parameters")
    known = {str(symbol): value for symbol, value in values.items()}
    sizes: dict[str, int] = {}
    zeros = {symbol: value for symbol, value in values.items() if value == 0}
    free: dict[str, Any] = {}

    def exact(expr: sp.Expr, at: str, key: str | None = None) -> sp.Expr:
        if key is not None:
            free[key] = _defined(expr, expr.xreplace(zeros), zeros, at)
        return _defined(expr, expr.xreplace(values), values, at)

    inertia_in = table["inertia"]
    if not isinstance(inertia_in, list) or len(inertia_in) != 3:
        raise input_error(f"{where}.inertia", "a list [A, B, C] of 3 numbers", inertia_in)
    inertia = []
    free_inertia = []
    for i, item in enumerate(inertia_in):
        key = f"{where}.inertia[{i}]"
        moment = _constant(exact(_exact_number(item, key, names, known), key, "moment"), key)
        if moment <= 0:
            raise input_error(key, "a moment of inertia > 0", str(moment))
        inertia.append(moment)
        free_inertia.append(free.pop("moment"))
    free["inertia"] = tuple(free_inertia)
    V = exact(
        _only_gamma(_expression(table["V"], f"{where}.V", names, known, sizes), f"{where}.V"),
        f"{where}.V",
        "V",
    )
    texts["V"] = table["V"]
    if "l" in table and "mu" in table:
        raise InputError(f"{where}: give l or mu, not both")
    l_vec: sp.Matrix | None
    if "mu" in table:
        l_vec = None
        components = _vector(table["mu"], f"{where}.mu", names, known, sizes)
        mu = sp.Matrix([exact(e, f"{where}.mu[{i}]") for i, e in enumerate(components)])
        free["l"], free["mu"] = None, sp.Matrix([e.xreplace(zeros) for e in components])
        texts["mu"] = list(table["mu"])
    else:
        given = table.get("l", ["0", "0", "0"])
        components = _vector(given, f"{where}.l", names, known, sizes)
        l_vec = sp.Matrix([exact(e, f"{where}.l[{i}]") for i, e in enumerate(components)])
        mu = mu_from_l(l_vec)
        free["l"] = sp.Matrix([e.xreplace(zeros) for e in components])
        # with no free parameter the free form is the case itself (and is not kept)
        free["mu"] = mu_from_l(free["l"]) if len(values) > len(zeros) else mu
        texts["l"] = list(given)
    integral = exact(
        _expression(table["integral"], f"{where}.integral", names, known, sizes),
        f"{where}.integral",
        "integral",
    )
    texts["integral"] = table["integral"]
    level_in = table.get("level", "general")
    level: sp.Rational | None
    free["level"] = None
    if level_in != "general":
        key = f"{where}.level"
        if isinstance(level_in, str) and not level_in.strip():
            raise input_error(key, '"general" or a number', level_in)
        level = _constant(exact(_exact_number(level_in, key, names, known), key, "level"), key)
        if l_vec is None:
            raise InputError(
                f"{key}: a claim on a level needs l (mu fixes I3 only up to a constant)"
            )
    else:
        level = None
    check_expansion(sizes, where)
    for key, text in (("source", table.get("source", "")), ("note", table.get("note", ""))):
        if not isinstance(text, str) or len(text) > 2000:
            raise input_error(f"{where}.{key}", "a text of at most 2000 characters", text)
    case = Case(
        name=name,
        inertia=(inertia[0], inertia[1], inertia[2]),
        V=V,
        l=l_vec,
        mu=mu,
        integral=integral,
        level=level,
        parameters={str(s): v for s, v in values.items()},
        texts=texts,
        source=table.get("source", ""),
        note=table.get("note", ""),
        free=free if len(values) > len(zeros) else {},
    )
    _not_on_whole_sphere(V, f"{where}.V")
    _not_on_whole_sphere(integral, f"{where}.integral")
    for i, component in enumerate(l_vec if l_vec is not None else mu):
        _not_on_whole_sphere(component, f"{where}.{'l' if l_vec is not None else 'mu'}[{i}]")
    if l_vec is None:
        potential_of_mu(mu, f"{where}.mu")  # refuses a mu of no (mu) form, before the work
    return case


def read_case(path: str | os.PathLike[str]) -> Case:
    """The ``[case]`` table of a TOML file, validated (one-line errors)."""
    data = read_toml_file(path, "case file")
    if "case" not in data:
        raise InputError(f"{path}: no [case] table (a case file carries [case]: docs/workbench.md)")
    if "parameters" in data:
        raise InputError(
            f"{path}: [parameters] and [case] together (a case file carries [case] instead "
            "of the theorem's [parameters])"
        )
    return case_from_table(data["case"], "case")


def potential_of_mu(mu: sp.Matrix, where: str) -> sp.Expr:
    """A polynomial ``f(gamma)`` with ``gamma x (mu - grad f) = 0`` (``f = l . gamma`` for any
    ``l`` giving ``mu`` by (mu)): the gamma part of I3. Its constant is 0; ``f`` is fixed up
    to a function of ``|gamma|^2`` (a constant on the sphere).

    Raises
    ------
    InputError
        ``mu`` is rational (give ``l``) or of no (mu) form (then (ep) has no cyclic integral).
    """
    for i, component in enumerate(mu):
        if not component.is_polynomial(g1, g2, g3):
            raise InputError(f"{where}[{i}]: a rational mu needs l instead (give l)")
    degree = max((sp.Poly(c, g1, g2, g3).total_degree() for c in mu if c != 0), default=0)
    if degree > MAX_MU_DEGREE:
        raise InputError(
            f"{where}: degree {degree} > {MAX_MU_DEGREE}: give l instead (I3 from mu needs an "
            "ansatz whose size grows with the cube of the degree)"
        )
    monomials = [
        g1**i * g2**j * g3**k
        for total in range(1, degree + 2)
        for i in range(total + 1)
        for j in range(total + 1 - i)
        for k in (total - i - j,)
    ]
    unknowns = sp.symbols(f"f0:{len(monomials)}")
    f = sum((a * m for a, m in zip(unknowns, monomials, strict=True)), start=sp.Integer(0))
    residual = GAMMA.cross(mu - sp.Matrix([sp.diff(f, x) for x in GAMMA]))
    equations = []
    for component in residual:
        equations += sp.Poly(sp.expand(component), g1, g2, g3).coeffs()
    solution = sp.linsolve(equations, unknowns)
    if not solution:
        raise InputError(f"{where}: not of the form (mu) of any l (then I3 is no integral)")
    (values,) = solution
    free = dict.fromkeys(unknowns, 0)
    return sp.expand(
        f.xreplace({u: sp.sympify(v).xreplace(free) for u, v in zip(unknowns, values, strict=True)})
    )


#: largest work estimate of one certificate: the integral's terms (numerator times
#: denominator) times the largest right-hand side's terms times (1 + the integral's degree in
#: r). Measured here (2 shared cores): the theorem's case estimates 9.3e3 (0.5 s); its I4
#: times (1 + p + q)^3 7.9e4 (35 s), times (1 + p + q + r)^2 1.3e5 (76 s, refused)
MAX_CERTIFICATE_WORK = 100_000


def check_certificate_work(name: str, work: float) -> None:
    """Refuse, before the work, a certificate whose estimated ``work`` on the function
    ``name`` passes :data:`MAX_CERTIFICATE_WORK`."""
    if work > MAX_CERTIFICATE_WORK:
        raise InputError(
            f"case: the certificate's work on {name} is estimated at {work:.1e} (limit "
            f"{MAX_CERTIFICATE_WORK:.0e}, about a minute); simplify the case (fewer terms, "
            "lower degree)"
        )


def check_expansion(sizes: Mapping[str, int], where: str = "case") -> None:
    """Refuse, before anything is expanded, a case whose expansion alone would cost the
    certificate's whole budget: ``sizes`` are the parser's bounds on the expanded terms of
    V, l (or mu) and the integral. The right-hand sides of (ep) hold about as many terms as
    V and l together, and the energy's derivative costs its terms times theirs (the model's
    own estimate, :data:`MAX_CERTIFICATE_WORK`, needs the expansion: 50 s for
    ``(gamma1+gamma2+gamma3+1)**24``)."""
    sides = sum(n for key, n in sizes.items() if not key.endswith(".integral"))
    integral = sizes.get(f"{where}.integral", 1)
    work = (sides + 3) * max(sides, integral)
    if work > MAX_CERTIFICATE_WORK:
        raise InputError(
            f"{where}: V, l and the integral may expand to {sides} and {integral} terms: the "
            f"certificate's work is estimated at {work:.1e} (limit {MAX_CERTIFICATE_WORK:.0e},"
            " about a minute); simplify the case (fewer terms, lower degree)"
        )


def check_rational_points(name: str, found: int) -> None:
    """Refuse case ``name`` when no rational point where it is defined was ``found``."""
    if found == 0:
        raise InputError(f"case {name}: no rational point where the case is defined")


def check_denominator_on_level(vanishes: bool) -> None:
    """Refuse an integral whose denominator ``vanishes`` on the whole claimed level."""
    if vanishes:
        raise InputError("case.integral: its denominator vanishes on the whole level")


__all__ = [
    "GAMMA",
    "MAX_CERTIFICATE_WORK",
    "MAX_FACTORED_TERMS",
    "MAX_MU_DEGREE",
    "MAX_PARAMETERS",
    "OMEGA",
    "Case",
    "case_from_table",
    "check_certificate_work",
    "check_denominator_on_level",
    "check_expansion",
    "check_rational_points",
    "mu_from_l",
    "potential_of_mu",
    "read_case",
    "sphere_remainder",
    "vanishes_on_sphere",
]
