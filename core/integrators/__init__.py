"""Integrators: step-based objects behind one registry (see :mod:`core.integrators.base`).

Each family lives in its own module and registers its classes on import; importing this package
imports every module of it, so the registry :data:`METHODS` is the same for
:func:`core.simulation.simulate` (re-exported here as ``simulate``), the work-precision harness
and the command line.

======================  ======================================================================
module                  methods
======================  ======================================================================
``index1``              index-1 on scipy's solvers, plain / Baumgarte / projection
``generalized_alpha``   index-3 Lie-group generalized-α and HHT
``ggl``                 GGL index-2 with Radau IIA (numpy)
``half_explicit``       half-explicit HEM3 / HEM4
``compiled_rk``         compiled index-1 RK45 / DOP853 (numba)
``compiled_radau``      compiled GGL index-2 Radau IIA for stiff problems (numba)
======================  ======================================================================
"""

import importlib as _importlib
import pkgutil as _pkgutil

from .base import METHODS, IntegrationFailure, Integrator, get_method, register

for _info in _pkgutil.iter_modules(__path__):
    if not _info.name.startswith("_") and _info.name != "base":
        _importlib.import_module(f"{__name__}.{_info.name}")
del _info

__all__ = ["METHODS", "Integrator", "IntegrationFailure", "get_method", "register", "simulate"]


def __getattr__(name: str):
    # the driver lives in core.simulation, which imports this package: resolve it lazily
    if name == "simulate":
        from ..simulation import simulate

        return simulate
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
