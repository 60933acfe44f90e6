r"""Spring-damper force elements: point-to-point, zero-length, rotational and bushing.

=============================== ==============================================================
element                         law (details in each class)
=============================== ==============================================================
:class:`SpringDamper`           ``f = k (L − L₀) + c L̇ + f_a(t)`` along the line of the points
:class:`PointSpring`            ``F = k d + c ḋ`` (zero free length; the "penalty joint")
:class:`RotationalSpringDamper` ``T = k (θ − θ₀) + c θ̇ + T_a(t)`` about a relative angle
:class:`Bushing`                ``f = K Δ + C Δ̇`` on the 3/6 relative deflections of two markers
:class:`BumpStop`               ``f = ±g(|u|) + c u̇`` beyond a clearance along a body-fixed axis
:class:`SeriesSpringDamper`     spring ``k_s`` in series with a damper ``c`` (Maxwell element); the
                                series node is an extra coordinate with a small mass
=============================== ==============================================================

All supply exact Jacobians (:mod:`core.forces.coordinates`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..drivers import as_time_function
from ..errors import ModelError
from .coordinates import (
    ElementCoordinate,
    atan2_coordinate,
    combine_coordinates,
    coordinate_forces,
    coordinate_jacobian,
    dot1_coordinate,
    dot2_coordinate,
    pair_velocity,
    point_jacobian,
    point_pair_jacobian,
    stack_coordinates,
)
from .protocol import ForceElement, ForceEval, ForceJacobian, ForceKind, nonnegative, per_axis, two_bodies

Array = NDArray[np.float64]
IArray = NDArray[np.int64]

__all__ = [
    "SpringDamper",
    "SpringDamperKind",
    "PointSpring",
    "PointSpringKind",
    "RotationalSpringDamper",
    "RotationalSpringDamperKind",
    "Bushing",
    "BushingKind",
    "BumpStop",
    "BumpStopKind",
    "SeriesSpringDamper",
    "SeriesSpringDamperKind",
]


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
                raise ModelError(f"spring-damper {e.name!r}: stiffness must be ≥ 0, got {e.stiffness}")
            if not (np.isfinite(e.damping) and e.damping >= 0):
                raise ModelError(f"spring-damper {e.name!r}: damping must be ≥ 0, got {e.damping}")
            if L0[-1] < 0:
                raise ModelError(f"spring-damper {e.name!r}: free length must be ≥ 0, got {L0[-1]}")
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
        Jp, Jq = point_jacobian(bs, self.bi, self.si), point_jacobian(bs, self.bj, self.sj)
        Qi = np.einsum("ndk,nd->nk", Jp, F)
        Qj = -np.einsum("ndk,nd->nk", Jq, F)
        return ForceEval(np.concatenate([self.bi, self.bj]), np.concatenate([Qi, Qj]))

    def jacobian(self, bs, t):
        r"""Exact Jacobian along position increments (incl. lever-arm and velocity-transport terms).

        ``∂F/∂d = u (k uᵀ + c ḋᵀ(I − uuᵀ)/L) + f (I − uuᵀ)/L``, ``∂F/∂ḋ = c u uᵀ``.
        """
        dvec, L, u, dd, Ld = self._geometry(bs)
        f = self.k * (L - self.L0) + self.c * Ld + self._fa(t)
        dim = bs.space.dim
        I = np.eye(dim)
        P = I - u[:, :, None] * u[:, None, :]
        dLd_dd = np.einsum("ni,nij->nj", dd, P) / L[:, None]
        Kd = u[:, :, None] * (self.k[:, None] * u + self.c[:, None] * dLd_dd)[:, None, :] + (f / L)[:, None, None] * P
        Cd = self.c[:, None, None] * u[:, :, None] * u[:, None, :]
        Jp, Jq = point_jacobian(bs, self.bi, self.si), point_jacobian(bs, self.bj, self.sj)
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

    def compiled(self, layout):
        """Compiled form (:func:`core.compiled.elements.compile_spring_dampers`)."""
        from ..compiled.elements import compile_spring_dampers

        return compile_spring_dampers(self, layout)


# --------------------------------------------------------------------------------------------
# zero-free-length point spring
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class PointSpring(ForceElement):
    r"""Linear spring-damper between two points with zero free length (the "penalty joint").

    .. math::

        d = r_Q - r_P,\qquad F_P = k\,d + c\,\dot d,\qquad F_Q = -F_P,\qquad V = \tfrac12 k\,|d|^2

    (vector form, smooth at ``d = 0`` where :class:`SpringDamper`'s direction is undefined).
    Exact Jacobian ``∂F_P/∂d = k I``, ``∂F_P/∂ḋ = c I`` plus lever-arm and velocity-transport
    terms (Nikravesh 1988, Sec. 6.5 and 11.4, force element Jacobians of Eq. 6.178).

    Parameters
    ----------
    point_i, point_j : array_like, shape (d,)
        Global attachment points in the initial configuration [m]; ``point_j`` defaults to
        ``point_i`` (coincident points, a stiff penalty joint).
    stiffness : float
        k [N/m], ≥ 0.
    damping : float
        c [N s/m], ≥ 0.
    """

    name: str
    body_i: str
    body_j: str
    point_i: Any
    point_j: Any = None
    stiffness: float = 0.0
    damping: float = 0.0

    @classmethod
    def compile(cls, elements, ctx):
        return PointSpringKind(elements, ctx)



class PointSpringKind(ForceKind):
    """All :class:`PointSpring` elements of a model."""

    def __init__(self, elements: list[PointSpring], ctx):
        d = ctx.space.dim
        self.names = [e.name for e in elements]
        bi, bj, si, sj = [], [], [], []
        for e in elements:
            a, b = two_bodies(ctx, e)
            pi = np.asarray(e.point_i, float)
            pj = pi if e.point_j is None else np.asarray(e.point_j, float)
            if pi.shape != (d,) or pj.shape != (d,) or not (np.all(np.isfinite(pi)) and np.all(np.isfinite(pj))):
                raise ModelError(f"point spring {e.name!r}: points must be {d} finite numbers")
            bi.append(a)
            bj.append(b)
            si.append(ctx.local_point(a, pi))
            sj.append(ctx.local_point(b, pj))
        self.bi, self.bj = np.array(bi, np.int64), np.array(bj, np.int64)
        self.si, self.sj = np.array(si), np.array(sj)
        self.k = np.array([nonnegative(e.stiffness, "stiffness", e.name) for e in elements])
        self.c = np.array([nonnegative(e.damping, "damping", e.name) for e in elements])
        self.conservative = not np.any(self.c > 0)

    def _F(self, bs):
        d = bs.point(self.bj, self.sj) - bs.point(self.bi, self.si)
        dd = bs.point_velocity(self.bj, self.sj) - bs.point_velocity(self.bi, self.si)
        return d, self.k[:, None] * d + self.c[:, None] * dd

    def evaluate(self, bs, t):
        _, F = self._F(bs)
        Qi = np.einsum("ndk,nd->nk", point_jacobian(bs, self.bi, self.si), F)
        Qj = -np.einsum("ndk,nd->nk", point_jacobian(bs, self.bj, self.sj), F)
        return ForceEval(np.concatenate([self.bi, self.bj]), np.concatenate([Qi, Qj]))

    def jacobian(self, bs, t):
        _, F = self._F(bs)
        I = np.eye(bs.space.dim)
        return point_pair_jacobian(bs, self.bi, self.si, self.bj, self.sj, F,
                                    self.k[:, None, None] * I, self.c[:, None, None] * I)

    def potential(self, bs):
        d = bs.point(self.bj, self.sj) - bs.point(self.bi, self.si)
        return float(np.sum(0.5 * self.k * np.sum(d * d, 1)))

    def outputs(self, bs, t):
        d, F = self._F(bs)
        return {"elongation [m]": np.linalg.norm(d, axis=1), "force [N]": np.linalg.norm(F, axis=1)}

    def compiled(self, layout):
        """Compiled form (:func:`core.compiled.elements.compile_point_springs`)."""
        from ..compiled.elements import compile_point_springs

        return compile_point_springs(self, layout)


# --------------------------------------------------------------------------------------------
# rotational spring-damper-actuator
# --------------------------------------------------------------------------------------------


def _relative_angle_markers(ctx, bi: int, bj: int, axis) -> tuple[Array, Array, Array]:
    """Body-fixed markers ``f̄_i, ḡ_i`` (on i) and ``f̄_j`` (on j), coincident at build."""
    from ..joints import perpendicular_triad

    if ctx.space.dim == 2:
        f, g = np.array([1.0, 0.0]), np.array([0.0, 1.0])
    else:
        f, g, _ = perpendicular_triad(axis)
    return ctx.local_vector(bi, f), ctx.local_vector(bi, g), ctx.local_vector(bj, f)


@dataclass(frozen=True)
class RotationalSpringDamper(ForceElement):
    r"""Torsional spring-damper-actuator between two bodies (planar, or about a revolute axis).

    The relative rotation angle of body j with respect to body i is measured with markers
    ``f_i, g_i`` fixed to body i and ``f_j`` fixed to body j that coincide in the initial
    configuration (planar: the global x, y axes; spatial: a triad ⊥ to the global ``axis``):

    .. math::

        θ = \operatorname{atan2}(g_i^T f_j,\ f_i^T f_j), \qquad
        T = k (θ - θ_0) + c\,\dotθ + T_a(t), \qquad δW = -T\,δθ .

    Planar, θ is ``θ_j − θ_i`` minus its initial value (wrapped to (−π, π], so the element
    is meant for relative rotations below half a turn from the free angle); spatial, θ is the
    rotation about the axis when the bodies are joined by a revolute joint with that axis
    (Haug 1989, Sec. 9.2.4, relative-rotation driver; the same angle as
    :class:`core.constraints.SpatialAngleDriver`).  Generalized forces follow from the virtual
    work, ``Q = −T ∂θ/∂q``: the torque T acts on body i and −T on body j about the axis, i.e.
    a positive T (stretched spring, θ > θ_0) turns j back towards i.  Without the revolute
    joint the element is still exactly conservative (potential ``½ k (θ−θ_0)²``) but its torque
    has components off the axis.  Jacobians are exact in both the planar and spatial cases
    (second derivatives of atan2 of two dot products).

    Parameters
    ----------
    stiffness : float
        k [N m/rad], ≥ 0.
    damping : float
        c [N m s/rad], ≥ 0.
    free_angle : float
        θ_0 [rad], measured from the initial configuration (default 0: unstressed at build).
    actuator : number, callable, (times, values) or TimeFunction, optional
        T_a(t) [N m], in the same sense as the spring torque.
    axis : array_like, shape (3,)
        Global rotation axis at build (spatial models only).
    """

    name: str
    body_i: str
    body_j: str
    stiffness: float
    damping: float = 0.0
    free_angle: float = 0.0
    actuator: Any = None
    axis: Any = None

    @classmethod
    def compile(cls, elements, ctx):
        return RotationalSpringDamperKind(elements, ctx)


class RotationalSpringDamperKind(ForceKind):
    """All :class:`RotationalSpringDamper` elements of a model."""

    def __init__(self, elements: list[RotationalSpringDamper], ctx):
        self.names = [e.name for e in elements]
        bi, bj, fi, gi, fj = [], [], [], [], []
        for e in elements:
            a, b = two_bodies(ctx, e)
            if ctx.space.dim == 3 and e.axis is None:
                raise ModelError(f"rotational spring-damper {e.name!r}: a spatial model needs the rotation axis")
            try:
                m = _relative_angle_markers(ctx, a, b, e.axis)
            except ValueError as err:
                raise ModelError(f"rotational spring-damper {e.name!r}: {err}") from None
            bi.append(a)
            bj.append(b)
            fi.append(m[0])
            gi.append(m[1])
            fj.append(m[2])
        self.bi, self.bj = np.array(bi, np.int64), np.array(bj, np.int64)
        self.fi, self.gi, self.fj = np.array(fi), np.array(gi), np.array(fj)
        self.k = np.array([nonnegative(e.stiffness, "stiffness", e.name) for e in elements])
        self.c = np.array([nonnegative(e.damping, "damping", e.name) for e in elements])
        self.theta0 = np.array([float(e.free_angle) for e in elements])
        if not np.all(np.isfinite(self.theta0)):
            raise ModelError(f"rotational spring-damper {self.names[int(np.argmax(~np.isfinite(self.theta0)))]!r}: free angle not finite")
        self.act = [None if e.actuator is None else as_time_function(e.actuator, f"actuator of {e.name!r}") for e in elements]
        self.has_act = any(a is not None for a in self.act)
        self.conservative = not (np.any(self.c > 0) or self.has_act)

    def _coord(self, bs):
        a = dot1_coordinate(bs, self.bi, self.gi, self.bj, self.fj)
        b = dot1_coordinate(bs, self.bi, self.fi, self.bj, self.fj)
        return atan2_coordinate(a, b)

    def _torque(self, bs, t, c):
        w = pair_velocity(bs, self.bi, self.bj)
        thd = np.einsum("nmr,nr->nm", c.G, w)[:, 0]
        ta = 0.0 if not self.has_act else np.array([0.0 if a is None else a(t)[0] for a in self.act])
        dth = np.arctan2(np.sin(c.x[:, 0] - self.theta0), np.cos(c.x[:, 0] - self.theta0))
        return dth, thd, self.k * dth + self.c * thd + ta, w

    def evaluate(self, bs, t):
        c = self._coord(bs)
        _, _, T, _ = self._torque(bs, t, c)
        return coordinate_forces(self.bi, self.bj, c, T[:, None], bs.space.n_v)

    def jacobian(self, bs, t):
        c = self._coord(bs)
        _, _, T, w = self._torque(bs, t, c)
        return coordinate_jacobian(self.bi, self.bj, c, T[:, None], self.k[:, None], self.c[:, None], w, bs.space.n_v)

    def potential(self, bs):
        c = self._coord(bs)
        dth = np.arctan2(np.sin(c.x[:, 0] - self.theta0), np.cos(c.x[:, 0] - self.theta0))
        return float(np.sum(0.5 * self.k * dth**2))

    def outputs(self, bs, t):
        c = self._coord(bs)
        dth, thd, T, _ = self._torque(bs, t, c)
        return {"angle [rad]": c.x[:, 0], "torque [N m]": T}

    def compiled(self, layout):
        """Compiled form (:func:`core.compiled.elements.compile_rotational_spring_dampers`; Jacobian
        by differences on the compiled path)."""
        from ..compiled.elements import compile_rotational_spring_dampers

        return compile_rotational_spring_dampers(self, layout)


# --------------------------------------------------------------------------------------------
# bushing
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Bushing(ForceElement):
    r"""Linear bushing: 6-dof (spatial) / 3-dof (planar) spring-damper between two marker frames.

    Marker frames ``M_i = A_i M̄_i`` on body i (origin P) and ``M_j = A_j M̄_j`` on body j
    (origin Q) coincide in orientation at build (axes ``axes``, default global).  Deflections,
    in marker-i axes, relative to their initial values:

    .. math::

        Δ_t = M_i^T (r_Q - r_P) - Δ_{t0},\qquad
        R = M_i^T M_j,\qquad
        Δ_r = \tfrac12 \operatorname{vee}(R - R^T) \;(\text{spatial}),\quad
        Δ_r = \operatorname{atan2}(R_{21}, R_{11}) \;(\text{planar}),

    generalized force ``f = K Δ + C \dot Δ`` (diagonal K = diag(k_t, k_r), C = diag(c_t, c_r)),
    applied through its virtual work ``δW = −fᵀ δΔ`` (potential ``½ ΔᵀKΔ``).  The translational
    components of ``−f`` are exactly the force on body j in marker-i axes (and ``+f`` on i, with
    the moment that balances it).  The spatial rotational deflection is the small-angle
    definition ``Δ_r = sin φ · n`` of the relative rotation ``R = exp(φ ñ)`` (equal to the
    rotation vector to O(φ³); Adams/Solver BUSHING likewise assumes small rotations, valid to a
    few degrees): ``−f_r`` are the torques conjugate to Δ_r, equal to the marker-axis torques on
    j for small rotations.  Planar: the relative angle is exact.  Jacobians are exact
    (Δ_t components are dot-2 and Δ_r combinations of dot-1 primitives; Haug 1989, Sec. 9.2).

    Parameters
    ----------
    at : array_like, shape (d,)
        Global position of both markers at build [m] (``point_j`` overrides Q's position).
    translational_stiffness, rotational_stiffness : float or array_like
        k_t [N/m] (d values) and k_r [N m/rad] (3 spatial, 1 planar); ≥ 0.
    translational_damping, rotational_damping : float or array_like
        c_t [N s/m], c_r [N m s/rad]; ≥ 0.
    axes : array_like, shape (d, d), optional
        Marker axes at build as the columns of a rotation matrix (default identity).
    """

    name: str
    body_i: str
    body_j: str
    at: Any
    translational_stiffness: Any
    rotational_stiffness: Any
    translational_damping: Any = 0.0
    rotational_damping: Any = 0.0
    axes: Any = None
    point_j: Any = None

    @classmethod
    def compile(cls, elements, ctx):
        return BushingKind(elements, ctx)


class BushingKind(ForceKind):
    """All :class:`Bushing` elements of a model."""

    def __init__(self, elements: list[Bushing], ctx):
        d = ctx.space.dim
        nr = 1 if d == 2 else 3
        self.names = [e.name for e in elements]
        bi, bj, si, sj, Mi, Mj, K, C = [], [], [], [], [], [], [], []
        for e in elements:
            a, b = two_bodies(ctx, e)
            p = np.asarray(e.at, float)
            q = p if e.point_j is None else np.asarray(e.point_j, float)
            if p.shape != (d,) or q.shape != (d,) or not (np.all(np.isfinite(p)) and np.all(np.isfinite(q))):
                raise ModelError(f"bushing {e.name!r}: 'at' and 'point_j' must be {d} finite numbers")
            ax = np.eye(d) if e.axes is None else np.asarray(e.axes, float)
            if ax.shape != (d, d) or not np.allclose(ax.T @ ax, np.eye(d), atol=1e-9) or np.linalg.det(ax) < 0:
                raise ModelError(f"bushing {e.name!r}: axes must be a proper {d}×{d} rotation matrix (columns = marker axes)")
            bi.append(a)
            bj.append(b)
            si.append(ctx.local_point(a, p))
            sj.append(ctx.local_point(b, q))
            Mi.append(ctx.bs0.A[a].T @ ax)
            Mj.append(ctx.bs0.A[b].T @ ax)
            K.append(np.concatenate([per_axis(e.translational_stiffness, d, "translational stiffness", e.name),
                                     per_axis(e.rotational_stiffness, nr, "rotational stiffness", e.name)]))
            C.append(np.concatenate([per_axis(e.translational_damping, d, "translational damping", e.name),
                                     per_axis(e.rotational_damping, nr, "rotational damping", e.name)]))
        self.bi, self.bj = np.array(bi, np.int64), np.array(bj, np.int64)
        self.si, self.sj = np.array(si), np.array(sj)
        self.Mi, self.Mj = np.array(Mi), np.array(Mj)  # body-fixed marker axes (columns)
        self.K, self.C = np.array(K), np.array(C)
        self.conservative = not np.any(self.C > 0)
        self.x0 = self._coord(ctx.bs0).x

    def _coord(self, bs) -> ElementCoordinate:
        d = bs.space.dim
        mi = lambda k: self.Mi[:, :, k]  # noqa: E731
        mj = lambda k: self.Mj[:, :, k]  # noqa: E731
        trans = [dot2_coordinate(bs, self.bi, mi(k), self.si, self.bj, self.sj) for k in range(d)]
        R = lambda a, b: dot1_coordinate(bs, self.bi, mi(a), self.bj, mj(b))  # noqa: E731
        if d == 2:
            rot = [atan2_coordinate(R(1, 0), R(0, 0))]
        else:
            rot = [combine_coordinates([(0.5, R(2, 1)), (-0.5, R(1, 2))]),
                   combine_coordinates([(0.5, R(0, 2)), (-0.5, R(2, 0))]),
                   combine_coordinates([(0.5, R(1, 0)), (-0.5, R(0, 1))])]
        return stack_coordinates(trans + rot)

    def _force(self, bs, c):
        w = pair_velocity(bs, self.bi, self.bj)
        delta = c.x - self.x0
        if bs.space.dim == 2:
            delta[:, 2] = np.arctan2(np.sin(delta[:, 2]), np.cos(delta[:, 2]))
        dd = np.einsum("nmr,nr->nm", c.G, w)
        return delta, dd, self.K * delta + self.C * dd, w

    def evaluate(self, bs, t):
        c = self._coord(bs)
        _, _, f, _ = self._force(bs, c)
        return coordinate_forces(self.bi, self.bj, c, f, bs.space.n_v)

    def jacobian(self, bs, t):
        c = self._coord(bs)
        _, _, f, w = self._force(bs, c)
        return coordinate_jacobian(self.bi, self.bj, c, f, self.K, self.C, w, bs.space.n_v)

    def potential(self, bs):
        c = self._coord(bs)
        delta, _, _, _ = self._force(bs, c)
        return float(np.sum(0.5 * self.K * delta**2))

    def outputs(self, bs, t):
        c = self._coord(bs)
        delta, _, f, _ = self._force(bs, c)
        d = bs.space.dim
        out = {}
        ax = "xyz"
        for k in range(d):
            out[f"d{ax[k]} [m]"] = delta[:, k]
            out[f"F{ax[k]} [N]"] = -f[:, k]
        rl = ["z"] if d == 2 else ["x", "y", "z"]
        for k, r in enumerate(rl):
            out[f"a{r} [rad]"] = delta[:, d + k]
            out[f"M{r} [N m]"] = -f[:, d + k]
        return out

    def compiled(self, layout):
        """Compiled form (:func:`core.compiled.elements.compile_bushings`; Jacobian by differences on
        the compiled path)."""
        from ..compiled.elements import compile_bushings

        return compile_bushings(self, layout)


# --------------------------------------------------------------------------------------------
# bump stop (clearance spring with a tabulated force law)
# --------------------------------------------------------------------------------------------

_SIDES = ("both", "positive", "negative")


@dataclass(frozen=True)
class BumpStop(ForceElement):
    r"""Clearance spring (bump stop) between two bodies along a body-fixed axis, tabulated force law.

    A marker on body i has its origin P at ``at`` and the unit direction ``e = A_i ē`` (``axis``,
    given globally at build, stored body-fixed; normalised here); Q is a point of body j
    (``point_j``, default ``at``).  The deflection is the relative displacement along e from
    the build configuration,

    .. math::

        u = e^T (r_Q - r_P) - u_0 ,

    (a dot-2 element coordinate, Haug 1989, Sec. 9.2; ``u_0`` its value at build).  The table
    ``(d_k, f_k)``, k = 0 … n−1 (total relative displacement d_k ≥ 0 [m] strictly increasing,
    force f_k ≥ 0 [N] non-decreasing, f_0 = 0) defines the force magnitude for a gap closure
    ``s = |u|``:

    .. math::

        g(s) = \begin{cases}
            0 & s < d_0 \quad\text{(the clearance)}\\
            f_k + S_k (s - d_k) & d_k \le s < d_{k+1}\\
            f_{n-1} + S_{n-2} (s - d_{n-1}) & s \ge d_{n-1}
        \end{cases},\qquad S_k = \frac{f_{k+1} - f_k}{d_{k+1} - d_k},

    linear interpolation with the last slope beyond the last row.  The element force is

    .. math::

        f = \sigma(u)\,g(|u|) + c\,\dot u\,[\text{engaged}],\qquad
        δW = -f\,δu,

    with ``σ(u) = sgn u`` for ``sides="both"`` (a symmetric stop: the law is odd in u),
    ``σ = [u ≥ 0]`` for ``"positive"`` (a stop only against u > 0) and ``σ = −[u < 0]`` for
    ``"negative"``; *engaged* means ``|u| > d_0`` on an active side, and the damping c [N s/m]
    acts only then (it switches on with a jump ``c u̇`` at the clearance, and may pull while the
    bodies separate: no clipping).

    **Sign.**  ``Q = −f ∂u/∂q``: the force ``−f e`` acts at Q on body j and ``+f e`` at P on
    body i (with the moment that balances it, including the term from the rotation of e with
    body i, so the undamped stop is exactly conservative with potential ``V = ∫₀ᵘ f du``).  A
    positive u beyond the clearance (Q moved along +e) gives f > 0, which pushes Q back along −e
    and P along +e: the stop resists relative displacement beyond the clearance on either side.

    **Jacobians** are exact (the dot-2 coordinate's gradient and Hessian,
    :func:`core.forces.coordinates.coordinate_jacobian`) with ``∂f/∂u = g'(|u|)`` and
    ``∂f/∂u̇ = c`` while engaged.  ``g`` is continuous but its slope jumps at the table rows: at a
    row ``|u| = d_k`` (and at the clearance ``|u| = d_0``) the slope of the outer segment
    ``S_k`` (the right derivative in ``|u|``) is used, inside the clearance the slope is 0; these
    one-sided derivatives are what the Newton iterations of the implicit integrators see.

    Parameters
    ----------
    at : array_like, shape (d,)
        Global position of P at build [m] (and of Q unless ``point_j``).
    axis : array_like, shape (d,)
        Global direction of the stop axis e at build (normalised; fixed to body i).
    table : array_like, shape (n, 2), n ≥ 2
        Rows ``(d_k [m], f_k [N])``: total relative displacement and force, SI units.
    damping : float
        c [N s/m], ≥ 0, acting only while engaged.
    sides : {"both", "positive", "negative"}
        Which side(s) of the clearance the stop acts on.
    point_j : array_like, shape (d,), optional
        Global position of Q at build [m].

    Examples
    --------
    The Manchester benchmark vehicle's lateral bump stop between bogie frame and car body
    (Iwnicki 1998), clearance 25 mm, table converted from mm and N to SI::

        mm = [25, 30, 35, 40, 45, 50, 55, 60, 65]
        kN = [0, 0.6, 1.76, 3.73, 6.87, 11.58, 17.17, 29.2, 230.0]
        b.add_bump_stop("lateral stop", "bogie", "body", at, (0, 1, 0),
                        np.column_stack([np.array(mm) * 1e-3, np.array(kN) * 1e3]))

    References
    ----------
    E. J. Haug, *Computer-Aided Kinematics and Dynamics of Mechanical Systems*, 1989, Sec. 9.2.
    S. Iwnicki (ed.), "The Manchester benchmarks for rail vehicle simulation", Vehicle System
    Dynamics 30(3–4) (1998) 295–313.
    """

    name: str
    body_i: str
    body_j: str
    at: Any
    axis: Any
    table: Any
    damping: float = 0.0
    sides: str = "both"
    point_j: Any = None

    @classmethod
    def compile(cls, elements, ctx):
        return BumpStopKind(elements, ctx)


def _bump_stop_table(table, name: str) -> Array:
    """The validated force table of bump stop ``name`` as an (n, 2) float array."""
    try:
        T = np.array(table, dtype=float)
    except (TypeError, ValueError):
        raise ModelError(f"bump stop {name!r}: table must be rows (displacement [m], force [N]), "
                         f"got {table!r}") from None
    if T.ndim != 2 or T.shape[1] != 2 or T.shape[0] < 2:
        raise ModelError(f"bump stop {name!r}: table must have shape (n, 2) with n ≥ 2 rows "
                         f"(displacement [m], force [N]), got shape {T.shape}")
    if not np.all(np.isfinite(T)):
        k = int(np.argmax(~np.all(np.isfinite(T), 1)))
        raise ModelError(f"bump stop {name!r}: table row {k} is not finite: {T[k].tolist()}")
    d, f = T[:, 0], T[:, 1]
    if d[0] < 0:
        raise ModelError(f"bump stop {name!r}: the first displacement (the clearance) must be ≥ 0, got {d[0]} m")
    if f[0] != 0:
        raise ModelError(f"bump stop {name!r}: the first row is the clearance and must have force 0, got {f[0]} N")
    bad = np.flatnonzero(np.diff(d) <= 0)
    if len(bad):
        k = int(bad[0])
        raise ModelError(f"bump stop {name!r}: displacements must increase strictly (a repeated displacement "
                         f"would be a force jump of infinite slope), row {k + 1} has {d[k + 1]} m after {d[k]} m")
    bad = np.flatnonzero(np.diff(f) < 0)
    if len(bad):
        k = int(bad[0])
        raise ModelError(f"bump stop {name!r}: forces must not decrease, row {k + 1} has {f[k + 1]} N "
                         f"after {f[k]} N")
    return T


class BumpStopKind(ForceKind):
    """All :class:`BumpStop` elements of a model (tables padded to the longest one)."""

    def __init__(self, elements: list[BumpStop], ctx):
        d = ctx.space.dim
        self.names = [e.name for e in elements]
        n = len(elements)
        bi, bj, si, sj, ei, tables = [], [], [], [], [], []
        for e in elements:
            a, b = two_bodies(ctx, e)
            p = np.asarray(e.at, float)
            q = p if e.point_j is None else np.asarray(e.point_j, float)
            if p.shape != (d,) or q.shape != (d,) or not (np.all(np.isfinite(p)) and np.all(np.isfinite(q))):
                raise ModelError(f"bump stop {e.name!r}: 'at' and 'point_j' must be {d} finite numbers")
            ax = np.asarray(e.axis, float)
            nrm = float(np.linalg.norm(ax)) if ax.shape == (d,) else np.nan
            if not (np.isfinite(nrm) and nrm > 1e-12):
                raise ModelError(f"bump stop {e.name!r}: axis must be {d} finite numbers, not all zero, "
                                 f"got {np.asarray(e.axis).tolist()}")
            if e.sides not in _SIDES:
                raise ModelError(f"bump stop {e.name!r}: sides must be one of {', '.join(_SIDES)}, got {e.sides!r}")
            tables.append(_bump_stop_table(e.table, e.name))
            bi.append(a)
            bj.append(b)
            si.append(ctx.local_point(a, p))
            sj.append(ctx.local_point(b, q))
            ei.append(ctx.local_vector(a, ax / nrm))
        self.bi, self.bj = np.array(bi, np.int64), np.array(bj, np.int64)
        self.si, self.sj, self.ei = np.array(si), np.array(sj), np.array(ei)
        self.c = np.array([nonnegative(e.damping, "damping", e.name) for e in elements])
        self.positive = np.array([e.sides in ("both", "positive") for e in elements])
        self.negative = np.array([e.sides in ("both", "negative") for e in elements])
        # padded tables: D (displacements, +inf beyond the last row), F, slopes S, energies E
        K = max(len(T) for T in tables)
        self.n_rows = np.array([len(T) for T in tables], np.int64)
        self.D = np.full((n, K), np.inf)
        self.F, self.S, self.E = np.zeros((n, K)), np.zeros((n, K)), np.zeros((n, K))
        for k, T in enumerate(tables):
            m = len(T)
            dk, fk = T[:, 0], T[:, 1]
            slope = np.diff(fk) / np.diff(dk)
            self.D[k, :m], self.F[k, :m] = dk, fk
            self.S[k, :m] = np.append(slope, slope[-1])  # the last slope beyond the last row
            self.E[k, 1:m] = np.cumsum(0.5 * (fk[1:] + fk[:-1]) * np.diff(dk))  # ∫ g from d_0 to d_k
        self.conservative = not np.any(self.c > 0)
        self.u0 = self._coord(ctx.bs0).x[:, 0]

    def _coord(self, bs) -> ElementCoordinate:
        return dot2_coordinate(bs, self.bi, self.ei, self.si, self.bj, self.sj)

    def law(self, u: Array) -> tuple[Array, Array, Array, Array]:
        """Spring force ``σ(u) g(|u|)``, its slope ``∂f/∂u``, the potential ``∫₀ᵘ f`` and the
        engaged flag, for deflections ``u`` (n,) [m] of the kind's elements (no damping)."""
        n = len(u)
        r = np.arange(n)
        s = np.abs(u)
        k = np.sum(self.D <= s[:, None], axis=1) - 1  # segment of |u| (−1: inside the clearance)
        kk = np.maximum(k, 0)
        ds = s - self.D[r, kk]
        side = np.where(u >= 0, self.positive, self.negative) & (k >= 0)
        g = np.where(side, self.F[r, kk] + self.S[r, kk] * ds, 0.0)
        slope = np.where(side, self.S[r, kk], 0.0)
        V = np.where(side, self.E[r, kk] + self.F[r, kk] * ds + 0.5 * self.S[r, kk] * ds**2, 0.0)
        g = np.where(np.isnan(u), np.nan, g)  # a diverged state stays visible
        engaged = side & (s > self.D[:, 0])
        return np.where(u >= 0, g, -g), slope, V, engaged

    def _force(self, bs, c):
        w = pair_velocity(bs, self.bi, self.bj)
        u = c.x[:, 0] - self.u0
        ud = np.einsum("nmr,nr->nm", c.G, w)[:, 0]
        fs, slope, _, engaged = self.law(u)
        cd = np.where(engaged, self.c, 0.0)
        return u, ud, fs + cd * ud, slope, cd, engaged, w

    def evaluate(self, bs, t):
        c = self._coord(bs)
        f = self._force(bs, c)[2]
        return coordinate_forces(self.bi, self.bj, c, f[:, None], bs.space.n_v)

    def jacobian(self, bs, t):
        c = self._coord(bs)
        _, _, f, slope, cd, _, w = self._force(bs, c)
        return coordinate_jacobian(self.bi, self.bj, c, f[:, None], slope[:, None], cd[:, None], w, bs.space.n_v)

    def potential(self, bs):
        u = self._coord(bs).x[:, 0] - self.u0
        return float(np.sum(self.law(u)[2]))

    def outputs(self, bs, t):
        c = self._coord(bs)
        u, _, f, _, _, engaged, _ = self._force(bs, c)
        return {"u [m]": u, "engaged": engaged.astype(float), "F [N]": f}

    def compiled(self, layout):
        """Compiled form (:func:`core.compiled.elements.compile_bump_stops`; Jacobian by differences on
        the compiled path)."""
        from ..compiled.elements import compile_bump_stops

        return compile_bump_stops(self, layout)


# --------------------------------------------------------------------------------------------
# spring in series with a damper (Maxwell element)
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class SeriesSpringDamper(ForceElement):
    r"""Spring ``k_s`` in series with a damper ``c`` (a Maxwell element) along the line PQ.

    Typical use: a yaw or lateral damper with the stiffness of its rubber mounts.  P is a point
    of body i, Q of body j; ``ℓ = |r_Q − r_P|``, ``n = (r_Q − r_P)/ℓ``.  The node N between the
    damper (P–N) and the spring (N–Q) lies on the line at ``r_N = r_P + x n``; its position x
    along PQ, measured from P, is an **extra coordinate of the model** with a small mass m_n (the
    damper's moving mass: piston and rod), created by
    :meth:`core.model.ModelBuilder.add_series_spring_damper` (``add_coordinate(f"{name}.node",
    x_0, mass=m_n)``).  Tensions (positive pulling the ends together):

    .. math::

        F_s = k_s (\ell - x - \ell_{s0}), \qquad F_d = c\,\dot x,

    spring N–Q of length ``ℓ − x`` and free length ``ℓ_{s0}``, damper P–N of length x.  The
    virtual work of the two tensions, ``δW = −F_s δ(ℓ − x) − F_d δx = −F_s δℓ + (F_s − F_d) δx``
    with ``δℓ = nᵀ(δr_Q − δr_P)``, gives the generalized forces

    .. math::

        Q_x = F_s - F_d \;(\text{so } m_n \ddot x = F_s - c\,\dot x), \qquad
        F_P = +F_s\,n \text{ at P (body i)}, \qquad F_Q = -F_s\,n \text{ at Q (body j)},

    i.e. the bodies feel the spring tension along PQ, the damper acts on them through the node.
    The node's kinetic energy is taken as ``½ m_n ẋ²`` (relative to P along PQ): the node's
    share of the bodies' motion is neglected, which is consistent while ``m_n`` is small against
    the body masses (its role is to regularise the series node).  With ``c = 0`` the element is
    conservative with potential ``½ k_s (ℓ − x − ℓ_{s0})²``.  Dynamic stiffness between P and Q
    (ends moved harmonically along PQ, frequency ω):

    .. math::

        k^*(ω) = k_s \frac{iωc - m_n ω^2}{k_s + iωc - m_n ω^2}
        \;\xrightarrow{m_n \to 0}\; k_s \frac{iωτ}{1 + iωτ}, \qquad τ = c / k_s .

    ``free_length`` ``L_f`` is the distance PQ at which the spring is relaxed with the node at
    its initial position x_0 (default: the distance at build): ``ℓ_{s0} = L_f − x_0``.

    **Stiffness.**  The node adds the eigenvalue ``≈ −c/m_n`` (and, for small c, the node
    oscillation ``√(k_s/m_n)``), e.g. c = 300 kN s/m, m_n = 5 kg: −6·10⁴ 1/s.  Explicit
    integrators are limited to steps of order ``m_n/c`` by stability (the stiffness test of the
    compiled explicit methods reports it); use ``jit-radau`` (or another implicit method).  A
    massless node (a first-order state ``ẋ = F_s/c``) is not supported by core today, whose
    integrators are second order in (q, v).  Attainable accuracy: the node rate follows the
    positions with the gain ``1/τ = k_s/c`` (``ẋ ≈ F_s/c``), so the round-off of ``ℓ − x`` (≈ ε ℓ)
    puts a floor ``≈ ε ℓ k_s/c`` under its error; an absolute velocity tolerance below that cannot
    be met and the step size of an adaptive method collapses (for c = 300 kN s/m, k_s = 5 MN/m:
    4e-15 m/s, harmless; for a near-rigid spring, τ = 10 µs: 2e-11 m/s).

    **Jacobians** are exact: the body blocks of a spring-damper with tension F_s (stiffness
    ``k_s n nᵀ + F_s (I − n nᵀ)/ℓ``, lever-arm terms), plus the couplings with the node
    (:attr:`ForceJacobian.entries`): ``∂Q_i/∂x = −k_s J_Pᵀ n``, ``∂Q_j/∂x = k_s J_Qᵀ n``,
    ``∂Q_x/∂δw_i = −k_s nᵀ J_P``, ``∂Q_x/∂δw_j = k_s nᵀ J_Q``, ``∂Q_x/∂x = −k_s``,
    ``∂Q_x/∂ẋ = −c``.

    Parameters
    ----------
    point_i, point_j : array_like, shape (d,)
        Global positions of P and Q at build [m] (distinct).
    stiffness : float
        k_s [N/m], ≥ 0.
    damping : float
        c [N s/m], ≥ 0.
    node : str
        Name of the extra coordinate x (it must have a mass > 0; the builder helper makes it).
    free_length : float, optional
        L_f [m], ≥ 0.
    """

    name: str
    body_i: str
    body_j: str
    point_i: Any
    point_j: Any
    stiffness: float
    damping: float
    node: str
    free_length: float | None = None

    @classmethod
    def compile(cls, elements, ctx):
        return SeriesSpringDamperKind(elements, ctx)


class SeriesSpringDamperKind(ForceKind):
    """All :class:`SeriesSpringDamper` elements of a model."""

    def __init__(self, elements: list[SeriesSpringDamper], ctx):
        d = ctx.space.dim
        self.names = [e.name for e in elements]
        bi, bj, si, sj, L0 = [], [], [], [], []
        for e in elements:
            a, b = two_bodies(ctx, e)
            pi, pj = np.asarray(e.point_i, float), np.asarray(e.point_j, float)
            if pi.shape != (d,) or pj.shape != (d,) or not (np.all(np.isfinite(pi)) and np.all(np.isfinite(pj))):
                raise ModelError(f"series spring-damper {e.name!r}: points must be {d} finite numbers")
            L = float(np.linalg.norm(pj - pi))
            if L < 1e-9:
                raise ModelError(f"series spring-damper {e.name!r}: the points P and Q coincide "
                                 f"(distance {L:.3g} m): the line of action is undefined")
            bi.append(a)
            bj.append(b)
            si.append(ctx.local_point(a, pi))
            sj.append(ctx.local_point(b, pj))
            L0.append(L if e.free_length is None else nonnegative(e.free_length, "free length", e.name))
        self.bi, self.bj = np.array(bi, np.int64), np.array(bj, np.int64)
        self.si, self.sj = np.array(si), np.array(sj)
        self.k = np.array([nonnegative(e.stiffness, "stiffness", e.name) for e in elements])
        self.c = np.array([nonnegative(e.damping, "damping", e.name) for e in elements])
        self.xk = np.array([ctx.coordinate_index(e.node, e.name) for e in elements], np.int64)
        seen: dict[int, str] = {}
        for e, k in zip(elements, self.xk):
            if int(k) in seen:
                raise ModelError(f"series spring-damper {e.name!r}: node coordinate {e.node!r} is already the node "
                                 f"of {seen[int(k)]!r} (each element needs its own)")
            seen[int(k)] = e.name
        self.xv = np.array([ctx.velocity_index(e.node, e.name) for e in elements], np.int64)
        self.n_bodies = ctx.n_bodies
        self.xq = self.n_bodies * ctx.space.n_q + self.xk  # q index of the node (compiled path)
        self.ls0 = np.array(L0) - ctx.bs0.x[self.xk]  # spring free length ℓ_s0 = L_f − x_0
        self.conservative = not np.any(self.c > 0)

    def _geometry(self, bs):
        dvec = bs.point(self.bj, self.sj) - bs.point(self.bi, self.si)
        L = np.linalg.norm(dvec, axis=1)
        if np.any(L < 1e-12):
            k = int(np.argmin(L))
            raise FloatingPointError(f"series spring-damper {self.names[k]!r}: attachment points coincide "
                                     f"(length {L[k]:.3g} m)")
        return dvec, L, dvec / L[:, None]

    def _tensions(self, bs):
        _, L, u = self._geometry(bs)
        x, xd = bs.x[self.xk], bs.xdot[self.xk]
        return L, u, x, xd, self.k * (L - x - self.ls0), self.c * xd

    def evaluate(self, bs, t):
        _, u, _, _, Fs, Fd = self._tensions(bs)
        F = Fs[:, None] * u  # on P (body i)
        Qi = np.einsum("ndk,nd->nk", point_jacobian(bs, self.bi, self.si), F)
        Qj = -np.einsum("ndk,nd->nk", point_jacobian(bs, self.bj, self.sj), F)
        return ForceEval(np.concatenate([self.bi, self.bj]), np.concatenate([Qi, Qj]), self.xk, Fs - Fd)

    def jacobian(self, bs, t):
        L, u, _, _, Fs, _ = self._tensions(bs)
        dim, nv, nb = bs.space.dim, bs.space.n_v, self.n_bodies
        P = np.eye(dim) - u[:, :, None] * u[:, None, :]
        Kd = self.k[:, None, None] * u[:, :, None] * u[:, None, :] + (Fs / L)[:, None, None] * P
        jac = point_pair_jacobian(bs, self.bi, self.si, self.bj, self.sj, Fs[:, None] * u, Kd,
                                  np.zeros_like(Kd))
        # couplings with the node: g_b = ∂ℓ/∂δw_b (−J_Pᵀn on i, +J_Qᵀn on j), ∂F_s/∂x = −k_s
        gi = -np.einsum("ndk,nd->nk", point_jacobian(bs, self.bi, self.si), u)
        gj = np.einsum("ndk,nd->nk", point_jacobian(bs, self.bj, self.sj), u)
        rows, cols, kq = [], [], []
        for b, g in ((self.bi, gi), (self.bj, gj)):
            on = b < nb  # the ground has no velocity coordinates
            idx = (b[on, None] * nv + np.arange(nv)).ravel()
            val = (self.k[on, None] * g[on]).ravel()
            xv = np.repeat(self.xv[on], nv)
            rows += [idx, xv]  # ∂Q_b/∂x = ∂Q_x/∂δw_b = k_s g_b (symmetric: the spring is conservative)
            cols += [xv, idx]
            kq += [val, val]
        rows.append(self.xv)
        cols.append(self.xv)
        kq.append(-self.k)
        n_body = sum(len(r) for r in rows[:-1])
        kv = np.concatenate([np.zeros(n_body), -self.c])
        jac.entries = (np.concatenate(rows), np.concatenate(cols), np.concatenate(kq), kv)
        return jac

    def potential(self, bs):
        _, L, _ = self._geometry(bs)
        return float(np.sum(0.5 * self.k * (L - bs.x[self.xk] - self.ls0) ** 2))

    def outputs(self, bs, t):
        L, _, x, xd, Fs, Fd = self._tensions(bs)
        return {"length [m]": L, "node [m]": x, "node rate [m/s]": xd, "spring force [N]": Fs,
                "damper force [N]": Fd}

    def compiled(self, layout):
        """Compiled form (:func:`core.compiled.elements.compile_series_spring_dampers`, with its exact
        Jacobian kernel)."""
        from ..compiled.elements import compile_series_spring_dampers

        return compile_series_spring_dampers(self, layout)
