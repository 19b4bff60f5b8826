"""Automatic block signals (自动闭塞, four-aspect) and station coding (站内电码化): what follows from the routes and
the signal aspects without operator action."""

from __future__ import annotations

from collections.abc import Callable, Collection, Iterable

from liansuo.interlocking.aspects import TRAIN_STOP, at_stop_or_dark, block_aspect
from liansuo.interlocking.io import Outputs
from liansuo.interlocking.state import RouteStage, RouteState
from liansuo.rules import RuleSet
from liansuo.stations.schema import SignalKind
from liansuo.stations.station import Station


class AutoBlock:
    """The chain of block signals of a station's open line: each follows its own sections and the signal ahead."""

    def __init__(self, station: Station) -> None:
        topo = station.topology
        self.signals: list[tuple[str, tuple[str, ...], str | None]] = []
        self.line: dict[str, str] = {}  # block signal -> the automatic line it stands on
        for sig in station.model.signals:
            if sig.kind is not SignalKind.block:
                continue
            sections: list[str] = []
            move = topo.start_move(sig.at, sig.direction)
            nxt_signal = None
            for _ in range(100):
                sec = station.tracks[move[0]].section
                if not sections or sections[-1] != sec:
                    sections.append(sec)
                far = topo.far_node(move)
                ahead = [s for s in station.signals_at(far) if s.direction is sig.direction]
                if ahead:
                    nxt_signal = ahead[0].id
                    break
                moves = topo.next_moves(move)
                if not moves:
                    break
                move = moves[0][0]
            self.signals.append((sig.id, tuple(sections), nxt_signal))
            for lk in station.model.links:
                if lk.kind.value == "automatic" and sections and sections[0] in lk.sections:
                    self.line[sig.id] = lk.id
        self.signals = _ahead_first(self.signals)

    def update(self, out: Outputs, clear: Callable[[str], bool], proven: Callable[[str, str], str],
               red_dark: Collection[str] = (), reversed_lines: Collection[str] = ()) -> None:
        """Evaluate the chain until it settles, so a change at one end reaches the other within the cycle.

        ``red_dark``: signals whose red lamp is dark: one of them at stop shows nothing, so the block signal in rear
        of it shows H (红灯转移). ``reversed_lines``: lines whose direction is changed for departures from this station
        (改方): their block signals, which face the other way, are held at H."""
        for _ in range(len(self.signals) + 1):
            changed = False
            for sig, sections, nxt in self.signals:
                ahead = out.signals.get(nxt) if nxt else None
                if self.line.get(sig) in reversed_lines or any(not clear(s) for s in sections) or (
                        nxt in red_dark and at_stop_or_dark(ahead)):
                    aspect = TRAIN_STOP
                else:
                    aspect = block_aspect(ahead)
                shown = proven(sig, aspect) if aspect != TRAIN_STOP else TRAIN_STOP
                if out.signals.get(sig) != shown:
                    out.set_aspect(sig, shown)
                    changed = True
            if not changed:
                return


def _ahead_first(signals: list[tuple[str, tuple[str, ...], str | None]]
                 ) -> list[tuple[str, tuple[str, ...], str | None]]:
    """The block signals ordered so that each comes after the block signal ahead of it: one sweep of
    :meth:`AutoBlock.update` then settles the whole chain, in time proportional to its length (in file order a change
    at the far end would take one sweep per signal to reach the near end, a hang on a line of thousands)."""
    by_id = {entry[0]: entry for entry in signals}
    placed: set[str] = set()
    out: list[tuple[str, tuple[str, ...], str | None]] = []
    for sig, _, _ in signals:
        path: list[str] = []
        on_path: set[str] = set()
        cur: str | None = sig
        while cur is not None and cur in by_id and cur not in placed and cur not in on_path:  # a loop ends a chain
            path.append(cur)
            on_path.add(cur)
            cur = by_id[cur][2]
        for s in reversed(path):
            placed.add(s)
            out.append(by_id[s])
    return out


def cab_codes(station: Station, rules: RuleSet, routes: Iterable[RouteState],
              aspects: dict[str, str]) -> dict[str, str | None]:
    """The low-frequency code on every coded section: the code of the signal ahead of a train in its route."""
    codes: dict[str, str | None] = dict.fromkeys(station.derived(_coded))
    for rs in routes:
        r = rs.route
        if r.kind != "train" or rs.stage not in (RouteStage.open, RouteStage.guide, RouteStage.in_use):
            continue
        governing = r.end_signal if r.end_signal else r.signal
        code = rules.aspects.cab_codes.get(aspects.get(governing, rules.aspects.stop))
        for i, s in enumerate(rs.sections):
            if s in codes and not rs.released[i]:
                codes[s] = code
    return codes


def _coded(station: Station) -> tuple[str, ...]:
    """The coded sections, in the station's order."""
    return tuple(s.id for s in station.model.sections if s.coded)
