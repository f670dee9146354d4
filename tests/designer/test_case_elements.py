"""A case with gyroscopic forces or a cubic V designed as charges, dipoles and masses.

design.json is read with ``json`` alone; the torque of every element in its field is summed
here (Lorentz force on charges moving with omega x r, the dipoles' couple and force, the
masses' weight) and compared with the case's Euler-Poisson torque gamma x dV/dgamma - omega x
mu, differentiated here by sympy from the case's own expressions."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import sympy as sp

import chargedesign
from chargedesign.cli import main
from chargedesign.fields import AxisymmetricField
from chargedesign.model.case import GAMMA, mu_from_l
from chargedesign.model.case_numeric import case_from_record

CASES = Path(chargedesign.__file__).parent / "data" / "cases"
BODY = '\n[body]\nshape = "ball"\nradius = 0.5\nspacing = 0.125\n'
#: a Lagrange top with a cubic potential (any V(gamma3) keeps r when A = B): held out
CUBIC = """[case]
name = "cubic-lagrange"
inertia = [2, 2, 1]
V = "a*gamma3 + b*gamma3**3"
integral = "r"
[case.parameters]
a = 0.5
b = 0.3
"""
THEOREM_VARIANT = (
    (CASES / "yehia_elmandouh.toml")
    .read_text("utf-8")
    .replace("lambda = 0.1\nrho = 0.2", "lambda = 0\nrho = 0")
    .replace("n = 0.7", "n = -0.45")
)


def _design(tmp_path: Path, text: str) -> dict:
    scene = tmp_path / "case.toml"
    scene.write_text(text + BODY, "utf-8")
    out = tmp_path / "out"
    assert main(["design", str(scene), "--out", str(out), "--no-picture", "--quiet"]) == 0
    assert main(["check", str(out / "design.json"), "--json"]) == 0
    return json.loads((out / "design.json").read_text("utf-8"))


def _element_torques(data: dict, gammas: np.ndarray, omegas: np.ndarray) -> np.ndarray:
    fields = {k: AxisymmetricField(tuple(v["legendre"])) for k, v in data["fields"].items()}
    zero = AxisymmetricField(())
    total = np.zeros((len(gammas), 3))
    if data.get("charges", {}).get("values"):
        r = np.array(data["charges"]["positions"], dtype=float).reshape(-1, 3)
        q = np.array(data["charges"]["values"], dtype=float)
        for i, (g, w) in enumerate(zip(gammas, omegas, strict=True)):
            B = -fields.get("magnetic", zero).gradient_body(r, g[None])[0]
            E = -fields.get("electric", zero).gradient_body(r, g[None])[0]
            v = np.cross(w, r)
            total[i] += np.sum(np.cross(r, q[:, None] * (E + np.cross(v, B))), axis=0)
    if data.get("dipoles", {}).get("moments"):
        r = np.array(data["dipoles"]["positions"], dtype=float).reshape(-1, 3)
        s = np.array(data["dipoles"]["moments"], dtype=float).reshape(-1, 3)
        for i, g in enumerate(gammas):
            B = -fields["magnetic"].gradient_body(r, g[None])[0]
            H = fields["magnetic"].hessian_body(r, g[None])[0]
            force = -np.einsum("nij,nj->ni", H, s)
            total[i] += np.sum(np.cross(s, B) + np.cross(r, force), axis=0)
    if "masses" in data and "gravity" in fields:
        r = np.array(data["masses"]["positions"], dtype=float).reshape(-1, 3)
        m = np.array(data["masses"]["values"], dtype=float)
        for i, g in enumerate(gammas):
            grad = fields["gravity"].gradient_body(r, g[None])[0]
            total[i] += np.sum(np.cross(r, -m[:, None] * grad), axis=0)
    return total


def _case_torques(case, gammas: np.ndarray, omegas: np.ndarray) -> np.ndarray:
    mu = case.mu if case.l is None else mu_from_l(case.l)
    dV = [sp.lambdify(GAMMA, sp.diff(case.V, x)) for x in GAMMA]
    mus = [sp.lambdify(GAMMA, component) for component in mu]
    out = []
    for g, w in zip(gammas, omegas, strict=True):
        grad = np.array([float(f(*g)) for f in dV])
        m = np.array([float(f(*g)) for f in mus])
        out.append(np.cross(g, grad) - np.cross(w, m))
    return np.array(out)


def _states(count: int = 40) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(7)
    gammas = rng.standard_normal((count, 3))
    return gammas / np.linalg.norm(gammas, axis=1)[:, None], rng.standard_normal((count, 3))


@pytest.mark.parametrize(
    ("text", "sources"),
    [
        ((CASES / "steklov_lyapunov.toml").read_text("utf-8"), {"charges", "dipoles", "masses"}),
        (THEOREM_VARIANT, {"charges", "dipoles", "masses"}),
        (CUBIC, {"charges", "masses"}),
    ],
    ids=["steklov-lyapunov", "theorem-variant", "cubic-lagrange"],
)
def test_element_torques_are_the_cases_euler_poisson_torques(
    tmp_path: Path, text: str, sources: set[str]
) -> None:
    data = _design(tmp_path, text)
    present = {
        s
        for s, key in (("charges", "values"), ("dipoles", "moments"), ("masses", "values"))
        if s in data and data[s][key]
    }
    assert present == sources
    case = case_from_record(data["case"])
    gammas, omegas = _states()
    body = _element_torques(data, gammas, omegas)
    reference = _case_torques(case, gammas, omegas)
    scale = np.max(np.abs(reference))
    assert np.max(np.abs(body - reference)) <= 1e-10 * scale
    # the inertia about O recomputed from the masses is the case's, products zero
    r = np.array(data["masses"]["positions"], dtype=float)
    m = np.array(data["masses"]["values"], dtype=float)
    inertia = np.eye(3) * np.einsum("i,ij,ij->", m, r, r) - np.einsum("i,ij,ik->jk", m, r, r)
    assert np.allclose(inertia, np.diag([float(x) for x in case.inertia]), rtol=0, atol=1e-12)
    if case.name == "yehia-elmandouh":
        # the theorem's form: the theorem's own program and records (its forward accuracy)
        assert data["forward_accuracy"]["worst"] and "realism" not in data["case"]
        return
    # the realism budget and the realised window are recorded with the case
    assert set(data["case"]["realism"]["items"]) == {
        "radiation",
        "self_field",
        "relativistic",
        "gravity_balance",
    }
    assert "s_low" in data["case"]["realised"]
    # mu matched: the charges' l . gamma is the case's up to a constant on the sphere
    assert data["case"]["level_spread"] <= 1e-12


def test_a_wrong_sign_of_mu_is_caught_by_the_element_torques(tmp_path: Path) -> None:
    """The comparison can fail: the Steklov-Lyapunov body against the case with l reversed."""
    data = _design(tmp_path, (CASES / "steklov_lyapunov.toml").read_text("utf-8"))
    table = dict(data["case"]["table"])
    table["l"] = [f"-({x})" for x in table["l"]]
    data_case = case_from_record({"table": table})
    gammas, omegas = _states()
    body = _element_torques(data, gammas, omegas)
    reference = _case_torques(data_case, gammas, omegas)
    assert np.max(np.abs(body - reference)) > 0.1 * np.max(np.abs(reference))


def test_the_windows_laws_are_the_time_rescaled_bodies_budgets() -> None:
    """Steklov-Lyapunov with mu -> s mu is the same case s times faster (V ~ mu^2, l ~ mu):
    the body designed for it has the budget the window's laws predict from the body at s = 1
    (radiation s^3, self-field and (v/c)^2 s^2, the balance s^-2), and at the window's ends
    the worst item is the fraction."""
    import tomllib

    from chargedesign.designer.pipeline import design_from_scene
    from chargedesign.physical.window import case_realised_window, case_window_model
    from chargedesign.scene import scene_from_dict

    table = tomllib.loads((CASES / "steklov_lyapunov.toml").read_text("utf-8"))["case"]
    designs = {}
    for s in (1.0, 2.0):
        scaled = dict(table, parameters=dict(table["parameters"], mu=0.4 * s))
        body = {"shape": "ball", "radius": 0.5, "spacing": 0.125}
        designs[s] = design_from_scene(scene_from_dict({"case": scaled, "body": body}, "<s>"))
    budget = designs[1.0].design.further_keys["case"]["realism"]
    model = case_window_model(designs[1.0].design, budget)
    rescaled = designs[2.0].design.further_keys["case"]["realism"]["items"]
    for key, predicted in model.ratios(2.0).items():
        assert predicted == pytest.approx(rescaled[key]["value"], rel=1e-9)
    window = case_realised_window(designs[1.0].design, budget)
    assert window.s_low is not None and window.s_high is not None
    for end in (window.s_low, window.s_high):
        assert max(model.ratios(end).values()) == pytest.approx(window.fraction, rel=1e-6)
