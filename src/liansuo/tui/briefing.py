"""The exercise's briefing (what the trainee is told) and its goals, in a dialog of their own: shown when an exercise
starts, reopened with ``e`` (the footer's "briefing"), closed with Esc, Enter or ``e``.

The briefing is wrapped to the dialog's width (a file's own line breaks inside a paragraph are joined, so its text
reads as one paragraph at any width), and the dialog scrolls when the window is too small for it. Its text comes from
the exercise file and is shown as written (:mod:`tui.plain`).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import ClassVar

from rich.text import Text
from textual.app import ComposeResult
from textual.binding import Binding, BindingType
from textual.containers import VerticalScroll
from textual.widgets import Static

from liansuo.kit.printable import printable_block
from liansuo.tui.dialogs import Dialog, dialog_css


@dataclass
class Briefing:
    title: str
    text: str  # the briefing, as the exercise file gives it
    goals: list[tuple[str, bool]] = field(default_factory=list)  # each goal's description, and whether it is met
    note: str = ""  # how the exercise stands: the time left, or how it ended and the score


def reflow(text: str) -> str:
    """Paragraphs joined into one line each (a blank line parts them), for the widget to wrap at its own width."""
    paragraphs = [" ".join(p.split()) for p in text.strip().split("\n\n")]
    return "\n\n".join(p for p in paragraphs if p)


def briefing_text(b: Briefing) -> Text:
    out = Text()
    out.append(printable_block(b.title) + "\n\n", style="bold #ffd700")
    out.append(printable_block(reflow(b.text)) + "\n")
    if b.goals:
        out.append("\n目标 Goals\n", style="bold")
        for description, met in b.goals:
            out.append(f"{'✓' if met else '·'} ", style="bold #40e070" if met else "#a0a0a0")
            out.append(printable_block(reflow(description)) + "\n")
    if b.note:
        out.append("\n" + printable_block(b.note) + "\n", style="#ffd700")
    out.append("\nEsc / Enter closes; e shows this again", style="#8a8a8a")
    return out


class BriefingScreen(Dialog[None]):
    """The briefing and the goals, wrapped, in the middle of the window over the dimmed console."""

    DEFAULT_CSS = dialog_css("BriefingScreen") + """
    BriefingScreen > VerticalScroll { width: 90; max-width: 100%; height: auto; max-height: 100%; padding: 0 1;
        border: round #ffd700; background: #1b1f24; }
    BriefingScreen Static { width: 100%; text-wrap: wrap; }
    """
    AUTO_FOCUS = "VerticalScroll"  # taller than a small window: the arrows and the wheel scroll it
    BINDINGS: ClassVar[list[BindingType]] = [Binding("escape,enter,e,q", "close", "close")]

    def __init__(self, briefing: Briefing) -> None:
        super().__init__()
        self.briefing = briefing

    def compose(self) -> ComposeResult:
        with VerticalScroll() as box:
            box.border_title = "练习 Exercise"
            yield Static(briefing_text(self.briefing), id="briefing")

    def action_close(self) -> None:
        self.dismiss(None)
