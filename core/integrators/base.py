r"""Step-based integrator objects and their registry (the driver is :func:`core.simulation.simulate`).

Every integrator follows the scipy ``OdeSolver`` pattern (scipy/integrate/_ivp/base.py):
construct with the system, the time span and the initial state; call :meth:`Integrator.step`
until :attr:`status` is ``"finished"``, ``"finished with warnings"`` or ``"failed"``; read
:attr:`message`, :attr:`warnings`, the counters and :meth:`dense_output` for the last step.

Error checks of fixed-step methods
----------------------------------
A fixed-step method has no error control, so after every step the base class estimates the
local error from the step's own end data by the defect of the corrected trapezoidal rule
(Euler–Maclaurin; Hairer, Nørsett & Wanner I, Sec. II.10 on defect-based estimates):

.. math::

    e_n = q_{n+1} - q_n - \tfrac{h}{2}(\dot q_n + \dot q_{n+1}) - \tfrac{h^2}{12}(\ddot q_n - \ddot q_{n+1}),
    \qquad \varepsilon_n = \big\lVert e_n / (\mathrm{atol} + \mathrm{rtol}\,|q|) \big\rVert_{\mathrm{RMS}},

with ``q̇ = Z(q) v`` and ``q̈ = Z(q) v̇ + Ż v`` from the index-1 accelerations.  The exact motion
has ``e = O(h⁵)``; a numerical step whose positions and velocities disagree leaves its position
error in ``e`` (for the Newmark family it is the Zienkiewicz–Xie estimate
``(β − 1/6) h² (a_{n+1} − a_n)`` of the position error; for a method of order ≤ 3 it is the
leading local error; for order 4 it over-estimates by one power of h).  Errors of an
oscillating (conservative) motion add up along the run, so the **global error estimate** is
``Σ ε_n`` in units of the tolerance: the run ends ``"finished with warnings"`` when it exceeds 1,
naming the estimate, and ``"failed"`` at the first step whose estimate exceeds the state itself
(``‖e‖∞ > max(‖q_n‖∞, ‖q_{n+1}‖∞)``: no correct digit left).

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
5. Register with :func:`register` (or pass the class itself to :func:`core.simulation.simulate`).
6. Raise :class:`IntegrationFailure` (or let a :data:`core.errors.RUN_FAILURES` exception
   through) for numerical failures only; any other exception is a bug and propagates.
7. The base class calls ``system.begin_run`` on construction and ``system.accept_step`` after
   every accepted :meth:`step`; a method that takes several steps per call (``steps_to_output``)
   must call ``accept_step`` itself after each of them.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray

from ..assembly import check_initial_state
from ..errors import RUN_FAILURES, InputError, NumericalFailure, UnknownOptionError
from ..registry import Registry
from ..results import FINISHED_STATUSES, STATUS_FAILED, STATUS_FINISHED, STATUS_WARNED
from ..system import ConstrainedSystem

Array = NDArray[np.float64]

STATUS_RUNNING = "running"

#: A fixed-step run fails when one step's local error estimate exceeds the size of the state itself
#: (not one correct digit left; see :meth:`Integrator._fixed_step_error_check`).
NO_CORRECT_DIGIT = 1.0


class IntegrationFailure(NumericalFailure):
    """Raised inside a step implementation to stop the run with a message (a numerical failure)."""


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
    h : float or str, optional
        Step size for fixed-step methods; initial step for adaptive ones [s], or a string with its
        unit (``"0.25 ms"``, :func:`core.inputs.parse_quantity`).
    max_step : float or str
        Largest step [s] (or a string with its unit).

    Attributes
    ----------
    status : {'running', 'finished', 'finished with warnings', 'failed'}
    message : str or None
    warnings : list of str
        What the checks found doubtful in a run that reached the end time (status
        ``"finished with warnings"``); each is also appended to :attr:`message`.
    error_estimate : float
        Fixed-step methods: the global error estimate ``Σ ε_n`` in units of the tolerance
        (see the module docstring); NaN for error-controlled methods.
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

    @property
    def estimates_fixed_step_error(self) -> bool:
        """True when the run has no error control, so the base class estimates it (module docstring)."""
        return self.fixed_step and not getattr(self, "adaptive", False)

    def __init__(self, system: ConstrainedSystem, t_span, q0=None, v0=None, *, rtol: float = 1e-6,
                 atol: float = 1e-8, h: float | None = None, max_step: float = np.inf, **options):
        if not isinstance(system, ConstrainedSystem):
            hint = (": call build() on the ModelBuilder first (model = builder.build())" if hasattr(system, "build")
                    else " (a built Model or another ConstrainedSystem)")
            raise InputError(f"{self.name}: expected a built model, got a {type(system).__name__}{hint}")
        t0, t_end = map(float, t_span)
        if not t_end > t0:
            raise InputError(f"{self.name}: t_span must have t_end > t0, got {t_span}")
        h, max_step = _time_argument(self.name, "h", h), _time_argument(self.name, "max_step", max_step)
        _check_number(self.name, "rtol", rtol)
        _check_number(self.name, "atol", atol)
        if not (rtol > 0 and atol > 0):
            raise InputError(f"{self.name}: rtol and atol must be > 0, got rtol={rtol}, atol={atol}")
        if self.fixed_step and (h is None or not h > 0):
            raise InputError(f"{self.name} is a fixed-step method: give a step size h > 0, got {h}")
        self.system = system
        self.t0, self.t_bound = t0, t_end
        self.t = self.t_old = t0
        self.q = _initial_vector(self.name, system, "q0", system.q0 if q0 is None else q0, system.n_q,
                                 "coordinates")
        self.v = _initial_vector(self.name, system, "v0", system.v0 if v0 is None else v0, system.n_v,
                                 "velocity coordinates")
        if q0 is not None or v0 is not None:
            # a state given here gets the check build() gives the model's own (simulate(assemble=True)
            # makes it consistent first)
            check_initial_state(system, t0, self.q, self.v, owner=f"{self.name}, model {system.name!r}",
                                remedy="Give consistent q0/v0, or simulate(..., assemble=True) to assemble them.")
        self.q_old, self.v_old = self.q.copy(), self.v.copy()
        self.a = self.a_old = None
        self.lam = None
        self.rtol, self.atol = float(rtol), float(atol)
        self.h = None if h is None else float(h)
        self.max_step = float(max_step)
        self.options = options
        self.status = STATUS_RUNNING
        self.message: str | None = None
        self.warnings: list[str] = []
        self.error_estimate = 0.0 if self.estimates_fixed_step_error else np.nan
        self._largest_local = (0.0, t0)  # largest ε_n and where
        self.counters = dict(n_steps=0, n_rejected=0, n_rhs=0, n_jac=0, n_factor=0, n_newton=0)
        unknown = set(options) - set(self.accepted_options())
        if unknown:
            accepted = sorted(self.accepted_options())
            raise UnknownOptionError(f"{self.name}: unknown option(s) {sorted(unknown)}; "
                                     + (f"accepted: {accepted}" if accepted else "this method takes no options"))
        # elements with a search state start from the initial state and are told of accepted
        # steps only (core.forces.protocol)
        self._stateful = bool(getattr(system, "stateful", False))
        system.begin_run(self.t, self.q, self.v)

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
        except RUN_FAILURES as exc:
            # run failures only (singular matrices, non-finite values, no convergence, a table
            # past its range); any other exception, e.g. a bug in a user element, propagates
            ok, msg = False, f"{type(exc).__name__}: {exc}"
        if ok and not (np.all(np.isfinite(self.q)) and np.all(np.isfinite(self.v))):
            ok, msg = False, "state became non-finite (NaN or Inf): the integration diverged"
        if ok and self.estimates_fixed_step_error:
            msg = self._fixed_step_error_check()
            ok = msg is None
        if not ok:
            self.status = STATUS_FAILED
            self.message = f"{self.name} failed at t = {self.t_old:.6g} s: {msg}"
            # keep the last good state
            self.t, self.q, self.v = self.t_old, self.q_old, self.v_old
            return self.message
        if self._stateful:
            try:
                self.system.accept_step(self.t, self.q, self.v)
            except (IntegrationFailure, *RUN_FAILURES) as exc:
                # an element found the accepted state unphysical (e.g. a derailed wheel): the
                # run ends there, keeping that state as its last one
                self.status = STATUS_FAILED
                self.counters["n_steps"] += 1
                self.message = f"{self.name} failed at t = {self.t:.6g} s: {exc}"
                return self.message
        self.counters["n_steps"] += 1
        if self.t >= self.t_bound - 1e-12 * max(1.0, abs(self.t_bound)):
            self._finish()
        return None

    def _finish(self) -> None:
        """Mark the run as having reached the end time (with warnings when a check found any)."""
        self.t = self.t_bound
        if self.estimates_fixed_step_error and self.error_estimate > 1.0:
            eps, where = self._largest_local
            self.warnings.append(
                f"fixed step h = {self.h:.3g} s: estimated global error {self.error_estimate:.3g} × the tolerance "
                f"(rtol = {self.rtol:.3g}, atol = {self.atol:.3g}; sum of the local error estimates of "
                f"{self.counters['n_steps']} steps, the largest {eps:.3g} at t = {where:.6g} s); use a smaller h")
        self.status = STATUS_WARNED if self.warnings else STATUS_FINISHED
        self.message = "; ".join(["reached the end of the time span"] + [f"warning: {w}" for w in self.warnings])

    def add_warning(self, text: str) -> None:
        """Record a doubt about a run; a finished run becomes ``"finished with warnings"``."""
        self.warnings.append(text)
        if self.status in FINISHED_STATUSES:
            self.status = STATUS_WARNED
            self.message = f"{self.message}; warning: {text}"

    # --- error estimate of fixed-step methods ---------------------------------------------------
    def _acceleration_at(self, t, q, v):
        from ..dynamics import accelerations

        a, _ = accelerations(self.system, t, q, v)
        self.counters["n_rhs"] += 1
        return a

    def _qddot(self, q, v, a):
        """``q̈ = Z(q) v̇ + Ż(q) v``; ``Ż v`` by a directional difference of ``qdot`` along ``q̇``."""
        sys_ = self.system
        qd = sys_.qdot(q, v)
        out = sys_.qdot(q, a)
        nrm = float(np.max(np.abs(qd), initial=0.0))
        if nrm > 0:
            eps = np.sqrt(np.finfo(float).eps) * max(1.0, float(np.max(np.abs(q), initial=0.0))) / nrm
            out = out + (sys_.qdot(q + eps * qd, v) - sys_.qdot(q, v)) / eps
        return out

    def _fixed_step_error_check(self) -> str | None:
        """Add this step's local error estimate ``ε_n`` to :attr:`error_estimate` (module docstring)."""
        if self.a_old is None:
            self.a_old = self._acceleration_at(self.t_old, self.q_old, self.v_old)
        if self.a is None:
            self.a = self._acceleration_at(self.t, self.q, self.v)
        sys_ = self.system
        h = self.t - self.t_old
        q0, q1 = self.q_old, self.q
        e = (q1 - q0 - 0.5 * h * (sys_.qdot(q0, self.v_old) + sys_.qdot(q1, self.v))
             - h * h / 12.0 * (self._qddot(q0, self.v_old, self.a_old) - self._qddot(q1, self.v, self.a)))
        w = self.atol + self.rtol * np.maximum(np.abs(q0), np.abs(q1))
        eps = float(np.sqrt(np.mean((e / w) ** 2))) if e.size else 0.0
        size = max(float(np.max(np.abs(q0), initial=0.0)), float(np.max(np.abs(q1), initial=0.0)), self.atol)
        if not np.isfinite(eps) or float(np.max(np.abs(e), initial=0.0)) > NO_CORRECT_DIGIT * size:
            return (f"local error estimate {float(np.max(np.abs(e), initial=0.0)):.3g} exceeds the size of the state "
                    f"({size:.3g}) with the fixed step h = {h:.3g} s: no correct digit left; use a smaller h")
        self.error_estimate += eps
        if eps > self._largest_local[0]:
            self._largest_local = (eps, self.t)
        return None

    def advance(self, t_target: float, max_steps: int | None = None) -> str | None:
        """Advance towards ``t_target``; the default takes one :meth:`step` (may pass ``t_target``).

        Methods with ``steps_to_output = True`` take as many steps as needed (at most
        ``max_steps``; ``simulate(..., record_steps=True)`` passes 1) and land on
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

    # --- multipliers at output states ------------------------------------------------------------
    def multipliers(self, t: float, q: Array, v: Array) -> Array:
        """The index-1 multipliers λ at ``(t, q, v)`` (:func:`core.dynamics.accelerations`, no
        Baumgarte terms): what :func:`core.simulation.simulate` reports, and the joint reactions it
        computes, at output states where the method has none of its own.  The compiled integrators
        evaluate the same equations on their compiled path."""
        from ..dynamics import accelerations

        return accelerations(self.system, t, q, v)[1]

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

def _check_integrator(obj) -> None:
    if not (isinstance(obj, type) and issubclass(obj, Integrator)):
        raise TypeError(f"the integrator registry takes Integrator subclasses, got {obj!r}")


#: Name → integrator class.  Every module of :mod:`core.integrators` registers its classes on
#: import, and the package imports all of them, so :func:`core.simulation.simulate`, the
#: work-precision harness and the command line see the same methods.
METHODS: Registry[type[Integrator]] = Registry("integrator", _check_integrator)


def register(cls: type[Integrator]) -> type[Integrator]:
    """Class decorator adding an integrator to :data:`METHODS` under ``cls.name``."""
    _check_integrator(cls)
    return METHODS.register(cls.name, cls)


def get_method(method: str | type[Integrator]) -> type[Integrator]:
    """Resolve a registry name, or accept an :class:`Integrator` subclass as it is."""
    if isinstance(method, type) and issubclass(method, Integrator):
        return method
    if not isinstance(method, str):
        raise InputError(f"method must be an integrator name or an Integrator subclass, got {method!r}")
    return METHODS[method]


def _check_number(method: str, what: str, value, unit: str = "a tolerance") -> None:
    """An :class:`InputError` unless ``value`` is None or a plain number (text, a flag or a list is
    refused by name instead of failing a comparison later)."""
    if value is None:
        return
    if isinstance(value, (str, bytes, bool)):
        raise InputError(f"{method}: {what} must be a number ({unit}), got {value!r} ({type(value).__name__})")
    try:
        float(value)
    except (TypeError, ValueError) as exc:
        raise InputError(f"{method}: {what} must be a number ({unit}), got {value!r} ({type(value).__name__}: "
                         f"{exc})") from None


def _time_argument(method: str, what: str, value):
    """``h`` or ``max_step``: a number of seconds, or a string with its unit (``"1 ms"``, converted by
    pint as every quantity a user gives, :func:`core.inputs.parse_quantity`)."""
    if isinstance(value, str):
        from ..inputs import parse_quantity

        return parse_quantity(value, "s", where=f"{method}: {what}")
    _check_number(method, what, value, "seconds, or a string with its unit")
    return value


def _initial_vector(method: str, system, what: str, value, n: int, kind: str) -> Array:
    """``value`` as a float vector of length ``n``, or an :class:`InputError` naming what is wrong."""
    try:
        x = np.array(value, dtype=float)
    except (TypeError, ValueError) as exc:
        raise InputError(f"{method}: {what} must be an array of {n} numbers for model {system.name!r}, "
                         f"got {type(value).__name__} ({exc})") from None
    if x.shape != (n,):
        names = list(getattr(system, "coordinate_names", []) if what == "q0" else [])
        shown = (": " + ", ".join(names[:6]) + (", ..." if len(names) > 6 else "")) if names else ""
        raise InputError(f"{method}: {what} has shape {x.shape}, model {system.name!r} has {n} {kind}{shown}")
    if not np.all(np.isfinite(x)):
        k = int(np.flatnonzero(~np.isfinite(x))[0])
        raise InputError(f"{method}: {what}[{k}] is {x[k]}; initial states must be finite")
    return x
