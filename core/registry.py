"""Name → object registries with one rule for a taken name.

Integrators (:data:`core.integrators.METHODS`), scenes, work-precision problems and the railway
creep laws are all looked up by name.  Each is a :class:`Registry`, so they share one behaviour:

* registering an object under a free name adds it;
* registering the *same* object again is a no-op (modules may be imported twice);
* registering a *different* object under a taken name raises :class:`core.errors.NameTakenError`
  naming both, unless ``replace=True`` is passed;
* looking up a missing name raises :class:`core.errors.UnknownNameError` listing the names that
  exist.

Insertion order is listing order.  A registry is a read-only mapping for callers (``in``, ``[]``,
iteration, ``len``, ``items()``); only :meth:`Registry.register` and :meth:`Registry.unregister`
change it.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator, Mapping
from typing import Generic, TypeVar

from .errors import NameTakenError, UnknownNameError

T = TypeVar("T")

__all__ = ["Registry"]


class Registry(Mapping[str, T], Generic[T]):
    """An ordered name → object registry (see the module docstring).

    Parameters
    ----------
    kind : str
        What is registered, for messages (``"integrator"``, ``"scene"``, ...).
    check : callable, optional
        ``check(obj)`` raises ``TypeError`` when ``obj`` cannot be registered here.
    """

    def __init__(self, kind: str, check: Callable[[object], None] | None = None):
        self.kind = kind
        self._check = check
        self._items: dict[str, T] = {}

    def register(self, name: str, obj: T, *, replace: bool = False) -> T:
        """Add ``obj`` under ``name`` and return it (see the module docstring for a taken name)."""
        if not isinstance(name, str) or not name:
            raise UnknownNameError(f"{self.kind} name must be a non-empty string, got {name!r}")
        if self._check is not None:
            self._check(obj)
        old = self._items.get(name)
        if old is not None and old is not obj and not replace:
            raise NameTakenError(f"{self.kind} name {name!r} is taken by {_describe(old)}; cannot register "
                                 f"{_describe(obj)} under it (pass replace=True to replace it)")
        self._items[name] = obj
        return obj

    def unregister(self, name: str) -> T:
        """Remove and return the entry ``name``."""
        obj = self[name]
        del self._items[name]
        return obj

    def __getitem__(self, name: str) -> T:
        try:
            return self._items[name]
        except (KeyError, TypeError):
            known = ", ".join(self._items) or "none"
            raise UnknownNameError(f"unknown {self.kind} {name!r}; registered: {known}") from None

    def __iter__(self) -> Iterator[str]:
        return iter(self._items)

    def __len__(self) -> int:
        return len(self._items)

    def __contains__(self, name: object) -> bool:
        return name in self._items

    def __repr__(self) -> str:
        return f"Registry({self.kind!r}, {list(self._items)})"


def _describe(obj: object) -> str:
    qual = getattr(obj, "__qualname__", None)
    if qual is not None:
        return f"{getattr(obj, '__module__', '?')}.{qual}"
    name = getattr(obj, "name", None)
    return f"{type(obj).__name__} {name!r}" if name is not None else repr(obj)
