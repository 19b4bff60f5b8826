"""Modal dialogs: the confirmation a real console asks for, element menus, the instructor password, help, and the
question before the console closes.

A dialog answers once: an answer that arrives after it has closed (a second click of a double click, a key pressed
twice in one burst of input) is dropped, so it can neither close the dialog opened by the first answer nor the
console's own screen. Text in a dialog that comes from a file (ids, names) is shown as written, never as markup.
"""

from __future__ import annotations

from typing import ClassVar, TypeVar

from textual.app import ComposeResult
from textual.await_complete import AwaitComplete
from textual.binding import Binding, BindingType
from textual.containers import Grid, Vertical
from textual.screen import ModalScreen
from textual.widgets import Button, Input, Label, Static

from .guard import Guarded, on_top
from .operate import MENUS, MODES
from .plain import plain

DIALOG_CSS = """
{name} {{ align: center middle; background: rgba(0, 0, 0, 0.55); }}
{name} > Vertical {{ width: 60; max-width: 100%; height: auto; padding: 0 1; border: round #ffd700;
    background: #1b1f24; }}
{name} Label {{ width: 100%; margin: 0 0 1 0; }}
{name} Grid {{ grid-size: 2; grid-columns: 1fr 1fr; grid-gutter: 0 1; height: auto; width: 100%; }}
{name} Button {{ width: 100%; margin: 0; }}
"""

T = TypeVar("T")


def dialog_css(name: str) -> str:
    return DIALOG_CSS.format(name=name)


class Dialog(Guarded, ModalScreen[T]):
    """A modal screen that is answered at most once. What it focuses first is its ``AUTO_FOCUS`` (Textual focuses it
    when the dialog shows, and quietly does nothing for a dialog closed before it showed)."""

    def dismiss(self, result: T | None = None) -> AwaitComplete:
        """Close with ``result`` while this dialog is the screen on top; a late second answer changes nothing."""
        if not on_top(self):
            return AwaitComplete()
        return super().dismiss(result)


class ConfirmScreen(Dialog[bool]):
    """总人解, 区故解, 引导, 引导总锁 and 上电解锁 are confirmed before they are sent (y / Enter yes, n / Esc no)."""

    DEFAULT_CSS = dialog_css("ConfirmScreen")
    AUTO_FOCUS = "#yes"
    BINDINGS: ClassVar[list[BindingType]] = [
        Binding("y", "answer(True)", "yes"),
        Binding("n,escape", "answer(False)", "no"),
    ]

    def __init__(self, question: str) -> None:
        super().__init__()
        self.question = question

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
    """Asked before the console closes, whichever way it is asked to (ctrl+q, the palette's Quit, ``quit``)."""

    DEFAULT_CSS = dialog_css("QuitScreen")


class MenuScreen(Dialog[str]):
    """What can be done with a turnout, a signal or a section; returns the function's name ('' for none)."""

    DEFAULT_CSS = dialog_css("MenuScreen")
    AUTO_FOCUS = "Button"
    BINDINGS: ClassVar[list[BindingType]] = [Binding("escape", "close", "close")]

    def __init__(self, kind: str, element: str, title: str = "") -> None:
        super().__init__()
        self.kind = kind
        self.element = element
        self.title_text = title or f"{kind} {element}"

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

    def compose(self) -> ComposeResult:
        with Vertical():
            yield Label("教员 Instructor mode: password")
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

Arrows move the cursor, Enter presses it. Shift+arrows or the wheel
pan; + - zoom, 0 fits.   : command bar (Tab, Up/Down, Esc)
space pause/run   . one cycle   > < speed   a acknowledge alarms
F2 instructor panel   ? this help   ctrl+q quit (asks first)
Esc also stops a long 'run' typed in the command bar
Replay: [ ] seek 10 s, { } 60 s, Home / End
"""


class HelpScreen(Dialog[None]):
    DEFAULT_CSS = dialog_css("HelpScreen") + "HelpScreen > Vertical { width: 78; }"
    BINDINGS: ClassVar[list[BindingType]] = [Binding("escape,q,question_mark,f1", "close", "close")]

    def compose(self) -> ComposeResult:
        with Vertical():
            yield Static(HELP)

    def action_close(self) -> None:
        self.dismiss(None)
