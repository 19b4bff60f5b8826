"""`liansuo test --junit-xml FILE`: the report is valid against the JUnit schema Jenkins reads (the xunit plugin's
junit-10.xsd, tests/data/) and tells passed tests, failed expectations and scripts that could not be run apart."""

from __future__ import annotations

from datetime import datetime
from pathlib import Path
from xml.etree import ElementTree

import pytest
import xmlschema
from conftest import TWO_TESTS_SCRIPT

from liansuo.cli.main import main

XSD = Path(__file__).parent / "data" / "junit-10.xsd"
EXAMPLE = Path(__file__).parent.parent / "src" / "liansuo" / "examples" / "scripts"



@pytest.fixture(scope="module")
def schema() -> xmlschema.XMLSchema:
    return xmlschema.XMLSchema(XSD)


def run(tmp_path: Path, *scripts: str, extra: tuple[str, ...] = ()) -> tuple[int, ElementTree.Element]:
    """``liansuo test SCRIPTS --junit-xml FILE``: the exit status and the report's ``<testsuite>``."""
    report = tmp_path / "report.xml"
    status = main(["test", *scripts, *extra, "--junit-xml", str(report)])
    return status, ElementTree.parse(report).getroot()


def test_a_passing_run_is_valid_with_times_timestamp_and_hostname(
        tmp_path: Path, schema: xmlschema.XMLSchema, capsys: pytest.CaptureFixture[str],
        monkeypatch: pytest.MonkeyPatch) -> None:
    before = datetime.now().replace(microsecond=0)
    monkeypatch.chdir(EXAMPLE.parent)
    script = "scripts/jiaopei-interlocking-test.yaml"
    status, suite = run(tmp_path, script, extra=("-k", "guide signal"))
    assert status == 0
    schema.validate(tmp_path / "report.xml")
    assert suite.tag == "testsuite"
    counts = {k: suite.get(k) for k in ("name", "tests", "failures", "errors")}
    assert counts == {"name": "liansuo", "tests": "1", "failures": "0", "errors": "0"}
    assert suite.get("hostname")
    stamp = datetime.fromisoformat(suite.get("timestamp", ""))
    assert before <= stamp <= datetime.now()
    [case] = suite.findall("testcase")
    assert case.get("classname") == "scripts.jiaopei-interlocking-test" and "guide signal" in case.get("name", "")
    assert float(case.get("time", "")) >= 0 and float(suite.get("time", "")) >= float(case.get("time", ""))
    assert not list(case)  # passed: no failure, no error
    assert "1 passed, 0 failed" in capsys.readouterr().out


def test_failures_and_errors_are_counted_apart_and_say_why(
        tmp_path: Path, schema: xmlschema.XMLSchema, capsys: pytest.CaptureFixture[str]) -> None:
    good = tmp_path / "routes.yaml"
    good.write_text(TWO_TESTS_SCRIPT, encoding="utf-8")
    malformed = tmp_path / "malformed.yaml"
    malformed.write_text("station: jiaopei\ntests:\n  - name: x\n    steps:\n      - rout X XI\n", encoding="utf-8")
    no_station = tmp_path / "no-station.yaml"
    no_station.write_text("station: nosuch-station\ntests:\n  - name: x\n    steps:\n      - run 1s\n",
                          encoding="utf-8")
    status, suite = run(tmp_path, str(good))
    assert status == 1
    schema.validate(tmp_path / "report.xml")
    counts = {k: suite.get(k) for k in ("tests", "failures", "errors", "skipped")}
    assert counts == {"tests": "2", "failures": "1", "errors": "0", "skipped": "0"}
    cases = {case.get("name"): case for case in suite.iter("testcase")}

    assert not list(cases["receiving route opens"])
    failure = cases["wrong aspect"].find("failure")
    assert failure is not None and cases["wrong aspect"].find("error") is None
    assert failure.get("message") == "step 'expect signal X L': signal X shows U, expected L (t = 2 s)"
    assert f"FAIL {good}:12: wrong aspect" in (failure.text or "")
    assert "route X XI -> ok: route X-XI selected" in (failure.text or "")  # every step's answer
    assert "expect signal X L -> refused: signal X shows U, expected L" in (failure.text or "")

    # scripts that cannot run are bad input (exit status 3): nothing runs, and the report holds each as an error
    status, suite = run(tmp_path, str(good), str(malformed), str(no_station), str(tmp_path / "missing.yaml"))
    assert status == 3
    schema.validate(tmp_path / "report.xml")
    counts = {k: suite.get(k) for k in ("tests", "failures", "errors", "skipped")}
    assert counts == {"tests": "3", "failures": "0", "errors": "3", "skipped": "0"}
    cases = {case.get("name"): case for case in suite.iter("testcase")}
    assert "wrong aspect" not in cases
    for name, why in (("malformed.yaml", f"{malformed}:5:9: error: unknown command 'rout'"),
                      ("no-station.yaml", "nosuch-station"), ("missing.yaml", "no such file")):
        error = cases[name].find("error")
        assert error is not None and cases[name].find("failure") is None, name
        assert error.get("message", "").startswith("the script could not be run: "), name
        assert why in error.get("message", "") and why in (error.text or ""), name
    assert "Traceback" not in capsys.readouterr().err


def test_hazards_of_a_passing_test_go_to_its_system_out(tmp_path: Path, schema: xmlschema.XMLSchema) -> None:
    status, root = run(tmp_path, str(EXAMPLE / "dead-zone-hazard.yaml"))
    assert status == 0
    schema.validate(tmp_path / "report.xml")
    outs = [e.text or "" for e in root.iter("system-out")]
    assert outs and all(o.startswith("HAZARD ") for o in outs)


def test_the_schema_rejects_the_old_hand_written_report(schema: xmlschema.XMLSchema) -> None:
    """The check has teeth: a suite without the errors count, as liansuo wrote it before, is not valid."""
    old = ('<testsuite name="liansuo" tests="1" failures="0">'
           '<testcase classname="s.yaml" name="t"/></testsuite>')
    assert not schema.is_valid(old)
    assert schema.is_valid(old.replace('failures="0"', 'failures="0" errors="0" time="0.5"'))
    assert not schema.is_valid(old.replace('failures="0"', 'failures="0" errors="0" time="1e-05"'))
