"""One validation helper for every array or number a user hands in.

Every error uses the same template, ``"<name>: expected <what>, got <received>"``, raised as
:class:`~chargedesign.errors.InputError` (a ``ValueError``).

The number rules (docs/reliability.md):

- a number is a real ``int`` or ``float`` (numpy's too): never a ``bool``, never complex,
  never a string; arrays of bool or complex dtype are refused, not coerced;
- it is finite; an integer too large for a float64 is refused by its size before any
  conversion;
- a number read from a file or the command line (:func:`check_input_number`,
  :func:`check_input_array`, :func:`check_tree`) lies within the supported range:
  ``|x| <= MAX_MAGNITUDE``, and a non-zero ``|x| >= MIN_MAGNITUDE`` where a tiny value would
  be divided by; the theorem's parameters have the narrower ranges of
  :data:`PARAMETER_RANGES`, the scales the stability suite
  (tests/designer/test_stability.py) covers.
  Outside it the one-line error states the range and suggests rescaling the units.

The checks here are the ones several modules share; a check one module alone makes, or one
that needs a figure a stage computes, sits at that module's or stage's entry instead
(docs/architecture.md).
"""

from __future__ import annotations

import math
import re
from collections.abc import Iterator, Mapping, Sequence
from fractions import Fraction
from typing import Any

import numpy as np

from chargedesign.errors import InputError
from chargedesign.formatting import PLAIN, fmt
from chargedesign.limits import (
    MAX_DESIGN_ELEMENTS,
    MAX_FIELD_DEGREE,
)
from chargedesign.vocabulary import FIELD_KINDS, MATERIAL_ERROR_KEYS

#: largest magnitude of any number read from a file or the command line (SI units): beyond it
#: a quantity is a units mistake, and eighth powers (moments up to order 8) would overflow
MAX_MAGNITUDE = 1e30
#: smallest non-zero magnitude of a scene's numbers (sizes, field coefficients, options):
#: below it reciprocals overflow. Element values in design.json have no lower bound.
MIN_MAGNITUDE = 1e-30
#: supported magnitudes of the theorem's parameters (zero is always allowed, C must be > 0):
#: the stability suite covers each unit (mass, time, length, tesla) scaled by 1e-8..1e8, so
#: C (kg m^2, mass) in 1e-8..1e8, n, K (1/s) in 1e-8..1e8, kappa, lambda, rho (1/s^2) in
#: 1e-16..1e16; c and d (dimensionless) up to 1e8
PARAMETER_RANGES: dict[str, tuple[float, float]] = {
    "C": (1e-8, 1e8),
    "c": (0.0, 1e8),
    "d": (0.0, 1e8),
    "n": (1e-8, 1e8),
    "K": (1e-8, 1e8),
    "kappa": (1e-16, 1e16),
    "lambda": (1e-16, 1e16),
    "rho": (1e-16, 1e16),
}
#: integers with more decimal digits than this are refused before conversion
_MAX_INT_DIGITS = 40
_RESCALE = "rescale the units (e.g. mm or g instead of m or kg) so the numbers fall inside it"


def _describe(value: Any) -> str:
    if isinstance(value, np.ndarray):
        return f"array of shape {value.shape} and dtype {value.dtype}"
    if isinstance(value, int) and not isinstance(value, bool) and abs(value) > 10**20:
        return f"an integer of {len(str(abs(value)))} digits"
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."


def input_error(name: str, expected: str, received: Any) -> InputError:
    """Build the one error message template: names the input and what was received."""
    return InputError(f"{name}: expected {expected}, got {_describe(received)}")


#: the letters of a moment key ("xxz": x^2 z), in their sorted order
MOMENT_AXES = "xyz"


def parse_moment_key(key: str) -> tuple[int, int, int]:
    """``"xxz" -> (2, 0, 1)``; the letters must be sorted (x before y before z)."""
    if any(ch not in MOMENT_AXES for ch in key) or list(key) != sorted(key):
        raise input_error("moment key", "sorted axis letters such as 'xxz'", key)
    return (key.count("x"), key.count("y"), key.count("z"))


def _is_real_scalar(value: Any) -> bool:
    return not isinstance(value, (bool, np.bool_)) and isinstance(
        value, (int, float, np.integer, np.floating)
    )


def _int_too_large(value: Any) -> bool:
    """True for a Python/numpy integer whose size a float64 cannot hold (checked exactly)."""
    return isinstance(value, (int, np.integer)) and abs(int(value)) > 2**1023


def as_finite_float(value: Any, name: str, *, positive: bool = False) -> float:
    """Return ``value`` as a finite float (bools, complex numbers and strings are rejected).

    Integers too large for a float64 are refused by their size, before any conversion.
    """
    if not _is_real_scalar(value):
        raise input_error(name, "a real number", value)
    if _int_too_large(value):
        raise input_error(name, "a finite number (this integer overflows a float)", value)
    out = float(value)
    if not math.isfinite(out):
        raise input_error(name, "a finite number", value)
    if positive and out <= 0.0:
        raise input_error(name, "a number > 0", value)
    return out


def _leaves(value: Any) -> Iterator[Any]:
    """The scalars of nested lists/tuples, without recursion (arrays yield themselves)."""
    stack = [value]
    while stack:
        item = stack.pop()
        if isinstance(item, (list, tuple)):
            stack.extend(item)
        else:
            yield item


def _check_array_types(value: Any, name: str, shape: Sequence[int | None]) -> None:
    """Refuse bools, complex numbers, strings and huge integers before float conversion."""
    if isinstance(value, np.ndarray):
        if value.dtype.kind in "iuf":
            return
        if value.dtype.kind == "O":
            for item in value.ravel():
                _check_leaf(item, value, name, shape)
            return
        raise input_error(name, f"real numbers of shape {_shape_text(shape)}", value)
    if isinstance(value, (list, tuple)):
        for item in _leaves(value):
            _check_leaf(item, value, name, shape)
        return
    _check_leaf(value, value, name, shape)


def _check_leaf(item: Any, whole: Any, name: str, shape: Sequence[int | None]) -> None:
    if isinstance(item, np.ndarray):
        _check_array_types(item, name, shape)
        return
    if not _is_real_scalar(item):
        raise input_error(
            name, f"real numbers of shape {_shape_text(shape)} (not {type(item).__name__})", item
        )
    if _int_too_large(item):
        raise input_error(name, "finite numbers (an integer overflows a float)", item)


def as_array(value: Any, name: str, shape: Sequence[int | None]) -> np.ndarray:
    """Return ``value`` as a finite float64 array of the given shape (None: any length).

    Bool and complex inputs (arrays of those dtypes, or such items in lists) are refused
    rather than coerced. Shape and finiteness are checked before any reshaping, so a wrong
    input is named as it was received.
    """
    _check_array_types(value, name, shape)
    try:
        arr = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError, OverflowError) as exc:
        raise input_error(name, f"numbers of shape {_shape_text(shape)}", value) from exc
    if arr.ndim != len(shape) or any(
        s is not None and a != s for a, s in zip(arr.shape, shape, strict=True)
    ):
        raise input_error(name, f"shape {_shape_text(shape)}", arr)
    if not np.all(np.isfinite(arr)):
        raise input_error(name, "finite numbers (no NaN or inf)", arr)
    return arr


def as_points(value: Any, name: str = "positions", n: int | None = None) -> np.ndarray:
    """Points as ``ndarray, shape (n, 3)``, float64, finite. An empty list gives shape (0, 3)."""
    if isinstance(value, (list, tuple)) and len(value) == 0:
        value = np.zeros((0, 3))
    return as_array(value, name, (n, 3))


def as_weights(value: Any, name: str = "values", n: int | None = None) -> np.ndarray:
    """Weights as ``ndarray, shape (n,)``, float64, finite."""
    return as_array(value, name, (n,))


def check_keys(table: Mapping[str, Any], allowed: Sequence[str], where: str) -> None:
    """One-line error naming ``where.key`` for the first unknown key (sorted) of ``table``."""
    unknown = sorted(set(table) - set(allowed))
    if unknown:
        raise input_error(f"{where}.{unknown[0]}", "one of " + ", ".join(allowed), unknown[0])


def check_integer(
    value: Any, name: str, *, minimum: int, none_allowed: bool = False, expected: str = ""
) -> None:
    """Refuse anything but an integer >= ``minimum`` (or None, when allowed) in one line."""
    if value is None and none_allowed:
        return
    if (
        isinstance(value, (bool, np.bool_))
        or not isinstance(value, (int, np.integer))
        or value < minimum
    ):
        default = f"an integer >= {minimum}" + (" or None" if none_allowed else "")
        raise input_error(name, expected or default, value)


def check_instance(value: Any, kind: type | tuple[type, ...], name: str, expected: str) -> None:
    """Refuse a value of the wrong type (an argument of the Python API) in one line."""
    if not isinstance(value, kind):
        raise input_error(name, expected, value)


def check_choice(value: Any, choices: Sequence[Any], name: str) -> None:
    """Refuse a value outside ``choices`` in one line (``one of a, b, c``)."""
    if value not in choices:
        raise input_error(name, "one of " + ", ".join(str(c) for c in choices), value)


# --------------------------------------------------------------------- the input range


def _range_error(name: str, value: Any, lo: float, hi: float) -> InputError:
    low = (
        f"0 or {fmt(lo, PLAIN)} <= |x| <= {fmt(hi, PLAIN)}"
        if lo > 0
        else f"|x| <= {fmt(hi, PLAIN)}"
    )
    return InputError(
        f"{name}: {_describe(value)} is outside the supported range ({low}); {_RESCALE}"
    )


def check_input_number(
    value: Any, name: str, *, lo: float = MIN_MAGNITUDE, hi: float = MAX_MAGNITUDE
) -> float:
    """A number read from a file or the command line: real, finite and within the range.

    ``lo`` is the smallest non-zero magnitude (0: no lower bound), ``hi`` the largest.
    """
    out = as_finite_float(value, name)
    size = abs(out)
    if size > hi or (0.0 < size < lo):
        raise _range_error(name, value, lo, hi)
    return out


#: largest written exponent of a decimal literal (``1e99``): with at most
#: :data:`MAX_LITERAL_DIGITS` digits of mantissa, every number of the supported range has one
MAX_LITERAL_EXPONENT = 99
#: most digits of the mantissa of one decimal literal
MAX_LITERAL_DIGITS = 40
#: a decimal literal as written (sign, digits, fraction digits, exponent sign and digits)
DECIMAL_PATTERN = re.compile(
    r"([+-]?)(?=\.?\d)(\d(?:_?\d)*)?(?:\.(\d(?:_?\d)*)?)?(?:[eE]([+-]?)(\d(?:_?\d)*))?\Z"
)


def exact_decimal(
    text: str,
    name: str,
    *,
    fraction: bool = False,
    lo: float = MIN_MAGNITUDE,
    hi: float = MAX_MAGNITUDE,
    at: str = "",
) -> Fraction:
    """A decimal literal (``2.5e-3``; with ``fraction``, also ``P/Q`` of two of them) read
    exactly, its size checked on the text before any number is built: at most
    :data:`MAX_LITERAL_DIGITS` digits of mantissa, a written exponent of at most
    :data:`MAX_LITERAL_EXPONENT` in size, and a non-zero magnitude within ``lo .. hi``
    (``1e99999999`` would otherwise build a number of 10^8 digits, and ``int()`` of more than
    4300 digits fails).

    Raises
    ------
    InputError
        One line naming ``name``, the text (shortened) and the bound.
    """
    shown = text.strip()
    shown = shown if len(shown) <= 30 else shown[:27] + "..."
    parts = text.strip().split("/") if fraction else [text.strip()]
    if len(parts) > 2:
        raise InputError(f"{name}: expected a number or a fraction P/Q, got {shown!r}")
    values = [_decimal_part(part, name, shown, fraction, at) for part in parts]
    if len(values) == 2 and values[1] == 0:
        raise InputError(f"{name}: a fraction with denominator zero, got {shown!r}")
    value = values[0] / values[1] if len(values) == 2 else values[0]
    # the bounds as written (the float 1e-30 lies above the exact 10^-30)
    if value != 0 and not Fraction(repr(lo)) <= abs(value) <= Fraction(repr(hi)):
        raise InputError(
            f"{name}: the number `{shown}`{at} is outside {fmt(lo, PLAIN)}..{fmt(hi, PLAIN)} in "
            f"magnitude; {_RESCALE}"
        )
    return value


def _decimal_part(part: str, name: str, shown: str, fraction: bool, at: str) -> Fraction:
    match = DECIMAL_PATTERN.match(part.strip())
    if match is None:
        what = "a number or a fraction P/Q" if fraction else "a decimal number"
        raise InputError(f"{name}: expected {what}, got {shown!r}")
    sign, whole, decimals, exponent_sign, exponent = match.groups()
    whole = (whole or "").replace("_", "")
    decimals = (decimals or "").replace("_", "")
    digits = (whole + decimals).lstrip("0")
    if (
        len(digits.rstrip("0")) > MAX_LITERAL_DIGITS
        or len(whole + decimals) > 4 * MAX_LITERAL_DIGITS
    ):
        raise InputError(
            f"{name}: the number `{shown}`{at} has more than {MAX_LITERAL_DIGITS} digits"
        )
    written = (exponent or "0").replace("_", "").lstrip("0") or "0"
    if len(written) > len(str(MAX_LITERAL_EXPONENT)) or int(written) > MAX_LITERAL_EXPONENT:
        raise InputError(
            f"{name}: the exponent of `{shown}`{at} is larger than {MAX_LITERAL_EXPONENT} in size "
            "(outside the supported range of numbers)"
        )
    if not digits:
        return Fraction(0)
    power = (-1 if exponent_sign == "-" else 1) * int(written) - len(decimals)
    mantissa = int(digits) * (-1 if sign == "-" else 1)
    return Fraction(mantissa * 10**power) if power >= 0 else Fraction(mantissa, 10**-power)


def check_input_array(
    value: Any, name: str, *, lo: float = 0.0, hi: float = MAX_MAGNITUDE
) -> np.ndarray:
    """Numbers (any shape) read from a file: real, finite and within the range."""
    ndim = value.ndim if isinstance(value, np.ndarray) else _list_ndim(value)
    arr = as_array(value, name, (None,) * ndim)
    size = np.abs(arr)
    bad = (size > hi) | ((size > 0) & (size < lo))
    if np.any(bad):
        index = np.unravel_index(int(np.argmax(bad)), arr.shape)
        where = "".join(f"[{i}]" for i in index)
        raise _range_error(f"{name}{where}", float(arr[index]), lo, hi)
    return arr


def _list_ndim(value: Any) -> int:
    ndim = 0
    while isinstance(value, (list, tuple)):
        ndim += 1
        if not value:
            break
        value = value[0]
    return ndim


def check_parameters_range(data: Any, where: str = "parameters") -> None:
    """The theorem's parameters (a mapping as read from a file) within :data:`PARAMETER_RANGES`.

    Unknown names and wrong types are left to :class:`~chargedesign.params.Parameters`.
    """
    if not isinstance(data, dict):
        return
    for key, value in data.items():
        bounds = PARAMETER_RANGES.get(key)
        if bounds is None or not _is_real_scalar(value):
            continue
        check_input_number(value, f"{where}.{key}", lo=bounds[0], hi=bounds[1])


def check_tree(
    data: Any,
    where: str,
    *,
    lo: float = MIN_MAGNITUDE,
    hi: float = MAX_MAGNITUDE,
    skip: Sequence[str] = (),
) -> None:
    """Every number in a parsed TOML/JSON tree: real (no bool where a number is), finite, in range.

    Walks without recursion; ``skip`` names top-level keys left alone (free-form extras).
    Bools and strings are left to the keys' own validators (they may be flags or names).
    """
    stack: list[tuple[str, Any]] = [(where, data)]
    while stack:
        path, item = stack.pop()
        if isinstance(item, dict):
            for key, value in item.items():
                if path == where and key in skip:
                    continue
                stack.append((f"{path}.{key}" if path else str(key), value))
        elif isinstance(item, (list, tuple)):
            if not _check_number_list(item, path, lo, hi):
                for i, value in enumerate(item):
                    stack.append((f"{path}[{i}]", value))
        elif isinstance(item, np.ndarray):
            check_input_array(item, path, lo=lo, hi=hi)
        elif _is_real_scalar(item):
            check_input_number(item, path, lo=lo, hi=hi)
        elif isinstance(item, complex):
            raise input_error(path, "a real number", item)


def _check_number_list(item: Any, path: str, lo: float, hi: float) -> bool:
    """Range-check a (nested) list of plain numbers at once; False when it holds other things."""
    leaves = list(_leaves(item))
    if not all(
        type(x) in (int, float) or (_is_real_scalar(x) and not isinstance(x, np.ndarray))
        for x in leaves
    ):
        return False
    if any(type(x) is int and abs(x) > 2**1023 for x in leaves):
        return False  # named item by item
    arr = np.asarray(leaves, dtype=np.float64)
    size = np.abs(arr)
    bad = ~np.isfinite(arr) | (size > hi) | ((size > 0) & (size < lo))
    if np.any(bad):
        return False  # named item by item
    return True


def _shape_text(shape: Sequence[int | None]) -> str:
    return (
        "("
        + ", ".join("n" if s is None else str(s) for s in shape)
        + ("," if len(shape) == 1 else "")
        + ")"
    )


def check_field_degree(coefficients: Any, name: str) -> None:
    """Refuse a ``legendre`` list longer than :data:`~chargedesign.limits.MAX_FIELD_DEGREE`."""
    if isinstance(coefficients, (list, tuple, np.ndarray)) and len(coefficients) > MAX_FIELD_DEGREE:
        raise InputError(
            f"{name}: expected a field of degree <= {MAX_FIELD_DEGREE}, got "
            f"{len(coefficients)} coefficients"
        )


#: keys of one field in design.json (what body.py reads and writes)
DESIGN_FIELD_KEYS = ("legendre",)


def check_design_numbers(data: Any, where: str, *, required: Sequence[str] = ()) -> None:
    """The whole of a design.json mapping, before the body is built from it.

    Parameters within :data:`PARAMETER_RANGES`; field coefficients, element arrays and
    continuous bodies real, finite and ``|x| <= MAX_MAGNITUDE`` (no lower bound: a solver's
    tiny weights are legitimate); fields of degree <= ``MAX_FIELD_DEGREE`` with no key but
    ``legendre``; ``realises`` a list of names; at most
    :data:`~chargedesign.limits.MAX_DESIGN_ELEMENTS` elements (counted before any is
    converted); ``materials`` an object, which a physical design (one with a ``medium``)
    must fill. ``required`` names keys a verdict needs (``check`` needs ``realises``: a file
    without it would claim nothing and pass). Other extra keys are free-form (the JSON
    reader already refused NaN and inf).
    """
    if not isinstance(data, dict):
        return
    for key in required:
        if key not in data:
            raise InputError(
                f"{where}: missing key {key!r}"
                + (
                    " (the quantities the body claims: a list among mu, V, inertia; [] claims "
                    "nothing); without it there is nothing to verify"
                    if key == "realises"
                    else ""
                )
            )
    _check_element_count(data, where)
    check_parameters_range(data.get("parameters"), f"{where}.parameters")
    fields = data.get("fields")
    if isinstance(fields, dict):
        for kind, spec in fields.items():
            if kind not in FIELD_KINDS:
                raise input_error(
                    f"{where}.fields.{kind}", "one of " + ", ".join(FIELD_KINDS), kind
                )
            if isinstance(spec, dict):
                check_keys(spec, DESIGN_FIELD_KEYS, f"{where}.fields.{kind}")
            if isinstance(spec, dict) and "legendre" in spec:
                name = f"{where}.fields.{kind}.legendre"
                check_field_degree(spec["legendre"], name)
                check_tree(spec["legendre"], name, lo=0.0)
    realises = data.get("realises", [])
    if not isinstance(realises, list) or not all(isinstance(r, str) for r in realises):
        raise input_error(f"{where}.realises", "a list of names (mu, V, inertia)", realises)
    if "materials" in data:
        materials = data["materials"]
        if not isinstance(materials, dict):
            raise input_error(f"{where}.materials", "an object role -> material", materials)
        if not materials and data.get("medium") is not None:
            raise InputError(
                f"{where}.materials: empty, but the design has a medium (a physical body): its "
                "parts' materials are what the realism checks read"
            )
    for block in ("charges", "masses", "dipoles", "continuous"):
        if block in data:
            check_tree(data[block], f"{where}.{block}", lo=0.0)
    if "larmor" in data:
        _check_larmor_rate(data["larmor"], data.get("parameters"), f"{where}.larmor")
    if "material_errors" in data:
        # the scene's [tolerance] the design records: read by `tolerance`, so checked by
        # every reader (check passed a file whose chi_relative was 2 or a string)
        check_material_errors(data["material_errors"], f"{where}.material_errors")


def check_material_error(value: Any, name: str) -> float:
    """One relative error of a material property (one standard deviation): in [0, 1)."""
    number = as_finite_float(value, name)
    if not 0.0 <= number < 1.0:
        raise input_error(name, "a relative error in [0, 1)", value)
    return number


def check_material_errors(table: Any, where: str) -> dict[str, float]:
    """A ``[tolerance]`` table (or design.json's ``material_errors``): keys among
    :data:`~chargedesign.vocabulary.MATERIAL_ERROR_KEYS`, each a relative error in [0, 1)
    (None: left out). The checked numbers by key."""
    if not isinstance(table, Mapping):
        raise input_error(where, "a table", table)
    check_keys(table, MATERIAL_ERROR_KEYS, where)
    return {
        key: check_material_error(value, f"{where}.{key}")
        for key, value in table.items()
        if value is not None
    }


def check_material_analysis(where: str, physical: bool, magnetic: Sequence[float]) -> None:
    """What the materials' error analysis needs: a physical design (``[medium]``, its
    materials) in a magnetic field of degree <= 2 (``magnetic``: its Legendre
    coefficients)."""
    if not physical:
        raise InputError(f"{where}: material errors need a physical design (a scene with [medium])")
    if any(magnetic[2:]):
        raise InputError(
            f"{where}: material errors are analysed for magnetic fields of degree <= 2"
        )


def _check_larmor_rate(larmor: Any, parameters: Any, where: str) -> None:
    """design.json's ``larmor.rate`` is the theorem's n (docs/contract.md): within n's range
    and equal to ``parameters.n``. A rate that differs was silently ignored (``charges``) or
    turned the axes at a rate the parameters do not have (``frame``).

    The object's shape and ``reading`` are :class:`~chargedesign.larmor.LarmorReading`'s.
    """
    if not isinstance(larmor, dict) or not _is_real_scalar(larmor.get("rate")):
        return
    lo, hi = PARAMETER_RANGES["n"]
    rate = check_input_number(larmor["rate"], f"{where}.rate", lo=lo, hi=hi)
    n = parameters.get("n", 0.0) if isinstance(parameters, dict) else 0.0
    if _is_real_scalar(n) and not math.isclose(rate, float(n), rel_tol=1e-12, abs_tol=0.0):
        raise InputError(
            f"{where}.rate: {fmt(rate, PLAIN)} differs from parameters.n = {fmt(float(n), PLAIN)};"
            " the rate is the "
            "theorem's n (the turning axes' rate for a frame body): give the same number"
        )


def _check_element_count(data: Any, where: str) -> None:
    """At most :data:`~chargedesign.limits.MAX_DESIGN_ELEMENTS` elements in a design.json
    mapping, counted from the list lengths before any number is converted or checked."""
    total = 0
    for block, key in (("charges", "values"), ("masses", "values"), ("dipoles", "moments")):
        part = data.get(block)
        if isinstance(part, dict) and isinstance(part.get(key), list):
            total += len(part[key])
    if isinstance(data.get("continuous"), list):
        total += len(data["continuous"])
    if total > MAX_DESIGN_ELEMENTS:
        raise InputError(
            f"{where}: {total} elements exceed the cap of {MAX_DESIGN_ELEMENTS} "
            "(chargedesign.limits.MAX_DESIGN_ELEMENTS, the most candidates a design has)"
        )


def motion_rate(parameters: Any, initial: Any = None) -> float:
    """The fastest angular rate of a motion, 1/s, estimated before it runs: the parameters'
    rates n, K and sqrt|kappa|, sqrt|lambda|, sqrt|rho| (1/s^2), and the initial state's
    |omega| (or |p|, |q| on a level). 0 when all vanish."""
    rates = [abs(getattr(parameters, name, 0.0)) for name in ("n", "K")]
    rates += [math.sqrt(abs(getattr(parameters, name, 0.0))) for name in ("kappa", "lam", "rho")]
    if isinstance(initial, Mapping):
        if "omega" in initial:
            rates.append(float(np.linalg.norm(np.asarray(initial["omega"], dtype=float))))
        if "p" in initial or "q" in initial:  # on a level, r is solved later: |(p, q)| alone
            rates.append(math.hypot(float(initial.get("p", 0.0)), float(initial.get("q", 0.0))))
        if "states" in initial:
            states = np.asarray(initial["states"], dtype=float)
            if states.size:
                rates.append(float(np.abs(states[:, :3]).max()))
    return max(rates)


def check_periods(
    t_end: float, parameters: Any, initial: Any, cap: float, option: str, raise_with: str = ""
) -> float:
    """Refuse a run of more than ``cap`` periods of its fastest rate (:func:`motion_rate`):
    ``t_end * rate / (2 pi)``, the work a solver does grows with it. Returns the periods."""
    rate = motion_rate(parameters, initial)
    periods = float(t_end) * rate / (2.0 * math.pi)
    if periods > cap:
        how = f"{raise_with} raises the cap" if raise_with else f"give a shorter {option}"
        fits = f"t_end <= {fmt(cap * 2.0 * math.pi / rate, PLAIN)} s fits"
        own = motion_rate(parameters)  # the parameters' rates alone: the start's excluded
        if own > 0.0 and rate > 10.0 * own:
            fits += f", or a start turning at the body's own rate {fmt(own)} 1/s"
        raise InputError(
            f"{option}: t_end = {fmt(t_end, PLAIN)} s is {fmt(periods)} periods of the body's"
            " fastest rate, "
            f"past the cap of {fmt(cap, PLAIN)} (chargedesign.limits.MAX_PERIODS): {fits}; {how}"
        )
    return periods


def check_error_spreads(model: Any, prefix: str = "--") -> None:
    """A tolerance error model's spreads within their range: a relative one at most 100 %, an
    absolute one within the input range (|x| <= 1e30, docs/reliability.md). ``prefix`` names
    where they came from (``--`` on the command line, ``x.sweep: options.`` in a sweep)."""
    for name in ("position", "charge", "dipole", "mass"):
        spread = getattr(model, name)
        if spread.relative and spread.value > 1.0:
            raise InputError(
                f"{prefix}{name}: expected a relative error of at most 100%, got "
                f"{fmt(100 * spread.value, PLAIN)}%"
            )
        if not spread.relative:
            check_input_number(spread.value, f"{prefix}{name}")
