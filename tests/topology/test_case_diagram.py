"""The bifurcation diagram of any case (issue 34 item 5), checked against closed forms.

- Kowalevski on I3 = 0: every traced point on one of the curves of
  :mod:`chargedesign.topology.kowalevski` (the published normalization reached by an exact
  substitution, checked here with sympy), and every curve traced over the energy range.
- Lagrange on I3 = 0: the curves derived here from the reduced potential (sympy), both ways.
- The command line: a bare case file accepted; refusals in one line before any work.
"""

from __future__ import annotations

import json

import numpy as np
import pytest
import sympy as sp
from scipy.optimize import brentq

from chargedesign.cli import main
from chargedesign.model.case import g1, g2, g3, p, q, r
from chargedesign.scene.case_file import read_case
from chargedesign.topology import general
from chargedesign.topology.branches import Branch, distance_to_branch
from chargedesign.topology.case_map import CaseMomentumMap
from chargedesign.topology.chambers import FlowCount, FlowCounting, LevelSampling, count_by_flow
from chargedesign.topology.critical import Scales
from chargedesign.topology.diagram import (
    BifurcationDiagram,
    CaseDiagram,
    bifurcation_diagram,
    theorem_reading,
)
from chargedesign.topology.general import case_scales
from chargedesign.topology.kowalevski import CURVES, curve_points, curve_value

CASES = "chargedesign/data/cases"
#: a traced point lies on a closed-form curve: |F(h, k)| below this (published units; the
#: continuation converges to 1e-11 residuals: measured 7.6e-12 at worst)
ON_CURVE = 1e-9
#: every closed-form point in range is within this (diagram units) of a traced branch
COVERED = 3e-3


@pytest.fixture(scope="module")
def kowalevski():
    case = read_case(f"{CASES}/kowalevski.toml")
    return case, bifurcation_diagram(case, level=0, count=False)


@pytest.fixture(scope="module")
def lagrange():
    case = read_case(f"{CASES}/lagrange.toml")
    return case, bifurcation_diagram(case, level=0, count=False)


def _scales(diagram) -> Scales:
    raw = diagram.raw
    hk = np.concatenate([b.hk for b in raw.branches])
    return Scales(raw.h_range[1] - raw.h_range[0], float(np.ptp(hk[:, 1])), *raw.h_range)


def _distance(hk, diagram, scales) -> float:
    return min(
        distance_to_branch(hk, Branch(np.zeros((len(b.hk), 9)), b.hk, b.ends), scales)
        for b in diagram.branches
    )


@pytest.mark.parametrize("name", ["kowalevski", "lagrange", "goriachev_chaplygin"])
def test_the_case_poisson_tensor_gives_the_case_equations(name):
    case = read_case(f"{CASES}/{name}.toml")
    F = CaseMomentumMap(case, case.level or 0)
    rng = np.random.default_rng(3)
    for _ in range(5):
        x = rng.normal(size=6)
        x[3:] /= np.linalg.norm(x[3:])
        dH = F.gradients(x)[0, 0]
        assert np.allclose(F.poisson(x) @ dH, F.velocity(x), rtol=0, atol=1e-12)


def test_the_published_normalization_is_an_exact_substitution():
    """p = -sqrt(a) w1, q = -sqrt(a) w2, r = sqrt(a) w3, gamma = (-a1, -a2, a3) gives
    H = C a H_BRF, F = a^2 K_BRF and I3 = 2 C sqrt(a) G_BRF exactly."""
    C, a = sp.symbols("C a", positive=True)
    w1, w2, w3, a1, a2, a3 = sp.symbols("w1 w2 w3 a1 a2 a3")
    s = sp.sqrt(a)
    sub = {p: -s * w1, q: -s * w2, r: s * w3, g1: -a1, g2: -a2, g3: a3}
    H = C * (p**2 + q**2 + r**2 / 2 + a * g1)
    F = (p**2 - q**2 - a * g1) ** 2 + (2 * p * q - a * g2) ** 2
    I3 = 2 * C * p * g1 + 2 * C * q * g2 + C * r * g3
    H_brf = w1**2 + w2**2 + w3**2 / 2 - a1
    K_brf = (w1**2 - w2**2 + a1) ** 2 + (2 * w1 * w2 + a2) ** 2
    G_brf = w1 * a1 + w2 * a2 + w3 * a3 / 2
    assert sp.expand(H.xreplace(sub) - C * a * H_brf) == 0
    assert sp.expand(F.xreplace(sub) - a**2 * K_brf) == 0
    assert sp.expand(I3.xreplace(sub) - 2 * C * s * G_brf) == 0
    # and the catalogue's file is that case
    case = read_case(f"{CASES}/kowalevski.toml")
    Cv, av = case.parameters["C"], case.parameters["a"]
    assert sp.expand(case.I1 - H.subs({C: Cv, a: av})) == 0
    assert sp.expand(case.integral - F.subs({a: av})) == 0


def test_every_kowalevski_point_lies_on_a_published_curve(kowalevski):
    case, diagram = kowalevski
    C, a = float(case.parameters["C"]), float(case.parameters["a"])
    for b in diagram.branches:
        h, k = b.hk[:, 0] / (C * a), b.hk[:, 1] / a**2
        gap = np.min([np.abs(curve_value(i, h, k)) for i in range(len(CURVES))], axis=0)
        assert np.max(gap) < ON_CURVE, (b.ends, float(np.max(gap)))


def test_every_published_kowalevski_curve_is_traced_and_named(kowalevski):
    case, diagram = kowalevski
    C, a = float(case.parameters["C"]), float(case.parameters["a"])
    scales = _scales(diagram)
    h_high = diagram.raw.h_range[1] / (C * a)
    for index, (name, _, start) in enumerate(CURVES):
        h = np.linspace(start, h_high, 60)
        k = curve_points(index, h)
        worst = max(
            _distance(np.array([hi * C * a, ki * a**2]), diagram, scales)
            for hi, ki in zip(h, k, strict=True)
        )
        assert worst < COVERED, (name, worst)
        assert name in diagram.raw.names
    # the two equilibria: the hanging and the upright body on gamma = -+e1
    vertices = sorted((float(v.hk[0]), float(v.hk[1]), v.type) for v in diagram.raw.vertices)
    assert [v[2] for v in vertices] == ["centre-centre", "saddle-saddle"]
    assert np.allclose([v[:2] for v in vertices], [[-C * a, a**2], [C * a, a**2]], atol=1e-10)
    text = str(diagram)
    assert "Appelrot I (Delone)" in text and "Appelrot II" in text


def _lagrange_curve():
    """The critical values of (H, r) on I3 = 0 derived from the reduced potential:
    ``U(u, r) = C^2 r^2 u^2 / (2 A (1 - u^2)) + C r^2 / 2 + C a u``, ``u = gamma3``
    (``A (p^2 + q^2) >= (C r u)^2 / (A (1 - u^2))`` on I3 = 0); critical where ``dU/du = 0``."""
    A, C, a, u, rr = sp.symbols("A C a u r", real=True)
    U = C**2 * rr**2 * u**2 / (2 * A * (1 - u**2)) + C * rr**2 / 2 + C * a * u
    r2 = sp.solve(sp.Eq(sp.diff(U, u), 0), rr**2)
    assert len(r2) == 1
    return sp.lambdify((u, A, C, a), r2[0]), sp.lambdify((u, rr, A, C, a), U)


def test_every_lagrange_point_lies_on_the_derived_curve_and_back(lagrange):
    case, diagram = lagrange
    A, C, a = (float(case.parameters[n]) for n in ("A", "C", "a"))
    r_squared, energy = _lagrange_curve()
    for b in diagram.branches:
        for h, k in b.hk:
            if k * k < 1e-8:  # the vertex (the body hanging at rest)
                continue
            u = brentq(lambda u, k=k: r_squared(u, A, C, a) - k * k, -1 + 1e-12, -1e-12, xtol=1e-15)
            assert abs(energy(u, k, A, C, a) - h) < 1e-8 * max(1.0, abs(h))
    scales = _scales(diagram)
    for u in np.linspace(-0.999, -0.05, 40):
        rr = np.sqrt(r_squared(u, A, C, a))
        h = energy(u, rr, A, C, a)
        if h <= diagram.raw.h_range[1]:
            for k in (rr, -rr):
                assert _distance(np.array([h, k]), diagram, scales) < COVERED


def test_the_lagrange_level_is_one_torus():
    """One cell's count by the flow (the case's own equations): a Lagrange top on I3 = 0
    has one torus over every regular value (its reduced motion has one well)."""
    case = read_case(f"{CASES}/lagrange.toml")
    F = CaseMomentumMap(case, 0)
    scales = case_scales(F, (-3.0, 6.0))
    F.time_unit = float(np.sqrt(np.max(F.inertia()) / scales.energy))
    counting = FlowCounting(sampling=LevelSampling(800, 32), t_end=150.0, samples=4000)
    found = count_by_flow(F, 1.0, 0.8, counting)
    assert found.tori == 1 and found.points > 0


def _cli(tmp_path, *argv: str) -> int:
    return main(["bifurcation", *argv, "--out", str(tmp_path / "out"), "--quiet"])


def test_a_bare_case_file_draws_its_diagram(tmp_path, capsys, monkeypatch):
    """The command's files and JSON for a case (the counts are the flow's, tested above;
    here each cell's count is replaced to keep the test fast)."""

    monkeypatch.setattr(general, "count_by_flow", lambda F, h, k, counting: _seven())
    assert _cli(tmp_path, f"{CASES}/kowalevski.toml", "--json") == 0
    out = json.loads(capsys.readouterr().out)
    assert out["case"] == "kowalevski" and out["level"] == "0"
    assert {b["name"] for b in out["branches"]} >= {c[0] for c in CURVES}
    assert all(c["tori"] == 7 for c in out["chambers"])
    assert (tmp_path / "out" / "bifurcation.png").stat().st_size > 1000
    header = (tmp_path / "out" / "bifurcation.csv").read_text().splitlines()[0]
    assert header == "h,k,branch,type,p,q,r,gamma1,gamma2,gamma3"


def _seven() -> FlowCount:
    """A stand-in count (7 tori, an impossible figure, so the test sees it passed through)."""
    return FlowCount(7, 10, 1, [0.01], [7], [1.0], (0.01, 0.02), None)


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        ((f"{CASES}/goriachev.toml",), "singular case (its expressions blow up on gamma3 = 0"),
        ((f"{CASES}/goriachev_chaplygin.toml", "--level", "1"), "holds on I3 = 0 only"),
        ((f"{CASES}/kowalevski.toml", "--level", "x"), "--level: expected a number"),
        ((f"{CASES}/kowalevski.toml", "--h-range", "2", "1"), "--h-range: expected two"),
        ((f"{CASES}/kowalevski.toml", "--h-range", "-5", "-4"), "no admissible motion"),
        ((f"{CASES}/kowalevski.toml", "--at", "0.5"), "--at: the atlas is drawn"),
        ((f"{CASES}/euler.toml",), "have no scale"),
        ((f"{CASES}/kowalevski.toml", "--tori", "0.5", "0.1"), "--tori counts the theorem"),
        (("examples/scenes/unit_scale.toml", "--level", "1"), "--level: for a [case] scene"),
    ],
)
def test_refusals_are_one_line(tmp_path, capsys, argv, message):
    assert _cli(tmp_path, *argv) == 2
    err = capsys.readouterr().err.strip()
    assert message in err and "\n" not in err
    assert not (tmp_path / "out").exists()


def test_the_chaplygin_case_file_gives_the_theorems_closed_form():
    """The catalogue's Chaplygin entry (the theorem's file with K = n = lambda = rho = 0) through
    the stages of a case without closed form (``closed_form=False``): every traced point on
    k = 0 or on the theorem's closed form k = (h / C -+ a)^2, a = |kappa| sqrt(c^2 + d^2)
    (docs/bifurcation.md), to 1e-9 of k's scale."""
    from chargedesign.model.catalogue import catalogue_case

    case = catalogue_case("chaplygin")
    C, c, d, kappa = (float(case.parameters[n]) for n in ("C", "c", "d", "kappa"))
    a = abs(kappa) * np.hypot(c, d)
    diagram = bifurcation_diagram(case, level=0, count=False, closed_form=False)
    assert isinstance(diagram, CaseDiagram)
    scale = max(float(np.max(b.hk[:, 1])) for b in diagram.branches)
    curves = {"elliptic": 0, "hyperbolic": 0}
    for b in diagram.branches:
        h, k = b.hk[:, 0], b.hk[:, 1]
        gaps = np.stack([np.abs(k), np.abs(k - (h / C + a) ** 2), np.abs(k - (h / C - a) ** 2)])
        assert np.max(np.min(gaps, axis=0)) < 1e-9 * scale
        for kind, row in (("elliptic", 1), ("hyperbolic", 2)):
            curves[kind] += int(np.sum(gaps[row] < 1e-9 * scale))
    assert curves["elliptic"] > 10 and curves["hyperbolic"] > 10


def test_the_theorem_is_read_as_its_catalogue_entry():
    """One route: the theorem's catalogue entry as a case (``theorem_case``) gives the diagram
    of its parameters, row for row; a case of the theorem's form with the theorem's I4 (the
    catalogue's Chaplygin entry) is read through the closed form at its parameters."""
    from chargedesign.model.catalogue import catalogue_case, theorem_case, theorem_parameters
    from chargedesign.params import Parameters

    params = Parameters(C=1.0, c=0.3, d=-0.4, n=0.7, K=0.5, kappa=0.9)
    direct = bifurcation_diagram(params, count=False)
    entry = bifurcation_diagram(theorem_case(params), count=False)
    assert isinstance(entry, BifurcationDiagram)
    assert entry.raw.params == params and entry.csv_text() == direct.csv_text()
    chaplygin = catalogue_case("chaplygin")
    read = bifurcation_diagram(chaplygin, count=False)
    assert isinstance(read, BifurcationDiagram)
    assert read.raw.params == theorem_parameters(chaplygin)
    assert theorem_reading(chaplygin, 1) is None  # I4 is an integral on I3 = 0 only
