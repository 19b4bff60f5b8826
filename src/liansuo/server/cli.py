"""``liansuo serve``: the classroom server, registered by the command line (``cli/main.py``)."""

from __future__ import annotations

import argparse
import asyncio
import getpass
import signal
import socket
import sys
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING

from liansuo.kit.exitcodes import Exit, bad_input, refuse
from liansuo.kit.source import StationError

if TYPE_CHECKING:
    from liansuo.server.websocket import ClassroomServer

Handler = Callable[[argparse.Namespace], int]
Add = Callable[[str, Handler, str], argparse.ArgumentParser]


def register(add: Add) -> None:
    sp = add("serve", cmd_serve, "serve a classroom: one simulation per trainee seat, and the instructor")
    sp.add_argument("station", nargs="?", default="jiaopei", help="bundled station name or path (default jiaopei)")
    sp.add_argument("--seats", type=int, default=2, metavar="N", help="trainee seats, 1 to 64 (default 2)")
    sp.add_argument("--shared", action="store_true",
                    help="a team exercise: every seat operates one simulation of the station, with one clock")
    sp.add_argument("--reports", metavar="DIR", default="liansuo-reports",
                    help="where each trainee's exercise report is written, JSON, text and HTML (default "
                         "liansuo-reports)")
    sp.add_argument("--exercise-dir", metavar="DIR", action="append", default=[],
                    help="exercises the instructor may start besides the bundled ones (repeatable)")
    sp.add_argument("--host", default="127.0.0.1",
                    help="address to listen on (default 127.0.0.1: this machine only; 0.0.0.0 for a classroom)")
    sp.add_argument("--port", type=int, default=8765, metavar="P", help="port (default 8765; 0 picks a free one)")
    sp.add_argument("--password-file", metavar="FILE",
                    help="the instructor's password: a hash written by --hash-password (or a password); without it "
                         "the environment variable LIANSUO_INSTRUCTOR_PASSWORD")
    sp.add_argument("--web", action="store_true",
                    help="also serve the console client to browsers (textual-serve): trainees and the instructor "
                         "need nothing but a browser")
    sp.add_argument("--web-port", type=int, default=8000, metavar="P",
                    help="with --web: the browsers' port (default 8000; 0 picks a free one)")
    sp.add_argument("--public-url", metavar="URL",
                    help="with --web: the address browsers use to reach this machine, when it is not "
                         "http://HOST:PORT (behind a proxy, or --host 0.0.0.0)")
    sp.add_argument("--lockout", type=float, default=60.0, metavar="S",
                    help="after 5 wrong instructor passwords from one address, refuse it for S seconds, twice as long "
                         "at each lockout after (default 60, at most 3600)")
    sp.add_argument("--hash-password", action="store_true",
                    help="read a password on the terminal (or standard input), print its hash for --password-file, "
                         "and exit")


def cmd_serve(args: argparse.Namespace) -> int:
    from liansuo.classroom.passwords import PasswordError, hash_password, instructor_hash

    if args.hash_password:
        pw = getpass.getpass("instructor password: ") if sys.stdin.isatty() else sys.stdin.readline().rstrip("\n")
        if not pw:
            return refuse("serve", "an empty password protects nothing", Exit.USAGE)
        print(hash_password(pw))
        return 0
    for name, port in (("--port", args.port), ("--web-port", args.web_port)):
        if not 0 <= port <= 65535:
            return refuse("serve", f"{name} is 0 to 65535, not {port}", Exit.USAGE)
    if not 0 <= args.lockout <= 3600:
        return refuse("serve", f"--lockout is 0 to 3600 seconds, not {args.lockout:g}", Exit.USAGE)
    if args.web and args.public_url is None and args.host in ("0.0.0.0", "::", ""):
        return refuse("serve", f"with --host {args.host} and --web, give --public-url http://ADDRESS:{args.web_port} "
                      "(this machine's address as the classroom's browsers reach it): the page tells them where to "
                      "connect", Exit.USAGE)
    if args.public_url is not None and not args.public_url.startswith(("http://", "https://")):
        return refuse("serve", f"--public-url is an http:// or https:// address, not {args.public_url!r}",
                      Exit.USAGE)
    try:
        stored = instructor_hash(args.password_file)
    except PasswordError as exc:
        return refuse("serve", str(exc), Exit.USAGE)
    missing = [d for d in args.exercise_dir if not Path(d).is_dir()]
    if missing:
        return refuse("serve", f"--exercise-dir {missing[0]}: no such directory", Exit.USAGE)
    from liansuo.server.classroom import Classroom, SeatError
    from liansuo.server.websocket import ClassroomServer

    try:
        classroom = Classroom(args.station, args.seats, shared=args.shared, reports=Path(args.reports),
                              exercise_dirs=tuple(Path(d) for d in args.exercise_dir))
    except StationError as exc:
        return bad_input(exc)
    except SeatError as exc:
        return refuse("serve", str(exc), Exit.USAGE)
    server = ClassroomServer(classroom, stored, lockout_s=args.lockout)
    web_port: int | None = None
    if args.web:
        try:
            web_port = _free(args.host, args.web_port)
        except OSError as exc:
            classroom.close()
            return refuse("serve", f"cannot serve browsers on {args.host}:{args.web_port}: {exc.strerror or exc}",
                          Exit.USAGE)
    try:
        asyncio.run(_serve(server, args.host, args.port, web_port, args.public_url))
    except OSError as exc:
        return refuse("serve", f"cannot listen on {args.host}:{args.port}: {exc.strerror or exc}", Exit.USAGE)
    except (KeyboardInterrupt, asyncio.CancelledError):
        pass
    finally:
        classroom.close()
    return 0


def _free(host: str, port: int) -> int:
    """``port`` (or a free one for 0) once it is known that it can be listened on: raises OSError if not."""
    with socket.socket(socket.AF_INET6 if ":" in host else socket.AF_INET) as s:
        s.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        s.bind((host, port))
        return int(s.getsockname()[1])


async def _serve(server: ClassroomServer, host: str, port: int, web_port: int | None, public_url: str | None) -> None:
    ready: asyncio.Future[int] = asyncio.get_running_loop().create_future()
    task = asyncio.create_task(server.serve(host, port, ready))
    asyncio.get_running_loop().add_signal_handler(signal.SIGTERM, task.cancel)  # kill: stop as ctrl+c does
    while not ready.done():  # listening, or the task ended: the OSError of a port it could not listen on goes up
        if task.done():
            task.result()
        await asyncio.sleep(0.01)
    seats = len(server.classroom.seats)
    browsers = ""
    web = None
    if web_port is not None:
        from liansuo.server import web as webserver

        web = webserver.start(webserver.local_url(host, ready.result()), host, web_port, public_url)
        browsers = f", browsers on {public_url or f'http://{host}:{web_port}'}"
    of = "at one simulation of" if server.classroom.shared else "of"
    print(f"liansuo serve: {seats} seats {of} {server.classroom.station_ref} on ws://{host}:{ready.result()}"
          f"{browsers} (ctrl+c stops)", flush=True)
    try:
        await task
    finally:
        if web is not None:
            web.terminate()
            web.join(5)
