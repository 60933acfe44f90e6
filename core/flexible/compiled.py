r"""Flexible bodies on the compiled path: node frames, modal forces and mass groups as kernels.

The compiled integrators take every flexible body of :mod:`core.flexible.body`, in one of two forms
chosen by :func:`compiled_flexible_body`.

**Rigid body plus modal oscillators.**  When the kinetic energy is the undeformed body's
(``inertia="undeformed"``) and the modes are mean axes with the frame origin at the centre of mass,
:math:`\hat M_0` is block diagonal,

.. math::

    \hat M_0 = \operatorname{diag}\big(m I,\ \bar J_0,\ \mu_1, \dots, \mu_m\big),

a rigid body (translation in global axes, rotation in body axes, gyroscopic moment
:math:`-\bar\omega\times\bar J_0\bar\omega`, weight :math:`m g`) plus one oscillator per mode with
modal mass :math:`\mu_k`, stiffness and damping :math:`Q_f = -K_{ff} q_f - D_{ff}\dot q_f`
(:func:`modal_forces`; its exact Jacobian :func:`modal_forces_jacobian`).  The packer inverts
these constant blocks once, as for a rigid body: the cheapest form.

**A mass group.**  Otherwise — the inertia of the deformed body (the default), or an undeformed
inertia that couples the frame and the modes (a frame off the centre of mass, Craig–Bampton or
cantilever modes) — the body's frame and modal coordinates form one *mass group*
(:class:`core.compiled.protocol.CompiledMass`): its mass matrix in the velocity coordinates
``(ṙ, ω̄, q̇_f)``,

.. math::

    M_b(q) = T_A^\mathsf{T} D(q_f)^\mathsf{T}\,\mathcal M\, D(q_f)\, T_A,\qquad
    T_A = \operatorname{diag}(A^\mathsf{T}, I, I),

is rebuilt at every evaluation from the one constant Gram matrix :math:`\mathcal M` of the inertia
invariants (:func:`flexible_mass`), and its generalized forces — the quadratic-velocity vector of
the Kirchhoff–Lagrange equations, gravity, modal stiffness and damping, centrifugal geometric
stiffness — by :func:`flexible_inertia_forces` (the equations of
:meth:`core.flexible.body.FlexibleBodyData.mass_and_forces`, written as loops over the same
invariants; ``D(0)`` without ``Ḋ`` and ``∂T/∂q_f`` for the undeformed inertia).  The saddle-point
solve inverts the group's matrix by its Cholesky factor at every evaluation
(:func:`core.compiled.dynamics.mass_update`), and every constraint row that touches the body gets
a slot on all of its blocks, so that ``M⁻¹Φ_qᵀ`` is complete.  Its force Jacobian for the implicit
integrators is :func:`flexible_inertia_jacobian` (forward differences over the body's own
coordinates, the numpy path's rule).

The body couples to the rest of the model through its frame and its node frames, whose
constraint (:class:`core.flexible.body.FlexibleNodes`; equations there) is :func:`flexible_nodes`;
its rows are solved with the border of the saddle-point solve (they fix massless node bodies;
:mod:`core.compiled.layout`).  A node frame's rows touch the frame, the node body and every mode,
so a body on the compiled path has at most ``MAX_SLOTS − 2`` modes, and a row touching two mass
groups at most ``MAX_SLOTS`` blocks in all; a body or row beyond that is refused, naming it.
"""

from __future__ import annotations

import numba
import numpy as np

from ..compiled.protocol import (
    L_DIM,
    L_NVB,
    MAX_SLOTS,
    NONFINITE,
    OK,
    WANT_GAMMA,
    WANT_NU,
    WANT_PHI,
    CompiledConstraints,
    CompiledForces,
    CompiledMass,
    body_slot,
    constraint_kernel,
    force_jacobian_kernel,
    force_kernel,
    mass_kernel,
)
from ..errors import NotCompilable

__all__ = ["compile_flexible_nodes", "compiled_flexible_body", "inertia_records", "flexible_nodes", "modal_forces",
           "modal_forces_jacobian", "flexible_mass", "flexible_inertia_forces", "flexible_inertia_jacobian",
           "MAX_COMPILED_MODES", "COUPLING_TOL"]

#: Modes a flexible body may have on the compiled path (a node row touches frame, node and modes).
MAX_COMPILED_MODES = MAX_SLOTS - 2
#: Largest correlation abs(M_ij) / sqrt(M_ii M_jj) between different blocks of M̂₀ taken as zero.
COUPLING_TOL = 1e-8

_internal = numba.njit(cache=True, fastmath=False, boundscheck=False, no_cpython_wrapper=True, no_cfunc_wrapper=True)


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


@_internal
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
                               names=list(nodes.node_bodies), what=f"node frame of flexible body {nodes.body!r}",
                               border=True)


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

    Returns ``dict(form=...)``:

    * ``form="oscillators"`` (undeformed inertia, mean axes with the origin at the centre of mass:
      a block diagonal M̂₀): ``mass_block`` (the constant ``n_v_body`` square block), ``inertia``
      J̄₀ (3 × 3; planar: J in [2, 2]), ``modal_mass`` μ_k, ``weight``, and the rows ``fd``, ``ix``
      of its :func:`modal_forces` element;
    * ``form="group"`` (the inertia of the deformed body, or an undeformed inertia that couples the
      frame and the modes): ``name``, ``fd``, ``ix`` — the row of its :func:`flexible_mass` and
      :func:`flexible_inertia_forces` elements (:func:`inertia_records`).

    Raises
    ------
    NotCompilable
        Naming the body: more than :data:`MAX_COMPILED_MODES` modes.
    """
    name, d, r, m = data.name, data.dim, data.n_rot, data.n_modes
    _check_modes(data)
    a = d + r
    qi = [layout.extra_q_index(c, name) for c in coordinates]
    vi = [layout.extra_v_index(c, name) for c in coordinates]
    if data.inertia == "undeformed":
        M0 = data.undeformed_mass()
        dg = np.sqrt(np.abs(np.diag(M0)))
        corr = np.abs(M0) / np.outer(dg, dg)
        block = np.zeros_like(M0, bool)
        block[:d, :d] = True
        block[d:a, d:a] = True
        block[a:, a:] = np.eye(m, dtype=bool)
        if float(np.max(np.where(block, 0.0, corr))) <= COUPLING_TOL:
            J = np.zeros((3, 3))
            if d == 2:
                J[2, 2] = M0[2, 2]
            else:
                J[:] = M0[3:6, 3:6]
            mass_block = np.zeros((v_body, v_body))
            mass_block[:d, :d] = M0[:d, :d]
            mass_block[d:a, d:a] = M0[d:a, d:a]
            fd = np.concatenate([data.K.ravel(), data.D.ravel()])
            ix = np.concatenate([[m], qi, vi]).astype(np.int64)
            return dict(form="oscillators", mass_block=mass_block, inertia=J, modal_mass=np.diag(M0[a:, a:]).copy(),
                        weight=data.mass, fd=fd, ix=ix)
    # a mass group: the frame and the modes with the mass matrix M(q_f) (module docstring)
    b = layout.model_body_index(name)
    n_prod = 0 if data.KG is None else data.KG.shape[0]
    S3 = np.zeros((3, m))
    S3[:d] = data.S
    f3 = np.zeros(3)
    f3[:d] = data.first_moment
    g3 = np.zeros(3)
    g3[:d] = layout.gravity
    fd = np.concatenate([g3, [data.mass], f3, S3.ravel(), data.K.ravel(), data.D.ravel(), data.gram.ravel(),
                         np.zeros(0) if data.KG is None else data.KG.ravel()])
    ix = np.concatenate([[b, m, int(data.inertia == "undeformed"), n_prod], qi, vi]).astype(np.int64)
    return dict(form="group", name=name, fd=fd, ix=ix)


def inertia_records(rows: list[dict]) -> tuple[CompiledMass, CompiledForces]:
    """The mass groups of the flexible bodies whose mass matrix follows the deformation: one
    :func:`flexible_mass` record and one :func:`flexible_inertia_forces` kind for all of them (rows
    of :func:`compiled_flexible_body` with ``form="group"``, each with the body's ``v_index``: frame
    coordinates then modal coordinates), rows padded to the longest."""
    fd, ix = _padded_rows(rows)
    names = [rw["name"] for rw in rows]
    mass = CompiledMass(kernel=flexible_mass, fd=fd, ix=ix, groups=[rw["v_index"] for rw in rows], names=names,
                        what="flexible body")
    forces = CompiledForces(forces=flexible_inertia_forces, fd=fd, ix=ix, names=names,
                            jacobian=flexible_inertia_jacobian,
                            what="inertia, elastic and gravity forces of flexible body")
    return mass, forces


# ================================================================================================
# mass groups: the inertia of the deformed body
# ================================================================================================
#
# Row e of fd: g (3), m_total, ∫ρx̄ (3), S (3 × m), K (m × m), D (m × m), the Gram matrix 𝓜 (n_c × n_c),
# K_G (n_prod × m × m); of ix: body, m, undeformed (0/1), n_prod, m q indices, m v indices.
# With the notation of core.flexible.body: d = dim, r = n_rot, a = d + r, n_c = a + m r + m;
# c = (V̄, ω̄, q₁ω̄ … q_mω̄, q̇_f), D(q_f) maps ν̂ = (V̄, ω̄, q̇_f) to c.


@_internal
def _offsets(m, nc):
    """Offsets of K, D, the Gram matrix and K_G in a row of fd (g at 0, the mass at 3, ∫ρx̄ at 4, S at 7)."""
    o_s = 7
    o_k = o_s + 3 * m
    o_d = o_k + m * m
    o_g = o_d + m * m
    return o_k, o_d, o_g, o_g + nc * nc


@_internal
def _dt(x, qe, d, r, m, out):
    """``out = D(q_e)ᵀ x`` (x of length n_c, out of length a + m)."""
    a = d + r
    for i in range(d):
        out[i] = x[i]
    for j in range(r):
        acc = x[d + j]
        for k in range(m):
            acc += qe[k] * x[a + k * r + j]
        out[d + j] = acc
    for k in range(m):
        out[a + k] = x[a + m * r + k]


@_internal
def _cross_into(dim, a0, a1, a2, b0, b1, b2, out, o, sign):
    """``out[o:] += sign · a × b`` (planar: the z component into ``out[o]``)."""
    if dim == 2:
        out[o] += sign * (a0 * b1 - a1 * b0)
    else:
        out[o] += sign * (a1 * b2 - a2 * b1)
        out[o + 1] += sign * (a2 * b0 - a0 * b2)
        out[o + 2] += sign * (a0 * b1 - a1 * b0)


@_internal
def _mass_block(fd, e, d, r, m, undeformed, Ab, qf, Mb, wk):
    r"""``Mb`` = the body's mass block in the model's velocity coordinates ``(ṙ, ω̄, q̇_f)``:
    :math:`T_A^T D^T\mathcal M D\, T_A` (``D = D(0)`` for the undeformed inertia).  ``wk``: work
    (at least 3 n_c + m)."""
    a = d + r
    nc = a + m * r + m
    n = a + m
    o_gr = _offsets(m, nc)[2]
    t = wk[:nc]
    col = wk[nc:nc + n]
    qe = wk[2 * nc:2 * nc + m]
    for k in range(m):
        qe[k] = 0.0 if undeformed else qf[k]
    for i in range(n):
        # t = 𝓜 D[:, i]
        if i < d:
            for u in range(nc):
                t[u] = fd[e, o_gr + u * nc + i]
        elif i < a:
            j = i - d
            for u in range(nc):
                acc = fd[e, o_gr + u * nc + d + j]
                for k in range(m):
                    acc += qe[k] * fd[e, o_gr + u * nc + a + k * r + j]
                t[u] = acc
        else:
            for u in range(nc):
                t[u] = fd[e, o_gr + u * nc + a + m * r + (i - a)]
        _dt(t, qe, d, r, m, col)
        for u in range(n):
            Mb[u, i] = col[u]
    # rows and columns of the translation in global axes: A M[:d, :], M[:, :d] Aᵀ
    for j in range(n):
        for i in range(d):
            t[i] = Mb[i, j]
        for i in range(d):
            acc = 0.0
            for k in range(d):
                acc += Ab[i, k] * t[k]
            Mb[i, j] = acc
    for i in range(n):
        for j in range(d):
            t[j] = Mb[i, j]
        for j in range(d):
            acc = 0.0
            for k in range(d):
                acc += t[k] * Ab[j, k]
            Mb[i, j] = acc
    for i in range(n):
        for j in range(i):
            x = 0.5 * (Mb[i, j] + Mb[j, i])
            Mb[i, j] = x
            Mb[j, i] = x


@_internal
def _inertia_rhs(fd, e, d, r, m, undeformed, n_prod, Ab, rdot, om, qf, qfd, rhs, wk):
    r"""The body's generalized forces ``rhs`` (length a + m) in the model's velocity coordinates:
    :math:`T_A^T(F - h)` with the quadratic-velocity vector ``h``, gravity, elastic, damping and
    geometric-stiffening forces of :meth:`core.flexible.body.FlexibleBodyData.mass_and_forces`.

    ``Ab`` (3 × 3) the frame's rotation, ``rdot`` (3) its velocity, ``om`` (3) the body-axes angular
    velocity (planar: ``om[0]`` = θ̇); ``wk``: work (at least 5 n_c + 2 a + m + 6).

    With ``y = 𝓜 c`` and ``z = 𝓜 u``, ``u = Ḋ ν̂ − D[:, :d](ω̄ × V̄)`` (the ``q̇_k ω̄`` rows and
    ``−ω̄ × V̄``), the momenta are ``p = Dᵀ y`` and

    .. math::

        h = D^T z + \dot D^T y + (\bar\omega\times p_V,\ \bar\omega\times p_\omega + \bar V\times p_V,\ 
            -(\textstyle\sum_j y_{k,j}\,\omega_j)_k)

    (Kirchhoff–Lagrange equations, module docstring of :mod:`core.flexible.body`); the undeformed
    inertia takes ``D = D(0)`` and drops ``Ḋ`` and ``∂T/∂q_f``.
    """
    a = d + r
    nc = a + m * r + m
    o_k, o_d, o_gr, o_kg = _offsets(m, nc)
    c = wk[:nc]
    u = wk[nc:2 * nc]
    y = wk[2 * nc:3 * nc]
    z = wk[3 * nc:4 * nc]
    p = wk[4 * nc:4 * nc + a + m]
    qe = wk[4 * nc + a + m:4 * nc + a + 2 * m]
    V = wk[4 * nc + a + 2 * m:4 * nc + a + 2 * m + 3]
    gb = wk[4 * nc + a + 2 * m + 3:4 * nc + a + 2 * m + 6]
    for k in range(m):
        qe[k] = 0.0 if undeformed else qf[k]
    for i in range(3):
        V[i] = 0.0
        gb[i] = 0.0
    for i in range(d):
        acc = 0.0
        acc_g = 0.0
        for k in range(d):
            acc += Ab[k, i] * rdot[k]
            acc_g += Ab[k, i] * fd[e, k]
        V[i] = acc
        gb[i] = acc_g
    # c and u
    for i in range(nc):
        c[i] = 0.0
        u[i] = 0.0
    for i in range(d):
        c[i] = V[i]
    for j in range(r):
        c[d + j] = om[j]
    for k in range(m):
        for j in range(r):
            c[a + k * r + j] = qe[k] * om[j]
            if not undeformed:
                u[a + k * r + j] = qfd[k] * om[j]
        c[a + m * r + k] = qfd[k]
    if d == 2:  # ω × V with ω = θ̇ e_z
        u[0] = om[0] * V[1]
        u[1] = -om[0] * V[0]
    else:
        u[0] = -(om[1] * V[2] - om[2] * V[1])
        u[1] = -(om[2] * V[0] - om[0] * V[2])
        u[2] = -(om[0] * V[1] - om[1] * V[0])
    for i in range(nc):
        acc_y = 0.0
        acc_z = 0.0
        for j in range(nc):
            gij = fd[e, o_gr + i * nc + j]
            acc_y += gij * c[j]
            acc_z += gij * u[j]
        y[i] = acc_y
        z[i] = acc_z
    _dt(y, qe, d, r, m, p)
    _dt(z, qe, d, r, m, rhs)  # h, negated below
    if not undeformed:
        for j in range(r):
            acc = 0.0
            for k in range(m):
                acc += qfd[k] * y[a + k * r + j]
            rhs[d + j] += acc  # Ḋᵀ y
        for k in range(m):
            acc = 0.0
            for j in range(r):
                acc += y[a + k * r + j] * om[j]
            rhs[a + k] -= acc  # −∂T/∂q_k
    if d == 2:
        rhs[0] += -om[0] * p[1]
        rhs[1] += om[0] * p[0]
        rhs[2] += V[0] * p[1] - V[1] * p[0]
    else:
        _cross_into(3, om[0], om[1], om[2], p[0], p[1], p[2], rhs, 0, 1.0)
        _cross_into(3, om[0], om[1], om[2], p[3], p[4], p[5], rhs, 3, 1.0)
        _cross_into(3, V[0], V[1], V[2], p[0], p[1], p[2], rhs, 3, 1.0)
    for i in range(a + m):
        rhs[i] = -rhs[i]
    # F: gravity, elastic, damping, geometric stiffening
    mass = fd[e, 3]
    for i in range(d):
        rhs[i] += mass * gb[i]
    s0, s1, s2 = fd[e, 4], fd[e, 5], fd[e, 6]
    for k in range(m):
        s0 += fd[e, 7 + k] * qf[k]
        s1 += fd[e, 7 + m + k] * qf[k]
        s2 += fd[e, 7 + 2 * m + k] * qf[k]
    _cross_into(d, s0, s1, s2, gb[0], gb[1], gb[2], rhs, d, 1.0)
    for k in range(m):
        acc = fd[e, 7 + k] * gb[0] + fd[e, 7 + m + k] * gb[1] + fd[e, 7 + 2 * m + k] * gb[2]
        for l in range(m):
            acc -= fd[e, o_k + k * m + l] * qf[l] + fd[e, o_d + k * m + l] * qfd[l]
        rhs[a + k] += acc
    if n_prod:
        for pp in range(n_prod):
            if d == 2:
                w_p = om[0] * om[0]
            else:  # ω_x², ω_xω_y, ω_xω_z, ω_y², ω_yω_z, ω_z² (core.flexible.body._omega_products)
                i0, j0 = _pair(pp)
                w_p = om[i0] * om[j0]
            for k in range(m):
                acc = 0.0
                for l in range(m):
                    acc += fd[e, o_kg + pp * m * m + k * m + l] * qf[l]
                rhs[a + k] -= w_p * acc
    # translation rows in global axes
    t0 = rhs[0]
    t1 = rhs[1]
    t2 = rhs[2] if d == 3 else 0.0
    for i in range(d):
        rhs[i] = Ab[i, 0] * t0 + Ab[i, 1] * t1 + (Ab[i, 2] * t2 if d == 3 else 0.0)


@_internal
def _pair(pp):
    """Indices (i, j) of the p-th product ω_i ω_j in the order xx, xy, xz, yy, yz, zz."""
    if pp < 3:
        return 0, pp
    if pp < 5:
        return 1, pp - 2
    return 2, 2


@_internal
def _body_state(e, ix, q, v, A, rd, w, d, m, Ab, rdot, om, qf, qfd):
    """The frame's rotation, velocity and body-axes angular velocity, modal coordinates and rates
    of body ``e`` copied into the work arrays (``om[0]`` = θ̇ in the plane)."""
    b = ix[e, 0]
    for i in range(3):
        rdot[i] = rd[b, i]
        for j in range(3):
            Ab[i, j] = A[b, i, j]
    if d == 2:
        om[0] = w[b, 2]
    else:
        for i in range(3):
            om[i] = w[b, i]
    for k in range(m):
        qf[k] = q[ix[e, 4 + k]]
        qfd[k] = v[ix[e, 4 + m + k]]


@_internal
def _work(lay, ix):
    """Work arrays of the mass-group kernels, sized for the body with the most modes:
    ``(dim, n_rot, A_b, ṙ, ω̄, q_f, q̇_f, rhs, wk)``."""
    d = lay[L_DIM]
    r_ = 1 if d == 2 else 3
    mx = 0
    for e in range(ix.shape[0]):
        mx = max(mx, ix[e, 1])
    nc_max = d + r_ + mx * r_ + mx
    return (d, r_, np.zeros((3, 3)), np.zeros(3), np.zeros(3), np.zeros(mx), np.zeros(mx), np.zeros(d + r_ + mx),
            np.zeros(5 * nc_max + 2 * (d + r_) + 2 * mx + 6))


@mass_kernel
def flexible_mass(t, q, v, r, A, rd, w, lay, fd, ix, Mg, err):
    r"""``Mg[e]``: the mass matrix :math:`T_A^T D(q_f)^T\mathcal M D(q_f) T_A` of flexible body ``e`` in
    its velocity coordinates ``(ṙ, ω̄, q̇_f)`` (:meth:`core.flexible.body.FlexibleBodyData.mass_block`)."""
    d, r_, Ab, rdot, om, qf, qfd, rhs, wk = _work(lay, ix)
    for e in range(ix.shape[0]):
        m = ix[e, 1]
        _body_state(e, ix, q, v, A, rd, w, d, m, Ab, rdot, om, qf, qfd)
        _mass_block(fd, e, d, r_, m, ix[e, 2] != 0, Ab, qf, Mg[e], wk)
        for i in range(d + r_ + m):
            if not np.isfinite(Mg[e, i, i]):
                err[1] = e
                return NONFINITE
    return OK


@force_kernel
def flexible_inertia_forces(t, q, v, r, A, rd, w, lay, fd, ix, state, Q, err):
    """``Q +=`` the quadratic-velocity, gravity, elastic, damping and geometric-stiffening forces of
    every flexible body in a mass group, on its frame and modal coordinates (:func:`_inertia_rhs`)."""
    d, r_, Ab, rdot, om, qf, qfd, rhs, wk = _work(lay, ix)
    nvb = lay[L_NVB]
    for e in range(ix.shape[0]):
        m = ix[e, 1]
        _body_state(e, ix, q, v, A, rd, w, d, m, Ab, rdot, om, qf, qfd)
        _inertia_rhs(fd, e, d, r_, m, ix[e, 2] != 0, ix[e, 3], Ab, rdot, om, qf, qfd, rhs, wk)
        o = ix[e, 0] * nvb
        for i in range(d + r_):
            Q[o + i] += rhs[i]
        for k in range(m):
            Q[ix[e, 4 + m + k]] += rhs[d + r_ + k]
    return OK


@force_jacobian_kernel
def flexible_inertia_jacobian(t, q, v, r, A, rd, w, lay, fd, ix, state, K, D, err):
    r"""``K += ∂Q/∂q``, ``D += ∂Q/∂v`` of :func:`flexible_inertia_forces` over each body's own
    coordinates, by forward differences (steps 1e-7 along rotation and modal increments,
    1e-7 · max(1, |v_j|) along velocities; the numpy path's rule, :meth:`core.model.Model`):
    the forces do not depend on the frame's position, and on its translational velocity only
    through terms that cancel (``V̄̇ = Aᵀr̈ − ω̄ × V̄``), so those columns are zero."""
    d, r_, Ab, rdot, om, qf, qfd, rhs0, wk = _work(lay, ix)
    a = d + r_
    nvb = lay[L_NVB]
    Ap = np.zeros((3, 3))
    R = np.zeros((3, 3))
    omp = np.zeros(3)
    qfp = np.zeros(qf.shape[0])
    qfdp = np.zeros(qf.shape[0])
    rhs1 = np.zeros(rhs0.shape[0])
    vidx = np.zeros(rhs0.shape[0], np.int64)
    for e in range(ix.shape[0]):
        m = ix[e, 1]
        n = a + m
        und, npr = ix[e, 2] != 0, ix[e, 3]
        _body_state(e, ix, q, v, A, rd, w, d, m, Ab, rdot, om, qf, qfd)
        for i in range(a):
            vidx[i] = ix[e, 0] * nvb + i
        for k in range(m):
            vidx[a + k] = ix[e, 4 + m + k]
        _inertia_rhs(fd, e, d, r_, m, und, npr, Ab, rdot, om, qf, qfd, rhs0, wk)
        for j in range(d, n):
            # --- velocity column ---
            for i in range(3):
                omp[i] = om[i]
            for k in range(m):
                qfdp[k] = qfd[k]
            vj = om[j - d] if j < a else qfd[j - a]
            h = 1e-7 * max(1.0, abs(vj))
            if j < a:
                omp[j - d] += h
            else:
                qfdp[j - a] += h
            _inertia_rhs(fd, e, d, r_, m, und, npr, Ab, rdot, omp, qf, qfdp, rhs1, wk)
            for i in range(n):
                D[vidx[i], vidx[j]] += (rhs1[i] - rhs0[i]) / h
            # --- position column: a body-axes rotation (A ← A R) or a modal coordinate ---
            h = 1e-7
            for k in range(m):
                qfp[k] = qf[k]
            for i in range(3):
                for l in range(3):
                    Ap[i, l] = Ab[i, l]
            if j < a:
                _small_rotation(d, j - d, h, R)
                for i in range(3):
                    for l in range(3):
                        acc = 0.0
                        for k in range(3):
                            acc += Ab[i, k] * R[k, l]
                        Ap[i, l] = acc
            else:
                qfp[j - a] += h
            _inertia_rhs(fd, e, d, r_, m, und, npr, Ap, rdot, om, qfp, qfd, rhs1, wk)
            for i in range(n):
                K[vidx[i], vidx[j]] += (rhs1[i] - rhs0[i]) / h
    return OK


@_internal
def _small_rotation(d, axis, h, R):
    """``R`` = the rotation by ``h`` about body axis ``axis`` (planar: about z)."""
    ax = 2 if d == 2 else axis
    c, s = np.cos(h), np.sin(h)
    for i in range(3):
        for j in range(3):
            R[i, j] = 1.0 if i == j else 0.0
    i1, i2 = (ax + 1) % 3, (ax + 2) % 3
    R[i1, i1] = c
    R[i2, i2] = c
    R[i1, i2] = -s
    R[i2, i1] = s


def modal_force_record(rows: list[dict], names: list[str]) -> CompiledForces:
    """One :func:`modal_forces` kind for all flexible bodies (rows padded to the largest mode count)."""
    fd, ix = _padded_rows(rows)
    return CompiledForces(forces=modal_forces, fd=fd, ix=ix, names=list(names), jacobian=modal_forces_jacobian,
                          what="modal stiffness and damping of flexible body")


def _padded_rows(rows: list[dict]) -> tuple[np.ndarray, np.ndarray]:
    """The bodies' ``fd`` and ``ix`` rows as two 2-D arrays, zero-padded to the longest row."""
    fd = np.zeros((len(rows), max(len(rw["fd"]) for rw in rows)))
    ix = np.zeros((len(rows), max(len(rw["ix"]) for rw in rows)), np.int64)
    for e, rw in enumerate(rows):
        fd[e, :len(rw["fd"])] = rw["fd"]
        ix[e, :len(rw["ix"])] = rw["ix"]
    return fd, ix
