"""Fuzz kind ``console``: random sequences of what an operator can do to the console, played through Textual's
pilot on a bundled station (``liansuo fuzz console --budget N``; ``tests/test_tui_fuzz.py`` runs a few).

A sample is a station, a window size and a few dozen events: keys (every binding of the console, the dialogs and the
command palette, and stray ones), commands typed or pasted into the command bar (real command lines with their
numbers and ids mutated: nan, inf, -1, 0, 1e308, 2**31, long words, control characters, markup), clicks on the
diagram's elements and on random cells (single, or two in one burst as a hasty double click), the command palette,
the dialogs (confirmations, menus, the instructor password, help, the question before quitting), resizes from 1x1 to
a very large window, and short waits in which the clock runs. Input goes in as a terminal sends it: keys and mouse
buttons to the app, which makes the clicks itself.

:func:`attempt` plays one sample and returns ``"accepted"`` when the console survived it (closing it by answering
yes to the quit question is surviving). Any exception is a defect: one that ends the console escapes from Textual's
test harness, and one the console caught and showed in its alarm panel (:mod:`tui.incidents`) is raised again here.
"""

from __future__ import annotations

import asyncio
import functools
import tempfile
import unicodedata
from dataclasses import dataclass
from typing import Any

from hypothesis import strategies as st
from textual import events

from liansuo.circuits.faults import KINDS
from liansuo.stations.loader import load
from liansuo.tui.app import ConsoleApp
from liansuo.tui.diagram import CLICKABLE

NAME = "console"
STATIONS = ("jiaopei", "gaotie", "depot")
PASSWORD = "pw"  # the instructor password of the samples that have one
EVENTS = (4, 24)  # events per sample, fewest and most (each takes some 10 to 50 ms through the pilot)
LONGEST_WAIT_S = 0.3  # a wait lets the clock tick (8 per second) and a long run advance

# Every key the console and its dialogs bind, and a few they do not.
KEYS = (
    "colon", "space", "full_stop", "greater_than_sign", "less_than_sign", "escape", "a", "f1", "question_mark", "f2",
    "c", "r", "f", "g", "G", "n", "v", "l", "u", "b", "B", "o", "P", "y", "left", "right", "up", "down",
    "shift+left", "shift+right", "shift+up", "shift+down", "plus", "minus", "0", "enter", "tab", "shift+tab",
    "backspace", "home", "end", "left_square_bracket", "right_square_bracket", "ctrl+p", "ctrl+q", "ctrl+c",
    "pageup", "pagedown", "delete", "x", "9",
)
EXTREMES = ("nan", "inf", "-inf", "-1", "0", "1e308", str(2**31), "1e-300", "1e9", "-0", "0x10", "")
NOISE = ("\x1b[2J", "\x1b]0;pwned\x07", "[bold red]x", "[/x]", "道岔", "'unclosed", "\t", "\x00", "X" * 300,
         "1" * 40, "#", "=", "at")
DURATIONS = ("250ms", "1s", "30s", "3min", "2h", "168h", "1e400s", "0s", "-5s", "nan", "99999999h", "1.5min")


# ---- the sample ----------------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Key:
    key: str


@dataclass(frozen=True)
class Type:
    """Characters typed one by one (the focused widget takes them: the command bar, the palette, a password)."""

    text: str


@dataclass(frozen=True)
class Paste:
    text: str


@dataclass(frozen=True)
class Click:
    """A click at a fraction of the window (so it lands inside whatever size the window has then)."""

    fx: float
    fy: float
    button: int = 1
    twice: bool = False  # two clicks in one burst, before the console has handled the first


@dataclass(frozen=True)
class ClickElement:
    """A click on the diagram's n-th clickable element (a signal's button, a turnout, a section ...)."""

    n: int
    twice: bool = False


@dataclass(frozen=True)
class Resize:
    width: int
    height: int


@dataclass(frozen=True)
class Wait:
    seconds: float


Event = Key | Type | Paste | Click | ClickElement | Resize | Wait


@dataclass(frozen=True)
class Sample:
    station: str
    size: tuple[int, int]
    paused: bool
    password: str | None
    events: tuple[Event, ...]


# ---- generating samples --------------------------------------------------------------------------------------------
@functools.cache
def _ids(station: str) -> dict[str, tuple[str, ...]]:
    s = load(station)
    return {"signal": tuple(s.signals), "section": tuple(s.sections), "turnout": tuple(s.turnouts),
            "button": tuple(s.buttons) or tuple(s.signals), "track": tuple(s.tracks)}


def _commands(station: str) -> st.SearchStrategy[str]:
    """Real command lines of this station, then mutated."""
    ids = _ids(station)
    sig, sec, tur = (st.sampled_from(ids[k]) for k in ("signal", "section", "turnout"))
    num = st.one_of(st.sampled_from(EXTREMES), st.integers(-10, 500).map(str))
    name = st.sampled_from(("T1", "T2", "S9"))
    kind = st.sampled_from(sorted(KINDS))
    fault_param = st.tuples(st.sampled_from(sorted({p for k in KINDS.values() for p in k.params} | {"at"})),
                            num).map(lambda kv: f"{kv[0]}={kv[1]}")
    train_param = st.tuples(st.sampled_from(("length", "axles", "vmax", "back", "front", "mode", "dir", "kind")),
                            st.one_of(num, st.sampled_from(("signal", "auto", "up", "down", "emu", "shunter")))
                            ).map(lambda kv: f"{kv[0]}={kv[1]}")
    base = st.one_of(
        st.tuples(st.sampled_from(("route", "shunt")), sig, sig).map(" ".join),
        st.tuples(st.sampled_from(("cancel", "release", "guide", "reopen", "guide-lock")), sig).map(" ".join),
        st.tuples(st.sampled_from(("fault-release", "occupy", "vacate", "axle-reset")), sec).map(" ".join),
        st.tuples(st.just("throw"), tur, st.sampled_from(("normal", "reverse", "sideways"))).map(" ".join),
        st.tuples(st.sampled_from(("lock", "unlock", "block", "unblock")), tur).map(" ".join),
        st.tuples(st.just("fault"), kind, st.one_of(sec, sig, tur), st.lists(fault_param, max_size=2)).map(
            lambda t: " ".join([t[0], t[1], t[2], *t[3]])),
        st.tuples(st.just("repair"), kind, st.one_of(sec, sig, tur)).map(" ".join),
        st.tuples(st.just("train"), name, st.just("at"), sec, st.lists(train_param, max_size=3)).map(
            lambda t: " ".join([t[0], t[1], t[2], t[3], *t[4]])),
        st.tuples(st.just("drive"), name, num).map(" ".join),
        st.tuples(st.sampled_from(("stop", "auto", "reverse")), name).map(" ".join),
        st.tuples(st.just("run"), st.sampled_from(DURATIONS)).map(" ".join),
        st.tuples(st.just("expect"), st.sampled_from(("signal", "section", "refused", "alarm")), sig).map(" ".join),
        st.sampled_from(("restart", "power-up-release", "faults", "quit", "exit", "seek 5s", "help", "")),
    )
    return st.tuples(base, st.lists(st.tuples(st.integers(0, 9), st.sampled_from(NOISE + EXTREMES)), max_size=2)
                     ).map(_mutate)


def _mutate(parts: tuple[str, list[tuple[int, str]]]) -> str:
    line, edits = parts
    words = line.split(" ")
    for where, what in edits:
        i = where % (len(words) + 1)
        if what in EXTREMES and i < len(words):
            words[i] = what  # a number where a word was
        elif what == "" and i < len(words):
            del words[i]  # a word dropped
        else:
            words.insert(i, what)
    return " ".join(words)


def _events(station: str) -> st.SearchStrategy[list[Event]]:
    line = _commands(station)
    key = st.sampled_from(KEYS).map(Key)
    frac = st.floats(0, 0.999)
    click = st.builds(Click, frac, frac, st.sampled_from((1, 1, 1, 3)), st.booleans())
    element = st.builds(ClickElement, st.integers(0, 10_000), st.booleans())
    size = st.one_of(st.sampled_from(((1, 1), (2, 1), (1, 2), (3, 3), (10, 4), (80, 24), (120, 36), (400, 120))),
                     st.tuples(st.integers(1, 250), st.integers(1, 80)))
    resize = size.map(lambda wh: Resize(*wh))
    wait = st.floats(0, LONGEST_WAIT_S).map(lambda s: Wait(round(s, 3)))
    answer = st.sampled_from(("y", "n", "escape", "enter", "tab", "ctrl+q")).map(Key)
    one: st.SearchStrategy[list[Event]] = st.one_of(
        key.map(lambda e: [e]), click.map(lambda e: [e]), element.map(lambda e: [e]), resize.map(lambda e: [e]),
        wait.map(lambda e: [e]),
        line.map(lambda text: [Key("colon"), Type(text), Key("enter")]),  # a command typed
        line.map(lambda text: [Key("colon"), Paste(text), Key("enter")]),  # a command pasted
        st.tuples(st.sampled_from(("", "quit", "keys", "theme", "screenshot", "max", "zz")),  # the command palette
                  st.sampled_from(("enter", "escape", "down", "tab"))).map(
            lambda t: [Key("ctrl+p"), Type(t[0]), Key(t[1])]),
        st.tuples(st.sampled_from(("P", "question_mark", "f2", "ctrl+q", "f1")), answer).map(
            lambda t: [Key(t[0]), t[1]]),  # a dialog opened and answered
        st.tuples(element, st.lists(answer, max_size=2)).map(lambda t: [t[0], *t[1]]),  # an element's menu
        st.tuples(st.just("f2"), st.sampled_from((PASSWORD, "wrong", "")), answer).map(
            lambda t: [Key(t[0]), Type(t[1]), Key("enter"), t[2]]),  # the instructor password
    )
    return st.lists(one, min_size=1, max_size=EVENTS[1]).map(lambda chunks: [e for c in chunks for e in c][:EVENTS[1]])


def strategy() -> st.SearchStrategy[Sample]:
    """One console session: a bundled station, a window, and a few dozen operator events."""
    return st.sampled_from(STATIONS).flatmap(lambda station: st.builds(
        Sample,
        st.just(station),
        st.sampled_from(((80, 24), (120, 36), (60, 20), (200, 60))),
        st.booleans(),
        st.sampled_from((None, PASSWORD)),
        _events(station).filter(lambda ev: len(ev) >= EVENTS[0]).map(tuple),
    ))


# ---- playing a sample ----------------------------------------------------------------------------------------------
def attempt(sample: Sample) -> str:
    """Play ``sample`` on a fresh console; "accepted" when it survived (an exception is a defect)."""
    asyncio.run(_play(sample))
    return "accepted"


async def _play(sample: Sample) -> None:
    app = ConsoleApp(sample.station, paused=sample.paused, instructor_password=sample.password)
    with tempfile.TemporaryDirectory(prefix="liansuo-fuzz-") as folder:
        # the palette's Screenshot writes an SVG into the current folder; here it goes into a folder thrown away
        setattr(app, "deliver_screenshot", functools.partial(app.deliver_screenshot, path=folder))  # noqa: B010
        async with app.run_test(size=sample.size) as pilot:
            for event in sample.events:
                if app.return_code is not None or not app.is_running:
                    break  # the quit question was answered yes: the console closed as asked
                await _event(pilot, app, event)
            if app.return_code is None and app.is_running:
                await pilot.pause()
    if app.incidents.items:
        raise app.incidents.items[0].error


async def _event(pilot: Any, app: ConsoleApp, event: Event) -> None:
    if isinstance(event, Key):
        _post(app, events.Key(event.key, _character(event.key)))
    elif isinstance(event, Type):
        for ch in event.text:
            name = _key_name(ch)
            _post(app, events.Key(name, ch) if name else events.Paste(ch))
            await pilot.pause(0)
    elif isinstance(event, Paste):
        _post(app, events.Paste(event.text))
    elif isinstance(event, Click):
        width, height = app.size
        if width and height:
            at = (int(event.fx * width), int(event.fy * height))
            _clicks(app, at, event.button, 2 if event.twice else 1)
    elif isinstance(event, ClickElement):
        where = _element_at(app, event.n)
        if where is not None:
            _clicks(app, where, 1, 2 if event.twice else 1)
    elif isinstance(event, Resize):
        await pilot.resize_terminal(event.width, event.height)
        return
    elif isinstance(event, Wait):
        await pilot.pause(event.seconds)
        return
    await pilot.pause(0)


def _post(app: ConsoleApp, message: events.Event) -> None:
    app.post_message(message)


def _clicks(app: ConsoleApp, at: tuple[int, int], button: int, times: int) -> None:
    """Mouse button down and up, ``times`` over in one burst: the app turns each pair into a click."""
    x, y = at
    for _ in range(times):
        for kind in (events.MouseDown, events.MouseUp):
            _post(app, kind(None, x, y, 0, 0, button, False, False, False, screen_x=x, screen_y=y))


def _element_at(app: ConsoleApp, n: int) -> tuple[int, int] | None:
    """Where the diagram's n-th clickable element is on the screen now (scrolled into view), if it is."""
    diagram = app.diagram  # with a dialog open, the click lands on the dialog where the element is underneath
    lay = diagram.layout_
    if lay is None:
        return None
    refs = sorted((r for r in lay.targets if r.kind in CLICKABLE), key=lambda r: (r.kind, r.id, r.sub))
    if not refs:
        return None
    ox, oy = diagram.offset_of(refs[n % len(refs)])
    x, y = diagram.region.x + ox, diagram.region.y + oy
    width, height = app.size
    return (x, y) if 0 <= x < width and 0 <= y < height else None


def _key_name(ch: str) -> str | None:
    """The key a terminal reports for a typed character (as Textual names it), None for one it cannot type."""
    if ch.isalnum() and len(ch.encode()) == 1:
        return ch
    if ch == " ":
        return "space"
    try:
        return unicodedata.name(ch).lower().replace("-", "_").replace(" ", "_")
    except ValueError:  # a control character: it arrives pasted
        return None


_CHARACTERS = {"space": " ", "colon": ":", "full_stop": ".", "greater_than_sign": ">", "less_than_sign": "<",
               "question_mark": "?", "plus": "+", "minus": "-", "left_square_bracket": "[",
               "right_square_bracket": "]", "enter": "\r", "tab": "\t", "escape": "\x1b", "backspace": "\x7f"}


def _character(key: str) -> str | None:
    if len(key) == 1:
        return key
    return _CHARACTERS.get(key)


def describe(sample: Sample) -> str:
    """One line per event, for a report of a failing sample."""
    head = (f"station {sample.station}, window {sample.size[0]}x{sample.size[1]}, "
            f"{'paused' if sample.paused else 'running'}, password {sample.password!r}")
    return "\n".join([head, *(repr(e) for e in sample.events)])
