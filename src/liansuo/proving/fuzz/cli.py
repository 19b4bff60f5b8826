"""``liansuo fuzz KIND [--budget N] [--seed S] [--limit SECONDS] [--keep DIR] [--format text|json] [-o FILE]``:
the suite's fuzz generators run longer (proving/fuzz/runner.py; docs/robustness.md).

The kinds live beside what they exercise, so the console's (tui/) and the others' (proving/) stay on their own
floors; this command, on the floor above both, knows them by name. hypothesis draws the samples: it comes with the
``fuzz`` extra (``pip install 'liansuo[fuzz]'``).
"""

from __future__ import annotations

import argparse
import json
from collections.abc import Callable
from importlib import import_module
from importlib.util import find_spec
from pathlib import Path
from types import ModuleType

from liansuo.kit.arguments import count, positive_int, positive_number, unwritable
from liansuo.kit.exitcodes import Exit, refuse
from liansuo.kit.extras import needed
from liansuo.kit.jsonreport import report
from liansuo.kit.output import deliver

Add = Callable[..., argparse.ArgumentParser]

# kind -> the module that generates and attempts it (NAME, strategy(), attempt(sample))
KINDS: dict[str, str] = {
    "stations": "liansuo.proving.fuzz.stations",
    "commands": "liansuo.proving.fuzz.commands",
    "console": "liansuo.proving.fuzz.console",
    "recordings": "liansuo.proving.fuzz.recordings",
}


def kind_module(kind: str) -> ModuleType:
    return import_module(KINDS[kind])


def _keep(folder: Path, kind: str, defects: list[tuple[int, str]]) -> list[str]:
    """Write each defect's whole sample to ``DIR/KIND-N.txt``; the files written."""
    folder.mkdir(parents=True, exist_ok=True)
    written = []
    for n, whole in defects:
        path = folder / f"{kind}-{n}.txt"
        path.write_text(whole + "\n", encoding="utf-8")
        written.append(str(path))
    return written


def cmd_fuzz(args: argparse.Namespace) -> int:
    if find_spec("hypothesis") is None:
        return refuse("fuzz", "needs hypothesis, which comes with the fuzz extra: pip install 'liansuo[fuzz]'",
                      Exit.USAGE)
    if args.kind == "console" and (why := needed("console")):  # it drives the console's widgets
        return refuse("fuzz", why, Exit.USAGE)
    if args.output and (why := unwritable(Path(args.output))):
        return refuse("fuzz", why, Exit.USAGE)
    from liansuo.proving.fuzz.runner import as_text, run
    from liansuo.proving.progress import progress

    kind = kind_module(args.kind)
    with progress(f"fuzz {args.kind}", args.budget) as advance:
        rep = run(kind, args.budget, seed=args.seed, limit_s=args.limit, memory_mb=args.memory, advance=advance)
    also = _keep(Path(args.keep), args.kind, list(enumerate((d.whole for d in rep.defects), 1))) if args.keep else []
    if args.format == "json":
        text = json.dumps(report("fuzz", rep.ok, rep.as_dict()), ensure_ascii=False, indent=2) + "\n"
    else:
        text = as_text(rep) + "\n"
    status = deliver("fuzz", text, args.output, also)
    return status or (Exit.OK if rep.ok else Exit.FAILED)


def register(add: Add) -> None:
    sp = add("fuzz", cmd_fuzz, "feed generated inputs (station files, command lines, recordings, console events) "
             "and count tracebacks and hangs")
    sp.add_argument("kind", choices=sorted(KINDS), help="what to generate")
    sp.add_argument("--budget", type=positive_int, default=1000, help="samples to try (default 1000)")
    sp.add_argument("--seed", type=count, default=0, help="the generator's seed: the same seed draws the same "
                    "samples (default 0)")
    sp.add_argument("--limit", type=positive_number, default=20.0, metavar="SECONDS",
                    help="a sample still running after this long is a hang (default 20)")
    sp.add_argument("--memory", type=positive_int, default=4096, metavar="MB",
                    help="address-space cap while a sample runs; past it a sample fails with MemoryError "
                    "(default 4096)")
    sp.add_argument("--keep", metavar="DIR", help="write each defect's whole sample to DIR/KIND-N.txt")
    sp.add_argument("--format", choices=("text", "json"), default="text", help="text (default) or json")
    sp.add_argument("-o", "--output", metavar="FILE", help="write the report to FILE instead of stdout")
