"""The whole benchmark: how much to run, every figure of every station, the targets met or missed, and the report
as JSON or text (``liansuo bench``)."""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from liansuo.bench import classroom
from liansuo.bench.busy import BUSY_ROUTES
from liansuo.bench.field import measure_field
from liansuo.bench.history import append
from liansuo.bench.machine import machine
from liansuo.bench.scale import ScaleSizes, measure_scale
from liansuo.bench.station import measure
from liansuo.bench.trains import TARGET_RATIO, TARGET_TRAINS, run_trains, trains_text
from liansuo.bench.zpw import ZPW_TARGET_CONFIGS_PER_S, measure_zpw
from liansuo.interlocking.table.build import build_table
from liansuo.kit.exitcodes import Exit, refuse
from liansuo.kit.fit import fit_all
from liansuo.kit.jsonreport import print_report
from liansuo.kit.jsonreport import report as jsonreport
from liansuo.kit.native import native_modules
from liansuo.proving.progress import Advance, progress
from liansuo.stations.hubgen import generate_hub
from liansuo.stations.loader import load_text

HUB_TURNOUTS = 200
HUB_TRACKS = 80

# (figure, comparison, target) per station; reported with the measured value, never asserted
TARGETS: dict[str, list[tuple[str, str, float]]] = {
    "hub": [("table_build_s", "<=", 5.0), ("cycle_us_busy", "<=", 1000.0), ("realtime_factor", ">=", 250.0)],
    "jiaopei": [("realtime_factor", ">=", 5000.0)],
}


@dataclass(frozen=True)
class Sizes:
    """How much to run: the full benchmark, ``--quick``, or a tiny run for the test suite."""

    hub_turnouts: int = HUB_TURNOUTS
    hub_tracks: int = HUB_TRACKS
    idle_cycles: int = 8000
    busy_cycles: int = 16000
    small_factor: int = 5  # jiaopei runs this many times more cycles (each is much cheaper)
    busy_routes: int = BUSY_ROUTES
    warmup_limit: int = 2400  # cycles allowed for the busy routes to be set and opened once
    zpw_repeats: int = 10  # vectorised ZPW-2000A sweeps timed
    train_cycles: int = 4800  # trains moving on the hub, each engine (trains.py); 0 skips it
    train_slots: int = 10
    field_cycles: int = 2000  # jiaopei in field control against field-sim (field.py); 0 skips it
    # the classroom under attack (classroom.py): honest round trips timed in each case (0 skips it all), commands
    # sent to one seat for its memory, wrong instructor logins sent at once
    classroom_round_trips: int = 200
    classroom_commands: int = 100_000
    classroom_logins: int = 500

    @staticmethod
    def quick() -> Sizes:
        return Sizes(idle_cycles=1000, busy_cycles=2400, zpw_repeats=3, train_cycles=1200, field_cycles=400,
                     classroom_round_trips=50, classroom_commands=10_000)

    @staticmethod
    def tiny() -> Sizes:
        return Sizes(hub_turnouts=20, hub_tracks=8, idle_cycles=20, busy_cycles=120, small_factor=1,
                     warmup_limit=400, zpw_repeats=1, train_cycles=240, train_slots=2, field_cycles=0,
                     classroom_round_trips=5, classroom_commands=1000, classroom_logins=20)


def _check_targets(results: dict[str, dict[str, Any]]) -> list[dict[str, Any]]:
    checks = []
    for key, targets in TARGETS.items():
        res = results.get(key)
        if res is None:
            continue
        for figure, op, target in targets:
            value = float(res[figure])
            met = value <= target if op == "<=" else value >= target
            checks.append({"station": res["station"], "figure": figure, "target": f"{op} {target:g}",
                           "value": value, "met": met})
    return checks


def run_bench(sizes: Sizes | None = None, *, quick: bool = False, stations: tuple[str, ...] = ("jiaopei", "hub"),
              scale: ScaleSizes | None = None, show_progress: bool | None = False) -> dict[str, Any]:
    """Run the benchmark and return every figure (see the module docstring and docs/benchmark.md); with ``scale``
    also the figures of :mod:`.scale` (verify, soak and the table at hub size). ``show_progress``: a bar of the
    parts on stderr (None: when it is a terminal)."""
    sizes = sizes or (Sizes.quick() if quick else Sizes())
    parts = len(stations) + 4 + (scale is not None)
    with progress("bench", parts, show=show_progress) as advance:
        return _run(sizes, quick, stations, scale, advance)


def _run(sizes: Sizes, quick: bool, stations: tuple[str, ...], scale: ScaleSizes | None, advance: Advance
         ) -> dict[str, Any]:
    start = time.perf_counter()
    results: dict[str, dict[str, Any]] = {}
    for key in stations:  # the small station first, so its peak memory is its own
        if key == "hub":
            text = generate_hub(sizes.hub_turnouts, sizes.hub_tracks)
            results[key] = measure(text, label=f"hub{sizes.hub_turnouts}", text=True,
                                   idle_cycles=sizes.idle_cycles, busy_cycles=sizes.busy_cycles,
                                   routes_limit=sizes.busy_routes, warmup_limit=sizes.warmup_limit)
            results[key]["hub_tracks"] = sizes.hub_tracks
        else:
            results[key] = measure(key, label=key, text=False, idle_cycles=sizes.idle_cycles * sizes.small_factor,
                                   busy_cycles=sizes.busy_cycles * sizes.small_factor,
                                   routes_limit=sizes.busy_routes, warmup_limit=sizes.warmup_limit)
        advance(1)
    scaled = measure_scale(scale) if scale is not None else None
    advance(1 if scale is not None else 0)
    zpw = measure_zpw(sizes.zpw_repeats)
    advance(1)
    trains = _trains(sizes) if "hub" in stations and sizes.train_cycles > 0 else None
    advance(1)
    field = measure_field(sizes.field_cycles) if sizes.field_cycles > 0 else None
    advance(1)
    room = (classroom.measure_classroom(sizes.classroom_round_trips, sizes.classroom_commands,
                                        sizes.classroom_logins) if sizes.classroom_round_trips > 0 else None)
    advance(1)
    targets = _check_targets(results)
    targets.append({"station": "zpw", "figure": "zpw_configs_per_s", "target": f">= {ZPW_TARGET_CONFIGS_PER_S:g}",
                    "value": zpw["zpw_configs_per_s"], "met": zpw["zpw_configs_per_s"] >= ZPW_TARGET_CONFIGS_PER_S})
    if trains is not None:
        value = trains["realtime_factor_trains"]
        targets.append({"station": trains["station"], "figure": "realtime_factor_trains",
                        "target": f">= {TARGET_TRAINS:g}", "value": value, "met": value >= TARGET_TRAINS})
        ratio = trains["ratio_kinematic_to_sumo"]
        if ratio is not None:  # SUMO ran beside it (without SUMO the trains figures say why not)
            targets.append({"station": trains["station"], "figure": "ratio_kinematic_to_sumo",
                            "target": f">= {TARGET_RATIO:g}", "value": ratio, "met": ratio >= TARGET_RATIO})
    if room is not None:
        targets += classroom.targets(room)
    return {
        "benchmark": "liansuo bench",
        "mode": "quick" if quick else ("custom" if sizes != Sizes() else "full"),
        "machine": machine(),
        # the modules that ran compiled (a native build, docs/native.md); [] for the Python sources
        "native": native_modules(),
        "cycle_s": 0.25,
        "results": results,
        "zpw": zpw,
        **({"trains": trains} if trains is not None else {}),
        **({"field": field} if field is not None else {}),
        **({"classroom": room} if room is not None else {}),
        **({"scale": scaled} if scaled is not None else {}),
        "targets": targets + [{"station": "hub", **t} for t in (scaled or {}).get("targets", [])],
        "total_s": round(time.perf_counter() - start, 2),
    }


def _trains(sizes: Sizes) -> dict[str, Any]:
    """Trains moving on the hub: the kinematic engine and SUMO side by side (:mod:`.trains`)."""
    station = load_text(generate_hub(sizes.hub_turnouts, sizes.hub_tracks), f"<hub{sizes.hub_turnouts}>")
    return run_trains(station, build_table(station), cycles=sizes.train_cycles, sumo_cycles=sizes.train_cycles,
                      slots=sizes.train_slots)


def all_finite(value: object) -> bool:
    """True when every number in a (nested) benchmark result is finite."""
    if isinstance(value, dict):
        return all(all_finite(v) for v in value.values())
    if isinstance(value, list):
        return all(all_finite(v) for v in value)
    if isinstance(value, float):
        return math.isfinite(value)
    return True


# ---- output --------------------------------------------------------------------------------------------------------
_TEXT_ROWS = [
    ("turnouts", "turnouts", "{:d}"), ("sections", "sections", "{:d}"), ("routes", "routes", "{:d}"),
    ("load_s", "load (s)", "{:.3f}"), ("table_build_s", "table build (s)", "{:.3f}"),
    ("cycle_us_idle", "cycle idle (us)", "{:.1f}"), ("cycle_us_busy", "cycle busy (us)", "{:.1f}"),
    ("circuit_us_busy", "  of it circuits (us)", "{:.1f}"),
    ("busy_routes", "busy routes", "{:d}"), ("realtime_factor", "real-time factor (busy)", "{:.0f}x"),
    ("realtime_factor_idle", "real-time factor (idle)", "{:.0f}x"), ("busy_traversals", "traversals", "{:d}"),
    ("busy_stalls", "stalls", "{:d}"), ("peak_memory_mb", "peak RSS (MB)", "{:.1f}"),
]


def as_text(report: dict[str, Any]) -> str:
    m = report["machine"]
    lines = [f"liansuo bench ({report['mode']}) on {m['cpu_model'] or m['processor'] or m['machine']}, "
             f"{m['cpu_count']} CPUs, Python {m['python']}, "
             + (f"native build ({len(report['native'])} modules compiled)" if report.get("native") else "pure Python")]
    results = report["results"]
    keys = list(results)
    lines.append(f"{'':26}" + "".join(f"{results[k]['station']:>14}" for k in keys))
    for field, title, fmt in _TEXT_ROWS:
        lines.append(f"{title:26}" + "".join(f"{fmt.format(results[k][field]):>14}" for k in keys))
    z = report.get("zpw")
    if z:
        lines.append(f"{'zpw configs/s':26}{z['zpw_configs_per_s']:>14.0f}  ({z['configurations']} per sweep of "
                     f"{z['sweep_s'] * 1000:.1f} ms; evaluate {z['evaluate_us_one_shunt']:.0f} us, 64-axle train "
                     f"{z['evaluate_us_train64']:.0f} us)")
    if report.get("trains"):
        lines += trains_text(report["trains"])
    f = report.get("field")
    if f:
        lines.append(f"{'field mode':26}" + (f"skipped: {f['skipped']}" if "skipped" in f else
                     f"{f['field_cycles_per_s']:.0f} cycles/s on {f['station']} over {f['transport']} "
                     f"({f['field_cycle_ms']:.2f} ms a cycle, {f['realtime_factor_field']:.0f}x real time; simulated "
                     f"control {f['simulated_cycles_per_s']:.0f} cycles/s, {f['ratio_simulated_to_field']:.1f}x)"))
    if report.get("classroom"):
        lines += classroom.text(report["classroom"])
    sc = report.get("scale")
    if sc:
        lines.append("scale:")
        lines += [f"  {k:34} {v}" for k, v in sc.items() if k != "targets"]
    lines.append("targets:")
    for t in report["targets"]:
        lines.append(f"  {t['station']:10} {t['figure']:16} {t['target']:>8}  measured {t['value']:g}  "
                     f"{'met' if t['met'] else 'MISSED'}")
    lines.append(f"total {report['total_s']:.1f} s")
    return fit_all(lines)


def main(quick: bool = False, fmt: str = "json", scale: bool = False, explore: bool = False,
         history: Path | None = None) -> int:
    if explore:  # its own run: it takes the better part of an hour in full
        from liansuo.bench.explore import ExploreSizes, measure_explore

        figures = measure_explore(ExploreSizes.quick() if quick else ExploreSizes())
        report: dict[str, Any] = {"benchmark": "liansuo explore", "mode": "quick" if quick else "full",
                                  "machine": machine(), "explore": figures}
        if fmt == "json":
            print_report("bench", True, report)
        else:
            print(explore_text(figures))
        return _keep(history, report)
    sizes = (ScaleSizes.quick() if quick else ScaleSizes()) if scale else None
    report = run_bench(quick=quick, scale=sizes, show_progress=None)
    if fmt == "json":
        print_report("bench", True, report)  # the figures are reported, never judged: always ok
    else:
        print(as_text(report))
    return _keep(history, report)


def _keep(history: Path | None, report: dict[str, Any]) -> int:
    """Append the report to the history, if one was asked for; a file that became unwritable during the run is
    refused with the report already printed."""
    if history is None:
        return 0
    try:
        append(history, jsonreport("bench", True, report))
    except OSError as exc:
        return refuse("bench", f"cannot append to {history}: {exc.strerror or exc}; the report above was not kept",
                      Exit.BAD_INPUT)
    return 0


def explore_text(f: dict[str, Any]) -> str:
    lines = ["liansuo explore"]
    for s in f["saturation"]:
        lines.append(f"  {s['station']} (bounds {s['bounds']}): depth {s['depth']}, {s['states']:,} states in "
                     f"{s['seconds']} s, {'saturated' if s['saturated'] else 'not saturated: ' + s['stopped']}")
    d = f["depth"]
    lines.append(f"  {d['station']} on {d['workers']} workers within {d['budget_s']:g} s: depth {d['depth']} in full, "
                 f"{d['states']:,} states, {d['states_per_s_per_worker']:,} states/s per worker ({d['stopped']})")
    ms = f["mutant_score"]
    lines.append(f"  mutants found by explore alone: {ms['caught']} of {ms['mutants']}")
    for m in f["mutants"]:
        where = f"{m['station']} at depth {m['depth']} ({m['by']}: {m['finding']})" if m["found"] else "not found"
        lines.append(f"    {m['mutant']:<34} {where}, {m['seconds']} s")
    return fit_all(lines)
