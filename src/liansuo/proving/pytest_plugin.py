"""A pytest plugin: YAML test scripts are collected and reported by pytest alongside Python tests.

Registered with the ``pytest11`` entry point, so it is active wherever liansuo is installed. It collects

- files matching the ``liansuo_scripts`` ini patterns (default ``test_*.yaml test_*.yml *_test.yaml *_test.yml``)
  in the directories pytest searches, and
- any YAML file named on the command line,

but only when the file is a test script: a mapping with ``station:`` and a ``tests:`` list. Station files and other
YAML are never collected. Each test of a script is one pytest item (``path::test name``), so ``-k``, ``--junitxml``
and ``-x`` work as for Python tests; a failure shows the step, the expectation and the state, as ``liansuo test``
does, followed by every step's answer. Set ``liansuo_scripts =`` (empty) in the ini file to collect only scripts
named on the command line, or disable the plugin with ``-p no:liansuo``.

The entry point loads this module into every pytest run of an environment where liansuo is installed, so it imports
nothing but pytest at module level: YAML is read only for a ``.yaml`` file that matches, and the station model, the
interlocking and the simulation are imported only when a script is collected (tests/test_pytest_plugin.py checks it).
"""

from __future__ import annotations

import re
from collections.abc import Iterator
from fnmatch import fnmatch
from pathlib import Path
from typing import TYPE_CHECKING, Any

import pytest

if TYPE_CHECKING:
    from liansuo.stations.station import Station

DEFAULT_PATTERNS = ["test_*.yaml", "test_*.yml", "*_test.yaml", "*_test.yml"]


def pytest_addoption(parser: pytest.Parser) -> None:
    parser.addini("liansuo_scripts", type="args", default=DEFAULT_PATTERNS,
                  help="file name patterns of liansuo YAML test scripts to collect (empty: only scripts named on "
                       "the command line)")


_STATION_KEY = re.compile(rb"^station[ \t]*:", re.MULTILINE)
_TESTS_KEY = re.compile(rb"^tests[ \t]*:", re.MULTILINE)
_LOOK_BYTES = 16 * 1024 * 1024  # the input limit of every liansuo file (kit/inputlimits.py)


def is_script(path: Path) -> bool:
    """A regular file whose top level has ``station:`` and ``tests:`` keys: a test script to collect. The look is
    textual, so a pytest run stays light whatever YAML lies beside its tests (the reader brings pydantic); the script
    itself is read, within the input limits, when its items are collected, and a malformed one is reported there with
    its ``FILE:LINE:COLUMN``."""
    if not path.is_file():  # a regular file only: a pipe would be waited on
        return False
    try:
        with path.open("rb") as fh:
            head = fh.read(_LOOK_BYTES)
    except OSError:
        return False
    return bool(_STATION_KEY.search(head) and _TESTS_KEY.search(head))


def pytest_collect_file(file_path: Path, parent: pytest.Collector) -> ScriptCollector | None:
    if file_path.suffix not in (".yaml", ".yml"):
        return None
    patterns: list[str] = parent.config.getini("liansuo_scripts")
    wanted = any(fnmatch(file_path.name, p) for p in patterns) or parent.session.isinitpath(file_path)
    if not wanted or not is_script(file_path):
        return None
    return ScriptCollector.from_parent(parent, path=file_path)


class ScriptError(Exception):
    """A malformed script or a station that does not load: its diagnostics, FILE:LINE:COLUMN each."""


class ScriptFailure(Exception):
    """A script test failed: the outcome says which step, what was expected and what the state was."""


class ScriptCollector(pytest.File):
    def collect(self) -> Iterator[ScriptItem]:
        from liansuo.interlocking.table.build import build_table
        from liansuo.kit.source import StationError
        from liansuo.proving.scripts import parse_script, script_station

        try:
            script = parse_script(self.path)
            station = script_station(script)
            table = build_table(station)
        except StationError as exc:
            raise ScriptError("\n".join(str(d) for d in exc.diagnostics)) from None
        for test in script.tests:
            yield ScriptItem.from_parent(self, name=test.name, script=script, test=test, station=station,
                                         table=table)

    def repr_failure(self, excinfo: pytest.ExceptionInfo[BaseException],
                     style: Any = None) -> str:
        if isinstance(excinfo.value, ScriptError):
            return f"liansuo script {self.path} cannot be run:\n{excinfo.value}"
        return str(super().repr_failure(excinfo))


class ScriptItem(pytest.Item):
    def __init__(self, *, script: Any, test: Any, station: Station, table: Any, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        self.script = script
        self.test = test
        self.station = station
        self.table = table

    def runtest(self) -> None:
        from liansuo.proving.scripts import run_test

        outcome = run_test(self.script, self.test, self.station, self.table)
        if not outcome.passed:
            raise ScriptFailure(outcome)

    def repr_failure(self, excinfo: pytest.ExceptionInfo[BaseException],
                     style: Any = None) -> str:
        if isinstance(excinfo.value, ScriptFailure):
            return str(excinfo.value.args[0].report())
        return str(super().repr_failure(excinfo))

    def reportinfo(self) -> tuple[Path, int, str]:
        return self.path, self.test.line - 1, f"liansuo script: {self.test.name}"
