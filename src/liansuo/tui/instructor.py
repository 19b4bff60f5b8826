"""The instructor's panel (教员台): faults, occupancy, trains and exercises, all sent as commands.

Everything here becomes a line of the command language sent through the console (so it is logged, recorded and
refused with a reason like any other command): ``fault KIND TARGET [key=value ...]`` / ``repair KIND TARGET``,
``occupy`` / ``vacate``, ``train NAME at SECTION ...``, ``drive NAME SPEED``, ``stop NAME``, ``auto NAME``.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING

from textual.app import ComposeResult
from textual.containers import Horizontal, VerticalScroll
from textual.message import Message
from textual.widgets import Button, Input, Label, Select, Static

from liansuo.circuits.faults import KINDS
from liansuo.tui.completion import fault_targets
from liansuo.tui.grid import Ref
from liansuo.tui.guard import Guarded
from liansuo.tui.plain import plain

if TYPE_CHECKING:
    from liansuo.tui.consolesim import ConsoleSim


class InstructorPanel(Guarded, VerticalScroll):
    DEFAULT_CSS = """
    InstructorPanel { width: 46; dock: right; background: #1a1520; border-left: solid #a070d0; padding: 0 1;
        display: none; scrollbar-size: 1 1; }
    InstructorPanel.-shown { display: block; }
    InstructorPanel Label.title { color: #d0a0ff; text-style: bold; margin: 1 0 0 0; }
    InstructorPanel Select { width: 100%; margin: 0; }
    InstructorPanel Input { width: 100%; }
    InstructorPanel Horizontal { height: 1; width: 100%; }
    InstructorPanel Button { margin: 0 1 0 0; min-width: 6; }
    InstructorPanel Static { color: #c8c8c8; }
    """

    class Send(Message):
        """A command the instructor's panel wants sent."""

        def __init__(self, line: str) -> None:
            super().__init__()
            self.line = line

    class LoadExercise(Message):
        def __init__(self, path: str) -> None:
            super().__init__()
            self.path = path

    def __init__(self, sim_of: Callable[[], ConsoleSim], exercises: list[Path], *, id: str | None = None) -> None:
        super().__init__(id=id)
        self._sim_of = sim_of
        self.exercises = exercises
        self.picking = False
        # the panels the console writes to from outside (its clock, the recorder, an exercise): made here, so they
        # take their text whether or not the panel has finished composing
        self.fault_help = Static("", id="fault-help")
        self.fault_list = Static("no active faults", id="fault-list")
        self.ex_goal = Static("", id="ex-goal")
        self.rec_status = Static("", id="rec-status")

    @property
    def sim(self) -> ConsoleSim:
        return self._sim_of()

    def compose(self) -> ComposeResult:
        st = self.sim.station
        yield Label("教员台 Instructor", classes="title")
        yield Label("故障 Faults", classes="title")
        yield Select([(f"{k.name}", k.name) for k in KINDS.values()], prompt="fault kind", id="fault-kind",
                     compact=True, allow_blank=False, value="broken-rail")
        yield Select(self._target_options("broken-rail"), prompt="target", id="fault-target", compact=True)
        yield Input(placeholder="parameters key=value ...", id="fault-params", compact=True)
        with Horizontal():
            yield Button("注入 Inject", id="fault-inject", compact=True, variant="error")
            yield Button("修复 Repair", id="fault-repair", compact=True, variant="success")
            yield Button("Pick", id="fault-pick", compact=True)
        yield self.fault_help
        yield self.fault_list
        yield Label("现场 Field (switch K)", classes="title")
        yield Select([(s, s) for s in st.sections], prompt="section", id="field-section", compact=True)
        with Horizontal():
            yield Button("占用 Occupy", id="field-occupy", compact=True)
            yield Button("出清 Vacate", id="field-vacate", compact=True)
        yield Label("列车 Trains", classes="title")
        yield Input(value="T1", placeholder="train name", id="train-name", compact=True)
        yield Select([(s, s) for s in st.sections], prompt="at section", id="train-section", compact=True)
        yield Input(placeholder="mode=signal length=300 dir=down ...", id="train-params", compact=True)
        with Horizontal():
            yield Button("Place", id="train-place", compact=True)
            yield Button("Remove", id="train-remove", compact=True)
            yield Button("Auto", id="train-auto", compact=True)
        yield Input(placeholder="speed km/h", id="train-speed", compact=True)
        with Horizontal():
            yield Button("Drive", id="train-drive", compact=True)
            yield Button("Stop", id="train-stop", compact=True)
        yield Label("练习 Exercise", classes="title")
        yield Select([(plain(p.stem), str(p)) for p in self.exercises], prompt="exercise", id="ex-file",
                     compact=True)
        yield Button("Load", id="ex-load", compact=True)
        yield self.ex_goal
        yield self.rec_status

    def on_mount(self) -> None:
        self._describe_kind("broken-rail")

    def _target_options(self, kind: str) -> list[tuple[str, str]]:
        return [(t, t) for t in fault_targets(self.sim, kind)]

    def _describe_kind(self, kind: str) -> None:
        k = KINDS.get(kind)
        if k is None:
            return
        params = ", ".join(f"{p}={v:g}" if isinstance(v, float) else f"{p}={v or '?'}" for p, v in k.params.items())
        text = f"{k.summary}" + (f"\nparameters: {params}" if params else "")
        self.fault_help.update(plain(text))

    # ---- events ----
    def on_select_changed(self, event: Select.Changed) -> None:
        if event.select.id == "fault-kind" and isinstance(event.value, str):
            target = self.query_one("#fault-target", Select)
            target.set_options(self._target_options(event.value))
            self._describe_kind(event.value)
            self.query_one("#fault-params", Input).value = ""
        elif event.select.id == "fault-target" and isinstance(event.value, str):
            self._default_params()

    def _default_params(self) -> None:
        kind = self.query_one("#fault-kind", Select).selection
        target = self.query_one("#fault-target", Select).selection
        params = self.query_one("#fault-params", Input)
        if isinstance(kind, str) and isinstance(target, str):
            params.value = default_params(self.sim, kind, target, params.value)

    def on_button_pressed(self, event: Button.Pressed) -> None:
        bid = event.button.id or ""
        event.stop()
        if bid in ("fault-inject", "fault-repair"):
            kind = self.query_one("#fault-kind", Select).selection
            target = self.query_one("#fault-target", Select).selection
            if not isinstance(kind, str) or not isinstance(target, str):
                self.post_message(self.Send("fault"))  # refused with the usage and the kinds
                return
            params = self.query_one("#fault-params", Input).value
            line = fault_line(self.sim, kind, target, params) if bid == "fault-inject" else f"repair {kind} {target}"
            self.post_message(self.Send(line))
        elif bid == "fault-pick":
            self.picking = True
            self.app.notify("click an element on the diagram to make it the fault's target", timeout=3)
        elif bid in ("field-occupy", "field-vacate"):
            sec = self.query_one("#field-section", Select).selection
            verb = "occupy" if bid == "field-occupy" else "vacate"
            self.post_message(self.Send(f"{verb} {sec}" if isinstance(sec, str) else verb))
        elif bid.startswith("train-"):
            self._train(bid.removeprefix("train-"))
        elif bid == "ex-load":
            path = self.query_one("#ex-file", Select).selection
            if isinstance(path, str):
                self.post_message(self.LoadExercise(path))

    def _train(self, what: str) -> None:
        name = self.query_one("#train-name", Input).value.strip() or "T1"
        if what == "place":
            sec = self.query_one("#train-section", Select).selection
            params = self.query_one("#train-params", Input).value.strip()
            line = f"train {name} at {sec if isinstance(sec, str) else '?'} {params}".strip()
        elif what == "remove":
            line = f"train {name} remove"
        elif what == "drive":
            line = f"drive {name} {self.query_one('#train-speed', Input).value.strip() or '0'}"
        else:
            line = f"{what} {name}"
        self.post_message(self.Send(line))

    def pick(self, ref: Ref) -> str:
        """A diagram press while picking: make the element the fault's target (and the field's section)."""
        self.picking = False
        target = ref.sub if ref.kind == "platform" else ref.id
        if ref.kind == "section":
            self.query_one("#field-section", Select).value = ref.id
            self.query_one("#train-section", Select).value = ref.id
        sel = self.query_one("#fault-target", Select)
        options = {v for _, v in self._target_options(str(self.query_one("#fault-kind", Select).selection))}
        if ref.kind == "platform" and ref.id in options:
            target = ref.id
        if target in options:
            sel.value = target
            return f"fault target: {target}"
        kinds = [k for k in KINDS if target in fault_targets(self.sim, k)]
        if kinds:
            self.query_one("#fault-kind", Select).value = kinds[0]
            sel.set_options(self._target_options(kinds[0]))
            sel.value = target
            return f"fault target: {target} (kind {kinds[0]}; other kinds: {', '.join(kinds[1:]) or 'none'})"
        return f"no fault applies to {ref.kind} {ref.id}"

    def show_faults(self, sim: ConsoleSim) -> None:
        active = [f.describe() for f in sim.field.faults.values()]
        text = "active: " + "; ".join(active) if active else "no active faults"
        shown = plain(text)
        if str(self.fault_list.content) != str(shown):
            self.fault_list.update(shown)

    def show_goal(self, text: str) -> None:
        self.ex_goal.update(plain(text))

    def show_recording(self, text: str) -> None:
        self.rec_status.update(plain(text))


def default_params(sim: ConsoleSim, kind: str, target: str, params: str = "") -> str:
    """Parameters a fault needs that have no default: the lamp of a filament fault (the red one, the lamp of the stop
    aspect, if there is)."""
    params = params.strip()
    if kind == "filament" and target in sim.station.signals and "lamp=" not in params:
        lamps = [lamp.value for lamp in sim.station.signals[target].lamps]
        red = sim.rules.aspects.stop_lamp
        params = (params + f" lamp={red if red in lamps else lamps[0]}").strip()
    return params


def fault_line(sim: ConsoleSim, kind: str, target: str, params: str = "") -> str:
    """The command the Inject button sends."""
    return f"fault {kind} {target} {default_params(sim, kind, target, params)}".strip()

