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

from difflib import get_close_matches

from liansuo.interlocking.io import Result
from liansuo.simulation.language import command_name, parse_line
from liansuo.simulation.sim import LANGUAGE

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


def is_typo(line: str) -> bool:
    """Whether ``line`` names no command at all (an unknown word, or a line the language cannot read): a slip of the
    keyboard, which an exercise never counts as a refused command."""
    try:
        words = parse_line(line)
    except ValueError:
        return True
    return bool(words) and words[0] not in LANGUAGE


def typo(role: str, line: str) -> Result | None:
    """The refusal of a line that names no command, with the closest commands ``role`` has; None for a command."""
    if not is_typo(line):
        return None
    word = command_word(line)
    if not word:
        return None  # unreadable: the language says why
    mine = sorted(OPERATOR_COMMANDS) if role != INSTRUCTOR else sorted(LANGUAGE)
    close = get_close_matches(word, mine, n=2, cutoff=0.6)
    hint = f"; did you mean {' or '.join(repr(c) for c in close)}?" if close else f"; commands: {', '.join(mine)}"
    return Result.refuse(f"unknown command '{word}'{hint} (a typo: not counted)")


def refusal(role: str, line: str) -> Result | None:
    """None when ``role`` may send ``line``; otherwise the refusal, in the signaller's terms: a typo is told as one
    (:func:`typo`), an instructor's command from a trainee as the instructor's."""
    if (no := typo(role, line)) is not None:
        return no
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
