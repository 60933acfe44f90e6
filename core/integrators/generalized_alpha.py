r"""Index-3 generalized-α integrator (Lie-group form) and its HHT-α special case.

Equations
---------
For the constrained system of :mod:`core.system` the scheme of Arnold & Brüls (2007, Eqs. 7–10)
in the Lie-group form of Brüls & Cardona (2010, Eqs. 20–24) advances ``(q, v, v̇, a, λ)``:

.. math::

    q_{n+1} &= q_n \oplus h\,\Delta q_n, \qquad
    \Delta q_n = v_n + h(\tfrac12 - \beta)\, a_n + h\beta\, a_{n+1}              \\
    v_{n+1} &= v_n + h(1-\gamma)\, a_n + h\gamma\, a_{n+1}                        \\
    (1-\alpha_m)\, a_{n+1} + \alpha_m a_n &= (1-\alpha_f)\, \dot v_{n+1} + \alpha_f \dot v_n \\
    M \dot v_{n+1} + \Phi_q^T \lambda_{n+1} - Q(t_{n+1}, q_{n+1}, v_{n+1}) &= 0      \\
    \tfrac{1}{\beta h^2}\, \Phi(t_{n+1}, q_{n+1}) &= 0

``a`` is the algorithmic ("α-") acceleration; ``⊕`` is ``system.retract`` (exact for planar
bodies, the exponential map on the Euler parameters of spatial bodies).  Parameters from the
spectral radius at infinity ``ρ∞ ∈ [0, 1]`` (Chung & Hulbert 1993, Eqs. 25, 17, 20; Arnold &
Brüls 2007, Eq. 9):

.. math::

    \alpha_m = \frac{2\rho_\infty - 1}{\rho_\infty + 1},\quad
    \alpha_f = \frac{\rho_\infty}{\rho_\infty + 1},\quad
    \gamma = \tfrac12 + \alpha_f - \alpha_m,\quad
    \beta = \tfrac14 (\gamma + \tfrac12)^2 .

HHT-α (Hilber, Hughes & Taylor 1977) is the special case ``α_m = 0``,
``α_f = (1-ρ∞)/(1+ρ∞)`` in this sign convention.

Newton iteration on the position increment ``δx`` (v-space) and ``δλ`` with the iteration
matrix (Arnold & Brüls 2007, Eq. 14; the tangent operator ``T ≈ I``), scaled by ``βh²`` for
conditioning (the unknown of the second block row is ``βh² δλ``):

.. math::

    S = \begin{bmatrix} M \tfrac{1-\alpha_m}{1-\alpha_f} + h\gamma\, C_t + \beta h^2 K_t & \Phi_q^T \\
                         \Phi_q & 0 \end{bmatrix},\qquad C_t = -Q_v,\ K_t = -Q_q + (\Phi_q^T\lambda)_q,

``δv̇ = β' δx``, ``δv = γ' δx`` with ``β' = (1-α_m)/(βh²(1-α_f))``, ``γ' = γ/(βh)``.
The sparse ``S`` is factorised with SuperLU and reused across iterations and steps while the
modified Newton iteration contracts quickly (rate θ ≤ ``theta_refresh``); it is refactored at the
current iterate when convergence is slow.  Convergence is declared when the estimated remaining
error ``θ/(1-θ)·‖δ‖`` (Hairer & Wanner II, §IV.8, Eq. 8.10) is below 1 in the weighted RMS norm
of the position increment (weights ``atol + rtol|q|``) and of the velocity increment
(``atol + rtol|v|``).

Starting value: ``a_0 = v̇(t_0 + Δ_α h)`` with ``Δ_α = α_m − α_f`` (Arnold & Brüls 2007,
Sec. 4, Eq. 32), evaluated from the index-1 accelerations at a second-order Taylor state;
this removes the O(h) transient of ``v̇`` and ``λ``.

Failure policy: with ``adaptive=False`` (fixed step) a step whose Newton iteration does not
converge is retried once with a fresh iteration matrix and the constant predictor (counter
``n_newton_retries``); if that fails too the run ends with status ``"failed"`` and a message
giving the time and the residual norm.  Within a step the matrix is refactored at the current
iterate when the contraction rate θ exceeds 0.3 or when ``θ^(k_max − k)/(1 − θ)·‖δ‖`` predicts
no convergence in the iterations left (Hairer & Wanner II, Sec. IV.8).  The fixed-step run's
error is estimated by the base class (:mod:`core.integrators.base`).  With ``adaptive=True`` the step is error controlled with the Newmark estimate
``e = (β − 1/6) h² (a_{n+1} − a_n)`` of the position local error (Zienkiewicz & Xie 1991,
Eq. 9), halved after a Newton failure, and the run fails if ``h < h_min``.

Velocity constraints ``Φ_q v = ν`` are not enforced by the index-3 scheme and drift O(h²).
That drift is not harmless: on a rod pendulum released horizontally (1 m, 1 kg) the violation
grew from 1.5e-2 to 0.25 m/s within 5 s at h = 0.05 s, ρ∞ = 0.9, the energy with it, until the
discrete equations had no nearby solution ("Newton did not converge"; an independent dense
implementation with full Newton, ``scipy.optimize.fsolve``, reproduced the same trajectory and
failed the same way), and at ρ∞ = 1 (no numerical damping of the algebraic components) the
accelerations grew exponentially even at h = 0.005 s.  Hence by default (``velocity_projection=True``) ``v_{n+1}`` is
projected onto the velocity constraints after each step in the metric of ``M`` (one extra KKT
factorisation per step): ``v ← v − M^{-1}Φ_q^T(Φ_q M^{-1}Φ_q^T)^{-1}(Φ_q v − ν)``; with it the
point and rod pendulums run for 10 s at every h from 1e-3 to 0.1 s and every ρ∞ tested
(generalized-α 0, 0.3, 0.6, 0.9, 1; HHT 0.5, 0.7, 0.9, 1).  ``velocity_projection=False`` gives the
plain index-3 scheme of the papers.

References
----------
J. Chung, G. M. Hulbert, "A time integration algorithm for structural dynamics with improved
numerical dissipation: the generalized-α method", J. Appl. Mech. 60 (1993) 371–375.
M. Arnold, O. Brüls, "Convergence of the generalized-α scheme for constrained mechanical
systems", Multibody Syst. Dyn. 18 (2007) 185–202.
O. Brüls, A. Cardona, "On the use of Lie group time integrators in multibody dynamics",
J. Comput. Nonlinear Dynam. 5 (2010) 031002.
O. Brüls, A. Cardona, M. Arnold, "Lie group generalized-α time integration of constrained
flexible multibody systems", Mech. Mach. Theory 48 (2012) 121–137.
H. M. Hilber, T. J. R. Hughes, R. L. Taylor, "Improved numerical dissipation for time
integration algorithms in structural dynamics", Earthq. Eng. Struct. Dyn. 5 (1977) 283–292.
O. C. Zienkiewicz, Y. M. Xie, "A simple error estimator and adaptive time stepping procedure
for dynamic analysis", Earthq. Eng. Struct. Dyn. 20 (1991) 871–887.
E. Hairer, G. Wanner, *Solving Ordinary Differential Equations II*, 2nd ed., Springer, 1996.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ..dynamics import accelerations, constraint_terms, project_velocities
from ..errors import InputError
from .base import IntegrationFailure, Integrator, register


def _sparse(A) -> sp.csr_matrix:
    return A.tocsr() if sp.issparse(A) else sp.csr_matrix(np.asarray(A, float))


def rmatvec(J, y: np.ndarray) -> np.ndarray:
    """``Jᵀ y`` without forming the transpose (CSR arrays directly; dense fallback)."""
    if sp.isspmatrix_csr(J) or isinstance(J, sp.csr_array):
        rows = np.repeat(np.arange(J.shape[0]), np.diff(J.indptr))
        return np.bincount(J.indices, weights=J.data * y[rows], minlength=J.shape[1])
    return np.asarray(J.T @ y).ravel()


def kkt_csc(A, J) -> sp.csc_matrix:
    """Sparse ``[[A, Jᵀ], [J, 0]]`` in CSC from COO triplets (faster than ``sp.bmat``)."""
    A = A.tocoo() if sp.issparse(A) else sp.coo_matrix(A)
    n = A.shape[0]
    if J is None or J.shape[0] == 0:
        return A.tocsc()
    J = J.tocoo() if sp.issparse(J) else sp.coo_matrix(J)
    m = J.shape[0]
    r = np.concatenate([A.row, J.col, J.row + n])
    c = np.concatenate([A.col, J.row + n, J.col])
    d = np.concatenate([A.data, J.data, J.data])
    return sp.csc_matrix((d, (r, c)), shape=(n + m, n + m))


class ConstraintCurvature:
    r"""Sparse finite-difference derivatives of ``Φ_q(q)ᵀλ`` and ``Φ_q(q) w`` along v-space increments.

    ``(Φ_qᵀλ)_q`` is the geometric stiffness of the constraint forces and ``(Φ_q w)_q`` the
    curvature term of the velocity constraints; both are needed for a fast-converging Newton
    iteration when the multipliers or velocities are large (Arnold & Brüls 2007, Eq. 14 keeps the
    former in ``K_t``).  The columns are grouped by a greedy distance-2 colouring of the pattern
    of ``Φ_q`` (Curtis, Powell & Reid 1974): one evaluation of ``Φ_q`` per colour (9 for a planar
    chain, whatever its length) instead of one per coordinate.
    """

    def __init__(self, system, t, q):
        J_raw = system.Phi_q(t, q)
        J = _sparse(J_raw)
        self.system = system
        if sp.issparse(J_raw):
            S = J.copy()  # structural pattern (the Model keeps explicit zeros of its fixed pattern)
            S.data = np.ones_like(S.data)
        else:
            # a dense Jacobian has no structural zeros: an entry that is zero at this q (sin 0 in a
            # loop closure) need not stay zero, so every entry is in the pattern
            S = sp.csr_matrix(np.ones(np.shape(J_raw)))
        G = (S.T @ S).tocsr()  # columns sharing a row of J, and (through JᵀJ) distance-2 partners
        G2 = (G @ G).tocsr()
        n = J.shape[1]
        color = -np.ones(n, np.int64)
        for k in range(n):  # build-time only (n_v columns)
            nb = G2.indices[G2.indptr[k]:G2.indptr[k + 1]]
            used = set(color[nb][color[nb] >= 0].tolist())
            c = 0
            while c in used:
                c += 1
            color[k] = c
        self.color = color
        self.n_colors = int(color.max()) + 1 if n else 0
        P = G.tocoo()  # the derivative pattern of Φ_qᵀλ (structural, includes diagonal blocks)
        self.P_rows, self.P_cols = P.row, P.col
        Jc = S.tocoo()
        self.J_rows, self.J_cols = Jc.row, Jc.col
        self.groups = [np.flatnonzero(color == c) for c in range(self.n_colors)]
        self.shape_P = (n, n)
        self.shape_J = J.shape

    def __call__(self, t, q, J, lam, w, eps=1e-7):
        """``((Φ_qᵀλ)_q, (Φ_q w)_q)`` as CSR matrices at ``q`` (``J = Φ_q(t, q)``)."""
        sys_ = self.system
        n = self.shape_P[0]
        base_l = rmatvec(J, lam)
        base_w = J @ w
        DL = np.empty((self.n_colors, n))
        DW = np.empty((self.n_colors, self.shape_J[0]))
        for c, g in enumerate(self.groups):
            dv = np.zeros(n)
            dv[g] = eps
            Jp = _sparse(sys_.Phi_q(t, sys_.retract(q, dv)))
            DL[c] = (rmatvec(Jp, lam) - base_l) / eps
            DW[c] = (Jp @ w - base_w) / eps
        GL = sp.csr_matrix((DL[self.color[self.P_cols], self.P_rows], (self.P_rows, self.P_cols)), shape=self.shape_P)
        GW = sp.csr_matrix((DW[self.color[self.J_cols], self.J_rows], (self.J_rows, self.J_cols)), shape=self.shape_J)
        return GL, GW


def q_magnitude(system, q: np.ndarray) -> np.ndarray:
    """Magnitudes of the position coordinates in v-space (for error weights), shape (n_v,).

    Planar / generalized coordinates: ``|q|``.  Spatial Cartesian models: ``|r|`` for the
    translations and 1 rad for the rotation increments.  Other systems with ``n_q ≠ n_v``: 1.
    """
    if system.n_q == system.n_v:
        return np.abs(q)
    space = getattr(system, "space", None)
    nb = getattr(system, "n_bodies", None)
    if space is not None and nb is not None and space.dim == 3:
        out = np.ones(system.n_v)
        ob = out[: nb * 6].reshape(nb, 6)
        ob[:, :3] = np.abs(q[: nb * 7].reshape(nb, 7)[:, :3])
        out[nb * 6:] = np.abs(q[nb * 7:])
        return out
    return np.ones(system.n_v)


def q_jacobians(system, t, q, v):
    """``(Q_q, Q_v)`` as sparse matrices (the system's one-pass evaluator when it has one)."""
    Kq, Kv = system.Q_jacobians(t, q, v)
    return _sparse(Kq), _sparse(Kv)


def alpha_parameters(rho_inf: float, variant: str = "generalized-alpha") -> tuple[float, float, float, float]:
    """``(α_m, α_f, β, γ)`` from the spectral radius at infinity (see module docstring)."""
    rho = float(rho_inf)
    if not 0.0 <= rho <= 1.0:
        raise InputError(f"{variant}: rho_inf must lie in [0, 1], got {rho_inf}")
    if variant == "hht" and rho < 0.5:
        # HHT's α = (1 − ρ∞)/(1 + ρ∞) ∈ [0, 1/3] (Hilber et al. 1977: unconditional stability and
        # second order for α ≤ 1/3); ρ∞ < 1/2 is outside and ρ∞ = 0 divides by 1 − α_f = 0
        raise InputError(f"hht: rho_inf must lie in [0.5, 1] (HHT alpha in [0, 1/3]), got {rho_inf}; "
                         "use generalized-alpha for stronger damping")
    if variant == "hht":
        am, af = 0.0, (1.0 - rho) / (1.0 + rho)
    else:
        am, af = (2.0 * rho - 1.0) / (rho + 1.0), rho / (rho + 1.0)
    gam = 0.5 + af - am
    beta = 0.25 * (gam + 0.5) ** 2
    return am, af, beta, gam


@register
class GeneralizedAlpha(Integrator):
    """Index-3 Lie-group generalized-α (Arnold & Brüls 2007; Brüls & Cardona 2010).

    Fixed step ``h`` (required), or error-controlled with ``adaptive=True`` (``h`` is then the
    initial step).  See the module docstring for equations, Newton strategy and failure policy.

    Options
    -------
    rho_inf : float, default 0.9
        Spectral radius at infinity (1: no numerical damping; 0: asymptotic annihilation).
    adaptive : bool, default False
        Error control with step halving after Newton failure; otherwise Newton failure fails the run.
    h_min : float, optional
        Smallest step of the adaptive mode [s] (default ``1e-6 h``).
    velocity_projection : bool, default True
        Project ``v`` onto ``Φ_q v = ν`` after every step (M-metric); False gives the plain
        index-3 scheme, whose velocity drift can grow (module docstring).
    max_newton : int, default 12
        Newton iterations per step attempt (including refactorisations).
    theta_refresh : float, default 0.1
        Contraction rate above which the iteration matrix is rebuilt for the next step (also
        rebuilt after a step needing more than 3 iterations, and within a step when the rate
        exceeds 0.3).
    consistent_start : bool, default True
        Use ``a_0 = v̇(t_0 + (α_m − α_f) h)`` (Arnold & Brüls 2007, Sec. 4); else ``a_0 = v̇_0``.
    geometric_stiffness : bool, default True
        Include the constraint-force stiffness ``(Φ_qᵀλ)_q`` in ``K_t`` (sparse coloured finite
        differences, :class:`ConstraintCurvature`); restores fast Newton convergence when the
        multipliers are large (fast chains).  False gives the plain ``K_t = −Q_q`` of the brief.
    """

    name = "generalized-alpha"
    summary = "index-3 Lie-group generalized-alpha (Arnold & Brüls 2007), sparse modified Newton"
    fixed_step = True
    provides_multipliers = True
    variant = "generalized-alpha"

    @classmethod
    def accepted_options(cls):
        return ("rho_inf", "adaptive", "h_min", "velocity_projection", "max_newton", "theta_refresh",
                "consistent_start", "geometric_stiffness", "newton_tol")

    def __init__(self, system, t_span, q0=None, v0=None, **kw):
        super().__init__(system, t_span, q0, v0, **kw)
        o = self.options
        self.rho_inf = float(o.get("rho_inf", 0.9))
        self.alpha_m, self.alpha_f, self.beta, self.gamma = alpha_parameters(self.rho_inf, self.variant)
        self.adaptive = bool(o.get("adaptive", False))
        if self.adaptive:
            self.error_estimate = np.nan  # error-controlled: no fixed-step estimate (base class)
        # Newton tolerance (relative; absolute = 1e-2 × relative × unit scale). With a fixed step the
        # discretisation error is set by h, so the nonlinear solve must be well below it: tying it to
        # the default rtol = 1e-6 made the scheme look first-order; 1e-8 restores order 2 (1e-9 and
        # below can stall on round-off of the scaled increments at h = 1e-4).
        # Adaptive runs use rtol/atol as given.
        default_ntol = self.rtol if self.adaptive else min(self.rtol, 1e-8)
        self.newton_rtol = float(o.get("newton_tol", default_ntol))
        self.newton_atol = self.atol if self.adaptive and "newton_tol" not in o else min(self.atol, 1e-2 * self.newton_rtol)
        self.h_min = float(o.get("h_min", 1e-6 * self.h))
        self.velocity_projection = bool(o.get("velocity_projection", True))
        self.max_newton = int(o.get("max_newton", 12))
        if self.max_newton < 1:
            raise InputError(f"{self.name}: max_newton must be ≥ 1, got {self.max_newton}")
        self.theta_refresh = float(o.get("theta_refresh", 0.1))
        sys_ = system
        self.nv, self.nc = sys_.n_v, sys_.n_c
        self._M_const = _sparse(sys_.M(self.t, self.q)) if sys_.mass_is_constant else None
        # consistent accelerations and multipliers at t0
        vd0, lam0 = accelerations(sys_, self.t, self.q, self.v)
        self.counters["n_rhs"] += 1
        self.vd = vd0
        self.lam = lam0
        self.a = vd0.copy()  # v̇ for the base-class dense output
        d_alpha = self.alpha_m - self.alpha_f
        if o.get("consistent_start", True) and d_alpha != 0.0:
            s = d_alpha * self.h
            qs = sys_.retract(self.q, s * self.v + 0.5 * s * s * vd0)
            vs = self.v + s * vd0
            acc_s, _ = accelerations(sys_, self.t + s, qs, vs)
            self.counters["n_rhs"] += 1
            self.acc = acc_s
        else:
            self.acc = vd0.copy()
        self._lu = None
        self._lu_h = None
        self.geometric_stiffness = bool(o.get("geometric_stiffness", True))
        self._curv = None
        self._eta = 1.0  # Hairer's η = θ/(1−θ) carried across steps
        self.last_residual = np.nan
        self._vd_prev = self._lam_prev = self._h_prev = None

    # ------------------------------------------------------------------------------------------
    def _M(self, t, q):
        return self._M_const if self._M_const is not None else _sparse(self.system.M(t, q))

    def _factor(self, t, q, v, J, h, lam):
        am, af, beta, gam = self.alpha_m, self.alpha_f, self.beta, self.gamma
        Kq, Kv = q_jacobians(self.system, t, q, v)
        if self.geometric_stiffness and self.nc:
            if self._curv is None:
                self._curv = ConstraintCurvature(self.system, t, q)
            GL, _ = self._curv(t, q, J, lam, v)
            self.counters["n_rhs"] += self._curv.n_colors
            Kq = Kq - GL
        A = self._M(t, q) * ((1.0 - am) / (1.0 - af))
        if Kv.nnz:
            A = A - (h * gam) * Kv
        if Kq.nnz:
            A = A - (beta * h * h) * Kq
        S = kkt_csc(A, J)
        try:
            self._lu = spla.splu(S)
        except RuntimeError as exc:
            raise IntegrationFailure(f"iteration matrix singular at t = {t:.6g} s ({exc})") from None
        self._lu_h = h
        self._eta = 1.0
        self.counters["n_jac"] += 1
        self.counters["n_factor"] += 1

    def _attempt(self, h):
        """One step of size h; returns (ok, info) and sets the trial state on success."""
        sys_ = self.system
        am, af, beta, gam = self.alpha_m, self.alpha_f, self.beta, self.gamma
        nv = self.nv
        t1 = self.t + h
        bh2 = beta * h * h
        ca = (1.0 - af) / (1.0 - am)
        c0 = (af * self.vd - am * self.acc) / (1.0 - am)
        base_x = h * self.v + h * h * (0.5 - beta) * self.acc
        base_v = self.v + h * (1.0 - gam) * self.acc
        # predictor: linear extrapolation of v̇ and λ over the last step (constant after a restart)
        if self._vd_prev is not None and self._h_prev == h:
            vd = 2.0 * self.vd - self._vd_prev
            lam = 2.0 * self.lam - self._lam_prev
        else:
            vd = self.vd.copy()
            lam = self.lam.copy()
        a1 = ca * vd + c0
        x = base_x + bh2 * a1
        v1 = base_v + h * gam * a1
        # weights floored at the rounding level of each block: the constraint rows mix fast and
        # slow members (Andrews: crank at 400 rad/s, others at 1e-3 rad/s), so every increment
        # carries a noise of ~ε‖block‖∞ amplified by the conditioning; asking for less never
        # converges (contraction ≈ 1 at any h). Same remedy as radau-ggl's _newton_scale.
        qmag = q_magnitude(sys_, self.q)
        noise = 1e3 * np.finfo(float).eps
        sq = np.maximum(self.newton_atol + self.newton_rtol * qmag, noise * np.max(qmag, initial=0.0))
        # velocities follow from position increments through v = … + γ/(βh) x, so their noise also
        # includes the position round-off amplified by γ/(βh): the O(ε/h) velocity round-off of
        # index-3 schemes at small steps
        gp_ = self.gamma / (self.beta * h)
        sv = np.maximum(self.newton_atol + self.newton_rtol * np.abs(self.v),
                        noise * max(np.max(np.abs(self.v), initial=0.0), 0.1 * gp_ * np.max(qmag, initial=0.0)))
        wq, wv = 1.0 / sq, 1.0 / sv
        gp = gam / (beta * h)  # δv = γ' δx
        bp = 1.0 / (ca * bh2)  # δv̇ = β' δx
        if self._lu_h != h:
            self._lu = None
        norm_old = None
        theta = None
        k_total = 0
        res_norm = np.nan
        while k_total < self.max_newton:
            q1 = sys_.retract(self.q, x)
            phi, J, nu, _ = constraint_terms(sys_, t1, q1, v1)
            Qv = sys_.Q(t1, q1, v1)
            self.counters["n_rhs"] += 1
            J = _sparse(J)
            Mc = self._M_const if self._M_const is not None else _sparse(sys_.M(t1, q1))
            r1 = Mc @ vd + rmatvec(J, lam) - Qv
            res_norm = float(np.sqrt(np.linalg.norm(r1) ** 2 + (np.linalg.norm(phi) / bh2) ** 2))
            if not np.isfinite(res_norm):
                return False, f"Newton residual not finite at t = {t1:.6g} s"
            if self._lu is None:
                self._factor(t1, q1, v1, J, h, lam)
                norm_old = None
            rhs = np.concatenate([-bh2 * r1, -np.asarray(phi)])
            d = self._lu.solve(rhs)
            self.counters["n_newton"] += 1
            k_total += 1
            dx = d[:nv]
            x += dx
            vd += bp * dx
            a1 += dx / bh2
            v1 += gp * dx
            dlam = d[nv:] / bh2
            lam += dlam
            eq, ev = dx * wq, dx * wv
            dnorm = np.sqrt(max(eq @ eq, gp * gp * (ev @ ev)) / nv) if nv else 0.0
            # the multipliers must converge too: with a reused iteration matrix the position
            # increments can be tiny while λ is still far off (e.g. massless rotations, where λ
            # alone balances the equations). The force-equilibrium residual r1 of this iterate
            # measures that; its round-off is ~eps·(force level) whatever h is, whereas δλ = d/(βh²)
            # amplifies round-off at small h.
            f_scale = max(float(np.max(np.abs(Qv))) if nv else 0.0, float(np.max(np.abs(Mc @ vd))) if nv else 0.0,
                          float(np.max(np.abs(r1 - Mc @ vd + Qv))) if nv else 0.0, 1e-300)
            # floor: Φ = 0 holds only to round-off ε|q|, which the 1/(βh²) scaling turns into a force
            # noise ~ ε |M| |q| / (βh²) -- the known O(ε/h²) multiplier round-off of index-3 schemes
            m_scale = float(np.max(np.abs(Mc.diagonal()))) if nv else 0.0
            q_scale = max(1.0, float(np.max(np.abs(self.q)))) if len(self.q) else 1.0
            floor = 100.0 * np.finfo(float).eps * m_scale * q_scale / bh2
            force_ok = float(np.max(np.abs(r1))) <= max(max(self.newton_rtol, 1e-12) * f_scale, floor) if nv else True
            if not np.isfinite(dnorm):
                return False, f"Newton iteration diverged (non-finite increment) at t = {t1:.6g} s"
            if norm_old is None:
                # first correction with this matrix: accept only if already within tolerance
                conv = dnorm <= 1.0 and self._eta * dnorm <= 0.1
            else:
                theta = dnorm / norm_old if norm_old > 0 else 0.0
                conv = False
                if theta < 1.0:
                    self._eta = theta / (1.0 - theta)
                    conv = self._eta * dnorm <= 1.0
            if (conv and force_ok) or dnorm == 0.0:
                q1 = sys_.retract(self.q, x)
                self._trial = (t1, q1, v1, vd, a1, lam)
                # keep the matrix for the next step while convergence is fast
                if k_total > 3 or (theta is not None and theta > self.theta_refresh):
                    self._lu = None
                self.last_residual = res_norm
                return True, k_total
            if theta is not None and (theta > 0.3 or theta ** (self.max_newton - k_total) / (1.0 - theta) * dnorm > 1.0):
                # slow contraction, or too slow to converge in the iterations left (Hairer & Wanner
                # II, Sec. IV.8, Eq. 8.13): refactor at the current iterate
                self._lu = None
            norm_old = dnorm
        return False, (f"Newton iteration did not converge at t = {t1:.6g} s "
                       f"(h = {h:.3g} s, residual norm {res_norm:.3e}, last contraction "
                       f"{theta if theta is not None else float('nan'):.3g} after {k_total} iterations)")

    def _error_norm(self, h, a1):
        e = (self.beta - 1.0 / 6.0) * h * h * (a1 - self.acc)
        w = 1.0 / (self.atol + self.rtol * q_magnitude(self.system, self.q))
        return float(np.sqrt(np.mean((e * w) ** 2))) if self.nv else 0.0

    def _project_velocity(self, t, q, v):
        self.counters["n_factor"] += 1
        return project_velocities(self.system, t, q, v, "mass")

    def _step_impl(self):
        h = self.next_step_size() if not self.adaptive else min(self.h, self.max_step, self.t_bound - self.t)
        retried = False
        while True:
            ok, info = self._attempt(h)
            if ok:
                if self.adaptive:
                    err = self._error_norm(h, self._trial[4])
                    if err > 1.0:
                        self.counters["n_rejected"] += 1
                        h *= max(0.2, 0.9 * err ** (-1.0 / 3.0))
                        if h < self.h_min:
                            return False, f"step size {h:.3g} s below h_min = {self.h_min:.3g} s (error estimate {err:.3g})"
                        continue
                    fac = min(2.0, max(0.2, 0.9 * err ** (-1.0 / 3.0))) if err > 0 else 2.0
                    if not 1.0 <= fac <= 1.2:
                        self.h = min(h * fac, self.max_step)
                break
            if not self.adaptive:
                if not retried:
                    # once per step: a fresh iteration matrix and the constant predictor (a stale
                    # matrix or an extrapolated λ across a fast change can stall the iteration)
                    retried = True
                    self._lu = None
                    self._vd_prev = None
                    self.counters["n_newton_retries"] = self.counters.get("n_newton_retries", 0) + 1
                    continue
                return False, info
            self.counters["n_rejected"] += 1
            h *= 0.5
            self._lu = None
            if h < self.h_min:
                return False, f"step size {h:.3g} s below h_min = {self.h_min:.3g} s after Newton failure: {info}"
        t1, q1, v1, vd, a1, lam = self._trial
        if self.velocity_projection and self.nc:
            v1 = self._project_velocity(t1, q1, v1)
        self._vd_prev, self._lam_prev, self._h_prev = self.vd, self.lam, h
        self.t, self.q, self.v = t1, q1, v1
        self.vd, self.acc, self.lam = vd, a1, lam
        self.a = vd
        return True, None


@register
class HHTAlpha(GeneralizedAlpha):
    """HHT-α as the special case ``α_m = 0`` of :class:`GeneralizedAlpha` (Hilber et al. 1977)."""

    name = "hht"
    summary = "index-3 HHT-alpha (generalized-alpha with alpha_m = 0)"
    variant = "hht"
