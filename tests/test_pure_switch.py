"""``LIANSUO_PURE=1``: liansuo's Python sources are imported even where a native build put compiled modules beside
them (docs/native.md), as ``liansuo mutate`` and the suite need; other packages are left to Python's own finders."""

from __future__ import annotations

import importlib.machinery
import os
import subprocess
import sys
from pathlib import Path

import liansuo
from liansuo.kit.native import PureFinder

SUFFIX = importlib.machinery.EXTENSION_SUFFIXES[0]


def a_native_build(tmp_path: Path) -> Path:
    """A folder as a native build leaves it: a module's source with a compiled module of the same name beside it."""
    (tmp_path / "cycle.py").write_text("WHAT = 'source'\n", encoding="utf-8")
    (tmp_path / f"cycle{SUFFIX}").write_bytes(b"\x7fELF not really")
    return tmp_path


def test_the_pure_finder_takes_the_source_where_python_would_take_the_compiled_module(tmp_path: Path) -> None:
    folder = a_native_build(tmp_path)
    usual = importlib.machinery.PathFinder.find_spec("cycle", [str(folder)])
    assert usual is not None and usual.origin is not None and usual.origin.endswith(SUFFIX)  # what it is there for
    spec = PureFinder().find_spec("liansuo.cycle", [str(folder)])
    assert spec is not None and spec.origin == str(folder / "cycle.py")


def test_the_pure_finder_leaves_other_packages_alone(tmp_path: Path) -> None:
    folder = a_native_build(tmp_path)
    assert PureFinder().find_spec("cycle", [str(folder)]) is None
    assert PureFinder().find_spec("numpy.cycle", [str(folder)]) is None
    assert PureFinder().find_spec("liansuo.nothing_here", [str(folder)]) is None


def test_the_suite_runs_the_python_sources_and_so_do_its_subprocesses() -> None:
    assert os.environ.get("LIANSUO_PURE") == "1"
    assert any(isinstance(f, PureFinder) for f in sys.meta_path)
    import liansuo.interlocking.core as core

    assert core.__file__ is not None and core.__file__.endswith(".py")
    assert liansuo.native_modules() == []
    out = subprocess.run([sys.executable, "-c", "import liansuo, sys; import liansuo.circuits.field as f; "
                          "print(f.__file__, any(type(x).__name__ == 'PureFinder' for x in sys.meta_path))"],
                         capture_output=True, text=True, check=True)
    path, installed = out.stdout.split()
    assert path.endswith("field.py") and installed == "True"
