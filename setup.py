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
from setuptools.command.build_py import build_py


def compiled_modules() -> tuple[str, ...]:
    """``MODULES`` of src/liansuo/kit/native.py, read without importing liansuo (its dependencies may be missing)."""
    spec = spec_from_file_location("liansuo_native", Path(__file__).parent / "src" / "liansuo" / "kit" / "native.py")
    assert spec is not None and spec.loader is not None
    module = module_from_spec(spec)
    spec.loader.exec_module(module)
    return tuple(module.MODULES)


ROOT = Path(__file__).parent
NEEDED = ("LICENSE", "docs/pypi.md", "src/liansuo/__init__.py")  # the licence, the long description, the package
DATA = {".py", ".typed"}  # what may lie at the package's top level besides its folders


def layout_problems(root: Path = ROOT) -> list[str]:
    """What makes this tree unfit to build from: a file the wheel needs is missing, or a layer of the package is a
    file instead of a folder (a checkout that turned links into text files, or a copy that lost folders). Setuptools
    builds such a tree without a word and the wheel then fails on import."""
    problems = [f"{name} is missing" for name in NEEDED if not (root / name).is_file()]
    package = root / "src" / "liansuo"
    if package.is_dir():
        problems += [f"src/liansuo/{p.name} is a file, not a folder of the package" for p in sorted(package.iterdir())
                     if p.is_file() and p.suffix not in DATA]
    return problems


def check_layout() -> None:
    problems = layout_problems()
    if problems:
        raise SystemExit("liansuo cannot be built from this tree: " + "; ".join(problems) + ". Build from a complete "
                         "checkout (git clone, or git checkout -- . to restore what is missing)")


class BuildWithDocs(build_py):
    """The package as built, with the documentation pages (docs/*.md) in it as liansuo/docs/, where
    ``liansuo docs TOPIC`` reads them wherever liansuo is installed."""

    def run(self) -> None:
        super().run()
        target = Path(self.build_lib) / "liansuo" / "docs"
        target.mkdir(parents=True, exist_ok=True)
        for page in sorted((ROOT / "docs").glob("*.md")):
            self.copy_file(str(page), str(target / page.name))


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


check_layout()
setup(cmdclass={"build_py": BuildWithDocs}, **native())
