r"""Index-1 (acceleration-level) formulation integrated by any scipy ODE solver.

Equations
---------
State ``y = (q, v)`` (``n_q + n_v``).  The right-hand side solves, at every evaluation, the KKT
system of the acceleration-level equations (Haug 1989, Ch. 6; Hairer & Wanner II, Sec. VII.1,
the index reduction of the index-3 system):

.. math::

    \dot q = Z(q)\, v, \qquad
    \begin{bmatrix} M & \Phi_q^T \\ \Phi_q & 0 \end{bmatrix}
    \begin{bmatrix} \dot v \\ \lambda \end{bmatrix} =
    \begin{bmatrix} Q(t, q, v) \\ \gamma(t, q, v) - 2\alpha(\Phi_q v - \nu) - \beta^2 \Phi \end{bmatrix}

Three variants of every solver ``rk45, dop853, radau, bdf, lsoda`` are registered:

``"<method>"``
    ``α = β = 0``: the underlying ODE.  Its solutions keep ``Φ = 0`` and ``Φ_q v = ν`` only as
    invariants, so the discretisation error makes the constraints drift (linearly in velocity,
    quadratically in position, Hairer & Wanner II, Sec. VII.2).
``"<method>-baumgarte"``
    Baumgarte (1972) stabilisation, ``Φ̈ + 2αΦ̇ + β²Φ = 0``.  Default ``α = β = 10 s⁻¹``:
    critically damped, violations decay with time constant 0.1 s, and the added eigenvalues
    (``−10 s⁻¹``, double) stay far inside the stability region of the explicit methods for any
    step they take on multibody problems (``h ≲ 0.1 s``).  The choice is problem dependent
    (no general rule exists); pass ``alpha``, ``beta`` [1/s] to change it.
``"<method>-projection"``
    Coordinate projection after every accepted step (Eich 1993; Eich-Soellner & Führer 1998,
    Ch. 5): positions onto ``Φ = 0`` by simplified Gauss–Newton iterations for the
    M-weighted minimum-norm correction along velocity-space increments ``q ⊕ Δ``
    (tolerance ``projection_tol``, default ``atol``), then velocities onto ``Φ_q v = ν`` by the
    M-orthogonal projection, then ``system.normalize``.  See :func:`project`.

Solver reset after a projection (what is done and what it costs)
    ``RK45``, ``DOP853`` and ``Radau``: ``solver.y`` is overwritten and the cached derivative
    ``solver.f`` recomputed at the projected state (one extra right-hand side per step); the Radau
    Jacobian and LU factors are kept (they only drive the Newton iteration) and its collocation
    polynomial still serves as the Newton start.  ``BDF``: ``solver.y`` and the zeroth backward
    difference ``D[0]`` are overwritten, i.e. the whole interpolation polynomial of the history is
    shifted by the correction (order and step size are kept; no extra evaluations).  ``LSODA``
    keeps its Nordsieck history in the work array ``rwork`` of the wrapped ODEPACK solver; its zeroth
    column (the current ``y``) is overwritten in place, the same polynomial shift as for BDF (if
    scipy's private layout ever changes, a new solver is started from the projected state instead,
    restarting at order 1).
    The dense output of a projected step is the solver's interpolant plus the linear blend of the
    projection corrections at both ends, so it is continuous and exact at the step ends.

Jacobian for the implicit solvers (Radau, BDF, LSODA)
    By default scipy's own forward differences of the index-1 right-hand side (``n_q + n_v``
    evaluations per Jacobian; counted in ``n_rhs``).  Pass ``jac=callable(t, y)`` to supply one.

Performance
    Each right-hand side evaluates ``Q`` once and ``(Φ, Φ_q, ν, γ)`` in one pass
    (``system.constraint_terms``); for a constant invertible ``M`` the KKT system is solved by the
    Schur complement with ``M⁻¹`` computed once (:class:`SaddleSolver`).

Counters: ``n_rhs`` right-hand sides (including difference-quotient Jacobians), ``n_jac`` scipy
Jacobian evaluations, ``n_factor`` factorisations (KKT/Schur per right-hand side and projection,
plus scipy's LU decompositions), ``n_rejected`` not available from scipy (left at 0).

References
----------
J. Baumgarte, "Stabilization of constraints and integrals of motion in dynamical systems",
Comput. Methods Appl. Mech. Eng. 1 (1972) 1–16.
E. Eich, "Convergence results for a coordinate projection method applied to mechanical systems
with algebraic constraints", SIAM J. Numer. Anal. 30(5) (1993) 1467–1482.
E. Eich-Soellner, C. Führer, *Numerical Methods in Multibody Dynamics*, Teubner, 1998, Ch. 5.
E. Hairer, G. Wanner, *Solving Ordinary Differential Equations II*, 2nd ed., Springer, 1996,
Sec. VII.1–VII.2.
E. J. Haug, *Computer-Aided Kinematics and Dynamics of Mechanical Systems*, Allyn & Bacon, 1989.
"""

from __future__ import annotations

import numpy as np
import scipy.integrate as _si
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ..dynamics import kkt_matrix, solve_kkt
from ..dynamics import constraint_terms
from .base import Integrator, register

_DENSE_MAX = 400


def _wants_minimum_norm(system) -> bool:
    """Redundant rows kept in the model (same rule as :func:`core.dynamics.accelerations`)."""
    return bool(len(getattr(system, "redundant_rows", ())) and getattr(system, "_active_rows", None) is None)


class SaddleSolver:
    """Reusable solver for ``[[M, Gᵀ], [J, 0]]`` systems of one constrained system.

    Parameters
    ----------
    system : ConstrainedSystem
    counters : dict
        The integrator's counters; ``n_factor`` is incremented per factorisation.
    """

    def __init__(self, system, counters: dict):
        self.system = system
        self.counters = counters
        self.minimum_norm = _wants_minimum_norm(system)
        self._Minv = None
        self._M = None
        self._minv_diag = None  # diagonal M: 1/diag(M)
        self._Minv_dense = None
        self.dense = system.n_v <= _DENSE_MAX
        if system.mass_is_constant:
            M = system.M(0.0, system.q0)
            self._M = M
            if not self.minimum_norm and system.n_v:
                try:
                    Md = M.toarray() if sp.issparse(M) else np.asarray(M, float)
                    off = Md - np.diag(np.diag(Md))
                    if not np.any(off) and np.all(np.diag(Md) > 0):
                        self._minv_diag = 1.0 / np.diag(Md)
                        self._Minv = sp.diags(self._minv_diag, format="csr")
                    else:
                        Minv = spla.inv(sp.csc_matrix(Md)) if sp.issparse(M) else np.linalg.inv(Md)
                        dense = Minv.toarray() if sp.issparse(Minv) else np.asarray(Minv)
                        if np.all(np.isfinite(dense)) and np.allclose(Md @ dense, np.eye(system.n_v), atol=1e-9):
                            self._Minv = sp.csr_matrix(dense)
                            self._Minv_dense = dense if self.dense else None
                except (RuntimeError, np.linalg.LinAlgError, ValueError):
                    self._Minv = None

    def mass(self, t, q):
        """``M(t, q)`` (cached when constant)."""
        return self._M if self._M is not None else self.system.M(t, q)

    def factor(self, t, q, J, G=None):
        """Factorisation object with ``solve(f, g) -> (x, μ)`` for ``[[M, Gᵀ], [J, 0]]``."""
        self.counters["n_factor"] += 1
        return _Factor(self, t, q, J, J if G is None else G, G is None)

    def solve(self, t, q, J, f, g, G=None):
        """One-off solve of ``[[M, Gᵀ], [J, 0]] [x; μ] = [f; g]``."""
        return self.factor(t, q, J, G).solve(f, g)


class _Factor:
    def __init__(self, owner: SaddleSolver, t, q, J, G, symmetric: bool):
        self.owner = owner
        self.n_c = J.shape[0]
        self.M = owner.mass(t, q)
        self.J, self.G = J, G
        self._J_orig = J
        self.mode = None
        Minv = owner._Minv
        if self.n_c == 0:
            self.mode = "free"
            return
        if Minv is not None:
            try:
                if owner.dense:
                    Jd = J.toarray() if sp.issparse(J) else np.asarray(J, float)
                    Gd = Jd if G is J else (G.toarray() if sp.issparse(G) else np.asarray(G, float))
                    self.J = Jd
                    if owner._minv_diag is not None:
                        self.MGt = owner._minv_diag[:, None] * Gd.T
                    else:
                        self.MGt = owner._Minv_dense @ Gd.T
                    Sd = Jd @ self.MGt
                    if symmetric:
                        if not np.all(np.isfinite(Sd)):
                            raise np.linalg.LinAlgError("non-finite Schur complement")
                        self.fac = sla.cho_factor(Sd, check_finite=False)
                        self.mode = "chol"
                    else:
                        lu = sla.lu_factor(Sd, check_finite=True)
                        d = np.abs(np.diag(lu[0]))
                        if d.min() <= 1e-13 * max(d.max(), 1e-300):
                            raise np.linalg.LinAlgError("singular Schur complement")
                        self.fac = lu
                        self.mode = "lu"
                else:
                    self.MGt = Minv @ sp.csr_matrix(G).T
                    self.fac = spla.splu(sp.csc_matrix(J @ self.MGt))
                    self.mode = "splu"
            except (np.linalg.LinAlgError, RuntimeError, ValueError):
                self.mode = None
                self.J = J
        if self.mode is None and not owner.minimum_norm:
            try:
                K = kkt_matrix(self.M, J) if G is J else sp.bmat(
                    [[sp.csr_matrix(self.M), sp.csr_matrix(G).T], [sp.csr_matrix(J), None]], format="csc")
                with np.errstate(all="raise"):
                    self.fac = spla.splu(sp.csc_matrix(K))
                self.K = K
                self.mode = "kkt"
            except (RuntimeError, FloatingPointError, ValueError):
                self.mode = None
        if self.mode is None:
            self.mode = "lstsq"

    def solve(self, f, g):
        n_v = len(f)
        mode = self.mode
        if mode == "free":
            if self.owner._minv_diag is not None:  # constant diagonal M: cached inverse
                return self.owner._minv_diag * f, np.zeros(0)
            Md = self.M.toarray() if sp.issparse(self.M) else np.asarray(self.M)
            return np.linalg.solve(Md, f), np.zeros(0)
        Minv = self.owner._Minv
        if mode in ("chol", "lu", "splu"):
            x0 = self.owner._minv_diag * f if self.owner._minv_diag is not None else Minv @ f
            r = self.J @ x0 - g
            if mode == "chol":
                mu = sla.cho_solve(self.fac, r, check_finite=False)
            elif mode == "lu":
                mu = sla.lu_solve(self.fac, r, check_finite=False)
            else:
                mu = self.fac.solve(r)
            return x0 - self.MGt @ mu, mu
        if mode == "kkt":
            rhs = np.concatenate([f, g])
            sol = self.fac.solve(rhs)
            res = self.K @ sol - rhs
            if np.all(np.isfinite(sol)) and np.linalg.norm(res) <= 1e-8 * (1.0 + np.linalg.norm(rhs)):
                return sol[:n_v], sol[n_v:]
        if self.G is self.J:
            return solve_kkt(self.M, self.J, f, g, minimum_norm=True)
        # non-symmetric saddle point with rank-deficient blocks: dense least squares
        Md = self.M.toarray() if sp.issparse(self.M) else np.asarray(self.M, float)
        Jd = self.J.toarray() if sp.issparse(self.J) else np.asarray(self.J, float)
        Gd = self.G.toarray() if sp.issparse(self.G) else np.asarray(self.G, float)
        K = np.block([[Md, Gd.T], [Jd, np.zeros((self.n_c, self.n_c))]])
        sol, *_ = sla.lstsq(K, np.concatenate([f, g]), cond=1e-12, lapack_driver="gelsd")
        return sol[:n_v], sol[n_v:]


def project(system, solver: SaddleSolver, t: float, q, v, tol: float, max_iter: int = 10):
    r"""Coordinate projection onto ``Φ(t, q) = 0`` and ``Φ_q v = ν`` (Eich 1993).

    Positions: simplified Gauss–Newton iterations for the M-weighted minimum-norm correction,

    .. math::  \begin{bmatrix} M & Φ_q^T \\ Φ_q & 0 \end{bmatrix}
               \begin{bmatrix} Δ \\ μ \end{bmatrix} = \begin{bmatrix} 0 \\ -Φ(q^{(k)}) \end{bmatrix},
               \qquad q^{(k+1)} = q^{(k)} ⊕ Δ,

    with ``Φ_q`` and its factorisation frozen at the unprojected point, until ``‖Φ‖∞ ≤ tol``.
    Velocities: one M-orthogonal projection at the projected positions,
    ``[[M, Φ_qᵀ], [Φ_q, 0]] [Δv; μ] = [0; ν − Φ_q v]``.

    Returns
    -------
    q, v : ndarray
    n_iter : int
        Position iterations used; ``-1`` when they did not reach ``tol`` in ``max_iter``.
    """
    q = system.normalize(q)
    n_v = system.n_v
    if system.n_c == 0:
        return q, v, 0
    phi = system.Phi(t, q)
    n_iter = 0
    if np.max(np.abs(phi)) > tol:
        fac = solver.factor(t, q, system.Phi_q(t, q))
        zero = np.zeros(n_v)
        prev = np.inf
        while True:
            dq, _ = fac.solve(zero, -phi)
            q = system.retract(q, dq)
            n_iter += 1
            phi = system.Phi(t, q)
            err = np.max(np.abs(phi))
            if err <= tol:
                break
            if n_iter >= max_iter or not np.isfinite(err) or err > 2.0 * prev:
                return q, v, -1
            prev = err
        q = system.normalize(q)
    J = system.Phi_q(t, q)
    res = J @ v - system.nu(t, q)
    dv, _ = solver.solve(t, q, J, np.zeros(n_v), -np.asarray(res))
    return q, v + dv, n_iter


# --------------------------------------------------------------------------------------------
# index-1 ODE on top of scipy solvers
# --------------------------------------------------------------------------------------------


_SCIPY_SOLVERS = {
    "rk45": _si.RK45,
    "dop853": _si.DOP853,
    "radau": _si.Radau,
    "bdf": _si.BDF,
    "lsoda": _si.LSODA,
}
_IMPLICIT = {"radau", "bdf", "lsoda"}
DEFAULT_BAUMGARTE = 10.0  # [1/s], alpha = beta (critical damping)


class ScipyIndex1(Integrator):
    """Index-1 formulation stepped by a scipy ``OdeSolver`` (see the module docstring).

    Concrete classes (one per scipy method and stabilisation) are generated below; options:

    Parameters
    ----------
    alpha, beta : float, optional
        Baumgarte parameters [1/s] (``-baumgarte`` variants only); default 10 each.
    projection_tol : float, optional
        Position-projection tolerance on ``‖Φ‖∞`` (``-projection`` variants); default ``atol``.
    max_projection_iter : int, optional
        Gauss–Newton iterations allowed per projection (default 10).
    jac : callable, optional
        ``jac(t, y)`` of the index-1 ODE for the implicit methods; default scipy differences.
    """

    scipy_solver: type = _si.RK45
    stabilization: str = "none"
    method_key: str = "rk45"

    @classmethod
    def accepted_options(cls):
        opts = []
        if cls.stabilization == "baumgarte":
            opts += ["alpha", "beta"]
        if cls.stabilization == "projection":
            opts += ["projection_tol", "max_projection_iter"]
        if cls.method_key in _IMPLICIT:
            opts.append("jac")
        return tuple(opts)

    def __init__(self, system, t_span, q0=None, v0=None, **kw):
        super().__init__(system, t_span, q0, v0, **kw)
        o = self.options
        if self.stabilization == "baumgarte":
            self.alpha = float(o.get("alpha", DEFAULT_BAUMGARTE))
            self.beta = float(o.get("beta", DEFAULT_BAUMGARTE))
            if not (self.alpha >= 0 and np.isfinite(self.beta)):
                raise ValueError(f"{self.name}: Baumgarte alpha must be ≥ 0 and beta finite, got {self.alpha}, {self.beta}")
        else:
            self.alpha = self.beta = 0.0
        self.projection_tol = float(o.get("projection_tol", self.atol))
        self.max_projection_iter = int(o.get("max_projection_iter", 10))
        if not self.projection_tol > 0:
            raise ValueError(f"{self.name}: projection_tol must be > 0, got {self.projection_tol}")
        self._jac = o.get("jac")
        self._n_q, self._n_v = system.n_q, system.n_v
        self._saddle = SaddleSolver(system, self.counters)
        self._nonfinite: str | None = None
        self._dense = None
        self._offsets = dict(n_jac=0)
        if self.stabilization == "projection":
            q, v, it = project(system, self._saddle, self.t, self.q, self.v, self.projection_tol, self.max_projection_iter)
            if it < 0:
                raise ValueError(f"{self.name}: initial state of {system.name!r} cannot be projected onto the constraints")
            self.q, self.v = q, v
        self._solver = self._make_solver(self.t, np.concatenate([self.q, self.v]), self.h)

    # --- right-hand side ----------------------------------------------------------------------
    def _fun(self, t, y):
        self.counters["n_rhs"] += 1
        sys_ = self.system
        q, v = y[: self._n_q], y[self._n_q :]
        Q = sys_.Q(t, q, v)
        phi, J, nu, gam = constraint_terms(sys_, t, q, v)
        if self.alpha or self.beta:
            gam = gam - 2.0 * self.alpha * (J @ v - nu) - self.beta * self.beta * phi
        Jd = J.data if sp.issparse(J) else J
        if not (np.all(np.isfinite(Q)) and np.all(np.isfinite(gam)) and np.all(np.isfinite(y)) and np.all(np.isfinite(Jd))):
            if self._nonfinite is None:
                what = "Q" if not np.all(np.isfinite(Q)) else ("state" if not np.all(np.isfinite(y)) else "constraint terms")
                self._nonfinite = f"non-finite {what} in the right-hand side first seen at t = {t:.6g} s"
            return np.full(len(y), np.nan)
        a, _ = self._saddle.solve(t, q, J, Q, gam)
        return np.concatenate([sys_.qdot(q, v), a])

    def _make_solver(self, t, y, first_step):
        kw = dict(rtol=self.rtol, atol=self.atol, max_step=self.max_step)
        if first_step is not None:
            kw["first_step"] = min(first_step, self.t_bound - t)
        if self.method_key in _IMPLICIT and self._jac is not None:
            kw["jac"] = self._jac
        return self.scipy_solver(self._fun, t, y, self.t_bound, **kw)

    # --- stepping -----------------------------------------------------------------------------
    def _step_impl(self):
        solver = self._solver
        self._nonfinite = None
        lu0 = int(getattr(solver, "nlu", 0))
        msg = solver.step()
        self.counters["n_factor"] += int(getattr(solver, "nlu", 0)) - lu0
        self.counters["n_jac"] = self._offsets["n_jac"] + int(getattr(solver, "njev", 0))
        if solver.status == "failed":
            extra = f" ({self._nonfinite})" if self._nonfinite else ""
            return False, f"scipy {self.scipy_solver.__name__}: {msg}{extra}"
        y = solver.y
        if not np.all(np.isfinite(y)):
            return False, "state became non-finite (NaN or Inf)" + (f" ({self._nonfinite})" if self._nonfinite else "")
        t_new = solver.t
        q, v = y[: self._n_q].copy(), y[self._n_q :].copy()
        self._dense = (solver, None, None)
        if self.stabilization == "projection":
            qp, vp, it = project(self.system, self._saddle, t_new, q, v, self.projection_tol, self.max_projection_iter)
            if it < 0:
                return False, (f"coordinate projection did not reach ‖Φ‖ ≤ {self.projection_tol:g} in "
                               f"{self.max_projection_iter} iterations at t = {t_new:.6g} s")
            y_proj = np.concatenate([qp, vp])
            self._dense = (solver, self.t_old, y_proj)
            self._reset_solver(solver, t_new, y_proj)
            q, v = qp, vp
        self.t, self.q, self.v = float(t_new), q, v
        return True, None

    def _reset_solver(self, solver, t, y):
        key = self.method_key
        if key in ("rk45", "dop853", "radau"):
            solver.y = y.copy()
            solver.f = self._fun(t, solver.y)
        elif key == "bdf":
            solver.D[0] = y
            solver.y = y.copy()
        else:  # lsoda: shift the zeroth Nordsieck column held in the work array (as for BDF)
            try:
                inner = solver._lsoda_solver
                rwork = inner._integrator.rwork
                rwork[20 : 20 + len(y)] = y
                inner._y = y.copy()
                solver.y = y.copy()
            except AttributeError:  # scipy internals changed: restart from the projected state
                h_next = getattr(solver, "step_size", None)
                self._offsets["n_jac"] += int(getattr(solver, "njev", 0))
                if self.t_bound - t > 1e-12 * max(1.0, abs(self.t_bound)):
                    self._solver = self._make_solver(t, y, h_next if h_next and h_next > 0 else self.h)

    # --- dense output -------------------------------------------------------------------------
    def _dense_output_impl(self):
        solver, t_start, y_end = self._dense
        sol = solver.dense_output()
        sys_, nq = self.system, self._n_q
        t0, t1 = self.t_old, self.t
        if y_end is None:
            def f(t):
                y = sol(t)
                return sys_.normalize(y[:nq]), y[nq:].copy()
            return f
        y0 = np.concatenate([self.q_old, self.v_old])
        c0 = y0 - sol(t0)
        c1 = y_end - sol(t1)
        h = t1 - t0

        def f(t):
            s = 0.0 if h <= 0 else (t - t0) / h
            y = sol(t) + (1.0 - s) * c0 + s * c1
            return sys_.normalize(y[:nq]), y[nq:].copy()

        return f


def _make_class(key: str, stab: str) -> type[ScipyIndex1]:
    scipy_cls = _SCIPY_SOLVERS[key]
    name = key if stab == "none" else f"{key}-{stab}"
    label = {"none": "unstabilised", "baumgarte": "Baumgarte-stabilised",
             "projection": "with coordinate projection"}[stab]
    cls_name = f"{scipy_cls.__name__}Index1" + {"none": "", "baumgarte": "Baumgarte", "projection": "Projection"}[stab]
    doc = (f"Index-1 formulation ({label}) stepped by :class:`scipy.integrate.{scipy_cls.__name__}`.\n\n"
           f"Registry name ``{name!r}``.  Equations, options, reset strategy and references: see\n"
           f":mod:`core.integrators.index1` and :class:`ScipyIndex1`.\n")
    cls = type(cls_name, (ScipyIndex1,), dict(
        name=name, summary=f"index-1 {label}, scipy {scipy_cls.__name__}", scipy_solver=scipy_cls,
        stabilization=stab, method_key=key, __doc__=doc, __module__=__name__))
    return register(cls)


INDEX1_METHODS: dict[str, type[ScipyIndex1]] = {}
for _key in _SCIPY_SOLVERS:
    for _stab in ("none", "baumgarte", "projection"):
        _cls = _make_class(_key, _stab)
        INDEX1_METHODS[_cls.name] = _cls
        globals()[_cls.__name__] = _cls
del _key, _stab, _cls
