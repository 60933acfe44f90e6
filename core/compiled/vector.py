r"""Scalar 3-vector kinematics for writing kernels (each compiled once, called by the kernels; no allocation).

Body states are in three-dimensional form (see :mod:`core.compiled.protocol`); for a body ``b``
and a body-fixed vector ``s̄`` (Nikravesh 1988, Eqs. 6.151–6.156):

================================================= ================================================================
function                                          returns
================================================= ================================================================
``Av(A, b, x)``                                   ``A_b x``
``ATv(A, b, x)``                                  ``A_bᵀ x``
``cross(a, b)``                                   ``a × b``
``vel(A, w, b, s̄)``                               ``C(s̄) ω_b = A_b (ω̄_b × s̄)``: velocity of a body-fixed vector
``aq(A, w, b, s̄)``                                ``a^q(s̄) = A_b (ω̄ × (ω̄ × s̄))``: its velocity-product
                                                  acceleration
``uC(A, b, s̄, u)``                                ``uᵀ C(s̄) = (s̄ × A_bᵀu)ᵀ``: a row of the rotational Jacobian
``rel_point(…)``                                  ``d = r_Q − r_P`` (P = s̄_p on body i, Q = s̄_q on body j)
``rel_vel(…)``                                    ``ḋ = ṙ_Q − ṙ_P``
``put_row(G, row, sl, dim, t, c)``                writes a Jacobian row block ``(t; c)`` in the model's velocity
                                                  layout: planar ``(t₀, t₁, c₂)``, spatial ``(t, c)``
``add_point_force(Q, A, b, dim, s̄, F, sign)``     ``Q_b += sign · [F; C(s̄)ᵀ F]``
``add_body_moment(Q, b, dim, M̄)``                 ``Q_b`` rotational part ``+= M̄`` (body-frame moment; planar: z)
``add_block(Q, b, dim, t, c, s)``                 ``Q_b += s · (t; c)``: a generalized force given in the 3-D
                                                  block form (translation, body-frame rotation) of a gradient row
================================================= ================================================================

The three ``add_*`` functions take a body, never the ground (``b < nb``): the caller tests
``if b < nb:`` before the call.  A test inside the function costs, measured, about 25 ns per call
(numba keeps the reference-count updates of ``Q`` and ``A`` around a conditional exit of the
callee), more than the force itself: the kernel of eight point springs took 0.60 µs with the
test inside and 0.14–0.20 µs with it in the caller (2-core Intel Xeon, issue 24).

Planar bodies rotate about z, so ``C(s̄) ω = A(ω × s̄)`` and ``a^q = A(ω × (ω × s̄))`` reproduce
the planar ``A R s̄ θ̇`` and ``−A s̄ θ̇²`` exactly: one kernel serves planar and spatial models.

References
----------
P. E. Nikravesh, *Computer-Aided Analysis of Mechanical Systems*, Prentice Hall, 1988.
"""

from __future__ import annotations

import numba

_internal = numba.njit(cache=True, fastmath=False, boundscheck=False, no_cpython_wrapper=True, no_cfunc_wrapper=True)

__all__ = ["Av", "ATv", "cross", "vel", "aq", "uC", "rel_point", "rel_vel", "put_row", "add_point_force",
           "add_body_moment", "add_block", "velocity_offset"]


@_internal
def Av(A, b, x0, x1, x2):
    """``A_b x``."""
    return (A[b, 0, 0] * x0 + A[b, 0, 1] * x1 + A[b, 0, 2] * x2,
            A[b, 1, 0] * x0 + A[b, 1, 1] * x1 + A[b, 1, 2] * x2,
            A[b, 2, 0] * x0 + A[b, 2, 1] * x1 + A[b, 2, 2] * x2)


@_internal
def ATv(A, b, x0, x1, x2):
    """``A_bᵀ x``."""
    return (A[b, 0, 0] * x0 + A[b, 1, 0] * x1 + A[b, 2, 0] * x2,
            A[b, 0, 1] * x0 + A[b, 1, 1] * x1 + A[b, 2, 1] * x2,
            A[b, 0, 2] * x0 + A[b, 1, 2] * x1 + A[b, 2, 2] * x2)


@_internal
def cross(a0, a1, a2, b0, b1, b2):
    """``a × b``."""
    return a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0


@_internal
def vel(A, w, b, s0, s1, s2):
    """``C(s̄) ω_b = A_b (ω̄_b × s̄)`` (velocity of a body-fixed vector)."""
    c0, c1, c2 = cross(w[b, 0], w[b, 1], w[b, 2], s0, s1, s2)
    return Av(A, b, c0, c1, c2)


@_internal
def aq(A, w, b, s0, s1, s2):
    """``a^q(s̄) = A_b (ω̄ × (ω̄ × s̄))``."""
    w0, w1, w2 = w[b, 0], w[b, 1], w[b, 2]
    c0, c1, c2 = cross(w0, w1, w2, s0, s1, s2)
    d0, d1, d2 = cross(w0, w1, w2, c0, c1, c2)
    return Av(A, b, d0, d1, d2)


@_internal
def uC(A, b, s0, s1, s2, u0, u1, u2):
    """``uᵀ C(s̄) = (s̄ × A_bᵀu)ᵀ`` (row of the rotational Jacobian along u)."""
    t0, t1, t2 = ATv(A, b, u0, u1, u2)
    return cross(s0, s1, s2, t0, t1, t2)


@_internal
def rel_point(r, A, bi, p0, p1, p2, bj, q0, q1, q2):
    """``d = r_Q − r_P`` with P = s̄_p on body i, Q = s̄_q on body j."""
    u0, u1, u2 = Av(A, bi, p0, p1, p2)
    v0, v1, v2 = Av(A, bj, q0, q1, q2)
    return r[bj, 0] + v0 - r[bi, 0] - u0, r[bj, 1] + v1 - r[bi, 1] - u1, r[bj, 2] + v2 - r[bi, 2] - u2


@_internal
def rel_vel(rd, A, w, bi, p0, p1, p2, bj, q0, q1, q2):
    """``ḋ = ṙ_Q − ṙ_P`` (velocities of the same two body-fixed points)."""
    x0, x1, x2 = vel(A, w, bi, p0, p1, p2)
    y0, y1, y2 = vel(A, w, bj, q0, q1, q2)
    return rd[bj, 0] + y0 - rd[bi, 0] - x0, rd[bj, 1] + y1 - rd[bi, 1] - x1, rd[bj, 2] + y2 - rd[bi, 2] - x2


@_internal
def put_row(G, row, sl, dim, t0, t1, t2, c0, c1, c2):
    """Store a Jacobian row block (translation t, rotation c) in the model's velocity layout."""
    if dim == 2:
        G[row, sl, 0] = t0
        G[row, sl, 1] = t1
        G[row, sl, 2] = c2
    else:
        G[row, sl, 0] = t0
        G[row, sl, 1] = t1
        G[row, sl, 2] = t2
        G[row, sl, 3] = c0
        G[row, sl, 4] = c1
        G[row, sl, 5] = c2


@_internal
def add_point_force(Q, A, b, dim, s0, s1, s2, F0, F1, F2, sign):
    """``Q_b += sign · [F; C(s̄)ᵀ F]`` with ``C(s̄)ᵀF = s̄ × A_bᵀF``; ``b`` a body, not the ground (see below)."""
    c0, c1, c2 = uC(A, b, s0, s1, s2, F0, F1, F2)
    if dim == 2:
        o = 3 * b
        Q[o] += sign * F0
        Q[o + 1] += sign * F1
        Q[o + 2] += sign * c2
    else:
        o = 6 * b
        Q[o] += sign * F0
        Q[o + 1] += sign * F1
        Q[o + 2] += sign * F2
        Q[o + 3] += sign * c0
        Q[o + 4] += sign * c1
        Q[o + 5] += sign * c2


@_internal
def add_body_moment(Q, b, dim, m0, m1, m2, sign):
    """``Q_b`` rotational part ``+= sign · M̄`` (body-frame moment; planar: only ``M̄_z``); ``b`` not the ground."""
    if dim == 2:
        Q[3 * b + 2] += sign * m2
    else:
        o = 6 * b
        Q[o + 3] += sign * m0
        Q[o + 4] += sign * m1
        Q[o + 5] += sign * m2


@_internal
def add_block(Q, b, dim, t0, t1, t2, c0, c1, c2, s):
    """``Q_b += s · (t; c)`` in the model's velocity layout (planar: ``(t₀, t₁, c₂)``); ``b`` not the ground."""
    if dim == 2:
        o = 3 * b
        Q[o] += s * t0
        Q[o + 1] += s * t1
        Q[o + 2] += s * c2
    else:
        o = 6 * b
        Q[o] += s * t0
        Q[o + 1] += s * t1
        Q[o + 2] += s * t2
        Q[o + 3] += s * c0
        Q[o + 4] += s * c1
        Q[o + 5] += s * c2


@_internal
def velocity_offset(b, nb, nvb):
    """First velocity index of body ``b`` (−1 for the ground)."""
    if b >= nb:
        return -1
    return b * nvb
