"""One registry mechanism for tasks, skills, predicates, planners, critics, backends, placers,
executors and the object catalog.

A registry maps names to items. Items are added when the module defining them is imported, and
every package imports its built-in modules from its ``__init__``, so importing a package fills its
registry. Adding a name twice raises; an unknown name lists the valid ones.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from typing import Generic, TypeVar

from vcage.errors import RegistryError

T = TypeVar("T")


class Registry(Generic[T]):
    """A named mapping; duplicates raise and unknown names list the valid ones.

    ``error`` is the exception raised for both (a subclass of :class:`RegistryError` or of another
    ``VcageError`` taking one message), so a domain can keep its own error type.
    """

    def __init__(self, kind: str, error: type[Exception] = RegistryError) -> None:
        self.kind = kind
        self.error = error
        self._items: dict[str, T] = {}

    def add(self, name: str, item: T) -> T:
        if name in self._items:
            raise self.error(f"{self.kind} {name!r} is already registered; choose another name")
        self._items[name] = item
        return item

    def register(self, name: str) -> Callable[[T], T]:
        """Decorator form of :meth:`add`."""

        def deco(item: T) -> T:
            return self.add(name, item)

        return deco

    def get(self, name: str) -> T:
        try:
            return self._items[name]
        except (KeyError, TypeError):
            valid = ", ".join(sorted(self._items)) or "(none registered)"
            raise self.error(f"unknown {self.kind} {name!r}; valid names: {valid}") from None

    def names(self) -> list[str]:
        return sorted(self._items)

    def values(self) -> list[T]:
        """The items, in name order."""
        return [self._items[n] for n in self.names()]

    def __contains__(self, name: object) -> bool:
        return name in self._items

    def __iter__(self) -> Iterator[str]:
        return iter(self.names())

    def __len__(self) -> int:
        return len(self._items)
