"""Regression (found by the hypothesis safety test): a guide aspect over a route one of whose sections had been
released by section fault release (区故解) showed HB with that section's turnout unlocked, and the turnout could be
thrown under the open guide aspect."""

from __future__ import annotations

from conftest import Driver


def test_guide_is_refused_over_a_route_with_a_released_section(jiaopei: Driver) -> None:
    jiaopei("route X X3", "run 7s", "expect signal X UU", "occupy 3G", "run 1s", "expect signal X H",
            "fault-release 7DG", "expect section 7DG free")
    jiaopei.refused("guide X", "section 7DG of route X-X3 has been released")
    jiaopei("run 1s", "expect signal X H", "throw 7 reverse")


def test_guide_over_an_intact_route_still_works(jiaopei: Driver) -> None:
    jiaopei("route X X3", "run 7s", "occupy 3G", "run 1s", "expect signal X H", "guide X", "run 1s",
            "expect signal X HB")
    jiaopei.refused("throw 7 reverse", "locked in route X-X3")
