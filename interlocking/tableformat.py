"""The interlocking table as text (like the signed table), CSV and JSON."""

from __future__ import annotations

import csv
import io
import json

from .table import InterlockingTable, Route


def _turnouts(r: Route) -> str:
    parts = []
    for t in r.turnouts:
        pos = t.id if t.position.value == "normal" else f"({t.id})"  # reverse is written in brackets
        if t.role == "protection":
            pos = f"[{pos}]"
        elif t.role == "driven":
            pos = f"{{{pos}}}"
        parts.append(pos)
    return " ".join(parts)


def as_text(table: InterlockingTable) -> str:
    st = table.station
    lines = [f"联锁表 Interlocking table: {st.model.name.zh} ({st.model.name.en}), station id {st.id}",
             "turnouts: 1 = normal, (1) = reverse, [1] = flank protection (防护), {1} = driven (带动)", ""]
    header = f"{'No.':>3}  {'route':<14} {'kind':<9} {'buttons':<14} {'signal':<7} {'aspects':<10} " \
             f"{'turnouts':<26} {'sections':<34} {'approach':<8} conflicting routes"
    lines.append(header)
    lines.append("-" * len(header))
    for n, r in enumerate(table.routes.values(), 1):
        buttons = " ".join([r.start, *r.via, r.end])
        sections = " ".join(r.sections) + ("".join(f" <{f.section}>" for f in r.fouling))
        if r.overlap_sections:
            sections += " +overlap " + " ".join(r.overlap_sections)
        conflicts = ", ".join(sorted(r.conflicts))
        lines.append(f"{n:>3}  {r.id:<14} {r.category:<9} {buttons:<14} {r.signal:<7} {'/'.join(r.aspects):<10} "
                     f"{_turnouts(r):<26} {sections:<34} {' '.join(r.approach):<8} {conflicts}")
        if r.opposing:
            lines.append(f"{'':>3}  {'':<14} opposing: {', '.join(r.opposing)}")
    lines.append("")
    lines.append("throats (guide total lock): " + "; ".join(f"{k}: {' '.join(v)}" for k, v in table.throats.items()))
    if table.unselectable:
        lines.append("paths without a distinguishing variant button (not selectable): " + "; ".join(table.unselectable))
    lines.append(f"{len(table.routes)} routes")
    return "\n".join(lines)


def as_csv(table: InterlockingTable) -> str:
    buf = io.StringIO()
    w = csv.writer(buf)
    w.writerow(["id", "kind", "category", "start", "via", "end", "signal", "aspects", "turnouts", "sections",
                "fouling_sections", "approach", "overlap", "conflicts", "opposing"])
    for r in table.routes.values():
        w.writerow([r.id, r.kind, r.category, r.start, " ".join(r.via), r.end, r.signal, "/".join(r.aspects),
                    " ".join(f"{t.id}:{t.position.value}:{t.role}" for t in r.turnouts), " ".join(r.sections),
                    " ".join(f.section for f in r.fouling), " ".join(r.approach), " ".join(r.overlap_sections),
                    " ".join(sorted(r.conflicts)), " ".join(r.opposing)])
    return buf.getvalue()


def as_json(table: InterlockingTable) -> str:
    return json.dumps(table.as_dict(), ensure_ascii=False, indent=2)
