"""Sweeps: the same summary on every executor, resume after a killed worker, bad files."""

from __future__ import annotations

import csv
import json
import sys
from pathlib import Path

import pytest
from unit_scene import UNIT_SCENE

from chargedesign.body import read_design
from chargedesign.cli import main
from chargedesign.errors import InputError
from chargedesign.physical.materials import BREAKDOWN_V_PER_M
from chargedesign.sweeps import load_sweep, make_executor, run_sweep, sweep_from_dict
from chargedesign.tolerancing import MaterialErrors, tolerance_report

HERE = Path(__file__).parent
if str(HERE) not in sys.path:  # sweep_helpers, for this process and the spawned workers
    sys.path.insert(0, str(HERE))
EXAMPLES = HERE.parent.parent / "examples" / "sweeps"

import sweep_helpers  # noqa: E402  (after the path above, for the spawned workers)


def _rows(path: Path) -> list[dict[str, str]]:
    with open(path / "summary.csv", newline="") as fh:
        rows = list(csv.DictReader(fh))
    for r in rows:
        r.pop("seconds")
    return rows


def _theorem_sweep(tmp_path: Path) -> Path:
    text = (EXAMPLES / "theorem_scene.toml").read_text()
    (tmp_path / "scene.toml").write_text(text)
    sweep = tmp_path / "sweep.toml"
    sweep.write_text(
        'scene = "scene.toml"\ncommand = "simulate"\n[grid]\n'
        '"parameters.n" = [0.5, 0.7, 0.9]\n"simulation.t_end" = [1.0, 2.0]\n'
    )
    return sweep


@pytest.fixture(scope="module")
def serial_summary(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("serial")
    spec = load_sweep(_theorem_sweep(tmp))
    result = run_sweep(spec, tmp / "out")
    assert result.failed == 0 and result.lost == 0 and len(result.rows) == 6
    return _rows(tmp / "out")


def test_serial_summary_has_keys_status_figures(serial_summary, tmp_path):
    row = serial_summary[0]
    assert list(row)[:4] == ["point", "parameters.n", "simulation.t_end", "status"]
    assert row["status"] == "ok" and float(row["I4_rel_drift"]) < 1e-9
    import pyarrow.parquet as pq

    spec = load_sweep(_theorem_sweep(tmp_path))
    run_sweep(spec, tmp_path / "o")
    table = pq.read_table(tmp_path / "o" / "summary.parquet")
    assert table.num_rows == 6 and "I4_rel_drift" in table.column_names


def test_process_pool_gives_the_same_summary(serial_summary, tmp_path):
    handle = make_executor("process", workers=2)
    try:
        result = run_sweep(load_sweep(_theorem_sweep(tmp_path)), tmp_path / "out", executor=handle)
    finally:
        handle.close()
    assert result.workers == 2
    assert _rows(tmp_path / "out") == serial_summary


@pytest.mark.filterwarnings("ignore::DeprecationWarning:distributed.*")
@pytest.mark.filterwarnings("ignore::ResourceWarning")
def test_dask_local_cluster_gives_the_same_summary(serial_summary, tmp_path):
    pytest.importorskip("distributed")
    handle = make_executor("dask", workers=2)
    try:
        result = run_sweep(load_sweep(_theorem_sweep(tmp_path)), tmp_path / "out", executor=handle)
    finally:
        handle.close()
    assert result.executor == "dask" and result.failed == 0
    assert _rows(tmp_path / "out") == serial_summary


def _helper_sweep(tmp_path: Path, values: list[float], **options: object) -> Path:
    opts = "".join(
        f'{k} = "{v}"\n' if isinstance(v, str) else f"{k} = {v}\n" for k, v in options.items()
    )
    sweep = tmp_path / "helper.toml"
    sweep.write_text(f'chunk = 1\n[grid]\n"parameters.n" = {values}\n[options]\n{opts}')
    return sweep


def test_failing_point_records_one_line_and_the_sweep_goes_on(tmp_path):
    spec = load_sweep(_helper_sweep(tmp_path, [1.0, -1.0, 2.0]), command=sweep_helpers.square)
    result = run_sweep(spec, tmp_path / "out")
    assert result.failed == 1
    rows = {r["parameters.n"]: r for r in _rows(tmp_path / "out")}
    assert rows["-1.0"]["status"] == "failed"
    assert rows["-1.0"]["reason"] == "ValueError: n must be >= 0 here"
    assert rows["2.0"]["n2"] == "4.0" and rows["2.0"]["status"] == "ok"
    assert (tmp_path / "out" / "points" / "p0002" / "note.txt").read_text() == "2.0\n"


def test_killed_worker_loses_no_finished_point_and_resume_completes(tmp_path):
    marker = tmp_path / "killed"
    values = [0.0, 1.0, 2.0, 3.0, 4.0, 5.0]
    sweep = _helper_sweep(tmp_path, values, marker=str(marker), kill=3.0, sleep=0.2)
    out = tmp_path / "out"
    handle = make_executor("process", workers=2)
    try:
        first = run_sweep(load_sweep(sweep, command=sweep_helpers.square), out, executor=handle)
    finally:
        handle.close()
    assert marker.exists()
    assert first.lost >= 1 and "BrokenProcessPool" in first.lost_reason
    done = {r["point"] for r in _rows(out) if r["status"] == "ok"}
    for r in _rows(out):
        assert r["status"] in ("ok", "not run")
        if r["status"] == "ok":  # every finished point is complete on disk
            assert (out / "points" / r["point"] / "note.txt").is_file()
    with pytest.raises(InputError, match="--resume"):
        run_sweep(load_sweep(sweep, command=sweep_helpers.square), out)
    handle = make_executor("process", workers=2)
    try:
        spec = load_sweep(sweep, command=sweep_helpers.square)
        second = run_sweep(spec, out, executor=handle, resume=True)
    finally:
        handle.close()
    assert second.skipped == len(done) and second.ran == len(values) - len(done)
    rows = _rows(out)
    assert all(r["status"] == "ok" for r in rows)
    assert [float(r["n2"]) for r in rows] == [v * v for v in values]


@pytest.mark.parametrize(
    ("body", "needle"),
    [
        ('command = "design"\n[grid]\n"bodyy.radius" = [1.0]\n', "'bodyy.radius'"),
        ('command = "design"\n[grid]\n"parameters.nn" = [1.0]\n', "'parameters.nn'"),
        ('command = "design"\n[grid]\n"body.radiuss" = [1.0]\n', "'body.radiuss'"),
        ('command = "design"\n[grid]\n"simulation.t_end" = [-1.0]\n', "'simulation.t_end'"),
        ('command = "design"\n[grid]\n"body.radius" = []\n', "empty"),
        ('command = "design"\n[grid]\n', "empty grid"),
        ('command = "desing"\n[grid]\n"body.radius" = [1.0]\n', "'desing'"),
        ('command = "design"\nsamples = 3\n[grid]\n"body.radius" = [1.0]\n', "'samples'"),
        (
            'command = "design"\n[random]\nsamples = 2\n"body.radius" = {normal = [1, 2]}\n',
            "'body.radius'",
        ),
    ],
)
def test_bad_sweep_files_get_one_line_errors_naming_the_key(tmp_path, capsys, body, needle):
    path = tmp_path / "bad.toml"
    path.write_text(body)
    assert main(["sweep", str(path), "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err.strip()
    assert needle in err and "\n" not in err, err
    assert not (tmp_path / "o").exists()


def test_unreachable_scheduler_is_a_one_line_error(tmp_path, capsys):
    pytest.importorskip("distributed")
    sweep = _theorem_sweep(tmp_path)
    code = main(
        ["sweep", str(sweep), "--out", str(tmp_path / "o"), "--scheduler", "tcp://127.0.0.1:9"]
    )
    assert code == 2
    err = capsys.readouterr().err.strip()
    assert "--scheduler tcp://127.0.0.1:9" in err and "\n" not in err


def test_random_sample_points(tmp_path):
    spec = sweep_from_dict(
        {
            "command": "frontier",
            "grid": {"fields.magnetic.a1": [1.0, 2.0]},
            "random": {"samples": 3, "seed": 1, "parameters.n": {"uniform": [0.1, 1.0]}},
        }
    )
    assert len(spec.points) == 6 and spec.keys == ["fields.magnetic.a1", "parameters.n"]
    assert all(0.1 <= p["parameters.n"] <= 1.0 for p in spec.points)


def test_a_frontier_sweep_over_media_follows_their_breakdown_fields(tmp_path):
    """Where the carriers' breakdown binds, n_max is proportional to the breakdown field
    (docs/buildable.md): the ratio across media is that of the materials' table, to the
    frontier's 1 % bisection; a scene without [medium] fails its point with the reason."""
    small = Path(__file__).resolve().parents[1] / "physical" / "small.toml"
    spec = sweep_from_dict(
        {
            "scene": str(small),
            "command": "frontier",
            # the charges reading: n_max is its frontier (frame's is K_max)
            "grid": {"medium.name": ["air", "sf6"], "design.larmor": ["charges"]},
        }
    )
    result = run_sweep(spec, tmp_path / "f")
    assert result.failed == 0 and result.lost == 0
    n_max = {row["medium.name"]: row["n_max"] for row in result.rows}
    # the carriers' breakdown sets how many carriers a rate needs; their ballast may be what
    # fails first (masses), and the design depends on the safe field only through s / E_safe
    assert all(row["binding_detail.stage"] in ("charges", "masses") for row in result.rows)
    expected = BREAKDOWN_V_PER_M["sf6"] / BREAKDOWN_V_PER_M["air"]
    assert n_max["sf6"] / n_max["air"] == pytest.approx(expected, rel=0.025)
    for row in result.rows:
        written = json.loads(
            (tmp_path / "f" / "points" / row["point"] / "frontier.json").read_text()
        )
        assert written["n_max"] == row["n_max"]
    bare = run_sweep(
        sweep_from_dict(
            {"command": "frontier", "grid": {"parameters.n": [0.5]}, "scene": str(UNIT_SCENE)}
        ),
        tmp_path / "bare",
    )
    (row,) = bare.rows
    assert row["status"] == "failed" and row["reason"].startswith(
        "frontier: the scene has no [medium]"
    )


def test_ctrl_c_keeps_finished_points_and_the_summary_lists_every_point(tmp_path):
    sweep = tmp_path / "ctrl_c.toml"
    sweep.write_text(
        '[grid]\n"parameters.n" = [0.0, 1.0, 2.0, 3.0]\n'
        f'[options]\nat = 2.0\nmarker = "{tmp_path / "marker"}"\n'
    )
    out = tmp_path / "out"
    with pytest.raises(KeyboardInterrupt):
        run_sweep(load_sweep(sweep, command=sweep_helpers.interrupt_at), out)
    rows = _rows(out)
    assert [r["status"] for r in rows] == ["ok", "ok", "not run", "not run"]
    assert not list((out / "points").glob(".*"))  # no staging folder left behind
    second = run_sweep(load_sweep(sweep, command=sweep_helpers.interrupt_at), out, resume=True)
    assert second.skipped == 2 and second.ran == 2
    assert [r["n2"] for r in _rows(out)] == ["0.0", "1.0", "4.0", "9.0"]


@pytest.mark.filterwarnings("ignore::DeprecationWarning:distributed.*")
@pytest.mark.filterwarnings("ignore::ResourceWarning")
def test_joining_a_running_dask_scheduler(serial_summary, tmp_path):
    distributed = pytest.importorskip("distributed")
    import logging

    cluster = distributed.LocalCluster(
        n_workers=1,
        threads_per_worker=1,
        processes=True,
        dashboard_address=None,
        silence_logs=logging.ERROR,
    )
    try:
        handle = make_executor("process", scheduler=cluster.scheduler_address)
        try:
            assert handle.kind == "dask" and handle.workers == 1
            run_sweep(load_sweep(_theorem_sweep(tmp_path)), tmp_path / "out", executor=handle)
        finally:
            handle.close()
    finally:
        cluster.close()
    assert _rows(tmp_path / "out") == serial_summary


def test_sweep_and_scene_files_go_through_the_safe_readers(tmp_path):
    """A FIFO would block a plain read and a deep TOML exhaust the parser: both get one line."""
    import os

    fifo = tmp_path / "scene.fifo"
    os.mkfifo(fifo)
    sweep = tmp_path / "s.sweep"
    sweep.write_text(f'scene = "{fifo}"\ncommand = "design"\n[grid]\n"parameters.n" = [0.5]\n')
    with pytest.raises(InputError, match=r"scene: .*not a regular file") as info:
        load_sweep(sweep)
    assert "\n" not in str(info.value)
    deep = tmp_path / "deep.sweep"
    deep.write_text("a = " + "[" * 200 + "]" * 200 + "\n")
    with pytest.raises(InputError, match="nested deeper"):
        load_sweep(deep)
    with pytest.raises(InputError, match="is a directory, expected a sweep file"):
        load_sweep(tmp_path)


def test_a_tolerance_sweep_takes_the_materials_errors_as_the_command_does(tmp_path):
    """options.chi_relative (tolerance --chi-relative) reaches each point's material
    analysis: its tolerance.json and figures equal the tolerance report of the point's own
    design with the same errors, computed here directly."""
    small = Path(__file__).resolve().parents[1] / "physical" / "small.toml"
    spec = sweep_from_dict(
        {
            "scene": str(small),
            "command": "tolerance",
            "grid": {"medium.name": ["sf6"]},
            "options": {"chi_relative": 1e-3, "samples": 20},
        }
    )
    result = run_sweep(spec, tmp_path / "t")
    assert result.failed == 0 and result.lost == 0
    (row,) = result.rows
    folder = tmp_path / "t" / "points" / row["point"]
    written = json.loads((folder / "tolerance.json").read_text())
    assert written["materials"]["errors"]["chi_relative"] == 1e-3
    direct = tolerance_report(
        read_design(folder / "design.json"),
        material_errors=MaterialErrors(chi_relative=1e-3),
        material_samples=20,
    ).materials
    assert direct is not None
    p90 = direct.to_dict()["induced_over_term"]["monte_carlo"]["p90"]
    assert row["induced_over_term_p90"] == pytest.approx(p90, rel=1e-12)
    assert (
        written["materials"]["induced_over_term"]["monte_carlo"]["p90"]
        == row["induced_over_term_p90"]
    )
    # the deprecated column is an alias of the same figure, not a second one
    assert row["induced_fraction_p90"] == row["induced_over_term_p90"]


#: a small region scene whose body the designer would make (charges reading: no [medium])
_REGION = (
    "[parameters]\nC = 1.0\nc = 0.3\nd = -0.4\nn = 0.7\nK = 0.5\nkappa = 0.9\n"
    '[fields.magnetic]\na1 = 1.0\na2 = 0.5\n[body]\nshape = "ball"\nradius = 1.0\n'
    "spacing = 0.34\n[simulation]\nt_end = 1.0\nsamples = 11\n"
)


@pytest.mark.parametrize(
    ("scene", "command", "grid", "refused"),
    [
        # the theorem's reduced model and a region designed in the charges reading: no frame
        ("theorem", "simulate", '"simulation.axes" = ["inertial", "turning"]', "p0001"),
        ("region", "simulate", '"simulation.axes" = ["inertial", "turning"]', "p0001"),
        ("region", "design", '"design.solver" = ["auto", "NOSUCH"]', "p0001"),
        ("region", "design", '"design.solver" = ["clarabel", "highs"]', None),
        # the same region designed in the frame reading may be read in turning axes
        (
            "region",
            "simulate",
            '"simulation.axes" = ["turning"]\n"design.larmor" = ["frame"]',
            None,
        ),
    ],
)
def test_values_valid_only_for_some_bodies_are_checked_for_every_point_before_any_runs(
    tmp_path, scene, command, grid, refused
):
    """Issue 32: "simulation.axes" = "turning" on a body without a frame reading, and a
    design.solver that names no installed solver, failed only when their point ran, after the
    points before them had written. Validation alone (load_sweep) finds them now."""
    text = (EXAMPLES / "theorem_scene.toml").read_text() if scene == "theorem" else _REGION
    (tmp_path / "scene.toml").write_text(text)
    path = tmp_path / "sweep.toml"
    path.write_text(f'scene = "scene.toml"\ncommand = "{command}"\n[grid]\n{grid}\n')
    if refused is None:
        assert len(load_sweep(path).points) >= 1
        return
    with pytest.raises(InputError) as info:
        load_sweep(path)
    line = str(info.value)
    assert "\n" not in line and f"point {refused}" in line, line
    key = "simulation.axes" if "axes" in grid else "design.solver"
    assert f"{key}: " in line and ("frame body" in line or "installed solver" in line), line
