r"""Step-based integrator objects and their registry (the driver is :func:`core.simulation.simulate`).

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
from ..system import ConstrainedSystem

Array = NDArray[np.float64]

STATUS_RUNNING, STATUS_FINISHED, STATUS_FAILED = "running", "finished", "failed"


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
        if not isinstance(system, ConstrainedSystem):
            hint = (": call build() on the ModelBuilder first (model = builder.build())" if hasattr(system, "build")
                    else " (a built Model or another ConstrainedSystem)")
            raise InputError(f"{self.name}: expected a built model, got a {type(system).__name__}{hint}")
        t0, t_end = map(float, t_span)
        if not t_end > t0:
            raise InputError(f"{self.name}: t_span must have t_end > t0, got {t_span}")
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
        self.counters = dict(n_steps=0, n_rejected=0, n_rhs=0, n_jac=0, n_factor=0, n_newton=0)
        unknown = set(options) - set(self.accepted_options())
        if unknown:
            raise UnknownOptionError(f"{self.name}: unknown option(s) {sorted(unknown)}; accepted: {sorted(self.accepted_options())}")
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
        if not ok:
            self.status = STATUS_FAILED
            self.message = f"{self.name} failed at t = {self.t_old:.6g} s: {msg}"
            # keep the last good state
            self.t, self.q, self.v = self.t_old, self.q_old, self.v_old
            return self.message
        if self._stateful:
            self.system.accept_step(self.t, self.q, self.v)
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
