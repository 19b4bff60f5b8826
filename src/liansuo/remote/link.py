"""The connection of a console to the classroom server: one websocket, read by a thread of its own.

The thread keeps what arrives unasked (the newest snapshot of the seat shown, the events of every snapshot, the
instructor's seat summaries) and hands each reply to the request waiting for it: the server answers a client's
messages one by one, in order (docs/classroom.md, "The protocol"), so the oldest request waiting gets the next reply.
When the connection drops, every request waiting is answered "connection lost", and the thread dials again, with the
seat's token (a trainee) or the password (the instructor, who then watches the same seat again), until it is back or
the console closes.
"""

from __future__ import annotations

import json
import ssl
import threading
import time
from collections import deque
from dataclasses import dataclass, field
from typing import Any

from websockets.exceptions import ConnectionClosed, InvalidURI, WebSocketException
from websockets.sync.client import ClientConnection, connect

from liansuo.server.tls import hint

REQUEST_TIMEOUT_S = 5.0  # a reply slower than this is answered "no answer" (the console does not freeze longer)
OPEN_TIMEOUT_S = 5.0
REDIAL_S = 1.0


class LinkError(RuntimeError):
    """The server could not be reached, or refused the client: the message says which, in one line."""


@dataclass
class _Waiting:
    done: threading.Event = field(default_factory=threading.Event)
    reply: dict[str, Any] | None = None


def dial(url: str, hello: dict[str, Any], timeout: float = OPEN_TIMEOUT_S, *,
         tls: ssl.SSLContext | None = None) -> tuple[ClientConnection, dict[str, Any]]:
    """Connect and say hello; the connection and the server's welcome, or :class:`LinkError` saying why not.
    ``tls``: how a wss:// server is verified (server/tls.py; None: against the system's CAs)."""
    try:
        ws = connect(url, open_timeout=timeout, close_timeout=1, ssl=tls).__enter__()  # closed by Link.close()
    except ssl.SSLError as exc:  # a certificate refused is a ValueError too
        raise LinkError(f"cannot reach the classroom server at {url}: {exc}{hint(url, exc)}") from None
    except (InvalidURI, ValueError) as exc:
        raise LinkError(f"{url} is not a websocket address (ws://HOST:PORT): {exc}") from None
    except (OSError, TimeoutError, WebSocketException) as exc:
        raise LinkError(f"cannot reach the classroom server at {url}: {exc}{hint(url, exc)}") from None
    try:
        ws.send(json.dumps({"type": "hello", **hello}))
        reply = json.loads(ws.recv(timeout=timeout))
    except (OSError, TimeoutError, WebSocketException, ValueError) as exc:
        ws.close()
        raise LinkError(f"the classroom server at {url} did not answer the hello: {exc}") from None
    if not isinstance(reply, dict) or reply.get("type") != "welcome":
        ws.close()
        why = reply.get("message", reply) if isinstance(reply, dict) else reply
        raise LinkError(f"the classroom server refused: {why}")
    return ws, reply


class ServerLink:
    """A console's connection to the server (see the module's docstring). Thread-safe; never raises once open."""

    def __init__(self, url: str, hello: dict[str, Any], *, timeout: float = REQUEST_TIMEOUT_S,
                 tls: ssl.SSLContext | None = None) -> None:
        self.url = url
        self.timeout = timeout
        self.tls = tls
        self._hello = dict(hello)
        self._ws, self.welcome = dial(url, self._hello, tls=tls)
        if self.welcome.get("token"):
            self._hello["token"] = self.welcome["token"]
        self.seat = int(self.welcome.get("seat") or 1)  # the trainee's seat, or the seat the instructor watches
        self._lock = threading.Lock()
        self._waiting: deque[_Waiting] = deque()
        self._snapshot: dict[str, Any] | None = None
        self._events: list[list[Any]] = []
        self._seats: list[dict[str, Any]] = []
        self._id = 0
        self._closing = False
        self.connected = True
        self.problem = ""  # why the link is down, while it is
        self.generation = 0  # counts the connections: a console sees it was back without having noticed the drop
        self._thread = threading.Thread(target=self._run, name="liansuo-link", daemon=True)
        self._thread.start()

    @property
    def role(self) -> str:
        return str(self.welcome.get("role", "trainee"))

    # ---- what arrived ---------------------------------------------------------------------------------------------
    def take(self) -> tuple[dict[str, Any] | None, list[list[Any]]]:
        """The newest snapshot of the seat shown (None before the first), and the events of every snapshot since
        the last call."""
        with self._lock:
            events, self._events = self._events, []
            return self._snapshot, events

    def seats(self) -> list[dict[str, Any]]:
        """The newest summary of every seat (the instructor's)."""
        with self._lock:
            return list(self._seats)

    # ---- requests -------------------------------------------------------------------------------------------------
    def request(self, message: dict[str, Any]) -> dict[str, Any]:
        """Send one message and wait for its reply; while the link is down, or without a reply in time, an
        ``error`` saying so (nothing is sent while down)."""
        waiting = _Waiting()
        with self._lock:
            if not self.connected:
                return {"type": "error", "message": f"connection to the classroom server lost ({self.problem}); "
                                                    "reconnecting: nothing was sent"}
            self._waiting.append(waiting)
            try:
                self._ws.send(json.dumps(message))
            except (OSError, WebSocketException):
                self._waiting.remove(waiting)
                return {"type": "error", "message": "connection to the classroom server lost: nothing was sent"}
        if not waiting.done.wait(self.timeout):
            with self._lock:
                if waiting in self._waiting:  # its reply, if it comes, goes to nobody
                    waiting.reply = {"type": "late"}
            return {"type": "error", "message": f"no answer from the classroom server in {self.timeout:g} s"}
        assert waiting.reply is not None
        return waiting.reply

    def command(self, line: str, seat: int | None = None) -> dict[str, Any]:
        with self._lock:
            self._id += 1
            n = self._id
        return self.request({"type": "command", "id": n, "line": line, **({} if seat is None else {"seat": seat})})

    def watch(self, seat: int) -> dict[str, Any]:
        """The instructor shows another seat: its snapshots from now on, and only its."""
        reply = self.request({"type": "watch", "seat": seat})
        if reply.get("type") == "ok":
            with self._lock:
                self.seat, self._snapshot, self._events = seat, None, []
        return reply

    def close(self) -> None:
        self._closing = True
        with self._lock:
            ws = self._ws
        ws.close()
        self._thread.join(3)

    # ---- the thread -----------------------------------------------------------------------------------------------
    def _run(self) -> None:
        while not self._closing:
            self._read()
            if self._closing:
                return
            self._redial()

    def _read(self) -> None:
        try:
            for raw in self._ws:
                self._arrived(json.loads(raw))
        except (ConnectionClosed, OSError, ValueError) as exc:
            self.problem = str(exc) or type(exc).__name__
        with self._lock:
            self.connected = False
            self.problem = self.problem or "closed by the server"
            for w in self._waiting:
                w.reply = {"type": "error", "message": "connection to the classroom server lost before its answer"}
                w.done.set()
            self._waiting.clear()

    def _arrived(self, msg: dict[str, Any]) -> None:
        kind = msg.get("type")
        with self._lock:
            if kind == "snapshot":
                if msg.get("seat") == self.seat:
                    self._snapshot = msg
                    self._events += msg.get("events", [])
            elif kind == "seats":
                self._seats = list(msg.get("seats", []))
            elif self._waiting:
                w = self._waiting.popleft()
                w.reply = msg
                w.done.set()

    def _redial(self) -> None:
        while not self._closing:
            time.sleep(REDIAL_S)
            try:
                ws, welcome = dial(self.url, self._hello, tls=self.tls)
            except LinkError as exc:
                self.problem = str(exc)
                continue
            if welcome.get("token"):
                self._hello["token"] = welcome["token"]  # a restarted server gives the seat a new one
            with self._lock:
                self._ws, self._snapshot = ws, None
            if self.role == "instructor" and self.seat != int(welcome.get("seat") or 1):
                ws.send(json.dumps({"type": "watch", "seat": self.seat}))
                with self._lock:
                    self._waiting.append(_Waiting())  # its reply goes to nobody
            with self._lock:
                self.connected, self.problem = True, ""
                self.generation += 1
            return


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
    generation = 0
    role = "trainee"
    seat = 0
    problem = "not logged in"

    def __init__(self, url: str, lobby: dict[str, Any], tls: ssl.SSLContext | None = None) -> None:
        self.url = url
        self.lobby = lobby
        self.tls = tls
        self.welcome = {"station": lobby.get("station") or {}, "cycle_s": lobby.get("cycle_s", 0.25)}

    def take(self) -> tuple[dict[str, Any] | None, list[list[Any]]]:
        return None, []

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
