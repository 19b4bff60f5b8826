"""The instructor's password (教员口令), for the classroom server and the console's instructor mode: read from a file
or the environment, never the command line (``ps`` shows that), and kept only as a salted scrypt hash, in memory and
in the file (``liansuo serve --hash-password`` writes one)."""

from __future__ import annotations

import hashlib
import hmac
import os
import secrets
from pathlib import Path

ENV = "LIANSUO_INSTRUCTOR_PASSWORD"
TOKEN_ENV = "LIANSUO_SEAT_TOKEN"  # a seat's token, to take it back (a browser's console is started with it)
CHANGEOVER_ENV = "LIANSUO_CHANGEOVER_PASSWORD"  # QHA, the change-over to field control (docs/field-mode.md)
N, R, P = 2**14, 8, 1  # scrypt's cost: about 20 ms and 16 MB a check


class PasswordError(ValueError):
    """No usable password: the message says where one is looked for."""


def hash_password(password: str, salt: bytes | None = None) -> str:
    salt = salt if salt is not None else secrets.token_bytes(16)
    digest = hashlib.scrypt(password.encode(), salt=salt, n=N, r=R, p=P)
    return f"scrypt${N}${R}${P}${salt.hex()}${digest.hex()}"


def matches(password: str, stored: str) -> bool:
    """Whether ``password`` is the one ``stored`` (a hash from :func:`hash_password`) was made from."""
    try:
        kind, n, r, p, salt, digest = stored.split("$")
        if kind != "scrypt":
            return False
        got = hashlib.scrypt(password.encode(), salt=bytes.fromhex(salt), n=int(n), r=int(r), p=int(p))
    except (ValueError, MemoryError):
        return False
    return hmac.compare_digest(got.hex(), digest)


def instructor_hash(file: str | Path | None, *, whose: str = "instructor", env: str = ENV,
                    option: str = "--password-file") -> str:
    """The stored hash: the file's first line (a hash; a line that is not one is taken as a password and hashed
    here), else the environment variable ``env``, hashed at once. ``whose`` and ``option`` name the password in the
    messages (the change-over's, QHA's, is another: docs/field-mode.md)."""
    if file is not None:
        path = Path(file)
        try:
            line = path.read_text(encoding="utf-8").strip().splitlines()[0].strip()
        except (OSError, UnicodeDecodeError, IndexError) as exc:
            raise PasswordError(f"{path}: cannot read the {whose}'s password ({exc or 'the file is empty'}); "
                                f"write one with: liansuo serve --hash-password > {path}") from None
        return line if line.startswith("scrypt$") else hash_password(line)
    plain = os.environ.get(env)
    if not plain:
        raise PasswordError(f"no {whose} password: give {option} FILE (liansuo serve --hash-password "
                            f"writes one) or set {env}")
    return hash_password(plain)
