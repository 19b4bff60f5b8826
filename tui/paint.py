"""Colours of the station diagram from the simulation's state, as a Chinese CBI display shows them.

Sections: a plain band when free, white when locked in a route, red when occupied (红光带). Turnouts: the number
green at normal, yellow at reverse, flashing red without indication; the leg not set is left open at the turnout;
a red mark for single lock (单锁), a red cross for single block (单封), a white mark for guide total lock. Signals:
the lamps actually lit in the field (a flashing USU lamp blinks with the flasher), a dark lamp of the commanded
aspect as a hollow circle; the countdown of a manual release beside the signal. Platform doors: green closed and
locked, yellow open, magenta bypassed (互锁解除). Trains: their name on the sections they occupy.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

from rich.style import Style

from liansuo.stations.printable import printable

from .layout import Glyph, Layout, Ref

if TYPE_CHECKING:
    from liansuo.simulation.sim import Simulation

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
    overlay: dict[tuple[int, int], tuple[str, Style]] = field(default_factory=dict)


def read_frame(sim: Simulation, lay: Layout) -> Frame:
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
    lost = any(pos is None for pos, _ in turnouts.values())
    return Frame(sections, turnouts, lamps, countdown, alarmed, doors, int(sim.t * 2) % 2 == 0 if lost else True)


def add_overlays(frame: Frame, sim: Simulation, lay: Layout) -> None:
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
        run = _longest_run(cells)
        arrow = ">" if tv.direction == "down" else "<"
        name = printable(tv.name)
        text = f"{name}{arrow}" if tv.direction == "down" else f"{arrow}{name}"
        text = text[: len(run)] if len(run) < len(text) else text
        start = (len(run) - len(text)) // 2
        for i, ch in enumerate(text):
            ov[run[start + i]] = (ch, S_TRAIN)


def _longest_run(cells: list[tuple[int, int]]) -> list[tuple[int, int]]:
    best: list[tuple[int, int]] = []
    cur: list[tuple[int, int]] = []
    for c in cells:
        if cur and (c[1] != cur[-1][1] or c[0] != cur[-1][0] + 1):
            cur = []
        cur.append(c)
        if len(cur) > len(best):
            best = list(cur)
    return best


def band_style(frame: Frame, g: Glyph) -> Style:
    state = frame.sections.get(g.section, "free")
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
