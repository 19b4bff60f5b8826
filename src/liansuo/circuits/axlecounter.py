"""Axle counters (计轴): a section proven clear by counting the axles in and out at its ends.

The evaluator (计轴主机) adds one for every axle its counting heads see entering and takes one away for every axle
leaving; the section is clear only at a count of exactly zero, so a miscount either way shows occupied (fail-safe).
Unlike a track circuit it sees every axle whatever its shunting resistance (no poor shunting), and it sees no broken
rail. A disturbed count stays until the operator resets it (计轴复零, a sealed button): the reset sets the count to
zero, which is why it is given only after the line has been confirmed clear on site. An axle still inside at the
reset is not counted in, so counting it out later disturbs the count again.
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass
class AxleCounter:
    """The count of one section, kept as the difference to the axles really inside (0 while counting is healthy)."""

    error: int = 0  # axles counted minus axles inside: a miscount, or axles inside at a reset (negative)

    def count(self, inside: int) -> int:
        """The evaluator's count with ``inside`` axles really in the section."""
        return inside + self.error

    def clear(self, inside: int) -> bool:
        return self.count(inside) == 0

    def miscount(self) -> None:
        """A counting head counted an axle that is not there (interference, a trolley's wheel, a failed head)."""
        self.error += 1

    def reset(self, inside: int) -> None:
        """计轴复零: the count is set to zero, whatever is inside."""
        self.error = -inside


__all__ = ["AxleCounter"]
