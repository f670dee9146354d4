"""The one-line refusals of a ``[case]`` scene that the design stages find (issue 33: an
``InputError`` is raised at the boundary only).

Each function takes plain values (the case's name, a figure the stage computed) and raises
the refusal the user reads; the stages call them where the figure is known, before any
design work.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import NoReturn

from chargedesign.constants import STANDARD_GRAVITY
from chargedesign.errors import InputError


def case_gravity(fields: Mapping[str, Sequence[float]]) -> float:
    """g (m/s^2) of a ``[case]`` scene designed as masses: the uniform part of
    ``[fields.gravity]`` (standard gravity when absent or 0). Electric and magnetic fields act
    on no mass and are refused."""
    others = sorted(kind for kind in fields if kind != "gravity")
    if others:
        raise InputError(
            f"fields.{others[0]}: a [case] scene is designed as masses in gravity; only "
            "[fields.gravity] (its uniform part) may be given"
        )
    legendre = fields.get("gravity", ())
    if len(legendre) > 1 and any(legendre[1:]):
        raise InputError(
            "fields.gravity.legendre: give the uniform part only ([g]); the gradient is "
            "derived from the case's quadratic V"
        )
    if not legendre or legendre[0] == 0.0:
        return STANDARD_GRAVITY
    if legendre[0] < 0.0:
        raise InputError(f"fields.gravity.legendre[0]: expected g > 0, got {legendre[0]}")
    return float(legendre[0])


def refuse_gyroscopic(name: str) -> NoReturn:
    """Masses realise no gyroscopic forces: a case with ``l`` not zero."""
    raise InputError(
        f"case {name}: l is not zero; masses realise no gyroscopic forces (charges in "
        "a magnetic field would: not derived for a general case yet)"
    )


def refuse_singular_v(name: str, v_text: str) -> NoReturn:
    """A V that is not a polynomial in gamma (``v_text``: its sympy string)."""
    raise InputError(f"case {name}: V is singular ({v_text[:60]}); no field realises it")


def refuse_mass_degree(name: str, degree: int) -> None:
    """Masses in gravity realise V of degree 1 and 2 only."""
    if degree > 2:
        raise InputError(
            f"case {name}: V has degree {degree} in gamma; masses in gravity realise "
            "degrees 1 and 2 only (higher degrees need charges or dipoles: not yet)"
        )


def refuse_quadratic_mismatch(name: str) -> NoReturn:
    """V's quadratic part is not a multiple of the inertia's second moments."""
    raise InputError(
        f"case {name}: the quadratic part of V is not the inertia's second moments "
        "(up to a constant on the sphere): no gravity gradient realises it with these "
        "masses (it needs dipoles or charges: not yet)"
    )


def refuse_free_symbol(name: str, what: str, term_text: str) -> NoReturn:
    """A term of the case's ``what`` (V, mu_i) holds a symbol that is no gamma."""
    raise InputError(f"case {name}: {what} has a free symbol in {term_text[:60]}")
