"""The build: pure Python by default. With ``LIANSUO_NATIVE=1`` in the environment the modules of the hot path are also
compiled to C extensions with mypyc (part of mypy), which runs them about 1.5-2x faster with the same results. Which
modules, and the rules they keep, are in src/liansuo/kit/native.py (docs/native.md); everything else about the package
is in pyproject.toml.
"""

from __future__ import annotations

import os
from importlib.util import module_from_spec, spec_from_file_location
from pathlib import Path

from setuptools import setup


def compiled_modules() -> tuple[str, ...]:
    """``MODULES`` of src/liansuo/kit/native.py, read without importing liansuo (its dependencies may be missing)."""
    spec = spec_from_file_location("liansuo_native", Path(__file__).parent / "src" / "liansuo" / "kit" / "native.py")
    assert spec is not None and spec.loader is not None
    module = module_from_spec(spec)
    spec.loader.exec_module(module)
    return tuple(module.MODULES)


def native() -> dict[str, object]:
    """What ``setup`` takes for a native build, if asked for one."""
    if os.environ.get("LIANSUO_NATIVE", "") != "1":
        return {}
    try:
        from mypyc.build import mypycify
    except ImportError:
        raise SystemExit("a native build (LIANSUO_NATIVE=1) compiles with mypyc, which type-checks the modules first: "
                         "build it with --no-build-isolation in an environment with mypy, setuptools>=77 and "
                         "liansuo's dependencies installed (`make native` does all of it; docs/native.md)") from None
    return {"ext_modules": mypycify([f"src/liansuo/{m}.py" for m in compiled_modules()], opt_level="3")}


setup(**native())
