"""The station diagram widget (站场图): the layout of :mod:`tui.layout` coloured by :mod:`tui.paint`.

A Line-API widget (Textual ``ScrollView``): it pans (shift+arrows, mouse wheel, drag with the right button) and
zooms (``+`` / ``-``; ``0`` fits the window again). Clicks and the keyboard cursor (arrows move it between
operable elements by :func:`nearest`, Enter presses) post :class:`Diagram.Pressed` with the element's
:class:`~tui.layout.Ref`; a move of the cursor posts :class:`Diagram.CursorMoved`.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING, ClassVar

from rich.segment import Segment
from rich.style import Style
from textual import events
from textual.binding import Binding, BindingType
from textual.containers import Vertical
from textual.css.scalar import Scalar, Unit
from textual.geometry import Region, Size
from textual.message import Message
from textual.scroll_view import ScrollView
from textual.strip import Strip

from liansuo.tui.grid import Layout, Ref
from liansuo.tui.guard import Guarded
from liansuo.tui.layout import MAX_ZOOM, build_layout
from liansuo.tui.paint import S_CURSOR, Frame, add_overlays, glyph, read_frame

if TYPE_CHECKING:
    from liansuo.tui.consolesim import ConsoleSim

CLICKABLE = ("button", "turnout", "signal", "section", "platform", "block")
LINES_PER_ROW = (8, 7, 6, 5, 4, 3)  # the schematic rows' spacing, widest first
MIN_PANELS = 5  # lines the alarm and event panels keep however small the window
PANELS_SHARE = 3  # ... and a third of a column that has the room: the rest is the diagram's


def lines_per_row(column: int, height: Callable[[int], int]) -> int:
    """The widest spacing of the schematic rows whose drawing (``height(lpr)`` lines, a line more for a scroll bar)
    leaves the panels under it a third of the ``column`` and at least :data:`MIN_PANELS` lines; the narrowest when
    none does (the diagram then takes all but :data:`MIN_PANELS` lines and scrolls)."""
    room = column - max(MIN_PANELS, column // PANELS_SHARE)
    return next((n for n in LINES_PER_ROW if height(n) + 1 <= room), LINES_PER_ROW[-1])


class DiagramColumn(Guarded, Vertical):
    """The diagram over the alarm and event panels: on every change of its size it tells the diagram how many lines
    they share (:meth:`Diagram.share`)."""

    def on_resize(self, event: events.Resize) -> None:
        for diagram in self.query(Diagram):
            diagram.share(self.size.height)


class Diagram(Guarded, ScrollView, can_focus=True):
    DEFAULT_CSS = """
    Diagram {
        background: #101418;
        scrollbar-size: 1 1;
    }
    """

    BINDINGS: ClassVar[list[BindingType]] = [
        Binding("left", "cursor(-1, 0)", "cursor", show=False),
        Binding("right", "cursor(1, 0)", "cursor", show=False),
        Binding("up", "cursor(0, -1)", "cursor", show=False),
        Binding("down", "cursor(0, 1)", "cursor", show=False),
        Binding("enter", "press", "press", show=False),
        Binding("shift+left", "pan(-8, 0)", "pan", show=False),
        Binding("shift+right", "pan(8, 0)", "pan", show=False),
        Binding("shift+up", "pan(0, -3)", "pan", show=False),
        Binding("shift+down", "pan(0, 3)", "pan", show=False),
        Binding("plus,equals_sign", "zoom(1)", "zoom+", show=False),
        Binding("minus", "zoom(-1)", "zoom-", show=False),
        Binding("0", "fit", "fit", show=False),
    ]

    class Pressed(Message):
        def __init__(self, ref: Ref) -> None:
            super().__init__()
            self.ref = ref

    class CursorMoved(Message):
        """The keyboard cursor is on another element (the console names it on the answer line)."""

        def __init__(self, ref: Ref) -> None:
            super().__init__()
            self.ref = ref

    def __init__(self, sim_of: Callable[[], ConsoleSim], pressed: Callable[[], set[Ref]], *, id: str | None = None,
                 operable: Callable[[Ref], bool] = lambda ref: True) -> None:
        super().__init__(id=id)
        self._sim_of = sim_of
        self._pressed = pressed
        self._operable = operable  # where the keyboard cursor may stop now (a route started: only buttons)
        self.zoom: int | None = None  # None: fit the window
        self.lpr: int | None = None  # lines per schematic row; None: chosen for the window
        self.column: int | None = None  # the lines of the column shared with the panels (:meth:`share`)
        self.layout_: Layout | None = None
        self._layouts: dict[tuple[int, int, int], Layout] = {}
        self._frame: Frame | None = None
        self.cursor: Ref | None = None
        self._drag: tuple[int, int, float, float] | None = None
        self._centred = False
        self._shown_pressed: set[Ref] = set()

    # ---- layout ----
    @property
    def sim(self) -> ConsoleSim:
        return self._sim_of()

    def _build(self, lpr: int, zoom: int, width: int) -> Layout:
        key = (lpr, zoom, width)
        if key not in self._layouts:
            self._layouts[key] = build_layout(self.sim.station, self.sim.rules.lamps, lpr=lpr, zoom=zoom, width=width)
        return self._layouts[key]

    def share(self, column: int) -> None:
        """The diagram stands over the panels in a column of ``column`` lines: it takes the lines its drawing needs
        (:func:`lines_per_row`), the panels the rest."""
        if column != self.column:
            self.column = column
            self.relayout()

    def relayout(self) -> None:
        w, h = max(20, self.size.width), max(6, self.size.height)
        if self.lpr is not None:
            lpr = self.lpr
        elif self.column is not None:
            lpr = lines_per_row(self.column, lambda n: self._build(n, 0, 0).height)
        else:
            lpr = next((n for n in (6, 5, 4) if self._build(n, 0, 0).height <= h - 1), 3)
        if self.zoom is None:
            zoom = next((z for z in range(MAX_ZOOM, -1, -1) if self._build(lpr, z, 0).width <= w), 1)
            lay = self._build(lpr, zoom, w if self._build(lpr, zoom, 0).width <= w else 0)
        else:
            lay = self._build(lpr, self.zoom, 0)
        self.layout_ = lay
        self.virtual_size = Size(lay.width, lay.height)
        if self.column is not None:
            # the drawing's lines, a line for the scroll bar when it is wider than the window; the panels keep theirs
            lines = lay.height + (1 if lay.width > self.size.width else 0)
            lines = max(3, min(lines, self.column - MIN_PANELS))
            if self.styles.height != Scalar(lines, Unit.CELLS, Unit.WIDTH):
                self.styles.height = lines
        if not self._centred and self.size.width > 0:
            self._centred = True
            self.call_after_refresh(self._centre)
        self.refresh()

    def _centre(self) -> None:
        """Start with the station tracks in the middle of the window (the open line may not fit)."""
        lay = self.layout_
        if lay is not None and lay.width > self.size.width:
            x = self._station_centre(lay) - self.size.width // 2
            self.scroll_to(x=max(0, x), animate=False, immediate=True)

    def _station_centre(self, lay: Layout) -> int:
        """Between the home signals (the station's two throats), else the middle of the station tracks."""
        st = self.sim.station
        xs = [lay.targets[r][0] for s in st.model.signals if s.kind.value == "home"
              if (r := Ref("signal", s.id)) in lay.targets]
        if len(xs) < 2:
            xs = [x for sec in st.sections if st.is_station_track(sec) for x, _ in lay.section_cells.get(sec, [])]
        return (min(xs) + max(xs)) // 2 if xs else lay.width // 2

    def reset_station(self) -> None:
        """The simulation was replaced (replay seek, exercise on another station): lay out again."""
        self._layouts.clear()
        self._centred = False
        self.cursor = None
        self.relayout()

    def on_resize(self, event: events.Resize) -> None:
        self.relayout()

    def on_mount(self) -> None:
        self.relayout()

    # ---- drawing ----
    def update_view(self) -> None:
        """Read the simulation again; redraw when what is shown changed (called by the console's clock)."""
        before, pressed = self._frame, self._pressed()
        self._frame = None
        if self.layout_ is None or before is None or self.frame() != before or pressed != self._shown_pressed:
            self._shown_pressed = pressed
            self.refresh()

    def frame(self) -> Frame:
        if self._frame is None:
            assert self.layout_ is not None
            self._frame = read_frame(self.sim, self.layout_)
            add_overlays(self._frame, self.sim, self.layout_)
        return self._frame

    def render_line(self, y: int) -> Strip:
        lay = self.layout_
        sx, sy = self.scroll_offset
        width = self.size.width
        row = y + sy
        if lay is None or not 0 <= row < lay.height:
            return Strip.blank(width, self.rich_style)
        frame = self.frame()
        pressed = self._pressed()
        cursor_cells = self._cells_of(self.cursor) if self.cursor is not None else set()
        base = self.rich_style
        segs: list[Segment] = []
        text: list[str] = []
        style: Style | None = None
        grid_row = lay.grid[row]
        for x in range(sx, min(sx + width, lay.width)):
            ov = frame.overlay.get((x, row))
            if ov is not None:
                ch, st = ov
            else:
                g = grid_row[x]
                if g is None:
                    ch, st = " ", base
                else:
                    ch, st = glyph(frame, g, pressed)
            if (x, row) in cursor_cells:
                st = st + S_CURSOR
            if st is not style and text:
                segs.append(Segment("".join(text), base + style if style is not None else base))
                text = []
            style = st
            text.append(ch)
        if text:
            segs.append(Segment("".join(text), base + style if style is not None else base))
        return Strip(segs).adjust_cell_length(width, base)

    def _cells_of(self, ref: Ref) -> set[tuple[int, int]]:
        lay = self.layout_
        if lay is None or ref not in lay.targets:
            return set()
        x, y = lay.targets[ref]
        out = set()
        while (g := lay.at(x, y)) is not None and g.ref == ref:
            out.add((x, y))
            x += 1
        return out

    # ---- hit testing ----
    def ref_at(self, x: int, y: int) -> Ref | None:
        """The element under the widget cell (x, y)."""
        if self.layout_ is None:
            return None
        sx, sy = self.scroll_offset
        g = self.layout_.at(x + sx, y + sy)
        return g.ref if g is not None and g.ref is not None and g.ref.kind not in ("end",) else None

    def offset_of(self, ref: Ref) -> tuple[int, int]:
        """Where ``ref`` is drawn, relative to the widget (scrolling it into view first)."""
        assert self.layout_ is not None
        x, y = self.layout_.targets[ref]
        w, h = self.size.width, self.size.height
        sx, sy = self.scroll_offset
        if not (sx <= x < sx + w - 1 and sy <= y < sy + h - 1):
            self.scroll_to(x=max(0, x - w // 2), y=max(0, y - h // 2), animate=False, immediate=True)
            sx, sy = self.scroll_offset
        return x - sx, y - sy

    def on_click(self, event: events.Click) -> None:
        if event.button != 1:
            return
        ref = self.ref_at(event.x, event.y)
        if ref is not None:
            self.cursor = ref
            self.post_message(self.Pressed(ref))
            self.refresh()

    def on_mouse_down(self, event: events.MouseDown) -> None:
        if event.button == 3:
            self._drag = (event.screen_x, event.screen_y, self.scroll_x, self.scroll_y)
            self.capture_mouse()

    def on_mouse_move(self, event: events.MouseMove) -> None:
        if self._drag is not None:
            x0, y0, sx, sy = self._drag
            self.scroll_to(x=sx - (event.screen_x - x0), y=sy - (event.screen_y - y0), animate=False)

    def on_mouse_up(self, event: events.MouseUp) -> None:
        if self._drag is not None:
            self._drag = None
            self.release_mouse()

    # ---- keyboard ----
    def action_pan(self, dx: int, dy: int) -> None:
        self.scroll_to(x=self.scroll_x + dx, y=self.scroll_y + dy, animate=False)

    def action_zoom(self, step: int) -> None:
        lay = self.layout_
        current = lay.zoom if lay is not None else 1
        self.zoom = max(0, min(MAX_ZOOM, current + step))
        self.relayout()

    def action_fit(self) -> None:
        self.zoom = None
        self.lpr = None
        self._centred = False
        self.relayout()

    def action_press(self) -> None:
        if self.cursor is not None:
            self.post_message(self.Pressed(self.cursor))

    def action_cursor(self, dx: int, dy: int) -> None:
        """An arrow: the cursor goes to the nearest operable element in that direction (:func:`nearest`); the first
        press puts it on the element nearest the middle of the window."""
        lay = self.layout_
        if lay is None:
            return
        centres = self.centres()
        if not centres:
            return
        if self.cursor is None or self.cursor not in centres:
            sx, sy = self.scroll_offset
            middle = (sx + self.size.width / 2, sy + self.size.height / 2)
            self.cursor = min(centres, key=lambda r: distance(centres[r], middle))
        else:
            lines = track_lines(lay)
            rows = {ref: row_of(y, lines) for ref, (_, y) in centres.items()}
            self.cursor = nearest(centres, self.cursor, (dx, dy), rows) or self.cursor
        self.offset_of(self.cursor)
        self.refresh()
        self.post_message(self.CursorMoved(self.cursor))

    def centres(self) -> dict[Ref, tuple[float, float]]:
        """The middle of the cells of every element the cursor may stop on now (a section: of its band), and of the
        one under it, where the cursor measures from."""
        lay = self.layout_
        if lay is None:
            return {}
        out: dict[Ref, tuple[float, float]] = {}
        for ref in lay.targets:
            if ref.kind not in KEYBOARD or not (ref == self.cursor or self._operable(ref)):
                continue
            cells = lay.section_cells.get(ref.id) if ref.kind == "section" else None
            cells = cells or sorted(self._cells_of(ref))
            out[ref] = (sum(x for x, _ in cells) / len(cells), sum(y for _, y in cells) / len(cells))
        return out

    def cursor_region(self) -> Region | None:
        """Where the element under the cursor is on the screen, for a menu or a question about it to stand beside
        (None when there is no cursor or it is scrolled out of view)."""
        if self.cursor is None or self.layout_ is None or self.cursor not in self.layout_.targets:
            return None
        cells = self._cells_of(self.cursor)
        sx, sy = self.scroll_offset
        xs = [x - sx for x, _ in cells]
        ys = [y - sy for _, y in cells]
        if not xs or not (0 <= min(xs) < self.size.width and 0 <= ys[0] < self.size.height):
            return None
        region = self.content_region
        return Region(region.x + min(xs), region.y + min(ys), max(xs) - min(xs) + 1, max(ys) - min(ys) + 1)


KEYBOARD = ("button", "turnout", "signal", "section")  # what the arrow keys stop on
ROW_CELLS = 2.0  # a terminal cell is about twice as tall as it is wide: a line counts as two columns
OFF_AXIS = 2.0  # a step sideways costs as much as two steps along the arrow
CONE = 0.5  # within about 27 degrees of the arrow: sideways at most half as far as along it
WIDE_CONE = 3.0  # then within about 72 degrees; one nearly square to the arrow never
OUTSIDE_CONE = 1000.0  # an element outside the narrow cone is taken only when none lies within


def distance(a: tuple[float, float], b: tuple[float, float]) -> float:
    return abs(a[0] - b[0]) + ROW_CELLS * abs(a[1] - b[1])


def nearest(centres: dict[Ref, tuple[float, float]], start: Ref, direction: tuple[int, int],
            rows: dict[Ref, int] | None = None) -> Ref | None:
    """The element an arrow goes to from ``start``: among those ahead in ``direction`` (a unit step, (1, 0) right,
    (0, 1) down), the one with the least distance along the arrow plus twice the distance across it. Left and right
    first keep to the track ``start`` belongs to (its row in ``rows``: the track's line, for a label the track it is
    written beside), within 45 degrees of the arrow; then come those within :data:`CONE` of the arrow, then those
    within :data:`WIDE_CONE`. None when nothing lies that way (the cursor stays)."""
    x0, y0 = centres[start]
    ux, uy = direction
    row = rows.get(start) if rows is not None and uy == 0 else None
    best: tuple[float, Ref] | None = None
    for ref, (x, y) in centres.items():
        dx, dy = x - x0, ROW_CELLS * (y - y0)
        along = dx * ux + dy * uy
        if ref == start or along <= 0:
            continue
        across = abs(dx * uy) + abs(dy * ux)
        if row is not None and rows is not None and rows.get(ref) == row and across <= along:
            tier = 0.0
        elif across <= CONE * along:
            tier = OUTSIDE_CONE
        elif across <= WIDE_CONE * along:
            tier = 2 * OUTSIDE_CONE
        else:
            continue  # nearly square to the arrow: not where it points
        score = tier + along + OFF_AXIS * across
        if best is None or score < best[0]:
            best = (score, ref)
    return best[1] if best is not None else None


def track_lines(lay: Layout) -> list[int]:
    """The lines a track is drawn along (its band), top to bottom."""
    return [y for y, line in enumerate(lay.grid) if any(g is not None and g.role == "band" for g in line)]


def row_of(y: float, lines: list[int]) -> int:
    """The track line nearest the line ``y``: a label's is the track it is written beside (on a tie, the one
    below)."""
    return min(lines, key=lambda line: (abs(line - y), line < y)) if lines else round(y)
