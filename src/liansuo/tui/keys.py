"""The console's keys (Textual bindings): the command bar, the clock, alarms, help, instructor mode, and one key per
function button (:data:`~.operate.MODES`)."""

from __future__ import annotations

from textual.binding import Binding, BindingType

from liansuo.tui.operate import MODES

CONSOLE_BINDINGS: list[BindingType] = [
    Binding("colon", "command_bar", "command", key_display=":", priority=True),
    Binding("space", "pause", "pause/run", key_display="space"),
    Binding("full_stop", "step", "step", show=False),
    Binding("greater_than_sign", "speed(1)", "faster", show=False),
    Binding("less_than_sign", "speed(-1)", "slower", show=False),
    Binding("escape", "escape", "drop", show=False),
    Binding("a", "acknowledge", "ack alarms", show=False),
    Binding("m", "mute", "mute bell", show=False),
    Binding("f1,question_mark", "help", "help", key_display="?"),
    Binding("f2", "instructor", "instructor", key_display="F2"),
    *[Binding(m.key, f"arm('{m.name}')", m.en, show=False) for m in MODES.values()],
]
