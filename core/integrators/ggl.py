r"""Stabilised index-2 (GGL) formulation integrated with the 3-stage Radau IIA method (order 5).

Equations
---------
Gear–Gupta–Leimkuhler (1985) stabilisation of the equations of :mod:`core.system`, written in
v-space increments ``X`` of the positions relative to the step start, ``q = q_n ⊕ X``
(RKMK form on the Lie group of the Euler parameters; for planar bodies ``⊕`` is ``+``):

.. math::

    \dot X &= \operatorname{dexp}^{-1}_{X}\big(v + \Phi_q(q)^T \mu\big)   \\
    M \dot v &= Q(t, q, v) - \Phi_q(q)^T \lambda                              \\
    0 &= \Phi(t, q)                                                           \\
    0 &= \Phi_q(q)\, v - \nu(t, q)

(``dexp⁻¹_X ω = ω + ½ X×ω + c(|X|) X×(X×ω)``, ``c(θ) = 1/θ² − (1+cos θ)/(2θ sin θ)``, on the
rotation blocks of spatial bodies, since ``⊕`` right-multiplies ``exp(X)``; identity otherwise).
This is a Hessenberg index-2 DAE in the differential variables ``y = (X, v)`` and the algebraic
variables ``z = (λ, μ)``; its exact solution has ``μ = 0``, and both the position and the
velocity constraints hold.  It is written as ``𝓜 ẏ = F(t, y)`` with the singular
``𝓜 = diag(I, M, 0, 0)`` and solved with Radau IIA (s = 3, c = ((4−√6)/10, (4+√6)/10, 1)),
stiffly accurate, order 5 for ``(X, v)`` and 3 for ``(λ, μ)`` on index-2 problems (Hairer &
Wanner II, Sec. VII.4, Table 4.1).  Implementation as in RADAU5 (Hairer & Wanner II, Sec. IV.8):
simplified Newton with the Jacobian frozen at the step start and ``A⁻¹`` transformed to one
real and one complex block, i.e. one real and one complex sparse LU of
``(μ/h) 𝓜 − ∂F/∂y``; the Jacobian contains ``Q_q, Q_v`` (``system.Q_jacobians``), the
constraint-force stiffness ``(Φ_qᵀλ)_q`` and the curvature ``(Φ_q v)_q − ν_q`` (sparse coloured
finite differences, :class:`core.integrators.generalized_alpha.ConstraintCurvature`; ``ν_q ≠ 0``
for moving constraints) and, when ``M = M(q)``, the term ``−(M(q) v̇)_q``.

Configuration-dependent mass matrix: the collocation conditions are
``M(t_i, Y_i) Ẏ_i = F(t_i, Y_i)`` at each stage, ``Ẏ = (A⁻¹ ⊗ I) Z / h`` (the Radau IIA solution
of the equivalent index-1 system ``ẏ = w, 0 = 𝓜(y) w − F``); only the iteration matrix uses
``M(t_n, q_n)``.  The Newton residual is therefore the constant-𝓜 one of RADAU5 plus the stage
corrections ``−(M(t_i, q_i) − M(t_n, q_n)) v̇_i``.  (Freezing ``M`` at the step start in the
residual too solves a different, first-order-accurate problem that the embedded error estimate
cannot see.)

Newton convergence is measured on ``(X, v)`` with the error weights, floored at
``10 ε ‖block‖_∞ / κ`` (``κ`` the Newton tolerance) per block: the constraint rows mix fast and
slow coordinates, so corrections of slow ones carry rounding errors ``~ε ‖v‖_∞`` that a purely
component-wise weight ``atol + rtol |v_i|`` cannot resolve at tight tolerances.
Error estimate: the embedded RADAU5 estimate
``err = (γ₀/h 𝓜 − J)⁻¹ (F(t_n, y_n) + 𝓜 Σ e_i Z_i / h)`` (Hairer & Wanner II, Eq. IV.8.20),
with the norm taken over the differential components ``(X, v)`` only — the index-2
components ``λ, μ`` are excluded as Hairer & Wanner recommend for index-2 problems
(Sec. VII.4, "the error estimate").  Step-size selection: the predictive (Gustafsson)
controller of RADAU5 (Eq. IV.8.25), no step increase directly after a rejected attempt
(error test or Newton failure, as RADAU5), Jacobian reuse and initial Newton guesses from the
previous collocation polynomial as in ``scipy.integrate.Radau``.  Unlike RADAU5, the user's
``rtol`` is used as given (RADAU5 internally replaces it by ``0.1 rtol^(2/3)``).  Multipliers are the last
stage's ``λ`` (stiffly accurate), so ``provides_multipliers`` is True.  Dense output: the
collocation polynomial (order 3), mapped through ``⊕``.

References
----------
C. W. Gear, B. Leimkuhler, G. K. Gupta, "Automatic integration of Euler–Lagrange equations
with constraints", J. Comput. Appl. Math. 12–13 (1985) 77–90.
E. Hairer, G. Wanner, *Solving Ordinary Differential Equations II*, 2nd ed., Springer, 1996,
Sec. IV.8 (RADAU5) and VII.4 (index-2 DAEs).
H. Munthe-Kaas, "Runge–Kutta methods on Lie groups", BIT 38 (1998) 92–111.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ..dynamics import accelerations, constraint_terms
from ..frames import skew
from ..system import as_dense
from .base import IntegrationFailure, Integrator, register
from .generalized_alpha import ConstraintCurvature, _sparse, q_jacobians, q_magnitude, rmatvec

S6 = 6 ** 0.5
C = np.array([(4 - S6) / 10, (4 + S6) / 10, 1.0])
E = np.array([-13 - 7 * S6, -13 + 7 * S6, -1.0]) / 3
MU_REAL = 3 + 3 ** (2 / 3) - 3 ** (1 / 3)
MU_COMPLEX = 3 + 0.5 * (3 ** (1 / 3) - 3 ** (2 / 3)) - 0.5j * (3 ** (5 / 6) + 3 ** (7 / 6))
T = np.array([
    [0.09443876248897524, -0.14125529502095421, 0.03002919410514742],
    [0.25021312296533332, 0.20412935229379994, -0.38294211275726192],
    [1, 1, 0]])
TI = np.array([
    [4.17871859155190428, 0.32768282076106237, 0.52337644549944951],
    [-4.17871859155190428, -0.32768282076106237, 0.47662355450055044],
    [0.50287263494578682, -2.57192694985560522, 0.59603920482822492]])
TI_REAL = TI[0]
TI_COMPLEX = TI[1] + 1j * TI[2]
P = np.array([
    [13 / 3 + 7 * S6 / 3, -23 / 3 - 22 * S6 / 3, 10 / 3 + 5 * S6],
    [13 / 3 - 7 * S6 / 3, -23 / 3 + 22 * S6 / 3, 10 / 3 - 5 * S6],
    [1 / 3, -8 / 3, 10 / 3]])
#: Radau IIA coefficient matrix inverse, ``A⁻¹`` (stage derivatives ``Ẏ_i = (A⁻¹ Z)_i / h``).
A_INV = T @ np.array([[MU_REAL, 0, 0], [0, MU_COMPLEX.real, -MU_COMPLEX.imag],
                      [0, MU_COMPLEX.imag, MU_COMPLEX.real]]) @ TI
NEWTON_MAXITER = 6
MIN_FACTOR, MAX_FACTOR = 0.2, 10.0


def _rotation_blocks(system):
    """(n_bodies) when the system is a spatial Cartesian model (rotation vectors in v-space)."""
    space = getattr(system, "space", None)
    nb = getattr(system, "n_bodies", None)
    if space is not None and nb and space.dim == 3:
        return nb
    return 0


def dexpinv(nb: int, X: np.ndarray, w: np.ndarray) -> np.ndarray:
    """``dexp⁻¹_X w`` on the rotation blocks of ``nb`` spatial bodies (identity elsewhere)."""
    if not nb:
        return w
    out = w.copy()
    th = X[: nb * 6].reshape(nb, 6)[:, 3:]
    om = w[: nb * 6].reshape(nb, 6)[:, 3:]
    a = np.linalg.norm(th, axis=1)
    small = a < 1e-3
    a_ = np.where(small, 1.0, a)
    c = np.where(small, 1.0 / 12.0 + a * a / 720.0, 1.0 / a_**2 - (1.0 + np.cos(a_)) / (2.0 * a_ * np.sin(a_)))
    xw = np.cross(th, om)
    out[: nb * 6].reshape(nb, 6)[:, 3:] = om + 0.5 * xw + c[:, None] * np.cross(th, xw)
    return out


@register
class RadauGGL(Integrator):
    """Radau IIA (order 5) on the GGL-stabilised index-2 equations, error controlled.

    ``h`` is the initial step (estimated when omitted).  See the module docstring.
    """

    name = "radau-ggl"
    summary = "GGL index-2 formulation, 3-stage Radau IIA (order 5), RADAU5-style error control"
    provides_multipliers = True

    def __init__(self, system, t_span, q0=None, v0=None, **kw):
        super().__init__(system, t_span, q0, v0, **kw)
        sys_ = system
        self.nv, self.nc = nv, nc = sys_.n_v, sys_.n_c
        self.n = 2 * nv + 2 * nc
        self.nd = 2 * nv  # differential components
        self.nb_rot = _rotation_blocks(sys_)
        self._M_const = _sparse(sys_.M(self.t, self.q)) if sys_.mass_is_constant else None
        a0, lam0 = accelerations(sys_, self.t, self.q, self.v)
        self.counters["n_rhs"] += 1
        self.a = a0
        self.lam = lam0
        self.mu = np.zeros(nc)
        self._curv = ConstraintCurvature(sys_, self.t, self.q) if nc else None
        # ν may depend on q only for moving (time-dependent) constraints
        self._rheonomic = bool(nc) and not (getattr(sys_, "time_dependent", None) is False
                                            and not getattr(sys_, "user_constraints", None))
        rtol = self.rtol
        self.newton_tol = max(10 * np.finfo(float).eps / rtol, min(0.03, rtol ** 0.5))
        f0 = np.concatenate([self.v, a0])
        if self.h is None:
            sc = self.atol + self.rtol * np.concatenate([q_magnitude(sys_, self.q), np.abs(self.v)])
            d0 = np.sqrt(np.mean((np.concatenate([q_magnitude(sys_, self.q), self.v]) / sc) ** 2))
            d1 = np.sqrt(np.mean((f0 / sc) ** 2))
            h0 = 1e-6 if d0 < 1e-5 or d1 < 1e-5 else 0.01 * d0 / d1
            self.h_abs = min(h0, 0.01 * (self.t_bound - self.t0))
        else:
            self.h_abs = self.h
        self.h_abs = min(self.h_abs, self.max_step)
        self.h_abs_old = None
        self.error_norm_old = None
        self._jac = None
        self._current_jac = False
        self.LU_real = self.LU_complex = None
        self._poly = None  # (Qpoly, h) of the last step for initial guesses / dense output
        self._last_rate = None

    # --- model pieces -----------------------------------------------------------------------
    def _Mbig(self, t, q):
        nv, nc = self.nv, self.nc
        if self._M_const is not None:
            M = self._M_const
        else:
            self._Mn = as_dense(self.system.M(t, q))
            M = _sparse(self._Mn)
        return sp.block_diag([sp.identity(nv, format="csr"), M, sp.csr_matrix((2 * nc, 2 * nc))], format="csc")

    def _F(self, t, qn, y):
        """``F(t, y)`` for ``y = (X, v, λ, μ)`` with ``q = q_n ⊕ X``."""
        sys_ = self.system
        nv, nc = self.nv, self.nc
        X, V, lam, mu = y[:nv], y[nv:2 * nv], y[2 * nv:2 * nv + nc], y[2 * nv + nc:]
        q = sys_.retract(qn, X)
        phi, J, nu, _ = constraint_terms(sys_, t, q, V)
        J = _sparse(J)
        self.counters["n_rhs"] += 1
        out = np.empty(self.n)
        out[:nv] = dexpinv(self.nb_rot, X, V + rmatvec(J, mu))
        out[nv:2 * nv] = sys_.Q(t, q, V) - rmatvec(J, lam)
        out[2 * nv:2 * nv + nc] = phi
        out[2 * nv + nc:] = J @ V - nu
        return out

    def _jacobian(self, t, q, v, lam, mu):
        sys_ = self.system
        nv, nc = self.nv, self.nc
        _, J, _, _ = constraint_terms(sys_, t, q, v)
        J = _sparse(J)
        Kq, Kv = q_jacobians(sys_, t, q, v)
        if self._M_const is None and self.a is not None:
            # configuration-dependent mass: the residual Q − Φ_qᵀλ − M(q) v̇ also varies with q
            # through −(M(q) v̇)_q (large for fast mechanisms, e.g. Andrews' squeezer)
            Kq = Kq - sp.csr_matrix(self._mass_stiffness(t, q, self.a))
        I = sp.identity(nv, format="csr")
        if nc:
            GL, GW = self._curv(t, q, J, lam, v)
            self.counters["n_rhs"] += self._curv.n_colors
            if self._rheonomic:
                # ∂(Φ_q v − ν)/∂q = (Φ_q v)_q − ν_q: ν = −Φ_t depends on q for moving
                # constraints (car axis: wheel contact on the moving road point)
                GW = GW - self._nu_q(t, q)
            GM, _ = self._curv(t, q, J, mu, v) if np.any(mu) else (None, None)
            A_XX = GM if GM is not None else None
            if self.nb_rot:
                # ∂/∂X of ½ X×w at X = 0: −½ w̃ on rotation blocks
                w = (v + rmatvec(J, mu))[: self.nb_rot * 6].reshape(self.nb_rot, 6)[:, 3:]
                blocks = np.zeros((self.nb_rot, 6, 6))
                blocks[:, 3:, 3:] = -0.5 * skew(w)
                D = sp.block_diag(list(blocks) + [sp.csr_matrix((nv - 6 * self.nb_rot,) * 2)], format="csr")
                A_XX = D if A_XX is None else A_XX + D
            jac = sp.bmat([[A_XX, I, None, J.T],
                           [Kq - GL, Kv, -J.T, None],
                           [J, None, None, None],
                           [GW, J, None, None]], format="csc")
        else:
            jac = sp.bmat([[None, I], [Kq, Kv]], format="csc")
        self.counters["n_jac"] += 1
        return jac

    def _nu_q(self, t, q, eps=1e-7):
        """``∂ν(t, q ⊕ X)/∂X`` at ``X = 0`` (sparse, pattern of ``Φ_q``; coloured differences)."""
        sys_, curv = self.system, self._curv
        nu0 = np.asarray(sys_.nu(t, q), float)
        D = np.empty((curv.n_colors, self.nc))
        for c, g in enumerate(curv.groups):
            dv = np.zeros(self.nv)
            dv[g] = eps
            D[c] = (np.asarray(sys_.nu(t, sys_.retract(q, dv)), float) - nu0) / eps
        self.counters["n_rhs"] += curv.n_colors
        r, c = curv.J_rows, curv.J_cols
        return sp.csr_matrix((D[curv.color[c], r], (r, c)), shape=curv.shape_J)

    def _mass_stiffness(self, t, q, a, eps=1e-7):
        """``∂(M(t, q ⊕ X) a)/∂X`` at ``X = 0`` by forward differences, shape (n_v, n_v)."""
        sys_ = self.system
        nv = self.nv
        Ma = as_dense(sys_.M(t, q)) @ a
        D = np.empty((nv, nv))
        for k in range(nv):  # Jacobian evaluations only, for systems with a non-constant M
            dv = np.zeros(nv)
            h = eps * max(1.0, abs(q[k]) if sys_.n_q == nv else 1.0)
            dv[k] = h
            D[:, k] = (as_dense(sys_.M(t, sys_.retract(q, dv))) @ a - Ma) / h
        self.counters["n_rhs"] += nv
        return D

    def _newton_scale(self, q, v):
        """Weights of the Newton increments: the error weights, floored at the rounding level.

        The corrections of all components of a block (positions, velocities) carry rounding
        errors of about ``ε ‖block‖_∞`` (the constraint rows mix all of them: ``Φ_q v`` of a
        mechanism with one fast and several slow members).  A weight below
        ``10 ε ‖block‖_∞ / newton_tol`` would ask the iteration to resolve increments below that
        noise, and it could never converge (rate ≈ 1 for any step size).
        """
        qm = q_magnitude(self.system, q)
        scale = self.atol + self.rtol * np.concatenate([qm, np.abs(v)])
        floor = 10 * np.finfo(float).eps / self.newton_tol
        scale[:self.nv] = np.maximum(scale[:self.nv], floor * np.max(qm, initial=0.0))
        scale[self.nv:] = np.maximum(scale[self.nv:], floor * np.max(np.abs(v), initial=0.0))
        return scale

    # --- collocation ------------------------------------------------------------------------
    def _solve_collocation(self, t, qn, y, h, Z0, scale, Mbig):
        nd = self.nd
        M_real = MU_REAL / h
        M_complex = MU_COMPLEX / h
        W = TI.dot(Z0)
        Z = Z0
        F = np.empty((3, self.n))
        ch = h * C
        dW_norm_old = None
        dW = np.empty_like(W)
        converged = False
        rate = None
        k = 0
        for k in range(NEWTON_MAXITER):
            for i in range(3):
                F[i] = self._F(t + ch[i], qn, y + Z[i])
            if self._M_const is None:
                # collocation of M(q) v̇ = …  at the stages: the residual needs M(t_i, Y_i), the
                # iteration matrix keeps M(t_n, q_n) (absorbed in the W-form term below)
                Vd = (A_INV @ Z[:, self.nv:nd]) / h
                Mn = self._Mn
                for i in range(3):
                    qi = self.system.retract(qn, Z[i, :self.nv])
                    F[i, self.nv:nd] -= (as_dense(self.system.M(t + ch[i], qi)) - Mn) @ Vd[i]
            if not np.all(np.isfinite(F)):
                break
            f_real = F.T.dot(TI_REAL) - M_real * (Mbig @ W[0])
            f_complex = F.T.dot(TI_COMPLEX) - M_complex * (Mbig @ (W[1] + 1j * W[2]))
            dW_real = self.LU_real.solve(f_real)
            dW_complex = self.LU_complex.solve(f_complex)
            self.counters["n_newton"] += 1
            dW[0] = dW_real
            dW[1] = dW_complex.real
            dW[2] = dW_complex.imag
            dW_norm = np.sqrt(np.mean((dW[:, :nd] / scale) ** 2))
            if dW_norm_old is not None:
                rate = dW_norm / dW_norm_old
            if rate is not None and (rate >= 1 or rate ** (NEWTON_MAXITER - k) / (1 - rate) * dW_norm > self.newton_tol):
                break
            W += dW
            Z = T.dot(W)
            if dW_norm == 0 or (rate is not None and rate / (1 - rate) * dW_norm < self.newton_tol):
                converged = True
                break
            dW_norm_old = dW_norm
        return converged, k + 1, Z, rate

    def _factor(self, h, Mbig):
        try:
            self.LU_real = spla.splu((MU_REAL / h) * Mbig - self._jac)
            self.LU_complex = spla.splu(((MU_COMPLEX / h) * Mbig - self._jac).astype(complex).tocsc())
        except RuntimeError as exc:
            raise IntegrationFailure(f"Radau iteration matrix singular (h = {h:.3g} s): {exc}") from None
        self.counters["n_factor"] += 2

    def _step_impl(self):
        sys_ = self.system
        t, qn = self.t, self.q
        nv, nc, nd = self.nv, self.nc, self.nd
        y = np.concatenate([np.zeros(nv), self.v, self.lam, self.mu])
        min_step = 10 * np.abs(np.nextafter(t, np.inf) - t)
        h_abs = min(self.h_abs, self.max_step)
        if h_abs < min_step:
            h_abs = min_step
        Mbig = self._Mbig(t, qn)
        if self._jac is None:
            self._jac = self._jacobian(t, qn, self.v, self.lam, self.mu)
            self._current_jac = True
            self.LU_real = None
        rejected = False
        step_accepted = False
        msg = None
        while not step_accepted:
            if h_abs < min_step:
                why = f" after: {msg}" if msg else ""
                return False, f"step size {h_abs:.3g} s too small (minimum {min_step:.3g} s){why}"
            h = h_abs
            t_new = t + h
            if t_new - self.t_bound > 0:
                t_new = self.t_bound
            h = t_new - t
            h_abs = abs(h)
            if self._poly is None:
                Z0 = np.zeros((3, self.n))
            else:
                Qp, h_old, t_old_base = self._poly
                x = (t + h * C - t_old_base) / h_old
                xp = np.vstack([x, x ** 2, x ** 3])
                Yp = (Qp @ xp).T  # increments relative to the previous step start
                x1 = (t - t_old_base) / h_old
                y1 = Qp @ np.array([x1, x1 ** 2, x1 ** 3])
                Z0 = Yp - y1
            scale = self._newton_scale(qn, self.v)
            converged = False
            while not converged:
                if self.LU_real is None:
                    self._factor(h, Mbig)
                converged, n_iter, Z, rate = self._solve_collocation(t, qn, y, h, Z0, scale, Mbig)
                if not converged:
                    if self._current_jac:
                        break
                    self._jac = self._jacobian(t, qn, self.v, self.lam, self.mu)
                    self._current_jac = True
                    self.LU_real = None
            if not converged:
                self.counters["n_rejected"] += 1
                h_abs *= 0.5
                self.LU_real = None
                rejected = True
                msg = f"Newton iteration did not converge (h = {h:.3g} s, rate {rate})"
                continue
            y_new = y + Z[-1]
            ZE = Z.T.dot(E) / h
            f0 = self._F(t, qn, y)
            err = self.LU_real.solve(f0 + Mbig @ ZE)
            q_new = sys_.retract(qn, y_new[:nv])
            scale_e = self.atol + self.rtol * np.maximum(
                np.concatenate([q_magnitude(sys_, qn), np.abs(self.v)]),
                np.concatenate([q_magnitude(sys_, q_new), np.abs(y_new[nv:2 * nv])]))
            error_norm = np.sqrt(np.mean((err[:nd] / scale_e) ** 2))
            safety = 0.9 * (2 * NEWTON_MAXITER + 1) / (2 * NEWTON_MAXITER + n_iter)
            if rejected and error_norm > 1:
                err = self.LU_real.solve(self._F(t, qn, y + err) + Mbig @ ZE)
                error_norm = np.sqrt(np.mean((err[:nd] / scale_e) ** 2))
            if not np.isfinite(error_norm):
                error_norm = np.inf
            if error_norm > 1:
                factor = self._predict_factor(h_abs, error_norm)
                h_abs *= max(MIN_FACTOR, safety * factor)
                self.LU_real = None
                rejected = True
                self.counters["n_rejected"] += 1
            else:
                step_accepted = True
        recompute_jac = self._jac is not None and n_iter > 2 and rate is not None and rate > 1e-3
        factor = self._predict_factor(h_abs, error_norm)
        factor = min(MAX_FACTOR, safety * factor)
        if rejected:
            # RADAU5: no increase right after a rejection (error test or Newton failure); else
            # a step limited by Newton convergence (kinematically driven systems, whose error
            # estimate is ≈ 0) grows tenfold and fails again at every other step
            factor = min(1.0, factor)
        if not recompute_jac and factor < 1.2:
            factor = 1
        else:
            self.LU_real = None
        self.h_abs_old = h_abs
        self.error_norm_old = error_norm
        self.h_abs = h_abs * factor
        # state update
        self._poly = (Z.T.dot(P), h, t)
        self.t = t_new
        self.q = q_new
        self.v = y_new[nv:2 * nv].copy()
        self.lam = y_new[2 * nv:2 * nv + nc].copy()
        self.mu = y_new[2 * nv + nc:].copy()
        # v̇ at t_new from the collocation polynomial derivative (for diagnostics)
        Qp = self._poly[0]
        self.a = (Qp[nv:2 * nv] @ np.array([1.0, 2.0, 3.0])) / h
        if recompute_jac:
            self._jac = self._jacobian(self.t, self.q, self.v, self.lam, self.mu)
            self._current_jac = True
            self.LU_real = None
        else:
            self._current_jac = False
        self._dense = (t, t_new, qn, y, Qp)
        return True, None

    def _predict_factor(self, h_abs, error_norm):
        if self.error_norm_old is None or self.h_abs_old is None or error_norm == 0:
            multiplier = 1
        else:
            multiplier = h_abs / self.h_abs_old * (self.error_norm_old / error_norm) ** 0.25
        with np.errstate(divide="ignore"):
            return min(1, multiplier) * error_norm ** -0.25

    def _dense_output_impl(self):
        t0, t1, qn, y, Qp = self._dense
        h = t1 - t0
        nv = self.nv
        sys_ = self.system

        def f(t):
            x = (t - t0) / h
            yy = y + Qp @ np.array([x, x * x, x ** 3])
            return sys_.retract(qn, yy[:nv]), yy[nv:2 * nv]

        return f
