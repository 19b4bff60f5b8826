"""The pytest plugin: YAML scripts are collected as pytest items, failures read like `liansuo test`, station files and
other YAML are left alone."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest
import xmlschema
from conftest import TWO_TESTS_SCRIPT

pytest_plugins = ["pytester"]

ROOT = Path(__file__).parent.parent
PKG = ROOT / "src" / "liansuo"
# the inner runs need neither the cache nor the Textual snapshot plugin (whose session hook expects its own run)
QUIET = ("-p", "no:cacheprovider", "-p", "no:textual-snapshot")



def test_scripts_are_collected_and_failures_show_step_expectation_and_state(pytester: pytest.Pytester) -> None:
    pytester.makefile(".yaml", test_routes=TWO_TESTS_SCRIPT)
    station = (PKG / "stations/library/jiaopei.yaml").read_text("utf-8")
    (pytester.path / "test_jiaopei.yaml").write_text(station, encoding="utf-8")  # a station file: not a script
    (pytester.path / "other.yaml").write_text(TWO_TESTS_SCRIPT, encoding="utf-8")  # no pattern: not collected
    result = pytester.runpytest(*QUIET, "--junitxml=report.xml")
    result.assert_outcomes(passed=1, failed=1)
    out = result.stdout.str()
    assert "test_routes.yaml:12: wrong aspect" in out
    assert "step 'expect signal X L': signal X shows U, expected L" in out
    assert "route X XI -> ok: route X-XI selected" in out
    assert 'name="receiving route opens"' in (pytester.path / "report.xml").read_text("utf-8")
    xmlschema.validate(pytester.path / "report.xml", ROOT / "tests" / "data" / "junit-10.xsd")  # as Jenkins reads it


def test_keyword_selection_and_explicit_paths(pytester: pytest.Pytester) -> None:
    pytester.makefile(".yaml", routes=TWO_TESTS_SCRIPT)  # matches no pattern, but named on the command line
    result = pytester.runpytest(*QUIET, "routes.yaml", "-k", "opens")
    result.assert_outcomes(passed=1, deselected=1)


def test_patterns_are_configurable(pytester: pytest.Pytester) -> None:
    pytester.makeini("[pytest]\nliansuo_scripts = *.check.yaml\n")
    pytester.makefile(".check.yaml", routes=TWO_TESTS_SCRIPT)
    pytester.makefile(".yaml", test_other=TWO_TESTS_SCRIPT)
    result = pytester.runpytest(*QUIET)
    result.assert_outcomes(passed=1, failed=1)


def test_malformed_script_is_a_collection_error_with_file_and_line(pytester: pytest.Pytester) -> None:
    pytester.makefile(".yaml", test_bad="station: jiaopei\ntests:\n  - name: x\n    steps:\n      - rout X XI\n")
    result = pytester.runpytest(*QUIET)
    result.assert_outcomes(errors=1)
    assert "test_bad.yaml:5:9: error: unknown command 'rout'" in result.stdout.str()


def test_the_example_scripts_run_under_pytest(pytester: pytest.Pytester) -> None:
    scripts = sorted(str(p) for p in (PKG / "examples" / "scripts").glob("*.yaml"))
    result = pytester.runpytest(*QUIET, *scripts)
    outcomes = result.parseoutcomes()
    assert outcomes.get("passed", 0) > 20 and "failed" not in outcomes


# What the plugin may bring into a pytest run that collects no script: the package root (lazy, tests/test_layout.py)
# and the plugin itself. The layers, YAML and the heavy dependencies come only with a script.
# the suite runs with LIANSUO_PURE=1 (conftest.py): the switch to the Python sources, kit/native.py (standard
# library only), comes with the package then
LIGHT = {"liansuo", "liansuo.proving", "liansuo.proving.pytest_plugin", "liansuo.kit", "liansuo.kit.native"}
HEAVY = ("liansuo", "yaml", "numpy", "textual", "pydantic", "networkx")
LOADED = f"sorted(m for m in sys.modules if m.startswith({HEAVY!r}))"


def packages(modules: set[str]) -> list[str]:
    """The layers and distributions the modules belong to (liansuo.simulation, numpy, ...), not every submodule."""
    return sorted({".".join(m.split(".")[:2]) if m.startswith("liansuo.") else m.split(".")[0] for m in modules})


def test_importing_the_plugin_imports_no_layer_and_no_heavy_dependency() -> None:
    code = f"import sys\nimport liansuo.proving.pytest_plugin\nprint(' '.join({LOADED}))"
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=False, cwd=ROOT)
    assert proc.returncode == 0, proc.stderr
    loaded = set(proc.stdout.split())
    assert loaded == LIGHT, f"importing the pytest plugin also imports {packages(loaded - LIGHT)}"


def test_a_pytest_run_without_scripts_loads_the_plugin_and_nothing_heavy(pytester: pytest.Pytester) -> None:
    station = (PKG / "stations/library/jiaopei.yaml").read_text("utf-8")
    (pytester.path / "test_jiaopei.yaml").write_text(station, encoding="utf-8")  # matches the patterns, not a script
    pytester.makepyfile(test_plain=f"import sys\n\ndef test_plain():\n    print('LOADED', *{LOADED})\n")
    # a fresh interpreter, so that this suite's own imports do not count; pytest-textual-snapshot imports textual
    result = pytester.runpytest_subprocess(*QUIET, "-s")
    result.assert_outcomes(passed=1)
    line = next(line for line in result.outlines if "LOADED" in line)
    loaded = set(line.split("LOADED", 1)[1].split())
    assert "liansuo.proving.pytest_plugin" in loaded, f"the pytest11 entry point did not load the plugin: {line}"
    heavy = {m for m in loaded - LIGHT if m.split(".")[0] != "yaml"}  # YAML: to see that the station is no script
    assert not heavy, f"a pytest run that collects no script imports {packages(heavy)}"
