"""A lamp alarm ends when the lamp is proved again (issue 17: it stayed active long after the repair, while the
signal already showed its aspect again)."""

from __future__ import annotations

import pytest

from liansuo.simulation import Simulation


def lamp_alarms(sim: Simulation, signal: str) -> list[str]:
    return [a.text for a in sim.view.alarms() if a.kind == "lamp" and a.element == signal]


@pytest.mark.parametrize("which", ["both", "main"])
def test_the_lamp_alarm_clears_within_a_cycle_of_the_aspect_showing_again(which: str) -> None:
    sim = Simulation("jiaopei")
    assert sim.command("route X XI").ok
    sim.run(2)
    assert sim.aspect("X") == "U"
    assert sim.command(f"fault filament X lamp=U which={which}").ok
    sim.run(1)
    if which == "main":  # lit on its backup filament: the aspect stays, only the filament alarm is raised
        assert sim.aspect("X") == "U" and not lamp_alarms(sim, "X")
        return
    assert sim.aspect("X") == "H"
    assert lamp_alarms(sim, "X") == ["signal X: lamp(s) U dark for U; showing H"]
    assert sim.command("repair filament X").ok
    assert sim.command("reopen X").ok
    shown_at = None
    for cycle in range(8):
        sim.step()
        if shown_at is None and sim.aspect("X") == "U":
            shown_at = cycle
        if shown_at is not None and cycle >= shown_at + 1:
            break
    assert shown_at is not None
    assert not lamp_alarms(sim, "X")
    assert not sim.view.signal("X").lamp_dark
    assert not sim.command("expect alarm lamp(s) U dark").ok


def test_a_lamp_alarm_stays_while_the_lamp_is_still_dark() -> None:
    sim = Simulation("jiaopei")
    assert sim.command("route X XI").ok
    sim.run(2)
    assert sim.command("fault filament X lamp=U").ok
    sim.run(60)
    assert lamp_alarms(sim, "X") and sim.aspect("X") == "H"
    assert sim.command("expect alarm lamp(s) U dark").ok
