"""Exercises on the classroom server's seats (docs/classroom.md, "Exercises, scores and reports"): started per seat
or for all, scored as the trainee's commands arrive, reported per trainee when they end; what the trainee is told of
them, and what never reaches the trainee."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from liansuo.classroom.passwords import hash_password
from liansuo.classroom.snapshot import EventCursor
from liansuo.server.classroom import Classroom, SeatError
from liansuo.server.websocket import ClassroomServer


@pytest.fixture
def room(tmp_path: Path) -> Classroom:
    r = Classroom("jiaopei", 3, reports=tmp_path / "reports")
    r.take(1, "Li Lei", None)
    r.take(2, "Wang", None)
    yield r
    r.close()


def run_for(room: Classroom, seconds: float) -> None:
    for _ in range(int(seconds / 0.25)):
        room.advance(0.25)


def test_an_exercise_is_scored_on_its_seat_and_reported_when_its_goals_are_met(room: Classroom) -> None:
    said = room.start_exercise([1], "jiaopei-cancel-route", seed=4)
    assert said == "exercise 'Cancel a wrong route (取消进路)' started on seats 1"
    assert room.seat(2).desk.assessment is None and room.seat(1).summary()["exercise"] == "jiaopei-cancel-route"
    run_for(room, 9)  # the setup's route X-X3 stands
    assert room.command(1, "trainee", "fault broken-rail IG").ok is False  # the instructor's: refused, counted
    assert room.command(1, "trainee", "cancel X").ok
    run_for(room, 2)
    assert room.command(1, "trainee", "route X XI").ok
    run_for(room, 6)
    progress = room.seat(1).summary()["progress"]
    assert progress["finished"] and progress["ended"] == "goals met" and progress["refused"] == 1
    assert room.seat(1).summary()["score"] == progress["score"] < 100  # the refused command cost 2 points
    written = sorted(p.name for p in room.seat(1).desk.reported)
    assert written == ["seat1-Li-Lei-jiaopei-cancel-route.html", "seat1-Li-Lei-jiaopei-cancel-route.json",
                       "seat1-Li-Lei-jiaopei-cancel-route.txt"]
    report = json.loads((room.reports / "seat1-Li-Lei-jiaopei-cancel-route.json").read_text(encoding="utf-8"))
    assert report["trainee"] == "Li Lei" and report["seat"] == "1" and report["seed"] == 4
    assert [c["command"] for c in report["commands"]] == ["fault broken-rail IG", "cancel X", "route X XI"]
    assert report["refused"] == 1 and report["all_goals_met"]
    told = room.snapshot(1, "trainee", EventCursor())["exercise"]
    assert told["finished"] and told["score"] == progress["score"] and all(g["met"] for g in told["goals"])


def test_a_trainee_is_told_the_briefing_and_goals_never_the_faults(room: Classroom) -> None:
    room.start_exercise([1, 2], "jiaopei-filament", seed=1, difficulty=3)
    for seat in (1, 2):
        faults = room.seat(seat).sim.field.faults
        assert faults  # drawn from the pool, the same for both seats (one seed)
    assert [f.describe() for f in room.seat(1).sim.field.faults.values()] == \
        [f.describe() for f in room.seat(2).sim.field.faults.values()]
    run_for(room, 3)
    snap = room.snapshot(1, "trainee", EventCursor())
    told = json.dumps(snap["exercise"])
    assert snap["exercise"]["briefing"] and snap["exercise"]["time_left_s"] > 0 and not snap["exercise"]["finished"]
    not_alarms = json.dumps([e for e in snap["events"] if e[1] != "alarm"])  # the CBI's filament alarm is shown
    for f in room.seat(1).sim.field.faults.values():
        assert f.describe() not in json.dumps(snap) and f.kind not in not_alarms
    assert "seed" not in told and "pool" not in told and snap["faults"] == []
    assert "expect" not in json.dumps(snap["events"])  # the goal checks are not the trainee's events


def test_stop_writes_the_report_of_an_unfinished_exercise_and_a_second_attempt_keeps_the_first(
        room: Classroom) -> None:
    room.start_exercise([2], "jiaopei-cancel-route")
    run_for(room, 2)
    first = room.stop_exercise([2])
    assert first[0].name == "seat2-Wang-jiaopei-cancel-route.json"
    report = json.loads(first[0].read_text(encoding="utf-8"))
    assert report["ended"] == "stopped by the instructor" and not report["all_goals_met"]
    told = room.snapshot(2, "trainee", EventCursor())["exercise"]
    assert told["finished"] and told["ended"] == "stopped by the instructor" and told["score"] is not None
    room.command(2, "trainee", "cancel X")
    stopped = room.seat(2).desk.assessment
    assert stopped is not None and stopped.entries == []  # after the stop nothing more is recorded
    assert room.stop_exercise([2]) == first  # stopping again writes nothing new
    room.start_exercise([2], "jiaopei-cancel-route")
    assert room.stop_exercise([2])[0].name == "seat2-Wang-jiaopei-cancel-route-2.json"
    assert room.stop_exercise([3]) == []  # no exercise there


def test_an_exercise_the_classroom_cannot_run_is_refused_and_changes_nothing(room: Classroom) -> None:
    assert room.command(1, "trainee", "route X XI").ok
    before = room.seat(1).sim
    with pytest.raises(SeatError, match=r"no exercise 'nosuch'.*jiaopei-cancel-route"):
        room.start_exercise([1], "nosuch")
    with pytest.raises(SeatError, match="is for station gaotie; this classroom serves jiaopei"):
        room.start_exercise([1, 2], "gaotie-flasher")
    with pytest.raises(SeatError, match="difficulty is 1"):
        room.start_exercise([1], "jiaopei-filament", difficulty=7)
    assert room.seat(1).sim is before and room.seat(1).desk.assessment is None


def test_a_team_at_a_shared_desk_is_scored_together_and_each_gets_the_report(tmp_path: Path) -> None:
    team = Classroom("jiaopei", 2, shared=True, reports=tmp_path)
    try:
        team.take(1, "Li", None)
        team.take(2, "Wang", None)
        team.start_exercise([1], "jiaopei-cancel-route", seed=1)
        assert team.seat(2).desk.assessment is team.seat(1).desk.assessment
        run_for(team, 9)
        assert team.command(1, "trainee", "cancel X").ok
        run_for(team, 2)
        assert team.command(2, "trainee", "route X XI").ok
        run_for(team, 6)
        names = sorted(p.name for p in tmp_path.glob("*.json"))
        assert names == ["seat1-Li-jiaopei-cancel-route.json", "seat2-Wang-jiaopei-cancel-route.json"]
        report = json.loads((tmp_path / names[1]).read_text(encoding="utf-8"))
        assert report["trainee"] == "Wang" and report["all_goals_met"]
        assert [c["command"] for c in report["commands"]] == ["cancel X", "route X XI"]
    finally:
        team.close()


def test_the_instructor_starts_and_stops_exercises_over_the_protocol(room: Classroom) -> None:
    server = ClassroomServer(room, hash_password("pw"))
    from liansuo.server.websocket import Client

    teacher, li = Client("instructor", 1), Client("trainee", 1)
    ok = server.answer(teacher, json.dumps({"type": "exercise", "seats": "all", "name": "jiaopei-cancel-route",
                                            "seed": 2}))
    assert ok["type"] == "ok" and "started on seats 1, 2, 3" in ok["message"]
    refused = server.answer(li, json.dumps({"type": "exercise", "seats": [1], "name": "jiaopei-cancel-route"}))
    assert refused["type"] == "error" and "instructor" in refused["message"]
    bad = server.answer(teacher, json.dumps({"type": "exercise", "seats": [1], "name": "x", "difficulty": 5}))
    assert bad["type"] == "error" and "difficulty" in bad["message"]
    stopped = server.answer(teacher, json.dumps({"type": "stop", "seats": [1, 3]}))
    assert stopped["type"] == "ok" and len(stopped["reports"]) == 6
    assert {Path(p).name.split("-")[0] for p in stopped["reports"]} == {"seat1", "seat3"}


def test_a_seat_whose_simulation_fails_stops_alone_and_says_why(room: Classroom, monkeypatch: pytest.MonkeyPatch,
                                                                capsys: pytest.CaptureFixture[str]) -> None:
    def fails() -> None:
        raise RuntimeError("a defect of the simulation")

    monkeypatch.setattr(room.seat(2).sim, "step", fails)
    t1 = room.seat(1).sim.t
    run_for(room, 2)
    assert room.seat(1).sim.t > t1 and room.seat(3).sim.t > t1  # the other seats' clocks go on
    summary = room.seat(2).summary()
    assert summary["paused"] and "internal error" in summary["broken"]
    assert "a defect of the simulation" in capsys.readouterr().err  # the traceback, in the server's log
    with pytest.raises(SeatError, match=r"seat 2 was stopped by an internal error.*reset it"):
        room.set_clock([2], paused=False)
    room.reset([2])  # a fresh simulation mends it
    assert room.seat(2).summary()["broken"] == ""
    room.set_clock([2], paused=False)
    run_for(room, 1)
    assert room.seat(2).sim.t > 0
