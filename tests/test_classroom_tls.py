"""The classroom over TLS (issue 45, item 8): ``liansuo serve --certfile --keyfile`` in its own process with a
self-signed certificate made here (openssl), clients on wss:// that verify it with ``--cafile``, browsers on https://,
and what a client without TLS, or without the certificate, is told (docs/classroom.md, "A secure setup for a LAN")."""

from __future__ import annotations

import http.client
import shutil
import ssl
import subprocess
import sys
import threading
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from urllib.parse import urlencode, urlsplit

import psutil
import pytest
from websockets.sync.client import connect

from liansuo.classroom.passwords import hash_password
from liansuo.remote.link import LinkError, ServerLink, lobby
from liansuo.server.client import ClassroomClient
from liansuo.server.tls import TLSError, client_context

PASSWORD = "correct horse"
pytestmark = pytest.mark.skipif(shutil.which("openssl") is None, reason="openssl makes the test's certificate")


def certificate(folder: Path, name: str = "cert") -> tuple[Path, Path]:
    """A self-signed certificate for 127.0.0.1 and localhost, and its key."""
    cert, key = folder / f"{name}.pem", folder / f"{name}-key.pem"
    subprocess.run(["openssl", "req", "-x509", "-newkey", "rsa:2048", "-nodes", "-keyout", str(key), "-out",
                    str(cert), "-days", "2", "-subj", "/CN=localhost", "-addext",
                    "subjectAltName=IP:127.0.0.1,DNS:localhost"], check=True, capture_output=True)
    return cert, key


def cli(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "liansuo.cli", *args], capture_output=True, text=True, timeout=60)


class Served:
    def __init__(self, folder: Path, *extra: str) -> None:
        self.cert, key = certificate(folder)
        secret = folder / "instructor.pw"
        secret.write_text(hash_password(PASSWORD) + "\n", encoding="utf-8")
        self.proc = subprocess.Popen([sys.executable, "-m", "liansuo.cli", "serve", "--seats", "2", "--port", "0",
                                      "--password-file", str(secret), "--reports", str(folder / "reports"),
                                      "--certfile", str(self.cert), "--keyfile", str(key), *extra],
                                     stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        assert self.proc.stdout is not None
        line = self.proc.stdout.readline()
        assert "on wss://127.0.0.1:" in line, line + (self.proc.stderr.read() if self.proc.stderr else "")
        self.ws = line.split(" on ")[1].split(",")[0].split()[0]
        self.web = line.split("browsers on ")[1].split()[0] if "browsers on" in line else ""

    def close(self) -> None:
        self.proc.terminate()
        try:
            self.proc.wait(15)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            self.proc.wait(5)


@pytest.fixture
def room(tmp_path: Path) -> Iterator[Served]:
    served = Served(tmp_path)
    try:
        yield served
    finally:
        served.close()


def until(ok: Callable[[], bool], timeout: float = 30.0, what: str = "") -> None:
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        try:
            if ok():
                return
        except (OSError, http.client.HTTPException, LinkError):
            pass
        time.sleep(0.2)
    raise AssertionError(f"not in {timeout:g} s: {what}")


def test_clients_connect_over_wss_and_verify_the_certificate(room: Served, tmp_path: Path) -> None:
    with ClassroomClient.trainee(room.ws, seat=1, name="Li", cafile=str(room.cert)) as li:
        assert li.command("route X XI")["ok"]
    tls = client_context(room.ws, str(room.cert))
    assert [s["taken"] for s in lobby(room.ws, tls=tls)["seats"]] == [True, False]
    link = ServerLink(room.ws, {"role": "instructor", "password": PASSWORD}, tls=tls)
    try:
        assert link.role == "instructor" and link.command("route X XI", seat=2)["ok"]
    finally:
        link.close()
    # without the certificate the client does not trust the server, and says what to do
    with pytest.raises(ssl.SSLCertVerificationError):
        ClassroomClient.trainee(room.ws, seat=2, name="Wang")
    other, _ = certificate(tmp_path, "other")  # another self-signed certificate proves nothing about this server
    with pytest.raises(LinkError, match=r"certificate verify failed.*give --cafile"):
        lobby(room.ws, tls=client_context(room.ws, str(other)))
    done = cli("tui", "--connect", room.ws, "--seat", "2", "--name", "Wang")
    assert done.returncode == 2 and "certificate verify failed" in done.stderr and "--cafile" in done.stderr, \
        done.stderr
    assert done.stderr.count("\n") == 1


def test_a_plain_client_to_a_tls_server_is_told_to_use_wss(room: Served) -> None:
    plain = room.ws.replace("wss://", "ws://")
    done = cli("tui", "--connect", plain, "--seat", "1", "--name", "Li")
    assert done.returncode == 2 and "did not receive a valid HTTP response" in done.stderr, done.stderr
    assert f"then connect to {room.ws}" in done.stderr and done.stderr.count("\n") == 1
    done = cli("tui", "--connect", plain, "--seat", "1", "--cafile", str(room.cert))
    assert done.returncode == 2 and "--cafile is for a server with TLS: connect to wss://" in done.stderr
    # the server carries on for clients that speak TLS
    with ClassroomClient.trainee(room.ws, seat=1, name="Li", cafile=str(room.cert)) as li:
        assert li.welcome["seat"] == 1


def test_a_tls_client_to_a_plain_server_is_told_to_use_ws(tmp_path: Path) -> None:
    secret = tmp_path / "pw"
    secret.write_text(hash_password(PASSWORD) + "\n", encoding="utf-8")
    proc = subprocess.Popen([sys.executable, "-m", "liansuo.cli", "serve", "--port", "0", "--password-file",
                             str(secret)], stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
    try:
        assert proc.stdout is not None
        url = proc.stdout.readline().split(" on ")[1].split()[0].replace("ws://", "wss://")
        with pytest.raises(LinkError, match=r"is the server without TLS\? then connect to ws://"):
            lobby(url)
    finally:
        proc.terminate()
        proc.wait(10)


def test_bad_certificates_and_ca_files_are_refused_with_their_names(tmp_path: Path) -> None:
    cert, key = certificate(tmp_path)
    secret = tmp_path / "pw"
    secret.write_text(hash_password(PASSWORD) + "\n", encoding="utf-8")
    junk = tmp_path / "junk.pem"
    junk.write_text("not a certificate\n", encoding="utf-8")
    for extra, why in ((["--certfile", str(cert)], "TLS needs both --certfile and --keyfile"),
                       (["--certfile", str(tmp_path / "none.pem"), "--keyfile", str(key)], "none.pem: no such file"),
                       (["--certfile", str(junk), "--keyfile", str(key)], "are not a PEM certificate and its private"),
                       (["--certfile", str(cert), "--keyfile", str(cert)], "are not a PEM certificate and its private"),
                       (["--web", "--certfile", str(cert), "--keyfile", str(key), "--public-url", "http://x:8000"],
                        "--public-url is an https:// address (with --certfile)")):
        done = cli("serve", "--port", "0", "--password-file", str(secret), *extra)
        assert done.returncode == 2 and why in done.stderr and done.stderr.count("\n") == 1, (extra, done.stderr)
    for cafile, why in ((tmp_path / "none.pem", "no such file"), (junk, "no PEM certificate in it")):
        with pytest.raises(TLSError, match=why):
            client_context("wss://127.0.0.1:1", str(cafile))
        done = cli("tui", "--connect", "wss://127.0.0.1:1", "--seat", "1", "--cafile", str(cafile))
        assert done.returncode == 2 and why in done.stderr, done.stderr


def test_browsers_get_https_and_their_consoles_wss(tmp_path: Path) -> None:
    room = Served(tmp_path, "--web", "--web-port", "0")
    try:
        assert room.web.startswith("https://127.0.0.1:")
        where = urlsplit(room.web)
        trust = ssl.create_default_context(cafile=str(room.cert))

        def post(path: str, form: dict[str, str]) -> tuple[int, dict[str, str]]:
            conn = http.client.HTTPSConnection(where.hostname or "", where.port, timeout=30, context=trust)
            conn.request("POST", path, body=urlencode(form),
                         headers={"Content-Type": "application/x-www-form-urlencoded"})
            r = conn.getresponse()
            r.read()
            return r.status, {k.lower(): v for k, v in r.getheaders()}

        until(lambda: post("/login", {})[0] == 403, 30, "the browsers' server on https")
        status, headers = post("/login", {"role": "trainee", "name": "Li", "seat": "1"})
        assert status == 303 and "Secure" in headers["set-cookie"], headers
        key = headers["set-cookie"].split("liansuo_session=")[1].split(";")[0]
        conn = http.client.HTTPSConnection(where.hostname or "", where.port, timeout=30, context=trust)
        conn.request("GET", "/console", headers={"Cookie": f"liansuo_session={key}"})
        page = conn.getresponse().read().decode()
        assert f'data-session-websocket-url="wss://127.0.0.1:{where.port}/ws"' in page
        url = room.web.replace("https://", "wss://") + "/ws?width=120&height=40"
        with connect(url, ssl=trust, additional_headers={"Cookie": f"liansuo_session={key}"}) as tab:
            threading.Thread(target=lambda: [None for _ in tab], daemon=True).start()  # the page reads its draws

            def seated() -> bool:
                return bool(lobby(room.ws, tls=client_context(room.ws, str(room.cert)))["seats"][0]["connected"])

            until(seated, 60, "Li's browser console at seat 1, over wss")
            consoles = [p for p in psutil.Process(room.proc.pid).children(recursive=True)
                        if "liansuo.cli" in p.cmdline() and not p.name().endswith("sh")]
            line = consoles[0].cmdline()
            assert line[line.index("--connect") + 1] == room.ws and line[line.index("--cafile") + 1] == str(room.cert)
    finally:
        room.close()
