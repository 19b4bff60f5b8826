"""The names of the tests of a script (issue 44, item 5): each test of a script has its own name, JUnit reports name
a script's class by its dotted path, and ``liansuo test -k`` takes pytest's expressions. The command runs in a
process of its own, as a user runs it; the expression parser is held against pytest's own."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path
from xml.etree import ElementTree

import pytest
from _pytest.mark.expression import Expression as PytestExpression
from _pytest.mark.expression import ParseError

from liansuo.proving.keywords import Expression, ExpressionError

SRC = str(Path(__file__).resolve().parent.parent / "src")
SCRIPT = """\
station: jiaopei
tests:
  - name: Receiving route X-XI
    steps: [route X XI, run 2s, expect signal X U]
  - name: departing route XI
    steps: [run 1s]
  - name: shunt route D1
    steps: [run 1s]
  - name: guide signal X
    steps: [run 1s]
"""


def liansuo(*argv: str, cwd: Path) -> subprocess.CompletedProcess[str]:
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(p for p in (SRC, os.environ.get("PYTHONPATH")) if p)}
    return subprocess.run([sys.executable, "-m", "liansuo", *argv], capture_output=True, text=True, timeout=120,
                          env=env, cwd=cwd, check=False)


@pytest.fixture
def scripts(tmp_path: Path) -> Path:
    folder = tmp_path / "tests" / "scripts"
    folder.mkdir(parents=True)
    (folder / "jiaopei_cases.yaml").write_text(SCRIPT, encoding="utf-8")
    return tmp_path


def test_a_second_test_of_the_same_name_is_refused_at_its_place(tmp_path: Path) -> None:
    (tmp_path / "twice.yaml").write_text(SCRIPT + "  - name: departing route XI\n    steps: [run 1s]\n",
                                         encoding="utf-8")
    done = liansuo("test", "twice.yaml", cwd=tmp_path)
    assert done.returncode == 3 and done.stdout == "" and "Traceback" not in done.stderr
    assert done.stderr.startswith("twice.yaml:11:11: error: a second test named 'departing route XI' (the first is "
                                  "on line 5)\n    hint: give each test of a script its own name")
    report = json.loads(liansuo("test", "twice.yaml", "--format", "json", cwd=tmp_path).stdout)
    assert (report["error"]["file"], report["error"]["line"], report["error"]["column"]) == ("twice.yaml", 11, 11)


def test_junit_class_names_are_dotted_paths(scripts: Path) -> None:
    done = liansuo("test", "tests/scripts/jiaopei_cases.yaml", "--junit-xml", "report.xml", cwd=scripts)
    assert done.returncode == 0, done.stderr
    classes = {case.get("classname") for case in ElementTree.parse(scripts / "report.xml").iter("testcase")}
    assert classes == {"tests.scripts.jiaopei_cases"}
    done = liansuo("test", "jiaopei_cases.yaml", "--junit-xml", "../../report.xml", cwd=scripts / "tests" / "scripts")
    classes = {case.get("classname") for case in ElementTree.parse(scripts / "report.xml").iter("testcase")}
    assert classes == {"jiaopei_cases"}


@pytest.mark.parametrize(("k", "chosen"), [
    ("route", ["Receiving route X-XI", "departing route XI", "shunt route D1"]),
    ("ROUTE and not shunt", ["Receiving route X-XI", "departing route XI"]),
    ("receiving or guide", ["Receiving route X-XI", "guide signal X"]),
    ("not (route or signal)", []),
    ("(receiving or departing) and XI", ["Receiving route X-XI", "departing route XI"]),
    ("guide signal", ["guide signal X"]),  # words in a row: one phrase of the name
    ("jiaopei_cases and shunt", ["shunt route D1"]),  # the script's file name is a name of each of its tests
])
def test_k_takes_pytest_expressions(scripts: Path, k: str, chosen: list[str]) -> None:
    done = liansuo("test", "tests/scripts/jiaopei_cases.yaml", "-k", k, "--format", "json", cwd=scripts)
    if not chosen:
        assert done.returncode == 5 and done.stderr.startswith(f"liansuo test: no test matches -k {k!r}")
        return
    assert done.returncode == 0, done.stderr
    assert [t["name"] for t in json.loads(done.stdout)["tests"]] == chosen


def test_a_k_that_does_not_parse_is_a_usage_error(scripts: Path) -> None:
    done = liansuo("test", "tests/scripts/jiaopei_cases.yaml", "-k", "route and (shunt", cwd=scripts)
    assert done.returncode == 2 and done.stdout == "" and "Traceback" not in done.stderr
    assert done.stderr.splitlines()[-1] == ("liansuo test: error: argument -k: 'route and (shunt': at column 17: "
                                            "expected ')'; got end of input; see 'liansuo test --help'")


NAMES = [("receiving route x-xi", "routes.yaml"), ("shunt d1", "routes.yaml"), ("guide", "other.yaml")]


@pytest.mark.parametrize("text", [
    "route", "not route", "route and shunt", "route or shunt", "not route and not shunt", "(route or guide) and x",
    "not (routes.yaml)", "x-xi or d1 and guide", "not not guide", "GUIDE", "routes.yaml and not d1", "a or (b or c)",
    "[x]", "x/y", "d1:", "and", "route or", "(route", "route)", "not", "", "x.xi",
])
def test_the_expressions_mean_what_pytest_s_mean(text: str) -> None:
    """Every expression pytest's own parser reads (words without spaces between) selects the same tests here, and
    every one it refuses is refused here at the same column."""
    try:
        theirs = PytestExpression.compile(text)
    except ParseError as exc:
        with pytest.raises(ExpressionError) as info:
            Expression(text)
        assert f"at column {exc.column}:" in str(info.value)
        return
    ours = Expression(text)
    for names in NAMES:
        expected = theirs.evaluate(lambda word, names=names: any(word.lower() in n for n in names)) if text else True
        assert ours.matches(names) is expected, names
