"""``liansuo mutate``: the score of the checks against seeded defects (:mod:`proving.mutants`).

Each mutant is applied in turn and ``liansuo verify`` run on the stations, stopping at the first failure; a mutant
verify does not catch gets a short random run (``liansuo soak``) under the safety oracle on each station. A mutant
is caught when either finds anything. The score is the share caught.
"""

from __future__ import annotations

import argparse
import multiprocessing
import os
import time
from collections.abc import Callable, Iterable, Iterator, Sequence
from concurrent.futures import ProcessPoolExecutor
from contextlib import contextmanager
from dataclasses import dataclass
from importlib.resources import files
from pathlib import Path

from liansuo.kit.arguments import positive_int
from liansuo.kit.exitcodes import Exit, bad_input, refuse
from liansuo.kit.fit import fit, fit_all
from liansuo.kit.jsonreport import print_report
from liansuo.kit.native import native_modules
from liansuo.kit.source import StationError
from liansuo.proving.mutation.mutants import MUTANTS, Mutant
from liansuo.proving.soak.run import soak
from liansuo.proving.verify import verify_station
from liansuo.stations.hubgen import generate_hub
from liansuo.stations.library import bundled
from liansuo.stations.loader import load, load_text
from liansuo.stations.station import Station

Add = Callable[..., argparse.ArgumentParser]
SOAK_STEPS = 300


@dataclass
class Caught:
    mutant: str
    what: str
    by: str  # 'verify', 'oracle' (a safety property) or 'judge' (a command or release), during verify or a soak;
    station: str = ""
    check: str = ""
    detail: str = ""
    seconds: float = 0.0

    def as_dict(self) -> dict[str, object]:
        return {"mutant": self.mutant, "what": self.what, "caught_by": self.by or None, "station": self.station,
                "check": self.check, "detail": self.detail, "seconds": round(self.seconds, 2)}


HUB = "hub:10:4"  # a small generated hub: lines with no block described, double crossovers, paired signals


def default_stations() -> list[str]:
    """The bundled stations, the example stations (installed with the package, ``liansuo/examples``) and a small
    generated hub; the quickest to verify first."""
    out = sorted(bundled(), key=lambda name: (name != "jiaopei", name))
    examples = Path(str(files("liansuo"))) / "examples" / "stations"  # installed with the package
    if examples.is_dir():  # always, unless the package was installed without its data
        out[1:1] = [str(p) for p in sorted(examples.glob("*.yaml")) if p.stem != "minimal"]
    return [*out, HUB]


def load_station(spec: str) -> Station:
    """A bundled name, a station file, or ``hub:TURNOUTS:TRACKS`` for a generated hub."""
    if spec.startswith("hub:"):
        turnouts, tracks = (int(x) for x in spec.split(":")[1:3])
        return load_text(generate_hub(turnouts, tracks), f"<hub{turnouts}>")
    return load(spec)


def try_mutant(m: Mutant, stations: Sequence[Station], soak_steps: int = SOAK_STEPS) -> Caught:
    t0 = time.perf_counter()
    with m.applied():
        for st in stations:
            rep = verify_station(st, stop_at_first=True)
            if rep.failures:
                f = rep.failures[0]
                by = f.check if f.check in ("oracle", "judge") else "verify"
                return Caught(m.name, m.what, by, st.id, f.check if by == "verify" else f.subject, f.detail,
                              time.perf_counter() - t0)
        for st in stations:
            run = soak(st, soak_steps, 1)
            if run.violations:
                v = run.violations[0][0]
                return Caught(m.name, m.what, v.source, st.id, v.prop, f"soak: {v.text}", time.perf_counter() - t0)
    return Caught(m.name, m.what, "", seconds=time.perf_counter() - t0)


def _one(args: tuple[str, list[str], int]) -> Caught:
    name, stations, soak_steps = args
    m = next(x for x in MUTANTS if x.name == name)
    return try_mutant(m, [load_station(s) for s in stations], soak_steps)


def run_mutants(stations: Iterable[str] | None = None, mutants: Iterable[Mutant] = MUTANTS,
                soak_steps: int = SOAK_STEPS, workers: int | None = None) -> list[Caught]:
    """Try every mutant; ``workers`` processes at once (default: one per CPU), each mutant in a process of its
    own so its patches never leak into another's run."""
    chosen = list(stations or default_stations())
    jobs = [(m.name, first_where_it_shows(chosen, m.first), soak_steps) for m in mutants]
    # a seeded defect replaces a function or method, which compiled modules do not let happen: under a native build
    # (setup.py) the mutants run in fresh processes on the Python sources (LIANSUO_PURE=1), else forked from this one
    context = multiprocessing.get_context("spawn" if native_modules() else "fork")
    with _pure_children(bool(native_modules())), \
            ProcessPoolExecutor(max_workers=workers or os.cpu_count() or 1, mp_context=context) as pool:
        return list(pool.map(_one, jobs))


@contextmanager
def _pure_children(pure: bool) -> Iterator[None]:
    """While it lasts, the processes started from this one run liansuo's Python sources when ``pure``."""
    was = os.environ.get("LIANSUO_PURE")
    if pure:
        os.environ["LIANSUO_PURE"] = "1"
    try:
        yield
    finally:
        if pure:
            if was is None:
                os.environ.pop("LIANSUO_PURE", None)
            else:
                os.environ["LIANSUO_PURE"] = was


def first_where_it_shows(stations: list[str], first: str) -> list[str]:
    """``stations`` with those named ``first`` (a bundled name, a station file's name without .yaml, or a hub spec)
    in front: every station is still tried, in the same order otherwise."""
    def named(spec: str) -> bool:
        return bool(first) and (spec == first or Path(spec).stem == first)
    return sorted(stations, key=lambda spec: not named(spec))


def report_text(results: list[Caught]) -> str:
    caught = sum(bool(r.by) for r in results)
    lines = [f"liansuo mutate: {len(results)} seeded defects"]
    for r in results:
        where = f"{r.by} on {r.station} ({r.check})" if r.by else "NOT CAUGHT"
        lines.append(f"  {r.mutant:34} {where}")
        if r.by:
            lines.append(f"      {r.detail[:150]}")
    lines.append(f"score: {caught} of {len(results)} caught ({100 * caught / max(1, len(results)):.0f} %)")
    return fit_all(lines)


def cmd_mutate(args: argparse.Namespace) -> int:
    unknown = sorted(set(args.mutant or ()) - {m.name for m in MUTANTS})
    if unknown:
        return refuse("mutate", f"no mutant {', '.join(unknown)}; 'liansuo mutate --list' names them", Exit.USAGE)
    if args.list:
        for m in MUTANTS:
            print(fit(f"{m.name:34} {m.what}", " " * 35, keep=2))  # a long description under its own column
        return 0
    for spec in args.station or ():  # every station loads before any mutant runs
        try:
            load_station(spec)
        except StationError as exc:
            return bad_input(exc)
        except ValueError:
            return refuse("mutate", f"--station {spec}: a generated hub is hub:TURNOUTS:TRACKS", Exit.USAGE)
    chosen = [m for m in MUTANTS if not args.mutant or m.name in args.mutant]
    t0 = time.perf_counter()
    results = run_mutants(args.station or None, chosen, args.soak_steps)
    caught = sum(bool(r.by) for r in results)
    if args.format == "json":
        print_report("mutate", caught == len(results), {
            "mutants": len(results), "caught": caught, "score": round(caught / max(1, len(results)), 3),
            "elapsed_s": round(time.perf_counter() - t0, 1), "results": [r.as_dict() for r in results]})
    else:
        print(report_text(results))
    if caught < len(results):
        missed = [r.mutant for r in results if not r.by]
        return refuse("mutate", f"{len(missed)} seeded defect{'s' if len(missed) != 1 else ''} not caught: "
                      f"{', '.join(missed)}", Exit.FAILED)
    return 0


def register(add: Add) -> None:
    sp = add("mutate", cmd_mutate, "seed defects into the interlocking and show that verify and the oracle catch them")
    sp.add_argument("--station", action="append", metavar="STATION",
                    help="station to run on (repeatable; default: the bundled and example stations)")
    sp.add_argument("--mutant", action="append", metavar="NAME",
                    help="only this mutant (repeatable; --list names them)")
    sp.add_argument("--list", action="store_true", help="list the mutants and exit")
    sp.add_argument("--soak-steps", type=positive_int, default=SOAK_STEPS, metavar="N",
                    help=f"random steps per station for a mutant verify misses (default {SOAK_STEPS})")
    sp.add_argument("--format", choices=("text", "json"), default="text", help="text (default) or json")
    sp.set_defaults(handler=cmd_mutate)
