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
    M-orthogonal projection, then ``system.normalize`` (:func:`core.dynamics.project`).

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
import scipy.sparse as sp

from ..dynamics import SaddleSolver, constraint_terms, project
from ..errors import InputError
from .base import Integrator, register

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
                raise InputError(f"{self.name}: Baumgarte alpha must be ≥ 0 and beta finite, got {self.alpha}, {self.beta}")
        else:
            self.alpha = self.beta = 0.0
        self.projection_tol = float(o.get("projection_tol", self.atol))
        self.max_projection_iter = int(o.get("max_projection_iter", 10))
        if not self.projection_tol > 0:
            raise InputError(f"{self.name}: projection_tol must be > 0, got {self.projection_tol}")
        self._jac = o.get("jac")
        self._n_q, self._n_v = system.n_q, system.n_v
        self._saddle = SaddleSolver(system, self.counters)
        self._nonfinite: str | None = None
        self._dense = None
        self._offsets = dict(n_jac=0)
        if self.stabilization == "projection":
            q, v, it = project(system, self.t, self.q, self.v, self.projection_tol, self.max_projection_iter, self._saddle)
            if it < 0:
                raise InputError(f"{self.name}: initial state of {system.name!r} cannot be projected onto the constraints")
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
            qp, vp, it = project(self.system, t_new, q, v, self.projection_tol, self.max_projection_iter, self._saddle)
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
