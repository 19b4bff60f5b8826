"""What the oracle sees of the world: the field as it is, never the interlocking's memory.

Lamps actually lit, where switch rails lie and whether a machine runs, the indication relays, track relays, where
wheelsets stand (where known), screen doors, the block lines. The one thing it asks the interlocking is whether a
turnout is locked, as the operator's console shows it; what must be locked is the oracle's own judgment.
"""

from __future__ import annotations

from collections.abc import Iterable
from typing import Protocol


class FieldView(Protocol):
    def lit(self, signal: str) -> frozenset[str]:
        """Lamps showing light (a flashing lamp counts as lit while it flashes)."""

    def flashing(self, signal: str) -> bool:
        """The signal's flashing lamp is flashing (USU)."""

    def proven_lit(self, signal: str) -> tuple[frozenset[str], bool]:
        """What the lamp proving relays (DJ) and the flash check (SNJJ) say is lit and flashing: what the
        interlocking can know of the lamps, which a fault may keep from what they show."""

    def rails(self, turnout: str) -> str | None:
        """Where the switch rails lie: 'normal', 'reverse', or None between positions."""

    def running(self, turnout: str) -> bool:
        """The switch machine is moving the rails."""

    def target(self, turnout: str) -> str | None:
        """Where the machine is being driven to, while it runs."""

    def moving(self) -> set[str]:
        """Turnouts whose machines run now."""

    def proven(self, turnout: str) -> str | None:
        """The position the indication relays (DBJ/FBJ) prove, or None."""

    def clear(self, section: str) -> bool:
        """The track relay (GJ) of the section is up."""

    def occupied(self, sections: Iterable[str]) -> set[str]:
        """Those of ``sections`` whose track relay is down (what ``clear`` says of each, read at once)."""

    def locked(self, turnout: str) -> bool:
        """The interlocking reports the turnout locked (route, overlap, single lock, guide lock, power-up)."""

    def section_locked(self, section: str) -> bool:
        """The console shows the section locked (a white band: a route, an overlap, the power-up lock): what the
        reference judge reads of the releases, never the oracle."""

    def wheelsets(self, tracks: set[str]) -> list[tuple[str, float]]:
        """Wheelsets (track, position) standing on any of ``tracks``, where the world knows them."""

    def doors_safe(self, section: str) -> bool:
        """Every screen door of the platform at ``section`` is closed and locked, or its interlock is bypassed."""

    def line_permits(self, link: str) -> bool:
        """A semi-automatic (64D) line: the neighbour has accepted our train and it has not left yet. A
        station-block line: the neighbour has not blocked it for a train of its own."""

    def line_outbound(self, link: str) -> bool:
        """An automatic line whose direction has been changed (改方) for our departures."""
