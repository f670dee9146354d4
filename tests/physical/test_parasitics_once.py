"""The rate-free factors of the parasitics, computed once per body: the same figures as before.

The field response, the realisability map, the K law and the realised window of two bodies
(the default scene's, and examples/scenes/chaplygin_drop.toml's, read from their design.json
without the recomputed records) against the figures the code gave before the factors were
cached and the eddy factor's spectral norm was put in closed form
(``data/parasitics_figures.json``, written by this module's :func:`figures` with that code:
``python tests/physical/test_parasitics_once.py --write`` rewrites it with the code on the
path). The closed form is checked against the SVD of ``L`` itself, and the magnets' coil
torque against the route through the body-axes field gradient.
"""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from chargedesign.body import read_design
from chargedesign.fields import AxisymmetricField
from chargedesign.physical import window
from chargedesign.physical.budget import window_at_design
from chargedesign.physical.parasitics import (
    RESPONSE_ORIENTATIONS,
    eddy_coefficients_by_set,
    eddy_rate_squared,
    eddy_torques_by_set,
    induced_energies_by_set,
)
from chargedesign.physical.realism import field_response, k_law, material_parts, realisability_map
from chargedesign.physical.window import TORQUE_STEP, turned_about_axis, window_model
from chargedesign.results import json_ready
from chargedesign.sampling import fibonacci_sphere

DATA = Path(__file__).parent / "data"
BODIES = {
    "default": DATA / "default_body.json",
    "chaplygin_drop": DATA / "chaplygin_drop_body.json",
}
FIGURES = DATA / "parasitics_figures.json"
#: the rates (multiples of the body's) at which the window's laws are compared
RATES = (1e-2, 0.1, 0.5, 1.0, 2.0, 10.0, 100.0)
#: the figures agree to this (the closed form and the summation order change the last bits;
#: the coils' torque is a central difference, which multiplies them by 1 / TORQUE_STEP)
RTOL = 1e-10


def figures(design: Any) -> dict[str, Any]:
    """Every figure of the realism, map and window stages of one body (JSON-ready)."""
    legendre = tuple(design.field("magnetic"))
    parts = material_parts(design)
    energies = induced_energies_by_set(legendre, parts)
    model = window_model(design, 1.0)
    x = np.array(RATES)
    return json_ready(
        {
            "field_response": field_response(design),
            "eddy_by_set_at_rate_1": eddy_torques_by_set(legendre, parts, 1.0),
            "induced_range_by_set": np.ptp(energies, axis=1),
            "induced_range": float(np.ptp(np.sum(energies, axis=0))),
            "map": realisability_map(design),
            "k_law": k_law(design),
            "window": {
                "term_key": model.term_key,
                "term_size": model.term_size,
                "ratios": {p.key: np.asarray(p.ratio(x)) for p in model.items},
                "apparatus": model.apparatus,
                "support": model.support,
                "notes": model.notes,
            },
            "window_at_design": window_at_design(design),
        }
    )


def differences(before: Any, after: Any, where: str = "") -> list[str]:
    """Where two JSON-ready values differ: numbers beyond RTOL, anything else at all."""
    if isinstance(before, dict) and isinstance(after, dict):
        if set(before) != set(after):
            return [f"{where}: keys {sorted(set(before) ^ set(after))}"]
        return [d for k in before for d in differences(before[k], after[k], f"{where}/{k}")]
    if isinstance(before, list) and isinstance(after, list):
        if len(before) != len(after):
            return [f"{where}: {len(before)} items, now {len(after)}"]
        return [
            d
            for i, (u, v) in enumerate(zip(before, after, strict=True))
            for d in differences(u, v, f"{where}[{i}]")
        ]
    numbers = (int, float)
    if (
        isinstance(before, numbers)
        and isinstance(after, numbers)
        and not isinstance(before, bool)
        and not isinstance(after, bool)
    ):
        ok = math.isclose(before, after, rel_tol=RTOL, abs_tol=0.0)
        return [] if ok else [f"{where}: {before!r}, now {after!r}"]
    return [] if before == after else [f"{where}: {before!r}, now {after!r}"]


@pytest.fixture(scope="module")
def bodies() -> dict[str, Any]:
    return {name: read_design(path) for name, path in BODIES.items()}


@pytest.mark.parametrize("name", sorted(BODIES))
def test_the_figures_of_each_body_are_those_of_the_route_before(bodies, name):
    before = json.loads(FIGURES.read_text(encoding="utf-8"))[name]
    after = figures(bodies[name])
    assert before["field_response"], "the body has a field response to compare"
    assert not differences(before, after), "\n".join(differences(before, after)[:20])
    # asked again, the cached factors give the same figures (and none was changed in place)
    again = figures(bodies[name])
    assert not differences(after, again)


def test_a_changed_figure_is_found():
    assert differences({"a": [1.0, "x"]}, {"a": [1.0 + 1e-9, "x"]})
    assert differences({"a": "x"}, {"a": "y"}) and differences({"a": 1}, {"b": 1})
    assert not differences({"a": [1.0, None]}, {"a": [1.0 + 1e-12, None]})


def _skew(v: np.ndarray) -> np.ndarray:
    out = np.zeros((*v.shape, 3))
    out[..., 0, 1], out[..., 0, 2] = -v[..., 2], v[..., 1]
    out[..., 1, 0], out[..., 1, 2] = v[..., 2], -v[..., 0]
    out[..., 2, 0], out[..., 2, 1] = -v[..., 1], v[..., 0]
    return out


def svd_rate_squared(legendre: tuple[float, ...], centres: np.ndarray) -> np.ndarray:
    """``max |L|_2^2`` over the orientations, ``L = [B0]x - G [c]x`` in body axes, by SVD."""
    fld = AxisymmetricField(legendre)
    gammas = fibonacci_sphere(RESPONSE_ORIENTATIONS)
    b0 = -fld.gradient_body(centres, gammas)
    g = -fld.hessian_body(centres, gammas)
    lin = _skew(b0) - np.einsum("mkij,kjl->mkil", g, _skew(centres))
    return np.max(np.linalg.norm(lin, ord=2, axis=(-2, -1)), axis=0) ** 2


@pytest.mark.parametrize(
    "legendre",
    [(1.0,), (0.0, 0.06), (1.0, 2.0), (0.3, -0.5, 0.7, 0.2), (0.0, 0.0, 1.0), (0.0,) * 4 + (3.0,)],
)
def test_the_spectral_norm_in_closed_form_is_the_svds(legendre):
    rng = np.random.default_rng(len(legendre))
    centres = rng.normal(size=(30, 3)) * 0.05
    centres[1] = [0.0, 0.0, 0.03]  # on the field's axis when gamma passes it
    centres[2] = [0.02, 0.0, 0.0]
    centres = np.concatenate([centres[1:], [[0.0, 0.0, 0.0]]])
    svd = svd_rate_squared(legendre, centres)
    closed = eddy_rate_squared(legendre, centres)
    assert np.max(svd) > 0
    # each centre to 1e-12 of its own value (both exactly 0 at O in a field vanishing there)
    assert np.all(np.abs(closed - svd) <= 1e-12 * svd)


def test_the_factors_are_returned_fresh_and_the_eddy_torque_is_linear_in_the_rate(bodies):
    design = bodies["default"]
    legendre = tuple(design.field("magnetic"))
    parts = material_parts(design)
    first = induced_energies_by_set(legendre, parts)
    first[:] = 0.0  # a caller's change stays its own
    assert np.any(induced_energies_by_set(legendre, parts) != 0.0)
    centres = next(p["centres"] for p in parts if p["sigma"])
    rates = eddy_rate_squared(legendre, centres)
    rates[:] = -1.0
    assert np.all(eddy_rate_squared(legendre, centres) >= 0.0)
    coefficients = eddy_coefficients_by_set(legendre, parts)
    assert np.any(coefficients > 0)
    for rate in (0.3, 1.0, 7.0):
        assert np.array_equal(eddy_torques_by_set(legendre, parts, rate), rate * coefficients)


@pytest.mark.parametrize("name", sorted(BODIES))
def test_the_coil_search_runs_once_per_body_and_gives_each_window_its_own(bodies, name):
    """The coil sizes are tried once per body (the budget, map, verdict and record each build
    its window again): the same apparatus and item from the cache as from a fresh search,
    and a window's apparatus changed in place leaves the next window's as it was."""
    design = bodies[name]
    window.coil_search.cache_clear()
    fresh = window_model(design, 1.0)
    misses = window.coil_search.cache_info().misses
    fresh.apparatus.notes.append("changed by a caller")
    fresh.apparatus.pairs.clear()
    again = window_model(design, 1.0)
    assert window.coil_search.cache_info().misses == misses  # no new search
    assert again.apparatus is not fresh.apparatus
    assert again.apparatus.pairs and "changed by a caller" not in again.apparatus.notes
    window.coil_search.cache_clear()
    rebuilt = window_model(design, 1.0)
    assert again.apparatus.to_dict() == rebuilt.apparatus.to_dict()
    coil = {p.key: p.at(1.0) for p in again.items}["coil_harmonics"]
    assert coil == {p.key: p.at(1.0) for p in rebuilt.items}["coil_harmonics"]


@pytest.mark.parametrize("name", sorted(BODIES))
def test_the_magnets_coil_torque_is_the_body_axes_gradients(bodies, name):
    """The window's coil item against the magnets' energy from ``gradient_body`` (the route
    before), with the same central differences."""
    design = bodies[name]
    model = window_model(design, 1.0)
    coil = next(p for p in model.items if p.key == "coil_harmonics")
    error = AxisymmetricField(model.apparatus.error_legendre)
    gammas = fibonacci_sphere(RESPONSE_ORIENTATIONS)
    moments = np.asarray(design.dipole_moments, dtype=float)

    def energy(g: np.ndarray) -> np.ndarray:
        return np.einsum("mnk,nk->m", error.gradient_body(design.dipole_positions, g), moments)

    slopes = [
        (
            energy(turned_about_axis(gammas, k, TORQUE_STEP))
            - energy(turned_about_axis(gammas, k, -TORQUE_STEP))
        )
        / (2 * TORQUE_STEP)
        for k in range(3)
    ]
    magnets = float(np.max(np.linalg.norm(slopes, axis=0))) / model.term_size
    assert magnets > 0
    if not len(design.charge_values):  # with charges the field's own error may bind instead
        assert coil.at(1.0) == pytest.approx(magnets, rel=RTOL)
    else:
        assert coil.at(1.0) >= magnets * (1 - RTOL)


if __name__ == "__main__" and sys.argv[1:] == ["--write"]:
    written = {name: figures(read_design(path)) for name, path in BODIES.items()}
    FIGURES.write_text(json.dumps(written, allow_nan=False) + "\n", encoding="utf-8")
