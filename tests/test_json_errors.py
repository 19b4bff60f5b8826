"""``--format json`` on bad input prints a JSON error object on stdout, in every command that has it (issue 44,
item 5): a missing file, a file that is not YAML, a file against its schema, a bad value. Each command runs in a
process of its own, as a user (or a program reading its stdout) runs it."""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest

from liansuo.cli.main import build_parser

ROOT = Path(__file__).resolve().parent.parent
SRC = str(ROOT / "src")
MINIMAL = ROOT / "src" / "liansuo" / "examples" / "stations" / "minimal.yaml"


def liansuo(*argv: str, cwd: Path) -> subprocess.CompletedProcess[str]:
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(p for p in (SRC, os.environ.get("PYTHONPATH")) if p)}
    return subprocess.run([sys.executable, "-m", "liansuo", *argv], capture_output=True, text=True, timeout=120,
                          env=env, cwd=cwd, check=False)


def error_object(done: subprocess.CompletedProcess[str], status: int) -> dict[str, Any]:
    """The one JSON object on stdout: the envelope, ``ok: false`` and the error with the exit status; the text
    message still on stderr, and no traceback anywhere."""
    assert done.returncode == status, done.stderr
    assert "Traceback" not in done.stdout + done.stderr and done.stderr.strip()
    report: dict[str, Any] = json.loads(done.stdout)  # one object, nothing else
    assert list(report)[:3] == ["liansuo", "schema", "ok"] and report["ok"] is False
    error = report["error"]
    assert set(error) == {"status", "message", "file", "line", "column", "hint"}
    assert error["status"] == status and error["message"]
    return report


# every command with --format json, and a command line of it whose input file is missing (MISSING) or, for those
# that read no file, whose value is wrong
MISSING = "no-such-file.yaml"
BAD_INPUT: dict[str, list[str]] = {
    "check": ["check", MISSING],
    "table": ["table", MISSING],
    "zpw": ["zpw", MISSING],
    "25hz": ["25hz", MISSING, "--section", "IG"],
    "run": ["run", MISSING],
    "test": ["test", MISSING],
    "verify": ["verify", MISSING],
    "soak": ["soak", MISSING, "--steps", "10"],
    "explore": ["explore", MISSING],
    "replay": ["replay", MISSING, "--verify"],
    "exercise run": ["exercise", "run", MISSING, "--answers", MISSING],
}
BAD_VALUE: dict[str, list[str]] = {
    "stations": ["stations", "--nope"],
    "mutate": ["mutate", "--mutant", "nope"],
    "fuzz": ["fuzz", "nope"],
    "bench": ["bench", "--nope"],
    "exercise list": ["exercise", "list", "--nope"],
}


def json_commands() -> set[str]:
    """The commands whose --format takes json, from the parser itself."""
    found: set[str] = set()

    def walk(parser: argparse.ArgumentParser, name: str) -> None:
        for action in parser._actions:
            if isinstance(action, argparse._SubParsersAction):
                for sub, sp in action.choices.items():
                    walk(sp, f"{name} {sub}".strip())
            elif "--format" in action.option_strings and "json" in (action.choices or ()):
                found.add(name)
    walk(build_parser(), "")
    return found


def test_every_json_command_is_tried_here() -> None:
    assert json_commands() == set(BAD_INPUT) | set(BAD_VALUE)


@pytest.mark.parametrize("command", sorted(BAD_INPUT))
def test_a_missing_file_is_a_json_error_with_its_place(command: str, tmp_path: Path) -> None:
    report = error_object(liansuo(*BAD_INPUT[command], "--format", "json", cwd=tmp_path), 3)
    error = report["error"]
    assert (error["file"], error["line"], error["column"]) == (MISSING, 1, 1)
    assert "no such file" in error["message"] and "was not loaded" in error["message"]
    assert report["errors"][0]["file"] == MISSING and report["errors"][0]["severity"] == "error"


@pytest.mark.parametrize("command", sorted(BAD_VALUE))
def test_a_bad_value_is_a_json_error(command: str, tmp_path: Path) -> None:
    report = error_object(liansuo(*BAD_VALUE[command], "--format", "json", cwd=tmp_path), 2)
    assert report["error"]["file"] is None and report["errors"] == []
    assert "nope" in report["error"]["message"]


def test_without_json_the_error_stays_text(tmp_path: Path) -> None:
    done = liansuo("verify", MISSING, cwd=tmp_path)
    assert done.returncode == 3 and done.stdout == ""
    assert done.stderr.startswith(f"{MISSING}:1:1: error: no such file")


@pytest.mark.parametrize("command", ["check", "verify", "table", "test", "run"])
def test_a_file_that_is_not_yaml_or_breaks_its_schema_is_a_json_error(command: str, tmp_path: Path) -> None:
    syntax = tmp_path / "syntax.yaml"
    syntax.write_text("id: x\nname: {zh: a, en: b\nends: []\n", encoding="utf-8")
    schema = tmp_path / "schema.yaml"
    schema.write_text(MINIMAL.read_text(encoding="utf-8").replace("machine: ZD6", "machine: ZD7"), encoding="utf-8")
    if command in ("test", "run"):  # a script or scenario on each station: the station's own place is reported
        body = "tests:\n  - name: t\n    steps: [run 1s]\n" if command == "test" else "steps: [run 1s]\n"
        for name in ("syntax", "schema"):
            (tmp_path / f"{name}-{command}.yaml").write_text(f"station: {name}.yaml\n{body}", encoding="utf-8")
    names = {n: f"{n}-{command}.yaml" if command in ("test", "run") else f"{n}.yaml" for n in ("syntax", "schema")}

    report = error_object(liansuo(command, names["syntax"], "--format", "json", cwd=tmp_path), 3)
    assert report["error"]["file"].endswith("syntax.yaml") and report["error"]["line"] == 3

    report = error_object(liansuo(command, names["schema"], "--format", "json", cwd=tmp_path), 3)
    text = schema.read_text(encoding="utf-8")
    before = text[: text.index("ZD7")]
    error = report["error"]
    assert error["file"].endswith("schema.yaml")
    assert (error["line"], error["column"]) == (before.count("\n") + 1, len(before) - before.rfind("\n"))
    assert "ZD7" in error["message"] or "'ZD6'" in error["message"]
    assert error["hint"] and report["errors"][0]["hint"] == error["hint"]


def test_check_keeps_its_station_key(tmp_path: Path) -> None:
    report = error_object(liansuo("check", MISSING, "--format", "json", cwd=tmp_path), 3)
    assert report["station"] == MISSING


def test_a_report_is_not_followed_by_an_error_object(tmp_path: Path) -> None:
    """Checks that failed (status 1) come with the report, not an error object: stdout holds one object."""
    script = tmp_path / "fails.yaml"
    script.write_text("station: jiaopei\ntests:\n  - name: wrong aspect\n    steps:\n      - route X XI\n"
                      "      - run 2s\n      - expect signal X L\n", encoding="utf-8")
    done = liansuo("test", str(script), "--format", "json", cwd=tmp_path)
    assert done.returncode == 1
    report = json.loads(done.stdout)
    assert report["ok"] is False and "error" not in report and report["failed"] == 1
