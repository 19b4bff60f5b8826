"""The rule set as the interlocking reads it: the national rule sets live in ``liansuo.rules`` (``rules/NAME/``)."""

from __future__ import annotations

from liansuo.rules import RuleSet, load_rules

__all__ = ["RuleSet", "load_rules"]
