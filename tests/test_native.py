"""The native build against the Python sources: the same answers from the same installed wheel.

A native build (``LIANSUO_NATIVE=1 pip wheel --no-build-isolation .``, setup.py, docs/native.md) compiles the hot
path with mypyc. The wheel is built as a user builds it, from a copy of the checkout, and installed outside it; every
command below then runs twice in fresh processes on that install: compiled, and on its Python sources
(``LIANSUO_PURE=1``). The rest of the suite runs the Python sources only (tests/conftest.py), so this comparison is
what shows the compiled modules right: the interlocking test of every bundled and example station, random soak runs,
the example scripts and scenarios, the track-circuit models, and trains moving on a generated hub, each with the very
same report (timings left out). The console under a native build was tried by hand (docs/native.md).

It takes about four minutes (two of them building), so it runs on demand: ``pytest -m native``
(``make test-native``).
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from importlib.metadata import version
from pathlib import Path
from typing import Any

import pytest

from liansuo.kit.native import MODULES

pytestmark = pytest.mark.native

ROOT = Path(__file__).resolve().parents[1]
PKG = ROOT / "src" / "liansuo"
NOT_COPIED_AT_TOP = {".venv", ".git", "build", "dist", "tests", "docs"}
NOT_COPIED = {"__pycache__", ".pytest_cache", ".mypy_cache", ".ruff_cache", ".hypothesis"}
STATIONS = ["jiaopei", "gaotie", "depot", *(str(PKG / "examples" / "stations" / f"{name}.yaml")
                                            for name in ("danxian", "shuangxian", "doubleslip", "minimal"))]
TIMINGS = {"elapsed_s", "seconds"}

TRAINS = """\
import json
from liansuo.bench.trains import measure_trains
from liansuo.interlocking.table.build import build_table
from liansuo.stations.hubgen import generate_hub
from liansuo.stations.loader import load_text
station = load_text(generate_hub(50, 20), "<hub50>")
r = measure_trains(station, build_table(station), "kinematic", 1200)
print(json.dumps({k: r[k] for k in ("departures", "stalls", "mean_trains_moving")}))
"""

COMPILED = """\
import importlib, json, sys
import liansuo
for name in sys.argv[1:]:
    importlib.import_module(name)
print(json.dumps([liansuo.__file__, liansuo.native_modules()]))
"""


def native_list() -> list[str]:
    """The compiled modules (kit/native.py)."""
    return list(MODULES)


def _ignore(folder: str, names: list[str]) -> set[str]:
    top = Path(folder).resolve() == ROOT
    return {n for n in names if n in NOT_COPIED or n.endswith(".so") or (top and n in NOT_COPIED_AT_TOP)}


@pytest.fixture(scope="module")
def installed(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The native wheel, built from a copy of the checkout and installed into a folder of its own."""
    tmp = tmp_path_factory.mktemp("native")
    source = tmp / "source"
    shutil.copytree(ROOT, source, symlinks=True, ignore=_ignore)
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "LIANSUO_PURE")}
    env["LIANSUO_NATIVE"] = "1"
    # mypyc type-checks what it compiles, so the build runs in this environment, which has mypy and the dependencies
    assert int(version("setuptools").split(".")[0]) >= 77, "the build needs setuptools>=77 (make test-native has it)"
    built = subprocess.run([sys.executable, "-m", "pip", "wheel", "--no-deps", "--no-build-isolation", "--wheel-dir",
                            str(tmp / "dist"), str(source)], capture_output=True, text=True, env=env, timeout=900)
    assert built.returncode == 0, f"the native wheel did not build:\n{built.stdout[-3000:]}\n{built.stderr[-3000:]}"
    wheels = list((tmp / "dist").glob("liansuo-*.whl"))
    assert len(wheels) == 1 and "none-any" not in wheels[0].name, f"expected one platform wheel, got {wheels}"
    target = tmp / "site"
    done = subprocess.run([sys.executable, "-m", "pip", "install", "--no-deps", "--target", str(target),
                           str(wheels[0])], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr[-3000:]
    return target


def run(installed: Path, pure: bool, args: list[str], tmp: Path) -> subprocess.CompletedProcess[str]:
    env = {k: v for k, v in os.environ.items() if k not in ("LIANSUO_PURE", "LIANSUO_NATIVE")}
    env["PYTHONPATH"] = str(installed)
    if pure:
        env["LIANSUO_PURE"] = "1"
    return subprocess.run([sys.executable, *args], capture_output=True, text=True, env=env, cwd=tmp, timeout=600)


def both(installed: Path, args: list[str], tmp: Path) -> tuple[Any, Any]:
    """The JSON each build prints for ``args``, timings left out."""
    out = []
    for pure in (False, True):
        proc = run(installed, pure, args, tmp)
        assert proc.stdout.strip(), f"{'pure' if pure else 'native'} {args}: no output\n{proc.stderr[-3000:]}"
        out.append(_untimed(json.loads(proc.stdout)))
    return out[0], out[1]


def _untimed(value: Any) -> Any:
    if isinstance(value, dict):
        return {k: _untimed(v) for k, v in value.items() if k not in TIMINGS}
    if isinstance(value, list):
        return [_untimed(v) for v in value]
    return value


def test_the_hot_path_runs_compiled(installed: Path, tmp_path: Path) -> None:
    modules = [f"liansuo.{m.replace('/', '.')}" for m in native_list()]
    where, native = json.loads(run(installed, False, ["-c", COMPILED, *modules], tmp_path).stdout)
    assert Path(where).is_relative_to(installed)  # the wheel's install, not a checkout this environment may know
    assert native == sorted(modules)
    where, pure = json.loads(run(installed, True, ["-c", COMPILED, *modules], tmp_path).stdout)
    assert Path(where).is_relative_to(installed) and pure == []


@pytest.mark.parametrize("station", STATIONS, ids=lambda s: Path(s).stem)
def test_verify_reports_the_same(installed: Path, tmp_path: Path, station: str) -> None:
    native, pure = both(installed, ["-m", "liansuo.cli", "verify", station, "--format", "json"], tmp_path)
    assert native == pure
    assert pure["checks"] > 0


@pytest.mark.parametrize("station,seed", [("jiaopei", 3), ("gaotie", 5), ("depot", 7)])
def test_soak_runs_the_same(installed: Path, tmp_path: Path, station: str, seed: int) -> None:
    native, pure = both(installed, ["-m", "liansuo.cli", "soak", station, "--steps", "400", "--seed", str(seed),
                                    "--format", "json"], tmp_path)
    assert native == pure
    assert pure["cycles"] > 0


def test_example_scripts_pass_the_same(installed: Path, tmp_path: Path) -> None:
    scripts = sorted(str(p) for p in (PKG / "examples" / "scripts").glob("*.yaml"))
    native, pure = both(installed, ["-m", "liansuo.cli", "test", *scripts, "--format", "json"], tmp_path)
    assert native == pure
    assert pure["passed"] > 0 and pure["failed"] == 0


@pytest.mark.parametrize("scenario", sorted(p.name for p in (PKG / "examples" / "scenarios").glob("*.yaml")))
def test_scenarios_run_the_same(installed: Path, tmp_path: Path, scenario: str) -> None:
    """Trains, faults and commands in time: every event of the log, at the same time, with the same text."""
    native, pure = both(installed, ["-m", "liansuo.cli", "run", str(PKG / "examples" / "scenarios" / scenario),
                                    "--format", "json"], tmp_path)
    assert native == pure
    assert pure["events"]


@pytest.mark.parametrize("args", [["zpw", "gaotie", "--fault", "X3JG:capacitor:5:open"], ["25hz", "jiaopei",
                                                                                          "--section", "IG"]],
                         ids=["zpw", "25hz"])
def test_track_circuits_compute_the_same(installed: Path, tmp_path: Path, args: list[str]) -> None:
    native, pure = both(installed, ["-m", "liansuo.cli", *args, "--format", "json"], tmp_path)
    assert native == pure


def test_trains_move_the_same(installed: Path, tmp_path: Path) -> None:
    native, pure = both(installed, ["-c", TRAINS], tmp_path)
    assert native == pure
    assert pure["departures"] > 0


def test_mutate_seeds_its_defects_into_the_python_sources(installed: Path, tmp_path: Path) -> None:
    """A seeded defect replaces a function; compiled, that would change nothing, so mutate runs them on the
    Python sources: the defect is caught as in a pure install."""
    proc = run(installed, False, ["-m", "liansuo.cli", "mutate", "--station", "jiaopei", "--mutant",
                                  "blind-to-occupancy", "--format", "json"], tmp_path)
    report = json.loads(proc.stdout)
    assert report["caught"] == 1, proc.stdout + proc.stderr[-2000:]
