"""The command line as its users expect it (issue 14, items 2, 3 and 6), run as a user runs it: the same ``--format``
everywhere, one JSON envelope (``liansuo``, ``schema``, ``ok``), pytest's exit statuses each with its message on
stderr, every file kind told by its content, and argument values refused before any work starts."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

from liansuo.cli.main import main
from liansuo.kit.jsonreport import SCHEMAS, version
from liansuo.simulation.recording.recorder import FileRecorder
from liansuo.simulation.sim import Simulation

ROOT = Path(__file__).resolve().parent.parent
PKG = ROOT / "src" / "liansuo"
STATION = PKG / "examples" / "stations" / "minimal.yaml"
SCRIPT = PKG / "examples" / "scripts" / "jiaopei-interlocking-test.yaml"
SCENARIO = PKG / "examples" / "scenarios" / "jiaopei-receive-depart.yaml"
EXERCISE = PKG / "exercises" / "jiaopei-broken-rail-IG.yaml"


def run(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def usage_error(capsys: pytest.CaptureFixture[str], *argv: str) -> str:
    """argparse's own refusal: exit status 2 and its message on stderr, nothing on stdout."""
    with pytest.raises(SystemExit) as info:
        main(list(argv))
    out, err = capsys.readouterr()
    assert info.value.code == 2 and out == ""
    return err


def recording(path: Path) -> Path:
    sim = Simulation("jiaopei")
    rec = FileRecorder(sim, path).attach()
    sim.command("route X XI")
    sim.run(3)
    rec.close()
    return path


def envelope_of(out: str, command: str, ok: bool = True) -> dict[str, object]:
    report: dict[str, object] = json.loads(out)
    assert list(report)[:3] == ["liansuo", "schema", "ok"]
    assert report["liansuo"] == version() and re.fullmatch(r"\d+\.\d+\.\d+.*", version())
    assert report["schema"] == SCHEMAS[command] and isinstance(report["schema"], int)
    assert report["ok"] is ok
    return report


# ---- item 2: one --format, one JSON envelope ------------------------------------------------------------------------
@pytest.mark.parametrize(("command", "argv", "key"), [
    ("stations", ["stations"], "stations"),
    ("check", ["check", "jiaopei"], "turnouts"),
    ("table", ["table", "jiaopei"], "routes"),
    ("zpw", ["zpw", "gaotie"], "sections"),
    ("25hz", ["25hz", "jiaopei", "--section", "IG"], "points"),
    ("test", ["test", str(SCRIPT), "-k", "guide signal"], "tests"),
    ("run", ["run", str(SCENARIO)], "events"),
    ("verify", ["verify", "jiaopei", "--route", "X-XI", "--no-pairs"], "route_results"),
    ("soak", ["soak", "jiaopei", "--steps", "40"], "violations"),
], ids=lambda v: v if isinstance(v, str) else None)
def test_every_report_has_json_with_the_envelope(capsys: pytest.CaptureFixture[str], command: str, argv: list[str],
                                                 key: str) -> None:
    code, out, err = run(capsys, *argv, "--format", "json")
    assert code == 0, err
    report = envelope_of(out, command)
    assert key in report


def test_json_of_each_command_is_documented_with_its_schema_version() -> None:
    doc = (ROOT / "docs" / "commands.md").read_text(encoding="utf-8")
    for command, schema in SCHEMAS.items():
        name = "replay FILE --verify" if command == "replay" else command
        assert re.search(rf"\| `liansuo {re.escape(name)}[^|]*\|[^|]*json[^|]*\| {schema} \|", doc), command
        assert f"- `{command}" in doc, f"the keys of {command}'s JSON are not listed"


def test_test_json_lists_each_test_and_a_failure_makes_ok_false(tmp_path: Path,
                                                                capsys: pytest.CaptureFixture[str]) -> None:
    f = tmp_path / "t.yaml"
    f.write_text("station: jiaopei\ntests:\n  - name: wrong aspect\n    steps:\n      - route X XI\n"
                 "      - run 2s\n      - expect signal X L\n  - name: fine\n    steps:\n      - route X XI\n",
                 encoding="utf-8")
    code, out, err = run(capsys, "test", str(f), "--format", "json")
    assert code == 1
    report = envelope_of(out, "test", ok=False)
    assert (report["passed"], report["failed"]) == (1, 1)
    wrong, fine = report["tests"]  # type: ignore[misc]
    assert wrong["name"] == "wrong aspect" and wrong["passed"] is False and wrong["line"] == 7
    assert "signal X shows U, expected L" in wrong["failure"] and wrong["log"]
    assert fine == {"script": str(f), "name": "fine", "passed": True, "line": None, "failure": None, "hazards": [],
                    "log": []}
    assert err == "liansuo test: 1 of 2 tests failed\n"


def test_run_json_reports_a_refused_step(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    f = tmp_path / "s.yaml"
    f.write_text("station: jiaopei\nsteps:\n  - occupy 1DG\n  - route X XI\n", encoding="utf-8")
    code, out, err = run(capsys, "run", str(f), "--format", "json")
    assert code == 1
    report = envelope_of(out, "run", ok=False)
    assert report["problems"] == [{"line": 4, "command": "route X XI", "refused": True,
                                   "message": "section 1DG is occupied"}]
    assert err == f"liansuo run: {f}:4: 'route X XI' was refused; the run stopped\n"


def test_replay_verify_has_json(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = recording(tmp_path / "s.jsonl")
    code, out, err = run(capsys, "replay", str(path), "--verify", "--format", "json")
    assert code == 0, err
    report = envelope_of(out, "replay")
    assert report["mismatches"] == [] and report["station"] == "jiaopei" and report["commands"] == 1
    assert run(capsys, "replay", str(path), "--format", "json")[0] == 2  # json only goes with --verify


def test_zpw_spells_csv_as_table_does(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = run(capsys, "zpw", "gaotie", "--format", "csv")
    assert code == 0 and out.splitlines()[0].startswith("id,carrier,length_m")
    target = tmp_path / "z.json"
    code, out, _ = run(capsys, "zpw", "gaotie", "--format", "json", "-o", str(target))
    assert code == 0 and out == f"wrote {target}\n"
    envelope_of(target.read_text(encoding="utf-8"), "zpw")
    assert "unrecognized arguments: --csv" in usage_error(capsys, "zpw", "gaotie", "--csv", str(target))


# ---- item 3: exit statuses, each with its message ------------------------------------------------------------------
def test_nothing_selected_is_5_with_a_message(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, err = run(capsys, "test", "-k", "zzz", str(SCRIPT))
    assert code == 5 and out == ""
    assert err == "liansuo test: no test matches -k 'zzz' (of 17 tests in 1 script); nothing ran\n"
    code, out, err = run(capsys, "verify", "jiaopei", "--route", "NOPE", "--no-pairs")
    assert code == 5 and out == ""
    assert err.startswith("liansuo verify: no route NOPE in jiaopei") and len(err.splitlines()) == 1


def test_a_missing_script_is_bad_input_and_nothing_runs(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    missing = tmp_path / "nosuch.yaml"
    junit = tmp_path / "r.xml"
    code, out, err = run(capsys, "test", str(SCRIPT), str(missing), "--junit-xml", str(junit))
    assert code == 3
    assert out == ""  # the good script did not run either
    assert err == f"{missing}:1:1: error: no such file; give the path of a YAML test script (see examples/scripts/)\n"
    report = junit.read_text(encoding="utf-8")  # as pytest's collection errors: the CI server sees the error
    assert 'errors="1"' in report and 'tests="1"' in report and "no such file" in report


def test_failed_checks_are_1_and_say_so_on_stderr(capsys: pytest.CaptureFixture[str]) -> None:
    broken = PKG / "examples" / "broken" / "gaotie-no-diamond-protection.yaml"
    code, out, err = run(capsys, "verify", str(broken), "--no-pairs", "--route", "X-XI(BA1)")
    assert code == 1 and "FAIL" in out
    assert re.fullmatch(r"liansuo verify: \d+ checks? failed on gaotie-no-diamond-protection\n", err)


@pytest.mark.parametrize("argv", [["check", "{bad}"], ["table", "{bad}"], ["verify", "{bad}"], ["zpw", "{bad}"],
                                  ["soak", "{bad}"], ["tui", "{bad}"]], ids=lambda a: a[0])
def test_a_bad_station_is_3_with_file_line_column(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                                  argv: list[str]) -> None:
    bad = tmp_path / "bad.yaml"
    bad.write_text(STATION.read_text(encoding="utf-8").replace("machine: ZD6", "machine: ZD7"), encoding="utf-8")
    code, out, err = run(capsys, *(a.replace("{bad}", str(bad)) for a in argv))
    assert code == 3 and out == ""
    assert re.match(rf"{re.escape(str(bad))}:\d+:\d+: error: ", err)
    assert err.splitlines()[-1] == "1 error; the station was not loaded" and "Traceback" not in err


def test_run_names_the_scenario_not_the_station(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    f = tmp_path / "s.yaml"
    f.write_text("station: jiaopei\nsteps:\n  - fly X\n", encoding="utf-8")
    code, _, err = run(capsys, "run", str(f))
    assert code == 3 and err.splitlines()[-1] == "1 error; the scenario was not loaded"
    f.write_text("station: nowhere.yaml\nsteps:\n  - run 1s\n", encoding="utf-8")
    code, _, err = run(capsys, "run", str(f))
    assert code == 3 and "nowhere.yaml:1:1: error: no such file" in err


def test_an_unwritable_output_is_a_usage_error_before_any_work(tmp_path: Path,
                                                              capsys: pytest.CaptureFixture[str]) -> None:
    for argv in (["table", "jiaopei"], ["zpw", "gaotie"], ["generate", "hub", "--turnouts", "6", "--tracks", "4"]):
        target = tmp_path / "no-folder" / "out.txt"
        code, out, err = run(capsys, *argv, "-o", str(target))
        assert code == 2 and out == ""
        assert err == (f"liansuo {' '.join(argv[:2]) if argv[0] == 'generate' else argv[0]}: cannot write {target}: "
                       f"no folder {target.parent}; create it or give -o a file in a folder that exists\n")
        assert not target.parent.exists()


# ---- item 6: file kinds by content, argument values checked first --------------------------------------------------
@pytest.mark.parametrize(("argv", "found", "wanted"), [
    (["test", str(STATION)], "a station file", "a test script"),
    (["test", str(EXERCISE)], "an exercise", "a test script"),
    (["run", str(SCRIPT)], "a test script", "a scenario"),
    (["check", str(SCENARIO)], "a scenario", "a station file"),
    (["tui", "jiaopei", "--exercise", str(STATION)], "a station file", "an exercise"),
    (["replay", str(SCRIPT), "--verify"], "a test script", "a recording"),
    (["check", "{recording}"], "a recording", "a station file"),
    (["test", "{recording}"], "a recording", "a test script"),
], ids=lambda v: " ".join(Path(a).name for a in v) if isinstance(v, list) else None)
def test_a_file_of_another_kind_is_named_as_such(tmp_path: Path, capsys: pytest.CaptureFixture[str], argv: list[str],
                                                 found: str, wanted: str) -> None:
    rec = str(recording(tmp_path / "session.jsonl"))
    argv = [a.replace("{recording}", rec) for a in argv]
    code, out, err = run(capsys, *argv)
    assert code == 3 and out == ""
    (line,) = err.splitlines()  # one line: what it is, what was wanted, what to do with it
    assert f":1:1: error: this is {found}, not {wanted} (" in line
    assert "liansuo " in line.partition("(")[2]


def test_every_bundled_and_example_file_is_its_own_kind() -> None:
    from liansuo.kit.filekind import kind_of_file

    kinds = {"stations": "station", "scripts": "script", "scenarios": "scenario", "broken": "station"}
    for folder, kind in kinds.items():
        for path in (PKG / "examples" / folder).glob("*.yaml"):
            assert kind_of_file(path) == kind, path
    for path in (PKG / "stations" / "library").glob("*.yaml"):
        assert kind_of_file(path) == "station", path
    for path in (PKG / "exercises").glob("*.yaml"):
        assert kind_of_file(path) == "exercise", path


@pytest.mark.parametrize("speed", ["0", "-1", "nan", "fast"])
def test_speed_must_be_positive(capsys: pytest.CaptureFixture[str], speed: str) -> None:
    for command in ("tui", "replay"):
        argv = ["tui", "jiaopei"] if command == "tui" else ["replay", "x.jsonl"]
        err = usage_error(capsys, *argv, f"--speed={speed}")
        assert "argument --speed:" in err


def test_a_bad_exercise_stops_tui_before_any_console(monkeypatch: pytest.MonkeyPatch, tmp_path: Path,
                                                     capsys: pytest.CaptureFixture[str]) -> None:
    import liansuo.tui.app

    def no_console(*args: object, **kwargs: object) -> None:
        raise AssertionError("the console started")

    monkeypatch.setattr(liansuo.tui.app, "ConsoleApp", no_console)
    code, out, err = run(capsys, "tui", "--exercise", "nosuch.yaml")
    assert code == 3 and out == ""
    assert err.startswith("nosuch.yaml:1:1: error: no such file; give the path of an exercise file, or a bundled "
                          "exercise: ") and len(err.splitlines()) == 1
    assert "jiaopei-broken-rail-IG" in err and "gaotie-dead-zone-trolley" in err  # every bundled one, by name
    code, _, err = run(capsys, "tui", "gaotie", "--exercise", "jiaopei-broken-rail-IG")
    assert code == 2 and "is for station jiaopei; start the console with 'liansuo tui jiaopei --exercise" in err
    code, _, err = run(capsys, "tui", "--record", str(tmp_path / "no-folder" / "s.jsonl"))
    assert code == 2 and "no folder" in err


def test_soak_seed_has_help_and_a_default(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit):
        main(["soak", "--help"])
    text = " ".join(capsys.readouterr().out.split())
    assert "--seed S seed of the random choices (default 1)" in text
    assert "--steps N random steps (default 10000)" in text
    assert "not a positive number" in usage_error(capsys, "soak", "jiaopei", "--steps", "0")
