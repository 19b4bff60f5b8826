"""``liansuo tui`` and ``liansuo replay``, registered by the command line (``cli/main.py``).

Textual is imported only when a console actually starts, so the rest of the command line stays quick. Every argument
(the station, ``--speed``, ``--exercise``, ``--record``, the recording) is checked before a console starts: a bad one
ends the command with its one-line message and exit status (docs/commands.md, "Exit status"). A console that had an
internal error, or stopped on one, prints the tracebacks on stderr when it closes and exits with status 1.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING

from liansuo.kit.arguments import positive_number, unwritable
from liansuo.kit.exitcodes import Exit, bad_input, refuse
from liansuo.kit.printable import printable
from liansuo.kit.source import StationError
from liansuo.stations.station import Station

if TYPE_CHECKING:
    from liansuo.simulation.fieldlink import FieldLink
    from liansuo.simulation.recording.file import Recording
    from liansuo.tui.logfile import LogFile
    from liansuo.tui.safeapp import SafeApp

Handler = Callable[[argparse.Namespace], int]
Add = Callable[[str, Handler, str], argparse.ArgumentParser]


def register(add: Add, connect: Handler | None = None) -> None:
    """``connect``: what runs ``liansuo tui --connect URL`` (the classroom's client, a floor above the console)."""
    sp = add("tui", cmd_tui, "open the operator console (操作表示机) on a station")
    sp.set_defaults(connect_handler=connect)
    sp.add_argument("station", nargs="?", default=None, help="bundled station name or path (default jiaopei)")
    sp.add_argument("--paused", action="store_true", help="start with the clock paused")
    sp.add_argument("--speed", type=positive_number, default=1.0, metavar="X",
                    help="simulated seconds per wall-clock second, greater than 0 (default 1)")
    sp.add_argument("--record", metavar="FILE", help="record the session (JSON lines) for 'liansuo replay'")
    sp.add_argument("--exercise", metavar="FILE",
                    help="load an exercise: a file, or a bundled one by name (jiaopei-broken-rail-IG, ...)")
    sp.add_argument("--password-file", metavar="FILE",
                    help="the password for instructor mode (F2): a hash written by 'liansuo serve --hash-password' "
                         "(or a password); else LIANSUO_INSTRUCTOR_PASSWORD; never on the command line, where ps "
                         "shows it")
    sp.add_argument("--mute", action="store_true", help="start with the alarm bell muted (m or 'unmute' turns it on)")
    sp.add_argument("--log", metavar="FILE",
                    help="append warnings and internal errors (with their tracebacks) to FILE as they happen; "
                         "'2> FILE' would take the screen, which Textual draws on stderr")
    fld = sp.add_argument_group("field mode", "the interlocking against field equipment over Modbus TCP "
                                              "('liansuo docs field-mode')")
    fld.add_argument("--field", metavar="HOST:PORT",
                     help="the field's Modbus TCP address (an I/O module, a PLC, or 'liansuo field-sim'); the console "
                          "starts in simulated control and 'changeover field' (QHA) changes over")
    fld.add_argument("--points", metavar="FILE", help="with --field: the point map (default: the whole station, as "
                                                     "'liansuo field-map' writes it)")
    fld.add_argument("--changeover-password-file", metavar="FILE",
                     help="with --field: QHA's password (a hash from 'liansuo serve --hash-password', or the "
                          "password); else LIANSUO_CHANGEOVER_PASSWORD")
    room = sp.add_argument_group("classroom", "the console as a client of 'liansuo serve' ('liansuo docs classroom')")
    room.add_argument("--connect", metavar="URL",
                      help="connect to the classroom server at URL (ws://HOST:PORT, or wss:// to a server with TLS): "
                           "the station and the clock are the server's; without --seat or --instructor a login "
                           "screen asks")
    room.add_argument("--cafile", metavar="FILE",
                      help="with --connect wss://: trust the server's certificate if this CA (PEM: a school's own CA, "
                           "or the server's self-signed certificate) signed it, instead of the system's CAs")
    room.add_argument("--seat", type=int, metavar="N", help="with --connect: take trainee seat N")
    room.add_argument("--name", metavar="NAME", help="with --seat: the trainee's name, for the report")
    room.add_argument("--instructor", action="store_true",
                      help="with --connect: the instructor's dashboard of every seat (the password from "
                           "--password-file, its first line the password itself, or LIANSUO_INSTRUCTOR_PASSWORD)")


def register_replay(add: Add) -> None:
    sp = add("replay", cmd_replay, "play a recorded session back in the console, with seek and speed")
    sp.add_argument("file", help="a recording written by 'liansuo tui --record FILE'")
    sp.add_argument("--station", metavar="STATION",
                    help="replay on this station (a bundled name or a path) instead of the one the recording names, "
                         "e.g. after the files moved; it must be the station the recording was made on")
    sp.add_argument("--speed", type=positive_number, default=1.0, metavar="X",
                    help="playback speed, greater than 0 (default 1)")
    sp.add_argument("--verify", action="store_true",
                    help="no console: re-simulate the whole recording and check its start, answers and outputs")
    sp.add_argument("--format", choices=("text", "json"), default="text",
                    help="with --verify: text (default) or json")


def _load(station: str) -> Station | StationError:
    from liansuo.stations.loader import load

    try:
        return load(station)
    except StationError as exc:
        return exc


def cmd_tui(args: argparse.Namespace) -> int:
    if args.connect is not None:
        return _connect(args)
    if (given := _classroom_only(args)) is not None:
        return refuse("tui", f"{given} goes with --connect URL (a seat of the classroom server)", Exit.USAGE)
    args.station = args.station or "jiaopei"
    if isinstance(station := _load(args.station), StationError):
        return bad_input(station)
    if args.record and (why := unwritable(Path(args.record), "--record")):
        return refuse("tui", why, Exit.USAGE)
    if args.log and (why := unwritable(Path(args.log), "--log")):
        return refuse("tui", why, Exit.USAGE)
    if args.exercise:
        from liansuo.classroom.exercise import parse_exercise

        try:
            ex = parse_exercise(args.exercise)
        except StationError as exc:
            return bad_input(exc, "exercise")
        if ex.station_ref() not in (args.station, station.id):
            return refuse("tui", f"exercise '{ex.title}' is for station {ex.station}; start the console with "
                          f"'liansuo tui {ex.station} --exercise {args.exercise}'", Exit.USAGE)
    stored = None
    if args.password_file:
        from liansuo.classroom.passwords import PasswordError, instructor_hash

        try:
            stored = instructor_hash(args.password_file)
        except PasswordError as exc:
            return refuse("tui", str(exc), Exit.USAGE)
    field = _field(args, station)
    if isinstance(field, int):
        return field
    from liansuo.tui.app import ConsoleApp

    try:
        app = ConsoleApp(args.station, paused=args.paused, speed=args.speed, record=args.record,
                         exercise=args.exercise, instructor_hash=stored, mute=args.mute,
                         field=field[0] if field else None, changeover_hash=field[1] if field else None)
    except OSError as exc:
        return refuse("tui", str(exc), Exit.BAD_INPUT)
    return run_logged(app, "tui", args.log)


def run_logged(app: SafeApp, command: str, log: str | None) -> int:
    """Run the console, with its log file open (``--log``); its exit status (:func:`closed`)."""
    if log is None:
        app.run()
        return closed(app, command)
    from liansuo.tui.logfile import LogFile

    try:
        with LogFile(log, command) as logfile:
            app.run()
            return closed(app, command, logfile)
    except OSError as exc:
        return refuse(command, f"cannot write the log {log}: {exc.strerror or exc}", Exit.USAGE)


def _field(args: argparse.Namespace, station: Station) -> tuple[FieldLink, str] | int | None:
    """``--field``: the link and QHA's password hash; None without it; an exit status for a bad option."""
    if args.field is None:
        if args.points or args.changeover_password_file:
            return refuse("tui", f"{'--points' if args.points else '--changeover-password-file'} goes with "
                          "--field HOST:PORT", Exit.USAGE)
        return None
    from liansuo.classroom.passwords import CHANGEOVER_ENV, PasswordError, instructor_hash
    from liansuo.fieldio.cli import address, points_for
    from liansuo.fieldio.link import EXTRA, ModbusLink, available

    if not available():
        return refuse("tui", EXTRA, Exit.USAGE)
    try:
        host, port = address(args.field)
    except argparse.ArgumentTypeError as exc:
        return refuse("tui", f"--field: {exc}", Exit.USAGE)
    try:
        stored = instructor_hash(args.changeover_password_file, whose="change-over", env=CHANGEOVER_ENV,
                                 option="--changeover-password-file")
    except PasswordError as exc:
        return refuse("tui", str(exc), Exit.USAGE)
    try:
        points = points_for(station, args.points)
    except StationError as exc:
        return bad_input(exc, "point map")
    return ModbusLink(host, port, points), stored


def _classroom_only(args: argparse.Namespace) -> str | None:
    """The first option given that only a classroom's client takes."""
    given = (("--seat", args.seat), ("--name", args.name), ("--instructor", args.instructor), ("--cafile", args.cafile))
    return next((o for o, v in given if v not in (None, False)), None)


def _connect(args: argparse.Namespace) -> int:
    """``--connect``: the station, the clock and the exercises are the server's, so their options are refused."""
    local = [o for o, v in (("STATION", args.station), ("--paused", args.paused), ("--speed", args.speed != 1.0),
                            ("--record", args.record), ("--exercise", args.exercise), ("--field", args.field))
             if v not in (None, False)]
    if local:
        return refuse("tui", f"{local[0]} is not for --connect: the classroom server holds the station, its clock "
                      "and its exercises", Exit.USAGE)
    handler: Handler | None = getattr(args, "connect_handler", None)
    if handler is None:
        return refuse("tui", "this liansuo has no classroom client", Exit.USAGE)
    return handler(args)


def closed(app: SafeApp, command: str, log: LogFile | None = None) -> int:
    """After the console closed: 0, or every internal error's traceback on stderr (and in the log file) and
    :attr:`Exit.FAILED`."""
    if app.incidents:
        report = app.incidents.report(command)
        print(report, file=sys.stderr)
        if log is not None:
            log.write(report)
        return int(Exit.FAILED)
    if app.return_code:
        return refuse(command, f"the console stopped with status {app.return_code}", Exit.FAILED)
    return 0


def cmd_replay(args: argparse.Namespace) -> int:
    from liansuo.simulation.recording.file import RecordingError, load_recording, recording_station

    if args.format == "json" and not args.verify:
        return refuse("replay", "--format json goes with --verify (the console has no JSON)", Exit.USAGE)
    try:
        rec = load_recording(args.file)
        station = recording_station(rec, args.station)
    except RecordingError as exc:
        return bad_input(exc, "recording")
    except StationError as exc:
        return bad_input(exc, f"station of {printable(args.file)}")
    if args.verify:
        return _verify(args, rec, station)
    from liansuo.tui.replay import ReplayApp

    replay = ReplayApp(rec, station, speed=args.speed)
    replay.run()
    return closed(replay, "replay")


def _verify(args: argparse.Namespace, rec: Recording, station: Station) -> int:
    """``replay --verify``: the whole recording re-simulated, every mismatch listed; 1 when there is one."""
    from liansuo.simulation.recording.replayer import Replayer

    bad = Replayer(rec, station).verify()
    cmds = len(rec.commands)
    if args.format == "json":
        from liansuo.kit.jsonreport import print_report

        print_report("replay", not bad, {"recording": rec.path, "station": rec.station, "cycles": rec.cycles,
                                         "duration_s": round(rec.duration, 2), "commands": cmds,
                                         "mismatches": bad})
    else:
        from liansuo.kit.fit import fit, plural

        for line in bad:
            print(fit(printable(line)))
        verdict = "the start, every answer and every cycle reproduced" if not bad else plural(len(bad), "mismatch",
                                                                                               "mismatches")
        print(fit(f"{plural(rec.cycles, 'cycle')} ({rec.duration:g} s), {plural(cmds, 'command')}: {verdict}"))
    if bad:
        return refuse("replay", f"{len(bad)} of the recorded answers and outputs not reproduced", Exit.FAILED)
    return 0
