r"""The constrained mechanical system: the one interface shared by every integrator and analysis.

Equations
---------
A holonomic multibody system with position coordinates ``q`` (n_q) and velocity coordinates
``v`` (n_v) obeys

.. math::

    \dot q &= Z(q)\, v                                   \\
    M(q)\, \dot v + \Phi_q(t, q)^T \lambda &= Q(t, q, v)  \\
    \Phi(t, q) &= 0                                      \\
    \Phi_q(t, q)\, v &= \nu(t, q)                        \\
    \Phi_q(t, q)\, \dot v &= \gamma(t, q, v)

where ``Φ`` (n_c) are the constraint equations and ``λ`` the Lagrange multipliers.
``Φ_q`` is the constraint Jacobian *with respect to the velocity coordinates*:
``Φ̇ = Φ_q v + Φ_t``, i.e. ``Φ_q = (∂Φ/∂q) Z``.  For planar bodies and for models written in
generalized coordinates ``Z = I`` and ``Φ_q`` is the ordinary Jacobian; for Euler-parameter
bodies ``v`` holds the body-frame angular velocity, ``Z`` maps it to Euler-parameter rates and
the normalisation ``pᵀp = 1`` is kept by the retraction ``q ⊕ Δv`` rather than by a multiplier
(Brüls & Cardona 2010).  ``ν = −Φ_t`` and ``γ = −(Φ_q v)_q Z v − 2 Φ_qt v − Φ_tt``
(Haug 1989, Eqs. 6.3.4–6.3.6; Nikravesh 1988, Eqs. 3.29–3.31).

Any object implementing :class:`ConstrainedSystem` runs through every integrator of
:mod:`core.integrators` and every analysis of :mod:`core.analysis`: the Cartesian
:class:`core.model.Model` is one producer; hand-written models in generalized coordinates
(Andrews' squeezer, the car axis) are others.

References
----------
E. J. Haug, *Computer-Aided Kinematics and Dynamics of Mechanical Systems*, Allyn & Bacon, 1989.
P. E. Nikravesh, *Computer-Aided Analysis of Mechanical Systems*, Prentice Hall, 1988.
O. Brüls, A. Cardona, J. Comput. Nonlinear Dynam. 5 (2010) 031002.
"""

from __future__ import annotations

from abc import ABC, abstractmethod

import numpy as np
import scipy.sparse as sp
from numpy.typing import NDArray

from .errors import ModelError

Array = NDArray[np.float64]


class ConstrainedSystem(ABC):
    """Abstract constrained mechanical system ``(M, Q, Φ, Φ_q, ν, γ, Z)``.

    Subclasses set the sizes ``n_q``, ``n_v``, ``n_c``, the initial state ``q0``, ``v0`` and
    the name lists, and implement the abstract methods.  Matrices may be returned as dense
    ``ndarray`` or ``scipy.sparse`` matrices; integrators accept both.

    Attributes
    ----------
    name : str
    n_q, n_v, n_c : int
        Numbers of position coordinates, velocity coordinates and constraint equations.
    q0 : ndarray, shape (n_q,)
    v0 : ndarray, shape (n_v,)
    coordinate_names : list of str, length n_q
    velocity_names : list of str, length n_v
    constraint_names : list of str, length n_c
    mass_is_constant : bool
        True when ``M`` does not depend on ``q`` (lets integrators factor it once).
    is_conservative : bool
        True when :meth:`energy` is a conserved quantity of the exact motion.
    """

    name: str = "system"
    n_q: int
    n_v: int
    n_c: int
    q0: Array
    v0: Array
    coordinate_names: list[str]
    velocity_names: list[str]
    constraint_names: list[str]
    mass_is_constant: bool = False
    is_conservative: bool = False

    # --- dynamics -------------------------------------------------------------------------
    @abstractmethod
    def M(self, t: float, q: Array) -> Array | sp.spmatrix:
        """Mass matrix, shape (n_v, n_v), symmetric, positive (semi-)definite."""

    @abstractmethod
    def Q(self, t: float, q: Array, v: Array) -> Array:
        """Generalized applied plus velocity-dependent (gyroscopic) forces, shape (n_v,)."""

    # --- constraints ----------------------------------------------------------------------
    @abstractmethod
    def Phi(self, t: float, q: Array) -> Array:
        """Constraint residuals, shape (n_c,)."""

    @abstractmethod
    def Phi_q(self, t: float, q: Array) -> Array | sp.spmatrix:
        """Constraint Jacobian with respect to the velocity coordinates, shape (n_c, n_v)."""

    @abstractmethod
    def nu(self, t: float, q: Array) -> Array:
        """Velocity right-hand side ``ν = −Φ_t``, shape (n_c,)."""

    @abstractmethod
    def gamma(self, t: float, q: Array, v: Array) -> Array:
        """Acceleration right-hand side γ, shape (n_c,)."""

    # --- coordinate kinematics (identity by default) ---------------------------------------
    def qdot(self, q: Array, v: Array) -> Array:
        """Coordinate rates ``q̇ = Z(q) v``, shape (n_q,)."""
        return v

    def Z(self, q: Array) -> Array | sp.spmatrix:
        """Kinematic matrix ``Z(q)``, shape (n_q, n_v)."""
        return sp.identity(self.n_q, format="csr")

    def retract(self, q: Array, dv: Array) -> Array:
        """Position update ``q ⊕ Δv`` along a velocity-space increment, shape (n_q,)."""
        return q + dv

    def normalize(self, q: Array) -> Array:
        """Return ``q`` with any coordinate invariants (unit Euler parameters) restored."""
        return q

    def invariant_violation(self, q: Array) -> float:
        """Largest violation of coordinate invariants not held by multipliers (e.g. ``|p|²`` − 1)."""
        return 0.0

    # --- optional Jacobians of Q (finite differences by default) ----------------------------
    def Q_q(self, t: float, q: Array, v: Array) -> Array | sp.spmatrix:
        """∂Q/∂q along velocity-space increments, shape (n_v, n_v) (forward differences)."""
        Q0 = self.Q(t, q, v)
        J = np.empty((self.n_v, self.n_v))
        for k in range(self.n_v):
            h = 1e-7 * max(1.0, abs(q[k]) if self.n_q == self.n_v else 1.0)
            dv = np.zeros(self.n_v)
            dv[k] = h
            J[:, k] = (self.Q(t, self.retract(q, dv), v) - Q0) / h
        return J

    def Q_v(self, t: float, q: Array, v: Array) -> Array | sp.spmatrix:
        """∂Q/∂v, shape (n_v, n_v) (forward differences)."""
        Q0 = self.Q(t, q, v)
        J = np.empty((self.n_v, self.n_v))
        for k in range(self.n_v):
            h = 1e-7 * max(1.0, abs(v[k]))
            vv = v.copy()
            vv[k] += h
            J[:, k] = (self.Q(t, q, vv) - Q0) / h
        return J

    def Q_jacobians(self, t: float, q: Array, v: Array):
        """Both ``(Q_q, Q_v)``; systems with analytic Jacobians override this with one pass."""
        return self.Q_q(t, q, v), self.Q_v(t, q, v)

    # --- search state of stateful elements (no-ops unless a system keeps one) -----------------
    def begin_run(self, t: float, q: Array, v: Array) -> None:
        """A run starts at ``(t, q, v)`` (integrators call this once, on construction)."""

    def accept_step(self, t: float, q: Array, v: Array) -> None:
        """An integrator accepted a step ending at ``(t, q, v)``.

        Called after accepted steps only — never for rejected attempts, stage evaluations,
        Newton iterates or dense output — so a system whose elements keep a search state (a
        contact search's warm start) evaluates the same force at the same ``(t, q, v)``
        throughout a step (:mod:`core.forces.protocol`).
        """

    # --- diagnostics ----------------------------------------------------------------------
    def energy(self, t: float, q: Array, v: Array) -> float | None:
        """Total mechanical energy [J] where defined (kinetic + potential), else None."""
        return None

    def reaction_groups(self) -> dict[str, NDArray[np.int64]]:
        """Constraint rows belonging to each named joint or driver (for reaction tables)."""
        return {}

    def reactions(self, t: float, q: Array, lam: Array) -> dict[str, Array]:
        """Reaction force/torque per joint from the multipliers (model-specific), or empty."""
        return {}

    def reaction_names(self) -> dict[str, list[str]]:
        """Column names (with units) of :meth:`reactions` per joint."""
        return {}

    # --- helpers shared by integrators ----------------------------------------------------
    def velocity_violation(self, t: float, q: Array, v: Array) -> Array:
        """``Φ_q v − ν``, shape (n_c,)."""
        return np.asarray(self.Phi_q(t, q) @ v - self.nu(t, q))

    def check_sizes(self) -> None:
        """Validate the declared sizes against the initial state; :class:`ModelError` naming the field."""
        if np.shape(self.q0) != (self.n_q,):
            raise ModelError(f"{self.name}: q0 has shape {np.shape(self.q0)}, expected ({self.n_q},)")
        if np.shape(self.v0) != (self.n_v,):
            raise ModelError(f"{self.name}: v0 has shape {np.shape(self.v0)}, expected ({self.n_v},)")
        for label, names, n in (
            ("coordinate_names", self.coordinate_names, self.n_q),
            ("velocity_names", self.velocity_names, self.n_v),
            ("constraint_names", self.constraint_names, self.n_c),
        ):
            if len(names) != n:
                raise ModelError(f"{self.name}: {label} has {len(names)} entries, expected {n}")


def as_dense(A: Array | sp.spmatrix) -> Array:
    """Dense copy of a dense-or-sparse matrix."""
    return A.toarray() if sp.issparse(A) else np.asarray(A, dtype=float)


def as_sparse(A: Array | sp.spmatrix) -> sp.csc_matrix:
    """CSC copy of a dense-or-sparse matrix."""
    return sp.csc_matrix(A)
