"""Cross-checks a schema-valid station file must pass: the tracks' (:mod:`.trackchecks`: references resolve,
geometry is consistent, sections are bounded by joints or ends, turnout legs connect, the network is connected), then
signals standing at joints facing a real direction, buttons, markers, platforms on station tracks, lines, overlaps
and overrides. Each problem becomes a diagnostic at the offending key."""

from __future__ import annotations

from collections import Counter
from itertools import pairwise

from liansuo.kit.fit import metres, number
from liansuo.kit.source import Diagnostic, Source
from liansuo.stations.schema import (
    Button,
    Direction,
    EndKind,
    Lamp,
    LinkKind,
    Overlap,
    SectionRole,
    SignalKind,
    StationFile,
)
from liansuo.stations.station import Port, parse_port
from liansuo.stations.trackchecks import TrackChecks


class _Checker(TrackChecks):
    """Every cross-check, in order: the tracks' (:class:`~.trackchecks.TrackChecks`), then the signals', buttons',
    markers', platforms', lines' and overrides'."""

    def run(self) -> list[Diagnostic]:
        self.unique_ids()
        if self.errors:
            return self.errors
        self.node_positions = {e.id: e.at for e in self.m.ends}
        self.node_positions.update({j.id: j.at for j in self.m.joints})
        self.node_positions.update({t.id: t.at for t in self.m.turnouts})
        self.ports_resolve()
        if self.errors:
            return self.errors
        self.node_usage()
        self.geometry()
        if self.errors:
            return self.errors
        self.sections()
        self.pairs()
        self.drives()
        self.signals()
        self.standalone_buttons()
        self.fouling_points()
        self.diamonds()
        self.profile()
        self.markers()
        self.platforms()
        self.links()
        self.overlaps_and_overrides()
        if not self.errors:
            self.connected()
        return self.errors

    def signals(self) -> None:
        joints = self._joint_ids
        ends = {e.id: e for e in self.m.ends}
        sections = {x.id for x in self.m.sections}
        for k, s in enumerate(self.m.signals):
            if s.at in ends:
                e = ends[s.at]
                if e.kind is not EndKind.boundary:
                    self.err(("signals", k, "at"), f"signal {s.id} stands at buffer stop '{s.at}'",
                             "signals stand at joints (or at a boundary end facing into the station)")
                    continue
                a, b = self._ports[0][self._ports[1][Port(s.at)][0]]
                far = self.node_positions[b.node if a.node == s.at else a.node]
                into_down = far > e.at
                if into_down != (s.direction is Direction.down):
                    self.err(("signals", k, "direction"),
                             f"signal {s.id} at boundary '{s.at}' faces {s.direction.value}, out of the station",
                             "a signal at a boundary governs movements into the station")
            elif s.at not in joints:
                self.err(("signals", k, "at"), f"signal {s.id} stands at '{s.at}', which is not a joint",
                         "every signal stands at an insulated or electrical joint listed under 'joints:'")
            lamps = set(s.lamps)
            if s.kind is SignalKind.shunting:
                if Lamp.B not in lamps or not ({Lamp.A, Lamp.H} & lamps):
                    self.err(("signals", k, "lamps"), f"shunting signal {s.id} needs a moon-white B and a blue A "
                             "(or red H) lamp", "e.g. 'lamps: [A, B]'")
            elif Lamp.H not in lamps:
                self.err(("signals", k, "lamps"), f"{s.kind.value} signal {s.id} has no red H lamp",
                         "train signals show H when closed; add H to 'lamps'")
            if s.usu and not ({Lamp.U, Lamp.U2} <= lamps):
                self.err(("signals", k, "usu"), f"signal {s.id} may show USU but lacks a U or U2 lamp",
                         "USU needs the yellow (U) and second yellow (U2) lamps")
            if s.usu and s.kind not in (SignalKind.home, SignalKind.route):
                self.err(("signals", k, "usu"), f"only home and route signals show USU, not {s.kind.value} {s.id}",
                         "remove 'usu: true'")
            if Button.train in s.buttons and s.kind in (SignalKind.shunting, SignalKind.block):
                self.err(("signals", k, "buttons"), f"{s.kind.value} signal {s.id} cannot have a train button",
                         "train buttons belong to home, starting and route signals; a shunting signal takes "
                         "'buttons: [shunt]'")
            if s.kind is SignalKind.shunting and Button.shunt not in s.buttons and s.buttons:
                self.err(("signals", k, "buttons"), f"shunting signal {s.id} needs a shunt button",
                         "write 'buttons: [shunt]'")
            for m, sec in enumerate(s.approach or []):
                if sec not in sections:
                    self.err(("signals", k, "approach", m), f"signal {s.id}: approach section '{sec}' not declared",
                             "name a section listed under 'sections:'")

    def standalone_buttons(self) -> None:
        nodes = {j.id for j in self.m.joints} | {e.id for e in self.m.ends}
        tracks = {t.id for t in self.m.tracks}
        for k, b in enumerate(self.m.buttons):
            ok = b.at in tracks if b.kind == "variant" else b.at in nodes
            if not ok:
                where = "a track" if b.kind == "variant" else "a joint or an end"
                self.err(("buttons", k, "at"), f"button {b.id} ({b.kind}) is at '{b.at}', which is not {where}",
                         "variant buttons stand on a track; exit and end buttons at a joint or an end")

    def profile(self) -> None:
        """Each stretch of the profile runs forwards, and no two stretches overlap."""
        spans = sorted((g.start, g.end, k) for k, g in enumerate(self.m.profile))
        for g_start, g_end, k in spans:
            if g_end <= g_start:
                self.err(("profile", k, "to"), f"profile stretch {k + 1} runs from {metres(g_start)} to "
                                               f"{metres(g_end)}",
                         "'to' is the higher position: write each stretch with from < to")
        for (a0, a1, ka), (b0, _, kb) in pairwise(spans):
            if b0 < a1 and a1 > a0:
                self.err(("profile", kb, "from"), f"profile stretch {kb + 1} ({metres(b0)} on) overlaps stretch "
                         f"{ka + 1} (to {metres(a1)})", "give each part of the line one gradient")

    def markers(self) -> None:
        tracks = {t.id: t for t in self.m.tracks}
        for k, mk in enumerate(self.m.markers):
            t = tracks.get(mk.track)
            if t is None:
                self.err(("markers", k, "track"), f"marker {mk.id} is on unknown track '{mk.track}'",
                         "name a track declared under 'tracks:'")
                continue
            xa = self.node_positions[parse_port(t.start).node]
            xb = self.node_positions[parse_port(t.end).node]
            if not min(xa, xb) <= mk.at <= max(xa, xb):
                self.err(("markers", k, "at"), f"marker {mk.id} at {metres(mk.at)} is off track '{t.id}' "
                         f"({number(min(xa, xb))}-{metres(max(xa, xb))})", "a marker lies on its track, between its "
                         "two ends")

    def platforms(self) -> None:
        sections = {s.id: s for s in self.m.sections}
        for k, p in enumerate(self.m.platforms):
            s = sections.get(p.section)
            if s is None:
                self.err(("platforms", k, "section"), f"platform {p.id} is at unknown section '{p.section}'",
                         "name a station-track section listed under 'sections:'")
            elif s.role is not SectionRole.station_track:
                self.err(("platforms", k, "section"),
                         f"platform {p.id} is at section '{p.section}', which is not a station track",
                         "platforms and their screen doors stand at station tracks ('role: station_track')")
            sides = [d.side for d in p.screen_doors]
            if len(sides) != len(set(sides)):
                self.err(("platforms", k, "screen_doors"), f"platform {p.id} lists a side twice",
                         "give each side (left, right) at most once")

    def links(self) -> None:
        ends = {e.id: e for e in self.m.ends}
        sections = {s.id for s in self.m.sections}
        roles_of = {s.id: s.role for s in self.m.sections}
        for k, lk in enumerate(self.m.links):
            e = ends.get(lk.end)
            if e is None or e.kind is not EndKind.boundary:
                self.err(("links", k, "end"), f"link {lk.id} leaves from '{lk.end}', which is not a boundary end",
                         "block links leave the station at an end of 'kind: boundary'")
            for m, sec in enumerate(lk.sections):
                if sec not in sections:
                    self.err(("links", k, "sections", m), f"link {lk.id}: section '{sec}' is not declared",
                             "name a section listed under 'sections:'")
            if lk.bidirectional and lk.kind is not LinkKind.automatic:
                self.err(("links", k, "bidirectional"), f"link {lk.id} is a {lk.kind.value} line; only automatic "
                         "block lines have a running direction to change (改方)",
                         "remove 'bidirectional', or make the line 'kind: automatic'")
            if lk.kind is LinkKind.station and not lk.sections:
                self.err(("links", k, "kind"), f"station-to-station block line {lk.id} names no sections",
                         "list the line's sections under 'sections:' (those the axle counters prove clear), "
                         "nearest the station first")
            if lk.kind is LinkKind.semi_auto_64d and not lk.sections:
                self.err(("links", k, "kind"), f"64D semi-automatic block line {lk.id} names no sections: its block "
                         "machine sees our train depart by its departure section",
                         "name the departure section (the first a departing train occupies) under 'sections:'")
            if lk.kind is LinkKind.automatic and not lk.sections:
                self.err(("links", k, "kind"), f"automatic block line {lk.id} names no sections: the interlocking "
                         "reads the line's block sections to let a train depart or be received",
                         "list the line's sections under 'sections:' (the departure or approach section first)")
            roles = {roles_of[sec] for sec in lk.sections if sec in roles_of}
            if lk.kind is LinkKind.automatic and roles >= {SectionRole.approach, SectionRole.departure}:
                self.err(("links", k, "sections"), f"link {lk.id} mixes approach and departure sections, so its "
                         "running direction is unclear", "an automatic line runs one way: list its approach "
                         "sections (towards the station) or its departure sections (away from it)")

    def overlaps_and_overrides(self) -> None:
        signals = {s.id for s in self.m.signals}
        sections = {s.id for s in self.m.sections}
        turnouts = {t.id for t in self.m.turnouts}
        buttons = {b.id for b in self.m.buttons}
        by_end: dict[str, list[Overlap]] = {}
        for o in self.m.overlaps:
            by_end.setdefault(o.end_signal, []).append(o)
        ending = Counter((o.end_signal, o.end) for o in self.m.overlaps)
        for k, o in enumerate(self.m.overlaps):
            if o.end_signal not in signals:
                self.err(("overlaps", k, "end_signal"), f"overlap at unknown signal '{o.end_signal}'",
                         "name the signal at the end of the receiving route, as listed under 'signals:'")
            for m, sec in enumerate(o.sections):
                if sec not in sections:
                    self.err(("overlaps", k, "sections", m), f"overlap section '{sec}' is not declared",
                             "name a section listed under 'sections:'")
            for m, t in enumerate(o.turnouts):
                if t.turnout not in turnouts:
                    self.err(("overlaps", k, "turnouts", m), f"overlap turnout '{t.turnout}' is not declared",
                             "name a turnout listed under 'turnouts:'")
            if o.end is not None and o.end not in signals and o.end not in buttons:
                self.err(("overlaps", k, "end"), f"overlap end button '{o.end}' is not a signal or button",
                         "name the signal or button the overlap ends at (its end button)")
            alternatives = by_end[o.end_signal]
            if len(alternatives) > 1 and o.end is None:
                self.err(("overlaps", k), f"signal {o.end_signal} has {len(alternatives)} overlaps; each alternative "
                         "needs its 'end' (the overlap's end button the operator presses)",
                         "add 'end: BUTTON' to every overlap of this signal; the first listed is the basic one")
            if o.end is not None and ending[(o.end_signal, o.end)] > 1:
                self.err(("overlaps", k, "end"), f"signal {o.end_signal} has two overlaps ending at '{o.end}'",
                         "alternative overlaps end at different buttons")
        for m, f in enumerate(self.m.overrides.fouling):
            if f.section not in sections:
                self.err(("overrides", "fouling", m, "section"), f"override names unknown section '{f.section}'",
                         "name a section listed under 'sections:'")
        for key in ("protection", "remove_protection"):
            for m, p in enumerate(getattr(self.m.overrides, key)):
                if p.turnout not in turnouts:
                    self.err(("overrides", key, m, "turnout"), f"override names unknown turnout '{p.turnout}'",
                             "name a turnout listed under 'turnouts:'")

def cross_check(model: StationFile, src: Source) -> list[Diagnostic]:
    return _Checker(model, src).run()
