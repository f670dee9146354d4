"""The paper's printed formulas, transcribed from its LaTeX source *only to be audited*.

Nothing else in the package may use these: the model derives its own equations
(:mod:`chargedesign.model.equations`). Each function returns the formula exactly as printed
in Yehia & Elmandouh, "A new integrable problem with a quartic integral in the dynamics of a
rigid body" (theorem, section 2; moment conditions (p6), section 3), in the symbols of
:mod:`chargedesign.model.case`. Where the LaTeX has an unbalanced parenthesis the
transcription closes it at the end of the bracket it sits in; that reading is noted at the
formula.
"""

from __future__ import annotations

import sympy as sp

from chargedesign.model.case import C, K, c, d, g1, g2, g3, kappa, lam, n, p, q, r, rho

half = sp.Rational(1, 2)


def printed_mu() -> sp.Matrix:
    """Formula (muu): the gyroscopic vector as printed, shape (3,)."""
    return C * sp.Matrix(
        [
            2 * K * g3 * (c * g2 - d * g1) - n * g1,
            2 * K * g3 * (d * g2 + c * g1) - n * g2,
            K * (d * (g2**2 - g1**2) + 2 * c * g1 * g2) - 3 * n * g3,
        ]
    )


def printed_l() -> sp.Matrix:
    """The vector potential as printed after (muu) ("or, equivalently, l = ..."), shape (3,)."""
    return C * sp.Matrix(
        [2 * n * g1, 2 * n * g2, n * g3 + K * (d * (g2**2 - g1**2) + 2 * c * g1 * g2)]
    )


def printed_p_dot() -> sp.Expr:
    """The printed ``p'`` (four lines of the theorem's equations)."""
    return (
        half * q * r
        - q / 2 * (K * (d * (g2**2 - g1**2) + 2 * c * g1 * g2) - 3 * n * g3)
        + r / 2 * (2 * K * (c * g1 + d * g2) - n * g2)
        + K**2
        * g3
        * (
            c * d * g1 * (3 * g2**2 - g1**2)
            - d**2 * g2 * (2 * g1**2 - g3**2)
            + c**2 * g2 * (g1**2 + g3**2 - g2**2)
        )
        + kappa * g3 * (c * g2 - d * g1)
        - n * K / 2 * (2 * c * g1 * (g2**2 - g3**2) - g2 * d * (2 * g3**2 - g2**2 + g1**2))
        + g2 * (n**2 * g3 / 2 - lam / g3**3 - (2 * g3**2 - 3) / g3**7 * rho)
    )


def printed_q_dot() -> sp.Expr:
    """The printed ``q'``.

    The LaTeX ``\\frac{p}{2}\\left[K(d(\\gamma_2^2-\\gamma_1^2)+2c\\gamma_1\\gamma_2\\right]``
    has one unclosed parenthesis; it is read as ``p/2 [K (d (g2^2 - g1^2) + 2 c g1 g2)]``.
    """
    return (
        -p * r / 2
        + p / 2 * (K * (d * (g2**2 - g1**2) + 2 * c * g1 * g2))
        - r / 2 * (2 * K * (c * g2 - d * g1) - n * g1)
        - K**2
        * g3
        * (
            c * d * g2 * (3 * g1**2 - g2**2)
            - d**2 * g1 * (2 * g2**2 - g3**2)
            + c**2 * g1 * (g2**2 + g3**2 - g1**2)
        )
        + kappa * g3 * (c * g1 + d * g2)
        + n * K / 2 * (2 * c * g2 * (g1**2 - g3**2) - d * g1 * (g1**2 - g2**2 - 2 * g3**2))
        + g1 * ((2 * g3**2 - 3) / g3**7 * rho + lam / g3**3 - n**2 / 2 * g3)
    )


def printed_r_dot() -> sp.Expr:
    """The printed ``r'``."""
    return (
        (2 * K * (c * g2 - d * g1) * g3 - n * g1) * q
        - (2 * K * (c * g1 + d * g2) * g3 - n * g2) * p
        + 2
        * K**2
        * (
            c * d * (g1**4 + g2**4 - 6 * g1**2 * g2**2)
            - 2 * (c**2 - d**2) * g1 * g2 * (g1**2 - g2**2)
        )
        - 2 * kappa * (2 * c * g1 * g2 + d * (g2**2 - g1**2))
        - 2 * n * K * g3 * (c * (g1**2 - g2**2) + 2 * d * g1 * g2)
    )


def printed_gamma_dot() -> sp.Matrix:
    """The printed Poisson equations ``gamma'``, shape (3,)."""
    return sp.Matrix([r * g2 - q * g3, p * g3 - r * g1, q * g1 - p * g2])


def printed_equations() -> sp.Matrix:
    """All six printed right-hand sides ``(p', q', r', gamma1', gamma2', gamma3')``."""
    return sp.Matrix([printed_p_dot(), printed_q_dot(), printed_r_dot(), *printed_gamma_dot()])


def printed_I3() -> sp.Expr:
    """The printed cyclic integral whose zero level the theorem names (no factor C)."""
    return (
        2 * p * g1 + 2 * q * g2 + (r + K * (d * (g2**2 - g1**2) + 2 * c * g1 * g2)) * g3 - n * g3**2
    )


def printed_I4() -> sp.Expr:
    """The printed complementary (quartic) integral.

    In the first bracket the LaTeX
    ``cK^{2}(c(\\gamma_1^2-\\gamma_2^2)+2d\\gamma_1\\gamma_2\\right)`` has one unclosed
    parenthesis; it is read as ``c K^2 (c (g1^2 - g2^2) + 2 d g1 g2)`` inside the
    ``gamma3^2 ( ... )`` factor.
    """
    P = p + n * g1
    Q = q + n * g2
    R = r + n * g3
    first = (
        P**2
        - Q**2
        + c * kappa * g3**2
        + g3**2 * (K * d * R + c * K**2 * (c * (g1**2 - g2**2) + 2 * d * g1 * g2))
        - lam * (g1**2 - g2**2) / g3**2
    )
    second = (
        2 * P * Q
        + d * kappa * g3**2
        + (d * K**2 * (c * (g1**2 - g2**2) + 2 * d * g1 * g2) - K * c * R) * g3**2
        - 2 * lam * g1 * g2 / g3**2
    )
    braces = (
        2 * (g3**2 - 1) / g3**6 * (P**2 + Q**2)
        - 2 * K * R * (2 * c * g1 * g2 + d * (g2**2 - g1**2)) / g3**4
        + (1 - g3**2) ** 2 / g3**12 * (rho - 2 * lam * g3**4)
        + K**2
        * (
            2 * c**2 * (1 / g3**4 - 2 / g3**2)
            + 8 * ((d**2 - c**2) * g1**2 * g2**2 + c * d * g1 * g2 * (g1**2 - g2**2)) / g3**4
        )
        + 2 * kappa / g3**4 * (c * (g1**2 - g2**2) + 2 * d * g1 * g2)
    )
    return first**2 + second**2 + rho * braces


#: the magnetic field coefficients of (p3): ``Phi = a1 Z + a2 (3 Z^2 - R^2)``
a1, a2 = sp.symbols("a1 a2", real=True)

#: moment keys of the printed conditions (sorted axis letters, as in chargedesign.moments)
P6_KEYS = (
    "xx",
    "yy",
    "zz",
    "xy",
    "xz",
    "yz",
    "xxx",
    "xxy",
    "xxz",
    "xyy",
    "xyz",
    "xzz",
    "yyy",
    "yyz",
    "yzz",
    "zzz",
)


def moment_symbol(key: str) -> sp.Symbol:
    """The charge moment ``I_key = sum e x_i x_j (x_k)`` as a real symbol, e.g. ``I_xyz``."""
    return sp.Symbol(f"I_{key}", real=True)


def printed_p6() -> list[sp.Eq]:
    """The printed moment conditions (p6) on the charge distribution, as equations.

    ``I_xy = I_xz = I_yz = I_xxx = I_xxy = I_xyy = I_xzz = I_yyy = I_yzz = I_zzz
    = I_xxz + I_yyz = 0``, ``I_yy = I_xx = I_zz / 3 = -C n / a1``, ``6 a2 I_xxz = -C K d``,
    ``6 a2 I_xyz = c C K``, with ``a1, a2`` the field coefficients of (p3).
    """
    m = moment_symbol
    zero = ["xy", "xz", "yz", "xxx", "xxy", "xyy", "xzz", "yyy", "yzz", "zzz"]
    eqs = [sp.Eq(m(k), 0) for k in zero]
    eqs.append(sp.Eq(m("xxz") + m("yyz"), 0))
    eqs += [
        sp.Eq(m("yy"), -C * n / a1),
        sp.Eq(m("xx"), -C * n / a1),
        sp.Eq(m("zz") / 3, -C * n / a1),
        sp.Eq(6 * a2 * m("xxz"), -C * K * d),
        sp.Eq(6 * a2 * m("xyz"), c * C * K),
    ]
    return eqs
