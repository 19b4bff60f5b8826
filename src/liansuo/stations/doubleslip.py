"""Double slips (复式交分道岔): each entry of the station file's ``double_slips`` becomes the plain elements every
later layer already knows, right after the schema and before the cross-checks.

A double slip ``E`` with ``slips: [[a, b], [c, d]]``, centred at ``at`` and ``length`` long::

    a.point ━ a ━━━━━━━━━━━━━━━━━━ b ━ b.point      slip road a-b: a.reverse to b.reverse
               ╲              ╱
                 ╲          ╱
                   ╲      ╱                         straight roads a-d and c-b (a, b, c, d normal),
                      ╳                             crossing at the diamond E, at ``at``
                   ╱      ╲
                 ╱          ╲
               ╱              ╲
    c.point ━ c ━━━━━━━━━━━━━━━━━━ d ━ d.point      slip road c-d: c.reverse to d.reverse
          at - length/2      at + length/2

becomes

* turnouts ``a`` and ``c`` at ``at - length/2``, their points towards lower positions, and ``b`` and ``d`` at
  ``at + length/2``, their points towards higher positions; ``a/b`` and ``c/d`` are crossover pairs (双动道岔);
* four inner tracks in ``section``, each ``length`` long: the straight roads ``E_a-d`` (a.normal to d.normal) and
  ``E_c-b`` (c.normal to b.normal), the slip roads ``E_a-b`` (a.reverse to b.reverse) and ``E_c-d`` (c.reverse to
  d.reverse);
* the diamond ``E`` of the two straight roads.

The user's own tracks attach to the four points (``a.point`` ...), as to any turnout. An error about a generated
element points at the double slip's entry in the file: the expansion gives the generated elements the marks of the
entry's keys.
"""

from __future__ import annotations

from collections.abc import Iterator

from liansuo.kit.source import Diagnostic, Loc, Mark, Source
from liansuo.stations.schema import Diamond, DoubleSlip, StationFile, Track, Turnout
from liansuo.stations.station import parse_port

KEY = "double_slips"


# ---- what one double slip is made of --------------------------------------------------------------------------
def slip_ends(slip: DoubleSlip) -> Iterator[tuple[str, bool, int, int]]:
    """The four turnouts of ``slip`` as (turnout, at the low end?, slip road index, index in the road)."""
    for p, road in enumerate(slip.slips):
        for q, turnout in enumerate(road):
            yield turnout, q == 0, p, q


def inner_tracks(slip: DoubleSlip) -> dict[str, tuple[str, str]]:
    """The four inner tracks of ``slip``, id -> (from, to): the two straight roads first, then the two slip roads."""
    (a, b), (c, d) = slip.slips
    e = slip.id
    return {
        f"{e}_{a}-{d}": (f"{a}.normal", f"{d}.normal"),
        f"{e}_{c}-{b}": (f"{c}.normal", f"{b}.normal"),
        f"{e}_{a}-{b}": (f"{a}.reverse", f"{b}.reverse"),
        f"{e}_{c}-{d}": (f"{c}.reverse", f"{d}.reverse"),
    }


def _ends_at(slip: DoubleSlip) -> tuple[float, float]:
    """Positions of the low-end and the high-end turnouts."""
    return slip.at - slip.length / 2, slip.at + slip.length / 2


# ---- checks before the expansion ----------------------------------------------------------------------------------
class _Checker:
    """What must hold before the double slips can be expanded: each a new id, four new turnout numbers, inner track
    ids that are free, a declared section, and the user's tracks attached only at its four points, in its section,
    leading away from it."""

    def __init__(self, model: StationFile, src: Source) -> None:
        self.m = model
        self.src = src
        self.errors: list[Diagnostic] = []

    def err(self, loc: Loc, message: str, hint: str) -> None:
        self.errors.append(self.src.diagnostic(loc, message, hint))

    def run(self) -> list[Diagnostic]:
        self.ids()
        self.turnouts()
        self.sections()
        if self.errors:  # the names below are made from the turnouts' ids
            return self.errors
        self.pairs()
        self.tracks()
        if not self.errors:
            self.points()
        return self.errors

    def ids(self) -> None:
        seen = {d.id: f"diamond '{d.id}'" for d in self.m.diamonds}
        for i, s in enumerate(self.m.double_slips):
            if s.id in seen:
                self.err((KEY, i, "id"), f"double slip id '{s.id}' is already used by {seen[s.id]}",
                         "every double slip needs its own id, and its diamond takes that id too: rename one of them")
            else:
                seen[s.id] = f"double slip '{s.id}'"

    def turnouts(self) -> None:
        owner = {e.id: f"end '{e.id}'" for e in self.m.ends}
        owner.update({j.id: f"joint '{j.id}'" for j in self.m.joints})
        owner.update({t.id: f"turnout {t.id} under 'turnouts:'" for t in self.m.turnouts})
        for i, s in enumerate(self.m.double_slips):
            mine: set[str] = set()
            for t, _, p, q in slip_ends(s):
                loc = (KEY, i, "slips", p, q)
                if t in mine:
                    self.err(loc, f"double slip {s.id} names turnout {t} twice",
                             "its four ends are four turnouts: slips: [[LOW, HIGH], [LOW, HIGH]], e.g. [[21, 23], "
                             "[25, 27]]")
                elif t in owner:
                    self.err(loc, f"double slip {s.id}: turnout id '{t}' is already used by {owner[t]}",
                             "a double slip declares its four turnouts itself: remove the other declaration, or "
                             "give the double slip's turnouts numbers of their own")
                mine.add(t)
            owner.update(dict.fromkeys(mine - owner.keys(), f"double slip {s.id}"))

    def pairs(self) -> None:
        used = {t.pair: f"turnout {t.id}" for t in self.m.turnouts if t.pair}
        for i, s in enumerate(self.m.double_slips):
            for p, (low, high) in enumerate(s.slips):
                name = f"{low}/{high}"
                if name in used:
                    self.err((KEY, i, "slips", p), f"double slip {s.id}: crossover pair '{name}' is already used by "
                             f"{used[name]}", "give the double slip's turnouts numbers of their own")
                used.setdefault(name, f"double slip {s.id}")

    def tracks(self) -> None:
        taken = {t.id: "a track under 'tracks:'" for t in self.m.tracks}
        for i, s in enumerate(self.m.double_slips):
            for tid in inner_tracks(s):
                if tid in taken:
                    self.err((KEY, i, "id"), f"double slip {s.id}: the id '{tid}' of its inner track is already used "
                             f"by {taken[tid]}", "rename that track: a double slip ID names its four inner tracks "
                             "ID_LOW-HIGH ('liansuo docs station-format')")
                taken.setdefault(tid, f"double slip {s.id}")

    def sections(self) -> None:
        known = {s.id for s in self.m.sections}
        for i, s in enumerate(self.m.double_slips):
            if s.section not in known:
                self.err((KEY, i, "section"), f"double slip {s.id} lies in section '{s.section}', which is not "
                         "declared", "add it under 'sections:', or fix the spelling")

    def points(self) -> None:
        """The user's tracks attach to a double slip only at its points, lie in its section and lead away from it
        (from the low-end points towards lower positions, from the high-end points towards higher ones)."""
        ends = {t: (s, low) for s in self.m.double_slips for t, low, _, _ in slip_ends(s)}
        at = {e.id: e.at for e in self.m.ends} | {j.id: j.at for j in self.m.joints}
        at |= {t.id: t.at for t in self.m.turnouts}
        at |= {t: _ends_at(s)[0 if low else 1] for t, (s, low) in ends.items()}
        for k, t in enumerate(self.m.tracks):
            for key, ref, other in (("from", t.start, t.end), ("to", t.end, t.start)):
                port = parse_port(ref)
                if port.node not in ends:
                    continue
                s, low = ends[port.node]
                if port.leg != "point":
                    points = ", ".join(f"{x}.point" for x, _, _, _ in slip_ends(s))
                    self.err(("tracks", k, key), f"track '{t.id}' attaches to '{ref}', inside double slip {s.id}",
                             f"attach tracks to a double slip only at its four points: {points}")
                    continue
                if t.section != s.section:
                    self.err(("tracks", k, "section"), f"track '{t.id}' at {ref} is in section '{t.section}', but "
                             f"double slip {s.id} lies in section '{s.section}'", "a double slip lies inside one "
                             "section: the tracks at its four points belong to it too, up to the joints beyond")
                far = at.get(parse_port(other).node)
                if far is not None and (far >= at[port.node] if low else far <= at[port.node]):
                    self.err(("tracks", k, key), f"track '{t.id}' leaves {ref} ({at[port.node]:g} m) towards "
                             f"{'higher' if low else 'lower'} positions, into double slip {s.id}",
                             f"the tracks at the low-end points ({s.slips[0][0]}, {s.slips[1][0]}) lead towards "
                             f"lower positions, those at the high-end points ({s.slips[0][1]}, {s.slips[1][1]}) "
                             "towards higher ones")


def double_slip_errors(model: StationFile, src: Source) -> list[Diagnostic]:
    """Everything wrong with the double slips of a schema-valid file, each at the offending key."""
    return _Checker(model, src).run() if model.double_slips else []


# ---- the expansion ------------------------------------------------------------------------------------------------
def _rows(slip: DoubleSlip, tracks: list[Track]) -> tuple[float | None, float | None]:
    """Schematic rows of the two slip roads: those of the tracks at their points; where only one side has a row, the
    first slip road lies a row above the second."""
    at_point = {p.node: t.row for t in tracks if t.row is not None
                for p in map(parse_port, (t.start, t.end)) if p.leg == "point"}
    one, two = (next((at_point[x] for x in road if x in at_point), None) for road in slip.slips)
    if one is None and two is not None:
        one = two - 1
    if two is None and one is not None:
        two = one + 1
    return one, two


def _turnouts(slip: DoubleSlip) -> Iterator[tuple[Turnout, int, int]]:
    """The four turnouts, each with its place in ``slips``."""
    low_at, high_at = _ends_at(slip)
    for t, low, p, q in slip_ends(slip):
        pair = "/".join(slip.slips[p])
        yield Turnout(id=t, at=low_at if low else high_at, number=slip.number, machine=slip.machine, pair=pair,
                      diverging_speed_kmh=slip.diverging_speed_kmh), p, q


def _tracks(slip: DoubleSlip, rows: tuple[float | None, float | None]) -> list[Track]:
    one, two = rows
    middle = (one + two) / 2 if one is not None and two is not None else None
    road_rows = (middle, middle, one, two)
    return [Track.model_validate({"id": tid, "from": start, "to": end, "section": slip.section, "row": row})
            for (tid, (start, end)), row in zip(inner_tracks(slip).items(), road_rows, strict=True)]


def _marked(src: Source, loc: Loc, entry: Loc, keys: dict[str, Loc]) -> dict[Loc, Mark]:
    """Marks for a generated element at ``loc``: the entry's own for the element, its keys' for the element's."""
    out = {loc: src.mark(entry)}
    out.update({(*loc, name): src.mark((*entry, *sub)) for name, sub in keys.items()})
    return out


def expand_double_slips(model: StationFile, src: Source) -> tuple[StationFile, Source]:
    """The model with every double slip's turnouts, inner tracks and diamond added after the file's own (whose
    indices, and so whose marks, stay as they were), and a source that marks each generated element at the double
    slip's entry. Call only when :func:`double_slip_errors` found nothing."""
    if not model.double_slips:
        return model, src
    turnouts, tracks, diamonds = list(model.turnouts), list(model.tracks), list(model.diamonds)
    marks: dict[Loc, Mark] = {}
    for i, slip in enumerate(model.double_slips):
        entry: Loc = (KEY, i)
        same = {"at": ("at",), "number": ("number",), "machine": ("machine",),
                "diverging_speed_kmh": ("diverging_speed_kmh",)}
        for turnout, p, q in _turnouts(slip):
            marks |= _marked(src, ("turnouts", len(turnouts)), entry, {"id": ("slips", p, q), "pair": ("slips", p),
                                                                        **same})
            turnouts.append(turnout)
        for track in _tracks(slip, _rows(slip, model.tracks)):
            marks |= _marked(src, ("tracks", len(tracks)), entry, {"id": ("id",), "section": ("section",)})
            tracks.append(track)
        straight = list(inner_tracks(slip))[:2]
        marks |= _marked(src, ("diamonds", len(diamonds)), entry, {"id": ("id",), "at": ("at",)})
        diamonds.append(Diamond(id=slip.id, tracks=straight, at=slip.at))
    expanded = model.model_copy(update={"turnouts": turnouts, "tracks": tracks, "diamonds": diamonds})
    return expanded, Source(src.file, src.data, {**src.marks, **marks}, src.key_marks)
