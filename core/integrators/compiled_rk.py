r"""Explicit Runge–Kutta integration of the index-1 formulation with a compiled step loop.

The same formulation and error control as :mod:`core.integrators.index1` on scipy's ``RK45`` and
``DOP853`` — state ``y = (q, v)``, ``q̇ = Z(q) v``, ``v̇`` from the index-1 KKT system with optional
Baumgarte terms, optional coordinate projection after every accepted step — but the stages, the
step-size controller and the kernels of :mod:`core.compiled` run in numba-compiled code, so a
right-hand side costs microseconds instead of the ~100 µs of Python-level numpy calls.

Methods (Butcher tableaux taken from scipy's classes, so both paths integrate with the same
coefficients):

``"jit-rk45"``
    Dormand–Prince 5(4) (Dormand & Prince 1980; Hairer, Nørsett & Wanner I, Sec. II.5), FSAL,
    error ``h Kᵀ E`` of the embedded order-4 solution.
``"jit-dop853"``
    Dormand–Prince 8(5,3) (Hairer, Nørsett & Wanner I, Sec. II.10), with the combined 5th/3rd order
    error estimate ``‖err₅‖² / √(‖err₅‖² + 0.01‖err₃‖²)`` of the Fortran DOP853.
``"jit-rk4"``
    The classical fourth-order Runge–Kutta method (Kutta 1901; Hairer, Nørsett & Wanner I,
    Sec. II.1, Table 1.2, left) with a **fixed step** ``h``: four right-hand sides a step
    (``k₁ … k₄`` at ``c = 0, ½, ½, 1``; the derivative at the step's end is the next step's ``k₁``),
    no error control.  What it is for: a penalty-stiff model integrated at a step just inside the
    stability boundary, where the step of an error-controlled explicit method is limited by
    stability anyway and its error estimate is spent work (Exudyn's fastest configuration on the
    stiff penalty chain is its explicit ``RK44`` at such a step).  Like every fixed-step method it gets the
    global error estimate of :mod:`core.integrators.base` (defect of the corrected trapezoidal rule,
    evaluated in the compiled loop from the step's end data: ``q̇ = Z v`` and ``q̈ = Z v̇ + Ż v``,
    where ``Ż v = Z(q + q̇) v − Z(q) v`` exactly because ``Z`` is affine in ``q``): the run ends
    ``"finished with warnings"`` when ``Σ εₙ > 1`` and ``"failed"`` at a step with no correct digit left
    or a non-finite state (a step beyond the stability boundary diverges: the message says so).

each as ``"<method>"`` (unstabilised), ``"<method>-baumgarte"`` (α = β = 10 s⁻¹ by default) and
``"<method>-projection"`` (Eich 1993; tolerance ``projection_tol`` defaults to ``atol``).

Step-size control (identical to ``scipy.integrate.RK45/DOP853``; Hairer, Nørsett & Wanner I,
Sec. II.4): ``sc_i = atol + rtol · max(|y_i|, |ŷ_i|)``, ``err = ‖e / sc‖_RMS``, accept when
``err < 1``; ``h ← h · min(10, 0.9 err^{−1/(p̂+1)})`` (not above 1 after a rejection),
``h ← h · max(0.2, 0.9 err^{−1/(p̂+1)})`` on rejection; the initial step by the algorithm of
Hairer, Nørsett & Wanner I, Sec. II.4 (scipy ``select_initial_step``).  A step that would pass
the next output time is shortened to land on it, so output needs no interpolation; with one output
point (``t_eval = [t_end]``) the step sequence is the scipy one and the results agree with the
``rk45``/``dop853`` methods to round-off.  ``jit-rk4`` has no step-size control: every step is the
given ``h``, the last one before an output time shortened to land on it (or up to 1e-6 h longer,
rather than leave a sliver of a step from the round-off of ``t``).

Failure is honest: a non-positive pivot of the Schur complement (dependent constraints, singular
configuration), coincident spring-damper points, a step below ``10 ulp(t)`` (non-finite stages
are rejected like any failed error test) or a projection that does not converge stop the run with
status ``failed``, the message naming the cause and the time, and the state of the last accepted
step kept.

Counters: ``n_steps`` accepted steps, ``n_rejected``, ``n_rhs`` right-hand sides, ``n_factor``
Schur factorisations (one per right-hand side and per projection stage).

References
----------
J. R. Dormand, P. J. Prince, J. Comput. Appl. Math. 6 (1980) 19–26.
W. Kutta, Z. Math. Phys. 46 (1901) 435–453.
E. Eich, SIAM J. Numer. Anal. 30(5) (1993) 1467–1482.
E. Hairer, S. P. Nørsett, G. Wanner, *Solving Ordinary Differential Equations I*, 2nd ed., 1993.
"""

from __future__ import annotations

# numba bakes module constants such as protocol.MAX_SLOTS into its cached machine code and keys the
# cache on this file only: this file changed with MAX_SLOTS (3 -> 8, flexible bodies' node frames)
# and with the mass groups of core.compiled.dynamics (flexible bodies with the deformed body's
# inertia), so that no stale kernel runs (docs/architecture.md, numba's on-disk cache)

import numba
import numpy as np
import scipy.integrate as _si

from ..compiled import dynamics as _d
from ..compiled import layout as _l
from ..compiled import protocol as _p
from ..compiled.cache import notify_if_cold
from ..errors import InputError, NotCompilable, NumericalFailure
from .base import NO_CORRECT_DIGIT, STATUS_FAILED, STATUS_RUNNING, Integrator, register
from .index1 import DEFAULT_BAUMGARTE

_jit = numba.njit(cache=True, fastmath=False, boundscheck=False)
_internal = numba.njit(cache=True, fastmath=False, boundscheck=False, no_cpython_wrapper=True, no_cfunc_wrapper=True)
# arrays only, nothing allocated: without numba's reference counting, whose atomic counts of every
# view made the fixed-step error estimate a sixth of an RK4 step's time (the functions it calls are
# compiled in the same mode: numba's callees inherit the flag where they do not set it, so only
# array-only code may be called from here)
_internal_norc = numba.njit(cache=True, fastmath=False, boundscheck=False, no_cpython_wrapper=True,
                            no_cfunc_wrapper=True, _nrt=False)

SAFETY, MIN_FACTOR, MAX_FACTOR = 0.9, 0.2, 10.0
ERR_RK45, ERR_DOP853, ERR_FIXED = 0, 1, 2
# counters array layout
C_STEPS, C_REJ, C_RHS, C_FACT, C_IASTI, C_NONSTI, C_STIFF = 0, 1, 2, 3, 4, 5, 6
# loop exit codes (besides the kernel status codes of core.compiled)
EXIT_REACHED, EXIT_MAX_STEPS, EXIT_TOO_SMALL, EXIT_STIFF = 100, 101, 102, 103
#: fixed step (jit-rk4): a step with no correct digit left (base.NO_CORRECT_DIGIT), a non-finite state
EXIT_NO_DIGIT, EXIT_DIVERGED = 104, 105
# out_info layout
I_T, I_H, I_TOLD, I_TFAIL, I_TSTIFF, I_HL, I_EST, I_EPSMAX, I_TEPSMAX, I_EMAX, I_SIZE = range(11)
#: Stiffness test of Hairer's DOPRI5/DOP853 codes: h|λ| estimated after every accepted step; stiff
#: after 15 consecutive estimates beyond the method's stability boundary on the negative real axis
#: (3.25 DOPRI5, 6.1 DOP853; 2.78 for the classical RK4, whose stability domain reaches −2.785),
#: cleared after 6 below it (Hairer & Wanner II, Sec. IV.2: the stability domains, Fig. 2.1, and the
#: automatic stiffness detection of the codes).
STIFF_BOUND = {"rk45": 3.25, "dop853": 6.1, "rk4": 2.78}
STIFF_STEPS, NONSTIFF_STEPS = 15, 6
STIFF_OFF, STIFF_WARN, STIFF_FAIL = 0, 1, 2
DEFAULT_STIFFNESS = "warn"


@_internal
def _rhs(cd, states, ws, lay, nq, constrained, t, y, alpha, beta, out, lam, counters):
    """Index-1 right-hand side ``out = (Z v, v̇)``; status code."""
    q = y[:nq]
    v = y[nq:]
    counters[C_RHS] += 1
    if constrained:
        counters[C_FACT] += 1
    st = _d.accelerations(cd, states, ws, t, q, v, alpha, beta, out[nq:], lam)
    _d.qdot(lay, q, v, out[:nq])
    return st


@_internal
def _rms(e, y, y_new, rtol, atol):
    acc = 0.0
    for i in range(e.shape[0]):
        sc = atol + rtol * max(abs(y[i]), abs(y_new[i]))
        x = e[i] / sc
        acc += x * x
    return np.sqrt(acc / e.shape[0])


@_internal_norc
def _fixed_step_defect(lay, nq, h, t_new, y, y_new, f0, f1, w_err, tmp, rtol, atol, out_info):
    r"""Local error estimate of a fixed step (:mod:`core.integrators.base`, module docstring).

    .. math::

        e = q_1 - q_0 - \tfrac{h}{2}(\dot q_0 + \dot q_1) - \tfrac{h^2}{12}(\ddot q_0 - \ddot q_1),
        \qquad \ddot q = Z(q)\,\dot v + \dot Z v,\quad \dot Z v = Z(q + \dot q)\,v - Z(q)\,v

    (``Z`` affine in ``q``, :func:`core.compiled.dynamics.qdot`, so the difference is exact);
    ``q̇, v̇`` are the right-hand sides ``f0``, ``f1`` at the step's ends.  Adds
    ``ε = ‖e / (atol + rtol max(|q₀|, |q₁|))‖_RMS`` to ``out_info[I_EST]`` and keeps the largest;
    returns ``EXIT_NO_DIGIT`` when ``‖e‖∞`` exceeds the state's size (``base.NO_CORRECT_DIGIT``),
    ``EXIT_DIVERGED`` when ``e`` is not finite, else ``OK``.
    """
    for end in range(2):
        yy = y if end == 0 else y_new
        ff = f0 if end == 0 else f1
        row = w_err[end]
        _d.qdot(lay, yy[:nq], ff[nq:], row)  # Z(q) v̇
        for i in range(nq):
            w_err[2, i] = yy[i] + ff[i]
        _d.qdot(lay, w_err[2], yy[nq:], tmp[:nq])  # Z(q + q̇) v
        for i in range(nq):
            row[i] += tmp[i] - ff[i]  # + Ż v
    acc = 0.0
    emax = 0.0
    size = atol
    for i in range(nq):
        e = (y_new[i] - y[i] - 0.5 * h * (f0[i] + f1[i]) - h * h / 12.0 * (w_err[0, i] - w_err[1, i]))
        sc = atol + rtol * max(abs(y[i]), abs(y_new[i]))
        acc += (e / sc) ** 2
        emax = max(emax, abs(e))
        size = max(size, abs(y[i]), abs(y_new[i]))
    eps = np.sqrt(acc / nq) if nq > 0 else 0.0
    if not np.isfinite(eps):
        return EXIT_DIVERGED
    if emax > NO_CORRECT_DIGIT * size:
        out_info[I_EMAX] = emax
        out_info[I_SIZE] = size
        return EXIT_NO_DIGIT
    out_info[I_EST] += eps
    if eps > out_info[I_EPSMAX]:
        out_info[I_EPSMAX] = eps
        out_info[I_TEPSMAX] = t_new
    return _p.OK


@_jit
def advance(cd, states, ws, t, y, f, need_f, t_stop, t_bound, h_abs, max_steps, A, B, C, E, E3, E5, err_kind,
            err_exp, rtol, atol, max_step, alpha, beta, projection, proj_tol, max_proj_iter, stiff_bound, stiff_action,
            stateful, K, y_new, y_old, f_old, tmp, y_st, w_err, lam, counters, out_info):
    r"""Take accepted steps from ``t`` until ``t_stop`` (or ``max_steps``); ``y``, ``f`` updated in place.

    ``need_f``: evaluate ``f = F(t, y)`` first (initial state, after a projection); with
    ``max_steps = 0`` that is all it does.  Every right-hand side of the loop goes through one
    call site, where :func:`_rhs` is inlined (one copy of the kernels to compile).
    ``y_old``/``f_old`` receive the state and derivative at the start of the last accepted step.
    ``out_info = [t, h_abs, t_old, t_fail, t_stiff, h|λ|, Σε, ε_max, t(ε_max), ‖e‖∞, state size]``
    (indices ``I_*``; the last five are the fixed-step error estimate).  Returns an exit code:
    ``EXIT_REACHED``, ``EXIT_MAX_STEPS`` or a failure (kernel status, ``EXIT_TOO_SMALL``,
    ``EXIT_STIFF``, and for the fixed step ``EXIT_NO_DIGIT``, ``EXIT_DIVERGED``).  With
    ``stateful``, the kinds' search-state kernels run after every accepted step (and only then).

    Fixed step (``err_kind == ERR_FIXED``): ``h_abs`` is the step; every step is accepted unless it
    diverges; the defect ``e`` of the module docstring is evaluated with the scratch rows
    ``w_err[0:3]`` (length ``n_q``) and its ``ε`` summed into ``out_info[I_EST]``.

    Stiffness test (Hairer's codes): ``h|λ| ≈ h ‖f(ŷ) − f(y_s)‖ / ‖ŷ − y_s‖`` from the last internal
    stage ``y_s`` (at ``c = 1``) and the new solution ``ŷ`` — a difference quotient of the Jacobian
    along the error direction.  ``stiff_action``: 0 off, 1 record the first time in ``out_info[4]``,
    2 also stop with ``EXIT_STIFF`` (as DOP853's ``IDID = −4``).
    """
    n = y.shape[0]
    ns = B.shape[0]
    steps = 0
    lay = cd.lay
    nq = lay[4]
    constrained = cd.act.shape[0] > 0
    fixed = err_kind == ERR_FIXED
    h_fix = h_abs
    while True:
        if need_f:
            for i in range(n):
                tmp[i] = y[i]
            st = _rhs(cd, states, ws, lay, nq, constrained, t, tmp, alpha, beta, f, lam, counters)
            need_f = False
            if st != _p.OK:
                out_info[0] = t
                out_info[3] = t
                return st
            continue
        if t >= t_stop:
            out_info[0] = t
            out_info[1] = h_fix if fixed else h_abs
            return EXIT_REACHED
        if steps >= max_steps:
            out_info[0] = t
            out_info[1] = h_fix if fixed else h_abs
            return EXIT_MAX_STEPS
        min_step = 10.0 * abs(np.nextafter(t, np.inf) - t)
        if fixed:
            h_abs = h_fix
            if t_stop - t < (1.0 + 1e-6) * h_fix:
                # the last step before the output time lands on it: no sliver of a step left by
                # the round-off of t accumulated over thousands of steps (a step up to 1e-6 h longer)
                h_abs = t_stop - t
        if h_abs > max_step:
            h_abs = max_step
        elif h_abs < min_step:
            h_abs = min_step
        rejected = False
        while True:
            if h_abs < min_step:
                out_info[0] = t
                out_info[3] = t
                return EXIT_TOO_SMALL
            h = h_abs
            t_new = t + h
            if t_new > t_stop:
                t_new = t_stop
            h = t_new - t
            h_abs = abs(h)
            # stages
            for i in range(n):
                K[0, i] = f[i]
            # stages 1 … ns−1 and the FSAL evaluation at (t + h, y_new) through one call site
            # (the right-hand side is inlined here once)
            st = _p.OK
            for s in range(1, ns + 1):
                if s < ns:
                    for i in range(n):
                        acc = 0.0
                        for j in range(s):
                            acc += A[s, j] * K[j, i]
                        tmp[i] = y[i] + h * acc
                    if s == ns - 1:
                        for i in range(n):
                            y_st[i] = tmp[i]
                    ts = t + C[s] * h
                else:
                    for i in range(n):
                        acc = 0.0
                        for j in range(ns):
                            acc += B[j] * K[j, i]
                        y_new[i] = y[i] + h * acc
                        tmp[i] = y_new[i]
                    ts = t + h
                st = _rhs(cd, states, ws, lay, nq, constrained, ts, tmp, alpha, beta, K[s], lam, counters)
                if st != _p.OK and st != _p.NONFINITE:
                    break
            if st != _p.OK and st != _p.NONFINITE:
                out_info[0] = t
                out_info[3] = ts
                return st
            if fixed:
                code = _fixed_step_defect(lay, nq, h, t_new, y, y_new, K[0], K[ns], w_err, tmp, rtol, atol, out_info)
                if code != _p.OK or st == _p.NONFINITE:
                    out_info[0] = t
                    out_info[3] = t_new
                    return EXIT_DIVERGED if (code == EXIT_DIVERGED or st == _p.NONFINITE) else code
                break
            # error estimate (non-finite stages give a NaN error: rejected)
            if err_kind == ERR_RK45:
                for i in range(n):
                    acc = 0.0
                    for j in range(ns + 1):
                        acc += E[j] * K[j, i]
                    tmp[i] = h * acc
                err = _rms(tmp, y, y_new, rtol, atol)
            else:
                e5 = 0.0
                e3 = 0.0
                for i in range(n):
                    a5 = 0.0
                    a3 = 0.0
                    for j in range(ns + 1):
                        a5 += E5[j] * K[j, i]
                        a3 += E3[j] * K[j, i]
                    sc = atol + rtol * max(abs(y[i]), abs(y_new[i]))
                    e5 += (a5 / sc) ** 2
                    e3 += (a3 / sc) ** 2
                if e5 == 0.0 and e3 == 0.0:
                    err = 0.0
                else:
                    err = abs(h) * e5 / np.sqrt((e5 + 0.01 * e3) * n)
            if err < 1.0:
                if err == 0.0:
                    factor = MAX_FACTOR
                else:
                    factor = min(MAX_FACTOR, SAFETY * err ** err_exp)
                if rejected:
                    factor = min(1.0, factor)
                h_abs *= factor
                break
            fac = SAFETY * err ** err_exp
            h_abs *= fac if fac > MIN_FACTOR else MIN_FACTOR  # NaN error -> MIN_FACTOR
            rejected = True
            counters[C_REJ] += 1
        # accepted; stiffness test
        if stiff_action != STIFF_OFF:
            num = 0.0
            den = 0.0
            for i in range(n):
                num += (K[ns, i] - K[ns - 1, i]) ** 2
                den += (y_new[i] - y_st[i]) ** 2
            if den > 0.0:
                hl = abs(h) * np.sqrt(num / den)
                if hl > stiff_bound:
                    counters[C_NONSTI] = 0
                    counters[C_IASTI] += 1
                    if counters[C_IASTI] == STIFF_STEPS:
                        counters[C_STIFF] += 1
                        if not out_info[4] == out_info[4]:  # first detection (NaN before)
                            out_info[4] = t_new
                            out_info[5] = hl
                        if stiff_action == STIFF_FAIL:
                            out_info[0] = t
                            out_info[3] = t_new
                            return EXIT_STIFF
                else:
                    counters[C_NONSTI] += 1
                    if counters[C_NONSTI] == NONSTIFF_STEPS:
                        counters[C_IASTI] = 0
        for i in range(n):
            y_old[i] = y[i]
            f_old[i] = f[i]
        for i in range(n):
            y[i] = y_new[i]
            f[i] = K[ns, i]
        if projection:
            it = _d.project(cd, ws, t_new, y[:nq], y[nq:], proj_tol, max_proj_iter, counters)
            if it < 0:
                for i in range(n):  # keep the last good state
                    y[i] = y_old[i]
                    f[i] = f_old[i]
                out_info[0] = t
                out_info[3] = t_new
                return _p.PROJECTION
            need_f = True  # f at the projected state, evaluated at the top of the loop
        if stateful:
            st = _d.accept(cd, states, ws, t_new, y[:nq], y[nq:])
            if st != _p.OK:
                out_info[0] = t
                out_info[3] = t_new
                return st
            need_f = True  # the search state changed: f at the new state with the new seed
        out_info[2] = t
        t = t_new
        steps += 1
        counters[C_STEPS] += 1


class ClassicalRK4:
    """Butcher tableau of the classical fourth-order method (Kutta 1901; Hairer, Nørsett & Wanner I,
    Sec. II.1, Table 1.2, left), in the layout of scipy's ``RungeKutta`` classes."""

    A = np.array([[0.0, 0.0, 0.0, 0.0], [0.5, 0.0, 0.0, 0.0], [0.0, 0.5, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0]])
    B = np.array([1.0, 2.0, 2.0, 1.0]) / 6.0
    C = np.array([0.0, 0.5, 0.5, 1.0])
    order = 4


def compiled_multipliers(integ, t, q, v) -> np.ndarray:
    """λ of :func:`core.compiled.dynamics.accelerations` without Baumgarte terms at ``(t, q, v)``
    (equal to :func:`core.dynamics.accelerations`' to round-off, microseconds instead of a sparse
    factorisation); the force kinds' search states are the run's.  :class:`NumericalFailure`
    naming the cause when the equations cannot be evaluated there."""
    cm = integ._cm
    a = np.zeros(cm.n_v)
    lam = np.zeros(max(cm.m, 1))
    st = _d.accelerations(integ._cd, integ._states, integ._ws, float(t), np.ascontiguousarray(q, dtype=float),
                          np.ascontiguousarray(v, dtype=float), 0.0, 0.0, a, lam)
    if st != _p.OK:
        raise NumericalFailure(f"{integ.name}: multipliers at t = {float(t):.6g} s: "
                               f"{integ._status_message(st, (float(t), np.concatenate([q, v])))}")
    return lam[:cm.m].copy()


class CompiledRK(Integrator):
    """Index-1 formulation on a compiled explicit Runge–Kutta loop (see the module docstring).

    Parameters
    ----------
    alpha, beta : float, optional
        Baumgarte parameters [1/s] (``-baumgarte`` variants); default 10 each.
    projection_tol : float, optional
        Position-projection tolerance on ``‖Φ‖∞`` (``-projection`` variants); default ``atol``.
    max_projection_iter : int, optional
        Gauss–Newton iterations per projection (default 10).

    Raises
    ------
    core.compiled.NotCompilable
        When the model has an element without a compiled kernel (the message names it).
    """

    scipy_solver: type = _si.RK45
    #: ``"rk45"``, ``"dop853"`` (error-controlled) or ``"rk4"`` (fixed step)
    tableau = "rk45"
    stabilization = "none"
    #: steps land on output times: simulate() calls advance(t_out) instead of step() + dense output
    steps_to_output = True

    @classmethod
    def accepted_options(cls):
        # the fixed step has no stiffness test: a step beyond the stability boundary diverges
        # within a few steps and fails on the defect check, and at a step just inside it Hairer's
        # difference quotient (two stages at c = 1) measured h|λ| ≈ 126 on the stiff chain, which
        # integrates correctly at that step
        stiff = () if cls.fixed_step else ("stiffness",)
        if cls.stabilization == "baumgarte":
            return ("alpha", "beta") + stiff
        if cls.stabilization == "projection":
            return ("projection_tol", "max_projection_iter") + stiff
        return stiff

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
        self._cm = _l.compile_model(system)
        self._cd = self._cm.data
        self._states = self._cm.initial_states()
        self._ws = _d.make_workspace(self._cm)
        notify_if_cold(advance, self.name, "20-40 s")
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
        actions = {"off": STIFF_OFF, "warn": STIFF_WARN, "fail": STIFF_FAIL}
        stiffness = o.get("stiffness", DEFAULT_STIFFNESS)
        if stiffness not in actions:
            raise InputError(f"{self.name}: stiffness must be one of {sorted(actions)}, got {stiffness!r}")
        self._stiff_action = STIFF_OFF if self.fixed_step else actions[stiffness]
        self._stiff_bound = STIFF_BOUND[self.tableau]
        #: time [s] where the stiffness test first fired (None if it never did)
        self.stiffness_detected_at: float | None = None
        s = self.scipy_solver
        self._A = np.ascontiguousarray(s.A, float)
        self._B = np.ascontiguousarray(s.B, float)
        self._C = np.ascontiguousarray(s.C, float)
        ns = len(self._B)
        if self.fixed_step:
            self._err_kind = ERR_FIXED
            self._E = self._E3 = self._E5 = np.zeros(ns + 1)
        elif s is _si.DOP853:
            self._err_kind = ERR_DOP853
            self._E = np.zeros(ns + 1)
            self._E3 = np.ascontiguousarray(s.E3, float)
            self._E5 = np.ascontiguousarray(s.E5, float)
        else:
            self._err_kind = ERR_RK45
            self._E = np.ascontiguousarray(s.E, float)
            self._E3 = self._E5 = np.zeros(ns + 1)
        self._err_exp = 0.0 if self.fixed_step else -1.0 / (s.error_estimator_order + 1)
        n = system.n_q + system.n_v
        self._K = np.zeros((ns + 1, n))
        self._y = np.concatenate([self.q, self.v])
        self._f = np.zeros(n)
        self._y_new, self._y_old, self._f_old, self._tmp = (np.zeros(n) for _ in range(4))
        self._lam = np.zeros(max(system.n_c, 1))
        self._cnt = np.zeros(7, np.int64)
        self._info = np.zeros(11)
        self._info[I_TSTIFF:I_EST] = np.nan
        self._w_err = np.zeros((3, system.n_q))
        self._y_st = np.zeros(n)
        self._h_abs = 0.0
        if self.stabilization == "projection":
            nq = system.n_q
            it = _d.project(self._cd, self._ws, self.t, self._y[:nq], self._y[nq:], self.projection_tol,
                            self.max_projection_iter, self._cnt)
            if it < 0:
                raise InputError(f"{self.name}: initial state of {system.name!r} cannot be projected onto the constraints")
        st = self._evaluate(self.t, self._y, self._f)
        if st != _p.OK:
            raise InputError(f"{self.name}: right-hand side fails at the initial state of {system.name!r}: "
                             f"{self._status_message(st, (self.t, self._y))}")
        if self.fixed_step:
            self._h_abs = min(self.h, self.max_step)
        elif self.h is not None:
            self._h_abs = min(self.h, self.t_bound - self.t)
        else:
            self._h_abs = self._initial_step(s.error_estimator_order)
        self._sync_counters()
        self.q, self.v = self._y[: system.n_q].copy(), self._y[system.n_q :].copy()
        self.a = self._f[system.n_q :].copy()

    def _advance_kernel(self, t, y, f, need_f, t_stop, max_steps):
        return advance(self._cd, self._states, self._ws, t, y, f, need_f, t_stop, self.t_bound, self._h_abs,
                       max_steps, self._A, self._B, self._C, self._E, self._E3, self._E5, self._err_kind,
                       self._err_exp, self.rtol, self.atol, self.max_step, self.alpha, self.beta,
                       self.stabilization == "projection", self.projection_tol, self.max_projection_iter,
                       self._stiff_bound, self._stiff_action, self._cm.stateful, self._K, self._y_new, self._y_old,
                       self._f_old, self._tmp, self._y_st, self._w_err, self._lam, self._cnt, self._info)

    def multipliers(self, t, q, v):
        """The index-1 multipliers at ``(t, q, v)`` on the compiled path (:func:`compiled_multipliers`)."""
        return compiled_multipliers(self, t, q, v)

    def _evaluate(self, t, y, out):
        """``out = F(t, y)`` through the compiled loop's right-hand side; kernel status code."""
        out[:] = 0.0
        code = self._advance_kernel(float(t), y, out, True, float(t), 0)
        return _p.OK if code in (EXIT_REACHED, EXIT_MAX_STEPS) else code

    def _status_message(self, code, state=None) -> str:
        """The failure of a kernel status code in the words of the element that reported it
        (:func:`core.compiled.layout.status_message`)."""
        return _l.status_message(self._cm, self.system, self._ws.err, self._states, code, state)

    def _initial_step(self, order):
        """Initial step of Hairer, Nørsett & Wanner I, Sec. II.4 (scipy's ``select_initial_step``)."""
        t0, y0, f0 = self.t, self._y, self._f
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
            h1 = (0.01 / max(d1, d2)) ** (1.0 / (order + 1))
        h = min(100.0 * h0, h1, interval, self.max_step)
        if not np.isfinite(h) or h <= 0:
            raise InputError(f"{self.name}: no usable initial step at t = {t0:g} s for {self.system.name!r} "
                             "(non-finite right-hand side near the initial state)")
        return h

    def _sync_counters(self):
        c = self.counters
        c["n_rejected"] = int(self._cnt[C_REJ])
        c["n_rhs"] = int(self._cnt[C_RHS])
        c["n_factor"] = int(self._cnt[C_FACT])

    def advance(self, t_target: float, max_steps: int = 2**62) -> str | None:
        """Take steps until ``t == min(t_target, t_end)`` (steps land on it); return the failure message or None."""
        if self.status != STATUS_RUNNING:
            raise RuntimeError(f"{self.name}: advance() called on a {self.status} integrator")
        t_stop = min(float(t_target), self.t_bound)
        if t_stop <= self.t:
            return None
        steps0 = int(self._cnt[C_STEPS])
        info = self._info
        info[:4] = (self.t, self._h_abs, self.t, np.nan)
        code = self._advance_kernel(self.t, self._y, self._f, False, t_stop, max_steps)
        nq = self.system.n_q
        taken = int(self._cnt[C_STEPS]) - steps0
        self.counters["n_steps"] += taken
        self._sync_counters()
        if taken:
            self.t_old = float(info[2])
            self.q_old, self.v_old = self._y_old[:nq].copy(), self._y_old[nq:].copy()
            self.a_old = self._f_old[nq:].copy()
        self.t = float(info[0])
        self._h_abs = float(info[1])
        self.q, self.v = self._y[:nq].copy(), self._y[nq:].copy()
        self.a = self._f[nq:].copy()
        if self.stiffness_detected_at is None and np.isfinite(info[I_TSTIFF]):
            self.stiffness_detected_at = float(info[I_TSTIFF])
        if self.fixed_step:
            self.error_estimate = float(info[I_EST])
            self._largest_local = (float(info[I_EPSMAX]), float(info[I_TEPSMAX]))
        if code in (EXIT_REACHED, EXIT_MAX_STEPS):
            if self.t >= self.t_bound - 1e-12 * max(1.0, abs(self.t_bound)):
                if self.stiffness_detected_at is not None:
                    self.warnings.append(
                        f"the problem became stiff at t = {self.stiffness_detected_at:.6g} s "
                        f"(h|λ| ≈ {info[5]:.3g} beyond the stability boundary {self._stiff_bound} on "
                        f"{STIFF_STEPS} consecutive steps): the step size is limited by stability and "
                        "the stiff components are not error-controlled; check with an implicit method")
                self._finish()
            return None
        if code == EXIT_TOO_SMALL:
            why = (f"step size fell below 10 ulp(t) at t = {info[3]:.6g} s (error test failing, e.g. non-finite "
                   "stages or a stiff problem beyond the explicit method's reach)")
        elif code == EXIT_STIFF:
            why = (f"the problem became stiff at t = {info[3]:.6g} s: h|λ| ≈ {info[5]:.3g} beyond the stability "
                   f"boundary {self._stiff_bound} of the method on {STIFF_STEPS} consecutive steps (Hairer's "
                   "stiffness test); use an implicit method (radau-ggl, generalized-alpha) or stiffness='warn'")
        elif code == EXIT_DIVERGED:
            why = (f"the state became non-finite in the step to t = {info[3]:.6g} s with the fixed step h = {self.h:.3g} s: "
                   f"the step is beyond the method's stability boundary (h|λ| ≤ {self._stiff_bound} on the negative "
                   "real axis) or the motion itself diverges; use a smaller h or an implicit method (jit-radau)")
        elif code == EXIT_NO_DIGIT:
            why = (f"local error estimate {info[I_EMAX]:.3g} exceeds the size of the state ({info[I_SIZE]:.3g}) with "
                   f"the fixed step h = {self.h:.3g} s in the step to t = {info[3]:.6g} s: no correct digit left; "
                   "use a smaller h")
        elif code == _p.PROJECTION:
            why = (f"coordinate projection did not reach ‖Φ‖ ≤ {self.projection_tol:g} in "
                   f"{self.max_projection_iter} iterations at t = {info[3]:.6g} s")
        else:
            # the right-hand side that failed was evaluated at (info[3], tmp): the stage state
            why = (f"{self._status_message(code, (float(info[3]), self._tmp.copy()))} "
                   f"(in the step to t = {info[3]:.6g} s)")
        self.status = STATUS_FAILED
        self.message = f"{self.name} failed at t = {self.t:.6g} s: {why}"
        return self.message

    def step(self) -> str | None:
        """One accepted step (the :class:`Integrator` contract)."""
        return self.advance(self.t_bound, max_steps=1)

    def _step_impl(self):  # pragma: no cover - step() is overridden
        raise NotImplementedError


def _make_class(key: str, stab: str) -> type[CompiledRK]:
    scipy_cls = {"rk45": _si.RK45, "dop853": _si.DOP853, "rk4": ClassicalRK4}[key]
    title = {"rk45": "RK45", "dop853": "DOP853", "rk4": "fixed-step classical RK4"}[key]
    name = f"jit-{key}" + ("" if stab == "none" else f"-{stab}")
    label = {"none": "unstabilised", "baumgarte": "Baumgarte-stabilised",
             "projection": "with coordinate projection"}[stab]
    cls_name = f"Compiled{key.upper()}" + {"none": "", "baumgarte": "Baumgarte", "projection": "Projection"}[stab]
    doc = (f"Index-1 formulation ({label}) on a compiled {title} loop.\n\n"
           f"Registry name ``{name!r}``.  See :mod:`core.integrators.compiled_rk` and :class:`CompiledRK`.\n")
    cls = type(cls_name, (CompiledRK,), dict(
        name=name, summary=f"index-1 {label}, compiled {title} (numba)", scipy_solver=scipy_cls, tableau=key,
        fixed_step=key == "rk4", stabilization=stab, __doc__=doc, __module__=__name__))
    return register(cls)


COMPILED_METHODS: dict[str, type[CompiledRK]] = {}
for _key in ("rk45", "dop853", "rk4"):
    for _stab in ("none", "baumgarte", "projection"):
        _cls = _make_class(_key, _stab)
        COMPILED_METHODS[_cls.name] = _cls
        globals()[_cls.__name__] = _cls
del _key, _stab, _cls
