r"""The compiled (numba) path: a frozen model's equations evaluated in microseconds.

Why it exists: the vectorised numpy path of :class:`core.model.Model` costs ~100 µs per index-1
right-hand side, almost all of it Python-level call overhead of small numpy operations; Exudyn's
C++ needs a few µs (``benchmarks/peer_chain.py``).  Here the same equations run in compiled loops
over flat arrays fixed at set-up, and the saddle-point system is solved through the Schur
complement with a sparse (envelope) Cholesky factorisation in a bandwidth-reducing order.

How element kinds join it
-------------------------
There is no list of element types in core's compiled code.  Every constraint and force kind
supplies its compiled form through ``compiled(layout)`` — kernels with the fixed signatures of
:mod:`core.compiled.protocol` plus its data arrays — or raises :class:`NotCompilable` naming the
element.  Core's own kinds do so with the kernels of :mod:`core.compiled.elements`; a domain
package writes kernels the same way (the scalar kinematics of :mod:`core.compiled.vector` help)
and its models reach the fast integrators without any branch in core.  Kernels are called through
function pointers, so the compiled code of this package is compiled once (cached on disk) for
every model.

=====================  ========================================================================
module                 contents
=====================  ========================================================================
``protocol``           kernel signatures and decorators, status codes, the records a kind returns
                       (and a mass group: bodies whose mass matrix depends on the configuration)
``vector``             inlined 3-vector kinematics for writing kernels
``timefunctions``      compiled functions of time (ramp, harmonic, polynomial, tabulated spline)
``elements``           kernels of core's joints, drivers and force elements
``layout``             packing a model: blocks, rows, Schur pattern, kernel tuples
``dynamics``           forces, constraints, saddle-point solves, accelerations, projection
``cache``              numba's disk cache keyed on every compiled source of mbsuite
=====================  ========================================================================
"""

from . import cache as _cache

_cache.install()  # before any submodule decorates a cached function (core.compiled.cache)

from ..errors import NotCompilable  # noqa: E402
from .dynamics import Workspace, make_workspace  # noqa: E402
from .layout import KIND_CAPACITY, CompiledModel, Layout, compile_model
from .protocol import (
    ACCEPT_SIGNATURE,
    CONSTRAINT_SIGNATURE,
    FORCE_JACOBIAN_SIGNATURE,
    FORCE_SIGNATURE,
    MASS_SIGNATURE,
    MAX_SLOTS,
    OK,
    STATUS_MESSAGES,
    CompiledConstraints,
    CompiledForces,
    CompiledMass,
    Kernel,
    accept_kernel,
    body_slot,
    constraint_kernel,
    extra_slot,
    force_jacobian_kernel,
    force_kernel,
    mass_kernel,
)

__all__ = [
    "NotCompilable",
    "compile_model",
    "CompiledModel",
    "Layout",
    "Workspace",
    "make_workspace",
    "KIND_CAPACITY",
    "CompiledForces",
    "CompiledConstraints",
    "CompiledMass",
    "Kernel",
    "force_kernel",
    "constraint_kernel",
    "force_jacobian_kernel",
    "accept_kernel",
    "mass_kernel",
    "body_slot",
    "extra_slot",
    "FORCE_SIGNATURE",
    "CONSTRAINT_SIGNATURE",
    "FORCE_JACOBIAN_SIGNATURE",
    "ACCEPT_SIGNATURE",
    "MASS_SIGNATURE",
    "MAX_SLOTS",
    "OK",
    "STATUS_MESSAGES",
]
