"""Assessment (docs/exercises.md): every bundled exercise is solvable with its model answer; wrong, unsafe and slow
answers score lower and the report says why; draws are reproducible; bad files are reported at their lines; the
command line as a trainee's instructor runs it."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

from liansuo.classroom.answers import Answer, parse_answers, play
from liansuo.classroom.assessment import Assessment
from liansuo.classroom.exercise import bundled_exercises, parse_exercise
from liansuo.classroom.report import html_report, text_report, write_report
from liansuo.classroom.roles import TRAINEE, refusal
from liansuo.classroom.unsafe import fault_release_cause, guide_cause, planted, reach
from liansuo.cli.main import main
from liansuo.kit.source import StationError
from liansuo.simulation.sim import Simulation
from liansuo.stations.loader import load

ROOT = Path(__file__).resolve().parent.parent
ANSWERS = ROOT / "tests" / "data" / "exercises"
BUNDLED = [p.stem for p in bundled_exercises()]


def attempt(name: str, lines: list[tuple[float, str]], *, seed: int = 1, difficulty: int | None = None,
            trainee: str = "Li Lei") -> Assessment:
    ex = parse_exercise(name)
    a = Assessment(ex, Simulation(ex.station_ref()), seed=seed, trainee=trainee, seat="3", difficulty=difficulty)
    play(a, [Answer(t, line, n) for n, (t, line) in enumerate(lines, 1)])
    return a


def run(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


# ---- every bundled exercise is solvable ------------------------------------------------------------------------------
def test_at_least_twelve_exercises_ship_each_with_a_model_answer() -> None:
    assert len(BUNDLED) >= 12
    assert sorted(p.stem for p in ANSWERS.glob("*.answers")) == sorted(BUNDLED)


@pytest.mark.parametrize("name", BUNDLED)
def test_the_model_answer_meets_every_goal_with_a_high_score(name: str, capsys: pytest.CaptureFixture[str]) -> None:
    code, out, err = run(capsys, "exercise", "run", name, "--answers", str(ANSWERS / f"{name}.answers"),
                         "--format", "json")
    assert code == 0, err
    report = json.loads(out)
    assert report["ok"] is True and report["all_goals_met"] is True and report["ended"] == "goals met"
    assert all(g["met_at"] is not None for g in report["goals"])
    assert all(f["diagnosed_at"] is not None for f in report["findings"])
    assert report["unsafe"] == [] and report["refused"] == 0
    assert report["score"]["total"] >= 90, report["score"]


# ---- the exercises as a user sees them -------------------------------------------------------------------------------
def test_exercise_list_names_every_bundled_exercise(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = run(capsys, "exercise", "list")
    assert code == 0
    lines = out.splitlines()
    assert lines[0].split() == ["name", "station", "level", "title"]
    for name in BUNDLED:
        assert any(line.startswith(name + " ") for line in lines), name
    assert any("gaotie" in line and "dead zone" in line for line in lines)
    code, out, _ = run(capsys, "exercise", "list", "--format", "json")
    rows = json.loads(out)["exercises"]
    assert {r["name"] for r in rows} == set(BUNDLED) and all(r["difficulty"] in (1, 2, 3) for r in rows)


def test_the_exercises_cover_every_topic_the_classroom_needs() -> None:
    text = " ".join(p.read_text(encoding="utf-8") for p in bundled_exercises())
    for word in ("cancel X", "release X", "fault-release", "guide X", "guide-lock X", "block-line SL",
                 "psd-stuck", "broken-rail", "filament", "no-indication", "flasher", "poor-shunt", "dead-zone"):
        assert word in text or word in " ".join(p.read_text() for p in ANSWERS.glob("*.answers")), word


def test_run_writes_the_report_as_json_text_and_html(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code, out, err = run(capsys, "exercise", "run", "jiaopei-total-release", "--answers",
                         str(ANSWERS / "jiaopei-total-release.answers"), "--report", str(tmp_path),
                         "--trainee", "Li Lei", "--seat", "3")
    assert code == 0, err
    assert "Sealed buttons used (铅封计数): release 1" in out
    assert "100 / 100" in out
    stem = tmp_path / "jiaopei-total-release-Li-Lei"
    for suffix in (".json", ".txt", ".html"):
        assert f"wrote {stem}{suffix}" in out
    report = json.loads(stem.with_suffix(".json").read_text(encoding="utf-8"))
    assert report["trainee"] == "Li Lei" and report["seat"] == "3" and report["seed"] == 1
    assert report["sealed_uses"] == {"release": 1}
    assert [c["command"] for c in report["commands"]] == ["release X", "route X X3"]
    assert report["goals"][0]["met_at"] >= 180  # the manual release takes its 180 s
    assert "<h1>Manual time release" in stem.with_suffix(".html").read_text(encoding="utf-8")
    assert "Commands:" in stem.with_suffix(".txt").read_text(encoding="utf-8")


def test_doing_nothing_runs_to_the_time_limit_and_fails(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    answers = tmp_path / "nothing.answers"
    answers.write_text("# nothing\n", encoding="utf-8")
    code, out, err = run(capsys, "exercise", "run", "jiaopei-cancel-route", "--answers", str(answers))
    assert code == 1
    assert err == "liansuo exercise: 0 of 2 goals met (time limit); score 0\n"
    assert "Time: 5:00.0 of 5:00.0 (time limit)" in out and "[ ] the route X-X3 is cancelled" in out


def test_a_bad_answers_file_is_one_line_with_its_place(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    answers = tmp_path / "bad.answers"
    answers.write_text("5s route X XI\nsoon cancel X\n", encoding="utf-8")
    code, out, err = run(capsys, "exercise", "run", "jiaopei-cancel-route", "--answers", str(answers))
    assert code == 3 and out == "" and "Traceback" not in err
    assert err == (f"{answers}:2:1: error: 'soon' is not a time: write the time since the exercise began, then the "
                   "command, e.g. '30s route X X3'\n")
    answers.write_text("20s route X XI\n10s cancel X\n", encoding="utf-8")
    code, _, err = run(capsys, "exercise", "run", "jiaopei-cancel-route", "--answers", str(answers))
    assert code == 3 and f"{answers}:2:1: error: 10s is before the previous answer's time (20 s)" in err
    code, _, err = run(capsys, "exercise", "run", "nosuch", "--answers", str(answers))
    assert code == 3 and err.startswith("nosuch:1:1: error: no such file")


def test_a_bad_difficulty_is_a_usage_error(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as info:
        main(["exercise", "run", "jiaopei-filament", "--answers", "x", "--difficulty", "4"])
    assert info.value.code == 2 and "invalid choice" in capsys.readouterr().err


# ---- wrong, unsafe and slow answers score lower, and the report says why ------------------------------------------
def test_a_guide_without_cause_is_unsafe_and_costs_points() -> None:
    model = [(5, "route X3 S"), (8, "block-line SL request")]
    good = attempt("jiaopei-64d-departure", model)
    bad = attempt("jiaopei-64d-departure", [*model, (10, "route X XI"), (10, "guide X")])
    assert good.report()["unsafe"] == []
    unsafe = bad.report()["unsafe"]
    assert [(u["command"], u["rule"]) for u in unsafe] == [("guide X", "guide without cause")]
    assert "nothing stops X's normal opening" in unsafe[0]["why"]
    assert bad.report()["score"]["unsafe"] == -15
    assert bad.report()["score"]["total"] == good.report()["score"]["total"] - 15 == 85
    assert bad.sealed_uses() == {"guide": 1} and bad.report()["sealed_uses"] == {"guide": 1}


def test_a_guide_with_cause_is_not_unsafe() -> None:
    a = attempt("jiaopei-guide-home-signal", [(5, "guide X")], seed=1)
    assert a.report()["unsafe"] == [] and a.report()["all_goals_met"]
    assert a.report()["findings"][0]["diagnosed_at"] is None  # ... but the dark lamp was never registered
    assert a.report()["score"]["diagnosis"] == 0 and a.report()["ended"] == "time limit"


def test_a_section_fault_release_without_cause_is_unsafe() -> None:
    """The route X-XI stands locked under a home signal that went red for a dark lamp (seed 1), no train near: 1DG
    is freed although nothing touched it."""
    a = attempt("jiaopei-guide-home-signal", [(5, "fault-release 1DG")], seed=1)
    report = a.report()
    assert [(u["command"], u["rule"]) for u in report["unsafe"]] == [
        ("fault-release 1DG", "section fault release without cause")]
    assert report["sealed_uses"] == {"fault-release": 1}


def test_a_section_fault_release_cannot_cut_a_manual_time_release_short() -> None:
    """The route X-XI is approach-locked and released by hand: a fault release of 1DG meanwhile is refused (it would
    have freed the route before its 180 s), and the route releases on time."""
    a = attempt("jiaopei-total-release", [(5, "release X"), (8, "fault-release 1DG"), (190, "route X X3")])
    report = a.report()
    assert report["unsafe"] == [] and report["refused"] == 1 and report["all_goals_met"]
    (refused,) = [c for c in report["commands"] if not c["ok"]]
    assert refused["command"] == "fault-release 1DG" and "being released by time" in refused["answer"]


def test_a_route_over_a_hidden_wagon_is_unsafe() -> None:
    a = attempt("jiaopei-poor-shunt", [(5, "route X X3"), (20, "cancel X"), (25, "block 5"), (30, "route X XI"),
                                       (35, "diagnose poor-shunt 5DG")])
    report = a.report()
    assert [(u["command"], u["rule"]) for u in report["unsafe"]] == [("route X X3", "over a hidden vehicle")]
    assert "shunts poorly" in report["unsafe"][0]["why"] and report["all_goals_met"]
    assert report["score"]["total"] <= 85


def test_wrong_diagnoses_and_refused_commands_are_counted() -> None:
    a = attempt("jiaopei-broken-rail-IG", [(2, "route X XI"), (4, "diagnose low-ballast 3G"), (6, "fault occupy"),
                                           (8, "diagnose red-band IG"), (10, "route X X3")])
    report = a.report()
    assert report["refused"] == 2  # the route over the red band, and the instructor's command
    assert [c["answer"] for c in report["commands"] if not c["ok"]] == [
        "section IG is occupied", report["commands"][2]["answer"]]
    assert "is not an operator's command" in report["commands"][2]["answer"]
    assert [(d["diagnosis"], d["correct"]) for d in report["diagnoses"]] == [
        ("low-ballast 3G", False), ("red-band IG", True)]
    assert report["score"]["wrong_diagnosis"] == -5 and report["score"]["refused"] == -4
    assert report["score"]["total"] == 100 - 9


def test_a_late_diagnosis_earns_less() -> None:
    quick = attempt("jiaopei-broken-rail-IG", [(5, "diagnose broken-rail IG"), (10, "route X X3")])
    slow = attempt("jiaopei-broken-rail-IG", [(5, "route X X3"), (400, "diagnose broken-rail IG")])
    assert quick.report()["findings"][0]["diagnosed_at"] == 5
    assert slow.report()["findings"][0]["diagnosed_at"] == 400
    assert slow.report()["score"]["diagnosis"] < quick.report()["score"]["diagnosis"] == 30


def test_progress_is_what_a_dashboard_shows() -> None:
    ex = parse_exercise("jiaopei-cancel-route")
    sim = Simulation("jiaopei")
    a = Assessment(ex, sim, seed=1)
    a.record("cancel X", sim.command("cancel X"))
    for _ in range(8):
        sim.step()
        a.tick()
    p = a.progress()
    assert (p["goals_met"], p["goals"], p["refused"], p["unsafe"], p["finished"]) == (1, 2, 0, 0, False)
    assert p["elapsed_s"] == 2 and p["time_left_s"] == 298
    assert p["score"] == 45  # half the goals' 90 points (nothing to find: the diagnosis points go to the goals)


# ---- draws ----------------------------------------------------------------------------------------------------------
def test_draws_are_reproducible_and_harder_draws_more() -> None:
    ex = parse_exercise("jiaopei-filament")
    assert ex.drawn_faults(5) == ex.drawn_faults(5)
    assert {tuple(ex.drawn_faults(s)) for s in range(20)} != {tuple(ex.drawn_faults(0))}
    assert [len(ex.drawn_faults(3, d)) for d in (1, 2, 3)] == [1, 2, 3]
    a = attempt("jiaopei-filament", [], seed=3, difficulty=3)
    report = a.report()
    assert report["seed"] == 3 and report["difficulty"] == 3
    assert report["faults"]["drawn"] == ex.drawn_faults(3, 3) and len(report["findings"]) == 3


# ---- the unsafe rules on their own --------------------------------------------------------------------------------
def test_a_signals_reach_runs_to_the_next_signals_the_same_way() -> None:
    st = load("jiaopei")
    sections, turnouts = reach(st, "X")
    assert {"7DG", "1DG", "IG", "3DG", "5DG", "3G"} <= sections and {"1", "3", "5", "7"} <= turnouts
    assert "2DG" not in sections  # beyond XI and X3


@pytest.mark.parametrize(("lines", "cause"), [
    ([], False),
    (["fault broken-rail 1DG"], True),
    (["fault broken-rail 2DG"], False),  # the other throat
    (["fault filament X lamp=U"], True),  # which=both: the lamp is dark
    (["fault filament X lamp=U which=main"], False),  # on its backup filament, the aspect is kept
    (["fault no-indication 1"], True),
    (["fault poor-shunt 1DG"], False),  # a poor shunt shows clear: nothing stops the signal
    (["occupy IG"], True),
    (["fault filament XI lamp=L"], False),  # another signal's lamp
])
def test_guide_cause(lines: list[str], cause: bool) -> None:
    st = load("jiaopei")
    assert bool(guide_cause(st, planted(st, lines), "X")) is cause


@pytest.mark.parametrize(("lines", "seen", "cause"), [
    ([], set(), False),
    (["fault broken-rail 1DG"], set(), True),
    (["fault no-indication 1"], set(), True),  # turnout 1 stands in 1DG
    (["fault no-indication 5"], set(), False),
    ([], {"1DG"}, True),  # it was occupied and left locked
    ([], {"7DG"}, True),  # the train passed by it: 7DG meets 1DG at a joint
    ([], {"IIAG"}, False),  # a train at the other end of the station
])
def test_fault_release_cause(lines: list[str], seen: set[str], cause: bool) -> None:
    st = load("jiaopei")
    assert bool(fault_release_cause(st, planted(st, lines), "1DG", seen)) is cause


def test_a_vehicle_in_a_dead_zone_is_hidden_and_one_that_shunts_is_not() -> None:
    st = load("gaotie")
    assert "3-5DG" in planted(st, ["axles trolley t-3r 4569 4576"]).hidden
    seen = planted(st, ["axles trolley t-1r 4562 t-3r 4569"])
    assert "1-7DG" in seen.occupied and "1-7DG" not in seen.hidden


# ---- the file format -----------------------------------------------------------------------------------------------
def test_a_malformed_exercise_is_reported_at_its_lines(tmp_path: Path) -> None:
    path = tmp_path / "bad.yaml"
    path.write_text("title: t\nstation: jiaopei\nfaults:\n  pool:\n    - fly X\n  draw: -1\n"
                    "goals:\n  - description: d\ndiagnosis:\n  - accept: [red IG]\ntime_limit: soon\n",
                    encoding="utf-8")
    with pytest.raises(StationError) as info:
        parse_exercise(path)
    where = [(d.line, d.column, d.message) for d in info.value.diagnostics]
    assert (5, 7, "unknown command 'fly'") in where
    assert any(line == 6 and "draw" in message for line, _, message in where)
    assert any(line == 8 and message == "a goal needs expect lines" for line, _, message in where)
    assert (10, 14, "'red IG' is not a diagnosis") in where
    assert any(line == 11 and "time_limit" in message for line, _, message in where)


def test_an_old_exercise_still_loads_as_one_goal() -> None:
    ex = parse_exercise("jiaopei-broken-rail-IG")
    assert len(ex.goals) == 1 and ex.expect == list(ex.goals[0].expect) and ex.briefing.startswith("The main track")
    assert ex.time_limit == 600 and ex.difficulty == 1


def test_diagnose_is_an_operators_command_that_changes_nothing() -> None:
    sim = Simulation("jiaopei")
    assert refusal(TRAINEE, "diagnose broken-rail IG") is None
    r = sim.command("diagnose broken-rail IG")
    assert r.ok and r.message.startswith("registered: broken-rail IG")
    assert sim.section_state("IG") == "free" and any("registered: broken-rail IG" in e for e in sim.event_texts())
    assert "is not a kind of finding" in sim.command("diagnose red IG").message
    assert "did you mean 'IG'" in sim.command("diagnose broken-rail ig").message


def test_the_html_report_escapes_what_the_trainee_typed() -> None:
    a = attempt("jiaopei-cancel-route", [(1, "route <b>X</b> XI")], trainee="<script>x</script>")
    page = html_report(a.report())
    assert "<script>x" not in page and "&lt;script&gt;x&lt;/script&gt;" in page and "&lt;b&gt;X" in page


def test_write_report_returns_the_three_files(tmp_path: Path) -> None:
    a = attempt("jiaopei-cancel-route", [(5, "cancel X"), (10, "route X XI")])
    paths = write_report(a.report(), tmp_path / "out", "seat-3")
    assert [p.name for p in paths] == ["seat-3.json", "seat-3.txt", "seat-3.html"]
    assert json.loads(paths[0].read_text(encoding="utf-8"))["score"]["total"] == 100


def test_parse_answers_reads_times_and_comments(tmp_path: Path) -> None:
    path = tmp_path / "a.answers"
    path.write_text("# heading\n\n5s route X XI  # the main track\n1min cancel X\n", encoding="utf-8")
    assert [(a.at, a.line, a.lineno) for a in parse_answers(path)] == [(5, "route X XI", 3), (60, "cancel X", 4)]


def test_a_guide_over_a_route_counts_only_what_lies_on_that_route() -> None:
    st = load("jiaopei")
    plant = planted(st, ["occupy 3G"])
    assert guide_cause(st, plant, "X")  # under guide total lock (no route), anything in the reach
    assert guide_cause(st, plant, "X", ["7DG", "1DG", "3DG", "5DG", "3G"])  # the route to 3G
    assert not guide_cause(st, plant, "X", ["7DG", "1DG", "IG"])  # the route to IG: 3G is no reason
    assert guide_cause(st, planted(st, ["fault no-indication 1"]), "X", ["7DG", "1DG", "IG"])  # 1 stands in 1DG


def test_a_typo_is_told_as_one_and_costs_nothing_an_instructors_command_does() -> None:
    """Issue 46, item 4: ``rout X XI`` on a trainee's seat was told it belongs to the instructor and counted as a
    refused command, costing points; a word that is no command is a typo, with a suggestion, never counted."""
    typo = attempt("jiaopei-cancel-route", [(1, "rout X XI"), (2, "xyzzy"), (3, "route 'X XI")])
    answers = [c["answer"] for c in typo.report()["commands"]]
    assert answers[0] == "unknown command 'rout'; did you mean 'route'? (a typo: not counted)"
    assert "unknown command 'xyzzy'" in answers[1] and "a typo" in answers[1]
    assert typo.report()["refused"] == 0
    instructor = attempt("jiaopei-cancel-route", [(1, "fault broken-rail IG")])
    assert instructor.report()["refused"] == 1
    assert "belongs to the instructor" in instructor.report()["commands"][0]["answer"]
    assert typo.report()["score"]["refused"] == 0 and instructor.report()["score"]["refused"] < 0


def test_exercise_run_says_where_the_model_answers_are(capsys: pytest.CaptureFixture[str]) -> None:
    """Issue 46, item 10: ``--answers`` is required, and its help names the model answers' place, which exists."""
    with pytest.raises(SystemExit):
        main(["exercise", "run", "--help"])
    help_text = " ".join(capsys.readouterr().out.split())
    assert "tests/data/exercises/NAME.answers" in help_text, help_text
    assert all((ANSWERS / f"{p.stem}.answers").is_file() for p in bundled_exercises())


def html_rows(page: str, heading: str) -> list[list[str]]:
    """The cells of the table under ``<h2>heading</h2>`` in a report page."""
    table = page.split(f"<h2>{heading}</h2>", 1)[1].split("</table>", 1)[0]
    return [re.findall(r"<td>(.*?)</td>", row) for row in table.split("<tr>")[2:]]


def test_a_goal_has_one_number_of_points_in_the_report_and_they_add_up_to_the_score() -> None:
    """Issue 46, item 10: the HTML report gave a goal its weight (10 'points') beside a score whose goals part was 45:
    two different points for one goal. A goal now shows its points of the score, earned of its worth."""
    a = attempt("jiaopei-cancel-route", [(1, "cancel X")])  # the first goal met, not the second
    report = a.report()
    page = html_report(report)
    goals = html_rows(page, "Goals")
    score = dict(row[:2] for row in html_rows(page, "Score"))
    assert [row[1] for row in goals] == ["45 / 45", "0 / 45"], goals  # 90 for the goals (nothing to find), halved
    assert score["goals"] == "45" == f"{sum(g['worth'] for g in report['goals'] if g['met_at'] is not None):g}"
    assert "45 / 45 points" in text_report(report) and "0 / 45 points" in text_report(report)
