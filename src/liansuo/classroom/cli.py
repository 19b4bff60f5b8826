"""``liansuo exercise list`` and ``liansuo exercise run``: the bundled exercises, and an exercise run headless with a
trainee's timed answers, scored as the classroom server scores a seat (docs/exercises.md).

``run`` exits with 0 when every goal was met, 1 when not, 2 for a bad option value and 3 for a bad exercise or
answers file (``FILE:LINE:COLUMN: error: ...`` on one line), as every ``liansuo`` command does (docs/commands.md,
"Exit status").
"""

from __future__ import annotations

import argparse
import re
from collections.abc import Callable
from typing import Any

from liansuo.kit.exitcodes import Exit, bad_input, refuse
from liansuo.kit.fit import fit
from liansuo.kit.jsonreport import print_report
from liansuo.kit.source import StationError

Handler = Callable[[argparse.Namespace], int]
Add = Callable[[str, Handler, str], argparse.ArgumentParser]


def register(add: Add) -> None:
    sp = add("exercise", cmd_exercise, "list the bundled exercises, or run one headless with timed answers and "
                                       "score it")
    sub = sp.add_subparsers(dest="action", metavar="ACTION", required=True)
    ls = sub.add_parser("list", help="the bundled exercises: name, station, difficulty, title")
    ls.add_argument("--format", choices=("text", "json"), default="text", help="text (default) or json")
    run = sub.add_parser("run", help="run an exercise with a trainee's timed answers and print the score")
    run.add_argument("exercise", metavar="NAME|FILE", help="a bundled exercise by name, or an exercise file")
    run.add_argument("--answers", required=True, metavar="FILE",
                     help="the trainee's answers, one a line: the time since the start, then the command "
                          "('30s route X X3'); the model answers of the bundled exercises are in liansuo's source "
                          "repository, tests/data/exercises/NAME.answers (not installed, so that a trainee's "
                          "machine does not hold them)")
    run.add_argument("--seed", type=int, default=1, metavar="N", help="the seed of the pool's draw (default 1)")
    run.add_argument("--difficulty", type=int, choices=(1, 2, 3), metavar="D",
                     help="1 easy, 2 medium, 3 hard (default: the exercise's own)")
    run.add_argument("--report", metavar="DIR", help="write the report there as JSON, text and HTML")
    run.add_argument("--trainee", default="", metavar="NAME", help="the trainee's name, for the report")
    run.add_argument("--seat", default="", metavar="SEAT", help="the seat, for the report")
    run.add_argument("--format", choices=("text", "json"), default="text",
                     help="text (default: the text report) or json (the report in the JSON envelope)")


def cmd_exercise(args: argparse.Namespace) -> int:
    return cmd_list(args) if args.action == "list" else cmd_run(args)


def cmd_list(args: argparse.Namespace) -> int:
    from liansuo.classroom.exercise import bundled_exercises, parse_exercise

    rows: list[dict[str, Any]] = []
    for path in bundled_exercises():
        ex = parse_exercise(path)
        rows.append({"name": ex.name, "station": ex.station, "difficulty": ex.difficulty, "title": ex.title,
                     "time_limit_s": ex.time_limit})
    if args.format == "json":
        print_report("exercise", True, {"exercises": rows})
        return int(Exit.OK)
    width = max(len(r["name"]) for r in rows) if rows else 4
    print(f"{'name':<{width}}  {'station':<8} level  title")
    lead = " " * (width + 18)  # a long title goes on under its own column
    for r in rows:
        print(fit(f"{r['name']:<{width}}  {r['station']:<8} {r['difficulty']:<5}  {r['title']}", lead,
                  keep=4))
    return int(Exit.OK)


def _stem(name: str, trainee: str) -> str:
    who = re.sub(r"[^\w.-]+", "-", trainee).strip("-.") or "trainee"
    return f"{name}-{who}"


def cmd_run(args: argparse.Namespace) -> int:
    from liansuo.classroom.answers import parse_answers, play
    from liansuo.classroom.assessment import Assessment, ExerciseSetupError
    from liansuo.classroom.exercise import parse_exercise
    from liansuo.classroom.report import text_report, write_report
    from liansuo.simulation.sim import Simulation

    try:
        ex = parse_exercise(args.exercise)
    except StationError as exc:
        return bad_input(exc, "exercise")
    try:
        answers = parse_answers(args.answers)
    except StationError as exc:
        return bad_input(exc, "answers file")
    try:
        sim = Simulation(ex.station_ref())
    except StationError as exc:
        return bad_input(exc)
    try:
        assessment = Assessment(ex, sim, seed=args.seed, trainee=args.trainee, seat=args.seat,
                                difficulty=args.difficulty)
    except ExerciseSetupError as exc:
        return refuse("exercise", str(exc), Exit.BAD_INPUT)
    play(assessment, answers)
    report: dict[str, Any] = assessment.report()
    ok = bool(report["all_goals_met"])
    written = write_report(report, args.report, _stem(ex.name, args.trainee)) if args.report else []
    if args.format == "json":
        print_report("exercise", ok, report)
    else:
        print(text_report(report), end="")
        for path in written:
            print(f"wrote {path}")
    if not ok:
        met = sum(g["met_at"] is not None for g in report["goals"])
        return refuse("exercise", f"{met} of {len(report['goals'])} goals met ({report['ended']}); score "
                                  f"{report['score']['total']:g}", Exit.FAILED)
    return int(Exit.OK)


__all__ = ["register"]
