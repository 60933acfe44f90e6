r"""Kinematics of an OpenSim model in its generalized coordinates: body poses, Jacobians, muscle paths.

:class:`Skeleton` takes an :class:`biomech.osim.OsimModel` and evaluates, for one coordinate vector
or for every frame of a motion at once (``q`` of shape ``(n_frames, n_coordinates)``), the pose of
every body in ground, the Jacobians of the body origins and angular velocities with respect to the
coordinates, and the musculotendon lengths and moment arms of the muscles.  It does not use the
Cartesian engine of :mod:`core`; it is the tree of OpenSim joints evaluated as OpenSim (Simbody)
evaluates it.

Joint transform (OpenSim ``CustomJoint`` = Simbody ``MobilizedBody::FunctionBased``)
-------------------------------------------------------------------------------------
A joint connects a frame F fixed in the parent body P (``X_PF``, the parent offset frame) and a
frame M fixed in the child body C (``X_CM``, the child offset frame).  Its six ``TransformAxis``
entries give, for coordinates q, three angles θ_i = f_i(q_{c_i}) about unit axes a_i and three
displacements s_i = f_{3+i}(q_{c_{3+i}}) along unit axes t_i.  Simbody composes them as
(``Simbody/src/MobilizedBodyImpl.h``, Simbody 3.7, ``FunctionBasedImpl``: axes normalised at
lines 1226-1227; ``calcMobilizerTransformFromQ`` lines 1271-1274):

.. math::

    R_{FM} = R(θ_1, a_1)\, R(θ_2, a_2)\, R(θ_3, a_3), \qquad
    p_{FM} = s_1 t_1 + s_2 t_2 + s_3 t_3                                        \quad (1)

with R(θ, a) = I + sin θ [a]× + (1 − cos θ)[a]×² (Rodrigues, right-handed).  The product is a
*body-fixed* (intrinsic) sequence: a_1 has its components in F, a_2 in the intermediate frame
after the first rotation, a_3 in M (a_3 is fixed in M, a_1 in F).  The translation p_FM -- the
position of M's origin -- is along the axes t_i *expressed in F*, not rotated by R_FM: M's origin
sits at p_FM in F whatever the rotation, which orients M about its own origin (line 1273 assigns
``X.updP()`` from the unrotated ``Atrans`` columns).  OpenSim passes the six axes of the file unchanged
(``SpatialTransform::getAxes``) with the joint frames as ``inbX``/``outbX`` to
``MobilizedBody::FunctionBased`` (``OpenSim/Simulation/SimbodyEngine/CustomJoint.cpp``,
``CustomJoint::extendAddToSystem``).  The child body's pose in ground is then

.. math::

    X_{GC} = X_{GP}\, X_{PF}\, X_{FM}(q)\, X_{CM}^{-1}                           \quad (2)

i.e. R_GC = R_GP R_PF R_FM R_CMᵀ and, with R_GF = R_GP R_PF,
x_F = x_P + R_GP p_PF, x_M = x_F + R_GF p_FM, x_C = x_M − R_GC p_CM.
``PinJoint``, ``SliderJoint`` and ``WeldJoint`` use the same rule with the six equivalent axes the
reader supplies (rotation about F's z axis, translation along F's x axis, none).  OpenSim's
``reverse`` flag only changes which body Simbody treats as inboard (``extendAddToSystem`` swaps
the frames and passes ``Direction::Reverse``); the relation X_FM between the joint frames, and so
Eq. (2), is the same (the optional OpenSim comparison in the tests checks a reversed knee).

Angular velocity and Jacobians (analytic)
-----------------------------------------
Differentiating Eq. (1) (Simbody ``FunctionBasedImpl::CacheInfo::buildH``, lines 1746-1758):

.. math::

    ω_{FM}^F = \dot θ_1 a_1 + \dot θ_2 R_1 a_2 + \dot θ_3 R_1 R_2 a_3, \qquad
    \dot p_{FM}^F = \textstyle\sum_i \dot s_i t_i, \qquad
    \dot θ_i = f_i'(q_{c_i})\, \dot q_{c_i}                                       \quad (3)

(R_i = R(θ_i, a_i)), and along the tree, every vector in ground,

.. math::

    ω_C = ω_P + R_{GF} ω_{FM}^F, \qquad
    \dot x_C = \dot x_P + ω_P × (x_M − x_P) + R_{GF} \dot p_{FM}^F + ω_C × (x_C − x_M). \quad (4)

Eq. (4) is linear in q̇, ω_B = J_ω,B(q) q̇ and ẋ_B = J_x,B(q) q̇; :meth:`Skeleton.forward_kinematics`
with ``jacobians=True`` returns J_x,B = ∂x_B/∂q and J_ω,B for every body, computed with the
functions' analytic first derivatives (:class:`biomech.functions.Function1D`), not by differences.
A point fixed in body B at r = x_S − x_B has J_S = J_x,B − [r]× J_ω,B, and a force f at S with a
torque m on B does the virtual work of the generalized forces Q = J_Sᵀ f + J_ω,Bᵀ m
(:meth:`Skeleton.generalized_forces`).

Muscle paths
------------
A path is the polyline through its *active* points (OpenSim ``GeometryPath`` without wrapping):
``PathPoint`` always, ``ConditionalPathPoint`` while ``range[0] − 1e-5 ≤ q_c ≤ range[1] + 1e-5``
(``ConditionalPathPoint::isActive``), ``MovingPathPoint`` with its location components
f_k(clamp(q_{c_k}, range of c_k)) in its body (``MovingPathPoint::getLocation``).  With the active
points p_1 … p_m in ground and e_k = (p_{k+1} − p_k)/``|p_{k+1} − p_k|``,

.. math::

    L(q) = \sum_{k=1}^{m-1} |p_{k+1} − p_k|, \qquad
    \frac{∂L}{∂q} = \sum_{k=1}^{m} g_k^T \frac{∂p_k}{∂q}, \quad g_k = e_{k-1} − e_k  \quad (5)

(e_0 = e_m = 0), where ∂p_k/∂q = J_x,B − [p_k − x_B]× J_ω,B + R_GB ∂s_k/∂q includes the motion of
a moving point in its body.  The moment arm is r_j = −∂L/∂q_j (Delp & Loan 1995, Eq. 1; An et al.
1984): the generalized force of a unit tension, −g_k being the unit-tension force on the body of
point k.  Eq. (5) is exact wherever the active set does not change and no moving point's
coordinate sits at its clamp limit; :meth:`Skeleton.moment_arm_check` compares it with central
differences of L(q) and marks the entries whose stencil crosses such a switch.

What is not modelled
--------------------
* **Wrapping surfaces**: paths are straight segments between their points.  The reader reports
  wrap objects and path wraps it ignored (``OsimModel.ignored``); :attr:`Skeleton.unwrapped_muscles`
  lists the muscles concerned, whose lengths and moment arms differ from OpenSim's where the path
  would wrap.  (The gait10dof18musc and gait2392 subject01 models used in the tests have none.)
* **Constraints** (``CoordinateCouplerConstraint``): coordinates are used as given and treated as
  independent in the Jacobians; give dependent coordinates consistent values (IK output does).
* Coordinate ``clamped``/``locked`` flags (simulation options, not kinematics).

References
----------
Seth A. et al. (2018) OpenSim: simulating musculoskeletal dynamics and neuromuscular control to
study human and animal movement. PLoS Comput. Biol. 14(7):e1006223.
Sherman M.A., Seth A., Delp S.L. (2011) Simbody: multibody dynamics for biomedical research.
Procedia IUTAM 2:241-261 (mobilizers: X_FM(q), H matrix, Eqs. for ω and v across a mobilizer).
Delp S.L., Loan J.P. (1995) A graphics-based software system to develop and analyze models of
musculoskeletal structures. Comput. Biol. Med. 25(1):21-34, Eq. 1 (r = −∂L/∂q).
An K.N., Takahashi K., Harrigan T.P., Chao E.Y. (1984) Determination of muscle orientations and
moment arms. J. Biomech. Eng. 106:280-282.
Source read for the definitions (not copied): Simbody 3.7 ``Simbody/src/MobilizedBodyImpl.h``
(``FunctionBasedImpl``); opensim-core ``CustomJoint.cpp``, ``SpatialTransform.cpp``,
``ConditionalPathPoint.cpp``, ``MovingPathPoint.cpp``.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from functools import cached_property

import numpy as np
import pandas as pd

from core.errors import InputError, ModelError

from .osim import ConditionalPathPoint, MovingPathPoint, OsimModel, PathPoint

__all__ = [
    "Skeleton",
    "BodyKinematics",
    "MuscleGeometry",
    "MusclePath",
    "MomentArmCheck",
    "axis_rotation",
]

#: ConditionalPathPoint activity tolerance on the coordinate range [rad or m], as OpenSim's
#: ``ConditionalPathPoint::isActive``.
CONDITIONAL_TOLERANCE = 1e-5


# =============================================================================================
# small vectorised geometry
# =============================================================================================


def axis_rotation(axis, angle) -> np.ndarray:
    r"""Rotation matrices R(θ, a) = I + sin θ [a]× + (1 − cos θ)[a]×² about a unit axis.

    Parameters
    ----------
    axis : array_like, shape (3,)
        Rotation axis (normalised here).
    angle : array_like, shape (n,)
        Angles θ [rad], right-handed about ``axis``.

    Returns
    -------
    ndarray, shape (n, 3, 3)
    """
    a = np.asarray(axis, float)
    a = a / np.linalg.norm(a)
    th = np.atleast_1d(np.asarray(angle, float))
    k = np.array([[0.0, -a[2], a[1]], [a[2], 0.0, -a[0]], [-a[1], a[0], 0.0]])
    k2 = k @ k
    return np.eye(3) + np.sin(th)[:, None, None] * k + (1.0 - np.cos(th))[:, None, None] * k2


def _cross_columns(vectors: np.ndarray, columns: np.ndarray) -> np.ndarray:
    """``columns[..., :, j] × vectors`` for every column j: (n, 3, k) × (n, 3) -> (n, 3, k).

    Written out by components: ``np.cross`` with axis arguments spends most of its time moving
    axes on arrays this small (the products and their order are those of ``np.cross``)."""
    c0, c1, c2 = columns[:, 0], columns[:, 1], columns[:, 2]
    v0, v1, v2 = vectors[:, 0, None], vectors[:, 1, None], vectors[:, 2, None]
    out = np.empty(columns.shape)
    out[:, 0] = c1 * v2 - c2 * v1
    out[:, 1] = c2 * v0 - c0 * v2
    out[:, 2] = c0 * v1 - c1 * v0
    return out


def _cross_last(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``a × b`` along the last axis (length 3), by components as :func:`_cross_columns`."""
    out = np.empty(np.broadcast_shapes(a.shape, b.shape))
    out[..., 0] = a[..., 1] * b[..., 2] - a[..., 2] * b[..., 1]
    out[..., 1] = a[..., 2] * b[..., 0] - a[..., 0] * b[..., 2]
    out[..., 2] = a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]
    return out


# =============================================================================================
# results
# =============================================================================================


@dataclass(frozen=True, eq=False)
class BodyKinematics:
    """Poses of the bodies in ground, optionally with their Jacobians.

    Attributes
    ----------
    body_names : tuple of str
        The model's bodies in file order (ground excluded).
    coordinate_names : tuple of str
        Columns of ``q`` and of the Jacobians.
    q : ndarray, shape (n_frames, n_coordinates)
        The coordinates evaluated (SI: rad, m).
    rotation : ndarray, shape (n_frames, n_bodies, 3, 3)
        R_GB: columns are the body's x, y, z axes expressed in ground.
    origin : ndarray, shape (n_frames, n_bodies, 3)
        Body origin in ground [m].
    origin_jacobian : ndarray, shape (n_frames, n_bodies, 3, n_coordinates) or None
        J_x = ∂(origin)/∂q, in ground [m/rad or m/m].
    angular_jacobian : ndarray, shape (n_frames, n_bodies, 3, n_coordinates) or None
        J_ω with ω_B = J_ω q̇, in ground [rad/rad or rad/m].
    time : ndarray, shape (n_frames,) or None
        Times of the frames [s] when the coordinates came from a motion table.
    """

    body_names: tuple[str, ...]
    coordinate_names: tuple[str, ...]
    q: np.ndarray
    rotation: np.ndarray
    origin: np.ndarray
    origin_jacobian: np.ndarray | None = None
    angular_jacobian: np.ndarray | None = None
    time: np.ndarray | None = None

    @property
    def n_frames(self) -> int:
        return int(self.origin.shape[0])

    def index(self, body: str) -> int:
        """Position of ``body`` in :attr:`body_names` (InputError naming it if absent)."""
        try:
            return self.body_names.index(body)
        except ValueError:
            raise InputError(f"no body {body!r}; bodies: {', '.join(self.body_names)}") from None

    def _require_jacobians(self, what: str):
        if self.angular_jacobian is None:
            raise InputError(f"{what} needs the Jacobians: call forward_kinematics(q, jacobians=True)")

    def angular_velocity(self, qdot, expressed_in: str = "body") -> np.ndarray:
        r"""Body angular velocities ω_B = J_ω q̇ [rad/s], shape (n_frames, n_bodies, 3).

        Parameters
        ----------
        qdot : array_like, shape (n_frames, n_coordinates) or (n_coordinates,)
            Coordinate rates [rad/s, m/s].
        expressed_in : {"body", "ground"}
            ``"body"``: components in each body's own frame, R_GBᵀ ω_B (the body-frame angular
            velocity); ``"ground"``: in ground.
        """
        self._require_jacobians("angular_velocity")
        qd = _rates(qdot, self.q.shape)
        w = np.einsum("nbij,nj->nbi", self.angular_jacobian, qd)
        if expressed_in == "ground":
            return w
        if expressed_in == "body":
            return np.einsum("nbji,nbj->nbi", self.rotation, w)
        raise InputError(f"expressed_in must be 'body' or 'ground', got {expressed_in!r}")

    def origin_velocity(self, qdot) -> np.ndarray:
        """Velocity of each body origin in ground, J_x q̇ [m/s], shape (n_frames, n_bodies, 3)."""
        self._require_jacobians("origin_velocity")
        return np.einsum("nbij,nj->nbi", self.origin_jacobian, _rates(qdot, self.q.shape))

    def origins_table(self) -> pd.DataFrame:
        """Body origins in ground as a table: ``time`` (if known), then ``<body>_x``, ``_y``, ``_z`` [m]."""
        cols = {}
        if self.time is not None:
            cols["time"] = self.time
        for b, name in enumerate(self.body_names):
            for k, ax in enumerate("xyz"):
                cols[f"{name}_{ax}"] = self.origin[:, b, k]
        df = pd.DataFrame(cols)
        df.attrs["units"] = {c: ("s" if c == "time" else "m") for c in df.columns}
        return df


@dataclass(frozen=True, eq=False)
class MuscleGeometry:
    """Musculotendon lengths and moment arms.

    Attributes
    ----------
    muscle_names, coordinate_names : tuple of str
    length : ndarray, shape (n_frames, n_muscles)
        L(q) [m].
    moment_arm : ndarray, shape (n_frames, n_muscles, n_coordinates) or None
        r = −∂L/∂q [m for rotational coordinates; dimensionless for translational ones].
    time : ndarray or None
    """

    muscle_names: tuple[str, ...]
    coordinate_names: tuple[str, ...]
    length: np.ndarray
    moment_arm: np.ndarray | None = None
    time: np.ndarray | None = None

    def of(self, muscle: str, coordinate: str | None = None) -> np.ndarray:
        """Length of ``muscle`` (shape (n_frames,)) or, with ``coordinate``, its moment arm."""
        try:
            i = self.muscle_names.index(muscle)
        except ValueError:
            raise InputError(f"no muscle {muscle!r}") from None
        if coordinate is None:
            return self.length[:, i]
        if self.moment_arm is None:
            raise InputError("moment arms were not computed (moment_arms=False)")
        try:
            j = self.coordinate_names.index(coordinate)
        except ValueError:
            raise InputError(f"no coordinate {coordinate!r}") from None
        return self.moment_arm[:, i, j]


@dataclass(frozen=True, eq=False)
class MusclePath:
    """The active path of one muscle at one pose.

    Attributes
    ----------
    muscle : str
    point_names, bodies : tuple of str
        The active points in path order and the bodies they are fixed in.
    local : ndarray, shape (m, 3)
        Their locations in their bodies [m] (moving points evaluated at q).
    positions : ndarray, shape (m, 3)
        Their positions in ground [m].
    length : float
        Σ ``|p_{k+1} − p_k|`` [m].
    """

    muscle: str
    point_names: tuple[str, ...]
    bodies: tuple[str, ...]
    local: np.ndarray
    positions: np.ndarray
    length: float


@dataclass(frozen=True, eq=False)
class MomentArmCheck:
    """Analytic moment arms against central differences of L(q).

    Attributes
    ----------
    analytic, finite_difference : ndarray, shape (n_frames, n_muscles, n_coordinates)
        r = −∂L/∂q from Eq. (5) and −(L(q + h e_j) − L(q − h e_j)) / (2h).
    valid : ndarray of bool, same shape
        False where the stencil q ± h e_j changes the set of active path points or crosses the
        clamp limit of a moving point's coordinate (L is not differentiable there).
    step : float
        h [rad or m].
    """

    muscle_names: tuple[str, ...]
    coordinate_names: tuple[str, ...]
    analytic: np.ndarray
    finite_difference: np.ndarray
    valid: np.ndarray
    step: float

    @property
    def error(self) -> np.ndarray:
        """``|analytic − finite difference|``, NaN where not :attr:`valid`."""
        return np.where(self.valid, np.abs(self.analytic - self.finite_difference), np.nan)

    @property
    def max_error(self) -> float:
        """Largest error over the valid entries [m]."""
        e = self.error
        return float(np.nanmax(e)) if np.any(self.valid) else float("nan")


def _rates(qdot, shape) -> np.ndarray:
    qd = np.asarray(qdot, float)
    if qd.ndim == 1:
        qd = np.broadcast_to(qd, shape)
    if qd.shape != shape:
        raise InputError(f"qdot must have shape {shape} or ({shape[1]},), got {np.shape(qdot)}")
    return qd


# =============================================================================================
# compiled model tables
# =============================================================================================


@dataclass(frozen=True, eq=False)
class _CompiledJoint:
    name: str
    parent: int            # index in the internal frame list (0 = ground)
    child: int
    R_PF: np.ndarray       # (3, 3)
    p_PF: np.ndarray       # (3,)
    R_CM: np.ndarray
    p_CM: np.ndarray
    axes: np.ndarray       # (6, 3) unit axes: a1, a2, a3, t1, t2, t3
    functions: tuple       # 6 Function1D
    coords: tuple          # 6 coordinate indices (-1: constant axis)


@dataclass(frozen=True, eq=False)
class _PointTable:
    """All path points of all muscles, in muscle order then path order."""

    muscle: np.ndarray     # (P,) muscle index
    body: np.ndarray       # (P,) internal frame index (0 = ground)
    local: np.ndarray      # (P, 3) fixed location (moving points: value of constant components)
    starts: np.ndarray     # (n_muscles + 1,) first point of every muscle, then P
    cond_points: np.ndarray   # (K,) point indices of conditional points
    cond_coords: np.ndarray   # (K,) their coordinate indices
    cond_ranges: np.ndarray   # (K, 2)
    moving: tuple          # (point, component, coordinate index or -1, function, lo, hi)
    names: tuple           # point names


class Skeleton:
    """Kinematics of an OpenSim model in its generalized coordinates (see the module docstring).

    Parameters
    ----------
    model : OsimModel
        From :func:`biomech.osim.read_osim`.

    Raises
    ------
    core.errors.ModelError
        A joint whose bodies are not the model's, a body reached by two joints or not connected
        to ground, an axis function of an unknown coordinate, a muscle path point on a body the
        model does not have or driven by an unknown coordinate (the muscle and point are named).

    Examples
    --------
    >>> from core.paths import data_path
    >>> from biomech.osim import read_osim
    >>> sk = Skeleton(read_osim(data_path("biomech", "opensim", "gait10dof18musc_subject01_walk",
    ...                                   "subject01.osim")))
    >>> geo = sk.muscle_geometry({"knee_angle_r": -0.5})
    >>> bool(geo.of("vasti_r", "knee_angle_r")[0] > 0)   # knee extensor; flexion is negative
    True
    """

    def __init__(self, model: OsimModel):
        self.model = model
        self.ground = model.ground
        self.coordinate_names: tuple[str, ...] = tuple(c.name for c in model.coordinates)
        self.body_names: tuple[str, ...] = tuple(b.name for b in model.bodies)
        self.muscle_names: tuple[str, ...] = tuple(m.name for m in model.muscles)
        self._coord_index = {n: i for i, n in enumerate(self.coordinate_names)}
        if len(self._coord_index) != len(self.coordinate_names):
            raise ModelError(f"model {model.name!r}: repeated coordinate names")
        # internal frame list: ground first, then the bodies in file order
        self._frame_index = {self.ground: 0, **{b: i + 1 for i, b in enumerate(self.body_names)}}
        self._defaults = np.array([c.default_value for c in model.coordinates], float)
        self._joints = self._compile_joints()
        self._points = self._compile_paths()

    # ---- sizes and names -------------------------------------------------------------------
    @property
    def n_coordinates(self) -> int:
        return len(self.coordinate_names)

    @property
    def n_bodies(self) -> int:
        return len(self.body_names)

    @property
    def n_muscles(self) -> int:
        return len(self.muscle_names)

    def coordinate_index(self, name: str) -> int:
        """Column of coordinate ``name`` in ``q`` (InputError naming it if absent)."""
        try:
            return self._coord_index[name]
        except KeyError:
            raise InputError(f"model {self.model.name!r} has no coordinate {name!r}") from None

    def body_index(self, name: str) -> int:
        """Position of body ``name`` in :attr:`body_names`."""
        if name not in self._frame_index or name == self.ground:
            raise InputError(f"model {self.model.name!r} has no body {name!r}")
        return self._frame_index[name] - 1

    @property
    def default_coordinates(self) -> np.ndarray:
        """Default values of the coordinates (SI), shape (n_coordinates,)."""
        return self._defaults.copy()

    @cached_property
    def unwrapped_muscles(self) -> tuple[str, ...]:
        """Muscles whose path wraps were ignored by the reader (their paths are straight here)."""
        out = []
        for item in self.model.ignored:
            if item.kind == "path wrap" and item.owner.startswith("muscle "):
                name = item.owner[len("muscle "):].strip("'\"")
                if name not in out:
                    out.append(name)
        return tuple(out)

    # ---- compilation -----------------------------------------------------------------------
    def _compile_joints(self) -> tuple[_CompiledJoint, ...]:
        model = self.model
        by_parent: dict[str, list] = {}
        child_of: dict[str, str] = {}
        for j in model.joints:
            for role, body in (("parent", j.parent_body), ("child", j.child_body)):
                if body not in self._frame_index:
                    raise ModelError(f"model {model.name!r}: joint {j.name!r} has {role} body {body!r}, which is "
                                     f"neither ground nor a body of the model")
            if j.child_body == self.ground:
                raise ModelError(f"model {model.name!r}: joint {j.name!r} has ground as its child")
            if j.child_body in child_of:
                raise ModelError(f"model {model.name!r}: body {j.child_body!r} is the child of joints "
                                 f"{child_of[j.child_body]!r} and {j.name!r} (closed loops are not supported)")
            child_of[j.child_body] = j.name
            by_parent.setdefault(j.parent_body, []).append(j)
        order = []
        reached = {self.ground}
        queue = [self.ground]
        while queue:
            body = queue.pop(0)
            for j in by_parent.get(body, []):
                order.append(j)
                reached.add(j.child_body)
                queue.append(j.child_body)
        missing = [b for b in self.body_names if b not in reached]
        if missing:
            raise ModelError(f"model {model.name!r}: bodies {missing} are not connected to {self.ground!r} by joints")
        out = []
        for j in order:
            if len(j.transform_axes) != 6:
                raise ModelError(f"model {model.name!r}: joint {j.name!r} has {len(j.transform_axes)} transform axes, "
                                 f"not 6")
            coords = []
            for ax in j.transform_axes:
                if len(ax.coordinates) > 1:
                    raise ModelError(f"joint {j.name!r}, axis {ax.name!r}: functions of several coordinates "
                                     f"{list(ax.coordinates)} are not supported")
                if ax.coordinates:
                    if ax.coordinates[0] not in self._coord_index:
                        raise ModelError(f"joint {j.name!r}, axis {ax.name!r}: coordinate {ax.coordinates[0]!r} is "
                                         f"not a coordinate of model {model.name!r}")
                    coords.append(self._coord_index[ax.coordinates[0]])
                else:
                    coords.append(-1)
            axes = np.array([np.asarray(ax.axis, float) / np.linalg.norm(ax.axis) for ax in j.transform_axes])
            out.append(_CompiledJoint(
                name=j.name, parent=self._frame_index[j.parent_body], child=self._frame_index[j.child_body],
                R_PF=np.asarray(j.parent_frame.rotation, float), p_PF=np.asarray(j.parent_frame.location, float),
                R_CM=np.asarray(j.child_frame.rotation, float), p_CM=np.asarray(j.child_frame.location, float),
                axes=axes, functions=tuple(ax.function for ax in j.transform_axes), coords=tuple(coords)))
        return tuple(out)

    def _compile_paths(self) -> _PointTable:
        muscle_idx, body_idx, local, names = [], [], [], []
        starts = [0]
        cond_p, cond_c, cond_r = [], [], []
        moving = []
        for m, mus in enumerate(self.model.muscles):
            for pt in mus.path:
                where = f"muscle {mus.name!r}, path point {pt.name!r}"
                if pt.body not in self._frame_index:
                    raise ModelError(f"model {self.model.name!r}: {where} is on {pt.body!r}, which is neither "
                                     f"ground nor a body of the model")
                p = len(body_idx)
                muscle_idx.append(m)
                body_idx.append(self._frame_index[pt.body])
                names.append(pt.name)
                if isinstance(pt, MovingPathPoint):
                    loc = np.zeros(3)
                    for k in range(3):
                        c = pt.coordinates[k]
                        fn = pt.functions[k]
                        if c is None:
                            loc[k] = float(fn(0.0))
                            continue
                        if c not in self._coord_index:
                            raise ModelError(f"model {self.model.name!r}: {where}: coordinate {c!r} of the "
                                             f"{'xyz'[k]} location is not a coordinate of the model")
                        lo, hi = (float(v) for v in pt.ranges[k])
                        moving.append((p, k, self._coord_index[c], fn, lo, hi))
                    local.append(loc)
                elif isinstance(pt, (PathPoint, ConditionalPathPoint)):
                    local.append(np.asarray(pt.location, float))
                    if isinstance(pt, ConditionalPathPoint):
                        if pt.coordinate not in self._coord_index:
                            raise ModelError(f"model {self.model.name!r}: {where}: coordinate {pt.coordinate!r} is "
                                             f"not a coordinate of the model")
                        cond_p.append(p)
                        cond_c.append(self._coord_index[pt.coordinate])
                        cond_r.append(np.asarray(pt.range, float))
                else:
                    raise ModelError(f"model {self.model.name!r}: {where}: unsupported path point type "
                                     f"{type(pt).__name__}")
            if len(body_idx) - starts[-1] < 2:
                raise ModelError(f"model {self.model.name!r}: muscle {mus.name!r} has fewer than two path points")
            starts.append(len(body_idx))
        return _PointTable(
            muscle=np.array(muscle_idx, int), body=np.array(body_idx, int),
            local=np.array(local, float).reshape(-1, 3), starts=np.array(starts, int),
            cond_points=np.array(cond_p, int), cond_coords=np.array(cond_c, int),
            cond_ranges=np.array(cond_r, float).reshape(-1, 2), moving=tuple(moving), names=tuple(names))

    # ---- coordinates -----------------------------------------------------------------------
    def coordinate_array(self, q=None) -> tuple[np.ndarray, np.ndarray | None]:
        """Coordinates as an array of shape (n_frames, n_coordinates), and the times if known.

        Parameters
        ----------
        q : None, array_like, Mapping or DataFrame
            None: the default pose.  An array of shape (n_coordinates,) or (n_frames,
            n_coordinates) in the order of :attr:`coordinate_names`.  A mapping name → value
            (scalar or array of frames); coordinates it omits take their default values.  A
            :class:`pandas.DataFrame` such as :func:`biomech.storage.read_storage` returns (SI
            units, one column per coordinate, an optional ``time`` column; other columns are
            ignored); every coordinate must be present.

        Returns
        -------
        q : ndarray, shape (n_frames, n_coordinates)
        time : ndarray, shape (n_frames,) or None

        Raises
        ------
        core.errors.InputError
            Wrong shape, unknown or missing coordinate names, non-finite values (coordinate and
            frame named).
        """
        time = None
        if q is None:
            arr = self._defaults[None, :].copy()
        elif isinstance(q, pd.DataFrame):
            missing = [c for c in self.coordinate_names if c not in q.columns]
            if missing:
                src = q.attrs.get("source", "motion")
                raise InputError(f"{src}: coordinates {missing} of model {self.model.name!r} are not columns of "
                                 f"the motion")
            arr = q[list(self.coordinate_names)].to_numpy(dtype=float)
            if "time" in q.columns:
                time = q["time"].to_numpy(dtype=float)
        elif isinstance(q, Mapping):
            unknown = [k for k in q if k not in self._coord_index]
            if unknown:
                raise InputError(f"model {self.model.name!r} has no coordinates {unknown}")
            vals = {k: np.atleast_1d(np.asarray(v, float)) for k, v in q.items()}
            sizes = {v.shape for v in vals.values()}
            if any(len(s) != 1 for s in sizes) or len({s[0] for s in sizes} - {1}) > 1:
                raise InputError(f"coordinate values must be scalars or 1-D arrays of one length, got shapes {sizes}")
            n = max([s[0] for s in sizes], default=1)
            arr = np.repeat(self._defaults[None, :], n, axis=0)
            for k, v in vals.items():
                arr[:, self._coord_index[k]] = v
        else:
            arr = np.asarray(q, float)
            if arr.ndim == 1:
                arr = arr[None, :]
            if arr.ndim != 2 or arr.shape[1] != self.n_coordinates:
                raise InputError(f"q must have shape (n_frames, {self.n_coordinates}) or ({self.n_coordinates},) "
                                 f"(coordinates {', '.join(self.coordinate_names)}), got {np.shape(q)}")
            arr = np.array(arr, float)
        bad = ~np.isfinite(arr)
        if np.any(bad):
            f, c = np.argwhere(bad)[0]
            raise InputError(f"coordinate {self.coordinate_names[c]!r} is {arr[f, c]} in frame {f}")
        return arr, time

    # ---- forward kinematics ----------------------------------------------------------------
    def joint_transform(self, joint: str, q=None) -> tuple[np.ndarray, np.ndarray]:
        """X_FM(q) of one joint, Eq. (1): (R_FM, p_FM) of shapes (n_frames, 3, 3) and (n_frames, 3).

        ``p_FM`` is the origin of the child-side frame M in the parent-side frame F, expressed in F.
        """
        qq, _ = self.coordinate_array(q)
        for j in self._joints:
            if j.name == joint:
                R, p, _, _ = self._joint_motion(j, qq, derivatives=False)
                return R, p
        raise InputError(f"model {self.model.name!r} has no joint {joint!r}")

    def _axis_values(self, j: _CompiledJoint, q: np.ndarray, derivatives: bool):
        n = q.shape[0]
        val = np.empty((6, n))
        der = np.zeros((6, n)) if derivatives else None
        for i in range(6):
            c = j.coords[i]
            fn = j.functions[i]
            if c < 0:
                val[i] = fn.value(0.0)
            else:
                x = q[:, c]
                val[i] = fn.value(x)
                if derivatives:
                    der[i] = fn.first_derivative(x)
        return val, der

    def _joint_motion(self, j: _CompiledJoint, q: np.ndarray, derivatives: bool):
        """R_FM, p_FM and, with derivatives, the columns w_i of Eq. (3) and the axis derivatives."""
        val, der = self._axis_values(j, q, derivatives)
        R1 = axis_rotation(j.axes[0], val[0])
        R2 = axis_rotation(j.axes[1], val[1])
        R3 = axis_rotation(j.axes[2], val[2])
        R12 = R1 @ R2
        R = R12 @ R3
        p = val[3, :, None] * j.axes[3] + val[4, :, None] * j.axes[4] + val[5, :, None] * j.axes[5]
        w = None
        if derivatives:
            w = (np.broadcast_to(j.axes[0], p.shape), R1 @ j.axes[1], R12 @ j.axes[2])
        return R, p, w, der

    def forward_kinematics(self, q=None, *, jacobians: bool = False) -> BodyKinematics:
        """Body poses in ground (Eq. 2) and, optionally, their Jacobians (Eq. 4).

        Parameters
        ----------
        q : see :meth:`coordinate_array`
            One pose, many frames, a mapping or a motion table.
        jacobians : bool
            Also compute ∂x_B/∂q and J_ω,B analytically.

        Returns
        -------
        BodyKinematics
        """
        qq, time = self.coordinate_array(q)
        R, x, Jx, Jw = self._kinematics(qq, jacobians)
        return BodyKinematics(self.body_names, self.coordinate_names, qq, R[:, 1:], x[:, 1:],
                              None if Jx is None else Jx[:, 1:], None if Jw is None else Jw[:, 1:], time)

    def _kinematics(self, q: np.ndarray, jacobians: bool):
        n = q.shape[0]
        nf = self.n_bodies + 1
        nq = self.n_coordinates
        R = np.empty((n, nf, 3, 3))
        x = np.empty((n, nf, 3))
        R[:, 0] = np.eye(3)
        x[:, 0] = 0.0
        Jx = Jw = None
        if jacobians:
            Jx = np.zeros((n, nf, 3, nq))
            Jw = np.zeros((n, nf, 3, nq))
        for j in self._joints:
            P, C = j.parent, j.child
            R_FM, p_FM, w, der = self._joint_motion(j, q, jacobians)
            R_GP, x_P = R[:, P], x[:, P]
            R_GF = R_GP @ j.R_PF
            x_F = x_P + R_GP @ j.p_PF
            x_M = x_F + np.einsum("nij,nj->ni", R_GF, p_FM)
            R_GC = R_GF @ R_FM @ j.R_CM.T
            x_C = x_M - R_GC @ j.p_CM
            R[:, C] = R_GC
            x[:, C] = x_C
            if not jacobians:
                continue
            Jw_C = Jw[:, P].copy()
            Jx_C = Jx[:, P] + _cross_columns(x_M - x_P, Jw[:, P])
            for i in range(3):
                c = j.coords[i]
                if c >= 0:
                    Jw_C[:, :, c] += np.einsum("nij,nj->ni", R_GF, w[i]) * der[i][:, None]
                c = j.coords[3 + i]
                if c >= 0:
                    Jx_C[:, :, c] += (R_GF @ j.axes[3 + i]) * der[3 + i][:, None]
            Jx_C += _cross_columns(x_C - x_M, Jw_C)
            Jw[:, C] = Jw_C
            Jx[:, C] = Jx_C
        return R, x, Jx, Jw

    # ---- points fixed in bodies ------------------------------------------------------------
    def station_positions(self, body: str, stations, q=None) -> np.ndarray:
        """Ground positions of points fixed in ``body`` (or ground), shape (n_frames, k, 3) [m].

        Parameters
        ----------
        body : str
        stations : array_like, shape (k, 3) or (3,)
            Locations in the body frame [m].
        """
        s = np.atleast_2d(np.asarray(stations, float))
        if s.shape[-1] != 3 or s.ndim != 2:
            raise InputError(f"stations must have shape (k, 3), got {np.shape(stations)}")
        b = self._frame(body)
        qq, _ = self.coordinate_array(q)
        R, x, _, _ = self._kinematics(qq, False)
        return x[:, b, None, :] + np.einsum("nij,kj->nki", R[:, b], s)

    def station_jacobian(self, body: str, station, q=None) -> np.ndarray:
        """∂(ground position of a point fixed in ``body``)/∂q = J_x,B − [r]× J_ω,B.

        Returns an array of shape (n_frames, 3, n_coordinates).
        """
        s = np.asarray(station, float)
        if s.shape != (3,):
            raise InputError(f"station must have shape (3,), got {s.shape}")
        b = self._frame(body)
        qq, _ = self.coordinate_array(q)
        R, x, Jx, Jw = self._kinematics(qq, True)
        r = R[:, b] @ s
        return Jx[:, b] + _cross_columns(r, Jw[:, b])

    def generalized_forces(self, body: str, station, force, q=None, torque=None) -> np.ndarray:
        r"""Generalized forces Q = J_Sᵀ f + J_ω,Bᵀ m of a force ``f`` at a point of ``body``.

        Q has the virtual power of the load: Qᵀq̇ = f·v_S + m·ω_B.

        Parameters
        ----------
        body : str
        station : array_like, shape (3,)
            Point of application in the body frame [m].
        force : array_like, shape (3,) or (n_frames, 3)
            Force in ground [N].
        torque : array_like, shape (3,) or (n_frames, 3), optional
            Torque on the body, in ground [N·m].

        Returns
        -------
        ndarray, shape (n_frames, n_coordinates)
            [N·m for rotational coordinates, N for translational ones].
        """
        b = self._frame(body)
        qq, _ = self.coordinate_array(q)
        s = np.asarray(station, float)
        if s.shape != (3,):
            raise InputError(f"station must have shape (3,), got {s.shape}")
        R, x, Jx, Jw = self._kinematics(qq, True)
        r = R[:, b] @ s
        J = Jx[:, b] + _cross_columns(r, Jw[:, b])
        f = np.broadcast_to(np.asarray(force, float), (qq.shape[0], 3))
        Q = np.einsum("nij,ni->nj", J, f)
        if torque is not None:
            m = np.broadcast_to(np.asarray(torque, float), (qq.shape[0], 3))
            Q = Q + np.einsum("nij,ni->nj", Jw[:, b], m)
        return Q

    def marker_positions(self, q=None) -> dict[str, np.ndarray]:
        """Ground positions of the model's markers, name → array of shape (n_frames, 3) [m]."""
        qq, _ = self.coordinate_array(q)
        R, x, _, _ = self._kinematics(qq, False)
        out = {}
        for mk in self.model.markers:
            b = self._frame(mk.body)
            out[mk.name] = x[:, b] + R[:, b] @ np.asarray(mk.location, float)
        return out

    def _frame(self, body: str) -> int:
        try:
            return self._frame_index[body]
        except KeyError:
            raise InputError(f"model {self.model.name!r} has no body {body!r}") from None

    # ---- muscle paths ----------------------------------------------------------------------
    def _point_locals(self, q: np.ndarray, derivatives: bool):
        """Locations in their bodies (n, P, 3), activity (n, P) and moving-point derivatives."""
        pt = self._points
        n = q.shape[0]
        loc = np.broadcast_to(pt.local, (n, *pt.local.shape)).copy()
        dloc = []
        for p, k, c, fn, lo, hi in pt.moving:
            xc = q[:, c]
            xcl = np.clip(xc, lo, hi)
            loc[:, p, k] = fn.value(xcl)
            if derivatives:
                d = np.where((xc >= lo) & (xc <= hi), fn.first_derivative(xcl), 0.0)
                dloc.append((p, k, c, d))
        active = np.ones((n, pt.body.size), bool)
        if pt.cond_points.size:
            v = q[:, pt.cond_coords]
            active[:, pt.cond_points] = ((v >= pt.cond_ranges[:, 0] - CONDITIONAL_TOLERANCE)
                                         & (v <= pt.cond_ranges[:, 1] + CONDITIONAL_TOLERANCE))
        return loc, active, dloc

    def _segments(self, X: np.ndarray, active: np.ndarray):
        """For every point j: the previous active point of its muscle, the segment to it and its length."""
        pt = self._points
        n, P = active.shape
        idx = np.where(active, np.arange(P), -1)
        cum = np.maximum.accumulate(idx, axis=1)
        prev = np.full((n, P), -1)
        prev[:, 1:] = cum[:, :-1]
        start = pt.starts[pt.muscle]
        has = active & (prev >= start[None, :])
        prev_safe = np.where(has, prev, np.arange(P)[None, :])
        d = X - np.take_along_axis(X, prev_safe[:, :, None], axis=1)
        seg = np.linalg.norm(d, axis=2)
        seg = np.where(has, seg, 0.0)
        return prev_safe, has, d, seg

    def _lengths(self, q: np.ndarray) -> np.ndarray:
        R, x, _, _ = self._kinematics(q, False)
        loc, active, _ = self._point_locals(q, False)
        X = self._ground_points(R, x, loc)
        _, _, _, seg = self._segments(X, active)
        return np.add.reduceat(seg, self._points.starts[:-1], axis=1)

    def _ground_points(self, R, x, loc):
        b = self._points.body
        return x[:, b] + np.einsum("npij,npj->npi", R[:, b], loc)

    def muscle_geometry(self, q=None, *, moment_arms: bool = True) -> MuscleGeometry:
        """Musculotendon lengths L(q) and moment arms r = −∂L/∂q of every muscle (Eq. 5).

        Parameters
        ----------
        q : see :meth:`coordinate_array`
        moment_arms : bool
            Also compute the moment arms (analytic, Eq. 5).

        Returns
        -------
        MuscleGeometry
            ``length`` (n_frames, n_muscles) [m]; ``moment_arm`` (n_frames, n_muscles,
            n_coordinates), positive when a tension would drive the coordinate positive.
        """
        qq, time = self.coordinate_array(q)
        pt = self._points
        n = qq.shape[0]
        R, x, Jx, Jw = self._kinematics(qq, moment_arms)
        loc, active, dloc = self._point_locals(qq, moment_arms)
        X = self._ground_points(R, x, loc)
        prev, has, d, seg = self._segments(X, active)
        length = np.add.reduceat(seg, pt.starts[:-1], axis=1)
        if not moment_arms:
            return MuscleGeometry(self.muscle_names, self.coordinate_names, length, None, time)
        P = pt.body.size
        # g_k = ∂L/∂p_k: +e at the segment's end point j, −e at its start point prev(j)
        with np.errstate(invalid="ignore", divide="ignore"):
            e = np.where(has[:, :, None], d / np.where(seg > 0, seg, 1.0)[:, :, None], 0.0)
        g = e.copy()
        rows = np.repeat(np.arange(n), P)
        np.add.at(g, (rows, prev.ravel()), -e.reshape(-1, 3))
        # resultant force and moment about the body origin, per muscle and body (Eq. 5)
        nf = self.n_bodies + 1
        key = pt.muscle * nf + pt.body
        rho = X - x[:, pt.body]
        F = np.zeros((n, self.n_muscles * nf, 3))
        M = np.zeros((n, self.n_muscles * nf, 3))
        np.add.at(F, (slice(None), key), g)
        np.add.at(M, (slice(None), key), _cross_last(rho, g))
        F = F.reshape(n, self.n_muscles, nf, 3)
        M = M.reshape(n, self.n_muscles, nf, 3)
        # Σ_b,i F_mbi Jx_bij + M_mbi Jw_bij, one batched product per frame (einsum loops over it)
        nq = self.n_coordinates
        dLdq = (F.reshape(n, self.n_muscles, 3 * nf) @ Jx.reshape(n, 3 * nf, nq)
                + M.reshape(n, self.n_muscles, 3 * nf) @ Jw.reshape(n, 3 * nf, nq))
        for p, k, c, dd in dloc:
            col = R[:, pt.body[p], :, k]          # ∂(R s)/∂s_k
            dLdq[:, pt.muscle[p], c] += np.einsum("ni,ni->n", g[:, p], col) * dd
        return MuscleGeometry(self.muscle_names, self.coordinate_names, length, -dLdq, time)

    def muscle_lengths(self, q=None) -> np.ndarray:
        """L(q) of every muscle, shape (n_frames, n_muscles) [m]."""
        qq, _ = self.coordinate_array(q)
        return self._lengths(qq)

    def muscle_path(self, muscle: str, q=None) -> MusclePath:
        """The active path points of ``muscle`` at one pose (``q`` a single frame)."""
        try:
            m = self.muscle_names.index(muscle)
        except ValueError:
            raise InputError(f"model {self.model.name!r} has no muscle {muscle!r}") from None
        qq, _ = self.coordinate_array(q)
        if qq.shape[0] != 1:
            raise InputError(f"muscle_path takes one pose, got {qq.shape[0]} frames")
        R, x, _, _ = self._kinematics(qq, False)
        loc, active, _ = self._point_locals(qq, False)
        X = self._ground_points(R, x, loc)
        sl = slice(self._points.starts[m], self._points.starts[m + 1])
        act = active[0, sl]
        pos = X[0, sl][act]
        bodies = [self._frame_names[b] for b in self._points.body[sl][act]]
        names = [nm for nm, a in zip(self._points.names[sl], act) if a]
        length = float(np.sum(np.linalg.norm(np.diff(pos, axis=0), axis=1))) if len(pos) > 1 else 0.0
        return MusclePath(muscle, tuple(names), tuple(bodies), loc[0, sl][act], pos, length)

    @cached_property
    def _frame_names(self) -> tuple[str, ...]:
        return (self.ground, *self.body_names)

    # ---- finite-difference check -----------------------------------------------------------
    def moment_arm_check(self, q=None, step: float = 1e-5,
                         coordinates: Sequence[str] | None = None) -> MomentArmCheck:
        r"""Compare the analytic moment arms with central differences of L(q).

        r_j^FD = −(L(q + h e_j) − L(q − h e_j)) / (2h).  Its error is bounded by
        h²/6 · max|∂³L/∂q_j³| (truncation) plus about ε_L/h (rounding of L, ε_L ≈ a few ulp of L),
        so with h = 1e-5 and lengths below 1 m the difference to the exact derivative is of order
        1e-10 m for any path whose third derivative is below ~10 m (per rad³).

        Parameters
        ----------
        q : see :meth:`coordinate_array`
        step : float
            h [rad or m].
        coordinates : sequence of str, optional
            Coordinates to difference (default: all); the other columns are marked not valid.

        Returns
        -------
        MomentArmCheck
        """
        if not (np.isfinite(step) and step > 0):
            raise InputError(f"step must be a positive number, got {step!r}")
        qq, _ = self.coordinate_array(q)
        geo = self.muscle_geometry(qq)
        n = qq.shape[0]
        fd = np.full((n, self.n_muscles, self.n_coordinates), np.nan)
        valid = np.zeros(fd.shape, bool)
        cols = range(self.n_coordinates) if coordinates is None else [self.coordinate_index(c) for c in coordinates]
        pt = self._points
        _, act0, _ = self._point_locals(qq, False)
        for j in cols:
            qp = qq.copy()
            qm = qq.copy()
            qp[:, j] += step
            qm[:, j] -= step
            fd[:, :, j] = -(self._lengths(qp) - self._lengths(qm)) / (2.0 * step)
            _, actp, _ = self._point_locals(qp, False)
            _, actm, _ = self._point_locals(qm, False)
            same = (actp == act0) & (actm == act0)                      # (n, P)
            ok_point = same.copy()
            for p, _k, c, _fn, lo, hi in pt.moving:
                if c == j:
                    ok_point[:, p] &= ~((qm[:, j] <= lo) & (qp[:, j] >= lo) | (qm[:, j] <= hi) & (qp[:, j] >= hi))
            ok_muscle = np.logical_and.reduceat(ok_point, pt.starts[:-1], axis=1)
            valid[:, :, j] = ok_muscle
        return MomentArmCheck(self.muscle_names, self.coordinate_names, geo.moment_arm, fd, valid, float(step))
