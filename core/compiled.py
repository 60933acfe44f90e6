r"""Compiled (numba) evaluation of a frozen :class:`core.model.Model`: index-1 accelerations and projection.

Why this module exists
----------------------
The vectorised numpy path of :class:`core.model.Model` costs 110–180 µs per index-1 right-hand
side on the N-link chain (N = 8…32), almost all of it Python-level call overhead of small numpy
operations; Exudyn's C++ needs 4–6 µs (``benchmarks/peer_chain.py``).  Here the same equations are
evaluated element by element in compiled loops over flat arrays fixed at compile time, and the
saddle-point system is solved through its Schur complement with a sparse (envelope) Cholesky
factorisation in a bandwidth-reducing row order.  The explicit integrators of
:mod:`core.integrators.compiled_rk` call these kernels from their own compiled step loop.

Equations (identical to the numpy path; see :mod:`core.constraints`, :mod:`core.forces`)
-----------------------------------------------------------------------------------------
Per body (planar ``q_b = (x, y, θ)``, spatial ``q_b = (r, e0…e3)`` with body-frame ω̄),
``r_P = r + A s̄``, ``ṙ_P = ṙ + C(s̄) ω``, ``a^q(s̄)`` with, planar, ``C = A R s̄``, ``a^q = −A s̄ θ̇²``
and, spatial, ``C = −A s̄̃``, ``a^q = A(ω̄ × (ω̄ × s̄))`` (Nikravesh 1988, Eqs. 6.151–6.156).

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

Forces: gravity ``m g``; gyroscopic ``−ω̄ × J ω̄`` (spatial); zero-length point spring
``F_P = k d + c ḋ``; spring-damper ``F_P = (k (L − L₀) + c L̇) u``; each applied at its points as
``Q_b += [F; C(s̄)ᵀ F]``.

Index-1 accelerations with Baumgarte terms (Baumgarte 1972), solved by the Schur complement
(Haug 1989, Sec. 6.3; Nocedal & Wright 2006, Sec. 16.2):

.. math::

    \hat\gamma = \gamma - 2\alpha\,\Phi_q v - \beta^2 \Phi,\qquad
    S = \Phi_q M^{-1} \Phi_q^T,\qquad
    S\,\lambda = \Phi_q M^{-1} Q - \hat\gamma,\qquad
    \dot v = M^{-1}(Q - \Phi_q^T \lambda).

``S`` is symmetric positive definite for independent constraints; its sparsity follows the
bodies shared by constraint rows.  Rows are ordered by reverse Cuthill–McKee
(``scipy.sparse.csgraph.reverse_cuthill_mckee``) at compile time and ``S`` is factorised by the
envelope (profile) Cholesky algorithm (George & Liu 1981, Ch. 4; Golub & Van Loan 2013,
Alg. 4.2.1 restricted to the envelope): ``O(Σ_i w_i²)`` work for row widths ``w_i`` — a band of
width 3–4 on chains.  A non-positive pivot means dependent or singular constraints and is reported
as a failure (redundant rows must be removed at build, ``redundant="remove"``); so is a pivot below
``PIVOT_RTOL = 1e-12`` times its diagonal entry (rows dependent to round-off).

Coordinate projection (Eich 1993), the same algorithm as :func:`core.integrators.index1.project`:
simplified Gauss–Newton ``S μ = Φ``, ``Δ = −M⁻¹Φ_qᵀ μ``, ``q ← q ⊕ Δ`` with ``Φ_q`` frozen, until
``‖Φ‖∞ ≤ tol``; then ``v ← v − M⁻¹Φ_qᵀ S⁻¹ (Φ_q v)`` at the projected positions.

What compiles
-------------
Planar and spatial bodies; point-coincidence, dot-1, dot-2, distance and planar-angle primitives
(all time-independent joints: revolute, spherical, universal, cylindrical, translational, fixed,
distance); gravity, point springs and spring-dampers without actuator functions.  Drivers,
user constraints, extra coordinates and the other force kinds evaluate Python callables or have no
kernel yet: :func:`compile_model` raises :class:`NotCompilable` naming the element.

References
----------
J. Baumgarte, Comput. Methods Appl. Mech. Eng. 1 (1972) 1–16.
E. Eich, SIAM J. Numer. Anal. 30(5) (1993) 1467–1482.
A. George, J. W. H. Liu, *Computer Solution of Large Sparse Positive Definite Systems*, 1981.
G. H. Golub, C. F. Van Loan, *Matrix Computations*, 4th ed., 2013.
E. J. Haug, *Computer-Aided Kinematics and Dynamics of Mechanical Systems*, 1989.
P. E. Nikravesh, *Computer-Aided Analysis of Mechanical Systems*, 1988.
J. Nocedal, S. J. Wright, *Numerical Optimization*, 2nd ed., 2006.
"""

from __future__ import annotations

import weakref
from collections import namedtuple

import numba
import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import reverse_cuthill_mckee

from .constraints import Distance, Dot1, Dot2, PlanarAngle, PointCoincidence
from .forces import PointSpringKind, SpringDamperKind

# status codes returned by the kernels (messages in STATUS_MESSAGES)
OK, SINGULAR, COINCIDENT, NONFINITE, PROJECTION = 0, 1, 2, 3, 4
STATUS_MESSAGES = {
    SINGULAR: "the constraint Schur complement Φ_q M⁻¹ Φ_qᵀ is not positive definite "
              "(dependent constraints or a singular configuration)",
    COINCIDENT: "the attachment points of a spring-damper coincide (direction undefined)",
    NONFINITE: "non-finite value in the right-hand side",
    PROJECTION: "coordinate projection did not converge",
}

#: a Cholesky pivot below this fraction of its diagonal entry means numerically dependent rows
PIVOT_RTOL = 1e-12

# kind codes for constraint primitives
K_POINT, K_DOT1, K_DOT2, K_DIST, K_ANGLE = 0, 1, 2, 3, 4


class NotCompilable(TypeError):
    """The model contains an element without a compiled kernel (the message names it)."""


CompiledData = namedtuple("CompiledData", [
    "nb", "dim", "nqb", "nvb", "n_q", "n_v", "m",
    # constraint primitives (one entry per element): kind, bodies, 4 local vectors, scalar, first row
    "c_kind", "c_bi", "c_bj", "c_v1", "c_v2", "c_v3", "c_scalar", "c_row0", "c_rows",
    # bodies of each model row (slot 0 = i, 1 = j; nb = ground); (model row index of each active row) and the inverse permutation to the RCM order
    "r_b", "act", "perm_of_row", "row_is_active",
    # Schur pattern: pairs (a, sa, b, sb) with S[pa, pb] += G[a, sa]·X[b, sb]; envelope starts
    "p_a", "p_sa", "p_b", "p_sb", "p_i", "p_j", "env_first",
    # masses
    "minv", "Qg", "J",
    # forces: point springs (ps_*) and spring-dampers (sd_*)
    "ps_bi", "ps_bj", "ps_si", "ps_sj", "ps_k", "ps_c",
    "sd_bi", "sd_bj", "sd_si", "sd_sj", "sd_k", "sd_c", "sd_L0",
])

#: Scratch arrays: body poses r, A (3-D), velocities rd, w; Φ, Φ_q blocks G, γ, M⁻¹Φ_qᵀ blocks X (all
#: model rows); Schur complement S and its envelope factor L; Q; Schur right-hand side; a velocity vector.
Workspace = namedtuple("Workspace", ["r", "A", "rd", "w", "phi", "G", "gam", "X", "S", "L", "Q", "rhs", "tmp_v"])


# ================================================================================================
# compile time (Python)
# ================================================================================================


_CACHE: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def compile_model(model) -> CompiledData:
    """Pack a frozen :class:`core.model.Model` into the flat arrays of the compiled kernels.

    The arrays are built once per model and cached (the model is immutable): like Exudyn's
    ``Assemble`` it is model set-up, ~2 ms for the 8-link chain, not repeated per simulation.
    The arrays are read-only; every integrator allocates its own :func:`make_workspace`.

    Raises
    ------
    NotCompilable
        For drivers, user constraints, extra coordinates, force kinds without a kernel, spring
        actuators, massless bodies or redundant rows kept in the model (``redundant="keep"``).
    """
    from .model import Model

    if isinstance(model, Model):
        try:
            return _CACHE[model]
        except (KeyError, TypeError):
            pass
    cd = _compile(model)
    for arr in cd:
        if isinstance(arr, np.ndarray):
            arr.setflags(write=False)
    try:
        _CACHE[model] = cd
    except TypeError:  # pragma: no cover - a model class without weak references
        pass
    return cd


def _compile(model) -> CompiledData:
    from .model import Model

    if not isinstance(model, Model):
        raise NotCompilable(f"compiled integrators need a core.model.Model, got {type(model).__name__} "
                            f"{getattr(model, 'name', '')!r}; use the numpy integrators for hand-written systems")
    sp_ = model.space
    nb, dim = model.n_bodies, sp_.dim
    nqb, nvb = sp_.n_q, sp_.n_v
    if model.extra_names:
        raise NotCompilable(f"model {model.name!r}: extra coordinate {model.extra_names[0]!r} has no compiled kernel")
    if model.user_constraints:
        raise NotCompilable(f"model {model.name!r}: user constraint {model.user_constraints[0].name!r} "
                            "evaluates Python callables and cannot be compiled")
    if len(getattr(model, "redundant_rows", ())) and model._active_rows is None:
        raise NotCompilable(f"model {model.name!r} keeps redundant constraint rows "
                            f"({', '.join(model.redundant_constraints[:3])}...); build it with redundant='remove' "
                            "for the compiled integrators (their Schur complement must be positive definite)")
    # --- constraint primitives ------------------------------------------------------------------
    kinds, bis, bjs, v1, v2, v3, sc, row0, nrows = [], [], [], [], [], [], [], [], []
    row = 0
    z = np.zeros(3)

    def pad(a):
        out = np.zeros(3)
        out[:dim] = a
        return out

    for kind in model.kinds:
        if kind.time_dependent or type(kind) not in (PointCoincidence, Dot1, Dot2, Distance, PlanarAngle):
            raise NotCompilable(f"model {model.name!r}: constraint {kind.labels[0]!r} ({type(kind).__name__}) has no "
                                "compiled kernel (drivers evaluate Python time functions)")
        for e in range(kind.n):
            bis.append(kind.bi[e])
            bjs.append(kind.bj[e])
            row0.append(row)
            nrows.append(kind.rows)
            row += kind.rows
            if isinstance(kind, PointCoincidence):
                kinds.append(K_POINT); v1.append(pad(kind.si[e])); v2.append(pad(kind.sj[e])); v3.append(z); sc.append(0.0)
            elif isinstance(kind, Dot1):
                kinds.append(K_DOT1); v1.append(pad(kind.ai[e])); v2.append(pad(kind.aj[e])); v3.append(z); sc.append(kind.c[e])
            elif isinstance(kind, Dot2):
                kinds.append(K_DOT2); v1.append(pad(kind.ai[e])); v2.append(pad(kind.si[e])); v3.append(pad(kind.sj[e]))
                sc.append(kind.c[e])
            elif isinstance(kind, Distance):
                kinds.append(K_DIST); v1.append(pad(kind.si[e])); v2.append(pad(kind.sj[e])); v3.append(z); sc.append(kind.L[e])
            else:
                kinds.append(K_ANGLE); v1.append(z); v2.append(z); v3.append(z); sc.append(kind.c[e])
    m_all = row
    if m_all != len(model._jac_indptr) - 1:  # pragma: no cover - guards a model-layout change
        raise NotCompilable(f"model {model.name!r}: row layout of the constraint kinds is not the compiled one")
    act = np.arange(m_all) if model._active_rows is None else np.asarray(model._active_rows, np.int64)
    m = len(act)
    # --- row bodies, Schur pattern and RCM order ------------------------------------------------
    row_bodies = np.full((m_all, 2), nb, np.int64)
    for e in range(len(kinds)):
        row_bodies[row0[e]:row0[e] + nrows[e], 0] = bis[e]
        row_bodies[row0[e]:row0[e] + nrows[e], 1] = bjs[e]
    touching: dict[int, list[tuple[int, int]]] = {}
    for k, a in enumerate(act):
        for slot in (0, 1):
            b = int(row_bodies[a, slot])
            if b < nb:
                touching.setdefault(b, []).append((k, slot))
    pairs = []
    for lst in touching.values():
        for (ka, sa) in lst:
            for (kb, sb) in lst:
                pairs.append((ka, sa, kb, sb))
    if m:
        pr = np.array([p[0] for p in pairs] + list(range(m)), np.int64)
        pc = np.array([p[2] for p in pairs] + list(range(m)), np.int64)
        pattern = sp.csr_matrix((np.ones(len(pr)), (pr, pc)), shape=(m, m))
        order = np.asarray(reverse_cuthill_mckee(pattern, symmetric_mode=True), np.int64)
    else:
        order = np.zeros(0, np.int64)
    pos = np.empty(m, np.int64)
    pos[order] = np.arange(m)  # position in the factorisation order of active row k
    keep = [(ka, sa, kb, sb) for (ka, sa, kb, sb) in pairs if pos[ka] >= pos[kb]]
    p_a = np.array([act[p[0]] for p in keep], np.int64)
    p_sa = np.array([p[1] for p in keep], np.int64)
    p_b = np.array([act[p[2]] for p in keep], np.int64)
    p_sb = np.array([p[3] for p in keep], np.int64)
    p_i = np.array([pos[p[0]] for p in keep], np.int64)
    p_j = np.array([pos[p[2]] for p in keep], np.int64)
    env_first = np.arange(m, dtype=np.int64)
    for i, j in zip(p_i, p_j):
        env_first[i] = min(env_first[i], j)
    perm_of_row = np.full(m_all, -1, np.int64)
    perm_of_row[act] = pos
    row_is_active = perm_of_row >= 0
    # --- masses ---------------------------------------------------------------------------------
    minv = np.zeros((nb + 1, nvb, nvb))
    for k, bd in enumerate(model.bodies):
        blk = model._M[k * nvb:(k + 1) * nvb, k * nvb:(k + 1) * nvb].toarray()
        if not (np.all(np.isfinite(blk)) and np.all(np.linalg.eigvalsh(0.5 * (blk + blk.T)) > 0)):
            raise NotCompilable(f"model {model.name!r}: body {bd.name!r} has a singular mass matrix "
                                f"(mass {bd.mass}, inertia {bd.inertia}); the compiled path needs M > 0 per body")
        minv[k] = np.linalg.inv(blk)
    Jt = np.zeros((nb + 1, 3, 3))
    if dim == 3:
        Jt[:nb] = model._J
    Qg = np.asarray(model._Qg[: nb * nvb], float).copy()
    # --- forces ---------------------------------------------------------------------------------
    ps = dict(bi=[], bj=[], si=[], sj=[], k=[], c=[])
    sd = dict(bi=[], bj=[], si=[], sj=[], k=[], c=[], L0=[])
    for fk in model.force_kinds:
        if isinstance(fk, PointSpringKind):
            for e in range(len(fk.bi)):
                ps["bi"].append(fk.bi[e]); ps["bj"].append(fk.bj[e]); ps["si"].append(pad(fk.si[e]))
                ps["sj"].append(pad(fk.sj[e])); ps["k"].append(fk.k[e]); ps["c"].append(fk.c[e])
        elif isinstance(fk, SpringDamperKind):
            if fk.has_act:
                name = fk.names[[a is not None for a in fk.act].index(True)]
                raise NotCompilable(f"model {model.name!r}: spring-damper {name!r} has an actuator function "
                                    "(a Python callable) and cannot be compiled")
            for e in range(len(fk.bi)):
                sd["bi"].append(fk.bi[e]); sd["bj"].append(fk.bj[e]); sd["si"].append(pad(fk.si[e]))
                sd["sj"].append(pad(fk.sj[e])); sd["k"].append(fk.k[e]); sd["c"].append(fk.c[e]); sd["L0"].append(fk.L0[e])
        else:
            raise NotCompilable(f"model {model.name!r}: force element {fk.names[0]!r} ({type(fk).__name__}) has no "
                                "compiled kernel (compiled: gravity, point springs, spring-dampers without actuator)")

    def ia(x):
        return np.asarray(x, np.int64).reshape(-1)

    def fa(x, shape):
        return np.asarray(x, float).reshape(shape)

    n_el = len(kinds)
    return CompiledData(
        nb=nb, dim=dim, nqb=nqb, nvb=nvb, n_q=model.n_q, n_v=model.n_v, m=m,
        c_kind=ia(kinds), c_bi=ia(bis), c_bj=ia(bjs), c_v1=fa(v1, (n_el, 3)), c_v2=fa(v2, (n_el, 3)),
        c_v3=fa(v3, (n_el, 3)), c_scalar=fa(sc, (n_el,)), c_row0=ia(row0), c_rows=ia(nrows),
        r_b=row_bodies, act=ia(act), perm_of_row=perm_of_row, row_is_active=row_is_active,
        p_a=p_a, p_sa=p_sa, p_b=p_b, p_sb=p_sb, p_i=p_i, p_j=p_j, env_first=env_first,
        minv=minv, Qg=Qg, J=Jt,
        ps_bi=ia(ps["bi"]), ps_bj=ia(ps["bj"]), ps_si=fa(ps["si"], (-1, 3)), ps_sj=fa(ps["sj"], (-1, 3)),
        ps_k=fa(ps["k"], (-1,)), ps_c=fa(ps["c"], (-1,)),
        sd_bi=ia(sd["bi"]), sd_bj=ia(sd["bj"]), sd_si=fa(sd["si"], (-1, 3)), sd_sj=fa(sd["sj"], (-1, 3)),
        sd_k=fa(sd["k"], (-1,)), sd_c=fa(sd["c"], (-1,)), sd_L0=fa(sd["L0"], (-1,)),
    )


def make_workspace(cd: CompiledData) -> Workspace:
    """Scratch arrays of the kernels (allocated once per integrator)."""
    nb, m_all = cd.nb, int(np.sum(cd.c_rows))
    A = np.zeros((nb + 1, 3, 3))
    A[:, 2, 2] = 1.0  # planar bodies rotate about z (body_states writes the 2×2 block)
    A[nb] = np.eye(3)
    m = cd.m
    return Workspace(
        r=np.zeros((nb + 1, 3)), A=A, rd=np.zeros((nb + 1, 3)), w=np.zeros((nb + 1, 3)),
        phi=np.zeros(m_all), G=np.zeros((m_all, 2, 6)), gam=np.zeros(m_all), X=np.zeros((m_all, 2, 6)),
        S=np.zeros((max(m, 1), max(m, 1))), L=np.zeros((max(m, 1), max(m, 1))), Q=np.zeros(cd.n_v),
        rhs=np.zeros(max(m, 1)), tmp_v=np.zeros(cd.n_v),
    )


# ================================================================================================
# kernels
# ================================================================================================

_jit = numba.njit(cache=True, fastmath=False, boundscheck=False)
_jit_inline = numba.njit(cache=True, fastmath=False, boundscheck=False, inline="always")


@_jit_inline
def body_states(cd, q, v, ws):
    """Fill ``ws.r, ws.A, ws.rd, ws.w`` in 3-D form; the ground row ``nb`` stays at rest with A = I.

    Planar bodies are embedded as rotations about z: ``A = [[c, −s, 0], [s, c, 0], [0, 0, 1]]``,
    ``ω = (0, 0, θ̇)``; then ``C(s̄)ω = A(ω × s̄)`` and ``a^q = A(ω × (ω × s̄))`` reproduce the planar
    ``A R s̄ θ̇`` and ``−A s̄ θ̇²`` exactly, and one set of kernels serves both.
    """
    _positions_only(cd, q, ws)
    nb = cd.nb
    rd, w = ws.rd, ws.w
    if cd.dim == 2:
        for b in range(nb):
            rd[b, 0] = v[3 * b]
            rd[b, 1] = v[3 * b + 1]
            w[b, 2] = v[3 * b + 2]
    else:
        for b in range(nb):
            o = 6 * b
            rd[b, 0], rd[b, 1], rd[b, 2] = v[o], v[o + 1], v[o + 2]
            w[b, 0], w[b, 1], w[b, 2] = v[o + 3], v[o + 4], v[o + 5]


# --- scalar 3-vector helpers (inlined; no array views are created on the hot path) -------------


@_jit_inline
def _Av(A, b, x0, x1, x2):
    """``A_b x``."""
    return (A[b, 0, 0] * x0 + A[b, 0, 1] * x1 + A[b, 0, 2] * x2,
            A[b, 1, 0] * x0 + A[b, 1, 1] * x1 + A[b, 1, 2] * x2,
            A[b, 2, 0] * x0 + A[b, 2, 1] * x1 + A[b, 2, 2] * x2)


@_jit_inline
def _ATv(A, b, x0, x1, x2):
    """``A_bᵀ x``."""
    return (A[b, 0, 0] * x0 + A[b, 1, 0] * x1 + A[b, 2, 0] * x2,
            A[b, 0, 1] * x0 + A[b, 1, 1] * x1 + A[b, 2, 1] * x2,
            A[b, 0, 2] * x0 + A[b, 1, 2] * x1 + A[b, 2, 2] * x2)


@_jit_inline
def _cross(a0, a1, a2, b0, b1, b2):
    return a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0


@_jit_inline
def _vel(A, w, b, s0, s1, s2):
    """``C(s̄) ω_b = A_b (ω̄_b × s̄)`` (velocity of a body-fixed vector)."""
    c0, c1, c2 = _cross(w[b, 0], w[b, 1], w[b, 2], s0, s1, s2)
    return _Av(A, b, c0, c1, c2)


@_jit_inline
def _aq(A, w, b, s0, s1, s2):
    """``a^q(s̄) = A_b (ω̄ × (ω̄ × s̄))``."""
    w0, w1, w2 = w[b, 0], w[b, 1], w[b, 2]
    c0, c1, c2 = _cross(w0, w1, w2, s0, s1, s2)
    d0, d1, d2 = _cross(w0, w1, w2, c0, c1, c2)
    return _Av(A, b, d0, d1, d2)


@_jit_inline
def _uC(A, b, s0, s1, s2, u0, u1, u2):
    """``uᵀ C(s̄) = (s̄ × A_bᵀu)ᵀ`` (row of the rotational Jacobian along u)."""
    t0, t1, t2 = _ATv(A, b, u0, u1, u2)
    return _cross(s0, s1, s2, t0, t1, t2)


@_jit_inline
def _rel_point(r, A, bi, p0, p1, p2, bj, q0, q1, q2):
    """``d = r_Q − r_P`` with P = s̄_p on body i, Q = s̄_q on body j."""
    u0, u1, u2 = _Av(A, bi, p0, p1, p2)
    v0, v1, v2 = _Av(A, bj, q0, q1, q2)
    return r[bj, 0] + v0 - r[bi, 0] - u0, r[bj, 1] + v1 - r[bi, 1] - u1, r[bj, 2] + v2 - r[bi, 2] - u2


@_jit_inline
def _rel_vel(rd, A, w, bi, p0, p1, p2, bj, q0, q1, q2):
    """``ḋ = ṙ_Q − ṙ_P`` (velocities of the same two body-fixed points)."""
    x0, x1, x2 = _vel(A, w, bi, p0, p1, p2)
    y0, y1, y2 = _vel(A, w, bj, q0, q1, q2)
    return rd[bj, 0] + y0 - rd[bi, 0] - x0, rd[bj, 1] + y1 - rd[bi, 1] - x1, rd[bj, 2] + y2 - rd[bi, 2] - x2


@_jit_inline
def _put(G, row, sl, dim, t0, t1, t2, c0, c1, c2):
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


@_jit_inline
def constraint_terms(cd, ws, want_phi, want_gamma):
    """Rows of ``Φ`` (optional), ``Φ_q`` blocks ``ws.G[row, slot]`` and ``γ`` (optional), all model rows."""
    dim = cd.dim
    G, phi, gam, A, w, r, rd = ws.G, ws.phi, ws.gam, ws.A, ws.w, ws.r, ws.rd
    V1, V2, V3 = cd.c_v1, cd.c_v2, cd.c_v3
    for e in range(cd.c_kind.shape[0]):
        kind = cd.c_kind[e]
        bi, bj, r0 = cd.c_bi[e], cd.c_bj[e], cd.c_row0[e]
        p0, p1, p2 = V1[e, 0], V1[e, 1], V1[e, 2]
        q0, q1, q2 = V2[e, 0], V2[e, 1], V2[e, 2]
        if kind == K_POINT:
            # p = s̄_i, q = s̄_j
            a0, a1, a2 = _Av(A, bi, p0, p1, p2)
            b0, b1, b2 = _Av(A, bj, q0, q1, q2)
            if want_phi:
                phi[r0] = r[bi, 0] + a0 - r[bj, 0] - b0
                phi[r0 + 1] = r[bi, 1] + a1 - r[bj, 1] - b1
                if dim == 3:
                    phi[r0 + 2] = r[bi, 2] + a2 - r[bj, 2] - b2
            for i in range(dim):
                ci0, ci1, ci2 = _cross(p0, p1, p2, A[bi, i, 0], A[bi, i, 1], A[bi, i, 2])
                cj0, cj1, cj2 = _cross(q0, q1, q2, A[bj, i, 0], A[bj, i, 1], A[bj, i, 2])
                t0 = 1.0 if i == 0 else 0.0
                t1 = 1.0 if i == 1 else 0.0
                t2 = 1.0 if i == 2 else 0.0
                _put(G, r0 + i, 0, dim, t0, t1, t2, ci0, ci1, ci2)
                _put(G, r0 + i, 1, dim, -t0, -t1, -t2, -cj0, -cj1, -cj2)
            if want_gamma:
                g0, g1, g2 = _aq(A, w, bi, p0, p1, p2)
                h0, h1, h2 = _aq(A, w, bj, q0, q1, q2)
                gam[r0] = -(g0 - h0)
                gam[r0 + 1] = -(g1 - h1)
                if dim == 3:
                    gam[r0 + 2] = -(g2 - h2)
        elif kind == K_DOT1:
            # p = ā_i, q = ā_j
            a0, a1, a2 = _Av(A, bi, p0, p1, p2)
            b0, b1, b2 = _Av(A, bj, q0, q1, q2)
            if want_phi:
                phi[r0] = a0 * b0 + a1 * b1 + a2 * b2 - cd.c_scalar[e]
            ci0, ci1, ci2 = _uC(A, bi, p0, p1, p2, b0, b1, b2)
            cj0, cj1, cj2 = _uC(A, bj, q0, q1, q2, a0, a1, a2)
            _put(G, r0, 0, dim, 0.0, 0.0, 0.0, ci0, ci1, ci2)
            _put(G, r0, 1, dim, 0.0, 0.0, 0.0, cj0, cj1, cj2)
            if want_gamma:
                g0, g1, g2 = _aq(A, w, bi, p0, p1, p2)
                h0, h1, h2 = _aq(A, w, bj, q0, q1, q2)
                x0, x1, x2 = _vel(A, w, bi, p0, p1, p2)
                y0, y1, y2 = _vel(A, w, bj, q0, q1, q2)
                gam[r0] = -(b0 * g0 + b1 * g1 + b2 * g2 + a0 * h0 + a1 * h1 + a2 * h2
                            + 2.0 * (x0 * y0 + x1 * y1 + x2 * y2))
        elif kind == K_DOT2:
            # p = ā_i, q = s̄_i (P on i), v3 = s̄_j (Q on j); d = r_Q − r_P
            s0, s1, s2 = V3[e, 0], V3[e, 1], V3[e, 2]
            a0, a1, a2 = _Av(A, bi, p0, p1, p2)
            d0, d1, d2 = _rel_point(r, A, bi, q0, q1, q2, bj, s0, s1, s2)
            if want_phi:
                phi[r0] = a0 * d0 + a1 * d1 + a2 * d2 - cd.c_scalar[e]
            x0, x1, x2 = _uC(A, bi, p0, p1, p2, d0, d1, d2)
            y0, y1, y2 = _uC(A, bi, q0, q1, q2, a0, a1, a2)
            _put(G, r0, 0, dim, -a0, -a1, -a2, x0 - y0, x1 - y1, x2 - y2)
            z0, z1, z2 = _uC(A, bj, s0, s1, s2, a0, a1, a2)
            _put(G, r0, 1, dim, a0, a1, a2, z0, z1, z2)
            if want_gamma:
                ad0, ad1, ad2 = _vel(A, w, bi, p0, p1, p2)  # ȧ_i
                dd0, dd1, dd2 = _rel_vel(rd, A, w, bi, q0, q1, q2, bj, s0, s1, s2)
                g0, g1, g2 = _aq(A, w, bi, p0, p1, p2)
                h0, h1, h2 = _aq(A, w, bj, s0, s1, s2)
                k0, k1, k2 = _aq(A, w, bi, q0, q1, q2)
                gam[r0] = -(d0 * g0 + d1 * g1 + d2 * g2 + 2.0 * (ad0 * dd0 + ad1 * dd1 + ad2 * dd2)
                            + a0 * (h0 - k0) + a1 * (h1 - k1) + a2 * (h2 - k2))
        elif kind == K_DIST:
            # p = s̄_i, q = s̄_j
            L = cd.c_scalar[e]
            d0, d1, d2 = _rel_point(r, A, bi, p0, p1, p2, bj, q0, q1, q2)
            if want_phi:
                phi[r0] = (d0 * d0 + d1 * d1 + d2 * d2 - L * L) / (2.0 * L)
            e0, e1, e2 = d0 / L, d1 / L, d2 / L
            x0, x1, x2 = _uC(A, bi, p0, p1, p2, e0, e1, e2)
            y0, y1, y2 = _uC(A, bj, q0, q1, q2, e0, e1, e2)
            _put(G, r0, 0, dim, -e0, -e1, -e2, -x0, -x1, -x2)
            _put(G, r0, 1, dim, e0, e1, e2, y0, y1, y2)
            if want_gamma:
                dd0, dd1, dd2 = _rel_vel(rd, A, w, bi, p0, p1, p2, bj, q0, q1, q2)
                g0, g1, g2 = _aq(A, w, bj, q0, q1, q2)
                h0, h1, h2 = _aq(A, w, bi, p0, p1, p2)
                gam[r0] = -(dd0 * dd0 + dd1 * dd1 + dd2 * dd2
                            + d0 * (g0 - h0) + d1 * (g1 - h1) + d2 * (g2 - h2)) / L
        else:  # K_ANGLE (planar)
            if want_phi:
                ti = np.arctan2(A[bi, 1, 0], A[bi, 0, 0])
                tj = np.arctan2(A[bj, 1, 0], A[bj, 0, 0])
                x = tj - ti - cd.c_scalar[e]
                phi[r0] = np.arctan2(np.sin(x), np.cos(x))
            _put(G, r0, 0, dim, 0.0, 0.0, 0.0, 0.0, 0.0, -1.0)
            _put(G, r0, 1, dim, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0)
            if want_gamma:
                gam[r0] = 0.0


@_jit_inline
def _add_point_force(Q, A, b, nb, dim, s0, s1, s2, F0, F1, F2, sign):
    """``Q_b += sign · [F; C(s̄)ᵀ F]`` with ``C(s̄)ᵀF = s̄ × A_bᵀF`` (skips the ground)."""
    if b >= nb:
        return
    c0, c1, c2 = _uC(A, b, s0, s1, s2, F0, F1, F2)
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


@_jit_inline
def applied_forces(cd, ws, Q):
    """``Q``: gravity, gyroscopic terms, point springs and spring-dampers; returns a status code."""
    dim, nb, nvb = cd.dim, cd.nb, cd.nvb
    A, w, r, rd = ws.A, ws.w, ws.r, ws.rd
    for i in range(nb * nvb):
        Q[i] = cd.Qg[i]
    if dim == 3:
        for b in range(nb):
            w0, w1, w2 = w[b, 0], w[b, 1], w[b, 2]
            J = cd.J
            h0 = J[b, 0, 0] * w0 + J[b, 0, 1] * w1 + J[b, 0, 2] * w2
            h1 = J[b, 1, 0] * w0 + J[b, 1, 1] * w1 + J[b, 1, 2] * w2
            h2 = J[b, 2, 0] * w0 + J[b, 2, 1] * w1 + J[b, 2, 2] * w2
            Q[6 * b + 3] -= w1 * h2 - w2 * h1
            Q[6 * b + 4] -= w2 * h0 - w0 * h2
            Q[6 * b + 5] -= w0 * h1 - w1 * h0
    for kind in range(2):
        if kind == 0:
            BI, BJ, SI, SJ, K, C = cd.ps_bi, cd.ps_bj, cd.ps_si, cd.ps_sj, cd.ps_k, cd.ps_c
        else:
            BI, BJ, SI, SJ, K, C = cd.sd_bi, cd.sd_bj, cd.sd_si, cd.sd_sj, cd.sd_k, cd.sd_c
        for e in range(BI.shape[0]):
            bi, bj = BI[e], BJ[e]
            p0, p1, p2 = SI[e, 0], SI[e, 1], SI[e, 2]
            q0, q1, q2 = SJ[e, 0], SJ[e, 1], SJ[e, 2]
            d0, d1, d2 = _rel_point(r, A, bi, p0, p1, p2, bj, q0, q1, q2)
            dd0, dd1, dd2 = _rel_vel(rd, A, w, bi, p0, p1, p2, bj, q0, q1, q2)
            if kind == 0:  # zero-length point spring: F_P = k d + c ḋ
                F0 = K[e] * d0 + C[e] * dd0
                F1 = K[e] * d1 + C[e] * dd1
                F2 = K[e] * d2 + C[e] * dd2
            else:  # spring-damper: F_P = (k (L − L0) + c L̇) u
                L = np.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
                if L < 1e-12:
                    return COINCIDENT
                Ld = (d0 * dd0 + d1 * dd1 + d2 * dd2) / L
                f = (K[e] * (L - cd.sd_L0[e]) + C[e] * Ld) / L
                F0, F1, F2 = f * d0, f * d1, f * d2
            _add_point_force(Q, A, bi, nb, dim, p0, p1, p2, F0, F1, F2, 1.0)
            _add_point_force(Q, A, bj, nb, dim, q0, q1, q2, F0, F1, F2, -1.0)
    return OK


@_jit_inline
def _minv_times_rows(cd, ws):
    """``X[row, slot] = M_b⁻¹ G[row, slot]ᵀ`` for the active rows."""
    nvb, nb = cd.nvb, cd.nb
    for k in range(cd.act.shape[0]):
        a = cd.act[k]
        for sl in range(2):
            b = cd.r_b[a, sl]
            if b >= nb:
                continue
            for i in range(nvb):
                acc = 0.0
                for j in range(nvb):
                    acc += cd.minv[b, i, j] * ws.G[a, sl, j]
                ws.X[a, sl, i] = acc


@_jit_inline
def factor_schur(cd, ws):
    """Assemble ``S = Φ_q M⁻¹ Φ_qᵀ`` on its pattern and factorise it (envelope Cholesky) into ``ws.L``."""
    m = cd.m
    S, L, first = ws.S, ws.L, cd.env_first
    _minv_times_rows(cd, ws)
    for i in range(m):
        for j in range(first[i], i + 1):
            S[i, j] = 0.0
    nvb = cd.nvb
    for p in range(cd.p_a.shape[0]):
        a, sa, b, sb = cd.p_a[p], cd.p_sa[p], cd.p_b[p], cd.p_sb[p]
        acc = 0.0
        for c in range(nvb):
            acc += ws.G[a, sa, c] * ws.X[b, sb, c]
        S[cd.p_i[p], cd.p_j[p]] += acc
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
    return OK


@_jit_inline
def solve_schur(cd, ws, b):
    """Solve ``S x = b`` in place (``b`` in factorisation order) with the envelope factor."""
    m, L, first = cd.m, ws.L, cd.env_first
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


@_jit_inline
def _minv_times(cd, f, out):
    """``out = M⁻¹ f`` (block diagonal)."""
    nvb = cd.nvb
    for b in range(cd.nb):
        o = b * nvb
        for i in range(nvb):
            acc = 0.0
            for j in range(nvb):
                acc += cd.minv[b, i, j] * f[o + j]
            out[o + i] = acc


@_jit_inline
def _rows_dot(G, r_b, nb, nvb, x, a):
    """``(Φ_q x)_a`` for model row ``a`` (arrays passed explicitly: large tuples are copied per call)."""
    acc = 0.0
    for sl in range(2):
        b = r_b[a, sl]
        if b < nb:
            o = b * nvb
            for c in range(nvb):
                acc += G[a, sl, c] * x[o + c]
    return acc


@_jit_inline
def _subtract_X_mu(X, r_b, act, perm_of_row, nb, nvb, mu, out):
    """``out −= M⁻¹ Φ_qᵀ μ`` (μ in factorisation order)."""
    for k in range(act.shape[0]):
        a = act[k]
        mk = mu[perm_of_row[a]]
        for sl in range(2):
            b = r_b[a, sl]
            if b < nb:
                o = b * nvb
                for c in range(nvb):
                    out[o + c] -= X[a, sl, c] * mk


@_jit_inline
def accelerations(cd, ws, q, v, alpha, beta, vdot, lam):
    r"""Index-1 accelerations ``vdot`` and multipliers ``lam`` (model active-row order); status code."""
    body_states(cd, q, v, ws)
    st = applied_forces(cd, ws, ws.Q)
    if st != OK:
        return st
    _minv_times(cd, ws.Q, vdot)
    m = cd.m
    if m == 0:
        return OK
    baum = alpha != 0.0 or beta != 0.0
    constraint_terms(cd, ws, baum, True)
    st = factor_schur(cd, ws)
    if st != OK:
        return st
    rhs, G, r_b, act, perm, gam, phi = ws.rhs, ws.G, cd.r_b, cd.act, cd.perm_of_row, ws.gam, ws.phi
    nb, nvb = cd.nb, cd.nvb
    for k in range(m):
        a = act[k]
        g = gam[a]
        if baum:
            g -= 2.0 * alpha * _rows_dot(G, r_b, nb, nvb, v, a) + beta * beta * phi[a]
        rhs[perm[a]] = _rows_dot(G, r_b, nb, nvb, vdot, a) - g
    solve_schur(cd, ws, rhs)
    _subtract_X_mu(ws.X, r_b, act, perm, nb, nvb, rhs, vdot)
    for k in range(m):
        lam[k] = rhs[perm[act[k]]]
    return OK


@_jit_inline
def qdot(cd, q, v, out):
    """``q̇ = Z(q) v``: planar identity; spatial ``ṗ = ½ L(p)ᵀ ω̄`` (Nikravesh 1988, Eq. 6.101)."""
    if cd.dim == 2:
        for i in range(cd.n_q):
            out[i] = v[i]
        return
    for b in range(cd.nb):
        o, u = 7 * b, 6 * b
        out[o], out[o + 1], out[o + 2] = v[u], v[u + 1], v[u + 2]
        e0, e1, e2, e3 = q[o + 3], q[o + 4], q[o + 5], q[o + 6]
        w0, w1, w2 = v[u + 3], v[u + 4], v[u + 5]
        # L = [−e, −ẽ + e0 I];  ṗ = ½ Lᵀ ω̄
        out[o + 3] = 0.5 * (-e1 * w0 - e2 * w1 - e3 * w2)
        out[o + 4] = 0.5 * (e0 * w0 - e3 * w1 + e2 * w2)
        out[o + 5] = 0.5 * (e3 * w0 + e0 * w1 - e1 * w2)
        out[o + 6] = 0.5 * (-e2 * w0 + e1 * w1 + e0 * w2)


@_jit
def normalize(cd, q):
    """Euler parameters scaled to unit norm in place (spatial bodies)."""
    if cd.dim == 2:
        return
    for b in range(cd.nb):
        o = 7 * b + 3
        n = np.sqrt(q[o] ** 2 + q[o + 1] ** 2 + q[o + 2] ** 2 + q[o + 3] ** 2)
        for i in range(4):
            q[o + i] /= n


@_jit
def retract(cd, q, dv):
    r"""``q ← q ⊕ Δ``: translations add; spatial rotations ``p ← p ⊗ exp(Δθ̄/2)`` (body-frame increment)."""
    if cd.dim == 2:
        for i in range(cd.n_q):
            q[i] += dv[i]
        return
    for b in range(cd.nb):
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


@_jit
def _max_abs_phi(cd, ws):
    mx = 0.0
    for k in range(cd.m):
        x = abs(ws.phi[cd.act[k]])
        if not x <= mx:  # NaN propagates
            mx = x
    return mx


@_jit
def project(cd, ws, q, v, tol, max_iter, counters):
    """Coordinate projection of ``(q, v)`` in place (see the module docstring); returns iterations or −1."""
    normalize(cd, q)
    m = cd.m
    if m == 0:
        return 0
    zero_v = ws.tmp_v
    _body_states_ool(cd, q, v, ws)
    _constraint_terms_ool(cd, ws, True, False)
    err = _max_abs_phi(cd, ws)
    n_iter = 0
    if err > tol:
        if _factor_schur_ool(cd, ws) != OK:
            return -1
        counters[3] += 1
        prev = np.inf
        while True:
            rhs = ws.rhs
            for k in range(m):
                a = cd.act[k]
                rhs[cd.perm_of_row[a]] = ws.phi[a]
            _solve_schur_ool(cd, ws, rhs)
            for i in range(cd.n_v):
                zero_v[i] = 0.0
            _subtract_X_mu(ws.X, cd.r_b, cd.act, cd.perm_of_row, cd.nb, cd.nvb, rhs, zero_v)  # Δ = −M⁻¹ Φ_qᵀ S⁻¹ Φ
            retract(cd, q, zero_v)
            n_iter += 1
            # Φ at the new positions; the factor L and M⁻¹Φ_qᵀ blocks X stay frozen (constraint_terms
            # rewrites only Φ, the G blocks and γ; G is not used until the velocity stage re-evaluates it)
            _body_states_ool(cd, q, v, ws)
            _constraint_terms_ool(cd, ws, True, False)
            err = _max_abs_phi(cd, ws)
            if err <= tol:
                break
            if n_iter >= max_iter or not np.isfinite(err) or err > 2.0 * prev:
                return -1
            prev = err
        normalize(cd, q)
    # velocities at the projected positions
    _body_states_ool(cd, q, v, ws)
    _constraint_terms_ool(cd, ws, False, False)
    if _factor_schur_ool(cd, ws) != OK:
        return -1
    counters[3] += 1
    rhs = ws.rhs
    for k in range(m):
        a = cd.act[k]
        rhs[cd.perm_of_row[a]] = _rows_dot(ws.G, cd.r_b, cd.nb, cd.nvb, v, a)
    _solve_schur_ool(cd, ws, rhs)
    _subtract_X_mu(ws.X, cd.r_b, cd.act, cd.perm_of_row, cd.nb, cd.nvb, rhs, v)
    return n_iter


@_jit_inline
def _positions_only(cd, q, ws):
    nb = cd.nb
    if cd.dim == 2:
        for b in range(nb):
            th = q[3 * b + 2]
            c, s = np.cos(th), np.sin(th)
            ws.r[b, 0] = q[3 * b]
            ws.r[b, 1] = q[3 * b + 1]
            ws.A[b, 0, 0] = c
            ws.A[b, 0, 1] = -s
            ws.A[b, 1, 0] = s
            ws.A[b, 1, 1] = c
    else:
        for b in range(nb):
            o = 7 * b
            e0, e1, e2, e3 = q[o + 3], q[o + 4], q[o + 5], q[o + 6]
            ws.r[b, 0], ws.r[b, 1], ws.r[b, 2] = q[o], q[o + 1], q[o + 2]
            ws.A[b, 0, 0] = 2.0 * (e0 * e0 + e1 * e1) - 1.0
            ws.A[b, 0, 1] = 2.0 * (e1 * e2 - e0 * e3)
            ws.A[b, 0, 2] = 2.0 * (e1 * e3 + e0 * e2)
            ws.A[b, 1, 0] = 2.0 * (e1 * e2 + e0 * e3)
            ws.A[b, 1, 1] = 2.0 * (e0 * e0 + e2 * e2) - 1.0
            ws.A[b, 1, 2] = 2.0 * (e2 * e3 - e0 * e1)
            ws.A[b, 2, 0] = 2.0 * (e1 * e3 - e0 * e2)
            ws.A[b, 2, 1] = 2.0 * (e2 * e3 + e0 * e1)
            ws.A[b, 2, 2] = 2.0 * (e0 * e0 + e3 * e3) - 1.0


# Out-of-line twins of the inlined kernels for the projection: it runs once per step, so a call
# boundary costs nothing there, and not inlining everything into it saves compile time.
_body_states_ool = _jit(body_states.py_func)
_constraint_terms_ool = _jit(constraint_terms.py_func)
_factor_schur_ool = _jit(factor_schur.py_func)
_solve_schur_ool = _jit(solve_schur.py_func)
