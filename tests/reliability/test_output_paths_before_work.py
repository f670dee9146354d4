"""Output paths are checked before the work (issue 43 item 6): ``frontier --recommend
rec.toml`` onto an existing file was refused ("... is not a directory"), and
``--recommend new/rec.toml`` with ``new/`` missing failed only after 51 s of search. An
existing file is a valid target unless it is an input; a file's missing folder is refused at
once, for every command's file output. And (issue 39 item 7) what ``files.py`` keeps beyond
a temporary file and ``os.replace``, each with the test that shows it protects the user."""

from __future__ import annotations

import os
from pathlib import Path

import pytest
from reliability_support import refused

from chargedesign import files
from chargedesign.errors import InputError
from chargedesign.files import atomic_directory, check_output_location

EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "scenes"


def test_an_existing_file_is_a_valid_target(tmp_path: Path) -> None:
    target = tmp_path / "rec.toml"
    target.write_text("old\n")
    assert check_output_location(target, option="--recommend") == target


@pytest.mark.parametrize("option", ["--recommend", "--out", "--screenshot"])
def test_a_files_missing_folder_is_refused_at_once(option: str, tmp_path: Path) -> None:
    with pytest.raises(InputError, match=f"{option}: .*directory .*new does not exist"):
        check_output_location(tmp_path / "new" / "rec.toml", option=option)


def test_a_folder_output_may_still_be_made_with_its_parents(tmp_path: Path) -> None:
    check_output_location(tmp_path / "a" / "b", option="--out", directory=True)


def _no_search(*args: object, **kwargs: object) -> None:
    raise AssertionError("the search ran before the output was checked")


def test_frontier_recommend_into_a_missing_folder_is_refused_before_the_search(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    import chargedesign.commands.frontier as frontier

    monkeypatch.setattr(frontier, "recommend", _no_search)
    scene = EXAMPLES / "chaplygin_magnetic.toml"
    argv = ["frontier", str(scene), "--recommend", str(tmp_path / "new" / "rec.toml")]
    line = refused(argv, "frontier", capsys, tmp_path)
    assert "--recommend" in line and "does not exist" in line, line


def test_frontier_recommend_onto_its_own_scene_is_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    scene = tmp_path / "scene.toml"
    scene.write_text((EXAMPLES / "chaplygin_magnetic.toml").read_text())
    line = refused(
        ["frontier", str(scene), "--recommend", str(scene)], "frontier", capsys, tmp_path
    )
    assert "input" in line, line


def test_a_folder_swap_never_leaves_the_folder_missing(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Why ``atomic_directory`` keeps the exchange (renameat2) beyond ``os.replace``: a
    folder cannot be replaced by ``os.replace`` when it is not empty, and renaming it aside
    first leaves a moment without it. With the exchange the folder exists at every rename."""
    target = tmp_path / "out"
    target.mkdir()
    (target / "design.json").write_text("old")
    seen: list[bool] = []
    rename = os.rename

    def watched(src: object, dst: object) -> None:
        seen.append(target.exists())
        rename(src, dst)  # type: ignore[arg-type]

    monkeypatch.setattr(files.os, "rename", watched)
    with atomic_directory(target) as stage:
        (stage / "design.json").write_text("new")
    assert (target / "design.json").read_text() == "new"
    assert all(seen), "the folder was missing during the swap"
