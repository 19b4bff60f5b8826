"""Who may try the instructor's password, and when: a lockout per address after repeated wrong passwords
(docs/classroom.md, "Limits").

After ``failures`` wrong passwords in a row from one address (the checks under way counted with them, so that many
sent at once are no way round it), the address is locked out for ``lockout_s`` seconds, doubled at each lockout that
follows (at most an hour); the right password, once it may be tried, clears the count. The clock is the caller's.
"""

from __future__ import annotations

from dataclasses import dataclass

FAILURES = 5  # wrong passwords in a row from one address before it is locked out
LOCKOUT_S = 60.0  # the first lockout; each one after it is twice as long
MAX_LOCKOUT_S = 3600.0
MAX_ADDRESSES = 10_000  # addresses remembered; past it, those that are not locked out are forgotten


@dataclass
class _Address:
    failures: int = 0
    checking: int = 0
    lockouts: int = 0
    until: float = 0.0  # locked out until then


class LoginGuard:
    def __init__(self, failures: int = FAILURES, lockout_s: float = LOCKOUT_S) -> None:
        if failures < 1 or lockout_s < 0:
            raise ValueError(f"at least 1 failure and a lockout of 0 s or more, not {failures} and {lockout_s:g}")
        self.failures, self.lockout_s = failures, lockout_s
        self._seen: dict[str, _Address] = {}

    def begin(self, address: str, now: float) -> str | None:
        """A password check from ``address`` may start (None; then call :meth:`end`), or why not."""
        a = self._seen.get(address)
        if a is not None and now < a.until:
            return (f"too many wrong instructor passwords from {address}: locked out, try again in "
                    f"{max(1, round(a.until - now))} s")
        if a is not None and a.failures + a.checking >= self.failures:
            return f"too many instructor logins under way from {address}: try again in a few seconds"
        if a is None:
            if len(self._seen) >= MAX_ADDRESSES:
                self._seen = {k: v for k, v in self._seen.items() if now < v.until or v.checking}
            a = self._seen.setdefault(address, _Address())
        a.checking += 1
        return None

    def end(self, address: str, ok: bool, now: float) -> str:
        """A check from ``address`` ended: '' or, when this wrong password locks the address out, what to say."""
        a = self._seen.setdefault(address, _Address(checking=1))
        a.checking = max(0, a.checking - 1)
        if ok:
            a.failures = a.lockouts = 0
            if not a.checking:
                del self._seen[address]
            return ""
        a.failures += 1
        if a.failures < self.failures:
            return ""
        a.lockouts += 1
        a.failures = 0
        wait = min(MAX_LOCKOUT_S, self.lockout_s * 2 ** min(a.lockouts - 1, 16))
        a.until = now + wait
        return f"{address} is locked out for {wait:g} s after {self.failures} wrong passwords"
