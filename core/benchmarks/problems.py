r"""Work-precision problems: :class:`WorkPrecisionProblem`, its grids, the registry and the problem sets.

A problem names a system to integrate over ``[0, t_end]``, a reference quantity at ``t_end``
(from :mod:`core.benchmarks.references` or a published solution of
:mod:`core.benchmarks.testset`), an error measure, and three grids of settings (:class:`Grid`):
``"quick"`` (CI, about a minute for the quick problem set), ``"standard"`` (the report of
``make run``, about ten minutes on two cores for the standard set) and ``"full"`` (every method,
rtol 1e−3 … 1e−10, long runs included).  Error-controlled methods get ``rtol`` from the grid and
``atol = rtol · atol_scale`` (:attr:`~WorkPrecisionProblem.atol_scale`, 1 for every registered
problem: their coordinates are O(0.1–10) m or rad); fixed-step methods get the step ``h [s]``.

Problems are looked up by name in :data:`PROBLEMS`, a :class:`core.registry.Registry`: an
unknown name raises :class:`core.errors.UnknownNameError` listing the registered ones, a
different problem under a taken name :class:`core.errors.NameTakenError`.  :data:`PROBLEM_SETS`
names the "quick" and "standard" selections ("full" is every problem).

Adding a problem is one entry: build a :class:`WorkPrecisionProblem` from module-level
(picklable) functions and call :func:`register_problem`.

References
----------
E. Hairer, G. Wanner, *Solving Ordinary Differential Equations II*, 2nd ed., Springer, 1996,
Sec. IV.10 (work-precision diagrams) and Sec. VII.7 (Andrews' squeezer, car axis).
F. Mazzia, C. Magherini, *Test Set for Initial Value Problem Solvers*, release 2.4, University of
Bari, 2008 (problems "andrews" and "caraxis": reference solutions at t_end).
M. González, D. Dopico, U. Lugrís, J. Cuadrado, "A benchmarking system for MBS simulation
software: problem standardization and performance measurement", Multibody Syst. Dyn. 16 (2006)
179–190 (IFToMM A01 pendulum, A02, A04; error against CPU time at precision levels).
"""

from __future__ import annotations

import fnmatch
import math
import weakref
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from functools import partial
from typing import Any

import numpy as np

from ..registry import Registry
from .references import (
    A04_REFERENCE_TOL,
    A04_T_END,
    G_EARTH,
    iftomm_a02_reference,
    iftomm_a04_p2,
    iftomm_a04_reference,
    iftomm_a04_system,
    n_link_chain_reference,
    pendulum_angle_exact,
    stiff_chain_tip_reference,
)

__all__ = [
    "GRID_NAMES",
    "PROBLEMS",
    "PROBLEM_SETS",
    "Grid",
    "WorkPrecisionProblem",
    "problem_sets",
    "register_problem",
]

GRID_NAMES = ("quick", "standard", "full")


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
    n = round(np.log10(hi / lo) * per_decade)
    return tuple(float(f"{v:.3g}") for v in np.geomspace(hi, lo, n + 1))


#: Reference quantities are cached per process (per problem object).
_REFERENCE_CACHE: weakref.WeakKeyDictionary[WorkPrecisionProblem, Any] = weakref.WeakKeyDictionary()


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
        if not result.success or abs(float(result.t[-1]) - self.t_end) > 1e-9 * max(1.0, self.t_end):
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


def _check_problem(obj) -> None:
    if not isinstance(obj, WorkPrecisionProblem):
        raise TypeError(f"register_problem expects a WorkPrecisionProblem, got {type(obj).__name__}")


#: Registry of named problems (insertion order is listing order).
PROBLEMS: Registry[WorkPrecisionProblem] = Registry("work-precision problem", _check_problem)


def register_problem(problem: WorkPrecisionProblem) -> WorkPrecisionProblem:
    """Add a problem to :data:`PROBLEMS` (:class:`core.registry.Registry`: re-registering the same
    object is a no-op, a different problem under a taken name raises :class:`core.errors.NameTakenError`)."""
    _check_problem(problem)
    return PROBLEMS.register(problem.name, problem)


# ---------------------------------------------------------------------------------------------
# systems, references at t_end and error measures (module level: picklable)
# ---------------------------------------------------------------------------------------------


def _chain_system(n: int, spatial: bool = False, stiff_k: float | None = None):
    from ..models import n_link_chain

    return n_link_chain(n, spatial=spatial, stiff_k=stiff_k)


def _chain_tip_reference(n: int) -> np.ndarray:
    """Tip (x, y) [m] at t = 1 s from :func:`~core.benchmarks.references.n_link_chain_reference` (DOP853, 1e−13)."""
    tip, _ = n_link_chain_reference(n, t_end=1.0)
    return np.asarray(tip, float)


def _chain_tip_error(system, q, v, tip_ref) -> float:
    from ..models import chain_tip

    return float(np.linalg.norm(chain_tip(system, q) - tip_ref))


def _pendulum_system():
    from ..models import simple_pendulum

    return simple_pendulum(length=1.0, mass=1.0, angle0=np.pi / 2, planar=True, bob="point")


def _pendulum_reference(t_end: float) -> float:
    return float(pendulum_angle_exact(t_end, np.pi / 2, 1.0, G_EARTH))


def _pendulum_angle_error(system, q, v, theta_ref) -> float:
    """|θ − θ_ref| [rad], θ = atan2(x, −y) of the bob (the body's centre of mass)."""
    theta = np.arctan2(q[0], -q[1])
    return float(abs(np.angle(np.exp(1j * (theta - theta_ref)))))


def _andrews_system():
    from .testset import AndrewsSqueezer

    return AndrewsSqueezer()


def _andrews_reference() -> np.ndarray:
    from .testset import AndrewsSqueezer

    return np.array(AndrewsSqueezer.reference["q"], float)


def _car_axis_system():
    from .testset import CarAxis

    return CarAxis()


def _car_axis_reference() -> np.ndarray:
    from .testset import CarAxis

    return np.array(CarAxis.reference["q"], float)


def _max_abs_q_error(system, q, v, q_ref) -> float:
    return float(np.max(np.abs(np.asarray(q, float) - q_ref)))


def _simeon_crank_system():
    from .testset import SimeonCrank

    return SimeonCrank()


def _simeon_crank_reference() -> float:
    from .testset import SimeonCrank

    return float(SimeonCrank.reference["q"][3])


def _simeon_crank_error(system, q, v, q1_ref) -> float:
    return float(abs(q[3] - q1_ref))


def _spin_up_system():
    from ..flexible.models import spin_up_beam

    return spin_up_beam(n_elements=20, n_modes=2, geometric_stiffening=True)


def _spin_up_tip(system, q) -> float:
    from ..flexible.models import hub_frame_deflection, spin_up_angle

    tip = system.point_position(q, "beam.tip", np.zeros(2))
    return float(hub_frame_deflection(tip[None], np.array([spin_up_angle()(SPIN_UP_T_END)[0]]), 10.0)[0][0])


#: end time of the spin-up work-precision problem [s] (the lag is near its peak)
SPIN_UP_T_END = 8.0


def _spin_up_reference() -> float:
    from ..simulation import simulate

    system = _spin_up_system()
    res = simulate(system, (0.0, SPIN_UP_T_END), "dop853-projection", rtol=1e-12, atol=1e-12, n_output=2)
    if res.status != "finished":  # pragma: no cover - the reference run must succeed
        raise RuntimeError(f"spin-up reference run: {res.message}")
    return _spin_up_tip(system, res.q[-1])


def _spin_up_error(system, q, v, v_ref) -> float:
    return abs(_spin_up_tip(system, q) - v_ref)


def _andrews_cartesian_system():
    from ..models import andrews_cartesian

    return andrews_cartesian()


def _andrews_cartesian_error(system, q, v, q_ref) -> float:
    """Max-abs error of the seven angles recovered from the Cartesian state [rad]."""
    from ..models import andrews_angles_from_cartesian

    return float(np.max(np.abs(andrews_angles_from_cartesian(system, np.asarray(q, float)) - q_ref)))


A02_T_END = 1.0


def _a02_system():
    from ..models import iftomm_a02_four_bar_chain

    return iftomm_a02_four_bar_chain(n_windows=40, redundant="keep")


def _a02_reference() -> float:
    """Bar angle φ(t_end) [rad] of the equivalent pendulum (minimal coordinate, DOP853 1e-12)."""
    phi, _ = iftomm_a02_reference(np.array([0.0, A02_T_END]), n_windows=40)
    return float(phi[-1])


def _a02_error(system, q, v, phi_ref) -> float:
    """|φ − φ_ref| [rad] of the first bar (body 'bar0'), through its passage of the horizontal."""
    k = system.body_index("bar0")
    return float(abs(np.angle(np.exp(1j * (q[3 * k + 2] - phi_ref)))))


def _a04_error(system, q, v, ref) -> float:
    return float(np.linalg.norm(iftomm_a04_p2(system, q) - ref))


# ---------------------------------------------------------------------------------------------
# the registered problems
# ---------------------------------------------------------------------------------------------


#: Methods left out of the standard grid of the costlier problems: the unstabilised and the
#: Baumgarte index-1 variants (their projected counterparts stay) and LSODA (it restarts
#: after every projection, see core.integrators.index1).  Patterns, so integrators registered
#: later are included by default.
_STD_EXCLUDE = ("rk45", "dop853", "radau", "bdf", "lsoda*", "*-baumgarte", "jit-rk45", "jit-dop853", "jit-rk4")
#: For unconstrained (stiff spring) problems projection and Baumgarte change nothing.
_ODE_EXCLUDE = ("*-projection", "*-baumgarte", "lsoda*")
_QUICK_METHODS = ("rk45-projection", "dop853-projection", "jit-dop853-projection", "radau-projection",
                  "generalized-alpha", "radau-ggl", "hem4")

_CHAIN_NOTE = ("minimal-coordinate ODE of the chain (absolute link angles), scipy DOP853 at rtol = atol = "
               "1e-13 (core.benchmarks.references.n_link_chain_reference; core_benchmarks.md §1)")


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
                reference_fn=partial(stiff_chain_tip_reference, n, k),
                error_fn=_chain_tip_error,
                error_measure="|tip - tip_ref| [m]",
                reference_note=("the same stiff chain integrated by scipy DOP853 at rtol = atol = 1e-12 with an "
                                "independent right-hand side (core.benchmarks.references.stiff_chain_rhs); the "
                                "rigid-chain reference differs from it by O(m g / k) and is not used"),
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
                        "core.benchmarks.testset.AndrewsSqueezer.reference"),
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
                        "DOP853 at 1e-12 (core.benchmarks.references.iftomm_a02_reference); the bars pass the "
                        "horizontal at t = 0.72 s, where the number of degrees of freedom jumps"),
        conservative=True,
        grids={"quick": Grid(rtols=(1e-4,), steps=(2e-3,), methods=("rk45-projection", "generalized-alpha")),
               "standard": Grid(rtols=(1e-4, 1e-6), steps=(4e-3, 2e-3, 1e-3),
                                methods=("rk45-projection", "dop853-projection", "radau-ggl", "generalized-alpha")),
               "full": Grid(rtols=_geom(1e-3, 1e-8, 1), steps=_geom(4e-3, 2.5e-4, 2))},
    ))
    register_problem(WorkPrecisionProblem(
        name="iftomm-a04",
        title="IFToMM A04: Bricard's over-constrained 6R mechanism under gravity (dependent row removed), t = 10 s",
        build_system=iftomm_a04_system,
        t_end=A04_T_END,
        reference_fn=iftomm_a04_reference,
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
                        "caraxis.f, subroutine soln; core.benchmarks.testset.CarAxis.reference"),
        conservative=False,
        grids={"quick": Grid(rtols=(1e-4,), steps=(3e-3,), methods=_QUICK_METHODS),
               "standard": Grid(rtols=(1e-3, 1e-5, 1e-7), steps=(1e-2, 3e-3, 1e-3), exclude=_STD_EXCLUDE),
               "full": Grid(rtols=_geom(1e-3, 1e-10, 1), steps=_geom(1e-2, 1e-4, 2))},
    ))
    register_problem(WorkPrecisionProblem(
        name="simeon-crank",
        title="Slider crank with an elastic rod (Simeon), published two-mode model, index-3 DAE (t = 0.1 s)",
        build_system=_simeon_crank_system,
        t_end=0.1,
        reference_fn=_simeon_crank_reference,
        error_fn=_simeon_crank_error,
        error_measure="|q1 - q1_ref|, the rod's midpoint deflection [m]",
        reference_note=("published solution at t = 0.1 s: Test Set for IVP Solvers, crank.f, subroutine cranksoln "
                        "(MEBDFI, rtol = atol = 1e-14); core.benchmarks.testset.SimeonCrank.reference"),
        conservative=False,
        grids={"quick": Grid(rtols=(1e-5,), steps=(1e-5,), methods=("dop853-projection", "radau-ggl")),
               # about 11 s per repeat on the 2-core host; the full grid covers every method
               "standard": Grid(rtols=(1e-4, 1e-6), steps=(1e-5,),
                                methods=("dop853-projection", "radau-ggl", "generalized-alpha")),
               "full": Grid(rtols=_geom(1e-3, 1e-10, 1), steps=_geom(1e-4, 1e-6, 2))},
    ))
    register_problem(WorkPrecisionProblem(
        name="flexible-spin-up",
        title="Spin-up beam (Kane, Ryan & Banerjee 1987): flexible body, 20 elements, 2 cantilever modes, "
              "centrifugal stiffening, driven hub (t = 8 s)",
        build_system=_spin_up_system,
        t_end=SPIN_UP_T_END,
        reference_fn=_spin_up_reference,
        error_fn=_spin_up_error,
        error_measure="|v_tip - v_tip,ref|, tip deflection in the hub frame [m]",
        reference_note=("the same model by scipy DOP853 with coordinate projection at rtol = atol = 1e-12; the "
                        "model itself is validated against a geometrically exact rigid-link chain (scene "
                        "flexible-spin-up-beam)"),
        conservative=False,
        grids={"quick": Grid(rtols=(1e-5,), steps=(1e-2,), methods=("dop853-projection", "radau-projection")),
               # one method of each family on the numpy path (about 14 s a repeat on the 2-core host;
               # the fixed-step ones at h = 1e-2 s only: at 1e-3 s HEM4 alone takes 30 s) and the
               # compiled ones, which take the flexible body as a mass group (core.flexible.compiled)
               "standard": Grid(rtols=(1e-4, 1e-6, 1e-8), steps=(1e-2,),
                                methods=("dop853-projection", "radau-projection", "radau-ggl", "generalized-alpha",
                                         "hem4", "jit-dop853-projection", "jit-radau", "jit-radau-projection")),
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
                 "pendulum-100s", "iftomm-a04", "simeon-crank", "flexible-spin-up"],
}


def problem_sets() -> dict[str, list[str]]:
    """:data:`PROBLEM_SETS` and the set "full": every registered problem."""
    return {**PROBLEM_SETS, "full": list(PROBLEMS)}


def _resolve_problem(problem: str | WorkPrecisionProblem) -> WorkPrecisionProblem:
    """The problem object itself, or the registered problem of that name (else :class:`UnknownNameError`)."""
    if isinstance(problem, WorkPrecisionProblem):
        return problem
    return PROBLEMS[problem]
