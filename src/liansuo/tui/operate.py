"""What the console's buttons do: presses on the diagram and the function buttons become command lines.

Route setting is by buttons, as on a real console (操作表示机): the start button (a signal's train button L or
shunting button D), optional variant buttons (变通按钮), then the end button. The console looks the buttons up in
the interlocking table only to know when the selection is complete; the interlocking itself judges the route, and a
refusal comes back with its reason.

Function buttons (总取消, 总人解, 区故解, 引导, 引导总锁, 总定位/总反位, 单锁/单解, 单封/解封, 重开) arm a mode;
the next press on the diagram names its target. Those a real console asks to confirm (总人解, 区故解, 引导,
引导总锁) come back with a question for the operator. The sealed buttons (铅封按钮: 总人解, 区故解, 引导, 引导总锁,
上电解锁) have counters of their accepted uses, kept by the simulation (``sim.sealed_uses()``) and shown beside them.
The power-up release (上电解锁) acts on the whole station: pressing it asks at once, with its counter.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Literal

from liansuo.tui.grid import Ref

if TYPE_CHECKING:
    from liansuo.tui.consolesim import ConsoleSim


@dataclass(frozen=True)
class Mode:
    name: str
    key: str
    zh: str
    en: str
    target: str  # signal, section, turnout, throat, or station (no target: the button acts at once)
    template: str
    confirm: bool = False
    sealed: bool = False  # a sealed button (铅封): each accepted use is counted by the simulation
    short: str = ""  # its label on a narrow function bar, when shorter than ``zh``

    @property
    def command(self) -> str:
        """The command it sends, which names its counter in ``sim.sealed_uses()``."""
        return self.template.split()[0]


MODES: dict[str, Mode] = {m.name: m for m in [
    Mode("cancel", "c", "总取消", "cancel", "signal", "cancel {}"),
    Mode("release", "r", "总人解", "manual release", "signal", "release {}", True, sealed=True),
    Mode("fault-release", "f", "区故解", "fault release", "section", "fault-release {}", True, sealed=True),
    Mode("guide", "g", "引导", "guide", "signal", "guide {}", True, sealed=True),
    Mode("guide-lock", "G", "引导总锁", "guide lock", "throat", "guide-lock {}", True, sealed=True),
    Mode("normal", "n", "总定位", "normal", "turnout", "throw {} normal"),
    Mode("reverse", "v", "总反位", "reverse", "turnout", "throw {} reverse"),
    Mode("lock", "l", "单锁", "lock", "turnout", "lock {}"),
    Mode("unlock", "u", "单解", "unlock", "turnout", "unlock {}"),
    Mode("block", "b", "单封", "block", "turnout", "block {}"),
    Mode("unblock", "B", "解封", "unblock", "turnout", "unblock {}"),
    Mode("reopen", "o", "重开", "reopen", "signal", "reopen {}"),
    Mode("power-up", "P", "上电解锁", "power-up release", "station", "power-up-release", True, sealed=True,
         short="上电"),
]}

MENUS: dict[str, tuple[str, ...]] = {
    "signal": ("cancel", "release", "reopen", "guide", "guide-lock"),
    "turnout": ("normal", "reverse", "lock", "unlock", "block", "unblock", "fault-release"),
    "section": ("fault-release",),
}


@dataclass
class PressOutcome:
    """What a press leads to: a command to send (perhaps after a question), a menu to open, or just a message."""

    command: str = ""
    confirm: str = ""
    menu: tuple[str, str] | None = None  # (element kind, id)
    message: str = ""


class ConsoleOperator:
    def __init__(self, sim: ConsoleSim) -> None:
        self.sim = sim
        self.mode: Mode | None = None
        self.start: tuple[str, str] | None = None  # (signal, train|shunt)
        self.via: list[str] = []

    # ---- state shown on the diagram ----
    def pressed(self) -> set[Ref]:
        out: set[Ref] = set()
        if self.start is not None:
            sig, kind = self.start
            out.add(Ref("button", sig, "train" if kind == "guide" else kind))  # a guide route starts at L
            out |= {self._button_ref(b) for b in self.via}
        return out

    def _button_ref(self, button: str) -> Ref:
        b = self.sim.station.buttons.get(button)
        return Ref("button", button, b.kind if b is not None else "train")

    def prompt(self) -> str:
        if self.mode is not None:
            return f"{self.mode.zh} {self.mode.en}: choose the {self.mode.target} (Esc cancels)"
        if self.start is not None:
            kind = {"train": "列车进路 train route", "shunt": "调车进路 shunting route",
                    "guide": "引导进路 guide route"}[self.start[1]]
            via = f" via {' '.join(self.via)}" if self.via else ""
            return f"{kind} from {self.start[0]}{via}: press the end button (Esc cancels)"
        return ""

    def operable(self, ref: Ref) -> bool:
        """Whether pressing ``ref`` now does something: with a route started only buttons, with a function armed only
        what it acts on. The keyboard cursor stops only on these."""
        if self.start is not None:
            return ref.kind == "button"
        if self.mode is None:
            return True
        if self.mode.target in ("signal", "throat"):
            return ref.kind == "signal" or (ref.kind == "button" and ref.id in self.sim.station.signals)
        if self.mode.target == "section":
            return ref.kind in ("section", "turnout")
        return ref.kind == "turnout"

    def reset(self) -> None:
        self.mode = None
        self.start = None
        self.via = []

    def arm(self, mode: str) -> PressOutcome:
        """A function button: pressing the armed one again disarms it."""
        self.start, self.via = None, []
        if self.mode is not None and self.mode.name == mode:
            self.mode = None
            return PressOutcome(message="")
        m = MODES[mode]
        if m.target == "station":  # nothing to choose: it asks at once
            self.mode = None
            count = ""
            if m.sealed:
                n = self.sim.sealed_uses().get(m.command, 0)
                count = f" (sealed button 铅封, used {n} time{'' if n == 1 else 's'})"
            return PressOutcome(command=m.template, confirm=f"{m.zh} ({m.en}){count}: {m.template}?")
        self.mode = m
        return PressOutcome(message=self.prompt())

    # ---- presses ----
    def press(self, ref: Ref) -> PressOutcome:
        if self.mode is not None:
            mode, self.mode = self.mode, None
            return self.apply(mode.name, ref)
        if ref.kind == "button":
            return self._route_button(ref)
        if self.start is not None:
            return PressOutcome(message="press an end button to finish the route, or Esc to drop it")
        if ref.kind in ("turnout", "section", "signal"):
            return PressOutcome(menu=(ref.kind, ref.id))
        if ref.kind == "fouling":
            return PressOutcome(message=f"fouling point {ref.id} (警冲标)")
        if ref.kind == "joint":
            dz = next((d for d in self.sim.station.dead_zones if d.joint == ref.id), None)
            extra = f": dead zone {dz.length:.2f} m (死区段)" if dz else ""
            return PressOutcome(message=f"insulated joint {ref.id}{extra}")
        if ref.kind == "platform":
            return PressOutcome(message=f"platform {ref.id}: screen doors {ref.sub}")
        if ref.kind == "block":
            return self._block_button(ref.id, ref.sub)
        if ref.kind == "line":
            return PressOutcome(message=f"block line {ref.id}: {self.sim.view.block_line(ref.id) or 'automatic block'}")
        return PressOutcome()

    def _block_button(self, link: str, button: str) -> PressOutcome:
        """A 64D block line's buttons: BSA (闭塞按钮) requests the block, or accepts the neighbour's request;
        FUA (复原按钮) restores it after the arrival, or cancels it before a departure; SGA (事故按钮, sealed)
        forces it back to normal after asking. The interlocking judges each and says why it refuses."""
        state = self.sim.view.block_line(link)
        if button == "BSA":
            return PressOutcome(command=f"block-line {link} {'accept' if state == 'asked' else 'request'}")
        if button == "FUA":
            return PressOutcome(command=f"block-line {link} {'restore' if state == 'arrived' else 'cancel'}")
        n = self.sim.sealed_uses().get("block-line accident", 0)
        command = f"block-line {link} accident"
        return PressOutcome(command=command, confirm=f"事故 SGA (accident, sealed button 铅封, used {n} time"
                                                f"{'' if n == 1 else 's'}): {command}?")

    def apply(self, mode_name: str, ref: Ref) -> PressOutcome:
        """A function applied to an element (from an armed function button or an element's menu)."""
        mode = MODES[mode_name]
        target, why = self._target(mode, ref)
        if not target:
            return PressOutcome(message=why)
        template = mode.template
        if mode.name == "guide" and self._guide_route_first(target):
            # no route set and the throat not under guide total lock: the guide route is chosen by its buttons
            self.start, self.via = (target, "guide"), []
            return PressOutcome(message=self.prompt())
        if mode.name == "guide-lock":
            turnouts = self.sim.table.throats.get(target, ())
            if turnouts and all(self.sim.turnout_mark(t) == "guide" for t in turnouts):
                template = "guide-unlock {}"
        command = template.format(target)
        question = f"{mode.zh} ({mode.en}): {command}?" if mode.confirm else ""
        return PressOutcome(command=command, confirm=question)

    def _guide_route_first(self, signal: str) -> bool:
        """引导 on a signal with no route set and its throat not under guide total lock: a guide route (引导进路锁闭)
        is selected by its end button, as a train route is."""
        if any(r.signal == signal and r.state != "released" for r in self.sim.view.routes()):
            return False
        turnouts = self.sim.table.throats.get(signal, ())
        locked = bool(turnouts) and all(self.sim.turnout_mark(t) == "guide" for t in turnouts)
        return not locked and any(r.kind == "train" and r.start == signal for r in self.sim.table.routes.values())

    def _target(self, mode: Mode, ref: Ref) -> tuple[str, str]:
        st = self.sim.station
        if mode.target in ("signal", "throat"):
            sig = ref.id if ref.kind == "signal" or (ref.kind == "button" and ref.id in st.signals) else ""
            if not sig:
                return "", f"{mode.zh}: choose a signal (its lamp, name or button)"
            if mode.target == "throat" and sig not in self.sim.table.throats:
                names = ", ".join(sorted(self.sim.table.throats))
                return "", f"{mode.zh}: throats are named by their home signals ({names})"
            return sig, ""
        if mode.target == "section":
            if ref.kind == "section":
                return ref.id, ""
            if ref.kind == "turnout":
                return st.turnout_section[ref.id], ""
            return "", f"{mode.zh}: choose a section (its band)"
        if ref.kind == "turnout":
            return ref.id, ""
        return "", f"{mode.zh}: choose a turnout (its number)"

    def _route_button(self, ref: Ref) -> PressOutcome:
        if self.start is None:
            if ref.sub not in ("train", "shunt"):
                return PressOutcome(message=f"{ref.id} is an end button: a route starts at a signal's train (L) or "
                                       "shunting (D) button")
            self.start, self.via = (ref.id, ref.sub), []
            return PressOutcome(message=self.prompt())
        start, kind_word = self.start
        kind: Literal["train", "shunt"] = "shunt" if kind_word == "shunt" else "train"
        if ref.id == start and ref.sub in (kind_word, "train" if kind_word == "guide" else kind_word):
            self.reset()
            return PressOutcome(message="route selection dropped")
        table = self.sim.table
        if table.by_buttons(kind, start, ref.id, tuple(self.via)) is None and any(
                r.kind == kind and r.start == start and tuple(r.via[: len(self.via)]) == tuple(self.via)
                and len(r.via) > len(self.via) and r.via[len(self.via)] == ref.id for r in table.routes.values()):
            self.via.append(ref.id)
            return PressOutcome(message=self.prompt())
        word = {"train": "route", "shunt": "shunt", "guide": "guide"}[kind_word]
        words = [word, start, *self.via, ref.id]
        self.reset()
        if word == "guide":  # a sealed button: counted, and asked before it is given
            n = self.sim.sealed_uses().get("guide", 0)
            return PressOutcome(command=" ".join(words), confirm=f"引导 (guide, sealed button 铅封, used {n} time"
                                                            f"{'' if n == 1 else 's'}): {' '.join(words)}?")
        return PressOutcome(command=" ".join(words))
