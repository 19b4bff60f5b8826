"""The schematic layout of the station diagram (站场图): where every cell of the drawing goes.

Tracks are horizontal bands on their schematic row (``row`` in the station file; inferred from the topology where a
track has none), turnout legs leave their turnout diagonally (╱ ╲), and every node (end, joint, turnout) gets a
column. Columns keep the order of positions along the line but not their scale: a throat is spread out and an open
line squeezed, and they are pushed apart just enough for every label (signals with their lamps and buttons, turnout
numbers) to fit on its line. A node's ``draw: {x, y}`` in the station file gives its row (``y``) and a minimum column
(``x``).

The layout is static: it says which cell shows which element (:class:`~.grid.Ref`, in the laid-out
:class:`~.grid.Layout`). The diagram widget colours the cells from the simulation's state at every redraw.
"""

from __future__ import annotations

import math
from collections.abc import Iterable

from liansuo.stations.schema import Direction, SectionRole
from liansuo.stations.station import Station
from liansuo.tui.grid import (
    BAND,
    CROSS,
    DEAD_JOINT,
    DIAG_DOWN,
    DIAG_UP,
    FOULING,
    JOINT,
    LAMP,
    ROLE_PRIORITY,
    Glyph,
    Item,
    Layout,
    Ref,
)
from liansuo.tui.rows import drawn_at, node_rows, track_rows

# ---- the builder ----------------------------------------------------------------------------------------------------
ZOOM_K = (0.18, 0.35, 0.6, 0.9, 1.3)  # columns per sqrt(metre) between neighbouring positions, by zoom level
MAX_ZOOM = len(ZOOM_K) - 1
BLOCK_KINDS = ("64d", "station")  # lines whose block the operator sees on the diagram (automatic block has signals)
BLOCK_BUTTONS = ("BSA", "FUA", "SGA")  # 64D: block (闭塞按钮), restore (复原按钮), accident (事故按钮)
MIN_DOORS = 4  # screen doors drawn at least, beside the platform's id
MAX_DOORS = 12


def platform_track(station: Station, section: str) -> str | None:
    """The track a platform at ``section`` is drawn along: the section's longest."""
    tracks = station.section_tracks.get(section, [])
    return max(tracks, key=lambda t: station.track_span(t)[1] - station.track_span(t)[0], default=None)


class _Builder:
    def __init__(self, station: Station, lamps_per_aspect: dict[str, list[str]], lpr: int, zoom: int) -> None:
        self.st = station
        self.lamps_per_aspect = lamps_per_aspect
        self.lpr = lpr
        self.zoom = max(0, min(MAX_ZOOM, zoom))
        self.rows = track_rows(station)
        self.nrows = node_rows(station, self.rows)
        all_rows = list(self.rows.values()) + list(self.nrows.values())
        self.rmin = min(all_rows) if all_rows else 0.0
        self.top = 2
        # positions along the line that get a column: nodes, fouling points, variant buttons
        pos: set[float] = set()
        for n in station.node_tracks:
            pos.add(self._p(station.node_at(n)))
        for fp in station.model.fouling_points:
            pos.add(self._p(fp.at))
        for b in station.model.buttons:
            if b.kind == "variant" and b.at in station.tracks:
                pos.add(self._p(self._track_mid(b.at)))
        self.positions = sorted(pos)
        self.index = {p: i for i, p in enumerate(self.positions)}
        self.items: list[Item] = []
        self.min_gap: list[int] = [0] * len(self.positions)  # col[i] - col[i-1] >= this
        self.pairs: list[tuple[int, int, int]] = []  # (i, j, k): col[j] - col[i] >= k
        self.lower: list[int] = [0] * len(self.positions)

    @staticmethod
    def _p(x: float) -> float:
        return round(x, 2)

    def _track_mid(self, track: str) -> float:
        lo, hi = self.st.track_span(track)
        return (lo + hi) / 2

    def pos_of(self, node: str) -> int:
        return self.index[self._p(self.st.node_at(node))]

    def line(self, row: float) -> int:
        return math.floor((row - self.rmin) * self.lpr + 0.5) + self.top

    # ---- gathering constraints ----
    def plan(self) -> None:
        k = ZOOM_K[self.zoom]
        for i in range(1, len(self.positions)):
            d = self.positions[i] - self.positions[i - 1]
            self.min_gap[i] = max(1, min(14, round(k * math.sqrt(d))))
        station_track = 10 + 6 * self.zoom
        for tid, (a, b) in self.st.track_ports.items():
            pa, pb = self.pos_of(a.node), self.pos_of(b.node)
            (pa, a), (pb, b) = sorted([(pa, a), (pb, b)], key=lambda x: x[0])
            yt = self.line(self.rows[tid])
            da = abs(self.line(self.nrows[a.node]) - yt)
            db = abs(self.line(self.nrows[b.node]) - yt)
            need = da + db + 2
            if self.st.sections[self.st.tracks[tid].section].role is SectionRole.station_track:
                need = max(need, station_track)
            if pa != pb:
                self.pairs.append((pa, pb, need))
            # diagonal cells are fixed relative to their node: labels must keep clear of them
            ya, yb = self.line(self.nrows[a.node]), self.line(self.nrows[b.node])
            for i in range(1, da + 1):
                self.items.append(Item(ya + (i if yt > ya else -i), pa, [(i, "", "diag", None, 0)], 0))
            for i in range(1, db + 1):
                self.items.append(Item(yb + (i if yt > yb else -i), pb, [(-i, "", "diag", None, 0)], 0))
        for node in self.st.node_tracks:
            drawn = drawn_at(self.st, node)
            if drawn is not None:
                p = self.pos_of(node)
                self.lower[p] = max(self.lower[p], int(drawn[0]))
        self._signal_items()
        self._turnout_items()
        self._variant_items()
        self._block_items()
        self._platform_room()

    def lamp_slots(self, signal: str) -> int:
        have = {lamp.value for lamp in self.st.signals[signal].lamps}
        best = 1
        for lamps in self.lamps_per_aspect.values():
            if lamps and set(lamps) <= have:
                best = max(best, len(lamps))
        return best

    def _signal_items(self) -> None:
        """Signals stand beside their joint on the approach side: a down signal left of it on the line below, an up
        signal right of it on the line above. Outwards from the joint: lamps, buttons (L train, D shunting), name."""
        st = self.st
        Token = list[tuple[str, str, Ref | None, int]]
        by_side: dict[tuple[str, str], list[Token]] = {}
        for sig in st.model.signals:
            if sig.at not in st.node_tracks:
                continue
            ref = Ref("signal", sig.id)
            n = self.lamp_slots(sig.id)
            down = sig.direction is Direction.down
            # lamp slot 0 is the one next to the joint; tokens are in reading order
            tokens: list[Token] = [[(LAMP, "lamp", ref, n - 1 - i if down else i) for i in range(n)]]
            buttons: Token = [("L" if b.value == "train" else "D", "button", Ref("button", sig.id, b.value), 0)
                              for b in sig.buttons]
            if buttons:
                tokens.append(buttons)
            tokens.append([(" ", "gap", None, 0)])
            tokens.append([(ch, "signame", ref, 0) for ch in sig.id])
            by_side.setdefault((sig.at, sig.direction.value), []).extend(tokens)
        for b in st.model.buttons:
            if b.kind == "variant" or b.at not in st.node_tracks:
                continue
            direction = b.direction.value if b.direction else self._free_side(b.at)
            group = by_side.setdefault((b.at, direction), [])
            if group:
                group.append([(" ", "gap", None, 0)])
            group.append([(ch, "button", Ref("button", b.id, b.kind), 0) for ch in b.id])
        for (node, direction), tokens in by_side.items():
            y = self.line(self.nrows[node])
            down = direction == "down"
            cells: list[tuple[int, str, str, Ref | None, int]] = []
            edge = 0  # the next free cell outwards from the joint
            for token in tokens:
                n = len(token)
                first = edge - n + 1 if down else edge
                for i, (ch, role, tref, slot) in enumerate(token):
                    if role != "gap":
                        cells.append((first + i, ch, role, tref, slot))
                edge = first - 1 if down else first + n
            self.items.append(Item(y + 1 if down else y - 1, self.pos_of(node), cells, 2))

    def _block_items(self) -> None:
        """A block line's panel beside its end, outwards, on the line above the track: its name, the departure and
        arrival lamps (发车, 接车 表示灯) and, on a 64D line, the block (BSA), restore (FUA) and accident (SGA)
        buttons."""
        st = self.st
        for lk in st.model.links:
            if lk.kind.value not in BLOCK_KINDS or lk.end not in st.node_tracks:
                continue
            line = Ref("line", lk.id)
            cells: list[tuple[str, str, Ref | None, int]] = [(ch, "plabel", line, 0) for ch in lk.id]
            cells += [(" ", "gap", None, 0), (LAMP, "blamp", line, 0), (LAMP, "blamp", line, 1)]
            if lk.kind.value == "64d":
                for button in BLOCK_BUTTONS:
                    cells.append((" ", "gap", None, 0))
                    cells += [(ch, "button", Ref("block", lk.id, button), 0) for ch in button]
            at_left = self._free_side(lk.end) == "up"
            first = -len(cells) - 1 if at_left else 2
            placed = [(first + i, ch, role, ref, slot) for i, (ch, role, ref, slot) in enumerate(cells)
                      if role != "gap"]
            self.items.append(Item(self.line(self.nrows[lk.end]) - 1, self.pos_of(lk.end), placed, 2))

    def _platform_room(self) -> None:
        """Room along each platform's track for its id and at least ``MIN_DOORS`` doors on each doors' line,
        clear of the labels (signals, buttons) that stand at the track's two ends on that line and of the track's
        own diagonals, so the platform is drawn at every zoom."""
        st = self.st
        for p in st.model.platforms:
            track = platform_track(st, p.section)
            if track is None:
                continue
            a, b = st.track_ports[track]
            pa, pb = sorted((self.pos_of(a.node), self.pos_of(b.node)))
            if pa == pb:
                continue
            yt = self.line(self.rows[track])
            ends = sorted((a.node, b.node), key=self.pos_of)
            da, db = (abs(self.line(self.nrows[n]) - yt) for n in ends)
            for sd in p.screen_doors or []:
                line = yt - 1 if sd.side.value == "left" else yt + 1
                left = max([da] + [it.hi for it in self.items if it.line == line and it.pos == pa and it.priority])
                right = max([db] + [-it.lo for it in self.items if it.line == line and it.pos == pb and it.priority])
                # free cells run from col[pa] + left + 2 to col[pb] - right - 2, each with free neighbours
                self.pairs.append((pa, pb, left + right + 3 + len(p.id) + 1 + MIN_DOORS))

    def _free_side(self, node: str) -> str:
        """For a button at an end: the side of the line away from its track, i.e. where the line leads."""
        (_, track), *_ = self.st.node_tracks[node]
        lo, _hi = self.st.track_span(track)
        return "up" if self._p(lo) == self._p(self.st.node_at(node)) else "down"

    def _turnout_items(self) -> None:
        st = self.st
        for t in st.model.turnouts:
            y = self.line(self.nrows[t.id])
            rev = st.leg_track(t.id, "reverse")
            ry = self.line(self.rows[rev])
            a, b = st.track_ports[rev]
            other = b if a.node == t.id else a
            if ry == y:
                ry = self.line(self.nrows[other.node])
            if ry == y:  # a reverse leg along the turnout's own line (a double slip's slip road): mind the normal leg
                ry = self.line(self.rows[st.leg_track(t.id, "normal")])
            line = y - 1 if ry > y else y + 1
            legs_right = st.node_at(other.node) > st.node_at(t.id)
            text = t.id
            n = len(text) + 1  # the number and one cell for the lock mark
            ref = Ref("turnout", t.id)
            cells: list[tuple[int, str, str, Ref | None, int]] = []
            for i in range(n):
                dx = i if legs_right else i - n + 1
                ch, role = (text[i], "tlabel") if i < len(text) else (" ", "tmark")
                cells.append((dx, ch, role, ref, 0))
            self.items.append(Item(line, self.pos_of(t.id), cells, 2))

    def _variant_items(self) -> None:
        for b in self.st.model.buttons:
            if b.kind != "variant" or b.at not in self.st.tracks:
                continue
            y = self.line(self.rows[b.at])
            bands = {self.line(r) for r in self.rows.values()}
            y = next((c for c in (y + 1, y - 1) if c not in bands), y)
            p = self.index[self._p(self._track_mid(b.at))]
            ref: Ref | None = Ref("button", b.id, "variant")
            cells = [(i - len(b.id) // 2, ch, "button", ref, 0) for i, ch in enumerate(b.id)]
            self.items.append(Item(y, p, cells, 2))

    # ---- solving: longest paths over a DAG of lower bounds ----
    def columns(self) -> list[int]:
        n = len(self.positions)
        need: list[list[tuple[int, int]]] = [[] for _ in range(n)]  # j -> [(i, k)]
        for i, j, k in self.pairs:
            need[j].append((i, k))
        by_line: dict[int, list[Item]] = {}
        for it in self.items:
            by_line.setdefault(it.line, []).append(it)
        for items in by_line.values():
            for a in items:
                for b in items:
                    if a.pos < b.pos:
                        need[b.pos].append((a.pos, a.hi - b.lo + 2))
        left = [0] * n
        for it in self.items:
            left[it.pos] = max(left[it.pos], -it.lo)
        col = [0] * n
        for j in range(n):
            c = max(2 + left[j], self.lower[j])
            if j:
                c = max(c, col[j - 1] + self.min_gap[j])
            for i, k in need[j]:
                c = max(c, col[i] + k)
            col[j] = c
        return col


def build_layout(station: Station, lamps_per_aspect: dict[str, list[str]], *, lpr: int = 3, zoom: int = 1,
                 width: int = 0) -> Layout:
    """Lay the station out; with ``width`` the columns are stretched to fill that many cells where they fit."""
    b = _Builder(station, lamps_per_aspect, lpr, zoom)
    b.plan()
    col = b.columns()
    right = max((col[it.pos] + it.hi for it in b.items), default=0)
    natural = max(max(col, default=0), right) + 3
    if width > natural:
        factor = (width - 3) / (natural - 3)
        col = [c + math.floor((factor - 1) * c) for c in col]
    right = max((col[it.pos] + it.hi for it in b.items), default=0)
    w = max(max(col, default=0), right) + 3
    lines = [b.line(r) for r in list(b.rows.values()) + list(b.nrows.values())]
    h = max(max(lines, default=0), max((it.line for it in b.items), default=0)) + 2
    lay = Layout(w, h, [[None] * w for _ in range(h)], lpr=lpr, zoom=b.zoom)
    _paint(b, col, lay)
    return lay


# ---- painting -------------------------------------------------------------------------------------------------------
def _put(lay: Layout, x: int, y: int, g: Glyph) -> None:
    if not (0 <= y < lay.height and 0 <= x < lay.width):
        return
    old = lay.grid[y][x]
    if old is not None:
        if old.role == "diag" and g.role == "diag" and old.ch != g.ch:
            old.ch, old.also = CROSS, g.section
            return
        if old.role in ("band", "diag") and g.role in ("band", "diag"):
            if old.section != g.section:
                old.also = g.section
            return
        if ROLE_PRIORITY.get(old.role, 0) > ROLE_PRIORITY.get(g.role, 0):
            return
    lay.grid[y][x] = g
    if g.ref is not None and g.ref not in lay.targets:
        lay.targets[g.ref] = (x, y)


def _paint(b: _Builder, col: list[int], lay: Layout) -> None:
    st = b.st
    cx = {n: col[b.pos_of(n)] for n in st.node_tracks}
    cy = {n: b.line(b.nrows[n]) for n in st.node_tracks}
    runs: dict[str, list[tuple[int, int, int]]] = {}  # section -> horizontal runs (y, x0, x1)
    for tid, (pa, pb) in st.track_ports.items():
        sec = st.tracks[tid].section
        a, bb = (pa, pb) if cx[pa.node] <= cx[pb.node] else (pb, pa)
        xa, xb, ya, yb = cx[a.node], cx[bb.node], cy[a.node], cy[bb.node]
        yt = b.line(b.rows[tid])
        da, db = abs(ya - yt), abs(yb - yt)
        path: list[tuple[int, int, str]] = []
        for i in range(1, da + 1):
            path.append((xa + i, ya + (i if yt > ya else -i), DIAG_DOWN if yt > ya else DIAG_UP))
        x0, x1 = xa + da + 1, xb - db - 1
        path += [(x, yt, BAND) for x in range(x0, x1 + 1)]
        for i in range(db, 0, -1):
            path.append((xb - i, yb + (i if yt > yb else -i), DIAG_DOWN if yb > yt else DIAG_UP))
        if x1 >= x0:
            runs.setdefault(sec, []).append((yt, x0, x1))
        lay.track_cells[tid] = (st.node_at(a.node), st.node_at(bb.node), [(x, y) for x, y, _ in path])
        for k, (x, y, ch) in enumerate(path):
            leg = None
            if k == 0 and a.leg in ("normal", "reverse"):
                leg = (a.node, a.leg)
            if k == len(path) - 1 and bb.leg in ("normal", "reverse"):
                leg = (bb.node, bb.leg)
            role = "band" if ch == BAND else "diag"
            _put(lay, x, y, Glyph(ch, role, Ref("section", sec), sec, leg, track=tid))
            lay.section_cells.setdefault(sec, []).append((x, y))
    _paint_nodes(b, lay, cx, cy)
    for fp in st.model.fouling_points:
        track = fp.track if fp.track is not None else (fp.tracks or [""])[0]  # tied: drawn by the normal-side track
        x, y = col[b.index[b._p(fp.at)]], b.line(b.rows[track])
        g = lay.at(x, y)
        if g is not None and g.role == "band":
            _put(lay, x, y, Glyph(FOULING, "fp", Ref("fouling", fp.id), g.section))
    for sec, rs in runs.items():
        y, x0, x1 = max(rs, key=lambda r: r[2] - r[1])
        if x1 - x0 + 1 >= len(sec) + 4:
            start = x0 + (x1 - x0 + 1 - len(sec)) // 2
            for i, ch in enumerate(sec):
                _put(lay, start + i, y, Glyph(ch, "label", Ref("section", sec), sec))
    for it in sorted(b.items, key=lambda it: it.priority):
        if it.priority == 0:
            continue
        for dx, ch, role, ref, slot in it.cells:
            x = col[it.pos] + dx
            _put(lay, x, it.line, Glyph(ch, role, ref, slot=slot))
            if role == "lamp" and ref is not None:
                lay.lamp_slots.setdefault(ref.id, []).append((x, it.line))
        sig_refs = [c[3] for c in it.cells if c[2] == "lamp" and c[3] is not None]
        if sig_refs:
            step = 1 if it.cells[-1][0] > it.cells[0][0] else -1
            outer = col[it.pos] + (it.hi + 2 if step > 0 else it.lo - 2)
            # beyond the name on the same line, else on the next line out, under (over) the name
            beside = (col[it.pos] + (it.hi if step > 0 else it.lo), it.line - step, -step)
            for r in {r.id for r in sig_refs}:
                lay.countdown_at[r] = [(outer, it.line, step), beside]
    _paint_platforms(b, lay, cx, cy)


def _paint_nodes(b: _Builder, lay: Layout, cx: dict[str, int], cy: dict[str, int]) -> None:
    st = b.st
    dead = {dz.joint for dz in st.dead_zones}
    for n in st.node_tracks:
        x, y = cx[n], cy[n]
        if n in st.turnouts:
            sec = st.turnout_section[n]
            _put(lay, x, y, Glyph(BAND, "node", Ref("turnout", n), sec))
        elif n in st.joints:
            ch = DEAD_JOINT if n in dead else JOINT
            _put(lay, x, y, Glyph(ch, "joint", Ref("joint", n)))
        else:
            (_, track), *_ = st.node_tracks[n]
            lo, _hi = st.track_span(track)
            at_left = b._p(lo) == b._p(st.node_at(n))
            end = st.ends[n]
            buffer = end.kind.value == "buffer"
            ch = ("╟" if at_left else "╢") if buffer else ("«" if at_left else "»")
            _put(lay, x, y, Glyph(ch, "end", Ref("end", n)))


def _paint_platforms(b: _Builder, lay: Layout, cx: dict[str, int], cy: dict[str, int]) -> None:
    st = b.st
    for p in st.model.platforms:
        best = platform_track(st, p.section)
        if best is None:
            continue
        a, bb = st.track_ports[best]
        x0, x1 = sorted((cx[a.node], cx[bb.node]))
        y = b.line(b.rows[best])
        sides = p.screen_doors or []
        for sd in sides:
            # seen facing the down direction (towards the right): left is up the screen
            line = y - 1 if sd.side.value == "left" else y + 1
            free = [x for x in range(x0 + 2, x1 - 1) if lay.at(x, line) is None and lay.at(x - 1, line) is None
                    and lay.at(x + 1, line) is None]
            if len(free) < len(p.id) + 3:
                continue
            key = f"{p.id}:{sd.side.value}"
            ref = Ref("platform", p.id, key)
            span = _longest_run(free)
            n_doors = min(len(span) - len(p.id) - 1, MAX_DOORS)
            start = span[0] + (len(span) - (len(p.id) + 1 + n_doors)) // 2
            for i, ch in enumerate(p.id):
                _put(lay, start + i, line, Glyph(ch, "plabel", ref))
            for i in range(n_doors):
                _put(lay, start + len(p.id) + 1 + i, line, Glyph("▬", "door", ref, slot=i))


def _longest_run(xs: Iterable[int]) -> list[int]:
    best: list[int] = []
    cur: list[int] = []
    for x in xs:
        if cur and x != cur[-1] + 1:
            cur = []
        cur.append(x)
        if len(cur) > len(best):
            best = list(cur)
    return best
