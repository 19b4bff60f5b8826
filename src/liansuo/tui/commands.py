"""The console's actions in the command palette (ctrl+p): each does what its key, button or command line does.

- every route of the interlocking table (``route X XI``, ``shunt D1 D7``, with its variant buttons), sent as the
  buttons send it; ``cancel S`` for every route set now;
- each function button armed (总取消 cancel ... 上电解锁), as its key arms it;
- zoom in, zoom out, fit; help; the exercise's briefing; acknowledge alarms, mute the bell; the clock where it is
  this operator's;
- the instructor's: the panel (F2), repairing each active fault, loading each exercise as the panel's Load does,
  and on a classroom's console the seats (F3).

What a command may do is asked of the console as for its key (``allowed``), so a trainee's palette has no clock
and no instructor's panel.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from dataclasses import dataclass
from functools import partial
from pathlib import Path
from typing import Any, Protocol

from textual.command import DiscoveryHit, Hit, Hits, Provider

from liansuo.kit.printable import printable
from liansuo.simulation import Result
from liansuo.tui.consolesim import ConsoleSim
from liansuo.tui.diagram import Diagram
from liansuo.tui.operate import MODES


@dataclass(frozen=True)
class PaletteCommand:
    title: str
    help: str
    run: Callable[[], Any]


class Console(Protocol):
    """What the palette asks of the console (:class:`~tui.app.ConsoleApp`, which hands its commands to the
    provider through ``palette_commands``)."""

    sim: ConsoleSim
    diagram: Diagram
    instructor: bool

    def submit_line(self, line: str) -> None: ...
    def send(self, line: str, source: str = "trainee") -> Result: ...
    def check_action(self, action: str, parameters: tuple[object, ...]) -> bool | None: ...
    def allowed(self, action: str) -> bool: ...
    def action_arm(self, mode: str) -> None: ...
    def action_help(self) -> None: ...
    def action_briefing(self) -> None: ...
    def action_acknowledge(self) -> None: ...
    def action_mute(self) -> None: ...
    def action_pause(self) -> None: ...
    def action_speed(self, step: int) -> None: ...
    async def action_instructor(self) -> None: ...
    def exercise_files(self) -> list[Path]: ...
    def load_chosen_exercise(self, path: str) -> None: ...


def console_commands(app: Console) -> list[PaletteCommand]:
    """What the palette offers on ``app`` now, in this order: the routes set (to cancel), the table's routes, the
    function buttons, the view, the exercise, the clock and the alarms, the instructor's."""
    return [*_cancels(app), *_routes(app), *_functions(app), *_view(app), *_instructor(app)]


def _cancels(app: Console) -> Iterator[PaletteCommand]:
    for r in app.sim.view.routes():
        line = f"cancel {r.signal}"
        yield PaletteCommand(printable(line), f"总取消: cancel route {printable(r.id)} ({r.state})",
                             partial(app.submit_line, line))


def _routes(app: Console) -> Iterator[PaletteCommand]:
    for r in app.sim.table.routes.values():
        word = "route" if r.kind == "train" else "shunt"
        line = " ".join([word, r.start, *r.via, r.end])
        kind = "列车进路 train route" if r.kind == "train" else "调车进路 shunting route"
        yield PaletteCommand(printable(line), f"{kind} {printable(r.id)}: as its buttons set it",
                             partial(app.submit_line, line))


def _functions(app: Console) -> Iterator[PaletteCommand]:
    for m in MODES.values():
        then = f"then the {m.target}" if m.target != "station" else "asks at once"
        yield PaletteCommand(f"{m.zh} {m.en}", f"function button (key {m.key}): {then}",
                             partial(app.action_arm, m.name))


def _view(app: Console) -> Iterator[PaletteCommand]:
    d = app.diagram
    yield PaletteCommand("zoom in", "the diagram wider (key +)", partial(d.action_zoom, 1))
    yield PaletteCommand("zoom out", "the diagram narrower (key -)", partial(d.action_zoom, -1))
    yield PaletteCommand("zoom to fit", "the diagram fitted to the window again (key 0)", d.action_fit)
    yield PaletteCommand("help", "keys, mouse and the colours of the diagram (key ?)", app.action_help)
    if app.check_action("briefing", ()):
        yield PaletteCommand("briefing", "the exercise's briefing and goals (key e)", app.action_briefing)
    yield PaletteCommand("acknowledge alarms", "every alarm acknowledged (key a)", app.action_acknowledge)
    yield PaletteCommand("mute / unmute the bell", "the alarm bell (key m)", app.action_mute)
    if app.allowed("pause"):
        yield PaletteCommand("pause / run", "the simulation's clock (space)", app.action_pause)
        yield PaletteCommand("faster", "the clock's speed (key >)", partial(app.action_speed, 1))
        yield PaletteCommand("slower", "the clock's speed (key <)", partial(app.action_speed, -1))


def _instructor(app: Console) -> Iterator[PaletteCommand]:
    if not app.allowed("instructor"):
        return
    yield PaletteCommand("instructor panel", "faults, field, trains and exercises (F2)", app.action_instructor)
    dashboard = getattr(app, "action_dashboard", None)  # a classroom's console has the seats
    if dashboard is not None and app.allowed("dashboard"):
        yield PaletteCommand("seats", "the classroom's dashboard of seats (F3)", dashboard)
    if not app.instructor:
        return
    for fault in app.sim.field.faults.values():
        line = " ".join(["repair", *fault.describe().split()[:2]])  # 'KIND TARGET params': the fault's kind and target
        yield PaletteCommand(printable(line), f"repair the fault: {printable(fault.describe())}",
                             partial(app.send, line, "instructor"))
    for path in app.exercise_files():
        yield PaletteCommand(f"exercise {printable(Path(path).stem)}", "load it, as the panel's Load does",
                             partial(app.load_chosen_exercise, str(path)))


class ConsoleCommands(Provider):
    """The console's commands for Textual's command palette."""

    def _commands(self) -> list[PaletteCommand]:
        commands: Callable[[], list[PaletteCommand]] | None = getattr(self.app, "palette_commands", None)
        return commands() if commands is not None else []

    async def discover(self) -> Hits:
        for c in self._commands():
            yield DiscoveryHit(c.title, c.run, help=c.help)

    async def search(self, query: str) -> Hits:
        matcher = self.matcher(query)
        for c in self._commands():
            score = matcher.match(c.title)
            if score > 0:
                yield Hit(score, matcher.highlight(c.title), c.run, help=c.help)
