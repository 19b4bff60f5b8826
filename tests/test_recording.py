"""Session recording (JSON lines) and its replay by re-simulation; exercises and their goals."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from liansuo.classroom.exercise import bundled_exercises, check_goal, parse_exercise
from liansuo.cli.main import main
from liansuo.kit.source import StationError
from liansuo.simulation import Simulation
from liansuo.simulation.recording.recorder import FileRecorder, Recorder, RecordingError, load_recording
from liansuo.simulation.recording.replayer import Replayer


def record_session(path: Path) -> Simulation:
    sim = Simulation("jiaopei")
    rec = FileRecorder(sim, path).attach()
    rec.source = "trainee"
    sim.run(2)
    sim.command("route X XI")
    sim.run(5)
    sim.command("occupy IAG")
    sim.command("run 5s")  # cycles inside a command are recorded after it
    sim.command("release X")
    rec.source = "instructor"
    sim.command("fault no-indication 5")
    sim.command("route S SI")  # refused: recorded with its reason
    sim.run(10)
    rec.close()
    return sim


def test_the_recording_is_compact_json_lines_with_commands_and_changes(tmp_path: Path) -> None:
    path = tmp_path / "s.jsonl"
    sim = record_session(path)
    records = [json.loads(line) for line in path.read_text(encoding="utf-8").splitlines()]
    kinds = [r["k"] for r in records]
    assert kinds[0] == "header" and kinds[1] == "init" and kinds[-1] == "end"
    head = records[0]
    assert (head["version"], head["station"], head["station_id"]) == (2, "jiaopei", "jiaopei")
    assert len(head["station_sha256"]) == 64
    cmds = [r for r in records if r["k"] == "cmd"]
    assert [c["i"] for c in cmds] == list(range(1, 7)) and records[-1]["cmds"] == 6
    assert [(c["line"], c["by"], c["ok"]) for c in cmds] == [
        ("route X XI", "trainee", True), ("occupy IAG", "trainee", True), ("run 5s", "trainee", True),
        ("release X", "trainee", True), ("fault no-indication 5", "instructor", True),
        ("route S SI", "instructor", False)]
    assert "conflicting route X-XI" in cmds[-1]["msg"]
    run_cmd = next(i for i, r in enumerate(records) if r.get("line") == "run 5s")
    assert records[run_cmd + 1]["n"] > records[run_cmd]["n"]  # the cycles of 'run 5s' follow the command
    cycles = [r for r in records if r["k"] == "cyc"]
    assert len(cycles) < records[-1]["n"]  # quiet cycles are not written
    assert any(r.get("out", {}).get("sig", {}).get("X") == "U" for r in cycles)
    assert any(r.get("in", {}).get("ind", {}).get("5", "x") is None for r in records if r["k"] in ("chg", "cyc"))
    assert records[-1]["t"] == sim.t


def test_replay_reproduces_the_recorded_outputs_and_seeks(tmp_path: Path) -> None:
    path = tmp_path / "s.jsonl"
    sim = record_session(path)
    rec = load_recording(path)
    assert rec.duration == pytest.approx(sim.t)
    rp = Replayer(rec)
    assert rp.verify() == []
    assert rp.sim.route_state("X-XI") == sim.route_state("X-XI") == "time_release"
    rp.seek(3.0)
    assert rp.sim.t == 3.0 and rp.sim.route_state("X-XI") == "open"
    rp.seek(1.0)  # back: re-simulated from the start
    assert rp.sim.t == 1.0 and rp.sim.route_state("X-XI") == "released"


def test_replay_finds_a_tampered_recording(tmp_path: Path) -> None:
    path = tmp_path / "s.jsonl"
    record_session(path)
    lines = path.read_text(encoding="utf-8").splitlines()
    i = next(i for i, line in enumerate(lines) if '"X":"U"' in line)
    lines[i] = lines[i].replace('"X":"U"', '"X":"L"')
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    bad = Replayer(load_recording(path)).verify()
    assert bad and "recorded" in bad[0]
    assert main(["replay", str(path), "--verify"]) == 1


def test_replay_verify_from_the_command_line(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "s.jsonl"
    record_session(path)
    assert main(["replay", str(path), "--verify"]) == 0
    assert "6 commands: the start, every answer and every cycle reproduced" in capsys.readouterr().out


def test_a_malformed_recording_names_its_line(tmp_path: Path) -> None:
    path = tmp_path / "bad.jsonl"
    record_session(path)
    lines = path.read_text(encoding="utf-8").splitlines()
    lines[2] = "not json"
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    with pytest.raises(RecordingError, match=r"bad.jsonl:3:2: error: not a JSON record: expected ident"):
        load_recording(path)
    path.write_text('{"k": "cmd"}\n', encoding="utf-8")
    with pytest.raises(RecordingError, match="not a liansuo recording"):
        load_recording(path)


def test_a_recorder_can_be_detached() -> None:
    sim = Simulation("jiaopei")
    out: list[dict[str, object]] = []
    rec = Recorder(sim, out.append).attach()
    sim.command("route X XI")
    rec.detach()
    sim.command("cancel X")
    assert [r.get("line") for r in out if r["k"] == "cmd"] == ["route X XI"]


def test_the_bundled_exercises_load_and_their_goals_can_be_reached() -> None:
    files = {p.name: p for p in bundled_exercises()}
    assert {"jiaopei-broken-rail-IG.yaml", "jiaopei-turnout-5-no-indication.yaml"} <= set(files)
    ex = parse_exercise(files["jiaopei-broken-rail-IG.yaml"])
    sim = Simulation(ex.station_ref())
    for line in ex.setup:
        assert sim.command(line).ok
    assert not check_goal(sim, ex).reached
    assert sim.command("route X X3").ok
    sim.run(15)
    assert check_goal(sim, ex).reached

    ex = parse_exercise(files["jiaopei-turnout-5-no-indication.yaml"])
    sim = Simulation(ex.station_ref())
    for line in ex.setup:
        assert sim.command(line).ok
    assert sim.command("route X X3").ok
    sim.run(20)
    assert sim.route_state("X-X3") == "setting" and sim.aspect("X") == "H"  # never locks without indication
    assert sim.command("cancel X").ok
    assert sim.command("lock 5").ok and sim.command("route X XI").ok
    sim.run(5)
    assert check_goal(sim, ex).reached


def test_a_malformed_exercise_is_reported_at_its_line(tmp_path: Path) -> None:
    path = tmp_path / "ex.yaml"
    path.write_text("title: x\nstation: jiaopei\nsetup:\n  - flip IG\ngoal:\n  expect: [section IG free]\n"
                    "colour: red\n", encoding="utf-8")
    with pytest.raises(StationError) as err:
        parse_exercise(path)
    text = "\n".join(str(d) for d in err.value.diagnostics)
    assert "unknown command 'flip'" in text and ":4:" in text
    assert "unknown key 'colour'" in text


def test_a_command_line_past_the_languages_limit_is_recorded_and_replays(tmp_path: Path) -> None:
    """A 300,000-character line sent at the console is refused by the language (issue 45, item 8); the recording keeps
    it cut one character past the limit, so it stays readable and the replay is refused in the same words."""
    path = tmp_path / "long.jsonl"
    sim = Simulation("jiaopei")
    rec = FileRecorder(sim, path).attach()
    sim.run(1)
    assert not sim.command("route X XI '" + "a" * 300_000 + "'").ok
    assert sim.command("route X XI").ok
    rec.close()
    assert Replayer(load_recording(path)).verify() == []
