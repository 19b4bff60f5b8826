"""The console's panels: status line, alarms, event log, function buttons, answer line and command bar.

Text that may come from a file (ids, names, messages quoting them) reaches the screen through these panels with its
control characters written out (:func:`~stations.printable.printable`) and never as markup.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, ClassVar

from rich.text import Text
from textual import events
from textual.binding import Binding, BindingType
from textual.message import Message
from textual.suggester import Suggester
from textual.widget import Widget
from textual.widgets import Input, RichLog, Static

from liansuo.classroom.snapshot import EventCursor
from liansuo.kit.printable import printable
from liansuo.tui.completion import candidates, complete, example_route
from liansuo.tui.grid import Ref
from liansuo.tui.guard import Guarded
from liansuo.tui.operate import MODES

if TYPE_CHECKING:
    from liansuo.tui.consolesim import ConsoleSim


def waiting_text(sim: ConsoleSim, focus: Ref | None) -> str:
    """Why a signal stays red over its locked route ('XI red: block line SL has not been accepted ...'): the signal
    under the cursor (its lamp, name or button) if its route waits, else the route set last that waits; '' if none."""
    view = sim.view
    signals = [r.signal for r in reversed(view.routes())]
    if focus is not None and focus.kind in ("signal", "button") and focus.id in sim.station.signals:
        signals.insert(0, focus.id)
    for signal in signals:
        why = view.waiting(signal)
        if why:
            return printable(f"{signal} red: {why}")
    return ""


def clock_text(t: float) -> str:
    h, rest = divmod(t, 3600)
    m, s = divmod(rest, 60)
    return f"{int(h):02d}:{int(m):02d}:{s:04.1f}"


def sender(source: str) -> str:
    """How the event log names who sent a command."""
    return {"trainee": "trainee>", "instructor": "instr.>", "exercise": "lesson>"}.get(source, f"{source}>")


class StatusBar(Guarded, Static):
    DEFAULT_CSS = """
    StatusBar { height: 1; background: #1d3557; color: #f1faee; }
    """


@dataclass
class AlarmLine:
    key: str
    t: float | None  # None: the world keeps no time for its alarms
    text: str
    acknowledged: bool


def read_alarms(sim: ConsoleSim, acknowledged: set[str]) -> list[AlarmLine]:
    """Active alarms of the interlocking and of the world (trains), newest first."""
    out = [AlarmLine(a.key, a.t, a.text, a.key in acknowledged) for a in sim.alarm_views()]
    out.sort(key=lambda a: -1.0 if a.t is None else a.t, reverse=True)
    return out


class AlarmBell:
    """The terminal bell on a new alarm: due once for each alarm that appears unacknowledged (not at every redraw);
    muted, never."""

    def __init__(self, muted: bool = False) -> None:
        self.muted = muted
        self._unacknowledged: set[str] = set()

    def due(self, alarms: Sequence[AlarmLine]) -> bool:
        now = {a.key for a in alarms if not a.acknowledged}
        new = now - self._unacknowledged
        self._unacknowledged = now
        return bool(new) and not self.muted


class AlarmPanel(Guarded, Widget):
    """Active alarms; an unacknowledged one is red and blinks. Click one (or press ``a``) to acknowledge."""

    DEFAULT_CSS = """
    AlarmPanel { border-top: solid #c03030; padding: 0 0; overflow-y: auto; }
    """

    class Acknowledge(Message):
        def __init__(self, key: str | None) -> None:
            super().__init__()
            self.key = key

    def __init__(self, *, id: str | None = None) -> None:
        super().__init__(id=id)
        self.lines: list[AlarmLine] = []
        self.flash = True
        self.border_title = "报警 Alarms (a: acknowledge)"

    def show(self, lines: list[AlarmLine], flash: bool) -> None:
        if lines != self.lines or (flash != self.flash and any(not a.acknowledged for a in lines)):
            self.lines = lines
            self.flash = flash
            self.refresh()

    def render(self) -> Text:
        if not self.lines:
            return Text("no alarms", style="#6a6a6a")
        out = Text()
        for i, a in enumerate(self.lines):
            if i:
                out.append("\n")
            when = f"{a.t:7.1f} " if a.t is not None else "        "
            text = printable(a.text)
            if a.acknowledged:
                out.append(when + text, style="#c08080")
            else:
                out.append(when + text, style="bold #ff4040" if self.flash else "bold #ffb0b0")
        return out

    def on_click(self, event: events.Click) -> None:
        i = event.y + int(self.scroll_y)
        if 0 <= i < len(self.lines):
            self.post_message(self.Acknowledge(self.lines[i].key))


class EventLog(Guarded, RichLog):
    """Events of the interlocking and the world, and every command sent from the console with its answer."""

    DEFAULT_CSS = """
    EventLog { border-top: solid #3a6ea5; background: #0c0f12; scrollbar-size: 1 1; }
    """

    def __init__(self, *, id: str | None = None) -> None:
        super().__init__(id=id, max_lines=2000, wrap=False, markup=False, highlight=False)
        self.border_title = "事件 Events"
        self.lines_text: list[str] = []
        self.line_styles: list[str] = []  # each line's style, beside lines_text

    def add(self, text: str, style: str = "") -> None:
        text = printable(text)
        self.lines_text.append(text)
        self.line_styles.append(style)
        if len(self.lines_text) > 4000:
            del self.lines_text[:2000], self.line_styles[:2000]
        self.write(Text(text, style=style))

    def entries(self) -> list[tuple[str, str]]:
        """Every line kept, with its style: what :meth:`show` writes back."""
        return list(zip(self.lines_text, self.line_styles, strict=True))

    def show(self, entries: list[tuple[str, str]]) -> None:
        """These lines instead of those shown (the instructor's console shows each seat's own log)."""
        self.clear()
        self.lines_text, self.line_styles = [], []
        for text, style in entries[-self.max_lines if self.max_lines else 0:]:
            self.add(text, style)


class EventReader:
    """Reads new events from the interlocking's and the world's event logs, in time order, as ``role`` may see
    them (a trainee's console leaves out the instructor's faults and trains: :mod:`simulation.roles`)."""

    def __init__(self) -> None:
        self._cursor = EventCursor()

    def reset(self) -> None:
        self._cursor = EventCursor()

    def new(self, sim: ConsoleSim, role: str) -> list[tuple[float, str, str]]:
        return [(e.t, e.kind, e.text) for e in self._cursor.fresh_from(sim.view.events(), sim.events, role)]


class FunctionBar(Guarded, Widget):
    """The function buttons of the console (总取消, 总人解, ...): click one, then the element it acts on."""

    DEFAULT_CSS = """
    FunctionBar { height: 1; background: #22262b; }
    """

    class Selected(Message):
        def __init__(self, mode: str) -> None:
            super().__init__()
            self.mode = mode

    def __init__(self, *, id: str | None = None) -> None:
        super().__init__(id=id)
        self.armed: str | None = None
        self.spans: list[tuple[int, int, str]] = []
        self.counts: dict[str, int] = {}  # sealed button's command -> its accepted uses (铅封计数)

    def set_counts(self, uses: dict[str, int]) -> None:
        """The sealed buttons' counters, from ``sim.sealed_uses()``: shown beside each used one (总人解 3)."""
        if uses != self.counts:
            self.counts = dict(uses)
            self.refresh()

    def set_armed(self, mode: str | None) -> None:
        if mode != self.armed:
            self.armed = mode
            self.refresh()

    def _count(self, name: str) -> str:
        m = MODES[name]
        n = self.counts.get(m.command, 0) if m.sealed else 0
        return f" {n}" if n else ""

    def _labels(self, width: int) -> list[tuple[str, str]]:
        long = [(m.name, f"{m.key}:{m.zh}{self._count(m.name)}") for m in MODES.values()]
        if sum(len(t) + sum(1 for c in t if ord(c) > 0x2E80) + 1 for _, t in long) <= width:
            return long
        return [(m.name, f"{m.short or m.zh}{self._count(m.name)}") for m in MODES.values()]

    def render(self) -> Text:
        out = Text()
        self.spans = []
        x = 0
        for name, label in self._labels(self.size.width):
            out.append(" ")
            x += 1
            w = sum(2 if ord(c) > 0x2E80 else 1 for c in label)
            style = "bold black on #ffd700" if name == self.armed else "#e0e0e0 on #3a4048"
            out.append(label, style=style)
            self.spans.append((x, x + w, name))
            x += w
        return out

    def offset_of(self, mode: str) -> tuple[int, int]:
        if not self.spans:
            self.render()
        for x0, _x1, name in self.spans:
            if name == mode:
                return x0, 0
        raise KeyError(mode)

    def on_click(self, event: events.Click) -> None:
        for x0, x1, name in self.spans:
            if x0 <= event.x < x1:
                self.post_message(self.Selected(name))


class MessageLine(Guarded, Static):
    DEFAULT_CSS = """
    MessageLine { height: 1; background: #15181c; }
    """

    said = ""  # the text said last, as given

    def say(self, text: str, ok: bool | None = None) -> None:
        self.said = text
        style = "#e0e0e0" if ok is None else "bold #40e070" if ok else "bold #ff5050"
        mark = "" if ok is None else "✓ " if ok else "✗ "
        self.update(Text(mark + printable(text), style=style, no_wrap=True, overflow="ellipsis"))


class CommandSuggester(Suggester):
    def __init__(self, sim_of: Callable[[], ConsoleSim]) -> None:
        super().__init__(use_cache=False, case_sensitive=True)
        self._sim_of = sim_of

    async def get_suggestion(self, value: str) -> str | None:
        try:
            hits = candidates(self._sim_of(), value)
        except Exception:  # a suggestion must never break typing
            return None
        head, _, partial = value.rpartition(" ")
        if not hits or not partial:
            return None
        return (f"{head} " if head else "") + hits[0]


class CommandBar(Guarded, Input):
    """The command line (focus it with ``:``): any command of the command language, Tab completes ids, Up/Down
    walk the history, Enter sends, Esc goes back to the diagram."""

    DEFAULT_CSS = """
    CommandBar { height: 1; border: none; padding: 0 1; background: #0b0d10; }
    CommandBar:focus { border: none; background: #141a22; }
    """

    BINDINGS: ClassVar[list[BindingType]] = [
        Binding("tab", "complete", "complete", show=False, priority=True),
        Binding("up", "history(-1)", "history", show=False),
        Binding("down", "history(1)", "history", show=False),
    ]

    class Hint(Message):
        def __init__(self, text: str) -> None:
            super().__init__()
            self.text = text

    def __init__(self, sim_of: Callable[[], ConsoleSim], *, id: str | None = None) -> None:
        example = printable(example_route(sim_of()))  # in the station's own ids
        super().__init__(placeholder=f": command (Tab completes, ↑↓ history), e.g. {example}", id=id,
                         suggester=CommandSuggester(sim_of))
        self._sim_of = sim_of
        self.history: list[str] = []
        self._pos = 0

    def remember(self, line: str) -> None:
        if line and (not self.history or self.history[-1] != line):
            self.history.append(line)
        self._pos = len(self.history)

    def action_complete(self) -> None:
        if not self.has_focus:
            self.screen.focus_next()
            return
        try:
            text, hits = complete(self._sim_of(), self.value)
        except Exception as exc:  # never let completion raise into the screen
            self.post_message(self.Hint(f"completion failed: {exc}"))
            return
        self.value = text
        self.cursor_position = len(text)
        if len(hits) > 1:
            self.post_message(self.Hint("  ".join(hits[:40]) + (" ..." if len(hits) > 40 else "")))
        elif not hits:
            self.post_message(self.Hint("no completion"))

    def action_history(self, step: int) -> None:
        if not self.history:
            return
        self._pos = max(0, min(len(self.history), self._pos + step))
        self.value = self.history[self._pos] if self._pos < len(self.history) else ""
        self.cursor_position = len(self.value)
