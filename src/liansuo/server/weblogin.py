"""The browsers' login (``liansuo serve --web``): who a browser is, checked before any console is started for it.

A trainee's seat and name are checked by the classroom server itself, over its websocket, which gives the seat and
its token (the console started later takes the seat back with it); the instructor's password is checked here against
the server's hash, off the event loop, one check at a time, with the lockout per browser's address of
:class:`.LoginGuard`. A login that passes gets a session: a random key, kept in the browser's cookie, that the
console's websocket must show.
"""

from __future__ import annotations

import asyncio
import json
import secrets
import ssl
from dataclasses import dataclass, field
from typing import Any

from websockets.asyncio.client import connect
from websockets.exceptions import WebSocketException

from liansuo.server.lockout import LoginGuard
from liansuo.server.passwordcheck import PasswordCheck

SESSION_S = 12 * 3600.0  # a login serves for a school day: its tab reloaded, or reopened, gets its console again
MAX_SESSIONS = 512  # past it, the oldest sessions without a console are forgotten
MAX_DIALS = 8  # logins and lobbies asked of the classroom server at once; more are told to try again
DIAL_TIMEOUT_S = 5.0


class Refused(Exception):
    """A login that does not pass: the message is for the login page."""


class SeatLost(Refused):
    """The classroom server refused the trainee: the seat is taken, or no longer this trainee's."""


@dataclass
class Session:
    key: str
    role: str  # trainee or instructor
    seat: int = 0
    name: str = ""
    secret: str = field(default="", repr=False)  # the seat's token, or the instructor's password
    until: float = 0.0

    def who(self) -> str:
        return f"seat {self.seat}, {self.name}" if self.role == "trainee" else "the instructor"


class Sessions:
    """The logins that passed, by key; ``busy(key)`` says whether one has a console now (never forgotten then)."""

    def __init__(self) -> None:
        self._by_key: dict[str, Session] = {}

    def new(self, role: str, seat: int, name: str, secret: str, now: float, busy: set[str]) -> Session:
        if len(self._by_key) >= MAX_SESSIONS:
            idle = [k for k, s in self._by_key.items() if k not in busy]
            for k in sorted(idle, key=lambda k: self._by_key[k].until)[: len(self._by_key) - MAX_SESSIONS + 1]:
                del self._by_key[k]
        s = Session(secrets.token_urlsafe(32), role, seat, name, secret, now + SESSION_S)
        self._by_key[s.key] = s
        return s

    def get(self, key: str | None, now: float) -> Session | None:
        s = self._by_key.get(key or "")
        if s is not None and now >= s.until:
            del self._by_key[s.key]
            return None
        return s

    def drop(self, key: str) -> None:
        self._by_key.pop(key, None)


class Desk:
    """Checks logins against the classroom server at ``ws_url`` (verified with ``tls`` when it is wss://)."""

    def __init__(self, ws_url: str, tls: ssl.SSLContext | None, instructor_hash: str, guard: LoginGuard) -> None:
        self.ws_url, self.tls = ws_url, tls
        self.passwords = PasswordCheck(instructor_hash, guard, "liansuo-web-password")
        self._dials = 0

    async def ask(self, message: dict[str, Any]) -> dict[str, Any]:
        """One message to the classroom server, as the first of a connection, and its reply (then it closes)."""
        if self._dials >= MAX_DIALS:
            raise Refused("the server is busy with other logins: try again in a few seconds")
        self._dials += 1
        try:
            async with connect(self.ws_url, ssl=self.tls, open_timeout=DIAL_TIMEOUT_S, close_timeout=1) as ws:
                await ws.send(json.dumps(message))
                reply = json.loads(await asyncio.wait_for(ws.recv(), DIAL_TIMEOUT_S))
        except (OSError, TimeoutError, WebSocketException, ValueError) as exc:
            raise Refused(f"the classroom server does not answer ({exc or type(exc).__name__}): ask the instructor") \
                from None
        finally:
            self._dials -= 1
        if not isinstance(reply, dict):
            raise Refused("the classroom server answered what is not a message")
        return reply

    async def lobby(self) -> dict[str, Any]:
        """The station and which seats are taken, for the login page ({} when it cannot be asked now)."""
        try:
            reply = await self.ask({"type": "lobby"})
        except Refused:
            return {}
        return reply if reply.get("type") == "lobby" else {}

    async def trainee(self, seat: int, name: str, token: str | None = None) -> str:
        """Take ``seat`` (or, with its ``token``, check it is still this trainee's); the seat's token."""
        reply = await self.ask({"type": "hello", "role": "trainee", "seat": seat, "name": name, "token": token})
        if reply.get("type") != "welcome":
            raise SeatLost(str(reply.get("message", "refused")))
        return str(reply.get("token", ""))

    async def instructor(self, password: str, address: str) -> None:
        """Refused unless ``password`` is the instructor's and ``address`` may try it now (:class:`.PasswordCheck`,
        as the classroom server checks it)."""
        why = await self.passwords.refusal(password, address)
        if why is not None:
            raise Refused(why)
