r"""The force-element protocol: declared elements, compiled kinds, and what a kind returns.

A force element is a frozen dataclass naming its bodies (and, optionally, extra coordinates of
the model) in the initial configuration.  At ``build()`` all elements of one class are compiled by
``compile(elements, ctx)`` into one :class:`ForceKind`, which evaluates every element at once and
returns generalized forces per body block and per extra coordinate.

Generalized forces
------------------
A global force ``F`` at the body-fixed point ``s̄`` of body ``b`` contributes (Nikravesh 1988,
Eq. 6.178)

.. math::

    Q_b = J_P^T F = \begin{bmatrix} F \\ C(\bar s)^T F \end{bmatrix},

i.e. the force and, planar, the moment ``(A R s̄)ᵀF``; spatial, the body-frame moment
``s̄ × (AᵀF)``.  A generalized force ``f_x`` on an extra coordinate ``x`` (e.g. a traction force
along a path parameter) enters ``Q`` at that coordinate's velocity index.

Jacobians for the implicit integrators are blocks ``∂Q_a/∂v_b`` of body pairs along position
increments (``Kq``, stiffness) and along velocities (``Kv``, damping), plus scalar entries for
couplings with extra coordinates (``entries``, in the model's velocity indices).

Search state (the hook for stateful elements)
---------------------------------------------
A kind may keep a *search state* that only speeds up or seeds its evaluation, e.g. the warm
start of a contact search.  The rule that keeps the right-hand side a function of ``(t, q, v)``:

* :meth:`ForceKind.evaluate`, :meth:`ForceKind.jacobian`, :meth:`ForceKind.outputs` read the
  state but never change it;
* the integrators call :meth:`ForceKind.reset_state` once when a run starts and
  :meth:`ForceKind.accept_step` after every *accepted* step, at the step's end state — never
  for rejected attempts, Newton iterates, stage evaluations or dense output.

So within a step (its stages, its Newton iterations, its rejected attempts and the dense output
computed from it) every evaluation at the same ``(t, q, v)`` returns the same force.  Set
``stateful = True`` on such a kind; :class:`core.model.Model` forwards the two calls.

References
----------
P. E. Nikravesh, *Computer-Aided Analysis of Mechanical Systems*, Prentice Hall, 1988.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from ..bodies import BodyStates
from ..errors import ModelError

Array = NDArray[np.float64]
IArray = NDArray[np.int64]

__all__ = [
    "ForceEval",
    "ForceJacobian",
    "ForceElement",
    "ForceKind",
    "nonnegative",
    "per_axis",
    "two_bodies",
]


def _no_index() -> IArray:
    return np.zeros(0, np.int64)


def _no_value() -> Array:
    return np.zeros(0)


@dataclass
class ForceEval:
    """Generalized forces of one kind: ``Q[bodies[k]] += Qb[k]`` and ``Q_x[coords[j]] += Qx[j]``.

    Attributes
    ----------
    bodies : ndarray of int, shape (m,)
        Body indices (the ground index ``n_bodies`` is ignored).
    Qb : ndarray, shape (m, n_v_body)
    coords : ndarray of int, shape (k,)
        Indices into the model's extra coordinates (0 for the first one added).
    Qx : ndarray, shape (k,)
        Generalized forces on those coordinates [N or N m per unit of the coordinate].
    """

    bodies: IArray
    Qb: Array
    coords: IArray = field(default_factory=_no_index)
    Qx: Array = field(default_factory=_no_value)


@dataclass
class ForceJacobian:
    """Jacobian blocks ``∂Q_{rows[k]}/∂v_{cols[k]}``: ``Kq`` (m, n_v, n_v) and ``Kv`` (m, n_v, n_v).

    ``entries`` optionally adds scalar entries ``(i, j, dQ/dq, dQ/dv)`` in the model's velocity
    indices (arrays of equal length), for couplings that involve extra coordinates.
    """

    rows: IArray
    cols: IArray
    Kq: Array
    Kv: Array
    entries: tuple[IArray, IArray, Array, Array] | None = None


class ForceElement:
    """Base class of declared force elements (frozen dataclasses with a ``name``)."""

    name: str

    @classmethod
    def compile(cls, elements: list[ForceElement], ctx) -> ForceKind:  # pragma: no cover - abstract
        """All elements of this class in one model → their :class:`ForceKind`."""
        raise NotImplementedError


class ForceKind:
    """Vectorised evaluator of all elements of one force class (see the module docstring).

    Attributes
    ----------
    names : list of str
        Element names, in evaluation order.
    conservative : bool
        True if the force derives from a potential (no damping, no time dependence).
    stateful : bool
        True if the kind keeps a search state (see the module docstring).
    """

    conservative: bool = False
    stateful: bool = False
    names: list[str]

    def evaluate(self, bs: BodyStates, t: float) -> ForceEval:  # pragma: no cover - abstract
        raise NotImplementedError

    def jacobian(self, bs: BodyStates, t: float) -> ForceJacobian | None:
        """Analytic Jacobian blocks, or None (the model then differentiates numerically)."""
        return None

    def potential(self, bs: BodyStates) -> float:
        """Potential energy [J] (only meaningful when ``conservative``)."""
        return 0.0

    def outputs(self, bs: BodyStates, t: float) -> dict[str, Array]:
        """Per-element output quantities for result tables (e.g. length, force)."""
        return {}

    # --- search state ------------------------------------------------------------------------
    def reset_state(self, bs: BodyStates, t: float) -> None:
        """Start of a run at ``(t, q, v)``: initialise the search state (stateful kinds only)."""

    def accept_step(self, bs: BodyStates, t: float) -> None:
        """An integrator accepted a step ending at ``(t, q, v)``: update the search state."""

    # --- compiled path -----------------------------------------------------------------------
    def compiled(self, layout):
        """The compiled form of this kind for :mod:`core.compiled` (override to provide one).

        Returns a :class:`core.compiled.CompiledForces`; the default raises
        :class:`core.errors.NotCompilable` naming the first element.
        """
        from ..errors import NotCompilable

        raise NotCompilable(f"force element {self.names[0]!r} ({type(self).__name__}) has no compiled kernel")


# --------------------------------------------------------------------------------------------
# checks shared by the element kinds (each names the element)
# --------------------------------------------------------------------------------------------


def nonnegative(value, what: str, element: str) -> float:
    """``float(value)``, which must be finite and ≥ 0 (:class:`ModelError` naming the element)."""
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise ModelError(f"{element!r}: {what} must be a finite number ≥ 0, got {value!r}") from None
    if not (np.isfinite(x) and x >= 0):
        raise ModelError(f"{element!r}: {what} must be a finite number ≥ 0, got {value}")
    return x


def per_axis(value, n: int, what: str, element: str) -> Array:
    """A scalar or ``n`` non-negative finite numbers, as an array of ``n``."""
    a = np.asarray(value, float)
    if a.ndim == 0:
        a = np.full(n, float(a))
    if a.shape != (n,) or not np.all(np.isfinite(a)) or np.any(a < 0):
        raise ModelError(f"{element!r}: {what} must be a number or {n} numbers, all finite and ≥ 0, "
                         f"got {np.asarray(value).tolist()}")
    return a


def two_bodies(ctx, e) -> tuple[int, int]:
    """Indices of ``e.body_i`` and ``e.body_j``, which must differ."""
    bi, bj = ctx.index(e.body_i, e.name), ctx.index(e.body_j, e.name)
    if bi == bj:
        raise ModelError(f"force element {e.name!r} connects body {e.body_i!r} to itself")
    return bi, bj
