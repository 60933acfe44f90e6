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

Elements: :class:`SpringDamper` (point-to-point, free length > 0), :class:`PointSpring`
(zero free length, vector form), :class:`RotationalSpringDamper`, :class:`Bushing`,
:class:`AppliedForce`, :class:`AppliedTorque`, :class:`PlaneContact` (Lankarani–Nikravesh /
Flores / Hunt–Crossley continuous contact).  All supply exact Jacobians (PlaneContact only
without friction).

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


# ============================================================================================
# Generalized-coordinate machinery shared by the elements below
# ============================================================================================
#
# Several elements are linear (or scalar non-linear) springs on scalar *element coordinates*
# x(q) built from dot products of body-fixed vectors and points.  For one element, with the
# velocity coordinates of its two bodies stacked as ``w = (v_i, v_j)`` (2 n_v entries), we carry
#
#   x (value), G = ∂x/∂w (gradient along retraction increments), H[r, c] = ∂G_r/∂δw_c,
#
# where δw are retraction increments (global translation, body-frame rotation for spatial
# bodies; planar: the angle).  A generalized force ``f(x, ẋ, t)`` acting *against* x
# (virtual work δW = −f δx) then contributes, exactly (Géradin & Cardona 2001, Ch. 5):
#
#   Q = −f Gᵀ,  ∂Q/∂δw = −(Gᵀ (f_x G + f_ẋ ∂ẋ/∂δw) + f H),  ∂ẋ/∂δw = wᵀ H,  ∂Q/∂w = −f_ẋ GᵀG,
#
# with ``ẋ = G w`` (body-frame ω held fixed under the increment, as in ``Model.Q_q``).
# The blocks of the rotation derivatives come from the body algebra of :mod:`core.bodies`:
# ``∂(A ā)/∂δθ = C(ā)`` and ``∂(C(ā)ᵀF)/∂δθ`` = ``Space.Cdot_T_force``.


@dataclass
class _Coord:
    """Element coordinate(s): value (n, m), gradient G (n, m, 2 n_v), Hessian H (n, m, 2 n_v, 2 n_v)."""

    x: Array
    G: Array
    H: Array


def _T(C: Array) -> Array:
    return np.swapaxes(C, 1, 2)


def _mm(A: Array, B: Array) -> Array:
    return np.einsum("nij,njk->nik", A, B)


def _dot_coord(bs: BodyStates, bi: IArray, ui: Array, bj: IArray, wj: Array) -> _Coord:
    r"""``x = (A_i ū_i)ᵀ (A_j w̄_j)`` (dot-1) with exact gradient and Hessian blocks.

    ``G_i = [0, C_i(ū)ᵀ w_j]``, ``G_j = [0, C_j(w̄)ᵀ u_i]``; ``H_ii = ∂(C_i(ū)ᵀ w_j)/∂θ_i``,
    ``H_ij = C_i(ū)ᵀ C_j(w̄)``, ``H_ji = C_j(w̄)ᵀ C_i(ū)``, ``H_jj = ∂(C_j(w̄)ᵀ u_i)/∂θ_j``.
    """
    sp_ = bs.space
    d, nv = sp_.dim, sp_.n_v
    n = len(bi)
    U, W = bs.vector(bi, ui), bs.vector(bj, wj)
    Cu, Cw = bs.C(bi, ui), bs.C(bj, wj)
    G = np.zeros((n, 2 * nv))
    H = np.zeros((n, 2 * nv, 2 * nv))
    ri, rj = slice(d, nv), slice(nv + d, 2 * nv)
    G[:, ri] = np.einsum("ndk,nd->nk", Cu, W)
    G[:, rj] = np.einsum("ndk,nd->nk", Cw, U)
    H[:, ri, ri] = sp_.Cdot_T_force(bs.A[bi], ui, W)
    H[:, ri, rj] = _mm(_T(Cu), Cw)
    H[:, rj, ri] = _mm(_T(Cw), Cu)
    H[:, rj, rj] = sp_.Cdot_T_force(bs.A[bj], wj, U)
    return _Coord(np.sum(U * W, 1)[:, None], G[:, None], H[:, None])


def _dot2_coord(bs: BodyStates, bi: IArray, ui: Array, si: Array, bj: IArray, sj: Array) -> _Coord:
    r"""``x = (A_i ū_i)ᵀ (r_Q − r_P)`` (dot-2; P on i at s̄_i, Q on j at s̄_j), exact G and H.

    ``G_i = [−u, C_i(ū)ᵀd − C_i(s̄_i)ᵀu]``, ``G_j = [u, C_j(s̄_j)ᵀu]``; H by differentiating
    each block once more (translation increments are global, rotation increments body-frame).
    """
    sp_ = bs.space
    d, nv = sp_.dim, sp_.n_v
    n = len(bi)
    U = bs.vector(bi, ui)
    D = bs.point(bj, sj) - bs.point(bi, si)
    Cu, Csi, Csj = bs.C(bi, ui), bs.C(bi, si), bs.C(bj, sj)
    ti, ri = slice(0, d), slice(d, nv)
    tj, rj = slice(nv, nv + d), slice(nv + d, 2 * nv)
    G = np.zeros((n, 2 * nv))
    G[:, ti] = -U
    G[:, ri] = np.einsum("ndk,nd->nk", Cu, D) - np.einsum("ndk,nd->nk", Csi, U)
    G[:, tj] = U
    G[:, rj] = np.einsum("ndk,nd->nk", Csj, U)
    H = np.zeros((n, 2 * nv, 2 * nv))
    H[:, ti, ri] = -Cu
    H[:, ri, ti] = -_T(Cu)
    H[:, ri, tj] = _T(Cu)
    H[:, ri, ri] = (sp_.Cdot_T_force(bs.A[bi], ui, D) - _mm(_T(Cu), Csi)
                    - sp_.Cdot_T_force(bs.A[bi], si, U) - _mm(_T(Csi), Cu))
    H[:, ri, rj] = _mm(_T(Cu), Csj)
    H[:, tj, ri] = Cu
    H[:, rj, ri] = _mm(_T(Csj), Cu)
    H[:, rj, rj] = sp_.Cdot_T_force(bs.A[bj], sj, U)
    return _Coord(np.sum(U * D, 1)[:, None], G[:, None], H[:, None])


def _atan2_coord(a: _Coord, b: _Coord) -> _Coord:
    r"""``θ = atan2(a, b)`` of two scalar coordinates, with ``ρ² = a² + b²``.

    ``G = (b G_a − a G_b)/ρ²``,
    ``H = (b H_a − a H_b + G_a⊗G_b − G_b⊗G_a)/ρ² − 2 G⊗(a G_a + b G_b)/ρ²`` (``(x⊗y)_{rc} = x_r y_c``).
    """
    av, bv = a.x[..., None], b.x[..., None]
    rho2 = av * av + bv * bv
    G = (bv * a.G - av * b.G) / rho2
    outer = lambda x, y: x[..., :, None] * y[..., None, :]  # noqa: E731
    H = (bv[..., None] * a.H - av[..., None] * b.H + outer(a.G, b.G) - outer(b.G, a.G)) / rho2[..., None]
    H -= 2.0 * outer(G, av * a.G + bv * b.G) / rho2[..., None]
    return _Coord(np.arctan2(a.x, b.x), G, H)


def _stack(coords: list[_Coord]) -> _Coord:
    """Concatenate coordinates along the coordinate axis (m)."""
    return _Coord(np.concatenate([c.x for c in coords], 1), np.concatenate([c.G for c in coords], 1),
                  np.concatenate([c.H for c in coords], 1))


def _lincomb(terms: list[tuple[float, _Coord]]) -> _Coord:
    x = sum(w * c.x for w, c in terms)
    G = sum(w * c.G for w, c in terms)
    H = sum(w * c.H for w, c in terms)
    return _Coord(x, G, H)


def _pair_velocity(bs: BodyStates, bi: IArray, bj: IArray) -> Array:
    """Stacked velocity coordinates ``(v_i, v_j)``, shape (n, 2 n_v)."""
    return np.concatenate([bs.rdot[bi], bs.w[bi], bs.rdot[bj], bs.w[bj]], 1)


def _coord_forces(bi: IArray, bj: IArray, c: _Coord, f: Array, nv: int) -> ForceEval:
    """``Q = −Σ_k f_k G_k`` split into the two body blocks."""
    Q = -np.einsum("nm,nmr->nr", f, c.G)
    return ForceEval(np.concatenate([bi, bj]), np.concatenate([Q[:, :nv], Q[:, nv:]]))


def _coord_jacobian(bi: IArray, bj: IArray, c: _Coord, f: Array, f_x: Array, f_xd: Array, w: Array,
                    nv: int) -> ForceJacobian:
    """Exact ``∂Q/∂δw`` and ``∂Q/∂w`` for ``Q = −Σ f_k(x_k, ẋ_k) G_k`` (see the section comment)."""
    xd_q = np.einsum("nr,nmrc->nmc", w, c.H)  # ∂ẋ/∂δw
    dfq = f_x[..., None] * c.G + f_xd[..., None] * xd_q
    Kq = -(np.einsum("nmr,nmc->nrc", c.G, dfq) + np.einsum("nm,nmrc->nrc", f, c.H))
    Kv = -np.einsum("nmr,nm,nmc->nrc", c.G, f_xd, c.G)
    return _split_pair_blocks(bi, bj, Kq, Kv, nv)


def _split_pair_blocks(bi, bj, Kq, Kv, nv) -> ForceJacobian:
    a, b = slice(0, nv), slice(nv, 2 * nv)
    rows = np.concatenate([bi, bi, bj, bj])
    cols = np.concatenate([bi, bj, bi, bj])
    return ForceJacobian(rows, cols,
                         np.concatenate([Kq[:, a, a], Kq[:, a, b], Kq[:, b, a], Kq[:, b, b]]),
                         np.concatenate([Kv[:, a, a], Kv[:, a, b], Kv[:, b, a], Kv[:, b, b]]))


def _nonneg(value, what: str, element: str) -> float:
    x = float(value)
    if not (np.isfinite(x) and x >= 0):
        raise ValueError(f"{element!r}: {what} must be a finite number ≥ 0, got {value}")
    return x


def _per_axis(value, n: int, what: str, element: str) -> Array:
    """A scalar or ``n`` non-negative finite numbers."""
    a = np.asarray(value, float)
    if a.ndim == 0:
        a = np.full(n, float(a))
    if a.shape != (n,) or not np.all(np.isfinite(a)) or np.any(a < 0):
        raise ValueError(f"{element!r}: {what} must be a number or {n} numbers, all finite and ≥ 0, got {np.asarray(value).tolist()}")
    return a


def _two_bodies(ctx, e) -> tuple[int, int]:
    bi, bj = ctx.index(e.body_i, e.name), ctx.index(e.body_j, e.name)
    if bi == bj:
        raise ValueError(f"force element {e.name!r} connects body {e.body_i!r} to itself")
    return bi, bj


def _time_components(values, n: int, element: str, what: str):
    """Split ``n`` components into constants (array) and time functions (list of (k, TimeFunction))."""
    if isinstance(values, (str, bytes)) or not hasattr(values, "__len__") or len(values) != n:
        raise ValueError(f"{element!r}: {what} must be a sequence of {n} components (each a number, a callable "
                         f"f(t), a (times, values) table or a TimeFunction), got {values!r}")
    comps = list(values)
    const = np.zeros(n)
    funcs = []
    for k, c in enumerate(comps):
        if isinstance(c, (int, float, np.floating, np.integer)):
            if not np.isfinite(c):
                raise ValueError(f"{element!r}: {what} component {k} is not finite ({c})")
            const[k] = float(c)
        else:
            funcs.append((k, as_time_function(c, f"{what} component {k} of {element!r}")))
    return const, funcs


def _eval_components(const: Array, funcs: list, t: float) -> Array:
    out = const.copy()
    for k, fn in funcs:
        out[k] = fn(t)[0]
    return out


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


def _point_pair_jacobian(bs: BodyStates, bi, si, bj, sj, F, Kd, Cd) -> ForceJacobian:
    """Exact Jacobian of ``Q_i = J_Pᵀ F``, ``Q_j = −J_Qᵀ F`` with ``F(d, ḋ)``, ``d = r_Q − r_P``.

    ``Kd = ∂F/∂d`` and ``Cd = ∂F/∂ḋ`` (n, d, d); includes the lever-arm terms ``∂(Cᵀ F)/∂θ`` and
    the dependence of ḋ on the orientation at fixed angular velocity.
    """
    dim = bs.space.dim
    Jp, Jq = _point_jac(bs, bi, si), _point_jac(bs, bj, sj)
    Vp, Vq = np.zeros_like(Jp), np.zeros_like(Jq)
    Vp[:, :, dim:] = bs.space.dvel_dtheta(bs.A[bi], bs.w[bi], si)
    Vq[:, :, dim:] = bs.space.dvel_dtheta(bs.A[bj], bs.w[bj], sj)
    dF_di = -_mm(Kd, Jp) - _mm(Cd, Vp)
    dF_dj = _mm(Kd, Jq) + _mm(Cd, Vq)
    dFv_di, dFv_dj = -_mm(Cd, Jp), _mm(Cd, Jq)
    Kii, Kij = _mm(_T(Jp), dF_di), _mm(_T(Jp), dF_dj)
    Kji, Kjj = -_mm(_T(Jq), dF_di), -_mm(_T(Jq), dF_dj)
    Kii[:, dim:, dim:] += bs.space.Cdot_T_force(bs.A[bi], si, F)
    Kjj[:, dim:, dim:] += bs.space.Cdot_T_force(bs.A[bj], sj, -F)
    Dii, Dij = _mm(_T(Jp), dFv_di), _mm(_T(Jp), dFv_dj)
    Dji, Djj = -_mm(_T(Jq), dFv_di), -_mm(_T(Jq), dFv_dj)
    rows = np.concatenate([bi, bi, bj, bj])
    cols = np.concatenate([bi, bj, bi, bj])
    return ForceJacobian(rows, cols, np.concatenate([Kii, Kij, Kji, Kjj]), np.concatenate([Dii, Dij, Dji, Djj]))


class PointSpringKind(ForceKind):
    """All :class:`PointSpring` elements of a model."""

    def __init__(self, elements: list[PointSpring], ctx):
        d = ctx.space.dim
        self.names = [e.name for e in elements]
        bi, bj, si, sj = [], [], [], []
        for e in elements:
            a, b = _two_bodies(ctx, e)
            pi = np.asarray(e.point_i, float)
            pj = pi if e.point_j is None else np.asarray(e.point_j, float)
            if pi.shape != (d,) or pj.shape != (d,) or not (np.all(np.isfinite(pi)) and np.all(np.isfinite(pj))):
                raise ValueError(f"point spring {e.name!r}: points must be {d} finite numbers")
            bi.append(a)
            bj.append(b)
            si.append(ctx.local_point(a, pi))
            sj.append(ctx.local_point(b, pj))
        self.bi, self.bj = np.array(bi, np.int64), np.array(bj, np.int64)
        self.si, self.sj = np.array(si), np.array(sj)
        self.k = np.array([_nonneg(e.stiffness, "stiffness", e.name) for e in elements])
        self.c = np.array([_nonneg(e.damping, "damping", e.name) for e in elements])
        self.conservative = not np.any(self.c > 0)

    def _F(self, bs):
        d = bs.point(self.bj, self.sj) - bs.point(self.bi, self.si)
        dd = bs.point_velocity(self.bj, self.sj) - bs.point_velocity(self.bi, self.si)
        return d, self.k[:, None] * d + self.c[:, None] * dd

    def evaluate(self, bs, t):
        _, F = self._F(bs)
        Qi = np.einsum("ndk,nd->nk", _point_jac(bs, self.bi, self.si), F)
        Qj = -np.einsum("ndk,nd->nk", _point_jac(bs, self.bj, self.sj), F)
        return ForceEval(np.concatenate([self.bi, self.bj]), np.concatenate([Qi, Qj]))

    def jacobian(self, bs, t):
        _, F = self._F(bs)
        I = np.eye(bs.space.dim)
        return _point_pair_jacobian(bs, self.bi, self.si, self.bj, self.sj, F,
                                    self.k[:, None, None] * I, self.c[:, None, None] * I)

    def potential(self, bs):
        d = bs.point(self.bj, self.sj) - bs.point(self.bi, self.si)
        return float(np.sum(0.5 * self.k * np.sum(d * d, 1)))

    def outputs(self, bs, t):
        d, F = self._F(bs)
        return {"elongation [m]": np.linalg.norm(d, axis=1), "force [N]": np.linalg.norm(F, axis=1)}


# --------------------------------------------------------------------------------------------
# rotational spring-damper-actuator
# --------------------------------------------------------------------------------------------


def _relative_angle_markers(ctx, bi: int, bj: int, axis) -> tuple[Array, Array, Array]:
    """Body-fixed markers ``f̄_i, ḡ_i`` (on i) and ``f̄_j`` (on j), coincident at build."""
    from .joints import perpendicular_triad

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
            a, b = _two_bodies(ctx, e)
            if ctx.space.dim == 3 and e.axis is None:
                raise ValueError(f"rotational spring-damper {e.name!r}: a spatial model needs the rotation axis")
            try:
                m = _relative_angle_markers(ctx, a, b, e.axis)
            except ValueError as err:
                raise ValueError(f"rotational spring-damper {e.name!r}: {err}") from None
            bi.append(a)
            bj.append(b)
            fi.append(m[0])
            gi.append(m[1])
            fj.append(m[2])
        self.bi, self.bj = np.array(bi, np.int64), np.array(bj, np.int64)
        self.fi, self.gi, self.fj = np.array(fi), np.array(gi), np.array(fj)
        self.k = np.array([_nonneg(e.stiffness, "stiffness", e.name) for e in elements])
        self.c = np.array([_nonneg(e.damping, "damping", e.name) for e in elements])
        self.theta0 = np.array([float(e.free_angle) for e in elements])
        if not np.all(np.isfinite(self.theta0)):
            raise ValueError(f"rotational spring-damper {self.names[int(np.argmax(~np.isfinite(self.theta0)))]!r}: free angle not finite")
        self.act = [None if e.actuator is None else as_time_function(e.actuator, f"actuator of {e.name!r}") for e in elements]
        self.has_act = any(a is not None for a in self.act)
        self.conservative = not (np.any(self.c > 0) or self.has_act)

    def _coord(self, bs):
        a = _dot_coord(bs, self.bi, self.gi, self.bj, self.fj)
        b = _dot_coord(bs, self.bi, self.fi, self.bj, self.fj)
        return _atan2_coord(a, b)

    def _torque(self, bs, t, c):
        w = _pair_velocity(bs, self.bi, self.bj)
        thd = np.einsum("nmr,nr->nm", c.G, w)[:, 0]
        ta = 0.0 if not self.has_act else np.array([0.0 if a is None else a(t)[0] for a in self.act])
        dth = np.arctan2(np.sin(c.x[:, 0] - self.theta0), np.cos(c.x[:, 0] - self.theta0))
        return dth, thd, self.k * dth + self.c * thd + ta, w

    def evaluate(self, bs, t):
        c = self._coord(bs)
        _, _, T, _ = self._torque(bs, t, c)
        return _coord_forces(self.bi, self.bj, c, T[:, None], bs.space.n_v)

    def jacobian(self, bs, t):
        c = self._coord(bs)
        _, _, T, w = self._torque(bs, t, c)
        return _coord_jacobian(self.bi, self.bj, c, T[:, None], self.k[:, None], self.c[:, None], w, bs.space.n_v)

    def potential(self, bs):
        c = self._coord(bs)
        dth = np.arctan2(np.sin(c.x[:, 0] - self.theta0), np.cos(c.x[:, 0] - self.theta0))
        return float(np.sum(0.5 * self.k * dth**2))

    def outputs(self, bs, t):
        c = self._coord(bs)
        dth, thd, T, _ = self._torque(bs, t, c)
        return {"angle [rad]": c.x[:, 0], "torque [N m]": T}


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
            a, b = _two_bodies(ctx, e)
            p = np.asarray(e.at, float)
            q = p if e.point_j is None else np.asarray(e.point_j, float)
            if p.shape != (d,) or q.shape != (d,) or not (np.all(np.isfinite(p)) and np.all(np.isfinite(q))):
                raise ValueError(f"bushing {e.name!r}: 'at' and 'point_j' must be {d} finite numbers")
            ax = np.eye(d) if e.axes is None else np.asarray(e.axes, float)
            if ax.shape != (d, d) or not np.allclose(ax.T @ ax, np.eye(d), atol=1e-9) or np.linalg.det(ax) < 0:
                raise ValueError(f"bushing {e.name!r}: axes must be a proper {d}×{d} rotation matrix (columns = marker axes)")
            bi.append(a)
            bj.append(b)
            si.append(ctx.local_point(a, p))
            sj.append(ctx.local_point(b, q))
            Mi.append(ctx.bs0.A[a].T @ ax)
            Mj.append(ctx.bs0.A[b].T @ ax)
            K.append(np.concatenate([_per_axis(e.translational_stiffness, d, "translational stiffness", e.name),
                                     _per_axis(e.rotational_stiffness, nr, "rotational stiffness", e.name)]))
            C.append(np.concatenate([_per_axis(e.translational_damping, d, "translational damping", e.name),
                                     _per_axis(e.rotational_damping, nr, "rotational damping", e.name)]))
        self.bi, self.bj = np.array(bi, np.int64), np.array(bj, np.int64)
        self.si, self.sj = np.array(si), np.array(sj)
        self.Mi, self.Mj = np.array(Mi), np.array(Mj)  # body-fixed marker axes (columns)
        self.K, self.C = np.array(K), np.array(C)
        self.conservative = not np.any(self.C > 0)
        self.x0 = self._coord(ctx.bs0).x

    def _coord(self, bs) -> _Coord:
        d = bs.space.dim
        mi = lambda k: self.Mi[:, :, k]  # noqa: E731
        mj = lambda k: self.Mj[:, :, k]  # noqa: E731
        trans = [_dot2_coord(bs, self.bi, mi(k), self.si, self.bj, self.sj) for k in range(d)]
        R = lambda a, b: _dot_coord(bs, self.bi, mi(a), self.bj, mj(b))  # noqa: E731
        if d == 2:
            rot = [_atan2_coord(R(1, 0), R(0, 0))]
        else:
            rot = [_lincomb([(0.5, R(2, 1)), (-0.5, R(1, 2))]),
                   _lincomb([(0.5, R(0, 2)), (-0.5, R(2, 0))]),
                   _lincomb([(0.5, R(1, 0)), (-0.5, R(0, 1))])]
        return _stack(trans + rot)

    def _force(self, bs, c):
        w = _pair_velocity(bs, self.bi, self.bj)
        delta = c.x - self.x0
        if bs.space.dim == 2:
            delta[:, 2] = np.arctan2(np.sin(delta[:, 2]), np.cos(delta[:, 2]))
        dd = np.einsum("nmr,nr->nm", c.G, w)
        return delta, dd, self.K * delta + self.C * dd, w

    def evaluate(self, bs, t):
        c = self._coord(bs)
        _, _, f, _ = self._force(bs, c)
        return _coord_forces(self.bi, self.bj, c, f, bs.space.n_v)

    def jacobian(self, bs, t):
        c = self._coord(bs)
        _, _, f, w = self._force(bs, c)
        return _coord_jacobian(self.bi, self.bj, c, f, self.K, self.C, w, bs.space.n_v)

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


# --------------------------------------------------------------------------------------------
# applied loads
# --------------------------------------------------------------------------------------------


def _check_frame(frame: str, element: str) -> None:
    if frame not in ("global", "body"):
        raise ValueError(f"{element!r}: frame must be 'global' or 'body', got {frame!r}")


@dataclass(frozen=True)
class AppliedForce(ForceElement):
    r"""Force of time applied at a body point (action only; no reaction body).

    .. math::

        F(t) = F_g(t) \;(\text{frame='global'}) \quad\text{or}\quad F(t) = A \bar F(t)
        \;(\text{frame='body'}),\qquad Q = J_P^T F = [F;\ C(\bar s)^T F]

    (Nikravesh 1988, Eq. 6.178).  Each of the d components is a number, a callable f(t), a
    ``(times, values)`` table (cubic spline) or a :class:`core.drivers.TimeFunction`.
    Exact Jacobian: global force ``∂Q/∂θ = ∂(C(s̄)ᵀF)/∂θ``; body-fixed force
    ``∂F/∂θ = C(F̄)`` with a constant moment ``C(s̄)ᵀ A F̄``.

    Parameters
    ----------
    body : str
    point : array_like, shape (d,)
        Global point of application at build [m].
    force : sequence of d components
        [N].
    frame : {'global', 'body'}
    """

    name: str
    body: str
    point: Any
    force: Any
    frame: str = "global"

    @classmethod
    def compile(cls, elements, ctx):
        return AppliedForceKind(elements, ctx)


class AppliedForceKind(ForceKind):
    """All :class:`AppliedForce` elements of a model."""

    conservative = False

    def __init__(self, elements: list[AppliedForce], ctx):
        d = ctx.space.dim
        self.names = [e.name for e in elements]
        b, s, const, funcs, body_frame = [], [], [], [], []
        for e in elements:
            k = ctx.index(e.body, e.name)
            if k == len(ctx.bs0.r) - 1:
                raise ValueError(f"applied force {e.name!r}: cannot act on the ground")
            _check_frame(e.frame, e.name)
            p = np.asarray(e.point, float)
            if p.shape != (d,) or not np.all(np.isfinite(p)):
                raise ValueError(f"applied force {e.name!r}: point must be {d} finite numbers")
            c, f = _time_components(e.force, d, e.name, "force")
            b.append(k)
            s.append(ctx.local_point(k, p))
            const.append(c)
            funcs.append(f)
            body_frame.append(e.frame == "body")
        self.b = np.array(b, np.int64)
        self.s = np.array(s)
        self.const = np.array(const)
        self.funcs = funcs
        self.body_frame = np.array(body_frame)

    def _F(self, bs, t):
        Fc = np.array([_eval_components(c, f, t) for c, f in zip(self.const, self.funcs)])
        Fg = Fc.copy()
        if np.any(self.body_frame):
            bf = self.body_frame
            Fg[bf] = bs.vector(self.b[bf], Fc[bf])
        return Fc, Fg

    def evaluate(self, bs, t):
        _, F = self._F(bs, t)
        return ForceEval(self.b, np.einsum("ndk,nd->nk", _point_jac(bs, self.b, self.s), F))

    def jacobian(self, bs, t):
        Fc, Fg = self._F(bs, t)
        d, nv = bs.space.dim, bs.space.n_v
        n = len(self.b)
        Kq = np.zeros((n, nv, nv))
        g = ~self.body_frame
        if np.any(g):
            Kq[g, d:, d:] = bs.space.Cdot_T_force(bs.A[self.b[g]], self.s[g], Fg[g])
        if np.any(self.body_frame):
            bf = self.body_frame
            Kq[bf, :d, d:] = bs.C(self.b[bf], Fc[bf])
        return ForceJacobian(self.b, self.b, Kq, np.zeros((n, nv, nv)))

    def outputs(self, bs, t):
        _, F = self._F(bs, t)
        return {f"F{a} [N]": F[:, k] for k, a in enumerate("xyz"[: bs.space.dim])}


@dataclass(frozen=True)
class AppliedTorque(ForceElement):
    r"""Torque of time applied to a body (action only).

    Planar: a scalar torque ``T(t)``, ``Q_θ = T``.  Spatial: a torque vector ``T_g(t)`` in
    global axes (frame='global') giving the body-frame moment ``Q_ω = Aᵀ T_g`` with the exact
    Jacobian ``∂(AᵀT_g)/∂θ = (AᵀT_g)~``, or ``T̄(t)`` in body axes (frame='body'),
    ``Q_ω = T̄`` (Nikravesh 1988, Sec. 6.6).  Components as for :class:`AppliedForce`.

    Parameters
    ----------
    body : str
    torque : number/function (planar) or sequence of 3 components (spatial)
        [N m].
    frame : {'global', 'body'}
    """

    name: str
    body: str
    torque: Any
    frame: str = "global"

    @classmethod
    def compile(cls, elements, ctx):
        return AppliedTorqueKind(elements, ctx)


class AppliedTorqueKind(ForceKind):
    """All :class:`AppliedTorque` elements of a model."""

    conservative = False

    def __init__(self, elements: list[AppliedTorque], ctx):
        nr = ctx.space.n_v - ctx.space.dim
        self.names = [e.name for e in elements]
        b, const, funcs, body_frame = [], [], [], []
        for e in elements:
            k = ctx.index(e.body, e.name)
            if k == len(ctx.bs0.r) - 1:
                raise ValueError(f"applied torque {e.name!r}: cannot act on the ground")
            _check_frame(e.frame, e.name)
            tq = e.torque
            if nr == 1 and not (isinstance(tq, (list, np.ndarray)) and np.ndim(tq) == 1 and len(tq) == 1):
                tq = [tq]
            c, f = _time_components(tq, nr, e.name, "torque")
            b.append(k)
            const.append(c)
            funcs.append(f)
            body_frame.append(e.frame == "body")
        self.b = np.array(b, np.int64)
        self.const = np.array(const)
        self.funcs = funcs
        self.body_frame = np.array(body_frame)

    def _T(self, bs, t):
        Tc = np.array([_eval_components(c, f, t) for c, f in zip(self.const, self.funcs)])
        Tb = Tc.copy()
        if bs.space.dim == 3:
            g = ~self.body_frame
            Tb[g] = np.einsum("nji,nj->ni", bs.A[self.b[g]], Tc[g])
        return Tc, Tb

    def evaluate(self, bs, t):
        d, nv = bs.space.dim, bs.space.n_v
        _, Tb = self._T(bs, t)
        Q = np.zeros((len(self.b), nv))
        Q[:, d:] = Tb
        return ForceEval(self.b, Q)

    def jacobian(self, bs, t):
        from .frames import skew

        d, nv = bs.space.dim, bs.space.n_v
        n = len(self.b)
        Kq = np.zeros((n, nv, nv))
        if d == 3:
            _, Tb = self._T(bs, t)
            g = ~self.body_frame
            Kq[g, 3:, 3:] = skew(Tb[g])
        return ForceJacobian(self.b, self.b, Kq, np.zeros((n, nv, nv)))

    def outputs(self, bs, t):
        Tc, _ = self._T(bs, t)
        if bs.space.dim == 2:
            return {"Mz [N m]": Tc[:, 0]}
        return {f"M{a} [N m]": Tc[:, k] for k, a in enumerate("xyz")}


# --------------------------------------------------------------------------------------------
# sphere (or point) on a ground plane: continuous contact
# --------------------------------------------------------------------------------------------

_HYSTERESIS = {
    # χ(e) in F = K δ^p (1 + χ δ̇/δ̇⁻)
    "lankarani-nikravesh": lambda e: 0.75 * (1.0 - e * e),
    "flores": lambda e: 8.0 * (1.0 - e) / (5.0 * e),
    "hunt-crossley": lambda e: 1.5 * (1.0 - e),
}


@dataclass(frozen=True)
class PlaneContact(ForceElement):
    r"""Continuous (penalty) contact of a body sphere (or point) with a ground plane.

    Sphere centre C on the body (global position at build ``center``), radius R (0: a point);
    plane through ``plane_point`` with outward unit normal ``n``.  Penetration and its rate:

    .. math::

        δ = R - n^T (r_C - p_0), \qquad \dot δ = -n^T \dot r_C,

    normal force along ``n`` through the centre (for δ > 0, clamped at 0 so the plane never pulls):

    .. math::

        F_n = \max\bigl(0,\ K δ^{p}\,[1 + χ(e)\, \dot δ / \dot δ^{-}]\bigr),

    with χ = 3(1 − e²)/4 (Lankarani & Nikravesh 1990, Eq. 17; ``model='lankarani-nikravesh'``),
    χ = 8(1 − e)/(5e) (Flores et al. 2011, Eq. 24; ``'flores'``) or χ = 3(1 − e)/2 (Hunt &
    Crossley 1975; ``'hunt-crossley'``).  K is the user ``stiffness`` with ``exponent`` p, or
    the Hertz sphere-on-plane value (Johnson 1985, Eq. 4.23) ``K = (4/3) E* √R``,
    ``1/E* = (1−ν₁²)/E₁ + (1−ν₂²)/E₂`` with p = 3/2 from ``materials=((E1, nu1), (E2, nu2))``.

    **Approach velocity.**  Force kinds are stateless functions of (t, q, v) called inside
    integrators (including rejected steps and Newton iterations), so the approach velocity
    δ̇⁻ at the start of each impact is *not* tracked per impact: it is the user parameter
    ``impact_velocity`` (e.g. √(2 g h) for a drop from height h).  The dissipated energy of an
    impact whose actual approach speed differs from it scales like the ratio of the two; choose
    e and ``impact_velocity`` together.

    Optional regularised Coulomb friction at the contact point ``r_C − R n``:
    ``F_t = −μ F_n v_t / √(|v_t|² + v_ε²)``, ``v_t`` the tangential slip velocity.

    The element is conservative (potential ``K δ^{p+1}/(p+1)``) only when e = 1 and μ = 0.
    The Jacobian is exact without friction (F_n non-smooth only at δ = 0, and where the clamp
    acts); with friction ``jacobian`` returns None and the model differentiates numerically.

    References
    ----------
    H. M. Lankarani, P. E. Nikravesh, "A contact force model with hysteresis damping for impact
    analysis of multibody systems", J. Mech. Des. 112 (1990) 369–376.
    P. Flores, M. Machado, M. T. Silva, J. M. Martins, "On the continuous contact force models for
    soft materials in multibody dynamics", Multibody Syst. Dyn. 25 (2011) 357–375.
    K. H. Hunt, F. R. E. Crossley, "Coefficient of restitution interpreted as damping in
    vibroimpact", J. Appl. Mech. 42 (1975) 440–445.
    K. L. Johnson, *Contact Mechanics*, Cambridge University Press, 1985.
    """

    name: str
    body: str
    center: Any
    radius: float
    plane_point: Any
    plane_normal: Any
    restitution: float = 1.0
    impact_velocity: float | None = None
    stiffness: float | None = None
    exponent: float = 1.5
    materials: Any = None
    friction: float = 0.0
    friction_velocity: float = 1e-3
    model: str = "lankarani-nikravesh"

    @classmethod
    def compile(cls, elements, ctx):
        return PlaneContactKind(elements, ctx)


def hertz_sphere_plane_stiffness(radius: float, E1: float, nu1: float, E2: float, nu2: float) -> float:
    r"""``K = (4/3) E* √R`` with ``1/E* = (1−ν₁²)/E₁ + (1−ν₂²)/E₂`` [N/m^1.5] (Johnson 1985, Eq. 4.23)."""
    Estar = 1.0 / ((1 - nu1**2) / E1 + (1 - nu2**2) / E2)
    return 4.0 / 3.0 * Estar * np.sqrt(radius)


class PlaneContactKind(ForceKind):
    """All :class:`PlaneContact` elements of a model."""

    def __init__(self, elements: list[PlaneContact], ctx):
        d = ctx.space.dim
        self.names = [e.name for e in elements]
        nb = len(ctx.bs0.r) - 1
        b, s, p0, n, R, K, p, chi, v0, mu, veps = [], [], [], [], [], [], [], [], [], [], []
        for e in elements:
            k = ctx.index(e.body, e.name)
            if k == nb:
                raise ValueError(f"plane contact {e.name!r}: the sphere must be on a body, not the ground")
            c = np.asarray(e.center, float)
            pp = np.asarray(e.plane_point, float)
            nn = np.asarray(e.plane_normal, float)
            for what, a in (("center", c), ("plane_point", pp), ("plane_normal", nn)):
                if a.shape != (d,) or not np.all(np.isfinite(a)):
                    raise ValueError(f"plane contact {e.name!r}: {what} must be {d} finite numbers, got {np.asarray(a).tolist()}")
            if np.linalg.norm(nn) == 0:
                raise ValueError(f"plane contact {e.name!r}: plane_normal is zero")
            rad = _nonneg(e.radius, "radius", e.name)
            if e.model not in _HYSTERESIS:
                raise ValueError(f"plane contact {e.name!r}: model must be one of {sorted(_HYSTERESIS)}, got {e.model!r}")
            rest = float(e.restitution)
            lo = 0.0 if e.model != "flores" else 1e-12
            if not (lo <= rest <= 1.0) or (e.model == "flores" and rest == 0.0):
                raise ValueError(f"plane contact {e.name!r}: restitution must be in {'(0' if e.model == 'flores' else '[0'}, 1], got {e.restitution}")
            if e.stiffness is not None and e.materials is not None:
                raise ValueError(f"plane contact {e.name!r}: give either stiffness or materials, not both")
            if e.stiffness is not None:
                kk = _nonneg(e.stiffness, "stiffness", e.name)
                ex = float(e.exponent)
                if not (np.isfinite(ex) and ex >= 1.0):
                    raise ValueError(f"plane contact {e.name!r}: exponent must be ≥ 1, got {e.exponent}")
            elif e.materials is not None:
                try:
                    (E1, nu1), (E2, nu2) = e.materials
                    E1, nu1, E2, nu2 = map(float, (E1, nu1, E2, nu2))
                except (TypeError, ValueError):
                    raise ValueError(f"plane contact {e.name!r}: materials must be ((E1, nu1), (E2, nu2))") from None
                if not (E1 > 0 and E2 > 0 and -1 < nu1 < 0.5 + 1e-12 and -1 < nu2 < 0.5 + 1e-12):
                    raise ValueError(f"plane contact {e.name!r}: need E > 0 and −1 < ν ≤ 0.5, got {e.materials}")
                if rad == 0:
                    raise ValueError(f"plane contact {e.name!r}: Hertz stiffness needs radius > 0 (give stiffness for a point)")
                kk, ex = hertz_sphere_plane_stiffness(rad, E1, nu1, E2, nu2), 1.5
            else:
                raise ValueError(f"plane contact {e.name!r}: give stiffness (with exponent) or materials")
            if rest < 1.0:
                if e.impact_velocity is None or not (np.isfinite(e.impact_velocity) and e.impact_velocity > 0):
                    raise ValueError(f"plane contact {e.name!r}: restitution < 1 needs impact_velocity > 0 "
                                     f"(the expected approach speed δ̇⁻ [m/s]), got {e.impact_velocity}")
            b.append(k)
            s.append(ctx.local_point(k, c))
            p0.append(pp)
            n.append(nn / np.linalg.norm(nn))
            R.append(rad)
            K.append(kk)
            p.append(ex)
            chi.append(_HYSTERESIS[e.model](rest) if rest < 1.0 else 0.0)
            v0.append(float(e.impact_velocity) if rest < 1.0 else 1.0)
            mu.append(_nonneg(e.friction, "friction coefficient", e.name))
            ve = float(e.friction_velocity)
            if not (np.isfinite(ve) and ve > 0):
                raise ValueError(f"plane contact {e.name!r}: friction_velocity must be > 0, got {e.friction_velocity}")
            veps.append(ve)
        self.b = np.array(b, np.int64)
        self.ground = np.full(len(b), nb, np.int64)
        self.s = np.array(s)
        self.p0, self.n = np.array(p0), np.array(n)
        self.R, self.K, self.p = np.array(R), np.array(K), np.array(p)
        self.chi, self.v0 = np.array(chi), np.array(v0)
        self.mu, self.veps = np.array(mu), np.array(veps)
        self.conservative = not (np.any(self.chi > 0) or np.any(self.mu > 0))

    def _coord(self, bs) -> _Coord:
        # s = nᵀ(r_C − p_0): dot-2 with i = ground (u = n, P = p_0) and j = the body (Q = C)
        return _dot2_coord(bs, self.ground, self.n, self.p0, self.b, self.s)

    def _normal(self, bs, c):
        w = _pair_velocity(bs, self.ground, self.b)
        sd = np.einsum("nr,nr->n", c.G[:, 0], w)
        delta = self.R - c.x[:, 0]
        ddelta = -sd
        on = delta > 0
        dp = np.where(on, delta, 0.0)
        base = self.K * dp**self.p
        damp = 1.0 + self.chi * ddelta / self.v0
        Fn = base * damp
        active = on & (Fn > 0)
        Fn = np.where(active, Fn, 0.0)
        dF_ddelta = np.where(active, self.p * self.K * np.where(on, dp, 1.0) ** (self.p - 1.0) * damp, 0.0)
        dF_dddelta = np.where(active, base * self.chi / self.v0, 0.0)
        return delta, Fn, dF_ddelta, dF_dddelta, w

    def _friction(self, bs, Fn):
        """Friction force (global, on the body) and body-local contact points."""
        scp = self.s - self.R[:, None] * np.einsum("nji,nj->ni", bs.A[self.b], self.n)
        vcp = bs.point_velocity(self.b, scp)
        vt = vcp - np.sum(vcp * self.n, 1)[:, None] * self.n
        Ft = -(self.mu * Fn / np.sqrt(np.sum(vt * vt, 1) + self.veps**2))[:, None] * vt
        return Ft, scp

    def evaluate(self, bs, t):
        c = self._coord(bs)
        _, Fn, _, _, _ = self._normal(bs, c)
        ev = _coord_forces(self.ground, self.b, c, -Fn[:, None], bs.space.n_v)
        if np.any(self.mu > 0):
            Ft, scp = self._friction(bs, Fn)
            Qt = np.einsum("ndk,nd->nk", _point_jac(bs, self.b, scp), Ft)
            ev = ForceEval(np.concatenate([ev.bodies, self.b]), np.concatenate([ev.Qb, Qt]))
        return ev

    def jacobian(self, bs, t):
        if np.any(self.mu > 0):
            return None
        c = self._coord(bs)
        _, Fn, dF_dd, dF_ddd, w = self._normal(bs, c)
        # f = −F_n as a generalized force against s; δ = R − s, δ̇ = −ṡ
        return _coord_jacobian(self.ground, self.b, c, -Fn[:, None], dF_dd[:, None], dF_ddd[:, None], w, bs.space.n_v)

    def potential(self, bs):
        c = self._coord(bs)
        delta = np.maximum(self.R - c.x[:, 0], 0.0)
        return float(np.sum(self.K * delta ** (self.p + 1.0) / (self.p + 1.0)))

    def outputs(self, bs, t):
        c = self._coord(bs)
        delta, Fn, _, _, _ = self._normal(bs, c)
        out = {"penetration [m]": delta, "normal force [N]": Fn}
        if np.any(self.mu > 0):
            Ft, _ = self._friction(bs, Fn)
            out["friction force [N]"] = np.linalg.norm(Ft, axis=1)
        return out
