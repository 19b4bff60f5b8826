"""Station-data checks of the interlocking test: what the file itself must get right.

- coded sections (电码化) at least the coding minimum long (``stations.rules.min_coded_length``);
- dead zones and the other design rules, from the station's warnings (reported as warnings: a dead zone is a
  design condition the file declares; ``--strict`` makes them failures);
- paths the table cannot select for want of a variant button (warnings).

What the table must protect (flank turnouts, fouling sections, the extent of each route, the enemy routes) is held
against the oracle in :mod:`.against`.
"""

from __future__ import annotations

from liansuo.proving.verify.probe import Context, Failure
from liansuo.stations.rules import min_coded_length

_DEAD_ZONE_WORDS = ("dead zone", "staggered")


def check_station(ctx: Context, focus: set[str] | None = None) -> None:
    st = ctx.station
    rules = ctx.rules.design
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
