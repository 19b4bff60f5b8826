"""The classroom over a websocket: one JSON message a frame, each way (docs/classroom.md, "The protocol").

A client's first message is a ``hello`` naming its role. A trainee gets one seat and its snapshots; the instructor
(with the password) may watch any seat, send any command to any seat, and run the seats' clocks. The server answers
every message, with the message's ``id`` when it has one; one it cannot read gets an ``error`` reply and changes
nothing, and a client that disconnects may
take its seat back with the token it was given (only that token: the instructor frees a seat for another trainee).

No client can freeze the class: each connection's messages are read at a bounded rate (:mod:`.throttle`), and the
instructor's password is checked off the event loop, one check at a time, with a lockout per address
(:mod:`.lockout`).
"""

from __future__ import annotations

import asyncio
import json
import ssl
import sys
import time
import traceback
import weakref
from collections.abc import Coroutine
from dataclasses import dataclass, field
from http import HTTPStatus
from typing import Any

from pydantic import ValidationError
from websockets.asyncio.server import ServerConnection, serve
from websockets.exceptions import ConnectionClosed
from websockets.http11 import Request, Response
from websockets.protocol import State

from liansuo.classroom.roles import INSTRUCTOR, TRAINEE
from liansuo.classroom.snapshot import EventCursor
from liansuo.server.classroom import Classroom, SeatError
from liansuo.server.lockout import FAILURES, LOCKOUT_S, LoginGuard
from liansuo.server.messages import (
    MESSAGE,
    ClientMessage,
    ClockMessage,
    CommandMessage,
    ExerciseMessage,
    FreeMessage,
    HelloMessage,
    LobbyMessage,
    StopMessage,
    WatchMessage,
    message_id,
    problem,
)
from liansuo.server.passwordcheck import PasswordCheck
from liansuo.server.throttle import BURST, RATE, TokenBucket

TICK_S = 0.05  # the clocks' pace on the wall clock
PUSH_S = 0.25  # a snapshot to each client this often
MAX_MESSAGE = 64 * 1024
HELLO_TIMEOUT_S = 10.0
MAX_ADDRESSES = 10_000  # addresses remembered with connections open


@dataclass
class Client:
    role: str
    seat: int  # the trainee's seat, or the seat the instructor watches
    token: str = ""
    # where each seat's event stream stands for this client: the instructor watching a seat again gets the events
    # since they last saw it, never its earlier ones twice (a seat reset or given an exercise has a new simulation,
    # whose events the cursor sends from its first)
    cursors: dict[int, EventCursor] = field(default_factory=dict)

    @property
    def cursor(self) -> EventCursor:
        return self.cursors.setdefault(self.seat, EventCursor())


class ClassroomServer:
    def __init__(self, classroom: Classroom, instructor_hash: str, *, rate: float = RATE, burst: float = BURST,
                 failures: int = FAILURES, lockout_s: float = LOCKOUT_S) -> None:
        """``rate`` and ``burst``: how fast each connection's messages are read (:class:`.TokenBucket`);
        ``failures`` and ``lockout_s``: the wrong passwords from one address before it is locked out, and for how
        long at first (:class:`.LoginGuard`)."""
        self.classroom = classroom
        self.errors = 0  # unexpected errors answered and survived (their tracebacks went to stderr)
        TokenBucket(0.0, rate, burst)  # a rate or burst it cannot use is refused here, not at the first message
        self.rate, self.burst = rate, burst
        self.passwords = PasswordCheck(instructor_hash, LoginGuard(failures, lockout_s), "liansuo-password")
        self.guard = self.passwords.guard
        self.clients: dict[ServerConnection, Client] = {}
        self._tasks: set[asyncio.Task[None]] = set()
        # connections from one address at once: every seat's console and its redial, the browsers' logins, the
        # instructor; past it a connection is refused before its websocket opens, so a wave of them costs little
        self.per_address = 2 * len(classroom.seats) + 16
        self._by_address: dict[str, weakref.WeakSet[ServerConnection]] = {}

    @property
    def instructor_hash(self) -> str:
        """The hash the instructor's password is checked against (a server restarted may be given another)."""
        return self.passwords.instructor_hash

    @instructor_hash.setter
    def instructor_hash(self, value: str) -> None:
        self.passwords.instructor_hash = value

    # ---- the loop -------------------------------------------------------------------------------------------------
    async def serve(self, host: str, port: int, ready: asyncio.Future[int] | None = None,
                    tls: ssl.SSLContext | None = None) -> None:
        """Serve until cancelled; ``ready`` gets the port listened on (useful with port 0); with ``tls``, wss://."""
        try:
            async with serve(self.handle, host, port, max_size=MAX_MESSAGE, ssl=tls,
                             process_request=self.admit_connection) as server:
                bound = next(iter(server.sockets)).getsockname()[1]
                if ready is not None:
                    ready.set_result(bound)
                await self.run_clocks()
        finally:
            self.passwords.close()

    def admit_connection(self, ws: ServerConnection, request: Request) -> Response | None:
        """Before the websocket opens: refused (429) when its address has :attr:`per_address` connections open."""
        address = _address(ws)
        live = self._by_address.setdefault(address, weakref.WeakSet())
        if sum(c.state is not State.CLOSED for c in live) >= self.per_address:
            return ws.respond(HTTPStatus.TOO_MANY_REQUESTS, f"{address} has {self.per_address} connections open to "
                              "this classroom: close some, or wait\n")
        live.add(ws)
        if len(self._by_address) > MAX_ADDRESSES:  # forget the addresses with nothing open
            self._by_address = {a: c for a, c in self._by_address.items() if any(
                x.state is not State.CLOSED for x in c)}
        return None

    async def run_clocks(self) -> None:
        last = time.monotonic()
        while True:
            await asyncio.sleep(TICK_S)
            now = time.monotonic()
            self.classroom.advance(now - last)
            last = now

    async def handle(self, ws: ServerConnection) -> None:
        client: Client | None = None
        pusher: asyncio.Task[None] | None = None
        try:
            client = await self.greet(ws)
            if client is None:
                return
            self.clients[ws] = client
            pusher = asyncio.create_task(self.push(ws, client))
            bucket = TokenBucket(time.monotonic(), self.rate, self.burst)
            async for raw in ws:
                wait = bucket.take(time.monotonic())
                if wait > 0:  # nothing more is read from this client meanwhile: its own sends stall, not the class
                    await asyncio.sleep(wait)
                await ws.send(json.dumps(self.answer(client, raw)))
                await asyncio.sleep(0)  # the other clients' turn, even while this one's messages are all there
        except ConnectionClosed:
            pass
        finally:
            self.clients.pop(ws, None)
            if pusher is not None:
                pusher.cancel()
            if client is not None and client.role == TRAINEE:
                self.classroom.leave(client.seat, client.token)

    async def greet(self, ws: ServerConnection) -> Client | None:
        """The first message: who the client is. None (after an error reply, connection closed) when refused."""
        ident: int | None = None
        try:
            raw = await asyncio.wait_for(ws.recv(), HELLO_TIMEOUT_S)
            ident = message_id(raw)
            hello = MESSAGE.validate_json(raw)
            if isinstance(hello, LobbyMessage):
                await ws.send(json.dumps(_replying(ident, self.lobby())))
                await ws.close(1000, "lobby")
                return None
            if not isinstance(hello, HelloMessage):
                raise SeatError("the first message is a hello: {\"type\": \"hello\", \"role\": ...}")
            client = await self.admit(hello, _address(ws))
        except (TimeoutError, ValidationError, SeatError, ValueError) as exc:
            why = problem(exc) if isinstance(exc, ValidationError) else str(exc) or "no hello in time"
            await ws.send(json.dumps(_replying(ident, {"type": "error", "message": why})))
            await ws.close(1008, why[:120])
            return None
        seat = self.classroom.seat(client.seat)
        await ws.send(json.dumps(_replying(ident, {
            "type": "welcome", "role": client.role, "seat": client.seat, "token": client.token,
            "station": self.classroom.station_source(), "cycle_s": seat.sim.cycle_s,
            "seats": len(self.classroom.seats),
            **({"exercises": self.classroom.station_exercises()} if client.role == INSTRUCTOR else {})})))
        return client

    def lobby(self) -> dict[str, Any]:
        """What a login screen shows: the station and which seats are taken (no names, no token, nothing of any seat's
        state: whoever asks has not logged in)."""
        room = self.classroom
        return {"type": "lobby", "station": room.station_source(), "cycle_s": room.cycle_s, "shared": room.shared,
                "seats": [{"seat": s.number, "taken": bool(s.token), "connected": s.connected}
                          for s in room.seats.values()]}

    async def admit(self, hello: HelloMessage, address: str) -> Client:
        if hello.role == INSTRUCTOR:
            await self.check_password(hello.password, address)
            return Client(INSTRUCTOR, 1)
        if hello.seat is None:
            raise SeatError("a trainee names a seat: {\"seat\": N}")
        token = self.classroom.take(hello.seat, hello.name, hello.token)
        return Client(TRAINEE, hello.seat, token)

    async def check_password(self, password: str | None, address: str) -> None:
        """Raise SeatError unless ``password`` is the instructor's and ``address`` may try it now
        (:class:`.PasswordCheck`: off the event loop, with the lockout)."""
        why = await self.passwords.refusal(password, address)
        if why is not None:
            raise SeatError(why)

    async def push(self, ws: ServerConnection, client: Client) -> None:
        n = 0
        while True:
            await ws.send(json.dumps(self.classroom.snapshot(client.seat, client.role, client.cursor)))
            if client.role == INSTRUCTOR and n % 4 == 0:
                await ws.send(json.dumps({"type": "seats", "seats": self.classroom.summaries()}))
            n += 1
            await asyncio.sleep(PUSH_S)

    # ---- one message --------------------------------------------------------------------------------------------
    def answer(self, client: Client, raw: str | bytes) -> dict[str, Any]:
        """The reply to one message, with its ``id`` when it has one; never raises (an unexpected error is answered,
        and its traceback printed)."""
        try:
            msg = MESSAGE.validate_json(raw)
        except ValidationError as exc:
            return _replying(message_id(raw), {"type": "error", "message": f"cannot read the message: {problem(exc)}"})
        try:
            reply = self.dispatch(client, msg)
        except SeatError as exc:
            reply = {"type": "error", "message": str(exc)}
        except Exception:  # the server carries on for every other client
            self.errors += 1
            traceback.print_exc(file=sys.stderr)
            reply = {"type": "error", "message": "internal error on the server (reported in its log)"}
        return _replying(msg.id, reply)

    def dispatch(self, client: Client, msg: ClientMessage) -> dict[str, Any]:
        instructor = client.role == INSTRUCTOR
        if isinstance(msg, HelloMessage | LobbyMessage):
            raise SeatError(f"a {msg.type} is sent once, first")
        if not instructor and not self.classroom.holds(client.seat, client.token):
            raise SeatError(f"the instructor freed seat {client.seat}: log in again")
        if isinstance(msg, CommandMessage):
            if msg.seat is not None and msg.seat != client.seat and not instructor:
                raise SeatError("a trainee operates only their own seat")
            seat = msg.seat if instructor and msg.seat is not None else client.seat
            r = self.classroom.command(seat, client.role, msg.line)
            return {"type": "answer", "seat": seat, "ok": r.ok, "message": r.message}
        if not instructor:
            raise SeatError(f"'{msg.type}' is the instructor's: a trainee sends commands only")
        if isinstance(msg, WatchMessage):
            self.classroom.seat(msg.seat)
            client.seat = msg.seat
            return {"type": "ok", "message": f"watching seat {msg.seat}"}
        seats = list(self.classroom.seats) if msg.seats == "all" else [int(s) for s in msg.seats]
        if isinstance(msg, ClockMessage):
            paused = None if msg.action is None else msg.action == "pause"
            self.classroom.set_clock(seats, paused=paused, speed=msg.speed)
            return {"type": "ok", "message": f"clock of seats {', '.join(map(str, seats))}: "
                                             f"{msg.action or 'speed'} {'' if msg.speed is None else msg.speed}"}
        if isinstance(msg, ExerciseMessage):
            said = self.classroom.start_exercise(seats, msg.name, difficulty=msg.difficulty, seed=msg.seed)
            return {"type": "ok", "message": said}
        if isinstance(msg, StopMessage):
            written = self.classroom.stop_exercise(seats)
            return {"type": "ok", "message": f"reports written: {', '.join(str(p) for p in written)}" if written
                    else "no exercise on those seats", "reports": [str(p) for p in written]}
        if isinstance(msg, FreeMessage):
            self.classroom.free(seats)
            for ws, c in list(self.clients.items()):
                if c.role == TRAINEE and c.seat in seats:
                    self._later(ws.close(1008, f"the instructor freed seat {c.seat}"))
            return {"type": "ok", "message": f"seats {', '.join(map(str, seats))} freed: a new trainee may take them"}
        self.classroom.reset(seats)
        return {"type": "ok", "message": f"seats {', '.join(map(str, seats))} reset"}

    def _later(self, work: Coroutine[Any, Any, None]) -> None:
        task = asyncio.create_task(work)
        self._tasks.add(task)
        task.add_done_callback(self._tasks.discard)


def _replying(ident: int | None, reply: dict[str, Any]) -> dict[str, Any]:
    """A reply carries the id of the message it answers; a message without one gets a reply without one."""
    return reply if ident is None else {**reply, "id": ident}


def _address(ws: ServerConnection) -> str:
    """The client's address, without its port: what a lockout applies to."""
    peer = ws.remote_address
    return str(peer[0]) if isinstance(peer, tuple) and peer else "unknown"
