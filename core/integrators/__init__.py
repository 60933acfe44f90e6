"""Integrators: step-based objects behind one registry (see :mod:`core.integrators.base`).

Each family lives in its own module and registers its classes on import.
"""

from .base import METHODS, Integrator, IntegrationFailure, get_method, register, simulate

__all__ = ["METHODS", "Integrator", "IntegrationFailure", "get_method", "register", "simulate"]
