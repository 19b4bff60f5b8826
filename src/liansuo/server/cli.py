"""``liansuo serve``: the classroom server, registered by the command line (``cli/main.py``)."""

from __future__ import annotations

import argparse
import asyncio
import getpass
import signal
import socket
import ssl
import sys
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from liansuo.kit.exitcodes import Exit, bad_input, refuse
from liansuo.kit.source import StationError

if TYPE_CHECKING:
    from liansuo.server.classroom import Classroom
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
    sp.add_argument("--web-consoles", type=int, metavar="N",
                    help="with --web: at most N browser consoles at once, each a process of about 90 MB started "
                         "after a login (default: the seats and 4 more)")
    sp.add_argument("--certfile", metavar="FILE",
                    help="TLS: the server's certificate (PEM; its CA's after it), so that clients connect to wss:// "
                         "and browsers to https://; with --keyfile")
    sp.add_argument("--keyfile", metavar="FILE", help="TLS: the certificate's private key (PEM), with --certfile")
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
    scheme = "https" if args.certfile else "http"
    if args.web and args.public_url is None and args.host in ("0.0.0.0", "::", ""):
        return refuse("serve", f"with --host {args.host} and --web, give --public-url {scheme}://ADDRESS:"
                      f"{args.web_port} (this machine's address as the classroom's browsers reach it): the page tells "
                      "them where to connect", Exit.USAGE)
    schemes = ("https://",) if args.certfile else ("http://", "https://")  # https:// also behind a TLS proxy
    if args.public_url is not None and not args.public_url.startswith(schemes):
        kind = "an https:// address (with --certfile)" if args.certfile else "an http:// or https:// address"
        return refuse("serve", f"--public-url is {kind}, not {args.public_url!r}", Exit.USAGE)
    consoles = args.seats + 4 if args.web_consoles is None else args.web_consoles
    if not 1 <= consoles <= 256:
        return refuse("serve", f"--web-consoles is 1 to 256, not {consoles}", Exit.USAGE)
    if (args.certfile is None) != (args.keyfile is None):
        return refuse("serve", "TLS needs both --certfile and --keyfile", Exit.USAGE)
    tls = None
    if args.certfile is not None:
        from liansuo.server.tls import TLSError, server_context

        try:
            tls = server_context(args.certfile, args.keyfile)
        except TLSError as exc:
            return refuse("serve", str(exc), Exit.USAGE)
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
    web = None if web_port is None else WebPlan(web_port, args.public_url, stored, args.lockout, consoles,
                                                args.certfile, args.keyfile)
    try:
        asyncio.run(_serve(server, args.host, args.port, web, tls))
    except OSError as exc:
        return refuse("serve", f"cannot listen on {args.host}:{args.port}: {exc.strerror or exc}", Exit.USAGE)
    except (KeyboardInterrupt, asyncio.CancelledError):
        pass
    finally:
        _keep_attempts(classroom)
        classroom.close()
    return 0


STOPPED = "stopped: the server was stopped before the end"


def _keep_attempts(classroom: Classroom) -> None:
    """The server stops (ctrl+c, SIGTERM, an error): each exercise still going gets its report, marked as stopped."""
    try:
        written = classroom.stop_unfinished(STOPPED)
    except Exception as exc:  # the reports are worth a try, never a traceback over the server's own ending
        print(f"liansuo serve: the unfinished exercises' reports could not be written: {exc}", file=sys.stderr)
        return
    if written:
        print(f"liansuo serve: stopped; reports of the exercises it stopped ({STOPPED}): "
              f"{', '.join(str(p) for p in written)}", flush=True)


def _free(host: str, port: int) -> int:
    """``port`` (or a free one for 0) once it is known that it can be listened on: raises OSError if not."""
    with socket.socket(socket.AF_INET6 if ":" in host else socket.AF_INET) as s:
        s.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        s.bind((host, port))
        return int(s.getsockname()[1])


@dataclass(frozen=True)
class WebPlan:
    """What the browsers' server is given besides the classroom server's address (``server/web.py``)."""

    port: int
    public_url: str | None
    instructor_hash: str
    lockout_s: float
    consoles: int
    certfile: str | None
    keyfile: str | None


async def _serve(server: ClassroomServer, host: str, port: int, plan: WebPlan | None,
                 tls: ssl.SSLContext | None) -> None:
    ready: asyncio.Future[int] = asyncio.get_running_loop().create_future()
    task = asyncio.create_task(server.serve(host, port, ready, tls))
    asyncio.get_running_loop().add_signal_handler(signal.SIGTERM, task.cancel)  # kill: stop as ctrl+c does
    while not ready.done():  # listening, or the task ended: the OSError of a port it could not listen on goes up
        if task.done():
            task.result()
        await asyncio.sleep(0.01)
    seats = len(server.classroom.seats)
    scheme = "wss" if tls else "ws"
    browsers = ""
    web = None
    if plan is not None:
        from liansuo.server import web as webserver

        ws_url = webserver.local_url(host, ready.result(), plan.public_url, tls is not None)
        web = webserver.start(webserver.WebConfig(ws_url, host, plan.port, plan.public_url, plan.instructor_hash,
                                                  plan.lockout_s, plan.consoles, plan.certfile, plan.keyfile))
        http = "https" if tls else "http"
        browsers = f", browsers on {plan.public_url or f'{http}://{host}:{plan.port}'}"
    of = "at one simulation of" if server.classroom.shared else "of"
    print(f"liansuo serve: {seats} seats {of} {server.classroom.station_ref} on {scheme}://{host}:{ready.result()}"
          f"{browsers} (ctrl+c stops)", flush=True)
    try:
        await task
    finally:
        if web is not None:
            web.terminate()
            web.join(5)
