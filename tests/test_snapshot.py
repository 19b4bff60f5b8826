"""What a snapshot (classroom/snapshot.py) carries beyond the state of the elements, for a console drawing a seat of
the classroom server: the sealed buttons' counters, why a red signal waits, and the faults, for the instructor only."""

from __future__ import annotations

import json

from liansuo.classroom.roles import INSTRUCTOR, TRAINEE
from liansuo.classroom.snapshot import EventCursor, SnapshotView, snapshot
from liansuo.simulation.sim import Simulation


def test_a_snapshot_says_why_a_signal_waits_and_counts_the_sealed_buttons() -> None:
    sim = Simulation("jiaopei")
    assert sim.command("route XI S")
    assert sim.command("guide-lock X")
    sim.run(2)
    data = json.loads(json.dumps(snapshot(sim, TRAINEE, EventCursor())))  # as it goes over the wire
    view = SnapshotView("jiaopei", data)
    assert view.waiting("XI") == sim.view.waiting("XI") and "block line SL" in view.waiting("XI")
    assert view.waiting("X") == ""
    assert view.sealed == sim.sealed_uses() == {"guide-lock": 1}


def test_the_faults_are_in_the_instructors_snapshot_only() -> None:
    sim = Simulation("jiaopei")
    assert sim.command("fault broken-rail IG")
    sim.run(1)
    trainee = snapshot(sim, TRAINEE, EventCursor())
    instructor = snapshot(sim, INSTRUCTOR, EventCursor())
    assert trainee["faults"] == [] and "broken" not in json.dumps(trainee)
    assert trainee["sections"]["IG"][0] is True  # the red band is all a trainee sees of it
    assert SnapshotView("jiaopei", instructor).faults == [f.describe() for f in sim.field.faults.values()]
    assert "IG" in instructor["faults"][0]
