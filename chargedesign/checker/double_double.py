"""Double-double arithmetic (an unevaluated sum of two doubles, about 106 bits).

Part of :mod:`chargedesign.checker` (see its docstring for the method).
"""

from __future__ import annotations

from typing import Any

import numpy as np

# ------------------------------------------------------------------ accurate evaluation
# Double-double numbers: an unevaluated sum hi + lo of two doubles, |lo| <= ulp(hi) / 2, about
# 106 bits (Dekker 1971; Hida, Li & Bailey's QD library for the add/multiply variants used).
# Products use Dekker's split (numpy has no fused multiply-add); every operation is a fixed
# sequence of numpy ufuncs, so it vectorises like the double kernel, some 20 to 40 times
# slower per pair (bench/check.py measures it).
DEKKER_SPLITTER = 134217729.0  # 2^27 + 1
#: unit roundoff of the double-double operations used (a few times 2^-106; conservative)
DD_UNIT = 2.0**-104


def dekker_split(a: Any) -> tuple[Any, Any]:
    """Dekker's split of ``a`` into a high part of 26 bits and the exact remainder."""
    t = DEKKER_SPLITTER * a
    hi = t - (t - a)
    return hi, a - hi


def two_prod(a: Any, b: Any) -> tuple[Any, Any]:
    """``a * b = p + e`` exactly (Dekker)."""
    p = a * b
    ah, al = dekker_split(a)
    bh, bl = dekker_split(b)
    return p, ((ah * bh - p) + ah * bl + al * bh) + al * bl


def two_sum(a: Any, b: Any) -> tuple[Any, Any]:
    """``a + b = s + e`` exactly (Knuth)."""
    s = a + b
    bb = s - a
    return s, (a - (s - bb)) + (b - bb)


def fast_two_sum(a: Any, b: Any) -> tuple[Any, Any]:
    """``a + b = s + e`` exactly when ``|a| >= |b|``."""
    s = a + b
    return s, b - (s - a)


class DoubleDouble:
    """Double-double array ``hi + lo`` (numpy broadcasting; operands: DoubleDouble, ndarray, float).

    A float or float64 array operand is taken as exact (it is an input of the check).
    """

    __slots__ = ("hi", "lo")
    __array_ufunc__ = None  # ndarray op DoubleDouble defers to DoubleDouble's reflected operators

    def __init__(self, hi: Any, lo: Any = None) -> None:
        self.hi = np.asarray(hi, dtype=np.float64)
        self.lo = np.zeros_like(self.hi) if lo is None else lo

    def __getitem__(self, index: Any) -> DoubleDouble:
        return DoubleDouble(self.hi[index], self.lo[index])

    @property
    def shape(self) -> tuple[int, ...]:
        return tuple(self.hi.shape)

    def __neg__(self) -> DoubleDouble:
        return DoubleDouble(-self.hi, -self.lo)

    def __add__(self, other: Any) -> DoubleDouble:
        if isinstance(other, DoubleDouble):
            s, e = two_sum(self.hi, other.hi)
            t, f = two_sum(self.lo, other.lo)
            s, e = fast_two_sum(s, e + t)
            return DoubleDouble(*fast_two_sum(s, e + f))
        s, e = two_sum(self.hi, other)
        return DoubleDouble(*fast_two_sum(s, e + self.lo))

    __radd__ = __add__

    def __sub__(self, other: Any) -> DoubleDouble:
        return self + (-other)

    def __rsub__(self, other: Any) -> DoubleDouble:
        return (-self) + other

    def __mul__(self, other: Any) -> DoubleDouble:
        if isinstance(other, DoubleDouble):
            p, e = two_prod(self.hi, other.hi)
            return DoubleDouble(*fast_two_sum(p, e + (self.hi * other.lo + self.lo * other.hi)))
        p, e = two_prod(self.hi, other)
        return DoubleDouble(*fast_two_sum(p, e + self.lo * other))

    __rmul__ = __mul__

    def __truediv__(self, other: float) -> DoubleDouble:
        """Division by a double (used for the recurrences' integer denominators)."""
        q1 = self.hi / other
        p, e = two_prod(q1, other)
        s, f = two_sum(self.hi, -p)
        q2 = (s + ((f - e) + self.lo)) / other
        return DoubleDouble(*fast_two_sum(q1, q2))

    def sqrt(self) -> DoubleDouble:
        q = np.sqrt(self.hi)
        p, e = two_prod(q, q)
        return DoubleDouble(*fast_two_sum(q, (((self.hi - p) - e) + self.lo) / (2.0 * q)))

    def total(self, axis: int = -1) -> DoubleDouble:
        """Pairwise double-double sum along ``axis`` (the axis is removed)."""
        x = DoubleDouble(np.moveaxis(self.hi, axis, 0), np.moveaxis(self.lo, axis, 0))
        if x.hi.shape[0] == 0:
            return DoubleDouble(np.zeros(x.hi.shape[1:]))
        while x.hi.shape[0] > 1:
            half = x.hi.shape[0] // 2
            pair = x[:half] + x[half : 2 * half]
            if x.hi.shape[0] % 2:
                pair = DoubleDouble(
                    np.concatenate([pair.hi, x.hi[-1:]]), np.concatenate([pair.lo, x.lo[-1:]])
                )
            x = pair
        return x[0]

    def to_float(self) -> np.ndarray:
        return self.hi + self.lo


def sum_last_axis(x: Any) -> Any:
    """Sum over the last axis (pairwise in both arithmetics)."""
    if isinstance(x, DoubleDouble):
        return x.total(-1)
    return np.sum(x, axis=-1)


def to_float_array(x: Any) -> np.ndarray:
    """A double-double value or array rounded to a float64 array (floats passed through)."""
    return x.to_float() if isinstance(x, DoubleDouble) else np.asarray(x, dtype=np.float64)
