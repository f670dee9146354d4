"""The documentation site builds with warnings as errors, and the contract is in the repo."""

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


# CI builds the site in `make docs` (mkdocs --strict, then tools/check_site.py): here only with
# `make test-slow`, where it would repeat that half a minute of the suite
@pytest.mark.slow
def test_docs_build_strict(tmp_path):
    mkdocs = Path(sys.executable).with_name("mkdocs")
    command = [str(mkdocs)] if mkdocs.exists() else [shutil.which("mkdocs") or "mkdocs"]
    env = {**os.environ, "NO_MKDOCS_2_WARNING": "1"}
    run = subprocess.run(
        [*command, "build", "--strict", "--site-dir", str(tmp_path / "site")],
        cwd=ROOT,
        capture_output=True,
        text=True,
        env=env,
        timeout=300,
    )
    assert run.returncode == 0, run.stderr[-3000:]
    assert _site_checks().site_problems(tmp_path / "site") == []


def _site_checks():
    import importlib.util

    spec = importlib.util.spec_from_file_location("check_site", ROOT / "tools/check_site.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_the_site_checks_find_a_missing_reference_and_pictures(tmp_path):
    (tmp_path / "api" / "viz").mkdir(parents=True)
    (tmp_path / "api" / "viz" / "index.html").write_text("<p>nothing</p>")
    (tmp_path / "gallery").mkdir()
    (tmp_path / "gallery" / "index.html").write_text("<img>" * 4)
    problems = _site_checks().site_problems(tmp_path)
    assert len(problems) == 2 and "design_blocks" in problems[0] and "4 pictures" in problems[1]
    (tmp_path / "api" / "viz" / "index.html").write_text("design_blocks")
    (tmp_path / "gallery" / "index.html").write_text("<img>" * 5)
    assert _site_checks().site_problems(tmp_path) == []


def test_the_contract_is_in_the_repository_and_linked():
    contract = ROOT / "docs" / "contract.md"
    assert "design.json (format `chargedesign.design/1`)" in contract.read_text()
    assert "(docs/contract.md)" in (ROOT / "README.md").read_text()
    assert "(contract.md)" in (ROOT / "docs" / "index.md").read_text()


@pytest.mark.parametrize("name", ["gallery_default.png", "gallery_yehia2003.png"])
def test_gallery_pictures_exist(name):
    assert (ROOT / "docs" / "images" / name).stat().st_size > 10_000


def test_the_docs_key_tables_are_the_declarations():
    """Every ``<!-- keys:TABLE -->`` block of docs/ is the table generated from
    chargedesign/scene/keys.py (regenerate: python tools/docs_tables.py)."""
    import importlib.util

    spec = importlib.util.spec_from_file_location("docs_tables", ROOT / "tools/docs_tables.py")
    assert spec is not None and spec.loader is not None
    docs_tables = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(docs_tables)
    pages = docs_tables.pages()
    assert {p.name for p in pages} >= {"schemas.md", "design.md"}
    for page in pages:
        text = page.read_text("utf-8")
        assert docs_tables.generated(text) == text, f"{page.name}: run tools/docs_tables.py"
    blocks = {m.group(2) for p in pages for m in docs_tables.BLOCK.finditer(p.read_text("utf-8"))}
    from chargedesign.scene.keys import DECLARED

    assert blocks == set(DECLARED)  # every declared table has its generated table
