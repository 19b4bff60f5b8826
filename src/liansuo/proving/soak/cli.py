"""``liansuo soak STATION --steps N --seed S [--runs K] [--workers W] [--scheduler ADDRESS] [--format text|json]
[--out DIR]``: long random runs under the safety oracle, with a reproducer script for each violation.

``--runs K`` makes K independent runs, seeds S .. S+K-1, each of N steps; ``--workers W`` fans them out on Dask
(:mod:`.spread`; K defaults to W), and the runs are reported in seed order whatever finished first.

A reproducer is a YAML test script with ``safety: true``: ``liansuo test FILE`` (or pytest) replays the commands and
fails at the step where the violation happens. It is cut down from the run: first the shortest tail of the commands
before the violation that still shows it on a fresh station, then single steps and chunks are dropped while it still
does (within a budget of replays).
"""

from __future__ import annotations

import argparse
import time
from collections.abc import Callable
from pathlib import Path

from liansuo.kit.arguments import count, positive_int
from liansuo.kit.exitcodes import Exit, bad_input, refuse
from liansuo.kit.fit import fit_all
from liansuo.kit.jsonreport import print_report
from liansuo.proving.oracle import Violation, Watch
from liansuo.proving.progress import progress
from liansuo.proving.soak.run import SoakRun, soak
from liansuo.proving.spread import WAIT_S, SpreadError, add_wait_option, fan_out
from liansuo.simulation.sim import Simulation

Add = Callable[..., argparse.ArgumentParser]
MAX_REPRODUCERS = 5
SHRINK_BUDGET_S = 30.0


def shows(station: str, lines: list[str], key: str, cycle_s: float = 0.25) -> bool:
    """Do ``lines`` on a fresh simulation lead to a violation with ``key``?"""
    sim = Simulation(station, cycle_s=cycle_s)
    checker = Watch(sim)
    for line in lines:
        sim.command(line)
        if any(v.key == key for v in checker.violations):
            return True
    return False


def shrink(station: str, lines: list[str], key: str, budget_s: float = SHRINK_BUDGET_S) -> list[str]:
    """A short list of lines that still shows the violation ``key`` (``lines`` itself if nothing shorter does)."""
    deadline = time.perf_counter() + budget_s
    best = lines
    n = 16
    while n < len(lines):  # the shortest tail that shows it
        if time.perf_counter() > deadline:
            return best
        if shows(station, lines[-n:], key):
            best = lines[-n:]
            break
        n *= 2
    chunk = max(1, len(best) // 2)
    while chunk >= 1 and time.perf_counter() < deadline:
        i = 0
        while i < len(best) and time.perf_counter() < deadline:
            candidate = best[:i] + best[i + chunk:]
            if candidate and shows(station, candidate, key):
                best = candidate
            else:
                i += chunk
        chunk //= 2
    return best


def merge_runs(lines: list[str]) -> list[str]:
    """Consecutive ``run Nms`` lines as one (the same cycles)."""
    out: list[str] = []
    for line in lines:
        if line.startswith("run ") and line.endswith("ms") and out and out[-1].startswith("run ") \
                and out[-1].endswith("ms"):
            out[-1] = f"run {int(out[-1][4:-2]) + int(line[4:-2])}ms"
        else:
            out.append(line)
    return out


def annotate_refusals(station: str, lines: list[str], cycle_s: float = 0.25) -> list[str]:
    """The lines with ``expect refused ...`` after each command a fresh station refuses, so that the script replays
    under ``liansuo test`` (where a refused command otherwise fails the test) up to the violation."""
    sim = Simulation(station, cycle_s=cycle_s)
    out: list[str] = []
    for line in lines:
        out.append(line)
        result = sim.command(line)
        if not result.ok and not line.startswith("run "):
            out.append(f"expect refused {result.message[:60]}")
    return out


def reproducer(run: SoakRun, v: Violation, lines: list[str]) -> str:
    import yaml

    lines = annotate_refusals(run.source, merge_runs(lines))

    head = (f"# liansuo soak {run.station} --seed {run.seed}: at t = {v.t:g} s, {v.prop}: {v.text}\n"
            f"# Replays with the safety oracle on: 'liansuo test FILE' fails at the step where it happens.\n")
    body = {"station": run.source, "safety": True,
            "tests": [{"name": f"soak seed {run.seed}: {v.prop} {v.key.partition(':')[2]}", "steps": lines}]}
    return head + yaml.safe_dump(body, allow_unicode=True, sort_keys=False, width=200)


def report(run: SoakRun, *, shrink_budget_s: float = SHRINK_BUDGET_S) -> dict[str, object]:
    done: set[str] = set()
    out = []
    for v, n in run.violations:
        entry: dict[str, object] = {**v.as_dict(), "line": n, "reproducer": None}
        if v.key not in done and len(done) < MAX_REPRODUCERS:
            done.add(v.key)
            entry["reproducer"] = reproducer(run, v, shrink(run.source, run.lines[:n], v.key, shrink_budget_s))
        out.append(entry)
    return {"station": run.station, "seed": run.seed, "steps": run.steps, "cycles": run.cycles,
            "simulated_s": round(run.simulated_s, 2), "commands": len(run.lines), "refused": run.refused,
            "elapsed_s": round(run.elapsed_s, 2), "hazards": dict(sorted(run.hazards.items())), "violations": out}


def run_seed(shared: tuple[str, int], seed: int) -> dict[str, object]:
    """One whole run and its report (reproducers included): what a worker does for one seed."""
    station, steps = shared
    return report(soak(station, steps, seed))


def soak_runs(station: str, steps: int, seeds: list[int], *, workers: int = 0, scheduler: str | None = None,
              show_progress: bool | None = False, cluster_wait_s: float = WAIT_S) -> list[dict[str, object]]:
    """The report of a run for each seed, in seed order: here one after the other, or on Dask."""
    from liansuo.stations.loader import load

    load(station)  # a station that does not load is reported here, once, not by every worker
    with progress(f"soak {Path(station).stem}", len(seeds) * steps, show=show_progress) as advance:
        if not workers:
            out = []
            for seed in seeds:
                out.append(run_seed((station, steps), seed))
                advance(steps)
            return out
        return fan_out((station, steps), seeds, run_seed, workers=workers, scheduler=scheduler, advance=advance,
                       size=lambda seed: steps, wait_s=cluster_wait_s)


def cmd_soak(args: argparse.Namespace) -> int:
    from liansuo.kit.source import StationError

    workers = args.workers or (1 if args.scheduler else 0)
    runs = args.runs or max(1, workers)
    seeds = [args.seed + k for k in range(runs)]
    t0 = time.perf_counter()
    try:
        reps = soak_runs(args.station, args.steps, seeds, workers=workers, scheduler=args.scheduler,
                         show_progress=None, cluster_wait_s=args.cluster_wait)
    except StationError as exc:
        return bad_input(exc)
    except SpreadError as exc:
        return refuse("soak", str(exc), Exit.USAGE)
    elapsed = time.perf_counter() - t0
    found = 0
    for rep in reps:
        violations: list[dict[str, object]] = rep["violations"]  # type: ignore[assignment]
        found += len(violations)
        if args.out:
            out = Path(args.out)
            out.mkdir(parents=True, exist_ok=True)
            for k, v in enumerate(x for x in violations if x["reproducer"]):
                (out / f"soak-{rep['station']}-{rep['seed']}-{k + 1}.yaml").write_text(str(v["reproducer"]),
                                                                                    encoding="utf-8")
    if args.format == "json":
        if len(reps) == 1 and not workers:
            print_report("soak", not found, reps[0])
        else:
            steps = sum(int(str(r["steps"])) for r in reps)
            print_report("soak", not found, {"station": reps[0]["station"], "runs": reps, "workers": workers,
                                             "steps": steps, "elapsed_s": round(elapsed, 2),
                                             "steps_per_s": round(steps / elapsed, 1), "violations": found})
    else:
        for rep in reps:
            print(run_text(rep))
        if len(reps) > 1:
            print(f"{len(reps)} runs (seeds {seeds[0]}..{seeds[-1]}) on {workers or 1} worker(s) in {elapsed:.1f} s: "
                  f"{found} violations")
    if found:
        return refuse("soak", f"{found} safety violation{'s' if found != 1 else ''} (the reproducers are in the "
                      "report)", Exit.FAILED)
    return 0


def run_text(rep: dict[str, object]) -> str:
    violations: list[dict[str, object]] = rep["violations"]  # type: ignore[assignment]
    hazards: dict[str, int] = rep["hazards"]  # type: ignore[assignment]
    lines = [f"liansuo soak {rep['station']}: {rep['steps']} steps (seed {rep['seed']}), {rep['cycles']} cycles, "
             f"{float(str(rep['simulated_s'])):.0f} s simulated, {rep['commands']} commands ({rep['refused']} "
             f"refused), {float(str(rep['elapsed_s'])):.1f} s"]
    if hazards:
        lines.append("hazards (dangers the interlocking cannot see by design, not violations): "
                     + ", ".join(f"{k} {n}" for k, n in sorted(hazards.items())))
    for v in violations:
        lines.append(f"VIOLATION t = {v['t']:g} s {v['property']}: {v['text']}")
        if v["reproducer"]:
            lines.append("  reproducer:\n" + "\n".join(f"    {line}" for line in str(v["reproducer"]).splitlines()))
    lines.append(f"{len(violations)} violations")
    return fit_all(lines)


def register(add: Add) -> None:
    sp = add("soak", cmd_soak, "random operation under the safety oracle; a reproducer script per violation")
    sp.add_argument("station", help="bundled station name or path to a station YAML file")
    sp.add_argument("--steps", type=positive_int, default=10_000, metavar="N", help="random steps (default 10000)")
    sp.add_argument("--seed", type=int, default=1, metavar="S",
                    help="seed of the random choices (default 1): the same seed gives the same run")
    sp.add_argument("--format", choices=("text", "json"), default="text", help="text (default) or json")
    sp.add_argument("--out", metavar="DIR", help="also write each reproducer to DIR/soak-STATION-SEED-N.yaml")
    sp.add_argument("--runs", type=count, default=0, metavar="K",
                    help="independent runs, seeds SEED .. SEED+K-1 (default: one per worker)")
    sp.add_argument("--workers", type=count, default=0, metavar="N",
                    help="fan the runs out on Dask over N local worker processes (default: run here)")
    sp.add_argument("--scheduler", metavar="ADDRESS",
                    help="run on the Dask cluster whose scheduler is at ADDRESS (tcp://host:8786); "
                         "'liansuo docs cluster'")
    add_wait_option(sp)
    sp.set_defaults(handler=cmd_soak)
