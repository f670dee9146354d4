"""Every listed point is on the level and critical; the CSV is what the contract says."""

from __future__ import annotations

import csv
import io

import numpy as np
import pytest
from unit_scene import UNIT_PARAMETERS as UNIT

from chargedesign.model.evaluators import integrals, rhs
from chargedesign.topology.diagram import CSV_COLUMNS
from chargedesign.topology.equations import MomentumMap, poisson_tensor, relative_singular_value

#: the unit-scale case (examples/scenes/unit_scale.toml)


def _table(diagram):
    reader = csv.reader(io.StringIO(diagram.csv_text()))
    header = next(reader)
    return header, list(reader)


def test_csv_header_is_the_contracts(unit_diagram):
    header, rows = _table(unit_diagram)
    assert header == ["h", "k", "branch", "type", "p", "q", "r", "gamma1", "gamma2", "gamma3"]
    assert tuple(header) == CSV_COLUMNS
    assert len(rows) > 100
    assert {row[3] for row in rows} <= {"elliptic", "hyperbolic", "degenerate"}


def test_every_point_is_on_the_level_and_critical(unit_diagram):
    _, rows = _table(unit_diagram)
    values = np.array([[float(v) for i, v in enumerate(row) if i not in (2, 3)] for row in rows])
    hk, states = values[:, :2], values[:, 2:]
    model = integrals(states, UNIT)  # I1, I2, I3, I4 from the model's own evaluators
    assert np.max(np.abs(model[:, 1] - 1.0)) < 1e-9
    assert np.max(np.abs(model[:, 2])) < 1e-9
    scale = np.ptp(hk, axis=0)
    assert np.max(np.abs(model[:, 0] - hk[:, 0])) < 1e-8 * scale[0]
    assert np.max(np.abs(model[:, 3] - hk[:, 1])) < 1e-8 * scale[1]
    sigma = relative_singular_value(MomentumMap(UNIT).gradients(states))
    assert np.max(sigma) <= 1e-6


def test_consecutive_rows_of_a_branch_are_neighbours(unit_diagram):
    """Each step of a branch's polyline is short (2 % of the diagram at most)."""
    for branch in unit_diagram.branches:
        steps = np.diff(branch.hk, axis=0) / np.ptp(
            np.concatenate([b.hk for b in unit_diagram.branches]), axis=0
        )
        assert np.max(np.linalg.norm(steps, axis=1)) <= 0.021


def test_poisson_tensor_gives_the_model_equations():
    F = MomentumMap(UNIT)
    rng = np.random.default_rng(3)
    for x in rng.normal(size=(5, 6)):
        grads = F.gradients(x)[0]
        tensor = poisson_tensor(F, x)
        assert np.allclose(tensor @ grads[0], rhs(x, UNIT), atol=1e-12)
        # |gamma|^2 and I3 are Casimirs
        assert np.allclose(tensor @ grads[2], 0.0, atol=1e-12)
        assert np.allclose(tensor @ grads[3], 0.0, atol=1e-12)


def test_the_default_case_has_its_three_vertices(unit_diagram):
    """Minimum on the equator (centre-centre), gamma = +-e3 (centre-saddle), the equator's
    other extreme (saddle-saddle); each twice (the symmetry gamma -> -gamma)."""
    kinds = sorted(v.type for v in unit_diagram.raw.vertices)
    assert kinds == sorted(["centre-centre", "centre-saddle", "saddle-saddle"] * 2)
    types = {t for b in unit_diagram.branches for t in b.types}
    assert {"elliptic", "hyperbolic"} <= types


def test_the_result_follows_the_protocol(unit_diagram):
    import json

    from chargedesign.results import REPR_LIMIT

    data = json.loads(unit_diagram.to_json())
    assert data["larmor_shift"] == pytest.approx(UNIT.C * UNIT.n**2)
    assert len(data["branches"]) == len(unit_diagram.branches)
    assert len(repr(unit_diagram)) <= REPR_LIMIT
    assert repr(unit_diagram).startswith("BifurcationDiagram(")
    assert str(unit_diagram).startswith("bifurcation diagram of (H, I4) on I3 = 0")
    page = unit_diagram._repr_html_()
    assert "<table>" in page and "<img" in page


def test_write_puts_both_files_in_place(unit_diagram, tmp_path):
    out = unit_diagram.write(tmp_path / "bif")
    assert (out / "bifurcation.csv").read_text().startswith("h,k,branch,type,p,q,r,")
    assert (out / "bifurcation.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
