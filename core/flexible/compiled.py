r"""Flexible bodies on the compiled path: the node-frame constraint and the modal forces as kernels.

The compiled integrators eliminate the mass matrix block by block with constant inverse blocks
(:mod:`core.compiled.layout`).  A flexible body fits that form when its kinetic energy is the
undeformed body's (``inertia="undeformed"``, :mod:`core.flexible.body`) and its modes are mean
axes with the frame origin at the centre of mass: then :math:`\hat M_0` is block diagonal,

.. math::

    \hat M_0 = \operatorname{diag}\big(m I,\ \bar J_0,\ \mu_1, \dots, \mu_m\big),

a rigid body (translation in global axes, rotation in body axes, gyroscopic moment
:math:`-\bar\omega\times\bar J_0\bar\omega`, weight :math:`m g`) plus one oscillator per mode with
modal mass :math:`\mu_k`, stiffness and damping :math:`Q_f = -K_{ff} q_f - D_{ff}\dot q_f`
(:func:`modal_forces`; its exact Jacobian :func:`modal_forces_jacobian`).  The body couples to the
rest of the model only through its node frames, whose constraint
(:class:`core.flexible.body.FlexibleNodes`; equations there) is :func:`flexible_nodes`.  A node
frame's rows touch the frame, the node body and every mode, so a body on the compiled path has at
most ``MAX_SLOTS − 2`` modes.  :func:`compiled_flexible_body` checks all of this and refuses a body
that does not fit, naming it and the reason.
"""

from __future__ import annotations

import numba
import numpy as np

from ..compiled.protocol import (
    L_DIM,
    MAX_SLOTS,
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
from ..errors import NotCompilable

__all__ = ["compile_flexible_nodes", "compiled_flexible_body", "flexible_nodes", "modal_forces",
           "modal_forces_jacobian", "MAX_COMPILED_MODES", "COUPLING_TOL"]

#: Modes a flexible body may have on the compiled path (a node row touches frame, node and modes).
MAX_COMPILED_MODES = MAX_SLOTS - 2
#: Largest correlation abs(M_ij) / sqrt(M_ii M_jj) between different blocks of M̂₀ taken as zero.
COUPLING_TOL = 1e-8

_inline = numba.njit(cache=True, fastmath=False, boundscheck=False, inline="always")


# ================================================================================================
# node-frame constraint
# ================================================================================================


@constraint_kernel
def flexible_nodes(t, q, v, r, A, rd, w, lay, fd, ix, row0, flags, phi, G, nu, gam, err):
    r"""Compiled :class:`core.flexible.body.FlexibleNodes`, one element per node frame.

    ``fd[e]``: x̄ (3), then Φ_t (3 × m) and Ψ (3 × m) row by row (planar: Φ_t's z row zero, the
    rotation row in Ψ's z row); ``ix[e]``: frame body, node body, m, then m q indices and m v
    indices of the modal coordinates.  Rows ``row0 + e (dim + n_rot)``: position, then rotation.
    Slots: 0 the frame, 1 the node body, 2 + k mode k.
    """
    dim = lay[L_DIM]
    nr = 1 if dim == 2 else 3
    per = dim + nr
    s = np.zeros(3)
    sd = np.zeros(3)
    As = np.zeros(3)
    C = np.zeros((3, 3))
    H = np.zeros((3, 3))
    W = np.zeros((3, 3))
    WN = np.zeros((3, 3))
    T1 = np.zeros((3, 3))
    for e in range(ix.shape[0]):
        b, n, m = ix[e, 0], ix[e, 1], ix[e, 2]
        r0 = row0 + e * per
        for i in range(3):
            s[i] = fd[e, i]
            sd[i] = 0.0
        for k in range(m):
            qk, vk = q[ix[e, 3 + k]], v[ix[e, 3 + m + k]]
            for i in range(3):
                s[i] += fd[e, 3 + i * m + k] * qk
                sd[i] += fd[e, 3 + i * m + k] * vk
        for i in range(3):
            As[i] = A[b, i, 0] * s[0] + A[b, i, 1] * s[1] + A[b, i, 2] * s[2]
        # --- rows of the position: Φ = r_N − r − A s ------------------------------------------------
        for i in range(dim):
            row = r0 + i
            if flags & WANT_PHI:
                phi[row] = r[n, i] - r[b, i] - As[i]
            for j in range(6):
                G[row, 0, j] = 0.0
                G[row, 1, j] = 0.0
            G[row, 0, i] = -1.0
            G[row, 1, i] = 1.0
            if dim == 2:
                # ∂(−A s)/∂θ = −A R90 s = (A s)_⊥ with the sign: −(−(As)_y, (As)_x)
                G[row, 0, 2] = As[1] if i == 0 else -As[0]
            else:
                # −∂(A s)/∂θ̄ = A s̃: (A s̃)_ij = Σ_k A_ik s̃_kj
                G[row, 0, 3] = A[b, i, 1] * s[2] - A[b, i, 2] * s[1]
                G[row, 0, 4] = -A[b, i, 0] * s[2] + A[b, i, 2] * s[0]
                G[row, 0, 5] = A[b, i, 0] * s[1] - A[b, i, 1] * s[0]
            for k in range(m):
                G[row, 2 + k, 0] = -(A[b, i, 0] * fd[e, 3 + k] + A[b, i, 1] * fd[e, 3 + m + k]
                                     + A[b, i, 2] * fd[e, 3 + 2 * m + k])
            if flags & WANT_NU:
                nu[row] = 0.0
        if flags & WANT_GAMMA:
            w0, w1, w2 = w[b, 0], w[b, 1], w[b, 2]
            # a = ω̄ × (ω̄ × s) + 2 ω̄ × ṡ (body axes), γ = A a
            c0, c1, c2 = w1 * s[2] - w2 * s[1], w2 * s[0] - w0 * s[2], w0 * s[1] - w1 * s[0]
            a0 = w1 * c2 - w2 * c1 + 2.0 * (w1 * sd[2] - w2 * sd[1])
            a1 = w2 * c0 - w0 * c2 + 2.0 * (w2 * sd[0] - w0 * sd[2])
            a2 = w0 * c1 - w1 * c0 + 2.0 * (w0 * sd[1] - w1 * sd[0])
            for i in range(dim):
                gam[r0 + i] = A[b, i, 0] * a0 + A[b, i, 1] * a1 + A[b, i, 2] * a2
        # --- rows of the rotation -----------------------------------------------------------------
        o = 3 + 3 * m  # Ψ
        if dim == 2:
            row = r0 + 2
            if flags & WANT_PHI:
                val = q[3 * n + 2] - q[3 * b + 2]
                for k in range(m):
                    val -= fd[e, o + 2 * m + k] * q[ix[e, 3 + k]]
                phi[row] = val
            for j in range(6):
                G[row, 0, j] = 0.0
                G[row, 1, j] = 0.0
            G[row, 0, 2] = -1.0
            G[row, 1, 2] = 1.0
            for k in range(m):
                G[row, 2 + k, 0] = -fd[e, o + 2 * m + k]
            if flags & WANT_NU:
                nu[row] = 0.0
            if flags & WANT_GAMMA:
                gam[row] = 0.0
            continue
        # C = Aᵀ A_N
        for i in range(3):
            for j in range(3):
                C[i, j] = A[b, 0, i] * A[n, 0, j] + A[b, 1, i] * A[n, 1, j] + A[b, 2, i] * A[n, 2, j]
        tr = C[0, 0] + C[1, 1] + C[2, 2]
        for i in range(3):
            row = r0 + 3 + i
            if flags & WANT_PHI:
                if i == 0:
                    val = 0.5 * (C[2, 1] - C[1, 2])
                elif i == 1:
                    val = 0.5 * (C[0, 2] - C[2, 0])
                else:
                    val = 0.5 * (C[1, 0] - C[0, 1])
                for k in range(m):
                    val -= fd[e, o + i * m + k] * q[ix[e, 3 + k]]
                phi[row] = val
            for j in range(6):
                G[row, 0, j] = 0.0
                G[row, 1, j] = 0.0
            for j in range(3):
                dij = tr if i == j else 0.0
                G[row, 0, 3 + j] = -0.5 * (dij - C[i, j])
                G[row, 1, 3 + j] = 0.5 * (dij - C[j, i])
            for k in range(m):
                G[row, 2 + k, 0] = -fd[e, o + i * m + k]
            if flags & WANT_NU:
                nu[row] = 0.0
        if flags & WANT_GAMMA:
            # γ = −ax(W² C − 2 W C W_N + C W_N²), W = ω̄̃ (frame), W_N = ω̄̃_N (node)
            _skew(w[b, 0], w[b, 1], w[b, 2], W)
            _skew(w[n, 0], w[n, 1], w[n, 2], WN)
            for i in range(3):
                for j in range(3):
                    acc = 0.0
                    for k in range(3):
                        acc += W[i, k] * C[k, j]
                    T1[i, j] = acc  # W C
            for i in range(3):
                for j in range(3):
                    acc = 0.0
                    for k in range(3):
                        acc += W[i, k] * T1[k, j] - 2.0 * T1[i, k] * WN[k, j]
                    H[i, j] = acc  # W W C − 2 W C W_N
            for i in range(3):
                for j in range(3):
                    acc = 0.0
                    for k in range(3):
                        acc += C[i, k] * WN[k, j]
                    T1[i, j] = acc  # C W_N
            for i in range(3):
                for j in range(3):
                    acc = 0.0
                    for k in range(3):
                        acc += T1[i, k] * WN[k, j]
                    H[i, j] += acc
            gam[r0 + 3] = -0.5 * (H[2, 1] - H[1, 2])
            gam[r0 + 4] = -0.5 * (H[0, 2] - H[2, 0])
            gam[r0 + 5] = -0.5 * (H[1, 0] - H[0, 1])
    return OK


@_inline
def _skew(a0, a1, a2, S):
    S[0, 0], S[0, 1], S[0, 2] = 0.0, -a2, a1
    S[1, 0], S[1, 1], S[1, 2] = a2, 0.0, -a0
    S[2, 0], S[2, 1], S[2, 2] = -a1, a0, 0.0


def compile_flexible_nodes(nodes, layout) -> CompiledConstraints:
    """Compiled form of a :class:`core.flexible.body.FlexibleNodes` kind (one element per node frame)."""
    data = nodes.data
    d, m = data.dim, data.n_modes
    nb = layout.n_bodies
    _check_modes(data)
    b = layout.model_body_index(nodes.body)
    per = d + data.n_rot
    k = len(nodes.nodes)
    qi = [layout.extra_q_index(c, nodes.name) for c in nodes.coordinates]
    vi = [layout.extra_v_index(c, nodes.name) for c in nodes.coordinates]
    slots_modes = [layout.extra_slot(c, nodes.name) for c in nodes.coordinates]
    fd = np.zeros((k, 3 + 6 * m))
    ix = np.zeros((k, 3 + 2 * m), np.int64)
    slots = np.full((k * per, MAX_SLOTS), -1, np.int64)
    for e, (nbody, node) in enumerate(zip(nodes.node_bodies, nodes.nodes)):
        n = layout.model_body_index(nbody)
        fd[e, :d] = data.nodes[node]
        Pt = np.zeros((3, m))
        Pt[:d] = data.translation_rows(node)
        Pr = np.zeros((3, m))
        if d == 2:
            Pr[2] = data.rotation_rows(node)[0]
        else:
            Pr[:] = data.rotation_rows(node)
        fd[e, 3:3 + 3 * m] = Pt.ravel()
        fd[e, 3 + 3 * m:] = Pr.ravel()
        ix[e, :3] = (b, n, m)
        ix[e, 3:3 + m] = qi
        ix[e, 3 + m:] = vi
        rows = slice(e * per, (e + 1) * per)
        slots[rows, 0] = body_slot(b, nb)
        slots[rows, 1] = body_slot(n, nb)
        slots[rows, 2:2 + m] = slots_modes
    return CompiledConstraints(kernel=flexible_nodes, fd=fd, ix=ix, rows=k * per, slots=slots,
                               names=list(nodes.node_bodies), what=f"node frame of flexible body {nodes.body!r}")


# ================================================================================================
# modal stiffness and damping
# ================================================================================================


@force_kernel
def modal_forces(t, q, v, r, A, rd, w, lay, fd, ix, state, Q, err):
    """``Q_f −= K q_f + D q̇_f`` per flexible body (fd: K then D, m × m each, row by row, padded;
    ix: m, then m q indices and m v indices, padded)."""
    for e in range(ix.shape[0]):
        m = ix[e, 0]
        for i in range(m):
            acc = 0.0
            for j in range(m):
                acc += fd[e, i * m + j] * q[ix[e, 1 + j]] + fd[e, m * m + i * m + j] * v[ix[e, 1 + m + j]]
            Q[ix[e, 1 + m + i]] -= acc
    return OK


@force_jacobian_kernel
def modal_forces_jacobian(t, q, v, r, A, rd, w, lay, fd, ix, state, K, D, err):
    """Exact Jacobian of :func:`modal_forces`: ``∂Q_f/∂q_f = −K``, ``∂Q_f/∂q̇_f = −D``."""
    for e in range(ix.shape[0]):
        m = ix[e, 0]
        for i in range(m):
            vi = ix[e, 1 + m + i]
            for j in range(m):
                vj = ix[e, 1 + m + j]
                K[vi, vj] -= fd[e, i * m + j]
                D[vi, vj] -= fd[e, m * m + i * m + j]
    return OK


# ================================================================================================
# checks and packing
# ================================================================================================


def _check_modes(data) -> None:
    if data.n_modes > MAX_COMPILED_MODES:
        raise NotCompilable(f"flexible body {data.name!r} has {data.n_modes} modes; on the compiled path a body "
                            f"has at most {MAX_COMPILED_MODES} (a node frame's rows touch the frame, the node and "
                            "every mode); keep fewer modes or use the numpy integrators")


def compiled_flexible_body(data, layout, v_body: np.ndarray, coordinates) -> dict:
    """What the packer needs of one flexible body on the compiled path.

    Returns ``dict(mass_block, inertia, modal_mass, weight, forces)``: the body's constant mass
    block (``n_v_body`` square), its inertia tensor J̄₀ (3 × 3; planar: J in [2, 2]), the modal
    masses μ_k, and the rows of its :func:`modal_forces` element (``fd``, ``ix``).

    Raises
    ------
    NotCompilable
        Naming the body: the inertia of the deformed body (``inertia="full"``), modes that are not
        mean axes or a frame origin off the centre of mass (a coupled M̂₀), modes coupled in mass,
        more than :data:`MAX_COMPILED_MODES` modes.
    """
    name, d, r, m = data.name, data.dim, data.n_rot, data.n_modes
    if data.inertia != "undeformed":
        raise NotCompilable(f"flexible body {name!r} has the inertia of the deformed body (inertia='full'), whose "
                            "mass matrix changes with the deformation and has no compiled form; build it with "
                            "inertia='undeformed' (slowly rotating bodies) or use the numpy integrators")
    _check_modes(data)
    a = d + r
    M0 = data.undeformed_mass()
    dg = np.sqrt(np.abs(np.diag(M0)))
    corr = np.abs(M0) / np.outer(dg, dg)
    block = np.zeros_like(M0, bool)
    block[:d, :d] = True
    block[d:a, d:a] = True
    block[a:, a:] = np.eye(m, dtype=bool)
    worst = float(np.max(np.where(block, 0.0, corr)))
    if worst > COUPLING_TOL:
        i, j = np.unravel_index(int(np.argmax(np.where(block, 0.0, corr))), corr.shape)
        what = lambda k: ("translation" if k < d else "rotation" if k < a else f"mode {k - a + 1}")  # noqa: E731
        raise NotCompilable(
            f"flexible body {name!r}: its undeformed mass matrix couples {what(i)} and {what(j)} "
            f"(correlation {worst:.2e} > {COUPLING_TOL:g}); the compiled path takes mean-axis modes "
            "(free-free, orthonormalized(drop_rigid=True)) with the frame origin at the centre of mass, "
            "where the body is a rigid body plus independent modal oscillators; use the numpy integrators")
    J = np.zeros((3, 3))
    if d == 2:
        J[2, 2] = M0[2, 2]
    else:
        J[:] = M0[3:6, 3:6]
    mass_block = np.zeros((v_body, v_body))
    mass_block[:d, :d] = M0[:d, :d]
    mass_block[d:a, d:a] = M0[d:a, d:a]
    fd = np.concatenate([data.K.ravel(), data.D.ravel()])
    ix = np.concatenate([[m], [layout.extra_q_index(c, name) for c in coordinates],
                         [layout.extra_v_index(c, name) for c in coordinates]]).astype(np.int64)
    return dict(mass_block=mass_block, inertia=J, modal_mass=np.diag(M0[a:, a:]).copy(), weight=data.mass,
                fd=fd, ix=ix)


def modal_force_record(rows: list[dict], names: list[str]) -> CompiledForces:
    """One :func:`modal_forces` kind for all flexible bodies (rows padded to the largest mode count)."""
    wf = max(len(rw["fd"]) for rw in rows)
    wi = max(len(rw["ix"]) for rw in rows)
    fd = np.zeros((len(rows), wf))
    ix = np.zeros((len(rows), wi), np.int64)
    for e, rw in enumerate(rows):
        fd[e, :len(rw["fd"])] = rw["fd"]
        ix[e, :len(rw["ix"])] = rw["ix"]
    return CompiledForces(forces=modal_forces, fd=fd, ix=ix, names=list(names), jacobian=modal_forces_jacobian,
                          what="modal stiffness and damping of flexible body")
