"""``liansuo explore``: every sequence of operator commands, field events and time up to a depth, each state once,
judged by the independent safety oracle at every cycle (docs/explore.md).

- :mod:`.snapshot` takes a watched simulation's state and puts it back, to branch from one state many times;
- :mod:`.key` writes a state out as its canonical key (two states with the same key behave the same);
- :mod:`.actions` says what can happen next, within the model's bounds, with each action's footprint;
- :mod:`.search` explores breadth first, in this process or on Dask, with the partial-order reduction;
- :mod:`.report` turns what it found into shortest reproducer scripts and a report; :mod:`.cli` is the command.
"""

from liansuo.proving.explore.actions import Bounds
from liansuo.proving.explore.search import Expander, SearchOutcome, expand_here, search

__all__ = ["Bounds", "Expander", "SearchOutcome", "expand_here", "search"]
