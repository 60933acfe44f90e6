"""Old module paths of the railway package, kept working after the split into sub-packages.

Issue 22 split ``railway/`` into :mod:`railway.contact` (contact mechanics),
:mod:`railway.vehicles` (vehicle dynamics) and :mod:`railway.cli`.  Every module that moved is
one row of :data:`MOVED`.  Importing an old path (``import railway.profiles``, ``from
railway.contact_search import ContactSearch``, a relative ``from .vehicle import build_vehicle``
inside the package) gives the *same module object* as the new path -- registered in
``sys.modules`` under both names, so that monkeypatching, ``isinstance`` and numba's caches see
one module -- and emits a :class:`DeprecationWarning` naming the new place, attributed to the
line that imported it::

    DeprecationWarning: railway.profiles moved to railway.contact.profiles

A name that is neither in the table nor a real module still raises ``ModuleNotFoundError``.

The mechanism is one meta-path finder (:class:`MovedModuleFinder`, PEP 451), installed by
``railway/__init__.py``; it answers only for the old names of the table and loads nothing
itself: the module is imported under its new name and the old name made an alias of it.
"""

from __future__ import annotations

import importlib
import importlib.abc
import importlib.util
import sys
import warnings

__all__ = ["MOVED", "MovedModuleFinder", "install", "old_module_attribute"]

#: old module name -> new module name
MOVED = {
    # contact mechanics: railway/contact/
    "railway.profiles": "railway.contact.profiles",
    "railway.surfaces": "railway.contact.surfaces",
    "railway.contact_search": "railway.contact.search",
    "railway._kernels": "railway.contact.search.kernels",
    "railway.contact_geometry": "railway.contact.geometry",
    "railway.two_point": "railway.contact.two_point",
    "railway.creep": "railway.contact.creep",
    "railway.creepage": "railway.contact.creepage",
    "railway.creep_curve": "railway.contact.creep_curve",
    "railway.forces": "railway.contact.forces",
    "railway.quasi_static": "railway.contact.quasi_static",
    "railway.manchester_contact": "railway.contact.manchester_contact",
    # vehicle dynamics: railway/vehicles/
    "railway.vehicle": "railway.vehicles.vehicle",
    "railway.vehicle_file": "railway.vehicles.vehicle_file",
    "railway.wheel_rail": "railway.vehicles.wheel_rail",
    "railway.wheel_rail_compiled": "railway.vehicles.wheel_rail_compiled",
    "railway.traction": "railway.vehicles.traction",
    "railway.hunting": "railway.vehicles.hunting",
    "railway.wheelset_models": "railway.vehicles.wheelset_models",
    "railway.curving_start": "railway.vehicles.curving_start",
    # command line: railway/cli/ (railway.cli itself, with register, kept its name)
    "railway.cli_checks": "railway.cli.checks",
    "railway.cli_creep": "railway.cli.creep_curve",
}


def _importer_frame():
    """The first frame outside the import machinery and this module: the importing line."""
    frame = sys._getframe(1)
    while frame is not None:
        name = frame.f_code.co_filename
        if not (name == __file__ or name.startswith("<frozen importlib") or name == importlib.__file__):
            return frame
        frame = frame.f_back
    return None


class MovedModuleFinder(importlib.abc.MetaPathFinder, importlib.abc.Loader):
    """Resolves an old module name of :data:`MOVED` to the module under its new name."""

    def find_spec(self, fullname, path=None, target=None):
        if fullname not in MOVED:
            return None
        return importlib.util.spec_from_loader(fullname, self)

    def create_module(self, spec):
        new = MOVED[spec.name]
        message = f"{spec.name} moved to {new}"
        frame = _importer_frame()
        if frame is None:  # pragma: no cover - an import always has an importing frame
            warnings.warn(message, DeprecationWarning, stacklevel=2)
        else:
            g = frame.f_globals
            warnings.warn_explicit(message, DeprecationWarning, frame.f_code.co_filename, frame.f_lineno,
                                   module=g.get("__name__", "<unknown>"),
                                   registry=g.setdefault("__warningregistry__", {}), module_globals=g)
        module = importlib.import_module(new)
        spec.loader_state = module.__spec__  # the import machinery sets module.__spec__ = spec
        return module

    def exec_module(self, module):
        # nothing to run: the module was executed under its new name; give it back its own spec
        module.__spec__ = module.__spec__.loader_state


def install() -> None:
    """Put the finder on ``sys.meta_path`` (once)."""
    if not any(isinstance(f, MovedModuleFinder) for f in sys.meta_path):
        sys.meta_path.append(MovedModuleFinder())


def old_module_attribute(name: str):
    """Module ``__getattr__`` of :mod:`railway` for the old sub-module names, so that ``import
    railway; railway.profiles.WheelProfile`` keeps working (with the same warning)."""
    full = f"railway.{name}"
    if full in MOVED:
        return importlib.import_module(full)
    raise AttributeError(f"module 'railway' has no attribute {name!r}")
