"""The Larmor certificate: the n-system is the n = 0 system read in axes turning at n."""

from __future__ import annotations

import json
from dataclasses import replace

import numpy as np
import pytest
import sympy as sp

from chargedesign.cli import main
from chargedesign.model import evaluators
from chargedesign.model.case import GAMMA, C, g1, g2, g3, n, p, q, r
from chargedesign.model.larmor import (
    LARMOR_CHECKS,
    certify_larmor,
    euler_poincare_residuals,
    lagrangian,
)
from chargedesign.params import Parameters

PARAMS = Parameters(C=1.3, c=0.3, d=-0.4, n=0.7, K=0.5, kappa=0.9, lam=0.2, rho=0.05)


def test_every_larmor_identity_is_an_exact_zero() -> None:
    cert = certify_larmor()
    assert tuple(cert.checks) == LARMOR_CHECKS
    assert all(cert.checks.values()), cert.checks
    assert cert.holds is True
    data = cert.to_dict()
    assert data["holds"] is True and "omega0 - n gamma" in data["map"]


def test_the_reported_differences_are_the_computed_constants() -> None:
    cert = certify_larmor()
    ids = cert.expressions
    assert cert.identities == {k: str(v) for k, v in ids.items()}
    sphere = g1**2 + g2**2 + g3**2
    # L differs by -C n^2 |gamma|^2 (not -C n^2 |gamma|^2 / 2): -C n^2 on the sphere
    assert sp.expand(ids["lagrangian_difference"] + C * n**2 * sphere) == 0
    assert sp.expand(ids["lagrangian_difference_on_sphere"] + C * n**2) == 0
    assert sp.expand(ids["energy_remainder"] - C * n**2 * sphere) == 0
    assert sp.expand(ids["energy_shift_on_level"] - C * n**2) == 0


def test_the_lagrangian_difference_by_plain_expansion() -> None:
    """A second route: sympy expand on the Lagrangian itself, no Laurent ring."""
    L = lagrangian()
    shifted = L.xreplace({n: 0}).xreplace({p: p + n * g1, q: q + n * g2, r: r + n * g3})
    assert sp.simplify(L - shifted + C * n**2 * GAMMA.dot(GAMMA)) == 0
    # and the residuals of the Euler-Poincare form vanish
    assert all(sp.simplify(e) == 0 for e in euler_poincare_residuals())


def test_the_wrong_map_fails_the_certificate() -> None:
    wrong = certify_larmor(map_sign=+1)
    assert wrong.holds is False
    for name in ("equations_omega", "I3_level", "I4_map", "energy_shift_on_level_constant"):
        assert wrong.checks[name] is False, name
    # gamma's equation holds for any shift along gamma (gamma x gamma = 0): not a discriminator
    assert wrong.checks["equations_gamma"] is True
    with pytest.raises(ValueError, match="map_sign"):
        certify_larmor(map_sign=2)


def test_numeric_route_maps_i3_and_i4_at_random_states() -> None:
    """The compiled evaluators (an independent numeric route) agree with the exact map."""
    rng = np.random.default_rng(4)
    gamma = rng.normal(size=(50, 3))
    gamma /= np.linalg.norm(gamma, axis=1)[:, None]
    gamma[:, 2] = np.abs(gamma[:, 2]) + 0.2  # away from the singular plane
    gamma /= np.linalg.norm(gamma, axis=1)[:, None]
    omega0 = rng.normal(size=(50, 3))
    zero = replace(PARAMS, n=0.0)
    at_n = evaluators.integrals(np.hstack([omega0 - PARAMS.n * gamma, gamma]), PARAMS)
    at_0 = evaluators.integrals(np.hstack([omega0, gamma]), zero)
    at_n, at_0 = np.asarray(at_n, dtype=float), np.asarray(at_0, dtype=float)
    np.testing.assert_allclose(at_n[:, 2], at_0[:, 2], rtol=1e-12, atol=1e-12)  # I3
    np.testing.assert_allclose(at_n[:, 3], at_0[:, 3], rtol=1e-11, atol=1e-11)  # I4
    # H_n(omega0 - n gamma) = H_0(omega0) - n I3_0(omega0) + C n^2 on the sphere
    expected = at_0[:, 0] - PARAMS.n * at_0[:, 2] + PARAMS.C * PARAMS.n**2
    np.testing.assert_allclose(at_n[:, 0], expected, rtol=1e-12, atol=1e-12)


def test_verify_json_and_text_carry_the_larmor_certificate(
    capsys: pytest.CaptureFixture[str],
) -> None:
    assert main(["verify", "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert list(report)[:2] == ["certificate", "printed"]
    assert report["larmor"]["holds"] is True
    assert set(report["larmor"]["checks"]) == set(LARMOR_CHECKS)
    assert main(["verify"]) == 0
    out = capsys.readouterr().out
    assert "Larmor certificate" in out and "-C*n**2 on |gamma| = 1" in out
