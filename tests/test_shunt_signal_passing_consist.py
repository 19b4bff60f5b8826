"""Regression (found by `liansuo soak`): a shunting signal held open while its consist passes it (approach and first
section both occupied) skipped every other check, so a train trailing through one of its turnouts (squeezed, no
indication) or a dark B lamp left it showing B. Only the sections the consist occupies are now left out."""

from __future__ import annotations

from conftest import Driver

from liansuo.simulation.sim import Simulation


def passing() -> Driver:
    gaotie = Driver(Simulation("gaotie"))
    return gaotie("shunt D5 D1", "run 10s", "expect signal D5 B", "occupy 3G", "occupy 9-15DG", "run 1s",
                  "expect signal D5 B")


def test_closes_when_a_turnout_loses_its_indication_while_the_consist_passes() -> None:
    d = passing()
    d("fault no-indication 9", "run 1s", "expect signal D5 A", "expect alarm signal D5 closed")
    # the consist vanishes from 9-15DG without reaching the next section or drawing back into 3G: the three-point
    # check keeps the section locked (a flickering track circuit must not release it), and D5 stays closed
    d("repair no-indication 9", "vacate 3G", "occupy 11-13DG", "vacate 9-15DG", "run 1s",
      "expect section 9-15DG locked", "expect signal D5 A")


def test_closes_when_its_lamp_goes_dark_while_the_consist_passes() -> None:
    passing()("fault filament D5 lamp=B", "run 1s", "expect signal D5 A")


def test_still_stays_open_for_the_consist_and_closes_once_it_is_past() -> None:
    passing()("occupy 11-13DG", "run 1s", "expect signal D5 B", "vacate 3G", "run 1s", "expect signal D5 A")
