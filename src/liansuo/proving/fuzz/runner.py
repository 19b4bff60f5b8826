"""The fuzz runner: feeds generated inputs of one kind to liansuo and counts what came back (docs/robustness.md).

A *kind* is a module with ``NAME``, ``strategy()`` (a hypothesis strategy that draws one input: a station file's text,
a command line, a recording, a sequence of console events) and ``attempt(sample)``, which gives the input to liansuo as
a user would and answers ``"accepted"`` or ``"refused"`` (a clear message, a non-zero exit, a refused command). The
kinds live beside it in ``proving/fuzz/``; ``liansuo fuzz`` (proving/fuzz/cli.py) knows them by name.

What counts as a defect: any exception that escapes ``attempt`` (a traceback the user would have seen), and a sample
that runs past the time limit (a hang). A sample that exhausts the memory limit raises MemoryError, so it is a
defect too. The suite runs every kind derandomized with a small budget (tests/test_fuzz_*.py); ``liansuo fuzz KIND
--budget N`` runs the same generator for longer and reports the figures the docs quote.
"""

from __future__ import annotations

import resource
import signal
import sysconfig
import time
import traceback
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
from types import FrameType, ModuleType
from typing import Any

SAMPLE_TEXT = 400  # characters of a sample kept in a report (the whole sample goes to --keep)


class Hang(Exception):
    """A sample ran past the time limit."""


@contextmanager
def time_limit(seconds: float) -> Iterator[None]:
    """Raise :class:`Hang` in the main thread once ``seconds`` have passed (the real-time interval timer)."""
    def expire(signum: int, frame: FrameType | None) -> None:
        raise Hang(f"no answer within {seconds:g} s")

    previous = signal.signal(signal.SIGALRM, expire)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)


@contextmanager
def memory_limit(megabytes: int) -> Iterator[None]:
    """Cap this process's address space at ``megabytes`` so a runaway sample raises MemoryError instead of taking
    the machine; the previous limit is restored afterwards."""
    soft, hard = resource.getrlimit(resource.RLIMIT_AS)
    cap = megabytes * 1024 * 1024
    if hard != resource.RLIM_INFINITY:
        cap = min(cap, hard)
    resource.setrlimit(resource.RLIMIT_AS, (cap, hard))
    try:
        yield
    finally:
        resource.setrlimit(resource.RLIMIT_AS, (soft, hard))


@dataclass
class Defect:
    """One sample that crashed or hung: what it was and what escaped."""

    kind: str  # 'traceback' or 'hang'
    error: str  # the exception's type and message, one line
    where: str  # the innermost frame of liansuo's code, FILE:LINE in FUNCTION
    sample: str  # the sample's repr, cut to SAMPLE_TEXT characters
    whole: str = field(repr=False, default="")  # the sample's whole repr, for --keep

    def as_dict(self) -> dict[str, str]:
        return {"kind": self.kind, "error": self.error, "where": self.where, "sample": self.sample}


@dataclass
class FuzzReport:
    """What a run found: samples tried, accepted, refused, the defects, and how long it took."""

    kind: str
    seed: int
    budget: int
    samples: int = 0
    accepted: int = 0
    refused: int = 0
    defects: list[Defect] = field(default_factory=list)
    elapsed_s: float = 0.0
    slowest_s: float = 0.0

    @property
    def ok(self) -> bool:
        return not self.defects

    def as_dict(self) -> dict[str, Any]:
        return {"kind": self.kind, "seed": self.seed, "budget": self.budget, "samples": self.samples,
                "accepted": self.accepted, "refused": self.refused,
                "tracebacks": sum(d.kind == "traceback" for d in self.defects),
                "hangs": sum(d.kind == "hang" for d in self.defects),
                "defects": [d.as_dict() for d in self.defects],
                "elapsed_s": round(self.elapsed_s, 1), "slowest_s": round(self.slowest_s, 2)}


def _where(exc: BaseException) -> str:
    """The innermost frame of the project's own code (not the runner's, not a library's or Python's), else the
    innermost of all."""
    libraries = {sysconfig.get_paths()[k] for k in ("stdlib", "platstdlib", "purelib", "platlib")}
    frames = [f for f in traceback.extract_tb(exc.__traceback__) if f.filename != __file__]
    ours = [f for f in frames if not any(f.filename.startswith(lib) for lib in libraries)] or frames
    if not ours:
        return "?"
    f = ours[-1]
    return f"{f.filename}:{f.lineno} in {f.name}"


def _one_line(exc: BaseException) -> str:
    text = " ".join(str(exc).split())
    return f"{type(exc).__name__}: {text[:200]}" if text else type(exc).__name__


def run(kind: ModuleType, budget: int, *, seed: int = 0, limit_s: float = 20.0, memory_mb: int = 4096,
        advance: Callable[[int], None] | None = None) -> FuzzReport:
    """Draw ``budget`` samples of ``kind`` (reproducibly from ``seed``) and give each to ``kind.attempt`` under the
    time and memory limits. Nothing is shrunk: every sample is tried once and its outcome counted."""
    from hypothesis import HealthCheck, Phase, given, settings
    from hypothesis import seed as hypothesis_seed

    out = FuzzReport(kind=kind.NAME, seed=seed, budget=budget)

    @hypothesis_seed(seed)
    @settings(max_examples=budget, database=None, deadline=None, phases=[Phase.generate],
              suppress_health_check=list(HealthCheck))
    @given(kind.strategy())
    def one(sample: Any) -> None:
        out.samples += 1
        started = time.perf_counter()
        try:
            with memory_limit(memory_mb), time_limit(limit_s):
                answer = kind.attempt(sample)
        except (KeyboardInterrupt, SystemExit):
            raise
        except BaseException as exc:  # every escape is what the run is looking for
            whole = repr(sample)
            out.defects.append(Defect("hang" if isinstance(exc, Hang) else "traceback", _one_line(exc),
                                      _where(exc), whole[:SAMPLE_TEXT], whole))
        else:
            if answer == "accepted":
                out.accepted += 1
            elif answer == "refused":
                out.refused += 1
            else:
                raise ValueError(f"fuzz kind {kind.NAME}: attempt() answered {answer!r}, not 'accepted' or 'refused'")
        finally:
            out.slowest_s = max(out.slowest_s, time.perf_counter() - started)
            if advance:
                advance(1)

    started = time.perf_counter()
    one()
    out.elapsed_s = time.perf_counter() - started
    return out


def as_text(rep: FuzzReport, shown: int = 10) -> str:
    """The run in a few lines: the figures, then the first ``shown`` defects with their samples."""
    hangs = sum(d.kind == "hang" for d in rep.defects)
    lines = [f"fuzz {rep.kind}: {rep.samples} samples (seed {rep.seed}) in {rep.elapsed_s:.0f} s, slowest "
             f"{rep.slowest_s:.1f} s: {rep.accepted} accepted, {rep.refused} refused, "
             f"{len(rep.defects) - hangs} tracebacks, {hangs} hangs"]
    for d in rep.defects[:shown]:
        lines += [f"  {d.kind}: {d.error}", f"    at {d.where}", f"    sample: {d.sample}"]
    if len(rep.defects) > shown:
        lines.append(f"  ... and {len(rep.defects) - shown} more (--format json lists them all)")
    lines.append("PASS" if rep.ok else "FAIL")
    return "\n".join(lines)
