r"""Work-precision harness: error against run time for every integrator on benchmark problems.

For a :class:`WorkPrecisionProblem` and every integrator of :data:`core.integrators.METHODS`
(or a chosen subset), :func:`run_work_precision` integrates the problem over a grid of
settings -- relative tolerances for error-controlled methods, step sizes for fixed-step ones --
and records, per run, one row of a tidy table:

* ``error``: the problem's error measure at ``t_end`` against an independent reference
  (column ``error measure`` names it with its unit);
* ``wall time [s]``: the median over ``repeats`` solves of the time spent inside the
  integrator's ``step()`` calls (``SimulationResult.meta["wall_time_s"]``, which
  :func:`core.integrators.simulate` accumulates around ``step()`` only: model building, output
  sampling by dense output, violation/energy evaluation and multipliers are not counted);
* the largest position- and velocity-level constraint violations over the output samples
  (:attr:`WorkPrecisionProblem.n_output` equally spaced times; between steps these come from
  the method's dense output, so they include its interpolation error), and the violations at
  ``t_end``, which is always a step point (what the method itself holds);
* the relative energy drift ``max_k |E(t_k) − E(t_0)| / E_ref`` for conservative problems
  (``E_ref`` = :attr:`WorkPrecisionProblem.energy_scale`, else ``|E(t_0)|``), NaN otherwise;
* the work counters ``n_steps, n_rejected, n_rhs, n_jac, n_factor, n_newton``, the final
  ``status`` and ``message``.

A run that fails (status ``"failed"``, or an exception while setting it up) stays in the table
as a row with ``status = "failed"``, the message, and ``error = NaN``; nothing is dropped.  Only
a method that cannot integrate the system at all (:meth:`Integrator.applicable` gives a reason,
e.g. a compiled integrator on a hand-written system) is left out of the problem's table.

Settings
--------
Error-controlled methods get ``rtol`` from the grid and ``atol = rtol · atol_scale`` (the
problem's :attr:`~WorkPrecisionProblem.atol_scale`, 1 for every registered problem: their
coordinates are O(0.1–10) m or rad).  Fixed-step methods get the step ``h [s]`` from the grid
and a tight Newton tolerance ``rtol = atol = newton_tol`` (default 1e−10): with the integrators'
default 1e−6 the Newton error, not the discretisation error, limits the accuracy at small steps
(measured: generalized-α on the N = 2 chain, h = 1e−4, tip error 4.2e−6 m at 1e−6 against
4.6e−7 m at 1e−10, the second-order value).

Grids (:class:`Grid`) come in three sizes per problem: ``"quick"`` (CI, about a minute for the
quick problem set), ``"standard"`` (the report of ``make run``, about ten minutes on two cores
for the standard set) and ``"full"`` (every method, rtol 1e−3 … 1e−10, long runs included).

Sweeps run through :func:`core.sweep.run_sweep`, so any :class:`concurrent.futures.Executor`
may execute them; the reference of a problem is computed once in the calling process and sent
with every case, so the deterministic columns (error, status, counters, violations) do not
depend on the executor.

Adding a problem is one entry: build a :class:`WorkPrecisionProblem` from module-level
(picklable) functions and call :func:`register_problem` (IFToMM A02 and A04 go here once
their models exist).

References
----------
E. Hairer, G. Wanner, *Solving Ordinary Differential Equations II*, 2nd ed., Springer, 1996,
Sec. IV.10 (work-precision diagrams) and Sec. VII.7 (Andrews' squeezer, car axis).
F. Mazzia, C. Magherini, *Test Set for Initial Value Problem Solvers*, release 2.4, University of
Bari, 2008 (problems "andrews" and "caraxis": reference solutions at t_end).
M. González, D. Dopico, U. Lugrís, J. Cuadrado, "A benchmarking system for MBS simulation
software: problem standardization and performance measurement", Multibody Syst. Dyn. 16 (2006)
179–190 (IFToMM A01 pendulum; error against CPU time at precision levels).
P. F. Byrd, M. D. Friedman, *Handbook of Elliptic Integrals for Engineers and Scientists*,
2nd ed., Springer, 1971, formula 121.00 (large-amplitude pendulum); D. F. Lawden, *Elliptic
Functions and Applications*, Springer, 1989, Sec. 5.2.
"""

from __future__ import annotations

import dataclasses
import fnmatch
import importlib
import math
import pkgutil
import statistics
import warnings
import weakref
from collections.abc import Callable, Iterable, Mapping, Sequence
from concurrent.futures import Executor
from dataclasses import dataclass, field
from functools import partial
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

__all__ = [
    "COLUMNS",
    "Grid",
    "PROBLEMS",
    "PROBLEM_SETS",
    "WorkPrecisionProblem",
    "available_methods",
    "fastest_to_tolerance",
    "pendulum_angle_exact",
    "stiff_chain_rhs",
    "register_bench_command",
    "register_problem",
    "run_work_precision",
    "work_precision_figure",
    "work_precision_scenes",
    "write_work_precision",
]

SETTING_RTOL = "rtol"
SETTING_STEP = "h [s]"
#: Row status of a method that cannot integrate the problem's system (dropped from the tables).
NOT_APPLICABLE = "not applicable"
COUNTERS = ("n_steps", "n_rejected", "n_rhs", "n_jac", "n_factor", "n_newton")

#: Columns of the table returned by :func:`run_work_precision`, in order.
COLUMNS = [
    "problem",
    "method",
    "setting kind",
    "setting value",
    "rtol",
    "atol",
    "error",
    "error measure",
    "wall time [s]",
    "n repeats",
    "max position violation [m]",
    "max velocity violation [m/s]",
    "final position violation [m]",
    "final velocity violation [m/s]",
    "energy drift [-]",
    *COUNTERS,
    "status",
    "message",
    "t reached [s]",
]
#: Columns that do not depend on timing or on the executor (equal serial vs parallel).
DETERMINISTIC_COLUMNS = [
    "problem", "method", "setting kind", "setting value", "rtol", "atol", "error",
    "max position violation [m]", "max velocity violation [m/s]", "final position violation [m]",
    "final velocity violation [m/s]", "energy drift [-]", *COUNTERS,
    "status", "t reached [s]",
]

GRID_NAMES = ("quick", "standard", "full")
G_EARTH = 9.81


# ---------------------------------------------------------------------------------------------
# method discovery
# ---------------------------------------------------------------------------------------------


_BROKEN_MODULES: set[str] = set()


def _load_integrators() -> dict:
    """Import every module of :mod:`core.integrators` (each registers its classes) and return METHODS."""
    from . import integrators

    for info in pkgutil.iter_modules(integrators.__path__):
        name = f"{integrators.__name__}.{info.name}"
        if info.name.startswith("_") or name in _BROKEN_MODULES:
            continue
        try:
            importlib.import_module(name)
        except Exception as exc:  # noqa: BLE001 - one broken integrator module must not stop the others
            _BROKEN_MODULES.add(name)
            warnings.warn(f"integrator module {name} could not be imported ({type(exc).__name__}: {exc}); "
                          "its methods are missing from the benchmark", RuntimeWarning, stacklevel=2)
    return integrators.METHODS


def available_methods() -> list[str]:
    """Names of all registered integrators (after importing every integrator module)."""
    return list(_load_integrators())


# ---------------------------------------------------------------------------------------------
# grids and problems
# ---------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Grid:
    """Settings of one sweep size.

    Parameters
    ----------
    rtols : tuple of float
        Relative tolerances for error-controlled methods (``atol = rtol · atol_scale``).
    steps : tuple of float
        Step sizes [s] for fixed-step methods.
    methods : tuple of str, optional
        Registry names to run; None means every registered method.  Names not registered
        (yet) are skipped silently here (they are an error when the *user* asks for them).
    exclude : tuple of str
        ``fnmatch`` patterns of method names to leave out (applied after ``methods``), so
        integrators registered later are included by default.
    """

    rtols: tuple[float, ...] = ()
    steps: tuple[float, ...] = ()
    methods: tuple[str, ...] | None = None
    exclude: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        for label, vals in (("rtols", self.rtols), ("steps", self.steps)):
            bad = [v for v in vals if not (np.isfinite(v) and v > 0)]
            if bad:
                raise ValueError(f"Grid.{label} must hold positive finite numbers, got {bad}")
        object.__setattr__(self, "rtols", tuple(float(v) for v in self.rtols))
        object.__setattr__(self, "steps", tuple(float(v) for v in self.steps))

    def select(self, registered: Sequence[str]) -> list[str]:
        """The grid's methods among the ``registered`` names, in registry order."""
        names = list(registered) if self.methods is None else [m for m in self.methods if m in registered]
        return [m for m in names if not any(fnmatch.fnmatchcase(m, pat) for pat in self.exclude)]


def _geom(hi: float, lo: float, per_decade: int) -> tuple[float, ...]:
    """Geometric sequence from ``hi`` down to ``lo`` with ``per_decade`` points per decade."""
    n = int(round(np.log10(hi / lo) * per_decade))
    return tuple(float(f"{v:.3g}") for v in np.geomspace(hi, lo, n + 1))


#: Reference quantities are cached per process (per problem object).
_REFERENCE_CACHE: "weakref.WeakKeyDictionary[WorkPrecisionProblem, Any]" = weakref.WeakKeyDictionary()


@dataclass(frozen=True, eq=False)
class WorkPrecisionProblem:
    """One benchmark problem of the work-precision harness.

    Parameters
    ----------
    name : str
        Registry key, e.g. ``"chain8-planar"`` (lower case, digits, ``-``).
    title : str
        One line for listings and figure titles.
    build_system : callable
        ``build_system() -> ConstrainedSystem``; module-level (picklable) for process pools.
    t_end : float
        End time [s]; every run integrates ``[0, t_end]``.
    reference_fn : callable
        ``reference_fn() -> object``: the reference quantity at ``t_end`` (cached by
        :meth:`reference`).
    error_fn : callable
        ``error_fn(system, q_end, v_end, reference) -> float``: the error of the state reached
        at ``t_end``.
    error_measure : str
        What ``error`` is, with its unit, e.g. ``"|tip − tip_ref| [m]"``.
    reference_note : str
        Where the reference comes from (source, tolerance, citation).
    conservative : bool
        Record the relative energy drift.
    energy_scale : float, optional
        ``E_ref`` [J] of the relative drift; None uses ``|E(t_0)|``.
    grids : dict of str to Grid
        ``"quick"``, ``"standard"``, ``"full"``.
    atol_scale : float
        ``atol = rtol · atol_scale`` for error-controlled methods.
    newton_tol : float
        ``rtol = atol`` given to fixed-step methods (their Newton tolerance).
    n_output : int
        Output samples (equally spaced, t = 0 and t_end included) for violations and energy.
    method_options : dict of str to dict
        Extra keyword options per method name (e.g. Baumgarte parameters).
    """

    name: str
    title: str
    build_system: Callable[[], Any]
    t_end: float
    reference_fn: Callable[[], Any]
    error_fn: Callable[[Any, np.ndarray, np.ndarray, Any], float]
    error_measure: str
    reference_note: str
    conservative: bool = False
    energy_scale: float | None = None
    grids: Mapping[str, Grid] = field(default_factory=dict)
    atol_scale: float = 1.0
    newton_tol: float = 1e-10
    n_output: int = 21
    method_options: Mapping[str, Mapping[str, Any]] = field(default_factory=dict)

    def __post_init__(self) -> None:
        if not (np.isfinite(self.t_end) and self.t_end > 0):
            raise ValueError(f"problem {self.name!r}: t_end must be > 0, got {self.t_end}")
        missing = [g for g in GRID_NAMES if g not in self.grids]
        if missing:
            raise ValueError(f"problem {self.name!r}: grids {missing} missing (need {list(GRID_NAMES)})")
        if self.n_output < 2:
            raise ValueError(f"problem {self.name!r}: n_output must be ≥ 2, got {self.n_output}")

    def reference(self) -> Any:
        """The reference quantity at ``t_end`` (computed once per process)."""
        try:
            return _REFERENCE_CACHE[self]
        except KeyError:
            ref = self.reference_fn()
            _REFERENCE_CACHE[self] = ref
            return ref

    def error(self, result, system=None, reference=None) -> float:
        """Error of a finished :class:`~core.results.SimulationResult` (NaN if it failed).

        Parameters
        ----------
        result : SimulationResult
        system : ConstrainedSystem, optional
            The system that was integrated (default: a fresh ``build_system()``).
        reference : optional
            The reference quantity (default: :meth:`reference`).
        """
        if result.status != "finished" or abs(float(result.t[-1]) - self.t_end) > 1e-9 * max(1.0, self.t_end):
            return math.nan
        system = self.build_system() if system is None else system
        ref = self.reference() if reference is None else reference
        return float(self.error_fn(system, np.asarray(result.q[-1]), np.asarray(result.v[-1]), ref))

    def grid(self, name: str) -> Grid:
        """The named grid (``"quick"``, ``"standard"`` or ``"full"``)."""
        try:
            return self.grids[name]
        except KeyError:
            raise ValueError(f"problem {self.name!r}: unknown grid {name!r}; use one of {list(self.grids)}") from None


#: Registry of named problems (insertion order is listing order).
PROBLEMS: dict[str, WorkPrecisionProblem] = {}


def register_problem(problem: WorkPrecisionProblem) -> WorkPrecisionProblem:
    """Add a problem to :data:`PROBLEMS` (a different problem under an existing name is an error)."""
    if not isinstance(problem, WorkPrecisionProblem):
        raise TypeError(f"register_problem expects a WorkPrecisionProblem, got {type(problem).__name__}")
    old = PROBLEMS.get(problem.name)
    if old is not None and old is not problem:
        raise ValueError(f"a different work-precision problem named {problem.name!r} is already registered")
    PROBLEMS[problem.name] = problem
    return problem


# ---------------------------------------------------------------------------------------------
# references and error measures (module level: picklable)
# ---------------------------------------------------------------------------------------------


def _chain_system(n: int, spatial: bool = False, stiff_k: float | None = None):
    from .models import n_link_chain

    return n_link_chain(n, spatial=spatial, stiff_k=stiff_k)


def _chain_tip_reference(n: int) -> np.ndarray:
    """Tip (x, y) [m] at t = 1 s from :func:`core.models.n_link_chain_reference` (DOP853, 1e−13)."""
    from .models import n_link_chain_reference

    tip, _ = n_link_chain_reference(n, t_end=1.0)
    return np.asarray(tip, float)


def stiff_chain_rhs(n: int, stiff_k: float, total_length: float = 1.0, total_mass: float = 1.0,
                    gravity: float = G_EARTH) -> Callable[[float, np.ndarray], np.ndarray]:
    r"""Right-hand side of the planar point-spring chain, written independently of :mod:`core.model`.

    State ``y = (x_1..x_N, y_1..y_N, θ_1..θ_N, ẋ.., ẏ.., θ̇..)`` of N uniform links (``L = 1/N``,
    ``m = 1/N``, ``J = m L²/12``).  Joint j joins the tail ``p_j = r_j − (L/2) e_j`` of link j to
    the head ``h_{j−1} = r_{j−1} + (L/2) e_{j−1}`` of link j − 1 (the origin for j = 1) by a
    zero-length spring: ``d_j = p_j − h_{j−1}``, force ``−k d_j`` on link j at ``p_j`` and
    ``+k d_j`` on link j − 1 at ``h_{j−1}``; gravity ``−m g`` along y::

        m r̈_j = −k d_j + k d_{j+1} − m g ŷ
        J θ̈_j = (−(L/2) e_j) × (−k d_j) + ((L/2) e_j) × (k d_{j+1})

    (``d_{N+1} = 0``; × is the planar cross product).  Used by the stiff-chain reference so that
    it shares no code with the model under test.
    """
    L, m = total_length / n, total_mass / n
    J = m * L * L / 12.0
    k = float(stiff_k)

    def rhs(t, y):
        x, yy, th = y[:n], y[n:2 * n], y[2 * n:3 * n]
        c, s = np.cos(th), np.sin(th)
        px, py = x - 0.5 * L * c, yy - 0.5 * L * s  # tails
        hx, hy = x + 0.5 * L * c, yy + 0.5 * L * s  # heads
        dx = px - np.concatenate(([0.0], hx[:-1]))
        dy = py - np.concatenate(([0.0], hy[:-1]))
        fx_t, fy_t = -k * dx, -k * dy  # force on link j at its tail
        fx_h = np.concatenate((-fx_t[1:], [0.0]))  # force on link j at its head (reaction of joint j+1)
        fy_h = np.concatenate((-fy_t[1:], [0.0]))
        ax = (fx_t + fx_h) / m
        ay = (fy_t + fy_h) / m - gravity
        # torques: arm × F with arms −(L/2) e (tail) and +(L/2) e (head)
        tq = 0.5 * L * (-(c * fy_t - s * fx_t) + (c * fy_h - s * fx_h))
        return np.concatenate((y[3 * n:], ax, ay, tq / J))

    return rhs


def _stiff_chain_tip_reference(n: int, stiff_k: float, t_end: float = 1.0, rtol: float = 1e-12) -> np.ndarray:
    r"""Tip [m] at ``t_end`` of the stiff (point-spring) chain by scipy DOP853, ``rtol = atol = 1e−12``.

    The stiff chain is an unconstrained ODE; it is integrated from the initial state of
    :func:`core.models.n_link_chain` (links along +x at rest, springs unstretched) with the
    independent right-hand side :func:`stiff_chain_rhs`.  The springs are undamped, so the
    reference resolves the high-frequency spring oscillations (amplitude O(m g / k)); the
    rigid-chain reference differs from it by O(m g / k) and is not used.
    """
    from scipy.integrate import solve_ivp

    L = 1.0 / n
    y0 = np.zeros(6 * n)
    y0[:n] = (np.arange(n) + 0.5) * L
    sol = solve_ivp(stiff_chain_rhs(n, stiff_k), (0.0, t_end), y0, method="DOP853", rtol=rtol, atol=rtol)
    if sol.status != 0:
        raise RuntimeError(f"stiff chain reference (n={n}, k={stiff_k:g}) failed: {sol.message}")
    th = sol.y[2 * n:3 * n, -1]
    return np.array([sol.y[n - 1, -1] + 0.5 * L * np.cos(th[-1]), sol.y[2 * n - 1, -1] + 0.5 * L * np.sin(th[-1])])


def _chain_tip_error(system, q, v, tip_ref) -> float:
    from .models import chain_tip

    return float(np.linalg.norm(chain_tip(system, q) - tip_ref))


def pendulum_angle_exact(t, angle0: float = np.pi / 2, length: float = 1.0, gravity: float = G_EARTH):
    r"""Exact angle [rad] from the downward vertical of a pendulum released from rest at ``angle0``.

    .. math::

        \theta(t) = 2 \arcsin\!\big(k\, \mathrm{sn}(K(k) - \omega t,\ k)\big), \qquad
        k = \sin(\theta_0/2),\quad \omega = \sqrt{g/l},

    with ``K`` the complete elliptic integral of the first kind (scipy's parameter
    ``m = k²``).  At ``t = 0``, ``sn(K) = 1`` gives ``θ = θ0``; the period is ``4K/ω``.  The
    argument is reduced modulo the period ``4K`` of ``sn`` before :func:`scipy.special.ellipj`
    is called, so the accuracy does not degrade over long times.

    Parameters
    ----------
    t : float or array_like
        Time [s].
    angle0 : float
        Release angle θ0 [rad], ``0 < θ0 < π``.
    length, gravity : float
        l [m], g [m/s²].

    References
    ----------
    Byrd & Friedman (1971), formula 121.00; Lawden (1989), Sec. 5.2.
    """
    from scipy.special import ellipj, ellipk

    if not 0.0 < angle0 < np.pi:
        raise ValueError(f"pendulum_angle_exact: angle0 must be in (0, π), got {angle0}")
    k = np.sin(angle0 / 2.0)
    m = k * k
    K = ellipk(m)
    omega = np.sqrt(gravity / length)
    u = np.mod(K - omega * np.asarray(t, float), 4.0 * K)
    sn, _, _, _ = ellipj(u, m)
    return 2.0 * np.arcsin(k * sn)


def _pendulum_system():
    from .models import simple_pendulum

    return simple_pendulum(length=1.0, mass=1.0, angle0=np.pi / 2, planar=True, bob="point")


def _pendulum_reference(t_end: float) -> float:
    return float(pendulum_angle_exact(t_end, np.pi / 2, 1.0, G_EARTH))


def _pendulum_angle_error(system, q, v, theta_ref) -> float:
    """|θ − θ_ref| [rad], θ = atan2(x, −y) of the bob (the body's centre of mass)."""
    theta = np.arctan2(q[0], -q[1])
    return float(abs(np.angle(np.exp(1j * (theta - theta_ref)))))


def _andrews_system():
    from .benchmark_problems import AndrewsSqueezer

    return AndrewsSqueezer()


def _andrews_reference() -> np.ndarray:
    from .benchmark_problems import AndrewsSqueezer

    return np.array(AndrewsSqueezer.reference["q"], float)


def _car_axis_system():
    from .benchmark_problems import CarAxis

    return CarAxis()


def _car_axis_reference() -> np.ndarray:
    from .benchmark_problems import CarAxis

    return np.array(CarAxis.reference["q"], float)


def _max_abs_q_error(system, q, v, q_ref) -> float:
    return float(np.max(np.abs(np.asarray(q, float) - q_ref)))


def _andrews_cartesian_system():
    from .models import andrews_cartesian

    return andrews_cartesian()


def _andrews_cartesian_error(system, q, v, q_ref) -> float:
    """Max-abs error of the seven angles recovered from the Cartesian state [rad]."""
    from .models import andrews_angles_from_cartesian

    return float(np.max(np.abs(andrews_angles_from_cartesian(system, np.asarray(q, float)) - q_ref)))


A02_T_END = 1.0


def _a02_system():
    from .models import iftomm_a02_four_bar_chain

    return iftomm_a02_four_bar_chain(n_windows=40, redundant="keep")


def _a02_reference() -> float:
    """Bar angle φ(t_end) [rad] of the equivalent pendulum (minimal coordinate, DOP853 1e-12)."""
    from .models import iftomm_a02_reference

    phi, _ = iftomm_a02_reference(np.array([0.0, A02_T_END]), n_windows=40)
    return float(phi[-1])


def _a02_error(system, q, v, phi_ref) -> float:
    """|φ − φ_ref| [rad] of the first bar (body 'bar0'), through its passage of the horizontal."""
    k = system.body_index("bar0")
    return float(abs(np.angle(np.exp(1j * (q[3 * k + 2] - phi_ref)))))


A04_T_END = 10.0
A04_REFERENCE_TOL = 1e-12


def _a04_system():
    """Bricard's mechanism with its one dependent equation removed (named by ``build``)."""
    from .models import iftomm_a04_bricard

    with warnings.catch_warnings():  # the redundancy warning is the expected, documented one
        warnings.simplefilter("ignore", UserWarning)
        return iftomm_a04_bricard(redundant="remove")


def _a04_tip(system, q) -> np.ndarray:
    """Global position [m] of P2 = (1, −1, 0) m at t = 0, the joint J3 end of rod2."""
    k = system.body_index("rod2")
    q0 = system.q0
    r0 = q0[7 * k:7 * k + 3]
    s = system.body_frame(q0, "rod2").T @ (np.array([1.0, -1.0, 0.0]) - r0)
    return system.point_position(q, "rod2", s)


def _a04_reference() -> np.ndarray:
    """P2 at t = 10 s by the compiled DOP853 with coordinate projection at rtol = atol = 1e-12.

    A converged solution of the same Cartesian model, as the IFToMM library's references are; it is
    cross-checked in ``tests/core/test_workprecision.py`` (slow) against scipy's DOP853 with
    projection driving the numpy right-hand side, and against energy conservation.
    """
    from .integrators import simulate

    system = _a04_system()
    res = simulate(system, (0.0, A04_T_END), "jit-dop853-projection", t_eval=[A04_T_END], rtol=A04_REFERENCE_TOL,
                   atol=A04_REFERENCE_TOL, compute_multipliers=False)
    if res.status != "finished":  # pragma: no cover - the reference run is deterministic
        raise RuntimeError(f"A04 reference run failed: {res.message}")
    return _a04_tip(system, res.q[-1])


def _a04_error(system, q, v, ref) -> float:
    return float(np.linalg.norm(_a04_tip(system, q) - ref))


# ---------------------------------------------------------------------------------------------
# the registry
# ---------------------------------------------------------------------------------------------

#: Methods left out of the standard grid of the costlier problems: the unstabilised and the
#: Baumgarte index-1 variants (their projected counterparts stay) and LSODA (it restarts
#: after every projection, see core.integrators.index1).  Patterns, so integrators registered
#: later are included by default.
_STD_EXCLUDE = ("rk45", "dop853", "radau", "bdf", "lsoda*", "*-baumgarte", "jit-rk45", "jit-dop853")
#: For unconstrained (stiff spring) problems projection and Baumgarte change nothing.
_ODE_EXCLUDE = ("*-projection", "*-baumgarte", "lsoda*")
_QUICK_METHODS = ("rk45-projection", "dop853-projection", "jit-dop853-projection", "radau-projection",
                  "generalized-alpha", "radau-ggl", "hem4")

_CHAIN_NOTE = ("minimal-coordinate ODE of the chain (absolute link angles), scipy DOP853 at rtol = atol = "
               "1e-13 (core.models.n_link_chain_reference; core_benchmarks.md §1)")


def _chain_grids(n: int, spatial: bool) -> dict[str, Grid]:
    full = Grid(rtols=_geom(1e-3, 1e-10, 1), steps=_geom(1e-2, 1e-4, 2) if n < 32 else _geom(2e-3, 1e-4, 2))
    if n <= 2 and not spatial:  # the showcase: every integrator family, four decades
        std = Grid(rtols=(1e-3, 1e-5, 1e-7, 1e-9), steps=(1e-2, 3e-3, 1e-3), exclude=("lsoda*",))
        quick = Grid(rtols=(1e-3, 1e-6), steps=(1e-2, 3e-3), methods=_QUICK_METHODS)
    elif n <= 8:
        std = Grid(rtols=(1e-3, 1e-5, 1e-7), steps=(1e-2, 3e-3, 1e-3), exclude=_STD_EXCLUDE)
        quick = Grid(rtols=(1e-4, 1e-7), steps=(3e-3,), methods=_QUICK_METHODS)
    else:
        std = Grid(rtols=(1e-4, 1e-6), steps=(1e-3,),
                   methods=("dop853-projection", "jit-dop853-projection", "generalized-alpha", "hem4"))
        quick = Grid(rtols=(1e-5,), steps=(1e-3,), methods=("dop853-projection", "generalized-alpha"))
    return {"quick": quick, "standard": std, "full": full}


def _stiff_grids(k: float) -> dict[str, Grid]:
    full = Grid(rtols=_geom(1e-3, 1e-10, 1), steps=_geom(1e-2, 1e-5, 1), exclude=("*-projection", "*-baumgarte"))
    std = Grid(rtols=(1e-3, 1e-6), steps=(1e-2, 1e-3),
               exclude=_ODE_EXCLUDE if k < 1e7 else _ODE_EXCLUDE + ("rk45", "dop853"))
    quick = Grid(rtols=(1e-4,), steps=(1e-3,), methods=("radau", "bdf", "generalized-alpha"))
    return {"quick": quick, "standard": std, "full": full}


def _build_registry() -> None:
    for n in (2, 8, 32):
        for spatial in (False, True):
            kind = "spatial" if spatial else "planar"
            register_problem(WorkPrecisionProblem(
                name=f"chain{n}-{kind}",
                title=f"N-link whip chain, N = {n}, {kind} ({'Euler parameters, ' if spatial else ''}t = 1 s)",
                build_system=partial(_chain_system, n, spatial),
                t_end=1.0,
                reference_fn=partial(_chain_tip_reference, n),
                error_fn=_chain_tip_error,
                error_measure="|tip - tip_ref| [m]",
                reference_note=_CHAIN_NOTE,
                conservative=True,
                energy_scale=0.5 * 1.0 * G_EARTH * 1.0,  # m g L/2: potential energy drop of the hanging chain
                grids=_chain_grids(n, spatial),
            ))
    for k in (1e4, 1e6, 1e8):
        for n in (2, 8):
            register_problem(WorkPrecisionProblem(
                name=f"chain{n}-stiff-k{k:.0e}".replace("+0", ""),
                title=f"N-link chain, N = {n}, joints replaced by point springs k = {k:.0e} N/m (t = 1 s)",
                build_system=partial(_chain_system, n, False, k),
                t_end=1.0,
                reference_fn=partial(_stiff_chain_tip_reference, n, k),
                error_fn=_chain_tip_error,
                error_measure="|tip - tip_ref| [m]",
                reference_note=("the same stiff chain integrated by scipy DOP853 at rtol = atol = 1e-12 with an "
                                "independent right-hand side (core.workprecision.stiff_chain_rhs); the rigid-chain "
                                "reference differs from it by O(m g / k) and is not used"),
                conservative=True,
                energy_scale=0.5 * 1.0 * G_EARTH * 1.0,
                grids=_stiff_grids(k),
            ))
    # one grid for both Andrews models, so that their tables compare like with like
    andrews_grids = {"quick": Grid(rtols=(1e-4,), steps=(3e-5,), methods=_QUICK_METHODS),
                     "standard": Grid(rtols=(1e-3, 1e-5, 1e-7), steps=(1e-4, 3e-5, 1e-5), exclude=_STD_EXCLUDE),
                     "full": Grid(rtols=_geom(1e-3, 1e-10, 1), steps=_geom(1e-4, 1e-6, 2))}
    register_problem(WorkPrecisionProblem(
        name="andrews",
        title="Andrews' squeezing mechanism, seven-angle index-3 DAE (t = 0.03 s)",
        build_system=_andrews_system,
        t_end=0.03,
        reference_fn=_andrews_reference,
        error_fn=_max_abs_q_error,
        error_measure="max_k |q_k - q_k,ref| over the 7 angles [rad]",
        reference_note=("published solution at t = 0.03 s: Mazzia & Magherini, Test Set for IVP Solvers 2.4 "
                        "(2008), andrews.f, subroutine andsoln (PSIDE, rtol = atol = 1e-14); "
                        "core.benchmark_problems.AndrewsSqueezer.reference"),
        conservative=True,
        grids=andrews_grids,
    ))
    register_problem(WorkPrecisionProblem(
        name="andrews-cartesian",
        title="Andrews' squeezing mechanism as a Cartesian model of the same seven bodies (t = 0.03 s)",
        build_system=_andrews_cartesian_system,
        t_end=0.03,
        reference_fn=_andrews_reference,
        error_fn=_andrews_cartesian_error,
        error_measure="max_k |angle_k - angle_k,ref| over the 7 angles [rad]",
        reference_note=("published solution at t = 0.03 s (Test Set for IVP Solvers 2.4, andrews.f), compared "
                        "through core.models.andrews_angles_from_cartesian"),
        conservative=True,
        grids=andrews_grids,
    ))
    register_problem(WorkPrecisionProblem(
        name="iftomm-a02",
        title="IFToMM A02: 40-window four-bar chain through its singular (horizontal) configuration, t = 1 s",
        build_system=_a02_system,
        t_end=A02_T_END,
        reference_fn=_a02_reference,
        error_fn=_a02_error,
        error_measure="|phi - phi_ref| of bar 0 [rad]",
        reference_note=("equivalent-pendulum ODE [(N+1)/3 + N] L phi'' = -g cos(phi) [(N+1)/2 + N] integrated by "
                        "DOP853 at 1e-12 (core.models.iftomm_a02_reference); the bars pass the horizontal at "
                        "t = 0.72 s, where the number of degrees of freedom jumps"),
        conservative=True,
        grids={"quick": Grid(rtols=(1e-4,), steps=(2e-3,), methods=("rk45-projection", "generalized-alpha")),
               "standard": Grid(rtols=(1e-4, 1e-6), steps=(4e-3, 2e-3, 1e-3),
                                methods=("rk45-projection", "dop853-projection", "radau-ggl", "generalized-alpha")),
               "full": Grid(rtols=_geom(1e-3, 1e-8, 1), steps=_geom(4e-3, 2.5e-4, 2))},
    ))
    register_problem(WorkPrecisionProblem(
        name="iftomm-a04",
        title="IFToMM A04: Bricard's over-constrained 6R mechanism under gravity (dependent row removed), t = 10 s",
        build_system=_a04_system,
        t_end=A04_T_END,
        reference_fn=_a04_reference,
        error_fn=_a04_error,
        error_measure="|P2 - P2_ref|, P2 the rod2/rod3 joint (1, -1, 0) m at t = 0 [m]",
        reference_note=(f"converged run of the same model: compiled DOP853 with coordinate projection at rtol = atol "
                        f"= {A04_REFERENCE_TOL:g}, cross-checked against scipy DOP853 + projection on the numpy "
                        "right-hand side (tests); energy is conserved (IFToMM A04)"),
        conservative=True,
        grids={"quick": Grid(rtols=(1e-5,), steps=(1e-2,), methods=("jit-dop853-projection", "generalized-alpha")),
               "standard": Grid(rtols=(1e-4, 1e-6, 1e-8), steps=(1e-2, 3e-3),
                                methods=("dop853-projection", "jit-dop853-projection", "jit-rk45-projection",
                                         "radau-ggl", "generalized-alpha")),
               "full": Grid(rtols=_geom(1e-3, 1e-10, 1), steps=_geom(1e-2, 1e-3, 2))},
    ))
    register_problem(WorkPrecisionProblem(
        name="car-axis",
        title="Car axis, index-3 stiff DAE with a moving support (t = 3)",
        build_system=_car_axis_system,
        t_end=3.0,
        reference_fn=_car_axis_reference,
        error_fn=_max_abs_q_error,
        error_measure="max_k |q_k - q_k,ref| over (xl, yl, xr, yr) [m]",
        reference_note=("published solution at t = 3: Mazzia & Magherini, Test Set for IVP Solvers 2.4 (2008), "
                        "caraxis.f, subroutine soln; core.benchmark_problems.CarAxis.reference"),
        conservative=False,
        grids={"quick": Grid(rtols=(1e-4,), steps=(3e-3,), methods=_QUICK_METHODS),
               "standard": Grid(rtols=(1e-3, 1e-5, 1e-7), steps=(1e-2, 3e-3, 1e-3), exclude=_STD_EXCLUDE),
               "full": Grid(rtols=_geom(1e-3, 1e-10, 1), steps=_geom(1e-2, 1e-4, 2))},
    ))
    register_problem(WorkPrecisionProblem(
        name="pendulum-100s",
        title="Simple pendulum (IFToMM A01: 1 kg point mass, 1 m massless link, from horizontal), t = 100 s",
        build_system=_pendulum_system,
        t_end=100.0,
        reference_fn=partial(_pendulum_reference, 100.0),
        error_fn=_pendulum_angle_error,
        error_measure="|theta - theta_exact| at t_end [rad]",
        reference_note=("exact solution theta(t) = 2 asin(k sn(K - w t, k)), k = sin(theta0/2), w = sqrt(g/l) "
                        "(Byrd & Friedman 1971, 121.00), evaluated by scipy.special.ellipj; energy E(0) = 0, "
                        "drift relative to m g l"),
        conservative=True,
        energy_scale=1.0 * G_EARTH * 1.0,
        n_output=101,
        grids={"quick": Grid(rtols=(1e-5,), steps=(1e-2,), methods=("dop853-projection", "generalized-alpha")),
               "standard": Grid(rtols=(1e-4, 1e-7), steps=(1e-2,),
                                methods=("rk45", "dop853-projection", "generalized-alpha", "hht", "hem4")),
               "full": Grid(rtols=_geom(1e-3, 1e-10, 1), steps=_geom(1e-2, 1e-3, 2))},
    ))


_build_registry()

#: Named problem sets: "quick" for CI, "standard" for the report (`make run`), "full" = all.
PROBLEM_SETS: dict[str, list[str]] = {
    "quick": ["chain2-planar", "chain8-planar", "chain2-stiff-k1e4", "andrews", "car-axis", "pendulum-100s"],
    # chain*-stiff-k1e8 is in "full" only: its resolved reference alone takes 1-2 min (DOP853 must
    # follow the undamped 2.8e4 rad/s spring oscillation at 1e-12)
    "standard": ["chain2-planar", "chain8-planar", "chain2-spatial", "chain32-planar",
                 "chain2-stiff-k1e4", "chain2-stiff-k1e6", "chain8-stiff-k1e6", "andrews", "car-axis",
                 "pendulum-100s", "iftomm-a04"],
}


def _problem_sets() -> dict[str, list[str]]:
    return {**PROBLEM_SETS, "full": list(PROBLEMS)}


def _resolve_problem(problem: str | WorkPrecisionProblem) -> WorkPrecisionProblem:
    if isinstance(problem, WorkPrecisionProblem):
        return problem
    if isinstance(problem, str) and problem in PROBLEMS:
        return PROBLEMS[problem]
    raise ValueError(f"unknown work-precision problem {problem!r}; registered: {', '.join(PROBLEMS)}")


# ---------------------------------------------------------------------------------------------
# one run (a sweep case) -> one row
# ---------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class _Case:
    problem: WorkPrecisionProblem
    method: str
    kind: str
    value: float
    rtol: float
    atol: float
    h: float | None
    repeats: int
    max_repeat_time: float
    reference: Any


def _row_template(case: _Case) -> dict[str, Any]:
    row: dict[str, Any] = {c: math.nan for c in COLUMNS}
    row.update({
        "problem": case.problem.name, "method": case.method, "setting kind": case.kind,
        "setting value": case.value, "rtol": case.rtol, "atol": case.atol,
        "error measure": case.problem.error_measure, "n repeats": 0, "status": "failed", "message": "",
    })
    for c in COUNTERS:
        row[c] = 0
    return row


def _run_case(case: _Case) -> dict[str, Any]:
    """Run one (problem, method, setting) ``repeats`` times; return its table row."""
    from .integrators import simulate

    _load_integrators()
    prob = case.problem
    row = _row_template(case)
    try:
        system = prob.build_system()
    except Exception as exc:  # noqa: BLE001 - reported in the row
        row["message"] = f"building the system failed: {type(exc).__name__}: {exc}"
        return row
    reason = _load_integrators()[case.method].applicable(system)
    if reason is not None:
        row["status"] = NOT_APPLICABLE
        row["message"] = reason
        return row
    options = dict(prob.method_options.get(case.method, {}))
    t_eval = np.linspace(0.0, prob.t_end, prob.n_output)
    walls: list[float] = []
    result = None
    for _ in range(max(1, case.repeats)):
        try:
            with np.errstate(all="ignore"):  # diverging runs overflow; they are reported, not warned about
                result = simulate(system, (0.0, prob.t_end), case.method, t_eval=t_eval, rtol=case.rtol,
                                  atol=case.atol, h=case.h, progress=False, compute_multipliers=False,
                                  **options)
        except Exception as exc:  # noqa: BLE001 - a run that cannot start is a failed row
            row["message"] = f"{type(exc).__name__}: {exc}"
            return row
        walls.append(float(result.meta["wall_time_s"]))
        if result.status != "finished" or sum(walls) >= case.max_repeat_time:
            break
    assert result is not None
    row["wall time [s]"] = statistics.median(walls)
    row["n repeats"] = len(walls)
    row["status"] = result.status
    row["message"] = result.message
    row["t reached [s]"] = float(result.meta.get("t_end_reached", result.t[-1]))
    for c in COUNTERS:
        row[c] = int(result.counters.get(c, 0))
    with np.errstate(all="ignore"):
        pv = np.asarray(result.position_violation, float)
        vv = np.asarray(result.velocity_violation, float)
        row["max position violation [m]"] = float(np.max(pv)) if pv.size else math.nan
        row["max velocity violation [m/s]"] = float(np.max(vv)) if vv.size else math.nan
        row["final position violation [m]"] = float(pv[-1]) if pv.size else math.nan
        row["final velocity violation [m/s]"] = float(vv[-1]) if vv.size else math.nan
        if prob.conservative and result.energy is not None:
            E = np.asarray(result.energy, float)
            scale = prob.energy_scale if prob.energy_scale is not None else abs(E[0])
            row["energy drift [-]"] = float(np.max(np.abs(E - E[0])) / scale) if scale > 0 else math.nan
    if result.status == "finished":
        try:
            err = prob.error(result, system=system, reference=case.reference)
        except Exception as exc:  # noqa: BLE001
            err = math.nan
            row["message"] = f"{result.message}; error measure failed: {type(exc).__name__}: {exc}"
        row["error"] = err
    return row


# ---------------------------------------------------------------------------------------------
# the sweep
# ---------------------------------------------------------------------------------------------


def _grid_from(problem: WorkPrecisionProblem, settings) -> Grid:
    if settings is None:
        return problem.grid("standard")
    if isinstance(settings, str):
        return problem.grid(settings)
    if isinstance(settings, Grid):
        return settings
    if isinstance(settings, Mapping):
        unknown = set(settings) - {"rtol", "rtols", "h", "steps", SETTING_STEP}
        if unknown:
            raise ValueError(f"settings: unknown key(s) {sorted(unknown)}; use 'rtol' and/or 'h'")
        rt = settings.get("rtol", settings.get("rtols", ()))
        st = settings.get("h", settings.get("steps", settings.get(SETTING_STEP, ())))
        base = problem.grid("standard")
        return Grid(rtols=tuple(np.atleast_1d(rt)) if rt is not None else base.rtols,
                    steps=tuple(np.atleast_1d(st)) if st is not None else base.steps)
    raise TypeError(f"settings must be None, a grid name, a Grid or a mapping, got {type(settings).__name__}")


def _cases(problem: WorkPrecisionProblem, methods, grid: Grid, repeats: int, max_repeat_time: float,
           reference) -> list[_Case]:
    registry = _load_integrators()
    if methods is None:
        names = grid.select(list(registry))
    else:
        names = [methods] if isinstance(methods, str) else list(methods)
        unknown = [m for m in names if m not in registry]
        if unknown:
            raise ValueError(f"unknown integrator(s) {unknown}; registered: {sorted(registry)}")
    cases = []
    for m in dict.fromkeys(names):
        cls = registry[m]
        if cls.fixed_step:
            for h in grid.steps:
                cases.append(_Case(problem, m, SETTING_STEP, h, problem.newton_tol, problem.newton_tol, h,
                                   repeats, max_repeat_time, reference))
        else:
            for rt in grid.rtols:
                cases.append(_Case(problem, m, SETTING_RTOL, rt, rt, rt * problem.atol_scale, None,
                                   repeats, max_repeat_time, reference))
    return cases


def run_work_precision(problem: str | WorkPrecisionProblem, methods: str | Sequence[str] | None = None,
                       settings: str | Grid | Mapping | None = None, repeats: int = 3,
                       executor: Executor | None = None, progress: bool = False,
                       max_repeat_time: float = 2.0) -> pd.DataFrame:
    """Run ``problem`` with every method over a grid of settings; one row per (method, setting).

    Parameters
    ----------
    problem : str or WorkPrecisionProblem
        A name of :data:`PROBLEMS` or a problem object.
    methods : str or sequence of str, optional
        Integrator names; default the grid's selection among all registered integrators.
    settings : str, Grid or mapping, optional
        A grid name (``"quick"``, ``"standard"`` (default), ``"full"``), a :class:`Grid`, or
        ``{"rtol": [...], "h": [...]}`` (rtols for error-controlled, steps [s] for fixed-step
        methods).
    repeats : int
        Solves per case; the wall time is their median.  A case stops repeating once its
        solves took ``max_repeat_time`` seconds in total (column ``n repeats`` says how many ran).
    executor : concurrent.futures.Executor, optional
        Where the cases run (:func:`core.sweep.run_sweep`); None = serially in this process.
    progress : bool
        Progress bar over cases.
    max_repeat_time : float
        [s], see ``repeats``.

    Returns
    -------
    pandas.DataFrame
        Columns :data:`COLUMNS`; ``attrs`` hold the problem's title, error measure, reference
        note and the grid.
    """
    from .sweep import run_sweep

    prob = _resolve_problem(problem)
    if int(repeats) < 1:
        raise ValueError(f"repeats must be ≥ 1, got {repeats}")
    grid = _grid_from(prob, settings)
    cases = _cases(prob, methods, grid, int(repeats), float(max_repeat_time), prob.reference())
    rows = run_sweep(_run_case, cases, executor=executor, progress=progress)
    return _frame(prob, grid, rows)


def _frame(prob: WorkPrecisionProblem, grid: Grid, rows: list[dict]) -> pd.DataFrame:
    # methods that cannot integrate this system at all (Integrator.applicable) are left out of the table
    df = pd.DataFrame([r for r in rows if r["status"] != NOT_APPLICABLE], columns=COLUMNS)
    for c in (*COUNTERS, "n repeats"):
        df[c] = df[c].astype(int)
    df.attrs.update(problem=prob.name, title=prob.title, error_measure=prob.error_measure,
                    reference=prob.reference_note, t_end=prob.t_end, grid=dataclasses.asdict(grid))
    return df


def run_problems(problems: Iterable[str | WorkPrecisionProblem], **kwargs) -> pd.DataFrame:
    """:func:`run_work_precision` for several problems, concatenated into one tidy table."""
    frames = [run_work_precision(p, **kwargs) for p in problems]
    if not frames:
        return pd.DataFrame(columns=COLUMNS)
    return pd.concat(frames, ignore_index=True)


# ---------------------------------------------------------------------------------------------
# summaries, figures, files
# ---------------------------------------------------------------------------------------------


def fastest_to_tolerance(df: pd.DataFrame, targets: Sequence[float] = (1e-2, 1e-4, 1e-6, 1e-8)) -> pd.DataFrame:
    """Per problem and error target: the fastest finished run whose error is at most the target.

    The IFToMM benchmark scores software by the CPU time needed for a given precision
    (González et al. 2006); this is that score over all methods and settings of the table.

    Returns
    -------
    pandas.DataFrame
        Columns ``problem, target error, method, setting kind, setting value, error,
        wall time [s]``; a target no run reached has ``method = "none"``.
    """
    out = []
    ok = df[(df["status"] == "finished") & np.isfinite(df["error"])]
    for prob in dict.fromkeys(df["problem"]):
        sub = ok[ok["problem"] == prob]
        for tgt in targets:
            hit = sub[sub["error"] <= tgt]
            if len(hit):
                best = hit.loc[hit["wall time [s]"].idxmin()]
                out.append({"problem": prob, "target error": tgt, "method": best["method"],
                            "setting kind": best["setting kind"], "setting value": best["setting value"],
                            "error": best["error"], "wall time [s]": best["wall time [s]"]})
            else:
                out.append({"problem": prob, "target error": tgt, "method": "none", "setting kind": "",
                            "setting value": math.nan, "error": math.nan, "wall time [s]": math.nan})
    return pd.DataFrame(out, columns=["problem", "target error", "method", "setting kind", "setting value",
                                      "error", "wall time [s]"])


def work_precision_figure(df: pd.DataFrame, problem: str | None = None, ax=None):
    """Log-log work-precision diagram of one problem: error against median wall time.

    One line per method (points of finished runs in order of tightening setting, drawn by
    :func:`core.plot.plot_work_precision`); failed runs -- and finished runs whose error is
    not finite -- are drawn as ``x`` markers at their wall time on a "failed" band right of
    the largest error, so they cannot be mistaken for results.

    Parameters
    ----------
    df : pandas.DataFrame
        Table of :func:`run_work_precision` (or several concatenated; then give ``problem``).
    problem : str, optional
        Which problem to draw; required when ``df`` holds more than one.
    ax : matplotlib.axes.Axes, optional

    Returns
    -------
    matplotlib.figure.Figure
    """
    from .plot import _axes, plot_work_precision

    probs = list(dict.fromkeys(df["problem"]))
    if problem is None:
        if len(probs) != 1:
            raise ValueError(f"work_precision_figure: the table holds problems {probs}; pass problem=")
        problem = probs[0]
    elif problem not in probs:
        raise ValueError(f"work_precision_figure: problem {problem!r} not in the table ({probs})")
    sub = df[df["problem"] == problem]
    good = sub[(sub["status"] == "finished") & np.isfinite(sub["error"]) & (sub["error"] > 0)
               & (sub["wall time [s]"] > 0)]
    bad = sub.drop(good.index)
    fig, ax = _axes(ax, figsize=(7.5, 5.0))
    colours: dict[str, Any] = {}
    if len(good):
        plot_work_precision(good, "wall time [s]", "error", "method", ax=ax)
        for line in ax.get_lines():
            colours[line.get_label()] = line.get_color()
    else:
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("error")
        ax.set_ylabel("wall time [s]")
    measure = sub["error measure"].iloc[0] if len(sub) else "error"
    ax.set_xlabel(f"error: {measure}")
    ax.set_ylabel("median wall time of the solve [s]")
    if len(bad):
        x_fail = 10.0 * (float(good["error"].max()) if len(good) else 1.0)
        tmax = bad["wall time [s]"].where(bad["wall time [s]"] > 0)
        y_default = float(good["wall time [s]"].min()) if len(good) else 1e-3
        for meth, grp in bad.groupby("method", sort=False):
            y = tmax.loc[grp.index].fillna(y_default).to_numpy()
            ax.plot(np.full(len(y), x_fail), y, linestyle="none", marker="x", markersize=9,
                    color=colours.get(meth, "k"), label=f"{meth} (failed)")
        ax.axvline(x_fail / 3.0, color="0.6", linestyle=":", linewidth=1)
        ax.annotate("failed", xy=(x_fail, 1.0), xycoords=("data", "axes fraction"), ha="center", va="top",
                    fontsize=8, color="0.3")
    ax.set_title(f"{problem}: error vs. run time", fontsize=10)
    ax.legend(fontsize=7, ncol=2 if sub["method"].nunique() > 8 else 1, title="method", title_fontsize=8)
    ax.grid(True, which="both", alpha=0.3)
    return fig


def _markdown_table(df: pd.DataFrame) -> pd.DataFrame:
    """The table with shortened messages (full text stays in the CSV)."""
    out = df.copy()
    out["message"] = out["message"].astype(str).str.slice(0, 120)
    return out


def write_work_precision(df: pd.DataFrame, out_dir: str | Path, prefix: str = "wp") -> dict[str, dict[str, Path]]:
    """Write ``<prefix>_<problem>.csv/.md/.png`` per problem and ``<prefix>_summary.csv/.md``.

    Returns
    -------
    dict
        ``{problem: {"csv": path, "md": path, "png": path}, "summary": {...}}``.
    """
    from .plot import save_figure
    from .results import write_table

    out = Path(out_dir)
    written: dict[str, dict[str, Path]] = {}
    for prob in dict.fromkeys(df["problem"]):
        sub = df[df["problem"] == prob].reset_index(drop=True)
        stem = f"{prefix}_{prob}"
        paths = write_table(sub, out, stem)
        md = _markdown_table(sub).to_markdown(index=False, floatfmt=".3g")
        paths["md"].write_text(md + "\n", encoding="utf-8")
        paths["png"] = save_figure(work_precision_figure(sub), out, stem)
        written[prob] = paths
    summary = fastest_to_tolerance(df)
    written["summary"] = write_table(summary, out, f"{prefix}_summary", floatfmt=".3g")
    return written


# ---------------------------------------------------------------------------------------------
# scenes and command line
# ---------------------------------------------------------------------------------------------


def _default_jobs() -> int:
    import os

    env = os.environ.get("MBSUITE_JOBS")
    if env:
        return max(1, int(env))
    return max(1, min(2, os.cpu_count() or 1))


def _reference_of(problem: WorkPrecisionProblem) -> Any:
    return problem.reference_fn()


def _run_set(problems: Sequence[str], grid: str, methods=None, repeats: int = 3, jobs: int = 1,
             progress: bool = False, report: Callable[[str], None] | None = None,
             max_repeat_time: float = 2.0) -> pd.DataFrame:
    """Run several problems as one sweep (so a process pool stays busy across problems)."""
    from concurrent.futures import ProcessPoolExecutor

    from .sweep import run_sweep

    probs = [_resolve_problem(name) for name in problems]
    executor = ProcessPoolExecutor(max_workers=jobs) if jobs > 1 else None
    try:
        if report is not None:
            report(f"computing the references of {len(probs)} problem(s)")
        missing = [p for p in probs if p not in _REFERENCE_CACHE]
        for p, ref in zip(missing, run_sweep(_reference_of, missing, executor=executor)):
            _REFERENCE_CACHE[p] = ref
        plan = []
        all_cases: list[_Case] = []
        for prob in probs:
            g = prob.grid(grid)
            cases = _cases(prob, methods, g, repeats, max_repeat_time, prob.reference())
            plan.append((prob, g, len(all_cases), len(cases)))
            all_cases += cases
        if report is not None:
            report(f"{len(all_cases)} runs of {len(plan)} problem(s) on {jobs} process(es)")
        rows = run_sweep(_run_case, all_cases, executor=executor, progress=progress)
    finally:
        if executor is not None:
            executor.shutdown()
    frames = []
    for prob, g, start, n in plan:
        df = _frame(prob, g, rows[start:start + n])
        if report is not None:
            report(f"{prob.name}: {n} runs, {int((df['status'] != 'finished').sum())} failed")
        frames.append(df)
    return pd.concat(frames, ignore_index=True) if frames else pd.DataFrame(columns=COLUMNS)


def _scene_notes(problems: Sequence[str], grid: str, jobs: int) -> str:
    lines = [f"Grid `{grid}`; {jobs} worker process(es) (solves run concurrently when > 1, which may "
             "inflate wall times slightly). Wall time = median over repeats of the time inside the "
             "integrator steps. Fixed-step methods: Newton tolerance rtol = atol = 1e-10; "
             "error-controlled methods: atol = rtol.", "", "| problem | error measure | reference |", "|---|---|---|"]
    for name in problems:
        p = PROBLEMS[name]
        lines.append(f"| {name} | {p.error_measure} | {p.reference_note} |")
    return "\n".join(lines)


def _work_precision_scene_run(ctx) -> Any:
    from .scenes import SceneResult

    grid = "quick" if ctx.fast else "standard"
    problems = PROBLEM_SETS[grid]
    jobs = _default_jobs()
    df = _run_set(problems, grid, repeats=1 if ctx.fast else 3, jobs=jobs)
    tables = {f"wp_{p}": df[df["problem"] == p].reset_index(drop=True) for p in problems}
    tables["wp_summary"] = fastest_to_tolerance(df)
    figures = {f"wp_{p}": work_precision_figure(df, p) for p in problems}
    return SceneResult(tables=tables, figures=figures, notes=_scene_notes(problems, grid, jobs))


def work_precision_scenes() -> list:
    """Scenes of the harness (for :func:`core.scenes.register_scene`): ``work-precision``.

    ``work-precision`` runs the ``standard`` problem set on the ``standard`` grids (``--fast``:
    the ``quick`` set and grids, one repeat), on ``MBSUITE_JOBS`` (default min(2, cores))
    worker processes, and writes one table and one figure per problem plus the
    fastest-to-tolerance summary.
    """
    from .scenes import Scene

    return [Scene(
        name="work-precision",
        title="Work-precision: error against run time for every integrator",
        description=("Every registered integrator on the benchmark problems of core_benchmarks.md (N-link "
                     "chain rigid/spatial/stiff, Andrews' squeezer, car axis, 100-s pendulum) over tolerance "
                     "or step-size grids: error against median wall time, constraint violations, energy "
                     "drift, counters and status (core.workprecision)."),
        run=_work_precision_scene_run,
    )]


def _cmd_bench(args) -> int:
    import sys
    import time

    if args.list:
        sets = _problem_sets()
        width = max(len(n) for n in PROBLEMS)
        for name, p in PROBLEMS.items():
            tags = ",".join(s for s in ("quick", "standard") if name in sets[s]) or "-"
            print(f"{name:<{width}}  [{tags}]  {p.title}")
        print("\nsets: " + "; ".join(f"{k}: {len(v)} problems" for k, v in sets.items()))
        print("methods: " + ", ".join(available_methods()))
        return 0
    grid = "quick" if args.quick else ("full" if args.full else "standard")
    names = list(args.problems) or _problem_sets()[grid]
    expanded: list[str] = []
    sets = _problem_sets()
    for n in names:
        if n in sets:
            expanded += sets[n]
        elif n in PROBLEMS:
            expanded.append(n)
        else:
            matches = [p for p in PROBLEMS if fnmatch.fnmatchcase(p, n)]
            if not matches:
                args._parser.error(f"unknown problem {n!r}; see `mbsuite bench --list`")
            expanded += matches
    expanded = list(dict.fromkeys(expanded))
    methods = None
    if args.methods:
        methods = [m for item in args.methods for m in item.split(",") if m]
        registry = available_methods()
        unknown = [m for m in methods if m not in registry]
        if unknown:
            args._parser.error(f"unknown method(s) {unknown}; registered: {', '.join(registry)}")
    start = time.perf_counter()
    df = _run_set(expanded, grid, methods=methods, repeats=args.repeats, jobs=args.jobs, progress=True,
                  report=lambda s: print(s, file=sys.stderr))
    written = write_work_precision(df, args.out)
    summary = fastest_to_tolerance(df)
    print(summary.to_markdown(index=False, floatfmt=".3g"))
    print(f"mbsuite bench: {len(df)} runs of {len(expanded)} problem(s) in {time.perf_counter() - start:.1f} s "
          f"-> {args.out} ({len(written) - 1} tables + figures, summary)")
    return 0


def register_bench_command(subparsers) -> None:
    """Add ``mbsuite bench`` to an argparse sub-parser collection."""
    p = subparsers.add_parser(
        "bench", help="work-precision benchmark: error vs run time of every integrator",
        description=("Run benchmark problems with every integrator over tolerance / step-size grids and write "
                     "<out>/wp_<problem>.csv/.md/.png and wp_summary.csv/.md. PROBLEM may be a problem name, a "
                     "glob (chain*), or a set name (quick, standard, full); default: the standard set "
                     "(--quick: the quick set)."))
    p.add_argument("problems", nargs="*", metavar="PROBLEM", help="problem names, globs or sets (see --list)")
    p.add_argument("--list", action="store_true", help="list problems, sets and registered methods")
    p.add_argument("--methods", nargs="+", metavar="METHOD", help="integrator names (default: the grid's)")
    p.add_argument("--repeats", type=int, default=3, help="solves per case; wall time = median (default 3)")
    g = p.add_mutually_exclusive_group()
    g.add_argument("--quick", action="store_true", help="CI-sized grids (about a minute for the quick set)")
    g.add_argument("--full", action="store_true", help="full grids: every method, rtol 1e-3..1e-10 (long)")
    p.add_argument("-j", "--jobs", type=int, default=1, help="worker processes (default 1: serial)")
    p.add_argument("-o", "--out", default="out/bench", help="output folder (default: %(default)s)")
    p.set_defaults(func=_cmd_bench, _parser=p)
