r"""What an element kind supplies to the compiled path: kernels with fixed signatures, and data.

Any element kind — core's or a domain's — joins the compiled path by implementing
``compiled(layout)`` and returning one of the records below (or raising
:class:`core.errors.NotCompilable` naming the element).  A kernel is a Python function in numba's
subset declared with one of the decorators :func:`force_kernel`, :func:`constraint_kernel`,
:func:`force_jacobian_kernel`, :func:`accept_kernel`, which fix its signature; it is compiled on
first use and cached on disk by numba.  The compiled
integrators call every kind's kernel through a function pointer, so a new kind needs no branch
anywhere in core and core's compiled code is compiled once, whatever kinds a model holds.

Kernel arguments
----------------
Every kernel receives the time ``t``, the full coordinate vectors ``q`` (n_q) and ``v`` (n_v),
the body states of all bodies plus the ground in three-dimensional form

* ``r`` (n_b + 1, 3) positions, ``A`` (n_b + 1, 3, 3) rotation matrices (body → global),
* ``rd`` (n_b + 1, 3) velocities, ``w`` (n_b + 1, 3) body-frame angular velocities,

(planar bodies embedded as rotations about z: ``A = [[c, −s, 0], [s, c, 0], [0, 0, 1]]``,
``ω̄ = (0, 0, θ̇)``; the ground is row ``n_b`` with ``A = I``), the model layout ``lay``
(see :data:`LAYOUT_FIELDS`), the kind's own data ``fd`` (float64, 2-D) and ``ix`` (int64, 2-D) as
returned by its ``compiled()`` (all arrays C-contiguous), and an ``err`` array (int64, 2) in which a failing kernel stores
the index of the element at fault in ``err[1]`` (the caller fills ``err[0]`` with the kind).
Extra coordinates are read from ``q``/``v`` at the indices the kind stored in ``ix``.
Kernels return a status code (:data:`OK` or one of the failure codes below).

=========================  ======================================================================
kernel                     extra arguments and what it does
=========================  ======================================================================
forces                     ``state`` (float64, 2-D, the kind's search state), ``Q`` (n_v):
                           **adds** the generalized forces of all elements of the kind
constraints                ``row0`` (int64: first model row of the kind), ``flags`` (bits
                           :data:`WANT_PHI`, :data:`WANT_NU`, :data:`WANT_GAMMA`; the Jacobian is
                           always written), ``phi``, ``G`` (rows, :data:`MAX_SLOTS`, 6), ``nu``,
                           ``gam``: **writes** the kind's rows
force Jacobian             ``state``, ``K``, ``D`` (n_v, n_v): **adds** ∂Q/∂q along velocity-space
                           increments and ∂Q/∂v (optional; the implicit integrators difference
                           the forces of kinds that do not supply it)
accept                     ``state``: the search-state hook, called after accepted steps only
mass                       ``Mg`` (n_groups, w, w): **writes** the mass matrix of every
                           configuration-dependent mass group of the record (a flexible body
                           with the deformed body's inertia), in the group's velocity order
=========================  ======================================================================

Constraint rows and their Jacobian slots
----------------------------------------
A constraint row touches at most :data:`MAX_SLOTS` *blocks*: a body (``n_v_body`` velocity
coordinates in the model's layout: planar ``(ẋ, ẏ, θ̇)``, spatial ``(ṙ, ω̄)``) or one extra
coordinate (one velocity coordinate).  ``CompiledConstraints.slots`` (rows, MAX_SLOTS) names the
block of each slot — a body index ``0 … n_b − 1``, an extra coordinate ``n_b + 1 + k``, or −1
(unused, or the ground) — and the kernel writes ``G[row, slot, :width]``.  Use
:func:`body_slot` and :func:`extra_slot` to build the array.

Mass groups
-----------
Most blocks have a constant mass block, inverted once when the model is packed.  A *mass group*
(:class:`CompiledMass`) is a set of blocks whose joint mass matrix depends on the configuration —
a flexible body with the inertia of the deformed body couples its frame with its modal
coordinates through :math:`M(q_f)`.  Its mass kernel writes the group's matrix at every
evaluation; the packer gives every constraint row that touches a block of a group a slot on every
block of that group (the added slots' Jacobian entries stay zero), so that ``M⁻¹Φ_qᵀ`` of the row
is complete on the group.  A row then touches at most :data:`MAX_SLOTS` blocks *including* the
added ones.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field

import numba
import numpy as np
from numba import types
from numba.core.errors import NumbaExperimentalFeatureWarning

__all__ = [
    "OK", "SINGULAR", "COINCIDENT", "NONFINITE", "PROJECTION", "OUT_OF_RANGE", "ELEMENT_FAILED", "MASS_NOT_PD",
    "STATUS_MESSAGES", "WANT_PHI", "WANT_NU", "WANT_GAMMA", "WANT_ALL", "MAX_SLOTS", "LAYOUT_FIELDS",
    "L_NB", "L_DIM", "L_NQB", "L_NVB", "L_NQ", "L_NV", "L_NX",
    "FRC_TAB_FIELDS", "FRC_TAB_WIDTH", "FT_FD0", "FT_FD1", "FT_N", "FT_FW", "FT_IX0", "FT_IX1", "FT_IW", "FT_ST0",
    "FT_ST1", "FT_STN", "FT_STW",
    "FORCE_SIGNATURE", "CONSTRAINT_SIGNATURE", "FORCE_JACOBIAN_SIGNATURE", "ACCEPT_SIGNATURE", "MASS_SIGNATURE",
    "Kernel", "force_kernel", "constraint_kernel", "force_jacobian_kernel", "accept_kernel", "mass_kernel",
    "resolve_kernel", "CompiledForces", "CompiledConstraints", "CompiledMass", "body_slot", "extra_slot",
]

# Calling kernels through numba's first-class function type is marked experimental by numba; its
# behaviour is covered by the tests of the compiled path, so the warning is not repeated per call.
warnings.filterwarnings("ignore", category=NumbaExperimentalFeatureWarning,
                        message=".*[Ff]irst-class function type.*")

# --- status codes ---------------------------------------------------------------------------------
OK, SINGULAR, COINCIDENT, NONFINITE, PROJECTION, OUT_OF_RANGE, ELEMENT_FAILED, MASS_NOT_PD = 0, 1, 2, 3, 4, 5, 6, 7
STATUS_MESSAGES = {
    SINGULAR: "the constraint Schur complement Φ_q M⁻¹ Φ_qᵀ is not positive definite "
              "(dependent constraints or a singular configuration)",
    COINCIDENT: "the attachment points of a spring-damper coincide (direction undefined)",
    NONFINITE: "non-finite value in the right-hand side",
    PROJECTION: "coordinate projection did not converge",
    OUT_OF_RANGE: "time outside the range of a tabulated function",
    ELEMENT_FAILED: "an element could not be evaluated",
    MASS_NOT_PD: "the mass matrix of a body whose inertia follows its deformation is not positive definite "
                 "(a deformation far beyond the range of its modes, or non-finite modal coordinates)",
}

# --- constraint kernel flags ---------------------------------------------------------------------
WANT_PHI, WANT_NU, WANT_GAMMA = 1, 2, 4
WANT_ALL = WANT_PHI | WANT_NU | WANT_GAMMA

#: Blocks a constraint row may touch: two bodies and one extra coordinate (a path joint), or a
#: flexible body's node frame — the frame, the node body and up to six modes
#: (:mod:`core.flexible.compiled`).  Rows fill the slots they use; unused slots (−1) cost a skipped
#: test in the loops over slots.  The compiled functions read it when they are compiled: a change
#: must come with a change of every file whose jitted code loops over it (numba keys its disk cache
#: on the function's own file).
MAX_SLOTS = 8

#: Entries of the layout array ``lay`` passed to every kernel.
LAYOUT_FIELDS = ("n_bodies", "dim", "n_q_body", "n_v_body", "n_q", "n_v", "n_extra")
L_NB, L_DIM, L_NQB, L_NVB, L_NQ, L_NV, L_NX = range(len(LAYOUT_FIELDS))

#: Columns of the force kinds' table ``frc_tab`` of the compiled model (one row per kind): the
#: kind's data ``frc_fd[FD0:FD1].reshape(N, FW)``, indices ``frc_ix[IX0:IX1].reshape(N, IW)`` and
#: search state ``states[ST0:ST1].reshape(STN, STW)`` (:mod:`core.compiled.layout`).
FRC_TAB_FIELDS = ("fd0", "fd1", "n", "fw", "ix0", "ix1", "iw", "st0", "st1", "st_n", "st_w")
FT_FD0, FT_FD1, FT_N, FT_FW, FT_IX0, FT_IX1, FT_IW, FT_ST0, FT_ST1, FT_STN, FT_STW = range(len(FRC_TAB_FIELDS))
FRC_TAB_WIDTH = len(FRC_TAB_FIELDS)

_f8, _i8 = types.float64, types.int64
# C-contiguous arrays throughout: the compiler then knows the unit inner stride
_v = types.float64[::1]
_m2 = types.float64[:, ::1]
_m3 = types.float64[:, :, ::1]
_iv = types.int64[::1]
_im2 = types.int64[:, ::1]
_common = (_f8, _v, _v, _m2, _m3, _m2, _m2, _iv, _m2, _im2)

#: ``(t, q, v, r, A, rd, w, lay, fd, ix, state, Q, err) -> status``
FORCE_SIGNATURE = _i8(*_common, _m2, _v, _iv)
#: ``(t, q, v, r, A, rd, w, lay, fd, ix, row0, flags, phi, G, nu, gam, err) -> status``
CONSTRAINT_SIGNATURE = _i8(*_common, _i8, _i8, _v, _m3, _v, _v, _iv)
#: ``(t, q, v, r, A, rd, w, lay, fd, ix, state, K, D, err) -> status``
FORCE_JACOBIAN_SIGNATURE = _i8(*_common, _m2, _m2, _m2, _iv)
#: ``(t, q, v, r, A, rd, w, lay, fd, ix, state, err) -> status``
ACCEPT_SIGNATURE = _i8(*_common, _m2, _iv)
#: ``(t, q, v, r, A, rd, w, lay, fd, ix, Mg, err) -> status``
MASS_SIGNATURE = _i8(*_common, _m3, _iv)

_JIT = dict(cache=True, fastmath=False, boundscheck=False, nogil=True)


class Kernel:
    """A kernel function with its fixed signature, compiled (or loaded from numba's on-disk cache)
    on first use, so that importing a module of kernels costs nothing.

    ``kernel.dispatcher`` is the numba function (compiled for exactly ``signature``); calling the
    object calls it.
    """

    def __init__(self, fn, signature, role: str):
        self.py_func = fn
        self.signature = signature
        self.role = role
        self._dispatcher = None
        self.__name__ = getattr(fn, "__name__", "kernel")
        self.__qualname__ = getattr(fn, "__qualname__", self.__name__)
        self.__module__ = getattr(fn, "__module__", None)
        self.__doc__ = getattr(fn, "__doc__", None)

    @property
    def dispatcher(self):
        if self._dispatcher is None:
            self._dispatcher = numba.njit(self.signature, **_JIT)(self.py_func)
        return self._dispatcher

    def __call__(self, *args):
        return self.dispatcher(*args)

    def __repr__(self) -> str:
        return f"<{self.role} kernel {self.__module__}.{self.__qualname__}>"


def force_kernel(fn) -> Kernel:
    """Declare ``fn`` a force kernel (:data:`FORCE_SIGNATURE`; compiled on first use, cached on disk)."""
    return Kernel(fn, FORCE_SIGNATURE, "force")


def constraint_kernel(fn) -> Kernel:
    """Declare ``fn`` a constraint kernel (:data:`CONSTRAINT_SIGNATURE`)."""
    return Kernel(fn, CONSTRAINT_SIGNATURE, "constraint")


def force_jacobian_kernel(fn) -> Kernel:
    """Declare ``fn`` a force-Jacobian kernel (:data:`FORCE_JACOBIAN_SIGNATURE`)."""
    return Kernel(fn, FORCE_JACOBIAN_SIGNATURE, "force Jacobian")


def accept_kernel(fn) -> Kernel:
    """Declare ``fn`` a search-state kernel (:data:`ACCEPT_SIGNATURE`)."""
    return Kernel(fn, ACCEPT_SIGNATURE, "accept")


def mass_kernel(fn) -> Kernel:
    """Declare ``fn`` a mass kernel (:data:`MASS_SIGNATURE`)."""
    return Kernel(fn, MASS_SIGNATURE, "mass")


def resolve_kernel(k, role: str, signature, owner: str):
    """The numba function of a :class:`Kernel` (or of a numba function compiled for ``signature``);
    :class:`core.errors.NotCompilable` naming ``owner`` otherwise."""
    from ..errors import NotCompilable

    if isinstance(k, Kernel):
        if k.signature != signature:
            raise NotCompilable(f"{owner}: {k!r} is declared as a {k.role} kernel, used as a {role} kernel")
        return k.dispatcher
    sigs = getattr(k, "nopython_signatures", None)
    if sigs and len(sigs) == 1 and sigs[0] == signature:
        return k
    raise NotCompilable(f"{owner}: its {role} kernel {k!r} must be declared with core.compiled.{role.replace(' ', '_')}"
                        "_kernel (a fixed signature)")


def _empty2(dtype=float) -> np.ndarray:
    return np.zeros((0, 0), dtype)


@dataclass
class CompiledForces:
    """The compiled form of one force kind.

    Attributes
    ----------
    forces : Kernel (:func:`force_kernel`)
    fd, ix : ndarray, 2-D (float64, int64)
        The kind's data, as the kernels read it.
    names : list of str
        Element names; a kernel's ``err[1]`` indexes this list.
    jacobian : Kernel (:func:`force_jacobian_kernel`), optional
    accept : Kernel (:func:`accept_kernel`), optional
        Search-state update after accepted steps (stateful kinds).
    state : ndarray, 2-D, optional
        Initial search state (copied per integrator run).
    what : str
        Kind description for messages (e.g. ``"point spring"``).
    initial_state : callable, optional
        ``initial_state() -> ndarray`` of ``state``'s shape, called at the start of every run
        after the kind's :meth:`~core.forces.protocol.ForceKind.reset_state` (the state of a
        run's initial conditions, where ``state`` is only that of the model's build).
    describe_failure : callable, optional
        ``describe_failure(state) -> str``: the cause of a failure the kind's kernels reported
        (e.g. which wheel derailed), read from its state block at the failure; appended to the
        run's message.
    groups : list of sequences of int, optional
        Body groups of the kind's coupling, for the difference Jacobian
        (:func:`core.compiled.dynamics.force_jacobian`): the kind's generalized forces on the bodies
        of a group depend on the coordinates and velocities of that group's bodies only (layout
        body indices; the ground index is ignored), and the kind writes no force on a body outside
        every group nor on extra coordinates.  A pair element gives the group of its two bodies;
        the wheel–rail element one group per wheelset.  Columns whose rows do not meet are then
        perturbed together, and the columns of bodies in no group are not perturbed at all
        (Curtis, Powell & Reid 1974).  None: any body's coordinates may act on any force (every
        column perturbed on its own).
    """

    forces: object
    fd: np.ndarray
    ix: np.ndarray
    names: list[str]
    jacobian: object | None = None
    accept: object | None = None
    state: np.ndarray = field(default_factory=_empty2)
    what: str = "force element"
    initial_state: object | None = None
    describe_failure: object | None = None
    groups: list | None = None


@dataclass
class CompiledConstraints:
    """The compiled form of one constraint kind (rows in the model's row order).

    Attributes
    ----------
    kernel : Kernel (:func:`constraint_kernel`)
    fd, ix : ndarray, 2-D (float64, int64)
    rows : int
        Number of model rows the kind writes (from its ``row0``).
    slots : ndarray of int, shape (rows, w), w <= MAX_SLOTS
        Block of each Jacobian slot of each row (see the module docstring); the packer pads
        narrower arrays with −1 (unused) to ``MAX_SLOTS``.
    names : list of str
        Element names; ``err[1]`` indexes this list.
    time_dependent : bool
        The rows depend on time explicitly (ν ≠ 0).
    what : str
    border : bool
        The rows fix massless coordinates (a flexible body's node frames): in a model with
        border coordinates the packer solves them with the border (rows E of
        :mod:`core.compiled.layout`) rather than in the Schur complement, whose rows must stay
        independent as the model moves.
    """

    kernel: object
    fd: np.ndarray
    ix: np.ndarray
    rows: int
    slots: np.ndarray
    names: list[str]
    time_dependent: bool = False
    what: str = "constraint"
    border: bool = False


@dataclass
class CompiledMass:
    """Mass groups whose mass matrix depends on the configuration (see the module docstring).

    Attributes
    ----------
    kernel : Kernel (:func:`mass_kernel`)
        Writes ``Mg[g, :w_g, :w_g]`` of every group ``g`` (symmetric positive definite).
    fd, ix : ndarray, 2-D (float64, int64)
        The kernel's data.
    groups : list of ndarray of int
        Velocity indices of each group, in the order of the rows of its ``Mg`` block; a group
        is made of whole blocks (all coordinates of a body, and extra coordinates).
    names : list of str
        Group names (one per group; a failure names the group).
    what : str
    """

    kernel: object
    fd: np.ndarray
    ix: np.ndarray
    groups: list
    names: list[str]
    what: str = "mass group"


def body_slot(b: int, n_bodies: int) -> int:
    """Slot block of body ``b`` (−1 for the ground, index ``n_bodies``)."""
    return -1 if b >= n_bodies else int(b)


def extra_slot(k: int, n_bodies: int) -> int:
    """Slot block of the model's extra coordinate ``k`` (0 for the first one added)."""
    return n_bodies + 1 + int(k)
