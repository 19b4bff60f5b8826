"""The laid-out station diagram: a grid of glyphs (:class:`Layout`), each saying which element it draws
(:class:`Ref`); the shapes of the drawing, and the labels the layout places (:class:`Item`)."""

from __future__ import annotations

from dataclasses import dataclass, field

BAND = "━"
DIAG_DOWN = "╲"  # going right and down the screen
DIAG_UP = "╱"
CROSS = "╳"
JOINT = "┃"
DEAD_JOINT = "╏"
FOULING = "┿"
LAMP = "●"

ROLE_PRIORITY = {"diag": 0, "band": 0, "node": 1, "fp": 1, "joint": 2, "end": 2, "label": 3, "door": 4, "plabel": 4,
                 "tlabel": 5, "tmark": 5, "signame": 5, "lamp": 6, "button": 6, "blamp": 6}


@dataclass(frozen=True)
class Ref:
    """What a cell shows: ``kind`` is section, turnout, signal, button, joint, end, platform, fouling, line (a block
    line's name and lamps) or block (a block line's button)."""

    kind: str
    id: str
    sub: str = ""  # button kind (train, shunt, end, exit, variant); door key for platforms; block button (BSA ...)


@dataclass
class Glyph:
    ch: str
    role: str  # band, diag, node, joint, end, fp, label, tlabel, tmark, lamp, signame, button, door, plabel, blamp
    ref: Ref | None
    section: str = ""  # the section whose band colour this cell takes (band, diag, node, fp, label)
    leg: tuple[str, str] | None = None  # (turnout, leg) for the cell next to a turnout on that leg
    slot: int = 0  # lamp slot of a signal; door index of a platform; block lamp (0 departure, 1 arrival)
    also: str = ""  # a second section drawn over the same cell (a crossing)
    track: str = ""  # the track a band or diagonal cell draws (a turnout section's branch lights on its own)


@dataclass
class Item:
    """A label of fixed shape anchored at a position's column: cells (dx, ch, role, ref, slot) on one line."""

    line: int
    pos: int  # index into the sorted positions
    cells: list[tuple[int, str, str, Ref | None, int]]
    priority: int = 1

    @property
    def lo(self) -> int:
        return min(c[0] for c in self.cells)

    @property
    def hi(self) -> int:
        return max(c[0] for c in self.cells)


@dataclass
class Layout:
    width: int
    height: int
    grid: list[list[Glyph | None]]
    targets: dict[Ref, tuple[int, int]] = field(default_factory=dict)  # first cell of every clickable element
    lamp_slots: dict[str, list[tuple[int, int]]] = field(default_factory=dict)
    # signal -> places for its release countdown, best first: (x, y, step) where the text starts and grows by step
    countdown_at: dict[str, list[tuple[int, int, int]]] = field(default_factory=dict)
    section_cells: dict[str, list[tuple[int, int]]] = field(default_factory=dict)
    # track -> (position of its left end, of its right end, its cells from left to right): where a train's head is
    track_cells: dict[str, tuple[float, float, list[tuple[int, int]]]] = field(default_factory=dict)
    lpr: int = 3
    zoom: int = 1

    def at(self, x: int, y: int) -> Glyph | None:
        if 0 <= y < self.height and 0 <= x < self.width:
            return self.grid[y][x]
        return None

    def text(self) -> str:
        """The drawing as plain text (for tests and for a quick look)."""
        return "\n".join("".join(g.ch if g else " " for g in row).rstrip() for row in self.grid)
