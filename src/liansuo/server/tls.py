"""TLS for the classroom (docs/classroom.md, "A secure setup for a LAN"): the server's certificate
(``liansuo serve --certfile F --keyfile F``: wss:// for the clients, https:// for the browsers) and the clients' trust
in it (``--cafile F``: a school's own CA, or the server's self-signed certificate itself).

A client always verifies the server's certificate and its name: against the system's CAs, or against ``--cafile``
alone. A certificate given as ``--cafile`` is trusted as it is, a CA's or the server's own (a partial chain).
"""

from __future__ import annotations

import ssl

from websockets.exceptions import InvalidMessage


class TLSError(ValueError):
    """A certificate, key or CA file that cannot be used; the message names the file and says why."""


def server_context(certfile: str, keyfile: str) -> ssl.SSLContext:
    """What the server presents: ``certfile`` (PEM, the certificate, then any intermediate CA's) and its key."""
    ctx = ssl.create_default_context(ssl.Purpose.CLIENT_AUTH)
    ctx.minimum_version = ssl.TLSVersion.TLSv1_2
    try:
        ctx.load_cert_chain(certfile, keyfile)
    except FileNotFoundError as exc:
        raise TLSError(f"{exc.filename or certfile}: no such file") from None
    except OSError as exc:
        if isinstance(exc, ssl.SSLError):
            raise TLSError(f"--certfile {certfile} and --keyfile {keyfile} are not a PEM certificate and its private "
                           f"key ({exc.reason or exc}): see 'liansuo docs classroom', \"A secure setup for a LAN\"") \
                from None
        raise TLSError(f"cannot read {exc.filename or certfile}: {exc.strerror or exc}") from None
    return ctx


def client_context(url: str, cafile: str | None) -> ssl.SSLContext | None:
    """How a client reaches ``url``: None for ws:// (no TLS); for wss:// a context that verifies the server against
    ``cafile`` (or, without one, the system's CAs)."""
    if not url.startswith("wss://"):
        if cafile is not None:
            raise TLSError(f"--cafile is for a server with TLS: connect to wss://..., not {url}")
        return None
    if cafile is None:
        return ssl.create_default_context()
    try:
        ctx = ssl.create_default_context(cafile=cafile)
    except FileNotFoundError:
        raise TLSError(f"--cafile {cafile}: no such file") from None
    except ssl.SSLError as exc:
        raise TLSError(f"--cafile {cafile}: no PEM certificate in it ({exc.reason or exc})") from None
    except OSError as exc:
        raise TLSError(f"--cafile {cafile}: cannot read it ({exc.strerror or exc})") from None
    ctx.verify_flags |= ssl.VERIFY_X509_PARTIAL_CHAIN  # the server's own certificate may be the one trusted
    return ctx


def hint(url: str, exc: BaseException) -> str:
    """What to do about a connection to ``url`` that failed with ``exc`` for TLS's sake ('' when not)."""
    if isinstance(exc, ssl.SSLCertVerificationError):
        name = ", and connect to the name the certificate is for" if "mismatch" in str(exc) else ""
        return (f" (the server's certificate is not trusted here: give --cafile with the school's CA or the server's "
                f"certificate{name})")
    if url.startswith("wss://") and isinstance(exc, ssl.SSLError):
        return f" (is the server without TLS? then connect to ws://{url.removeprefix('wss://')})"
    if url.startswith("ws://") and isinstance(exc, InvalidMessage):
        return f" (does the server use TLS, liansuo serve --certfile? then connect to wss://{url.removeprefix('ws://')})"
    return ""
