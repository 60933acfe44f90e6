r"""The compiled equations of motion: forces, constraints, saddle-point solves, accelerations, projection.

The same equations as the numpy path (:mod:`core.model`, :mod:`core.dynamics`), evaluated over
the flat arrays of :func:`core.compiled.layout.compile_model` and the kinds' kernels:

* :func:`body_states` — positions, rotation matrices and velocities of all bodies (3-D form);
* :func:`forces` — gravity, gyroscopic moments ``−ω̄ × J ω̄`` and every force kind's kernel;
* :func:`constraints` — every constraint kind's rows of ``Φ``, ``Φ_q`` (slot blocks), ``ν``, ``γ``;
* :func:`mass_update` — the mass matrices of the mass groups (bodies whose inertia follows their
  deformation) and their inverses;
* :func:`factor` / :func:`saddle_solve` — ``[[M, Φ_qᵀ], [Φ_q, 0]] [x; μ] = [f; g]`` by the Schur
  complement of the regular rows with the border of massless coordinates
  (:mod:`core.compiled.layout`);
* :func:`accelerations` — index-1 accelerations and multipliers with Baumgarte terms
  (Baumgarte 1972): ``g = γ − 2α(Φ_q v − ν) − β²Φ``;
* :func:`project` — coordinate projection (Eich 1993), the rule of
  :func:`core.dynamics.project`: simplified Gauss–Newton ``[[M, Φ_qᵀ], [Φ_q, 0]] [Δ; μ] = [0; −Φ]``
  with ``Φ_q`` and its factorisation frozen, ``q ← q ⊕ Δ`` until ``‖Φ‖∞ ≤ tol``, then the
  M-orthogonal velocity correction onto ``Φ_q v = ν``;
* :func:`force_jacobian` — ``∂Q/∂q`` (velocity-space increments) and ``∂Q/∂v`` from the kinds'
  Jacobian kernels, by forward differences of a kind's force kernel where it has none;
* :func:`qdot`, :func:`retract`, :func:`normalize` — coordinate kinematics of Euler parameters.

Failures are status codes (:mod:`core.compiled.protocol`); a kernel that fails names its element
in ``ws.err`` = (kind, element, family: 1 force, 2 constraint).

References
----------
J. Baumgarte, Comput. Methods Appl. Mech. Eng. 1 (1972) 1–16.
E. Eich, SIAM J. Numer. Anal. 30(5) (1993) 1467–1482.
G. H. Golub, C. F. Van Loan, *Matrix Computations*, 4th ed., 2013, Alg. 3.4.1 (LU with partial
pivoting), Alg. 4.2.1 (Cholesky) restricted to the envelope (George & Liu 1981, Ch. 4).
P. E. Nikravesh, *Computer-Aided Analysis of Mechanical Systems*, 1988, Eq. 6.101 (Euler
parameter rates).
"""

from __future__ import annotations

# numba bakes module constants such as protocol.MAX_SLOTS into its cached machine code and keys the
# cache on this file only: this file changed with MAX_SLOTS (3 -> 8, flexible bodies' node frames)
# and with the mass groups (the saddle solve's signature), so that no stale kernel runs
# (docs/architecture.md, numba's on-disk cache)

import numba
import numpy as np
from numba.core import types
from numba.experimental import structref

from .protocol import (
    FT_FD0,
    FT_FD1,
    FT_FW,
    FT_IW,
    FT_IX0,
    FT_IX1,
    FT_N,
    FT_ST0,
    FT_ST1,
    FT_STN,
    FT_STW,
    MASS_NOT_PD,
    MAX_SLOTS,
    NONFINITE,
    OK,
    SINGULAR,
    WANT_GAMMA,
    WANT_NU,
    WANT_PHI,
)

__all__ = ["Workspace", "make_workspace", "body_states", "forces", "constraints", "factor", "saddle_solve",
           "accelerations", "project", "accept", "force_jacobian", "qdot", "retract", "normalize", "mass_update", "PIVOT_RTOL",
           "FAMILY_FORCE", "FAMILY_CONSTRAINT"]

_jit = numba.njit(cache=True, fastmath=False, boundscheck=False)
_internal = numba.njit(cache=True, fastmath=False, boundscheck=False, no_cpython_wrapper=True, no_cfunc_wrapper=True)
_inline = numba.njit(cache=True, fastmath=False, boundscheck=False, inline="always")

#: a Cholesky pivot below this fraction of its diagonal entry means numerically dependent rows
PIVOT_RTOL = 1e-12
FAMILY_FORCE, FAMILY_CONSTRAINT = 1, 2

WORKSPACE_FIELDS = (
    "r", "A", "rd", "w",           # body states (n_b + 1, 3 / 3×3)
    "phi", "G", "nu", "gam",       # constraint rows (m_all; G (m_all, MAX_SLOTS, 6))
    "X",                           # M⁻¹ Φ_qᵀ blocks (m_all, MAX_SLOTS, 6)
    "S", "L", "rhs",               # Schur complement, envelope factor, right-hand side (m_R)
    "C", "W", "T", "piv", "z",     # border: C (m_R, n_z), W = S⁻¹C, T (n_z, n_z) LU, pivots, z (n_z)
    "Q", "g", "mu", "tmp_v", "tmp_v2", "err",
    "Mg", "Mgi", "gx", "gy",       # mass groups: matrices, inverses (n_g, w, w); work vectors (w)
)


@structref.register
class WorkspaceType(types.StructRef):
    """numba type of :class:`Workspace`."""

    def preprocess_fields(self, fields):
        return tuple((name, types.unliteral(typ)) for name, typ in fields)


class Workspace(structref.StructRefProxy):
    """Scratch arrays of the compiled equations (fields :data:`WORKSPACE_FIELDS`).

    A numba structref, passed into compiled functions as a pointer: a tuple of ~20 arrays would be
    copied at every call of a compiled function that takes it.  From Python the fields read as
    the same numpy arrays (shared memory).
    """

    def __new__(cls, *values):
        obj = _new_workspace(*values)
        obj._arrays = dict(zip(WORKSPACE_FIELDS, values))
        return obj

    def __getattr__(self, name):
        try:
            return self.__dict__["_arrays"][name]
        except KeyError:
            raise AttributeError(f"Workspace has no field {name!r}") from None


structref.define_proxy(Workspace, WorkspaceType, list(WORKSPACE_FIELDS))


@numba.njit(cache=True)
def _new_workspace(*values):
    """Built in compiled code cached on disk (``StructRefProxy.__new__`` compiles an uncached
    constructor in every process; see :func:`core.compiled.layout._new_compiled_data`)."""
    return Workspace(*values)


def make_workspace(cm) -> Workspace:
    """Scratch arrays of the compiled equations (allocated once per integrator)."""
    nb, m_all, n_v = cm.n_b, cm.m_all, cm.n_v
    m_r = max(cm.n_reg, 1)
    nz = cm.n_x + cm.n_e
    A = np.zeros((nb + 1, 3, 3))
    A[:, 2, 2] = 1.0  # planar bodies rotate about z (body_states writes the 2×2 block)
    A[nb] = np.eye(3)
    fields = dict(
        r=np.zeros((nb + 1, 3)), A=A, rd=np.zeros((nb + 1, 3)), w=np.zeros((nb + 1, 3)),
        phi=np.zeros(m_all), G=np.zeros((m_all, MAX_SLOTS, 6)), nu=np.zeros(m_all), gam=np.zeros(m_all),
        X=np.zeros((m_all, MAX_SLOTS, 6)),
        S=np.zeros((m_r, m_r)), L=np.zeros((m_r, m_r)), rhs=np.zeros(m_r),
        C=np.zeros((m_r, max(nz, 1))), W=np.zeros((m_r, max(nz, 1))), T=np.zeros((max(nz, 1), max(nz, 1))),
        piv=np.zeros(max(nz, 1), np.int64), z=np.zeros(max(nz, 1)),
        Q=np.zeros(n_v), g=np.zeros(m_all), mu=np.zeros(m_all), tmp_v=np.zeros(n_v), tmp_v2=np.zeros(n_v),
        err=np.zeros(3, np.int64),
        Mg=np.zeros((max(cm.n_grp, 1), cm.group_width, cm.group_width)),
        Mgi=np.zeros((max(cm.n_grp, 1), cm.group_width, cm.group_width)),
        gx=np.zeros(cm.group_width), gy=np.zeros(cm.group_width),
    )
    return Workspace(*(fields[f] for f in WORKSPACE_FIELDS))


# ================================================================================================
# kinematics
# ================================================================================================


@_jit
def body_states(lay, q, v, ws):
    """Fill ``ws.r, ws.A, ws.rd, ws.w`` in 3-D form; the ground row ``n_b`` stays at rest with A = I.

    Planar bodies are embedded as rotations about z: ``A = [[c, −s, 0], [s, c, 0], [0, 0, 1]]``,
    ``ω̄ = (0, 0, θ̇)``.  Spatial: ``A(p)`` of the Euler parameters (Nikravesh 1988, Eq. 6.19).
    """
    _body_states(lay, q, v, ws.r, ws.A, ws.rd, ws.w)


@_inline
def _body_states(lay, q, v, r, A, rd, w):
    """:func:`body_states` on the arrays themselves (read from the workspace once by the caller)."""
    nb, dim = lay[0], lay[1]
    if dim == 2:
        for b in range(nb):
            th = q[3 * b + 2]
            c, s = np.cos(th), np.sin(th)
            r[b, 0] = q[3 * b]
            r[b, 1] = q[3 * b + 1]
            A[b, 0, 0] = c
            A[b, 0, 1] = -s
            A[b, 1, 0] = s
            A[b, 1, 1] = c
            rd[b, 0] = v[3 * b]
            rd[b, 1] = v[3 * b + 1]
            w[b, 2] = v[3 * b + 2]
    else:
        for b in range(nb):
            o = 7 * b
            e0, e1, e2, e3 = q[o + 3], q[o + 4], q[o + 5], q[o + 6]
            r[b, 0], r[b, 1], r[b, 2] = q[o], q[o + 1], q[o + 2]
            A[b, 0, 0] = 2.0 * (e0 * e0 + e1 * e1) - 1.0
            A[b, 0, 1] = 2.0 * (e1 * e2 - e0 * e3)
            A[b, 0, 2] = 2.0 * (e1 * e3 + e0 * e2)
            A[b, 1, 0] = 2.0 * (e1 * e2 + e0 * e3)
            A[b, 1, 1] = 2.0 * (e0 * e0 + e2 * e2) - 1.0
            A[b, 1, 2] = 2.0 * (e2 * e3 - e0 * e1)
            A[b, 2, 0] = 2.0 * (e1 * e3 - e0 * e2)
            A[b, 2, 1] = 2.0 * (e2 * e3 + e0 * e1)
            A[b, 2, 2] = 2.0 * (e0 * e0 + e3 * e3) - 1.0
            u = 6 * b
            rd[b, 0], rd[b, 1], rd[b, 2] = v[u], v[u + 1], v[u + 2]
            w[b, 0], w[b, 1], w[b, 2] = v[u + 3], v[u + 4], v[u + 5]


@_jit
def qdot(lay, q, v, out):
    """``q̇ = Z(q) v``: identity for planar bodies and extras; ``ṗ = ½ L(p)ᵀ ω̄`` (Nikravesh 1988, Eq. 6.101)."""
    nb, dim, n_q = lay[0], lay[1], lay[4]
    if dim == 2:
        for i in range(n_q):
            out[i] = v[i]
        return
    for b in range(nb):
        o, u = 7 * b, 6 * b
        out[o], out[o + 1], out[o + 2] = v[u], v[u + 1], v[u + 2]
        e0, e1, e2, e3 = q[o + 3], q[o + 4], q[o + 5], q[o + 6]
        w0, w1, w2 = v[u + 3], v[u + 4], v[u + 5]
        out[o + 3] = 0.5 * (-e1 * w0 - e2 * w1 - e3 * w2)
        out[o + 4] = 0.5 * (e0 * w0 - e3 * w1 + e2 * w2)
        out[o + 5] = 0.5 * (e3 * w0 + e0 * w1 - e1 * w2)
        out[o + 6] = 0.5 * (-e2 * w0 + e1 * w1 + e0 * w2)
    for k in range(lay[6]):
        out[7 * nb + k] = v[6 * nb + k]


@_jit
def normalize(lay, q):
    """Euler parameters scaled to unit norm in place (spatial bodies)."""
    if lay[1] == 2:
        return
    for b in range(lay[0]):
        o = 7 * b + 3
        n = np.sqrt(q[o] ** 2 + q[o + 1] ** 2 + q[o + 2] ** 2 + q[o + 3] ** 2)
        for i in range(4):
            q[o + i] /= n


@_jit
def retract(lay, q, dv):
    r"""``q ← q ⊕ Δ``: translations and extras add; spatial rotations ``p ← p ⊗ exp(Δθ̄/2)``."""
    nb, dim = lay[0], lay[1]
    if dim == 2:
        for i in range(lay[4]):
            q[i] += dv[i]
        return
    for b in range(nb):
        o, u = 7 * b, 6 * b
        for i in range(3):
            q[o + i] += dv[u + i]
        t0, t1, t2 = dv[u + 3], dv[u + 4], dv[u + 5]
        ang = np.sqrt(t0 * t0 + t1 * t1 + t2 * t2)
        if ang < 1e-4:
            a2 = ang * ang
            sh = 0.5 - a2 / 48.0 + a2 * a2 / 3840.0
        else:
            sh = np.sin(0.5 * ang) / ang
        r0, r1, r2, r3 = np.cos(0.5 * ang), sh * t0, sh * t1, sh * t2
        p0, p1, p2, p3 = q[o + 3], q[o + 4], q[o + 5], q[o + 6]
        q[o + 3] = p0 * r0 - p1 * r1 - p2 * r2 - p3 * r3
        q[o + 4] = p0 * r1 + r0 * p1 + (p2 * r3 - p3 * r2)
        q[o + 5] = p0 * r2 + r0 * p2 + (p3 * r1 - p1 * r3)
        q[o + 6] = p0 * r3 + r0 * p3 + (p1 * r2 - p2 * r1)
    for k in range(lay[6]):
        q[7 * nb + k] += dv[6 * nb + k]


# ================================================================================================
# forces and constraints through the kinds' kernels
# ================================================================================================


# Compiled code reads the fields of the model and workspace tuples into locals once per call:
# reading a tuple field inside a loop reference-counts the array on every access (measured 15×
# slower on the Schur assembly).  Every read of a structure's array, and every view, is one atomic
# increment and decrement (~10 ns): the right-hand side reads the body-state arrays once and the
# force kinds' offsets and shapes from one table (``frc_tab``): the 8-link penalty chain's
# accelerations 0.69 -> 0.59 µs, the same run.


@_inline
def _ffd(cd, k):
    """Data of force kind ``k`` (a C-contiguous view of the flat storage)."""
    tab = cd.frc_tab
    return cd.frc_fd[tab[k, FT_FD0]:tab[k, FT_FD1]].reshape((tab[k, FT_N], tab[k, FT_FW]))


@_inline
def _fix(cd, k):
    tab = cd.frc_tab
    return cd.frc_ix[tab[k, FT_IX0]:tab[k, FT_IX1]].reshape((tab[k, FT_N], tab[k, FT_IW]))


@_inline
def _fst(cd, states, k):
    tab = cd.frc_tab
    return states[tab[k, FT_ST0]:tab[k, FT_ST1]].reshape((tab[k, FT_STN], tab[k, FT_STW]))


@_jit
def forces(cd, states, ws, t, q, v, Q):
    """``Q``: gravity, gyroscopic moments and every force kind (call :func:`body_states` first)."""
    return _forces(cd, states, t, q, v, ws.r, ws.A, ws.rd, ws.w, ws.err, Q)


@_inline
def _forces(cd, states, t, q, v, r, A, rd, w, err, Q):
    """:func:`forces` with the workspace's body-state arrays read by the caller."""
    lay = cd.lay
    Qg = cd.Qg
    nb, dim, n_v = lay[0], lay[1], lay[5]
    for i in range(n_v):
        Q[i] = Qg[i]
    if dim == 3:
        J = cd.Jt
        for b in range(nb):
            w0, w1, w2 = w[b, 0], w[b, 1], w[b, 2]
            h0 = J[b, 0, 0] * w0 + J[b, 0, 1] * w1 + J[b, 0, 2] * w2
            h1 = J[b, 1, 0] * w0 + J[b, 1, 1] * w1 + J[b, 1, 2] * w2
            h2 = J[b, 2, 0] * w0 + J[b, 2, 1] * w1 + J[b, 2, 2] * w2
            Q[6 * b + 3] -= w1 * h2 - w2 * h1
            Q[6 * b + 4] -= w2 * h0 - w0 * h2
            Q[6 * b + 5] -= w0 * h1 - w1 * h0
    n_frc = cd.n_frc
    if n_frc:
        frc = cd.frc
        fd, ix, tab = cd.frc_fd, cd.frc_ix, cd.frc_tab
        for k in range(n_frc):
            n = tab[k, FT_N]
            st = frc[k](t, q, v, r, A, rd, w, lay, fd[tab[k, FT_FD0]:tab[k, FT_FD1]].reshape((n, tab[k, FT_FW])),
                        ix[tab[k, FT_IX0]:tab[k, FT_IX1]].reshape((n, tab[k, FT_IW])),
                        states[tab[k, FT_ST0]:tab[k, FT_ST1]].reshape((tab[k, FT_STN], tab[k, FT_STW])), Q, err)
            if st != OK:
                err[0] = k
                err[2] = 1
                return st
    for i in range(n_v):
        if not np.isfinite(Q[i]):
            return NONFINITE
    return OK


@_jit
def constraints(cd, ws, t, q, v, flags):
    """Every constraint kind's rows of Φ (flag), Φ_q, ν (flag), γ (flag) (after :func:`body_states`)."""
    lay = cd.lay
    r, A, rd, w, err = ws.r, ws.A, ws.rd, ws.w, ws.err
    phi, G, nu, gam = ws.phi, ws.G, ws.nu, ws.gam
    con = cd.con
    fd, fo, fn, fw = cd.con_fd, cd.con_fo, cd.con_n, cd.con_fw
    ix, io, iw, row0 = cd.con_ix, cd.con_io, cd.con_iw, cd.con_row0
    for k in range(cd.n_con):
        st = con[k](t, q, v, r, A, rd, w, lay, fd[fo[k]:fo[k + 1]].reshape((fn[k], fw[k])),
                    ix[io[k]:io[k + 1]].reshape((fn[k], iw[k])), row0[k], flags, phi, G, nu, gam, err)
        if st != OK:
            err[0] = k
            err[2] = 2
            return st
    pad = cd.pad_slots
    for p in range(pad.shape[0]):  # slots a row holds for a mass group it touches in part (layout)
        a, sl = pad[p, 0], pad[p, 1]
        for c in range(6):
            G[a, sl, c] = 0.0
    return OK


@_jit
def mass_update(cd, ws, t, q, v):
    r"""The mass matrices of the mass groups at ``q`` and their inverses (after :func:`body_states`).

    A group's kernel writes ``M_g(q)`` (symmetric positive definite); its inverse is formed from
    the Cholesky factor, :math:`M_g^{-1} = L^{-T} L^{-1}` (Golub & Van Loan 2013, Alg. 4.2.1).
    Without groups this returns at once.  Status :data:`~core.compiled.protocol.MASS_NOT_PD` with
    ``ws.err = (group, 0, 3)`` for a matrix that is not positive definite.
    """
    n_g = cd.n_grp
    if n_g == 0:
        return OK
    err = ws.err
    st = cd.mass_k[0](t, q, v, ws.r, ws.A, ws.rd, ws.w, cd.lay, cd.mass_fd, cd.mass_ix, ws.Mg, err)
    if st != OK:
        err[2] = 3
        return st
    Mg, Mi, grp_w = ws.Mg, ws.Mgi, cd.grp_w
    for g in range(n_g):
        if not _spd_inverse(Mg, Mi, g, grp_w[g]):
            err[0] = g
            err[2] = 3
            return MASS_NOT_PD
    return OK


@_internal
def _spd_inverse(Mg, Mi, g, n):
    """``Mi[g] = Mg[g]⁻¹`` of a symmetric positive definite ``n × n`` block (Cholesky: the factor in
    the lower triangle of ``Mi[g]``, then ``L⁻¹`` and ``L⁻ᵀL⁻¹``); False if not positive definite."""
    for i in range(n):
        for j in range(i + 1):
            s = Mg[g, i, j]
            for k in range(j):
                s -= Mi[g, i, k] * Mi[g, j, k]
            if i == j:
                if not s > 0.0:
                    return False
                Mi[g, i, i] = np.sqrt(s)
            else:
                Mi[g, i, j] = s / Mi[g, j, j]
    # L⁻¹ in place (lower triangle)
    for i in range(n):
        Mi[g, i, i] = 1.0 / Mi[g, i, i]
        for j in range(i):
            s = 0.0
            for k in range(j, i):
                s += Mi[g, i, k] * Mi[g, k, j]
            Mi[g, i, j] = -s * Mi[g, i, i]
    # L⁻ᵀ L⁻¹, symmetric: the upper triangle from the lower one
    for i in range(n):
        for j in range(i, n):
            s = 0.0
            for k in range(j, n):
                s += Mi[g, k, i] * Mi[g, k, j]
            Mi[g, j, i] = s
    for i in range(n):
        for j in range(i + 1, n):
            Mi[g, i, j] = Mi[g, j, i]
    return True


@_inline
def _group_times(Mi, grp_v, g, n, src, dst):
    """``dst[v_g] = M_g⁻¹ src[v_g]`` over the velocity indices ``v_g`` of group ``g``."""
    for i in range(n):
        acc = 0.0
        for j in range(n):
            acc += Mi[g, i, j] * src[grp_v[g, j]]
        dst[grp_v[g, i]] = acc


@_jit
def accept(cd, states, ws, t, q, v):
    """Search-state hook of the stateful force kinds after an accepted step at ``(t, q, v)``."""
    lay = cd.lay
    body_states(lay, q, v, ws)
    r, A, rd, w, err = ws.r, ws.A, ws.rd, ws.w, ws.err
    acc, stateful = cd.frc_acc, cd.frc_stateful
    for k in range(cd.n_frc):
        if stateful[k]:
            st = acc[k](t, q, v, r, A, rd, w, lay, _ffd(cd, k), _fix(cd, k), _fst(cd, states, k), err)
            if st != OK:
                err[0] = k
                err[2] = 1
                return st
    return OK


# ================================================================================================
# saddle-point solves (see core.compiled.layout for the block elimination)
# ================================================================================================


# Blocks have width 3 (planar body), 6 (spatial body) or 1 (extra coordinate).  The helpers below
# write the three widths out: a loop over a run-time width is not unrolled by LLVM, and with it the
# Schur assembly of the 32-link chain was measured 3× slower.


@_inline
def _minv_times(minv, b, wdt, src, so, dst, do):
    """``dst[do:do+w] = M_b⁻¹ src[so:so+w]``."""
    if wdt == 3:
        x0, x1, x2 = src[so], src[so + 1], src[so + 2]
        dst[do] = minv[b, 0, 0] * x0 + minv[b, 0, 1] * x1 + minv[b, 0, 2] * x2
        dst[do + 1] = minv[b, 1, 0] * x0 + minv[b, 1, 1] * x1 + minv[b, 1, 2] * x2
        dst[do + 2] = minv[b, 2, 0] * x0 + minv[b, 2, 1] * x1 + minv[b, 2, 2] * x2
    elif wdt == 6:
        x0, x1, x2, x3, x4, x5 = src[so], src[so + 1], src[so + 2], src[so + 3], src[so + 4], src[so + 5]
        for i in range(6):
            dst[do + i] = (minv[b, i, 0] * x0 + minv[b, i, 1] * x1 + minv[b, i, 2] * x2
                           + minv[b, i, 3] * x3 + minv[b, i, 4] * x4 + minv[b, i, 5] * x5)
    else:
        dst[do] = minv[b, 0, 0] * src[so]


@_inline
def _minv_times_row(minv, b, wdt, G, X, a, sl):
    """``X[a, sl] = M_b⁻¹ G[a, sl]`` (one Jacobian row block)."""
    if wdt == 3:
        x0, x1, x2 = G[a, sl, 0], G[a, sl, 1], G[a, sl, 2]
        X[a, sl, 0] = minv[b, 0, 0] * x0 + minv[b, 0, 1] * x1 + minv[b, 0, 2] * x2
        X[a, sl, 1] = minv[b, 1, 0] * x0 + minv[b, 1, 1] * x1 + minv[b, 1, 2] * x2
        X[a, sl, 2] = minv[b, 2, 0] * x0 + minv[b, 2, 1] * x1 + minv[b, 2, 2] * x2
    elif wdt == 6:
        x0, x1, x2, x3, x4, x5 = G[a, sl, 0], G[a, sl, 1], G[a, sl, 2], G[a, sl, 3], G[a, sl, 4], G[a, sl, 5]
        for i in range(6):
            X[a, sl, i] = (minv[b, i, 0] * x0 + minv[b, i, 1] * x1 + minv[b, i, 2] * x2
                           + minv[b, i, 3] * x3 + minv[b, i, 4] * x4 + minv[b, i, 5] * x5)
    else:
        X[a, sl, 0] = minv[b, 0, 0] * G[a, sl, 0]


@_inline
def _block_dot(G, a, sa, X, b, sb, wdt):
    """``G[a, sa] · X[b, sb]`` over a block of width ``wdt``."""
    if wdt == 3:
        return G[a, sa, 0] * X[b, sb, 0] + G[a, sa, 1] * X[b, sb, 1] + G[a, sa, 2] * X[b, sb, 2]
    if wdt == 6:
        return (G[a, sa, 0] * X[b, sb, 0] + G[a, sa, 1] * X[b, sb, 1] + G[a, sa, 2] * X[b, sb, 2]
                + G[a, sa, 3] * X[b, sb, 3] + G[a, sa, 4] * X[b, sb, 4] + G[a, sa, 5] * X[b, sb, 5])
    return G[a, sa, 0] * X[b, sb, 0]


@_inline
def _block_dot_vec(G, a, sl, x, o, wdt):
    """``G[a, sl] · x[o:o+w]``."""
    if wdt == 3:
        return G[a, sl, 0] * x[o] + G[a, sl, 1] * x[o + 1] + G[a, sl, 2] * x[o + 2]
    if wdt == 6:
        return (G[a, sl, 0] * x[o] + G[a, sl, 1] * x[o + 1] + G[a, sl, 2] * x[o + 2]
                + G[a, sl, 3] * x[o + 3] + G[a, sl, 4] * x[o + 4] + G[a, sl, 5] * x[o + 5])
    return G[a, sl, 0] * x[o]


@_inline
def _block_sub(x, o, X, a, sl, mk, wdt):
    """``x[o:o+w] -= X[a, sl] mk``."""
    if wdt == 3:
        x[o] -= X[a, sl, 0] * mk
        x[o + 1] -= X[a, sl, 1] * mk
        x[o + 2] -= X[a, sl, 2] * mk
    elif wdt == 6:
        for c in range(6):
            x[o + c] -= X[a, sl, c] * mk
    else:
        x[o] -= X[a, sl, 0] * mk


@_jit
def factor(cd, ws):
    """``X = M⁻¹Φ_qᵀ`` blocks, ``S`` of the regular rows with its envelope Cholesky factor, and the
    border ``C``, ``W = S⁻¹C``, ``T`` with its LU (:mod:`core.compiled.layout`); status code.
    The inverse mass matrices of the mass groups are those of the last :func:`mass_update`."""
    return _factor(cd.reg, cd.env_first, cd.r_blk, cd.blk_x, cd.blk_w, cd.minv, cd.pat, cd.ext, cd.rs_cnt, cd.rs,
                   cd.n_x, cd.xm, cd.hpat, cd.epat, ws.S, ws.L, ws.G, ws.X, ws.C, ws.W, ws.T, ws.piv,
                   cd.blk_g, cd.blk_go, cd.grp_w, cd.rg_cnt, cd.rg, ws.Mgi, ws.gx, ws.gy)


@_inline
def _factor(reg, first, r_blk, blk_x, blk_w, minv, pat, ext, rs_cnt, rs, nx, xm, hpat, epat, S, L, G, X, C, W, T,
            piv, blk_g, blk_go, grp_w, rg_cnt, rg, Mgi, gx, gy):
    """:func:`factor` on arrays (inlined into it)."""
    m = reg.shape[0]
    ne = ext.shape[0]
    for k in range(m + ne):
        a = reg[k] if k < m else ext[k - m]
        for u in range(rs_cnt[a]):
            if blk_g[rs[a, u, 1]] < 0:
                _minv_times_row(minv, rs[a, u, 1], rs[a, u, 3], G, X, a, rs[a, u, 0])
        for i in range(rg_cnt[a]):  # X on a mass group: gather the row's entries, M_g⁻¹, scatter
            _group_row(Mgi, rg[a, i], grp_w[rg[a, i]], blk_g, blk_go, rs_cnt, rs, G, X, a, gx, gy)
    for i in range(m):
        for j in range(first[i], i + 1):
            S[i, j] = 0.0
    for p in range(pat.shape[0]):
        a, sa, b, sb, wdt = pat[p, 0], pat[p, 1], pat[p, 2], pat[p, 3], pat[p, 6]
        S[pat[p, 4], pat[p, 5]] += _block_dot(G, a, sa, X, b, sb, wdt)
    for i in range(m):
        fi = first[i]
        for j in range(fi, i + 1):
            s = S[i, j]
            k0 = fi if fi > first[j] else first[j]
            for k in range(k0, j):
                s -= L[i, k] * L[j, k]
            if j == i:
                if s != s:
                    return NONFINITE
                if not s > PIVOT_RTOL * S[i, i]:
                    return SINGULAR
                L[i, i] = np.sqrt(s)
            else:
                L[i, j] = s / L[j, j]
    nz = nx + ne
    if nz == 0:
        return OK
    for k in range(m):
        for j in range(nz):
            C[k, j] = 0.0
        a = reg[k]
        for sl in range(MAX_SLOTS):
            b = r_blk[a, sl]
            if b >= 0 and blk_x[b] >= 0:
                for c in range(blk_w[b]):
                    C[k, blk_x[b] + c] -= G[a, sl, c]
    for p in range(hpat.shape[0]):  # H = G_RB M_B⁻¹ G_EBᵀ
        a, sa, e_row, se, wdt = hpat[p, 0], hpat[p, 1], hpat[p, 2], hpat[p, 3], hpat[p, 6]
        C[hpat[p, 4], nx + hpat[p, 5]] += _block_dot(G, a, sa, X, e_row, se, wdt)
    for j in range(nz):
        for k in range(m):
            W[k, j] = C[k, j]
        _solve_envelope(L, first, m, W[:, j])
    for i in range(nz):
        for j in range(nz):
            acc = 0.0
            for k in range(m):
                acc += C[k, i] * W[k, j]
            T[i, j] = acc
    for i in range(nx):
        for j in range(nx):
            T[i, j] += xm[i, j]
    for e in range(ne):
        a = ext[e]
        for sl in range(MAX_SLOTS):
            b = r_blk[a, sl]
            if b >= 0 and blk_x[b] >= 0:
                for c in range(blk_w[b]):
                    x = blk_x[b] + c
                    T[x, nx + e] += G[a, sl, c]
                    T[nx + e, x] += G[a, sl, c]
    for p in range(epat.shape[0]):  # −S_EE
        a, sa, b, sb, wdt = epat[p, 0], epat[p, 1], epat[p, 2], epat[p, 3], epat[p, 6]
        T[nx + epat[p, 4], nx + epat[p, 5]] -= _block_dot(G, a, sa, X, b, sb, wdt)
    return _lu_factor(T, nz, piv)


@_internal
def _group_row(Mgi, g, n, blk_g, blk_go, rs_cnt, rs, G, X, a, gx, gy):
    """``X[a] = M_g⁻¹ G[a]`` on the blocks of group ``g`` (the row holds a slot on each of them)."""
    for c in range(n):
        gx[c] = 0.0
    for u in range(rs_cnt[a]):
        b = rs[a, u, 1]
        if blk_g[b] == g:
            o, sl = blk_go[b], rs[a, u, 0]
            for c in range(rs[a, u, 3]):
                gx[o + c] = G[a, sl, c]
    for i in range(n):
        acc = 0.0
        for j in range(n):
            acc += Mgi[g, i, j] * gx[j]
        gy[i] = acc
    for u in range(rs_cnt[a]):
        b = rs[a, u, 1]
        if blk_g[b] == g:
            o, sl = blk_go[b], rs[a, u, 0]
            for c in range(rs[a, u, 3]):
                X[a, sl, c] = gy[o + c]


@_inline
def _solve_envelope(L, first, m, b):
    """Solve ``L Lᵀ x = b`` in place with the envelope factor."""
    for i in range(m):
        s = b[i]
        for k in range(first[i], i):
            s -= L[i, k] * b[k]
        b[i] = s / L[i, i]
    for i in range(m - 1, -1, -1):
        b[i] /= L[i, i]
        xi = b[i]
        for k in range(first[i], i):
            b[k] -= L[i, k] * xi


@_jit
def _lu_factor(T, n, piv):
    """LU with partial pivoting of ``T[:n, :n]`` in place (Golub & Van Loan, Alg. 3.4.1); status."""
    scale = 0.0
    for i in range(n):
        for j in range(n):
            if abs(T[i, j]) > scale:
                scale = abs(T[i, j])
    for k in range(n):
        p = k
        big = abs(T[k, k])
        for i in range(k + 1, n):
            if abs(T[i, k]) > big:
                big, p = abs(T[i, k]), i
        piv[k] = p
        if not big > PIVOT_RTOL * scale:
            return SINGULAR
        if p != k:
            for j in range(n):
                T[k, j], T[p, j] = T[p, j], T[k, j]
        for i in range(k + 1, n):
            T[i, k] /= T[k, k]
            f = T[i, k]
            for j in range(k + 1, n):
                T[i, j] -= f * T[k, j]
    return OK


@_inline
def _lu_solve(T, n, piv, b):
    for k in range(n):
        p = piv[k]
        if p != k:
            b[k], b[p] = b[p], b[k]
    for i in range(n):
        s = b[i]
        for j in range(i):
            s -= T[i, j] * b[j]
        b[i] = s
    for i in range(n - 1, -1, -1):
        s = b[i]
        for j in range(i + 1, n):
            s -= T[i, j] * b[j]
        b[i] = s / T[i, i]


@_jit
def saddle_solve(cd, ws, f, g, x, mu):
    """Solve ``[[M, Φ_qᵀ], [Φ_q, 0]] [x; μ] = [f; g]`` with the factors of :func:`factor`
    (block elimination of :mod:`core.compiled.layout`).

    ``g`` and ``mu`` are indexed by model rows (``mu`` is written for the active rows).
    """
    _saddle(cd.reg, cd.env_first, cd.blk_v0, cd.blk_w, cd.blk_x, cd.minv, cd.ext, cd.rs_cnt, cd.rs, cd.mass_blocks,
            cd.n_x, ws.G, ws.X, ws.rhs, ws.z, ws.L, ws.C, ws.W, ws.T, ws.piv, f, g, x, mu, cd.n_grp, cd.grp_v,
            cd.grp_w, ws.Mgi)


@_inline
def _saddle(reg, first, blk_v0, blk_w, blk_x, minv, ext, rs_cnt, rs, mass_blocks, nx, G, X, rhs, z, L, C, W, T, piv,
            f, g, x, mu, n_grp, grp_v, grp_w, Mgi):
    """:func:`saddle_solve` on arrays (inlined into it)."""
    # x_B0 = M_B⁻¹ f_B
    for u in range(mass_blocks.shape[0]):
        b = mass_blocks[u]
        o = blk_v0[b]
        _minv_times(minv, b, blk_w[b], f, o, x, o)
    for gi in range(n_grp):
        _group_times(Mgi, grp_v, gi, grp_w[gi], f, x)
    m = reg.shape[0]
    for k in range(m):
        a = reg[k]
        acc = 0.0
        for u in range(rs_cnt[a]):
            acc += _block_dot_vec(G, a, rs[a, u, 0], x, rs[a, u, 2], rs[a, u, 3])
        rhs[k] = acc - g[a]
    _solve_envelope(L, first, m, rhs)
    ne = ext.shape[0]
    nz = nx + ne
    if nz > 0:
        for b in range(blk_x.shape[0]):
            if blk_x[b] >= 0:
                for c in range(blk_w[b]):
                    z[blk_x[b] + c] = f[blk_v0[b] + c]
        for e in range(ne):  # −r_E = g_E − G_EB M_B⁻¹ f_B
            a = ext[e]
            acc = 0.0
            for u in range(rs_cnt[a]):
                acc += _block_dot_vec(G, a, rs[a, u, 0], x, rs[a, u, 2], rs[a, u, 3])
            z[nx + e] = g[a] - acc
        for j in range(nz):
            acc = 0.0
            for k in range(m):
                acc += C[k, j] * rhs[k]
            z[j] += acc
        _lu_solve(T, nz, piv, z)
        for k in range(m):
            acc = 0.0
            for j in range(nz):
                acc += W[k, j] * z[j]
            rhs[k] -= acc
    # x_B = x_B0 − M_B⁻¹ (G_RBᵀ μ_R + G_EBᵀ μ_E)
    for k in range(m + ne):
        if k < m:
            a = reg[k]
            mk = rhs[k]
        else:
            a = ext[k - m]
            mk = z[nx + k - m]
        mu[a] = mk
        for u in range(rs_cnt[a]):
            _block_sub(x, rs[a, u, 2], X, a, rs[a, u, 0], mk, rs[a, u, 3])
    if nz > 0:
        for b in range(blk_x.shape[0]):
            if blk_x[b] >= 0:
                for c in range(blk_w[b]):
                    x[blk_v0[b] + c] = z[blk_x[b] + c]


@_inline
def _row_dot(r_blk, blk_v0, blk_w, G, a, x):
    """``(Φ_q x)_a`` for model row ``a``."""
    acc = 0.0
    for sl in range(MAX_SLOTS):
        b = r_blk[a, sl]
        if b >= 0 and blk_w[b] > 0:
            acc += _block_dot_vec(G, a, sl, x, blk_v0[b], blk_w[b])
    return acc


@_jit
def accelerations(cd, states, ws, t, q, v, alpha, beta, vdot, lam):
    r"""Index-1 accelerations ``vdot`` and multipliers ``lam`` (active-row order); status code.

    ``M v̇ + Φ_qᵀλ = Q``, ``Φ_q v̇ = γ − 2α(Φ_q v − ν) − β²Φ``.
    """
    lay, act, blk_v0, blk_w, minv = cd.lay, cd.act, cd.blk_v0, cd.blk_w, cd.minv
    Q = ws.Q
    r, A, rd, w = ws.r, ws.A, ws.rd, ws.w
    _body_states(lay, q, v, r, A, rd, w)
    st = _forces(cd, states, t, q, v, r, A, rd, w, ws.err, Q)
    if st != OK:
        return st
    st = mass_update(cd, ws, t, q, v)
    if st != OK:
        return st
    m = act.shape[0]
    if m == 0:
        mass_blocks = cd.mass_blocks
        for u in range(mass_blocks.shape[0]):
            b = mass_blocks[u]
            o = blk_v0[b]
            _minv_times(minv, b, blk_w[b], Q, o, vdot, o)
        for gi in range(cd.n_grp):
            _group_times(ws.Mgi, cd.grp_v, gi, cd.grp_w[gi], Q, vdot)
        for i in range(vdot.shape[0]):
            if not np.isfinite(vdot[i]):
                return NONFINITE
        return OK
    r_blk = cd.r_blk
    baum = alpha != 0.0 or beta != 0.0
    flags = WANT_GAMMA
    if baum:
        flags = flags | WANT_PHI | WANT_NU
    st = constraints(cd, ws, t, q, v, flags)
    if st != OK:
        return st
    # factor and saddle_solve take the two structrefs: a call that passed their ~30 arrays one by one
    # cost more than the small chain's whole right-hand side (numba counts references per array)
    st = factor(cd, ws)
    if st != OK:
        return st
    G = ws.G
    g, gam, nu, phi, mu = ws.g, ws.gam, ws.nu, ws.phi, ws.mu
    for k in range(m):
        a = act[k]
        ga = gam[a]
        if baum:
            ga -= 2.0 * alpha * (_row_dot(r_blk, blk_v0, blk_w, G, a, v) - nu[a]) + beta * beta * phi[a]
        g[a] = ga
    saddle_solve(cd, ws, Q, g, vdot, mu)
    for k in range(m):
        lam[k] = mu[act[k]]
    for i in range(vdot.shape[0]):
        if not np.isfinite(vdot[i]):
            return NONFINITE
    return OK


@_inline
def _max_abs_phi(act, phi):
    mx = 0.0
    for k in range(act.shape[0]):
        x = abs(phi[act[k]])
        if not x <= mx:  # NaN propagates
            mx = x
    return mx


@_jit
def project(cd, ws, t, q, v, tol, max_iter, counters):
    """Coordinate projection of ``(q, v)`` in place (module docstring); returns iterations or −1.

    ``counters[3]`` counts the factorisations.
    """
    lay, act, r_blk, blk_v0, blk_w = cd.lay, cd.act, cd.r_blk, cd.blk_v0, cd.blk_w
    phi, nu, G, g, mu = ws.phi, ws.nu, ws.G, ws.g, ws.mu
    normalize(lay, q)
    m = act.shape[0]
    if m == 0:
        return 0
    zero_f = ws.tmp_v
    dq = ws.tmp_v2
    for i in range(zero_f.shape[0]):
        zero_f[i] = 0.0
    body_states(lay, q, v, ws)
    if constraints(cd, ws, t, q, v, np.int64(WANT_PHI)) != OK:
        return -1
    err = _max_abs_phi(act, phi)
    n_iter = 0
    if err > tol:
        if mass_update(cd, ws, t, q, v) != OK or factor(cd, ws) != OK:
            return -1
        counters[3] += 1
        prev = np.inf
        while True:
            for k in range(m):
                g[act[k]] = -phi[act[k]]
            saddle_solve(cd, ws, zero_f, g, dq, mu)
            retract(lay, q, dq)
            n_iter += 1
            # Φ at the new positions; the factors and M⁻¹Φ_qᵀ blocks stay frozen (constraints()
            # rewrites Φ and the G blocks, which saddle_solve reads for the right-hand side only:
            # they are restored at the velocity stage, which re-evaluates and refactorises)
            body_states(lay, q, v, ws)
            if constraints(cd, ws, t, q, v, np.int64(WANT_PHI)) != OK:
                return -1
            err = _max_abs_phi(act, phi)
            if err <= tol:
                break
            if n_iter >= max_iter or not np.isfinite(err) or err > 2.0 * prev:
                return -1
            prev = err
        normalize(lay, q)
    # velocities at the projected positions: Φ_q (v + Δv) = ν, M-orthogonal
    body_states(lay, q, v, ws)
    if constraints(cd, ws, t, q, v, np.int64(WANT_NU)) != OK:
        return -1
    if mass_update(cd, ws, t, q, v) != OK or factor(cd, ws) != OK:
        return -1
    counters[3] += 1
    for k in range(m):
        a = act[k]
        g[a] = nu[a] - _row_dot(r_blk, blk_v0, blk_w, G, a, v)
    saddle_solve(cd, ws, zero_f, g, dq, mu)
    for i in range(v.shape[0]):
        v[i] += dq[i]
    return n_iter


# ================================================================================================
# force Jacobians (implicit integrators)
# ================================================================================================


@_jit
def _kind_forces(cd, states, ws, k, t, q, v, Q):
    """``Q`` ← the generalized forces of force kind ``k`` alone at ``(t, q, v)``; status (a kernel
    failure names the kind in ``ws.err``)."""
    for i in range(Q.shape[0]):
        Q[i] = 0.0
    body_states(cd.lay, q, v, ws)
    st = cd.frc[k](t, q, v, ws.r, ws.A, ws.rd, ws.w, cd.lay, _ffd(cd, k), _fix(cd, k), _fst(cd, states, k), Q, ws.err)
    if st != OK:
        ws.err[0] = k
        ws.err[2] = 1
    return st


@_jit
def _add_group_differences(M, col, reach, c, d, nb, nvb, Qa, Qb, eps, v, velocity):
    """Columns ``nvb b + d`` of the bodies ``b`` of colour ``c``: ``(Qb − Qa)/h`` on the rows their
    perturbation reaches, ``h = √ε`` (positions) or ``√ε max(1, |v_j|)`` (``velocity``)."""
    for b in range(nb):
        if col[b] == c:
            j = nvb * b + d
            h = eps * max(1.0, abs(v[j])) if velocity else eps
            for rb in range(nb):
                if reach[b, rb]:
                    for i in range(nvb * rb, nvb * rb + nvb):
                        M[i, j] += (Qb[i] - Qa[i]) / h


@_jit
def _grouped_differences(cd, states, ws, k, t, q, v, K, D, qp, vp, Qa, Qb, eps):
    r"""Forward differences of kind ``k``'s forces (``Qa`` at ``(q, v)``) by column groups
    (:func:`core.compiled.layout.fd_colouring`): per colour and per body freedom ``d`` one
    evaluation with the freedom ``d`` of every body of that colour perturbed, each body's
    difference read from the rows its perturbation reaches; ``2 n_colours n_vb`` evaluations
    instead of ``2 n_v``."""
    lay = cd.lay
    nb, nvb, n_v = lay[0], lay[3], lay[5]
    col, reach = cd.frc_col[k], cd.frc_reach[k]
    for c in range(cd.frc_ncol[k]):
        for d in range(nvb):
            for i in range(q.shape[0]):
                qp[i] = q[i]
            for i in range(n_v):
                vp[i] = 0.0
            for b in range(nb):
                if col[b] == c:
                    vp[nvb * b + d] = eps
            retract(lay, qp, vp)
            st = _kind_forces(cd, states, ws, k, t, qp, v, Qb)
            if st != OK:
                return st
            _add_group_differences(K, col, reach, c, d, nb, nvb, Qa, Qb, eps, v, False)
            for i in range(n_v):
                vp[i] = v[i]
            for b in range(nb):
                if col[b] == c:
                    j = nvb * b + d
                    vp[j] += eps * max(1.0, abs(v[j]))
            st = _kind_forces(cd, states, ws, k, t, q, vp, Qb)
            if st != OK:
                return st
            _add_group_differences(D, col, reach, c, d, nb, nvb, Qa, Qb, eps, v, True)
    return OK


@_jit
def force_jacobian(cd, states, ws, t, q, v, K, D, qp, vp, Qa, Qb):
    r"""``K = ∂Q/∂q`` along velocity-space increments and ``D = ∂Q/∂v`` of every force kind.

    Kinds with a Jacobian kernel add their exact blocks; for the others, forward differences of
    the kind's own force kernel with steps ``h = √ε`` along position increments and
    ``h = √ε · max(1, |v_j|)`` along velocities (error O(h)), by column groups where the kind
    names its body groups (:func:`_grouped_differences`), else column by column.  The gyroscopic
    moment's ∂/∂ω̄ is exact; gravity is constant.  ``qp, vp, Qa, Qb`` are work vectors.
    """
    lay = cd.lay
    nb, dim, n_v = lay[0], lay[1], lay[5]
    for i in range(n_v):
        for j in range(n_v):
            K[i, j] = 0.0
            D[i, j] = 0.0
    body_states(lay, q, v, ws)
    if dim == 3:
        J, w = cd.Jt, ws.w
        for b in range(nb):
            # ∂(−ω̄ × Jω̄)/∂ω̄ = −(ω̄~ J − (Jω̄)~)
            w0, w1, w2 = w[b, 0], w[b, 1], w[b, 2]
            h0 = J[b, 0, 0] * w0 + J[b, 0, 1] * w1 + J[b, 0, 2] * w2
            h1 = J[b, 1, 0] * w0 + J[b, 1, 1] * w1 + J[b, 1, 2] * w2
            h2 = J[b, 2, 0] * w0 + J[b, 2, 1] * w1 + J[b, 2, 2] * w2
            for j in range(3):
                # column j of ω̄~ J − (Jω̄)~ : ω̄ × J[:, j] − (Jω̄) × e_j
                c0, c1, c2 = J[b, 0, j], J[b, 1, j], J[b, 2, j]
                x0, x1, x2 = w1 * c2 - w2 * c1, w2 * c0 - w0 * c2, w0 * c1 - w1 * c0
                e0 = 1.0 if j == 0 else 0.0
                e1 = 1.0 if j == 1 else 0.0
                e2 = 1.0 if j == 2 else 0.0
                y0, y1, y2 = h1 * e2 - h2 * e1, h2 * e0 - h0 * e2, h0 * e1 - h1 * e0
                D[6 * b + 3, 6 * b + 3 + j] -= x0 - y0
                D[6 * b + 4, 6 * b + 3 + j] -= x1 - y1
                D[6 * b + 5, 6 * b + 3 + j] -= x2 - y2
    eps = 1.4901161193847656e-08
    for k in range(cd.n_frc):
        if cd.frc_has_jac[k]:
            body_states(lay, q, v, ws)
            st = cd.frc_jac[k](t, q, v, ws.r, ws.A, ws.rd, ws.w, lay, _ffd(cd, k), _fix(cd, k), _fst(cd, states, k),
                               K, D, ws.err)
            if st != OK:
                ws.err[0] = k
                ws.err[2] = 1
                return st
            continue
        # forward differences of this kind's forces
        st = _kind_forces(cd, states, ws, k, t, q, v, Qa)
        if st != OK:
            return st
        if cd.frc_ncol[k] >= 0:
            st = _grouped_differences(cd, states, ws, k, t, q, v, K, D, qp, vp, Qa, Qb, eps)
            if st != OK:
                return st
            continue
        for j in range(n_v):
            for i in range(q.shape[0]):
                qp[i] = q[i]
            for i in range(n_v):
                vp[i] = 0.0
            h = eps
            vp[j] = h
            retract(lay, qp, vp)
            st = _kind_forces(cd, states, ws, k, t, qp, v, Qb)
            if st != OK:
                return st
            for i in range(n_v):
                K[i, j] += (Qb[i] - Qa[i]) / h
            for i in range(n_v):
                vp[i] = v[i]
            h = eps * max(1.0, abs(v[j]))
            vp[j] += h
            st = _kind_forces(cd, states, ws, k, t, q, vp, Qb)
            if st != OK:
                return st
            for i in range(n_v):
                D[i, j] += (Qb[i] - Qa[i]) / h
    body_states(lay, q, v, ws)
    return OK
