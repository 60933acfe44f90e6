r"""Compiled kernels of core's element kinds (constraint primitives, drivers, force elements).

Every kind of :mod:`core.constraints` and :mod:`core.forces` reaches the compiled path through its
``compiled(layout)`` method, which packs its arrays and names the kernel defined here — the same
route a domain kind takes with kernels of its own (:mod:`core.compiled.protocol`).  The
equations are those of the numpy kinds (see there); the kernels evaluate them element by element
with the scalar helpers of :mod:`core.compiled.vector`, and the tests compare both paths to
round-off for every kind, planar and spatial.

Constraint primitives (Haug 1989, Sec. 9.2), ``d = r_Q − r_P``:

=================  ===============================  ======================================================
kind               Φ                                γ
=================  ===============================  ======================================================
point coincidence  ``r_P − r_Q``                    ``−(a^q_P − a^q_Q)``
dot-1              ``a_iᵀ a_j − c``                 ``−(a_jᵀ a^q(ā_i) + a_iᵀ a^q(ā_j) + 2 ȧ_iᵀ ȧ_j)``
dot-2              ``a_iᵀ d − c``                   ``−(dᵀ a^q(ā_i) + 2 ȧ_iᵀ ḋ + a_iᵀ(a^q_Q − a^q_P))``
distance           ``(dᵀd − L²)/(2L)``              ``−(ḋᵀḋ + dᵀ(a^q_Q − a^q_P))/L``
planar angle       ``θ_j − θ_i − c``                ``0``
=================  ===============================  ======================================================

Drivers subtract ``f(t)`` (:mod:`core.compiled.timefunctions`): ``ν = ḟ``, ``γ ⊃ f̈``; the spatial
revolute angle driver ``Φ = cos f (g_iᵀ f_j) − sin f (f_iᵀ f_j)`` as in
:class:`core.constraints.SpatialAngleDriver`.

Forces: zero-length point spring ``F_P = k d + c ḋ``; spring-damper-actuator
``F_P = (k (L − L₀) + c L̇ + f_a(t)) u``; applied force and torque of time (global or body axes);
plane contact ``F_n = max(0, K δᵖ (1 + χ δ̇/δ̇⁻))`` along the plane normal with optional
regularised friction; each applied as ``Q_b += [F; C(s̄)ᵀF]``; bump stop ``f = σ(u) g(|u|) + c u̇``
on a dot-2 coordinate with a tabulated law; spring in series with a damper
``F_s = k_s (ℓ − x − ℓ_s0)``, ``Q_x = F_s − c ẋ`` on its node coordinate.  Exact Jacobian kernels
for the two point-pair springs and the series spring-damper (stiffness and damping blocks with the
lever-arm and velocity-transport terms of :func:`core.forces.coordinates.point_pair_jacobian`, and
the node couplings); the other force kinds are differenced by the implicit integrators.

References
----------
E. J. Haug, *Computer-Aided Kinematics and Dynamics of Mechanical Systems*, 1989.
P. E. Nikravesh, *Computer-Aided Analysis of Mechanical Systems*, 1988.
"""

from __future__ import annotations

import numba
import numpy as np

from . import vector as V
from .protocol import (
    COINCIDENT,
    L_DIM,
    L_NB,
    MAX_SLOTS,
    NONFINITE,
    OK,
    WANT_GAMMA,
    WANT_NU,
    WANT_PHI,
    CompiledConstraints,
    CompiledForces,
    body_slot,
    constraint_kernel,
    force_jacobian_kernel,
    force_kernel,
)
from .timefunctions import encode_rows
from .timefunctions import evaluate as tf_evaluate

_internal = numba.njit(cache=True, fastmath=False, boundscheck=False, no_cpython_wrapper=True, no_cfunc_wrapper=True)


def pad3(a) -> np.ndarray:
    """Vectors of length 2 or 3 (rows of ``a``) as 3-vectors (z = 0 for planar ones)."""
    a = np.atleast_2d(np.asarray(a, float))
    out = np.zeros((a.shape[0], 3))
    out[:, : a.shape[1]] = a
    return out


def _ints(*cols) -> np.ndarray:
    return np.ascontiguousarray(np.column_stack([np.asarray(c, np.int64).reshape(-1) for c in cols]))


def _groups(*cols) -> list:
    """Body groups of one- or two-body elements (:attr:`CompiledForces.groups`): the bodies of each."""
    return _ints(*cols).tolist()


def _pair_slots(bi, bj, rows_per, nb) -> np.ndarray:
    """Slots (two bodies) of ``rows_per`` rows per element."""
    n = len(bi)
    s = np.full((n * rows_per, MAX_SLOTS), -1, np.int64)
    for e in range(n):
        s[e * rows_per:(e + 1) * rows_per, 0] = body_slot(bi[e], nb)
        s[e * rows_per:(e + 1) * rows_per, 1] = body_slot(bj[e], nb)
    return s


# ================================================================================================
# constraint primitives
# ================================================================================================


@constraint_kernel
def point_coincidence(t, q, v, r, A, rd, w, lay, fd, ix, row0, flags, phi, G, nu, gam, err):
    """``r_i + A_i s̄_i − r_j − A_j s̄_j`` (fd: s̄_i, s̄_j; ix: i, j)."""
    dim = lay[L_DIM]
    for e in range(ix.shape[0]):
        bi, bj = ix[e, 0], ix[e, 1]
        r0 = row0 + e * dim
        p0, p1, p2 = fd[e, 0], fd[e, 1], fd[e, 2]
        q0, q1, q2 = fd[e, 3], fd[e, 4], fd[e, 5]
        if flags & WANT_PHI:
            a0, a1, a2 = V.Av(A, bi, p0, p1, p2)
            b0, b1, b2 = V.Av(A, bj, q0, q1, q2)
            phi[r0] = r[bi, 0] + a0 - r[bj, 0] - b0
            phi[r0 + 1] = r[bi, 1] + a1 - r[bj, 1] - b1
            if dim == 3:
                phi[r0 + 2] = r[bi, 2] + a2 - r[bj, 2] - b2
        for i in range(dim):
            ci0, ci1, ci2 = V.cross(p0, p1, p2, A[bi, i, 0], A[bi, i, 1], A[bi, i, 2])
            cj0, cj1, cj2 = V.cross(q0, q1, q2, A[bj, i, 0], A[bj, i, 1], A[bj, i, 2])
            t0 = 1.0 if i == 0 else 0.0
            t1 = 1.0 if i == 1 else 0.0
            t2 = 1.0 if i == 2 else 0.0
            V.put_row(G, r0 + i, 0, dim, t0, t1, t2, ci0, ci1, ci2)
            V.put_row(G, r0 + i, 1, dim, -t0, -t1, -t2, -cj0, -cj1, -cj2)
        if flags & WANT_NU:
            for i in range(dim):
                nu[r0 + i] = 0.0
        if flags & WANT_GAMMA:
            g0, g1, g2 = V.aq(A, w, bi, p0, p1, p2)
            h0, h1, h2 = V.aq(A, w, bj, q0, q1, q2)
            gam[r0] = -(g0 - h0)
            gam[r0 + 1] = -(g1 - h1)
            if dim == 3:
                gam[r0 + 2] = -(g2 - h2)
    return OK


@constraint_kernel
def dot1(t, q, v, r, A, rd, w, lay, fd, ix, row0, flags, phi, G, nu, gam, err):
    """``a_iᵀ a_j − c`` (fd: ā_i, ā_j, c)."""
    dim = lay[L_DIM]
    for e in range(ix.shape[0]):
        bi, bj = ix[e, 0], ix[e, 1]
        r0 = row0 + e
        p0, p1, p2 = fd[e, 0], fd[e, 1], fd[e, 2]
        q0, q1, q2 = fd[e, 3], fd[e, 4], fd[e, 5]
        a0, a1, a2 = V.Av(A, bi, p0, p1, p2)
        b0, b1, b2 = V.Av(A, bj, q0, q1, q2)
        if flags & WANT_PHI:
            phi[r0] = a0 * b0 + a1 * b1 + a2 * b2 - fd[e, 6]
        ci0, ci1, ci2 = V.uC(A, bi, p0, p1, p2, b0, b1, b2)
        cj0, cj1, cj2 = V.uC(A, bj, q0, q1, q2, a0, a1, a2)
        V.put_row(G, r0, 0, dim, 0.0, 0.0, 0.0, ci0, ci1, ci2)
        V.put_row(G, r0, 1, dim, 0.0, 0.0, 0.0, cj0, cj1, cj2)
        if flags & WANT_NU:
            nu[r0] = 0.0
        if flags & WANT_GAMMA:
            g0, g1, g2 = V.aq(A, w, bi, p0, p1, p2)
            h0, h1, h2 = V.aq(A, w, bj, q0, q1, q2)
            x0, x1, x2 = V.vel(A, w, bi, p0, p1, p2)
            y0, y1, y2 = V.vel(A, w, bj, q0, q1, q2)
            gam[r0] = -(b0 * g0 + b1 * g1 + b2 * g2 + a0 * h0 + a1 * h1 + a2 * h2
                        + 2.0 * (x0 * y0 + x1 * y1 + x2 * y2))
    return OK


@constraint_kernel
def dot2(t, q, v, r, A, rd, w, lay, fd, ix, row0, flags, phi, G, nu, gam, err):
    """``a_iᵀ (r_Q − r_P) − c`` (fd: ā_i, s̄_i, s̄_j, c)."""
    dim = lay[L_DIM]
    for e in range(ix.shape[0]):
        bi, bj = ix[e, 0], ix[e, 1]
        r0 = row0 + e
        p0, p1, p2 = fd[e, 0], fd[e, 1], fd[e, 2]
        q0, q1, q2 = fd[e, 3], fd[e, 4], fd[e, 5]
        s0, s1, s2 = fd[e, 6], fd[e, 7], fd[e, 8]
        a0, a1, a2 = V.Av(A, bi, p0, p1, p2)
        d0, d1, d2 = V.rel_point(r, A, bi, q0, q1, q2, bj, s0, s1, s2)
        if flags & WANT_PHI:
            phi[r0] = a0 * d0 + a1 * d1 + a2 * d2 - fd[e, 9]
        x0, x1, x2 = V.uC(A, bi, p0, p1, p2, d0, d1, d2)
        y0, y1, y2 = V.uC(A, bi, q0, q1, q2, a0, a1, a2)
        V.put_row(G, r0, 0, dim, -a0, -a1, -a2, x0 - y0, x1 - y1, x2 - y2)
        z0, z1, z2 = V.uC(A, bj, s0, s1, s2, a0, a1, a2)
        V.put_row(G, r0, 1, dim, a0, a1, a2, z0, z1, z2)
        if flags & WANT_NU:
            nu[r0] = 0.0
        if flags & WANT_GAMMA:
            ad0, ad1, ad2 = V.vel(A, w, bi, p0, p1, p2)
            dd0, dd1, dd2 = V.rel_vel(rd, A, w, bi, q0, q1, q2, bj, s0, s1, s2)
            g0, g1, g2 = V.aq(A, w, bi, p0, p1, p2)
            h0, h1, h2 = V.aq(A, w, bj, s0, s1, s2)
            k0, k1, k2 = V.aq(A, w, bi, q0, q1, q2)
            gam[r0] = -(d0 * g0 + d1 * g1 + d2 * g2 + 2.0 * (ad0 * dd0 + ad1 * dd1 + ad2 * dd2)
                        + a0 * (h0 - k0) + a1 * (h1 - k1) + a2 * (h2 - k2))
    return OK


@constraint_kernel
def distance(t, q, v, r, A, rd, w, lay, fd, ix, row0, flags, phi, G, nu, gam, err):
    """``(dᵀd − L²)/(2L)`` (fd: s̄_i, s̄_j, L)."""
    dim = lay[L_DIM]
    for e in range(ix.shape[0]):
        bi, bj = ix[e, 0], ix[e, 1]
        r0 = row0 + e
        p0, p1, p2 = fd[e, 0], fd[e, 1], fd[e, 2]
        q0, q1, q2 = fd[e, 3], fd[e, 4], fd[e, 5]
        L = fd[e, 6]
        d0, d1, d2 = V.rel_point(r, A, bi, p0, p1, p2, bj, q0, q1, q2)
        if flags & WANT_PHI:
            phi[r0] = (d0 * d0 + d1 * d1 + d2 * d2 - L * L) / (2.0 * L)
        e0, e1, e2 = d0 / L, d1 / L, d2 / L
        x0, x1, x2 = V.uC(A, bi, p0, p1, p2, e0, e1, e2)
        y0, y1, y2 = V.uC(A, bj, q0, q1, q2, e0, e1, e2)
        V.put_row(G, r0, 0, dim, -e0, -e1, -e2, -x0, -x1, -x2)
        V.put_row(G, r0, 1, dim, e0, e1, e2, y0, y1, y2)
        if flags & WANT_NU:
            nu[r0] = 0.0
        if flags & WANT_GAMMA:
            dd0, dd1, dd2 = V.rel_vel(rd, A, w, bi, p0, p1, p2, bj, q0, q1, q2)
            g0, g1, g2 = V.aq(A, w, bj, q0, q1, q2)
            h0, h1, h2 = V.aq(A, w, bi, p0, p1, p2)
            gam[r0] = -(dd0 * dd0 + dd1 * dd1 + dd2 * dd2 + d0 * (g0 - h0) + d1 * (g1 - h1) + d2 * (g2 - h2)) / L
    return OK


@_internal
def _planar_angle(A, b):
    return np.arctan2(A[b, 1, 0], A[b, 0, 0])


@constraint_kernel
def planar_angle(t, q, v, r, A, rd, w, lay, fd, ix, row0, flags, phi, G, nu, gam, err):
    """``θ_j − θ_i − c`` wrapped to (−π, π] (fd: c)."""
    dim = lay[L_DIM]
    for e in range(ix.shape[0]):
        bi, bj = ix[e, 0], ix[e, 1]
        r0 = row0 + e
        if flags & WANT_PHI:
            x = _planar_angle(A, bj) - _planar_angle(A, bi) - fd[e, 0]
            phi[r0] = np.arctan2(np.sin(x), np.cos(x))
        V.put_row(G, r0, 0, dim, 0.0, 0.0, 0.0, 0.0, 0.0, -1.0)
        V.put_row(G, r0, 1, dim, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0)
        if flags & WANT_NU:
            nu[r0] = 0.0
        if flags & WANT_GAMMA:
            gam[r0] = 0.0
    return OK


# --- drivers ----------------------------------------------------------------------------------


@constraint_kernel
def point_position_driver(t, q, v, r, A, rd, w, lay, fd, ix, row0, flags, phi, G, nu, gam, err):
    """``uᵀ(r_P − o) − f(t)`` (fd: s̄, u, o, then the program of f from column 9)."""
    dim = lay[L_DIM]
    for e in range(ix.shape[0]):
        bi = ix[e, 0]
        r0 = row0 + e
        st, f, fdot, fddot = tf_evaluate(fd[e, 9:], t)
        if st != OK:
            err[1] = e
            return st
        s0, s1, s2 = fd[e, 0], fd[e, 1], fd[e, 2]
        u0, u1, u2 = fd[e, 3], fd[e, 4], fd[e, 5]
        if flags & WANT_PHI:
            a0, a1, a2 = V.Av(A, bi, s0, s1, s2)
            phi[r0] = (u0 * (r[bi, 0] + a0 - fd[e, 6]) + u1 * (r[bi, 1] + a1 - fd[e, 7])
                       + u2 * (r[bi, 2] + a2 - fd[e, 8]) - f)
        c0, c1, c2 = V.uC(A, bi, s0, s1, s2, u0, u1, u2)
        V.put_row(G, r0, 0, dim, u0, u1, u2, c0, c1, c2)
        if flags & WANT_NU:
            nu[r0] = fdot
        if flags & WANT_GAMMA:
            g0, g1, g2 = V.aq(A, w, bi, s0, s1, s2)
            gam[r0] = fddot - (u0 * g0 + u1 * g1 + u2 * g2)
    return OK


@constraint_kernel
def planar_angle_driver(t, q, v, r, A, rd, w, lay, fd, ix, row0, flags, phi, G, nu, gam, err):
    """``θ_j − θ_i − c − f(t)`` wrapped (fd: c, then the program of f from column 1)."""
    dim = lay[L_DIM]
    for e in range(ix.shape[0]):
        bi, bj = ix[e, 0], ix[e, 1]
        r0 = row0 + e
        st, f, fdot, fddot = tf_evaluate(fd[e, 1:], t)
        if st != OK:
            err[1] = e
            return st
        if flags & WANT_PHI:
            x = _planar_angle(A, bj) - _planar_angle(A, bi) - fd[e, 0] - f
            phi[r0] = np.arctan2(np.sin(x), np.cos(x))
        V.put_row(G, r0, 0, dim, 0.0, 0.0, 0.0, 0.0, 0.0, -1.0)
        V.put_row(G, r0, 1, dim, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0)
        if flags & WANT_NU:
            nu[r0] = fdot
        if flags & WANT_GAMMA:
            gam[r0] = fddot
    return OK


@_internal
def _dot(a0, a1, a2, b0, b1, b2):
    return a0 * b0 + a1 * b1 + a2 * b2


@constraint_kernel
def spatial_angle_driver(t, q, v, r, A, rd, w, lay, fd, ix, row0, flags, phi, G, nu, gam, err):
    """``cos f (g_iᵀf_j) − sin f (f_iᵀf_j)``, f ← f(t) + c (fd: f̄_i, ḡ_i, f̄_j, c, program from 10)."""
    dim = lay[L_DIM]
    for e in range(ix.shape[0]):
        bi, bj = ix[e, 0], ix[e, 1]
        r0 = row0 + e
        st, f, fdot, fddot = tf_evaluate(fd[e, 10:], t)
        if st != OK:
            err[1] = e
            return st
        f = f + fd[e, 9]
        cf, sf = np.cos(f), np.sin(f)
        fi0, fi1, fi2 = fd[e, 0], fd[e, 1], fd[e, 2]
        gi0, gi1, gi2 = fd[e, 3], fd[e, 4], fd[e, 5]
        fj0, fj1, fj2 = fd[e, 6], fd[e, 7], fd[e, 8]
        Fi0, Fi1, Fi2 = V.Av(A, bi, fi0, fi1, fi2)
        Gi0, Gi1, Gi2 = V.Av(A, bi, gi0, gi1, gi2)
        Fj0, Fj1, Fj2 = V.Av(A, bj, fj0, fj1, fj2)
        a = _dot(Gi0, Gi1, Gi2, Fj0, Fj1, Fj2)
        b = _dot(Fi0, Fi1, Fi2, Fj0, Fj1, Fj2)
        if flags & WANT_PHI:
            phi[r0] = cf * a - sf * b
        ja0, ja1, ja2 = V.uC(A, bi, gi0, gi1, gi2, Fj0, Fj1, Fj2)  # ∂a/∂θ̄_i
        ka0, ka1, ka2 = V.uC(A, bj, fj0, fj1, fj2, Gi0, Gi1, Gi2)  # ∂a/∂θ̄_j
        jb0, jb1, jb2 = V.uC(A, bi, fi0, fi1, fi2, Fj0, Fj1, Fj2)  # ∂b/∂θ̄_i
        kb0, kb1, kb2 = V.uC(A, bj, fj0, fj1, fj2, Fi0, Fi1, Fi2)  # ∂b/∂θ̄_j
        V.put_row(G, r0, 0, dim, 0.0, 0.0, 0.0, cf * ja0 - sf * jb0, cf * ja1 - sf * jb1, cf * ja2 - sf * jb2)
        V.put_row(G, r0, 1, dim, 0.0, 0.0, 0.0, cf * ka0 - sf * kb0, cf * ka1 - sf * kb1, cf * ka2 - sf * kb2)
        if flags & WANT_NU:
            nu[r0] = fdot * (sf * a + cf * b)
        if flags & WANT_GAMMA:
            x0, x1, x2 = V.aq(A, w, bi, gi0, gi1, gi2)
            y0, y1, y2 = V.aq(A, w, bj, fj0, fj1, fj2)
            z0, z1, z2 = V.aq(A, w, bi, fi0, fi1, fi2)
            gd0, gd1, gd2 = V.vel(A, w, bi, gi0, gi1, gi2)
            fd0, fd1, fd2 = V.vel(A, w, bj, fj0, fj1, fj2)
            id0, id1, id2 = V.vel(A, w, bi, fi0, fi1, fi2)
            ga = (_dot(Fj0, Fj1, Fj2, x0, x1, x2) + _dot(Gi0, Gi1, Gi2, y0, y1, y2)
                  + 2.0 * _dot(gd0, gd1, gd2, fd0, fd1, fd2))
            gb = (_dot(Fj0, Fj1, Fj2, z0, z1, z2) + _dot(Fi0, Fi1, Fi2, y0, y1, y2)
                  + 2.0 * _dot(id0, id1, id2, fd0, fd1, fd2))
            adot = _dot(ja0, ja1, ja2, w[bi, 0], w[bi, 1], w[bi, 2]) + _dot(ka0, ka1, ka2, w[bj, 0], w[bj, 1], w[bj, 2])
            bdot = _dot(jb0, jb1, jb2, w[bi, 0], w[bi, 1], w[bi, 2]) + _dot(kb0, kb1, kb2, w[bj, 0], w[bj, 1], w[bj, 2])
            rest = (cf * ga - sf * gb - 2.0 * fdot * (sf * adot + cf * bdot) - fddot * (sf * a + cf * b)
                    - fdot * fdot * (cf * a - sf * b))
            gam[r0] = -rest
    return OK


# --- packing (called by the kinds' compiled() methods) -----------------------------------------


def _primitive(kind, layout, kernel, fd, what, time_dependent=False) -> CompiledConstraints:
    nb = layout.n_bodies
    ix = _ints(kind.bi, kind.bj)
    return CompiledConstraints(kernel=kernel, fd=np.ascontiguousarray(fd, float), ix=ix, rows=kind.n * kind.rows,
                               slots=_pair_slots(kind.bi, kind.bj, kind.rows, nb), names=list(kind.labels),
                               time_dependent=time_dependent, what=what)


def compile_point_coincidence(kind, layout) -> CompiledConstraints:
    return _primitive(kind, layout, point_coincidence, np.hstack([pad3(kind.si), pad3(kind.sj)]), "point coincidence")


def compile_dot1(kind, layout) -> CompiledConstraints:
    return _primitive(kind, layout, dot1, np.hstack([pad3(kind.ai), pad3(kind.aj), np.reshape(kind.c, (-1, 1))]), "dot-1")


def compile_dot2(kind, layout) -> CompiledConstraints:
    fd = np.hstack([pad3(kind.ai), pad3(kind.si), pad3(kind.sj), np.reshape(kind.c, (-1, 1))])
    return _primitive(kind, layout, dot2, fd, "dot-2")


def compile_distance(kind, layout) -> CompiledConstraints:
    fd = np.hstack([pad3(kind.si), pad3(kind.sj), np.reshape(kind.L, (-1, 1))])
    return _primitive(kind, layout, distance, fd, "distance")


def compile_planar_angle(kind, layout) -> CompiledConstraints:
    return _primitive(kind, layout, planar_angle, np.reshape(kind.c, (-1, 1)), "planar angle")


def _programs(kind):
    return encode_rows(kind.functions, [f"driver {lab.split('/')[0]!r}" for lab in kind.labels])


def compile_point_position_driver(kind, layout) -> CompiledConstraints:
    fd = np.hstack([pad3(kind.si), pad3(kind.u), pad3(kind.o), _programs(kind)])
    return _primitive(kind, layout, point_position_driver, fd, "point driver", time_dependent=True)


def compile_planar_angle_driver(kind, layout) -> CompiledConstraints:
    fd = np.hstack([np.reshape(kind.c, (-1, 1)), _programs(kind)])
    return _primitive(kind, layout, planar_angle_driver, fd, "angle driver", time_dependent=True)


def compile_spatial_angle_driver(kind, layout) -> CompiledConstraints:
    fd = np.hstack([pad3(kind.fi), pad3(kind.gi), pad3(kind.fj), np.reshape(kind.c, (-1, 1)), _programs(kind)])
    return _primitive(kind, layout, spatial_angle_driver, fd, "angle driver", time_dependent=True)


# ================================================================================================
# forces
# ================================================================================================


@force_kernel
def point_springs(t, q, v, r, A, rd, w, lay, fd, ix, state, Q, err):
    """``F_P = k d + c ḋ`` on P (body i), ``−F_P`` on Q (fd: s̄_i, s̄_j, k, c)."""
    nb, dim = lay[L_NB], lay[L_DIM]
    for e in range(ix.shape[0]):
        bi, bj = ix[e, 0], ix[e, 1]
        p0, p1, p2 = fd[e, 0], fd[e, 1], fd[e, 2]
        q0, q1, q2 = fd[e, 3], fd[e, 4], fd[e, 5]
        k, c = fd[e, 6], fd[e, 7]
        d0, d1, d2 = V.rel_point(r, A, bi, p0, p1, p2, bj, q0, q1, q2)
        dd0, dd1, dd2 = V.rel_vel(rd, A, w, bi, p0, p1, p2, bj, q0, q1, q2)
        F0, F1, F2 = k * d0 + c * dd0, k * d1 + c * dd1, k * d2 + c * dd2
        if bi < nb:
            V.add_point_force(Q, A, bi, dim, p0, p1, p2, F0, F1, F2, 1.0)
        if bj < nb:
            V.add_point_force(Q, A, bj, dim, q0, q1, q2, F0, F1, F2, -1.0)
    return OK


@force_kernel
def spring_dampers(t, q, v, r, A, rd, w, lay, fd, ix, state, Q, err):
    """``F_P = (k (L − L₀) + c L̇ + f_a(t)) u`` (fd: s̄_i, s̄_j, k, c, L₀, has actuator, program)."""
    nb, dim = lay[L_NB], lay[L_DIM]
    for e in range(ix.shape[0]):
        bi, bj = ix[e, 0], ix[e, 1]
        p0, p1, p2 = fd[e, 0], fd[e, 1], fd[e, 2]
        q0, q1, q2 = fd[e, 3], fd[e, 4], fd[e, 5]
        d0, d1, d2 = V.rel_point(r, A, bi, p0, p1, p2, bj, q0, q1, q2)
        L = np.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
        if L < 1e-12:
            err[1] = e
            return COINCIDENT
        dd0, dd1, dd2 = V.rel_vel(rd, A, w, bi, p0, p1, p2, bj, q0, q1, q2)
        Ld = (d0 * dd0 + d1 * dd1 + d2 * dd2) / L
        fa = 0.0
        if fd[e, 9] != 0.0:
            st, fa, x1, x2 = tf_evaluate(fd[e, 10:], t)
            if st != OK:
                err[1] = e
                return st
        f = (fd[e, 6] * (L - fd[e, 8]) + fd[e, 7] * Ld + fa) / L
        F0, F1, F2 = f * d0, f * d1, f * d2
        if bi < nb:
            V.add_point_force(Q, A, bi, dim, p0, p1, p2, F0, F1, F2, 1.0)
        if bj < nb:
            V.add_point_force(Q, A, bj, dim, q0, q1, q2, F0, F1, F2, -1.0)
    return OK


# --- exact Jacobian of a point-pair force F(d, ḋ) ---------------------------------------------


@_internal
def _idx6(b, c, nb, dim):
    """Model velocity index of component c (0..5: translation, body-frame rotation) of body b, or −1."""
    if b >= nb:
        return -1
    if dim == 3:
        return 6 * b + c
    if c < 2:
        return 3 * b + c
    if c == 5:
        return 3 * b + 2
    return -1


@_internal
def _point_jac(A, b, s0, s1, s2, J):
    """``J_P = [I, C(s̄)]`` (3×6) with ``C(s̄) = −A s̄~`` into J."""
    for i in range(3):
        for j in range(6):
            J[i, j] = 0.0
        J[i, i] = 1.0
        # row i of −A s̄~ : −(A[i,:] s̄~)
        a0, a1, a2 = A[b, i, 0], A[b, i, 1], A[b, i, 2]
        # (A s̄~)[i, :] = a × ... : (s̄~)[k, :] rows; A[i,:] s̄~ = (s̄ × a)ᵀ... computed directly
        J[i, 3] = -(a1 * s2 - a2 * s1)
        J[i, 4] = -(a2 * s0 - a0 * s2)
        J[i, 5] = -(a0 * s1 - a1 * s0)


@_internal
def _vel_transport(A, w, b, s0, s1, s2, Vt):
    """``∂ṙ_P/∂θ̄ = −A [ω̄ × s̄]~`` (3×3) into columns 3..5 of Vt (translation columns zero)."""
    c0, c1, c2 = V.cross(w[b, 0], w[b, 1], w[b, 2], s0, s1, s2)
    for i in range(3):
        for j in range(6):
            Vt[i, j] = 0.0
        a0, a1, a2 = A[b, i, 0], A[b, i, 1], A[b, i, 2]
        Vt[i, 3] = -(a1 * c2 - a2 * c1)
        Vt[i, 4] = -(a2 * c0 - a0 * c2)
        Vt[i, 5] = -(a0 * c1 - a1 * c0)


@numba.njit(cache=True, fastmath=False, boundscheck=False)
def point_pair_jacobian(A, w, nb, dim, bi, si, bj, sj, F, Kd, Cd, K, D, Jp, Jq, Vp, Vq, T):
    r"""Add the exact ∂Q/∂q (v-space) and ∂Q/∂v of ``Q_i = J_PᵀF``, ``Q_j = −J_QᵀF`` to K, D.

    ``F(d, ḋ)`` with ``Kd = ∂F/∂d``, ``Cd = ∂F/∂ḋ`` (3×3); includes the lever-arm terms
    ``∂(C(s̄)ᵀF)/∂θ̄ = s̄~ F̄~`` (``F̄ = AᵀF``) and the velocity transport ``∂ḋ/∂θ̄``
    (:func:`core.forces.coordinates.point_pair_jacobian`).  Work arrays Jp, Jq, Vp, Vq (3×6), T (3×6).
    """
    _point_jac(A, bi, si[0], si[1], si[2], Jp)
    _point_jac(A, bj, sj[0], sj[1], sj[2], Jq)
    _vel_transport(A, w, bi, si[0], si[1], si[2], Vp)
    _vel_transport(A, w, bj, sj[0], sj[1], sj[2], Vq)
    for side in range(2):  # derivative with respect to body i (side 0) or j (side 1)
        sgn = -1.0 if side == 0 else 1.0
        Jx = Jp if side == 0 else Jq
        Vx = Vp if side == 0 else Vq
        bx = bi if side == 0 else bj
        # T = ∂F/∂δw_x = sgn (Kd Jx + Cd Vx)
        for i in range(3):
            for c in range(6):
                acc = 0.0
                for k in range(3):
                    acc += Kd[i, k] * Jx[k, c] + Cd[i, k] * Vx[k, c]
                T[i, c] = sgn * acc
        for row_side in range(2):
            Jr = Jp if row_side == 0 else Jq
            br = bi if row_side == 0 else bj
            rs = 1.0 if row_side == 0 else -1.0
            for a in range(6):
                ia = _idx6(br, a, nb, dim)
                if ia < 0:
                    continue
                for c in range(6):
                    ic = _idx6(bx, c, nb, dim)
                    if ic < 0:
                        continue
                    acc = 0.0
                    accd = 0.0
                    for k in range(3):
                        acc += Jr[k, a] * T[k, c]
                        dk = 0.0
                        for m in range(3):
                            dk += Cd[k, m] * Jx[m, c]
                        accd += Jr[k, a] * dk
                    K[ia, ic] += rs * acc
                    D[ia, ic] += rs * sgn * accd
    # lever-arm terms on the diagonal rotation blocks
    for side in range(2):
        b = bi if side == 0 else bj
        if b >= nb:
            continue
        s = si if side == 0 else sj
        sg = 1.0 if side == 0 else -1.0
        fb = np.empty(3)
        fb[0], fb[1], fb[2] = V.ATv(A, b, sg * F[0], sg * F[1], sg * F[2])
        sf = s[0] * fb[0] + s[1] * fb[1] + s[2] * fb[2]
        for i in range(3):  # s̄~ F̄~ = F̄ s̄ᵀ − (s̄·F̄) I
            ia = _idx6(b, 3 + i, nb, dim)
            if ia < 0:
                continue
            for j in range(3):
                ic = _idx6(b, 3 + j, nb, dim)
                if ic < 0:
                    continue
                K[ia, ic] += fb[i] * s[j] - (sf if i == j else 0.0)


@force_jacobian_kernel
def point_springs_jacobian(t, q, v, r, A, rd, w, lay, fd, ix, state, K, D, err):
    """Exact Jacobian of :func:`point_springs` (``Kd = k I``, ``Cd = c I``)."""
    nb, dim = lay[L_NB], lay[L_DIM]
    Kd = np.zeros((3, 3))
    Cd = np.zeros((3, 3))
    F = np.zeros(3)
    si = np.zeros(3)
    sj = np.zeros(3)
    Jp, Jq, Vp, Vq, T = np.zeros((3, 6)), np.zeros((3, 6)), np.zeros((3, 6)), np.zeros((3, 6)), np.zeros((3, 6))
    for e in range(ix.shape[0]):
        bi, bj = ix[e, 0], ix[e, 1]
        for i in range(3):
            si[i] = fd[e, i]
            sj[i] = fd[e, 3 + i]
        k, c = fd[e, 6], fd[e, 7]
        d0, d1, d2 = V.rel_point(r, A, bi, si[0], si[1], si[2], bj, sj[0], sj[1], sj[2])
        dd0, dd1, dd2 = V.rel_vel(rd, A, w, bi, si[0], si[1], si[2], bj, sj[0], sj[1], sj[2])
        F[0], F[1], F[2] = k * d0 + c * dd0, k * d1 + c * dd1, k * d2 + c * dd2
        for i in range(3):
            for j in range(3):
                Kd[i, j] = k if i == j else 0.0
                Cd[i, j] = c if i == j else 0.0
        point_pair_jacobian(A, w, nb, dim, bi, si, bj, sj, F, Kd, Cd, K, D, Jp, Jq, Vp, Vq, T)
    return OK


@force_jacobian_kernel
def spring_dampers_jacobian(t, q, v, r, A, rd, w, lay, fd, ix, state, K, D, err):
    """Exact Jacobian of :func:`spring_dampers`:
    ``∂F/∂d = u (k uᵀ + c ḋᵀ(I − uuᵀ)/L) + f (I − uuᵀ)/L``, ``∂F/∂ḋ = c u uᵀ``."""
    nb, dim = lay[L_NB], lay[L_DIM]
    Kd = np.zeros((3, 3))
    Cd = np.zeros((3, 3))
    F = np.zeros(3)
    si = np.zeros(3)
    sj = np.zeros(3)
    u = np.zeros(3)
    dd = np.zeros(3)
    Jp, Jq, Vp, Vq, T = np.zeros((3, 6)), np.zeros((3, 6)), np.zeros((3, 6)), np.zeros((3, 6)), np.zeros((3, 6))
    for e in range(ix.shape[0]):
        bi, bj = ix[e, 0], ix[e, 1]
        for i in range(3):
            si[i] = fd[e, i]
            sj[i] = fd[e, 3 + i]
        k, c, L0 = fd[e, 6], fd[e, 7], fd[e, 8]
        d0, d1, d2 = V.rel_point(r, A, bi, si[0], si[1], si[2], bj, sj[0], sj[1], sj[2])
        L = np.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
        if L < 1e-12:
            err[1] = e
            return COINCIDENT
        dd[0], dd[1], dd[2] = V.rel_vel(rd, A, w, bi, si[0], si[1], si[2], bj, sj[0], sj[1], sj[2])
        u[0], u[1], u[2] = d0 / L, d1 / L, d2 / L
        Ld = u[0] * dd[0] + u[1] * dd[1] + u[2] * dd[2]
        fa = 0.0
        if fd[e, 9] != 0.0:
            st, fa, x1, x2 = tf_evaluate(fd[e, 10:], t)
            if st != OK:
                err[1] = e
                return st
        f = k * (L - L0) + c * Ld + fa
        for i in range(3):
            F[i] = f * u[i]
        # dLd/dd = ḋᵀ(I − uuᵀ)/L
        for j in range(3):
            g = (dd[j] - Ld * u[j]) / L
            for i in range(3):
                P = (1.0 if i == j else 0.0) - u[i] * u[j]
                Kd[i, j] = u[i] * (k * u[j] + c * g) + f * P / L
                Cd[i, j] = c * u[i] * u[j]
        point_pair_jacobian(A, w, nb, dim, bi, si, bj, sj, F, Kd, Cd, K, D, Jp, Jq, Vp, Vq, T)
    return OK


@force_kernel
def applied_forces(t, q, v, r, A, rd, w, lay, fd, ix, state, Q, err):
    """Force of time at a body point, global or body axes (fd: s̄, then 3 programs; ix: b, body-frame, offsets)."""
    nb, dim = lay[L_NB], lay[L_DIM]
    F = np.zeros(3)
    for e in range(ix.shape[0]):
        b = ix[e, 0]
        for k in range(dim):
            o0, o1 = ix[e, 2 + k], ix[e, 2 + k + 1]
            st, F[k], x1, x2 = tf_evaluate(fd[e, o0:o1], t)
            if st != OK:
                err[1] = e
                return st
        if ix[e, 1]:
            F0, F1, F2 = V.Av(A, b, F[0], F[1], F[2])
        else:
            F0, F1, F2 = F[0], F[1], F[2]
        if b < nb:
            V.add_point_force(Q, A, b, dim, fd[e, 0], fd[e, 1], fd[e, 2], F0, F1, F2, 1.0)
    return OK


@force_kernel
def applied_torques(t, q, v, r, A, rd, w, lay, fd, ix, state, Q, err):
    """Torque of time on a body, global or body axes (planar: the z moment)."""
    nb, dim = lay[L_NB], lay[L_DIM]
    T = np.zeros(3)
    nr = 1 if dim == 2 else 3
    for e in range(ix.shape[0]):
        b = ix[e, 0]
        T[0] = T[1] = T[2] = 0.0
        for k in range(nr):
            o0, o1 = ix[e, 2 + k], ix[e, 2 + k + 1]
            st, val, x1, x2 = tf_evaluate(fd[e, o0:o1], t)
            if st != OK:
                err[1] = e
                return st
            T[k if dim == 3 else 2] = val
        if dim == 3 and not ix[e, 1]:
            m0, m1, m2 = V.ATv(A, b, T[0], T[1], T[2])
        else:
            m0, m1, m2 = T[0], T[1], T[2]
        if b < nb:
            V.add_body_moment(Q, b, dim, m0, m1, m2, 1.0)
    return OK


def _component_programs(kind, element_names) -> tuple[np.ndarray, np.ndarray]:
    """Constant and time-function components of applied loads as programs, concatenated per row,
    with the column offsets of each component."""
    from ..drivers import constant

    rows, offsets = [], []
    for const, funcs, name in zip(kind.const, kind.funcs, element_names):
        fns = {k: fn for k, fn in funcs}
        progs = [encode_rows([fns.get(k, constant(float(const[k])))], [f"applied load {name!r}"])[0]
                 for k in range(len(const))]
        off = [0]
        for p in progs:
            off.append(off[-1] + len(p))
        rows.append(np.concatenate(progs))
        offsets.append(off)
    width = max(len(x) for x in rows)
    out = np.zeros((len(rows), width))
    for k, x in enumerate(rows):
        out[k, :len(x)] = x
    return out, np.asarray(offsets, np.int64)


def compile_applied_forces(kind, layout) -> CompiledForces:
    progs, off = _component_programs(kind, kind.names)
    s = pad3(kind.s)
    fd = np.hstack([s, progs])
    ix = np.column_stack([kind.b, kind.body_frame.astype(np.int64), off + 3]).astype(np.int64)
    return CompiledForces(forces=applied_forces, fd=fd, ix=np.ascontiguousarray(ix), names=list(kind.names),
                          what="applied force", groups=_groups(kind.b))


def compile_applied_torques(kind, layout) -> CompiledForces:
    progs, off = _component_programs(kind, kind.names)
    ix = np.column_stack([kind.b, kind.body_frame.astype(np.int64), off]).astype(np.int64)
    return CompiledForces(forces=applied_torques, fd=np.ascontiguousarray(progs), ix=np.ascontiguousarray(ix),
                          names=list(kind.names), what="applied torque", groups=_groups(kind.b))


def compile_point_springs(kind, layout) -> CompiledForces:
    fd = np.hstack([pad3(kind.si), pad3(kind.sj), kind.k[:, None], kind.c[:, None]])
    return CompiledForces(forces=point_springs, fd=np.ascontiguousarray(fd), ix=_ints(kind.bi, kind.bj),
                          names=list(kind.names), jacobian=point_springs_jacobian, what="point spring")


def compile_spring_dampers(kind, layout) -> CompiledForces:
    from ..drivers import constant

    progs = encode_rows([constant(0.0) if a is None else a for a in kind.act],
                        [f"actuator of spring-damper {n!r}" for n in kind.names])
    has = np.array([0.0 if a is None else 1.0 for a in kind.act])[:, None]
    fd = np.hstack([pad3(kind.si), pad3(kind.sj), kind.k[:, None], kind.c[:, None], kind.L0[:, None], has, progs])
    return CompiledForces(forces=spring_dampers, fd=np.ascontiguousarray(fd), ix=_ints(kind.bi, kind.bj),
                          names=list(kind.names), jacobian=spring_dampers_jacobian, what="spring-damper")


# --- springs on element coordinates (rotational spring-damper, bushing) -------------------------
#
# The kernels below evaluate the element coordinates of :mod:`core.forces.coordinates` — dot-1
# ``x = (A_i ū)ᵀ(A_j w̄)``, dot-2 ``x = (A_i ū)ᵀ(r_Q − r_P)``, their atan2 and linear combinations —
# with the gradient row ``G = ∂x/∂(v_i, v_j)`` in 3-D block form (translation t, body-frame
# rotation c, per body), ``ẋ = G (v_i, v_j)`` and ``Q = −f G`` (virtual work ``δW = −f δx``).
# Their Jacobians on the compiled path are the forward differences of
# :func:`core.compiled.dynamics.force_jacobian` (the numpy kinds have exact ones).


@_internal
def _dot1_coordinate(A, bi, u0, u1, u2, bj, w0, w1, w2):
    """``x = (A_i ū)ᵀ(A_j w̄)`` and its rotational gradient blocks ``c_i, c_j`` (no translation part)."""
    a0, a1, a2 = V.Av(A, bi, u0, u1, u2)
    b0, b1, b2 = V.Av(A, bj, w0, w1, w2)
    ci0, ci1, ci2 = V.uC(A, bi, u0, u1, u2, b0, b1, b2)
    cj0, cj1, cj2 = V.uC(A, bj, w0, w1, w2, a0, a1, a2)
    return a0 * b0 + a1 * b1 + a2 * b2, ci0, ci1, ci2, cj0, cj1, cj2


@_internal
def _rotation_rate(w, bi, bj, ci0, ci1, ci2, cj0, cj1, cj2):
    """``ẋ = c_i·ω̄_i + c_j·ω̄_j`` of a coordinate with rotational gradient blocks only."""
    return (ci0 * w[bi, 0] + ci1 * w[bi, 1] + ci2 * w[bi, 2]
            + cj0 * w[bj, 0] + cj1 * w[bj, 1] + cj2 * w[bj, 2])


@_internal
def _wrap(x):
    return np.arctan2(np.sin(x), np.cos(x))


@force_kernel
def rotational_spring_dampers(t, q, v, r, A, rd, w, lay, fd, ix, state, Q, err):
    r"""``θ = atan2(g_iᵀ f_j, f_iᵀ f_j)``, ``T = k wrap(θ − θ₀) + c θ̇ + T_a(t)``, ``Q = −T ∂θ/∂q``
    (:class:`core.forces.springs.RotationalSpringDamper`; fd: f̄_i, ḡ_i, f̄_j, k, c, θ₀, has actuator,
    program)."""
    nb, dim = lay[L_NB], lay[L_DIM]
    for e in range(ix.shape[0]):
        bi, bj = ix[e, 0], ix[e, 1]
        a, ai0, ai1, ai2, aj0, aj1, aj2 = _dot1_coordinate(A, bi, fd[e, 3], fd[e, 4], fd[e, 5],
                                                           bj, fd[e, 6], fd[e, 7], fd[e, 8])
        b, bi0, bi1, bi2, bj0, bj1, bj2 = _dot1_coordinate(A, bi, fd[e, 0], fd[e, 1], fd[e, 2],
                                                           bj, fd[e, 6], fd[e, 7], fd[e, 8])
        rho2 = a * a + b * b
        if not rho2 > 0.0:
            err[1] = e
            return NONFINITE
        gi0, gi1, gi2 = (b * ai0 - a * bi0) / rho2, (b * ai1 - a * bi1) / rho2, (b * ai2 - a * bi2) / rho2
        gj0, gj1, gj2 = (b * aj0 - a * bj0) / rho2, (b * aj1 - a * bj1) / rho2, (b * aj2 - a * bj2) / rho2
        thd = _rotation_rate(w, bi, bj, gi0, gi1, gi2, gj0, gj1, gj2)
        ta = 0.0
        if fd[e, 12] != 0.0:
            st, ta, x1, x2 = tf_evaluate(fd[e, 13:], t)
            if st != OK:
                err[1] = e
                return st
        T = fd[e, 9] * _wrap(np.arctan2(a, b) - fd[e, 11]) + fd[e, 10] * thd + ta
        if bi < nb:
            V.add_block(Q, bi, dim, 0.0, 0.0, 0.0, gi0, gi1, gi2, -T)
        if bj < nb:
            V.add_block(Q, bj, dim, 0.0, 0.0, 0.0, gj0, gj1, gj2, -T)
    return OK


def compile_rotational_spring_dampers(kind, layout) -> CompiledForces:
    from ..drivers import constant

    progs = encode_rows([constant(0.0) if a is None else a for a in kind.act],
                        [f"actuator of rotational spring-damper {n!r}" for n in kind.names])
    has = np.array([0.0 if a is None else 1.0 for a in kind.act])[:, None]
    fd = np.hstack([pad3(kind.fi), pad3(kind.gi), pad3(kind.fj), kind.k[:, None], kind.c[:, None],
                    kind.theta0[:, None], has, progs])
    return CompiledForces(forces=rotational_spring_dampers, fd=np.ascontiguousarray(fd), ix=_ints(kind.bi, kind.bj),
                          names=list(kind.names), what="rotational spring-damper",
                          groups=_groups(kind.bi, kind.bj))


@_internal
def _bushing_rotation(A, fd, e, bi, bj, a, b):
    """``R_ab = (A_i m̄_i,a)ᵀ(A_j m̄_j,b)`` (marker axes a of i and b of j) with its gradient blocks."""
    return _dot1_coordinate(A, bi, fd[e, 6 + a], fd[e, 9 + a], fd[e, 12 + a],
                            bj, fd[e, 15 + b], fd[e, 18 + b], fd[e, 21 + b])


@force_kernel
def bushings(t, q, v, r, A, rd, w, lay, fd, ix, state, Q, err):
    r"""Linear bushing (:class:`core.forces.springs.Bushing`): deflections ``Δ_t = M_iᵀ(r_Q − r_P)``
    (dot-2 per marker axis), ``Δ_r = ½ vee(R − Rᵀ)`` (spatial) or ``atan2(R₁₀, R₀₀)`` (planar) of
    ``R = M_iᵀM_j``, minus their values at build; ``f = K Δ + C Δ̇`` per component, ``Q = −Σ f G``.
    fd: s̄_i, s̄_j, M̄_i (row-major 3×3, columns = marker axes), M̄_j, K (6), C (6), Δ₀ (6);
    planar components are (x, y, rotation) in the first three entries of K, C, Δ₀."""
    nb, dim = lay[L_NB], lay[L_DIM]
    for e in range(ix.shape[0]):
        bi, bj = ix[e, 0], ix[e, 1]
        p0, p1, p2 = fd[e, 0], fd[e, 1], fd[e, 2]
        s0, s1, s2 = fd[e, 3], fd[e, 4], fd[e, 5]
        d0, d1, d2 = V.rel_point(r, A, bi, p0, p1, p2, bj, s0, s1, s2)
        for k in range(dim):  # translations: dot-2 along marker axis k of body i
            u0, u1, u2 = fd[e, 6 + k], fd[e, 9 + k], fd[e, 12 + k]
            a0, a1, a2 = V.Av(A, bi, u0, u1, u2)
            x = a0 * d0 + a1 * d1 + a2 * d2
            x0_, x1_, x2_ = V.uC(A, bi, u0, u1, u2, d0, d1, d2)
            y0, y1, y2 = V.uC(A, bi, p0, p1, p2, a0, a1, a2)
            ci0, ci1, ci2 = x0_ - y0, x1_ - y1, x2_ - y2
            cj0, cj1, cj2 = V.uC(A, bj, s0, s1, s2, a0, a1, a2)
            xd = (-a0 * rd[bi, 0] - a1 * rd[bi, 1] - a2 * rd[bi, 2] + a0 * rd[bj, 0] + a1 * rd[bj, 1]
                  + a2 * rd[bj, 2] + _rotation_rate(w, bi, bj, ci0, ci1, ci2, cj0, cj1, cj2))
            f = fd[e, 24 + k] * (x - fd[e, 36 + k]) + fd[e, 30 + k] * xd
            if bi < nb:
                V.add_block(Q, bi, dim, -a0, -a1, -a2, ci0, ci1, ci2, -f)
            if bj < nb:
                V.add_block(Q, bj, dim, a0, a1, a2, cj0, cj1, cj2, -f)
        if dim == 2:
            ra, ai0, ai1, ai2, aj0, aj1, aj2 = _bushing_rotation(A, fd, e, bi, bj, 1, 0)
            rb, bi0, bi1, bi2, bj0, bj1, bj2 = _bushing_rotation(A, fd, e, bi, bj, 0, 0)
            rho2 = ra * ra + rb * rb
            if not rho2 > 0.0:
                err[1] = e
                return NONFINITE
            ci2 = (rb * ai2 - ra * bi2) / rho2
            cj2 = (rb * aj2 - ra * bj2) / rho2
            xd = ci2 * w[bi, 2] + cj2 * w[bj, 2]
            f = fd[e, 26] * _wrap(np.arctan2(ra, rb) - fd[e, 38]) + fd[e, 32] * xd
            if bi < nb:
                V.add_block(Q, bi, dim, 0.0, 0.0, 0.0, 0.0, 0.0, ci2, -f)
            if bj < nb:
                V.add_block(Q, bj, dim, 0.0, 0.0, 0.0, 0.0, 0.0, cj2, -f)
        else:
            for k in range(3):  # Δ_r,k = ½ (R[k2, k1] − R[k1, k2]) with (k1, k2) cyclic after k
                k1 = (k + 1) % 3
                k2 = (k + 2) % 3
                x1, pi0, pi1, pi2, pj0, pj1, pj2 = _bushing_rotation(A, fd, e, bi, bj, k2, k1)
                x2, qi0, qi1, qi2, qj0, qj1, qj2 = _bushing_rotation(A, fd, e, bi, bj, k1, k2)
                x = 0.5 * (x1 - x2)
                ci0, ci1, ci2 = 0.5 * (pi0 - qi0), 0.5 * (pi1 - qi1), 0.5 * (pi2 - qi2)
                cj0, cj1, cj2 = 0.5 * (pj0 - qj0), 0.5 * (pj1 - qj1), 0.5 * (pj2 - qj2)
                xd = _rotation_rate(w, bi, bj, ci0, ci1, ci2, cj0, cj1, cj2)
                f = fd[e, 27 + k] * (x - fd[e, 39 + k]) + fd[e, 33 + k] * xd
                if bi < nb:
                    V.add_block(Q, bi, dim, 0.0, 0.0, 0.0, ci0, ci1, ci2, -f)
                if bj < nb:
                    V.add_block(Q, bj, dim, 0.0, 0.0, 0.0, cj0, cj1, cj2, -f)
    return OK


def _pad_axes(M) -> np.ndarray:
    """Body-fixed marker axes (n, d, d; columns = axes) as row-major 3×3 blocks, flattened (n, 9)."""
    M = np.asarray(M, float)
    out = np.zeros((M.shape[0], 3, 3))
    d = M.shape[1]
    out[:, :d, :d] = M
    if d == 2:
        out[:, 2, 2] = 1.0
    return out.reshape(M.shape[0], 9)


def _pad6(a) -> np.ndarray:
    a = np.atleast_2d(np.asarray(a, float))
    out = np.zeros((a.shape[0], 6))
    out[:, : a.shape[1]] = a
    return out


def compile_bushings(kind, layout) -> CompiledForces:
    fd = np.hstack([pad3(kind.si), pad3(kind.sj), _pad_axes(kind.Mi), _pad_axes(kind.Mj), _pad6(kind.K),
                    _pad6(kind.C), _pad6(kind.x0)])
    return CompiledForces(forces=bushings, fd=np.ascontiguousarray(fd), ix=_ints(kind.bi, kind.bj),
                          names=list(kind.names), what="bushing", groups=_groups(kind.bi, kind.bj))


# --- bump stop (dot-2 coordinate with a tabulated law) -------------------------------------------


@force_kernel
def bump_stops(t, q, v, r, A, rd, w, lay, fd, ix, state, Q, err):
    r"""Bump stop (:class:`core.forces.springs.BumpStop`): ``u = (A_i ē)ᵀ(r_Q − r_P) − u₀`` (dot-2),
    ``f = σ(u) g(|u|) + c u̇`` while engaged (``|u| > d₀`` on an active side), ``Q = −f ∂u/∂q``.
    ``g`` interpolates the table linearly, 0 inside the clearance, the last slope beyond the last row.
    fd: s̄_i, s̄_j, ē, u₀, c, positive side, negative side, then the rows d_k, f_k, S_k (slopes) in
    three blocks of K columns; ix: i, j, number of rows n, K."""
    nb, dim = lay[L_NB], lay[L_DIM]
    for e in range(ix.shape[0]):
        bi, bj, n, K = ix[e, 0], ix[e, 1], ix[e, 2], ix[e, 3]
        p0, p1, p2 = fd[e, 0], fd[e, 1], fd[e, 2]
        s0, s1, s2 = fd[e, 3], fd[e, 4], fd[e, 5]
        u0, u1, u2 = fd[e, 6], fd[e, 7], fd[e, 8]
        d0, d1, d2 = V.rel_point(r, A, bi, p0, p1, p2, bj, s0, s1, s2)
        a0, a1, a2 = V.Av(A, bi, u0, u1, u2)
        u = a0 * d0 + a1 * d1 + a2 * d2 - fd[e, 9]
        side = fd[e, 11] if u >= 0.0 else fd[e, 12]
        if side == 0.0:
            continue
        s = abs(u)
        k = -1
        for m in range(n):  # the segment of |u|: the last row with d_m ≤ |u|
            if fd[e, 13 + m] <= s:
                k = m
        if k < 0:
            continue
        g = fd[e, 13 + K + k] + fd[e, 13 + 2 * K + k] * (s - fd[e, 13 + k])
        f = g if u >= 0.0 else -g
        x0_, x1_, x2_ = V.uC(A, bi, u0, u1, u2, d0, d1, d2)
        y0, y1, y2 = V.uC(A, bi, p0, p1, p2, a0, a1, a2)
        ci0, ci1, ci2 = x0_ - y0, x1_ - y1, x2_ - y2
        cj0, cj1, cj2 = V.uC(A, bj, s0, s1, s2, a0, a1, a2)
        if s > fd[e, 13] and fd[e, 10] != 0.0:
            ud = (-a0 * rd[bi, 0] - a1 * rd[bi, 1] - a2 * rd[bi, 2] + a0 * rd[bj, 0] + a1 * rd[bj, 1]
                  + a2 * rd[bj, 2] + _rotation_rate(w, bi, bj, ci0, ci1, ci2, cj0, cj1, cj2))
            f += fd[e, 10] * ud
        if bi < nb:
            V.add_block(Q, bi, dim, -a0, -a1, -a2, ci0, ci1, ci2, -f)
        if bj < nb:
            V.add_block(Q, bj, dim, a0, a1, a2, cj0, cj1, cj2, -f)
    return OK


def compile_bump_stops(kind, layout) -> CompiledForces:
    K = kind.D.shape[1]
    D = np.where(np.isfinite(kind.D), kind.D, 0.0)  # rows beyond n are never read
    fd = np.hstack([pad3(kind.si), pad3(kind.sj), pad3(kind.ei), kind.u0[:, None], kind.c[:, None],
                    kind.positive.astype(float)[:, None], kind.negative.astype(float)[:, None], D, kind.F, kind.S])
    ix = _ints(kind.bi, kind.bj, kind.n_rows, np.full(len(kind.bi), K))
    return CompiledForces(forces=bump_stops, fd=np.ascontiguousarray(fd), ix=ix, names=list(kind.names),
                          what="bump stop", groups=_groups(kind.bi, kind.bj))


# --- spring in series with a damper (node = extra coordinate) -------------------------------------


@force_kernel
def series_spring_dampers(t, q, v, r, A, rd, w, lay, fd, ix, state, Q, err):
    r"""Maxwell element (:class:`core.forces.springs.SeriesSpringDamper`): ``F_s = k_s (ℓ − x − ℓ_s0)``,
    ``F_P = F_s n`` on P, ``−F_s n`` on Q, ``Q_x = F_s − c ẋ`` on the node coordinate x
    (fd: s̄_i, s̄_j, k_s, c, ℓ_s0; ix: i, j, q index and v index of x)."""
    nb, dim = lay[L_NB], lay[L_DIM]
    for e in range(ix.shape[0]):
        bi, bj, xq, xv = ix[e, 0], ix[e, 1], ix[e, 2], ix[e, 3]
        p0, p1, p2 = fd[e, 0], fd[e, 1], fd[e, 2]
        q0, q1, q2 = fd[e, 3], fd[e, 4], fd[e, 5]
        d0, d1, d2 = V.rel_point(r, A, bi, p0, p1, p2, bj, q0, q1, q2)
        L = np.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
        if L < 1e-12:
            err[1] = e
            return COINCIDENT
        Fs = fd[e, 6] * (L - q[xq] - fd[e, 8])
        f = Fs / L
        if bi < nb:
            V.add_point_force(Q, A, bi, dim, p0, p1, p2, f * d0, f * d1, f * d2, 1.0)
        if bj < nb:
            V.add_point_force(Q, A, bj, dim, q0, q1, q2, f * d0, f * d1, f * d2, -1.0)
        Q[xv] += Fs - fd[e, 7] * v[xv]
    return OK


@force_jacobian_kernel
def series_spring_dampers_jacobian(t, q, v, r, A, rd, w, lay, fd, ix, state, K, D, err):
    """Exact Jacobian of :func:`series_spring_dampers`: body blocks of a spring with tension F_s
    (``∂F/∂d = k_s n nᵀ + F_s (I − n nᵀ)/ℓ``, no damping between the bodies) and the node couplings
    ``∂Q_b/∂x = ∂Q_x/∂δw_b = k_s g_b`` (``g_i = −J_Pᵀn``, ``g_j = J_Qᵀn``), ``∂Q_x/∂x = −k_s``,
    ``∂Q_x/∂ẋ = −c``."""
    nb, dim = lay[L_NB], lay[L_DIM]
    Kd = np.zeros((3, 3))
    Cd = np.zeros((3, 3))
    F = np.zeros(3)
    si = np.zeros(3)
    sj = np.zeros(3)
    u = np.zeros(3)
    Jp, Jq, Vp, Vq, T = np.zeros((3, 6)), np.zeros((3, 6)), np.zeros((3, 6)), np.zeros((3, 6)), np.zeros((3, 6))
    for e in range(ix.shape[0]):
        bi, bj, xq, xv = ix[e, 0], ix[e, 1], ix[e, 2], ix[e, 3]
        for i in range(3):
            si[i] = fd[e, i]
            sj[i] = fd[e, 3 + i]
        k, c = fd[e, 6], fd[e, 7]
        d0, d1, d2 = V.rel_point(r, A, bi, si[0], si[1], si[2], bj, sj[0], sj[1], sj[2])
        L = np.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
        if L < 1e-12:
            err[1] = e
            return COINCIDENT
        u[0], u[1], u[2] = d0 / L, d1 / L, d2 / L
        Fs = k * (L - q[xq] - fd[e, 8])
        for i in range(3):
            F[i] = Fs * u[i]
            for j in range(3):
                Kd[i, j] = k * u[i] * u[j] + Fs * ((1.0 if i == j else 0.0) - u[i] * u[j]) / L
        point_pair_jacobian(A, w, nb, dim, bi, si, bj, sj, F, Kd, Cd, K, D, Jp, Jq, Vp, Vq, T)
        for side in range(2):
            b = bi if side == 0 else bj
            if b >= nb:
                continue
            sg = -1.0 if side == 0 else 1.0
            s = si if side == 0 else sj
            c0, c1, c2 = V.uC(A, b, s[0], s[1], s[2], u[0], u[1], u[2])
            g = (u[0], u[1], u[2], c0, c1, c2)  # J_bᵀ n in 3-D block form
            for a in range(6):
                ia = _idx6(b, a, nb, dim)
                if ia < 0:
                    continue
                K[ia, xv] += sg * k * g[a]
                K[xv, ia] += sg * k * g[a]
        K[xv, xv] -= k
        D[xv, xv] -= c
    return OK


def compile_series_spring_dampers(kind, layout) -> CompiledForces:
    fd = np.hstack([pad3(kind.si), pad3(kind.sj), kind.k[:, None], kind.c[:, None], kind.ls0[:, None]])
    ix = _ints(kind.bi, kind.bj, kind.xq, kind.xv)
    return CompiledForces(forces=series_spring_dampers, fd=np.ascontiguousarray(fd), ix=ix, names=list(kind.names),
                          jacobian=series_spring_dampers_jacobian, what="series spring-damper")


# --- plane contact ------------------------------------------------------------------------------


@force_kernel
def plane_contacts(t, q, v, r, A, rd, w, lay, fd, ix, state, Q, err):
    r"""Sphere (radius R, centre s̄ on body b) on a ground plane (point p₀, normal n):
    ``δ = R − nᵀ(r_C − p₀)``, ``F_n = max(0, K δᵖ (1 + χ δ̇/v₀))`` along n at the centre, optional
    friction ``F_t = −μ F_n v_t/√(|v_t|² + v_ε²)`` at ``r_C − R n``
    (fd: s̄, p₀, n, R, K, p, χ, v₀, μ, v_ε)."""
    nb, dim = lay[L_NB], lay[L_DIM]
    for e in range(ix.shape[0]):
        b = ix[e, 0]
        s0, s1, s2 = fd[e, 0], fd[e, 1], fd[e, 2]
        n0, n1, n2 = fd[e, 6], fd[e, 7], fd[e, 8]
        R, K, p, chi, v0, mu, ve = fd[e, 9], fd[e, 10], fd[e, 11], fd[e, 12], fd[e, 13], fd[e, 14], fd[e, 15]
        a0, a1, a2 = V.Av(A, b, s0, s1, s2)
        x = n0 * (r[b, 0] + a0 - fd[e, 3]) + n1 * (r[b, 1] + a1 - fd[e, 4]) + n2 * (r[b, 2] + a2 - fd[e, 5])
        delta = R - x
        if not delta > 0.0:
            continue
        c0, c1, c2 = V.vel(A, w, b, s0, s1, s2)
        ddelta = -(n0 * (rd[b, 0] + c0) + n1 * (rd[b, 1] + c1) + n2 * (rd[b, 2] + c2))
        Fn = K * delta ** p * (1.0 + chi * ddelta / v0)
        if not Fn > 0.0:
            continue
        if b < nb:
            V.add_point_force(Q, A, b, dim, s0, s1, s2, Fn * n0, Fn * n1, Fn * n2, 1.0)
        if mu > 0.0:
            # contact point r_C − R n in body coordinates: s̄ − R Aᵀn
            m0, m1, m2 = V.ATv(A, b, n0, n1, n2)
            t0, t1, t2 = s0 - R * m0, s1 - R * m1, s2 - R * m2
            u0, u1, u2 = V.vel(A, w, b, t0, t1, t2)
            vc0, vc1, vc2 = rd[b, 0] + u0, rd[b, 1] + u1, rd[b, 2] + u2
            vn = vc0 * n0 + vc1 * n1 + vc2 * n2
            vt0, vt1, vt2 = vc0 - vn * n0, vc1 - vn * n1, vc2 - vn * n2
            g = mu * Fn / np.sqrt(vt0 * vt0 + vt1 * vt1 + vt2 * vt2 + ve * ve)
            if b < nb:
                V.add_point_force(Q, A, b, dim, t0, t1, t2, -g * vt0, -g * vt1, -g * vt2, 1.0)
    return OK


def compile_plane_contacts(kind, layout) -> CompiledForces:
    fd = np.hstack([pad3(kind.s), pad3(kind.p0), pad3(kind.n), kind.R[:, None], kind.K[:, None], kind.p[:, None],
                    kind.chi[:, None], kind.v0[:, None], kind.mu[:, None], kind.veps[:, None]])
    return CompiledForces(forces=plane_contacts, fd=np.ascontiguousarray(fd), ix=_ints(kind.b), names=list(kind.names),
                          what="plane contact", groups=_groups(kind.b))


__all__ = [
    "pad3",
    "point_coincidence", "dot1", "dot2", "distance", "planar_angle",
    "point_position_driver", "planar_angle_driver", "spatial_angle_driver",
    "point_springs", "spring_dampers", "applied_forces", "applied_torques", "plane_contacts",
    "point_springs_jacobian", "spring_dampers_jacobian", "point_pair_jacobian",
    "bump_stops", "series_spring_dampers", "series_spring_dampers_jacobian",
]



# --- driver of an extra coordinate (core.joints.CoordinateDriver) ---------------------------------


@constraint_kernel
def coordinate_driver(t, q, v, r, A, rd, w, lay, fd, ix, row0, flags, phi, G, nu, gam, err):
    """``Φ = x − f(t)``, ``Φ_x = 1``, ``ν = ḟ``, ``γ = f̈`` (fd: the program of f; ix: q index of x)."""
    st, f, fdot, fddot = tf_evaluate(fd[0, :], t)
    if st != OK:
        err[1] = 0
        return st
    if flags & WANT_PHI:
        phi[row0] = q[ix[0, 0]] - f
    for j in range(6):
        G[row0, 0, j] = 0.0
    G[row0, 0, 0] = 1.0
    if flags & WANT_NU:
        nu[row0] = fdot
    if flags & WANT_GAMMA:
        gam[row0] = fddot
    return OK


def compile_coordinate_driver(driver, layout) -> CompiledConstraints:
    """Pack a :class:`core.joints.CoordinateDriver` (one element, one row on its coordinate)."""
    owner = f"driver {driver.name!r}"
    fd = encode_rows([driver.function], [owner])
    slots = np.array([[layout.extra_slot(driver.coordinate, owner), -1, -1]], np.int64)
    ix = np.array([[layout.extra_q_index(driver.coordinate, owner)]], np.int64)
    return CompiledConstraints(kernel=coordinate_driver, fd=np.ascontiguousarray(fd), ix=ix, rows=1, slots=slots,
                               names=[driver.name], time_dependent=True, what="coordinate driver")
