"""The rows of the station diagram: which schematic row each track and each node stands on.

A track's row is its ``row`` in the station file, or inferred from its neighbours (a reverse leg one row off its
trunk); a node sits on the row of its trunk, or where its ``draw: {x, y}`` puts it.
"""

from __future__ import annotations

from liansuo.stations.station import Station


def track_rows(station: Station) -> dict[str, float]:
    """Every track's schematic row: the file's ``row``, or inferred from its neighbours (reverse legs one row off)."""
    rows: dict[str, float] = {t.id: t.row for t in station.model.tracks if t.row is not None}
    if not rows and station.model.tracks:
        longest = max(station.model.tracks, key=lambda t: station.track_length(t.id))
        rows[longest.id] = 0.0
    ports = station.track_ports
    changed = True
    while changed:
        changed = False
        for tid in ports:
            if tid in rows:
                continue
            guess = _guess_row(station, tid, rows)
            if guess is not None:
                rows[tid] = guess
                changed = True
        if not changed:
            missing = [t for t in ports if t not in rows]
            if missing:
                rows[missing[0]] = 0.0
                changed = True
    return rows


def _guess_row(station: Station, tid: str, rows: dict[str, float]) -> float | None:
    for port in station.track_ports[tid]:
        others = [(leg, t) for leg, t in station.node_tracks.get(port.node, []) if t != tid]
        if port.leg is None:
            known = [rows[t] for _, t in others if t in rows]
            if known:
                return known[0]
            continue
        by_leg = {leg: t for leg, t in others}
        if port.leg == "reverse":
            trunk = by_leg.get("point") or by_leg.get("normal")
            if trunk in rows:
                return rows[trunk] + 1.0
        else:
            twin = by_leg.get("normal" if port.leg == "point" else "point")
            if twin in rows:
                return rows[twin]
            rev = by_leg.get("reverse")
            if rev in rows:
                return rows[rev] - 1.0
    return None


def node_rows(station: Station, rows: dict[str, float]) -> dict[str, float]:
    """A node sits on the row of its trunk: a turnout on its point track, a joint on its plain (non-leg) track."""
    out: dict[str, float] = {}
    for node, attached in station.node_tracks.items():
        draw = drawn_at(station, node)
        if draw is not None:
            out[node] = draw[1]
            continue
        if node in station.turnouts:
            legs = {leg: t for leg, t in attached}
            trunk = legs.get("point") or legs.get("normal") or attached[0][1]
            out[node] = rows[trunk]
            continue
        plain = [rows[t] for _, t in attached if not _other_end_is_leg(station, t, node)]
        vals = plain or [rows[t] for _, t in attached]
        out[node] = sum(vals) / len(vals)
    return out


def _other_end_is_leg(station: Station, track: str, node: str) -> bool:
    a, b = station.track_ports[track]
    other = b if a.node == node else a
    return other.leg is not None


def drawn_at(station: Station, node: str) -> tuple[float, float] | None:
    obj = station.ends.get(node) or station.joints.get(node) or station.turnouts.get(node)
    d = getattr(obj, "draw", None)
    return (d.x, d.y) if d is not None else None
