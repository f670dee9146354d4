"""Designed bodies: the two force routes, each effect alone, and the quartic integral."""

from __future__ import annotations

import json
import tomllib
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from unit_scene import UNIT_SCENE

from chargedesign.bench.common import random_body as bench_random_body
from chargedesign.body import Design
from chargedesign.cli import main
from chargedesign.errors import InfeasibleError
from chargedesign.fields import AxisymmetricField
from chargedesign.model import evaluators
from chargedesign.params import Parameters
from chargedesign.scene import load_scene, scene_from_dict
from chargedesign.simulation import (
    Body,
    RigidBodySystem,
    attitude_from_gamma,
    quaternion_gamma,
    quaternion_rotation,
    reduced_polynomials,
    setup_from_source,
    simulate,
)
from chargedesign.simulation.polynomials import PolynomialBank

PHYSICAL = ["lorentz", "electric", "magnetization", "gravity"]
PARAMS = Parameters(C=1.0, c=0.3, d=-0.4, n=0.7, K=0.5, kappa=0.9)
A1, A2 = 1.0, 0.5


def _units(rng: np.random.Generator, n: int) -> np.ndarray:
    v = rng.normal(size=(n, 3))
    return v / np.linalg.norm(v, axis=1)[:, None]


#: fields of degree up to 4 for the random bodies of these tests
FIELDS = {"magnetic": (1.0, 0.7, -0.3), "electric": (0.2, 0.5, 0.3, 0.4), "gravity": (9.81, 0.3)}


def random_body(seed: int, n: int = 12) -> Body:
    """Elements of every kind in fields of degree up to 4 (no symmetry at all)."""
    return bench_random_body(seed, Parameters(C=0.8), FIELDS, n)


def _scale(*arrays: np.ndarray) -> float:
    return max(float(np.max(np.abs(a))) for a in arrays)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_direct_and_reduced_routes_agree(seed: int) -> None:
    body = random_body(seed)
    system = RigidBodySystem(body, PHYSICAL)
    rng = np.random.default_rng(100 + seed)
    quats = rng.normal(size=(6, 4))
    R, G = quaternion_rotation(quats), quaternion_gamma(quats)
    W = rng.normal(size=(6, 3))
    for effect in PHYSICAL:
        red = system.torque(W, G, R, effects=[effect], route="reduced")
        dire = system.torque(W, G, R, effects=[effect], route="direct")
        assert np.max(np.abs(red - dire)) <= 1e-13 * _scale(dire), effect
    for method in ("energy", "momentum_potential"):
        red = getattr(system, method)(G, R, "reduced")
        dire = getattr(system, method)(G, R, "direct")
        assert np.max(np.abs(red - dire)) <= 1e-13 * _scale(dire), method


@settings(max_examples=25, deadline=None)
@given(
    st.lists(st.floats(-1, 1), min_size=4, max_size=4).filter(
        lambda v: sum(x * x for x in v) > 0.1
    ),
    st.lists(st.floats(-3, 3), min_size=3, max_size=3),
)
def test_routes_agree_for_any_attitude(quat: list[float], omega: list[float]) -> None:
    system = RigidBodySystem(random_body(5, n=6), PHYSICAL)
    q = np.array([quat])
    R, G = quaternion_rotation(q), quaternion_gamma(q)
    W = np.array([omega])
    red = system.torque(W, G, R, route="reduced")
    dire = system.torque(W, G, R, route="direct")
    scale = sum(_scale(system.torque(W, G, R, effects=[e], route="direct")) for e in PHYSICAL)
    assert np.max(np.abs(red - dire)) <= 1e-13 * scale


def _rotated_energy(system: RigidBodySystem, R: np.ndarray, axis: int, angle: float) -> float:
    """Energy after turning the body by ``angle`` about its own axis ``axis``."""
    k = np.zeros(3)
    k[axis] = 1.0
    K = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    turn = np.eye(3) + np.sin(angle) * K + (1 - np.cos(angle)) * K @ K
    R2 = R @ turn
    return float(system.energy(R2[2:3].copy(), R2[None], "direct")[0])


@pytest.mark.parametrize("effect", ["electric", "magnetization", "gravity"])
def test_potential_effect_alone(effect: str) -> None:
    """Independent of omega, and minus the derivative of the energy under a body turn."""
    system = RigidBodySystem(random_body(3), [effect])
    R = attitude_from_gamma(np.array([0.3, -0.5, 0.81]), 0.4)
    G = R[2:3].copy()
    T0 = system.torque(np.zeros((1, 3)), G, R[None])
    T1 = system.torque(np.array([[1.0, -2.0, 0.5]]), G, R[None])
    assert np.array_equal(T0, T1)
    h = 1e-5
    for axis in range(3):
        dV = (_rotated_energy(system, R, axis, h) - _rotated_energy(system, R, axis, -h)) / (2 * h)
        assert abs(T0[0, axis] + dV) <= 1e-8 * _scale(T0)


def test_lorentz_alone_is_mu_cross_omega() -> None:
    body = random_body(4)
    system = RigidBodySystem(body, ["lorentz"])
    rng = np.random.default_rng(9)
    G = _units(rng, 4)
    R = np.array([attitude_from_gamma(g) for g in G])
    W = rng.normal(size=(4, 3))
    T = system.torque(W, G, R)
    assert np.all(system.torque(np.zeros_like(W), G, R) == 0.0)
    # mu = -sum q (r . B) r from the field evaluated in body axes (another route)
    B = -AxisymmetricField(body.fields["magnetic"]).gradient_body(body.charge_positions, G)
    rB = np.einsum("mni,ni->mn", B, body.charge_positions)
    mu = -np.einsum("n,mn,ni->mi", body.charge_values, rB, body.charge_positions)
    expected = np.cross(mu, W)
    assert np.max(np.abs(T - expected)) <= 1e-13 * _scale(expected)
    # the magnetic force does no work
    assert np.max(np.abs(np.einsum("ij,ij->i", T, W))) <= 1e-13 * _scale(T) * _scale(W)


def test_effects_add_and_each_changes_its_own_torque() -> None:
    body = random_body(6)
    rng = np.random.default_rng(4)
    G = _units(rng, 3)
    R = np.array([attitude_from_gamma(g) for g in G])
    W = rng.normal(size=(3, 3))
    alone = {e: RigidBodySystem(body, [e]).torque(W, G, R) for e in PHYSICAL}
    for e, T in alone.items():
        assert np.max(np.abs(T)) > 1e-3, e  # every effect acts on this body
    total = RigidBodySystem(body, PHYSICAL).torque(W, G, R)
    expected = sum(alone.values())
    assert np.max(np.abs(total - expected)) <= 1e-13 * _scale(*alone.values())
    # dropping one effect removes exactly its torque
    for e in PHYSICAL:
        rest = RigidBodySystem(body, [x for x in PHYSICAL if x != e]).torque(W, G, R)
        assert np.max(np.abs(total - rest - alone[e])) <= 1e-13 * _scale(*alone.values())


def test_uniform_gravity_torque() -> None:
    rng = np.random.default_rng(11)
    pos, m = rng.uniform(-1, 1, (5, 3)), rng.uniform(0.1, 1, 5)
    g = 9.81
    body = Body(Parameters(), {"gravity": (g,)}, mass_positions=pos, mass_values=m)
    system = RigidBodySystem(body, ["gravity"])
    G = _units(rng, 3)
    T = system.torque(np.zeros((3, 3)), G)
    expected = -g * np.cross(m @ pos, G)  # sum r x (-m g gamma)
    assert np.max(np.abs(T - expected)) <= 1e-14 * _scale(expected)


def p6_body(a1: float = A1, a2: float = A2, params: Parameters = PARAMS) -> Body:
    """22 charges with the paper's (p6) moments, built by hand from symmetric patterns."""
    C, n, K, c, d = params.C, params.n, params.K, params.c, params.d
    s = -C * n / a1
    A = -C * K * d / (6 * a2)  # I_xxz = -I_yyz
    B = c * C * K / (6 * a2)  # I_xyz
    a, b, h = 0.8, 0.6, 0.5
    pos: list[list[float]] = []
    val: list[float] = []
    for sign in (1, -1):  # second moments: diag(s, s, 3 s)
        pos += [[sign * a, 0, 0], [0, sign * a, 0], [0, 0, sign * b]]
        val += [s / (2 * a * a), s / (2 * a * a), 3 * s / (2 * b * b)]
    v = A / (4 * a * a * h)
    for x in (a, -a):
        for z, sz in ((h, 1), (-h, -1)):
            pos += [[x, 0, z], [0, x, z]]
            val += [sz * v, -sz * v]
    w = B / (8 * a * a * h)
    for x, y, sw in ((a, a, 1), (-a, -a, 1), (a, -a, -1), (-a, a, -1)):
        for z, sz in ((h, 1), (-h, -1)):
            pos.append([x, y, z])
            val.append(sw * sz * w)
    return Body(
        parameters=params,
        fields={"magnetic": (a1, 2 * a2)},
        charge_positions=np.array(pos),
        charge_values=np.array(val),
        has_elements=True,
    )


def test_p6_charges_realise_mu_and_l() -> None:
    body = p6_body()
    system = RigidBodySystem(body, ["lorentz"])
    G = _units(np.random.default_rng(2), 8)
    R = np.array([attitude_from_gamma(g) for g in G])
    mu_theorem = evaluators.gyroscopic(G, PARAMS)
    for route in ("reduced", "direct"):
        mu = system.gyroscopic(G)
        assert np.max(np.abs(mu - mu_theorem)) <= 1e-14 * _scale(mu_theorem)
        # physical canonical momentum = the theorem's l . gamma, constant included
        L = system.momentum_potential(G, R, route)
        l_gamma = np.einsum("ij,ij->i", evaluators.angular_potential(G, PARAMS), G)
        assert np.max(np.abs(L - l_gamma)) <= 1e-14 * _scale(l_gamma)


@pytest.fixture(scope="module")
def designed() -> Design:
    """Charges and dipoles realising the theorem's mu and V (lambda = rho = 0) exactly.

    Built by least squares on samples of the unit sphere: charges in the magnetic field
    (a1, a2) give mu, charges in an electric field of degree 3 and 4 give V's harmonics of
    degree 3 and 4, dipoles in the magnetic field give the quadratic part.
    """
    fields = {"magnetic": (A1, 2 * A2), "electric": (0.0, 0.0, -4 * PARAMS.n * A2 / 5, 1.0)}
    rng = np.random.default_rng(7)
    nq, nd = 40, 6
    cpos = _units(rng, nq) * rng.uniform(0.4, 1.0, (nq, 1))
    dpos = _units(rng, nd) * rng.uniform(0.4, 1.0, (nd, 1))
    G = _units(rng, 120)
    columns = []
    for j in range(nq):
        q = np.zeros(nq)
        q[j] = 1.0
        b = Body(PARAMS, fields, charge_positions=cpos, charge_values=q)
        out = PolynomialBank(reduced_polynomials(b, "lorentz", "electric"))(G)
        columns.append(np.concatenate([out[:, 4:7].ravel(), out[:, 0]]))
    for j in range(nd):
        for comp in range(3):
            sig = np.zeros((nd, 3))
            sig[j, comp] = 1.0
            b = Body(PARAMS, fields, dipole_positions=dpos, dipole_moments=sig)
            out = PolynomialBank(reduced_polynomials(b, "magnetization"))(G)
            columns.append(np.concatenate([np.zeros(3 * len(G)), out[:, 0]]))
    columns.append(np.concatenate([np.zeros(3 * len(G)), -np.ones(len(G))]))  # V constant
    A = np.array(columns).T
    rhs = np.concatenate(
        [evaluators.gyroscopic(G, PARAMS).ravel(), evaluators.potential(G, PARAMS)]
    )
    x = np.linalg.lstsq(A, rhs, rcond=None)[0]
    assert np.max(np.abs(A @ x - rhs)) <= 1e-12 * np.max(np.abs(rhs))
    return Design(
        parameters=PARAMS,
        fields=fields,
        charge_positions=cpos,
        charge_values=x[:nq],
        dipole_positions=dpos,
        dipole_moments=x[nq : nq + 3 * nd].reshape(nd, 3),
        realises=["mu", "V"],
    )


def test_designed_body_reproduces_the_theorem(designed: Design) -> None:
    system = RigidBodySystem(Body.from_design(designed), ["lorentz", "electric", "magnetization"])
    theorem = RigidBodySystem(Body(PARAMS), ["theorem"])
    rng = np.random.default_rng(3)
    quats = rng.normal(size=(5, 4))
    states = np.hstack([rng.normal(size=(5, 3)), quats])
    d_body = system.derivatives(states)
    d_theorem = theorem.derivatives(states)
    assert np.max(np.abs(d_body - d_theorem)) <= 1e-12 * _scale(d_theorem)
    # I3 of the body (physical canonical momentum) is the theorem's (omega I + l) . gamma
    I_body = system.integrals(states, route="direct")
    I_theorem = evaluators.integrals(np.hstack([states[:, :3], quaternion_gamma(quats)]), PARAMS)
    assert np.max(np.abs(I_body[:, 2] - I_theorem[:, 2])) <= 1e-12 * _scale(I_theorem[:, 2])


@pytest.mark.parametrize("route", ["direct", "reduced"])
def test_designed_body_i4_on_and_off_the_level(designed: Design, route: str) -> None:
    kw = {"t_end": 8.0, "route": route, "rtol": 1e-11, "atol": 1e-11}
    start = {"gamma": [0.36, 0.48, 0.8], "p": 0.6, "q": -0.4}
    on = simulate(designed, initial={**start, "level": "I3=0"}, **kw).summary()
    off = simulate(designed, initial={**start, "level": "I3=0.5"}, monitors=["I4"], **kw).summary()
    assert on["effects"] == off["effects"] == ["lorentz", "electric", "magnetization"]
    assert on["I3_max"] <= 1e-9
    assert on["I4_rel_drift"] <= 1e-8
    assert off["I3_max_dev"] <= 1e-9  # I3 itself is conserved off the level ...
    assert off["I4_rel_drift"] >= 1e-2  # ... but I4 is not
    assert on["I1_rel_drift"] <= 1e-9 and off["I1_rel_drift"] <= 1e-9


def test_routes_give_the_same_trajectory(designed: Design) -> None:
    kw = {"t_end": 2.0, "rtol": 1e-12, "atol": 1e-12, "samples": 5}
    red = simulate(designed, route="reduced", **kw)
    dire = simulate(designed, route="direct", **kw)
    assert abs(red.times[-1] - dire.times[-1]) == 0.0
    assert np.max(np.abs(red.omega[-1] - dire.omega[-1])) <= 1e-9
    assert np.max(np.abs(red.gamma[-1] - dire.gamma[-1])) <= 1e-9


def test_default_designed_body_keeps_i4_on_the_level_only() -> None:
    """The designer's body for the default scene, simulated from its own elements."""
    from chargedesign.designer import design_from_scene
    from chargedesign.scene import load_scene

    design = design_from_scene(load_scene(UNIT_SCENE)).design
    start = {"gamma": [0.36, 0.48, 0.8], "p": 0.6, "q": -0.4}
    kw = {"t_end": 10.0, "rtol": 1e-12, "atol": 1e-12}
    on = simulate(design, initial={**start, "level": "I3=0"}, **kw).summary()
    off = simulate(design, initial={**start, "level": "I3=0.5"}, monitors=["I4"], **kw).summary()
    assert on["effects"] == ["lorentz", "electric", "magnetization", "gravity"]
    assert on["I3_max"] <= 1e-10 and on["I4_rel_drift"] <= 1e-9
    assert off["I4_rel_drift"] >= 1e-2


# ------------------------------------------- a scene's [body] region designed on the fly
def _cli_json(args: list[str], capsys: pytest.CaptureFixture[str]) -> tuple[dict, str]:
    assert main(["simulate", *args, "--json"]) == 0
    captured = capsys.readouterr()
    return json.loads(captured.out), captured.err


def test_cli_default_run_designs_the_body_and_keeps_i4_on_the_level(
    capsys: pytest.CaptureFixture[str],
) -> None:
    out, err = _cli_json([str(UNIT_SCENE), "--t-end", "20"], capsys)
    assert list(out)[:3] == ["I4_rel_drift", "I3_max", "effects"]
    assert out["effects"] == PHYSICAL
    assert "designing body" in err
    body = out["body"]
    assert body["designed_from_scene"] is True and body["shape"] == "ball"
    assert body["realises"] == ["mu", "V", "inertia"]
    assert body["residuals"]["max_after_polish"] <= body["residuals"]["tolerance"] <= 1e-13
    assert min(body["counts"].values()) >= 1
    # on the level of the physical I3 = (omega I) . gamma + sum q psi
    assert out["level"] == "I3=0" and abs(out["initial"]["I3"]) <= 1e-13
    assert out["I3_max"] <= 1e-10
    assert out["I4_rel_drift"] <= 1e-9  # measured 3.0e-12 (t = 20 s, rtol = atol = 1e-12)
    assert out["I1_rel_drift"] <= 1e-10


def test_cli_off_level_breaks_i4_but_not_i1_and_i3(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    run = tmp_path / "run"
    out, _ = _cli_json(
        [
            str(UNIT_SCENE),
            "--t-end",
            "20",
            "--off-level",
            "0.5",
            "--monitors",
            "I4",
            "--out",
            str(run),
        ],
        capsys,
    )
    assert out["effects"] == PHYSICAL and out["level"] == "I3=0.5"
    assert abs(out["initial"]["I3"] - 0.5) <= 1e-13
    assert out["initial"]["omega"][:2] == [0.6, -0.4]  # the default start's p, q; r moved
    assert out["I4_rel_drift"] >= 1e-3  # measured 0.97
    assert out["I3_max_dev"] <= 1e-10 and out["I1_rel_drift"] <= 1e-10
    # the body written beside the motion is the body simulated
    design_file = out["body"]["design_file"]
    assert design_file in out["files"]
    saved = json.loads((run / "summary.json").read_text())
    assert saved["body"]["design_file"] == design_file
    again = simulate(design_file, t_end=20.0, level=0.5, monitors=["I4"]).summary()
    assert again["effects"] == PHYSICAL
    assert abs(again["I4_rel_drift"] - out["I4_rel_drift"]) <= 1e-12


def test_region_with_theorem_effect_uses_the_reduced_model(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    scene = tmp_path / "scene.toml"
    scene.write_text(
        UNIT_SCENE.read_text() + '\n[simulation]\nt_end = 5.0\neffects = ["theorem"]\n'
    )
    out, err = _cli_json([str(scene)], capsys)
    assert out["effects"] == ["theorem"] and "designing body" not in err
    assert out["body"]["designed_from_scene"] is False
    assert out["body"]["counts"] == {"charges": 0, "dipoles": 0, "masses": 0}
    assert any("was not designed" in note for note in out["notes"])
    reference = simulate(load_scene(scene).parameters, t_end=5.0).summary()
    assert out["I4_rel_drift"] == reference["I4_rel_drift"]
    assert out["I3_max"] == reference["I3_max"]
    # --effects theorem does the same for the default scene
    out, err = _cli_json([str(UNIT_SCENE), "--effects", "theorem", "--t-end", "2"], capsys)
    assert out["effects"] == ["theorem"] and "designing body" not in err


def test_a_setup_is_designed_once_and_keeps_its_own_options() -> None:
    setup = setup_from_source(UNIT_SCENE)
    messages: list[str] = []
    first = simulate(setup, t_end=2.0, design_progress=messages.append)
    designed = len(messages)
    assert designed >= 1 and setup.design is not None
    second = simulate(setup, level=0.5, design_progress=messages.append)
    assert len(messages) == designed  # the body is reused
    assert second.t_end == 100.0  # the first run's t_end did not stick to the setup
    assert first.summary()["body"]["counts"] == second.summary()["body"]["counts"]


def test_a_partial_design_skips_effects_without_a_source_with_notes() -> None:
    data = tomllib.loads(UNIT_SCENE.read_text())
    data["design"] = {"realise": ["mu"]}
    result = simulate(scene_from_dict(data), t_end=1.0)
    assert result.effects == ["lorentz"]  # charges only; no electric field is derived
    notes = " ".join(result.notes)
    assert "electric: skipped, the electric field is zero" in notes
    assert "gravity: skipped, the body has no masses" in notes
    assert "magnetization: skipped, the body has no dipoles" in notes
    assert "does not realise V, inertia" in notes


def test_a_region_that_cannot_be_designed_says_how_to_simulate_the_theorem() -> None:
    data = tomllib.loads(UNIT_SCENE.read_text())
    data["parameters"]["lambda"] = 0.3
    scene = scene_from_dict(data)
    with pytest.raises(InfeasibleError, match=r"singular.*effects = \['theorem'\]"):
        simulate(scene, t_end=1.0)
    assert simulate(scene, t_end=1.0, effects=["theorem"]).effects == ["theorem"]


def test_level_override_keeps_gamma_p_and_q() -> None:
    start = {"gamma": [0.36, 0.48, 0.8], "omega": [0.6, -0.4, 0.1]}
    result = simulate(PARAMS, t_end=0.5, initial=start, level=0.25)
    assert result.omega[0, :2].tolist() == [0.6, -0.4]
    assert np.max(np.abs(result.gamma[0] - [0.36, 0.48, 0.8])) <= 1e-15
    state = np.concatenate([result.omega[0], result.gamma[0]])
    assert abs(evaluators.integrals(state, PARAMS)[2] - 0.25) <= 1e-14
    assert result.summary()["level"] == "I3=0.25"
