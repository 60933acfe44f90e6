r"""Step-based integrator objects, their registry and the :func:`simulate` driver.

Every integrator follows the scipy ``OdeSolver`` pattern (scipy/integrate/_ivp/base.py):
construct with the system, the time span and the initial state; call :meth:`Integrator.step`
until :attr:`status` is ``"finished"`` or ``"failed"``; read :attr:`message`, the counters and
:meth:`dense_output` for the last step.

Extension contract (for a new integrator class):

1. Subclass :class:`Integrator`, set ``name`` and a one-line ``summary``.
2. Implement ``_step_impl() -> (ok: bool, message: str | None)`` advancing ``self.t``, ``self.q``,
   ``self.v`` (and ``self.lam`` when the method computes multipliers) from ``self.t_old``.
   Return ``(False, message)`` when the step cannot be taken (Newton divergence, step size
   underflow, tolerance not met); the base class marks the run failed with that message and the
   time where it happened.  Never return a result you know to be wrong.
3. Optionally override ``_dense_output_impl()``; the default is cubic Hermite interpolation
   of ``q`` (through ``q̇ = Z v``) and of ``v`` (through the accelerations at both ends when
   available, else linear), followed by ``system.normalize``.
4. Count work in ``self.counters``: ``n_steps, n_rejected, n_rhs, n_jac, n_factor, n_newton``.
5. Register with :func:`register` (or pass the class itself to :func:`simulate`).
"""

from __future__ import annotations

import time as _time
from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray

from ..dynamics import accelerations
from ..system import ConstrainedSystem

Array = NDArray[np.float64]

STATUS_RUNNING, STATUS_FINISHED, STATUS_FAILED = "running", "finished", "failed"


class IntegrationFailure(RuntimeError):
    """Raised inside a step implementation to stop the run with a message."""


class Integrator:
    """Base class of all integrators (see the module docstring for the contract).

    Parameters
    ----------
    system : ConstrainedSystem
    t_span : (float, float)
        Start and end time [s]; ``t_end > t0``.
    q0, v0 : ndarray, optional
        Initial state; defaults to ``system.q0``, ``system.v0``.
    rtol, atol : float
        Tolerances for error-controlled methods (and for Newton iterations of fixed-step ones).
    h : float, optional
        Step size for fixed-step methods; initial step for adaptive ones.
    max_step : float
        Largest step [s].

    Attributes
    ----------
    status : {'running', 'finished', 'failed'}
    message : str or None
    t, t_old : float
    q, v : ndarray
    lam : ndarray or None
        Multipliers at ``t`` when the method computes them.
    counters : dict of str to int
    """

    name: str = "base"
    summary: str = ""
    fixed_step: bool = False
    #: The method produces consistent multipliers itself (else simulate() computes them).
    provides_multipliers: bool = False
    #: Steps land on requested output times: :func:`simulate` calls :meth:`advance` with the next
    #: output time instead of :meth:`step` + dense output (compiled loops that take many steps per call).
    steps_to_output: bool = False

    def __init__(self, system: ConstrainedSystem, t_span, q0=None, v0=None, *, rtol: float = 1e-6,
                 atol: float = 1e-8, h: float | None = None, max_step: float = np.inf, **options):
        t0, t_end = map(float, t_span)
        if not t_end > t0:
            raise ValueError(f"{self.name}: t_span must have t_end > t0, got {t_span}")
        if not (rtol > 0 and atol > 0):
            raise ValueError(f"{self.name}: rtol and atol must be > 0, got rtol={rtol}, atol={atol}")
        if self.fixed_step and (h is None or not h > 0):
            raise ValueError(f"{self.name} is a fixed-step method: give a step size h > 0, got {h}")
        self.system = system
        self.t0, self.t_bound = t0, t_end
        self.t = self.t_old = t0
        self.q = np.array(system.q0 if q0 is None else q0, dtype=float)
        self.v = np.array(system.v0 if v0 is None else v0, dtype=float)
        self.q_old, self.v_old = self.q.copy(), self.v.copy()
        self.a = self.a_old = None
        self.lam = None
        self.rtol, self.atol = float(rtol), float(atol)
        self.h = None if h is None else float(h)
        self.max_step = float(max_step)
        self.options = options
        self.status = STATUS_RUNNING
        self.message: str | None = None
        self.counters = dict(n_steps=0, n_rejected=0, n_rhs=0, n_jac=0, n_factor=0, n_newton=0)
        unknown = set(options) - set(self.accepted_options())
        if unknown:
            raise TypeError(f"{self.name}: unknown option(s) {sorted(unknown)}; accepted: {sorted(self.accepted_options())}")

    @classmethod
    def accepted_options(cls) -> tuple[str, ...]:
        """Names of the method-specific keyword options."""
        return ()

    @classmethod
    def applicable(cls, system: ConstrainedSystem) -> str | None:
        """``None`` when the method can integrate ``system``, else the reason (e.g. no compiled kernel)."""
        return None

    # --- template method --------------------------------------------------------------------
    def step(self) -> str | None:
        """Advance one step; returns the message if the run ended in failure, else None."""
        if self.status != STATUS_RUNNING:
            raise RuntimeError(f"{self.name}: step() called on a {self.status} integrator")
        self.t_old, self.q_old, self.v_old, self.a_old = self.t, self.q.copy(), self.v.copy(), self.a
        try:
            ok, msg = self._step_impl()
        except IntegrationFailure as exc:
            ok, msg = False, str(exc)
        except (np.linalg.LinAlgError, FloatingPointError, ArithmeticError, ValueError) as exc:
            # ValueError: e.g. LAPACK refusing non-finite input in a fallback solve
            ok, msg = False, f"{type(exc).__name__}: {exc}"
        if ok and not (np.all(np.isfinite(self.q)) and np.all(np.isfinite(self.v))):
            ok, msg = False, "state became non-finite (NaN or Inf): the integration diverged"
        if not ok:
            self.status = STATUS_FAILED
            self.message = f"{self.name} failed at t = {self.t_old:.6g} s: {msg}"
            # keep the last good state
            self.t, self.q, self.v = self.t_old, self.q_old, self.v_old
            return self.message
        self.counters["n_steps"] += 1
        if self.t >= self.t_bound - 1e-12 * max(1.0, abs(self.t_bound)):
            self.t = self.t_bound
            self.status = STATUS_FINISHED
            self.message = "reached the end of the time span"
        return None

    def advance(self, t_target: float) -> str | None:
        """Advance towards ``t_target``; the default takes one :meth:`step` (may pass ``t_target``).

        Methods with ``steps_to_output = True`` take as many steps as needed and land on
        ``min(t_target, t_end)`` exactly.
        """
        return self.step()

    def _step_impl(self) -> tuple[bool, str | None]:  # pragma: no cover - abstract
        raise NotImplementedError

    def next_step_size(self) -> float:
        """Step for fixed-step methods, clipped to land on ``t_bound``."""
        h = min(self.h, self.max_step, self.t_bound - self.t)
        # avoid a sliver of a last step
        if self.t_bound - (self.t + h) < 1e-10 * self.h:
            h = self.t_bound - self.t
        return h

    # --- dense output ---------------------------------------------------------------------------
    def dense_output(self) -> Callable[[float], tuple[Array, Array]]:
        """Interpolant of the last step, ``f(t) -> (q, v)`` for ``t_old ≤ t ≤ t``."""
        return self._dense_output_impl()

    def _dense_output_impl(self):
        sys_ = self.system
        t0, t1 = self.t_old, self.t
        h = t1 - t0
        q0, q1, v0, v1 = self.q_old, self.q, self.v_old, self.v
        qd0, qd1 = sys_.qdot(q0, v0), sys_.qdot(q1, v1)
        a0, a1 = self.a_old, self.a

        def f(t):
            if h <= 0:
                return q1.copy(), v1.copy()
            s = (t - t0) / h
            h00, h10, h01, h11 = 2 * s**3 - 3 * s**2 + 1, s**3 - 2 * s**2 + s, -2 * s**3 + 3 * s**2, s**3 - s**2
            q = h00 * q0 + h10 * h * qd0 + h01 * q1 + h11 * h * qd1
            if a0 is not None and a1 is not None:
                v = h00 * v0 + h10 * h * a0 + h01 * v1 + h11 * h * a1
            else:
                v = (1 - s) * v0 + s * v1
            return sys_.normalize(q), v

        return f


# --------------------------------------------------------------------------------------------
# registry
# --------------------------------------------------------------------------------------------

METHODS: dict[str, type[Integrator]] = {}


def register(cls: type[Integrator]) -> type[Integrator]:
    """Class decorator adding an integrator to the name → class registry."""
    if not (isinstance(cls, type) and issubclass(cls, Integrator)):
        raise TypeError(f"register expects an Integrator subclass, got {cls!r}")
    METHODS[cls.name] = cls
    return cls


def get_method(method: str | type[Integrator]) -> type[Integrator]:
    """Resolve a registry name or accept an :class:`Integrator` subclass."""
    if isinstance(method, type) and issubclass(method, Integrator):
        return method
    if isinstance(method, str) and method in METHODS:
        return METHODS[method]
    raise ValueError(f"unknown integrator {method!r}: must be one of {sorted(METHODS)} or an Integrator subclass")


# --------------------------------------------------------------------------------------------
# driver
# --------------------------------------------------------------------------------------------


def simulate(system: ConstrainedSystem, t_span, method: str | type[Integrator] = "rk45-projection", *,
             t_eval=None, n_output: int = 201, q0=None, v0=None, rtol: float = 1e-6, atol: float = 1e-8,
             h: float | None = None, max_step: float = np.inf, progress: bool | None = False,
             compute_multipliers: bool = True, **options):
    """Integrate ``system`` over ``t_span`` and return a :class:`core.results.SimulationResult`.

    Output is sampled at ``t_eval`` (default ``n_output`` equally spaced times) from each step's
    dense output.  Multipliers at output times come from the method when it provides consistent
    ones, else from the index-1 KKT solve at the output state.  Position and velocity constraint
    violations (max-abs over rows, plus coordinate invariants such as |p|−1) and, for
    conservative systems, the energy are recorded at every output time.

    A run that fails (NaN, divergence, unmet tolerance, exception) returns with
    ``status == "failed"``, the message saying where, all output computed up to that point and, as
    its last row, the last good state at the time where the run stopped.
    """
    from ..results import SimulationResult

    cls = get_method(method)
    t0, t_end = map(float, t_span)
    if t_eval is None:
        t_eval = np.linspace(t0, t_end, n_output)
    t_eval = np.asarray(t_eval, float)
    if np.any(np.diff(t_eval) <= 0) or t_eval[0] < t0 - 1e-14 or t_eval[-1] > t_end + 1e-12:
        raise ValueError(f"t_eval must be strictly increasing within t_span {t_span}")
    integ = cls(system, (t0, t_end), q0, v0, rtol=rtol, atol=atol, h=h, max_step=max_step, **options)
    ts, qs, vs, lams = [], [], [], []
    k = 0
    wall0 = _time.perf_counter()
    solve_time = 0.0
    bar = None
    if progress is not False:
        from tqdm.auto import tqdm

        bar = tqdm(total=t_end - t0, disable=None if progress is None else not progress, unit="s", desc=system.name)
    # output at t0
    while k < len(t_eval) and t_eval[k] <= t0 + 1e-15:
        ts.append(t0)
        qs.append(integ.q.copy())
        vs.append(integ.v.copy())
        lams.append(None)
        k += 1
    while integ.status == STATUS_RUNNING:
        s0 = _time.perf_counter()
        if integ.steps_to_output:
            integ.advance(t_eval[k] if k < len(t_eval) else t_end)
        else:
            integ.step()
        solve_time += _time.perf_counter() - s0
        if integ.status == STATUS_FAILED:
            break
        if bar is not None:
            bar.update(integ.t - integ.t_old)
        if k < len(t_eval) and t_eval[k] <= integ.t + 1e-12 * max(1.0, abs(integ.t)):
            try:
                dense = integ.dense_output()
            except (np.linalg.LinAlgError, FloatingPointError, ArithmeticError, ValueError) as exc:
                integ.status = STATUS_FAILED
                integ.message = (f"{integ.name} failed at t = {integ.t:.6g} s: dense output could not be "
                                 f"built ({type(exc).__name__}: {exc})")
                break
            while k < len(t_eval) and t_eval[k] <= integ.t + 1e-12 * max(1.0, abs(integ.t)):
                tk = t_eval[k]
                if abs(tk - integ.t) <= 1e-12 * max(1.0, abs(integ.t)):
                    q, v = integ.q.copy(), integ.v.copy()
                    lam = None if integ.lam is None else np.array(integ.lam)
                else:
                    try:
                        q, v = dense(tk)
                    except (np.linalg.LinAlgError, FloatingPointError, ArithmeticError, ValueError) as exc:
                        integ.status = STATUS_FAILED
                        integ.message = (f"{integ.name} failed at t = {tk:.6g} s: dense output could not be "
                                         f"evaluated ({type(exc).__name__}: {exc})")
                        break
                    if not (np.all(np.isfinite(q)) and np.all(np.isfinite(v))):
                        integ.status = STATUS_FAILED
                        integ.message = f"{integ.name} failed at t = {tk:.6g} s: dense output is not finite"
                        break
                    lam = None
                ts.append(tk)
                qs.append(q)
                vs.append(v)
                lams.append(lam)
                k += 1
            if integ.status == STATUS_FAILED:
                break
    if bar is not None:
        bar.close()
    if integ.status == STATUS_FAILED and (not ts or integ.t > ts[-1]):
        # keep what was computed: the last good state, where the run stopped (not a requested time)
        ts.append(float(integ.t))
        qs.append(integ.q.copy())
        vs.append(integ.v.copy())
        lams.append(None)
    wall = _time.perf_counter() - wall0
    ts = np.array(ts)
    n_t = len(ts)
    Q = np.array(qs).reshape(n_t, system.n_q)
    V = np.array(vs).reshape(n_t, system.n_v)
    pos_viol = np.zeros(n_t)
    vel_viol = np.zeros(n_t)
    inv_viol = np.zeros(n_t)
    energy = np.full(n_t, np.nan) if system.energy(t0, system.q0, system.v0) is not None else None
    L = np.full((n_t, system.n_c), np.nan) if compute_multipliers else None
    reactions: dict[str, list] = {}
    for i in range(n_t):
        t, q, v = ts[i], Q[i], V[i]
        if system.n_c:
            pos_viol[i] = np.max(np.abs(system.Phi(t, q)))
            vel_viol[i] = np.max(np.abs(system.velocity_violation(t, q, v)))
        inv_viol[i] = system.invariant_violation(q)
        if energy is not None:
            energy[i] = system.energy(t, q, v)
        if compute_multipliers and system.n_c:
            lam = lams[i]
            if lam is None or not (integ.provides_multipliers and len(lam) == system.n_c):
                try:
                    _, lam = accelerations(system, t, q, v)
                except np.linalg.LinAlgError:
                    lam = np.full(system.n_c, np.nan)
            L[i] = lam
            for name, val in system.reactions(t, q, lam).items():
                reactions.setdefault(name, []).append(val)
    reactions_arr = {n: np.array(v) for n, v in reactions.items() if len(v) == n_t}
    meta = dict(
        system=system.name,
        method=cls.name,
        rtol=rtol,
        atol=atol,
        h=h,
        wall_time_s=solve_time,
        total_time_s=wall,
        t_end_reached=float(integ.t),
        max_invariant_violation=float(inv_viol.max()) if n_t else 0.0,
    )
    return SimulationResult(
        t=ts,
        q=Q,
        v=V,
        lam=L,
        status=integ.status,
        message=integ.message or "",
        counters=dict(integ.counters),
        meta=meta,
        coordinate_names=list(system.coordinate_names),
        velocity_names=list(system.velocity_names),
        constraint_names=list(system.constraint_names),
        position_violation=np.maximum(pos_viol, inv_viol),
        velocity_violation=vel_viol,
        energy=energy,
        reactions=reactions_arr,
        reaction_names={n: system.reaction_names().get(n, []) for n in reactions_arr},
    )
