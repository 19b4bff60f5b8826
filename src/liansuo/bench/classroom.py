"""The classroom under attack, measured (issue 45, docs/classroom.md "Limits"): an honest trainee's round trips to a
``liansuo serve`` on this machine with no load, while one raw client floods, and while wrong instructor logins arrive
all at once; and the memory of a classroom seat over many commands.

The server runs in a process of its own on 127.0.0.1 (port 0), and so does each attacker (:mod:`.attackers`), so
that neither takes the honest client's time in this process; the server is always terminated."""

from __future__ import annotations

import json
import math
import secrets
import subprocess
import sys
import tempfile
import time
import tracemalloc
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from importlib.util import find_spec
from pathlib import Path
from typing import IO, TYPE_CHECKING, Any

from liansuo.bench.attackers import KINDS

if TYPE_CHECKING:
    from liansuo.server.client import ClassroomClient

STATION = "jiaopei"
GAP_S = 0.025  # between the honest client's round trips: 40 a second, under the server's 50 a connection
FLOOD_LEAD_S = 0.5  # the flood runs this long before the honest round trips are timed
HONEST_LINE = "cancel X"  # answered by the interlocking every time, changes nothing
FLOOD_TARGET_MS = 100.0  # the honest round trip's target while one client floods (issue 45)
FLOOD_TARGET_PER_S = 20_000.0  # ... at this many messages a second from that client
LOGIN_TARGET_MS = 100.0  # and while wrong logins arrive
MEMORY_TARGET_KB = 1000.0  # the growth over the last 90 % of the commands: flat


class NotMeasured(RuntimeError):
    """The server or an attacker did not start: the message says why."""


def measure_classroom(round_trips: int, commands: int, logins: int) -> dict[str, Any]:
    """Every figure, or ``{"skipped": why}`` where the classroom server cannot run (docs/benchmark.md)."""
    if find_spec("websockets") is None:
        return {"station": STATION, "skipped": "the serve extra is not installed: pip install 'liansuo[serve]'"}
    from liansuo.server.client import ClassroomError

    figures: dict[str, Any] = {"station": STATION, "round_trips": round_trips, "gap_ms": GAP_S * 1000}
    try:
        with tempfile.TemporaryDirectory(prefix="liansuo-bench-") as folder:
            figures |= _memory(commands, Path(folder))
            password = secrets.token_hex(8)
            with _server(Path(folder), password) as url:
                figures |= _attacks(url, password, round_trips, logins)
    except NotMeasured as exc:
        return {"station": STATION, "skipped": str(exc)}
    except ClassroomError as exc:  # the honest client, or the instructor counting the flood, got no answer
        return {"station": STATION, "skipped": f"the server did not answer: {exc}"}
    return figures


# ---- memory ---------------------------------------------------------------------------------------------------------
def _memory(commands: int, folder: Path) -> dict[str, Any]:
    """A seat in an exercise sent ``commands`` command lines of the longest length, each refused (so the exercise
    never ends): the memory traced (tracemalloc) grown over the last 90 % of them."""
    from liansuo.server.classroom import MAX_LINE, Classroom

    room = Classroom(STATION, 1, reports=folder / "reports")
    try:
        room.start_exercise([1], "jiaopei-cancel-route", seed=1)
        line = "route NOSUCH X # " + "x" * (MAX_LINE - 20)
        warm = commands // 10
        tracemalloc.start()
        try:
            for _ in range(warm):
                room.command(1, "trainee", line)
            before = tracemalloc.get_traced_memory()[0]
            for _ in range(commands - warm):
                room.command(1, "trainee", line)
            grown = tracemalloc.get_traced_memory()[0] - before
        finally:
            tracemalloc.stop()
        seat = room.seat(1)
        return {"memory_commands": commands, "memory_line_chars": len(line),
                "memory_growth_kb": round(grown / 1000, 1), "memory_log_lines": len(seat.log)}
    finally:
        room.close()


# ---- the server and its attackers ----------------------------------------------------------------------------------
@contextmanager
def _server(folder: Path, password: str) -> Iterator[str]:
    """``liansuo serve`` with two seats on 127.0.0.1, a port of its own: its address, until it is terminated."""
    from liansuo.classroom.passwords import hash_password

    secret = folder / "instructor.pw"
    secret.write_text(hash_password(password) + "\n", encoding="utf-8")
    with (folder / "serve.log").open("w+", encoding="utf-8") as log:
        proc = subprocess.Popen([sys.executable, "-m", "liansuo", "serve", STATION, "--seats", "2", "--host",
                                 "127.0.0.1", "--port", "0", "--password-file", str(secret), "--reports",
                                 str(folder / "reports")], stdout=subprocess.PIPE, stderr=log, text=True)
        try:
            line = proc.stdout.readline() if proc.stdout else ""
            if "ws://" not in line:
                log.seek(0)
                raise NotMeasured(f"liansuo serve did not start: {(line + log.read()).strip()[-300:] or 'no output'}")
            yield "ws://" + line.split("ws://", 1)[1].split()[0]
        finally:
            _end(proc)


def _attacker(*args: str | int) -> subprocess.Popen[str]:
    return subprocess.Popen([sys.executable, "-m", "liansuo.bench.attackers", *map(str, args)], stdin=subprocess.PIPE,
                            stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)


def _end(proc: subprocess.Popen[str]) -> None:
    proc.terminate()
    try:
        proc.wait(10)
    except subprocess.TimeoutExpired:
        proc.kill()
        proc.wait(10)


def _said(out: IO[str] | None, expected: str) -> None:
    line = out.readline() if out else ""
    if line.strip() != expected:
        raise NotMeasured(f"an attacker did not start: {line.strip() or 'no output'}")


def _attacks(url: str, password: str, n: int, logins: int) -> dict[str, Any]:
    from liansuo.server.client import ClassroomClient

    with ClassroomClient.trainee(url, seat=1, name="Honest") as honest:
        quiet = _round_trips(honest, n)
        figures = {**_stats("quiet", quiet), **_flood(url, password, honest, n)}
        figures |= _logins(url, honest, n, logins)
    return figures


def _flood(url: str, password: str, honest: ClassroomClient, n: int) -> dict[str, Any]:
    """Seat 2 floods while the honest client's round trips are timed; the instructor then reads how many of the
    flood's commands the server ran."""
    from liansuo.server.client import ClassroomClient

    flooder = _attacker("flood", url, 2)
    try:
        _said(flooder.stdout, "ready")
        t0 = time.perf_counter()
        time.sleep(FLOOD_LEAD_S)
        loud = _round_trips(honest, n)
        with ClassroomClient.instructor(url, password) as teacher:
            read, read_s = int(teacher.seats()[1]["commands"]), time.perf_counter() - t0
        out, _ = flooder.communicate("stop\n", timeout=60)
        sent = json.loads(out.strip().splitlines()[-1])
    except (subprocess.TimeoutExpired, ValueError, IndexError) as exc:
        raise NotMeasured(f"the flood did not report its counts: {exc}") from None
    finally:
        _end(flooder)
    return {**_stats("flood", loud), "flood_sent": sent["sent"], "flood_s": round(sent["seconds"], 2),
            "flood_offered_per_s": round(sent["sent"] / sent["seconds"]),
            "flood_read": read, "flood_read_per_s": round(read / read_s, 1)}


def _logins(url: str, honest: ClassroomClient, n: int, logins: int) -> dict[str, Any]:
    """``logins`` wrong instructor logins sent at once; the honest client's round trips timed until the last of them
    is answered (at least one, at most ``10 n``)."""
    wave = _attacker("logins", url, logins)
    try:
        _said(wave.stdout, "started")
        during = _round_trips(honest, 10 * n, until=lambda: wave.poll() is not None)
        out, _ = wave.communicate(timeout=120)
        counts = json.loads(out.strip().splitlines()[-1])
    except (subprocess.TimeoutExpired, ValueError, IndexError) as exc:
        raise NotMeasured(f"the wrong logins did not report their counts: {exc}") from None
    finally:
        _end(wave)
    return {**_stats("login", during), "login_round_trips": len(during), "logins": logins,
            **{f"logins_{k}": counts[k] for k in KINDS},
            "logins_s": round(counts["seconds"], 2)}


def _round_trips(client: ClassroomClient, n: int, until: Callable[[], bool] | None = None) -> list[float]:
    """Up to ``n`` command round trips, ``GAP_S`` apart (fewer once ``until()`` is true, after the first)."""
    out: list[float] = []
    while len(out) < n and not (out and until is not None and until()):
        t0 = time.perf_counter()
        reply = client.command(HONEST_LINE)
        out.append(time.perf_counter() - t0)
        if reply.get("type") != "answer":
            raise NotMeasured(f"the honest client's command was not answered: {reply}")
        time.sleep(GAP_S)
    return out


def _stats(name: str, seconds: list[float]) -> dict[str, float]:
    """Median, 95th percentile (nearest rank) and maximum, in milliseconds."""
    ranked = sorted(seconds)
    p95 = ranked[max(0, math.ceil(0.95 * len(ranked)) - 1)]
    median = (ranked[(len(ranked) - 1) // 2] + ranked[len(ranked) // 2]) / 2
    return {f"{name}_rtt_ms_{k}": round(v * 1000, 2) for k, v in (("median", median), ("p95", p95),
                                                                  ("max", ranked[-1]))}


def targets(c: dict[str, Any]) -> list[dict[str, Any]]:
    """The issue's targets, each with the measured value and whether it was met ([] when skipped)."""
    if "skipped" in c:
        return []
    checks = [("flood_rtt_ms_p95", "<=", FLOOD_TARGET_MS), ("flood_offered_per_s", ">=", FLOOD_TARGET_PER_S),
              ("login_rtt_ms_p95", "<=", LOGIN_TARGET_MS), ("memory_growth_kb", "<=", MEMORY_TARGET_KB)]
    return [{"station": "classroom", "figure": f, "target": f"{op} {t:g}", "value": float(c[f]),
             "met": c[f] <= t if op == "<=" else c[f] >= t} for f, op, t in checks]


def text(c: dict[str, Any]) -> list[str]:
    if "skipped" in c:
        return [f"{'classroom':26}skipped: {c['skipped']}"]

    def rtt(name: str) -> str:
        return f"{c[f'{name}_rtt_ms_median']:.1f} / {c[f'{name}_rtt_ms_p95']:.1f} / {c[f'{name}_rtt_ms_max']:.1f} ms"

    return [f"{'classroom':26}honest round trip, median / p95 / max of {c['round_trips']}:",
            f"{'  no load':26}{rtt('quiet')}",
            f"{'  one client flooding':26}{rtt('flood')}  (it sent {c['flood_sent']:,} in {c['flood_s']:.1f} s, "
            f"{c['flood_offered_per_s']:,}/s; the server read {c['flood_read']:,}, {c['flood_read_per_s']:.0f}/s)",
            f"{'  wrong logins at once':26}{rtt('login')}  ({c['login_round_trips']} round trips during "
            f"{c['logins']} wrong logins in {c['logins_s']:.1f} s: {c['logins_checked']} checked, "
            f"{c['logins_locked_out']} locked out, {c['logins_busy']} busy, {c['logins_turned_away']} turned away at "
            f"connect, {c['logins_failed']} unanswered)",
            f"{'  memory':26}{c['memory_growth_kb']:+.0f} kB over the last 90 % of {c['memory_commands']:,} commands "
            f"({c['memory_log_lines']} log lines kept)"]
