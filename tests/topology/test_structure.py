"""The n-shift (Larmor) and the chamber counts' stability; bad input in one line."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

from chargedesign.errors import InputError
from chargedesign.topology.chambers import LevelSampler, LevelSampling
from chargedesign.topology.compute import critical_diagram
from chargedesign.topology.diagram import bifurcation_diagram, larmor_shift
from chargedesign.topology.equations import MomentumMap


def _polyline_distance(points, branches, size):
    """For each point (m, 2): distance to the nearest branch polyline, in units of ``size``."""
    out = []
    for q in points / size:
        best = np.inf
        for hk in branches:
            a, b = hk[:-1] / size, hk[1:] / size
            ab = b - a
            s = np.einsum("ij,ij->i", q - a, ab) / np.maximum(np.einsum("ij,ij->i", ab, ab), 1e-300)
            s = np.clip(s, 0.0, 1.0)[:, None]
            best = min(best, float(np.min(np.linalg.norm(a + s * ab - q, axis=1))))
        out.append(best)
    return np.array(out)


def test_energy_shift_is_exact_on_the_level(unit_params):
    """H_n(omega0 - n gamma) = H_0(omega0) + C n^2 and I4 is unchanged, on I3 = 0."""
    rng = np.random.default_rng(5)
    base = unit_params.replace(n=0.0)
    F0, Fn = MomentumMap(base), MomentumMap(unit_params)
    gamma = rng.normal(size=(20, 3))
    gamma /= np.linalg.norm(gamma, axis=1, keepdims=True)
    # states of I3 = 0 at n = 0: omega = omega0 + a vector of the plane (I omega) . gamma = -l.gamma
    sampler = LevelSampler(F0, 1.0, LevelSampling(200, 8))
    x0 = (
        sampler.points(float(np.median(sampler.quartic)))[:20]
        * np.r_[[sampler.omega_scale] * 3, [1] * 3]
    )
    x = x0.copy()
    x[:, :3] -= unit_params.n * x[:, 3:]
    v0, vn = F0.values(x0), Fn.values(x)
    assert np.allclose(vn[:, 0] - v0[:, 0], larmor_shift(unit_params), atol=1e-12)
    assert np.allclose(vn[:, 1], v0[:, 1], rtol=1e-12, atol=1e-14)
    assert np.allclose(vn[:, 3], 0.0, atol=1e-12)


def test_n_shift_matches_a_direct_computation(unit_params, small_options, unit_diagram):
    """The diagram at n = 0.7 computed directly agrees with the shifted n = 0 one to 1 %."""
    direct = critical_diagram(unit_params, unit_diagram.raw.h_range, small_options)
    shifted = [b.hk for b in unit_diagram.branches]
    size = np.ptp(np.concatenate(shifted), axis=0)
    for branch in direct.branches:
        assert np.max(_polyline_distance(branch.hk, shifted, size)) < 0.01
    direct_hk = [b.hk for b in direct.branches]
    for hk in shifted:
        assert np.max(_polyline_distance(hk, direct_hk, size)) < 0.01
    assert sorted(v.type for v in direct.vertices) == sorted(
        v.type for v in unit_diagram.raw.vertices
    )


def test_no_admissible_energy_is_one_line(unit_params):
    with pytest.raises(InputError, match="no admissible motion") as error:
        bifurcation_diagram(unit_params, (-5.0, -4.0))
    assert "\n" not in str(error.value)


def test_singular_parameters_are_refused(unit_params):
    with pytest.raises(InputError, match="lambda = rho = 0") as error:
        bifurcation_diagram(unit_params.replace(rho=0.1))
    assert "\n" not in str(error.value)


def _refused_by_the_command_line(tmp_path, *options: str) -> str:
    """``chargedesign bifurcation`` on the unit scene with ``options`` in its own process:
    exit 2, one line on stderr (returned), no output folder."""
    run = subprocess.run(
        [
            sys.executable,
            "-m",
            "chargedesign",
            "bifurcation",
            "examples/scenes/unit_scale.toml",
            *options,
            "--out",
            str(tmp_path / "out"),
        ],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert run.returncode == 2
    lines = run.stderr.strip().splitlines()
    assert len(lines) == 1, run.stderr
    assert not (tmp_path / "out").exists()
    return lines[0]


def test_command_line_bad_range_is_one_line(tmp_path):
    line = _refused_by_the_command_line(tmp_path, "--h-range", "-5", "-4")
    assert "no admissible motion" in line


def test_chaplygin_limit_lies_on_the_closed_form_curves(unit_params, small_options):
    """K = n = 0: the branches follow k = (h / C +- kappa sqrt(c^2 + d^2))^2."""
    chaplygin = unit_params.replace(K=0.0, n=0.0)
    diagram = bifurcation_diagram(chaplygin, None, small_options)
    a = chaplygin.kappa * np.hypot(chaplygin.c, chaplygin.d)
    hk = np.concatenate([b.hk for b in diagram.branches if not b.exact])
    curves = np.stack([(hk[:, 0] / chaplygin.C + a) ** 2, (hk[:, 0] / chaplygin.C - a) ** 2], 1)
    gap = np.min(np.abs(curves - hk[:, 1:2]), axis=1)
    assert np.max(gap) < 1e-8 * np.max(hk[:, 1])
    # both curves are there: the elliptic boundary and the hyperbolic one from (0, a^2)
    upper = np.abs(curves[:, 0] - hk[:, 1]) < 1e-8
    assert np.any(upper) and np.any(~upper)
    assert {"elliptic", "hyperbolic"} <= {t for b in diagram.branches for t in b.types}


def test_si_scale_is_the_unit_diagram_read_in_other_units(unit_params, small_options, unit_diagram):
    """Slower time (n, K x 1e-3, kappa x 1e-6) and C = 2e-5 kg m^2: h x 2e-11, k x 1e-12
    (the curves to 1e-4 of the diagram: the unit parameters agree to round-off, not bit for
    bit, so the continuation's steps may differ)."""
    slow = unit_params.replace(
        C=2e-5, n=unit_params.n * 1e-3, K=unit_params.K * 1e-3, kappa=unit_params.kappa * 1e-6
    )
    si = bifurcation_diagram(slow, None, small_options)
    units = np.array([2e-11, 1e-12])
    read_back = [b.hk / units for b in si.branches]
    reference = [b.hk for b in unit_diagram.branches]
    size = np.ptp(np.concatenate(reference), axis=0)
    assert len(read_back) == len(reference)
    for hk in read_back:
        assert np.max(_polyline_distance(hk, reference, size)) < 1e-4
    for hk in reference:
        assert np.max(_polyline_distance(hk, read_back, size)) < 1e-4
    assert [b.types[len(b.types) // 2] for b in si.branches] == [
        b.types[len(b.types) // 2] for b in unit_diagram.branches
    ]
    assert [c.tori for c in si.raw.chambers] == [c.tori for c in unit_diagram.raw.chambers]


def test_command_line_energy_outside_the_range_is_one_line(tmp_path):
    line = _refused_by_the_command_line(tmp_path, "--at", "99")
    assert "--at: expected an energy inside" in line
