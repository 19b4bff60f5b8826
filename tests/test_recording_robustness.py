"""Damaged, cut, edited and misplaced recordings through ``liansuo replay --verify`` (issue 17): a clear
``FILE:LINE`` message and a non-zero exit status, never a traceback or a hang; the start, every answer (refusals
included) and every cycle checked; the recording's station found beside the recording and checked to be the one it
was made on."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from liansuo.cli.main import main
from liansuo.simulation import Simulation
from liansuo.simulation.recording import file as recordingfile
from liansuo.simulation.recording.recorder import FileRecorder
from liansuo.simulation.recording.schema import MAX_ERRORS
from liansuo.stations.library import bundled
from liansuo.stations.loader import load_text

STEPS = ("route X XI", "run 2s", "occupy IAG", "run 5s", "release X", "route S SI", "fault no-indication 5",
         "run 10s")


def record(path: Path, station: str = "jiaopei", steps: tuple[str, ...] = STEPS) -> list[str]:
    """A session written by the recorder; its lines."""
    sim = Simulation(station)
    rec = FileRecorder(sim, path).attach()
    for step in steps:
        sim.command(step)
    rec.close()
    return path.read_text(encoding="utf-8").splitlines()


def write(path: Path, lines: list[str]) -> None:
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")


def replay(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    """The exit status, the report on stdout (folded lines joined again: one space between words) and stderr."""
    code = main(["replay", *argv, "--verify"])
    out, err = capsys.readouterr()
    assert "Traceback" not in out + err
    return code, " ".join(out.split()), err


def edit(lines: list[str], i: int, **values: object) -> list[str]:
    record = json.loads(lines[i])
    for key, value in values.items():
        if value is None:
            record.pop(key)
        else:
            record[key] = value
    return [*lines[:i], json.dumps(record, separators=(",", ":")), *lines[i + 1:]]


def line_of(lines: list[str], kind: str, text: str = "") -> int:
    return next(i for i, line in enumerate(lines) if f'"k":"{kind}"' in line and text in line)


@pytest.fixture
def session(tmp_path: Path) -> tuple[Path, list[str]]:
    path = tmp_path / "s.jsonl"
    return path, record(path)


def test_a_recording_replays_and_verifies(session: tuple[Path, list[str]],
                                          capsys: pytest.CaptureFixture[str]) -> None:
    path, _ = session
    code, out, _ = replay(capsys, str(path))
    assert code == 0 and "8 commands: the start, every answer and every cycle reproduced" in out


def test_bytes_that_are_not_utf8_are_named_at_their_line(session: tuple[Path, list[str]],
                                                         capsys: pytest.CaptureFixture[str]) -> None:
    path, lines = session
    data = path.read_bytes()
    at = data.index(b'"IAG"', len(lines[0]))
    path.write_bytes(data[:at] + b"\xff" + data[at:])
    code, _, err = replay(capsys, str(path))
    assert code == 3 and f"{path}:2:" in err and "not UTF-8 text (byte 0xff)" in err


@pytest.mark.parametrize(("kind", "key"), [("header", "station"), ("cmd", "n"), ("cyc", "n"), ("end", "n"),
                                           ("cmd", "ok"), ("init", "in")])
def test_a_missing_key_is_named_at_its_line(session: tuple[Path, list[str]], capsys: pytest.CaptureFixture[str],
                                            kind: str, key: str) -> None:
    path, lines = session
    i = line_of(lines, kind)
    write(path, edit(lines, i, **{key: None}))
    code, _, err = replay(capsys, str(path))
    assert code == 3 and f"{path}:{i + 1}:1: error: {kind} record: missing key '{key}'" in err


@pytest.mark.parametrize("cycle", ["0", "-0.25", "1e308", "NaN", "Infinity", '"0.25"', "0.001", "3"])
def test_a_cycle_out_of_range_is_refused(session: tuple[Path, list[str]], capsys: pytest.CaptureFixture[str],
                                         cycle: str) -> None:
    path, lines = session
    write(path, [lines[0].replace('"cycle_s":0.25', f'"cycle_s":{cycle}'), *lines[1:]])
    code, _, err = replay(capsys, str(path))
    assert code == 3 and f"{path}:1:1: error: header record: cycle_s:" in err


@pytest.mark.parametrize("line", [0, 2])
def test_nesting_deeper_than_the_parser_goes_is_refused(session: tuple[Path, list[str]],
                                                       capsys: pytest.CaptureFixture[str], line: int) -> None:
    path, lines = session
    deep = lines[line][:-1] + ',"x":' + "[" * 100_000 + "]" * 100_000 + "}"
    write(path, [*lines[:line], deep, *lines[line + 1:]])
    code, _, err = replay(capsys, str(path))
    assert code == 3 and f"{path}:{line + 1}:" in err and "not a JSON record: recursion limit exceeded" in err


def test_a_device_or_a_folder_is_refused_as_a_recording_and_as_its_station(
        session: tuple[Path, list[str]], capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    code, _, err = replay(capsys, "/dev/zero")
    assert code == 3 and "/dev/zero:1:1: error: not a regular file" in err
    code, _, err = replay(capsys, str(tmp_path))
    assert code == 3 and "this is a folder, not a recording" in err
    path, lines = session
    write(path, edit(lines, 0, station="/dev/zero"))
    code, _, err = replay(capsys, str(path))
    assert code == 3
    assert "names its station as /dev/zero, outside the recording's folder" in err and "--station" in err
    os.mkfifo(path.parent / "fifo.yaml")  # beside the recording: read never, a pipe would wait
    write(path, edit(lines, 0, station="fifo.yaml"))
    code, _, err = replay(capsys, str(path))
    assert code == 3
    assert "the recording was made on station jiaopei, and the station file it names, fifo.yaml " in err
    assert "is not a regular file" in err and "--station" in err


@pytest.mark.parametrize("n", [10**9, 2**31, 345_601, -1])
def test_an_end_far_away_is_refused_not_replayed(session: tuple[Path, list[str]],
                                                 capsys: pytest.CaptureFixture[str], n: int) -> None:
    path, lines = session
    write(path, edit(lines, len(lines) - 1, n=n, t=n * 0.25))
    code, _, err = replay(capsys, str(path))
    assert code == 3 and f"{path}:{len(lines)}:1: error: end record: n:" in err


def test_a_recording_without_its_init_or_end_is_refused_and_says_what_is_missing(
        session: tuple[Path, list[str]], capsys: pytest.CaptureFixture[str]) -> None:
    path, lines = session
    write(path, lines[:1])
    code, _, err = replay(capsys, str(path))
    assert code == 3 and "the recording has only its header: its 'init' record" in err and "missing" in err
    write(path, lines[:-1])
    code, _, err = replay(capsys, str(path))
    assert code == 3 and f"{path}:{len(lines) - 1}:1:" in err and "no 'end' record after this line" in err


def test_a_dropped_refused_command_is_found(session: tuple[Path, list[str]],
                                            capsys: pytest.CaptureFixture[str]) -> None:
    path, lines = session
    i = line_of(lines, "cmd", '"ok":false')
    write(path, lines[:i] + lines[i + 1:])
    code, _, err = replay(capsys, str(path))
    assert code == 3 and "command number 7 where 6 was next: a command record is missing" in err
    last = line_of(lines, "cmd", "run 10s")  # the last command dropped: only the end record's count tells
    write(path, lines[:last] + lines[last + 1:])
    code, _, err = replay(capsys, str(path))
    assert code == 3 and "the end record counts 8 commands, the file holds 7" in err


def test_the_start_every_answer_and_every_quiet_cycle_are_compared(session: tuple[Path, list[str]],
                                                                   capsys: pytest.CaptureFixture[str]) -> None:
    path, lines = session
    write(path, [lines[0], lines[1].replace('"IAG":true', '"IAG":false', 1), *lines[2:]])
    code, out, err = replay(capsys, str(path))
    assert code == 1 and f"{path}:2: the state at the start (init): recorded" in out
    assert "not reproduced" in err

    i = line_of(lines, "cmd", '"ok":false')
    write(path, edit(lines, i, msg="route set"))
    code, out, _ = replay(capsys, str(path))
    assert code == 1 and f"{path}:{i + 1}: 'route S SI' (t = 7 s) was refused: 'route set'; replayed, refused:" in out

    quiet = {json.loads(line)["n"] for line in lines if '"k":"cyc"' in line}
    n = next(n for n in range(1, 20) if n not in quiet)
    made_up = json.dumps({"k": "cyc", "n": n, "t": n * 0.25, "out": {"sig": {"X": "L"}}}, separators=(",", ":"))
    at = next(i for i, line in enumerate(lines[2:], 2) if json.loads(line)["n"] > n)
    write(path, [*lines[:at], made_up, *lines[at:]])
    code, out, _ = replay(capsys, str(path))
    assert code == 1 and f'cycle {n} (t = {n * 0.25:g} s): recorded {{"out": {{"sig": {{"X": "L"}}}}}}, replayed {{}}' \
        in out


def test_a_recording_on_another_station_is_refused_saying_which(session: tuple[Path, list[str]],
                                                                capsys: pytest.CaptureFixture[str]) -> None:
    path, lines = session
    write(path, edit(lines, 0, station="gaotie"))
    code, _, err = replay(capsys, str(path))
    assert code == 3 and "the recording was made on station jiaopei, but the bundled station gaotie it names is " \
                         "station gaotie" in err
    write(path, lines)
    code, _, err = replay(capsys, str(path), "--station", "depot")
    assert code == 3 and "the recording was made on station jiaopei, but --station depot is station depot" in err


def test_the_station_path_is_relative_to_the_recording_not_the_current_folder(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch) -> None:
    here = tmp_path / "recordings"
    here.mkdir()
    shutil.copy(bundled()["jiaopei"], here / "station.yaml")
    monkeypatch.chdir(here)
    lines = record(here / "s.jsonl", "station.yaml")
    assert json.loads(lines[0])["station"] == "station.yaml"
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    shutil.copy(bundled()["gaotie"], elsewhere / "station.yaml")  # the same name, another station, in the cwd
    monkeypatch.chdir(elsewhere)
    code, out, _ = replay(capsys, str(here / "s.jsonl"))
    assert code == 0 and "every cycle reproduced" in out


def test_a_station_file_changed_since_or_moved_away_is_refused_and_can_be_given(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    station = tmp_path / "station.yaml"
    shutil.copy(bundled()["jiaopei"], station)
    path = tmp_path / "s.jsonl"
    record(path, str(station))
    station.write_text(station.read_text(encoding="utf-8") + "# edited\n", encoding="utf-8")
    code, _, err = replay(capsys, str(path))
    assert code == 3 and "the file of the station file it names, station.yaml" in err and "has changed since" in err

    shutil.copy(bundled()["jiaopei"], station)
    moved = tmp_path / "away"
    moved.mkdir()
    shutil.move(path, moved / "s.jsonl")
    code, _, err = replay(capsys, str(moved / "s.jsonl"))
    assert code == 3 and f"station.yaml ({moved / 'station.yaml'}), does not exist" in err
    code, out, _ = replay(capsys, str(moved / "s.jsonl"), "--station", str(station))
    assert code == 0 and "every cycle reproduced" in out


def test_an_older_format_is_refused_with_its_version(session: tuple[Path, list[str]],
                                                     capsys: pytest.CaptureFixture[str]) -> None:
    path, lines = session
    write(path, edit(lines, 0, version=1))
    code, _, err = replay(capsys, str(path))
    assert code == 3 and f"{path}:1:1: error: recording format version 1; this liansuo reads version 2" in err


def test_a_command_that_runs_past_the_end_is_stopped_there(session: tuple[Path, list[str]],
                                                           capsys: pytest.CaptureFixture[str]) -> None:
    path, lines = session
    i = line_of(lines, "cmd", "release X")
    write(path, edit(lines, i, line="run 50min"))
    code, out, _ = replay(capsys, str(path))
    assert code == 1 and f"{path}:{i + 1}: 'run 50min' (t = 7 s) runs past the end of the recording (cycle 68" in out


def test_escape_sequences_in_a_recording_are_shown_written_out(session: tuple[Path, list[str]],
                                                               capsys: pytest.CaptureFixture[str]) -> None:
    path, lines = session
    i = line_of(lines, "cmd", '"ok":false')
    write(path, edit(lines, i, msg="\x1b[2J\x1b]0;owned\x07"))
    code, out, _ = replay(capsys, str(path))
    assert code == 1 and "\x1b" not in out and "\\x1b[2J\\x1b]0;owned\\x07" in out


def test_commands_of_the_trains_automation_are_not_recorded_and_replay(tmp_path: Path,
                                                                       capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "auto.jsonl"
    sim = Simulation("depot")
    rec = FileRecorder(sim, path).attach()
    sim.command("train L1 at RDG kind=shunter back=20")
    sim.command("auto L1 plan=D1-D5,D13-1KA")
    sim.run(60)  # the centre asks for D1-D5 during a cycle
    rec.close()
    lines = path.read_text(encoding="utf-8").splitlines()
    assert [json.loads(line)["line"] for line in lines if '"k":"cmd"' in line] == [
        "train L1 at RDG kind=shunter back=20", "auto L1 plan=D1-D5,D13-1KA"]
    assert any("centre asked for D1-D5" in e.text for e in sim.events)  # a command sent inside a cycle
    code, out, _ = replay(capsys, str(path))
    assert code == 0 and "every cycle reproduced" in out


def test_a_file_too_large_or_a_line_too_long_is_refused_before_it_is_parsed(
        session: tuple[Path, list[str]], capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch) -> None:
    path, lines = session
    monkeypatch.setattr(recordingfile, "MAX_LINE_CHARS", len(lines[1]) - 1)
    code, _, err = replay(capsys, str(path))
    assert code == 3 and f"{path}:2:1: error: a line of {len(lines[1]):,} characters; a record is at most" in err
    monkeypatch.setattr(recordingfile, "MAX_BYTES", 1000)
    code, _, err = replay(capsys, str(path))
    assert code == 3 and f"{path}:1:1: error: {path.stat().st_size:,} bytes: a recording is at most 1,000" in err


def test_a_badly_damaged_file_lists_its_first_errors_only(session: tuple[Path, list[str]],
                                                         capsys: pytest.CaptureFixture[str]) -> None:
    path, lines = session
    write(path, [*lines[:2], *["{oops"] * 50, *lines[2:]])
    code, _, err = replay(capsys, str(path))
    assert code == 3 and err.count("not a JSON record") == MAX_ERRORS
    assert f"{path}:{3 + MAX_ERRORS}:1: error: the lines from here not checked after {MAX_ERRORS} errors" in err


SECRET = "api_key: do-not-show-this-line\n"


def replay_process(*argv: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "liansuo", "replay", *argv, "--verify"], capture_output=True,
                          text=True, check=False, timeout=120)


@pytest.mark.parametrize("where", ["absolute", "parent", "symlink"])
def test_a_recordings_station_outside_its_folder_is_refused_unread(tmp_path: Path, where: str) -> None:
    """Issue 45, item 8: a recording naming /etc/shadow or ../.. as its station had that file read as a station and
    its lines echoed ('/etc/shadow:1:1: error: unknown key ...'). Its station is a bundled name or a file in its own
    folder; anything else is refused naming the path only, and replays when given on the command line."""
    secret = tmp_path / "secret.yaml"
    secret.write_text(SECRET, encoding="utf-8")
    folder = tmp_path / "recordings"
    folder.mkdir()
    path = folder / "s.jsonl"
    lines = record(path)
    named = {"absolute": str(secret), "parent": "../secret.yaml", "symlink": "link.yaml"}[where]
    if where == "symlink":
        (folder / "link.yaml").symlink_to(secret)
    write(path, edit(lines, 0, station=named))
    proc = replay_process(str(path))
    assert proc.returncode == 3, proc.stderr
    assert proc.stderr.startswith(f"{path}:1:1: error: the recording names its station as {named}, outside the "
                                  "recording's folder"), proc.stderr
    assert "--station" in proc.stderr and "do-not-show" not in proc.stdout + proc.stderr
    assert "Traceback" not in proc.stderr


def test_a_station_elsewhere_replays_when_given_on_the_command_line(tmp_path: Path) -> None:
    stations, recordings = tmp_path / "stations", tmp_path / "recordings"
    stations.mkdir()
    recordings.mkdir()
    station = stations / "jiaopei.yaml"
    shutil.copy(bundled()["jiaopei"], station)
    path = recordings / "s.jsonl"
    record(path, str(station))
    assert json.loads(path.read_text(encoding="utf-8").splitlines()[0])["station"] == "../stations/jiaopei.yaml"
    refused = replay_process(str(path))
    assert refused.returncode == 3 and "outside the recording's folder" in refused.stderr
    assert "--station" in refused.stderr and str(recordings / "../stations/jiaopei.yaml") in refused.stderr
    given = replay_process(str(path), "--station", str(station))
    assert given.returncode == 0, given.stderr
    beside = recordings / "jiaopei.yaml"  # a station beside the recording replays as it is named
    shutil.copy(station, beside)
    record(path, str(beside))
    assert replay_process(str(path)).returncode == 0


def test_an_empty_station_digest_is_refused(session: tuple[Path, list[str]],
                                            capsys: pytest.CaptureFixture[str]) -> None:
    """An empty station_sha256 turned the check of the station off: any file with the station's id replayed."""
    path, lines = session
    write(path, edit(lines, 0, station_sha256=""))
    code, _, err = replay(capsys, str(path))
    assert code == 3 and f"{path}:1:" in err and "station_sha256 is empty" in err and "record the session again" in err


def test_a_station_read_from_no_file_cannot_be_recorded(tmp_path: Path) -> None:
    """The recorder never writes a recording without its station's digest (issue 45, item 8)."""
    sim = Simulation(load_text(bundled()["jiaopei"].read_text(encoding="utf-8")))
    with pytest.raises(ValueError, match="was not read from a file"):
        FileRecorder(sim, tmp_path / "s.jsonl").attach()
