"""JUnit XML reports of script runs, for CI systems."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from collections.abc import Sequence

from .scripts import Outcome


def write_junit(path: str, outcomes: Sequence[Outcome]) -> None:
    suite = ET.Element("testsuite", name="liansuo", tests=str(len(outcomes)),
                       failures=str(sum(not o.passed for o in outcomes)))
    for o in outcomes:
        case = ET.SubElement(suite, "testcase", classname=o.script, name=o.name)
        if not o.passed:
            fail = ET.SubElement(case, "failure", message=o.failure)
            fail.text = "\n".join(o.log)
    ET.ElementTree(suite).write(path, encoding="utf-8", xml_declaration=True)
