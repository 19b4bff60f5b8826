"""Generator of large "hub" (枢纽) station files, for the benchmark and for stress tests.

``generate_hub(turnouts, tracks)`` returns the YAML text of a valid station file: a double-ended yard of ``tracks``
parallel station tracks between two throats. The tracks are split into groups; each group has its own line (lead)
at both ends, entered past a home signal. In each throat:

* the leads are joined by a staircase of crossovers (双动道岔, ``pair: a/b``), one between each pair of neighbouring
  leads, so a train from any line can reach the groups further along (down trains from lead ``g`` to leads
  ``>= g`` at the X end, the mirror image at the S end) and every route has a single path;
* each lead ends in a ladder of single turnouts fanning out to its group's station tracks;
* a pair of shunting signals (one each way) stands between the crossovers and the ladder, and some leads have a
  shunting neck (牵出线) on a turnout of its own, with a shunting signal and an end button at its buffer stop.

Every station track has a starting signal at each end with train and shunt buttons; every turnout lies in its own
25 Hz section bounded by insulated joints. The number of groups is chosen so that the file has exactly
``turnouts`` turnouts: ladders take ``2 * (tracks - groups)``, crossovers ``4 * (groups - 1)`` and the remaining
``0 .. 2 * groups`` become shunting necks.

Ids: station tracks ``1G`` .. ``{tracks}G`` with starting signals ``X{n}`` (down, at the S end) and ``S{n}`` (up, at
the X end); home signals ``XJ{g}`` / ``SJ{g}`` at boundaries ``XB{g}`` / ``SB{g}``; turnouts odd at the X end, even at
the S end; shunting signals ``D{n}``.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass, field
from typing import Any

import yaml

from liansuo.stations.schema import Lamp

# the lamps of the generated signals, as the station file lists them
SHUNTING_LAMPS = (Lamp.A.value, Lamp.B.value)
HOME_LAMPS = (Lamp.U.value, Lamp.L.value, Lamp.H.value, Lamp.U2.value, Lamp.B.value)
STARTING_LAMPS = (Lamp.L.value, Lamp.H.value, Lamp.B.value)

# layout in metres, measured from the boundary into the station ("u"); the S end is the mirror image
_HOME_U = 300.0  # home signal joint
_XOVER_START_U = 360.0  # first crossover turnout
_XOVER_STEP = 100.0  # between the crossovers of neighbouring lead pairs
_XOVER_LEN = 50.0  # between the two turnouts of one crossover
_LADDER_STEP = 50.0  # between turnouts of a ladder
_STATION_TRACK_M = 750.0
_MAX_PIECE_M = 1000.0  # longest stretch of lead without a joint
_GROUP_TRACKS = 12  # preferred largest number of station tracks behind one lead


def hub_groups(turnouts: int, tracks: int) -> int:
    """How many groups (lines) a hub with these numbers has; ValueError when no layout fits them."""
    if tracks < 1:
        raise ValueError("a hub needs at least one station track")
    if turnouts < 2 * tracks - 2:
        raise ValueError(f"{tracks} tracks need at least {2 * tracks - 2} turnouts (a ladder at each end)")
    spare = turnouts - 2 * tracks + 4  # = 2 * groups + necks, with 0 <= necks <= 2 * groups
    fewest, most = max(1, -(-spare // 4)), spare // 2
    if fewest > min(most, tracks):
        raise ValueError(f"{turnouts} turnouts cannot be laid out over {tracks} tracks: give more tracks "
                         f"(at most {6 * tracks - 4} turnouts fit over {tracks} tracks)")
    # groups of about _GROUP_TRACKS tracks where the numbers allow: a very deep ladder makes routes over 5 km
    return min(max(fewest, -(-tracks // _GROUP_TRACKS)), most, tracks)


@dataclass
class _Lead:
    """One lead of one throat, as a list of nodes in order of increasing u, with the turnout legs used."""

    nodes: list[tuple[str, str | None, str | None]] = field(default_factory=list)  # (node, low leg, high leg)


class _Builder:
    def __init__(self, turnouts: int, tracks: int) -> None:
        self.n_turnouts = turnouts
        self.n_tracks = tracks
        self.groups = hub_groups(turnouts, tracks)
        g, t = self.groups, tracks
        self.sizes = [t // g + (1 if i < t % g else 0) for i in range(g)]
        self.first_track = [sum(self.sizes[:i]) + 1 for i in range(g)]
        spare = turnouts - (2 * (t - g) + 4 * (g - 1))
        self.necks = {"X": (spare + 1) // 2, "S": spare // 2}
        # throat length: crossovers, then shunting signal, neck, ladder, station-track joints
        self.xover_end = _XOVER_START_U + max(g - 2, 0) * _XOVER_STEP + _XOVER_LEN if g > 1 else _HOME_U
        self.shunt_u = self.xover_end + 60.0
        self.ladder_u = self.shunt_u + 100.0  # first ladder turnout (room for a neck turnout before it)
        self.track_u = self.ladder_u + (max(self.sizes) - 1) * _LADDER_STEP + 40.0
        self.total = 2 * self.track_u + _STATION_TRACK_M
        self.ends: list[dict[str, Any]] = []
        self.joints: list[dict[str, Any]] = []
        self.turnouts: list[dict[str, Any]] = []
        self.tracks: list[dict[str, Any]] = []
        self.sections: list[dict[str, Any]] = []
        self.signals: list[dict[str, Any]] = []
        self.buttons: list[dict[str, Any]] = []
        self.next_turnout = {"X": 1, "S": 2}
        self.next_shunt = {"X": 1, "S": 2}
        self.positions: dict[str, float] = {}
        self.track_no = 0

    # ---- helpers ---------------------------------------------------------------------------------------------
    def x(self, end: str, u: float) -> float:
        return round(u if end == "X" else self.total - u, 1)

    def joint(self, jid: str, end: str, u: float, **extra: Any) -> str:
        self.positions[jid] = self.x(end, u)
        self.joints.append({"id": jid, "at": self.positions[jid], **extra})
        return jid

    def turnout(self, end: str, u: float, number: int, pair: str | None = None) -> str:
        tid = str(self.next_turnout[end])
        self.next_turnout[end] += 2
        self.positions[tid] = self.x(end, u)
        item: dict[str, Any] = {"id": tid, "at": self.positions[tid], "number": number, "machine": "ZD6"}
        if pair:
            item["pair"] = pair
        self.turnouts.append(item)
        self.sections.append({"id": f"{tid}DG", "type": "25hz"})
        return tid

    def track(self, a: str, b: str, section: str, row: float) -> None:
        self.track_no += 1
        self.tracks.append({"id": f"t{self.track_no}", "from": a, "to": b, "section": section, "row": row})

    def shunt_signal(self, end: str, at: str, direction: str) -> None:
        n = self.next_shunt[end]
        self.next_shunt[end] += 2
        self.signals.append({"id": f"D{n}", "kind": "shunting", "at": at, "direction": direction,
                             "lamps": list(SHUNTING_LAMPS), "buttons": ["shunt"]})

    # ---- one throat ------------------------------------------------------------------------------------------
    def throat(self, end: str) -> None:
        into = "down" if end == "X" else "up"
        g_count = self.groups
        leads = [_Lead() for _ in range(g_count)]
        lead_turnouts: list[list[tuple[float, str, str, str]]] = [[] for _ in range(g_count)]  # (u, id, low, high)
        # crossovers: 'a' on lead g faces movements into the station, 'b' on lead g+1 trails
        for g in range(g_count - 1):
            u_a = _XOVER_START_U + g * _XOVER_STEP
            pair_ids = (str(self.next_turnout[end]), str(self.next_turnout[end] + 2))
            pair = f"{pair_ids[0]}/{pair_ids[1]}"
            a = self.turnout(end, u_a, 12, pair)
            b = self.turnout(end, u_a + _XOVER_LEN, 12, pair)
            j = self.joint(f"J{a}-{b}", end, u_a + _XOVER_LEN / 2)
            self.track(f"{a}.reverse", j, f"{a}DG", g + 0.5)
            self.track(j, f"{b}.reverse", f"{b}DG", g + 0.5)
            lead_turnouts[g].append((u_a, a, "point", "normal"))
            lead_turnouts[g + 1].append((u_a + _XOVER_LEN, b, "normal", "point"))
        for g in range(g_count):
            lead = leads[g]
            row = float(g)
            # boundary, approach section, home signal
            bnd = f"{end}B{g}"
            self.positions[bnd] = self.x(end, 0.0)
            self.ends.append({"id": bnd, "kind": "boundary", "at": self.positions[bnd]})
            home = self.joint(f"J{end}J{g}", end, _HOME_U, at2=self.x(end, _HOME_U + 0.8))
            approach = f"{end}{g}AG"
            self.sections.append({"id": approach, "type": "25hz", "role": "approach"})
            self.track(bnd, home, approach, row)
            self.signals.append({"id": f"{end}J{g}", "kind": "home", "at": home, "direction": into,
                                 "lamps": list(HOME_LAMPS), "buttons": ["train"]})
            lead.nodes.append((home, None, None))
            for _, tid, low, high in sorted(lead_turnouts[g]):
                lead.nodes.append((tid, low, high))
            # a pair of shunting signals (并置调车信号机) between the crossovers and the ladder: one into the ladder,
            # one for movements out of it, which stop there rather than run on over the crossovers
            dj = self.joint(f"J{end}D{g}", end, self.shunt_u)
            lead.nodes.append((dj, None, None))
            self.shunt_signal(end, dj, into)
            self.shunt_signal(end, dj, "up" if into == "down" else "down")
            if g < self.necks[end]:
                neck = self.turnout(end, self.shunt_u + 40.0, 9)
                qj = self.joint(f"J{end}Q{g}", end, self.shunt_u + 15.0)
                buf = f"{end}Q{g}"
                self.positions[buf] = self.x(end, self.shunt_u - 185.0)
                self.ends.append({"id": buf, "kind": "buffer", "at": self.positions[buf]})
                self.sections.append({"id": f"{end}Q{g}G", "type": "25hz", "role": "spur",
                                      "name": f"shunting neck {end}{g}"})
                self.track(f"{neck}.reverse", qj, f"{neck}DG", row - 0.5)
                self.track(qj, buf, f"{end}Q{g}G", row - 0.5)
                self.shunt_signal(end, qj, into)
                self.buttons.append({"id": f"{end}Q{g}A", "at": buf, "kind": "end"})
                lead.nodes.append((neck, "normal", "point"))
            # the ladder: turnout i sends its reverse leg to track i of the group, the last normal leg to the last
            size = self.sizes[g]
            first = self.first_track[g]
            ladder = [self.turnout(end, self.ladder_u + i * _LADDER_STEP, 9) for i in range(size - 1)]
            for tid in ladder:
                lead.nodes.append((tid, "point", "normal"))
            track_joints = [self.joint(f"J{end}{first + i}G", end, self.track_u) for i in range(size)]
            for i, tid in enumerate(ladder):
                self.connect(end, g, tid, "reverse", track_joints[i], None, row + (i + 1) / (size + 1))
            lead.nodes.append((track_joints[-1], None, None))
            self.lay_lead(end, g, lead, row)
            for i, jid in enumerate(track_joints):
                n = first + i
                if end == "X":
                    self.signals.append({"id": f"S{n}", "kind": "starting", "at": jid, "direction": "up",
                                         "lamps": list(STARTING_LAMPS), "buttons": ["train", "shunt"]})
                else:
                    self.signals.append({"id": f"X{n}", "kind": "starting", "at": jid, "direction": "down",
                                         "lamps": list(STARTING_LAMPS), "buttons": ["train", "shunt"]})

    def lay_lead(self, end: str, g: int, lead: _Lead, row: float) -> None:
        nodes = lead.nodes
        for (a, _, a_high), (b, b_low, _) in itertools.pairwise(nodes):
            self.connect(end, g, a, a_high, b, b_low, row)

    def connect(self, end: str, g: int, a: str, a_leg: str | None, b: str, b_leg: str | None, row: float) -> None:
        """Track from node ``a`` (a turnout leg when ``a_leg`` is given) to ``b``, further into the station.

        Two turnouts get a joint between them, and a long stretch is cut by joints every kilometre at most (a 25 Hz
        track circuit is limited to about 1500 m); a piece with a turnout at neither end gets a plain section."""
        ua = self.positions[a] if end == "X" else self.total - self.positions[a]
        ub = self.positions[b] if end == "X" else self.total - self.positions[b]
        pieces = max(math.ceil((ub - ua) / _MAX_PIECE_M), 2 if a_leg and b_leg else 1)
        ports = [f"{a}.{a_leg}" if a_leg else a]
        for i in range(1, pieces):
            ports.append(self.joint(f"J{a}-{b}" + (f"-{i}" if pieces > 2 else ""), end,
                                    ua + (ub - ua) * i / pieces))
        ports.append(f"{b}.{b_leg}" if b_leg else b)
        for i, (p, q) in enumerate(itertools.pairwise(ports)):
            if i == 0 and a_leg:
                sec = f"{a}DG"
            elif i == pieces - 1 and b_leg:
                sec = f"{b}DG"
            else:
                sec = f"{end}{g}L{len(self.sections)}G"
                self.sections.append({"id": sec, "type": "25hz"})
            self.track(p, q, sec, row)

    def station_tracks(self) -> None:
        for g in range(self.groups):
            for i in range(self.sizes[g]):
                n = self.first_track[g] + i
                self.sections.append({"id": f"{n}G", "type": "25hz", "role": "station_track", "coded": True})
                self.track(f"JX{n}G", f"JS{n}G", f"{n}G", g + i / (self.sizes[g] + 1))

    def build(self) -> str:
        self.throat("X")
        self.throat("S")
        self.station_tracks()
        assert len(self.turnouts) == self.n_turnouts, (len(self.turnouts), self.n_turnouts)
        data: dict[str, Any] = {
            "id": f"hub{self.n_turnouts}",
            "name": {"zh": f"枢纽站 {self.n_turnouts} 组道岔 (生成)",
                     "en": f"Generated hub, {self.n_turnouts} turnouts, {self.n_tracks} tracks"},
            "description": (f"Generated by stations.hubgen: {self.groups} lines at each end, "
                            f"{self.n_tracks} station tracks, {self.n_turnouts} turnouts"),
            "line": "single",
            "line_speed_kmh": 120,
            "ends": self.ends,
            "joints": self.joints,
            "turnouts": self.turnouts,
            "tracks": self.tracks,
            "sections": self.sections,
            "signals": self.signals,
            "buttons": self.buttons,
        }
        header = ("# Generated by stations.hubgen.generate_hub"
                  f"(turnouts={self.n_turnouts}, tracks={self.n_tracks}); do not edit by hand.\n")
        return header + yaml.safe_dump(data, sort_keys=False, allow_unicode=True, default_flow_style=None,
                                       width=160)


def generate_hub(turnouts: int, tracks: int) -> str:
    """The YAML text of a valid hub station with exactly ``turnouts`` turnouts and ``tracks`` station tracks."""
    return _Builder(turnouts, tracks).build()
