"""The console's keys (Textual bindings): the command bar, the clock, alarms, help, the exercise's briefing,
instructor mode, and one key per function button (:data:`~.operate.MODES`). The console's ``check_action`` leaves
out of the footer, and refuses, the keys that are not this operator's (a classroom trainee's clock, F2, F3)."""

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
    Binding("e", "briefing", "briefing", key_display="e"),  # shown only while an exercise is on (check_action)
    Binding("f2", "instructor", "instructor", key_display="F2"),
    *[Binding(m.key, f"arm('{m.name}')", m.en, show=False) for m in MODES.values()],
]
