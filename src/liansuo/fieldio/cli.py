"""``liansuo field-sim STATION --modbus HOST:PORT`` and ``liansuo field-map STATION``: the field simulator served over
Modbus TCP, and a station's point map (docs/field-mode.md). ``liansuo check STATION --points FILE`` checks a map
(:func:`check_points`); ``liansuo tui STATION --field HOST:PORT`` runs the interlocking against a field
(:func:`field_link`)."""

from __future__ import annotations

import argparse
import asyncio
import contextlib
import ipaddress
import signal
import sys
import threading
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING

from liansuo.kit.arguments import unwritable
from liansuo.kit.exitcodes import Exit, bad_input, refuse
from liansuo.kit.source import Diagnostic, StationError
from liansuo.stations.station import Station

if TYPE_CHECKING:
    from liansuo.fieldio.points import PointMap
    from liansuo.fieldio.server import FieldServer

Handler = Callable[[argparse.Namespace], int]
Add = Callable[[str, Handler, str], argparse.ArgumentParser]


def address(text: str) -> tuple[str, int]:
    """'HOST:PORT' (an IPv6 host in brackets) as (host, port); argparse's error otherwise."""
    host, sep, port = text.rpartition(":")
    host = host.strip("[]")
    if not sep or not host or not port.isdigit() or not 0 < int(port) < 65536:
        raise argparse.ArgumentTypeError(f"'{text}' is not HOST:PORT (for example 127.0.0.1:5020)")
    return host, int(port)


def register(add: Add) -> None:
    sp = add("field-sim", cmd_field_sim, "serve a station's simulated trackside equipment over Modbus TCP, for an "
                                        "interlocking in field mode ('liansuo docs field-mode')")
    sp.add_argument("station", help="bundled station name or path to a station YAML file")
    sp.add_argument("--modbus", type=address, required=True, metavar="HOST:PORT",
                    help="where to listen, e.g. 127.0.0.1:5020 (0.0.0.0 listens on every network)")
    sp.add_argument("--points", metavar="FILE", help="the point map (default: the whole station, as 'liansuo "
                                                     "field-map' writes it)")
    sp.add_argument("--watchdog", type=float, default=1.0, metavar="SECONDS",
                    help="de-energise every output when no heartbeat comes for this long (default 1 s)")
    sp.add_argument("--cycle", type=float, default=0.25, metavar="SECONDS",
                    help="the interlocking's cycle, the field's step per heartbeat (default 0.25 s)")
    sp = add("field-map", cmd_field_map, "write a station's field I/O point map: every element, addressed from 0")
    sp.add_argument("station", help="bundled station name or path to a station YAML file")
    sp.add_argument("-o", "--output", metavar="FILE", help="write it here (default: stdout)")


def points_for(station: Station, path: str | None) -> PointMap:
    """The checked point map in ``path``, or the whole station's; :class:`StationError` for a bad map."""
    from liansuo.fieldio import points
    from liansuo.rules import load_rules

    rules = load_rules()
    return points.from_station(station, rules) if path is None else points.load(Path(path), station, rules)


def check_points(station: Station, path: str) -> tuple[list[Diagnostic], str]:
    """``liansuo check STATION --points FILE``: every problem of the map, and what it wires."""
    from liansuo.fieldio import points
    from liansuo.rules import load_rules

    try:
        pm, src = points.read(Path(path))
    except StationError as exc:
        return exc.diagnostics, ""
    found = points.check(pm, src, station, load_rules())
    e = points.elements_of(pm)
    return found, (f"field control of {e.describe()} ({len(pm.inputs)} inputs, {len(pm.outputs)} outputs, "
                   f"{len(pm.codes)} code registers); every other element stays simulated")


def cmd_field_map(args: argparse.Namespace) -> int:
    from liansuo.fieldio import points
    from liansuo.rules import load_rules
    from liansuo.stations.loader import load

    if args.output and (why := unwritable(Path(args.output))):
        return refuse("field-map", why, Exit.USAGE)
    try:
        station = load(args.station)
    except StationError as exc:
        return bad_input(exc)
    text = points.dump(points.generate(station, load_rules()))
    if not args.output:
        sys.stdout.write(text)
        return int(Exit.OK)
    try:
        Path(args.output).write_text(text, encoding="utf-8")
    except OSError as exc:
        return refuse("field-map", f"cannot write {args.output}: {exc.strerror or exc}", Exit.USAGE)
    print(f"wrote {args.output} (liansuo check {args.station} --points {args.output})", file=sys.stderr)
    return int(Exit.OK)


def cmd_field_sim(args: argparse.Namespace) -> int:
    from liansuo.fieldio.link import EXTRA, available
    from liansuo.stations.loader import load

    if not available():
        return refuse("field-sim", EXTRA, Exit.USAGE)
    if not 0.05 <= args.watchdog <= 60:
        return refuse("field-sim", f"--watchdog {args.watchdog:g}: give 0.05 to 60 seconds", Exit.USAGE)
    if not 0.05 <= args.cycle <= 1:
        return refuse("field-sim", f"--cycle {args.cycle:g}: give 0.05 to 1 second", Exit.USAGE)
    host, port = args.modbus
    try:
        station = load(args.station)
        pm = points_for(station, args.points)
    except StationError as exc:
        return bad_input(exc, "station or point map")
    from liansuo.fieldio.server import FieldServer
    from liansuo.fieldio.yard import FieldYard
    from liansuo.rules import load_rules

    def say(line: str) -> None:
        print(line, flush=True)

    yard = FieldYard(station, load_rules(), args.cycle)
    server = FieldServer(yard, pm, watchdog_s=args.watchdog, log=say)
    exposed = "" if _local(host) else " (on the network: anyone who reaches this port drives the yard)"
    try:
        asyncio.run(_serve(server, host, port, lambda: say(
            f"field-sim {station.id}: modbus {host}:{port}{exposed}, unit {pm.file.unit}, {pm.input_count} inputs, "
            f"{pm.coil_count} coils; {pm.elements.describe()}; instructor commands on stdin (fault, repair, "
            "train, axles, occupy ...); ctrl+c stops")))
    except OSError as exc:
        return refuse("field-sim", str(exc), Exit.USAGE)
    except KeyboardInterrupt:
        pass
    return int(Exit.OK)


def _local(host: str) -> bool:
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return host == "localhost"


async def _serve(server: FieldServer, host: str, port: int, ready: Callable[[], None]) -> None:
    from liansuo.fieldio.server import serve

    loop = asyncio.get_running_loop()
    lines: asyncio.Queue[str | None] = asyncio.Queue()

    def read_stdin() -> None:  # a thread: stdin blocks
        try:
            for line in sys.stdin:
                loop.call_soon_threadsafe(lines.put_nowait, line.rstrip("\n"))
            loop.call_soon_threadsafe(lines.put_nowait, None)
        except RuntimeError:  # the serving ended, and its loop with it
            pass

    def listening() -> None:  # the instructor's lines are read once the device serves
        ready()
        threading.Thread(target=read_stdin, daemon=True).start()

    task = asyncio.current_task()
    if task is not None:
        for sig in (signal.SIGTERM,):
            loop.add_signal_handler(sig, task.cancel)
    with contextlib.suppress(asyncio.CancelledError):
        await serve(server, host, port, ready=listening, lines=lines)
