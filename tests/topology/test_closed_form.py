"""The branches in closed form, k = ((h - h_j) / C)^2, proven symbolically and checked against
the continuation (an independent route: it knows nothing of the closed form)."""

from __future__ import annotations

import numpy as np
import sympy as sp
from topology_cases import GENERIC
from unit_scene import UNIT_PARAMETERS as UNIT

from chargedesign.model.case import (
    C,
    K,
    c,
    d,
    g1,
    g2,
    g3,
    kappa,
    lam,
    n,
    p,
    q,
    r,
    rho,
    symbolic_case,
)
from chargedesign.topology.closed_form import ClosedForm
from chargedesign.topology.equations import MomentumMap


def _at_n0():
    case = symbolic_case()
    zero = {lam: 0, rho: 0, n: 0}
    return case, {k: v.xreplace(zero) for k, v in (("V", case.V), ("I4", case.I4), ("H", case.I1))}


def test_potential_and_quartic_in_closed_form():
    """V / C = A^2/(2K^2) + K^2 a0^2 gamma3^4/2 - kappa^2/(2K^2) - K^2 c^2/2 on |gamma| = 1,
    and I4 = |w^2 + (c + i d) gamma3^2 (A - i K r)|^2 with A = kappa + K^2 s, w = p + i q."""
    _, f = _at_n0()
    s = c * (g1**2 - g2**2) + 2 * d * g1 * g2
    A = kappa + K**2 * s
    closed = A**2 / 2 + K**4 * (c**2 + d**2) * g3**4 / 2 - kappa**2 / 2 - K**4 * c**2 / 2
    sphere = {g3**2: 1 - g1**2 - g2**2}
    gap = sp.expand(K**2 * f["V"] / C - closed).subs(g3**4, (1 - g1**2 - g2**2) ** 2)
    assert sp.expand(gap.subs(sphere)) == 0
    xi = (p + sp.I * q) ** 2 + (c + sp.I * d) * g3**2 * (A - sp.I * K * r)
    assert sp.expand(f["I4"] - sp.expand(xi * sp.conjugate(xi))) == 0
    # |s| <= a0 (1 - gamma3^2): s^2 + f^2 = a0^2 (gamma1^2 + gamma2^2)^2
    f_quad = d * (g2**2 - g1**2) + 2 * c * g1 * g2
    assert sp.expand(s**2 + f_quad**2 - (c**2 + d**2) * (g1**2 + g2**2) ** 2) == 0


def test_equator_families_are_critical_with_k_from_h():
    """gamma = (cos phi, sin phi, 0), r = 0, omega = u (-sin phi, cos phi, 0) at a critical
    angle of V on the equator: I4 = u^4 = ((H - h_j)/C)^2 and dI4 - 2 u^2 dH / C lies in the
    span of dI2, dI3 (so the family is critical): solved for the multipliers symbolically."""
    case, f = _at_n0()
    u, phi = sp.symbols("u phi", real=True)
    state = {p: -u * sp.sin(phi), q: u * sp.cos(phi), r: 0, g1: sp.cos(phi), g2: sp.sin(phi), g3: 0}
    X = (p, q, r, g1, g2, g3)
    I3 = case.I3.xreplace({n: 0})
    grads = [
        sp.Matrix([sp.diff(e, x) for x in X]).subs(state) for e in (f["H"], f["I4"], case.I2, I3)
    ]
    V_eq = f["V"].subs(state)
    h_j = sp.simplify(f["H"].subs(state) - C * u**2)
    assert sp.simplify(f["I4"].subs(state) - ((f["H"].subs(state) - h_j) / C) ** 2) == 0
    # dI2 = (0, 0, 0, 2 gamma): delta = 0 from the omega rows, beta from the radial gamma row;
    # what remains (the tangential gamma row) is a multiple of dV_eq/dphi, so it vanishes at
    # the critical angles
    beta = sp.Symbol("beta")
    rest = grads[1] - 2 * u**2 / C * grads[0] - beta * grads[2]
    assert all(sp.simplify(rest[i]) == 0 for i in (0, 1, 2, 5))
    radial = sp.cos(phi) * rest[3] + sp.sin(phi) * rest[4]
    tangential = (-sp.sin(phi) * rest[3] + sp.cos(phi) * rest[4]).subs(
        beta, -radial.subs(beta, 0) / sp.diff(radial, beta)
    )
    ratio = sp.simplify(tangential / sp.diff(V_eq, phi))
    assert not ratio.has(phi)
    assert sp.simplify(tangential - ratio * sp.diff(V_eq, phi)) == 0


def test_quartic_is_bounded_by_the_least_energy_on_the_level():
    """I4 <= ((H - h_min)/C)^2 at 20,000 random states of I3 = 0 (n, kappa < 0 included),
    with equality on the equator family over h_min."""
    rng = np.random.default_rng(3)
    for params in (UNIT, GENERIC, GENERIC.replace(kappa=-0.05), UNIT.replace(kappa=-0.9)):
        F = MomentumMap(params)
        gamma = rng.normal(size=(20000, 3))
        gamma /= np.linalg.norm(gamma, axis=1, keepdims=True)
        omega = rng.normal(size=(20000, 3)) * rng.choice([0.05, 0.5, 2.0], size=(20000, 1))
        # onto I3 = 0 along gamma (I omega . gamma is linear in omega)
        x = np.concatenate([omega, gamma], axis=1)
        level = F.values(x)[:, 3]
        x[:, :3] -= (level / np.einsum("mi,i,mi->m", gamma, F.inertia(), gamma))[:, None] * gamma
        values = F.values(x)
        assert np.max(np.abs(values[:, 3])) < 1e-9
        closed = ClosedForm.of(params)
        bound = ((values[:, 0] - closed.h_min) / params.C) ** 2
        assert np.all(values[:, 0] >= closed.h_min - 1e-12)
        assert np.all(values[:, 1] <= bound * (1 + 1e-12) + 1e-14)


def test_continuation_lies_on_the_closed_form(unit_diagram, generic_diagram):
    """Every continued point on a parabola k = ((h - h_j)/C)^2 of its own type, and every
    parabola met by the continuation (two cases: the two shapes of the diagram)."""
    for diagram in (unit_diagram, generic_diagram):
        closed = ClosedForm.of(diagram.raw.params)
        scale = closed.energy_scale
        met = set()
        for branch in diagram.branches:
            if branch.exact:
                continue
            h, k = branch.hk[:, 0], branch.hk[:, 1]
            gaps = np.array(
                [np.abs(np.sqrt(k) * p.C - np.abs(h - p.h_j)) for p in closed.parabolas]
            )
            nearest = np.argmin(gaps, axis=0)
            assert np.max(np.min(gaps, axis=0)) < 1e-9 * scale
            for i, kind in zip(nearest, branch.types, strict=True):
                if kind != "degenerate":
                    assert kind == closed.parabolas[i].type
                met.add(int(i))
        assert met == set(range(len(closed.parabolas)))


def test_the_two_shapes_switch_at_K2_a0_and_kappa_sign_swaps_labels():
    a0 = float(np.hypot(UNIT.c, UNIT.d))
    switch = UNIT.K**2 * a0
    assert len(ClosedForm.of(UNIT.replace(kappa=0.999 * switch)).parabolas) == 3
    assert len(ClosedForm.of(UNIT.replace(kappa=1.001 * switch)).parabolas) == 2
    positive, negative = ClosedForm.of(UNIT), ClosedForm.of(UNIT.replace(kappa=-UNIT.kappa))
    assert positive.parabolas[0].type == negative.parabolas[0].type == "elliptic"
    assert positive.parabolas[0].s == -a0 and negative.parabolas[0].s == a0
    assert "kappa < 0" in negative.parabolas[0].name


def test_larmor_shifts_every_branch_by_C_n2():
    at0 = ClosedForm.of(GENERIC.replace(n=0.0))
    atn = ClosedForm.of(GENERIC)
    shift = GENERIC.C * GENERIC.n**2
    assert np.allclose(np.array(atn.energies) - at0.energies, shift, rtol=0, atol=1e-14)


def test_off_equator_zero_sheets_are_critical_over_k_0():
    """Off the equator, xi = 0 on I3 = 0 (w = sqrt(-(c + i d) gamma3^2 (A - i K r)), r from
    I3 = 0) gives states with gamma3 != 0 and I4 = 0: critical (I4 has its minimum there),
    so the critical set over k = 0 is more than the equator family. Measured: these lie at
    the energy of a vertex on k = 0 (an h_j with s = +-a0), not along the segment."""
    from scipy.optimize import brentq

    params = GENERIC.replace(n=0.0)
    F = MomentumMap(params)
    a0 = float(np.hypot(params.c, params.d))
    energies = []
    for theta, phi in ((0.7, 0.3), (1.1, 2.0), (0.4, 4.0), (1.3, 5.5)):
        gamma = np.array([np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi), np.cos(theta)])
        s = params.c * (gamma[0] ** 2 - gamma[1] ** 2) + 2 * params.d * gamma[0] * gamma[1]
        A = params.kappa + params.K**2 * s
        assert A > 0  # sqrt(A - i K r) is then continuous in r (right half-plane)

        def state(r: float, gamma=gamma, A=A) -> np.ndarray:
            w = np.sqrt(-(params.c + 1j * params.d) * gamma[2] ** 2 + 0j) * np.sqrt(
                A - 1j * params.K * r
            )
            return np.array([w.real, w.imag, r, *gamma])

        r = brentq(lambda r: F.values(state(r))[0, 3], -50.0, 50.0, xtol=1e-14)
        x = state(r)
        values = F.values(x)[0]
        assert abs(values[3]) < 1e-10 and abs(values[1]) < 1e-20
        assert np.max(np.abs(F.gradients(x)[0, 1])) < 1e-9  # dI4 = 0: critical
        assert abs(gamma[2]) > 0.2
        energies.append(values[0])
    vertices = [p.h_j for p in ClosedForm.of(params).parabolas if abs(abs(p.s) - a0) < 1e-12]
    for h in energies:
        assert min(abs(h - v) for v in vertices) < 1e-12


def test_vertices_on_k_0_are_degenerate_for_the_momentum_map(unit_diagram):
    """At the vertices on k = 0 the Hessian of I4 vanishes (xi vanishes to second order on
    the equator family), at the others it does not."""
    F = MomentumMap(unit_diagram.raw.params)
    for vertex in unit_diagram.raw.vertices:
        hessian = np.max(np.abs(F.hessians(vertex.state)[0, 1]))
        if vertex.hk[1] < 1e-12:
            assert hessian < 1e-12
        else:
            assert hessian > 1e-3
