"""`liansuo test`: the shipped example scripts pass; failures and malformed scripts are reported usefully."""

from __future__ import annotations

from pathlib import Path
from xml.etree import ElementTree

import pytest

from liansuo.cli.main import main

EXAMPLES = sorted((Path(__file__).parent.parent / "src" / "liansuo" / "examples" / "scripts").glob("*.yaml"))


@pytest.mark.parametrize("script", EXAMPLES, ids=lambda p: p.stem)
def test_example_scripts_pass(script: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["test", str(script)]) == 0
    last = capsys.readouterr().out.strip().splitlines()[-1]
    assert last.endswith(" 0 failed") and not last.startswith("0 passed")


def test_failing_step_shows_step_expectation_and_state(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    f = tmp_path / "t.yaml"
    f.write_text("station: jiaopei\ntests:\n  - name: wrong aspect\n    steps:\n      - route X XI\n"
                 "      - run 2s\n      - expect signal X L\n  - name: fine\n    steps:\n      - route X XI\n",
                 encoding="utf-8")
    assert main(["test", str(f), "--junit-xml", str(tmp_path / "r.xml")]) == 1
    out = capsys.readouterr().out
    assert f"FAIL {f}:7: wrong aspect" in out
    assert "expect signal X L" in out and "signal X shows U, expected L" in out
    assert out.strip().splitlines()[-1] == "1 passed, 1 failed"
    suite = ElementTree.parse(tmp_path / "r.xml").getroot()
    assert suite.get("tests") == "2" and suite.get("failures") == "1"


def test_refused_command_fails_unless_expected(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    f = tmp_path / "t.yaml"
    f.write_text("station: jiaopei\ntests:\n  - name: r\n    steps:\n      - occupy 1DG\n      - route X XI\n",
                 encoding="utf-8")
    assert main(["test", str(f)]) == 1
    assert "was refused: section 1DG is occupied" in capsys.readouterr().out


def test_filter_by_name(capsys: pytest.CaptureFixture[str]) -> None:
    script = next(p for p in EXAMPLES if p.stem.startswith("jiaopei"))
    assert main(["test", str(script), "-k", "guide signal"]) == 0
    assert capsys.readouterr().out.strip().splitlines()[-1] == "1 passed, 0 failed"


def test_malformed_script_gives_file_and_line(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    f = tmp_path / "bad.yaml"
    f.write_text("station: jiaopei\ntests:\n  - name: x\n    steps:\n      - rout X XI\n", encoding="utf-8")
    assert main(["test", str(f)]) == 3  # a bad input file
    err = capsys.readouterr().err
    assert f"{f}:5:9: error: unknown command 'rout'" in err and "Traceback" not in err


def test_a_script_naming_a_file_that_is_no_station_shows_nothing_of_it(tmp_path: Path) -> None:
    """Issue 45, item 8: a script (or scenario) handed over may name any file as its station; one that is no station
    file is refused at the script in one line, none of its keys or lines quoted."""
    import subprocess
    import sys

    secret = tmp_path / "elsewhere" / "secret.yaml"
    secret.parent.mkdir()
    secret.write_text("api_key_name: do-not-show\nroot: x\n", encoding="utf-8")
    script = tmp_path / "scripts" / "evil.yaml"
    script.parent.mkdir()
    script.write_text("station: ../elsewhere/secret.yaml\ntests:\n  - name: a\n    steps: ['route X XI']\n",
                      encoding="utf-8")
    proc = subprocess.run([sys.executable, "-m", "liansuo", "test", str(script)], capture_output=True, text=True,
                          check=False, timeout=120)
    assert proc.returncode == 3, proc.stderr
    assert proc.stderr.startswith(f"{script}:1:1: error: its station ../elsewhere/secret.yaml is not a station file"), \
        proc.stderr
    assert "api_key_name" not in proc.stdout + proc.stderr and "do-not-show" not in proc.stdout + proc.stderr
