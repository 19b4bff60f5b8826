"""JUnit XML reports of script runs (``liansuo test --junit-xml FILE``), for CI servers.

Written through junitparser in the layout of Ant's JUnit task, which CI servers read (Jenkins' xunit plugin, GitLab):
one ``<testsuite name="liansuo">`` with the counts (tests, failures, errors, skipped), the wall-clock ``time`` of the
whole run, the local ``timestamp`` it started and the ``hostname``. Each test of a script is a ``<testcase>`` (class
name: the script's path dotted, :func:`classname`; name: the test's) with its own ``time``; a failed test has a
``<failure>`` whose message is the failing step and why, and whose text is the report ``liansuo test -v`` prints
(every step's answer). A script that could not be run (it is malformed, or its station does not load) is one
``<testcase>`` with an ``<error>``: errors are scripts that never ran, failures are expectations that did not hold.
Hazards the safety oracle reported go to the test's ``<system-out>``. tests/test_junit.py validates the file against
the xunit plugin's ``junit-10.xsd``.
"""

from __future__ import annotations

import os
import socket
from collections.abc import Sequence
from datetime import datetime
from pathlib import Path

from junitparser import Error, Failure, TestCase, TestSuite

from liansuo.proving.scripts import Outcome, Unrunnable

SUITE = "liansuo"


def write_junit(path: str | Path, outcomes: Sequence[Outcome], unrunnable: Sequence[Unrunnable] = (), *,
                started: datetime | None = None, time_s: float | None = None) -> None:
    """Write the report of one ``liansuo test`` run to ``path``.

    ``started`` is when the run began (local time; now if not given) and ``time_s`` how long it took in wall-clock
    seconds (the sum of the tests' times if not given: loading the stations then does not count).
    """
    suite = TestSuite(SUITE)
    suite.hostname = socket.gethostname()
    suite.timestamp = (started or datetime.now()).isoformat(timespec="seconds")
    suite.add_testcases([_error_case(b) for b in unrunnable] + [_case(o) for o in outcomes])  # counts them too
    if time_s is not None:
        suite.time = _seconds(time_s)
    suite.write(str(path))


def _case(outcome: Outcome) -> TestCase:
    case = TestCase(outcome.name, classname(outcome.script), _seconds(outcome.time_s))
    if not outcome.passed:
        failure = Failure(outcome.failure)
        failure.text = outcome.report()
        case.result = [failure]
    if outcome.hazards:
        case.system_out = "\n".join(f"HAZARD {h}" for h in outcome.hazards)
    return case


def _error_case(broken: Unrunnable) -> TestCase:
    case = TestCase(Path(broken.script).name, classname(broken.script), 0.0)
    first = broken.diagnostics[0].splitlines()[0] if broken.diagnostics else "no diagnostic"
    error = Error(f"the script could not be run: {first}")
    error.text = "\n".join(broken.diagnostics)
    case.result = [error]
    return case


def classname(script: str) -> str:
    """The class name of a script's tests, as a CI server groups them: its path from the working folder (or from
    the root, outside it) without the suffix, a dot between folders (``tests/scripts/jiaopei_routes.yaml`` ->
    ``tests.scripts.jiaopei_routes``), as pytest names a test module's class. Jenkins cuts a class name at its last
    dot into package and class, so the path as written would show every script as class ``yaml``."""
    path = Path(os.path.abspath(script))
    try:
        path = path.relative_to(Path(os.path.abspath(os.curdir)))
    except ValueError:  # outside the working folder
        path = path.relative_to(path.anchor)
    return ".".join([*path.parent.parts, path.stem]) or script


def _seconds(t: float) -> float:
    """Milliseconds at most: the schema's time is digits with at most three decimals, never an exponent."""
    return round(max(t, 0.0), 3)
