"""Who may send which command: the trainee at an operator console (值班员) and the instructor (教员).

A trainee operates the station as its signaller does, with the CBI console's buttons: routes, releases, the guide,
turnouts, block lines, and writes findings in the equipment register (``diagnose``). Everything that stands for the
world around the console belongs to the instructor: faults and their repair, trains and vehicles, simulated
occupancy, the neighbour station's operator, the platform doors' own controls, the clock, the interlocking's
restart, and every question that would show what the console does not (``faults``, ``expect``). The classroom
server refuses the instructor's commands from a trainee's seat, and the console refuses them while the
instructor's panel is closed.
"""

from __future__ import annotations

from liansuo.interlocking.io import Result
from liansuo.simulation.language import command_name

# The commands of a CBI operator console (操作表示机), as the command language names them.
OPERATOR_COMMANDS = frozenset({
    "route", "shunt", "cancel", "release", "fault-release", "reopen", "guide", "guide-lock", "guide-unlock",
    "throw", "lock", "unlock", "block", "unblock", "block-line", "line-direction", "power-up-release", "axle-reset",
    "diagnose", "changeover",
})

TRAINEE = "trainee"
INSTRUCTOR = "instructor"


def command_word(line: str) -> str:
    """The command a line names, read by the command language's own parser (quotes, backslashes and comments as the
    language reads them: ``'run' 60s`` names ``run``); '' for an empty line, a comment, or a line the language
    refuses unread (an unclosed quote, a line too long), which then reaches no command."""
    return command_name(line)


def refusal(role: str, line: str) -> Result | None:
    """None when ``role`` may send ``line``; otherwise the refusal, in the signaller's terms."""
    if role == INSTRUCTOR:
        return None
    word = command_word(line)
    if not word or word in OPERATOR_COMMANDS:
        return None
    return Result.refuse(f"'{word}' is not an operator's command: it belongs to the instructor "
                         f"(an operator console has: {', '.join(sorted(OPERATOR_COMMANDS))})")

# The world's events a trainee's console shows: alarms, power and the change-over of control (the interlocking's own
# events, which follow from relay states, are all shown). Faults injected or repaired and trains placed are the
# instructor's secret.
TRAINEE_WORLD_EVENTS = frozenset({"alarm", "power", "control"})
