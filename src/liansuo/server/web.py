"""The classroom in browsers: textual-serve serves the classroom's own console client to every browser that opens
the page (``liansuo serve --web``).

textual-serve runs one command per browser tab, in a process of its own, and relays its terminal to the page. That
command is the console client (``liansuo tui --connect``), which asks for a seat or the instructor's password and then
talks to this server like any terminal client: a browser gets nothing a terminal client would not, and no simulation
runs in the browser's process (each tab's is the client's, a few MB; the simulations stay on the server).
"""

from __future__ import annotations

import multiprocessing
import os
import shlex
import sys
import threading
import time
from multiprocessing.process import BaseProcess

from textual_serve.server import Server

DEFAULT_PORT = 8000
ORPHAN_CHECK_S = 1.0


def client_command(ws_url: str) -> str:
    """The command each browser tab runs: the console client, with its login screen."""
    return f"{shlex.quote(sys.executable)} -m liansuo.cli tui --connect {shlex.quote(ws_url)}"


def local_url(host: str, port: int) -> str:
    """Where a client on this machine reaches the websocket server listening on ``host``."""
    return f"ws://{'127.0.0.1' if host in ('0.0.0.0', '::', '') else host}:{port}"


def _orphaned(parent: int) -> None:
    """End this process once the server that started it is gone, however it went (a SIGKILL runs no clean-up)."""
    while True:
        time.sleep(ORPHAN_CHECK_S)
        if os.getppid() != parent:
            os._exit(0)


def _serve(command: str, host: str, port: int, public_url: str | None, parent: int) -> None:
    threading.Thread(target=_orphaned, args=(parent,), name="liansuo-web-parent", daemon=True).start()
    Server(command, host=host, port=port, title="liansuo classroom", public_url=public_url).serve()


def start(ws_url: str, host: str, port: int, public_url: str | None = None) -> BaseProcess:
    """Serve the console client to browsers on ``host:port`` in a child process, which ends with the server."""
    proc = multiprocessing.get_context("spawn").Process(
        target=_serve, args=(client_command(ws_url), host, port, public_url, os.getpid()), name="liansuo-web",
        daemon=True)
    proc.start()
    return proc
