"""Named regressions of issue 15: each bad input is one line (exit 2), never a traceback,
never silently coerced, and a failed run leaves its output folder as it was."""

from __future__ import annotations

import json
import os
import stat
from pathlib import Path

import numpy as np
import pytest
from reliability_support import SMALL_DESIGN, SMALL_SCENE, assert_clean_error, run_cli, snapshot

from chargedesign.body import Design, read_design
from chargedesign.errors import InputError
from chargedesign.files import atomic_directory, atomic_path, check_output_path
from chargedesign.limits import MAX_FIELD_DEGREE
from chargedesign.params import Parameters
from chargedesign.scene import load_scene
from chargedesign.validation import as_array, as_finite_float


def scene_file(tmp_path: Path, text: str = SMALL_SCENE, name: str = "scene.toml") -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


# ----------------------------------------------------------------------------- numbers


@pytest.mark.parametrize(
    "value", [True, False, np.bool_(True), 1 + 2j, np.complex128(1), "1.0", None, 10**400]
)
def test_scalars_that_are_not_real_finite_numbers_are_refused(value) -> None:
    with pytest.raises(InputError):
        as_finite_float(value, "x")


@pytest.mark.parametrize(
    "value",
    [
        [True, 1.0],
        [[0.0, 0.0, True]],
        np.array([True]),
        np.array([1 + 0j]),
        [1.0, 1j],
        [1.0, 10**400],
        ["1.0"],
    ],
)
def test_arrays_of_bool_complex_or_huge_items_are_refused_not_coerced(value) -> None:
    with pytest.raises(InputError):
        as_array(value, "x", (None,) * np.ndim(np.asarray(value, dtype=object)))


def test_booleans_are_refused_as_positions_and_values() -> None:
    with pytest.raises(InputError, match=r"charges\.positions"):
        Design(parameters=Parameters(), charge_positions=[[True, 0, 0]], charge_values=[1.0])
    with pytest.raises(InputError, match=r"charges\.values"):
        Design(parameters=Parameters(), charge_positions=[[0, 0, 0]], charge_values=[True])


@pytest.mark.parametrize(
    ("old", "new", "key"),
    [
        ("a1 = 1.0", "legendre = [true]\n", "fields.magnetic.legendre"),
        ("n = 0.7", "n = 1e200", "parameters.n"),
        ("C = 1.0", "C = 1e-308", "parameters.C"),
        ("K = 0.5", "K = 1e200", "parameters.K"),
        ("c = 0.3", "c = 1e200", "parameters.c"),
        ("a1 = 1.0", "a1 = 1e-308", "fields.magnetic.a1"),
        ("radius = 1.0", "radius = 1e200", "body.radius"),
        ("n = 0.7", "n = " + "9" * 400, "parameters.n"),
        ("radius = 1.0", "radius = " + "1" + "0" * 320, "body.radius"),
        ("a1 = 1.0", "a1 = nan", "fields.magnetic.a1"),
        ("radius = 1.0", "radius = 1.0\nmystery = 1", "body.mystery"),
    ],
)
def test_bad_scene_numbers_are_one_line_in_every_command(
    tmp_path: Path, capsys, old: str, new: str, key: str
) -> None:
    text = SMALL_SCENE.replace(old, new, 1)
    if "legendre" in new:
        text = text.replace("a2 = 0.5\n", "")
    path = scene_file(tmp_path, text)
    out = tmp_path / "out"
    for argv in (
        ["design", str(path), "--out", str(out), "--quiet", "--no-picture"],
        ["conditions", str(path)],
        ["simulate", str(path), "--t-end", "1", "--no-progress"],
    ):
        code, _, err = run_cli(argv, capsys)
        line = assert_clean_error(code, err, argv[0])
        assert key in line, line
    assert not out.exists()


def test_out_of_range_numbers_say_the_range_and_suggest_rescaling(tmp_path: Path) -> None:
    path = scene_file(tmp_path, SMALL_SCENE.replace("n = 0.7", "n = 1e200"))
    with pytest.raises(InputError, match=r"supported range.*rescale the units"):
        load_scene(path)


@pytest.mark.parametrize(
    ("argv_tail", "option"),
    [
        (["--total-charge", "1e300"], "--total-charge"),
        (["--total-mass", "1e300"], "--total-mass"),
        (["--max-charge", "nan"], "--max-charge"),
        (["--total-charge", "inf"], "--total-charge"),
    ],
)
def test_design_options_out_of_range_write_nothing(
    tmp_path: Path, capsys, argv_tail: list[str], option: str
) -> None:
    out = tmp_path / "out"
    out.mkdir()
    (out / "design.json").write_text("old")
    before = snapshot(out)
    code, _, err = run_cli(
        [
            "design",
            str(scene_file(tmp_path)),
            "--out",
            str(out),
            "--no-picture",
            "--quiet",
            *argv_tail,
        ],
        capsys,
    )
    assert option in assert_clean_error(code, err, "design")
    assert snapshot(out) == before


# ----------------------------------------------------------------------------- design.json


@pytest.mark.parametrize(
    ("changes", "text"),
    [
        ({"realises": 5}, None),
        ({"realises": None}, None),
        ({"realises": [1]}, None),
        ({"charges": {"positions": [[True, 0, 0]], "values": [1.0]}}, None),
        ({"charges": {"positions": [[0, 0, 1e300]], "values": [1.0]}}, None),
        ({"parameters": {"C": 1e-308}}, None),
        ({"fields": {"magnetic": {"legendre": [1.0] * 1000}}}, None),
        ({"fields": {"magnetic": {"legendre": [True]}}}, None),
        ({}, "[" * 100_000 + "]" * 100_000),
        ({}, '{"format": "chargedesign.design/1", "parameters": {"C": ' + "1" * 5000 + "}}"),
        ({}, json.dumps(SMALL_DESIGN)[:-1] + ', "note": NaN}'),
        ({}, json.dumps(SMALL_DESIGN)[:-1] + ', "note": 1e999}'),
        ({}, '{"format": "chargedesign.design/1", "parameters": {"C": 1e309}}'),
        ({}, "\xff\xfe not json"),
    ],
)
def test_bad_design_files_are_one_line_in_every_reader(
    tmp_path: Path, capsys, design_file, changes: dict, text: str | None
) -> None:
    path = design_file(text=text, **changes)
    with pytest.raises(InputError):
        read_design(path)
    for argv in (
        ["check", str(path), "--orientations", "10"],
        ["simulate", str(path), "--t-end", "1", "--no-progress"],
        ["show", str(path), "--screenshot", str(tmp_path / "x.png")],
        ["export", str(path), "--out", str(tmp_path / "x.csv")],
    ):
        code, _, err = run_cli(argv, capsys)
        assert_clean_error(code, err, argv[0])
    assert not (tmp_path / "x.png").exists() and not (tmp_path / "x.csv").exists()


def test_a_field_longer_than_the_cap_is_refused_by_its_degree(design_file) -> None:
    path = design_file(fields={"magnetic": {"legendre": [1.0] * (MAX_FIELD_DEGREE + 1)}})
    with pytest.raises(InputError, match=f"degree <= {MAX_FIELD_DEGREE}"):
        read_design(path)


def test_max_field_degree_is_the_conditions_engine_s() -> None:
    from chargedesign.moment_conditions import MAX_FIELD_DEGREE as ENGINE

    assert ENGINE == MAX_FIELD_DEGREE


# ----------------------------------------------------------------------------- data files


@pytest.mark.parametrize(
    ("name", "content"),
    [
        ("points.csv", b"0 0 0\n1 1 \xff\n"),
        ("points.npy", None),
        ("bools.npy", None),
        ("secret.csv", b"root:x:0:0:SECRET-LINE:/root:/bin/bash\nsecond:SECRET-TWO\n"),
    ],
)
def test_bad_point_files_are_one_line_without_their_content(
    tmp_path: Path, capsys, name: str, content: bytes | None
) -> None:
    data = tmp_path / name
    if name == "points.npy":
        np.save(data, np.ones((4, 3)) * (1 + 1j))
    elif name == "bools.npy":
        np.save(data, np.ones((4, 3), dtype=bool))
    else:
        assert content is not None
        data.write_bytes(content)
    text = SMALL_SCENE.replace(
        'shape = "ball"\nradius = 1.0\nspacing = 0.34', f'shape = "points"\npath = "{name}"'
    )
    code, _, err = run_cli(
        ["design", str(scene_file(tmp_path, text)), "--out", str(tmp_path / "out"), "--quiet"],
        capsys,
    )
    line = assert_clean_error(code, err, "design")
    assert "SECRET" not in err and "root:x" not in err, line
    assert not (tmp_path / "out").exists()


# ----------------------------------------------------------------------------- caps


def test_caps_on_requested_work_are_one_line(tmp_path: Path, capsys, design_file) -> None:
    path = design_file()
    code, _, err = run_cli(["check", str(path), "--orientations", "100000000"], capsys)
    assert "--orientations" in assert_clean_error(code, err, "check")
    code, _, err = run_cli(["check", str(path), "--quadrature-order", "100000"], capsys)
    assert "--quadrature-order" in assert_clean_error(code, err, "check")
    many = np.random.default_rng(0).normal(size=(30_000, 3)).tolist()
    big = design_file("big.json", charges={"positions": many, "values": [1e-9] * len(many)})
    code, _, err = run_cli(["show", str(big), "--screenshot", str(tmp_path / "b.png")], capsys)
    assert "--max-elements" in assert_clean_error(code, err, "show")
    for tail in (
        ["--t-end", "1e300"],
        ["--t-end", "1e20", "--step", "1e-12"],
        ["--samples", "100000000"],
    ):
        code, _, err = run_cli(
            ["simulate", str(path), "--method", "gauss-legendre", "--no-progress", *tail]
            if "--step" in tail
            else ["simulate", str(path), "--no-progress", *tail],
            capsys,
        )
        assert_clean_error(code, err, "simulate")


def test_linf_design_on_many_candidates_is_capped(tmp_path: Path, capsys) -> None:
    text = SMALL_SCENE.replace("spacing = 0.34", "spacing = 0.05")
    code, _, err = run_cli(
        [
            "design",
            str(scene_file(tmp_path, text)),
            "--objective",
            "linf",
            "--out",
            str(tmp_path / "out"),
            "--quiet",
        ],
        capsys,
    )
    assert "--max-linf-candidates" in assert_clean_error(code, err, "design")


# ----------------------------------------------------------------------------- paths


def test_scene_output_dir_stays_inside_the_working_directory(tmp_path: Path, capsys) -> None:
    for bad in ("/tmp/elsewhere", "../escape", "a/../../b", "~/x"):
        text = SMALL_SCENE + f'\n[output]\ndir = "{bad}"\n'
        code, _, err = run_cli(
            ["simulate", str(scene_file(tmp_path, text)), "--t-end", "1", "--no-progress"],
            capsys,
        )
        assert "output.dir" in assert_clean_error(code, err, "simulate")


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="needs FIFOs")
def test_special_files_and_links_are_never_written(tmp_path: Path, capsys, design_file) -> None:
    path = design_file()
    fifo = tmp_path / "f.json"
    os.mkfifo(fifo)
    code, _, err = run_cli(["export", str(path), "--out", str(fifo)], capsys)
    assert "FIFO" in assert_clean_error(code, err, "export")
    assert stat.S_ISFIFO(os.lstat(fifo).st_mode)
    real = tmp_path / "real.csv"
    real.write_text("keep")
    link = tmp_path / "link.csv"
    link.symlink_to(real)
    code, _, err = run_cli(["export", str(path), "--out", str(link)], capsys)
    assert "symbolic link" in assert_clean_error(code, err, "export")
    assert link.is_symlink() and real.read_text() == "keep"
    shot = tmp_path / "shot.png"
    shot.symlink_to(real)
    code, _, err = run_cli(["show", str(path), "--screenshot", str(shot)], capsys)
    assert "symbolic link" in assert_clean_error(code, err, "show")
    assert real.read_text() == "keep"
    folder = tmp_path / "realdir"
    folder.mkdir()
    (tmp_path / "outlink").symlink_to(folder)
    code, _, err = run_cli(
        [
            "design",
            str(scene_file(tmp_path)),
            "--out",
            str(tmp_path / "outlink"),
            "--quiet",
            "--no-picture",
        ],
        capsys,
    )
    assert "symbolic link" in assert_clean_error(code, err, "design")
    assert list(folder.iterdir()) == []
    with pytest.raises(InputError, match="device"):
        check_output_path("/dev/null")


def test_reading_special_files_is_refused(tmp_path: Path, capsys) -> None:
    fifo = tmp_path / "scene.toml"
    os.mkfifo(fifo)
    code, _, err = run_cli(["conditions", str(fifo)], capsys)
    assert "regular file" in assert_clean_error(code, err, "conditions")
    code, _, err = run_cli(["check", str(tmp_path)], capsys)
    assert "directory" in assert_clean_error(code, err, "check")


def test_os_errors_are_one_line_naming_the_path(tmp_path: Path, capsys, design_file) -> None:
    path = design_file()
    for out in ("/sys/chargedesign-out", "/proc/chargedesign-out/x"):
        code, _, err = run_cli(
            [
                "simulate",
                str(path),
                "--t-end",
                "1",
                "--no-progress",
                "--effects",
                "theorem",
                "--out",
                out,
            ],
            capsys,
        )
        assert "chargedesign-out" in assert_clean_error(code, err, "simulate")
    code, _, err = run_cli(["export", str(path), "--out", "/sys/x.csv"], capsys)
    assert "/sys" in assert_clean_error(code, err, "export")


# ----------------------------------------------------------------------------- all or nothing


def test_atomic_directory_swaps_the_whole_folder_or_nothing(tmp_path: Path) -> None:
    out = tmp_path / "out"
    out.mkdir()
    (out / "a.txt").write_text("old a")
    (out / "keep.txt").write_text("kept")
    with atomic_directory(out) as stage:
        (stage / "a.txt").write_text("new a")
        (stage / "b.txt").write_text("new b")
    assert snapshot(out).keys() == {"a.txt", "b.txt", "keep.txt"}
    assert (out / "a.txt").read_text() == "new a" and (out / "keep.txt").read_text() == "kept"
    before = snapshot(out)
    with pytest.raises(RuntimeError), atomic_directory(out) as stage:
        (stage / "a.txt").write_text("newer")
        raise RuntimeError("boom")
    assert snapshot(out) == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]  # no staging left
    with atomic_directory(out, drop=("b.txt",)) as stage:
        (stage / "c.txt").write_text("c")
    assert set(snapshot(out)) == {"a.txt", "c.txt", "keep.txt"}


def test_writes_into_an_open_folder_join_its_one_swap(tmp_path: Path) -> None:
    out = tmp_path / "out"
    with atomic_directory(out):
        with atomic_path(out / "x.json") as tmp:
            tmp.write_text("x")
        with atomic_directory(out) as inner:
            (inner / "y.txt").write_text("y")
        assert not out.exists()  # nothing visible until the outer block ends
    assert set(snapshot(out)) == {"x.json", "y.txt"}


def test_stale_staging_of_a_dead_process_is_removed_and_set_aside_folders_restored(
    tmp_path: Path,
) -> None:
    import subprocess
    import sys

    child = subprocess.run(
        [sys.executable, "-c", "import os; print(os.getpid())"],
        capture_output=True,
        text=True,
        timeout=60,
        check=True,
    )
    dead = int(child.stdout)
    out = tmp_path / "out"
    (tmp_path / f".out.staging.{dead}.abc123").mkdir()
    (tmp_path / f".out.staging.{dead}.abc123" / "design.json").write_text("half")
    (tmp_path / f".x.json.tmp.{dead}.zz.json").write_text("half")
    (tmp_path / f".gone.old.{dead}.0a1b").mkdir()  # killed between its two renames
    (tmp_path / f".gone.old.{dead}.0a1b" / "summary.json").write_text("complete")
    alive = tmp_path / f".other.staging.{os.getpid()}.keep"
    alive.mkdir()
    with atomic_directory(out) as stage:
        (stage / "a").write_text("a")
    names = sorted(p.name for p in tmp_path.iterdir())
    assert names == sorted(["out", "gone", alive.name]), names
    assert (tmp_path / "gone" / "summary.json").read_text() == "complete"
