"""The Kowalevski example scene (examples/scenes/kowalevski_case.toml) with keys replaced:
the case inputs of the issue-43 classes."""

from __future__ import annotations

from pathlib import Path

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "scenes" / "kowalevski_case.toml"


def case_scene(folder: Path, name: str = "case.toml", **replace: str) -> Path:
    """The example with each ``key = value`` line of ``replace`` set (TOML text as given);
    a key not in the example is added to ``[case.parameters]``. Returns its path."""
    lines = EXAMPLE.read_text().splitlines()
    seen = set()
    for i, line in enumerate(lines):
        key = line.split("=")[0].strip()
        if "=" in line and key in replace and not line.startswith("#"):
            lines[i] = f"{key} = {replace[key]}"
            seen.add(key)
    extra = [f"{k} = {v}" for k, v in replace.items() if k not in seen]
    at = lines.index("[case.parameters]") + 1
    lines[at:at] = extra
    path = folder / name
    path.write_text("\n".join(lines) + "\n")
    return path
