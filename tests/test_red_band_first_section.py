"""Regression (found by `liansuo verify`): a red band (track-circuit fault) on the first section of a route with its
approach clear closes the signal abnormally; it is not a movement entering the route. Before the fix the next cycle
took it for one: a train route went `in_use` (no reopen, no cancel) and a shunting route released altogether."""

from __future__ import annotations

from conftest import Driver


def test_open_train_route_can_be_reopened_after_a_red_band_on_its_first_section(jiaopei: Driver) -> None:
    jiaopei("route X XI", "run 1s", "occupy 7DG", "run 1s", "expect signal X H", "expect alarm signal X closed",
            "vacate 7DG", "run 5s", "expect signal X H", "expect route X XI locked", "reopen X", "run 1s",
            "expect signal X U")


def test_shunting_route_stays_locked_through_a_red_band_on_its_only_section(jiaopei: Driver) -> None:
    jiaopei("shunt D2 D4", "run 5s", "expect signal D2 B", "occupy 6DG", "run 1s", "expect signal D2 A",
            "vacate 6DG", "run 1s", "expect route D2 D4 locked", "expect turnout 6 reverse locked", "reopen D2",
            "run 1s", "expect signal D2 B")


def test_route_with_a_red_band_before_its_signal_opened_can_be_cancelled(jiaopei: Driver) -> None:
    jiaopei("throw 7 reverse", "run 5s", "route X XI", "occupy 7DG", "run 10s", "expect signal X H", "cancel X",
            "expect route X XI released")


def test_a_train_entering_from_the_approach_still_releases_behind_it(jiaopei: Driver) -> None:
    jiaopei("route X XI", "run 1s", "occupy IAG", "run 1s", "occupy 7DG", "run 1s", "expect signal X H",
            "vacate IAG", "occupy 1DG", "run 1s", "vacate 7DG", "run 1s", "expect section 7DG free")
