r"""The three-car train of Pombo & Ambrósio on a track: model, assembly, runs and wheel forces.

Bodies and coordinates
----------------------
Three cars, two connecting bars and six wheelsets: 11 spatial bodies (66 velocity coordinates)
and the six arc lengths L_1 … L_6 of the wheelsets as extra coordinates (carrying the spin inertia of the
wheels, :attr:`TrainParameters.wheel_spin_mass`), 72 in all.
Wheelset ``ws{2k-1}`` is the front and ``ws{2k}`` the rear wheelset of car ``k``; L_1 leads and
the train runs towards increasing L.  One degree of freedom needs 71 independent equations.

Joint layout (and why it is not redundant)
------------------------------------------
=========================  ==============================================  ==========
joint                      what it fixes                                   equations
=========================  ==============================================  ==========
``path{i}`` (6×)           wheelset i on the centreline at L_i, locked to  6 × 6 = 36
                           the track frame (:class:`~coaster.path_joint.
                           PathFollowingJoint`)
``car{k}_front`` (3×)      spherical: car pivot P_f = front wheelset's     3 × 3 = 9
                           pivot point (z_p above the centreline)
``car{k}_rear`` (3×)       universal: car pivot P_r = rear wheelset's      3 × 4 = 12
                           pivot, plus y_car · b_rear = 0 (no relative
                           roll car/rear wheelset; yaw and pitch free)
``bar{k}_front`` (2×)      spherical: bar front end = coupler of car k     2 × 3 = 6
``bar{k}_rear`` (2×)       universal: bar rear end = coupler of car k+1,   2 × 4 = 8
                           plus y_bar · z_car(k+1) = 0 (no bar spin)
=========================  ==============================================  ==========

36 + 9 + 12 + 6 + 8 = 71.  Counting per body: a wheelset keeps one freedom (its L_i).  A car
given both pivot points keeps only its rotation about the pivot line P_f − P_r; the universal's
dot row fixes it, and its gradient with respect to that rotation is (x_car × y_car)·b_r =
z_car·b_r ≈ 1 (never small while the car stands on the track).  The remaining three point rows
of the two pivots are one scalar condition on (L_f, L_r): ``|P_f(L_f) − P_r(L_r)|`` = 2a, whose
derivative along the track, (P_f − P_r)/2a · t, is ≈ 1 as long as the chord between the pivots
points along the track.  A bar given its front end keeps two directions and its spin; the rear
point fixes the direction up to one scalar condition ``|C_k − C'_{k+1}|`` = l_b on the cars it
joins, its dot row fixes the spin (gradient (x_bar × y_bar)·z_car ≈ 1).  So the 71 equations are
three car chords + two bar lengths = five conditions on the six L_i, plus rows that each fix
one body freedom with an O(1) gradient: rank 71 everywhere on a track whose radius is large
compared with the pivot spacing.  The alternative of two revolute joints per car (5 + 5) has
two rows too many per car: on a twisted track the relative roll of the wheelsets cannot be
taken up, the rows are dependent at best and the multipliers (the wheel forces) are not unique
(notes/coaster.md).  :func:`rank_table` checks the rank of the full Jacobian by a
rank-revealing factorisation (QR with pivoting, singular values) at any set of positions.

Assembly
--------
Given the lead arc length L_1 (:meth:`Train.state_at`): each wheelset at its L_i takes the
track frame (A = R(L_i), r = g(L_i)); car k with its front wheelset at L_f has its rear
wheelset at the L_r < L_f with ``|P(L_f) − P(L_r)|`` = 2a (P(L) = g + z_p b, a 1-D root by
Brent's method), x_car = (P_f − P_r)/2a, y_car = b_r × x_car/``|b_r × x_car|``, z_car = x_car ×
y_car, r_car = P_f − A_car (a, 0, −d).  The next car's front arc length solves
``|C_k − C'_{k+1}(L)|`` = l_b (an outer 1-D root over the inner one).  Velocities at lead speed
v: the unique solution of [Φ_q; e_{L1}ᵀ] v = [ν; v] (71 + 1 rows, square and regular).

Forces along the track (:class:`TrackForces`)
---------------------------------------------
Generalized forces Q_{L_i} on the arc-length coordinates.  Because the path joint holds the
wheelset's point on g(L_i), a force F t at that point does the virtual work F δL_i, so Q_L = F
is exactly a force along the track at wheelset i (reacted by the train through the joints):

* rolling resistance  F_i = −c_rr m_i g tanh(L̇_i/v_ε)   (m_i the mass carried by wheelset i;
  the static weight, not the instantaneous normal load — a stated simplification);
* aerodynamic drag on the lead wheelset  F = −½ ρ c_d A L̇|L̇|;
* speed-control sections (lift-hill launch/booster, brakes) on the lead wheelset with a C1
  window w(L) (smooth steps over ``ramp`` m at both ends):
  brake  F = −w min(F_max, k max(0, L̇ − v_t)),  booster  F = +w min(F_max, k max(0, v_t − L̇)).

Chain lift (:class:`ChainLift`): a driving constraint L_1(t) = L_a + v_c (t − t_0) on the lead
coordinate (:class:`core.joints.CoordinateDriver`) until L_1 = L_b; its multiplier is the chain
pull (F_chain = −λ).  Then the train runs free.

Runs (:func:`run_train`)
------------------------
Phases are run one after the other with core's integrators (:func:`core.simulation.simulate`),
the free run in chunks; after each chunk the lead speed L̇_1 is checked.  A sign change outside
the chain means the train did not crest a hill and rolls back: the run stops there with status
``"rolled back"`` and a message naming the arc length, section and time where L̇_1 = 0.

Wheel forces (:func:`wheel_forces`): the reactions of each path joint resolved in the track
frame (along t, lateral n, up b; on the wheelset, N), one row per output time.

References
----------
Pombo, J. and Ambrósio, J. (2003). General spatial curve joint for rail guided vehicles:
kinematics and dynamics. Multibody System Dynamics 9(3):237-264 (the path joint).
Pombo, J. and Ambrósio, J. (2007). Modelling tracks for roller coaster dynamics. Int. J. Vehicle
Design 45(4):470-500 (the three-car train with connecting bars, reaction forces from the
multipliers; its joint layout and parameters were not available here: the layout above is
chosen and checked for rank, the masses and lengths of :class:`TrainParameters` are
representative values, not the paper's).
Haug, E. J. (1989). Computer-Aided Kinematics and Dynamics of Mechanical Systems, Table 9.1
(spherical and universal joints), Sec. 3.5 (driving constraints).
"""

from __future__ import annotations

import math
import time as _time
from dataclasses import dataclass, field, replace
from functools import lru_cache

import numpy as np
import pandas as pd
import scipy.optimize as so

from core import frames as cframes
from core.bodies import BodyStates
from core.curves import FramedCurve
from core.errors import InputError, ModelError
from core.forces.protocol import ForceElement, ForceEval, ForceKind
from core.inputs import checked_options
from core.joints import CoordinateDriver, Spherical, Universal
from core.model import Model, ModelBuilder

from .path_joint import PathFollowingJoint

__all__ = [
    "TrainParameters",
    "SpeedSection",
    "ChainLift",
    "TrackForces",
    "Train",
    "TrainRun",
    "run_train",
    "wheel_forces",
    "rider_peaks",
    "section_extremes",
    "wheel_force_peaks",
    "time_above_limits_dense",
    "rank_table",
    "sections_at",
    "section_summary",
    "circuit_frame",
    "CIRCUIT_SETTINGS",
    "circuit_sections",
    "named_sections",
    "G",
]

G = 9.81


# ---------------------------------------------------------------------------------------------
# parameters
# ---------------------------------------------------------------------------------------------
def _to_si(obj, fields: dict, who: str):
    """Convert ``obj``'s fields (name -> range quantity) given as strings with units to SI floats
    (frozen dataclass: object.__setattr__); numbers pass unchanged."""
    from core.inputs import parse_quantity

    from .inputs import ranges

    for f, quantity in fields.items():
        x = getattr(obj, f)
        if isinstance(x, str):
            object.__setattr__(obj, f, float(parse_quantity(x, ranges()[quantity].unit, where=f"{who} {f}")))


def _accept_tuple(obj):
    acc = (obj.accept,) if isinstance(obj.accept, str) else tuple(obj.accept)
    object.__setattr__(obj, "accept", acc)
    return acc


#: physical fields of TrainParameters -> vector length (None: a scalar); each has a plausible range
_PARAM_FIELDS = {"car_mass": None, "car_inertia": 3, "wheelset_mass": None, "wheelset_inertia": 3, "bar_mass": None,
                 "bar_inertia": 3, "pivot_spacing": None, "pivot_height": None, "cg_height": None,
                 "coupler_overhang": None, "bar_length": None, "rider_point": 3, "wheel_spin_mass": None,
                 "rider_mass": None}


@dataclass(frozen=True)
class TrainParameters:
    """Geometry and inertia of the train (SI units; body axes x forward, y left, z up).

    Representative values of a steel coaster train, not those of Pombo & Ambrósio (2007).
    Every physical field takes a number in SI units or a string with its unit (``"0.9 t"``,
    ``"1800 mm"``) and is checked against its plausible range (data/coaster/plausible_ranges.csv,
    :mod:`coaster.inputs`): ``car_mass=0.9`` is refused with "did you mean 0.9 t?", unless
    ``accept=("car_mass",)``.

    Attributes
    ----------
    n_cars : int
        Number of cars (bars = n_cars − 1, wheelsets = 2 n_cars).
    car_mass : float
        Car with riders (kg).
    car_inertia : (3,) tuple
        Principal moments about the car's centre of mass (kg m²).
    wheelset_mass, wheelset_inertia
        Wheel assembly (kg, kg m²); its centre of mass is on the track centreline.
    bar_mass, bar_inertia
        Connecting bar (kg, kg m²).
    pivot_spacing : float
        2a: distance between a car's front and rear pivots (m).
    pivot_height : float
        z_p: pivot points above the track centreline, in wheelset axes (m).
    cg_height : float
        d: car centre of mass above the pivot line (m).
    coupler_overhang : float
        e: couplers ahead of the front / behind the rear pivot, at pivot height (m).
    bar_length : float
        l_b: distance between the bar's two joints (m).
    rider_point : (3,) tuple
        A rider's position in car axes relative to the car's centre of mass (m).
    rider_mass : float
        Mass of one rider (kg); with ``riders_per_car`` a consistency check only: ``car_mass``
        includes the riders and must exceed ``riders_per_car * rider_mass``.
    riders_per_car : int
    accept : tuple of str
        Quantities whose plausible range (data/coaster/plausible_ranges.csv) is not enforced.
    wheel_spin_mass : float
        Equivalent mass of the spinning wheels of one wheelset on its arc length, Σ J_w/r_w²
        (kg; two road wheels of 0.1 kg m² on r_w = 0.2 m give 5 kg).  The wheelset body is locked to
        the track frame, so the wheels' spin is the only motion that carries this inertia and its
        kinetic energy is ½ m_s L̇².  It also keeps the arc lengths off the border of core's
        compiled saddle-point solve, whose choice of regular rows is fixed at the initial
        configuration and becomes singular once the track has turned by about 90° (measured on
        the circuit with m_s = 0).  0 makes L massless (numpy integrators only on turning track).
    """

    n_cars: int = 3
    car_mass: float = 900.0
    car_inertia: tuple = (190.0, 520.0, 550.0)
    wheelset_mass: float = 150.0
    wheelset_inertia: tuple = (14.5, 4.0, 14.5)
    bar_mass: float = 20.0
    bar_inertia: tuple = (0.01, 0.6, 0.6)
    pivot_spacing: float = 1.8
    pivot_height: float = 0.25
    cg_height: float = 0.5
    coupler_overhang: float = 0.3
    bar_length: float = 0.8
    rider_point: tuple = (0.0, 0.0, 0.4)
    wheel_spin_mass: float = 5.0
    rider_mass: float = 75.0
    riders_per_car: int = 4
    accept: tuple = ()

    def __post_init__(self):
        from core.inputs import parse_quantity

        from .inputs import check, ranges

        acc = (self.accept,) if isinstance(self.accept, str) else tuple(self.accept)
        object.__setattr__(self, "accept", acc)
        R = ranges()
        for f, n in _PARAM_FIELDS.items():  # units first (a string such as "0.9 t"), SI floats after
            x = getattr(self, f)
            v = parse_quantity(x, R[f].unit, where=f"TrainParameters {f}")
            if n is None:
                if np.ndim(v) != 0:
                    raise InputError(f"TrainParameters {f}: must be one number, got {x!r}")
                v = float(v)
            else:
                v = np.atleast_1d(v)
                if v.size != n:
                    raise InputError(f"TrainParameters {f}: must be {n} numbers, got {x!r}")
                v = tuple(float(a) for a in v)
            object.__setattr__(self, f, v)
        if int(self.n_cars) != self.n_cars or self.n_cars < 1:
            raise InputError(f"TrainParameters: n_cars must be a positive integer, got {self.n_cars!r}")
        for name in ("car_mass", "wheelset_mass", "bar_mass", "pivot_spacing", "bar_length"):
            x = getattr(self, name)
            if not (np.isfinite(x) and x > 0):
                raise InputError(f"TrainParameters: {name} must be positive and finite, got {x!r}")
        if not (np.isfinite(self.wheel_spin_mass) and self.wheel_spin_mass >= 0):
            raise InputError(f"TrainParameters: wheel_spin_mass must be finite and >= 0, got {self.wheel_spin_mass!r}")
        for name in ("pivot_height", "cg_height", "coupler_overhang"):
            x = getattr(self, name)
            if not np.isfinite(x):
                raise InputError(f"TrainParameters: {name} must be finite, got {x!r}")
        if self.coupler_overhang < 0:
            raise InputError(f"TrainParameters: coupler_overhang must be >= 0, got {self.coupler_overhang!r}")
        if isinstance(self.riders_per_car, bool) or int(self.riders_per_car) != self.riders_per_car:
            raise InputError(f"TrainParameters: riders_per_car must be a whole number, got {self.riders_per_car!r}")
        for f in _PARAM_FIELDS:
            check(f, getattr(self, f), where=f"TrainParameters {f}", accept=acc)
        check("riders_per_car", self.riders_per_car, where="TrainParameters riders_per_car", accept=acc)
        riders = self.riders_per_car * self.rider_mass
        if riders >= self.car_mass and "car_mass" not in acc:
            raise InputError(f"TrainParameters: car_mass {self.car_mass:g} kg is the car *with* its riders, but its "
                             f"{self.riders_per_car} riders of {self.rider_mass:g} kg weigh {riders:g} kg alone: is "
                             f"car_mass the empty car (add the riders), or rider_mass per car instead of per rider?")

    @classmethod
    def from_dict(cls, data: dict, source: str = "train parameters", accept=()) -> "TrainParameters":
        """Train parameters from a mapping (a table read from a file, keyword options).

        Unknown keys are refused with the closest valid one named
        (:class:`core.errors.UnknownOptionError`: ``car_mas: unknown option; did you mean
        'car_mass'?``); values are numbers in SI units or strings with their unit; an ``accept``
        entry in the mapping (a list of quantities) adds to ``accept``.
        """
        from dataclasses import fields as _fields

        from core.inputs import check_keywords

        if not isinstance(data, dict):
            raise InputError(f"{source}: train parameters must be a mapping of names to values, got "
                             f"{type(data).__name__}")
        names = [f.name for f in _fields(cls)]
        check_keywords(data.keys(), names, where=source)
        data = dict(data)
        acc = tuple(accept) + tuple(data.pop("accept", ()))
        try:
            return cls(**data, accept=acc)
        except InputError as exc:
            from core.inputs import ImplausibleValueError

            if isinstance(exc, ImplausibleValueError):
                raise ImplausibleValueError(f"{source}: {exc}", exc.quantity, exc.value, exc.suggestion) from None
            raise type(exc)(f"{source}: {exc}") from None

    @property
    def n_wheelsets(self) -> int:
        return 2 * self.n_cars

    @property
    def total_mass(self) -> float:
        """Mass of the whole train (kg; the wheels' spin equivalent mass not included)."""
        return (self.n_cars * self.car_mass + self.n_wheelsets * self.wheelset_mass
                + (self.n_cars - 1) * self.bar_mass)

    def wheelset_loads(self) -> np.ndarray:
        """Mass carried by each wheelset at rest on level track (kg): its own, half its car, half
        of each adjacent bar (the static share used by the rolling resistance)."""
        m = np.full(self.n_wheelsets, self.wheelset_mass + 0.5 * self.car_mass)
        for k in range(self.n_cars - 1):
            m[2 * k + 1] += 0.5 * self.bar_mass
            m[2 * k + 2] += 0.5 * self.bar_mass
        return m


@dataclass(frozen=True)
class SpeedSection:
    """A speed-control section on the track acting on the lead wheelset (brake or booster).

    brake: F = −w(L) min(F_max, k max(0, L̇ − v_t)); booster: F = +w(L) min(F_max, k max(0, v_t − L̇)),
    w(L) a C1 window rising over ``ramp`` m after ``L_start`` and falling over ``ramp`` m before
    ``L_end`` (arc lengths of the lead wheelset, modulo the length of a closed track).

    Attributes
    ----------
    name : str
    L_start, L_end : float
        Section on the track (m), L_end > L_start.
    target_speed : float
        v_t (m/s).
    max_force : float
        F_max (N).
    gain : float
        k (N s/m).
    mode : {"brake", "booster"}
    ramp : float
        Length of the window's smooth ends (m).
    accept : tuple of str
        Quantities whose plausible range is not enforced (``track_speed``, ``section_force``,
        ``section_gain``, ``section_ramp``); numbers are SI, strings carry their unit ("80 km/h").
    """

    name: str
    L_start: float
    L_end: float
    target_speed: float
    max_force: float
    gain: float = 2.0e4
    mode: str = "brake"
    ramp: float = 2.0
    accept: tuple = ()

    def __post_init__(self):
        who = f"speed section {self.name!r}"
        from .inputs import check

        acc = _accept_tuple(self)
        _to_si(self, {"L_start": "section_ramp", "L_end": "section_ramp", "target_speed": "track_speed",
                      "max_force": "section_force", "gain": "section_gain", "ramp": "section_ramp"}, who)
        if self.mode not in ("brake", "booster"):
            raise InputError(f"{who}: mode must be 'brake' or 'booster', got {self.mode!r}")
        if not (np.isfinite(self.L_start) and np.isfinite(self.L_end) and self.L_end > self.L_start):
            raise InputError(f"{who}: need L_end > L_start, got [{self.L_start!r}, {self.L_end!r}] m")
        for nm in ("target_speed", "max_force", "gain", "ramp"):
            x = getattr(self, nm)
            if not (np.isfinite(x) and x >= 0):
                raise InputError(f"{who}: {nm} must be finite and >= 0, got {x!r}")
        if 2 * self.ramp > self.L_end - self.L_start:
            raise InputError(f"{who}: ramp {self.ramp!r} m is longer than half the section "
                             f"({self.L_end - self.L_start:.3g} m)")
        check("track_speed", self.target_speed, where=f"{who} target_speed", accept=acc)
        check("section_force", self.max_force, where=f"{who} max_force", accept=acc)
        check("section_gain", self.gain, where=f"{who} gain", accept=acc)
        check("section_ramp", self.ramp, where=f"{who} ramp", accept=acc)

    @property
    def sign(self) -> float:
        return -1.0 if self.mode == "brake" else 1.0


@dataclass(frozen=True)
class ChainLift:
    """Chain lift: the lead wheelset driven at constant ``speed`` (m/s) from ``L_start`` to ``L_end`` (m).

    ``speed`` is checked against the plausible chain speed (0.1-12 m/s; "30" meant as km/h is
    refused with "did you mean 30 km/h?"); ``accept=("chain_speed",)`` takes an outlier.
    """

    L_start: float
    L_end: float
    speed: float
    accept: tuple = ()

    def __post_init__(self):
        from .inputs import check

        acc = _accept_tuple(self)
        _to_si(self, {"L_start": "section_ramp", "L_end": "section_ramp", "speed": "chain_speed"}, "chain lift")
        if not (np.isfinite(self.speed) and self.speed > 0):
            raise InputError(f"chain lift: speed must be positive, got {self.speed!r} m/s")
        if not (self.L_end > self.L_start):
            raise InputError(f"chain lift: need L_end > L_start, got [{self.L_start!r}, {self.L_end!r}] m")
        check("chain_speed", self.speed, where="chain lift speed", accept=acc)

    @property
    def duration(self) -> float:
        return (self.L_end - self.L_start) / self.speed


# ---------------------------------------------------------------------------------------------
# forces along the track
# ---------------------------------------------------------------------------------------------
def _smoothstep(x):
    """C1 step: 0 for x <= 0, 3x² − 2x³ on (0, 1), 1 for x >= 1."""
    x = np.clip(x, 0.0, 1.0)
    return x * x * (3.0 - 2.0 * x)


@dataclass(frozen=True)
class TrackForces(ForceElement):
    """Rolling resistance, aerodynamic drag and speed-control sections along the track.

    Equations in the module docstring ("Forces along the track"); all act on the model's
    arc-length coordinates (generalized force Q_L, N).

    Attributes
    ----------
    name : str
    coordinates : tuple of str
        The arc-length coordinates, lead first.
    loads : tuple of float
        Mass carried by each wheelset (kg), for the rolling resistance.
    rolling : float
        c_rr (-).
    drag_area : float
        c_d A (m²).
    air_density : float
        ρ (kg/m³).
    sections : tuple of SpeedSection
    period : float
        Length of a closed track (m; section windows are evaluated modulo it), 0 if open.
    gravity : float
        g (m/s²).
    v_smooth : float
        v_ε of the rolling-resistance sign (m/s).
    """

    name: str
    coordinates: tuple
    loads: tuple
    rolling: float = 0.0
    drag_area: float = 0.0
    air_density: float = 1.225
    sections: tuple = ()
    period: float = 0.0
    gravity: float = G
    v_smooth: float = 0.05

    def __post_init__(self):
        if len(self.coordinates) != len(self.loads) or not self.coordinates:
            raise InputError(f"track forces {self.name!r}: one load per coordinate needed, got "
                             f"{len(self.coordinates)} coordinates and {len(self.loads)} loads")
        for nm in ("rolling", "drag_area", "air_density", "period", "v_smooth"):
            x = getattr(self, nm)
            if not (np.isfinite(x) and x >= 0):
                raise InputError(f"track forces {self.name!r}: {nm} must be finite and >= 0, got {x!r}")
        if self.v_smooth == 0:
            raise InputError(f"track forces {self.name!r}: v_smooth must be > 0")

    @property
    def dissipative(self) -> bool:
        return self.rolling > 0 or self.drag_area > 0 or bool(self.sections)

    def generalized(self, L, Ld):
        """Q_L (n,) for arc lengths L (n,) and rates L̇ (n,) of the coordinates (lead first)."""
        L = np.asarray(L, float)
        Ld = np.asarray(Ld, float)
        m = np.asarray(self.loads, float)
        Q = -self.rolling * m * self.gravity * np.tanh(Ld / self.v_smooth)
        Q[0] -= 0.5 * self.air_density * self.drag_area * Ld[0] * abs(Ld[0])
        x = L[0] % self.period if self.period > 0 else L[0]
        for s in self.sections:
            w = _smoothstep((x - s.L_start) / s.ramp) * _smoothstep((s.L_end - x) / s.ramp) if s.ramp > 0 else \
                float(s.L_start <= x <= s.L_end)
            if w == 0.0:
                continue
            dv = (Ld[0] - s.target_speed) if s.mode == "brake" else (s.target_speed - Ld[0])
            Q[0] += s.sign * w * min(s.max_force, s.gain * max(0.0, dv))
        return Q

    @classmethod
    def compile(cls, elements, ctx):
        return TrackForcesKind(elements, ctx)


class TrackForcesKind(ForceKind):
    """Evaluator of :class:`TrackForces` elements (one generalized force per arc-length coordinate)."""

    conservative = False

    def __init__(self, elements, ctx):
        self.elements = list(elements)
        self.names = [e.name for e in self.elements]
        self.coords = [np.array([ctx.coordinate_index(c, e.name) for c in e.coordinates], np.int64)
                       for e in self.elements]
        self.conservative = not any(e.dissipative for e in self.elements)

    def evaluate(self, bs: BodyStates, t: float) -> ForceEval:
        Qx = [e.generalized(bs.x[k], bs.xdot[k]) for e, k in zip(self.elements, self.coords)]
        return ForceEval(np.zeros(0, np.int64), np.zeros((0, bs.space.n_v)), np.concatenate(self.coords),
                         np.concatenate(Qx))

    def compiled(self, layout):
        from ._kernels import compile_track_forces

        return compile_track_forces(self, layout)


# ---------------------------------------------------------------------------------------------
# the train on a track
# ---------------------------------------------------------------------------------------------
def _unit(x):
    return x / np.linalg.norm(x)


def _root_behind(f, L_guess, step, what):
    """The L near ``L_guess`` with f(L) = 0, where f < 0 ahead of the root and f > 0 behind it.

    Brackets by walking from ``L_guess`` in steps of ``step`` (at most 40), then Brent's method.
    """
    a = L_guess
    fa = f(a)
    if fa == 0.0:
        return a
    direction = -1.0 if fa < 0 else 1.0  # f < 0: too close, go back (smaller L)
    for _ in range(40):
        b = a + direction * step
        fb = f(b)
        if np.sign(fb) != np.sign(fa):
            lo, hi = (a, b) if a < b else (b, a)
            return so.brentq(f, lo, hi, xtol=1e-13, rtol=4 * np.finfo(float).eps, maxiter=200)
        a, fa = b, fb
    raise InputError(f"train assembly: no arc length found for {what} near L = {L_guess:.6g} m "
                     "(is the track radius comparable with the pivot spacing, or the track too short?)")


class Train:
    """The train of :class:`TrainParameters` on a framed track: models, assembly, rank.

    Parameters
    ----------
    track : core.curves.FramedCurve
        Centreline g(L) with its moving frame [t, n, b] (n lateral, b up), e.g. a
        :class:`coaster.frames.RotationMinimisingFrame`.
    params : TrainParameters, optional
    gravity : float
        g (m/s², along −z).
    name : str

    Attributes
    ----------
    bodies : list of str
        ``car1 … car3``, ``bar1, bar2``, ``ws1 … ws6`` (model order: cars, bars, wheelsets).
    coordinates : list of str
        ``L1 … L6``.
    path_joints : list of PathFollowingJoint
    """

    def __init__(self, track: FramedCurve, params: TrainParameters | None = None, gravity: float = G,
                 name: str = "train", accept=()):
        from .inputs import check

        if not isinstance(track, FramedCurve):
            raise InputError(f"Train {name!r}: track must be a core.curves.FramedCurve, got {type(track).__name__}")
        if params is not None and not isinstance(params, TrainParameters):
            raise InputError(f"Train {name!r}: params must be a TrainParameters, got {type(params).__name__}")
        self.track = track
        self.p = TrainParameters() if params is None else params
        self.gravity = float(check("gravity", gravity, where=f"Train {name!r} gravity", accept=accept))
        self.name = name
        nc = self.p.n_cars
        self.cars = [f"car{k + 1}" for k in range(nc)]
        self.bars = [f"bar{k + 1}" for k in range(nc - 1)]
        self.wheelsets = [f"ws{i + 1}" for i in range(2 * nc)]
        self.bodies = self.cars + self.bars + self.wheelsets
        self.coordinates = [f"L{i + 1}" for i in range(2 * nc)]
        self.path_joints = [PathFollowingJoint(f"path{i + 1}", ws, track, L, point=(0.0, 0.0, 0.0))
                            for i, (ws, L) in enumerate(zip(self.wheelsets, self.coordinates))]
        a, d, e = 0.5 * self.p.pivot_spacing, self.p.cg_height, self.p.coupler_overhang
        self._front = np.array([a, 0.0, -d])        # car pivots in car axes
        self._rear = np.array([-a, 0.0, -d])
        self._cfront = np.array([a + e, 0.0, -d])   # couplers
        self._crear = np.array([-(a + e), 0.0, -d])
        self._ws_pivot = np.array([0.0, 0.0, self.p.pivot_height])
        self._cache = {}

    # --- geometry ---------------------------------------------------------------------------
    def _frame(self, L):
        g, _, _, R, _, _ = self.track.evaluate_raw(np.array([float(L)]))
        return g[0], R[0]

    def _pivot(self, L):
        g, R = self._frame(L)
        return g + R @ self._ws_pivot

    def _car_pose(self, Lf, Lr):
        Pf, Pr = self._pivot(Lf), self._pivot(Lr)
        x = _unit(Pf - Pr)
        br = self._frame(Lr)[1][:, 2]
        y = np.cross(br, x)
        ny = np.linalg.norm(y)
        if ny < 1e-6:
            raise InputError(f"train assembly: car pivot line is along the rear wheelset's up axis at L = {Lr:.6g} m")
        y /= ny
        A = np.column_stack([x, y, np.cross(x, y)])
        return Pf - A @ self._front, A

    def _car_rear_L(self, Lf):
        Pf = self._pivot(Lf)
        two_a = self.p.pivot_spacing
        return _root_behind(lambda L: np.linalg.norm(self._pivot(L) - Pf) - two_a * (1 if L < Lf else -1),
                            Lf - two_a, 0.25 * two_a, f"the rear wheelset of the car with front L = {Lf:.6g} m")

    def arc_lengths(self, L1: float) -> np.ndarray:
        """Arc lengths L_1 … L_6 (m) of the assembled train with its lead wheelset at ``L1``."""
        L1 = float(L1)
        if not np.isfinite(L1):
            raise InputError(f"Train {self.name!r}: lead arc length must be finite, got {L1!r}")
        if L1 in self._cache:
            return self._cache[L1].copy()
        Ls = [L1, self._car_rear_L(L1)]
        lb, e = self.p.bar_length, self.p.coupler_overhang
        for k in range(1, self.p.n_cars):
            r_prev, A_prev = self._car_pose(Ls[-2], Ls[-1])
            C = r_prev + A_prev @ self._crear
            Lr_prev = Ls[-1]

            def f(Lf, C=C, Lr_prev=Lr_prev):
                r, A = self._car_pose(Lf, self._car_rear_L(Lf))
                dist = np.linalg.norm(r + A @ self._cfront - C)
                return dist - lb if Lf < Lr_prev else -1.0

            Lf = _root_behind(f, Lr_prev - (2 * e + lb), 0.25 * (2 * e + lb), f"the front wheelset of car {k + 1}")
            Ls += [Lf, self._car_rear_L(Lf)]
        out = np.array(Ls)
        self._check_on_track(L1, out)
        if len(self._cache) > 4096:
            self._cache.clear()
        self._cache[L1] = out
        return out.copy()

    def _check_on_track(self, L1, Ls):
        """Every wheelset of an open track within [0, length] (a closed track wraps)."""
        if getattr(self.track, "closed", False):
            return
        length = float(self.track.length)
        tol = 1e-9 * max(1.0, length)
        span = float(Ls[0] - Ls[-1])
        if Ls[-1] < -tol:
            k = int(np.argmax(Ls < -tol))
            if k < len(Ls) - 1:
                who = (f"the wheelsets {self.wheelsets[k]} ... {self.wheelsets[-1]} (cars {k // 2 + 1} ... "
                       f"{self.p.n_cars}) would be")
            else:
                who = f"the rear wheelset {self.wheelsets[-1]} would be"
            raise InputError(
                f"Train {self.name!r}: with the lead wheelset at L1 = {L1:.6g} m {who} before the start of the open "
                f"track {getattr(self.track, 'name', '')!r} (L = 0; the last at L = {float(Ls[-1]):.4g} m): place the "
                f"lead wheelset at "
                f"L1 >= {span:.4g} m (the train spans {span:.4g} m from its first to its last wheelset)")
        if Ls[0] > length + tol:
            raise InputError(
                f"Train {self.name!r}: the lead wheelset at L1 = {L1:.6g} m is beyond the end of the open track "
                f"{getattr(self.track, 'name', '')!r} (L = {length:.6g} m): place it at "
                f"{span:.4g} m <= L1 <= {length:.6g} m")

    def poses(self, L1: float) -> dict:
        """Body poses {name: (r (3,), A (3, 3))} of the train assembled at lead arc length ``L1``."""
        Ls = self.arc_lengths(L1)
        out = {}
        cars = []
        for k, car in enumerate(self.cars):
            r, A = self._car_pose(Ls[2 * k], Ls[2 * k + 1])
            out[car] = (r, A)
            cars.append((r, A))
        for k, bar in enumerate(self.bars):
            (r0, A0), (r1, A1) = cars[k], cars[k + 1]
            Cf, Cr = r0 + A0 @ self._crear, r1 + A1 @ self._cfront
            x = _unit(Cf - Cr)
            y = _unit(np.cross(A1[:, 2], x))
            out[bar] = (0.5 * (Cf + Cr), np.column_stack([x, y, np.cross(x, y)]))
        for ws, L in zip(self.wheelsets, Ls):
            g, R = self._frame(L)
            out[ws] = (g, R)
        return out

    # --- models -----------------------------------------------------------------------------
    def builder(self, L1: float, forces: TrackForces | None = None, chain: ChainLift | None = None,
                t0: float = 0.0, name: str | None = None, v0=None) -> ModelBuilder:
        """A :class:`core.model.ModelBuilder` of the train assembled at ``L1`` (velocities ``v0`` in
        the model's velocity layout, default zero).

        Joints are placed in this configuration (module docstring table).  ``chain`` adds the
        driver ``chain`` L_1(t) = L1 + v_c (t − t0) (the model must then start at L1 with L̇_1 = v_c).
        """
        P = self.p
        b = ModelBuilder(3, name or self.name, gravity=(0.0, 0.0, -self.gravity))
        poses = self.poses(L1)
        Ls = self.arc_lengths(L1)
        inert = {"car": (P.car_mass, P.car_inertia), "bar": (P.bar_mass, P.bar_inertia),
                 "ws": (P.wheelset_mass, P.wheelset_inertia)}
        nb = len(self.bodies)
        vb = np.zeros((nb, 6)) if v0 is None else np.asarray(v0, float)[:6 * nb].reshape(nb, 6)
        vx = np.zeros(nb) if v0 is None else np.asarray(v0, float)[6 * nb:]
        for k, body in enumerate(self.bodies):
            r, A = poses[body]
            m, J = inert["ws" if body.startswith("ws") else body[:3]]
            b.add_body(body, m, J, r, orientation=cframes.matrix_to_euler(A), velocity=vb[k, :3],
                       angular_velocity=A @ vb[k, 3:])
        for k, (Lname, L) in enumerate(zip(self.coordinates, Ls)):
            b.add_coordinate(Lname, float(L), float(vx[k]) if v0 is not None else 0.0, P.wheel_spin_mass)
        for j in self.path_joints:
            b.add_joint(j)
        for k, car in enumerate(self.cars):
            r, A = poses[car]
            wf, wr = self.wheelsets[2 * k], self.wheelsets[2 * k + 1]
            b.add_joint(Spherical(f"{car}_front", car, wf, at=r + A @ self._front))
            Rr = poses[wr][1]
            b.add_joint(Universal(f"{car}_rear", car, wr, at=r + A @ self._rear, axis_i=A[:, 1], axis_j=Rr[:, 2]))
        for k, bar in enumerate(self.bars):
            r0, A0 = poses[self.cars[k]]
            r1, A1 = poses[self.cars[k + 1]]
            Ab = poses[bar][1]
            b.add_joint(Spherical(f"{bar}_front", self.cars[k], bar, at=r0 + A0 @ self._crear))
            b.add_joint(Universal(f"{bar}_rear", bar, self.cars[k + 1], at=r1 + A1 @ self._cfront,
                                  axis_i=Ab[:, 1], axis_j=A1[:, 2]))
        if forces is not None:
            b.add_force(forces)
        if chain is not None:
            from core.drivers import polynomial

            b.add_joint(CoordinateDriver("chain", self.coordinates[0],
                                         polynomial([float(L1) - chain.speed * t0, chain.speed])))
        return b

    def model(self, L1: float, speed: float = 0.0, forces: TrackForces | None = None,
              chain: ChainLift | None = None, t0: float = 0.0, name: str | None = None) -> Model:
        """The frozen model with the train at lead arc length ``L1`` moving at lead speed ``speed`` (m/s).

        Raises
        ------
        core.errors.RedundantConstraintError
            If the joint layout is redundant at ``L1`` (it is not on tracks whose radius is large
            compared with the pivot spacing; the error names the dependent rows).
        """
        model = self.builder(L1, forces, None, t0, name).build(redundant="raise")
        q0 = np.array(model.q0)
        v0 = self.velocities(model, q0, speed, t=t0)
        if chain is not None:  # the driver needs the consistent velocities at build
            model = self.builder(L1, forces, chain, t0, name, v0=v0).build(redundant="raise")
        return model.with_state(q0, v0)

    def lead_index(self, model: Model) -> tuple[int, int]:
        """(q index, v index) of L_1 in ``model``."""
        k = model.extra_names.index(self.coordinates[0])
        return model.n_bodies * 7 + k, model.n_bodies * 6 + k

    def velocities(self, model: Model, q: np.ndarray, speed: float, t: float = 0.0) -> np.ndarray:
        """v with Φ_q v = ν and L̇_1 = speed: [Φ_q; e_{L1}ᵀ] v = [ν; speed] (rows of a driver dropped)."""
        J = model.Phi_q(t, q).toarray()
        nu = model.nu(t, q)
        names = model.constraint_names
        keep = np.array([not n.startswith("chain") for n in names])
        _, iv = self.lead_index(model)
        e = np.zeros((1, model.n_v))
        e[0, iv] = 1.0
        A = np.vstack([J[keep], e])
        rhs = np.concatenate([nu[keep], [speed]])
        return np.linalg.solve(A, rhs)

    def state_at(self, model: Model, L1: float, speed: float) -> tuple[np.ndarray, np.ndarray]:
        """(q, v) of ``model`` with the train assembled at lead arc length ``L1`` and lead speed ``speed``."""
        poses = self.poses(L1)
        q = np.zeros(model.n_q)
        for body in self.bodies:
            r, A = poses[body]
            s = model.q_slice(body)
            q[s] = np.concatenate([r, cframes.matrix_to_euler(A)])
        for Lname, L in zip(self.coordinates, self.arc_lengths(L1)):
            q[model.n_bodies * 7 + model.extra_names.index(Lname)] = L
        return q, self.velocities(model, q, speed)

    def forces(self, rolling=0.0, drag_area=0.0, air_density=1.225, sections=(), name="track_forces",
               accept=()) -> TrackForces:
        """A :class:`TrackForces` element on this train's coordinates (period = track length if closed).

        ``rolling`` (c_rr, a fraction: "2.5 %" or 0.025), ``drag_area`` (m²) and ``air_density``
        (kg/m³) are checked against their plausible ranges (``accept`` names outliers); a
        section beyond the end of an open track is refused.
        """
        from .inputs import check

        where = f"Train {self.name!r}.forces"
        rolling = float(check("rolling", rolling, where=f"{where}(rolling=...)", accept=accept))
        drag_area = float(check("drag_area", drag_area, where=f"{where}(drag_area=...)", accept=accept))
        air_density = float(check("air_density", air_density, where=f"{where}(air_density=...)", accept=accept))
        if not getattr(self.track, "closed", False):
            for sec in sections:
                if sec.L_start < 0 or sec.L_end > self.track.length:
                    raise InputError(f"{where}: speed section {sec.name!r} [{sec.L_start:g}, {sec.L_end:g}] m lies "
                                     f"outside the open track [0, {self.track.length:.6g}] m")
        period = float(self.track.length) if getattr(self.track, "closed", False) else 0.0
        return TrackForces(name, tuple(self.coordinates), tuple(self.p.wheelset_loads()), rolling=rolling,
                           drag_area=drag_area, air_density=air_density, sections=tuple(sections), period=period,
                           gravity=self.gravity)


# ---------------------------------------------------------------------------------------------
# rank of the constraint Jacobian along the track
# ---------------------------------------------------------------------------------------------
def rank_table(train: Train, L1_values, model: Model | None = None, tol: float = 1e-9) -> pd.DataFrame:
    """Rank of the full constraint Jacobian Φ_q of the train at lead arc lengths ``L1_values``.

    Per position: the numerical rank (singular values above ``tol`` σ_max max(shape)), the
    degrees of freedom n_v − rank, the smallest non-zero singular value relative to the largest
    (σ_71/σ_1: a measure of how far the layout is from redundancy), the indices of dependent rows
    by QR with column pivoting (:meth:`core.model.Model.dependent_constraints`), and the residual
    max|Φ| of the assembly.

    Returns
    -------
    pandas.DataFrame
        Columns ``L1 [m]``, ``rows``, ``rank``, ``dof``, ``sigma_min/sigma_max``, ``dependent rows``,
        ``max|Phi|``.
    """
    if model is None:
        model = train.model(float(np.asarray(L1_values, float).ravel()[0]))
    rows = []
    for L1 in np.asarray(L1_values, float).ravel():
        q, _ = train.state_at(model, float(L1), 0.0)
        J = model.Phi_q(0.0, q).toarray()
        s = np.linalg.svd(J, compute_uv=False)
        rank = int(np.sum(s > tol * s[0] * max(J.shape)))
        dep = model.dependent_constraints(q, tol)
        rows.append({"L1 [m]": float(L1), "rows": J.shape[0], "rank": rank, "dof": model.n_v - rank,
                     "sigma_min/sigma_max": float(s[min(rank, len(s)) - 1] / s[0]),
                     "dependent rows": ", ".join(model.constraint_names[i] for i in dep),
                     "max|Phi|": float(np.max(np.abs(model.Phi(0.0, q))))})
    return pd.DataFrame(rows)


# ---------------------------------------------------------------------------------------------
# runs: chain lift, free running, roll-back detection
# ---------------------------------------------------------------------------------------------
STATUS_FINISHED = "finished"
STATUS_ROLLED_BACK = "rolled back"
STATUS_FAILED = "failed"
STATUS_TIME_LIMIT = "time limit"


@dataclass
class TrainRun:
    """Time history of a train run over one or more phases (chain lift, free running).

    Attributes
    ----------
    train : Train
    t : (n_t,) ndarray
        Output times (s).
    q, v, vdot : (n_t, n_q), (n_t, n_v), (n_t, n_v) ndarray
        Coordinates, velocities and accelerations (index-1 solve at the output states).
    phase : (n_t,) int ndarray
        Index into ``phases`` / ``models`` of each output row.
    lam : list of (n_t_phase, n_c_phase) ndarray
        Multipliers per phase (the chain phase has one row more: the driver).
    models : list of core.model.Model
    phases : pandas.DataFrame
        One row per phase: name, t and L of its start and end, method, integrator status, wall time.
    status : str
        ``"finished"`` (reached ``L_stop``), ``"rolled back"`` (L̇_1 changed sign outside the chain),
        ``"time limit"`` (``t_max`` reached first) or ``"failed"`` (the integrator's message).
    message : str
    wall_time : float
        Integration wall time (s), all phases.
    """

    train: Train
    t: np.ndarray
    q: np.ndarray
    v: np.ndarray
    vdot: np.ndarray
    phase: np.ndarray
    lam: list
    models: list
    phases: pd.DataFrame
    status: str
    message: str
    wall_time: float
    meta: dict = field(default_factory=dict)

    @property
    def L(self) -> np.ndarray:
        """Arc lengths (n_t, 6) of the wheelsets (m)."""
        m = self.models[0]
        idx = [m.n_bodies * 7 + m.extra_names.index(c) for c in self.train.coordinates]
        return self.q[:, idx]

    @property
    def Ldot(self) -> np.ndarray:
        """Rates (n_t, 6) of the arc lengths (m/s); column 0 is the lead speed along the track."""
        m = self.models[0]
        idx = [m.n_bodies * 6 + m.extra_names.index(c) for c in self.train.coordinates]
        return self.v[:, idx]

    @property
    def real_time_factor(self) -> float:
        """Simulated time / integration wall time (> 1: faster than real time).

        The first run of a process includes the compilation (or loading from numba's cache) of
        the kernels in its wall time: warm up with a short run first (the circuit scene and
        benchmarks/coaster_circuit.py do, and report the warm-up's wall time on its own)."""
        return float((self.t[-1] - self.t[0]) / self.wall_time) if self.wall_time > 0 else float("inf")

    def energy(self) -> np.ndarray:
        """T + V (J) at the output times (gravity; the track forces have no potential)."""
        m = self.models[0]
        return np.array([m.energy(t, q, v) for t, q, v in zip(self.t, self.q, self.v)])

    def states_at(self, times) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """States at arbitrary times of the run, by re-integrating from the output before each.

        For a time t with t_i <= t <= t_(i+1) (outputs of the run) the phase model of row i+1
        is integrated from the state of row i (projected onto the constraints) to t with the
        run's method and tolerances: the state agrees with the run's own dense solution to the
        integration tolerance, independently of the output step.  Times sharing a start row are
        integrated in one call.

        Parameters
        ----------
        times : (m,) array_like
            Times within [t_0, t_end] (s).

        Returns
        -------
        (phase (m,) int, q (m, n_q), v (m, n_v), t (m,)) in the order of ``times``.
        """
        from core.dynamics import project
        from core.simulation import simulate

        T = np.atleast_1d(np.asarray(times, float)).reshape(-1)
        if T.size and (np.min(T) < self.t[0] - 1e-12 or np.max(T) > self.t[-1] + 1e-12):
            raise InputError(f"states_at: times must lie within the run [{self.t[0]:g}, {self.t[-1]:g}] s")
        T = np.clip(T, self.t[0], self.t[-1])
        start = np.clip(np.searchsorted(self.t, T, side="right") - 1, 0, len(self.t) - 1)
        ph = np.empty(T.size, int)
        Q = np.empty((T.size, self.q.shape[1]))
        Vv = np.empty((T.size, self.v.shape[1]))
        meta = self.meta
        for i in np.unique(start):
            sel = np.flatnonzero(start == i)
            k = int(self.phase[min(i + 1, len(self.t) - 1)])
            model = self.models[k]
            ts = np.unique(T[sel])
            exact = ts <= self.t[i] + 1e-13
            out = {}
            for tt in ts[exact]:
                out[float(tt)] = (self.q[i], self.v[i])
            if not np.all(exact):
                qi, vi, _ = project(model, float(self.t[i]), self.q[i].copy(), self.v[i].copy(),
                                    tol=min(meta.get("atol", 1e-8), 1e-10))
                te = np.concatenate([[self.t[i]], ts[~exact]])
                res = simulate(model, (float(self.t[i]), float(te[-1])), meta.get("method", "jit-dop853-projection"),
                               q0=qi, v0=vi, t_eval=te, rtol=meta.get("rtol", 1e-8), atol=meta.get("atol", 1e-8),
                               compute_multipliers=False)
                if res.status == "failed" or len(res.t) != len(te):
                    raise RuntimeError(f"states_at: re-integration from t = {self.t[i]:.6g} s failed: {res.message}")
                for tt, qq, vv in zip(te[1:], res.q[1:], res.v[1:]):
                    out[float(tt)] = (qq, vv)
            for j in sel:
                qq, vv = out[float(T[j])]
                ph[j], Q[j], Vv[j] = k, qq, vv
        return ph, Q, Vv, T

    def rider_loads(self, car: str = "car1", rider_point=None, jerk: bool = True) -> pd.DataFrame:
        """Load factors and jerk at a rider over every phase of the run, one row per output.

        :func:`coaster.rider.rider_loads` of each phase's model (n = Cᵀ Aᵀ (a_P − g_vec)/g in
        car axes x forward, y left, z up), the rows of all phases concatenated.

        Parameters
        ----------
        car : str
            Car body of the rider.
        rider_point : (3,) array_like, optional
            Rider point in car axes (m); default the train's ``rider_point``.
        jerk : bool
            Compute the jerk columns (two more solves per row).

        Returns
        -------
        pandas.DataFrame
            ``t [s]``, ``L [m]`` (lead arc length), ``n_x [g]`` … ``n_z [g]``, with ``jerk`` the
            columns ``jerk_x [g/s]`` … ``jerk_z [g/s]``, and ``v_P [m/s]``.
        """
        from types import SimpleNamespace

        from .rider import rider_loads

        rp = self.train.p.rider_point if rider_point is None else rider_point
        parts = []
        for k, model in enumerate(self.models):
            sel = np.flatnonzero(self.phase == k)
            if not len(sel):
                continue
            res = SimpleNamespace(t=self.t[sel], q=self.q[sel], v=self.v[sel], meta=self.meta, status=self.status)
            parts.append(rider_loads(model, res, car, rp, coordinate=self.train.coordinates[0], jerk=jerk))
        return pd.concat(parts, ignore_index=True)

    def energy_drift(self, L_end: float) -> tuple[float, float, float, float]:
        """Energy drift of the free run (the last phase) up to lead arc length ``L_end``.

        drift = max ``|E − E_0|`` / T_peak over the outputs of the last phase with L_1 < ``L_end``,
        E = T + V (:meth:`energy`), T_peak = ½ M_e max L̇_1² with the effective mass M_e = total
        mass + n_wheelsets × wheel spin mass.  Without dissipative forces before ``L_end`` the
        drift measures the integration error.

        Returns
        -------
        (drift [-], t from [s], t to [s], T_peak [J])
        """
        E = self.energy()
        sel = (self.phase == len(self.models) - 1) & (self.L[:, 0] < L_end)
        if not np.any(sel):
            raise InputError(f"energy_drift: no output of the free run before L = {L_end!r} m")
        p = self.train.p
        T_peak = 0.5 * (p.total_mass + p.n_wheelsets * p.wheel_spin_mass) * float(np.max(self.Ldot[sel, 0]) ** 2)
        Es = E[sel]
        return float(np.max(np.abs(Es - Es[0])) / T_peak), float(self.t[sel][0]), float(self.t[sel][-1]), T_peak

    def table(self) -> pd.DataFrame:
        """Lead arc length, speed, acceleration along the track, height, energy, phase: one row per output."""
        m = self.models[0]
        ws1 = m.q_slice(self.train.wheelsets[0])
        _, iv = self.train.lead_index(m)
        return pd.DataFrame({
            "t [s]": self.t,
            "L [m]": self.L[:, 0],
            "speed [m/s]": self.Ldot[:, 0],
            "acceleration [m/s2]": self.vdot[:, iv],
            "z [m]": self.q[:, ws1][:, 2],
            "E [J]": self.energy(),
            "phase": [self.phases["phase"].iloc[k] for k in self.phase],
        })


def _accelerations(model, T, Q, V):
    """v̇ and λ at output states: compiled index-1 solve when the model compiles, numpy otherwise."""
    n = len(T)
    A = np.zeros((n, model.n_v))
    Lm = np.zeros((n, model.n_c))
    try:
        from core.compiled import compile_model, make_workspace
        from core.compiled import dynamics as D
        from core.compiled.protocol import OK

        cm = compile_model(model)
        ws = make_workspace(cm)
        st = cm.initial_states()
        for i in range(n):
            lam = np.zeros(max(model.n_c, 1))
            a = np.zeros(model.n_v)
            s = D.accelerations(cm.data, st, ws, float(T[i]), np.array(Q[i], float), np.array(V[i], float),
                                0.0, 0.0, a, lam)
            A[i] = a
            if s != OK:
                raise RuntimeError(f"compiled accelerations failed (status {s}) at t = {T[i]:.6g} s")
            Lm[i] = lam[:model.n_c]
        return A, Lm
    except Exception as exc:  # noqa: BLE001 - NotCompilable or a failed compiled solve: use numpy
        from core.dynamics import accelerations
        from core.errors import NotCompilable

        if not isinstance(exc, (NotCompilable, RuntimeError)):
            raise
        for i in range(n):
            A[i], Lm[i] = accelerations(model, float(T[i]), Q[i], V[i])
        return A, Lm


def _section_at(sections: pd.DataFrame | None, L: float, period: float) -> str:
    return str(sections_at(sections, [L], period)[0])


def sections_at(sections: pd.DataFrame | None, L, period: float = 0.0) -> np.ndarray:
    """The name of the track section at each arc length.

    Section i covers L_start,i ≤ x < L_end,i with x = L mod ``period`` on a closed track
    (``period`` its length) and x = L on an open one (``period`` = 0).

    Parameters
    ----------
    sections : pandas.DataFrame or None
        ``section``, ``L_start [m]``, ``L_end [m]`` (:func:`circuit_sections`).
    L : (n,) array_like
        Arc lengths (m).
    period : float
        Length of a closed track (m), 0 for an open one.

    Returns
    -------
    (n,) ndarray of str (object)
        The section's name, ``"track"`` where no section covers L (or without sections).
    """
    L = np.atleast_1d(np.asarray(L, float))
    x = np.mod(L, period) if period > 0 else L
    out = np.full(len(x), "track", dtype=object)
    if sections is None:
        return out
    for _, row in sections.iloc[::-1].iterrows():  # the first covering row wins
        out[(x >= row["L_start [m]"]) & (x < row["L_end [m]"])] = str(row["section"])
    return out


@checked_options
def run_train(train: Train, L_start: float, speed: float, L_stop: float, *, chain: ChainLift | None = None,
              forces: TrackForces | None = None, method: str = "jit-dop853-projection", rtol: float = 1e-8,
              atol: float = 1e-8, output_step: float = 0.05, chunk: float = 10.0, t_max: float = 600.0,
              max_step: float = np.inf, sections: pd.DataFrame | None = None, progress=None,
              accept=()) -> TrainRun:
    r"""Run the train from lead arc length ``L_start`` at lead speed ``speed`` until ``L_stop``.

    With ``chain`` the first phase drives L_1 at the chain speed from ``chain.L_start`` (= ``L_start``,
    and ``speed`` must equal the chain speed) to ``chain.L_end``; the train then runs free under
    gravity and ``forces``.  The free run is integrated in chunks of ``chunk`` s; after each the
    lead speed is checked: if L̇_1 changes sign (outside the chain) the train did not crest a hill
    and rolls back — the run stops at the reversal with status ``"rolled back"`` and a message
    naming the arc length, section and time.  It also stops at ``L_stop`` (``"finished"``), at
    ``t_max`` (``"time limit"``) or when the integrator fails (``"failed"``, its message).

    Parameters
    ----------
    train : Train
    L_start, speed : float
        Initial lead arc length (m) and speed along the track (m/s, > 0: forward).
    L_stop : float
        The run ends when L_1 reaches it (m; unbounded on a closed track: a lap is + length).
    chain : ChainLift, optional
    forces : TrackForces, optional
    method, rtol, atol, max_step
        Integrator (any of :data:`core.integrators.METHODS`) and its tolerances.
    output_step : float
        Output interval (s).
    chunk : float
        Length of the free-running chunks between the roll-back checks (s).
    t_max : float
        Largest simulated time (s).
    sections : pandas.DataFrame, optional
        Named sections (:func:`circuit_sections`) for the messages.
    accept : sequence of str
        Quantities whose plausible range is not enforced (``track_speed``, ``output_step``).

    Returns
    -------
    TrainRun

    Notes
    -----
    On an open track a run that reaches its end (or, rolling back, its start) ends with status
    ``"failed"`` and a message naming the end of the track; the rows computed up to there are
    kept.  The centreline is never extrapolated (the path joint refuses an arc length outside
    the track: :class:`core.errors.DataRangeError` on the numpy path, ``OUT_OF_RANGE`` on the
    compiled one).  ``speed`` may be a string with its unit ("29 km/h"); it and
    ``output_step`` are checked against their plausible ranges.
    """
    from core.dynamics import project
    from core.inputs import parse_quantity
    from core.simulation import simulate

    from .inputs import check

    speed = float(parse_quantity(speed, "m/s", where="run_train(speed=...)"))
    check("track_speed", abs(speed), where="run_train(speed=...)", accept=accept)
    output_step = float(check("output_step", output_step, where="run_train(output_step=...)", accept=accept))
    if not (np.isfinite(L_stop) and L_stop > L_start):
        raise InputError(f"run_train: L_stop must be beyond L_start = {L_start!r} m, got {L_stop!r}")
    if output_step <= 0 or chunk <= 0:
        raise InputError(f"run_train: output_step and chunk must be > 0, got {output_step!r}, {chunk!r}")
    period = float(train.track.length) if getattr(train.track, "closed", False) else 0.0
    track_name = getattr(train.track, "name", "track")

    ts, qs, vs, accs, ph, lams, models, rows = [], [], [], [], [], [], [], []
    wall = 0.0
    t0 = 0.0
    status, message = STATUS_FINISHED, ""

    def record(res, model, k, first):
        sl = slice(0 if first else 1, None)
        T, Q, V = res.t[sl], res.q[sl], res.v[sl]
        A, Lm = _accelerations(model, T, Q, V)
        ts.append(T), qs.append(Q), vs.append(V), accs.append(A), ph.append(np.full(len(T), k))
        return Lm

    open_length = None if period else float(train.track.length)
    if open_length is not None and chain is not None and chain.L_end > open_length:
        raise InputError(f"run_train: the chain lift ends at L = {chain.L_end:g} m, beyond the end of the open track "
                         f"{track_name!r} (L = {open_length:.6g} m)")
    if chain is not None:
        if abs(chain.L_start - L_start) > 1e-9 or abs(chain.speed - speed) > 1e-12:
            raise InputError(f"run_train: the chain lift starts at L = {chain.L_start!r} m at {chain.speed!r} m/s; "
                             f"the train must start there at that speed, got L = {L_start!r}, speed = {speed!r}")
        mc = train.model(L_start, speed, forces, chain, t0=0.0, name=f"{train.name} (chain)")
        T = chain.duration
        n = max(2, int(math.ceil(T / output_step)) + 1)
        w0 = _time.perf_counter()
        res = simulate(mc, (0.0, T), method, t_eval=np.linspace(0.0, T, n), rtol=rtol, atol=atol,
                       max_step=max_step, compute_multipliers=False)
        wall += _time.perf_counter() - w0
        lams.append(record(res, mc, 0, True))
        models.append(mc)
        rows.append({"phase": "chain lift", "t_start [s]": 0.0, "t_end [s]": float(res.t[-1]),
                     "L_start [m]": L_start, "L_end [m]": float(res.q[-1, train.lead_index(mc)[0]]),
                     "method": method, "integrator": res.status, "wall [s]": wall})
        if res.status == "failed":
            status, message = STATUS_FAILED, f"chain lift: {res.message}"
        q, v, t0 = res.q[-1].copy(), res.v[-1].copy(), float(res.t[-1])
        mf = train.model(L_start, speed, forces, name=f"{train.name} (free)")
    else:
        mf = train.model(L_start, speed, forces, name=f"{train.name} (free)")
        q, v = np.array(mf.q0), np.array(mf.v0)
    kf = len(models)
    models.append(mf)
    iq, iv = train.lead_index(mf)
    t_free0, L_free0, w_free0 = t0, float(q[iq]), wall
    lam_free = []
    first = chain is None  # after a chain phase the release state is already recorded
    sign0 = np.sign(v[iv]) if v[iv] != 0 else 1.0
    while status == STATUS_FINISHED:
        if t0 >= t_max - 1e-12:
            status = STATUS_TIME_LIMIT
            message = f"time limit t_max = {t_max:g} s reached at L = {q[iq]:.6g} m before L_stop = {L_stop:g} m"
            break
        t1 = min(t0 + chunk, t_max)
        n = max(2, int(round((t1 - t0) / output_step)) + 1)
        q, v, _ = project(mf, t0, q, v, tol=min(atol, 1e-10))
        w0 = _time.perf_counter()
        res = simulate(mf, (t0, t1), method, q0=q, v0=v, t_eval=np.linspace(t0, t1, n), rtol=rtol, atol=atol,
                       max_step=max_step, compute_multipliers=False)
        wall += _time.perf_counter() - w0
        Ld = res.v[:, iv]
        L1 = res.q[:, iq]
        cut = len(res.t)
        rev = np.flatnonzero(np.sign(Ld[1:]) * sign0 < 0)
        done = np.flatnonzero(L1 >= L_stop)
        if open_length is not None:  # the centreline is extrapolated past an open track's ends: cut there
            Lrear = res.q[:, iq + len(train.coordinates) - 1]
            off = np.flatnonzero((L1 > open_length) | (Lrear < 0.0))
            if len(off) and (not len(done) or off[0] <= done[0]) and (not len(rev) or off[0] <= rev[0] + 1):
                k = int(off[0])
                ahead = L1[k] > open_length
                x = (L1 - open_length) if ahead else -Lrear
                tz = res.t[k - 1] + (res.t[k] - res.t[k - 1]) * (-x[k - 1]) / (x[k] - x[k - 1]) if k else res.t[0]
                status = STATUS_FAILED
                message = (f"free running: the train reached the {'end' if ahead else 'start'} of the open track "
                           f"{track_name!r} (L = {open_length if ahead else 0.0:.6g} m) at t = {tz:.4g} s "
                           f"({'lead wheelset ws1' if ahead else 'rear wheelset ' + train.wheelsets[-1]}); the "
                           f"centreline is not extrapolated: the rows up to there are kept; "
                           + (f"stop before the end (L_stop <= {open_length:.6g} m) or extend the track" if ahead
                              else "the train ran backwards off the start"))
                rev, done = rev[:0], done[:0]
                cut = max(k, 1)
        if len(rev) and (not len(done) or rev[0] + 1 <= done[0]):
            i = int(rev[0])
            tz = res.t[i] + (res.t[i + 1] - res.t[i]) * Ld[i] / (Ld[i] - Ld[i + 1])
            Lz = float(np.interp(tz, res.t[i:i + 2], L1[i:i + 2]))
            status = STATUS_ROLLED_BACK
            message = (f"the train did not crest the hill and rolls back: lead speed L̇_1 = 0 at L = {Lz:.2f} m "
                       f"({_section_at(sections, Lz, period)}) at t = {tz:.3f} s, after free running from "
                       f"L = {L_free0:.2f} m")
            cut = i + 2
        elif len(done):
            cut = int(done[0]) + 1
        lam_free.append(record(type("R", (), {"t": res.t[:cut], "q": res.q[:cut], "v": res.v[:cut]}), mf, kf, first))
        first = False
        if res.status == "failed" and cut == len(res.t):
            status, message = STATUS_FAILED, f"free running: {res.message}"
            break
        if status != STATUS_FINISHED:
            break
        if len(done):
            message = f"reached L_stop = {L_stop:g} m at t = {res.t[cut - 1]:.3f} s"
            break
        q, v, t0 = res.q[-1].copy(), res.v[-1].copy(), float(res.t[-1])
        if progress is not None:
            progress(t0, float(q[iq]))
    lams.append(np.vstack(lam_free) if lam_free else np.zeros((0, mf.n_c)))
    T = np.concatenate(ts)
    rows.append({"phase": "free running", "t_start [s]": t_free0, "t_end [s]": float(T[-1]),
                 "L_start [m]": L_free0, "L_end [m]": float(np.concatenate(qs)[-1, iq]), "method": method,
                 "integrator": status, "wall [s]": wall - w_free0})
    return TrainRun(train, T, np.vstack(qs), np.vstack(vs), np.vstack(accs), np.concatenate(ph), lams, models,
                    pd.DataFrame(rows), status, message, wall,
                    meta={"method": method, "rtol": rtol, "atol": atol, "output_step": output_step, "chunk": chunk})


def _section_labels(run: TrainRun, sections: pd.DataFrame | None):
    """(period of a closed track or 0, section label of the lead wheelset per output row,
    section -> (L_start, L_end))."""
    period = float(run.train.track.length) if getattr(run.train.track, "closed", False) else 0.0
    if sections is None:
        return period, np.array(["all"] * len(run.t), dtype=object), {}
    labels = sections_at(sections, run.L[:, 0], period)
    bounds = {str(r["section"]): (float(r["L_start [m]"]), float(r["L_end [m]"])) for _, r in sections.iterrows()}
    return period, labels, bounds


def _boundary_time(t, L1, period, i, Lb, state) -> float:
    """Time in [t_i, t_i+1] where L_1 (mod period) passes the boundary Lb: linear guess between
    the outputs, then two Newton steps t <- t - (L_1(t) - Lb)/dL_1/dt on ``state(t) -> (L_1, dL_1/dt)``."""
    a, b = L1[i], L1[i + 1]
    if period:
        Lb = Lb + period * np.floor(min(a, b) / period)
        if Lb < min(a, b) - 1e-9:
            Lb += period
    x = (Lb - a) / (b - a) if b != a else 0.0
    tc = float(t[i] + np.clip(x, 0.0, 1.0) * (t[i + 1] - t[i]))
    for _ in range(2):
        L, Ld = state(tc)
        if Ld == 0.0:
            break
        tc = float(np.clip(tc - (L - Lb) / Ld, t[i], t[i + 1]))
    return tc


def _occurrences(t, L1, labels, bounds, crossing):
    """Contiguous occurrences of a section: [name, first row, last row, entry time, exit time]
    (None at the run's ends); a boundary time from ``crossing(i, L_b)`` (the midpoint of the two
    outputs for a boundary of an unnamed stretch)."""
    occ = []
    i0 = 0
    for i in range(1, len(t) + 1):
        if i == len(t) or labels[i] != labels[i0]:
            occ.append([labels[i0], i0, i - 1, None, None])
            i0 = i
    for k in range(len(occ) - 1):
        name, b = occ[k][0], occ[k][2]
        forward = L1[b + 1] >= L1[b]
        Lb = bounds.get(occ[k + 1][0] if forward else name, (None,))[0]
        tc = 0.5 * (t[b] + t[b + 1]) if Lb is None else crossing(b, Lb)
        occ[k][4] = tc
        occ[k + 1][3] = tc
    return occ


def section_extremes(run: TrainRun, channels, names, sections: pd.DataFrame | None = None,
                     n_fine: int = 12) -> pd.DataFrame:
    r"""Maximum and minimum of functions of the state per track section, independent of the output step.

    A statistic read from a run's outputs moves with the output step, most where the extreme
    lies at a section boundary or between two outputs.  Here, per contiguous occurrence of a
    section (the section of the lead wheelset's arc length L_1) and for each channel and sign:

    1. the section's boundaries are located in time (L_1(t*) = L_b: linear guess between the
       outputs, Newton steps t* <- t* - (L_1(t*) - L_b)/dL_1/dt on the re-integrated state) and
       the channels are evaluated there (a boundary state belongs to both sections);
    2. around the extreme output sample the channel is evaluated at ``n_fine`` times between its
       two neighbours (clipped to the section), then at ``n_fine`` times within one fine spacing
       of the best, and at the vertex of the parabola through the best and its two neighbours;

    with states from :meth:`TrainRun.states_at` (re-integration at the run's tolerance) and the
    accelerations and multipliers of the index-1 solve there.  The extreme is the largest of all
    evaluated values: the true one up to the integration error and the parabola's residual on
    the last grid (spacing 4 dt/n_fine^2 for an output step dt).

    Parameters
    ----------
    run : TrainRun
    channels : callable
        ``channels(k, t, q, v, a, lam) -> (m,) array``: the values at one state of phase ``k``
        (``run.models[k]``), with accelerations ``a`` and multipliers ``lam``.
    names : sequence of str
        The m channel names (columns ``{name} max``, ``{name} min``, ``t of {name} max``, ...).
    sections : pandas.DataFrame, optional
        ``section``, ``L_start [m]``, ``L_end [m]`` (e.g. :func:`circuit_sections`); default one
        section ``"all"``.
    n_fine : int
        Evaluations per refinement pass (>= 3).

    Returns
    -------
    pandas.DataFrame
        One row per section, in order of first appearance.
    """
    names = list(names)
    if int(n_fine) < 3:
        raise InputError(f"section_extremes: n_fine must be >= 3, got {n_fine!r}")
    period, labels, bounds = _section_labels(run, sections)
    L1 = run.L[:, 0]
    t = run.t
    cache = {}

    def values(times):
        times = np.asarray(times, float)
        need = [float(x) for x in np.unique(times) if float(x) not in cache]
        if need:
            ph, Q, V, _ = run.states_at(need)
            for p_ in np.unique(ph):
                sel = np.flatnonzero(ph == p_)
                m = run.models[p_]
                iq, iv = run.train.lead_index(m)
                A, Lm = _accelerations(m, np.asarray(need)[sel], Q[sel], V[sel])
                for j, k in enumerate(sel):
                    x = np.asarray(channels(int(p_), need[k], Q[k], V[k], A[j], Lm[j]), float)
                    cache[need[k]] = (x, float(Q[k, iq]), float(V[k, iv]))
        return [cache[float(x)] for x in times]

    first_row = {int(k): int(np.flatnonzero(run.phase == k)[0]) for k in np.unique(run.phase)}
    for i, tt in enumerate(t):  # the output samples themselves (the run's accelerations and multipliers)
        k = int(run.phase[i])
        x = np.asarray(channels(k, tt, run.q[i], run.v[i], run.vdot[i], run.lam[k][i - first_row[k]]), float)
        cache[float(tt)] = (x, float(L1[i]), float(run.Ldot[i, 0]))

    def crossing(i, Lb):
        tc = _boundary_time(t, L1, period, i, Lb, lambda u: values([u])[0][1:])
        values([tc])
        return tc

    occ = _occurrences(t, L1, labels, bounds, crossing)
    values([o[4] for o in occ[:-1]])
    out = {}
    for name, a, b, te, tx in occ:
        lo = float(t[a]) if te is None else te
        hi = float(t[b]) if tx is None else tx
        base = [float(x) for x in t[a:b + 1]] + [x for x in (te, tx) if x is not None]
        for c, ch in enumerate(names):
            for sgn, tag in ((1.0, "max"), (-1.0, "min")):
                vals = {x: sgn * cache[x][0][c] for x in base}

                def add(grid):
                    for x, (n, _, _) in zip(grid, values(grid)):
                        vals[float(x)] = sgn * n[c]

                k = max(range(a, b + 1), key=lambda j: vals[float(t[j])])
                w0 = max(lo, float(t[max(k - 1, 0)]))
                w1 = min(hi, float(t[min(k + 1, len(t) - 1)]))
                if w1 > w0:
                    add(np.linspace(w0, w1, n_fine))
                    best = max(vals, key=vals.get)
                    h = (w1 - w0) / (n_fine - 1)
                    grid = np.linspace(max(lo, best - h), min(hi, best + h), n_fine)
                    add(grid)
                    best = max(vals, key=vals.get)
                    hh = grid[1] - grid[0]
                    if hh > 0 and lo <= best - hh and best + hh <= hi:
                        tp = np.array([best - hh, best, best + hh])
                        add(tp)
                        yp = np.array([vals[float(x)] for x in tp])
                        den = yp[0] - 2 * yp[1] + yp[2]
                        if den < 0:
                            tv = float(best + 0.5 * hh * (yp[0] - yp[2]) / den)
                            if lo <= tv <= hi:
                                add([tv])
                best = max(vals, key=vals.get)
                key = f"{ch} {tag}"
                row = out.setdefault(name, {"section": name})
                v = sgn * vals[best]
                if key not in row or sgn * v > sgn * row[key]:
                    row[key] = v
                    row[f"t of {ch} {tag}"] = best
    df = pd.DataFrame(list(out.values()))
    cols = ["section"] + [f"{ch} {tag}" for ch in names for tag in ("max", "min")]
    df = df[cols + [c for c in df.columns if c not in cols]]
    df.attrs["method"] = (f"extremes at the outputs, at the section boundaries and refined by two passes of {n_fine} "
                          f"re-integrated states and a parabola (coaster.train.section_extremes)")
    return df


def rider_peaks(run: TrainRun, car: str = "car1", rider_point=None, sections: pd.DataFrame | None = None,
                n_fine: int = 12) -> pd.DataFrame:
    """Peak rider load factors per track section, independent of the output step.

    :func:`section_extremes` of the load factor n at the rider point (:mod:`coaster.rider`, car
    axes x forward, y left, z up).

    Parameters
    ----------
    run : TrainRun
    car : str
        Car body of the rider.
    rider_point : (3,) array_like, optional
        Rider point in car axes (m); default the train's ``rider_point``.
    sections : pandas.DataFrame, optional
        As :func:`section_extremes`.
    n_fine : int

    Returns
    -------
    pandas.DataFrame
        ``section``, ``n_x max [g]``, ``n_x min [g]``, ``n_y max [g]``, ``n_y min [g]``,
        ``n_z max [g]``, ``n_z min [g]``, ``|n_y| max [g]``, and the time of each extreme
        (``t of n_z max [s]``, ...).
    """
    from .rider import _Rider

    rp = run.train.p.rider_point if rider_point is None else rider_point
    riders = [_Rider(m, car, rp, None) for m in run.models]
    df = section_extremes(run, lambda k, t, q, v, a, lam: riders[k].loads_given(q, v, a)[0],
                          ["n_x", "n_y", "n_z"], sections, n_fine)
    df = df.rename(columns=lambda c: f"{c} [g]" if c.startswith("n_") else f"{c} [s]" if c.startswith("t of") else c)
    df.insert(7, "|n_y| max [g]", np.maximum(df["n_y max [g]"], -df["n_y min [g]"]))
    return df


def wheel_force_peaks(run: TrainRun, sections: pd.DataFrame | None = None, n_fine: int = 12) -> pd.DataFrame:
    """Extreme wheel forces over all wheelsets per track section, independent of the output step.

    :func:`section_extremes` of max_i F_b,i, min_i F_b,i and max_i ``|F_n,i|`` over the wheelsets
    (the path joints' reactions in the track frame, :func:`wheel_forces`).

    Returns
    -------
    pandas.DataFrame
        ``section``, ``F_b max [kN]``, ``F_b min [kN]``, ``|F_n| max [kN]`` and their times.
    """
    joints = run.train.path_joints

    def ch(k, t, q, v, a, lam):
        m = run.models[k]
        F = np.array([j.reactions(q, j.joint_multipliers(m, lam)) for j in joints]).reshape(len(joints), 6)
        return np.array([F[:, 2].max(), F[:, 2].min(), np.abs(F[:, 1]).max()]) / 1e3

    df = section_extremes(run, ch, ["F_b hi", "F_b lo", "|F_n|"], sections, n_fine)
    out = pd.DataFrame({"section": df["section"], "F_b max [kN]": df["F_b hi max"], "F_b min [kN]": df["F_b lo min"],
                        "|F_n| max [kN]": df["|F_n| max"], "t of F_b max [s]": df["t of F_b hi max"],
                        "t of F_b min [s]": df["t of F_b lo min"], "t of |F_n| max [s]": df["t of |F_n| max"]})
    return out


class _DenseLoads:
    """Load factor n (3,) [g] and its rate dn/dt (3,) [g/s] at the rider point at any time of a
    run, with L_1 and dL_1/dt: outputs from the run's states and accelerations, other times from
    :meth:`TrainRun.states_at`; the rate is the derivative along the flow (central difference of
    the index-1 load factor, :mod:`coaster.rider`, eps = ``jerk_step``); cached by time."""

    def __init__(self, run, car, rider_point, jerk_step):
        from .rider import _Rider

        self.run = run
        rp = run.train.p.rider_point if rider_point is None else rider_point
        self.riders = [_Rider(m, car, rp, None) for m in run.models]
        self.eps = float(jerk_step)
        self.cache = {}
        for k in np.unique(run.phase):
            sel = np.flatnonzero(run.phase == k)
            self._fill(int(k), run.t[sel], run.q[sel], run.v[sel], run.vdot[sel])

    def _fill(self, k, T, Q, V, A=None):
        m, r, e = self.run.models[k], self.riders[k], self.eps
        if A is None:
            A, _ = _accelerations(m, T, Q, V)
        Qp = np.array([m.retract(q, e * v) for q, v in zip(Q, V)])
        Qm = np.array([m.retract(q, -e * v) for q, v in zip(Q, V)])
        Ap, _ = _accelerations(m, T + e, Qp, V + e * A)
        Am, _ = _accelerations(m, T - e, Qm, V - e * A)
        iq, iv = self.run.train.lead_index(m)
        for j, tt in enumerate(T):
            n = r.loads_given(Q[j], V[j], A[j])[0]
            n_p = r.loads_given(Qp[j], V[j] + e * A[j], Ap[j])[0]
            n_m = r.loads_given(Qm[j], V[j] - e * A[j], Am[j])[0]
            nd = (n_p - n_m) / (2 * e)
            self.cache[float(tt)] = (n, nd, float(Q[j, iq]), float(V[j, iv]))

    def __call__(self, tt):
        tt = float(tt)
        if tt not in self.cache:
            ph, Q, V, T = self.run.states_at([tt])
            self._fill(int(ph[0]), np.array([tt]), Q, V)
        return self.cache[tt]


def time_above_limits_dense(run: TrainRun, limits: pd.DataFrame | None = None, sections: pd.DataFrame | None = None,
                            car: str = "car1", rider_point=None, peaks: pd.DataFrame | None = None,
                            xtol: float | None = None, jerk_step: float = 1e-5, warn: bool = True) -> pd.DataFrame:
    r"""Time spent beyond each acceleration-limit level per track section, from the run's dense solution.

    The same table as :func:`coaster.rider.time_above_limits`, but independent of the output step:
    per contiguous occurrence of a section (its boundaries located in time as in
    :func:`section_extremes`) and per limit row (axis, signed level c), the load factor
    n(t) at the rider point and its rate ṅ(t) (derivative along the flow) are known at the
    outputs and, through :meth:`TrainRun.states_at` (re-integration from the output before, at
    the run's tolerance), at any time.  :func:`core.signals.dense_level_intervals` then

    1. searches every output interval whose slopes change sign and whose tangents (Eq. S2 of
       :mod:`core.signals`) reach the level for its extreme (root of ṅ, Brent): an exceedance
       that lies entirely between two outputs is found;
    2. locates every crossing n(t*) = c by a safeguarded Newton iteration t <- t − (n − c)/ṅ
       to ``xtol`` (default 10 rtol max(1 s, output step));

    the time above is the sum of the located intervals, their number the exceedances.  What it
    cannot see: two extremes of n within one output step (ṅ changing sign twice between two
    outputs) — choose the output step below half the shortest period of the load factor.

    Parameters
    ----------
    run : TrainRun
    limits : pandas.DataFrame, optional
        :func:`coaster.rider.read_acceleration_limits` table; default the shipped file.
    sections : pandas.DataFrame, optional
        ``section``, ``L_start [m]``, ``L_end [m]`` (:func:`circuit_sections`); default one
        section ``"all"``.
    car : str
        Car body of the rider.
    rider_point : (3,) array_like, optional
        Default the train's ``rider_point``.
    peaks : pandas.DataFrame, optional
        :func:`rider_peaks` of the same run, sections, car and rider point (computed if not
        given): the ``peak [g]`` column is the section's extreme when it is beyond the level.
    xtol : float, optional
        Time tolerance of the located crossings and extremes (s).
    jerk_step : float
        eps (s) of the derivative along the flow.
    warn : bool
        Issue a :class:`core.signals.GridResolutionWarning` when an exceedance lies between two
        outputs (the value here is right; a table on the output grid does not show it).

    Returns
    -------
    pandas.DataFrame
        One row per (section, limit row): ``section``, ``axis``, ``level [g]``,
        ``max duration [s]``, ``peak [g]``, ``exceedances [-]``, ``time above [s]``,
        ``longest [s]``, ``longest starts at [s]``, ``between outputs [-]`` (exceedances with no
        output inside them), ``verdict``, ``basis``; ``attrs["method"]``, ``attrs["xtol_s"]``.
    """
    import warnings

    from core.signals import GridResolutionWarning, dense_level_intervals

    from .rider import limit_verdict, read_acceleration_limits

    limits = read_acceleration_limits() if limits is None else limits
    rtol = float(run.meta.get("rtol", 1e-8))
    h = float(run.meta.get("output_step", np.max(np.diff(run.t)) if len(run.t) > 1 else 1.0))
    xtol = 10.0 * rtol * max(1.0, h) if xtol is None else float(xtol)
    dense = _DenseLoads(run, car, rider_point, jerk_step)
    if peaks is None:
        peaks = rider_peaks(run, car, rider_point, sections)
    pk = peaks.set_index("section")
    period, labels, bounds = _section_labels(run, sections)
    t, L1 = run.t, run.L[:, 0]
    occ = _occurrences(t, L1, labels, bounds,
                       lambda i, Lb: _boundary_time(t, L1, period, i, Lb, lambda u: dense(u)[2:]))
    rows, missed = [], 0
    for sec in dict.fromkeys(labels):
        for _, lim in limits.iterrows():
            ax = {"x": 0, "y": 1, "z": 2}[lim["axis"]]
            level, allowed = float(lim["level [g]"]), float(lim["max duration [s]"])
            side = "above" if level > 0 else "below"
            ivs = []
            for name, a, b, te, tx in occ:
                if name != sec:
                    continue
                ts = [float(x) for x in t[a:b + 1]]
                ts = sorted(set(([te] if te is not None else []) + [x for x in ts if (te is None or x > te)
                                                                       and (tx is None or x < tx)]
                                + ([tx] if tx is not None else [])))
                if len(ts) < 2:
                    continue
                vals = [dense(x) for x in ts]
                iv = dense_level_intervals(ts, [v[0][ax] for v in vals], [v[1][ax] for v in vals], level, side,
                                           lambda u: (dense(u)[0][ax], dense(u)[1][ax]), xtol)
                if len(iv):
                    iv["between samples"] = ~_grid_sees(iv, t)
                    ivs.append(iv)
            iv = pd.concat(ivs, ignore_index=True) if ivs else None
            if iv is None or not len(iv):
                count, total, longest, at, nb, peak = 0, 0.0, 0.0, np.nan, 0, np.nan
            else:
                k = int(np.argmax(iv["duration [s]"].to_numpy()))
                count, total = len(iv), float(iv["duration [s]"].sum())
                longest, at = float(iv["duration [s]"].iloc[k]), float(iv["start [s]"].iloc[k])
                nb = int(iv["between samples"].sum())
                col = f"n_{lim['axis']} {'max' if level > 0 else 'min'} [g]"
                peak = float(pk.loc[sec, col]) if sec in pk.index and col in pk.columns else \
                    float(iv["peak"].max() if level > 0 else iv["peak"].min())
            missed += nb
            verdict = limit_verdict(count, longest, allowed)
            rows.append({"section": sec, "axis": lim["axis"], "level [g]": level, "max duration [s]": allowed,
                         "peak [g]": peak, "exceedances [-]": count, "time above [s]": total, "longest [s]": longest,
                         "longest starts at [s]": at, "between outputs [-]": nb, "verdict": verdict,
                         "basis": lim.get("basis", "")})
    out = pd.DataFrame(rows)
    out.attrs["source"] = limits.attrs.get("source", "")
    out.attrs["xtol_s"] = xtol
    out.attrs["method"] = ("crossings of each level located on re-integrated states (TrainRun.states_at) by "
                           f"safeguarded Newton to {xtol:.2g} s, extremes between outputs searched where the slopes' "
                           "tangents reach "
                           "the level (core.signals.dense_level_intervals; coaster.train.time_above_limits_dense)")
    if warn and missed:
        warnings.warn(f"time_above_limits_dense: {missed} exceedances lie between two outputs (output step {h:.3g} s): "
                      "their durations come from the dense solution, a table on the output grid does not show them",
                      GridResolutionWarning, stacklevel=2)
    return out


def _grid_sees(iv, t_grid):
    from core.signals import grid_resolution

    return grid_resolution(iv, t_grid)


def wheel_forces(run: TrainRun) -> pd.DataFrame:
    """Wheel forces per wheelset from the path joints' multipliers, one row per output time.

    For wheelset i the reaction of its path joint on the wheelset, resolved in the track frame
    (:meth:`coaster.path_joint.PathFollowingJoint.reactions`): ``ws{i} F_t [N]`` along the track,
    ``ws{i} F_n [N]`` lateral (n, to the left), ``ws{i} F_b [N]`` along the track's up axis b
    (positive: the track pushes the wheelset up), and the moments about the contact point
    ``ws{i} M_t/M_n/M_b [N m]``, with ``t [s]`` and the wheelset's ``L [m]``.
    """
    cols = {"t [s]": run.t}
    for i, joint in enumerate(run.train.path_joints):
        out = np.zeros((len(run.t), 6))
        for k, model in enumerate(run.models):
            sel = np.flatnonzero(run.phase == k)
            if not len(sel):
                continue
            lam6 = joint.joint_multipliers(model, run.lam[k])
            out[sel] = joint.reactions(run.q[sel], lam6)
        ws = run.train.wheelsets[i]
        cols[f"{ws} L [m]"] = run.L[:, i]
        for c, name in enumerate(("F_t [N]", "F_n [N]", "F_b [N]", "M_t [N m]", "M_n [N m]", "M_b [N m]")):
            cols[f"{ws} {name}"] = out[:, c]
    df = pd.DataFrame(cols)
    df.attrs["frame"] = "track frame at each wheelset: t along, n lateral (left), b up; force on the wheelset"
    return df


def chain_force(run: TrainRun) -> pd.DataFrame:
    """Chain pull F = −λ_chain (N) during the chain lift (empty without a chain phase)."""
    m = run.models[0]
    if "chain" not in m.reaction_groups():
        return pd.DataFrame({"t [s]": [], "chain force [N]": []})
    row = m.reaction_groups()["chain"][0]
    sel = np.flatnonzero(run.phase == 0)
    return pd.DataFrame({"t [s]": run.t[sel], "chain force [N]": -run.lam[0][:, row]})


# ---------------------------------------------------------------------------------------------
# the shared circuit
# ---------------------------------------------------------------------------------------------
@lru_cache(maxsize=2)
def circuit_frame(bank: bool = True, max_step: float = 2.0):
    """The shared circuit as a framed track: quintic periodic centreline, rotation-minimising frame.

    ``bank=True`` rolls the frame by the file's roll angles relative to the vertical
    (:class:`coaster.frames.RotationMinimisingFrame` with ``bank_reference="vertical"``, a closed
    quintic spline of the rolls); ``bank=False`` keeps the lateral axis horizontal.  Cached
    (building the table takes a few seconds).

    Returns
    -------
    (RotationMinimisingFrame, CircuitData, SplineCentreline)
    """
    from .frames import Bank, RotationMinimisingFrame
    from .track import circuit_centreline, read_circuit

    data = read_circuit()
    cl = circuit_centreline(data, "quintic")
    b = Bank.from_samples(cl.L_points, data.roll, closed=True, length=cl.length) if bank else None
    fr = RotationMinimisingFrame(cl, bank=b, bank_reference="vertical", max_step=max_step)
    return fr, data, cl


def circuit_sections(data=None, centreline=None) -> pd.DataFrame:
    """Named sections of the circuit as arc-length ranges: one row per run of equal names.

    :func:`named_sections` of the circuit's section names (default: the shared circuit).

    Returns
    -------
    pandas.DataFrame
        ``section``, ``L_start [m]``, ``L_end [m]``, ``length [m]``, ``z_start [m]``, ``z_end [m]``,
        ``z_max [m]``, ``z_min [m]``.
    """
    if data is None or centreline is None:
        _, data, centreline = circuit_frame()
    return named_sections(data.section, centreline)


def named_sections(names, centreline) -> pd.DataFrame:
    """Track sections as arc-length ranges from a section name per control point.

    Control point i's section covers [L_i, L_{i+1}) (L_i its arc length, ``centreline.L_points``);
    a run of equal names i … j is one section [L_i, L_{j+1}), the last run ends at the track's
    length (closed or open).

    Parameters
    ----------
    names : (N,) sequence of str
        Section name of each control point.
    centreline : coaster.track.SplineCentreline
        The spline through the N control points.

    Returns
    -------
    pandas.DataFrame
        ``section``, ``L_start [m]``, ``L_end [m]``, ``length [m]``, ``z_start [m]``, ``z_end [m]``,
        ``z_max [m]``, ``z_min [m]`` (heights from 200 samples of the section).
    """
    names = [str(n) for n in names]
    if len(names) != len(centreline.L_points):
        raise InputError(f"named_sections: {len(names)} names for {len(centreline.L_points)} control points")
    Lp = np.append(centreline.L_points, centreline.length)
    rows = []
    i = 0
    while i < len(names):
        j = i
        while j + 1 < len(names) and names[j + 1] == names[i]:
            j += 1
        L = np.linspace(Lp[i], Lp[j + 1], 200)
        z = centreline.derivatives(L)[0][:, 2]
        rows.append({"section": names[i], "L_start [m]": float(Lp[i]), "L_end [m]": float(Lp[j + 1]),
                     "length [m]": float(Lp[j + 1] - Lp[i]), "z_start [m]": float(z[0]), "z_end [m]": float(z[-1]),
                     "z_max [m]": float(z.max()), "z_min [m]": float(z.min())})
        i = j + 1
    return pd.DataFrame(rows)


#: Operating settings of the circuit scene (SI units): chain, booster and brake speed controls,
#: the dissipative run's rolling resistance and drag, and the integrator.
CIRCUIT_SETTINGS = dict(
    chain_speed=8.0,          # m/s on the Lift section
    booster_speed=22.0,       # m/s target of the Launch section (linear synchronous motors)
    booster_force=40.0e3,     # N
    brake_speed=6.0,          # m/s target of the Brake section
    brake_force=30.0e3,       # N
    gain=2.0e4,               # N s/m of both speed controls
    rolling=0.0025,           # c_rr of the dissipative run
    drag_area=1.2,            # c_d A (m²) of the dissipative run
    rtol=1e-8,
    atol=1e-8,
    method="jit-dop853-projection",
)


def section_summary(loads: pd.DataFrame, rider: pd.DataFrame, wheels: pd.DataFrame,
                    above: pd.DataFrame) -> pd.DataFrame:
    """Per track section: time spent, peak rider loads and wheel forces, the limits exceeded.

    The peaks come from :func:`rider_peaks` and :func:`wheel_force_peaks` (independent of the
    output step); the time in a section is the sum of the output steps that start in it, the
    largest ``|jerk_z|`` is read on the outputs.

    Parameters
    ----------
    loads : pandas.DataFrame
        :meth:`TrainRun.rider_loads` with a ``section`` column (:func:`sections_at` of ``L [m]``).
    rider : pandas.DataFrame
        :func:`rider_peaks` of the run per section.
    wheels : pandas.DataFrame
        :func:`wheel_force_peaks` of the run per section.
    above : pandas.DataFrame
        :func:`time_above_limits_dense` (or :func:`coaster.rider.time_above_limits`) per section.

    Returns
    -------
    pandas.DataFrame
        One row per section in the order of the run: ``time in section [s]``, ``n_z max [g]``,
        ``n_z min [g]``, ``|n_y| max [g]``, ``n_x max [g]``, ``n_x min [g]``, ``|jerk_z| max [g/s]``,
        ``F_b max [kN]``, ``F_b min [kN]``, ``|F_n| max [kN]``, ``limits exceeded``.
    """
    rows = []
    t = loads["t [s]"].to_numpy()
    labels = loads["section"].to_numpy()
    pk = rider.set_index("section")
    wk = wheels.set_index("section")
    for name in dict.fromkeys(labels):
        m = labels == name
        p, w = pk.loc[name], wk.loc[name]
        exceeded = above[(above["section"] == name) & (above["verdict"] == "exceeds")]
        rows.append({
            "section": name, "time in section [s]": float(np.sum(np.diff(t)[m[:-1]])),
            "n_z max [g]": p["n_z max [g]"], "n_z min [g]": p["n_z min [g]"],
            "|n_y| max [g]": p["|n_y| max [g]"], "n_x max [g]": p["n_x max [g]"],
            "n_x min [g]": p["n_x min [g]"],
            "|jerk_z| max [g/s]": loads["jerk_z [g/s]"][m].abs().max(),
            "F_b max [kN]": w["F_b max [kN]"], "F_b min [kN]": w["F_b min [kN]"], "|F_n| max [kN]": w["|F_n| max [kN]"],
            "limits exceeded": ", ".join(f"{r['axis']} {r['level [g]']:+g} g" for _, r in exceeded.iterrows()) or "none",
        })
    return pd.DataFrame(rows)
