r"""Rigid bodies and their vectorised frame kinematics.

Coordinates per body
--------------------
* planar: ``q_b = (x, y, θ)``, ``v_b = (ẋ, ẏ, θ̇)``;  ``A(θ)`` rotates body to global.
* spatial: ``q_b = (x, y, z, e0, e1, e2, e3)``, ``v_b = (ẋ, ẏ, ż, ω̄x, ω̄y, ω̄z)`` with ω̄ the
  angular velocity in body coordinates; ``A(p)`` from the Euler parameters.

Body-fixed point P with local position s̄ (Nikravesh 1988, Eqs. 6.151–6.156; Haug 1989, Eq. 9.2.x):

.. math::

    r_P = r + A\bar s, \qquad
    \dot r_P = \dot r + C(\bar s)\,\omega, \qquad
    \ddot r_P = \ddot r + C(\bar s)\,\dot\omega + a^{q}(\bar s)

with, planar: ``C = A R s̄`` (R the 90° rotation), ``a^q = −A s̄ θ̇²``;
spatial: ``C = −A s̄̃``, ``a^q = A(ω̄ × (ω̄ × s̄))``.
A body-fixed direction ``a = A ā`` has the same ``C(ā)`` and ``a^q(ā)`` without the ``r`` terms.
The ground is a pseudo-body with index ``n_bodies``: identity pose, zero velocity, no columns.

References
----------
P. E. Nikravesh, *Computer-Aided Analysis of Mechanical Systems*, 1988, Ch. 6–7.
E. J. Haug, *Computer-Aided Kinematics and Dynamics of Mechanical Systems*, 1989, Ch. 9.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from . import frames

Array = NDArray[np.float64]


@dataclass(frozen=True)
class Body:
    """A rigid body.

    Parameters
    ----------
    name : str
    mass : float
        Mass [kg], > 0 (or 0 for a massless body only when constraints make M well posed).
    inertia : float or ndarray, shape (3, 3)
        Planar: polar moment about the centre of mass [kg m²].  Spatial: inertia tensor about
        the centre of mass in body axes [kg m²].
    position : ndarray, shape (2,) or (3,)
        Initial centre-of-mass position [m].
    orientation : float or ndarray, shape (4,)
        Initial angle [rad] (planar) or Euler parameters (spatial).
    velocity : ndarray, shape (2,) or (3,)
        Initial centre-of-mass velocity [m/s].
    angular_velocity : float or ndarray, shape (3,)
        Initial angular velocity [rad/s]; spatial: in *global* axes (converted at build).
    """

    name: str
    mass: float
    inertia: float | Array
    position: Array
    orientation: float | Array
    velocity: Array
    angular_velocity: float | Array
    extra: dict = field(default_factory=dict, compare=False)


class Space:
    """Dimension-specific body algebra (planar or spatial), vectorised over bodies/elements."""

    dim: int
    n_q: int  # position coordinates per body
    n_v: int  # velocity coordinates per body
    n_rot: int  # rotational velocity coordinates per body

    def rotation(self, qb: Array) -> Array:
        """Rotation matrices, shape (n, d, d), from body coordinate blocks (n, n_q)."""
        raise NotImplementedError

    def C(self, A: Array, s: Array) -> Array:
        """Rotational Jacobian of a body-fixed vector, shape (n, d, n_rot)."""
        raise NotImplementedError

    def aq(self, A: Array, w: Array, s: Array) -> Array:
        """Quadratic-velocity acceleration of a body-fixed vector, shape (n, d)."""
        raise NotImplementedError

    def Cdot_T_force(self, A: Array, s: Array, F: Array) -> Array:
        """``∂(C(s̄)ᵀF)/∂θ`` along body rotation increments, shape (n, n_rot, n_rot), F fixed."""
        raise NotImplementedError

    def dvel_dtheta(self, A: Array, w: Array, s: Array) -> Array:
        """``∂(C(s̄) ω)/∂θ`` along body rotation increments at fixed ω, shape (n, d, n_rot)."""
        raise NotImplementedError


class Planar(Space):
    """Planar bodies (x, y, θ)."""

    def __reduce__(self):
        return "PLANAR"

    dim = 2
    n_q = 3
    n_v = 3
    n_rot = 1

    def rotation(self, qb: Array) -> Array:
        return frames.rot2(qb[:, 2])

    def C(self, A: Array, s: Array) -> Array:
        return np.einsum("nij,jk,nk->ni", A, frames.ROT90, s)[:, :, None]

    def aq(self, A: Array, w: Array, s: Array) -> Array:
        return -np.einsum("nij,nj->ni", A, s) * (w[:, 0] ** 2)[:, None]

    def Cdot_T_force(self, A: Array, s: Array, F: Array) -> Array:
        # d/dθ (A R s)ᵀ F = (A R R s)ᵀ F = −(A s)ᵀ F
        return -np.einsum("nij,nj,ni->n", A, s, F)[:, None, None]

    def dvel_dtheta(self, A: Array, w: Array, s: Array) -> Array:
        # d/dθ (A R s θ̇) = −A s θ̇
        return (-np.einsum("nij,nj->ni", A, s) * w[:, :1])[:, :, None]


class Spatial(Space):
    """Spatial bodies (r, Euler parameters), body-frame angular velocity."""

    def __reduce__(self):
        return "SPATIAL"

    dim = 3
    n_q = 7
    n_v = 6
    n_rot = 3

    def rotation(self, qb: Array) -> Array:
        return frames.euler_to_matrix(qb[:, 3:7])

    def C(self, A: Array, s: Array) -> Array:
        return -np.einsum("nij,njk->nik", A, frames.skew(s))

    def aq(self, A: Array, w: Array, s: Array) -> Array:
        return np.einsum("nij,nj->ni", A, np.cross(w, np.cross(w, s)))

    def Cdot_T_force(self, A: Array, s: Array, F: Array) -> Array:
        # C(s̄)ᵀF = s̄ × (AᵀF); with A → A(I + δθ̃): AᵀF → AᵀF + (AᵀF)~ δθ
        Fb = np.einsum("nji,nj->ni", A, F)
        return np.einsum("nij,njk->nik", frames.skew(s), frames.skew(Fb))

    def dvel_dtheta(self, A: Array, w: Array, s: Array) -> Array:
        # C ω = A (ω̄ × s̄);  A → A(I + δθ̃): δ(Cω) = A δθ̃ (ω̄ × s̄) = −A (ω̄ × s̄)~ δθ
        return -np.einsum("nij,njk->nik", A, frames.skew(np.cross(w, s)))


PLANAR = Planar()
SPATIAL = Spatial()


@dataclass
class BodyStates:
    """Poses and velocities of all bodies plus the ground (last row), shared by element kinds.

    Attributes
    ----------
    r : ndarray, shape (n_bodies + 1, d)
    A : ndarray, shape (n_bodies + 1, d, d)
    rdot : ndarray, shape (n_bodies + 1, d)
    w : ndarray, shape (n_bodies + 1, n_rot)
        θ̇ (planar) or body-frame ω̄ (spatial).
    x, xdot : ndarray, shape (n_extra,)
        Values and rates of the model's extra coordinates (path parameters and the like), in
        the order they were added; element kinds that act on them index these arrays.
    """

    space: Space
    r: Array
    A: Array
    rdot: Array
    w: Array
    x: Array = field(default_factory=lambda: np.zeros(0))
    xdot: Array = field(default_factory=lambda: np.zeros(0))

    @classmethod
    def from_coordinates(cls, space: Space, n_bodies: int, q: Array, v: Array | None) -> BodyStates:
        """Body states from the model's coordinate vectors (extra coordinates follow the bodies)."""
        nb = n_bodies
        qb = np.empty((nb + 1, space.n_q))
        qb[:nb] = q[: nb * space.n_q].reshape(nb, space.n_q)
        qb[nb] = 0.0
        if space.dim == 3:
            qb[nb, 3] = 1.0
        A = space.rotation(qb)
        r = qb[:, : space.dim]
        vb = np.zeros((nb + 1, space.n_v))
        x = np.asarray(q[nb * space.n_q:], float)
        xdot = np.zeros(len(x))
        if v is not None:
            vb[:nb] = v[: nb * space.n_v].reshape(nb, space.n_v)
            xdot = np.asarray(v[nb * space.n_v:], float)
        return cls(space, r, A, vb[:, : space.dim], vb[:, space.dim :], x, xdot)

    @classmethod
    def from_frames(cls, space: Space, n_bodies: int, q: Array, v: Array | None) -> BodyStates:
        """Body states of many configurations at once: ``q`` (n_f, n_q), ``v`` (n_f, n_v) or None.

        Every array gains a leading frame axis: ``r`` (n_f, n_bodies + 1, d), ``A`` (n_f,
        n_bodies + 1, d, d), ``rdot``, ``w``, ``x`` (n_f, n_extra), ``xdot``.  Force kinds that
        offer ``evaluate_frames`` read these (:meth:`core.model.Model.Q_frames`).
        """
        nb, nf = n_bodies, q.shape[0]
        qb = np.zeros((nf, nb + 1, space.n_q))
        qb[:, :nb] = q[:, : nb * space.n_q].reshape(nf, nb, space.n_q)
        if space.dim == 3:
            qb[:, nb, 3] = 1.0
        A = space.rotation(qb.reshape(-1, space.n_q)).reshape(nf, nb + 1, space.dim, space.dim)
        vb = np.zeros((nf, nb + 1, space.n_v))
        x = np.asarray(q[:, nb * space.n_q:], float)
        xdot = np.zeros_like(x)
        if v is not None:
            vb[:, :nb] = v[:, : nb * space.n_v].reshape(nf, nb, space.n_v)
            xdot = np.asarray(v[:, nb * space.n_v:], float)
        return cls(space, qb[..., : space.dim], A, vb[..., : space.dim], vb[..., space.dim :], x, xdot)

    # --- point kinematics for element arrays (index arrays into bodies) -------------------
    def point(self, b: NDArray[np.int64], s: Array) -> Array:
        """Global position of body-fixed points, shape (n, d)."""
        return self.r[b] + np.einsum("nij,nj->ni", self.A[b], s)

    def vector(self, b: NDArray[np.int64], s: Array) -> Array:
        """Global components of body-fixed vectors, shape (n, d)."""
        return np.einsum("nij,nj->ni", self.A[b], s)

    def C(self, b: NDArray[np.int64], s: Array) -> Array:
        return self.space.C(self.A[b], s)

    def point_velocity(self, b: NDArray[np.int64], s: Array) -> Array:
        return self.rdot[b] + np.einsum("nij,nj->ni", self.C(b, s), self.w[b])

    def vector_velocity(self, b: NDArray[np.int64], s: Array) -> Array:
        return np.einsum("nij,nj->ni", self.C(b, s), self.w[b])

    def aq(self, b: NDArray[np.int64], s: Array) -> Array:
        return self.space.aq(self.A[b], self.w[b], s)
