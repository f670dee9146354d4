"""Regenerate ``tests/model/data/golden_model.json``: reference values of the symbolic model.

Run from the repository root::

    .venv/bin/python tests/model/data/make_golden.py

Every input float is converted to the exact rational it stores, the model's sympy expressions
(V, dV/dgamma, mu, l, the *expanded* derived equations of motion, I1..I4) are evaluated in
exact rational arithmetic, and each value is rounded once to the nearest float64. Beside each
value the file stores its *scale*: the sum of the absolute values of the expanded
expression's terms at that point, which bounds the rounding error any float evaluation can be
expected to reach (tests use ``|numeric - golden| <= tol * scale``).

Parameter sets cover the unit scale, a time/size scale of 1e-6, 1e-3, 1e3 and 1e6
(C ~ s, n, K, omega ~ s, kappa, lambda, rho ~ s^2), and the singular terms (lambda, rho != 0)
near the plane gamma3 = 0 (gamma3 = +-1e-3).
"""

from __future__ import annotations

import json
import sys
from fractions import Fraction
from pathlib import Path

import numpy as np
import sympy as sp

ROOT = Path(__file__).resolve().parents[3]
sys.path.insert(0, str(ROOT))

from chargedesign.files import write_text_atomic  # noqa: E402
from chargedesign.model.case import GAMMA, PARAMETER_SYMBOLS, STATE_SYMBOLS, symbolic_case  # noqa: E402
from chargedesign.model.certificate import RING_SYMBOLS, U, to_ring  # noqa: E402
from chargedesign.model.equations import equations_of_motion  # noqa: E402

OUT = Path(__file__).with_name("golden_model.json")

BASE = {"C": 1.0, "c": 0.3, "d": -0.4, "n": 0.7, "K": 0.5, "kappa": 0.9, "lambda": 0.0, "rho": 0.0}
SINGULAR = {"lambda": 0.25, "rho": -0.15}


def parameter_sets() -> list[tuple[str, dict[str, float], float]]:
    """(name, parameters, omega scale)."""
    sets = [("unit", dict(BASE), 1.0), ("unit_singular", {**BASE, **SINGULAR}, 1.0)]
    for s in (1e-6, 1e-3, 1e3, 1e6):
        scaled = dict(BASE)
        scaled["C"] = s
        for key in ("n", "K"):
            scaled[key] = BASE[key] * s
        scaled["kappa"] = BASE["kappa"] * s * s
        sets.append((f"scale_{s:g}", scaled, s))
        singular = {**scaled, **{k: v * s * s for k, v in SINGULAR.items()}}
        sets.append((f"scale_{s:g}_singular", singular, s))
    return sets


def states_for(omega_scale: float, singular: bool, rng: np.random.Generator) -> list[list[float]]:
    gammas = [rng.normal(size=3) for _ in range(3)]
    gammas = [g / np.linalg.norm(g) for g in gammas]
    for g3 in (1e-3, -1e-3, 1.0):
        rest = np.sqrt(1.0 - g3 * g3)
        gammas.append(np.array([0.6 * rest, -0.8 * rest, g3]))
    if not singular:
        gammas.append(np.array([0.6, 0.8, 0.0]))  # the plane gamma3 = 0 is regular here
    return [
        [float(v) for v in np.concatenate([omega_scale * rng.normal(size=3), g])] for g in gammas
    ]


def exact(value: float) -> sp.Rational:
    f = Fraction(value)
    return sp.Rational(f.numerator, f.denominator)


def evaluate(element, values: dict) -> tuple[float, float]:
    """Exact value (rounded to float64) and the scale sum |terms| of a ring element."""
    full = {s: Fraction(int(v.p), int(v.q)) for s, v in values.items()}
    on_plane = full[GAMMA[2]] == 0
    full[U] = Fraction(0) if on_plane else 1 / full[GAMMA[2]]
    point = [full[s] for s in RING_SYMBOLS]
    u_index = RING_SYMBOLS.index(U)
    total = Fraction(0)
    scale = Fraction(0)
    for monom, coeff in element.items():
        term = Fraction(int(coeff.numerator), int(coeff.denominator))
        for k, (x, e) in enumerate(zip(point, monom, strict=True)):
            if e and k != u_index:
                term *= x**e
        if monom[u_index]:
            # 1/gamma3 terms carry lambda or rho: zero for the regular sets, the only
            # ones evaluated on the plane gamma3 = 0
            if on_plane and term != 0:
                raise ValueError("singular term evaluated on gamma3 = 0")
            term *= full[U] ** monom[u_index]
        total += term
        scale += abs(term)
    return float(total), float(scale)


def main() -> None:
    case = symbolic_case()
    expressions = {
        "potential": [case.V],
        "potential_gradient": [sp.diff(case.V, x) for x in GAMMA],
        "gyroscopic": list(case.mu),
        "angular_potential": list(case.l),
        "rhs": list(equations_of_motion()),
        "integrals": [case.I1, case.I2, case.I3, case.I4],
    }
    rings = {k: [to_ring(e) for e in v] for k, v in expressions.items()}
    rng = np.random.default_rng(20240611)
    cases = []
    for name, params, omega_scale in parameter_sets():
        singular = params["lambda"] != 0.0 or params["rho"] != 0.0
        states = states_for(omega_scale, singular, rng)
        values = {k: [] for k in rings}
        scales = {k: [] for k in rings}
        for state in states:
            point = {s: exact(v) for s, v in zip(STATE_SYMBOLS, state, strict=True)}
            point.update(
                {s: exact(params[k]) for s, k in zip(PARAMETER_SYMBOLS, BASE, strict=True)}
            )
            for key, elements in rings.items():
                pairs = [evaluate(e, point) for e in elements]
                values[key].append([v for v, _ in pairs])
                scales[key].append([float(f"{s:.3g}") for _, s in pairs])
        cases.append(
            {
                "name": name,
                "parameters": params,
                "states": states,
                "values": values,
                "scales": scales,
            }
        )
    data = {
        "format": "chargedesign.golden_model/1",
        "generator": "tests/model/data/make_golden.py",
        "method": "exact rational arithmetic on the sympy model, rounded once to float64",
        "cases": cases,
    }
    # one line per case keeps the file small and its diffs readable
    lines = [json.dumps(case, separators=(",", ":"), allow_nan=False) for case in cases]
    head = json.dumps({k: v for k, v in data.items() if k != "cases"}, allow_nan=False)
    write_text_atomic(OUT, head[:-1] + ', "cases": [\n' + ",\n".join(lines) + "\n]}\n")
    print(f"wrote {OUT.relative_to(ROOT)} ({OUT.stat().st_size} bytes, {len(cases)} cases)")


if __name__ == "__main__":
    main()
