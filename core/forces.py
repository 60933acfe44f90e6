r"""Force elements: declared per element, evaluated per kind in one vectorised call.

A force element is a frozen dataclass naming its bodies in the initial configuration; at
``build()`` all elements of one class are compiled by ``compile(elements, ctx)`` into a
:class:`ForceKind`, which evaluates every element at once and returns generalized forces per
body block.  A global force ``F`` at body-fixed point ``s̄`` contributes (Nikravesh 1988, Eq. 6.178)

.. math::

    Q_b = J_P^T F = \begin{bmatrix} F \\ C(\bar s)^T F \end{bmatrix},

i.e. the force and, planar, the moment ``(A R s̄)ᵀF``; spatial, the body-frame moment
``s̄ × (AᵀF)``.  Kinds may also return Jacobian blocks ``∂Q_a/∂v_b`` along position increments
(stiffness) and velocities (damping) for the implicit integrators, and a potential energy.

Domain packages add force kinds the same way (the railway wheel–rail contact is one).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from .bodies import BodyStates
from .drivers import as_time_function

Array = NDArray[np.float64]
IArray = NDArray[np.int64]


@dataclass
class ForceEval:
    """Generalized forces of one kind: ``Q[bodies[k]] += Qb[k]``.

    Attributes
    ----------
    bodies : ndarray of int, shape (m,)
    Qb : ndarray, shape (m, n_v_body)
    """

    bodies: IArray
    Qb: Array


@dataclass
class ForceJacobian:
    """Jacobian blocks ``∂Q_{rows[k]}/∂v_{cols[k]}``: Kq (m, n_v, n_v) and Kv (m, n_v, n_v)."""

    rows: IArray
    cols: IArray
    Kq: Array
    Kv: Array


class ForceElement:
    """Base class of declared force elements."""

    name: str

    @classmethod
    def compile(cls, elements: list[ForceElement], ctx) -> ForceKind:  # pragma: no cover
        raise NotImplementedError


class ForceKind:
    """Vectorised evaluator of all elements of one force class."""

    #: True if the force derives from a potential (no damping, no time dependence).
    conservative: bool = False
    names: list[str]

    def evaluate(self, bs: BodyStates, t: float) -> ForceEval:  # pragma: no cover
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


def _point_jac(bs: BodyStates, b: IArray, s: Array) -> Array:
    """``J_P = [I, C(s̄)]``, shape (n, d, n_v)."""
    d = bs.space.dim
    n = len(b)
    J = np.zeros((n, d, bs.space.n_v))
    J[:, :, :d] = np.eye(d)
    J[:, :, d:] = bs.C(b, s)
    return J


# --------------------------------------------------------------------------------------------
# point-to-point spring-damper-actuator
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class SpringDamper(ForceElement):
    r"""Point-to-point translational spring-damper-actuator.

    .. math::

        L = |d|,\ d = r_Q - r_P,\ u = d/L,\qquad
        f = k (L - L_0) + c \dot L + f_a(t),\qquad F_P = f u,\ F_Q = -f u

    (tension positive: ``f > 0`` pulls P and Q together).  ``free_length`` defaults to the
    initial distance; ``actuator`` is an optional force of time (number, callable, table).

    Parameters
    ----------
    point_i, point_j : array_like
        Global attachment points in the initial configuration [m].
    stiffness : float
        k [N/m], ≥ 0.
    damping : float
        c [N s/m], ≥ 0.
    """

    name: str
    body_i: str
    body_j: str
    point_i: Any
    point_j: Any
    stiffness: float
    damping: float = 0.0
    free_length: float | None = None
    actuator: Any = None

    @classmethod
    def compile(cls, elements, ctx):
        return SpringDamperKind(elements, ctx)


class SpringDamperKind(ForceKind):
    """All :class:`SpringDamper` elements of a model."""

    def __init__(self, elements: list[SpringDamper], ctx):
        d = ctx.space.dim
        self.names = [e.name for e in elements]
        self.bi = np.array([ctx.index(e.body_i, e.name) for e in elements], dtype=np.int64)
        self.bj = np.array([ctx.index(e.body_j, e.name) for e in elements], dtype=np.int64)
        si, sj, L0 = [], [], []
        for e in elements:
            pi = np.asarray(e.point_i, float).reshape(d)
            pj = np.asarray(e.point_j, float).reshape(d)
            si.append(ctx.local_point(ctx.index(e.body_i, e.name), pi))
            sj.append(ctx.local_point(ctx.index(e.body_j, e.name), pj))
            L0.append(np.linalg.norm(pj - pi) if e.free_length is None else float(e.free_length))
            if not (np.isfinite(e.stiffness) and e.stiffness >= 0):
                raise ValueError(f"spring-damper {e.name!r}: stiffness must be ≥ 0, got {e.stiffness}")
            if not (np.isfinite(e.damping) and e.damping >= 0):
                raise ValueError(f"spring-damper {e.name!r}: damping must be ≥ 0, got {e.damping}")
            if L0[-1] < 0:
                raise ValueError(f"spring-damper {e.name!r}: free length must be ≥ 0, got {L0[-1]}")
        self.si, self.sj = np.array(si), np.array(sj)
        self.L0 = np.array(L0)
        self.k = np.array([e.stiffness for e in elements], float)
        self.c = np.array([e.damping for e in elements], float)
        self.act = [None if e.actuator is None else as_time_function(e.actuator, f"actuator of {e.name!r}") for e in elements]
        self.has_act = any(a is not None for a in self.act)
        self.conservative = not (np.any(self.c > 0) or self.has_act)

    def _geometry(self, bs):
        d = bs.point(self.bj, self.sj) - bs.point(self.bi, self.si)
        L = np.linalg.norm(d, axis=1)
        if np.any(L < 1e-12):
            k = int(np.argmin(L))
            raise FloatingPointError(f"spring-damper {self.names[k]!r}: attachment points coincide (length {L[k]:.3g} m)")
        u = d / L[:, None]
        dd = bs.point_velocity(self.bj, self.sj) - bs.point_velocity(self.bi, self.si)
        Ld = np.sum(u * dd, 1)
        return d, L, u, dd, Ld

    def _fa(self, t):
        if not self.has_act:
            return 0.0
        return np.array([0.0 if a is None else a(t)[0] for a in self.act])

    def evaluate(self, bs, t):
        d, L, u, dd, Ld = self._geometry(bs)
        f = self.k * (L - self.L0) + self.c * Ld + self._fa(t)
        F = f[:, None] * u  # on P (body i)
        Jp, Jq = _point_jac(bs, self.bi, self.si), _point_jac(bs, self.bj, self.sj)
        Qi = np.einsum("ndk,nd->nk", Jp, F)
        Qj = -np.einsum("ndk,nd->nk", Jq, F)
        return ForceEval(np.concatenate([self.bi, self.bj]), np.concatenate([Qi, Qj]))

    def jacobian(self, bs, t):
        r"""Exact Jacobian along position increments (incl. lever-arm and velocity-transport terms).

        ``∂F/∂d = u (k uᵀ + c ḋᵀ(I − uuᵀ)/L) + f (I − uuᵀ)/L``, ``∂F/∂ḋ = c u uᵀ``.
        """
        dvec, L, u, dd, Ld = self._geometry(bs)
        f = self.k * (L - self.L0) + self.c * Ld + self._fa(t)
        n, dim = len(L), bs.space.dim
        I = np.eye(dim)
        P = I - u[:, :, None] * u[:, None, :]
        dLd_dd = np.einsum("ni,nij->nj", dd, P) / L[:, None]
        Kd = u[:, :, None] * (self.k[:, None] * u + self.c[:, None] * dLd_dd)[:, None, :] + (f / L)[:, None, None] * P
        Cd = self.c[:, None, None] * u[:, :, None] * u[:, None, :]
        Jp, Jq = _point_jac(bs, self.bi, self.si), _point_jac(bs, self.bj, self.sj)
        # velocity of d depends on orientation at fixed ω: ḋ = ... + dvel_dtheta
        Vp = np.zeros_like(Jp)
        Vq = np.zeros_like(Jq)
        Vp[:, :, dim:] = bs.space.dvel_dtheta(bs.A[self.bi], bs.w[self.bi], self.si)
        Vq[:, :, dim:] = bs.space.dvel_dtheta(bs.A[self.bj], bs.w[self.bj], self.sj)
        # dF (on P) w.r.t. v-increments of body i and j
        dF_di = -np.einsum("nab,nbk->nak", Kd, Jp) - np.einsum("nab,nbk->nak", Cd, Vp)
        dF_dj = np.einsum("nab,nbk->nak", Kd, Jq) + np.einsum("nab,nbk->nak", Cd, Vq)
        dFv_di = -np.einsum("nab,nbk->nak", Cd, Jp)
        dFv_dj = np.einsum("nab,nbk->nak", Cd, Jq)
        F = f[:, None] * u
        Kii = np.einsum("ndk,ndl->nkl", Jp, dF_di)
        Kij = np.einsum("ndk,ndl->nkl", Jp, dF_dj)
        Kji = -np.einsum("ndk,ndl->nkl", Jq, dF_di)
        Kjj = -np.einsum("ndk,ndl->nkl", Jq, dF_dj)
        # lever-arm terms ∂(Cᵀ F)/∂θ at fixed F
        Kii[:, dim:, dim:] += bs.space.Cdot_T_force(bs.A[self.bi], self.si, F)
        Kjj[:, dim:, dim:] += bs.space.Cdot_T_force(bs.A[self.bj], self.sj, -F)
        Dii = np.einsum("ndk,ndl->nkl", Jp, dFv_di)
        Dij = np.einsum("ndk,ndl->nkl", Jp, dFv_dj)
        Dji = -np.einsum("ndk,ndl->nkl", Jq, dFv_di)
        Djj = -np.einsum("ndk,ndl->nkl", Jq, dFv_dj)
        rows = np.concatenate([self.bi, self.bi, self.bj, self.bj])
        cols = np.concatenate([self.bi, self.bj, self.bi, self.bj])
        return ForceJacobian(rows, cols, np.concatenate([Kii, Kij, Kji, Kjj]), np.concatenate([Dii, Dij, Dji, Djj]))

    def potential(self, bs):
        d = bs.point(self.bj, self.sj) - bs.point(self.bi, self.si)
        L = np.linalg.norm(d, axis=1)
        return float(np.sum(0.5 * self.k * (L - self.L0) ** 2))

    def outputs(self, bs, t):
        d, L, u, dd, Ld = self._geometry(bs)
        f = self.k * (L - self.L0) + self.c * Ld + self._fa(t)
        return {"length [m]": L, "force [N]": f}
