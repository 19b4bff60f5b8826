"""The classroom benchmark's attackers, each a process of its own so that its work never takes the honest client's
time in the benchmark's process (:mod:`.classroom`): raw websocket clients, as on a school's LAN.

    python -m liansuo.bench.attackers flood URL SEAT     # prints "ready", floods; "stop" on stdin: prints the counts
    python -m liansuo.bench.attackers logins URL N       # prints "started", then the replies counted, as JSON
"""

from __future__ import annotations

import asyncio
import json
import socket
import sys
import threading
import time
from typing import Any


def flood(url: str, seat: int) -> None:
    """Take ``seat`` and send the same command as fast as the connection takes it, reading nothing (back-pressure
    stalls the sends). A line on stdin stops it: it then prints ``{"sent", "seconds"}`` as JSON."""
    from websockets.exceptions import ConnectionClosed
    from websockets.sync.client import connect

    message = json.dumps({"type": "command", "id": 1, "line": "route X XI"})
    with connect(url, open_timeout=30) as ws:
        ws.send(json.dumps({"type": "hello", "role": "trainee", "seat": seat, "name": "Flood"}))
        welcome = json.loads(ws.recv(timeout=30))
        if welcome.get("type") != "welcome":
            print(f"refused: {welcome.get('message', welcome)}", flush=True)
            return
        sent, stop = 0, threading.Event()

        def watch() -> None:  # the stop: unblocks a send stalled by back-pressure
            sys.stdin.readline()
            stop.set()
            ws.socket.shutdown(socket.SHUT_RDWR)

        threading.Thread(target=watch, daemon=True).start()
        print("ready", flush=True)
        t0 = time.perf_counter()
        try:
            while not stop.is_set():
                ws.send(message)
                sent += 1
        except (ConnectionClosed, OSError):
            pass
        seconds = time.perf_counter() - t0
    print(json.dumps({"sent": sent, "seconds": seconds}), flush=True)


async def _login(url: str, i: int) -> str:
    """One wrong instructor login: the server's reply, or why there was none."""
    from websockets.asyncio.client import connect
    from websockets.exceptions import InvalidStatus, WebSocketException

    try:
        async with connect(url, open_timeout=60) as ws:
            await ws.send(json.dumps({"type": "hello", "role": "instructor", "password": f"guess {i}"}))
            reply = json.loads(await asyncio.wait_for(ws.recv(), 60))
            return str(reply.get("message", reply.get("type")))
    except InvalidStatus as exc:  # refused before the websocket opened (too many from this address)
        return f"refused with HTTP {exc.response.status_code}"
    except (OSError, TimeoutError, WebSocketException) as exc:
        return f"no reply: {type(exc).__name__}"


KINDS = ("checked", "locked_out", "busy", "turned_away", "failed")


def kind(reply: str) -> str:
    """What happened to a wrong login: its password ``checked``, or refused unchecked by the address's lockout
    (``locked_out``, with the checks under way from that address) or the server's limit on checks at once
    (``busy``), or refused before its websocket opened, its address having too many connections open
    (``turned_away``); ``failed``: no reply at all."""
    if reply.startswith("wrong instructor password"):
        return "checked"
    if reply.startswith("too many"):
        return "locked_out"
    if "busy checking" in reply:
        return "busy"
    if reply == "refused with HTTP 429":
        return "turned_away"
    return "failed"


async def _logins(url: str, n: int) -> dict[str, Any]:
    t0 = time.perf_counter()
    replies = await asyncio.gather(*(_login(url, i) for i in range(n)))
    counts = {k: 0 for k in KINDS}
    for reply in replies:
        counts[kind(reply)] += 1
    return {**counts, "seconds": time.perf_counter() - t0}


def logins(url: str, n: int) -> None:
    """``n`` wrong instructor logins at once, each on its own connection; prints the counts of :func:`kind` and the
    seconds until the last reply, as JSON."""
    import websockets.asyncio.client  # noqa: F401  (loaded before the start is announced: the wave starts at once)

    print("started", flush=True)
    print(json.dumps(asyncio.run(_logins(url, n))), flush=True)


if __name__ == "__main__":
    what, where, number = sys.argv[1], sys.argv[2], int(sys.argv[3])
    if what == "flood":
        flood(where, number)
    else:
        logins(where, number)
