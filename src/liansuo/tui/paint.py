"""Colours of the station diagram from the simulation's state, as a Chinese CBI display shows them.

Sections: a plain band when free, white when locked in a route (in a turnout section only the branch the route runs
over), red when occupied (红光带: the whole section, as its track relay shows it). Turnouts: the number
green at normal, yellow at reverse, flashing red without indication; the leg not set is left open at the turnout;
a red mark for single lock (单锁), a red cross for single block (单封), a white mark for guide total lock. Signals:
the lamps actually lit in the field (a flashing USU lamp blinks with the flasher), a dark lamp of the commanded
aspect as a hollow circle; the countdown of a manual release beside the signal. Block lines: the departure and
arrival lamps yellow (asked for), green (given), red (a train on the line), hollow when dark. Platform doors: green
closed and locked, yellow open, magenta bypassed (互锁解除). Trains: their name at the head of the train (车次窗), the
arrow leading.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

from rich.style import Style

from liansuo.kit.printable import printable
from liansuo.tui.grid import Glyph, Layout, Ref

if TYPE_CHECKING:
    from liansuo.tui.consolesim import ConsoleSim

# by the lamp's colour (the rule set gives each lamp's colour and their order on the mast)
LAMP_COLOUR = {"green": "#00e050", "yellow": "#ffd700", "red": "#ff2020", "white": "#f4f4ff", "blue": "#2f6bff"}
BAND_COLOUR = {"free": "#5b7ea8", "locked": "#ffffff", "occupied": "#ff2a2a"}
SEVERITY = {"free": 0, "locked": 1, "occupied": 2}

S_DIM = Style(color="#7a7a7a")
S_JOINT = Style(color="#9a9a9a")
S_DEAD = Style(color="#e070e0", bold=True)
S_NAME = Style(color="#e8e8e8")
S_NAME_ALARM = Style(color="#ff4040", bold=True)
S_COUNT = Style(color="#ffd700", bold=True)
S_TRAIN = Style(color="#000000", bgcolor="#ffd700", bold=True)
S_BUTTON = {"train": Style(color="#000000", bgcolor="#10b050"), "shunt": Style(color="#000000", bgcolor="#b8b8c8"),
            "end": Style(color="#000000", bgcolor="#b8b8c8"), "exit": Style(color="#000000", bgcolor="#10b050"),
            "variant": Style(color="#000000", bgcolor="#d0a020")}
S_PRESSED = Style(color="#000000", bgcolor="#ffff40", bold=True)
S_MODE_TARGET = Style(underline=True)
S_CURSOR = Style(reverse=True, underline=True)
S_TURNOUT = {"normal": Style(color="#00e050", bold=True), "reverse": Style(color="#ffd700", bold=True)}
S_LOST_ON = Style(color="#ffffff", bgcolor="#ff2020", bold=True)
S_LOST_OFF = Style(color="#ff2020", bold=True)
S_MARK = {"locked": Style(color="#ff2020", bold=True), "blocked": Style(color="#ff2020", bold=True),
          "guide": Style(color="#ffffff", bold=True)}
# a block line's state -> the colours of its departure (发车) and arrival (接车) lamps, '' dark: yellow asked for,
# green given, red a train on the line (64D: requested / asked, permitted / accepted, departed / arriving, arrived;
# station block: outbound, departed / inbound, arriving)
BLOCK_LAMPS = {"idle": ("", ""), "requested": ("yellow", ""), "permitted": ("green", ""), "departed": ("red", ""),
               "asked": ("", "yellow"), "accepted": ("", "green"), "arriving": ("", "red"), "arrived": ("", "red"),
               "outbound": ("green", ""), "inbound": ("", "green")}
S_DOOR = {"closed": Style(color="#00e050"), "open": Style(color="#ffd700", bold=True),
          "bypass": Style(color="#e070e0", bold=True)}


@dataclass
class Frame:
    """The state one redraw shows, read once from the simulation."""

    sections: dict[str, str]
    turnouts: dict[str, tuple[str | None, str]]  # position and mark (locked, blocked, guide or '')
    lamps: dict[str, list[tuple[str, bool]]]  # signal -> [(lamp colour, lit)] from the joint outwards
    countdown: dict[str, int]
    alarmed: set[str]
    doors: dict[str, str]
    flash: bool
    blocks: dict[str, str] = field(default_factory=dict)  # block line -> its state (view.block_line)
    # section -> the tracks of it that the routes held run over: a locked turnout section lights those only (the
    # branch its turnouts lie on for the route, as a 6502 panel and a CBI display do); a section with none of its
    # tracks on a route's path (locked by an overlap, say) lights whole
    lit: dict[str, set[str]] = field(default_factory=dict)
    overlay: dict[tuple[int, int], tuple[str, Style]] = field(default_factory=dict)


def read_frame(sim: ConsoleSim, lay: Layout) -> Frame:
    view = sim.view
    st = sim.station
    sections = {s.id: s.state for s in view.sections(list(st.sections))}
    turnouts = {t.id: (t.position, t.mark) for t in view.turnouts()}
    lamps: dict[str, list[tuple[str, bool]]] = {}
    colours = sim.rules.aspects.colours
    mast = list(colours)  # the rule set lists the lamps in their order on the mast
    for sig in st.model.signals:
        have = [lamp.value for lamp in sig.lamps]
        lit = sim.field.lit_lamps(sig.id)
        want = [lamp for lamp in sim.rules.lamps.get(view.aspect(sig.id), []) if lamp in have]
        shown = sorted(set(want) | (lit & set(have)), key=lambda x: mast.index(x) if x in mast else 9)
        lamps[sig.id] = [(colours.get(lamp, ""), lamp in lit) for lamp in shown]
    countdown: dict[str, int] = {}
    for r in view.routes():
        if r.state == "time_release" and r.release_at is not None:
            countdown[r.signal] = max(0, int(r.release_at - sim.t + 0.999))
    alarmed = {s.id for s in view.signals() if s.alarmed}
    doors: dict[str, str] = {}
    for key, d in sim.field.doors.items():
        doors[key] = "bypass" if d.pdqcj else "open" if d.is_open else "closed"
    blocks = {lk.id: state for lk in st.model.links if (state := view.block_line(lk.id)) is not None}
    lost = any(pos is None for pos, _ in turnouts.values())
    return Frame(sections, turnouts, lamps, countdown, alarmed, doors, int(sim.t * 2) % 2 == 0 if lost else True,
                 blocks=blocks, lit=routes_lit(sim))


def routes_lit(sim: ConsoleSim) -> dict[str, set[str]]:
    """Per section, the tracks the routes held run over (their paths, from the interlocking table)."""
    lit: dict[str, set[str]] = {}
    tracks = sim.station.tracks
    for r in sim.view.routes():
        route = sim.table.routes.get(r.id)
        if route is None:
            continue
        for t in route.path.tracks:
            lit.setdefault(tracks[t].section, set()).add(t)
    return lit


def add_overlays(frame: Frame, sim: ConsoleSim, lay: Layout) -> None:
    """Countdowns beside their signals and train names over the sections they occupy."""
    ov = frame.overlay
    for sig, secs in frame.countdown.items():
        text = f"{secs}s"
        for x, y, step in lay.countdown_at.get(sig, []):
            xs = range(x, x + len(text)) if step > 0 else range(x - len(text) + 1, x + 1)
            if xs.start >= 0 and xs.stop <= lay.width and 0 <= y < lay.height and \
                    all(lay.at(cx, y) is None and (cx, y) not in ov for cx in xs):
                for cx, ch in zip(xs, text, strict=True):
                    ov[(cx, y)] = (ch, S_COUNT)
                break
    for tv in sim.train_views():
        cells = sorted({c for s in tv.sections for c in lay.section_cells.get(s, [])}, key=lambda c: (c[1], c[0]))
        if not cells:
            continue
        down = tv.direction == "down"
        arrow = ">" if down else "<"
        name = printable(tv.name)
        text = f"{name}{arrow}" if down else f"{arrow}{name}"
        runs = _runs(cells)
        head = head_cell(lay, tv.head_track, tv.head_m)
        run = next((r for r in runs if head in r and len(r) >= len(text)), None)
        if run is None or head is None:  # the head on a diagonal or beyond the station: the longest run, its head end
            run = max(runs, key=len)
            head = run[-1] if down else run[0]
        text = text[: len(run)] if len(run) < len(text) else text
        # the arrow on the head's cell, the name trailing behind it, kept within the run
        at = run.index(head) - (len(text) - 1 if down else 0)
        start = max(0, min(len(run) - len(text), at))
        for i, ch in enumerate(text):
            ov[run[start + i]] = (ch, S_TRAIN)


def head_cell(lay: Layout, track: str | None, m: float | None) -> tuple[int, int] | None:
    """The cell of the diagram where a train's head (its leading wheelset, at ``m`` along ``track``) is drawn."""
    if track is None or m is None or track not in lay.track_cells:
        return None
    left, right, cells = lay.track_cells[track]
    if not cells:
        return None
    share = 0.5 if right == left else min(1.0, max(0.0, (m - left) / (right - left)))
    return cells[round(share * (len(cells) - 1))]


def _runs(cells: list[tuple[int, int]]) -> list[list[tuple[int, int]]]:
    """Cells sorted by line then column, cut into horizontal runs of neighbouring cells."""
    out: list[list[tuple[int, int]]] = []
    for c in cells:
        if out and c[1] == out[-1][-1][1] and c[0] == out[-1][-1][0] + 1:
            out[-1].append(c)
        else:
            out.append([c])
    return out


def band_style(frame: Frame, g: Glyph) -> Style:
    state = frame.sections.get(g.section, "free")
    if state == "locked" and g.track and g.track not in frame.lit.get(g.section, {g.track}):
        state = "free"  # the branch of a locked turnout section the route does not run over
    if g.also:
        other = frame.sections.get(g.also, "free")
        if SEVERITY[other] > SEVERITY[state]:
            state = other
    return Style(color=BAND_COLOUR[state], bold=state != "free")


def glyph(frame: Frame, g: Glyph, pressed: set[Ref]) -> tuple[str, Style]:
    """The character and style of one static cell now."""
    role = g.role
    if role in ("band", "diag", "node", "fp", "label"):
        if g.leg is not None:
            pos = frame.turnouts.get(g.leg[0], (None, ""))[0]
            if pos is not None and pos != g.leg[1]:
                return " ", S_DIM
        return g.ch, band_style(frame, g)
    if role in ("tlabel", "tmark"):
        assert g.ref is not None
        pos, mark = frame.turnouts.get(g.ref.id, (None, ""))
        if role == "tmark":
            if not mark:
                return " ", S_DIM
            return ("×" if mark == "blocked" else "■"), S_MARK[mark]
        if pos is None:
            return g.ch, S_LOST_ON if frame.flash else S_LOST_OFF
        return g.ch, S_TURNOUT[pos]
    if role == "lamp":
        assert g.ref is not None
        shown = frame.lamps.get(g.ref.id, [])
        if g.slot >= len(shown):
            return " ", S_DIM
        colour, lit = shown[g.slot]
        return ("●", Style(color=LAMP_COLOUR.get(colour, "white"), bold=True)) if lit else ("○", S_DIM)
    if role == "blamp":
        assert g.ref is not None
        colour = BLOCK_LAMPS.get(frame.blocks.get(g.ref.id, "idle"), ("", ""))[g.slot]
        return ("●", Style(color=LAMP_COLOUR[colour], bold=True)) if colour else ("○", S_DIM)
    if role == "signame":
        assert g.ref is not None
        return g.ch, S_NAME_ALARM if g.ref.id in frame.alarmed else S_NAME
    if role == "button":
        assert g.ref is not None
        if g.ref in pressed:
            return g.ch, S_PRESSED
        return g.ch, S_BUTTON.get(g.ref.sub, S_BUTTON["shunt"])
    if role == "joint":
        return g.ch, S_DEAD if g.ch == "╏" else S_JOINT
    if role == "door":
        assert g.ref is not None
        state = frame.doors.get(g.ref.sub, "closed")
        return ("▭" if state == "open" else "▬"), S_DOOR[state]
    if role == "plabel":
        return g.ch, S_NAME
    return g.ch, S_DIM
