"""Text from files and from users as the console shows it: control characters written out
(:func:`~stations.printable.printable`, so an escape sequence in a station name never reaches the terminal) and Rich
markup shown as it is written (a station named ``[bold red]x`` is shown so, and ``[/x]`` cannot break a widget).

Every widget that shows such text takes a :class:`~rich.text.Text` made here, never a markup string.
"""

from __future__ import annotations

from rich.text import Text

from liansuo.kit.printable import printable_block


def plain(text: str, style: str = "") -> Text:
    """``text`` to show as it is: line breaks kept, every other control character written out, no markup."""
    return Text(printable_block(text), style=style)
