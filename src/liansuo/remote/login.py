"""The login of a classroom client started without ``--seat`` or ``--instructor`` (as a browser's, served by
textual-serve, always is): a trainee gives a name and a seat, the instructor the password. The connection is tried
from the form, and a refusal (seat taken, wrong password) is shown there to be corrected.

It is a screen of the console itself, over the station drawn dark (the server's lobby names the station), not an
app of its own: textual-serve ends a browser's session when its process's first app exits."""

from __future__ import annotations

import ssl
from typing import Any, ClassVar

from rich.text import Text
from textual import work
from textual.app import ComposeResult
from textual.binding import Binding, BindingType
from textual.containers import Vertical
from textual.screen import ModalScreen
from textual.widgets import Button, Input, Label, RadioButton, RadioSet, Static

from liansuo.kit.printable import printable
from liansuo.remote.link import LinkError, ServerLink


def hello_of(role: str, name: str, seat: str, password: str) -> dict[str, Any] | str:
    """The hello the form asks for, or what is wrong with the form."""
    if role == "instructor":
        return {"role": "instructor", "password": password} if password else "the instructor's password, please"
    if not seat.strip().isdigit() or not 1 <= int(seat) <= 64:
        return "a seat is a number, 1 to 64"
    if not name.strip():
        return "your name, please (it goes on your report)"
    return {"role": "trainee", "seat": int(seat), "name": name.strip()[:64]}


def seats_text(lobby: dict[str, Any]) -> str:
    """Which seats are free, as the login screen lists them: '1 taken · 2 free · 3 taken (away)' (the lobby names
    nobody: whoever reads it has not logged in)."""
    out = []
    for s in lobby.get("seats", []):
        state = "free" if not s.get("taken") else "taken" if s.get("connected") else "taken (away)"
        out.append(f"{s.get('seat')} {state}")
    return " · ".join(out)


class LoginScreen(ModalScreen[ServerLink | None]):
    """The login form over the station drawn dark; it is dismissed with the open link (None: the console closes)."""

    DEFAULT_CSS = """
    LoginScreen { align: center middle; }
    LoginScreen #form { width: 64; height: auto; border: round #80d0ff; padding: 0 1; background: #0c0f12; }
    LoginScreen #why { height: auto; }
    LoginScreen #seats, LoginScreen #where { height: auto; color: #a0a0a0; }
    """
    BINDINGS: ClassVar[list[BindingType]] = [Binding("ctrl+q", "leave", "quit")]

    def __init__(self, url: str, lobby: dict[str, Any], tls: ssl.SSLContext | None = None) -> None:
        super().__init__()
        self.url = url
        self.lobby = lobby
        self.tls = tls

    def compose(self) -> ComposeResult:
        station = str((self.lobby.get("station") or {}).get("name", ""))
        with Vertical(id="form"):
            yield Label("登录 Log in to the classroom")
            yield Static(printable(f"{self.url} · station {station}"), id="where")
            yield Static(printable(f"seats: {seats_text(self.lobby)}"), id="seats")
            with RadioSet(id="role"):
                yield RadioButton("值班员 trainee", value=True, id="trainee")
                yield RadioButton("教员 instructor", id="instructor")
            yield Input(placeholder="name (trainee)", id="name")
            yield Input(placeholder="seat number (trainee)", id="seat", type="integer")
            yield Input(placeholder="password (instructor)", id="password", password=True)
            yield Button("Connect", id="connect", variant="primary")
            yield Static(id="why")

    def on_mount(self) -> None:
        self.query_one("#name", Input).focus()  # most who log in are trainees: they type their name first

    def role(self) -> str:
        pressed = self.query_one(RadioSet).pressed_button
        return "instructor" if pressed is not None and pressed.id == "instructor" else "trainee"

    def on_input_changed(self, event: Input.Changed) -> None:
        """Typing a password chooses the instructor, typing a name or a seat the trainee."""
        if event.value and event.input.id in ("name", "seat", "password"):
            chosen = "instructor" if event.input.id == "password" else "trainee"
            if self.role() != chosen:
                self.query_one(f"#{chosen}", RadioButton).value = True

    def on_input_submitted(self, event: Input.Submitted) -> None:
        self.connect()

    def on_button_pressed(self, event: Button.Pressed) -> None:
        self.connect()

    def action_leave(self) -> None:
        self.dismiss(None)

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
            link = ServerLink(self.url, hello, tls=self.tls)
        except LinkError as exc:
            self.app.call_from_thread(self.show, str(exc))
            return
        self.app.call_from_thread(self.dismiss, link)

    def show(self, text: str, bad: bool | None = True) -> None:
        style = "#e0e0e0" if bad is None else "bold #ff5050"
        self.query_one("#why", Static).update(Text(printable(text), style=style))
