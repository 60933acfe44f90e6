"""Integrators: step-based objects behind one registry (see :mod:`core.integrators.base`).

Each family lives in its own module and registers its classes on import.
"""

from .base import METHODS, Integrator, IntegrationFailure, get_method, register, simulate
from . import generalized_alpha, ggl  # noqa: F401
from . import index1, half_explicit  # noqa: F401,E402
from . import compiled_rk  # noqa: F401,E402

__all__ = ["METHODS", "Integrator", "IntegrationFailure", "get_method", "register", "simulate"]
