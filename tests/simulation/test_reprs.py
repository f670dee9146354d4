"""Short reprs of the simulation's objects (a designed body holds thousands of elements)."""

from unit_scene import UNIT_SCENE

from chargedesign.designer import design_from_scene
from chargedesign.scene import load_scene
from chargedesign.simulation import setup_from_source


def test_body_and_setup_reprs_are_short_and_name_the_counts():
    design = design_from_scene(load_scene(UNIT_SCENE)).design
    setup = setup_from_source(design)
    body = repr(setup.body)
    assert body.startswith("Body(charges=25, dipoles=4, masses=6, total_mass_kg=2.5")
    assert "array" not in body and len(body) <= 300
    text = repr(setup)
    assert text.startswith("SimulationSetup(source='<design>', charges=25, dipoles=4, masses=6")
    assert len(text) <= 300
