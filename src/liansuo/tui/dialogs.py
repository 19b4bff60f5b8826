"""Modal dialogs: the confirmation a real console asks for, element menus, the instructor password, help, and the
question before the console closes.

A dialog answers once: an answer that arrives after it has closed (a second click of a double click, a key pressed
twice in one burst of input) is dropped, so it can neither close the dialog opened by the first answer nor the
console's own screen. Text in a dialog that comes from a file (ids, names) is shown as written, never as markup.
"""

from __future__ import annotations

from typing import ClassVar, TypeVar

from rich.style import Style
from rich.text import Text
from textual.app import ComposeResult
from textual.await_complete import AwaitComplete
from textual.binding import Binding, BindingType
from textual.containers import Grid, Vertical, VerticalScroll
from textual.geometry import Offset, Region, Size
from textual.screen import ModalScreen
from textual.widgets import Button, Input, Label, Static

from liansuo.kit.printable import printable
from liansuo.tui.guard import Guarded, on_top
from liansuo.tui.operate import MENUS, MODES
from liansuo.tui.paint import (
    BAND_COLOUR,
    LAMP_COLOUR,
    S_BUTTON,
    S_COUNT,
    S_DEAD,
    S_DOOR,
    S_JOINT,
    S_LOST_ON,
    S_MARK,
    S_NAME,
    S_NAME_ALARM,
    S_PRESSED,
    S_TRAIN,
    S_TURNOUT,
)
from liansuo.tui.plain import plain

DIALOG_CSS = """
{name} {{ align: center middle; background: rgba(0, 0, 0, 0.55); }}
{name} > Vertical {{ width: 60; max-width: 100%; height: auto; padding: 0 1; border: round #ffd700;
    background: #1b1f24; }}
{name} Label {{ width: 100%; margin: 0 0 1 0; }}
{name} Grid {{ grid-size: 2; grid-columns: 1fr 1fr; grid-gutter: 0 1; height: auto; width: 100%; }}
{name} Button {{ width: 100%; margin: 0; }}
"""

# A menu or a question about an element stands beside it, over a diagram still drawn in full (no dimming).
BESIDE_CSS = """
{name} {{ align: left top; background: transparent; }}
{name} > Vertical {{ width: 44; }}
"""
GAP = (3, 1)  # columns and lines kept clear between the element and a dialog beside it


def place(box: Size, anchor: Region, screen: Size) -> Offset:
    """Where a dialog of size ``box`` goes beside ``anchor`` (an element on the screen): below it, above it, right of
    it or left of it, the first that fits in ``screen`` without covering the element and the ``GAP`` around it;
    kept inside the screen."""
    gx, gy = GAP
    clear = anchor.grow((gy, gx, gy, gx))
    left = anchor.x - box.width // 3
    middle = anchor.y - box.height // 2
    candidates = [Offset(left, clear.bottom), Offset(left, clear.y - box.height), Offset(clear.right, middle),
                  Offset(clear.x - box.width, middle)]
    area = Region(0, 0, screen.width, screen.height)
    for at in candidates:
        region = Region(at.x, at.y, box.width, box.height)
        inside = region.translate_inside(area, True, True)
        if area.contains_region(inside) and not inside.overlaps(clear):
            return inside.offset
    return Region(*candidates[0], box.width, box.height).translate_inside(area, True, True).offset

T = TypeVar("T")


def dialog_css(name: str) -> str:
    return DIALOG_CSS.format(name=name)


class Dialog(Guarded, ModalScreen[T]):
    """A modal screen that is answered at most once. What it focuses first is its ``AUTO_FOCUS`` (Textual focuses it
    when the dialog shows, and quietly does nothing for a dialog closed before it showed)."""

    beside: Region | None = None  # the dialog stands beside this region of the screen (:func:`place`)

    def on_mount(self) -> None:
        if self.beside is not None:
            self.call_after_refresh(self.place_beside)

    def on_resize(self) -> None:
        if self.beside is not None:
            self.call_after_refresh(self.place_beside)

    def place_beside(self) -> None:
        anchor = self.beside
        if anchor is None or not self.is_attached:
            return
        box = self.query_one(Vertical)
        self.styles.align = ("left", "top")
        box.styles.offset = place(box.outer_size, anchor, self.size)

    def dismiss(self, result: T | None = None) -> AwaitComplete:
        """Close with ``result`` while this dialog is the screen on top; a late second answer changes nothing."""
        if not on_top(self):
            return AwaitComplete()
        return super().dismiss(result)


class ConfirmScreen(Dialog[bool]):
    """总人解, 区故解, 引导, 引导总锁 and 上电解锁 are confirmed before they are sent (y / Enter yes, n / Esc no). The
    question stands beside the element it is about (``anchor``, its region on the screen), or at the foot of the
    window over the panels; the diagram stays drawn."""

    DEFAULT_CSS = dialog_css("ConfirmScreen") + BESIDE_CSS.format(name="ConfirmScreen") + \
        "ConfirmScreen { align: center bottom; } ConfirmScreen > Vertical { width: 60; margin: 0 0 3 0; }"
    AUTO_FOCUS = "#yes"
    BINDINGS: ClassVar[list[BindingType]] = [
        Binding("y", "answer(True)", "yes"),
        Binding("n,escape", "answer(False)", "no"),
    ]

    def __init__(self, question: str, anchor: Region | None = None) -> None:
        super().__init__()
        self.question = question
        self.beside = anchor

    def compose(self) -> ComposeResult:
        with Vertical():
            yield Label(plain(self.question))
            with Grid():
                yield Button("确认 Yes (y)", id="yes", variant="warning", compact=True)
                yield Button("取消 No (n)", id="no", compact=True)

    def on_button_pressed(self, event: Button.Pressed) -> None:
        self.dismiss(event.button.id == "yes")

    def action_answer(self, yes: bool) -> None:
        self.dismiss(yes)


class QuitScreen(ConfirmScreen):
    """Asked before the console closes, whichever way it is asked to (ctrl+q, the palette's Quit, ``quit``): in the
    middle, over a dimmed console."""

    DEFAULT_CSS = dialog_css("QuitScreen") + "QuitScreen > Vertical { margin: 0; }"


class MenuScreen(Dialog[str]):
    """What can be done with a turnout, a signal or a section; returns the function's name ('' for none). It stands
    beside the element (``anchor``) over the diagram, which stays drawn."""

    DEFAULT_CSS = dialog_css("MenuScreen") + BESIDE_CSS.format(name="MenuScreen")
    AUTO_FOCUS = "Button"
    BINDINGS: ClassVar[list[BindingType]] = [Binding("escape", "close", "close")]

    def __init__(self, kind: str, element: str, title: str = "", anchor: Region | None = None) -> None:
        super().__init__()
        self.kind = kind
        self.element = element
        self.title_text = title or f"{kind} {element}"
        self.beside = anchor

    def compose(self) -> ComposeResult:
        with Vertical():
            yield Label(plain(self.title_text))
            with Grid():
                for name in MENUS.get(self.kind, ()):
                    m = MODES[name]
                    yield Button(f"{m.zh} {m.en}", id=f"m-{name}", compact=True)
                yield Button("关闭 close", id="m-", compact=True)

    def on_button_pressed(self, event: Button.Pressed) -> None:
        self.dismiss((event.button.id or "m-")[2:])

    def action_close(self) -> None:
        self.dismiss("")


class PasswordScreen(Dialog[str]):
    DEFAULT_CSS = dialog_css("PasswordScreen") + "PasswordScreen Input { width: 34; }"
    AUTO_FOCUS = "Input"
    BINDINGS: ClassVar[list[BindingType]] = [Binding("escape", "close", "close")]

    def __init__(self, title: str = "教员 Instructor mode: password") -> None:
        super().__init__()
        self.title_text = title

    def compose(self) -> ComposeResult:
        with Vertical():
            yield Label(self.title_text)
            yield Input(password=True, id="password")

    def on_input_submitted(self, event: Input.Submitted) -> None:
        self.dismiss(event.value)

    def action_close(self) -> None:
        self.dismiss("")


HELP = """\
操作表示机 Operator console: keys and mouse

Route: click the start button (L train, D shunting), any variant
buttons, then the end button. Esc drops the selection.
Function button (bottom bar or key), then the signal / turnout / section:
  c 总取消 cancel        r 总人解 release      f 区故解 fault release
  g 引导 guide           G 引导总锁 guide lock  o 重开 reopen
  n 总定位 normal        v 总反位 reverse
  l 单锁 lock   u 单解 unlock   b 单封 block   B 解封 unblock
  P 上电解锁 power-up release (sealed: asks at once, counted)
Click a turnout number, a signal or a section for its menu.

Arrows move the cursor to the nearest element that way (named on the
answer line), Enter presses it. Shift+arrows or the wheel pan;
+ - zoom, 0 fits.   : command bar (Tab, Up/Down, Esc), e.g. {example}
space pause/run   . one cycle   > < speed   a acknowledge alarms
m mute / unmute the alarm bell (or 'mute' / 'unmute' in the bar)
e the exercise's briefing and goals   ctrl+p every action by name
F2 instructor panel   ? this help   ctrl+q quit (asks first)
Esc also stops a long 'run' typed in the command bar
Replay: [ ] seek 10 s, { } 60 s, Home / End
"""


def legend() -> Text:
    """What each colour of the diagram means, drawn in that colour (docs/console.md, "Reading the diagram")."""
    rows: list[tuple[str, list[tuple[str, Style]]]] = [
        ("sections", [("━━ free", Style(color=BAND_COLOUR["free"])), ("━━ locked in a route", Style(
            color=BAND_COLOUR["locked"])), ("━━ occupied (红光带)", Style(color=BAND_COLOUR["occupied"]))]),
        ("turnouts", [("5 normal 定位", S_TURNOUT["normal"]), ("5 reverse 反位", S_TURNOUT["reverse"]),
                      ("5 no indication (flashes)", S_LOST_ON)]),
        ("marks", [("■ single lock", S_MARK["locked"]), ("× single block", S_MARK["blocked"]),
                   ("■ guide lock", S_MARK["guide"])]),
        ("lamps", [("● L", Style(color=LAMP_COLOUR["green"])), ("● U", Style(color=LAMP_COLOUR["yellow"])),
                   ("● H", Style(color=LAMP_COLOUR["red"])), ("● B", Style(color=LAMP_COLOUR["white"])),
                   ("● A", Style(color=LAMP_COLOUR["blue"])), ("○ commanded, dark", Style(color=LAMP_COLOUR["red"]))]),
        ("names", [("X signal", S_NAME), ("X signal alarm", S_NAME_ALARM), ("178s manual release", S_COUNT)]),
        ("buttons", [("L", S_BUTTON["train"]), ("D", S_BUTTON["shunt"]), ("BA1", S_BUTTON["variant"]),
                     ("pressed", S_PRESSED)]),
        ("doors", [("▬ closed", S_DOOR["closed"]), ("▭ open", S_DOOR["open"]), ("▬ bypassed", S_DOOR["bypass"])]),
        ("joints", [("┃ joint", S_JOINT), ("╏ dead zone", S_DEAD), ("T1> train", S_TRAIN)]),
        ("alarms", [("new: red, blinking", Style(color="#ff4040", bold=True)), ("acknowledged", Style(
            color="#c08080"))]),
    ]
    out = Text("颜色 Colours\n")
    for name, samples in rows:
        out.append(f"  {name:9}")
        for text, style in samples:
            out.append("  ")
            out.append(text, style=style)
        out.append("\n")
    return out


class HelpScreen(Dialog[None]):
    """Keys and mouse, with a command in the station's own ids, and the colour legend."""

    DEFAULT_CSS = dialog_css("HelpScreen") + """
    HelpScreen > VerticalScroll { width: 80; max-width: 100%; height: auto; max-height: 100%; padding: 0 1;
        border: round #ffd700; background: #1b1f24; }
    """
    AUTO_FOCUS = "VerticalScroll"  # taller than a small window: the arrows and the wheel scroll it
    BINDINGS: ClassVar[list[BindingType]] = [Binding("escape,q,question_mark,f1", "close", "close")]

    def __init__(self, example: str = "route X XI") -> None:
        super().__init__()
        self.example = example

    def compose(self) -> ComposeResult:
        with VerticalScroll():
            yield Static(Text(HELP.replace("{example}", printable(self.example))) + legend())

    def action_close(self) -> None:
        self.dismiss(None)
