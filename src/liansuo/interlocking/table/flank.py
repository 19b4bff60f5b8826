"""Flank protection, driven turnouts and fouling sections of a route (防护道岔, 带动道岔, 侵限绝缘), from the station.

Flank protection: the first turnout met from the free leg of a route turnout (directly, or across joints within the
throat, short of a signal that stops movements heading for the route), met on its normal or reverse leg, must lie the
other way, unless that way also leads into the route (onto a track of the route or one crossing it at a diamond, as
the other diagonal of a scissors crossover does). A diamond the route runs over is protected the same way: the
turnouts whose legs lead onto the crossing track must lie away from it, so a route over one diagonal of a scissors
crossover keeps the other pair normal.
"""

from __future__ import annotations

from collections.abc import Sequence

from liansuo.interlocking.table.route import FoulingSection
from liansuo.rules import RuleSet
from liansuo.stations.schema import Direction, SectionRole, TurnoutPosition
from liansuo.stations.station import Station


def other_position(pos: TurnoutPosition | str) -> TurnoutPosition:
    return TurnoutPosition.reverse if str(pos) == "normal" else TurnoutPosition.normal


def driven_turnouts(st: Station, turnouts: Sequence[str], positions: dict[str, TurnoutPosition],
                    skip: set[str]) -> dict[str, TurnoutPosition]:
    """The driven turnouts (带动道岔) of ``turnouts``: the crossover partners that move with them and lie as they
    do, and the turnouts the station file has a turnout drive when a route sets it (``drives``). A turnout the
    route itself runs over keeps the route's position."""
    out: dict[str, TurnoutPosition] = {}
    for t in turnouts:
        pair = st.turnouts[t].pair
        for partner in st.pairs[pair] if pair else []:
            if partner not in positions and partner not in skip:
                out.setdefault(partner, positions[t])
        for d in st.turnouts[t].drives:
            if d.when == positions[t].value and d.turnout not in positions and d.turnout not in skip:
                out.setdefault(d.turnout, TurnoutPosition(d.position))
    return out


class Flank:
    """The flank protection and fouling sections of paths through one station, under one rule set."""

    def __init__(self, station: Station, rules: RuleSet) -> None:
        self.st = station
        self.rules = rules

    def of(self, tracks: Sequence[str], turnouts: Sequence[tuple[str, TurnoutPosition]],
               skip: set[str]) -> tuple[dict[str, TurnoutPosition], list[FoulingSection]]:
        """Protection turnouts (turnout -> position) and fouling sections of a path over ``tracks`` with
        ``turnouts``; turnouts in ``skip`` (already in the route) are never asked to protect it."""
        st = self.st
        on_path = set(tracks)
        crossing = {o for t in tracks for _, o in st.crossings.get(t, ())} - on_path
        protection: dict[str, TurnoutPosition] = {}
        fouling: list[FoulingSection] = []

        def protect(u: str, leg: str) -> None:
            if leg == "point" or u in skip or u in protection:
                return
            away = other_position(leg)
            if not self._leads_onto(st.leg_track(u, away.value), u, on_path | crossing):
                protection[u] = away

        for t, pos in turnouts:
            fouling += self._fouling_tied(t, pos)
            track, node_from = st.leg_track(t, other_position(pos).value), t
            joints = 0
            while track not in on_path:
                far = st.far_end(track, node_from)
                if joints == 1 and any(fp.track == track for fp in st.model.fouling_points):
                    # a fouling point on the first track past the joint: the joint lies inside the fouling limit
                    fouling.append(FoulingSection(st.tracks[track].section, t, pos))
                if st.sections[st.tracks[track].section].role is not SectionRole.throat:
                    break
                if far.leg is not None:
                    protect(far.node, far.leg)
                    break
                if far.node not in st.joints or self._guards(far.node, node_from):
                    break
                track, node_from = st.across(far.node, track), far.node
                joints += 1
        for x in sorted(crossing):  # a vehicle standing on a track that crosses the path fouls the crossing
            diamond = next(d for t in tracks for d, o in st.crossings.get(t, ()) if o == x)
            fouling.append(FoulingSection(st.tracks[x].section, diamond=diamond))
            for port in st.track_ports[x]:
                if port.leg is not None:
                    protect(port.node, port.leg)
                elif port.node in st.joints:
                    nxt = st.across(port.node, x)
                    far = st.far_end(nxt, port.node)
                    if far.leg is not None:
                        protect(far.node, far.leg)
        return protection, list(dict.fromkeys(fouling))

    def _fouling_tied(self, turnout: str, pos: TurnoutPosition) -> list[FoulingSection]:
        """Fouling sections from the fouling points tied to ``turnout`` (``turnout`` + ``tracks`` in the file), for a
        route over it in ``pos``: where the first joint on the other leg lies nearer the turnout than the fouling
        point plus the clearance (侵限绝缘), a vehicle standing just beyond that joint fouls the route."""
        st = self.st
        design = self.rules.design
        clearance = design.fouling_clearance_emu_m if st.model.emu else design.fouling_clearance_m
        at = st.turnouts[turnout].at
        out: list[FoulingSection] = []
        for fp in st.model.fouling_points:
            if fp.turnout != turnout:
                continue
            chain = st.fouling_legs(fp).get(other_position(pos).value, [])
            joint = chain[0][1] if chain else None
            if joint is None or joint not in st.joints:
                continue
            if abs(st.joints[joint].at - at) < abs(fp.at - at) + clearance:
                beyond = st.across(joint, chain[0][0])
                out.append(FoulingSection(st.tracks[beyond].section, turnout, pos))
        return out

    def _guards(self, joint: str, behind: str) -> bool:
        """Does a signal at ``joint`` face movements heading from it towards ``behind`` (so it stops them)?"""
        st = self.st
        towards = Direction.up if st.node_at(joint) > st.node_at(behind) else Direction.down
        return any(s.direction is towards for s in st.signals_at(joint))

    def _leads_onto(self, track: str, node_from: str, tracks: set[str]) -> bool:
        """Does a movement leaving ``node_from`` along ``track`` reach one of ``tracks`` before another turnout
        (across at most one joint)?"""
        st = self.st
        for _ in range(2):
            if track in tracks:
                return True
            far = st.far_end(track, node_from)
            if far.leg is not None or far.node not in st.joints:
                return False
            track, node_from = st.across(far.node, track), far.node
        return track in tracks
