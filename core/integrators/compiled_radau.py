r"""Radau IIA (order 5) on the index-1 formulation with a compiled step loop: the stiff integrator.

Stiff multibody problems — penalty joints, bushings, Hertzian wheel–rail contacts with normal
stiffness of order 1e9 N/m — limit every explicit method's step to its stability boundary
(``h |λ| ≲ 3…6`` for the fastest mode), whatever the accuracy asked for.  This integrator is
A- and L-stable: its step follows the accuracy of the motion, and it runs, like
:mod:`core.integrators.compiled_rk`, entirely in compiled code over the kernels of
:mod:`core.compiled` (any element kind with a compiled form).

Formulation
-----------
State ``y = (q, v)``, ``q̇ = Z(q) v``, ``v̇ = a(t, q, v)`` from the index-1 equations
``M a + Φ_qᵀλ = Q``, ``Φ_q a = γ − 2α(Φ_q v − ν) − β²Φ`` (:func:`core.compiled.dynamics.accelerations`),
as ``"jit-radau"`` (α = β = 0), ``"jit-radau-baumgarte"`` (α = β = 10 s⁻¹ by default) and
``"jit-radau-projection"`` (coordinate projection onto ``Φ = 0``, ``Φ_q v = ν`` after every step,
:func:`core.compiled.dynamics.project`; the dense output is corrected as in
:mod:`core.integrators.index1`).

Method
------
The 3-stage Radau IIA collocation method (stiffly accurate, order 5) with RADAU5's simplified
Newton iteration, error estimate and step-size controller (Hairer & Wanner II, Sec. IV.8; the
same algorithm and constants as :class:`scipy.integrate.Radau` and :mod:`core.integrators.ggl`):
the transformed stage system needs, per Newton iteration, one real solve with ``(μ_r/h) I − J``
and one complex solve with ``(μ_c/h) I − J``.  The Jacobian of the index-1 right-hand side is not
formed; its linear systems are solved through the second-order structure and the linearised
saddle-point equations.  With ``μ`` one of ``μ_r/h``, ``μ_c/h``, for a right-hand side
``(r_q, r_v)``:

.. math::

    Δq = (r_q + Z Δv)/μ,\qquad
    \begin{bmatrix} μ M - D - K/μ & Φ_q^T \\ Φ_q & 0 \end{bmatrix}
    \begin{bmatrix} Δv \\ δλ \end{bmatrix} =
    \begin{bmatrix} M r_v + K Z^{+} r_q / μ \\
                    (Φ_q r_v - (β²/μ) Φ_q Z^{+} r_q)/(μ + 2α + β²/μ) \end{bmatrix}

with ``K = ∂Q/∂q`` (velocity-space increments), ``D = ∂Q/∂v``
(:func:`core.compiled.dynamics.force_jacobian`: the kinds' analytic Jacobian kernels, differences
otherwise) and ``Z⁺`` the map of coordinate increments to velocity-space increments
(``δθ̄ = 2 L(p) δp`` for Euler parameters; Nikravesh 1988, Eq. 6.100).  This linearisation keeps
the stiff force terms and the constraints exactly and drops the derivatives of ``Φ_q``, ``γ`` and
the gyroscopic-free inertia terms, which are smooth: a simplified Newton iteration converges with
it (the residual is exact), and the Jacobian is refreshed when the iteration slows (RADAU5's rule).
The ``(n_v + m)`` matrices are assembled in reverse Cuthill–McKee order from the sparse rows of
``M``, ``K``, ``D`` and ``Φ_q`` (packed once per Jacobian, with the band they span) and factorised
by banded LU with partial pivoting (Golub & Van Loan 2013, Alg. 4.3.5), real and complex, and the
factors are reused over the steps in which the step size and the Jacobian stay unchanged (RADAU5
keeps the step when the predicted change is below 20 %).  When the iteration fails with an old
Jacobian, it restarts from the same starting guess with a fresh one; when it fails with a fresh
one, the step is halved (RADAU5).

Newton failures and the step size: on stiff springs that rotate with the bodies (the penalty
chain, a wheel–rail contact) the Jacobian of the step start goes stale within a step, so the
contraction rate ``θ`` of the simplified Newton iteration grows with h; RADAU5's controller, which
knows only the error estimate, then enlarges the step until the iteration fails and halves it,
over and over (8-link penalty chain, k = 1e8 N/m, rtol 3e-4: 1727 Newton failures in 1356 accepted
steps).  After the idea of Gustafsson & Söderlind (1997), to keep the convergence rate in check
through the step size, an accepted step whose last rate exceeds ``NEWTON_RATE_HOLD`` = 0.1 is not
enlarged (reductions still apply).  Measured on that chain: Newton failures 1727 → 512, right-hand
sides 24 527 → 16 297, factorisations 6258 → 2324 (k = 1e8); 129 → 82 failures and 5 % less work at
k = 1e6; identical step sequences on the rigid chain and at k = 1e4, where θ stays small.  A run
reports ``n_newton_failures`` (attempts whose iteration failed even with a fresh Jacobian, each
followed by halving the step; the rest of ``n_rejected`` are error-test rejections).

Euler parameters on the unit sphere: every stage state is evaluated with its Euler parameters
normalised, and the accepted state is normalised.  ``A(p)`` of Euler parameters off the sphere is
no rotation (Nikravesh 1988, Eq. 6.19 assumes ``|p| = 1``), and a stage leaves the sphere (a
linear update is tangent to it, so ``|p|² − 1`` grows with the square of the rotation in a step):
every attachment point ``A s̄`` then moves by about ``(|p|² − 1)|s̄|``.  On a stiff contact that is
a large force along a direction the velocity-space iteration matrix cannot contain
(``δθ̄ = 2L(p)δp`` has no component along ``p``), so the iteration stops contracting.  Measured on
the Manchester coach (wheelsets spinning at 22 rad/s on 1e9 N/m Hertz contacts, rtol 1e-4): without
the normalisation the largest Newton increment sat in the leading wheelset's vertical velocity with
rate ≈ 1, also with a fresh Jacobian at every step, and the step fell to 0.1 ms (9 407 steps in the
first second, 6 s in 16.8 s); with it, 102 steps in the first second and 6 s in 2.2 s, without a
stability limit.  The explicit integrators evaluate the model as it is (their step control sees
the off-sphere sensitivity as stiffness; the docs' benchmarks page has what changed when the model
itself used ``A(p/|p|)``).

Spinning bodies: the Jacobian in the frame where it stays put.  ``K`` and ``D`` are derivatives
with respect to body-frame rotation increments ``δθ̄``.  A force that acts at a point fixed in
space while the body turns under it (a wheel on the rail, a ball on the ground) has a body-frame
Jacobian that turns with the body: on the Manchester coach in steady curving (wheelsets at
22 rad/s) ``K`` changed by 4.9 % in 4 ms and 38 % in 34 ms, while ``T K_J Tᵀ`` with the body's
rotation since the Jacobian, ``T = diag(I, R)``, ``R = A(p)ᵀ A_J``, stayed within 0.014 % and 0.12 %.
Within one step the three stages then see three different Jacobians; the simplified Newton
iteration's contraction rate grew with h³ (0.083 at 5 ms, 0.53 at 10 ms, 1.05 at 15 ms) and held
the step at about 5 ms with a Newton failure in about a quarter of the steps.  So each stage's
increments are carried into the Jacobian's velocity space through the stage's own orientation
(:func:`_to_frame`: ``a = (δr, Rᵢᵀ 2L(pᵢ) δp)``, ``b = (δṙ, Rᵢᵀ δω̄)``, ``n = pᵢᵀ δp``, with ``pᵢ``
the stage's Euler parameters from the starting guess and ``Rᵢ = A(pᵢ)ᵀ A_J``), combined by ``T⁻¹``,
solved with the one factorisation, and carried back stage by stage (:func:`_from_frame`).  The
residual stays exact, so the iteration converges to the same collocation solution; only its
linear model changes (the mixing ``(hA)⁻¹ ⊗ I`` picks up ``RᵢᵀRⱼ − I = O(hω)``, small where the
stiff terms dominate).  Rates at a state of the same run (t ≈ 12.0 s): 0.018 at 5 ms, 0.031 at
10 ms, 0.066 at 15 ms; there the car body and the bogies use the body frame and the four
wheelsets the spatial one.

Which frame is right depends on the body: a spring attached to the body at both ends is constant
in the body frame, and the body-frame inertia ``J̄`` is constant there (``R J̄ Rᵀ = J̄`` only for a
body symmetric about its turning axis, such as a wheelset).  :func:`_choose_frames` decides per
spatial body at each new Jacobian, from the evidence of the last two: the spatial frame when the
previous Jacobian rotated by ``T`` predicts the body's block of the new iteration matrix
``μM − D − K/μ`` better than it does unrotated; otherwise (and always for bodies in a mass group,
and until a second Jacobian exists) the body frame with ``p₀`` at every stage, which is the
iteration of the step start as before (when no body uses the spatial frame, the three stages share
one map and the iteration is the one of before, up to rounding).  Measured (2026-12-02, AMD EPYC
host), the coach's 30 s run at rtol 1e-4 (``benchmarks/railway_vehicle.py``'s real-time case),
before → after: steps 7 321 → 4 427, Newton failures 1 206 → 44, Jacobians 3 467 → 1 375,
right-hand sides 80 010 → 39 736, factorisations 14 002 → 5 942; the steady-curving step 5.4 →
12–13 ms; wall time 6.52 / 6.67 / 6.46 → 3.80 / 3.60 / 3.63 s (alternated runs).  The wheelsets'
lateral displacement stays within 0.90 µm of ``jit-dop853`` at rtol 1e-8 (0.15 µm before: the
steps are no longer held below what rtol asks for).  Unchanged step sequences: a torque-free
asymmetric body tumbling at 6 rad/s (828 steps, 166 Jacobians, body frame), the 8-link spatial and
planar rigid chains; the coaster's train the same steps and Jacobians.

Error control is RADAU5's (estimate ``(γ₀/h − J)⁻¹ (f(y₀) + Σ eᵢ Zᵢ / h)``, norm
``‖e / (atol + rtol |y|)‖_RMS``); there is no stability limit and so no stiffness warning.
Failures are honest: a step below 10 ulp(t) (Newton not converging at any step, non-finite
stages), a singular iteration matrix, a projection that does not converge or a kernel failure end
the run with status ``failed``, the cause, the time and the element where one is to blame.

References
----------
E. Hairer, G. Wanner, *Solving Ordinary Differential Equations II*, 2nd ed., Springer, 1996,
Sec. IV.8 (RADAU5) and VII.1 (index-1 formulation of mechanical systems).
K. Gustafsson, G. Söderlind, "Control strategies for the iterative solution of nonlinear equations
in ODE solvers", SIAM J. Sci. Comput. 18 (1997) 23–40.
G. H. Golub, C. F. Van Loan, *Matrix Computations*, 4th ed., 2013, Sec. 4.3 (band LU).
E. Cuthill, J. McKee, "Reducing the bandwidth of sparse symmetric matrices", Proc. 24th ACM
National Conference (1969) 157–172.
P. E. Nikravesh, *Computer-Aided Analysis of Mechanical Systems*, Prentice Hall, 1988.
"""

from __future__ import annotations

# numba bakes module constants such as protocol.MAX_SLOTS into its cached machine code and keys the
# cache on this file only: this file changed with MAX_SLOTS (3 -> 8, flexible bodies' node frames)
# and with the mass groups of core.compiled.dynamics (flexible bodies with the deformed body's
# inertia), so that no stale kernel runs (docs/architecture.md, numba's on-disk cache)

import numba
import numpy as np
import scipy.sparse as sp
from numba.core import types
from numba.experimental import structref
from scipy.sparse.csgraph import reverse_cuthill_mckee

from ..compiled import dynamics as _d
from ..compiled import layout as _l
from ..compiled import protocol as _p
from ..compiled.cache import notify_if_cold
from ..errors import InputError, NotCompilable
from .base import STATUS_FAILED, STATUS_RUNNING, Integrator, register
from .compiled_rk import (
    C_FACT,
    C_REJ,
    C_RHS,
    C_STEPS,
    EXIT_MAX_STEPS,
    EXIT_REACHED,
    EXIT_TOO_SMALL,
    _rhs,
    compiled_multipliers,
)
from .ggl import MAX_FACTOR, MIN_FACTOR, MU_COMPLEX, MU_REAL, NEWTON_MAXITER, P, T, TI
from .ggl import C as RADAU_C
from .ggl import E as RADAU_E
from .index1 import DEFAULT_BAUMGARTE

_jit = numba.njit(cache=True, fastmath=False, boundscheck=False)
_internal = numba.njit(cache=True, fastmath=False, boundscheck=False, no_cpython_wrapper=True, no_cfunc_wrapper=True)

# counters beyond compiled_rk's layout (steps, rejected, rhs, factorisations, ...)
C_JAC, C_NEWTON, C_NEWTON_FAIL = 7, 8, 9
# contraction rate of the simplified Newton iteration above which an accepted step is not enlarged
NEWTON_RATE_HOLD = 0.1
EXIT_SINGULAR_MATRIX = 104

#: Work arrays of the compiled Radau loop (allocated once per integrator).
RADAU_WORK_FIELDS = (
    "Mden", "K", "D", "Gd", "KK_r", "KK_c", "piv_r", "piv_c", "band",  # Jacobian and factors
    "sp_ptr", "sp_col", "sp_m", "sp_k", "sp_d", "g_ptr", "g_col", "g_val",  # their sparse rows
    "ip",                                                               # RCM position of each unknown
    "f", "y_new", "y_old", "Z", "W", "F", "dW", "Zt", "yt", "scale",    # stages
    "b_c", "b", "err", "tmp", "qp", "vp", "Qa", "Qb", "lam", "Qpoly", "info",
    "AJ", "PS", "RS", "X", "dZ", "xs", "ys", "xs_c", "ys_c",            # stage frames (_to_frame)
    "spatial", "AP", "Kp", "Dp", "n_jac",                               # each body's frame (_choose_frames)
)


@structref.register
class RadauWorkType(types.StructRef):
    """numba type of :class:`RadauWork`."""

    def preprocess_fields(self, fields):
        return tuple((name, types.unliteral(typ)) for name, typ in fields)


class RadauWork(structref.StructRefProxy):
    """The arrays of one Radau run (a structref: passed by pointer into the compiled functions;
    from Python its fields read as the same numpy arrays)."""

    def __new__(cls, **arrays):
        obj = _new_radau_work(*(arrays[f] for f in RADAU_WORK_FIELDS))
        obj._arrays = arrays
        return obj

    def __getattr__(self, name):
        try:
            return self.__dict__["_arrays"][name]
        except KeyError:
            raise AttributeError(f"RadauWork has no field {name!r}") from None


structref.define_proxy(RadauWork, RadauWorkType, list(RADAU_WORK_FIELDS))


@numba.njit(cache=True)
def _new_radau_work(*values):
    """Built in compiled code cached on disk (``StructRefProxy.__new__`` compiles an uncached
    constructor in every process; see :func:`core.compiled.layout._new_compiled_data`)."""
    return RadauWork(*values)


# ================================================================================================
# linear algebra: the iteration matrices in RCM order, banded LU with partial pivoting
# ================================================================================================


@_internal
def _orientation(e0, e1, e2, e3, A):
    """``A(p)`` (Nikravesh 1988, Eq. 6.19) into ``A`` for one set of Euler parameters (a stage's;
    :func:`core.compiled.dynamics.body_states` writes the same for every body of a state)."""
    A[0, 0] = 2.0 * (e0 * e0 + e1 * e1) - 1.0
    A[1, 1] = 2.0 * (e0 * e0 + e2 * e2) - 1.0
    A[2, 2] = 2.0 * (e0 * e0 + e3 * e3) - 1.0
    A[0, 1] = 2.0 * (e1 * e2 - e0 * e3)
    A[1, 0] = 2.0 * (e1 * e2 + e0 * e3)
    A[0, 2] = 2.0 * (e1 * e3 + e0 * e2)
    A[2, 0] = 2.0 * (e1 * e3 - e0 * e2)
    A[1, 2] = 2.0 * (e2 * e3 - e0 * e1)
    A[2, 1] = 2.0 * (e2 * e3 + e0 * e1)


@_internal
def _frames(lay, y, Z, AJ, spatial, PS, RS):
    """The stage frames of a step (module docstring, "Spinning bodies"): ``PS[i, b]`` the Euler
    parameters of body ``b`` at stage ``i`` (``p₀ + Z_i`` normalised, ``i = 0, 1, 2``; ``i = 3`` the
    step start) and ``RS[i, b] = A(PS[i, b])ᵀ A_J``, ``A_J`` its orientation at the Jacobian, for a
    body whose Jacobian is carried in the spatial frame (:func:`_choose_frames`); ``p₀`` and ``I``
    at every stage for one in its own frame.  Returns whether any body uses the spatial frame (if
    none does, the three stages share one map)."""
    if lay[1] == 2:
        return False
    A = np.empty((3, 3))
    any_spatial = False
    for i in range(4):
        for bb in range(lay[0]):
            o = 7 * bb + 3
            nrm = 0.0
            sp = spatial[bb] != 0.0
            for c in range(4):  # a body in its own frame keeps the step start's (module docstring)
                e = y[o + c] + (Z[i, o + c] if i < 3 and sp else 0.0)
                PS[i, bb, c] = e
                nrm += e * e
            nrm = np.sqrt(nrm)
            for c in range(4):
                PS[i, bb, c] /= nrm
            if not sp:  # body frame: R = I
                for r in range(3):
                    for c in range(3):
                        RS[i, bb, r, c] = 1.0 if r == c else 0.0
                continue
            any_spatial = True
            _orientation(PS[i, bb, 0], PS[i, bb, 1], PS[i, bb, 2], PS[i, bb, 3], A)
            for r in range(3):
                for c in range(3):
                    RS[i, bb, r, c] = A[0, r] * AJ[bb, 0, c] + A[1, r] * AJ[bb, 1, c] + A[2, r] * AJ[bb, 2, c]
    return any_spatial


@_internal
def _to_frame(lay, nv, P, R, x, out):
    r"""A y-space vector ``x = (δq, δv)`` of a stage in the Jacobian's velocity space:
    ``out = (a, b, n)`` with ``a = (δr, Rᵀ 2L(p) δp)``, ``b = (δṙ, Rᵀ δω̄)``, ``n = pᵀδp`` per
    spatial body (``2L(p)δp = δθ̄``, Nikravesh 1988, Eq. 6.100); the identity for planar bodies
    and extra coordinates."""
    nb, nq = lay[0], lay[4]
    if lay[1] == 2:
        for i in range(nv):
            out[i] = x[i]
            out[nv + i] = x[nq + i]
        return
    for bb in range(nb):
        o, u = 7 * bb, 6 * bb
        for c in range(3):
            out[u + c] = x[o + c]
            out[nv + u + c] = x[nq + u + c]
        e0, e1, e2, e3 = P[bb, 0], P[bb, 1], P[bb, 2], P[bb, 3]
        d0, d1, d2, d3 = x[o + 3], x[o + 4], x[o + 5], x[o + 6]
        # L(p) = [−e, −ẽ + e0 I]  (Nikravesh 1988, Eq. 6.95)
        w0 = 2.0 * (-e1 * d0 + e0 * d1 + e3 * d2 - e2 * d3)
        w1 = 2.0 * (-e2 * d0 - e3 * d1 + e0 * d2 + e1 * d3)
        w2 = 2.0 * (-e3 * d0 + e2 * d1 - e1 * d2 + e0 * d3)
        v0, v1, v2 = x[nq + u + 3], x[nq + u + 4], x[nq + u + 5]
        for c in range(3):
            out[u + 3 + c] = R[bb, 0, c] * w0 + R[bb, 1, c] * w1 + R[bb, 2, c] * w2
            out[nv + u + 3 + c] = R[bb, 0, c] * v0 + R[bb, 1, c] * v1 + R[bb, 2, c] * v2
        out[2 * nv + bb] = e0 * d0 + e1 * d1 + e2 * d2 + e3 * d3
    for k in range(lay[6]):
        out[6 * nb + k] = x[7 * nb + k]
        out[nv + 6 * nb + k] = x[nq + 6 * nb + k]


@_internal
def _from_frame(lay, nv, P, R, X, out):
    r"""The inverse of :func:`_to_frame`: ``δp = ½ L(p)ᵀ R a_θ + p n``, ``δω̄ = R b_θ``
    (``L Lᵀ = I``, ``L p = 0`` for ``|p| = 1``)."""
    nb, nq = lay[0], lay[4]
    if lay[1] == 2:
        for i in range(nv):
            out[i] = X[i]
            out[nq + i] = X[nv + i]
        return
    for bb in range(nb):
        o, u = 7 * bb, 6 * bb
        for c in range(3):
            out[o + c] = X[u + c]
            out[nq + u + c] = X[nv + u + c]
        a0, a1, a2 = X[u + 3], X[u + 4], X[u + 5]
        b0, b1, b2 = X[nv + u + 3], X[nv + u + 4], X[nv + u + 5]
        w0 = R[bb, 0, 0] * a0 + R[bb, 0, 1] * a1 + R[bb, 0, 2] * a2
        w1 = R[bb, 1, 0] * a0 + R[bb, 1, 1] * a1 + R[bb, 1, 2] * a2
        w2 = R[bb, 2, 0] * a0 + R[bb, 2, 1] * a1 + R[bb, 2, 2] * a2
        for c in range(3):
            out[nq + u + 3 + c] = R[bb, c, 0] * b0 + R[bb, c, 1] * b1 + R[bb, c, 2] * b2
        e0, e1, e2, e3 = P[bb, 0], P[bb, 1], P[bb, 2], P[bb, 3]
        n = X[2 * nv + bb]
        out[o + 3] = 0.5 * (-e1 * w0 - e2 * w1 - e3 * w2) + e0 * n
        out[o + 4] = 0.5 * (e0 * w0 - e3 * w1 + e2 * w2) + e1 * n
        out[o + 5] = 0.5 * (e3 * w0 + e0 * w1 - e1 * w2) + e2 * n
        out[o + 6] = 0.5 * (-e2 * w0 + e1 * w1 + e0 * w2) + e3 * n
    for k in range(lay[6]):
        out[7 * nb + k] = X[6 * nb + k]
        out[nq + 6 * nb + k] = X[nv + 6 * nb + k]


@_jit
def _pack(rw, nv, m):
    """Sparse rows of ``M``, ``K``, ``D`` (their union pattern) and of ``Φ_q`` from the dense
    Jacobian, and the band ``(kl, ku)`` of the iteration matrices in RCM order (once per Jacobian).

    The products and the assembly then cost the number of nonzeros, not ``n_v²`` (measured on the
    stiff chain: the dense products took two thirds of a Newton solve).
    """
    Mden, K, D, Gd, ip = rw.Mden, rw.K, rw.D, rw.Gd, rw.ip
    ptr, col, vm, vk, vd = rw.sp_ptr, rw.sp_col, rw.sp_m, rw.sp_k, rw.sp_d
    kl = 0
    ku = 0
    p = 0
    for i in range(nv):
        ptr[i] = p
        pi = ip[i]
        for j in range(nv):
            if Mden[i, j] != 0.0 or K[i, j] != 0.0 or D[i, j] != 0.0:
                col[p], vm[p], vk[p], vd[p] = j, Mden[i, j], K[i, j], D[i, j]
                p += 1
                pj = ip[j]
                if pi - pj > kl:
                    kl = pi - pj
                if pj - pi > ku:
                    ku = pj - pi
    ptr[nv] = p
    gptr, gcol, gval = rw.g_ptr, rw.g_col, rw.g_val
    p = 0
    for r in range(m):
        gptr[r] = p
        pr = ip[nv + r]
        for j in range(nv):
            if Gd[r, j] != 0.0:
                gcol[p], gval[p] = j, Gd[r, j]
                p += 1
                d = pr - ip[j]
                if d < 0:
                    d = -d
                if d > kl:
                    kl = d
                if d > ku:
                    ku = d
    gptr[m] = p
    rw.band[0], rw.band[1] = kl, ku


@_internal
def _abs2(x):
    """``|x|²`` of a real or complex number (no square root: comparisons only)."""
    return x.real * x.real + x.imag * x.imag


@_jit
def _assemble(mu, rw, nv, m, A):
    """``A = P [[μM − D − K/μ, Gᵀ], [G, 0]] Pᵀ`` (RCM order; ``mu`` real or complex) on the band
    that the LU fills (columns ``i − kl … i + ku + kl``); returns the largest magnitude."""
    N = nv + m
    kl, ku = rw.band[0], rw.band[1]
    for i in range(N):
        for j in range(max(0, i - kl), min(N, i + ku + kl + 1)):
            A[i, j] = 0.0
    ip, ptr, col, vm, vk, vd = rw.ip, rw.sp_ptr, rw.sp_col, rw.sp_m, rw.sp_k, rw.sp_d
    inv_mu = 1.0 / mu
    big = 0.0
    for i in range(nv):
        pi = ip[i]
        for p in range(ptr[i], ptr[i + 1]):
            x = mu * vm[p] - vd[p] - vk[p] * inv_mu
            A[pi, ip[col[p]]] = x
            a2 = _abs2(x)
            if a2 > big:
                big = a2
    gptr, gcol, gval = rw.g_ptr, rw.g_col, rw.g_val
    for r in range(m):
        pr = ip[nv + r]
        for p in range(gptr[r], gptr[r + 1]):
            g = gval[p]
            pj = ip[gcol[p]]
            A[pr, pj] = g
            A[pj, pr] = g
            if g * g > big:
                big = g * g
    return np.sqrt(big)


@_jit
def _band_lu(A, N, kl, ku, scale, piv):
    """LU with partial pivoting of the band matrix ``A[:N, :N]`` (bandwidths ``kl``, ``ku``) in
    place; fill from row interchanges stays within ``ku + kl`` above the diagonal (Golub & Van Loan
    2013, Sec. 4.3.5); status (singular: a pivot below 1e-14 of the largest entry).  The pivot is
    the entry of largest ``|a|²`` and the multipliers use its reciprocal (complex division and
    modulus cost a multiple of a multiplication)."""
    uw = ku + kl
    tiny = (1e-14 * scale) ** 2
    for k in range(N):
        last = min(N - 1, k + kl)
        p = k
        big = _abs2(A[k, k])
        for i in range(k + 1, last + 1):
            a = _abs2(A[i, k])
            if a > big:
                big, p = a, i
        piv[k] = p
        if not big > tiny:
            return _p.SINGULAR
        jlast = min(N - 1, k + uw)
        if p != k:
            for j in range(k, jlast + 1):
                A[k, j], A[p, j] = A[p, j], A[k, j]
        inv_pivot = 1.0 / A[k, k]
        for i in range(k + 1, last + 1):
            f = A[i, k] * inv_pivot
            A[i, k] = f
            if f != 0.0:
                for j in range(k + 1, jlast + 1):
                    A[i, j] -= f * A[k, j]
    return _p.OK


@_jit
def _band_solve(A, N, piv, kl, ku, b):
    """Solve with the factors of :func:`_band_lu` in place."""
    uw = kl + ku
    for k in range(N):
        p = piv[k]
        if p != k:
            b[k], b[p] = b[p], b[k]
        bk = b[k]
        if bk != 0.0:
            for i in range(k + 1, min(N - 1, k + kl) + 1):
                b[i] -= A[i, k] * bk
    for i in range(N - 1, -1, -1):
        s = b[i]
        for j in range(i + 1, min(N - 1, i + uw) + 1):
            s -= A[i, j] * b[j]
        b[i] = s / A[i, i]


@_jit
def _vsolve(rw, nv, nb, m, mu, alpha, beta, A, piv, x, out, b):
    r"""``out = (μ I − J̃)⁻¹ x`` in the Jacobian's velocity space (:func:`_to_frame`), ``x = (r_a, r_b,
    r_n)``, through the saddle-point form (module docstring):
    ``[[μM − D − K/μ, Gᵀ], [G, 0]] (b, λ') = (M r_b + K r_a/μ, G (r_b − β² r_a/μ)/(μ + 2α + β²/μ))``,
    then ``a = (r_a + b)/μ`` and ``n = r_n/μ``."""
    ip, ptr, col, vm, vk = rw.ip, rw.sp_ptr, rw.sp_col, rw.sp_m, rw.sp_k
    inv_mu = 1.0 / mu
    for i in range(nv):
        acc = 0.0 * mu
        for p in range(ptr[i], ptr[i + 1]):
            j = col[p]
            acc += vm[p] * x[nv + j] + vk[p] * (x[j] * inv_mu)
        b[ip[i]] = acc
    denom = mu + 2.0 * alpha + beta * beta * inv_mu
    bb = beta * beta
    gptr, gcol, gval = rw.g_ptr, rw.g_col, rw.g_val
    for r in range(m):
        acc = 0.0 * mu
        for p in range(gptr[r], gptr[r + 1]):
            j = gcol[p]
            acc += gval[p] * (x[nv + j] - bb * (x[j] * inv_mu))
        b[ip[nv + r]] = acc / denom
    _band_solve(A, nv + m, piv, rw.band[0], rw.band[1], b)
    for i in range(nv):
        bi = b[ip[i]]
        out[nv + i] = bi
        out[i] = (x[i] + bi) * inv_mu
    for k in range(nb):
        out[2 * nv + k] = x[2 * nv + k] * inv_mu


@_internal
def _choose_frames(cd, rw, nv, h):
    r"""Each spatial body's frame for the Jacobian (module docstring, "Spinning bodies"), from the
    last two Jacobians: the spatial frame when the previous Jacobian, rotated by the body's rotation
    ``R = A_Jᵀ A_P`` between them, predicts the new body block of the real iteration matrix
    ``G = μM − D − K/μ`` (``μ = μ_r/h``) better than the previous one as it stands:

    ``‖μ(T M Tᵀ − M) − (D − T D_P Tᵀ) − (K − T K_P Tᵀ)/μ‖ < ‖−(D − D_P) − (K − K_P)/μ‖``,
    ``T = diag(I, R)``, over the body's 6 × 6 block (Frobenius norm).  A body that turned by less
    than 7e-4 rad keeps its choice; one in a mass group (a flexible body) keeps the body frame."""
    lay = cd.lay
    nb = lay[0]
    mu = MU_REAL / h
    inv_mu = 1.0 / mu
    Mden, K, D, Kp, Dp, AJ, AP = rw.Mden, rw.K, rw.D, rw.Kp, rw.Dp, rw.AJ, rw.AP
    T = np.zeros((6, 6))
    for bb in range(nb):
        u = 6 * bb
        grouped = False
        for g in range(cd.n_grp):
            for i in range(cd.grp_w[g]):
                if cd.grp_v[g, i] == u + 3:
                    grouped = True
        if grouped:
            rw.spatial[bb] = 0.0
            continue
        for i in range(6):
            for j in range(6):
                T[i, j] = 1.0 if (i == j and i < 3) else 0.0
        for i in range(3):
            for j in range(3):
                T[3 + i, 3 + j] = (AJ[bb, 0, i] * AP[bb, 0, j] + AJ[bb, 1, i] * AP[bb, 1, j]
                                   + AJ[bb, 2, i] * AP[bb, 2, j])
        if T[3, 3] + T[4, 4] + T[5, 5] > 3.0 - 5e-7:  # 1 + 2 cos θ: θ < 7e-4 rad
            continue
        e_body = 0.0
        e_spatial = 0.0
        for i in range(6):
            for j in range(6):
                tm = 0.0
                tk = 0.0
                td = 0.0
                for a in range(6):
                    for c in range(6):
                        w = T[i, a] * T[j, c]
                        if w != 0.0:
                            tm += w * Mden[u + a, u + c]
                            tk += w * Kp[u + a, u + c]
                            td += w * Dp[u + a, u + c]
                x = -(D[u + i, u + j] - Dp[u + i, u + j]) - (K[u + i, u + j] - Kp[u + i, u + j]) * inv_mu
                e_body += x * x
                x = mu * (tm - Mden[u + i, u + j]) - (D[u + i, u + j] - td) - (K[u + i, u + j] - tk) * inv_mu
                e_spatial += x * x
        rw.spatial[bb] = 1.0 if e_spatial < e_body else 0.0


@_jit
def _jacobian(cd, states, ws, rw, t, q, v, h):
    """``K``, ``D``, the mass matrix's configuration-dependent blocks (mass groups) and the active
    rows of ``Φ_q`` (dense) at ``(t, q, v)``, and each body's frame for them (:func:`_choose_frames`,
    step ``h``); status."""
    spatial_model = cd.lay[1] == 3
    if spatial_model:  # the previous Jacobian, for the choice of frames
        for i in range(rw.K.shape[0]):
            for j in range(rw.K.shape[0]):
                rw.Kp[i, j] = rw.K[i, j]
                rw.Dp[i, j] = rw.D[i, j]
        for bb in range(cd.lay[0]):
            for i in range(3):
                for j in range(3):
                    rw.AP[bb, i, j] = rw.AJ[bb, i, j]
    st = _d.force_jacobian(cd, states, ws, t, q, v, rw.K, rw.D, rw.qp, rw.vp, rw.Qa, rw.Qb)
    if st != _p.OK:
        return st
    act = cd.act
    m = act.shape[0]
    nv = rw.K.shape[0]
    _d.body_states(cd.lay, q, v, ws)
    if spatial_model:  # the orientations the Jacobian belongs to (_frames): A(p) of body_states
        for bb in range(cd.lay[0]):
            for i in range(3):
                for j in range(3):
                    rw.AJ[bb, i, j] = ws.A[bb, i, j]
    if cd.n_grp:  # the mass groups' blocks of M at this state (the rest of M is constant)
        st = _d.mass_update(cd, ws, t, q, v)
        if st != _p.OK:
            return st
        Mden, Mg, grp_v, grp_w = rw.Mden, ws.Mg, cd.grp_v, cd.grp_w
        for g in range(cd.n_grp):
            for i in range(grp_w[g]):
                for j in range(grp_w[g]):
                    Mden[grp_v[g, i], grp_v[g, j]] = Mg[g, i, j]
    if spatial_model:
        if rw.n_jac[0] > 0:
            _choose_frames(cd, rw, nv, h)
        rw.n_jac[0] += 1
    if m == 0:
        _pack(rw, nv, np.int64(0))
        return _p.OK
    st = _d.constraints(cd, ws, t, q, v, np.int64(0))  # np.int64: a literal would compile a copy
    if st != _p.OK:
        return st
    Gd, G, r_blk, blk_v0, blk_w = rw.Gd, ws.G, cd.r_blk, cd.blk_v0, cd.blk_w
    for k in range(m):
        a = act[k]
        for j in range(nv):
            Gd[k, j] = 0.0
        for sl in range(_p.MAX_SLOTS):
            blk = r_blk[a, sl]
            if blk >= 0 and blk_w[blk] > 0:
                o = blk_v0[blk]
                for c in range(blk_w[blk]):
                    Gd[k, o + c] += G[a, sl, c]
    _pack(rw, nv, m)
    return _p.OK


@_jit
def _factor_both(rw, h, nv, m, counters):
    """Real and complex iteration matrices for step ``h``, assembled and factorised; status."""
    mr = MU_REAL / h
    mc = (MU_COMPLEX_RE + 1j * MU_COMPLEX_IM) / h
    N = nv + m
    kl, ku = rw.band[0], rw.band[1]
    scale = _assemble(mr, rw, nv, m, rw.KK_r)
    st = _band_lu(rw.KK_r, N, kl, ku, scale, rw.piv_r)
    if st != _p.OK:
        return st
    scale = _assemble(mc, rw, nv, m, rw.KK_c)
    st = _band_lu(rw.KK_c, N, kl, ku, scale, rw.piv_c)
    counters[C_FACT] += 2
    return st


MU_COMPLEX_RE, MU_COMPLEX_IM = float(MU_COMPLEX.real), float(MU_COMPLEX.imag)
T_ = np.ascontiguousarray(T)
TI_ = np.ascontiguousarray(TI)
C_ = np.ascontiguousarray(RADAU_C)
E_ = np.ascontiguousarray(RADAU_E)


@_internal
def _rms_scaled(x, scale, rows):
    acc = 0.0
    n = scale.shape[0]
    for r in range(rows):
        for i in range(n):
            z = x[r, i] / scale[i]
            acc += z * z
    return np.sqrt(acc / (rows * n))


@_jit
def _solve_real(lay, rw, h, nv, m, alpha, beta, r, out):
    """``out = ((μ_r/h) I − J)⁻¹ r`` (y-space vectors at the step start, frame 3 of :func:`_frames`)."""
    _to_frame(lay, nv, rw.PS[3], rw.RS[3], r, rw.xs)
    _vsolve(rw, nv, lay[0], m, MU_REAL / h, alpha, beta, rw.KK_r, rw.piv_r, rw.xs, rw.ys, rw.b)
    _from_frame(lay, nv, rw.PS[3], rw.RS[3], rw.ys, out)


@_jit
def _collocation(cd, states, ws, rw, lay, nq, constrained, t, y, h, alpha, beta, tol, nv, m, counters, lam):
    """RADAU5's simplified Newton iteration for the stages; returns (converged, iterations, rate)."""
    Z, W, F, dW, yt, scale = rw.Z, rw.W, rw.F, rw.dW, rw.yt, rw.scale
    n = y.shape[0]
    mr = MU_REAL / h
    mc = (MU_COMPLEX_RE + 1j * MU_COMPLEX_IM) / h
    # W = TI Z
    for r in range(3):
        for i in range(n):
            W[r, i] = TI_[r, 0] * Z[0, i] + TI_[r, 1] * Z[1, i] + TI_[r, 2] * Z[2, i]
    dW_norm_old = -1.0
    rate = -1.0
    converged = False
    k = 0
    nb = lay[0]
    nf = 2 * nv + nb
    tmp, X, dZ, xs, ys, xs_c, ys_c = rw.tmp, rw.X, rw.dZ, rw.xs, rw.ys, rw.xs_c, rw.ys_c
    PS, RS = rw.PS, rw.RS
    per_stage = _frames(lay, y, Z, rw.AJ, rw.spatial, PS, RS)  # from the starting guess: fixed over the iteration
    # the complex row of TI: TI[1] + i TI[2]
    tc0 = TI_[1, 0] + 1j * TI_[2, 0]
    tc1 = TI_[1, 1] + 1j * TI_[2, 1]
    tc2 = TI_[1, 2] + 1j * TI_[2, 2]
    for k in range(NEWTON_MAXITER):
        finite = True
        for i in range(3):
            for j in range(n):
                yt[j] = y[j] + Z[i, j]
            _d.normalize(lay, yt)  # the stage's Euler parameters on the unit sphere (module docstring)
            st = _rhs(cd, states, ws, lay, nq, constrained, t + C_[i] * h, yt, alpha, beta, F[i], lam, counters)
            if st != _p.OK and st != _p.NONFINITE:
                return -st, k + 1, rate
            for j in range(n):
                if not np.isfinite(F[i, j]):
                    finite = False
        if not finite:
            break
        counters[C_NEWTON] += 1
        # the residual in W: g = TI F − Λ W, the real row and the complex pair (W1 + i W2) split
        for j in range(n):
            fc = tc0 * F[0, j] + tc1 * F[1, j] + tc2 * F[2, j] - mc * (W[1, j] + 1j * W[2, j])
            dW[0, j] = TI_[0, 0] * F[0, j] + TI_[0, 1] * F[1, j] + TI_[0, 2] * F[2, j] - mr * W[0, j]
            dW[1, j] = fc.real
            dW[2, j] = fc.imag
        if per_stage:
            # per stage (G = T g) into its frame, combined again by TI, solved, back per stage (docstring)
            for i in range(3):
                for j in range(n):
                    tmp[j] = T_[i, 0] * dW[0, j] + T_[i, 1] * dW[1, j] + T_[i, 2] * dW[2, j]
                _to_frame(lay, nv, PS[i], RS[i], tmp, X[i])
            for j in range(nf):
                xs[j] = TI_[0, 0] * X[0, j] + TI_[0, 1] * X[1, j] + TI_[0, 2] * X[2, j]
                xs_c[j] = tc0 * X[0, j] + tc1 * X[1, j] + tc2 * X[2, j]
        else:  # one map for all stages: it commutes with T and TI
            for r in range(3):
                _to_frame(lay, nv, PS[3], RS[3], dW[r], X[r])
            for j in range(nf):
                xs[j] = X[0, j]
                xs_c[j] = X[1, j] + 1j * X[2, j]
        _vsolve(rw, nv, nb, m, mr, alpha, beta, rw.KK_r, rw.piv_r, xs, ys, rw.b)
        _vsolve(rw, nv, nb, m, mc, alpha, beta, rw.KK_c, rw.piv_c, xs_c, ys_c, rw.b_c)
        if per_stage:
            for i in range(3):
                for j in range(nf):
                    X[i, j] = T_[i, 0] * ys[j] + T_[i, 1] * ys_c[j].real + T_[i, 2] * ys_c[j].imag
                _from_frame(lay, nv, PS[i], RS[i], X[i], dZ[i])
            for r in range(3):
                for j in range(n):
                    dW[r, j] = TI_[r, 0] * dZ[0, j] + TI_[r, 1] * dZ[1, j] + TI_[r, 2] * dZ[2, j]
        else:
            for j in range(nf):
                X[0, j] = ys[j]
                X[1, j] = ys_c[j].real
                X[2, j] = ys_c[j].imag
            for r in range(3):
                _from_frame(lay, nv, PS[3], RS[3], X[r], dW[r])
        dW_norm = _rms_scaled(dW, scale, 3)
        if dW_norm_old >= 0.0:
            rate = dW_norm / dW_norm_old
        if rate >= 0.0 and (rate >= 1.0 or rate ** (NEWTON_MAXITER - k) / (1.0 - rate) * dW_norm > tol):
            break
        for r in range(3):
            for j in range(n):
                W[r, j] += dW[r, j]
        for r in range(3):
            for j in range(n):
                Z[r, j] = T_[r, 0] * W[0, j] + T_[r, 1] * W[1, j] + T_[r, 2] * W[2, j]
        if dW_norm == 0.0 or (rate >= 0.0 and rate / (1.0 - rate) * dW_norm < tol):
            converged = True
            break
        dW_norm_old = dW_norm
    return 1 if converged else 0, k + 1, rate


@_internal
def _predict_factor(h_abs, h_abs_old, error_norm, error_norm_old):
    if error_norm_old < 0.0 or h_abs_old < 0.0 or error_norm == 0.0:
        multiplier = 1.0
    else:
        multiplier = h_abs / h_abs_old * (error_norm_old / error_norm) ** 0.25
    if error_norm == 0.0:
        return MAX_FACTOR
    return min(1.0, multiplier) * error_norm ** -0.25


@_jit
def advance(cd, states, ws, rw, t, y, t_stop, t_bound, h_abs, max_steps, rtol, atol, max_step, newton_tol, alpha,
            beta, projection, proj_tol, max_proj_iter, stateful, counters, info):
    r"""Take accepted Radau steps from ``t`` until ``t ≥ t_stop`` (or ``max_steps``); state in place.

    ``info = [t, h_abs, t_old, t_fail, h_abs_old, error_norm_old, have_jac, current_jac,
    have_lu, h_lu]`` carries the controller's memory between calls; the last step's collocation
    polynomial is left in ``Qpoly`` and its start state in ``y_old`` (dense output).
    Returns an exit code: ``EXIT_REACHED``, ``EXIT_MAX_STEPS`` or a failure.
    """
    lay = cd.lay
    nq = lay[4]
    nv = lay[5]
    m = cd.act.shape[0]
    constrained = m > 0
    n = y.shape[0]
    lam = rw.lam
    f = rw.f
    Z = rw.Z
    Zt = rw.Zt
    scale, y_new, y_old, Qpoly = rw.scale, rw.y_new, rw.y_old, rw.Qpoly
    err, tmp, yt, F0 = rw.err, rw.tmp, rw.yt, rw.F[0]
    steps = 0
    h_abs_old = info[4]
    error_norm_old = info[5]
    have_jac = info[6] != 0.0
    current_jac = info[7] != 0.0
    have_lu = info[8] != 0.0
    h_lu = info[9]
    while True:
        if t >= t_stop:
            break
        if steps >= max_steps:
            info[0] = t
            info[1] = h_abs
            info[4], info[5] = h_abs_old, error_norm_old
            info[6], info[7], info[8], info[9] = have_jac, current_jac, have_lu, h_lu
            return EXIT_MAX_STEPS
        if not have_jac:
            st = _jacobian(cd, states, ws, rw, t, y[:nq], y[nq:], h_abs)
            counters[C_JAC] += 1
            if st != _p.OK:
                info[0] = t
                info[3] = t
                return st
            have_jac = True
            current_jac = True
            have_lu = False
        min_step = 10.0 * abs(np.nextafter(t, np.inf) - t)
        if h_abs > max_step:
            h_abs = max_step
            h_abs_old = -1.0
            error_norm_old = -1.0
        elif h_abs < min_step:
            h_abs = min_step
            h_abs_old = -1.0
            error_norm_old = -1.0
        rejected = False
        accepted = False
        n_iter = 0
        rate = -1.0
        error_norm = 0.0
        safety = 0.9
        t_new = t
        while not accepted:
            if h_abs < min_step:
                info[0] = t
                info[3] = t
                return EXIT_TOO_SMALL
            t_new = t + h_abs
            if t_new > t_bound:
                t_new = t_bound
            h = t_new - t
            h_abs = abs(h)
            # initial guess: the previous collocation polynomial extrapolated (zero at the start)
            if info[2] == info[2] and steps + counters[C_STEPS] > 0:
                h_prev = t - info[2]
                for i in range(3):
                    x = (t + RADAU_C_[i] * h - info[2]) / h_prev
                    x1 = 1.0
                    for j in range(n):
                        Z[i, j] = 0.0
                    for p in range(3):
                        x1 = x1 * x
                        for j in range(n):
                            Z[i, j] += Qpoly[j, p] * x1
                    for j in range(n):
                        Z[i, j] += y_old[j] - y[j]
            else:
                for i in range(3):
                    for j in range(n):
                        Z[i, j] = 0.0
            for j in range(n):
                scale[j] = atol + abs(y[j]) * rtol
            for i in range(3):  # the guess, for a retry with a fresh Jacobian
                for j in range(n):
                    Zt[i, j] = Z[i, j]
            converged = 0
            while True:
                if not have_lu or h_lu != h:
                    st = _factor_both(rw, h, nv, m, counters)
                    if st != _p.OK:
                        info[0] = t
                        info[3] = t
                        return EXIT_SINGULAR_MATRIX
                    have_lu = True
                    h_lu = h
                converged, n_iter, rate = _collocation(cd, states, ws, rw, lay, nq, constrained, t, y, h, alpha, beta,
                                                       newton_tol, nv, m, counters, lam)
                if converged < 0:  # a kernel failure other than non-finite values
                    info[0] = t
                    info[3] = t
                    return -converged
                if converged == 1 or current_jac:
                    break
                st = _jacobian(cd, states, ws, rw, t, y[:nq], y[nq:], h_abs)
                counters[C_JAC] += 1
                if st != _p.OK:
                    info[0] = t
                    info[3] = t
                    return st
                current_jac = True
                have_lu = False
                for i in range(3):
                    for j in range(n):
                        Z[i, j] = Zt[i, j]
            if converged != 1:
                h_abs *= 0.5
                have_lu = False
                rejected = True
                counters[C_REJ] += 1
                counters[C_NEWTON_FAIL] += 1
                continue
            for j in range(n):
                y_new[j] = y[j] + Z[2, j]
            # error estimate: (μ_r/h − J)⁻¹ (f + Σ e_i Z_i / h)
            for j in range(n):
                tmp[j] = f[j] + (E_[0] * Z[0, j] + E_[1] * Z[1, j] + E_[2] * Z[2, j]) / h
            _solve_real(lay, rw, h, nv, m, alpha, beta, tmp, err)
            for j in range(n):
                scale[j] = atol + max(abs(y[j]), abs(y_new[j])) * rtol
            acc = 0.0
            for j in range(n):
                z = err[j] / scale[j]
                acc += z * z
            error_norm = np.sqrt(acc / n)
            safety = 0.9 * (2 * NEWTON_MAXITER + 1) / (2 * NEWTON_MAXITER + n_iter)
            if rejected and error_norm > 1.0:
                for j in range(n):
                    yt[j] = y[j] + err[j]
                _d.normalize(lay, yt)
                _rhs(cd, states, ws, lay, nq, constrained, t, yt, alpha, beta, F0, lam, counters)
                for j in range(n):
                    tmp[j] = F0[j] + (E_[0] * Z[0, j] + E_[1] * Z[1, j] + E_[2] * Z[2, j]) / h
                _solve_real(lay, rw, h, nv, m, alpha, beta, tmp, err)
                acc = 0.0
                for j in range(n):
                    z = err[j] / scale[j]
                    acc += z * z
                error_norm = np.sqrt(acc / n)
            if not error_norm == error_norm:
                error_norm = np.inf
            if error_norm > 1.0:
                factor = _predict_factor(h_abs, h_abs_old, error_norm, error_norm_old)
                h_abs *= max(MIN_FACTOR, safety * factor)
                have_lu = False
                rejected = True
                counters[C_REJ] += 1
            else:
                accepted = True
        # accepted
        recompute_jac = n_iter > 2 and rate > 1e-3
        factor = _predict_factor(h_abs, h_abs_old, error_norm, error_norm_old)
        factor = min(MAX_FACTOR, safety * factor)
        if rejected:
            factor = min(1.0, factor)
        if not recompute_jac and factor < 1.2:
            factor = 1.0
        if rate > NEWTON_RATE_HOLD:  # slow contraction: do not enlarge h (see the module docstring)
            factor = min(factor, 1.0)
        # dense output polynomial (Q = Zᵀ P) and the start state of the step
        for j in range(n):
            y_old[j] = y[j]
            for p in range(3):
                Qpoly[j, p] = Z[0, j] * P_[0, p] + Z[1, j] * P_[1, p] + Z[2, j] * P_[2, p]
        info[2] = t
        for j in range(n):
            y[j] = y_new[j]
        _d.normalize(lay, y)
        if projection:
            it = _d.project(cd, ws, t_new, y[:nq], y[nq:], proj_tol, max_proj_iter, counters)
            if it < 0:
                for j in range(n):
                    y[j] = y_old[j]
                info[0] = t
                info[3] = t_new
                return _p.PROJECTION
        if stateful:
            st = _d.accept(cd, states, ws, t_new, y[:nq], y[nq:])
            if st != _p.OK:
                info[0] = t
                info[3] = t_new
                return st
        st = _rhs(cd, states, ws, lay, nq, constrained, t_new, y, alpha, beta, f, lam, counters)
        if st != _p.OK and st != _p.NONFINITE:
            info[0] = t
            info[3] = t_new
            return st
        h_abs_old = h_abs
        error_norm_old = error_norm
        h_abs = h_abs * factor
        t = t_new
        steps += 1
        counters[C_STEPS] += 1
        if recompute_jac:
            st = _jacobian(cd, states, ws, rw, t, y[:nq], y[nq:], h_abs)
            counters[C_JAC] += 1
            if st != _p.OK:
                info[0] = t
                info[3] = t
                return st
            current_jac = True
            have_lu = False
        else:
            current_jac = False
    info[0] = t
    info[1] = h_abs
    info[4], info[5] = h_abs_old, error_norm_old
    info[6], info[7], info[8], info[9] = have_jac, current_jac, have_lu, h_lu
    return EXIT_REACHED


P_ = np.ascontiguousarray(P)
RADAU_C_ = C_


class CompiledRadau(Integrator):
    """Radau IIA (order 5) on the index-1 formulation in a compiled loop (see the module docstring).

    Parameters
    ----------
    alpha, beta : float, optional
        Baumgarte parameters [1/s] (``-baumgarte`` variant); default 10 each.
    projection_tol : float, optional
        Position-projection tolerance on ``‖Φ‖∞`` (``-projection`` variant); default ``atol``.
    max_projection_iter : int, optional
        Gauss–Newton iterations per projection (default 10).

    Raises
    ------
    core.errors.NotCompilable
        When the model has an element without a compiled kernel (the message names it).
    """

    stabilization = "none"
    #: steps are taken up to the next output time (or past it); the collocation polynomial
    #: gives the output in between
    steps_to_output = True

    @classmethod
    def accepted_options(cls):
        if cls.stabilization == "baumgarte":
            return ("alpha", "beta")
        if cls.stabilization == "projection":
            return ("projection_tol", "max_projection_iter")
        return ()

    @classmethod
    def applicable(cls, system):
        try:
            _l.compile_model(system)
        except NotCompilable as exc:
            return str(exc)
        return None

    def __init__(self, system, t_span, q0=None, v0=None, **kw):
        super().__init__(system, t_span, q0, v0, **kw)
        o = self.options
        self._cm = cm = _l.compile_model(system)
        self._cd = cm.data
        self._states = cm.initial_states()
        self._ws = _d.make_workspace(cm)
        notify_if_cold(advance, self.name, "30-70 s, 15-35 s after a jit-dop853 or jit-rk45")
        self.alpha = self.beta = 0.0
        if self.stabilization == "baumgarte":
            self.alpha = float(o.get("alpha", DEFAULT_BAUMGARTE))
            self.beta = float(o.get("beta", DEFAULT_BAUMGARTE))
            if not (self.alpha >= 0 and np.isfinite(self.beta)):
                raise InputError(f"{self.name}: Baumgarte alpha must be ≥ 0 and beta finite, got {self.alpha}, {self.beta}")
        self.projection_tol = float(o.get("projection_tol", self.atol))
        self.max_projection_iter = int(o.get("max_projection_iter", 10))
        if not self.projection_tol > 0:
            raise InputError(f"{self.name}: projection_tol must be > 0, got {self.projection_tol}")
        self.newton_tol = max(10 * np.finfo(float).eps / self.rtol, min(0.03, self.rtol ** 0.5))
        nq, nv, m = system.n_q, system.n_v, cm.m
        n = nq + nv
        N = nv + m
        nb = max(1, cm.n_b)
        nf = 2 * nv + nb
        Mden = system.M(self.t, self.q)
        Mden = Mden.toarray() if sp.issparse(Mden) else np.asarray(Mden, float)
        self._rw = RadauWork(
            Mden=np.ascontiguousarray(Mden), K=np.zeros((nv, nv)), D=np.zeros((nv, nv)), Gd=np.zeros((max(m, 1), nv)),
            KK_r=np.zeros((N, N)), KK_c=np.zeros((N, N), complex), piv_r=np.zeros(N, np.int64),
            piv_c=np.zeros(N, np.int64), band=np.zeros(2, np.int64), ip=self._cached_ordering(system, Mden, N),
            sp_ptr=np.zeros(nv + 1, np.int64), sp_col=np.zeros(nv * nv, np.int64), sp_m=np.zeros(nv * nv),
            sp_k=np.zeros(nv * nv), sp_d=np.zeros(nv * nv), g_ptr=np.zeros(m + 1, np.int64),
            g_col=np.zeros(max(m, 1) * nv, np.int64), g_val=np.zeros(max(m, 1) * nv),
            f=np.zeros(n), y_new=np.zeros(n), y_old=np.zeros(n), Z=np.zeros((3, n)), W=np.zeros((3, n)),
            F=np.zeros((3, n)), dW=np.zeros((3, n)), Zt=np.zeros((3, n)), yt=np.zeros(n), scale=np.zeros(n),
            b_c=np.zeros(N, complex), b=np.zeros(N), err=np.zeros(n), tmp=np.zeros(n), qp=np.zeros(nq), vp=np.zeros(nv), Qa=np.zeros(nv), Qb=np.zeros(nv),
            lam=np.zeros(max(m, 1)), Qpoly=np.zeros((n, 3)), info=np.zeros(10),
            AJ=np.zeros((nb, 3, 3)), PS=np.zeros((4, nb, 4)), RS=np.zeros((4, nb, 3, 3)),
            spatial=np.zeros(nb), AP=np.zeros((nb, 3, 3)), Kp=np.zeros((nv, nv)), Dp=np.zeros((nv, nv)),
            n_jac=np.zeros(1, np.int64),
            X=np.zeros((3, nf)), dZ=np.zeros((3, n)), xs=np.zeros(nf), ys=np.zeros(nf), xs_c=np.zeros(nf, complex),
            ys_c=np.zeros(nf, complex),
        )
        self._cnt = np.zeros(10, np.int64)
        self._info = np.zeros(10)
        self._info[2] = np.nan  # no previous step
        self._info[4:6] = -1.0
        self._y = np.concatenate([self.q, self.v])
        if self.stabilization == "projection":
            it = _d.project(self._cd, self._ws, self.t, self._y[:nq], self._y[nq:], self.projection_tol,
                            self.max_projection_iter, self._cnt)
            if it < 0:
                raise InputError(f"{self.name}: initial state of {system.name!r} cannot be projected onto the constraints")
        st = self._evaluate(self.t, self._y, self._rw.f)
        if st != _p.OK:
            raise InputError(f"{self.name}: right-hand side fails at the initial state of {system.name!r}: "
                             f"{self._status_message(st, (self.t, self._y))}")
        self._h_abs = min(self.h, self.t_bound - self.t) if self.h is not None else self._initial_step()
        self._corr = None
        self._sync()

    # --- set-up ---------------------------------------------------------------------------------
    def _cached_ordering(self, system, Mden, N):
        """:meth:`_ordering`, computed once per compiled model (model set-up, like the packing)."""
        cache = self._cm.setup_cache
        if "radau_ordering" not in cache:
            cache["radau_ordering"] = self._ordering(system, Mden, N)
        return cache["radau_ordering"]

    def _ordering(self, system, Mden, N):
        """Reverse Cuthill–McKee positions of the (n_v + m) unknowns of the iteration matrices.

        Pattern: the mass matrix, ``Φ_q`` and the force Jacobians at the initial state and at a
        randomly perturbed one (so that couplings through elements that are unloaded at ``t0``,
        e.g. an open contact, still shape the order; the band is taken from the actual pattern at
        every Jacobian, :func:`_pack`).
        """
        nv = system.n_v
        cm, cd = self._cm, self._cd
        ws = _d.make_workspace(cm)
        st = cm.initial_states()
        K, D = np.zeros((nv, nv)), np.zeros((nv, nv))
        pat = (np.abs(Mden) > 0).astype(float)
        for g in range(cm.n_grp):  # a mass group's block is full whatever its entries at t0
            vi = cm.fields["grp_v"][g, :cm.fields["grp_w"][g]]
            pat[np.ix_(vi, vi)] = 1.0
        rng = np.random.default_rng(0)
        work = (np.zeros(system.n_q), np.zeros(nv), np.zeros(nv), np.zeros(nv))
        for q, v in ((self.q.copy(), self.v.copy()),
                     (system.retract(self.q, 1e-3 * rng.standard_normal(nv)), rng.standard_normal(nv))):
            if _d.force_jacobian(cd, st, ws, self.t, np.ascontiguousarray(q), np.ascontiguousarray(v), K, D,
                                 *work) == _p.OK:
                pat += (np.abs(K) + np.abs(D) > 0)
        full = np.zeros((N, N))
        full[:nv, :nv] = pat
        if cm.m:
            J = system.Phi_q(self.t, self.q)
            J = (J.toarray() if sp.issparse(J) else np.asarray(J)) != 0
            full[nv:, :nv] = J
            full[:nv, nv:] = J.T
        full += np.eye(N)
        order = np.asarray(reverse_cuthill_mckee(sp.csr_matrix(full), symmetric_mode=True), np.int64)
        ip = np.empty(N, np.int64)
        ip[order] = np.arange(N)
        return ip

    def multipliers(self, t, q, v):
        """The index-1 multipliers at ``(t, q, v)`` on the compiled path
        (:func:`core.integrators.compiled_rk.compiled_multipliers`)."""
        return compiled_multipliers(self, t, q, v)

    def _evaluate(self, t, y, out):
        """``out = F(t, y)`` with the compiled right-hand side; kernel status code."""
        return int(_eval_rhs(self._cd, self._states, self._ws, float(t), y, self.alpha, self.beta, out, self._rw.lam,
                             self._cnt))

    def _status_message(self, code, state=None) -> str:
        """The failure of a kernel status code in the words of the element that reported it
        (:func:`core.compiled.layout.status_message`)."""
        return _l.status_message(self._cm, self.system, self._ws.err, self._states, code, state)

    def _initial_step(self):
        """Initial step of Hairer, Nørsett & Wanner I, Sec. II.4 for order 3 (scipy's Radau)."""
        t0, y0, f0 = self.t, self._y, self._rw.f
        interval = abs(self.t_bound - t0)
        scale = self.atol + np.abs(y0) * self.rtol
        d0 = float(np.sqrt(np.mean((y0 / scale) ** 2)))
        d1 = float(np.sqrt(np.mean((f0 / scale) ** 2)))
        h0 = 1e-6 if d0 < 1e-5 or d1 < 1e-5 else 0.01 * d0 / d1
        h0 = min(h0, interval)
        f1 = np.zeros_like(y0)
        if self._evaluate(t0 + h0, y0 + h0 * f0, f1) != _p.OK:
            f1[:] = np.nan
        d2 = float(np.sqrt(np.mean(((f1 - f0) / scale) ** 2))) / h0
        if d1 <= 1e-15 and d2 <= 1e-15:
            h1 = max(1e-6, h0 * 1e-3)
        else:
            h1 = (0.01 / max(d1, d2)) ** (1.0 / 4)
        h = min(100.0 * h0, h1, interval, self.max_step)
        if not np.isfinite(h) or h <= 0:
            raise InputError(f"{self.name}: no usable initial step at t = {t0:g} s for {self.system.name!r} "
                             "(non-finite right-hand side near the initial state)")
        return h

    def _sync(self):
        c, k = self.counters, self._cnt
        c["n_rejected"] = int(k[C_REJ])
        c["n_rhs"] = int(k[C_RHS])
        c["n_factor"] = int(k[C_FACT])
        c["n_jac"] = int(k[C_JAC])
        c["n_newton"] = int(k[C_NEWTON])
        c["n_newton_failures"] = int(k[C_NEWTON_FAIL])
        nq = self.system.n_q
        self.q, self.v = self._y[:nq].copy(), self._y[nq:].copy()
        self.a = self._rw.f[nq:].copy()

    # --- stepping -------------------------------------------------------------------------------
    def advance(self, t_target: float, max_steps: int = 2**62) -> str | None:
        """Take steps until ``t ≥ min(t_target, t_end)`` (the last may pass ``t_target``; the dense
        output covers it); return the failure message or None."""
        if self.status != STATUS_RUNNING:
            raise RuntimeError(f"{self.name}: advance() called on a {self.status} integrator")
        t_stop = min(float(t_target), self.t_bound)
        if t_stop <= self.t:
            return None
        steps0 = int(self._cnt[C_STEPS])
        info = self._info
        t_before = self.t
        code = advance(self._cd, self._states, self._ws, self._rw, self.t, self._y, t_stop, self.t_bound,
                       self._h_abs, max_steps, self.rtol, self.atol, self.max_step, self.newton_tol, self.alpha,
                       self.beta, self.stabilization == "projection", self.projection_tol, self.max_projection_iter,
                       self._cm.stateful, self._cnt, info)
        taken = int(self._cnt[C_STEPS]) - steps0
        self.counters["n_steps"] += taken
        nq = self.system.n_q
        if taken:
            rw = self._rw
            self.t_old = float(info[2])
            self.q_old, self.v_old = rw.y_old[:nq].copy(), rw.y_old[nq:].copy()
            # the collocation polynomial of the last step, corrected by the projection at its end
            h = float(info[0]) - self.t_old
            x = np.array([1.0, 1.0, 1.0])
            end = rw.y_old + rw.Qpoly @ x
            self._corr = (self.t_old, float(info[0]), rw.y_old.copy(), rw.Qpoly.copy(), self._y - end, h)
        self.t = float(info[0]) if code in (EXIT_REACHED, EXIT_MAX_STEPS) else float(info[0])
        self._h_abs = float(info[1]) if info[1] > 0 else self._h_abs
        self._sync()
        if code in (EXIT_REACHED, EXIT_MAX_STEPS):
            if self.t >= self.t_bound - 1e-12 * max(1.0, abs(self.t_bound)):
                self._finish()
            return None
        if code == EXIT_TOO_SMALL:
            why = (f"step size fell below 10 ulp(t) at t = {info[3]:.6g} s (the Newton iteration does not converge "
                   "or the stages are not finite at any step size)")
        elif code == EXIT_SINGULAR_MATRIX:
            why = (f"the Radau iteration matrix is singular at t = {info[3]:.6g} s (dependent constraints or a "
                   "singular configuration)")
        elif code == _p.PROJECTION:
            why = (f"coordinate projection did not reach ‖Φ‖ ≤ {self.projection_tol:g} in "
                   f"{self.max_projection_iter} iterations at t = {info[3]:.6g} s")
        else:
            # the Newton iterate that failed is not kept: the numpy element is asked at the last
            # accepted state, then along its tangent over the attempted step (where the failing
            # condition, e.g. a vanishing rolling speed, lies)
            h = max(float(self._h_abs), 1e-12)
            qd = self.system.qdot(self.q, self.v)
            ts = [self.t + k * h / 4.0 for k in range(5)]
            ys = [np.concatenate([self.system.normalize(self.q + (t_k - self.t) * qd), self.v + (t_k - self.t) * self.a])
                  for t_k in ts]
            why = f"{self._status_message(code, (ts, ys))} (in the step to t = {info[3]:.6g} s)"
        self.status = STATUS_FAILED
        self.t = max(t_before, self.t)
        self.message = f"{self.name} failed at t = {self.t:.6g} s: {why}"
        return self.message

    def step(self) -> str | None:
        """One accepted step (the :class:`Integrator` contract)."""
        return self.advance(self.t_bound, max_steps=1)

    def _step_impl(self):  # pragma: no cover - step() is overridden
        raise NotImplementedError

    def _dense_output_impl(self):
        t0, t1, y0, Qp, corr, h = self._corr
        nq = self.system.n_q
        sys_ = self.system

        def f(t):
            x = 0.0 if h <= 0 else (t - t0) / h
            y = y0 + Qp @ np.array([x, x * x, x ** 3]) + x * corr
            return sys_.normalize(y[:nq].copy()), y[nq:].copy()

        return f


@_jit
def _eval_rhs(cd, states, ws, t, y, alpha, beta, out, lam, counters):
    lay = cd.lay
    return _rhs(cd, states, ws, lay, lay[4], cd.act.shape[0] > 0, t, y, alpha, beta, out, lam, counters)


def _make_class(stab: str) -> type[CompiledRadau]:
    name = "jit-radau" + ("" if stab == "none" else f"-{stab}")
    label = {"none": "unstabilised", "baumgarte": "Baumgarte-stabilised", "projection": "with coordinate projection"}[stab]
    cls_name = "CompiledRadau" + {"none": "", "baumgarte": "Baumgarte", "projection": "Projection"}[stab]
    doc = (f"Index-1 formulation ({label}) on a compiled Radau IIA (order 5) loop for stiff problems.\n\n"
           f"Registry name ``{name!r}``.  See :mod:`core.integrators.compiled_radau` and :class:`CompiledRadau`.\n")
    cls = type(cls_name, (CompiledRadau,), dict(
        name=name, summary=f"index-1 {label}, compiled Radau IIA order 5 (stiff; numba)", stabilization=stab,
        __doc__=doc, __module__=__name__))
    return register(cls)


RADAU_METHODS: dict[str, type[CompiledRadau]] = {}
for _stab in ("none", "baumgarte", "projection"):
    _cls = _make_class(_stab)
    RADAU_METHODS[_cls.name] = _cls
    globals()[_cls.__name__] = _cls
del _stab, _cls
