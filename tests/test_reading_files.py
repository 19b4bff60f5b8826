"""Reading files safely (issue 17, docs/robustness.md "Reading files"): every YAML file goes through one bounded
reader, whatever reaches the terminal from a file is written out, and a file's ``station:`` means the same station
from wherever it is run. Each test is a reproducer of the issue, run as a user runs it."""

from __future__ import annotations

import hashlib
import json
import os
import re
from pathlib import Path

import pytest

from liansuo.cli.main import main
from liansuo.kit.inputlimits import LIMITS
from liansuo.kit.source import StationError
from liansuo.proving.pytest_plugin import is_script
from liansuo.rules import RuleError, load_rules
from liansuo.stations.library import describe
from liansuo.stations.loader import load

ROOT = Path(__file__).resolve().parent.parent
PKG = ROOT / "src" / "liansuo"
MINIMAL = (PKG / "examples" / "stations" / "minimal.yaml").read_text(encoding="utf-8")
DANXIAN = (PKG / "examples" / "stations" / "danxian.yaml").read_text(encoding="utf-8")
RAW_CONTROL = re.compile(r"[\x00-\x08\x0b-\x1f\x7f-\x9f]")
# 700 bytes that expand to 10^10 values: each list repeats the one above it ten times, nine deep
BOMB = "\n".join(["lol0: &l0 [lol, lol, lol, lol, lol, lol, lol, lol, lol, lol]",
                  *(f"lol{i}: &l{i} [{', '.join([f'*l{i - 1}'] * 10)}]" for i in range(1, 10))]) + "\n"


def run(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def written(tmp_path: Path, text: str, name: str = "station.yaml") -> Path:
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


def refused_at(capsys: pytest.CaptureFixture[str], path: Path, line: int, column: int, *argv: str) -> str:
    """``liansuo check PATH`` (or ARGV) exits 3 with the first error at LINE:COLUMN; its message, in plain words."""
    code, out, err = run(capsys, *(argv or ("check",)), str(path))
    assert code == 3 and out == "", err
    first = err.splitlines()[0]
    assert first.startswith(f"{path}:{line}:{column}: error: "), err
    assert "<unicode string>" not in err and "Traceback" not in err
    return first.split(": error: ", 1)[1]


# ---- item 1: aliases and sizes bounded ------------------------------------------------------------------------------
def test_an_alias_bomb_is_refused_at_the_alias_that_goes_over_the_limit(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = written(tmp_path, BOMB + MINIMAL)
    assert len(BOMB) < 700
    message = refused_at(capsys, path, 5, 47)
    assert message == ("the alias '*l3' repeats 11,111 values, and the file's aliases so far 101,218: liansuo "
                       "expands at most 100,000")


@pytest.mark.parametrize("argv", [("test",), ("run",)])
def test_the_alias_bomb_is_refused_through_a_script_or_a_scenario_too(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], argv: tuple[str]) -> None:
    bomb = written(tmp_path, BOMB + MINIMAL, "bomb.yaml")
    body = "tests:\n  - name: x\n    steps:\n      - run 1s\n" if argv[0] == "test" else "steps:\n  - run 1s\n"
    script = written(tmp_path, f"station: bomb.yaml\n{body}", "file.yaml")
    code, _, err = run(capsys, *argv, str(script))
    assert code == 3 and err.startswith(f"{bomb}:5:47: error: the alias '*l3' repeats 11,111 values")


def test_the_alias_bomb_is_refused_through_a_recording_header(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    bomb = written(tmp_path, BOMB + MINIMAL, "bomb.yaml")
    digest = hashlib.sha256(bomb.read_bytes()).hexdigest()
    records = [{"k": "header", "format": "liansuo-recording", "version": 2, "station": bomb.name,
                "station_id": "minimal", "station_sha256": digest, "cycle_s": 0.25, "t0": 0.0},
               {"k": "init", "n": 0, "t": 0.0, "in": {}, "out": {}}, {"k": "end", "n": 0, "t": 0.0, "cmds": 0}]
    header = "".join(json.dumps(r) + "\n" for r in records)
    code, _, err = run(capsys, "replay", str(written(tmp_path, header, "rec.jsonl")), "--verify")
    assert code == 3 and err.startswith(f"{bomb}:5:47: error: the alias '*l3' repeats 11,111 values")


def test_aliases_that_repeat_a_little_still_load(tmp_path: Path) -> None:
    text = MINIMAL.replace("lamps: [U, L, H, U2, B]", "lamps: &five [U, L, H, U2, B]").replace(
        "lamps: [L, U, H, B]", "lamps: *five")
    assert "*five" in text
    station = load(written(tmp_path, text))
    assert [lamp.value for lamp in station.model.signals[1].lamps] == ["U", "L", "H", "U2", "B"]


@pytest.mark.parametrize(("text", "line", "column", "message"), [
    ("id: &a [x, *a]\n", 1, 12, "the alias '*a' stands inside the part its anchor '&a' marks, so it would repeat "
                                "itself without end"),
    ("id: minimal\nname: *nope\n", 2, 7, "the alias '*nope' names no anchor '&nope' above it"),
    ("id: &a minimal\nname: &a x\n", 2, 7, "the anchor '&a' is defined twice (first at line 1)"),
    ("id: minimal\ndeep: " + "[" * 100_000 + "]" * 100_000 + "\n", 2, 70, "lists and mappings nested more than "
                                                                          f"{LIMITS.max_depth} deep"),
    ("id: minimal\n# [[[[ a comment [[\nkey: '[[[['\ndeep: " + "{a: " * 100_000 + "}" * 100_000 + "\n", 4, 259,
     f"lists and mappings nested more than {LIMITS.max_depth} deep"),
    ("id: minimal\n---\nid: other\n", 2, 1, "a second YAML document ('---'): a liansuo file holds one"),
])
def test_what_the_reader_refuses_is_reported_where_it_stands(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], text: str, line: int, column: int, message: str) -> None:
    """Nesting 100,000 deep used to crash the process (YAML's C composer recursing), a self-referring alias to
    raise RecursionError."""
    assert refused_at(capsys, written(tmp_path, text), line, column) == message


def test_nesting_past_the_yaml_library_s_own_limit_is_refused_in_our_words_where_it_cannot_be_placed_better(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """libyaml (PyYAML 6.0.4 on) refuses flow nesting past its own limit before the events reach ours; where the
    reader cannot find the bracket that passes our limit (a quote in a plain value, here), the limit is named at
    libyaml's place, on the right line, with no parser's words."""
    path = written(tmp_path, "id: minimal\ndeep: [it's, " + "[" * 100_000 + "]" * 100_000 + "]\n")
    code, out, err = run(capsys, "check", str(path))
    assert code == 3 and out == ""
    assert err.startswith(f"{path}:2:") and f": error: lists and mappings nested more than {LIMITS.max_depth} deep\n" \
        in err, err


def test_a_device_or_a_pipe_is_refused_without_being_read(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    for path in (Path("/dev/zero"), tmp_path / "fifo"):
        if path.name == "fifo":
            os.mkfifo(path)  # nobody writes to it: opening it to read would wait for ever
        code, out, err = run(capsys, "check", str(path))
        assert code == 3 and out == ""
        assert err == (f"{path}:1:1: error: not a regular file (a device, a pipe or a socket): liansuo reads its files "
                       "whole, so give a file saved on disk\n")
    assert not is_script(tmp_path / "fifo")  # the pytest plugin's collection does not wait on it either
    code, _, err = run(capsys, "replay", "/dev/zero", "--verify")  # nor does a recording's reader
    assert code == 3 and "not a regular file" in err


def test_a_file_larger_than_the_limit_is_refused(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "huge.yaml"
    with path.open("wb") as fh:
        fh.truncate(LIMITS.max_file_bytes + 1)
    code, _, err = run(capsys, "check", str(path))
    assert code == 3 and err.startswith(f"{path}:1:1: error: the file is too large: liansuo reads files of at most "
                                        "16 MB")


def test_bytes_that_are_not_utf8_are_placed(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "latin1.yaml"
    path.write_bytes(b"id: minimal\nname: {zh: \xe6\x9c\x80, en: Caf\xe9}\n")
    assert refused_at(capsys, path, 2, 22) == "not UTF-8 text (byte 0xe9)"


def test_an_id_too_long_is_refused_at_its_line(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    long_id = "X" * (LIMITS.max_id_chars + 1)
    path = written(tmp_path, MINIMAL.replace("{id: XI, kind: starting", f"{{id: {long_id}, kind: starting"))
    message = refused_at(capsys, path, 47, 10)
    assert message.startswith(f"signals.1.id: an id of 65 characters: an id has at most {LIMITS.max_id_chars}")
    # a million characters is refused by the reader before anything looks at it
    path = written(tmp_path, MINIMAL.replace("id: minimal", "id: " + "X" * 1_000_000))
    assert refused_at(capsys, path, 9, 5) == "a value of 1,000,000 characters: liansuo takes at most 20,000"


def test_an_id_ending_in_a_line_break_is_no_id(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = written(tmp_path, MINIMAL.replace("{id: XI, kind: starting", '{id: "XI\\n", kind: starting'))
    assert "is not a valid id" in refused_at(capsys, path, 47, 10)


def test_a_signal_listing_a_lamp_twice_is_refused_not_crashed_in_verify(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """Found by fuzzing: check accepted it, verify raised ValueError building the lamp circuits."""
    path = written(tmp_path, MINIMAL.replace("lamps: [L, U, H, B]", "lamps: [L, U, H, B, L]"))
    for command in ("check", "verify"):
        message = refused_at(capsys, path, 47, 64, command)
        assert message.startswith("signals.1.lamps: lamp L is listed twice: a signal has each lamp once")


def test_a_64d_line_without_sections_is_refused_not_crashed_in_verify(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """Found by fuzzing: check accepted it, verify raised IndexError looking for the line's departure section."""
    path = written(tmp_path, DANXIAN.replace("en: Station A}, sections: [IAG]}", "en: Station A}}"))
    for command in ("check", "verify"):
        assert refused_at(capsys, path, 78, 20, command) == (
            "64D semi-automatic block line XL names no sections: its block machine sees our train depart by its "
            "departure section")


def test_a_rule_file_goes_through_the_same_reader(tmp_path: Path) -> None:
    folder = tmp_path / "rules"
    folder.mkdir()
    for f in (PKG / "rules" / "china").glob("*.yaml"):
        (folder / f.name).write_text(f.read_text(encoding="utf-8"), encoding="utf-8")
    (folder / "design.yaml").write_text(BOMB, encoding="utf-8")
    with pytest.raises(RuleError) as info:
        load_rules(folder)
    assert [str(p) for p in info.value.problems] == [
        f"{folder / 'design.yaml'}:5:47: error: the alias '*l3' repeats 11,111 values, and the file's aliases so far "
        "101,218: liansuo expands at most 100,000"]


# ---- diagnostics: merge keys, tags, control characters at their place ----------------------------------------------
@pytest.mark.parametrize(("edit", "line", "column", "message"), [
    (("  - {id: 1DG, type: 25hz}", "  - <<: {id: 1DG}\n    type: 25hz"), 40, 5,
     "YAML merge keys ('<<') are not supported"),
    (("name: {zh:", "name: !!python/object/apply:os.system [ls]\nnames: {zh:"), 10, 7,
     "the tag '!!python/object/apply:os.system' is not allowed on a list: liansuo files hold plain values (text, "
     "numbers, true or false, lists and mappings)"),
    (("  - {id: 3G, type: 25hz", "  - {id: 3G, type: !!python/name:os.system 25hz"), 42, 20,
     "the tag '!!python/name:os.system' is not allowed on a value: liansuo files hold plain values (text, numbers, "
     "true or false, lists and mappings)"),
    (("en: Minimal station", "en: Minimal \x1b[2J station"), 10, 29,
     "the control character U+001B (ESC) is not allowed in a liansuo file"),
    (("en: Minimal station", "en: Minimal \x85station"), 10, 29,
     "the control character U+0085 (NEL) is not allowed in a liansuo file"),
    (("line: double", "line: !!int double"), 12, 7, "'double' is not a whole number"),
])
def test_yaml_features_liansuo_does_not_take_are_placed_in_plain_words(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], edit: tuple[str, str], line: int, column: int,
        message: str) -> None:
    assert edit[0] in MINIMAL
    assert refused_at(capsys, written(tmp_path, MINIMAL.replace(*edit, 1)), line, column) == message


# ---- text from files written out on the command line ---------------------------------------------------------------
ESCAPES = "\\e]0;pwned\\a\\e[2J"  # as written in YAML's double quotes: sets the terminal's title, clears the screen


@pytest.mark.parametrize("command", ["check", "table", "verify"])
def test_escape_sequences_in_a_station_name_are_written_out(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], command: str) -> None:
    path = written(tmp_path, MINIMAL.replace("en: Minimal station", f'en: "Minimal {ESCAPES}"'))
    code, out, err = run(capsys, command, str(path))
    assert code == 0, err
    assert not RAW_CONTROL.search(out + err)
    assert "Minimal \\x1b]0;pwned\\x07\\x1b[2J" in out


def test_escape_sequences_quoted_in_an_error_are_written_out(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = written(tmp_path, MINIMAL.replace("line: double", f'"line{ESCAPES}": double'))
    code, out, err = run(capsys, "check", str(path))
    assert code == 3 and not RAW_CONTROL.search(out + err)
    assert f"{path}:12:1: error: unknown key 'line\\x1b]0;pwned\\x07\\x1b[2J'" in err


def test_escape_sequences_in_a_test_name_and_a_station_description_are_written_out(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    script = written(tmp_path, f'station: jiaopei\ntests:\n  - name: "red {ESCAPES}"\n    steps:\n'
                               "      - expect signal X L\n", "script.yaml")
    code, out, err = run(capsys, "test", str(script))
    assert code == 1 and not RAW_CONTROL.search(out + err)
    assert f"FAIL {script}:5: red\n    \\x1b]0;pwned\\x07\\x1b[2J\n" in out  # folded at the space
    station = written(tmp_path, MINIMAL.replace("description: Down", f'description: "{ESCAPES} Down'))
    station.write_text(station.read_text(encoding="utf-8").replace("home and starting signal\n",
                                                                   'home and starting signal"\n'), encoding="utf-8")
    assert describe(station).startswith("最小站 Minimal station: \\x1b]0;pwned\\x07\\x1b[2J Down")


# ---- station: relative to the file that names it -------------------------------------------------------------------
def test_a_script_and_a_scenario_name_their_station_relative_to_themselves(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch) -> None:
    """The script's folder holds minimal (which has section 1LQG); the folder it is run from holds danxian under
    the same name (no 1LQG): docs/commands.md says the path is relative to the script."""
    here, elsewhere = tmp_path / "scripts", tmp_path / "cwd"
    here.mkdir()
    elsewhere.mkdir()
    written(here, MINIMAL, "st.yaml")
    written(elsewhere, DANXIAN, "st.yaml")
    script = written(here, "station: st.yaml\ntests:\n  - name: siding free\n    steps:\n"
                           "      - expect section 1LQG free\n", "script.yaml")
    scenario = written(here, "station: st.yaml\nsteps:\n  - expect section 1LQG free\n", "scenario.yaml")
    monkeypatch.chdir(elsewhere)
    code, out, err = run(capsys, "test", str(script))
    assert code == 0 and "1 passed, 0 failed" in out, out + err
    code, out, err = run(capsys, "run", str(scenario))
    assert code == 0, out + err
    # the station next to the script is the one meant, even when the folder it is run from has none
    (elsewhere / "st.yaml").unlink()
    assert run(capsys, "test", str(script))[0] == 0


def test_a_station_the_script_names_that_is_not_there_is_named_where_it_was_looked_for(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch) -> None:
    script = written(tmp_path, "station: nowhere.yaml\ntests:\n  - name: x\n    steps:\n      - run 1s\n",
                     "script.yaml")
    monkeypatch.chdir(ROOT)
    code, _, err = run(capsys, "test", str(script))
    assert code == 3 and err.startswith(f"{tmp_path / 'nowhere.yaml'}:1:1: error: no such file")


def test_loading_through_the_api_gives_the_same_refusal(tmp_path: Path) -> None:
    with pytest.raises(StationError) as info:
        load(written(tmp_path, BOMB + MINIMAL))
    assert (info.value.diagnostics[0].line, info.value.diagnostics[0].column) == (5, 47)
