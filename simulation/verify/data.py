"""Station-data checks of the interlocking test: what the file itself must get right, independently of the table.

- flank protection (防护道岔) the topology demands: the partner of a crossover pair moves with a route turnout, so
  it must be in the route in the same position; and where the free leg of a route turnout runs (directly or across
  one joint, within 250 m) into the normal or reverse leg of another turnout, that turnout must protect the route,
  lying the other way (unless that way leads back into the route, as the other diagonal of a scissors crossover does);
- coded sections (电码化) at least the coding minimum long (``stations.rules.min_coded_length``);
- dead zones and the other design rules, from the station's warnings (reported as warnings: a dead zone is a
  design condition the file declares; ``--strict`` makes them failures);
- paths the table cannot select for want of a variant button (warnings).
"""

from __future__ import annotations

from interlocking.table import Route
from stations.rules import design_rules, min_coded_length
from stations.station import Station

from .probe import Context, Failure, other

_DEAD_ZONE_WORDS = ("dead zone", "staggered")
FLANK_REACH_M = 250.0  # a turnout further than this from a route turnout's free leg does not endanger the route


def check_station(ctx: Context, focus: set[str] | None = None) -> None:
    st = ctx.station
    for r in ctx.table.routes.values():
        if focus and r.id not in focus:
            continue
        for problem in flank_problems(st, r):
            ctx.record(False, "flank-protection", r.id, problem)
        ctx.record(True, "flank-protection", r.id, "")
    rules = design_rules()
    for s in st.model.sections:
        if not s.coded:
            continue
        speed = s.speed_kmh or rules.coding_speed_kmh
        need, have = min_coded_length(speed, rules), st.section_length(s.id)
        ctx.record(have >= need, "coded-length", s.id, f"coded section {s.id} is {have:.1f} m long; at {speed:g} "
                   f"km/h the cab signal needs >= {need:.2f} m to read its code")
    ctx.checks += len(st.dead_zones)  # each measured against the rules by the station's design warnings
    for w in st.warnings:
        text = w.message
        if "coded section" in text:
            continue  # checked above, as a failure
        kind = "dead-zone" if any(word in text for word in _DEAD_ZONE_WORDS) else "design-rule"
        ctx.warnings.append(Failure(kind, f"{w.file}:{w.line}", text))
    for path in ctx.table.unselectable:
        ctx.warnings.append(Failure("unselectable-path", path, "a path between these buttons has no variant button "
                                    "(变通按钮) or signal of its own, so it can never be selected"))


def flank_problems(st: Station, r: Route) -> list[str]:
    """What the topology demands of ``r``'s turnouts and the table row lacks, in words."""
    have = {t.id: t for t in r.all_turnouts}
    problems: list[str] = []
    for t in r.turnouts:
        if t.role != "route":
            continue
        pair = st.turnouts[t.id].pair
        for partner in st.pairs[pair] if pair else []:
            got = have.get(partner)
            if got is None:
                problems.append(f"turnout {partner} moves with {t.id} (crossover {pair}) but is not in the route; "
                                f"it must be {t.position.value} (driven or protection)")
            elif got.position is not t.position:
                problems.append(f"turnout {partner} moves with {t.id} (crossover {pair}) but the route needs it "
                                f"{got.position.value} and {t.id} {t.position.value}")
        demand = _flank_demand(st, r, t.id, t.position.value)
        if demand is None:
            continue
        u, pos, via = demand
        got = have.get(u)
        if got is None:
            problems.append(f"the free ({other(t.position.value)}) leg of turnout {t.id} leads into turnout {u}'s "
                            f"{other(pos)} leg{via}: {u} must protect the route, lying {pos}")
        elif got.position.value != pos:
            problems.append(f"turnout {u} is in the route {got.position.value}, which leads a runaway from its "
                            f"{got.position.value} leg onto turnout {t.id}'s free leg; it must lie {pos}")
    return problems


def _flank_demand(st: Station, r: Route, turnout: str, position: str) -> tuple[str, str, str] | None:
    """(turnout, protective position, how it was reached) demanded by the free leg of a route turnout."""
    route_turnouts = {t.id for t in r.turnouts if t.role == "route"}
    track = st.leg_track(turnout, other(position))
    node_from = turnout
    joints: list[str] = []
    travelled = 0.0
    while True:
        if st.is_station_track(st.tracks[track].section):
            return None
        a, b = st.track_ports[track]
        far = b if a.node == node_from else a
        travelled += st.track_length(track)
        if far.leg is not None:
            u = far.node
            if far.leg == "point" or u in route_turnouts:
                return None
            protective = other(far.leg)
            if st.tracks[st.leg_track(u, protective)].section in r.sections:
                return None  # the other way leads back into the route (scissors diagonal): no protection possible
            return u, protective, f" (across joint {joints[0]})" if joints else ""
        if far.node not in st.joints or joints or travelled > FLANK_REACH_M:
            return None  # an end, a second joint, or too far to endanger the route
        lo, hi = st.joint_tracks(far.node)
        track = hi if lo == track else lo
        node_from = far.node
        joints.append(far.node)
