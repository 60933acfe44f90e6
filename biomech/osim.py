r"""Read OpenSim 4.x model files (``.osim``) and force-set files into plain frozen dataclasses.

No OpenSim installation is needed: the XML is read with the standard library (``xml.parsers.expat``
into an ``ElementTree``, keeping each element's line number for messages).

File-format conventions (OpenSim 4.x, ``OpenSimDocument Version >= 40000``)
---------------------------------------------------------------------------
Units
    SI throughout: lengths in metres (``<length_units>meters``), forces in newtons, masses in kg,
    angles in radians (coordinate ranges, default values, ``ConditionalPathPoint`` ranges, the
    argument of joint and path functions of rotational coordinates).  The reader refuses other
    length or force units rather than guessing a conversion.
Bodies
    ``<mass>``, ``<mass_center>`` (in the body frame), ``<inertia>`` six values
    ``Ixx Iyy Izz Ixy Ixz Iyz`` about the centre of mass in the body frame (``Body.h``), returned
    as the symmetric 3×3 matrix.  Attached geometry, frame geometry and appearance are display only
    and are not read (the one class of elements skipped without a report).
Joints
    A joint connects a *parent frame* P and a *child frame* C, each usually a
    ``PhysicalOffsetFrame`` listed in the joint's ``<frames>``: ``socket_parent`` names the body
    (``/bodyset/femur_r`` or ``/ground``), ``translation`` is the frame origin in that body and
    ``orientation`` its orientation as X-Y-Z *body-fixed* Euler angles (R = R_x(θ₁) R_y(θ₂) R_z(θ₃),
    ``PhysicalOffsetFrame``/``Frame`` documentation), so the joint frame's transform in its body is
    X_BF = (R, translation).  :class:`Joint` keeps both offsets as :class:`OffsetFrame`.
    The joint's mobility maps coordinates q to the transform X_PC(q) between the two joint frames.
    A ``CustomJoint`` states it as a ``SpatialTransform`` of six ``TransformAxis`` entries, each an
    axis (unit vector) and a function of at most one coordinate: three rotation angles, then three
    translations, passed in this order to Simbody's ``MobilizedBody::FunctionBased`` (whose
    composition rule this file layer does not apply; it only reads the axes, coordinates and
    functions).  ``PinJoint`` (rotation about the common Z
    axis), ``SliderJoint`` (translation along the common X axis) and ``WeldJoint`` (none) are
    returned with the equivalent six axes too, so every joint has the same description.  Other
    joint types raise :class:`core.errors.ModelError` (the kinematics would otherwise be wrong).
Coordinates
    Motion type as OpenSim 4 derives it (``CustomJoint::constructCoordinates``): a coordinate that
    drives an axis through a linear function of slope ±1 is *rotational* on a rotation axis and
    *translational* on a translation axis (the last such axis wins); a coordinate that only enters
    through other functions is *coupled*.  One deliberate difference: OpenSim tests for a
    ``LinearFunction`` only, so the scaled ``MultiplierFunction(LinearFunction)`` pelvis
    translations of a model scaled by the Scale tool come out *coupled* there; here a
    ``MultiplierFunction`` is unwrapped (slope × scale), giving *translational*.  Only rotational
    coordinates are converted from degrees in motion files, in both programs, so unit conversion
    is not affected.
Muscles and paths
    Any force element whose tag ends in ``Muscle`` (``Thelen2003Muscle``,
    ``Millard2012EquilibriumMuscle``, ...): the Hill-model parameters listed in :class:`Muscle`,
    every other property kept verbatim in ``Muscle.properties`` (e.g. the Millard curve
    parameters as ``"ActiveForceLengthCurve.minimum_value"``), and the path points:
    ``PathPoint`` (fixed in a body), ``ConditionalPathPoint`` (active while a coordinate lies in a
    range, ±1e-5 as OpenSim), ``MovingPathPoint`` (location components as functions of coordinates,
    each clamped to its coordinate's range as ``MovingPathPoint::getLocation`` does).
Other forces
    ``CoordinateActuator``, ``PointActuator`` and ``TorqueActuator`` are read as actuators; any
    other force (a ligament, a coordinate limit force, a spring) is listed in
    ``OsimModel.other_forces`` with its properties, and reported as ignored because its force law
    is not modelled.

What is not supported is reported, never dropped silently
---------------------------------------------------------
* *Safe to ignore* -- the rest of the model is still what the file says: wrap objects on bodies and
  path wraps on muscle paths (paths become straight segments between the path points, so their
  lengths and moment arms differ from OpenSim's where the path would wrap), constraints other than
  ``CoordinateCouplerConstraint`` (the model has the constraint's extra freedom), forces other than
  muscles and actuators, contact geometry, controllers, probes, extra components, unknown
  model-level elements, unknown properties of bodies, joints and coordinates.  Each becomes an
  :class:`IgnoredItem` in ``OsimModel.ignored`` and one :class:`OsimReaderWarning` per kind names
  the elements; ``strict=True`` turns them into a :class:`core.errors.ModelError`.
* *Unsafe* -- an error naming the file, line and element: an unknown joint type or path-point type,
  an unsupported function (:func:`biomech.functions.function_from_xml`), a reference to a body,
  frame or coordinate that does not exist, a body not connected to ground, a closed kinematic loop
  of joints, a muscle path that is a ``FunctionBasedPath``.

A file that is missing, not well-formed or truncated raises :class:`core.errors.DataFileError`
naming the file and the line the XML parser stopped at.  OpenSim 3.x files (``Version < 40000``,
joints inside bodies) are refused with a message saying how to convert them.

References
----------
Delp S.L. et al. (2007) OpenSim: open-source software to create and analyze dynamic simulations of
movement. IEEE Trans. Biomed. Eng. 54(11):1940-1950.
Seth A. et al. (2018) OpenSim: simulating musculoskeletal dynamics and neuromuscular control to
study human and animal movement. PLoS Comput. Biol. 14(7):e1006223 (the 4.x component model with
frames and sockets).
OpenSim documentation: "OpenSim Models" / "Joints" (simtk-confluence.stanford.edu, OpenSim
Documentation 4.0), and the 4.x source (``CustomJoint.cpp``, ``SpatialTransform.cpp``,
``ConditionalPathPoint.cpp``, ``MovingPathPoint.cpp``, ``Body.h``, ``PhysicalOffsetFrame.h``) at
github.com/opensim-org/opensim-core, read for the definitions.
"""

from __future__ import annotations

import warnings
import xml.etree.ElementTree as ET
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from functools import cached_property
from pathlib import Path
from typing import Any, Literal
from xml.parsers import expat

import numpy as np
from scipy.spatial.transform import Rotation

from core.errors import DataFileError, ModelError

from .functions import (
    Constant,
    Function1D,
    LinearFunction,
    function_in,
    is_constant,
    linear_slope,
)

__all__ = [
    "OsimReaderWarning",
    "IgnoredItem",
    "Body",
    "OffsetFrame",
    "TransformAxis",
    "Joint",
    "Coordinate",
    "PathPoint",
    "ConditionalPathPoint",
    "MovingPathPoint",
    "Muscle",
    "CoordinateActuator",
    "PointActuator",
    "TorqueActuator",
    "OtherForce",
    "CoordinateCouplerConstraint",
    "Marker",
    "OsimModel",
    "ForceSet",
    "read_osim",
    "read_force_set",
    "parse_xml",
    "XmlDocument",
    "SUPPORTED_JOINT_TYPES",
]

MotionType = Literal["rotational", "translational", "coupled"]

#: Joint types the reader understands.
SUPPORTED_JOINT_TYPES: tuple[str, ...] = ("CustomJoint", "PinJoint", "SliderJoint", "WeldJoint")

_AXIS_NAMES = ("rotation1", "rotation2", "rotation3", "translation1", "translation2", "translation3")


class OsimReaderWarning(UserWarning):
    """Part of an OpenSim file was not read (it is listed in ``OsimModel.ignored``)."""


# =============================================================================================
# XML with line numbers
# =============================================================================================


class XmlDocument:
    """A parsed XML file: its root element and the line of every element (for messages)."""

    def __init__(self, path: Path, root: ET.Element, lines: dict[int, int]):
        self.path = path
        self.root = root
        self._lines = lines

    def line(self, element: ET.Element) -> int | None:
        """1-based line where ``element`` starts."""
        return self._lines.get(id(element))

    def where(self, element: ET.Element | None, context: str = "") -> str:
        """``"<file>, line N: <Tag name='x'>"`` plus an optional context."""
        text = str(self.path)
        if element is not None:
            line = self.line(element)
            if line:
                text += f", line {line}"
            name = element.get("name")
            text += f": <{element.tag}" + (f" name={name!r}" if name else "") + ">"
        if context:
            text += f" ({context})"
        return text


def parse_xml(path: str | Path) -> XmlDocument:
    """Parse an XML file, keeping element line numbers.

    Raises
    ------
    core.errors.DataFileError
        The file is missing or unreadable, or not well-formed XML (truncated files included):
        the message names the file, line and column where the parser stopped.
    """
    p = Path(path)
    try:
        data = p.read_bytes()
    except FileNotFoundError:
        raise DataFileError(f"{p}: file does not exist") from None
    except OSError as exc:
        raise DataFileError(f"{p}: cannot be read ({exc.strerror or exc})") from None
    builder = ET.TreeBuilder()
    lines: dict[int, int] = {}
    parser = expat.ParserCreate()

    def start(tag, attrs):
        element = builder.start(tag, attrs)
        lines[id(element)] = parser.CurrentLineNumber

    parser.StartElementHandler = start
    parser.EndElementHandler = builder.end
    parser.CharacterDataHandler = builder.data
    try:
        parser.Parse(data, True)
        root = builder.close()
    except expat.ExpatError as exc:
        reason = expat.errors.messages[exc.code]
        at_end = {expat.errors.codes[expat.errors.XML_ERROR_NO_ELEMENTS],
                  expat.errors.codes[expat.errors.XML_ERROR_UNCLOSED_TOKEN]}
        n_lines = data.count(b"\n") + (0 if data.endswith(b"\n") else 1)
        hint = " (the file ends early: truncated?)" if exc.code in at_end and exc.lineno >= n_lines else ""
        raise DataFileError(f"{p}, line {exc.lineno}, column {exc.offset + 1}: not well-formed XML: {reason}{hint}") from None
    return XmlDocument(p, root, lines)


# =============================================================================================
# Result types
# =============================================================================================


def _readonly(a) -> np.ndarray:
    arr = np.array(a, dtype=float)
    arr.flags.writeable = False
    return arr


@dataclass(frozen=True)
class IgnoredItem:
    """An element of a file the reader did not turn into a model component.

    Attributes
    ----------
    kind : str
        ``"wrap object"``, ``"path wrap"``, ``"constraint"``, ``"force"``, ``"contact geometry"``,
        ``"controller"``, ``"probe"``, ``"component"``, ``"model element"``, ``"body component"``,
        ``"property"`` (an unknown property of a body, joint or coordinate), ``"force-set entry"``.
    type : str
        The XML tag (OpenSim class), e.g. ``"WrapCylinder"``.
    name : str
        Its ``name`` attribute (may be empty).
    owner : str
        Where it sits, e.g. ``"muscle 'gastroc_r'"``, or ``""`` at model level.
    line : int or None
        Line in the file.
    reason : str
        What is ignored and what that changes.
    """

    kind: str
    type: str
    name: str
    owner: str
    line: int | None
    reason: str

    def __str__(self) -> str:
        own = f" on {self.owner}" if self.owner else ""
        line = f" (line {self.line})" if self.line else ""
        name = f" {self.name!r}" if self.name else ""
        return f"{self.type}{name}{own}{line}: {self.reason}"


@dataclass(frozen=True, eq=False)
class Body:
    """A rigid body.

    Attributes
    ----------
    name : str
    mass : float
        [kg].
    mass_center : ndarray, shape (3,)
        Centre of mass in the body frame [m].
    inertia : ndarray, shape (3, 3)
        Inertia tensor about the centre of mass, body-frame axes [kg·m²] (from the six values
        Ixx Iyy Izz Ixy Ixz Iyz).
    """

    name: str
    mass: float
    mass_center: np.ndarray
    inertia: np.ndarray


@dataclass(frozen=True, eq=False)
class OffsetFrame:
    """A frame fixed in a body: X_BF = (R, location).

    Attributes
    ----------
    name : str
        Name of the ``PhysicalOffsetFrame`` (or of the body when the joint uses the body frame).
    body : str
        Body (or ``"ground"``) the frame is fixed in.
    location : ndarray, shape (3,)
        Origin of the frame in the body frame [m].
    orientation : ndarray, shape (3,)
        X-Y-Z body-fixed Euler angles of the frame relative to the body [rad].
    """

    name: str
    body: str
    location: np.ndarray
    orientation: np.ndarray

    @property
    def rotation(self) -> np.ndarray:
        """R_BF = R_x(θ₁) R_y(θ₂) R_z(θ₃), shape (3, 3): columns are the frame's axes in the body."""
        return Rotation.from_euler("XYZ", self.orientation).as_matrix()


@dataclass(frozen=True, eq=False)
class TransformAxis:
    """One of the six axes of a joint's spatial transform.

    The axis displacement is ``function(q_c)`` of its coordinate q_c (an angle about ``axis`` for
    rotation1-3 [rad], a distance along ``axis`` for translation1-3 [m]); an axis without a
    coordinate has a constant displacement.

    Attributes
    ----------
    name : str
        ``rotation1`` … ``translation3``.
    axis : ndarray, shape (3,)
        Unit axis (the file's axis normalised, as Simbody uses it).
    coordinates : tuple of str
        The coordinate the function takes (empty for a constant axis).
    function : Function1D
    """

    name: str
    axis: np.ndarray
    coordinates: tuple[str, ...]
    function: Function1D

    @property
    def is_rotation(self) -> bool:
        return self.name.startswith("rotation")

    def value(self, q: Mapping[str, float]) -> float:
        """Axis displacement for coordinate values ``q`` (name → value, SI)."""
        return float(self.function(q[self.coordinates[0]] if self.coordinates else 0.0))

    def derivative(self, q: Mapping[str, float]) -> float:
        """d(displacement)/d(q_c) of the axis' coordinate (0 for a constant axis)."""
        return float(self.function.first_derivative(q[self.coordinates[0]])) if self.coordinates else 0.0


@dataclass(frozen=True, eq=False)
class Joint:
    """A joint between a parent and a child body.

    Attributes
    ----------
    name, type : str
        Name and OpenSim class (``CustomJoint``, ``PinJoint``, ``SliderJoint``, ``WeldJoint``).
    parent_body, child_body : str
    parent_frame, child_frame : OffsetFrame
        The joint frames P (fixed in the parent body) and C (fixed in the child body).
    coordinates : tuple of str
        The joint's coordinates, in file order.
    transform_axes : tuple of TransformAxis, length 6
        rotation1-3 then translation1-3 (PinJoint: rotation about z; SliderJoint: translation
        along x; WeldJoint: all constant zero).
    reverse : bool
        OpenSim's ``reverse`` flag (direction of the underlying tree only).
    """

    name: str
    type: str
    parent_body: str
    child_body: str
    parent_frame: OffsetFrame
    child_frame: OffsetFrame
    coordinates: tuple[str, ...]
    transform_axes: tuple[TransformAxis, ...]
    reverse: bool = False


@dataclass(frozen=True, eq=False)
class Coordinate:
    """A generalized coordinate.

    Attributes
    ----------
    name, joint : str
    motion_type : {"rotational", "translational", "coupled"}
        See the module docstring.
    default_value, default_speed : float
        [rad] / [rad/s] or [m] / [m/s].
    range : ndarray, shape (2,)
        Lower and upper limit (SI).
    clamped, locked, prescribed : bool
    prescribed_function : Function1D or None
        Function of time when prescribed.
    """

    name: str
    joint: str
    motion_type: MotionType
    default_value: float
    default_speed: float
    range: np.ndarray
    clamped: bool
    locked: bool
    prescribed: bool = False
    prescribed_function: Function1D | None = None


@dataclass(frozen=True, eq=False)
class PathPoint:
    """A muscle-path point fixed in a body: ``location`` [m] in the body frame."""

    name: str
    body: str
    location: np.ndarray

    def is_active(self, q: Mapping[str, float]) -> bool:
        """Whether the point is part of the path at coordinate values ``q`` (always, here)."""
        return True

    def location_at(self, q: Mapping[str, float]) -> np.ndarray:
        """Location in the body frame at ``q`` [m], shape (3,)."""
        return np.array(self.location)

    def location_derivative(self, q: Mapping[str, float], coordinate: str) -> np.ndarray:
        """∂(location)/∂q_coordinate, shape (3,) (zero for a fixed point)."""
        return np.zeros(3)


@dataclass(frozen=True, eq=False)
class ConditionalPathPoint(PathPoint):
    """A path point that is part of the path only while ``range[0] - 1e-5 <= q_c <= range[1] +
    1e-5`` (q_c the value of ``coordinate``; inclusive with OpenSim's tolerance,
    ``ConditionalPathPoint::isActive``)."""

    coordinate: str = ""
    range: np.ndarray = field(default_factory=lambda: _readonly([-np.inf, np.inf]))

    def is_active(self, q: Mapping[str, float]) -> bool:
        value = q[self.coordinate]
        return bool(self.range[0] - 1e-5 <= value <= self.range[1] + 1e-5)


@dataclass(frozen=True, eq=False)
class MovingPathPoint:
    """A path point whose location components are functions of coordinates.

    location_k = f_k(clamp(q_{c_k}, lo_k, hi_k)) for k = x, y, z, with the coordinate value clamped
    to the coordinate's range (``MovingPathPoint::getLocation``); a component without a coordinate
    is f_k(0).

    Attributes
    ----------
    name, body : str
    coordinates : tuple of 3 (str or None)
        Coordinate of the x, y and z component.
    functions : tuple of 3 Function1D
    ranges : ndarray, shape (3, 2)
        Clamping range of each component's coordinate (±inf without a coordinate).
    """

    name: str
    body: str
    coordinates: tuple[str | None, str | None, str | None]
    functions: tuple[Function1D, Function1D, Function1D]
    ranges: np.ndarray

    def is_active(self, q: Mapping[str, float]) -> bool:
        return True

    def location_at(self, q: Mapping[str, float]) -> np.ndarray:
        out = np.empty(3)
        for k in range(3):
            c = self.coordinates[k]
            x = 0.0 if c is None else min(max(q[c], self.ranges[k, 0]), self.ranges[k, 1])
            out[k] = self.functions[k](x)
        return out

    def location_derivative(self, q: Mapping[str, float], coordinate: str) -> np.ndarray:
        """∂(location)/∂q_coordinate (zero for components of other coordinates and where the value
        is clamped)."""
        out = np.zeros(3)
        for k in range(3):
            if self.coordinates[k] == coordinate:
                x = q[coordinate]
                lo, hi = self.ranges[k]
                if lo <= x <= hi:
                    out[k] = self.functions[k].first_derivative(x)
        return out


AnyPathPoint = PathPoint | ConditionalPathPoint | MovingPathPoint


@dataclass(frozen=True, eq=False)
class Muscle:
    """A Hill-type muscle and its path.

    Attributes
    ----------
    name, type : str
        Name and OpenSim class.
    applies_force : bool
    max_isometric_force : float
        F₀ [N].
    optimal_fiber_length : float
        L₀ᴹ [m].
    tendon_slack_length : float
        Lₛᵀ [m].
    pennation_angle_at_optimal : float
        α₀ [rad] (0 if absent).
    max_contraction_velocity : float
        [optimal fibre lengths per second] (10 if absent, OpenSim's default).
    activation_time_constant, deactivation_time_constant : float or None
        [s].
    fmax_tendon_strain, fmax_muscle_strain, kshape_active, kshape_passive, af, flen : float or None
        Thelen (2003) parameters ``FmaxTendonStrain``, ``FmaxMuscleStrain``, ``KshapeActive``,
        ``KshapePassive``, ``Af``, ``Flen`` where present.
    path : tuple of path points
        In file order (origin first).
    properties : Mapping[str, str]
        Every other property, verbatim (nested ones as ``"Parent.child"``).
    """

    name: str
    type: str
    applies_force: bool
    max_isometric_force: float
    optimal_fiber_length: float
    tendon_slack_length: float
    pennation_angle_at_optimal: float
    max_contraction_velocity: float
    activation_time_constant: float | None
    deactivation_time_constant: float | None
    fmax_tendon_strain: float | None
    fmax_muscle_strain: float | None
    kshape_active: float | None
    kshape_passive: float | None
    af: float | None
    flen: float | None
    path: tuple[AnyPathPoint, ...]
    properties: Mapping[str, str]


@dataclass(frozen=True)
class CoordinateActuator:
    """Generalized force on one coordinate: τ = optimal_force · control, control in [min, max]."""

    name: str
    coordinate: str
    optimal_force: float
    min_control: float
    max_control: float
    applies_force: bool = True


@dataclass(frozen=True, eq=False)
class PointActuator:
    """Force optimal_force·control along ``direction`` at ``point`` of ``body`` (point and
    direction in the body frame unless ``point_is_global`` / ``force_is_global``)."""

    name: str
    body: str
    point: np.ndarray
    point_is_global: bool
    direction: np.ndarray
    force_is_global: bool
    optimal_force: float
    min_control: float
    max_control: float
    applies_force: bool = True


@dataclass(frozen=True, eq=False)
class TorqueActuator:
    """Torque optimal_force·control about ``axis`` on ``body_a`` (and its reaction on ``body_b``);
    the axis is in ground if ``torque_is_global``, else in body_a."""

    name: str
    body_a: str
    body_b: str
    axis: np.ndarray
    torque_is_global: bool
    optimal_force: float
    min_control: float
    max_control: float
    applies_force: bool = True


Actuator = CoordinateActuator | PointActuator | TorqueActuator


@dataclass(frozen=True)
class OtherForce:
    """A force element the reader lists but does not model (its properties verbatim)."""

    name: str
    type: str
    applies_force: bool
    properties: Mapping[str, str]


@dataclass(frozen=True, eq=False)
class CoordinateCouplerConstraint:
    """q_dependent = scale_factor · f(q_independent) (OpenSim ``CoordinateCouplerConstraint``
    with one independent coordinate)."""

    name: str
    independent_coordinate: str
    dependent_coordinate: str
    function: Function1D
    scale_factor: float
    enforced: bool


@dataclass(frozen=True, eq=False)
class Marker:
    """A marker fixed in ``body`` at ``location`` [m] (body frame)."""

    name: str
    body: str
    location: np.ndarray
    fixed: bool


@dataclass(frozen=True, eq=False)
class OsimModel:
    """An OpenSim model read from a file (see :func:`read_osim`).

    Attributes
    ----------
    name, path : str
        Model name and the file it came from.
    version : int
        ``OpenSimDocument Version``.
    gravity : ndarray, shape (3,)
        [m/s²] in ground.
    credits, publications : str
    ground : str
        Name of the ground frame (``"ground"``).
    bodies, joints, coordinates, muscles, actuators, other_forces, constraints, markers : tuple
    force_groups : Mapping[str, tuple of str]
        ``ObjectGroup``\\ s of the force set (e.g. ``R_hip_flex``) → member names.
    ignored : tuple of IgnoredItem
        Everything in the file the reader did not turn into one of the above (also reported by an
        :class:`OsimReaderWarning` when read).
    """

    name: str
    path: str
    version: int
    gravity: np.ndarray
    credits: str
    publications: str
    ground: str
    bodies: tuple[Body, ...]
    joints: tuple[Joint, ...]
    coordinates: tuple[Coordinate, ...]
    muscles: tuple[Muscle, ...]
    actuators: tuple[Actuator, ...]
    other_forces: tuple[OtherForce, ...]
    constraints: tuple[CoordinateCouplerConstraint, ...]
    markers: tuple[Marker, ...]
    force_groups: Mapping[str, tuple[str, ...]]
    ignored: tuple[IgnoredItem, ...]

    @cached_property
    def _index(self) -> dict[str, dict[str, Any]]:
        return {kind: {x.name: x for x in getattr(self, kind)}
                for kind in ("bodies", "joints", "coordinates", "muscles", "actuators", "markers")}

    def _get(self, kind: str, label: str, name: str):
        try:
            return self._index[kind][name]
        except KeyError:
            raise ModelError(f"model {self.name!r} ({self.path}) has no {label} {name!r}"
                             f"{_hint(name, self._index[kind])}") from None

    def body(self, name: str) -> Body:
        """The body called ``name`` (ModelError if there is none)."""
        return self._get("bodies", "body", name)

    def joint(self, name: str) -> Joint:
        return self._get("joints", "joint", name)

    def coordinate(self, name: str) -> Coordinate:
        return self._get("coordinates", "coordinate", name)

    def muscle(self, name: str) -> Muscle:
        return self._get("muscles", "muscle", name)

    def actuator(self, name: str) -> Actuator:
        return self._get("actuators", "actuator", name)

    @property
    def total_mass(self) -> float:
        """Sum of the body masses [kg]."""
        return float(sum(b.mass for b in self.bodies))

    @property
    def coordinate_names(self) -> tuple[str, ...]:
        return tuple(c.name for c in self.coordinates)

    @property
    def muscle_names(self) -> tuple[str, ...]:
        return tuple(m.name for m in self.muscles)

    def default_coordinates(self) -> dict[str, float]:
        """Coordinate name → default value (SI)."""
        return {c.name: c.default_value for c in self.coordinates}

    def __repr__(self) -> str:
        return (f"OsimModel({self.name!r}, {len(self.bodies)} bodies, {len(self.joints)} joints, "
                f"{len(self.coordinates)} coordinates, {len(self.muscles)} muscles, "
                f"{len(self.ignored)} ignored)")


@dataclass(frozen=True)
class ForceSet:
    """Actuators read from a force-set file (reserve / residual actuators)."""

    name: str
    path: str
    actuators: tuple[Actuator, ...]
    ignored: tuple[IgnoredItem, ...]

    def actuator(self, name: str) -> Actuator:
        for a in self.actuators:
            if a.name == name:
                return a
        raise ModelError(f"force set {self.name!r} ({self.path}) has no actuator {name!r}")


# =============================================================================================
# the reader
# =============================================================================================

_VISUAL = {"FrameGeometry", "attached_geometry", "Appearance", "VisibleObject", "geometry", "default_color",
           "display", "GeometrySet"}
_MODEL_ELEMENTS = {"Ground", "gravity", "credits", "publications", "length_units", "force_units", "BodySet",
                   "JointSet", "ControllerSet", "ConstraintSet", "ForceSet", "MarkerSet", "ContactGeometrySet",
                   "ProbeSet", "ComponentSet", "assembly_accuracy", "ModelVisualPreferences", "defaults",
                   "validateForces", "components"}
_MUSCLE_FIELDS = {
    "max_isometric_force": "max_isometric_force",
    "optimal_fiber_length": "optimal_fiber_length",
    "tendon_slack_length": "tendon_slack_length",
    "pennation_angle_at_optimal": "pennation_angle_at_optimal",
    "max_contraction_velocity": "max_contraction_velocity",
    "activation_time_constant": "activation_time_constant",
    "deactivation_time_constant": "deactivation_time_constant",
    "FmaxTendonStrain": "fmax_tendon_strain",
    "FmaxMuscleStrain": "fmax_muscle_strain",
    "KshapeActive": "kshape_active",
    "KshapePassive": "kshape_passive",
    "Af": "af",
    "Flen": "flen",
}
_IGNORE_REASONS = {
    "wrap object": "wrap surface not read; muscle paths are straight segments between their path points",
    "path wrap": "wrapping not modelled; the path is straight segments between its points, so its length and "
                 "moment arms differ from OpenSim's where it would wrap",
    "constraint": "constraint not modelled; the model keeps the freedom the constraint would remove",
    "force": "listed in model.other_forces, but its force law is not modelled",
    "contact geometry": "contact geometry not read",
    "controller": "controller not read",
    "probe": "probe not read",
    "component": "component not read",
    "body component": "component of a body not read",
    "model element": "model-level element not read",
    "force-set entry": "not an actuator type the reader supports; not read",
    "property": "property the reader does not know; not read",
}
# properties of bodies, joints and coordinates the reader knows (read, or display-only / only
# relevant to what is not modelled, such as assembly with constraints); anything else is reported
_KNOWN_PROPERTIES = {
    "Body": {"mass", "mass_center", "inertia", "WrapObjectSet", "components"},
    "Joint": {"socket_parent_frame", "socket_child_frame", "parent_frame", "child_frame", "coordinates", "frames",
              "SpatialTransform", "reverse", "components"},
    "Coordinate": {"default_value", "default_speed_value", "range", "clamped", "locked", "prescribed",
                   "prescribed_function", "is_free_to_satisfy_constraints", "motion_type"},
}


def _objects(set_element: ET.Element | None) -> list[ET.Element]:
    if set_element is None:
        return []
    objects = set_element.find("objects")
    return [] if objects is None else [c for c in objects if isinstance(c.tag, str)]


def _last_component(path_text: str) -> str:
    parts = [p for p in path_text.strip().split("/") if p and p not in (".", "..")]
    return parts[-1] if parts else ""


class _Reader:
    def __init__(self, doc: XmlDocument, what: str = "model"):
        self.doc = doc
        self.ignored: list[IgnoredItem] = []
        self.what = what
        self.accept: frozenset[str] = frozenset()

    def plausible(self, el, quantity: str, value: float, owner: str, tag: str) -> None:
        """Check a value read from the file against its plausible range (file, line, element, tag named)."""
        from core.inputs import ImplausibleValueError

        from .checks import ImplausibleDataError, check_value

        if quantity in self.accept:
            return
        child = el.find(tag)
        line = self.doc.line(child if child is not None else el)
        where = f"{self.doc.path}" + (f", line {line}" if line else "") + f": {owner} <{tag}>"
        try:
            check_value(quantity, value, where=where, accept=self.accept)
        except ImplausibleValueError as exc:
            raise ImplausibleDataError(str(exc), exc.quantity, exc.value, exc.suggestion) from None

    # ---- messages ---------------------------------------------------------------------------
    def where(self, el, context: str = "") -> str:
        return self.doc.where(el, context)

    def data_error(self, el, msg: str) -> DataFileError:
        return DataFileError(f"{self.where(el)}: {msg}")

    def model_error(self, el, msg: str) -> ModelError:
        return ModelError(f"{self.where(el)}: {msg}")

    def ignore(self, kind: str, el: ET.Element, owner: str = "", reason: str | None = None):
        self.ignored.append(IgnoredItem(kind, el.tag, el.get("name", ""), owner, self.doc.line(el),
                                        reason or _IGNORE_REASONS[kind]))

    # ---- properties -------------------------------------------------------------------------
    def text(self, el, tag: str, default: Any = ..., *, alternatives: tuple[str, ...] = ()) -> str:
        for t in (tag, *alternatives):
            child = el.find(t)
            if child is not None:
                return (child.text or "").strip()
        if default is ...:
            raise self.data_error(el, f"missing property <{tag}>")
        return default

    def numbers(self, el, tag: str, n: int | None = None, default: Any = ..., *,
                alternatives: tuple[str, ...] = ()) -> np.ndarray:
        raw = self.text(el, tag, None, alternatives=alternatives)
        if raw is None or raw == "":
            if default is ...:
                raise self.data_error(el, f"missing property <{tag}>")
            return default
        try:
            vals = np.array([float(t) for t in raw.split()], dtype=float)
        except ValueError:
            raise self.data_error(el, f"<{tag}> is not a list of numbers: {raw[:80]!r}") from None
        if n is not None and vals.size != n:
            raise self.data_error(el, f"<{tag}> must have {n} value{'s' if n > 1 else ''}, got {vals.size}: {raw[:80]!r}")
        return vals

    def number(self, el, tag: str, default: Any = ..., *, alternatives: tuple[str, ...] = ()) -> float:
        """One number; ``default`` when the property is absent or empty (required if not given)."""
        required = default is ...
        vals = self.numbers(el, tag, 1, ... if required else None, alternatives=alternatives)
        return default if vals is None else float(vals[0])

    def boolean(self, el, tag: str, default: bool) -> bool:
        raw = self.text(el, tag, None)
        if raw is None or raw == "":
            return default
        low = raw.lower()
        if low in ("true", "1"):
            return True
        if low in ("false", "0"):
            return False
        raise self.data_error(el, f"<{tag}> must be true or false, got {raw!r}")

    def applies_force(self, el) -> bool:
        if el.find("appliesForce") is not None:
            return self.boolean(el, "appliesForce", True)
        return not self.boolean(el, "isDisabled", False)

    def function(self, owner_el, container: str, context: str) -> Function1D | None:
        """The function of property ``container`` of ``owner_el`` (either form, see
        :func:`biomech.functions.function_in`), or None if absent or empty."""
        return function_in(owner_el, f"{self.doc.path}, {context}", line_of=self.doc.line, container=container)

    def flatten(self, el, prefix: str, out: dict[str, str], skip: set[str]):
        for child in el:
            if not isinstance(child.tag, str) or child.tag in skip or child.tag in _VISUAL:
                continue
            key = f"{prefix}{child.tag}"
            if len(child):
                self.flatten(child, key + ".", out, set())
            else:
                out[key] = (child.text or "").strip()


class _ModelReader(_Reader):
    def read(self, strict: bool) -> OsimModel:
        root = self.doc.root
        if root.tag != "OpenSimDocument":
            raise self.data_error(root, "not an OpenSim document (root element must be <OpenSimDocument>)")
        try:
            version = int(root.get("Version", ""))
        except ValueError:
            raise self.data_error(root, f"missing or invalid Version attribute {root.get('Version')!r}") from None
        if version < 40000:
            raise DataFileError(
                f"{self.doc.path}: OpenSim {version // 10000}.x model file (Version={version}); only the 4.x format "
                f"(Version >= 40000, joints with PhysicalOffsetFrames) is read -- open and save the model once in "
                f"OpenSim 4 (GUI, or opensim.Model(path).printToXML(new_path) in Python) to upgrade it")
        model_el = root.find("Model")
        if model_el is None:
            raise self.data_error(root, "no <Model> element")
        self.model_el = model_el
        name = model_el.get("name", "")
        for child in model_el:
            if isinstance(child.tag, str) and child.tag not in _MODEL_ELEMENTS:
                self.ignore("model element", child)
        for tag, expected in (("length_units", ("meters", "meter", "m")), ("force_units", ("n", "newtons", "newton"))):
            unit = self.text(model_el, tag, "")
            if unit and unit.lower() not in expected:
                raise self.model_error(model_el.find(tag), f"{tag} {unit!r} not supported (SI only: "
                                                          f"{'meters' if tag == 'length_units' else 'N'})")
        gravity = self.numbers(model_el, "gravity", 3, np.array([0.0, -9.80665, 0.0]))
        ground_el = model_el.find("Ground")
        self.ground = ground_el.get("name", "ground") if ground_el is not None else "ground"
        if ground_el is not None:
            self.read_wrap_objects(ground_el, f"ground {self.ground!r}")
        bodies = self.read_bodies(model_el.find("BodySet"))
        self.body_names = {b.name for b in bodies}
        if self.ground in self.body_names:
            raise self.model_error(model_el.find("BodySet"), f"a body is named like ground ({self.ground!r})")
        joints, coords = self.read_joints(model_el.find("JointSet"))
        self.coords = {c.name: c for c in coords}
        self.check_tree(joints, model_el.find("JointSet"))
        constraints = self.read_constraints(model_el.find("ConstraintSet"))
        muscles, actuators, others, groups = self.read_forces(model_el.find("ForceSet"))
        markers = self.read_markers(model_el.find("MarkerSet"))
        for tag, kind in (("ContactGeometrySet", "contact geometry"), ("ControllerSet", "controller"),
                          ("ProbeSet", "probe"), ("ComponentSet", "component")):
            for obj in _objects(model_el.find(tag)):
                self.ignore(kind, obj)
        comps = model_el.find("components")
        if comps is not None:
            for obj in comps:
                if isinstance(obj.tag, str):
                    self.ignore("component", obj)
        report(self.ignored, self.doc.path, strict, stacklevel=4)
        return OsimModel(
            name=name, path=str(self.doc.path), version=version, gravity=_readonly(gravity),
            credits=self.text(model_el, "credits", ""), publications=self.text(model_el, "publications", ""),
            ground=self.ground, bodies=tuple(bodies), joints=tuple(joints), coordinates=tuple(coords),
            muscles=tuple(muscles), actuators=tuple(actuators), other_forces=tuple(others),
            constraints=tuple(constraints), markers=tuple(markers),
            force_groups=dict(groups), ignored=tuple(self.ignored))

    # ---- bodies -----------------------------------------------------------------------------
    def check_properties(self, el, kind: str, owner: str):
        """Report child elements of a body, joint or coordinate that the reader does not know."""
        for child in el:
            if isinstance(child.tag, str) and child.tag not in _KNOWN_PROPERTIES[kind] and child.tag not in _VISUAL:
                self.ignore("property", child, owner)

    def read_wrap_objects(self, el, owner: str):
        for obj in _objects(el.find("WrapObjectSet")):
            self.ignore("wrap object", obj, owner)

    def read_bodies(self, set_el) -> list[Body]:
        bodies = []
        seen = set()
        for el in _objects(set_el):
            if el.tag != "Body":
                raise self.model_error(el, f"unsupported body type {el.tag!r} in the BodySet (supported: Body)")
            name = el.get("name", "")
            if not name or name in seen:
                raise self.model_error(el, f"body name {name!r} is empty or repeated")
            seen.add(name)
            mass = self.number(el, "mass")
            com = self.numbers(el, "mass_center", 3, np.zeros(3))
            six = self.numbers(el, "inertia", 6, np.zeros(6))
            inertia = np.array([[six[0], six[3], six[4]], [six[3], six[1], six[5]], [six[4], six[5], six[2]]])
            if not (np.isfinite(mass) and mass >= 0):
                raise self.model_error(el, f"body {name!r}: mass must be finite and >= 0, got {mass}")
            self.plausible(el, "segment_mass", mass, f"body {name!r}", "mass")
            eig = np.linalg.eigvalsh(inertia)
            if not np.all(np.isfinite(eig)) or eig[0] < -1e-12 * max(1.0, abs(eig[-1])):
                raise self.model_error(el, f"body {name!r}: inertia {six.tolist()} is not positive semi-definite "
                                           f"(principal moments {eig.tolist()})")
            self.read_wrap_objects(el, f"body {name!r}")
            comps = el.find("components")
            if comps is not None:
                for obj in comps:
                    if isinstance(obj.tag, str):
                        self.ignore("body component", obj, f"body {name!r}")
            self.check_properties(el, "Body", f"body {name!r}")
            bodies.append(Body(name, float(mass), _readonly(com), _readonly(inertia)))
        return bodies

    # ---- frames and joints ------------------------------------------------------------------
    def body_of(self, ref: str, el, what: str) -> str:
        """Body (or ground) named by a socket path like ``/bodyset/tibia_r`` or ``/ground``."""
        last = _last_component(ref)
        if last == self.ground or last in self.body_names:
            return last
        raise self.model_error(el, f"{what} {ref!r} is neither ground nor a body of the model"
                                   f"{_hint(last, sorted(self.body_names | {self.ground}))}")

    def resolve_frame(self, ref: str, frames: dict[str, ET.Element], el, depth: int = 0) -> OffsetFrame:
        ref = ref.strip()
        name = ref if ref in frames else _last_component(ref)
        if name in frames:
            if depth > len(frames):
                raise self.model_error(el, f"offset frames {sorted(frames)} refer to each other in a loop")
            fel = frames[name]
            parent_ref = self.text(fel, "socket_parent")
            parent = self.resolve_frame(parent_ref, frames, fel, depth + 1)
            loc = self.numbers(fel, "translation", 3, np.zeros(3))
            ori = self.numbers(fel, "orientation", 3, np.zeros(3))
            if np.any(parent.location) or np.any(parent.orientation):
                r_parent = parent.rotation
                loc = parent.location + r_parent @ loc
                ori = Rotation.from_matrix(r_parent @ Rotation.from_euler("XYZ", ori).as_matrix()).as_euler("XYZ")
            return OffsetFrame(name, parent.body, _readonly(loc), _readonly(ori))
        body = self.body_of(ref, el, "frame")
        return OffsetFrame(body, body, _readonly(np.zeros(3)), _readonly(np.zeros(3)))

    def read_joints(self, set_el):
        joints: list[Joint] = []
        coords: list[Coordinate] = []
        names = set()
        for el in _objects(set_el):
            jname = el.get("name", "")
            if el.tag not in SUPPORTED_JOINT_TYPES:
                raise self.model_error(el, f"unsupported joint type {el.tag!r} (joint {jname!r}); supported: "
                                           f"{', '.join(SUPPORTED_JOINT_TYPES)}")
            if not jname or jname in names:
                raise self.model_error(el, f"joint name {jname!r} is empty or repeated")
            names.add(jname)
            frames = {f.get("name", ""): f for f in (el.find("frames") if el.find("frames") is not None else [])
                      if isinstance(f.tag, str)}
            for fname, fel in frames.items():
                if fel.tag != "PhysicalOffsetFrame":
                    raise self.model_error(fel, f"joint {jname!r}: frame type {fel.tag!r} not supported "
                                                f"(PhysicalOffsetFrame only)")
            parent = self.resolve_frame(self.text(el, "socket_parent_frame", alternatives=("parent_frame",)), frames, el)
            child = self.resolve_frame(self.text(el, "socket_child_frame", alternatives=("child_frame",)), frames, el)
            if parent.body == child.body:
                raise self.model_error(el, f"joint {jname!r} connects body {parent.body!r} to itself")
            coord_els = [c for c in (el.find("coordinates") if el.find("coordinates") is not None else [])
                         if isinstance(c.tag, str)]
            for c in coord_els:
                if c.tag != "Coordinate":
                    raise self.model_error(c, f"joint {jname!r}: unexpected element <{c.tag}> among the coordinates")
            coord_names = tuple(c.get("name", "") for c in coord_els)
            axes = self.joint_axes(el, jname, coord_names)
            self.check_properties(el, "Joint", f"joint {jname!r}")
            joint = Joint(jname, el.tag, parent.body, child.body, parent, child, coord_names, axes,
                          self.boolean(el, "reverse", False))
            joints.append(joint)
            for cel in coord_els:
                coords.append(self.read_coordinate(cel, joint))
        seen = set()
        for c in coords:
            if c.name in seen:
                raise ModelError(f"{self.doc.path}: coordinate name {c.name!r} is used by two joints")
            seen.add(c.name)
        return joints, coords

    def joint_axes(self, el, jname: str, coord_names: tuple[str, ...]) -> tuple[TransformAxis, ...]:
        e = np.eye(3)
        zero = Constant(0.0)

        def fixed(i, axis):
            return TransformAxis(_AXIS_NAMES[i], _readonly(axis), (), zero)

        if el.tag in ("PinJoint", "SliderJoint"):
            if len(coord_names) != 1:
                raise self.model_error(el, f"{el.tag} {jname!r} must have exactly one coordinate, has {len(coord_names)}")
            q = coord_names
            ident = LinearFunction(1.0, 0.0)
            if el.tag == "PinJoint":  # rotation about the common z axis
                return (TransformAxis("rotation1", _readonly(e[2]), q, ident), fixed(1, e[0]), fixed(2, e[1]),
                        fixed(3, e[0]), fixed(4, e[1]), fixed(5, e[2]))
            return (fixed(0, e[0]), fixed(1, e[1]), fixed(2, e[2]),  # SliderJoint: translation along x
                    TransformAxis("translation1", _readonly(e[0]), q, ident), fixed(4, e[1]), fixed(5, e[2]))
        if el.tag == "WeldJoint":
            if coord_names:
                raise self.model_error(el, f"WeldJoint {jname!r} cannot have coordinates, has {list(coord_names)}")
            return tuple(fixed(i, e[i % 3]) for i in range(6))
        # CustomJoint
        st = el.find("SpatialTransform")
        if st is None:
            raise self.data_error(el, f"CustomJoint {jname!r} has no <SpatialTransform>")
        axis_els = [a for a in st if isinstance(a.tag, str)]
        if [a.tag for a in axis_els] != ["TransformAxis"] * 6 or [a.get("name") for a in axis_els] != list(_AXIS_NAMES):
            raise self.data_error(st, f"CustomJoint {jname!r}: the SpatialTransform must hold six TransformAxis "
                                      f"named {', '.join(_AXIS_NAMES)} in this order, found "
                                      f"{[(a.tag, a.get('name')) for a in axis_els]}")
        axes = []
        used: list[str] = []
        for a in axis_els:
            aname = a.get("name")
            context = f"joint {jname!r}, TransformAxis {aname!r}"
            names = tuple(self.text(a, "coordinates", "").split())
            vec = self.numbers(a, "axis", 3)
            norm = float(np.linalg.norm(vec))
            if not norm > 0:
                raise self.model_error(a, f"{context}: axis {vec.tolist()} has zero length")
            fn = self.function(a, "function", context)
            if len(names) > 1:
                raise self.model_error(a, f"{context}: a function of {len(names)} coordinates {list(names)} is not "
                                          f"supported (functions of one coordinate only)")
            for n_ in names:
                if n_ not in coord_names:
                    raise self.model_error(a, f"{context}: coordinate {n_!r} is not one of the joint's coordinates "
                                              f"{list(coord_names)}")
                used.append(n_)
            if fn is None:
                fn = LinearFunction(1.0, 0.0) if names else Constant(0.0)
            elif not names and not is_constant(fn):
                raise self.model_error(a, f"{context}: a non-constant function without a coordinate")
            axes.append(TransformAxis(aname, _readonly(vec / norm), names, fn))
        for group in (axes[:3], axes[3:]):
            u = [ax.axis for ax in group]
            for i, j in ((0, 1), (0, 2), (1, 2)):
                if np.linalg.norm(np.cross(u[i], u[j])) < 1e-5:
                    raise self.model_error(st, f"CustomJoint {jname!r}: axes {group[i].name} and {group[j].name} are "
                                               f"collinear ({u[i].tolist()}, {u[j].tolist()})")
        unused = [c for c in coord_names if c not in used]
        if unused:
            raise self.model_error(el, f"CustomJoint {jname!r}: coordinate(s) {unused} drive no TransformAxis")
        return tuple(axes)

    def read_coordinate(self, el, joint: Joint) -> Coordinate:
        name = el.get("name", "")
        self.check_properties(el, "Coordinate", f"coordinate {name!r}")
        if not name:
            raise self.model_error(el, f"joint {joint.name!r}: a coordinate without a name")
        if joint.type == "PinJoint":
            mt: MotionType = "rotational"
        elif joint.type == "SliderJoint":
            mt = "translational"
        else:
            found: MotionType | None = None
            for ax in joint.transform_axes:
                if name in ax.coordinates:
                    slope = linear_slope(ax.function)
                    if slope is not None and abs(abs(slope) - 1.0) <= 1e-12:
                        found = "rotational" if ax.is_rotation else "translational"
                    elif found is None:
                        found = "coupled"
            mt = found or "coupled"
        rng = self.numbers(el, "range", 2, np.array([-np.inf, np.inf]))
        if rng[0] > rng[1]:
            raise self.model_error(el, f"coordinate {name!r}: range {rng.tolist()} has min > max")
        pf = self.function(el, "prescribed_function", f"coordinate {name!r}, prescribed_function")
        return Coordinate(name=name, joint=joint.name, motion_type=mt,
                          default_value=self.number(el, "default_value", 0.0),
                          default_speed=self.number(el, "default_speed_value", 0.0),
                          range=_readonly(rng), clamped=self.boolean(el, "clamped", False),
                          locked=self.boolean(el, "locked", False), prescribed=self.boolean(el, "prescribed", False),
                          prescribed_function=pf)

    def check_tree(self, joints: list[Joint], set_el):
        parent_of: dict[str, Joint] = {}
        for j in joints:
            if j.child_body == self.ground:
                raise ModelError(f"{self.where(set_el)}: joint {j.name!r} has ground as its child frame's body")
            if j.child_body in parent_of:
                raise ModelError(f"{self.where(set_el)}: body {j.child_body!r} is the child of two joints "
                                 f"({parent_of[j.child_body].name!r} and {j.name!r}): a closed loop, not supported")
            parent_of[j.child_body] = j
        for body in sorted(self.body_names):
            seen = [body]
            b = body
            while b != self.ground:
                if b not in parent_of:
                    raise ModelError(f"{self.where(set_el)}: body {body!r} is not connected to {self.ground!r} by joints "
                                     f"(chain {' <- '.join(seen)}); OpenSim would add a free joint, this reader does not")
                b = parent_of[b].parent_body
                if b in seen:
                    raise ModelError(f"{self.where(set_el)}: joints form a loop through bodies {seen}")
                seen.append(b)

    # ---- constraints ------------------------------------------------------------------------
    def read_constraints(self, set_el) -> list[CoordinateCouplerConstraint]:
        out = []
        for el in _objects(set_el):
            name = el.get("name", "")
            if el.tag != "CoordinateCouplerConstraint":
                self.ignore("constraint", el)
                continue
            indep = self.text(el, "independent_coordinate_names", "").split()
            dep = self.text(el, "dependent_coordinate_name", "")
            if len(indep) != 1:
                self.ignore("constraint", el, reason=f"coupling to {len(indep)} independent coordinates {indep} not "
                                                     f"supported (one only); the model keeps the freedom it would remove")
                continue
            for c in (*indep, dep):
                if c not in self.coords:
                    raise self.model_error(el, f"constraint {name!r} names coordinate {c!r}, which the model lacks")
            fn = self.function(el, "coupled_coordinates_function", f"constraint {name!r}")
            if fn is None:
                raise self.data_error(el, f"constraint {name!r} has no <coupled_coordinates_function>")
            enforced = self.boolean(el, "isEnforced", True) and not self.boolean(el, "isDisabled", False)
            out.append(CoordinateCouplerConstraint(name, indep[0], dep, fn, self.number(el, "scale_factor", 1.0),
                                                   enforced))
        return out

    # ---- forces -----------------------------------------------------------------------------
    def read_forces(self, set_el):
        muscles, actuators, others = [], [], []
        names = set()
        for el in _objects(set_el):
            name = el.get("name", "")
            if name in names:
                raise self.model_error(el, f"force name {name!r} is repeated")
            names.add(name)
            if el.tag.endswith("Muscle") or el.tag.endswith("Muscle_Deprecated"):
                muscles.append(self.read_muscle(el))
            elif el.tag in _ACTUATOR_READERS:
                act = _ACTUATOR_READERS[el.tag](self, el)
                _check_actuator(self, el, act, self.coords, self.body_names | {self.ground})
                actuators.append(act)
            else:
                props: dict[str, str] = {}
                self.flatten(el, "", props, {"appliesForce", "isDisabled"})
                others.append(OtherForce(name, el.tag, self.applies_force(el), dict(props)))
                self.ignore("force", el)
        groups: dict[str, tuple[str, ...]] = {}
        gel = set_el.find("groups") if set_el is not None else None
        for g in (gel if gel is not None else []):
            if isinstance(g.tag, str) and g.tag == "ObjectGroup":
                members = tuple(self.text(g, "members", "").split())
                unknown = [m for m in members if m not in names]
                if unknown:
                    raise self.model_error(g, f"force group {g.get('name')!r} lists unknown forces {unknown}")
                groups[g.get("name", "")] = members
        return muscles, actuators, others, groups

    def read_muscle(self, el) -> Muscle:
        name = el.get("name", "")
        owner = f"muscle {name!r}"
        if el.find("FunctionBasedPath") is not None or any(c.tag == "FunctionBasedPath" for c in el):
            raise self.model_error(el, f"{owner}: FunctionBasedPath not supported (GeometryPath only)")
        gp = el.find("GeometryPath")
        if gp is None:
            gp = next((c for c in el if isinstance(c.tag, str) and c.get("name") == "path"), None)
        if gp is None or gp.tag != "GeometryPath":
            raise self.model_error(el, f"{owner}: no <GeometryPath>"
                                   + (f" (found <{gp.tag}>, not supported)" if gp is not None else ""))
        vals: dict[str, float | None] = {}
        for tag, attr in _MUSCLE_FIELDS.items():
            vals[attr] = self.number(el, tag, None)
        for required in ("max_isometric_force", "optimal_fiber_length", "tendon_slack_length"):
            v = vals[required]
            if v is None:
                raise self.data_error(el, f"{owner}: missing <{required}>")
            if not (np.isfinite(v) and v > 0):
                raise self.model_error(el, f"{owner}: {required} must be > 0, got {v}")
        for tag, quantity in (("max_isometric_force", "max_isometric_force"),
                              ("optimal_fiber_length", "optimal_fiber_length"),
                              ("tendon_slack_length", "tendon_slack_length"),
                              ("pennation_angle_at_optimal", "pennation_angle"),
                              ("max_contraction_velocity", "max_contraction_velocity")):
            v = vals[_MUSCLE_FIELDS[tag]] if tag in _MUSCLE_FIELDS else None
            if v is not None:
                self.plausible(el, quantity, v, owner, tag)
        props: dict[str, str] = {}
        self.flatten(el, "", props, set(_MUSCLE_FIELDS) | {"GeometryPath", "appliesForce", "isDisabled"})
        path = self.read_path(gp, owner)
        return Muscle(
            name=name, type=el.tag, applies_force=self.applies_force(el),
            max_isometric_force=float(vals["max_isometric_force"]),
            optimal_fiber_length=float(vals["optimal_fiber_length"]),
            tendon_slack_length=float(vals["tendon_slack_length"]),
            pennation_angle_at_optimal=float(vals["pennation_angle_at_optimal"] or 0.0),
            max_contraction_velocity=float(vals["max_contraction_velocity"] if vals["max_contraction_velocity"] is not None else 10.0),
            activation_time_constant=vals["activation_time_constant"],
            deactivation_time_constant=vals["deactivation_time_constant"],
            fmax_tendon_strain=vals["fmax_tendon_strain"], fmax_muscle_strain=vals["fmax_muscle_strain"],
            kshape_active=vals["kshape_active"], kshape_passive=vals["kshape_passive"],
            af=vals["af"], flen=vals["flen"], path=path, properties=dict(props))

    def read_path(self, gp, owner: str) -> tuple[AnyPathPoint, ...]:
        pps = gp.find("PathPointSet")
        points: list[AnyPathPoint] = []
        for pel in _objects(pps):
            pname = pel.get("name", "")
            ctx = f"{owner}, {pel.tag} {pname!r}"
            ref = self.text(pel, "socket_parent_frame", None, alternatives=("body", "parent_frame"))
            if ref is None:
                raise self.data_error(pel, f"{ctx}: no <socket_parent_frame>")
            body = self.body_of(ref, pel, f"{ctx}: parent frame")
            if pel.tag == "PathPoint":
                points.append(PathPoint(pname, body, _readonly(self.numbers(pel, "location", 3))))
            elif pel.tag == "ConditionalPathPoint":
                cref = self.text(pel, "socket_coordinate", None, alternatives=("coordinate",))
                coord = self.coordinate_ref(cref, pel, ctx)
                rng = self.numbers(pel, "range", 2)
                points.append(ConditionalPathPoint(pname, body, _readonly(self.numbers(pel, "location", 3)),
                                                   coord, _readonly(rng)))
            elif pel.tag == "MovingPathPoint":
                cs, fs, rs = [], [], []
                fallback = self.numbers(pel, "location", 3, np.zeros(3))
                for k, axis in enumerate("xyz"):
                    cref = self.text(pel, f"socket_{axis}_coordinate", None, alternatives=(f"{axis}_coordinate",))
                    coord = self.coordinate_ref(cref, pel, ctx) if cref else None
                    fn = self.function(pel, f"{axis}_location", f"{ctx}, {axis}_location")
                    if fn is None:
                        if coord is not None:
                            raise self.data_error(pel, f"{ctx}: {axis}_location has no function but a coordinate")
                        fn = Constant(float(fallback[k]))
                    cs.append(coord)
                    fs.append(fn)
                    rs.append(self.coords[coord].range if coord else [-np.inf, np.inf])
                points.append(MovingPathPoint(pname, body, tuple(cs), tuple(fs), _readonly(rs)))
            else:
                raise self.model_error(pel, f"{ctx}: unsupported path point type {pel.tag!r} (supported: PathPoint, "
                                            f"ConditionalPathPoint, MovingPathPoint)")
        if len(points) < 2:
            raise self.model_error(gp, f"{owner}: a path needs at least two points, has {len(points)}")
        for wel in _objects(gp.find("PathWrapSet")):
            wrap = self.text(wel, "wrap_object", "")
            self.ignore("path wrap", wel, owner,
                        reason=f"wrapping over {wrap!r} not modelled; " + _IGNORE_REASONS["path wrap"].split("; ", 1)[1])
        return tuple(points)

    def coordinate_ref(self, ref: str | None, el, ctx: str) -> str:
        if not ref:
            raise self.data_error(el, f"{ctx}: no coordinate named")
        name = _last_component(ref)
        if name not in self.coords:
            raise self.model_error(el, f"{ctx}: coordinate {ref!r} is not a coordinate of the model"
                                       f"{_hint(name, self.coords)}")
        return name

    # ---- markers ----------------------------------------------------------------------------
    def read_markers(self, set_el) -> list[Marker]:
        out = []
        for el in _objects(set_el):
            name = el.get("name", "")
            if el.tag != "Marker":
                self.ignore("component", el, reason="marker type not read")
                continue
            ref = self.text(el, "socket_parent_frame", alternatives=("body",))
            out.append(Marker(name, self.body_of(ref, el, f"marker {name!r}: parent frame"),
                              _readonly(self.numbers(el, "location", 3)), self.boolean(el, "fixed", False)))
        return out


# ---- actuators (model ForceSet and force-set files) ------------------------------------------


def _controls(r: _Reader, el) -> tuple[float, float]:
    return r.number(el, "min_control", -np.inf), r.number(el, "max_control", np.inf)


def _read_coordinate_actuator(r: _Reader, el) -> CoordinateActuator:
    name = el.get("name", "")
    coord = _last_component(r.text(el, "coordinate", alternatives=("socket_coordinate",)))
    if not coord:
        raise r.data_error(el, f"CoordinateActuator {name!r} names no coordinate")
    lo, hi = _controls(r, el)
    return CoordinateActuator(name, coord, r.number(el, "optimal_force", 1.0), lo, hi, r.applies_force(el))


def _read_point_actuator(r: _Reader, el) -> PointActuator:
    name = el.get("name", "")
    body = _last_component(r.text(el, "body", alternatives=("socket_body",)))
    lo, hi = _controls(r, el)
    return PointActuator(name, body, _readonly(r.numbers(el, "point", 3, np.zeros(3))),
                         r.boolean(el, "point_is_global", False),
                         _readonly(r.numbers(el, "direction", 3, np.array([1.0, 0.0, 0.0]))),
                         r.boolean(el, "force_is_global", False), r.number(el, "optimal_force", 1.0), lo, hi,
                         r.applies_force(el))


def _read_torque_actuator(r: _Reader, el) -> TorqueActuator:
    name = el.get("name", "")
    a = _last_component(r.text(el, "bodyA", alternatives=("socket_bodyA",)))
    b = _last_component(r.text(el, "bodyB", "", alternatives=("socket_bodyB",))) or "ground"
    lo, hi = _controls(r, el)
    return TorqueActuator(name, a, b, _readonly(r.numbers(el, "axis", 3, np.array([0.0, 0.0, 1.0]))),
                          r.boolean(el, "torque_is_global", True), r.number(el, "optimal_force", 1.0), lo, hi,
                          r.applies_force(el))


_ACTUATOR_READERS = {
    "CoordinateActuator": _read_coordinate_actuator,
    "PointActuator": _read_point_actuator,
    "TorqueActuator": _read_torque_actuator,
}


def _check_actuator(r: _Reader, el, act, coordinates, bodies):
    if isinstance(act, CoordinateActuator):
        if coordinates is not None and act.coordinate not in coordinates:
            raise r.model_error(el, f"CoordinateActuator {act.name!r}: coordinate {act.coordinate!r} is not in the model"
                                    f"{_hint(act.coordinate, coordinates)}")
    else:
        names = [act.body] if isinstance(act, PointActuator) else [act.body_a, act.body_b]
        for b in names:
            if bodies is not None and b not in bodies:
                raise r.model_error(el, f"{type(act).__name__} {act.name!r}: body {b!r} is not in the model"
                                        f"{_hint(b, bodies)}")
    if not act.min_control <= act.max_control:
        raise r.model_error(el, f"{act.name!r}: min_control {act.min_control} > max_control {act.max_control}")


# =============================================================================================
# reporting
# =============================================================================================


def checked_options(func):
    from .checks import checked_options as wrap

    return wrap(func)


def _hint(name: str, candidates) -> str:
    from .checks import name_hint

    return name_hint(name, candidates)


def report(ignored: list[IgnoredItem], path: Path | str, strict: bool, stacklevel: int = 2) -> None:
    """Warn (one :class:`OsimReaderWarning` per kind) or, if ``strict``, raise ModelError listing
    the ignored items of a file."""
    if not ignored:
        return
    if strict:
        raise ModelError(f"{path}: {len(ignored)} element(s) not supported (strict=True): "
                         + "; ".join(str(i) for i in ignored))
    by_kind: dict[str, list[IgnoredItem]] = {}
    for item in ignored:
        by_kind.setdefault(item.kind, []).append(item)
    for kind, items in by_kind.items():
        shown = items[:10]
        more = f"; and {len(items) - 10} more (see .ignored)" if len(items) > 10 else ""
        plural = "s" if len(items) > 1 else ""
        warnings.warn(f"{path}: {len(items)} {kind}{plural} ignored: " + "; ".join(str(i) for i in shown) + more,
                      OsimReaderWarning, stacklevel=stacklevel)


# =============================================================================================
# public entry points
# =============================================================================================


@checked_options
def read_osim(path: str | Path, *, strict: bool = False, accept: Sequence[str] = ()) -> OsimModel:
    """Read an OpenSim 4.x model file.

    Parameters
    ----------
    path : str or Path
        The ``.osim`` file.
    strict : bool
        If True, any element the reader would ignore (see the module docstring) raises
        :class:`core.errors.ModelError` instead of an :class:`OsimReaderWarning`.
    accept : sequence of str
        Plausible-range quantities not to enforce (``"segment_mass"``, ``"max_isometric_force"``,
        ``"optimal_fiber_length"``, ``"tendon_slack_length"``, ``"pennation_angle"``,
        ``"max_contraction_velocity"``; ``data/biomech/plausible_ranges.csv``).

    Returns
    -------
    OsimModel

    Raises
    ------
    core.errors.DataFileError
        Missing, unreadable, malformed or truncated file (file and line named); an OpenSim 3.x file;
        a missing or non-numeric property; an unsupported function.
    biomech.checks.ImplausibleDataError
        A segment mass or muscle parameter outside its plausible range (body or muscle, tag and
        line named, with the likely slip: grams, mm, cm, degrees).
    core.errors.ModelError
        Unknown joint or path-point type, references to bodies, frames or coordinates the model
        lacks, a body not connected to ground, a closed loop of joints (element and line named).

    Warns
    -----
    OsimReaderWarning
        One per kind of ignored element (wrap objects, path wraps, constraints, other forces, ...),
        naming them; the same items are in ``model.ignored``.

    Examples
    --------
    >>> from core.paths import data_path
    >>> m = read_osim(data_path("biomech", "opensim", "gait10dof18musc_subject01_walk", "subject01.osim"))
    >>> len(m.muscles), round(m.total_mass, 1)
    (18, 72.6)
    """
    reader = _ModelReader(parse_xml(path))
    reader.accept = frozenset([accept] if isinstance(accept, str) else accept)
    return reader.read(strict)


@checked_options
def read_force_set(path: str | Path, model: OsimModel | None = None, *, strict: bool = False) -> ForceSet:
    """Read an OpenSim force-set file of actuators (reserve and residual actuators).

    ``CoordinateActuator`` (coordinate, optimal_force, min/max control), ``PointActuator`` and
    ``TorqueActuator`` entries of ``<objects>`` are read; the ``<defaults>`` section (templates
    OpenSim's GUI uses for new objects, not actuators) is not.  Other entries are reported like the
    ignored elements of :func:`read_osim`.  Old files (Version 20302/30000) are accepted: the
    actuator properties have not changed; ``isDisabled`` is read as ``not applies_force``.

    Parameters
    ----------
    path : str or Path
    model : OsimModel, optional
        If given, every actuator's coordinate or bodies must exist in it (ModelError otherwise).
    strict : bool
        As in :func:`read_osim`.
    """
    doc = parse_xml(path)
    r = _Reader(doc, "force set")
    root = doc.root
    fs = root.find("ForceSet") if root.tag == "OpenSimDocument" else (root if root.tag == "ForceSet" else None)
    if fs is None:
        raise r.data_error(root, "no <ForceSet> element")
    coords = None if model is None else {c.name for c in model.coordinates}
    bodies = None if model is None else {b.name for b in model.bodies} | {model.ground}
    acts = []
    names = set()
    for el in _objects(fs):
        if el.tag not in _ACTUATOR_READERS:
            r.ignore("force-set entry", el)
            continue
        act = _ACTUATOR_READERS[el.tag](r, el)
        if act.name in names:
            raise r.model_error(el, f"actuator name {act.name!r} is repeated")
        names.add(act.name)
        _check_actuator(r, el, act, coords, bodies)
        acts.append(act)
    report(r.ignored, doc.path, strict, stacklevel=3)
    return ForceSet(fs.get("name", ""), str(doc.path), tuple(acts), tuple(r.ignored))
