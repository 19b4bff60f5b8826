"""What an exploration found, for people and for tools: each finding with its shortest sequence as a runnable
``liansuo test`` script (``safety: true``), the levels, the bounds and whether the search saturated."""

from __future__ import annotations

from dataclasses import asdict
from pathlib import Path
from typing import Any

import yaml

from liansuo.proving.explore.actions import Bounds
from liansuo.proving.explore.search import Found, SearchOutcome

# what the explored model leaves out or bounds, said with every report (docs/explore.md)
ABSTRACTIONS = (
    "the field at the level of its relays' causes: sections occupied and cleared (at an entry, next to an occupied "
    "section), turnout indications lost and machines stuck, lamps failing, screen doors sticking; no trains",
    "time runs only to the next moment something changes (a switch machine arriving, a timer running out); timers "
    "are told apart by the order in which they run out, not by the seconds left",
    "after a command or an event the interlocking answers (it takes its cycles) before the next one happens",
    "routes set in either order, and turnout moves queued in either order, are one state",
)


def script(station: str, f: Found) -> str:
    """The shortest sequence that shows finding ``f``, as a test script that fails at its last step."""
    lines = [part for step in f.trace for part in step.line.split("; ")]
    v = f.violation
    if Path(station).is_file():  # a file: found from wherever the script is written (a bundled name stays a name)
        station = str(Path(station).resolve())
    head = (f"# liansuo explore {station}: {v.prop}, found at depth {len(f.trace)} (t = {v.t:g} s): {v.text}\n"
            "# The shortest sequence that shows it; with the safety oracle on, 'liansuo test FILE' fails at its "
            "last step.\n")
    body = {"station": station, "safety": True,
            "tests": [{"name": f"explore: {v.prop} {v.key.partition(':')[2]}", "steps": lines}]}
    return head + yaml.safe_dump(body, allow_unicode=True, sort_keys=False, width=200)


def as_dict(out: SearchOutcome, station: str, asked: int, workers: int, bounds: Bounds, reduce: bool) -> dict[str, Any]:
    rate = out.states / out.seconds if out.seconds > 0 else 0.0
    hazards: dict[str, int] = {}
    for f in out.hazards.values():
        hazards[f.violation.prop] = hazards.get(f.violation.prop, 0) + 1
    return {
        "station": out.station, "depth_asked": asked, "depth": out.depth, "saturated": out.saturated,
        "stopped": out.stopped or None, "states": out.states, "transitions": out.transitions,
        "seconds": round(out.seconds, 2), "states_per_s": round(rate, 1),
        "states_per_s_per_worker": round(rate / max(1, workers), 1), "workers": workers,
        "bounds": asdict(bounds), "reduction": "partial order" if reduce else "none",
        "abstractions": list(ABSTRACTIONS),
        "levels": [{"depth": lv.depth, "states": lv.states, "transitions": lv.transitions,
                    "seconds": round(lv.seconds, 2)} for lv in out.levels],
        "violations": [{"key": key, "property": f.violation.prop, "text": f.violation.text, "depth": len(f.trace),
                        "t": f.violation.t, "steps": [p for s in f.trace for p in s.line.split("; ")],
                        "reproducer": script(station, f)} for key, f in sorted(out.findings.items())],
        "hazards": dict(sorted(hazards.items())),
    }


def as_text(rep: dict[str, Any]) -> list[str]:
    b = rep["bounds"]
    head = (f"liansuo explore {rep['station']}: depth {rep['depth']} of {rep['depth_asked']}, {rep['states']:,} "
            f"states, {rep['transitions']:,} transitions in {rep['seconds']:.1f} s ({rep['states_per_s']:,.0f} "
            f"states/s on {max(1, rep['workers'])} worker(s))")
    lines = [head]
    if rep["saturated"]:
        lines.append(f"SATURATED at depth {rep['depth']}: no new state at the next depth; every reachable state of the "
                     "bounded model was checked")
    elif rep["stopped"]:
        lines.append(f"not saturated: {rep['stopped']}")
    else:
        lines.append(f"not saturated: states still new at depth {rep['depth']}")
    lines.append(f"bounds: {b['routes']} routes, {b['faults']} faults, {b['occupied']} occupied sections, "
                 f"{b['turnout_marks']} single locks/blocks, {b['guide_locks']} guide total locks at once; reduction: "
                 f"{rep['reduction']}")
    lines.append("level  new states  transitions  seconds")
    lines += [f"{lv['depth']:>5}  {lv['states']:>10,}  {lv['transitions']:>11,}  {lv['seconds']:>7.1f}"
              for lv in rep["levels"]]
    if rep["hazards"]:
        lines.append("hazards (dangers the interlocking cannot see by design, not violations): "
                     + ", ".join(f"{k} {n}" for k, n in rep["hazards"].items()))
    for v in rep["violations"]:
        lines.append(f"VIOLATION {v['property']} at depth {v['depth']}: {v['text']}")
        lines.append("  " + " | ".join(v["steps"]))
    lines.append(f"{len(rep['violations'])} violations")
    return lines
