"""``liansuo bench --explore``: the figures of ``liansuo explore`` (docs/explore.md, docs/benchmark.md).

* ``saturation``: the bounded models of the minimal station and of danxian, one route at a time, explored until no
  new state comes (a proof for that model) or the budget runs out: depth, states, seconds;
* ``depth``: how deep every sequence of jiaopei gets within a time budget, on 2 Dask workers, with states/s per worker;
* ``mutants``: the mutation score of explore alone: every mutant of ``liansuo mutate``, explored breadth first until
  the first violation or the oracle's or judge's finding (a shortest sequence), on the station where its defect
  shows and on the minimal one, each within a budget; which were found, at what depth, in how long.
"""

from __future__ import annotations

import time
import uuid
from dataclasses import asdict, dataclass
from importlib.resources import files
from pathlib import Path
from typing import Any

from liansuo.proving.explore.actions import Bounds
from liansuo.proving.explore.search import Expander, expand_here, expand_on, search
from liansuo.proving.mutation.cli import default_stations, first_where_it_shows, load_station
from liansuo.proving.mutation.mutants import MUTANTS
from liansuo.proving.spread import client
from liansuo.rules import load_rules

EXAMPLES = Path(str(files("liansuo"))) / "examples" / "stations"  # installed with the package


@dataclass(frozen=True)
class ExploreSizes:
    saturate_depth: int = 60
    saturate_budget_s: float = 600.0  # per station: where it runs out, the report says how far it got
    depth_station: str = "jiaopei"
    depth_budget_s: float = 600.0
    depth_workers: int = 2
    mutant_depth: int = 7
    mutant_budget_s: float = 15.0  # per mutant and station
    mutants: tuple[str, ...] = ()  # () = every one

    @staticmethod
    def quick() -> ExploreSizes:
        return ExploreSizes(saturate_budget_s=60.0, depth_budget_s=60.0, mutant_depth=4, mutant_budget_s=5.0)


SATURATE = (("minimal", Bounds(1, 0, 1, 0, 0)), ("danxian", Bounds(1, 0, 1, 0, 0)))


def measure_explore(sizes: ExploreSizes | None = None) -> dict[str, Any]:
    sizes = sizes or ExploreSizes()
    rules = load_rules()
    out: dict[str, Any] = {"saturation": [], "mutants": []}
    st = load_station(sizes.depth_station)
    root = Expander(st, rules, bounds=Bounds())
    with client(sizes.depth_workers, None) as c:
        expand = expand_on(c, (uuid.uuid4().hex, st, rules, Bounds(), True))
        o = search(st, expand, root.root_key, 12, budget_s=sizes.depth_budget_s)
    out["depth"] = {"station": sizes.depth_station, "workers": sizes.depth_workers, "budget_s": sizes.depth_budget_s,
                    "depth": o.depth, "states": o.states, "transitions": o.transitions,
                    "seconds": round(o.seconds, 1), "states_per_s_per_worker":
                    round(o.states / o.seconds / sizes.depth_workers, 1) if o.seconds else 0.0,
                    "levels": [{"depth": lv.depth, "states": lv.states, "seconds": round(lv.seconds, 1)}
                               for lv in o.levels], "stopped": o.stopped, "violations": sorted(o.findings)}
    for name, bounds in SATURATE:
        st = load_station(str(EXAMPLES / f"{name}.yaml"))
        ex = Expander(st, rules, bounds=bounds)
        o = search(st, expand_here(ex), ex.root_key, sizes.saturate_depth, budget_s=sizes.saturate_budget_s)
        out["saturation"].append({"station": name, "bounds": asdict(bounds), "depth": o.depth, "states": o.states,
                                  "transitions": o.transitions, "seconds": round(o.seconds, 1),
                                  "saturated": o.saturated, "stopped": o.stopped,
                                  "violations": sorted(o.findings)})
    stations = default_stations()
    minimal = str(EXAMPLES / "minimal.yaml")
    for m in MUTANTS:
        if sizes.mutants and m.name not in sizes.mutants:
            continue
        tried = [first_where_it_shows(stations, m.first)[0] if m.first else "jiaopei", minimal]
        found: dict[str, Any] = {"mutant": m.name, "found": False}
        t0 = time.monotonic()
        with m.applied():
            for spec in dict.fromkeys(tried):
                st = load_station(spec)
                ex = Expander(st, rules, bounds=Bounds())
                o = search(st, expand_here(ex), ex.root_key, sizes.mutant_depth, budget_s=sizes.mutant_budget_s,
                           first=True)
                if o.findings:
                    key, f = min(o.findings.items(), key=lambda kv: len(kv[1].trace))
                    found.update(found=True, station=st.id, depth=len(f.trace), by=f.violation.source,
                                 finding=key, steps=[s.line for s in f.trace])
                    break
        found["seconds"] = round(time.monotonic() - t0, 1)
        out["mutants"].append(found)
    caught = sum(1 for r in out["mutants"] if r["found"])
    out["mutant_score"] = {"caught": caught, "mutants": len(out["mutants"]),
                           "score": round(caught / len(out["mutants"]), 3) if out["mutants"] else None}
    return out
