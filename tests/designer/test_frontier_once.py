"""`chargedesign frontier` designs the body at the scene's rate and locates its frontier from
one setup, once: the same s_max and binding as the frontier located on a setup of its own (the
route before: a second derivation of the conditions), every rate designed once, and the
induced magnetisation's one figure, the one the body records."""

from __future__ import annotations

import copy
import tomllib
from pathlib import Path

import pytest

from chargedesign.designer.assembly import design_physical
from chargedesign.designer.frontier import find_frontier
from chargedesign.designer.pipeline import (
    design_and_frontier_from_scene,
    physical_setup_from_scene,
)
from chargedesign.formatting import fmt
from chargedesign.scene import scene_from_dict
from chargedesign.scene.design_realism import INDUCED_KEY, K_LAW_KEY, induced_text

SMALL = Path(__file__).parents[1] / "physical" / "small.toml"


def _scene(k_zero: bool):
    data = copy.deepcopy(tomllib.loads(SMALL.read_text()))
    if k_zero:
        data["parameters"]["K"] = 0.0  # the frame reading then needs no charges at all
    return scene_from_dict(data, "<small K = 0>" if k_zero else "<small>")


@pytest.fixture(scope="module", params=[False, True], ids=["K", "K=0"])
def shared(request):
    k_zero = request.param
    return k_zero, design_and_frontier_from_scene(_scene(k_zero))


def test_the_shared_setup_finds_what_a_setup_of_its_own_finds(shared):
    k_zero, (body, front) = shared
    setup = physical_setup_from_scene(_scene(k_zero))  # derived again, as the command did
    own = design_physical(setup).design
    before = find_frontier(setup, feasible_rate=1.0, feasible=own)
    assert body is not None and front.s_max > 0
    assert front.s_max == pytest.approx(before.s_max, rel=1e-9)
    assert front.binding.stage == before.binding.stage
    # every rate is designed once (the body at s = 1 is not designed again by the frontier)
    rates = [s for s, _ in front.history]
    assert len(rates) == len(set(rates))
    assert len(rates) <= len(before.history)


def test_design_json_holds_this_frontier_and_the_verdict_judged_with_it(shared):
    _, (body, front) = shared
    assert body is not None
    assert body.design.frontier == front.to_dict()
    assert body.design.verdict is not None and body.design.verdict["state"]


def test_the_k_law_figure_is_the_one_the_body_records(shared):
    k_zero, (body, front) = shared
    assert body is not None
    law = body.design.realism.get(K_LAW_KEY) or {}
    figure = front.to_dict()["k_law_induced_ratio"]
    text = str(front)
    # the induced magnetisation's one figure: the body's record, printed under its name
    induced = body.design.realism.get(INDUCED_KEY)
    assert induced and front.to_dict()["induced_magnetisation"] == induced
    assert f"{induced_text(induced)}; the body at the scene's rate" in text
    assert "its induced magnetisation" not in text  # no second figure of the same effect
    if k_zero:  # no K term: no K law
        assert figure is None and "the K law" not in text
        return
    assert figure is not None and figure["value"] == law["value"]
    assert figure["name"] == "the K law"
    # the law named as the law, with the same number in its line and the why-line
    assert "the K law (ordinary matter's induced-magnetisation energy range at the K " in text
    assert f"any size and a2): {fmt(law['value'])} x" in " ".join(text.split())
    why = front.realised.why if front.realised is not None else ""
    if why.startswith("the K term cannot be realised"):
        assert f"the K law is {fmt(law['value'])} x" in why
