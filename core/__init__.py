"""Cartesian multibody dynamics engine of mbsuite.

``core`` holds everything that is not specific to one application domain: the
model builder and the frozen model (bodies, joints, force elements, drivers), the
constrained-system protocol (``M``, ``Q``, ``Phi``, ``Phi_q``, ``nu``, ``gamma``),
integrators and analyses, result tables, plots, parameter sweeps, scenes and the
``mbsuite`` command-line tool.

One-way rule: ``core`` never imports ``railway``, ``biomech`` or ``coaster``; the
domain packages build on ``core`` (``from core import ModelBuilder``) and never on
each other. ``tests/core/test_architecture.py`` enforces this.

Public names are re-exported lazily: ``import core`` imports no submodule, and
``core.ModelBuilder`` imports :mod:`core.model` on first access. A name whose
submodule does not exist (yet) raises :class:`AttributeError` on access instead
of breaking ``import core``.
"""

from __future__ import annotations

import importlib
import importlib.util

__version__ = "0.1.0"

#: Public name -> submodule of ``core`` that defines it.
_EXPORTS: dict[str, str] = {
    "ModelBuilder": "model",
    "Model": "model",
    "ConstrainedSystem": "system",
    "simulate": "simulation",
    "SimulationResult": "results",
    "write_table": "results",
}

__all__ = ["__version__", *sorted(_EXPORTS)]


def __getattr__(name: str):
    """Import the submodule that defines ``name`` on first access (PEP 562)."""
    try:
        submodule = _EXPORTS[name]
    except KeyError:
        raise AttributeError(f"module 'core' has no attribute {name!r}") from None
    full_name = f"{__name__}.{submodule}"
    if importlib.util.find_spec(full_name) is None:
        raise AttributeError(
            f"core.{name} is provided by {full_name}, which does not exist in this checkout"
        )
    # A submodule that exists but fails to import is a real error: let it propagate.
    value = getattr(importlib.import_module(full_name), name)
    globals()[name] = value  # cache: later lookups bypass __getattr__
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_EXPORTS))
