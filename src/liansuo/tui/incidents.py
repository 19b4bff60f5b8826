"""The unexpected errors of a console session (see :mod:`tui.guard` for how they are caught): shown in the alarm panel
at once, written to the log file (``--log``, :mod:`tui.logfile`) as they happen, and every traceback printed on stderr
when the console closes, with exit status 1.
"""

from __future__ import annotations

import traceback
from dataclasses import dataclass

from liansuo.kit.printable import printable, printable_block
from liansuo.tui.logfile import LOGGER
from liansuo.tui.panels import AlarmLine

# How many different incidents a session keeps (the same error again only counts up): enough for any report, and a
# handler failing on every redraw cannot grow the list without end.
MAX_INCIDENTS = 50
# The start of an incident's alarm key, so the alarm panel can tell incidents from the interlocking's alarms.
KEY_PREFIX = "console-error:"
# An error's text beyond this many characters is cut on the alarm line (the whole of it is in the report).
SUMMARY_MAX = 160


@dataclass
class Incident:
    """One unexpected error: where it happened, when (simulated time), what, and how often."""

    where: str
    t: float | None
    error: BaseException
    trace: str
    count: int = 1
    acknowledged: bool = False

    @property
    def summary(self) -> str:
        """``ZeroDivisionError: division by zero``, control characters written out, cut to one screen line."""
        text = printable(f"{type(self.error).__name__}: {self.error}")
        return text if len(text) <= SUMMARY_MAX else text[: SUMMARY_MAX - 1] + "…"


class Incidents:
    """The unexpected errors of one session, in the order they first happened."""

    def __init__(self) -> None:
        self.items: list[Incident] = []
        self.crashed = False  # an error Textual could not recover from ended the console
        self.dropped = 0  # incidents beyond MAX_INCIDENTS, counted but not kept

    def __bool__(self) -> bool:
        return bool(self.items) or self.dropped > 0

    def record(self, error: BaseException, where: str, t: float | None = None) -> Incident:
        trace = "".join(traceback.format_exception(error))
        for known in self.items:
            if known.where == where and known.trace == trace:
                known.count += 1
                known.acknowledged = False
                if known.count in (2, 10, 100, 1000, 10000):  # a handler failing on every redraw fills no disk
                    LOGGER.error("console error in %s again (%d times)", where, known.count)
                return known
        incident = Incident(where, t, error, trace)
        LOGGER.error("console error%s in %s:\n%s", "" if t is None else f" at t={t:g} s", where, trace.rstrip("\n"))
        if len(self.items) < MAX_INCIDENTS:
            self.items.append(incident)
        else:
            self.dropped += 1
        return incident

    def acknowledge(self, key: str | None = None) -> None:
        """Acknowledge one incident by its alarm key, or all of them."""
        for i, incident in enumerate(self.items):
            if key is None or key == f"{KEY_PREFIX}{i}":
                incident.acknowledged = True

    def alarms(self) -> list[AlarmLine]:
        """The incidents not yet acknowledged, as lines of the alarm panel (an acknowledged one leaves the panel: it
        stays in the report printed when the console closes)."""
        out = []
        for i, incident in enumerate(self.items):
            if incident.acknowledged:
                continue
            times = f" ({incident.count} times)" if incident.count > 1 else ""
            out.append(AlarmLine(f"{KEY_PREFIX}{i}", incident.t,
                                 f"console error in {incident.where}: {incident.summary}{times}; the console carries "
                                 "on, the traceback is printed when it closes", False))
        return out

    def report(self, command: str) -> str:
        """What ``liansuo COMMAND`` prints on stderr after the console closed: every traceback, then one line that
        says what happened and what to do."""
        lines = []
        for i, incident in enumerate(self.items, 1):
            when = f" at t={incident.t:g} s" if incident.t is not None else ""
            times = f", {incident.count} times" if incident.count > 1 else ""
            lines.append(f"--- console error {i}{when} in {incident.where}{times}:")
            lines.append(printable_block(incident.trace.rstrip("\n")))
        if self.dropped:
            lines.append(f"--- and {self.dropped} more errors, not kept")
        n = len(self.items) + self.dropped
        what = "stopped on an internal error" if self.crashed else \
            f"had {n} internal error{'s' if n != 1 else ''} and carried on"
        lines.append(f"liansuo {command}: the console {what} (traceback{'s' if n != 1 else ''} above); please report "
                     "it with the station and what you did")
        return "\n".join(lines)
