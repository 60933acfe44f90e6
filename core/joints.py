r"""Joints and driving constraints as the user declares them.

Joints are located in the *assembled initial configuration*, as in Adams or Simpack: a global
point ``at`` and, for spatial joints, global axis directions.  ``build()`` converts them to
body-fixed markers and expands every joint into the vectorised primitives of
:mod:`core.constraints` (Haug 1989, Table 9.1; Nikravesh 1988, Sec. 7.3):

=================  ========  ===============================================================
joint              planar    spatial (rows)
=================  ========  ===============================================================
Revolute           point(2)  point(3) + dot-1(f_i,h_j) + dot-1(g_i,h_j)            = 5
Spherical          —         point(3)                                               = 3
Universal          —         point(3) + dot-1(h_i,h_j) (cross axes ⊥)               = 4
Cylindrical        —         dot-1(f_i,h_j), dot-1(g_i,h_j), dot-2(f_i,d), dot-2(g_i,d) = 4
Translational      angle +   cylindrical + dot-1(f_i,g_j)                           = 5
                   dot-2(n)
Fixed              point +   point(3) + dot-1(f_i,g_j) + dot-1(g_i,h_j) + dot-1(h_i,f_j) = 6
                   angle
Distance           1         1
=================  ========  ===============================================================

``(f, g, h)`` is an orthonormal marker triad with ``h`` the joint axis.

Reaction forces are reported on the second body (``body_j``), or on ``body_i`` when ``body_j`` is
the ground, at the joint point, in global axes.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import constraints as C
from .drivers import TimeFunction, as_time_function

Array = NDArray[np.float64]


@dataclass
class PrimitiveSpec:
    """One primitive element: its kind, its constructor arguments for one element, a label."""

    kind: type
    params: dict[str, Any]
    label: str


def perpendicular_triad(axis: ArrayLike) -> tuple[Array, Array, Array]:
    """Orthonormal ``(f, g, h)`` with ``h`` along ``axis`` (deterministic choice of f)."""
    h = np.asarray(axis, dtype=float)
    n = np.linalg.norm(h)
    if h.shape != (3,) or not np.isfinite(n) or n == 0.0:
        raise ValueError(f"joint axis {np.asarray(axis).tolist()} is not a non-zero 3-vector")
    h = h / n
    e = np.eye(3)[int(np.argmin(np.abs(h)))]
    f = np.cross(h, e)
    f /= np.linalg.norm(f)
    g = np.cross(h, f)
    return f, g, h


class Joint:
    """Base class: a named constraint between ``body_i`` and ``body_j`` ("ground" allowed)."""

    name: str
    body_i: str
    body_j: str

    def primitives(self, ctx) -> list[PrimitiveSpec]:  # pragma: no cover
        raise NotImplementedError

    def report_point(self, ctx) -> Array:
        """Global point (initial configuration) at which reactions are reported."""
        return np.asarray(getattr(self, "at", np.zeros(ctx.space.dim)), float)


def _vec(x, dim, what, owner):
    a = np.asarray(x, dtype=float)
    if a.shape != (dim,) or not np.all(np.isfinite(a)):
        raise ValueError(f"{owner}: {what} must be a finite vector of length {dim}, got {np.asarray(x).tolist()}")
    return a


@dataclass(frozen=True)
class Revolute(Joint):
    """Revolute (pin) joint at global point ``at``; spatial joints need the global ``axis``."""

    name: str
    body_i: str
    body_j: str
    at: Any
    axis: Any = None

    def primitives(self, ctx):
        bi, bj = ctx.index(self.body_i, self.name), ctx.index(self.body_j, self.name)
        p = _vec(self.at, ctx.space.dim, "point 'at'", f"joint {self.name!r}")
        dim = ctx.space.dim
        out = [PrimitiveSpec(C.PointCoincidence, dict(bi=bi, si=ctx.local_point(bi, p), bj=bj, sj=ctx.local_point(bj, p), dim=dim), f"{self.name}/point")]
        if dim == 3:
            if self.axis is None:
                raise ValueError(f"joint {self.name!r}: a spatial revolute joint needs an axis")
            f, g, h = perpendicular_triad(self.axis)
            out += [
                PrimitiveSpec(C.Dot1, dict(bi=bi, ai=ctx.local_vector(bi, f), bj=bj, aj=ctx.local_vector(bj, h), c=0.0, dim=3), f"{self.name}/f.h"),
                PrimitiveSpec(C.Dot1, dict(bi=bi, ai=ctx.local_vector(bi, g), bj=bj, aj=ctx.local_vector(bj, h), c=0.0, dim=3), f"{self.name}/g.h"),
            ]
        return out


@dataclass(frozen=True)
class Spherical(Joint):
    """Spherical (ball) joint at global point ``at`` (spatial only)."""

    name: str
    body_i: str
    body_j: str
    at: Any

    def primitives(self, ctx):
        if ctx.space.dim != 3:
            raise ValueError(f"joint {self.name!r}: a spherical joint needs a spatial model")
        bi, bj = ctx.index(self.body_i, self.name), ctx.index(self.body_j, self.name)
        p = _vec(self.at, 3, "point 'at'", f"joint {self.name!r}")
        return [PrimitiveSpec(C.PointCoincidence, dict(bi=bi, si=ctx.local_point(bi, p), bj=bj, sj=ctx.local_point(bj, p), dim=3), f"{self.name}/point")]


@dataclass(frozen=True)
class Universal(Joint):
    """Universal (Cardan) joint at ``at``; ``axis_i`` fixed in body i, ``axis_j`` in body j, initially ⊥."""

    name: str
    body_i: str
    body_j: str
    at: Any
    axis_i: Any
    axis_j: Any

    def primitives(self, ctx):
        if ctx.space.dim != 3:
            raise ValueError(f"joint {self.name!r}: a universal joint needs a spatial model")
        bi, bj = ctx.index(self.body_i, self.name), ctx.index(self.body_j, self.name)
        p = _vec(self.at, 3, "point 'at'", f"joint {self.name!r}")
        hi = _vec(self.axis_i, 3, "axis_i", f"joint {self.name!r}")
        hj = _vec(self.axis_j, 3, "axis_j", f"joint {self.name!r}")
        hi, hj = hi / np.linalg.norm(hi), hj / np.linalg.norm(hj)
        if abs(hi @ hj) > 1e-9:
            raise ValueError(f"joint {self.name!r}: universal joint axes must be perpendicular, cos = {hi @ hj:.3g}")
        return [
            PrimitiveSpec(C.PointCoincidence, dict(bi=bi, si=ctx.local_point(bi, p), bj=bj, sj=ctx.local_point(bj, p), dim=3), f"{self.name}/point"),
            PrimitiveSpec(C.Dot1, dict(bi=bi, ai=ctx.local_vector(bi, hi), bj=bj, aj=ctx.local_vector(bj, hj), c=0.0, dim=3), f"{self.name}/hi.hj"),
        ]


def _cylinder_rows(self, ctx, f, g, h, bi, bj, p):
    return [
        PrimitiveSpec(C.Dot1, dict(bi=bi, ai=ctx.local_vector(bi, f), bj=bj, aj=ctx.local_vector(bj, h), c=0.0, dim=3), f"{self.name}/f.h"),
        PrimitiveSpec(C.Dot1, dict(bi=bi, ai=ctx.local_vector(bi, g), bj=bj, aj=ctx.local_vector(bj, h), c=0.0, dim=3), f"{self.name}/g.h"),
        PrimitiveSpec(C.Dot2, dict(bi=bi, ai=ctx.local_vector(bi, f), si=ctx.local_point(bi, p), bj=bj, sj=ctx.local_point(bj, p), c=0.0, dim=3), f"{self.name}/f.d"),
        PrimitiveSpec(C.Dot2, dict(bi=bi, ai=ctx.local_vector(bi, g), si=ctx.local_point(bi, p), bj=bj, sj=ctx.local_point(bj, p), c=0.0, dim=3), f"{self.name}/g.d"),
    ]


@dataclass(frozen=True)
class Cylindrical(Joint):
    """Cylindrical joint: rotation about and sliding along ``axis`` through ``at`` (spatial)."""

    name: str
    body_i: str
    body_j: str
    at: Any
    axis: Any

    def primitives(self, ctx):
        if ctx.space.dim != 3:
            raise ValueError(f"joint {self.name!r}: a cylindrical joint needs a spatial model")
        bi, bj = ctx.index(self.body_i, self.name), ctx.index(self.body_j, self.name)
        p = _vec(self.at, 3, "point 'at'", f"joint {self.name!r}")
        f, g, h = perpendicular_triad(self.axis)
        return _cylinder_rows(self, ctx, f, g, h, bi, bj, p)


@dataclass(frozen=True)
class Translational(Joint):
    """Translational (prismatic) joint: sliding along ``axis`` through ``at``, no relative rotation."""

    name: str
    body_i: str
    body_j: str
    at: Any
    axis: Any

    def primitives(self, ctx):
        bi, bj = ctx.index(self.body_i, self.name), ctx.index(self.body_j, self.name)
        dim = ctx.space.dim
        p = _vec(self.at, dim, "point 'at'", f"joint {self.name!r}")
        ax = _vec(self.axis, dim, "axis", f"joint {self.name!r}")
        if dim == 2:
            u = ax / np.linalg.norm(ax)
            nvec = np.array([-u[1], u[0]])
            return [
                PrimitiveSpec(C.PlanarAngle, dict(bi=bi, bj=bj, c=ctx.angle(bj) - ctx.angle(bi)), f"{self.name}/angle"),
                PrimitiveSpec(C.Dot2, dict(bi=bi, ai=ctx.local_vector(bi, nvec), si=ctx.local_point(bi, p), bj=bj, sj=ctx.local_point(bj, p), c=0.0, dim=2), f"{self.name}/n.d"),
            ]
        f, g, h = perpendicular_triad(ax)
        return _cylinder_rows(self, ctx, f, g, h, bi, bj, p) + [
            PrimitiveSpec(C.Dot1, dict(bi=bi, ai=ctx.local_vector(bi, f), bj=bj, aj=ctx.local_vector(bj, g), c=0.0, dim=3), f"{self.name}/f.g"),
        ]


Prismatic = Translational


@dataclass(frozen=True)
class Fixed(Joint):
    """Rigid (fixed) joint locking all relative motion; reactions reported at ``at``."""

    name: str
    body_i: str
    body_j: str
    at: Any

    def primitives(self, ctx):
        bi, bj = ctx.index(self.body_i, self.name), ctx.index(self.body_j, self.name)
        dim = ctx.space.dim
        p = _vec(self.at, dim, "point 'at'", f"joint {self.name!r}")
        out = [PrimitiveSpec(C.PointCoincidence, dict(bi=bi, si=ctx.local_point(bi, p), bj=bj, sj=ctx.local_point(bj, p), dim=dim), f"{self.name}/point")]
        if dim == 2:
            out.append(PrimitiveSpec(C.PlanarAngle, dict(bi=bi, bj=bj, c=ctx.angle(bj) - ctx.angle(bi)), f"{self.name}/angle"))
        else:
            f, g, h = np.eye(3)
            out += [
                PrimitiveSpec(C.Dot1, dict(bi=bi, ai=ctx.local_vector(bi, f), bj=bj, aj=ctx.local_vector(bj, g), c=0.0, dim=3), f"{self.name}/f.g"),
                PrimitiveSpec(C.Dot1, dict(bi=bi, ai=ctx.local_vector(bi, g), bj=bj, aj=ctx.local_vector(bj, h), c=0.0, dim=3), f"{self.name}/g.h"),
                PrimitiveSpec(C.Dot1, dict(bi=bi, ai=ctx.local_vector(bi, h), bj=bj, aj=ctx.local_vector(bj, f), c=0.0, dim=3), f"{self.name}/h.f"),
            ]
        return out


Rigid = Fixed


@dataclass(frozen=True)
class DistanceJoint(Joint):
    """Massless rigid link between global points ``point_i`` and ``point_j`` (initial configuration).

    ``length`` defaults to their initial distance.
    """

    name: str
    body_i: str
    body_j: str
    point_i: Any
    point_j: Any
    length: float | None = None

    def primitives(self, ctx):
        bi, bj = ctx.index(self.body_i, self.name), ctx.index(self.body_j, self.name)
        dim = ctx.space.dim
        pi = _vec(self.point_i, dim, "point_i", f"joint {self.name!r}")
        pj = _vec(self.point_j, dim, "point_j", f"joint {self.name!r}")
        L = float(np.linalg.norm(pj - pi)) if self.length is None else float(self.length)
        if not L > 0:
            raise ValueError(f"joint {self.name!r}: distance length must be > 0, got {L}")
        return [PrimitiveSpec(C.Distance, dict(bi=bi, si=ctx.local_point(bi, pi), bj=bj, sj=ctx.local_point(bj, pj), length=L, dim=dim), f"{self.name}/distance")]

    def report_point(self, ctx):
        return np.asarray(self.point_j, float)


# --------------------------------------------------------------------------------------------
# Driving constraints
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class JointAngleDriver(Joint):
    """Prescribe the relative angle of a revolute joint: ``θ(t) = θ(0) + f(t)`` with f(0) = 0 usually.

    ``motion`` is a number, a callable f(t), a (times, values) table or a TimeFunction
    (see :mod:`core.drivers`).  The driver's reaction torque is the actuator torque.
    """

    name: str
    joint: Revolute
    motion: Any
    body_i: str = field(init=False, default="")
    body_j: str = field(init=False, default="")

    def __post_init__(self):
        if not isinstance(self.joint, Revolute):
            raise TypeError(f"driver {self.name!r}: joint must be a Revolute, got {type(self.joint).__name__}")
        object.__setattr__(self, "body_i", self.joint.body_i)
        object.__setattr__(self, "body_j", self.joint.body_j)

    @property
    def at(self):
        return self.joint.at

    def primitives(self, ctx):
        fn: TimeFunction = as_time_function(self.motion, label=f"driver {self.name!r}")
        bi, bj = ctx.index(self.body_i, self.name), ctx.index(self.body_j, self.name)
        f0 = fn(0.0)[0]
        if ctx.space.dim == 2:
            c = ctx.angle(bj) - ctx.angle(bi) - f0
            return [PrimitiveSpec(C.PlanarAngleDriver, dict(bi=bi, bj=bj, c=c, functions=fn), f"{self.name}/angle")]
        f, g, h = perpendicular_triad(self.joint.axis)
        return [PrimitiveSpec(C.SpatialAngleDriver, dict(bi=bi, fi=ctx.local_vector(bi, f), gi=ctx.local_vector(bi, g), bj=bj,
                                                         fj=ctx.local_vector(bj, f), c=-f0, functions=fn), f"{self.name}/angle")]


@dataclass(frozen=True)
class PointDriver(Joint):
    """Prescribe the position of a body point along a global direction: ``uᵀ(r_P(t) − r_P(0)) = f(t) − f(0)``."""

    name: str
    body: str
    point: Any
    direction: Any
    motion: Any
    body_i: str = field(init=False, default="")
    body_j: str = field(init=False, default="ground")

    def __post_init__(self):
        object.__setattr__(self, "body_i", self.body)

    @property
    def at(self):
        return self.point

    def primitives(self, ctx):
        fn = as_time_function(self.motion, label=f"driver {self.name!r}")
        bi = ctx.index(self.body, self.name)
        dim = ctx.space.dim
        p = _vec(self.point, dim, "point", f"driver {self.name!r}")
        u = _vec(self.direction, dim, "direction", f"driver {self.name!r}")
        u = u / np.linalg.norm(u)
        origin = p - u * fn(0.0)[0]
        return [PrimitiveSpec(C.PointPositionDriver, dict(bi=bi, si=ctx.local_point(bi, p), u=u, origin=origin, functions=fn, dim=dim), f"{self.name}/position")]


class UserConstraint:
    r"""User-defined holonomic constraint on chosen coordinates (the escape hatch, not vectorised).

    Subclass and implement, for the velocity indices ``v_index`` this constraint acts on and
    the position indices ``q_index`` it reads (both resolved by the builder from body and extra
    coordinate names), the methods below.  ``q`` and ``v`` passed in are the *full* vectors.

    * ``phi(t, q) -> (rows,)``
    * ``jacobian(t, q) -> (rows, len(v_index))`` with respect to ``v[v_index]``
    * ``nu(t, q) -> (rows,)``
    * ``gamma(t, q, v) -> (rows,)``

    The coaster's path-following joint, with the arc length as an extra coordinate, is one.
    ``compiled(layout)`` may supply a compiled kernel (:mod:`core.compiled`).

    Optional, for analyses of a prescribed motion whose frames are independent
    (:meth:`core.model.Model.constraint_terms_frames`): the same four quantities at many states at
    once, ``t`` (n_f,), ``q`` (n_f, n_q), ``v`` (n_f, n_v) the full vectors,

    * ``phi_frames(t, q) -> (n_f, rows)``, ``jacobian_frames(t, q) -> (n_f, rows, len(v_index))``,
    * ``nu_frames(t, q) -> (n_f, rows)``, ``gamma_frames(t, q, v) -> (n_f, rows)``.

    Without them the model evaluates the frames one by one.

    Attributes
    ----------
    name : str
    rows : int
    bodies : list of str
        Bodies whose coordinates it uses (their full blocks are included in v_index).
    coordinates : list of str
        Extra coordinates (added with ``ModelBuilder.add_coordinate``) it uses.
    time_dependent : bool
        Φ depends on time explicitly (a driver); the model then counts as non-conservative.
    """

    name: str = "user"
    rows: int = 1
    #: True when Φ depends on time explicitly (ν ≠ 0); the model is then not conservative
    time_dependent: bool = False
    bodies: tuple[str, ...] = ()
    coordinates: tuple[str, ...] = ()
    body_i: str = "ground"
    body_j: str = "ground"
    at: Any = None

    # filled at build
    q_index: NDArray[np.int64]
    v_index: NDArray[np.int64]

    def bind(self, q_index, v_index, space):
        self.q_index = np.asarray(q_index, np.int64)
        self.v_index = np.asarray(v_index, np.int64)
        self.space = space

    def phi(self, t, q):  # pragma: no cover - abstract
        raise NotImplementedError(f"user constraint {self.name!r} does not implement phi")

    def jacobian(self, t, q):  # pragma: no cover - abstract
        raise NotImplementedError(f"user constraint {self.name!r} does not implement jacobian")

    def nu(self, t, q):
        return np.zeros(self.rows)

    def gamma(self, t, q, v):  # pragma: no cover - abstract
        raise NotImplementedError(f"user constraint {self.name!r} does not implement gamma")

    def compiled(self, layout):
        """The compiled form (:class:`core.compiled.CompiledConstraints`) for the fast integrators.

        Override it with a kernel of :mod:`core.compiled` to put the constraint on the compiled
        path (:class:`core.models.HelixConstraint` is an example); by default the constraint
        evaluates Python code and the compiled integrators refuse the model naming it.
        """
        from .errors import NotCompilable

        raise NotCompilable(f"user constraint {self.name!r} ({type(self).__name__}) has no compiled kernel; "
                            "give it a compiled() method (see core.compiled) or use the numpy integrators")


class CoordinateDriver(UserConstraint):
    r"""Prescribe an extra coordinate of the model as a function of time: ``Φ = x − f(t) = 0``.

    One row on the extra coordinate ``x`` (added with ``ModelBuilder.add_coordinate``):
    ``Φ_x = 1``, ``ν = ḟ(t)``, ``γ = f̈(t)`` (from ``Φ̈ = ẍ − f̈ = 0``).  Its multiplier λ is the
    generalized force the driver exerts, ``Q_x = −λ`` (N for a length coordinate): e.g. the chain of
    a lift hill pulling a path parameter.  ``motion`` is anything :func:`core.drivers.as_time_function`
    accepts; the closed forms and tables (``constant``, ``polynomial``, ``ramp``, ``harmonic``,
    ``tabulated``) also run on the compiled path.

    Parameters
    ----------
    name : str
    coordinate : str
        Name of the extra coordinate.
    motion : number, callable, (times, values) or TimeFunction
        f(t) in the coordinate's unit.

    References
    ----------
    Haug, E. J. (1989). Computer-Aided Kinematics and Dynamics of Mechanical Systems, Sec. 3.5
    (driving constraints ``Φ^D(q, t) = 0`` with ``ν = −Φ^D_t``, ``γ ⊃ −Φ^D_tt``).
    """

    rows = 1
    time_dependent = True

    def __init__(self, name: str, coordinate: str, motion):
        self.name = str(name)
        self.coordinate = str(coordinate)
        self.coordinates = (self.coordinate,)
        self.bodies = ()
        self.body_i = self.body_j = "ground"
        self.at = None
        self.function: TimeFunction = as_time_function(motion, label=f"driver {self.name!r}")

    def phi(self, t, q):
        return np.array([q[self.q_index[0]] - self.function(t)[0]])

    def jacobian(self, t, q):
        return np.ones((1, 1))

    def nu(self, t, q):
        return np.array([self.function(t)[1]])

    def gamma(self, t, q, v):
        return np.array([self.function(t)[2]])

    def compiled(self, layout):
        """Compiled form: :func:`core.compiled.elements.coordinate_driver` (fd: the program of f)."""
        from .compiled.elements import compile_coordinate_driver

        return compile_coordinate_driver(self, layout)
