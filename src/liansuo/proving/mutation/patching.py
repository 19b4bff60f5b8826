"""How a seeded defect changes the interlocking's code for as long as it is applied: a method or function
replaced, or wrapped, on an :class:`~contextlib.ExitStack` that puts it back."""

from __future__ import annotations

from collections.abc import Callable
from contextlib import ExitStack
from typing import Any
from unittest import mock


def patch(stack: ExitStack, owner: object, attr: str, new: Any) -> None:
    stack.enter_context(mock.patch.object(owner, attr, new))


def wrap(stack: ExitStack, owner: object, attr: str, make: Callable[[Any], Any]) -> None:
    patch(stack, owner, attr, make(getattr(owner, attr)))


def patched_during(stack: ExitStack, owner: object, method: str, target: Callable[[Any], object], attr: str,
                    value: Any) -> None:
    """``owner.method`` runs with ``attr`` of ``target(self)`` replaced by ``value``: a check it asks left out."""
    def make(real: Any) -> Any:
        def careless(self: Any, *args: Any) -> Any:
            with mock.patch.object(target(self), attr, value):
                return real(self, *args)
        return careless
    wrap(stack, owner, method, make)
