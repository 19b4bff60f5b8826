"""Station-design rules (joint stagger, dead-zone spacing, fouling clearance, coding length, carriers) as warnings.

The numbers come from the rule set (``rules/NAME/design.yaml``); each warning states the measured figure and the limit.
"""

from __future__ import annotations

from functools import cached_property
from itertools import pairwise

from liansuo.kit.fit import metres
from liansuo.kit.source import Diagnostic, Loc
from liansuo.rules import DesignRules, load_rules
from liansuo.stations.schema import CircuitType, Direction, FoulingPoint, JointKind, Signal, SignalKind
from liansuo.stations.station import Station


def design_rules() -> DesignRules:
    """The design rules of the default rule set."""
    return load_rules().design


def min_coded_length(speed_kmh: float, rules: DesignRules | None = None) -> float:
    """L >= t * v + margin: the shortest section on which the cab signal can read a code (51.25 m at 45 km/h)."""
    r = rules or design_rules()
    return r.cab_code_min_time_s * speed_kmh / 3.6 + r.cab_code_margin_m


class _Warner:
    def __init__(self, station: Station, rules: DesignRules | None = None) -> None:
        self.st = station
        self.r = rules or design_rules()
        self.out: list[Diagnostic] = []
        self._indices: dict[str, dict[str, int]] = {}  # key -> id -> index, made on the first warning under the key

    def warn(self, loc: Loc, message: str, hint: str = "") -> None:
        src = self.st.source
        if src is None:
            self.out.append(Diagnostic("<station>", 1, 1, message, hint, "warning"))
        else:
            self.out.append(src.diagnostic(loc, message, hint, severity="warning"))

    def loc(self, key: str, ident: str, field: str | None = None) -> Loc:
        index = self._indices.get(key)
        if index is None:
            index = self._indices[key] = {}
            for i, x in enumerate(getattr(self.st.model, key)):
                index.setdefault(getattr(x, "id", ""), i)
        i = index[ident]
        return (key, i, field) if field else (key, i)

    def run(self) -> list[Diagnostic]:
        self.stagger()
        self.spacing()
        self.fouling()
        self.coding()
        self.carriers()
        self.lengths()
        return self.out

    def _at_turnout_section(self, joint: str) -> bool:
        return any(s in self.st.turnout_section.values() for s in self.st.joint_sections(joint))

    def _crossing(self, joint: str) -> str:
        """The diamond crossing (菱形交叉: the middle of a scissors crossover or a double slip, or a stand-alone one)
        whose track ``joint`` bounds; '' when none."""
        for _, track in self.st.node_tracks.get(joint, []):
            for diamond, _ in self.st.crossings.get(track, []):
                return diamond
        return ""

    def stagger(self) -> None:
        """Dead zones longer than the rules allow (Chen Bo 2023): a stagger over 2.5 m (5 m inside an old turnout
        section); at a diamond crossing, where the standard scissors design itself leaves one, longer than that
        design's 6.3 m; in a tuning area, over 5 m. A dead zone within these limits is the accepted design."""
        for dz in self.st.dead_zones:
            j = self.st.joints[dz.joint]
            if j.kind is JointKind.electrical:
                if dz.length > self.r.tuning_dead_zone_max_m:
                    self.warn(self.loc("joints", j.id), f"dead zone of {metres(dz.length)} in tuning area '{j.id}' "
                              f"exceeds {metres(self.r.tuning_dead_zone_max_m)}", "check the tuning-unit positions")
                continue
            diamond = self._crossing(j.id)
            if diamond:
                if round(dz.length, 6) > self.r.dead_zone_long_m:  # 4573.3 - 4567 is 6.3 and a hair
                    self.warn(self.loc("joints", j.id, "at2"),
                              f"joint '{j.id}': the {metres(dz.length)} dead zone at crossing '{diamond}' is longer "
                              f"than the standard scissors design's {metres(self.r.dead_zone_long_m)}: wheelsets "
                              "standing in it carry traction return current into the next section (a flashing red "
                              "band) and let the cab read the next section's carrier (a lost code, an ATP brake)",
                              "put the crossing's insulated joints where the standard design has them (维规 13.3.3: "
                              "as short a dead zone as the crossing allows)")
                continue
            limit = self.r.joint_stagger_max_turnout_m if self._at_turnout_section(j.id) else self.r.joint_stagger_max_m
            if round(dz.length, 6) > limit:
                self.warn(self.loc("joints", j.id, "at2"),
                          f"joint '{j.id}': rail joints staggered {metres(dz.length)} (limit {metres(limit)}); the "
                          "dead zone can hide a wheelset",
                          "move one rail's joint to bring the stagger within the limit")

    def spacing(self) -> None:
        zones = {dz.joint: dz for dz in self.st.dead_zones}
        for sec, tracks in self.st.section_tracks.items():
            bounding = set()
            for t in tracks:
                for p in self.st.track_ports[t]:
                    if p.node in zones:
                        bounding.add(p.node)
            ordered = sorted(bounding, key=lambda j: self.st.joints[j].at)
            for a, b in pairwise(ordered):
                za, zb = zones[a], zones[b]
                gap = zb.start - za.end
                if gap <= 0 or gap >= self.r.dead_zone_spacing_min_m:
                    continue
                if (gap >= self.r.dead_zone_spacing_relaxed_m and za.length < self.r.dead_zone_short_m
                        and zb.length < self.r.dead_zone_short_m):
                    continue
                self.warn(self.loc("joints", b, "at"),
                          f"section '{sec}': dead zones at joints '{a}' and '{b}' are only {metres(gap)} apart "
                          f"(need >= {metres(self.r.dead_zone_spacing_min_m)}, or >= "
                          f"{metres(self.r.dead_zone_spacing_relaxed_m)} when both are under "
                          f"{metres(self.r.dead_zone_short_m)})",
                          "a short vehicle could stand in both dead zones at once and vanish from the interlocking")

    def _tracks_near(self, joint: str, reach: float) -> set[str]:
        """The tracks a movement can reach from ``joint`` within ``reach`` metres either way, through any turnout: a
        fouling point elsewhere (a parallel track at the same kilometre) is no concern of the signal there."""
        st, at = self.st, self.st.joints[joint].at
        seen: set[str] = set()
        todo = [t for _, t in st.node_tracks[joint]]
        while todo:
            track = todo.pop()
            if track in seen:
                continue
            seen.add(track)
            for port in st.track_ports[track]:
                if port.node != joint and abs(st.node_at(port.node) - at) < reach:
                    todo += [t for _, t in st.node_tracks[port.node] if t not in seen]
        return seen

    def fouling(self) -> None:
        """A train stopped at a starting signal must stand clear of the fouling point ahead of it. A fouling point tied
        to its turnout is measured along that turnout's legs; one in the short form (a bare track) against the
        starting signals that can reach its track within a short distance."""
        clearance = self.r.fouling_clearance_emu_m if self.st.model.emu else self.r.fouling_clearance_m
        for fp in self.st.model.fouling_points:
            if fp.turnout is None:
                self._fouling_short(fp, clearance)
                continue
            t_at = self.st.turnouts[fp.turnout].at
            for chain in self.st.fouling_legs(fp).values():
                joint = chain[0][1] if chain else None
                if joint not in self.st.joints:
                    continue
                j_at = self.st.joints[joint].at
                towards = Direction.down if t_at > j_at else Direction.up
                for sig in self.st.signals_at(joint):
                    if sig.kind is SignalKind.starting and sig.direction is towards:
                        self._fouling_warn(fp.id, sig.id, abs(j_at - t_at) - abs(fp.at - t_at), clearance)

    _FOULING_REACH_M = 50.0  # how far either way of a starting signal a fouling point in the short form is looked for

    @cached_property
    def _starting_near(self) -> dict[str, list[Signal]]:
        """Track -> the starting signals (in file order) that reach it within the fouling reach: each signal's
        neighbourhood walked once, not once per fouling point."""
        out: dict[str, list[Signal]] = {}
        for sig in self.st.model.signals:
            if sig.kind is SignalKind.starting and sig.at in self.st.joints:
                for track in self._tracks_near(sig.at, self._FOULING_REACH_M):
                    out.setdefault(track, []).append(sig)
        return out

    def _fouling_short(self, fp: FoulingPoint, clearance: float) -> None:
        reach = self._FOULING_REACH_M
        for sig in self._starting_near.get(fp.track or "", []):
            j = self.st.joints[sig.at]
            d = (fp.at - j.at) * (1.0 if sig.direction is Direction.down else -1.0)
            if -reach < d < clearance:
                self._fouling_warn(fp.id, sig.id, d, clearance)

    def _fouling_warn(self, fp: str, sig: str, d: float, clearance: float) -> None:
        if d >= clearance:
            return
        self.warn(self.loc("fouling_points", fp, "at"),
                  (f"fouling point {fp} is {metres(d)} ahead of the joint of starting signal {sig} (need >= "
                   f"{metres(clearance)})" if d >= 0 else
                   f"the joint of starting signal {sig} lies inside the fouling limit: fouling point {fp} is "
                   f"{metres(-d)} behind it (need >= {metres(clearance)} ahead)"),
                  "a train stopped at the signal could foul the throat; move the joint or the signal back")

    def coding(self) -> None:
        """A coded section must be long enough for the cab signal to read its code at the speed trains pass it:
        the section's own ``speed_kmh``; else line speed on the main line (the straight way from one end of the
        station to the other); else, on a side line, the highest diverging speed of the turnouts that lead onto it
        (a train reaches it over one of them), or the rule set's ``coding_speed_kmh`` where none does."""
        main = self._main_line()
        for s in self.st.model.sections:
            if not s.coded:
                continue
            v, why = self._coding_speed(s.id, s.speed_kmh, main)
            need = min_coded_length(v, self.r)
            have = self.st.section_span(s.id)
            if have < need:
                self.warn(self.loc("sections", s.id), f"coded section '{s.id}' is {metres(have)} long; at {v:g} km/h "
                          f"({why}) the cab signal needs >= {metres(need)} ({self.r.cab_code_min_time_s:g} s * v + "
                          f"{metres(self.r.cab_code_margin_m)})", "lengthen the section, or give it the 'speed_kmh' "
                          "trains really pass it at")

    def _coding_speed(self, section: str, own: float | None, main: set[str]) -> tuple[float, str]:
        st = self.st
        line = st.model.line_speed_kmh
        if own is not None:
            return own, "its speed_kmh"
        if any(t in main for t in st.section_tracks[section]):
            return line, "line speed on the main line"
        onto = self._onto.get(section, [])
        if not onto:
            return self.r.coding_speed_kmh, "no turnout leads onto it"
        fastest = max(onto, key=lambda t: st.diverging_speed_kmh(t, self.r))
        v = min(line, st.diverging_speed_kmh(fastest, self.r))
        return v, f"side line, over turnout {fastest}"

    @cached_property
    def _onto(self) -> dict[str, list[str]]:
        """Section -> the turnouts that lead onto it: it is their own section, or their reverse leg reaches it across
        joints. Worked out once for every turnout, not once per coded section."""
        st = self.st
        out: dict[str, list[str]] = {}
        for t in st.turnouts:
            reached = {st.tracks[tr].section for tr, _ in st.leg_chain(t, "reverse")}
            own = st.turnout_section.get(t)
            if own is not None:
                reached.add(own)
            for sec in reached:
                out.setdefault(sec, []).append(t)
        return out

    def _main_line(self) -> set[str]:
        """The tracks of the straight way from each boundary (facing turnouts normal), to the far end of the line."""
        st = self.st
        out: set[str] = set()
        for end in st.ends.values():
            if end.kind.value != "boundary":
                continue
            (_, track), = st.node_tracks[end.id]
            node = end.id
            while track not in out:
                out.add(track)
                far = next(p for p in st.track_ports[track] if p.node != node)
                if far.node in st.joints:
                    lo, hi = st.joint_tracks(far.node)
                    track, node = (hi if lo == track else lo), far.node
                elif far.node in st.turnouts:
                    track, node = st.leg_track(far.node, "normal" if far.leg == "point" else "point"), far.node
                else:
                    break
        return out

    def carriers(self) -> None:
        for j in self.st.model.joints:
            a, b = self.st.joint_sections(j.id)
            sa, sb = self.st.sections[a], self.st.sections[b]
            if (sa.type is CircuitType.zpw2000a and sb.type is CircuitType.zpw2000a and sa.carrier and sb.carrier
                    and sa.carrier.split("-")[0] == sb.carrier.split("-")[0]):
                self.warn(self.loc("joints", j.id), f"sections '{a}' and '{b}' on both sides of joint '{j.id}' "
                          f"use the same carrier frequency ({sa.carrier}, {sb.carrier})",
                          "alternate carriers along a line: 1700/2300 on the down line, 2000/2600 on the up line")
            if j.kind is JointKind.electrical:
                ta = j.tuning_area_m or self.r.tuning_area_m
                if abs(ta - self.r.tuning_area_m) > self.r.tuning_area_tolerance_m:
                    self.warn(self.loc("joints", j.id, "tuning_area_m"), f"tuning area of joint '{j.id}' is "
                              f"{metres(ta)} (standard {metres(self.r.tuning_area_m)}, tolerance "
                              f"{metres(self.r.tuning_area_tolerance_m)})",
                              "check the positions of the two tuning units")

    def lengths(self) -> None:
        for s in self.st.model.sections:
            length = self.st.section_span(s.id)  # what the live field solves (and holds down past the range)
            if s.type is CircuitType.phase25hz and length > self.r.phase25hz_max_length_m:
                self.warn(self.loc("sections", s.id), f"25 Hz section '{s.id}' is {metres(length)} long "
                          f"(limit about {metres(self.r.phase25hz_max_length_m)}): in dry ballast a train on it "
                          "might not drop its relay, so the simulation holds it occupied (red band)",
                          "split it with an insulated joint")
            run = self.st.section_span(s.id)  # the track circuit's main run, not its branches added to it
            if (s.type is CircuitType.zpw2000a and run > self.r.capacitor_min_section_m
                    and (s.capacitors is None or s.capacitors.count == 0)):
                self.warn(self.loc("sections", s.id), f"ZPW-2000A section '{s.id}' is {metres(run)} long but has no "
                          f"compensation capacitors (needed over {metres(self.r.capacitor_min_section_m)})",
                          "add 'capacitors: {rule: standard}'")


def design_warnings(station: Station, rules: DesignRules | None = None) -> list[Diagnostic]:
    """The station against the design rules (by default those of the default rule set)."""
    return _Warner(station, rules).run()
