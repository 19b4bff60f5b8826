"""The instructor's password, checked the one way the classroom server and the browsers' login page both check it:
scrypt on a thread of its own (the event loop, and every seat's class, go on meanwhile), one check at a time, at
most :data:`MAX_CHECKS` waiting, and the lockout per address of :class:`.LoginGuard`."""

from __future__ import annotations

import asyncio
import time
from concurrent.futures import ThreadPoolExecutor

from liansuo.classroom.passwords import matches
from liansuo.server.lockout import LoginGuard

MAX_CHECKS = 16  # instructor password checks waiting or running at once, from every address together


class PasswordCheck:
    """Checks against ``instructor_hash``, with ``guard``'s lockout, on a thread named ``thread``."""

    def __init__(self, instructor_hash: str, guard: LoginGuard, thread: str) -> None:
        self.instructor_hash = instructor_hash
        self.guard = guard
        self._checks = 0  # waiting or running
        self._thread = thread
        self._hasher: ThreadPoolExecutor | None = None  # started at the first check, again after close()

    async def refusal(self, password: str | None, address: str) -> str | None:
        """None when ``password`` is the instructor's and ``address`` may try one now; otherwise what to tell it."""
        if self._checks >= MAX_CHECKS:
            return "the server is busy checking instructor passwords: try again in a few seconds"
        no = self.guard.begin(address, time.monotonic())
        if no is not None:
            return no
        self._checks += 1
        if self._hasher is None:
            self._hasher = ThreadPoolExecutor(1, thread_name_prefix=self._thread)
        ok = False
        try:
            if password is not None:
                ok = await asyncio.get_running_loop().run_in_executor(self._hasher, matches, password,
                                                                      self.instructor_hash)
        finally:
            self._checks -= 1
            locked = self.guard.end(address, ok, time.monotonic())
        return None if ok else f"wrong instructor password{f': {locked}' if locked else ''}"

    def close(self) -> None:
        if self._hasher is not None:
            self._hasher.shutdown(wait=False, cancel_futures=True)
            self._hasher = None
