r"""Coordinate algebra shared by the force elements: point Jacobians and element coordinates.

Point forces
------------
A global force ``F`` at the body-fixed point ``s̄`` of body ``b`` acts through the point Jacobian
``J_P = [I, C(s̄)]`` (:func:`point_jacobian`; Nikravesh 1988, Eq. 6.178), ``Q_b = J_Pᵀ F``.  For a
force ``F(d, ḋ)`` between two points, ``d = r_Q − r_P``, :func:`point_pair_jacobian` gives the
exact stiffness and damping blocks including the lever-arm terms ``∂(C(s̄)ᵀF)/∂θ`` and the
dependence of ``ḋ`` on the orientation at fixed angular velocity.

Element coordinates
-------------------
Several elements are springs on scalar *element coordinates* ``x(q)`` built from dot products of
body-fixed vectors and points (:func:`dot1_coordinate`, :func:`dot2_coordinate`,
:func:`atan2_coordinate`, and their combinations).  For one element, with the velocity
coordinates of its two bodies stacked as ``w = (v_i, v_j)`` (2 n_v entries), an
:class:`ElementCoordinate` carries

``x`` (value), ``G = ∂x/∂w`` (gradient along retraction increments), ``H[r, c] = ∂G_r/∂δw_c``,

where δw are retraction increments (global translation, body-frame rotation for spatial bodies;
planar: the angle).  A generalized force ``f(x, ẋ, t)`` acting *against* x (virtual work
``δW = −f δx``) then contributes, exactly (Géradin & Cardona 2001, Ch. 5):

.. math::

    Q = -f\,G^T,\qquad
    \frac{\partial Q}{\partial \delta w} = -\Big(G^T\big(f_x G + f_{\dot x}\,\frac{\partial \dot x}{\partial \delta w}\big) + f H\Big),
    \qquad \frac{\partial \dot x}{\partial \delta w} = w^T H,\qquad
    \frac{\partial Q}{\partial w} = -f_{\dot x}\, G^T G

with ``ẋ = G w`` (body-frame ω held fixed under the increment, as in ``Model.Q_q``)
(:func:`coordinate_forces`, :func:`coordinate_jacobian`).  The rotation derivatives come from the
body algebra of :mod:`core.bodies`: ``∂(A ā)/∂δθ = C(ā)`` and ``∂(C(ā)ᵀF)/∂δθ =
Space.Cdot_T_force``.  Domain packages use the same functions for their own elements.

References
----------
P. E. Nikravesh, *Computer-Aided Analysis of Mechanical Systems*, Prentice Hall, 1988.
M. Géradin, A. Cardona, *Flexible Multibody Dynamics: A Finite Element Approach*, Wiley, 2001.
E. J. Haug, *Computer-Aided Kinematics and Dynamics of Mechanical Systems*, Allyn & Bacon, 1989.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..bodies import BodyStates
from .protocol import ForceEval, ForceJacobian

Array = NDArray[np.float64]
IArray = NDArray[np.int64]

__all__ = [
    "point_jacobian",
    "point_pair_jacobian",
    "ElementCoordinate",
    "dot1_coordinate",
    "dot2_coordinate",
    "atan2_coordinate",
    "stack_coordinates",
    "combine_coordinates",
    "pair_velocity",
    "coordinate_forces",
    "coordinate_jacobian",
    "pair_blocks",
    "batch_matmul",
    "batch_transpose",
]


def point_jacobian(bs: BodyStates, b: IArray, s: Array) -> Array:
    """``J_P = [I, C(s̄)]``, shape (n, d, n_v)."""
    d = bs.space.dim
    n = len(b)
    J = np.zeros((n, d, bs.space.n_v))
    J[:, :, :d] = np.eye(d)
    J[:, :, d:] = bs.C(b, s)
    return J


@dataclass
class ElementCoordinate:
    """Element coordinate(s): value (n, m), gradient G (n, m, 2 n_v), Hessian H (n, m, 2 n_v, 2 n_v)."""

    x: Array
    G: Array
    H: Array


def batch_transpose(C: Array) -> Array:
    return np.swapaxes(C, 1, 2)


def batch_matmul(A: Array, B: Array) -> Array:
    return np.einsum("nij,njk->nik", A, B)


def dot1_coordinate(bs: BodyStates, bi: IArray, ui: Array, bj: IArray, wj: Array) -> ElementCoordinate:
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
    H[:, ri, rj] = batch_matmul(batch_transpose(Cu), Cw)
    H[:, rj, ri] = batch_matmul(batch_transpose(Cw), Cu)
    H[:, rj, rj] = sp_.Cdot_T_force(bs.A[bj], wj, U)
    return ElementCoordinate(np.sum(U * W, 1)[:, None], G[:, None], H[:, None])


def dot2_coordinate(bs: BodyStates, bi: IArray, ui: Array, si: Array, bj: IArray, sj: Array) -> ElementCoordinate:
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
    H[:, ri, ti] = -batch_transpose(Cu)
    H[:, ri, tj] = batch_transpose(Cu)
    H[:, ri, ri] = (sp_.Cdot_T_force(bs.A[bi], ui, D) - batch_matmul(batch_transpose(Cu), Csi)
                    - sp_.Cdot_T_force(bs.A[bi], si, U) - batch_matmul(batch_transpose(Csi), Cu))
    H[:, ri, rj] = batch_matmul(batch_transpose(Cu), Csj)
    H[:, tj, ri] = Cu
    H[:, rj, ri] = batch_matmul(batch_transpose(Csj), Cu)
    H[:, rj, rj] = sp_.Cdot_T_force(bs.A[bj], sj, U)
    return ElementCoordinate(np.sum(U * D, 1)[:, None], G[:, None], H[:, None])


def atan2_coordinate(a: ElementCoordinate, b: ElementCoordinate) -> ElementCoordinate:
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
    return ElementCoordinate(np.arctan2(a.x, b.x), G, H)


def stack_coordinates(coords: list[ElementCoordinate]) -> ElementCoordinate:
    """Concatenate coordinates along the coordinate axis (m)."""
    return ElementCoordinate(np.concatenate([c.x for c in coords], 1), np.concatenate([c.G for c in coords], 1),
                  np.concatenate([c.H for c in coords], 1))


def combine_coordinates(terms: list[tuple[float, ElementCoordinate]]) -> ElementCoordinate:
    x = sum(w * c.x for w, c in terms)
    G = sum(w * c.G for w, c in terms)
    H = sum(w * c.H for w, c in terms)
    return ElementCoordinate(x, G, H)


def pair_velocity(bs: BodyStates, bi: IArray, bj: IArray) -> Array:
    """Stacked velocity coordinates ``(v_i, v_j)``, shape (n, 2 n_v)."""
    return np.concatenate([bs.rdot[bi], bs.w[bi], bs.rdot[bj], bs.w[bj]], 1)


def coordinate_forces(bi: IArray, bj: IArray, c: ElementCoordinate, f: Array, nv: int) -> ForceEval:
    """``Q = −Σ_k f_k G_k`` split into the two body blocks."""
    Q = -np.einsum("nm,nmr->nr", f, c.G)
    return ForceEval(np.concatenate([bi, bj]), np.concatenate([Q[:, :nv], Q[:, nv:]]))


def coordinate_jacobian(bi: IArray, bj: IArray, c: ElementCoordinate, f: Array, f_x: Array, f_xd: Array, w: Array,
                    nv: int) -> ForceJacobian:
    """Exact ``∂Q/∂δw`` and ``∂Q/∂w`` for ``Q = −Σ f_k(x_k, ẋ_k) G_k`` (see the section comment)."""
    xd_q = np.einsum("nr,nmrc->nmc", w, c.H)  # ∂ẋ/∂δw
    dfq = f_x[..., None] * c.G + f_xd[..., None] * xd_q
    Kq = -(np.einsum("nmr,nmc->nrc", c.G, dfq) + np.einsum("nm,nmrc->nrc", f, c.H))
    Kv = -np.einsum("nmr,nm,nmc->nrc", c.G, f_xd, c.G)
    return pair_blocks(bi, bj, Kq, Kv, nv)


def pair_blocks(bi, bj, Kq, Kv, nv) -> ForceJacobian:
    a, b = slice(0, nv), slice(nv, 2 * nv)
    rows = np.concatenate([bi, bi, bj, bj])
    cols = np.concatenate([bi, bj, bi, bj])
    return ForceJacobian(rows, cols,
                         np.concatenate([Kq[:, a, a], Kq[:, a, b], Kq[:, b, a], Kq[:, b, b]]),
                         np.concatenate([Kv[:, a, a], Kv[:, a, b], Kv[:, b, a], Kv[:, b, b]]))


def point_pair_jacobian(bs: BodyStates, bi, si, bj, sj, F, Kd, Cd) -> ForceJacobian:
    """Exact Jacobian of ``Q_i = J_Pᵀ F``, ``Q_j = −J_Qᵀ F`` with ``F(d, ḋ)``, ``d = r_Q − r_P``.

    ``Kd = ∂F/∂d`` and ``Cd = ∂F/∂ḋ`` (n, d, d); includes the lever-arm terms ``∂(Cᵀ F)/∂θ`` and
    the dependence of ḋ on the orientation at fixed angular velocity.
    """
    dim = bs.space.dim
    Jp, Jq = point_jacobian(bs, bi, si), point_jacobian(bs, bj, sj)
    Vp, Vq = np.zeros_like(Jp), np.zeros_like(Jq)
    Vp[:, :, dim:] = bs.space.dvel_dtheta(bs.A[bi], bs.w[bi], si)
    Vq[:, :, dim:] = bs.space.dvel_dtheta(bs.A[bj], bs.w[bj], sj)
    dF_di = -batch_matmul(Kd, Jp) - batch_matmul(Cd, Vp)
    dF_dj = batch_matmul(Kd, Jq) + batch_matmul(Cd, Vq)
    dFv_di, dFv_dj = -batch_matmul(Cd, Jp), batch_matmul(Cd, Jq)
    Kii, Kij = batch_matmul(batch_transpose(Jp), dF_di), batch_matmul(batch_transpose(Jp), dF_dj)
    Kji, Kjj = -batch_matmul(batch_transpose(Jq), dF_di), -batch_matmul(batch_transpose(Jq), dF_dj)
    Kii[:, dim:, dim:] += bs.space.Cdot_T_force(bs.A[bi], si, F)
    Kjj[:, dim:, dim:] += bs.space.Cdot_T_force(bs.A[bj], sj, -F)
    Dii, Dij = batch_matmul(batch_transpose(Jp), dFv_di), batch_matmul(batch_transpose(Jp), dFv_dj)
    Dji, Djj = -batch_matmul(batch_transpose(Jq), dFv_di), -batch_matmul(batch_transpose(Jq), dFv_dj)
    rows = np.concatenate([bi, bi, bj, bj])
    cols = np.concatenate([bi, bj, bi, bj])
    return ForceJacobian(rows, cols, np.concatenate([Kii, Kij, Kji, Kjj]), np.concatenate([Dii, Dij, Dji, Djj]))
