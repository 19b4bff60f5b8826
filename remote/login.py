"""The login of a classroom client started without ``--seat`` or ``--instructor`` (as a browser's, served by
textual-serve, always is): a trainee gives a name and a seat, the instructor the password. The connection is tried
from the form, and a refusal (seat taken, wrong password) is shown there to be corrected."""

from __future__ import annotations

from typing import Any, ClassVar

from rich.text import Text
from textual import work
from textual.app import App, ComposeResult
from textual.binding import Binding, BindingType
from textual.containers import Vertical
from textual.widgets import Button, Input, Label, RadioButton, RadioSet, Static

from liansuo.stations.printable import printable

from .link import Link, LinkError


def hello_of(role: str, name: str, seat: str, password: str) -> dict[str, Any] | str:
    """The hello the form asks for, or what is wrong with the form."""
    if role == "instructor":
        return {"role": "instructor", "password": password} if password else "the instructor's password, please"
    if not seat.strip().isdigit() or not 1 <= int(seat) <= 64:
        return "a seat is a number, 1 to 64"
    if not name.strip():
        return "your name, please (it goes on your report)"
    return {"role": "trainee", "seat": int(seat), "name": name.strip()[:64]}


class LoginApp(App[Link]):
    """The login form; it exits with the open link."""

    TITLE = "liansuo 联锁 classroom"
    CSS = """
    Screen { align: center middle; background: #0c0f12; }
    #form { width: 60; height: auto; border: round #80d0ff; padding: 0 1; }
    #why { height: auto; }
    """
    BINDINGS: ClassVar[list[BindingType]] = [Binding("ctrl+q", "quit", "quit")]

    def __init__(self, url: str) -> None:
        super().__init__()
        self.url = url

    def compose(self) -> ComposeResult:
        with Vertical(id="form"):
            yield Label(f"登录 Log in to the classroom at {printable(self.url)}")
            with RadioSet(id="role"):
                yield RadioButton("值班员 trainee", value=True, id="trainee")
                yield RadioButton("教员 instructor", id="instructor")
            yield Input(placeholder="name (trainee)", id="name")
            yield Input(placeholder="seat number (trainee)", id="seat", type="integer")
            yield Input(placeholder="password (instructor)", id="password", password=True)
            yield Button("Connect", id="connect", variant="primary")
            yield Static(id="why")

    def role(self) -> str:
        pressed = self.query_one(RadioSet).pressed_button
        return "instructor" if pressed is not None and pressed.id == "instructor" else "trainee"

    def on_input_submitted(self, event: Input.Submitted) -> None:
        self.connect()

    def on_button_pressed(self, event: Button.Pressed) -> None:
        self.connect()

    def connect(self) -> None:
        hello = hello_of(self.role(), self.query_one("#name", Input).value, self.query_one("#seat", Input).value,
                         self.query_one("#password", Input).value)
        if isinstance(hello, str):
            self.show(hello)
            return
        self.show("connecting ...", None)
        self.dial(hello)

    @work(thread=True, exclusive=True)
    def dial(self, hello: dict[str, Any]) -> None:
        try:
            link = Link(self.url, hello)
        except LinkError as exc:
            self.call_from_thread(self.show, str(exc))
            return
        self.call_from_thread(self.exit, link)

    def show(self, text: str, bad: bool | None = True) -> None:
        style = "#e0e0e0" if bad is None else "bold #ff5050"
        self.query_one("#why", Static).update(Text(printable(text), style=style))
