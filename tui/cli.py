"""``liansuo tui`` and ``liansuo replay``, registered by the command line (``cli/main.py``).

Textual is imported only when a console actually starts, so the rest of the command line stays quick.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable

Handler = Callable[[argparse.Namespace], int]
Add = Callable[[str, Handler, str], argparse.ArgumentParser]


def register(add: Add) -> None:
    sp = add("tui", cmd_tui, "open the operator console (操作表示机) on a station")
    sp.add_argument("station", nargs="?", default="jiaopei", help="bundled station name or path (default jiaopei)")
    sp.add_argument("--paused", action="store_true", help="start with the clock paused")
    sp.add_argument("--speed", type=float, default=1.0, help="simulated seconds per wall-clock second (default 1)")
    sp.add_argument("--record", metavar="FILE", help="record the session (JSON lines) for 'liansuo replay'")
    sp.add_argument("--exercise", metavar="FILE",
                    help="load an exercise: a file, or a bundled one by name (jiaopei-broken-rail-IG, ...)")
    sp.add_argument("--instructor-password", metavar="PW",
                    help="password for instructor mode (F2); also read from LIANSUO_INSTRUCTOR_PASSWORD")


def register_replay(add: Add) -> None:
    sp = add("replay", cmd_replay, "play a recorded session back in the console, with seek and speed")
    sp.add_argument("file", help="a recording written by 'liansuo tui --record FILE'")
    sp.add_argument("--speed", type=float, default=1.0, help="playback speed (default 1)")
    sp.add_argument("--verify", action="store_true",
                    help="no console: re-simulate the whole recording and check it reproduces the recorded outputs")


def _station_ok(station: str) -> str:
    from liansuo.stations.loader import load
    from liansuo.stations.source import StationError

    try:
        load(station)
    except StationError as exc:
        return "\n".join(str(d) for d in exc.diagnostics)
    return ""


def cmd_tui(args: argparse.Namespace) -> int:
    why = _station_ok(args.station)
    if why:
        print(why, file=sys.stderr)
        return 1
    from .app import ConsoleApp

    try:
        app = ConsoleApp(args.station, paused=args.paused, speed=args.speed, record=args.record,
                         exercise=args.exercise, instructor_password=args.instructor_password)
    except OSError as exc:
        print(f"liansuo tui: {exc}", file=sys.stderr)
        return 1
    app.run()
    return 0


def cmd_replay(args: argparse.Namespace) -> int:
    from liansuo.simulation.recording import RecordingError, Replayer, load_recording

    try:
        rec = load_recording(args.file)
    except RecordingError as exc:
        print(exc, file=sys.stderr)
        return 1
    why = _station_ok(rec.station)
    if why:
        print(why, file=sys.stderr)
        return 1
    if args.verify:
        bad = Replayer(rec).verify()
        for line in bad:
            print(line)
        cmds = len(rec.commands)
        verdict = "outputs reproduced" if not bad else f"{len(bad)} mismatches"
        print(f"{rec.cycles} cycles ({rec.duration:g} s), {cmds} commands: {verdict}")
        return 0 if not bad else 1
    from .replay import ReplayApp

    ReplayApp(rec, speed=args.speed).run()
    return 0
