"""A trainee's timed answers, for running an exercise headless (``liansuo exercise run --answers FILE``).

One command a line, after the simulated time since the exercise began at which the trainee sends it::

    # receive the down train on 3G
    0s    route X X3
    20s   diagnose broken-rail IG
    1min  cancel X

The time is a duration (``30s``, ``2min``, ``1.5s``, plain seconds); times never go back. ``#`` starts a comment.
Each command goes through the seat's role check, as at a trainee's console: an instructor's command is refused.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from liansuo.classroom.assessment import Assessment
from liansuo.classroom.roles import TRAINEE, refusal
from liansuo.kit.source import Diagnostic, StationError, read_text
from liansuo.simulation.timeparse import parse_duration


@dataclass(frozen=True)
class Answer:
    at: float  # seconds since the exercise began
    line: str
    lineno: int


def parse_answers(path: str | Path) -> list[Answer]:
    """The answers of a file; :class:`StationError` (one diagnostic, one line) at the first bad line."""
    name = str(path)
    text = read_text(Path(path), "give the path of a file of timed answers ('30s route X X3' a line)")
    out: list[Answer] = []
    for n, raw in enumerate(text.splitlines(), 1):
        body = raw.split("#", 1)[0]
        if not body.strip():
            continue
        column = len(body) - len(body.lstrip()) + 1
        when, _, line = body.strip().partition(" ")
        try:
            at = parse_duration(when)
        except ValueError:
            raise StationError([Diagnostic(name, n, column, f"'{when}' is not a time: write the time since the "
                                           "exercise began, then the command, e.g. '30s route X X3'")]) from None
        if not line.strip():
            raise StationError([Diagnostic(name, n, column, f"no command after '{when}': write e.g. "
                                           f"'{when} route X X3'")])
        if out and at < out[-1].at:
            raise StationError([Diagnostic(name, n, column, f"{when} is before the previous answer's time "
                                           f"({out[-1].at:g} s): write the answers in time order")])
        out.append(Answer(at, line.strip(), n))
    return out


def send(assessment: Assessment, line: str) -> None:
    """One trainee command: the role check, the simulation, the record."""
    refused = refusal(TRAINEE, line)
    result = refused if refused is not None else assessment.sim.command(line)
    assessment.record(line, result)


def play(assessment: Assessment, answers: list[Answer]) -> None:
    """Step the clock through the answers, sending each at its time, then on until the exercise finishes (every
    goal met and every finding diagnosed, or the time limit)."""
    sim = assessment.sim
    for answer in answers:
        while not assessment.finished and sim.t - assessment.start < answer.at - 1e-9:
            sim.step()
            assessment.tick()
        if assessment.finished:
            return
        send(assessment, answer.line)
    while not assessment.finished:
        sim.step()
        assessment.tick()
