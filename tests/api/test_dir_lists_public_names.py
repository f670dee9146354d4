"""``dir(chargedesign)`` lists only the public names: ``__all__`` (it once showed ``Any``,
``TYPE_CHECKING``, ``annotations`` and ``importlib``)."""

from __future__ import annotations

import chargedesign as cd


def test_dir_is_all_and_every_name_resolves() -> None:
    _ = cd.design  # a stage loaded: its submodules are attributes now, still not listed
    names = dir(cd)
    assert names == sorted(cd.__all__)
    for leaked in ("Any", "TYPE_CHECKING", "annotations", "importlib", "api", "errors"):
        assert leaked not in names, leaked
    assert all(not n.startswith("_") or n == "__version__" for n in names)
    for name in names:
        assert getattr(cd, name) is not None, name
