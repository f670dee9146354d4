"""The documentation site builds with warnings as errors, and the contract is in the repo."""

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


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
    api = (tmp_path / "site" / "api" / "viz" / "index.html").read_text()
    assert "design_blocks" in api  # the reference is generated from the docstrings
    gallery = (tmp_path / "site" / "gallery" / "index.html").read_text()
    assert gallery.count("<img") >= 5


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
