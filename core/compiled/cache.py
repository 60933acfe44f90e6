r"""numba's disk cache keyed on every compiled source of mbsuite, not only on a function's own file.

numba stores a compiled function in ``__pycache__`` (``*.nbi`` index, ``*.nbc`` code) and reuses it
while the *function's own file* is unchanged: its index holds a hash of that file's contents.  The
machine code of a compiled function also contains every compiled function it calls from other
modules (numba links the callees' code into the caller's library).  Edit a helper in
:mod:`core.compiled.vector` and every kernel of :mod:`core.compiled.elements` that calls it keeps
running the old helper from the cache, with no sign of it; the same holds for the integrators in
:mod:`core.integrators` and everything they call in :mod:`core.compiled.dynamics`.

:class:`ProjectCacheLocator` closes that trap: for a function defined in mbsuite's packages, the
source stamp that numba compares is the pair (hash of the function's own file, :func:`source_digest`),
the latter a SHA-256 over the contents of every source file of the packages that holds compiled
code (a file that mentions ``numba`` or a kernel).  A change in any such file invalidates every
cached function of mbsuite, so a changed kernel can never run old code; the price is that an edit
recompiles everything once.  Functions of other packages (a user's own kernels) keep numba's own
locators.  Where the cache goes is numba's choice unchanged: ``NUMBA_CACHE_DIR`` if set, else
``__pycache__`` next to the source.

:func:`install` puts the locator first in numba's list; it must run before a module decorates its
functions (numba picks the locator when the decorator runs), so :mod:`core.compiled` calls it
before importing its submodules, and every other module of mbsuite with cached compiled functions
imports :mod:`core.compiled` first.
"""

from __future__ import annotations

import hashlib
import os
import sys
from functools import lru_cache
from pathlib import Path

from numba.core import caching, config

__all__ = ["PACKAGES", "ProjectCacheLocator", "compiled_sources", "install", "is_cold", "notify_if_cold",
           "source_digest"]

#: The project's packages, relative to the repository root.
PACKAGES = ("core", "railway", "coaster", "biomech")

_ROOT = Path(__file__).resolve().parents[2]
_MARKERS = (b"numba", b"kernel")


def _in_project(path: str) -> bool:
    try:
        rel = Path(path).resolve().relative_to(_ROOT)
    except ValueError:
        return False
    return len(rel.parts) > 1 and rel.parts[0] in PACKAGES


@lru_cache(maxsize=1)
def compiled_sources() -> tuple[Path, ...]:
    """The project's source files that hold compiled code or kernels, sorted."""
    out = []
    for pkg in PACKAGES:
        for p in sorted((_ROOT / pkg).rglob("*.py")):
            if "__pycache__" in p.parts:
                continue
            text = p.read_bytes()
            if any(m in text for m in _MARKERS):
                out.append(p)
    return tuple(out)


def source_digest(paths=None) -> str:
    """SHA-256 over the relative paths and contents of ``paths`` (default :func:`compiled_sources`),
    read now: it changes with any edit of any of them."""
    h = hashlib.sha256()
    for p in compiled_sources() if paths is None else paths:
        p = Path(p)
        try:
            rel = p.resolve().relative_to(_ROOT).as_posix()
        except ValueError:
            rel = p.name
        h.update(rel.encode())
        h.update(b"\0")
        h.update(p.read_bytes())
        h.update(b"\0")
    return h.hexdigest()


@lru_cache(maxsize=1)
def _process_digest() -> str:
    # once per process: a source edited while a process runs is not recompiled by it anyway
    return source_digest()


class ProjectCacheLocator(caching._SourceFileBackedLocatorMixin, caching._CacheLocator):
    """numba cache locator for mbsuite's functions: numba's place, mbsuite's source stamp."""

    def __init__(self, py_func, py_file):
        self._py_file = py_file
        self._lineno = py_func.__code__.co_firstlineno
        if config.CACHE_DIR:
            self._cache_path = os.path.join(config.CACHE_DIR, self.get_suitable_cache_subpath(py_file))
        else:
            self._cache_path = os.path.join(os.path.dirname(py_file), "__pycache__")

    def get_cache_path(self):
        return self._cache_path

    def get_source_stamp(self):
        return (super().get_source_stamp(), _process_digest())

    @classmethod
    def from_function(cls, py_func, py_file):
        if not _in_project(py_file):
            return None
        return super().from_function(py_func, py_file)


def install() -> None:
    """Put :class:`ProjectCacheLocator` first in numba's locators (idempotent)."""
    classes = caching.CacheImpl._locator_classes
    if ProjectCacheLocator not in classes:
        classes.insert(0, ProjectCacheLocator)


def is_cold(dispatcher) -> bool:
    """True when numba's disk cache holds no code of ``dispatcher`` for the current sources (a
    first run will compile it); False when it does, or when that cannot be told."""
    try:
        return not dispatcher._cache._cache_file._load_index()
    except Exception:  # numba's private cache API changed: say nothing rather than guess
        return False


_NOTIFIED: set[str] = set()


def notify_if_cold(dispatcher, method: str, seconds: str, stream=None) -> bool:
    """Tell a person at a terminal that ``method`` is about to compile (once per process and
    method), so that a first run is not mistaken for a hang; returns whether it told.

    Printed to ``stream`` (default standard error) only when that is a terminal: logs, CI and
    tests stay clean.  ``seconds`` is the measured compile time quoted (e.g. "about 20 s").
    """
    stream = sys.stderr if stream is None else stream
    if method in _NOTIFIED or not is_cold(dispatcher):
        return False
    _NOTIFIED.add(method)
    if not getattr(stream, "isatty", lambda: False)():
        return False
    print(f"mbsuite: compiling the {method} integrator with numba for this machine and these sources "
          f"({seconds} on 2 cores; kept in numba's disk cache, later runs start in under a second)",
          file=stream, flush=True)
    return True
