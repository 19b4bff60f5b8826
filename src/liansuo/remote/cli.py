"""``liansuo tui --connect URL``: the console as a client of the classroom server (its options are registered with
``liansuo tui`` in ``tui/cli.py``; ``cli/main.py`` hands the connecting ones here).

Everything that can be wrong is said before a console starts, in one line, with exit status 2: a bad address, no
server there, a wrong password, a seat taken.
"""

from __future__ import annotations

import argparse
import os
from pathlib import Path
from typing import Any

from liansuo.classroom.passwords import ENV, TOKEN_ENV
from liansuo.kit.exitcodes import Exit, refuse


class LoginError(ValueError):
    """The command line's credentials cannot be used; the message says why."""


def instructor_password(file: str | None) -> str:
    """The instructor's password itself (the server checks it against its hash): the first line of ``file``, else
    the environment; never the command line."""
    if file is not None:
        try:
            line = Path(file).read_text(encoding="utf-8").strip().splitlines()[0].strip()
        except (OSError, UnicodeDecodeError, IndexError) as exc:
            raise LoginError(f"{file}: cannot read the instructor's password ({exc or 'the file is empty'})") from None
        if line.startswith("scrypt$"):
            raise LoginError(f"{file} holds the password's hash, which is the server's: the client needs a file "
                             f"with the password itself (or {ENV})")
        return line
    plain = os.environ.get(ENV)
    if not plain:
        raise LoginError(f"the instructor's password: give --password-file FILE (the password on its first line) "
                         f"or set {ENV}")
    return plain


def hello(args: argparse.Namespace) -> dict[str, Any] | None:
    """The hello the command line asks for; None: ask on the login screen."""
    if args.instructor:
        if args.seat is not None:
            raise LoginError("--instructor watches every seat: no --seat with it")
        return {"role": "instructor", "password": instructor_password(args.password_file)}
    if args.seat is None:
        return None
    if not 1 <= args.seat <= 64:
        raise LoginError(f"--seat is 1 to 64, not {args.seat}")
    return {"role": "trainee", "seat": args.seat, "name": args.name or os.environ.get("USER", ""),
            "token": os.environ.get(TOKEN_ENV) or None}


def cmd_connect(args: argparse.Namespace) -> int:
    from liansuo.kit.arguments import unwritable
    from liansuo.remote.link import LinkError, ServerLink, Unlinked, lobby
    from liansuo.server.tls import TLSError, client_context
    from liansuo.tui.cli import run_logged

    try:
        greeting = hello(args)
        if not args.connect.startswith(("ws://", "wss://")):
            raise LoginError(f"--connect takes a websocket address, ws://HOST:PORT or wss://HOST:PORT, not "
                             f"{args.connect!r}")
        tls = client_context(args.connect, args.cafile)
        if args.log and (why := unwritable(Path(args.log), "--log")):
            raise LoginError(why)
    except (LoginError, TLSError) as exc:
        return refuse("tui", str(exc), Exit.USAGE)
    try:
        link: ServerLink | Unlinked = Unlinked(args.connect, lobby(args.connect, tls=tls), tls) if greeting is None \
            else ServerLink(args.connect, greeting, tls=tls)
    except LinkError as exc:
        return refuse("tui", str(exc), Exit.USAGE)
    from liansuo.remote.app import RemoteConsoleApp

    app = RemoteConsoleApp(link, mute=args.mute)
    try:
        return run_logged(app, "tui", args.log)
    finally:
        link.close()
