"""The connection of a console to the classroom server: one websocket, run by a thread of its own.

The thread runs websockets' asyncio client on an event loop of its own. It keeps what arrives unasked (the newest
snapshot of the seat shown, the events of every snapshot by the seat they are of, the instructor's seat summaries)
and hands each reply to
the request with the reply's ``id``: each request gets a fresh id, and the server echoes it in the reply
(docs/classroom.md, "The protocol"). A reply that comes after its request gave up goes to nobody.

When the connection drops, every request waiting is answered "connection lost", and websockets' reconnecting client
dials again with exponential backoff, with the seat's token (a trainee) or the password (the instructor, who then
watches the same seat again), until it is back or the console closes. A server that refuses the hello (a wrong
password, a seat taken) or ends the session (the instructor freed the seat) is not dialled again: the link ends, and
``problem`` says why.
"""

from __future__ import annotations

import asyncio
import concurrent.futures
import contextlib
import itertools
import json
import ssl
import threading
from collections.abc import AsyncGenerator
from typing import Any, cast

from websockets.asyncio.client import ClientConnection
from websockets.asyncio.client import connect as connecting
from websockets.exceptions import ConnectionClosed, InvalidHandshake, InvalidStatus, InvalidURI, WebSocketException
from websockets.sync.client import connect

from liansuo.server.tls import hint

REQUEST_TIMEOUT_S = 5.0  # a reply slower than this is answered "no answer" (the console does not freeze longer)
OPEN_TIMEOUT_S = 5.0  # to connect and be welcomed
POLICY = 1008  # the close code of a server that ended the session on purpose (a seat freed, a hello refused)


class LinkError(RuntimeError):
    """The server could not be reached, or refused the client: the message says which, in one line."""


class Refused(LinkError):
    """The server answered the hello with a refusal: dialling again would be refused again."""


class NoWelcome(ConnectionError):
    """The connection closed before the hello was answered (a server stopping, say): worth dialling again."""


def greeted(hello: dict[str, Any]) -> type[ClientConnection]:
    """A connection that says ``hello`` as part of its opening, so that websockets' reconnecting client counts a
    connection the server did not welcome as one that failed: :class:`Refused` ends the reconnecting, anything
    else is dialled again with backoff. The welcome is its ``welcome``; ``hello`` is read at every dial (the
    link puts the seat's newest token in it)."""

    class Greeted(ClientConnection):
        welcome: dict[str, Any]

        async def handshake(self, *args: Any, **kwargs: Any) -> None:
            await super().handshake(*args, **kwargs)
            try:
                await self.send(json.dumps({"type": "hello", **hello}))
                reply = json.loads(await self.recv())
            except ConnectionClosed as exc:
                raise NoWelcome(f"the server closed the connection before answering the hello: {exc}") from None
            except ValueError as exc:
                raise NoWelcome(f"the server's answer to the hello is not JSON: {exc}") from None
            if not isinstance(reply, dict) or reply.get("type") != "welcome":
                why = reply.get("message", reply) if isinstance(reply, dict) else reply
                raise Refused(f"the classroom server refused: {why}")
            self.welcome = reply

    return Greeted


def transient(exc: Exception) -> Exception | None:
    """For websockets' reconnecting client: None to dial again after the next delay, or the exception that ends the
    reconnecting. A refusal, an address that is not a websocket server's, a handshake it refuses: ended."""
    if isinstance(exc, Refused | ssl.SSLCertVerificationError):  # a certificate not trusted stays so
        return exc
    if isinstance(exc, OSError | TimeoutError | EOFError | ConnectionClosed):  # NoWelcome is an OSError
        return None
    if isinstance(exc, InvalidStatus):
        return None if exc.response.status_code in (500, 502, 503, 504) else exc
    if isinstance(exc, InvalidHandshake) and isinstance(exc.__cause__, EOFError):  # closed during the handshake
        return None
    return exc


def why_not(url: str, exc: Exception) -> LinkError:
    """The first dial failed: why, in one line."""
    if isinstance(exc, LinkError):
        return exc
    if isinstance(exc, ssl.SSLError):  # a certificate refused is a ValueError too
        return LinkError(f"cannot reach the classroom server at {url}: {exc}{hint(url, exc)}")
    if isinstance(exc, InvalidURI | ValueError):
        return LinkError(f"{url} is not a websocket address (ws://HOST:PORT): {exc}")
    if isinstance(exc, NoWelcome):
        return LinkError(f"the classroom server at {url} did not answer the hello: {exc}")
    return LinkError(f"cannot reach the classroom server at {url}: {exc}{hint(url, exc)}")


class ServerLink:
    """A console's connection to the server (see the module's docstring). Thread-safe; never raises once open."""

    def __init__(self, url: str, hello: dict[str, Any], *, timeout: float = REQUEST_TIMEOUT_S,
                 tls: ssl.SSLContext | None = None) -> None:
        """Dial once (:class:`LinkError` saying why when that fails), then keep the connection in a thread;
        ``tls``: how a wss:// server is verified (server/tls.py; None: against the system's CAs)."""
        self.url = url
        self.timeout = timeout
        self.tls = tls
        self._hello = dict(hello)
        self._lock = threading.Lock()  # the snapshot, events and seats, read by the console's thread
        self._snapshot: dict[str, Any] | None = None
        self._events: dict[int, list[list[Any]]] = {}  # by seat: a snapshot of the seat watched before comes late
        self._seats: list[dict[str, Any]] = []
        self._runs: dict[int, int] = {}  # by seat: the simulation its last snapshot came from (classroom.Desk.runs)
        # the link's own thread only, on its loop:
        self._ids = itertools.count(1)
        self._pending: dict[int, asyncio.Future[dict[str, Any]]] = {}
        self._ws: ClientConnection | None = None
        self._closing = False
        self.connected = False
        self.ended = False  # the server refused the hello or ended the session: no more dialling
        self.problem = ""  # why the link is down, while it is
        self.generation = 0  # counts the connections: a console sees it was back without having noticed the drop
        self.welcome: dict[str, Any] = {}
        self.seat = 1  # the trainee's seat, or the seat the instructor watches
        self._loop = asyncio.new_event_loop()
        self._main: asyncio.Task[None] | None = None
        first: concurrent.futures.Future[dict[str, Any]] = concurrent.futures.Future()
        self._thread = threading.Thread(target=self._run, args=(first,), name="liansuo-link", daemon=True)
        self._thread.start()
        first.result()  # LinkError, raised here, when the first dial failed

    @property
    def role(self) -> str:
        return str(self.welcome.get("role", "trainee"))

    # ---- what arrived ---------------------------------------------------------------------------------------------
    def take(self) -> tuple[dict[str, Any] | None, int, list[list[Any]]]:
        """The newest snapshot of the seat shown (None before the first), that seat, and the events of its
        snapshots since the last call (those of another seat wait until it is shown again)."""
        with self._lock:
            return self._snapshot, self.seat, self._events.pop(self.seat, [])

    def seats(self) -> list[dict[str, Any]]:
        """The newest summary of every seat (the instructor's)."""
        with self._lock:
            return list(self._seats)

    # ---- requests -------------------------------------------------------------------------------------------------
    def request(self, message: dict[str, Any]) -> dict[str, Any]:
        """Send one message, with a fresh ``id``, and wait for the reply with that id; while the link is down, or
        without a reply in time, an ``error`` saying so (nothing is sent while down)."""
        if not self.connected or self._closing:
            state = "ended" if self.ended or self._closing else "lost"
            return {"type": "error", "message": f"connection to the classroom server {state} ({self.problem}); "
                                                f"{'' if state == 'ended' else 'reconnecting: '}nothing was sent"}
        try:
            asking = asyncio.run_coroutine_threadsafe(self._ask(message), self._loop)
        except RuntimeError:  # the loop has just ended
            return {"type": "error", "message": "connection to the classroom server ended: nothing was sent"}
        try:
            return asking.result(self.timeout + 1.0)  # _ask answers within the timeout; this is a backstop
        except (concurrent.futures.TimeoutError, concurrent.futures.CancelledError):
            asking.cancel()
            return {"type": "error", "message": f"no answer from the classroom server in {self.timeout:g} s"}

    def command(self, line: str, seat: int | None = None) -> dict[str, Any]:
        return self.request({"type": "command", "line": line, **({} if seat is None else {"seat": seat})})

    def watch(self, seat: int) -> dict[str, Any]:
        """The instructor shows another seat: its snapshots from now on, and only its."""
        reply = self.request({"type": "watch", "seat": seat})
        if reply.get("type") == "ok":
            with self._lock:
                self.seat, self._snapshot = seat, None
        return reply

    def close(self) -> None:
        self._closing = True
        with contextlib.suppress(RuntimeError):  # the loop has ended already
            self._loop.call_soon_threadsafe(self._cancel)
        self._thread.join(3)

    # ---- the thread -----------------------------------------------------------------------------------------------
    def _run(self, first: concurrent.futures.Future[dict[str, Any]]) -> None:
        # the Runner, as asyncio.run, cancels what is left (keepalives) and closes the loop at the end
        with asyncio.Runner(loop_factory=lambda: self._loop) as runner:
            try:
                runner.run(self._connections(first))
            except asyncio.CancelledError:
                pass
            finally:
                self.connected = False
                if not first.done():  # never left waiting, whatever ended the thread
                    first.set_exception(LinkError(f"the link to the classroom server at {self.url} ended at once"))

    def _cancel(self) -> None:
        if self._main is not None:
            self._main.cancel()

    async def _connections(self, first: concurrent.futures.Future[dict[str, Any]]) -> None:
        """The first connection, then every one websockets' reconnecting client makes after a drop."""
        self._main = asyncio.current_task()
        try:
            dial = connecting(self.url, open_timeout=OPEN_TIMEOUT_S, close_timeout=1, ssl=self.tls,
                              create_connection=greeted(self._hello), process_exception=transient)
            ws = await dial
        except Exception as exc:  # every way the first dial fails is said in one line
            first.set_exception(why_not(self.url, exc))
            return
        try:
            self.welcome = getattr(ws, "welcome", {})
            self.seat = int(self.welcome.get("seat") or 1)
            await self._open(ws)
            first.set_result(self.welcome)
            if not await self._session(ws):
                return
        finally:
            await ws.close()
        try:  # after a drop: dial again at once, then with backoff while that fails
            async with contextlib.aclosing(cast(AsyncGenerator[ClientConnection, None], dial.__aiter__())) as again:
                async for ws in again:  # closed with the generator, when the session ended or the link closes
                    await self._open(ws)
                    self.generation += 1
                    if not await self._session(ws):
                        return
        except Exception as exc:  # a refusal, or a failure that dialling again would not mend
            self.problem, self.ended = str(why_not(self.url, exc)), True

    async def _open(self, ws: ClientConnection) -> None:
        """A connection welcomed: requests go to it from now on."""
        welcome: dict[str, Any] = getattr(ws, "welcome", {})
        if welcome.get("token"):
            self._hello["token"] = welcome["token"]  # a restarted server gives the seat a new one
        if self.role == "instructor" and self.seat != int(welcome.get("seat") or 1):  # watch the same seat again
            with contextlib.suppress(ConnectionClosed):  # closed already: the session ends at once, and is dialled
                await ws.send(json.dumps({"type": "watch", "seat": self.seat, "id": next(self._ids)}))  # its reply,
                # with an id nobody waits for, goes to nobody
        with self._lock:
            self._snapshot = None
        self._ws, self.connected, self.problem = ws, True, ""

    async def _session(self, ws: ClientConnection) -> bool:
        """Read one connection until it closes; False when the server ended the session (dial no more)."""
        ended = ""
        try:
            async for raw in ws:
                self._arrived(raw)
            self.problem = "closed by the server"
        except ConnectionClosed as exc:
            self.problem = str(exc) or type(exc).__name__
            if exc.rcvd is not None and exc.rcvd.code == POLICY:
                ended = exc.rcvd.reason or "the classroom server ended the session"
        finally:
            self._ws, self.connected = None, False
            for waiting in self._pending.values():
                if not waiting.done():
                    waiting.set_result({"type": "error",
                                        "message": "connection to the classroom server lost before its answer"})
            self._pending.clear()
        if ended:
            self.problem, self.ended = ended, True
        return not ended

    def _arrived(self, raw: str | bytes) -> None:
        try:
            msg = json.loads(raw)
        except ValueError:
            return
        if not isinstance(msg, dict):
            return
        kind = msg.get("type")
        if kind == "snapshot":
            seat = msg.get("seat")
            with self._lock:
                if seat == self.seat:
                    self._snapshot = msg
                if isinstance(seat, int):
                    self._events.setdefault(seat, []).extend([*restarted(msg, self._runs), *msg.get("events", [])])
        elif kind == "seats":
            with self._lock:
                self._seats = list(msg.get("seats", []))
        else:
            ident = msg.get("id")
            waiting = self._pending.pop(ident, None) if isinstance(ident, int) else None  # None: asked by nobody
            if waiting is not None and not waiting.done():
                waiting.set_result(msg)

    async def _ask(self, message: dict[str, Any]) -> dict[str, Any]:
        """On the link's loop: send ``message`` with a fresh id, and wait for the reply with that id."""
        ws = self._ws
        if ws is None:
            return {"type": "error", "message": "connection to the classroom server lost: nothing was sent"}
        n = next(self._ids)
        reply: asyncio.Future[dict[str, Any]] = self._loop.create_future()
        self._pending[n] = reply
        try:
            await ws.send(json.dumps({**message, "id": n}))
            return await asyncio.wait_for(reply, self.timeout)
        except ConnectionClosed:
            return {"type": "error", "message": "connection to the classroom server lost: nothing was sent"}
        except TimeoutError:
            return {"type": "error", "message": f"no answer from the classroom server in {self.timeout:g} s"}
        finally:
            self._pending.pop(n, None)  # a reply that comes later goes to nobody


RESTART = "restart"  # the kind of the event that marks a seat's new simulation in its log


def restarted(snapshot: dict[str, Any], runs: dict[int, int]) -> list[list[Any]]:
    """The event that marks a new simulation on the snapshot's seat (an exercise started, a reset), before the first
    events of its clock, which starts at 0 again: so that a log whose times go back says why; [] when it is the
    simulation of the seat's last snapshot, or the first snapshot seen. ``runs`` is kept by the caller."""
    seat, run = snapshot["seat"], snapshot.get("run") or {}
    n = run.get("n")
    if not isinstance(n, int):
        return []
    before, runs[seat] = runs.get(seat), n
    if before is None or before == n:
        return []
    return [[0.0, RESTART, f"seat {seat}: {run.get('why') or 'a new simulation'}; its clock starts again at 0"]]


def lobby(url: str, timeout: float = OPEN_TIMEOUT_S, *, tls: ssl.SSLContext | None = None) -> dict[str, Any]:
    """What the server tells before a login: its station, cycle and seats (who sits where); :class:`LinkError`
    when it cannot be asked."""
    try:
        with connect(url, open_timeout=timeout, close_timeout=1, ssl=tls) as ws:
            ws.send(json.dumps({"type": "lobby"}))
            reply = json.loads(ws.recv(timeout=timeout))
    except ssl.SSLError as exc:  # a certificate refused is a ValueError too
        raise LinkError(f"cannot reach the classroom server at {url}: {exc}{hint(url, exc)}") from None
    except (InvalidURI, ValueError) as exc:
        raise LinkError(f"{url} is not a websocket address (ws://HOST:PORT): {exc}") from None
    except (OSError, TimeoutError, WebSocketException) as exc:
        raise LinkError(f"cannot reach the classroom server at {url}: {exc}{hint(url, exc)}") from None
    if not isinstance(reply, dict) or reply.get("type") != "lobby":
        why = reply.get("message", reply) if isinstance(reply, dict) else reply
        raise LinkError(f"the classroom server at {url} did not answer as one: {why}")
    return reply


class Unlinked:
    """A console not logged in yet: it has the station from the lobby to draw (dark, as with no inputs), and
    answers every request that it is not logged in. It stands where a :class:`Link` will."""

    connected = False
    ended = False
    generation = 0
    role = "trainee"
    seat = 0
    problem = "not logged in"

    def __init__(self, url: str, lobby: dict[str, Any], tls: ssl.SSLContext | None = None) -> None:
        self.url = url
        self.lobby = lobby
        self.tls = tls
        self.welcome = {"station": lobby.get("station") or {}, "cycle_s": lobby.get("cycle_s", 0.25)}

    def take(self) -> tuple[dict[str, Any] | None, int, list[list[Any]]]:
        return None, self.seat, []

    def seats(self) -> list[dict[str, Any]]:
        return []

    def request(self, message: dict[str, Any]) -> dict[str, Any]:
        return {"type": "error", "message": "not logged in to the classroom yet: nothing was sent"}

    def command(self, line: str, seat: int | None = None) -> dict[str, Any]:
        return self.request({})

    def watch(self, seat: int) -> dict[str, Any]:
        return self.request({})

    def close(self) -> None:
        pass
