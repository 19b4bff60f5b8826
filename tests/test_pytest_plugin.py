"""The pytest plugin: YAML scripts are collected as pytest items, failures read like `liansuo test`, station files and
other YAML are left alone."""

from __future__ import annotations

from pathlib import Path

import pytest

pytest_plugins = ["pytester"]

ROOT = Path(__file__).parent.parent
# the inner runs need neither the cache nor the Textual snapshot plugin (whose session hook expects its own run)
QUIET = ("-p", "no:cacheprovider", "-p", "no:textual-snapshot")

SCRIPT = """\
station: jiaopei
tests:
  - name: receiving route opens
    steps:
      - route X XI
      - run 2s
      - expect signal X U
  - name: wrong aspect
    steps:
      - route X XI
      - run 2s
      - expect signal X L
"""


def test_scripts_are_collected_and_failures_show_step_expectation_and_state(pytester: pytest.Pytester) -> None:
    pytester.makefile(".yaml", test_routes=SCRIPT)
    station = (ROOT / "stations/library/jiaopei.yaml").read_text("utf-8")
    (pytester.path / "test_jiaopei.yaml").write_text(station, encoding="utf-8")  # a station file: not a script
    (pytester.path / "other.yaml").write_text(SCRIPT, encoding="utf-8")  # no pattern: not collected
    result = pytester.runpytest(*QUIET, "--junitxml=report.xml")
    result.assert_outcomes(passed=1, failed=1)
    out = result.stdout.str()
    assert "test_routes.yaml:12: wrong aspect" in out
    assert "step 'expect signal X L': signal X shows U, expected L" in out
    assert "route X XI -> ok: route X-XI selected" in out
    assert 'name="receiving route opens"' in (pytester.path / "report.xml").read_text("utf-8")


def test_keyword_selection_and_explicit_paths(pytester: pytest.Pytester) -> None:
    pytester.makefile(".yaml", routes=SCRIPT)  # matches no pattern, but named on the command line
    result = pytester.runpytest(*QUIET, "routes.yaml", "-k", "opens")
    result.assert_outcomes(passed=1, deselected=1)


def test_patterns_are_configurable(pytester: pytest.Pytester) -> None:
    pytester.makeini("[pytest]\nliansuo_scripts = *.check.yaml\n")
    pytester.makefile(".check.yaml", routes=SCRIPT)
    pytester.makefile(".yaml", test_other=SCRIPT)
    result = pytester.runpytest(*QUIET)
    result.assert_outcomes(passed=1, failed=1)


def test_malformed_script_is_a_collection_error_with_file_and_line(pytester: pytest.Pytester) -> None:
    pytester.makefile(".yaml", test_bad="station: jiaopei\ntests:\n  - name: x\n    steps:\n      - rout X XI\n")
    result = pytester.runpytest(*QUIET)
    result.assert_outcomes(errors=1)
    assert "test_bad.yaml:5:9: error: unknown command 'rout'" in result.stdout.str()


def test_the_example_scripts_run_under_pytest(pytester: pytest.Pytester) -> None:
    scripts = sorted(str(p) for p in (ROOT / "examples" / "scripts").glob("*.yaml"))
    result = pytester.runpytest(*QUIET, *scripts)
    outcomes = result.parseoutcomes()
    assert outcomes.get("passed", 0) > 20 and "failed" not in outcomes
