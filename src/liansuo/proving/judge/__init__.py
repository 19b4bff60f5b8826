"""The reference judge of commands and releases (:mod:`.judge`), and the published rules' numbers it and
``liansuo verify`` expect (:mod:`.rules`). Apart from the interlocking: it reads the rule set's data, the station file
and what an observer of the console sees; apart from the oracle: it judges what the oracle has no view of."""

from liansuo.proving.judge.judge import Judge

__all__ = ["Judge"]
