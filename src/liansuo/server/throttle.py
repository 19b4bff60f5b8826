"""How fast one connection's messages are read: a token bucket per connection (docs/classroom.md, "Limits").

A message past the bucket waits for its token before it is read, so one client's flood costs the class nothing: its
messages wait in the websocket's bounded queue and then in the kernel's buffers, which fill up and stop the flooding
client's sends (back-pressure). Nothing is queued on the server beyond those bounds, and every message still gets its
reply, later."""

from __future__ import annotations

RATE = 50.0  # messages a second, per connection, read on
BURST = 100.0  # messages a connection may send at once before it waits


class TokenBucket:
    """``rate`` tokens a second, at most ``burst`` kept; a message takes one. The clock is the caller's."""

    def __init__(self, now: float, rate: float = RATE, burst: float = BURST) -> None:
        if rate <= 0 or burst < 1:
            raise ValueError(f"a rate above 0 and a burst of at least 1, not {rate:g} and {burst:g}")
        self.rate, self.burst = rate, burst
        self.tokens, self.at = burst, now

    def take(self, now: float) -> float:
        """Take a token: 0.0 when there was one, else the seconds to wait for it (it is taken all the same, so the
        waits of messages that come on queue up behind each other)."""
        self.tokens = min(self.burst, self.tokens + (now - self.at) * self.rate)
        self.at = now
        self.tokens -= 1.0
        return 0.0 if self.tokens >= 0 else -self.tokens / self.rate
