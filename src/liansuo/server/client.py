"""A classroom client in Python, for scripts and tests: the protocol of docs/classroom.md, synchronous.

    with ClassroomClient.trainee("ws://127.0.0.1:8765", seat=1, name="Li") as c:
        c.command("route X XI")        # {'type': 'answer', 'ok': True, 'message': 'route X-XI selected', ...}
        c.snapshot()["sections"]["IG"] # [occupied, locked]
"""

from __future__ import annotations

import json
from types import TracebackType
from typing import Any

from websockets.sync.client import ClientConnection, connect

from liansuo.server.tls import client_context


class ClassroomError(RuntimeError):
    """The server refused the client (its error message) or closed the connection."""


class ClassroomClient:
    def __init__(self, url: str, hello: dict[str, Any], *, timeout: float = 10.0, cafile: str | None = None) -> None:
        """``cafile``: for a wss:// server, the CA (or the server's own certificate) to verify it with, instead of
        the system's CAs."""
        self.timeout = timeout
        self.ws: ClientConnection = connect(url, open_timeout=timeout,
                                            ssl=client_context(url, cafile)).__enter__()  # closed by close()
        self.ws.send(json.dumps({"type": "hello", **hello}))
        self.welcome = self._next()
        if self.welcome.get("type") != "welcome":
            self.ws.close()
            raise ClassroomError(str(self.welcome.get("message", self.welcome)))
        self.last: dict[str, Any] | None = None  # the newest snapshot received
        self.events: list[tuple[float, str, str]] = []  # every event received, in order
        self._id = 0

    @classmethod
    def trainee(cls, url: str, seat: int, name: str = "", token: str | None = None, *,
                cafile: str | None = None) -> ClassroomClient:
        return cls(url, {"role": "trainee", "seat": seat, "name": name, "token": token}, cafile=cafile)

    @classmethod
    def instructor(cls, url: str, password: str, *, cafile: str | None = None) -> ClassroomClient:
        return cls(url, {"role": "instructor", "password": password}, cafile=cafile)

    @property
    def token(self) -> str:
        return str(self.welcome.get("token", ""))

    def _next(self) -> dict[str, Any]:
        try:
            msg: dict[str, Any] = json.loads(self.ws.recv(timeout=self.timeout))
        except TimeoutError:
            raise ClassroomError(f"no message from the server in {self.timeout:g} s") from None
        if msg.get("type") == "snapshot":
            self.last = msg
            self.events += [(t, k, x) for t, k, x in msg.get("events", [])]
        return msg

    def request(self, message: dict[str, Any]) -> dict[str, Any]:
        """Send one message, with a fresh ``id`` unless it has one, and return the server's reply with that id
        (snapshots that arrive meanwhile are kept; a reply to an earlier message, sent raw, is skipped)."""
        if "id" not in message:
            self._id += 1
            message = {**message, "id": self._id}
        self.ws.send(json.dumps(message))
        while True:
            msg = self._next()
            if msg.get("type") not in ("snapshot", "seats") and msg.get("id") == message["id"]:
                return msg

    def command(self, line: str, seat: int | None = None) -> dict[str, Any]:
        return self.request({"type": "command", "line": line, **({} if seat is None else {"seat": seat})})

    def snapshot(self) -> dict[str, Any]:
        """The next snapshot the server sends."""
        while True:
            msg = self._next()
            if msg.get("type") == "snapshot":
                return msg

    def seats(self) -> list[dict[str, Any]]:
        """The next summary of every seat the server sends (the instructor's dashboard: trainee, commands, ...)."""
        while True:
            msg = self._next()
            if msg.get("type") == "seats":
                return list(msg["seats"])

    def close(self) -> None:
        self.ws.close()

    def __enter__(self) -> ClassroomClient:
        return self

    def __exit__(self, kind: type[BaseException] | None, exc: BaseException | None, tb: TracebackType | None) -> None:
        self.close()
