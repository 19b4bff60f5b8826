"""The station diagram widget (站场图): the layout of :mod:`tui.layout` coloured by :mod:`tui.paint`.

A Line-API widget (Textual ``ScrollView``): it pans (shift+arrows, mouse wheel, drag with the right button) and
zooms (``+`` / ``-``; ``0`` fits the window again). Clicks and the keyboard cursor (arrows move it between
clickable elements, Enter presses) post :class:`Diagram.Pressed` with the element's :class:`~tui.layout.Ref`.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING, ClassVar

from rich.segment import Segment
from rich.style import Style
from textual import events
from textual.binding import Binding, BindingType
from textual.geometry import Size
from textual.message import Message
from textual.scroll_view import ScrollView
from textual.strip import Strip

from .guard import Guarded
from .layout import MAX_ZOOM, Layout, Ref, build_layout
from .paint import S_CURSOR, Frame, add_overlays, glyph, read_frame

if TYPE_CHECKING:
    from liansuo.simulation.sim import Simulation

CLICKABLE = ("button", "turnout", "signal", "section", "platform", "block")


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

    def __init__(self, sim_of: Callable[[], Simulation], pressed: Callable[[], set[Ref]], *, id: str | None = None
                 ) -> None:
        super().__init__(id=id)
        self._sim_of = sim_of
        self._pressed = pressed
        self.zoom: int | None = None  # None: fit the window
        self.lpr: int | None = None
        self.layout_: Layout | None = None
        self._layouts: dict[tuple[int, int, int], Layout] = {}
        self._frame: Frame | None = None
        self.cursor: Ref | None = None
        self._drag: tuple[int, int, float, float] | None = None
        self._centred = False
        self._shown_pressed: set[Ref] = set()

    # ---- layout ----
    @property
    def sim(self) -> Simulation:
        return self._sim_of()

    def _build(self, lpr: int, zoom: int, width: int) -> Layout:
        key = (lpr, zoom, width)
        if key not in self._layouts:
            self._layouts[key] = build_layout(self.sim.station, self.sim.rules.lamps, lpr=lpr, zoom=zoom, width=width)
        return self._layouts[key]

    def relayout(self) -> None:
        w, h = max(20, self.size.width), max(6, self.size.height)
        if self.lpr is None:
            lpr = 3
            for cand in (6, 5, 4):
                if self._build(cand, 0, 0).height <= h - 1:
                    lpr = cand
                    break
        else:
            lpr = self.lpr
        if self.zoom is None:
            zoom = next((z for z in range(MAX_ZOOM, -1, -1) if self._build(lpr, z, 0).width <= w), 1)
            lay = self._build(lpr, zoom, w if self._build(lpr, zoom, 0).width <= w else 0)
        else:
            lay = self._build(lpr, self.zoom, 0)
        self.layout_ = lay
        self.virtual_size = Size(lay.width, lay.height)
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
        lay = self.layout_
        if lay is None:
            return
        targets = [(r, xy) for r, xy in lay.targets.items() if r.kind in CLICKABLE]
        if not targets:
            return
        if self.cursor is None or self.cursor not in lay.targets:
            sx, sy = self.scroll_offset
            cx, cy = sx + self.size.width // 2, sy + self.size.height // 2
            self.cursor = min(targets, key=lambda t: abs(t[1][0] - cx) + 3 * abs(t[1][1] - cy))[0]
        else:
            x0, y0 = lay.targets[self.cursor]
            best: tuple[float, Ref] | None = None
            for r, (x, y) in targets:
                ddx, ddy = x - x0, y - y0
                along = ddx * dx + ddy * dy
                if along <= 0 or r == self.cursor:
                    continue
                across = abs(ddy) if dx else abs(ddx)
                score = along + 3 * across if dx else along * 2 + across
                if best is None or score < best[0]:
                    best = (score, r)
            if best is not None:
                self.cursor = best[1]
        self.offset_of(self.cursor)
        self.refresh()
