"""Completion for the command bar, from the simulation's command language: its commands and their usage lines.

The usage line of a command names what each argument is (``SIGNAL``, ``SECTION``, ``TURNOUT``, ``normal|reverse``,
``[key=value ...]``); the candidates are the station's ids of that kind. A route (``route``, ``shunt``, ``guide``)
is completed from the interlocking table: the starts of its routes, then the ends (and variant buttons) the table
has from the start typed.
"""

from __future__ import annotations

import re
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from liansuo.tui.consolesim import ConsoleSim

_EXPECT = {
    "signal": ("SIGNAL", "L|LL|LU|U|UU|USU|H|HB|B|A"),
    "route": ("START", "END", "setting|locked|open|guide|closed|in_use|time_release|released"),
    "turnout": ("TURNOUT", "normal|reverse|none", "locked"),
    "section": ("SECTION", "free|locked|occupied"),
    "block-line": ("LINK", "idle|requested|permitted|departed|asked|accepted|arriving|arrived|outbound|inbound"),
    "code": ("SECTION", "L|LU|U|UU|UUS|HU|HB|none"),
}


def placeholders(usage: str) -> list[str]:
    """``'route START END [VIA ...]'`` -> ``['START', 'END', 'VIA...']`` (a trailing ``...`` repeats)."""
    first = usage.split(" | ")[0]
    words = first.split()[1:]
    out: list[str] = []
    for w in words:
        w = w.strip("[]")
        if not w:
            continue
        if w.startswith("..."):
            if out:
                out[-1] += "..."
            continue
        out.append(w)
    return out


def _ids(sim: ConsoleSim, kind: str, words: list[str]) -> list[str]:
    st = sim.station
    kind = kind.rstrip(".")
    if kind in ("SIGNAL",):
        return list(st.signals)
    if kind in ("START", "END", "VIA"):
        return list(st.signals) + list(st.buttons)
    if kind == "SECTION":
        return list(st.sections)
    if kind == "TURNOUT":
        return list(st.turnouts) + list(st.pairs)
    if kind == "THROAT":
        return list(sim.table.throats)
    if kind == "LINK":
        return [lk.id for lk in st.model.links]
    if kind == "PLATFORM":
        return [p.id for p in st.model.platforms]
    if kind == "TRACK":
        return list(st.tracks)
    if kind == "DURATION":
        return ["1s", "5s", "10s", "30s", "1min", "3min"]
    if kind == "KIND":
        from liansuo.circuits.faults import KINDS

        return list(KINDS)
    if kind == "TARGET" and len(words) > 1:
        return fault_targets(sim, words[1])
    if kind == "NAME":
        return [t.name for t in sim.train_views()] + list(sim.parked)
    if kind.startswith("key=value") and words and words[0] == "fault" and len(words) > 1:
        from liansuo.circuits.faults import KINDS

        k = KINDS.get(words[1])
        return [f"{p}=" for p in k.params] if k else []
    if "=" in kind:  # kind=freight|emu ...
        key, _, values = kind.partition("=")
        return [f"{key}={v}" for v in values.split("|")] if "|" in values else [f"{key}="]
    if "|" in kind:
        return kind.split("|")
    if kind.islower():
        return [kind]  # a literal word such as 'at'
    return []


def fault_targets(sim: ConsoleSim, kind_name: str) -> list[str]:
    """What a fault kind can be applied to at this station."""
    from liansuo.circuits.faults import KINDS

    st = sim.station
    kind = KINDS.get(kind_name)
    if kind is None:
        return []
    t = kind.target
    if t == "section":
        if kind_name == "capacitor":
            return [s for s, sec in st.sections.items() if sec.type.value == "zpw2000a"]
        if kind_name == "axle-miscount":
            return [s for s, sec in st.sections.items() if sec.type.value == "axle_counter"]
        return list(st.sections)
    if t == "turnout":
        return list(st.turnouts)
    if t == "joint-or-turnout":
        return list(st.joints) + list(st.turnouts)
    if t == "signal":
        if kind_name == "flasher":
            return [s.id for s in st.model.signals if s.usu]
        return list(st.signals)
    if t == "platform":
        out = []
        for p in st.model.platforms:
            if p.screen_doors:
                out.append(p.id)
                out += [f"{p.id}:{d.side.value}" for d in p.screen_doors]
        return out
    return []


ROUTE_KINDS = {"route": "train", "shunt": "shunt", "guide": "train"}  # commands naming a route by its buttons


def route_words(sim: ConsoleSim, kind: str, words: list[str]) -> list[str]:
    """The next button of a route of the interlocking table after ``words`` (its start, then the variant buttons
    chosen): the starts of the table's routes of ``kind``; after a start, the ends of its routes from there and their
    next variant buttons."""
    routes = [r for r in sim.table.routes.values() if r.kind == kind]
    if not words:
        return [r.start for r in routes]
    start, via = words[0], tuple(words[1:])
    out = []
    for r in routes:
        if r.start != start or tuple(r.via[: len(via)]) != via:
            continue
        if len(r.via) == len(via):
            out.append(r.end)
        else:
            out.append(r.via[len(via)])
    return out


def candidates(sim: ConsoleSim, text: str) -> list[str]:
    """Candidates for the last (partial) word of ``text``."""
    words = text.split(" ")
    partial = words[-1]
    done = [w for w in words[:-1] if w]
    language = sim.language
    if not done:
        pool = sorted(language)
    else:
        cmd = done[0]
        if cmd == "expect":
            if len(done) == 1:
                pool = [*_EXPECT, "refused", "accepted", "alarm", "no-alarm"]
            else:
                shape = _EXPECT.get(done[1], ())
                i = len(done) - 2
                pool = _ids(sim, shape[i], done) if i < len(shape) else []
        elif cmd in ROUTE_KINDS and (cmd != "guide" or len(done) > 1):  # guide's SIGNAL: any, by its usage
            pool = route_words(sim, ROUTE_KINDS[cmd], done[1:])
        else:
            slots = placeholders(language.usage(cmd))
            i = len(done) - 1
            if i < len(slots):
                slot = slots[i]
            elif slots and slots[-1].endswith("..."):
                slot = slots[-1]
            else:
                slot = ""
            if "=" in slot:  # optional key=value parameters come in any order
                used = {w.partition("=")[0] for w in done if "=" in w}
                pool = [c for sl in slots[i:] + slots[:i] if "=" in sl for c in _ids(sim, sl, done)
                        if c.partition("=")[0] not in used]
            else:
                pool = _ids(sim, slot, done) if slot else []
    hits = [c for c in pool if c.startswith(partial)]
    if not hits:
        low = partial.lower()
        hits = [c for c in pool if c.lower().startswith(low)]
    return sorted(dict.fromkeys(hits), key=_natural)


def _natural(s: str) -> tuple[object, ...]:
    return tuple(int(p) if p.isdigit() else p for p in re.split(r"(\d+)", s))


def complete(sim: ConsoleSim, text: str) -> tuple[str, list[str]]:
    """Tab: the line completed as far as it is unambiguous, and the candidates."""
    hits = candidates(sim, text)
    head, _, partial = text.rpartition(" ")
    prefix = f"{head} " if head else ""
    if len(hits) == 1:
        word = hits[0]
        return prefix + word + ("" if word.endswith("=") else " "), hits
    if hits:
        common = hits[0]
        for h in hits[1:]:
            while not h.startswith(common):
                common = common[:-1]
        if len(common) > len(partial):
            return prefix + common, hits
    return text, hits


def example_route(sim: ConsoleSim) -> str:
    """A command line for hints and help, in the station's own ids: the train route of its interlocking table with the
    fewest turnouts reversed (the first such; ``route X XI`` on jiaopei), else such a shunting route (``shunt D1 D7``
    on the depot)."""
    routes = list(sim.table.routes.values())
    kind = "train" if any(r.kind == "train" for r in routes) else "shunt"
    routes = [r for r in routes if r.kind == kind]
    if not routes:
        return "route START END"
    best = min(routes, key=lambda r: (sum(pos.value == "reverse" for _, pos in r.path.turnouts), len(r.via)))
    return " ".join(["route" if kind == "train" else "shunt", best.start, *best.via, best.end])
