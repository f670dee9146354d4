"""Design.to_pyvista(), Design.plot(plotter) and the notebook pieces."""

import numpy as np
import pytest
import pyvista as pv

from chargedesign import viz
from chargedesign.body import Design
from chargedesign.params import Parameters


def small_design(**extra):
    return Design(
        parameters=Parameters(C=1.0, c=0.3, n=0.7),
        fields={"magnetic": (1.0, 1.0)},
        charge_positions=[[0.5, 0.0, 0.0], [0.0, 0.5, 0.0], [0.0, 0.0, 0.5]],
        charge_values=[1e-6, -2e-6, 1e-15],
        mass_positions=[[0.0, 0.0, -0.5], [0.3, 0.3, 0.0]],
        mass_values=[0.4, 0.1],
        dipole_positions=[[0.0, 0.0, -0.5]],
        dipole_moments=[[0.0, 0.1, 0.0]],
        realises=["mu"],
        **extra,
    )


def test_blocks_have_names_and_one_mesh_per_element():
    design = small_design()
    blocks = design.to_pyvista(region={"shape": "ball", "radius": 1.0})
    assert isinstance(blocks, pv.MultiBlock)
    assert list(blocks.keys()) == ["charges", "masses", "dipoles", "region", "scale_bar"]
    assert len(blocks["charges"]) == 3 and len(blocks["masses"]) == 2
    assert len(blocks["dipoles"]) == 1
    assert blocks["charges"].keys() == ["charge 0", "charge 1", "charge 2"]
    q = [float(blocks["charges"][i].field_data["charge (C)"][0]) for i in range(3)]
    np.testing.assert_allclose(q, design.charge_values)
    assert float(blocks["scale_bar"].field_data["length (m)"][0]) > 0
    legend = [str(x) for x in blocks.field_data["legend"]]
    assert legend[0].startswith("charges: red > 0, blue < 0") and legend[-1].startswith("scale")


def test_carriers_are_drawn_at_their_real_radius_and_magnets_by_volume():
    design = small_design(
        charge_radii=[0.02, 0.03, 0.01],
        charge_masses=[0.01, 0.01, 0.01],
        dipole_volumes=[1e-6],
        dipole_masses=[0.0075],
    )
    blocks = viz.design_blocks(design)
    for i, radius in enumerate((0.02, 0.03, 0.01)):
        sphere = blocks["charges"][i]
        reach = np.linalg.norm(sphere.points - design.charge_positions[i], axis=1)
        np.testing.assert_allclose(reach, radius, rtol=1e-5)  # float32 points
    assert len(blocks["magnets"]) == 1
    expected = np.cbrt(3e-6 / (4 * np.pi))
    assert float(blocks["magnets"][0].field_data["radius (m)"][0]) == pytest.approx(expected)


def test_dipole_arrows_stick_out_of_every_sphere_around_them():
    design = small_design()
    blocks = viz.design_blocks(design)
    arrow = blocks["dipoles"][0]
    mass = blocks["masses"][0]
    centre = design.mass_positions[0]
    mass_reach = np.max(np.linalg.norm(mass.points - centre, axis=1))
    arrow_reach = np.max(np.linalg.norm(arrow.points - centre, axis=1))
    assert arrow_reach > 1.2 * mass_reach


def test_plot_draws_into_a_users_plotter_and_renders():
    plotter = pv.Plotter(off_screen=True, window_size=(200, 150))
    try:
        out = small_design().plot(plotter, show=False)
        assert out is plotter
        assert len(plotter.renderer.actors) >= 5
        image = plotter.screenshot(None, return_img=True)
        assert image.shape[:2] == (150, 200)
    finally:
        plotter.close()


def test_render_image_is_a_picture_notebooks_display(tmp_path):
    picture = viz.render_image(small_design(), window_size=(160, 120))
    assert isinstance(picture, np.ndarray) and picture.shape == (120, 160, 3)
    assert picture._repr_png_().startswith(b"\x89PNG")
    assert picture.save(tmp_path / "p.png").stat().st_size > 0


def test_notebook_backend_falls_back_to_static_without_a_display(monkeypatch):
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    monkeypatch.setattr(viz.sys, "platform", "linux")
    previous = pv.global_theme.jupyter_backend
    try:
        assert viz.notebook_backend() == "static"
        assert pv.global_theme.jupyter_backend == "static"
    finally:
        pv.set_jupyter_backend(previous)


def test_design_html_has_a_table_and_a_picture():
    html = small_design()._repr_html_()
    assert "<table" in html and "data:image/png;base64" in html
