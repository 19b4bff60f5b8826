"""A short summary of a loaded station, for ``liansuo check``."""

from __future__ import annotations

from collections import Counter
from typing import Any

from liansuo.kit.fit import fit_all, metres, number
from liansuo.stations.station import Station


def summarise(station: Station) -> dict[str, Any]:
    m = station.model
    return {
        "station": station.id,
        "name": {"zh": m.name.zh, "en": m.name.en},
        "file": station.source.file if station.source else None,
        "tracks": len(m.tracks),
        "track_length_m": round(sum(station.track_length(t) for t in station.tracks), 1),
        "turnouts": len(m.turnouts),
        "crossover_pairs": sorted(station.pairs),
        "double_slips": [d.id for d in m.double_slips],  # their turnouts and pairs are counted above
        "sections": len(m.sections),
        "section_types": dict(Counter(s.type.value for s in m.sections)),
        "signals": len(m.signals),
        "signal_kinds": dict(Counter(s.kind.value for s in m.signals)),
        "platforms": len(m.platforms),
        "links": [{"id": lk.id, "kind": lk.kind.value, "neighbour": lk.neighbour.en} for lk in m.links],
        "dead_zones": [{"joint": dz.joint, "from_m": dz.start, "to_m": dz.end, "length_m": round(dz.length, 3)}
                       for dz in station.dead_zones],
        "warnings": [w.as_dict() for w in station.warnings],
    }


def summary_text(station: Station) -> str:
    s = summarise(station)
    lines = [
        f"{s['station']}: {s['name']['zh']} ({s['name']['en']})  [{s['file']}]",
        f"  tracks       {s['tracks']} ({metres(s['track_length_m'])} of track)",
        f"  turnouts     {s['turnouts']}" + (f" (crossover pairs {', '.join(s['crossover_pairs'])})"
                                             if s["crossover_pairs"] else ""),
        *([f"  double slips {', '.join(s['double_slips'])}"] if s["double_slips"] else []),
        f"  sections     {s['sections']} " + ", ".join(f"{k}: {v}" for k, v in s["section_types"].items()),
        f"  signals      {s['signals']} " + ", ".join(f"{k}: {v}" for k, v in s["signal_kinds"].items()),
        f"  platforms    {s['platforms']}",
        "  links        " + (", ".join(f"{lk['id']} ({lk['kind']} to {lk['neighbour']})" for lk in s["links"]) or "-"),
        f"  dead zones   {len(s['dead_zones'])}",
    ]
    lines += [f"    {d['joint']}: {number(d['from_m'])}-{metres(d['to_m'])}, {metres(d['length_m'])}"
              for d in s["dead_zones"]]
    lines.append(f"  warnings     {len(station.warnings)}")
    lines += [w.text("  ") for w in station.warnings]
    return fit_all(lines)
