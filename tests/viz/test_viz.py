"""Rendering (off screen), animation and the `show` command.

Pictures are checked structurally: size, many distinct colours, and the presence or absence of
the hues that only charges of each sign draw (red positive, blue negative).
"""

import math

import imageio.v3 as iio
import numpy as np
import pytest

from chargedesign import viz
from chargedesign.body import Design, write_design
from chargedesign.cli import main
from chargedesign.errors import InputError
from chargedesign.params import Parameters
from chargedesign.quadrature import ContinuousBody
from chargedesign.validation import input_error

SMALL = (160, 120)


def make_design(charges=(), masses=(), dipoles=(), continuous=()):
    """Elements on a ring of radius 0.6 m plus a few on the z axis."""

    def ring(n, z):
        angles = 2.0 * math.pi * np.arange(n) / max(n, 1)
        return np.column_stack([0.6 * np.cos(angles), 0.6 * np.sin(angles), np.full(n, z)])

    return Design(
        parameters=Parameters(C=1.0, c=0.3, d=-0.4, n=0.7, K=0.5, kappa=0.9),
        fields={"magnetic": (1.0, 1.0)},
        charge_positions=ring(len(charges), 0.2),
        charge_values=np.asarray(charges, dtype=float),
        mass_positions=ring(len(masses), -0.3),
        mass_values=np.asarray(masses, dtype=float),
        dipole_positions=np.zeros((len(dipoles), 3)),
        dipole_moments=np.asarray(dipoles, dtype=float).reshape(-1, 3),
        continuous=list(continuous),
        realises=["mu"],
    )


def red_pixels(image):
    r, g, b = (image[..., i].astype(int) for i in range(3))
    return int(np.count_nonzero((r >= 170) & (g <= 60) & (b <= 60)))


def blue_pixels(image):
    r, g, b = (image[..., i].astype(int) for i in range(3))
    return int(np.count_nonzero((b >= 170) & (r <= 60) & (g <= 60)))


def distinct_colours(image):
    return len(np.unique(image.reshape(-1, 3), axis=0))


def test_screenshot_of_both_signs_is_written_with_size_and_both_hues(tmp_path):
    design = make_design(charges=[1.0, -1.0, 0.5, -0.25], masses=[0.2, 0.2], dipoles=[[0, 0, 1]])
    path = viz.render_screenshot(
        design, tmp_path / "body.png", region={"shape": "ball", "radius": 1.0}, window_size=SMALL
    )
    image = iio.imread(path)
    assert path == tmp_path / "body.png"
    assert image.shape[:2] == (SMALL[1], SMALL[0])
    assert distinct_colours(image[..., :3]) > 200
    assert red_pixels(image) > 10 and blue_pixels(image) > 10
    assert sorted(p.name for p in tmp_path.iterdir()) == ["body.png"]  # no temporary left


@pytest.mark.parametrize(
    ("charges", "red", "blue"),
    [([0.7, 0.2], True, False), ([], False, False), ([-0.3, -1.0], False, True)],
)
def test_hues_appear_only_for_charges_of_that_sign(charges, red, blue):
    # masses, a dipole, a box region and a mass body draw grey, green, gold: never red or blue
    mass_body = ContinuousBody.from_dict(
        {
            "kind": "mass",
            "shape": "box",
            "half_size": 0.2,
            "density": {"type": "uniform", "value": 1},
        }
    )
    design = make_design(
        charges=charges, masses=[0.1, 0.3, 0.2], dipoles=[[0.2, 0.0, 0.1]], continuous=[mass_body]
    )
    image = viz.render_image(
        design,
        region={"shape": "box", "half_size": [0.8, 0.8, 0.5]},
        gamma=(0.3, 0.0, 1.0),
        window_size=SMALL,
    )
    assert image.shape == (SMALL[1], SMALL[0], 3) and image.dtype == np.uint8
    assert distinct_colours(image) > 100
    assert (red_pixels(image) > 10) is red
    assert (blue_pixels(image) > 10) is blue
    assert red_pixels(image) == 0 or red
    assert blue_pixels(image) == 0 or blue


def test_charge_colours_are_linear_in_q_and_keep_their_sign_near_zero():
    cmap, (lo, hi) = viz.charge_colormap(np.array([-0.5, 2.0]))
    assert (lo, hi) == (-0.5, 2.0)
    floor = viz.CHARGE_TINT_FLOOR

    def colour(q):
        return np.array(cmap((q - lo) / (hi - lo))[:3])

    def tint(color, weight):
        return weight * np.array(color) + (1.0 - weight)

    np.testing.assert_allclose(colour(2.0), viz.POSITIVE_COLOR, atol=1e-2)
    # just above and below zero: the lightest tint of each sign, never white or grey
    np.testing.assert_allclose(colour(0.02), tint(viz.POSITIVE_COLOR, floor), atol=1e-2)
    np.testing.assert_allclose(colour(-0.02), tint(viz.NEGATIVE_COLOR, floor), atol=1e-2)
    # the colours drawn are exact in the sign however small the charge, down to round-off
    # (|q| < viz.ROUND_OFF_CHARGE of the largest: white, as zero)
    rgb = viz.charge_colors(np.array([1e-8, -1e-8, 0.0, 2.0, 1e-300, -1e-12]))
    np.testing.assert_allclose(rgb[0], tint(viz.POSITIVE_COLOR, floor), atol=1e-8)
    np.testing.assert_allclose(rgb[1], tint(viz.NEGATIVE_COLOR, floor), atol=1e-8)
    np.testing.assert_allclose(rgb[2], (1.0, 1.0, 1.0))
    np.testing.assert_allclose(rgb[3], viz.POSITIVE_COLOR)
    np.testing.assert_allclose(rgb[4:], np.ones((2, 3)))
    # -0.5 is a quarter of the largest |q|: a quarter of the way from the floor to full blue
    weight = floor + (1.0 - floor) * 0.25
    np.testing.assert_allclose(colour(-0.5), tint(viz.NEGATIVE_COLOR, weight), atol=1e-2)
    only_positive, limits = viz.charge_colormap(np.array([0.1, 0.4]))
    assert limits == (0.0, 0.4)
    np.testing.assert_allclose(only_positive(0.0)[:3], tint(viz.POSITIVE_COLOR, floor), atol=1e-2)


def test_region_outlines_lie_on_the_region():
    ball = viz.region_mesh({"shape": "shell", "radius": 0.7})
    np.testing.assert_allclose(np.linalg.norm(ball.points, axis=1), 0.7, rtol=1e-6)
    box = viz.region_mesh({"shape": "box", "half_size": [0.1, 0.2, 0.3]})
    np.testing.assert_allclose(box.bounds, (-0.1, 0.1, -0.2, 0.2, -0.3, 0.3), atol=1e-7)
    cyl = viz.region_mesh({"shape": "cylinder", "radius": 0.5, "height": 2.0})
    np.testing.assert_allclose(np.hypot(cyl.points[:, 0], cyl.points[:, 1]), 0.5, rtol=1e-6)
    np.testing.assert_allclose(np.abs(cyl.points[:, 2]), 1.0, rtol=1e-7)
    assert viz.region_mesh({"shape": "points"}) is None
    with pytest.raises(ValueError, match=r"region\.shape: expected one of"):
        viz.region_mesh({"shape": "cone"})
    with pytest.raises(InputError, match=r"region\.radius: expected a number > 0"):
        viz.region_mesh({"shape": "ball", "radius": -1.0})


def test_region_recorded_in_the_design_is_found():
    design = make_design(charges=[1.0])
    assert viz.region_from_design(design) is None
    design.further_keys["body"] = {"shape": "ball", "radius": 1.0, "spacing": 0.25}
    assert viz.region_from_design(design) == {"shape": "ball", "radius": 1.0, "spacing": 0.25}


def test_continuous_body_meshes_and_colours():
    charge = ContinuousBody.from_dict(
        {
            "kind": "charge",
            "shape": "cylinder",
            "radius": 0.2,
            "height": 0.6,
            "center": [0.0, 0.0, 0.1],
            "density": {"type": "uniform", "value": -3.0},
        }
    )
    mesh = viz.continuous_body_mesh(charge)
    np.testing.assert_allclose(mesh.bounds[4:], (-0.2, 0.4), atol=1e-7)
    assert viz.continuous_body_color(charge, mesh) == viz.NEGATIVE_COLOR
    mixed = ContinuousBody.from_dict(
        {
            "kind": "charge",
            "shape": "ball",
            "radius": 0.5,
            "density": {"type": "polynomial", "coefficients": {"z": 1.0}},
        }
    )
    assert viz.continuous_body_color(mixed, viz.continuous_body_mesh(mixed)) == "orchid"


def test_bad_render_inputs_are_named():
    """A caller's bad arguments to the drawing kernel are ValueErrors in the error template's
    words (the command line refuses what a user gives first: below)."""
    design = make_design(charges=[1.0])
    with pytest.raises(ValueError, match="window_size: expected two integers"):
        viz.render_image(design, window_size=(0, 10))
    with pytest.raises(ValueError, match="gamma: expected a non-zero vector"):
        viz.render_image(design, gamma=(0, 0, 0), window_size=SMALL)
    with pytest.raises(ValueError, match=r"screenshot path: expected a file name ending in \.png"):
        viz.render_screenshot(design, "picture.jpg")


def test_no_display_gives_a_clear_error(monkeypatch):
    monkeypatch.setattr(viz.sys, "platform", "linux")
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    with pytest.raises(ValueError, match="--screenshot"):
        viz.show_interactive(make_design(charges=[1.0]))


def rotation_z(angle):
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def spin_trajectory(n=9, rate=0.8, tilt=0.4):
    """Steady spin about a tilted axis: R(t) = Rx(tilt) Rz(rate t)."""
    t = np.linspace(0.0, 4.0, n)
    c, s = math.cos(tilt), math.sin(tilt)
    tilt_x = np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])
    return {"t": t, "rotation": np.array([tilt_x @ rotation_z(rate * ti) for ti in t])}


def test_frames_interpolate_the_rotation_between_samples():
    traj = viz.load_trajectory(spin_trajectory())
    times = np.array([0.0, 0.25, 1.3, 4.0])
    expected = viz.load_trajectory(
        {
            "t": times,
            "rotation": spin_trajectory()["rotation"][:1]
            @ np.array([rotation_z(0.8 * ti) for ti in times]),
        }
    )
    np.testing.assert_allclose(
        viz.frame_rotations(traj, times), expected.rotation, rtol=0.0, atol=1e-12
    )


def test_animation_writes_the_requested_number_of_frames(tmp_path):
    design = make_design(charges=[1.0, -1.0], masses=[0.5], dipoles=[[0.0, 0.3, 0.0]])
    calls = []
    path = viz.animate(
        design,
        spin_trajectory(),
        tmp_path / "spin.gif",
        frames=5,
        fps=10.0,
        region={"shape": "ball", "radius": 0.8},
        window_size=(96, 72),
        progress=lambda done, total: calls.append((done, total)),
    )
    frames = iio.imread(path, index=None)
    assert frames.shape[:3] == (5, 72, 96)
    assert calls[-1] == (5, 5) and len(calls) == 5
    # the body turns: consecutive frames differ below the time stamp (top rows)
    assert all(np.any(frames[i, 20:] != frames[i + 1, 20:]) for i in range(4))


def test_bad_trajectories_are_named(tmp_path):
    design = make_design(charges=[1.0])
    bad = spin_trajectory()
    bad["rotation"] = bad["rotation"] * 1.01
    with pytest.raises(InputError, match=r"trajectory\.rotation: expected rotation matrices"):
        viz.animate(design, bad, tmp_path / "a.gif", frames=2)
    with pytest.raises(InputError, match="missing key 'rotation'"):
        viz.animate(design, {"t": [0.0]}, tmp_path / "a.gif", frames=2)
    not_npz = tmp_path / "traj.npz"
    not_npz.write_text("{}")
    with pytest.raises(InputError, match=r"not a \.npz trajectory file"):
        viz.animate(design, not_npz, tmp_path / "a.gif", frames=2)
    with pytest.raises(ValueError, match="frames: expected an integer in"):
        viz.animate(design, spin_trajectory(), tmp_path / "a.gif", frames=0)
    with pytest.raises(ValueError, match=r"animation path: expected a file name ending in \.gif"):
        viz.animate(design, spin_trajectory(), tmp_path / "a.png", frames=2)
    assert not (tmp_path / "a.gif").exists()


def test_show_command_writes_a_screenshot_and_an_animation(tmp_path, capsys):
    design_path = tmp_path / "design.json"
    write_design(make_design(charges=[1.0, -0.5], masses=[0.3]), design_path)
    traj = spin_trajectory(n=5)
    # the simulation's file also carries omega, gamma (= R^T e_Z), integrals, quaternion
    extra = {"omega": np.zeros((5, 3)), "gamma": traj["rotation"][:, 2, :]}
    extra |= {"integrals": np.zeros((5, 4)), "quaternion": np.zeros((5, 4))}
    np.savez(tmp_path / "traj.npz", **traj, **extra)
    png, gif = tmp_path / "v.png", tmp_path / "v.gif"
    argv = ["show", str(design_path), "--screenshot", str(png), "--size", "96", "72"]
    argv += ["--gamma", "0", "1", "1", "--animate", str(tmp_path / "traj.npz"), "--out", str(gif)]
    assert main([*argv, "--frames", "3", "--json"]) == 0
    assert capsys.readouterr().out.strip() == (f'{{"screenshot": "{png}", "animation": "{gif}"}}')
    assert iio.imread(png).shape[:2] == (72, 96)
    assert iio.imread(gif, index=None).shape[:3] == (3, 72, 96)


@pytest.mark.parametrize(
    ("extra", "fragment"),
    [
        (["--animate", "traj.npz"], "--animate: needs --out"),
        (["--out", "x.gif"], "--out: names the animation file"),
        (["--screenshot", "x.png", "--scene", "missing.toml"], "missing.toml: no such scene file"),
    ],
)
def test_show_command_errors_are_one_line(tmp_path, capsys, monkeypatch, extra, fragment):
    monkeypatch.chdir(tmp_path)
    write_design(make_design(charges=[1.0]), tmp_path / "design.json")
    assert main(["show", "design.json", *extra]) == 2
    err = capsys.readouterr().err
    assert fragment in err and err.count("\n") == 1


def test_show_command_without_display_or_design(tmp_path, capsys, monkeypatch):
    monkeypatch.setattr(viz.sys, "platform", "linux")
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    write_design(make_design(charges=[1.0]), tmp_path / "design.json")
    assert main(["show", str(tmp_path / "design.json")]) == 2
    assert "render to a file with --screenshot PNG" in capsys.readouterr().err
    assert main(["show", str(tmp_path / "none.json"), "--screenshot", "x.png"]) == 2
    assert "no such design file" in capsys.readouterr().err


def test_show_refuses_bad_view_options_in_one_line_before_drawing(tmp_path, capsys):
    """The command line's checks (commands/show.py): the same one-line messages the drawing
    kernel gave, now InputErrors at the boundary, exit code 2, nothing written."""
    from chargedesign.cli import main

    design_path = tmp_path / "design.json"
    write_design(make_design(charges=[1.0]), design_path)
    np.savez(tmp_path / "t.npz", **spin_trajectory(n=5))
    shot = str(tmp_path / "s.png")
    jpg, png = str(tmp_path / "s.jpg"), str(tmp_path / "a.png")
    cases = [  # options; the template's name, what it expects, what it got
        (["--screenshot", jpg], "screenshot path", "a file name ending in .png", jpg),
        (
            ["--screenshot", shot, "--size", "10000", "100"],
            "window_size",
            "two integers (width, height) in 16..8192",
            (10000, 100),
        ),
        (
            ["--screenshot", shot, "--gamma", "0", "0", "0"],
            "gamma",
            "a non-zero vector",
            [0.0, 0.0, 0.0],
        ),
        (
            ["--animate", str(tmp_path / "t.npz"), "--out", png],
            "animation path",
            "a file name ending in .gif or .mp4",
            png,
        ),
    ]
    for options, name, expected, got in cases:
        assert main(["show", str(design_path), *options]) == 2
        message = str(input_error(name, expected, got))
        assert capsys.readouterr().err == f"chargedesign show: error: {message}\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["design.json", "t.npz"]
