"""The classroom in browsers (``liansuo serve --web``): textual-serve serves the classroom's own console client to
browsers, behind a login of ours.

A browser first gets the login page (:mod:`.weblogin`, :mod:`.webpages`): a trainee's seat and name, checked by the
classroom server, or the instructor's password. No console process exists before a login passes. Then the page is
textual-serve's, whose websocket (``/ws``) starts one console client (``liansuo tui --connect``) for the tab, in a
process of its own (about 90 MB), logged in as the login said: the seat's token or the password reach it in its
environment, never its command line. The tab's console then talks to the classroom server like a terminal client,
so a browser gets nothing a terminal client would not; the simulations stay on the server.

Limits: at most ``consoles`` consoles at once (past it the page and the websocket are refused, and no process is
started), one per login (a second tab of the same login takes the console's place), and a console's size clamped
to :data:`WIDTH` by :data:`HEIGHT` cells, when it starts and at every resize.
"""

from __future__ import annotations

import asyncio
import logging
import multiprocessing
import os
import shlex
import signal
import sys
import threading
import time
from dataclasses import dataclass
from multiprocessing.process import BaseProcess
from typing import Any
from urllib.parse import urlsplit

import aiohttp_jinja2
import jinja2
from aiohttp import WSMsgType, web
from textual_serve.app_service import AppService
from textual_serve.server import Server

from liansuo.classroom.passwords import ENV, TOKEN_ENV
from liansuo.server.lockout import LoginGuard
from liansuo.server.tls import client_context, server_context
from liansuo.server.weblogin import SESSION_S, Desk, Refused, SeatLost, Session, Sessions
from liansuo.server.webpages import login_page, refusal_page

DEFAULT_PORT = 8000
ORPHAN_CHECK_S = 1.0
WIDTH = (40, 400)  # a browser console's columns, at least and at most
HEIGHT = (15, 200)  # and its rows: a 4000 x 4000 console took 260 MB
COOKIE = "liansuo_session"
MAX_BODY = 16 * 1024  # a login form is a few fields
REPLACE_WAIT_S = 5.0  # how long a login's new tab waits for the console of its old one to end

log = logging.getLogger("textual-serve")


@dataclass(frozen=True)
class WebConfig:
    """What the browsers' server needs, handed to its process."""

    ws_url: str  # where the consoles, and the logins, reach the classroom server
    host: str
    port: int
    public_url: str | None
    instructor_hash: str
    lockout_s: float
    consoles: int  # at most this many consoles at once
    certfile: str | None = None  # with keyfile: https://, and the consoles trust this certificate for wss://
    keyfile: str | None = None


def local_url(host: str, port: int, public_url: str | None = None, tls: bool = False) -> str:
    """Where a client on this machine reaches the websocket server listening on ``host``. With TLS, by the name the
    certificate is for: the browsers' address's (``public_url``) or ``host``."""
    if not tls:
        return f"ws://{'127.0.0.1' if host in ('0.0.0.0', '::', '') else host}:{port}"
    name = (urlsplit(public_url).hostname if public_url else None) or host
    return f"wss://{f'[{name}]' if ':' in name else name}:{port}"


def clamp(value: Any, default: int, bounds: tuple[int, int]) -> int:
    """``value`` as a whole number within ``bounds`` (``default`` when it is none)."""
    try:
        n = int(value)
    except (TypeError, ValueError, OverflowError):
        n = default
    return max(bounds[0], min(bounds[1], n))


def console_command(ws_url: str, session: Session, cafile: str | None) -> tuple[str, dict[str, str]]:
    """The command a login's console runs, and what its environment adds: the seat's token or the password."""
    parts = [sys.executable, "-m", "liansuo.cli", "tui", "--connect", ws_url]
    if cafile:
        parts += ["--cafile", cafile]
    if session.role == "instructor":
        parts.append("--instructor")
        env = {ENV: session.secret}
    else:
        parts += ["--seat", str(session.seat), f"--name={session.name}"]
        env = {TOKEN_ENV: session.secret}
    return " ".join(shlex.quote(p) for p in parts), env


class Console(AppService):
    """textual-serve's process of one tab, with the login's own environment (and no other login's secret)."""

    def __init__(self, command: str, env: dict[str, str], **kwargs: Any) -> None:
        super().__init__(command, **kwargs)
        self.env = env

    def _build_environment(self, width: int = 80, height: int = 24) -> dict[str, str]:
        environment = super()._build_environment(width, height)
        environment.pop(ENV, None)
        environment.pop(TOKEN_ENV, None)
        environment.update(self.env)
        return environment


class ClassroomWeb(Server):
    """textual-serve's server, with the login first, and the limits of the module's docstring."""

    def __init__(self, config: WebConfig) -> None:
        scheme = "https" if config.certfile else "http"
        super().__init__("liansuo tui --connect", host=config.host, port=config.port, title="liansuo classroom",
                         public_url=config.public_url or f"{scheme}://{config.host}:{config.port}")
        self.config = config
        self.tls = scheme == "https"
        self.sessions = Sessions()
        self.consoles: dict[str, web.WebSocketResponse] = {}  # a login's key: its console's websocket
        self.desk = Desk(config.ws_url, client_context(config.ws_url, config.certfile), config.instructor_hash,
                         LoginGuard(lockout_s=config.lockout_s))

    async def _make_app(self) -> web.Application:
        app = web.Application(client_max_size=MAX_BODY)
        aiohttp_jinja2.setup(app, loader=jinja2.FileSystemLoader(self.templates_path))
        app.add_routes([
            web.get("/", self.handle_login_page, name="login"),
            web.post("/login", self.handle_login),
            web.get("/console", self.handle_console, name="index"),
            web.get("/ws", self.handle_console_socket, name="websocket"),
            web.get("/download/{key}", self.handle_download, name="download"),
            web.static("/static", self.statics_path, name="static"),
        ])
        return app

    async def on_startup(self, app: web.Application) -> None:
        """Nothing to print: ``liansuo serve`` says where the browsers connect."""

    def serve(self, debug: bool = False) -> None:
        """textual-serve's, with https:// when there is a certificate."""
        self.debug = debug
        self.initialize_logging()
        loop = asyncio.new_event_loop()
        loop.add_signal_handler(signal.SIGINT, self.request_exit)
        loop.add_signal_handler(signal.SIGTERM, self.request_exit)
        tls = server_context(self.config.certfile, self.config.keyfile) \
            if self.config.certfile and self.config.keyfile else None
        web.run_app(self._make_app(), host=self.host, port=self.port, ssl_context=tls, handle_signals=False,
                    loop=loop, print=lambda *args: None)

    # ---- the login --------------------------------------------------------------------------------------------------
    def _session(self, request: web.Request) -> Session | None:
        return self.sessions.get(request.cookies.get(COOKIE), time.monotonic())

    def _full(self) -> str:
        n = self.config.consoles
        return (f"all {n} browser consoles of this classroom are in use (liansuo serve --web-consoles {n}): close a "
                "tab you no longer need, or ask the instructor")

    async def handle_login_page(self, request: web.Request) -> web.Response:
        session = self._session(request)
        return _html(login_page(await self.desk.lobby(), back=session.who() if session else ""))

    async def handle_login(self, request: web.Request) -> web.Response:
        form = await request.post()
        role, name = str(form.get("role", "trainee")), str(form.get("name", "")).strip()[:64]
        seat, password = str(form.get("seat", "")).strip(), str(form.get("password", ""))
        if role != "instructor" and not name and not seat and password:
            role = "instructor"  # typed the password only: as the console's login screen, the instructor
        now = time.monotonic()
        try:
            if role == "instructor":
                if not password:
                    raise Refused("the instructor's password, please")
                await self.desk.instructor(password, request.remote or "unknown")
                session = self.sessions.new("instructor", 0, "", password, now, set(self.consoles))
            else:
                if not seat.isdigit() or not 1 <= int(seat) <= 64:
                    raise Refused("a seat is a number, 1 to 64")
                if not name:
                    raise Refused("your name, please (it goes on your report)")
                token = await self.desk.trainee(int(seat), name)
                session = self.sessions.new("trainee", int(seat), name, token, now, set(self.consoles))
        except Refused as exc:
            page = login_page(await self.desk.lobby(), str(exc), role, name, seat)
            return _html(page, 403)
        response = web.Response(status=303, headers={"Location": "console"})
        response.set_cookie(COOKIE, session.key, max_age=int(SESSION_S), httponly=True, samesite="Strict",
                            secure=self.tls)
        return response

    async def handle_console(self, request: web.Request) -> web.StreamResponse:
        """textual-serve's page, for a login only, while a console may start."""
        session = self._session(request)
        if session is None:
            return web.Response(status=303, headers={"Location": "./"})
        if session.key not in self.consoles and len(self.consoles) >= self.config.consoles:
            return _html(refusal_page(self._full()), 503)
        if session.role == "trainee":  # still this trainee's seat? (freed, another trainee may have taken it)
            try:  # a seat freed and not taken since is this trainee's again, as a terminal console's redial takes it
                session.secret = await self.desk.trainee(session.seat, session.name, session.secret)
            except SeatLost as exc:
                self.sessions.drop(session.key)
                return _html(login_page(await self.desk.lobby(), str(exc)), 409)
            except Refused as exc:
                return _html(refusal_page(str(exc)), 503)
        response: web.StreamResponse = await self.handle_index(request)
        return response

    # ---- a login's console ------------------------------------------------------------------------------------------
    async def handle_console_socket(self, request: web.Request) -> web.StreamResponse:
        """textual-serve's websocket, after the checks: a login, one console for it, the cap, the size."""
        session = self._session(request)
        if session is None:
            return web.Response(status=403, text="log in first, on the classroom's page")
        old = self.consoles.get(session.key)
        if old is not None:  # the login's page reloaded, or opened in another tab: the old console ends
            if old.prepared:
                await old.close(message=b"opened in another tab")
            for _ in range(int(REPLACE_WAIT_S / 0.05)):
                if session.key not in self.consoles:
                    break
                await asyncio.sleep(0.05)
            else:
                return web.Response(status=409, text="this login's console in another tab is still closing: reload")
        if len(self.consoles) >= self.config.consoles:
            return web.Response(status=503, text=self._full())
        width = clamp(request.query.get("width"), 80, WIDTH)
        height = clamp(request.query.get("height"), 24, HEIGHT)
        websocket = web.WebSocketResponse(heartbeat=15, max_msg_size=64 * 1024)
        self.consoles[session.key] = websocket
        command, env = console_command(self.config.ws_url, session, self.config.certfile)
        service: Console | None = None
        try:
            await websocket.prepare(request)
            service = Console(command, env, write_bytes=websocket.send_bytes, write_str=websocket.send_str,
                              close=websocket.close, download_manager=self.download_manager, debug=self.debug)
            await service.start(width, height)
            await self._process_messages(websocket, service)
        except asyncio.CancelledError:
            await websocket.close()
        except Exception as error:  # as textual-serve: the tab's session ends, the server goes on
            log.exception(error)
        finally:
            if service is not None:
                await service.stop()
            if self.consoles.get(session.key) is websocket:
                del self.consoles[session.key]
        return websocket

    async def _process_messages(self, websocket: web.WebSocketResponse, app_service: AppService) -> None:
        """textual-serve's, with every resize clamped."""
        async for message in websocket:
            if message.type != WSMsgType.TEXT:
                continue
            envelope = message.json()
            if not isinstance(envelope, list) or not envelope:
                continue
            kind, data = envelope[0], envelope[1] if len(envelope) > 1 else None
            if kind == "stdin" and isinstance(data, str):
                await app_service.send_bytes(data.encode("utf-8"))
            elif kind == "resize" and isinstance(data, dict):
                await app_service.set_terminal_size(clamp(data.get("width"), 80, WIDTH),
                                                    clamp(data.get("height"), 24, HEIGHT))
            elif kind == "ping":
                await websocket.send_json(["pong", data])
            elif kind == "blur":
                await app_service.blur()
            elif kind == "focus":
                await app_service.focus()


def _html(text: str, status: int = 200) -> web.Response:
    return web.Response(text=text, status=status, content_type="text/html")


def _orphaned(parent: int) -> None:
    """End this process once the server that started it is gone, however it went (a SIGKILL runs no clean-up)."""
    while True:
        time.sleep(ORPHAN_CHECK_S)
        if os.getppid() != parent:
            os._exit(0)


def _serve(config: WebConfig, parent: int) -> None:
    threading.Thread(target=_orphaned, args=(parent,), name="liansuo-web-parent", daemon=True).start()
    ClassroomWeb(config).serve()


def start(config: WebConfig) -> BaseProcess:
    """Serve the browsers in a child process, which ends with the server."""
    proc = multiprocessing.get_context("spawn").Process(target=_serve, args=(config, os.getpid()), name="liansuo-web",
                                                        daemon=True)
    proc.start()
    return proc
