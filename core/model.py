r"""Build, then freeze: the mutable :class:`ModelBuilder` and the immutable Cartesian :class:`Model`.

``ModelBuilder`` collects bodies, extra coordinates, joints, drivers and force elements; ``build()``
validates them (every error names the element at fault), converts the joint locations to body-fixed
markers, expands joints into vectorised primitive kinds, fixes the sparse pattern of ``Φ_q``, checks
the initial configuration (or assembles it) and detects redundant constraints with a
rank-revealing QR factorisation of ``Φ_qᵀ``.  The resulting :class:`Model` is an implementation of
:class:`core.system.ConstrainedSystem` and is picklable.

Mass matrix (constant, block diagonal; body-frame angular velocity for spatial bodies):
``M = diag(m I, J̄)``; generalized forces add gravity ``m g`` and, spatial, the gyroscopic
moment ``−ω̄ × J̄ ω̄`` (Nikravesh 1988, Eq. 11.22; Shabana 2013, Eq. 7.x).
Energy ``T + V = ½ vᵀMv − Σ m gᵀr + Σ V_springs``.
"""

from __future__ import annotations

import warnings
from collections import OrderedDict
from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
from numpy.typing import ArrayLike, NDArray

from . import frames
from .assembly import assemble as assemble_model
from .assembly import check_initial_state
from .bodies import PLANAR, SPATIAL, Body, BodyStates, Space
from .constraints import PrimitiveKind
from .errors import InputError, ModelError, RedundantConstraintError
from .forces import ForceElement, ForceJacobian, ForceKind
from .joints import (
    Cylindrical,
    DistanceJoint,
    Fixed,
    Joint,
    JointAngleDriver,
    PointDriver,
    Revolute,
    Spherical,
    Translational,
    Universal,
    UserConstraint,
)
from .system import ConstrainedSystem, as_dense

Array = NDArray[np.float64]
GROUND = "ground"


def _csr_checked(data, indices, indptr, shape):
    return sp.csr_matrix((data, indices, indptr), shape=shape, copy=False)


def _csr_unchecked(data, indices, indptr, shape):
    """CSR matrix from arrays whose structure was validated at build time (skips format checks).

    scipy's constructor re-validates the index arrays on every call (~20 µs), which dominated
    ``constraint_terms`` for a 32-body chain.  The pattern is fixed at build, so only the data
    array changes; the fast path is self-tested below and falls back to the checked constructor
    if scipy's internals differ.
    """
    J = sp.csr_matrix.__new__(sp.csr_matrix)
    J._shape = shape
    J.data, J.indices, J.indptr = data, indices, indptr
    J.maxprint = 50
    return J


def _select_csr_builder():
    d = np.array([1.0, 2.0, 3.0])
    ix = np.array([0, 2, 1], np.int32)
    ip = np.array([0, 2, 3], np.int32)
    try:
        A = _csr_unchecked(d, ix, ip, (2, 3))
        ok = (np.array_equal(A.toarray(), _csr_checked(d, ix, ip, (2, 3)).toarray())
              and np.array_equal(A.T @ np.ones(2), np.array([1.0, 3.0, 2.0]))
              and np.array_equal(A[[1]].toarray(), np.array([[0.0, 3.0, 0.0]])))
    except Exception:  # noqa: BLE001 - any failure means: use the public constructor
        ok = False
    return _csr_unchecked if ok else _csr_checked


_make_csr = _select_csr_builder()


@dataclass
class ExtraCoordinate:
    name: str
    value: float
    rate: float
    mass: float


class BuildContext:
    """What element compilers may ask for at build time (body and coordinate indices, initial frames).

    Attributes
    ----------
    space : Space
    n_bodies : int
        Number of bodies; the ground has index ``n_bodies``.
    extra_names : list of str
        Extra coordinates in model order (their velocity index is ``n_bodies·n_v_body + k``).
    bs0 : BodyStates
        Body poses and extra coordinates at the initial configuration.
    """

    def __init__(self, space: Space, body_names: list[str], bs0: BodyStates, extra_names: list[str] | None = None):
        self.space = space
        self.n_bodies = len(body_names)
        self._index = {n: k for k, n in enumerate(body_names)}
        self._index[GROUND] = len(body_names)
        self.extra_names = list(extra_names or [])
        self._extra = {n: k for k, n in enumerate(self.extra_names)}
        self.bs0 = bs0

    def index(self, body: str, element: str) -> int:
        """Index of ``body`` (``n_bodies`` for the ground); :class:`ModelError` naming ``element``."""
        try:
            return self._index[body]
        except KeyError:
            raise ModelError(f"element {element!r} refers to unknown body {body!r}") from None

    def coordinate_index(self, coordinate: str, element: str) -> int:
        """Index of an extra coordinate among the model's extra coordinates (0 for the first)."""
        try:
            return self._extra[coordinate]
        except KeyError:
            known = ", ".join(self.extra_names) or "none"
            raise ModelError(f"element {element!r} refers to unknown coordinate {coordinate!r} "
                             f"(extra coordinates of the model: {known})") from None

    def velocity_index(self, coordinate: str, element: str) -> int:
        """Index of an extra coordinate in the model's velocity (and generalized-force) vector."""
        return self.n_bodies * self.space.n_v + self.coordinate_index(coordinate, element)

    def local_point(self, b: int, p: Array) -> Array:
        return self.bs0.A[b].T @ (np.asarray(p, float) - self.bs0.r[b])

    def local_vector(self, b: int, a: Array) -> Array:
        return self.bs0.A[b].T @ np.asarray(a, float)

    def angle(self, b: int) -> float:
        A = self.bs0.A[b]
        return float(np.arctan2(A[1, 0], A[0, 0]))


class ModelBuilder:
    """Mutable collector of a multibody model; ``build()`` returns a frozen :class:`Model`.

    Parameters
    ----------
    dimension : {2, 3}
        Planar (x, y, θ) or spatial (r, Euler parameters) bodies.
    name : str
    gravity : array_like, shape (dimension,)
        Gravitational acceleration [m/s²]; default ``(0, −9.81)`` planar, ``(0, 0, −9.81)`` spatial.

    Examples
    --------
    >>> b = ModelBuilder(2, "pendulum")
    >>> _ = b.add_body("bob", mass=1.0, inertia=0.0, position=(1.0, 0.0))
    >>> _ = b.add_revolute("pivot", "ground", "bob", at=(0.0, 0.0))
    >>> model = b.build()
    """

    def __init__(self, dimension: int = 2, name: str = "model", gravity: ArrayLike | None = None):
        if dimension not in (2, 3):
            raise ModelError(f"model {name!r}: dimension must be 2 or 3, got {dimension}")
        self.space: Space = PLANAR if dimension == 2 else SPATIAL
        self.name = name
        g = (0.0, -9.81) if dimension == 2 else (0.0, 0.0, -9.81)
        self.gravity = np.asarray(g if gravity is None else gravity, float)
        if self.gravity.shape != (dimension,):
            raise ModelError(f"model {name!r}: gravity must have {dimension} components, got {self.gravity.tolist()}")
        self.bodies: OrderedDict[str, Body] = OrderedDict()
        self.extras: OrderedDict[str, ExtraCoordinate] = OrderedDict()
        self.joints: OrderedDict[str, Joint | UserConstraint] = OrderedDict()
        self.forces: OrderedDict[str, ForceElement] = OrderedDict()
        self.flexible: OrderedDict[str, tuple] = OrderedDict()  # name -> (data, modal names, node constraint)

    # --- names ------------------------------------------------------------------------------
    def _check_new(self, name: str, what: str) -> None:
        if not isinstance(name, str) or not name:
            raise ModelError(f"{what} name must be a non-empty string, got {name!r}")
        if name == GROUND:
            raise ModelError(f"{what} name {name!r} is reserved for the ground")
        for table in (self.bodies, self.extras, self.joints, self.forces):
            if name in table:
                raise ModelError(f"duplicate name {name!r}: a {what} cannot reuse the name of an existing element")

    # --- bodies -----------------------------------------------------------------------------
    def add_body(self, name: str, mass: float, inertia, position, orientation=None, velocity=None,
                 angular_velocity=None) -> str:
        """Add a rigid body; see :class:`core.bodies.Body` for the parameters and units.

        ``orientation`` is an angle [rad] (planar) or Euler parameters (spatial; normalised
        here, error if far from unit length). ``angular_velocity`` is global for spatial bodies.
        """
        self._check_new(name, "body")
        d = self.space.dim
        pos = np.asarray(position, float)
        if pos.shape != (d,) or not np.all(np.isfinite(pos)):
            raise ModelError(f"body {name!r}: position must be {d} finite numbers, got {np.asarray(position).tolist()}")
        if not (np.isfinite(mass) and mass >= 0):
            raise ModelError(f"body {name!r}: mass must be ≥ 0, got {mass}")
        vel = np.zeros(d) if velocity is None else np.asarray(velocity, float)
        if vel.shape != (d,) or not np.all(np.isfinite(vel)):
            raise ModelError(f"body {name!r}: velocity must be {d} finite numbers")
        if d == 2:
            J = float(inertia)
            if not (np.isfinite(J) and J >= 0):
                raise ModelError(f"body {name!r}: polar moment of inertia must be ≥ 0, got {inertia}")
            ori = 0.0 if orientation is None else float(orientation)
            om = 0.0 if angular_velocity is None else float(angular_velocity)
            if not (np.isfinite(ori) and np.isfinite(om)):
                raise ModelError(f"body {name!r}: orientation and angular velocity must be finite, got {ori}, {om}")
            body = Body(name, float(mass), J, pos, ori, vel, om)
        else:
            J = np.asarray(inertia, float)
            if J.shape == (3,):
                J = np.diag(J)
            if J.shape != (3, 3) or not np.allclose(J, J.T) or np.any(np.linalg.eigvalsh(J) < -1e-15):
                raise ModelError(f"body {name!r}: inertia must be a symmetric positive semi-definite 3×3 tensor (or 3 principal moments)")
            # a rigid body's principal moments satisfy the triangle inequality J_a ≤ J_b + J_c
            # (J_a = ∫(y² + z²) dm etc.; Goldstein, Classical Mechanics, 3rd ed., Sec. 5.3); equality:
            # a flat body; a tensor that violates it belongs to no mass distribution
            Jp = np.linalg.eigvalsh(J)
            slack = Jp[0] + Jp[1] - Jp[2]
            if slack < -1e-9 * max(float(Jp[2]), np.finfo(float).tiny):
                raise ModelError(
                    f"body {name!r}: principal moments of inertia {Jp[0]:.6g}, {Jp[1]:.6g}, {Jp[2]:.6g} kg m² violate "
                    f"the triangle inequality (largest {Jp[2]:.6g} > {Jp[0]:.6g} + {Jp[1]:.6g}): no rigid body has "
                    "this inertia (check the units and which moments were given)")
            p = np.array([1.0, 0, 0, 0]) if orientation is None else np.asarray(orientation, float)
            if p.shape != (4,) or not abs(np.linalg.norm(p) - 1.0) <= 1e-6:  # `not <=` also rejects NaN
                raise ModelError(f"body {name!r}: orientation must be 4 Euler parameters of unit norm, got {np.asarray(orientation).tolist()}")
            om = np.zeros(3) if angular_velocity is None else np.asarray(angular_velocity, float)
            if om.shape != (3,) or not np.all(np.isfinite(om)):
                raise ModelError(f"body {name!r}: angular velocity must be 3 finite numbers")
            body = Body(name, float(mass), J, pos, p / np.linalg.norm(p), vel, om)
        self.bodies[name] = body
        return name

    def add_flexible_body(self, name: str, fe_model, modes, position=None, orientation=None, velocity=None,
                          angular_velocity=None, modal_coordinates=None, modal_velocities=None,
                          damping_ratio=0.0, geometric_stiffening: bool | str = False, inertia: str = "full") -> str:
        """Add a flexible body: a floating frame of reference with the modes of a reduced FE component
        (:mod:`core.flexible.body`).

        Parameters
        ----------
        fe_model : core.flexible.FEModel
            The component; its node coordinates define the body frame (origin and axes).
        modes : core.flexible.ModalComponent
            The reduction basis (cantilever modes from ``normal_mode_component`` with the clamp held,
            ``craig_bampton`` or ``free_interface`` with ``orthonormalized(drop_rigid=True)``); a basis
            holding rigid-body modes is refused.
        position, orientation, velocity, angular_velocity
            Of the body frame, as for :meth:`add_body`.
        modal_coordinates, modal_velocities : array_like, shape (n_modes,)
            Initial modal coordinates and rates (default 0).
        damping_ratio : float, str or array_like
            Modal damping ratio ζ (``0.02`` or ``"2 %"``), one for all modes or one per mode.
        geometric_stiffening : bool or str
            True or ``"centrifugal"``: the geometric stiffness of the centrifugal load, scaled with the
            spin (fast-spinning slender bodies); False (default): linear elastic.
        inertia : str
            ``"full"`` (default): the kinetic energy of the deformed body, exact for the floating
            frame; ``"undeformed"``: that of the undeformed body, a rigid body plus modal oscillators
            coupled through the node frames (slowly rotating bodies such as a railway car body; with
            mean-axis modes the cheapest form on the compiled path).  Both run on the numpy and the
            compiled integrators (:mod:`core.flexible.compiled`).

        Returns
        -------
        str
            ``name``; the modal coordinates are extra coordinates ``name.q1 …``; attach joints and
            forces to nodes with :meth:`add_node_frame`, or to ``name`` itself (the frame).
        """
        from .flexible.body import flexible_body_data

        self._check_new(name, "body")
        data = flexible_body_data(name, fe_model, modes, damping_ratio, geometric_stiffening, self.space.dim, inertia)
        m = data.n_modes
        q0 = np.zeros(m) if modal_coordinates is None else np.asarray(modal_coordinates, float)
        qd0 = np.zeros(m) if modal_velocities is None else np.asarray(modal_velocities, float)
        for label, arr in (("modal_coordinates", q0), ("modal_velocities", qd0)):
            if arr.shape != (m,) or not np.all(np.isfinite(arr)):
                raise ModelError(f"flexible body {name!r}: {label} must be {m} finite numbers (one per mode), "
                                 f"got shape {arr.shape}")
        d = self.space.dim
        self.add_body(name, 0.0, 0.0 if d == 2 else np.zeros((3, 3)), np.zeros(d) if position is None else position,
                      orientation, velocity, angular_velocity)
        names = []
        for k in range(m):
            cname = f"{name}.q{k + 1}"
            self._check_new(cname, "coordinate")
            self.extras[cname] = ExtraCoordinate(cname, float(q0[k]), float(qd0[k]), 0.0)
            names.append(cname)
        self.flexible[name] = (data, names, None)
        return name

    def add_node_frame(self, body: str, node: int, name: str | None = None) -> str:
        """A frame on node ``node`` of flexible body ``body`` that joints, forces and drivers attach to.

        The frame is a massless body held at the node's deformed position and orientation by the
        constraint ``body.nodes`` (:class:`core.flexible.body.FlexibleNodes`); its axes are the body
        frame's axes when undeformed, so give joint axes and points in the flexible body's coordinates
        (the node's position is the frame's origin).  Default name ``f"{body}.node{node}"``.
        """
        from .flexible.body import FlexibleNodes

        if body not in self.flexible:
            what = "a rigid body: attach to it directly" if body in self.bodies else "not a body of this model"
            known = ", ".join(self.flexible) or "none"
            raise ModelError(f"add_node_frame: {body!r} is {what} (flexible bodies: {known})")
        data, names, nodes = self.flexible[body]
        N = data.nodes.shape[0]
        if not (isinstance(node, (int, np.integer)) and 0 <= node < N):
            raise ModelError(f"add_node_frame: flexible body {body!r} has nodes 0..{N - 1}, got {node!r}")
        name = f"{body}.node{int(node)}" if name is None else name
        fb = self.bodies[body]
        q = np.array([self.extras[c].value for c in names])
        qd = np.array([self.extras[c].rate for c in names])
        s = data.nodes[node] + data.translation_rows(node) @ q
        sd = data.translation_rows(node) @ qd
        psi, psid = data.rotation_rows(node) @ q, data.rotation_rows(node) @ qd
        if self.space.dim == 2:
            A = frames.rot2(fb.orientation)
            w = float(fb.angular_velocity)
            pos = fb.position + A @ s
            vel = fb.velocity + A @ (w * (frames.ROT90 @ s) + sd)
            self.add_body(name, 0.0, 0.0, pos, fb.orientation + float(psi[0]), vel, w + float(psid[0]))
        else:
            A = frames.euler_to_matrix(fb.orientation)
            wb = A.T @ fb.angular_velocity
            sn = float(np.linalg.norm(psi))
            if sn >= 1.0:
                raise ModelError(f"add_node_frame: node {node} of {body!r} is rotated by {sn:.3g} rad by the initial "
                                 "modal coordinates; a linear floating frame needs small rotations")
            ang = np.arcsin(sn)
            Crel = frames.euler_to_matrix(frames.rotation_vector_to_euler(psi / sn * ang if sn > 0 else psi))
            AN = A @ Crel
            # ½(tr C I − Cᵀ) ω̄_N = ½(tr C I − C) ω̄ + Ψ q̇ (the rate of the orientation constraint)
            tr = np.trace(Crel) * np.eye(3)
            wN = np.linalg.solve(0.5 * (tr - Crel.T), 0.5 * (tr - Crel) @ wb + psid)
            pos = fb.position + A @ s
            vel = fb.velocity + A @ (np.cross(wb, s) + sd)
            self.add_body(name, 0.0, np.zeros((3, 3)), pos, frames.matrix_to_euler(AN), vel, AN @ wN)
        if nodes is None:
            nodes = FlexibleNodes(data, names)
            self.flexible[body] = (data, names, nodes)
            self._check_new(nodes.name, "joint")
            self.joints[nodes.name] = nodes
        nodes.add(name, int(node))
        return name

    def add_coordinate(self, name: str, value: float, rate: float = 0.0, mass: float = 0.0) -> str:
        """Add an extra scalar coordinate (e.g. a path parameter) with optional inertia ``mass``."""
        self._check_new(name, "coordinate")
        self.extras[name] = ExtraCoordinate(name, float(value), float(rate), float(mass))
        return name

    # --- joints -----------------------------------------------------------------------------
    def add_joint(self, joint: Joint | UserConstraint) -> Joint | UserConstraint:
        """Add any joint, driver or user constraint object."""
        self._check_new(joint.name, "joint")
        bi, bj = getattr(joint, "body_i", GROUND), getattr(joint, "body_j", GROUND)
        if not isinstance(joint, UserConstraint) and bi == bj:
            raise ModelError(f"joint {joint.name!r} connects body {bi!r} to itself")
        self.joints[joint.name] = joint
        return joint

    def add_revolute(self, name, body_i, body_j, at, axis=None) -> Revolute:
        """Revolute joint at global point ``at`` (spatial: about global ``axis``)."""
        return self.add_joint(Revolute(name, body_i, body_j, at, axis))

    def add_spherical(self, name, body_i, body_j, at) -> Spherical:
        return self.add_joint(Spherical(name, body_i, body_j, at))

    def add_universal(self, name, body_i, body_j, at, axis_i, axis_j) -> Universal:
        return self.add_joint(Universal(name, body_i, body_j, at, axis_i, axis_j))

    def add_cylindrical(self, name, body_i, body_j, at, axis) -> Cylindrical:
        return self.add_joint(Cylindrical(name, body_i, body_j, at, axis))

    def add_translational(self, name, body_i, body_j, at, axis) -> Translational:
        return self.add_joint(Translational(name, body_i, body_j, at, axis))

    def add_fixed(self, name, body_i, body_j, at) -> Fixed:
        return self.add_joint(Fixed(name, body_i, body_j, at))

    def add_distance(self, name, body_i, body_j, point_i, point_j, length=None) -> DistanceJoint:
        return self.add_joint(DistanceJoint(name, body_i, body_j, point_i, point_j, length))

    def add_angle_driver(self, name, joint: str | Revolute, motion) -> JointAngleDriver:
        """Drive the relative angle of revolute ``joint`` by ``motion`` (offset from its initial value)."""
        j = self.joints.get(joint) if isinstance(joint, str) else joint
        if not isinstance(j, Revolute):
            raise ModelError(f"driver {name!r}: {joint!r} is not a revolute joint of this model")
        return self.add_joint(JointAngleDriver(name, j, motion))

    def add_point_driver(self, name, body, point, direction, motion) -> PointDriver:
        """Drive a body point along a global ``direction`` by ``motion`` (offset from its initial value)."""
        return self.add_joint(PointDriver(name, body, point, direction, motion))

    # --- forces -----------------------------------------------------------------------------
    def add_force(self, element: ForceElement) -> ForceElement:
        """Add any force element (see :mod:`core.forces`)."""
        self._check_new(element.name, "force element")
        self.forces[element.name] = element
        return element

    def add_spring_damper(self, name, body_i, body_j, point_i, point_j, stiffness, damping=0.0,
                          free_length=None, actuator=None):
        from .forces import SpringDamper

        return self.add_force(SpringDamper(name, body_i, body_j, point_i, point_j, stiffness, damping, free_length, actuator))

    def add_point_spring(self, name, body_i, body_j, point_i, point_j=None, stiffness=0.0, damping=0.0):
        """Zero-free-length point-to-point spring-damper (:class:`core.forces.PointSpring`)."""
        from .forces import PointSpring

        return self.add_force(PointSpring(name, body_i, body_j, point_i, point_j, stiffness, damping))

    def add_rotational_spring_damper(self, name, body_i, body_j, stiffness, damping=0.0, free_angle=0.0,
                                     actuator=None, axis=None):
        """Torsional spring-damper-actuator (:class:`core.forces.RotationalSpringDamper`); spatial needs ``axis``."""
        from .forces import RotationalSpringDamper

        return self.add_force(RotationalSpringDamper(name, body_i, body_j, stiffness, damping, free_angle, actuator, axis))

    def add_bushing(self, name, body_i, body_j, at, translational_stiffness, rotational_stiffness,
                    translational_damping=0.0, rotational_damping=0.0, axes=None, point_j=None):
        """Linear bushing between marker frames at ``at`` (:class:`core.forces.Bushing`)."""
        from .forces import Bushing

        return self.add_force(Bushing(name, body_i, body_j, at, translational_stiffness, rotational_stiffness,
                                      translational_damping, rotational_damping, axes, point_j))

    def add_bump_stop(self, name, body_i, body_j, at, axis, table, damping=0.0, sides="both", point_j=None):
        """Clearance spring along a body-fixed axis with a tabulated force law (:class:`core.forces.BumpStop`).

        ``table`` rows are (total relative displacement [m], force [N]); the first row is the
        clearance with force 0.
        """
        from .forces import BumpStop

        return self.add_force(BumpStop(name, body_i, body_j, at, axis, table, damping, sides, point_j))

    def add_series_spring_damper(self, name, body_i, body_j, point_i, point_j, stiffness, damping, node_mass,
                                 free_length=None, node_position=None):
        """Spring in series with a damper (Maxwell element, :class:`core.forces.SeriesSpringDamper`).

        Adds the extra coordinate ``f"{name}.node"`` (the node position x along PQ from P [m],
        initially ``node_position``, default half the distance PQ) with mass ``node_mass`` [kg]
        (> 0: the damper's moving mass), then the element.  The node makes the model stiff
        (eigenvalue ≈ −c/m_n): integrate with ``jit-radau`` or another implicit method.
        """
        from .forces import SeriesSpringDamper

        self._check_new(name, "force element")
        try:
            m_n = float(node_mass)
        except (TypeError, ValueError):
            m_n = float("nan")
        if not (np.isfinite(m_n) and m_n > 0):
            raise ModelError(f"series spring-damper {name!r}: node mass must be a finite number > 0 [kg] (the "
                             f"damper's moving mass; a massless node is not supported by core), got {node_mass!r}")
        if node_position is None:
            try:
                x0 = 0.5 * float(np.linalg.norm(np.asarray(point_j, float) - np.asarray(point_i, float)))
            except (TypeError, ValueError):
                x0 = 0.0
            x0 = x0 if np.isfinite(x0) else 0.0  # the element reports bad points at build
        else:
            try:
                x0 = float(node_position)
            except (TypeError, ValueError):
                x0 = float("nan")
        if not np.isfinite(x0):
            raise ModelError(f"series spring-damper {name!r}: node position must be a finite number [m], "
                             f"got {node_position!r}")
        node = self.add_coordinate(f"{name}.node", x0, 0.0, m_n)
        return self.add_force(SeriesSpringDamper(name, body_i, body_j, point_i, point_j, stiffness, damping, node,
                                                 free_length))

    def add_applied_force(self, name, body, point, force, frame="global"):
        """Force of time at a body point (:class:`core.forces.AppliedForce`)."""
        from .forces import AppliedForce

        return self.add_force(AppliedForce(name, body, point, force, frame))

    def add_applied_torque(self, name, body, torque, frame="global"):
        """Torque of time on a body (:class:`core.forces.AppliedTorque`)."""
        from .forces import AppliedTorque

        return self.add_force(AppliedTorque(name, body, torque, frame))

    def add_plane_contact(self, name, body, center, radius, plane_point, plane_normal, restitution=1.0,
                          impact_velocity=None, stiffness=None, exponent=1.5, materials=None, friction=0.0,
                          friction_velocity=1e-3, model="lankarani-nikravesh"):
        """Sphere-on-ground-plane continuous contact (:class:`core.forces.PlaneContact`)."""
        from .forces import PlaneContact

        return self.add_force(PlaneContact(name, body, center, radius, plane_point, plane_normal, restitution,
                                           impact_velocity, stiffness, exponent, materials, friction,
                                           friction_velocity, model))

    # --- build ------------------------------------------------------------------------------
    def build(self, assemble: bool = False, redundant: str = "raise", tol: float = 1e-9) -> Model:
        """Validate and freeze.

        Parameters
        ----------
        assemble : bool
            If True, correct the initial positions and velocities onto the constraints
            (kinematic assembly, minimum-norm correction) instead of rejecting them.
        redundant : {'raise', 'remove', 'keep'}
            What to do with dependent constraint equations found at the initial configuration:
            raise :class:`RedundantConstraintError` naming them; remove them (their reaction
            share is then carried by the independent rows, a unique multiplier set, as Adams
            does); or keep them (integrators then use minimum-norm multipliers).
        tol : float
            Tolerance on the initial constraint residual [m or rad] and on the rank decision.
        """
        if redundant not in ("raise", "remove", "keep"):
            raise ModelError(f"model {self.name!r}: redundant must be 'raise', 'remove' or 'keep', got {redundant!r}")
        if not self.bodies and not self.extras:
            raise ModelError(f"model {self.name!r} has no bodies")
        model = Model._from_builder(self)
        if assemble:
            model = assemble_model(model)
        model._check_initial(tol)
        model._check_redundancy(redundant, tol)
        model._freeze()
        return model


@dataclass(frozen=True)
class _FlexRecord:
    """A flexible body in a model: its data, body index and coordinate/velocity indices."""

    data: object
    body: int
    qi: NDArray[np.int64]
    vi: NDArray[np.int64]


class Model(ConstrainedSystem):
    """Frozen Cartesian multibody model (see module docstring). Create with :class:`ModelBuilder`.

    After ``build()`` the model is immutable: assigning an attribute raises ``AttributeError``
    (change the builder and build again; :meth:`with_state` returns a copy with another initial
    state).  Arrays handed out (``q0``, ``v0``) are read-only views.
    """

    _frozen = False

    def _freeze(self) -> None:
        for name in ("q0", "v0", "gravity"):
            arr = np.array(getattr(self, name), dtype=float)
            arr.setflags(write=False)
            object.__setattr__(self, name, arr)
        object.__setattr__(self, "_frozen", True)

    def __setattr__(self, name, value):
        if self._frozen:
            raise AttributeError(f"model {self.name!r} is frozen: cannot set {name!r} "
                                 "(change the ModelBuilder and build again, or use with_state())")
        object.__setattr__(self, name, value)

    def __setstate__(self, state):
        object.__setattr__(self, "__dict__", dict(state))  # own dict (copy.copy passes the original)

    # ---------------------------------------------------------------------------------------
    @classmethod
    def _from_builder(cls, b: ModelBuilder) -> Model:
        self = cls.__new__(cls)
        sp_ = b.space
        self.space = sp_
        self.name = b.name
        self.gravity = b.gravity.copy()
        self.body_names = list(b.bodies)
        self.n_bodies = nb = len(self.body_names)
        self.extra_names = list(b.extras)
        ne = len(self.extra_names)
        self.n_q = nb * sp_.n_q + ne
        self.n_v = nb * sp_.n_v + ne
        bodies = list(b.bodies.values())
        self.bodies = tuple(bodies)
        # initial state -----------------------------------------------------------------------
        q0, v0 = np.zeros(self.n_q), np.zeros(self.n_v)
        for k, body in enumerate(bodies):
            qs, vs = slice(k * sp_.n_q, (k + 1) * sp_.n_q), slice(k * sp_.n_v, (k + 1) * sp_.n_v)
            if sp_.dim == 2:
                q0[qs] = [*body.position, body.orientation]
                v0[vs] = [*body.velocity, body.angular_velocity]
            else:
                q0[qs] = [*body.position, *body.orientation]
                A = frames.euler_to_matrix(body.orientation)
                v0[vs] = [*body.velocity, *(A.T @ body.angular_velocity)]
        for k, ex in enumerate(b.extras.values()):
            q0[nb * sp_.n_q + k] = ex.value
            v0[nb * sp_.n_v + k] = ex.rate
        self.q0, self.v0 = q0, v0
        # names -------------------------------------------------------------------------------
        qn = ("x", "y", "theta") if sp_.dim == 2 else ("x", "y", "z", "e0", "e1", "e2", "e3")
        vn = ("vx", "vy", "omega") if sp_.dim == 2 else ("vx", "vy", "vz", "wx", "wy", "wz")
        qu = ("[m]", "[m]", "[rad]") if sp_.dim == 2 else ("[m]",) * 3 + ("[-]",) * 4
        vu = ("[m/s]", "[m/s]", "[rad/s]") if sp_.dim == 2 else ("[m/s]",) * 3 + ("[rad/s]",) * 3
        self.coordinate_names = [f"{n}.{c} {u}" for n in self.body_names for c, u in zip(qn, qu)] + self.extra_names
        self.velocity_names = [f"{n}.{c} {u}" for n in self.body_names for c, u in zip(vn, vu)] + [f"{n}.rate" for n in self.extra_names]
        # mass matrix --------------------------------------------------------------------------
        blocks = []
        for body in bodies:
            if sp_.dim == 2:
                blocks.append(np.diag([body.mass, body.mass, body.inertia]))
            else:
                blk = np.zeros((6, 6))
                blk[:3, :3] = body.mass * np.eye(3)
                blk[3:, 3:] = body.inertia
                blocks.append(blk)
        blocks += [np.array([[ex.mass]]) for ex in b.extras.values()]
        self._M = sp.block_diag(blocks, format="csr") if blocks else sp.csr_matrix((0, 0))
        self.mass_is_constant = True
        self._setup_flexible(b)
        self._masses = np.array([bd.mass for bd in bodies])
        self._J = np.array([bd.inertia for bd in bodies]) if sp_.dim == 3 else None
        # constant gravity force --------------------------------------------------------------
        Qg = np.zeros((nb, sp_.n_v))
        Qg[:, : sp_.dim] = self._masses[:, None] * self.gravity
        self._Qg = np.concatenate([Qg.ravel(), np.zeros(ne)])
        # compile joints ------------------------------------------------------------------------
        bs0 = BodyStates.from_coordinates(sp_, nb, q0, v0)
        ctx = BuildContext(sp_, self.body_names, bs0, self.extra_names)
        self._ctx_names = self.body_names
        groups: OrderedDict[type, list] = OrderedDict()
        self.joints = tuple(b.joints.values())
        self.user_constraints: list[UserConstraint] = []
        joint_of_label: dict[str, str] = {}
        for j in self.joints:
            if isinstance(j, UserConstraint):
                self.user_constraints.append(j)
                continue
            for spec in j.primitives(ctx):
                groups.setdefault(spec.kind, []).append(spec)
                joint_of_label[spec.label] = j.name
        self.kinds: list[PrimitiveKind] = []
        for kind, specs in groups.items():
            params: dict[str, list] = {}
            for s in specs:
                for k, v in s.params.items():
                    params.setdefault(k, []).append(v)
            kw = {}
            for k, v in params.items():
                if k == "dim":
                    kw[k] = v[0]
                elif k == "functions":
                    kw[k] = v
                else:
                    kw[k] = np.array(v)
            obj = kind(labels=[s.label for s in specs], **kw)
            # ground index fix-up for drivers that use -1 for "no second body"
            obj.bj = np.where(obj.bj < 0, nb, obj.bj)
            self.kinds.append(obj)
        # rows, names and the fixed sparse pattern of Φ_q ---------------------------------------
        names, rows_of_joint = [], OrderedDict((j.name, []) for j in self.joints)
        coo_r, coo_c, coo_mask = [], [], []
        row = 0
        nvb = sp_.n_v
        self._kind_rows = []
        for kind in self.kinds:
            n, r = kind.n, kind.rows
            self._kind_rows.append(slice(row, row + n * r))
            rr = row + np.arange(n * r).reshape(n, r)
            for e in range(n):
                for k in range(r):
                    names.append(f"{kind.labels[e]}[{k}]" if r > 1 else kind.labels[e])
                rows_of_joint[joint_of_label[kind.labels[e]]].extend(rr[e].tolist())
            bodies2 = np.stack([kind.bi, kind.bj], 1)  # (n, 2)
            R = np.broadcast_to(rr[:, :, None, None], (n, r, 2, nvb))
            Cc = np.broadcast_to((bodies2[:, None, :, None] * nvb + np.arange(nvb)), (n, r, 2, nvb))
            M_ = np.broadcast_to((bodies2[:, None, :, None] < nb), (n, r, 2, nvb))
            coo_r.append(R.ravel())
            coo_c.append(Cc.ravel())
            coo_mask.append(M_.ravel())
            row += n * r
        self._user_rows = []
        for uc in self.user_constraints:
            qi, vi = [], []
            for bname in uc.bodies:
                k = ctx.index(bname, uc.name)
                if k == nb:
                    continue
                qi += list(range(k * sp_.n_q, (k + 1) * sp_.n_q))
                vi += list(range(k * nvb, (k + 1) * nvb))
            for cname in uc.coordinates:
                if cname not in self.extra_names:
                    raise ModelError(f"constraint {uc.name!r} refers to unknown coordinate {cname!r}")
                e = self.extra_names.index(cname)
                qi.append(nb * sp_.n_q + e)
                vi.append(nb * nvb + e)
            uc.bind(qi, vi, sp_)
            self._user_rows.append(slice(row, row + uc.rows))
            rr = np.arange(row, row + uc.rows)
            names += [f"{uc.name}[{k}]" for k in range(uc.rows)]
            rows_of_joint[uc.name].extend(rr.tolist())
            coo_r.append(np.repeat(rr, len(vi)))
            coo_c.append(np.tile(np.asarray(vi), uc.rows))
            coo_mask.append(np.ones(uc.rows * len(vi), bool))
            row += uc.rows
        self.n_c = row
        self.constraint_names = names
        self._rows_of_joint = {k: np.asarray(v, np.int64) for k, v in rows_of_joint.items()}
        self._active_rows = None  # set when redundant rows are removed
        if coo_r:
            r_all, c_all, m_all = np.concatenate(coo_r), np.concatenate(coo_c), np.concatenate(coo_mask)
        else:
            r_all = c_all = np.zeros(0, np.int64)
            m_all = np.zeros(0, bool)
        self._jac_mask = m_all
        r_k, c_k = r_all[m_all], c_all[m_all]
        order = np.lexsort((c_k, r_k))
        self._jac_order = order
        self._jac_indices = c_k[order].astype(np.int32)
        self._jac_indptr = np.concatenate([[0], np.cumsum(np.bincount(r_k, minlength=self.n_c))]).astype(np.int32)
        self._n_kind_entries = int(np.sum([k.n * k.rows * 2 * nvb for k in self.kinds]))
        # forces ---------------------------------------------------------------------------------
        fgroups: OrderedDict[type, list] = OrderedDict()
        for f in b.forces.values():
            fgroups.setdefault(type(f), []).append(f)
        self.force_elements = tuple(b.forces.values())
        self.force_kinds: list[ForceKind] = [cls_.compile(els, ctx) for cls_, els in fgroups.items()]
        self.time_dependent = (any(k.time_dependent for k in self.kinds)
                               or any(getattr(uc, "time_dependent", False) for uc in self.user_constraints))
        self.is_conservative = (all(fk.conservative for fk in self.force_kinds) and not self.time_dependent
                                and all(f.data.conservative for f in self.flexible))
        self._reaction_points = {}
        for j in self.joints:
            if isinstance(j, UserConstraint):
                continue
            bj_name = j.body_j if j.body_j != GROUND else j.body_i
            kb = ctx.index(bj_name, j.name)
            self._reaction_points[j.name] = (kb, ctx.local_point(kb, j.report_point(ctx)))
        return self

    def _setup_flexible(self, b: ModelBuilder) -> None:
        """Index the flexible bodies' blocks and fix the sparse pattern of ``M(q)`` (:mod:`core.flexible.body`)."""
        sp_, nb = self.space, self.n_bodies
        recs = []
        for name, (data, names, _) in b.flexible.items():
            k = self.body_names.index(name)
            ex = np.array([self.extra_names.index(c) for c in names], np.int64)
            vi = np.concatenate([k * sp_.n_v + np.arange(sp_.n_v), nb * sp_.n_v + ex])
            qi = np.concatenate([k * sp_.n_q + np.arange(sp_.n_q), nb * sp_.n_q + ex])
            recs.append(_FlexRecord(data, k, qi, vi))
        self.flexible = tuple(recs)
        if not recs:
            return
        self.mass_is_constant = False
        pattern = abs(self._M).tocoo()
        rows = [pattern.row] + [np.repeat(f.vi, len(f.vi)) for f in recs]
        cols = [pattern.col] + [np.tile(f.vi, len(f.vi)) for f in recs]
        P = sp.csr_matrix((np.ones(sum(len(r) for r in rows)), (np.concatenate(rows), np.concatenate(cols))),
                          shape=self._M.shape)
        P.sum_duplicates()
        P.sort_indices()
        pos = sp.csr_matrix((np.arange(P.nnz, dtype=float) + 1.0, P.indices, P.indptr), shape=P.shape)
        self._M_pattern = (P.indices.copy(), P.indptr.copy())
        base = self._M.tocoo()
        self._M_base = np.zeros(P.nnz)
        np.add.at(self._M_base, np.asarray(pos[base.row, base.col]).ravel().astype(np.int64) - 1, base.data)
        self._M_flex_pos = [np.asarray(pos[np.repeat(f.vi, len(f.vi)), np.tile(f.vi, len(f.vi))]).ravel().astype(np.int64) - 1
                            for f in recs]

    def _flexible_terms(self, q: Array, v: Array):
        """Per flexible body ``(M_b, Q_b)`` at ``(q, v)``."""
        out = []
        d = self.space.dim
        for f in self.flexible:
            qb = q[f.qi]
            vb = v[f.vi]
            nqb, nvb = self.space.n_q, self.space.n_v
            A = self.space.rotation(qb[None, :nqb])[0]
            out.append(f.data.mass_and_forces(A, vb[:d], vb[d:nvb], qb[nqb:], vb[nvb:], self.gravity))
        return out

    # --- picklability is automatic (plain attributes; time functions must be picklable) --------

    # --- kinematics -------------------------------------------------------------------------
    def body_states(self, q: Array, v: Array | None = None) -> BodyStates:
        return BodyStates.from_coordinates(self.space, self.n_bodies, q, v)

    def body_index(self, name: str) -> int:
        if name == GROUND:
            return self.n_bodies
        try:
            return self.body_names.index(name)
        except ValueError:
            raise ModelError(f"model {self.name!r} has no body {name!r}") from None

    def point_position(self, q: Array, body: str, point) -> Array:
        """Global position [m] of a body-fixed point given in body coordinates, shape (d,).

        ``q`` may also be a time history of shape (n_t, n_q); the result is then (n_t, d).
        """
        k = self.body_index(body)
        s = np.asarray(point, float).reshape(self.space.dim)
        Q = np.atleast_2d(np.asarray(q, float))
        out = np.array([self.body_states(qq).point(np.array([k]), s[None])[0] for qq in Q])
        return out[0] if np.ndim(q) == 1 else out

    def body_frame(self, q: Array, body: str) -> Array:
        """Rotation matrix (body → global) of ``body`` at ``q``, shape (d, d)."""
        return self.body_states(q).A[self.body_index(body)].copy()

    def q_slice(self, body: str) -> slice:
        k = self.body_index(body)
        return slice(k * self.space.n_q, (k + 1) * self.space.n_q)

    def v_slice(self, body: str) -> slice:
        k = self.body_index(body)
        return slice(k * self.space.n_v, (k + 1) * self.space.n_v)

    def qdot(self, q: Array, v: Array) -> Array:
        if self.space.dim == 2:
            return v.copy()
        nb = self.n_bodies
        out = np.empty(self.n_q)
        qb = q[: nb * 7].reshape(nb, 7)
        vb = v[: nb * 6].reshape(nb, 6)
        ob = out[: nb * 7].reshape(nb, 7)
        ob[:, :3] = vb[:, :3]
        ob[:, 3:] = 0.5 * np.einsum("nij,ni->nj", frames.euler_rate_matrix(qb[:, 3:]), vb[:, 3:])
        out[nb * 7 :] = v[nb * 6 :]
        return out

    def Z(self, q: Array):
        """``Z(q)``: identity for planar bodies; ``diag(I₃, ½L(p)ᵀ)`` per spatial body (one COO build)."""
        if self.space.dim == 2:
            return sp.identity(self.n_q, format="csr")
        nb, ne = self.n_bodies, len(self.extra_names)
        blk = np.zeros((nb, 7, 6))
        blk[:, :3, :3] = np.eye(3)
        blk[:, 3:, 3:] = 0.5 * np.swapaxes(frames.euler_rate_matrix(q[: nb * 7].reshape(nb, 7)[:, 3:]), 1, 2)
        b = np.arange(nb)[:, None, None]
        rows = np.broadcast_to(b * 7 + np.arange(7)[None, :, None], blk.shape).ravel()
        cols = np.broadcast_to(b * 6 + np.arange(6)[None, None, :], blk.shape).ravel()
        ex = np.arange(ne)
        data = np.concatenate([blk.ravel(), np.ones(ne)])
        rows = np.concatenate([rows, nb * 7 + ex])
        cols = np.concatenate([cols, nb * 6 + ex])
        return sp.csr_matrix((data, (rows, cols)), shape=(self.n_q, self.n_v))

    def retract(self, q: Array, dv: Array) -> Array:
        if self.space.dim == 2:
            return q + dv
        nb = self.n_bodies
        out = q.copy()
        qb = out[: nb * 7].reshape(nb, 7)
        db = dv[: nb * 6].reshape(nb, 6)
        qb[:, :3] += db[:, :3]
        qb[:, 3:] = frames.quat_multiply(qb[:, 3:], frames.rotation_vector_to_euler(db[:, 3:]))
        out[nb * 7 :] += dv[nb * 6 :]
        return out

    def normalize(self, q: Array) -> Array:
        if self.space.dim == 2:
            return q
        nb = self.n_bodies
        out = q.copy()
        p = out[: nb * 7].reshape(nb, 7)[:, 3:]
        p /= np.linalg.norm(p, axis=1, keepdims=True)
        return out

    def invariant_violation(self, q: Array) -> float:
        if self.space.dim == 2 or self.n_bodies == 0:
            return 0.0
        p = q[: self.n_bodies * 7].reshape(self.n_bodies, 7)[:, 3:]
        return float(np.max(np.abs(np.sum(p * p, 1) - 1.0)))

    # --- dynamics ----------------------------------------------------------------------------
    def M(self, t: float, q: Array):
        if not self.flexible:
            return self._M
        data = self._M_base.copy()
        nqb = self.space.n_q
        for f, pos in zip(self.flexible, self._M_flex_pos):
            qb = q[f.qi]
            Mb = f.data.mass_block(self.space.rotation(qb[None, :nqb])[0], qb[nqb:])
            np.add.at(data, pos, Mb.ravel())
        return _make_csr(data, *self._M_pattern, self._M.shape)

    def _force_accumulate(self, bs: BodyStates, t: float) -> Array:
        """Sum of every force kind's generalized forces, shape (n_v,) (gravity and gyroscopic excluded)."""
        nb, nvb = self.n_bodies, self.space.n_v
        acc = np.zeros((nb + 1, nvb))
        accx = np.zeros(len(self.extra_names))
        for fk in self.force_kinds:
            ev = fk.evaluate(bs, t)
            np.add.at(acc, ev.bodies, ev.Qb)
            if len(ev.coords):
                np.add.at(accx, ev.coords, ev.Qx)
        return np.concatenate([acc[:nb].ravel(), accx])

    def Q(self, t: float, q: Array, v: Array) -> Array:
        Q = self._Qg.copy()
        nb = self.n_bodies
        if self.space.dim == 3 and nb:
            w = v[: nb * 6].reshape(nb, 6)[:, 3:]
            Jw = np.einsum("nij,nj->ni", self._J, w)
            Q[: nb * 6].reshape(nb, 6)[:, 3:] -= np.cross(w, Jw)
        if self.force_kinds:
            bs = self.body_states(q, v)
            Q += self._force_accumulate(bs, t)
        for f, (_, Qb) in zip(self.flexible, self._flexible_terms(q, v)):
            Q[f.vi] += Qb
        return Q

    def _flexible_jacobian_entries(self, q, v):
        """Rows, columns and values of ∂Q/∂q and ∂Q/∂v of the flexible bodies' forces (forward
        differences over each body's own coordinates: 3–6 + n_modes columns)."""
        out = []
        nqb, nvb, d = self.space.n_q, self.space.n_v, self.space.dim
        for f in self.flexible:
            qb, vb = q[f.qi].copy(), v[f.vi].copy()

            def Qb(qq, vv, f=f):
                A = self.space.rotation(qq[None, :nqb])[0]
                return f.data.mass_and_forces(A, vv[:d], vv[d:nvb], qq[nqb:], vv[nvb:], self.gravity)[1]

            Q0 = Qb(qb, vb)
            n = len(f.vi)
            Jq, Jv = np.zeros((n, n)), np.zeros((n, n))
            for k in range(d, n):  # Q_b does not depend on the frame position
                h = 1e-7 * max(1.0, abs(vb[k]))
                vv = vb.copy()
                vv[k] += h
                Jv[:, k] = (Qb(qb, vv) - Q0) / h
                h = 1e-7
                dv = np.zeros(nvb)
                qq = qb.copy()
                if k < nvb:
                    dv[k] = h
                    if d == 2:
                        qq[2] += h
                    else:
                        qq[3:7] = frames.quat_multiply(qb[3:7], frames.rotation_vector_to_euler(dv[3:6]))
                else:
                    qq[nqb + k - nvb] += h
                Jq[:, k] = (Qb(qq, vb) - Q0) / h
            r_, c_ = np.repeat(f.vi, n), np.tile(f.vi, n)
            out.append((r_, c_, Jq.ravel(), Jv.ravel()))
        return out

    # --- search state of stateful force kinds (see core.forces.protocol) -----------------------
    @property
    def stateful(self) -> bool:
        """True when a force kind keeps a search state (integrators then call the hooks below)."""
        return any(fk.stateful for fk in self.force_kinds)

    def begin_run(self, t: float, q: Array, v: Array) -> None:
        """A run starts at ``(t, q, v)``: reset the search state of every stateful force kind."""
        kinds = [fk for fk in self.force_kinds if fk.stateful]
        if kinds:
            bs = self.body_states(q, v)
            for fk in kinds:
                fk.reset_state(bs, t)

    def accept_step(self, t: float, q: Array, v: Array) -> None:
        """An integrator accepted a step ending at ``(t, q, v)``: update the search states."""
        kinds = [fk for fk in self.force_kinds if fk.stateful]
        if kinds:
            bs = self.body_states(q, v)
            for fk in kinds:
                fk.accept_step(bs, t)

    def _force_jacobians(self, t, q, v):
        """Sparse (Q_q, Q_v) from analytic kind Jacobians; None if any kind lacks one."""
        nvb, nb = self.space.n_v, self.n_bodies
        bs = self.body_states(q, v)
        rows, cols, Kq, Kv = [], [], [], []
        extra_i, extra_j, extra_q, extra_v = [], [], [], []
        for fk in self.force_kinds:
            jac: ForceJacobian | None = fk.jacobian(bs, t)
            if jac is None:
                return None
            rows.append(jac.rows)
            cols.append(jac.cols)
            Kq.append(jac.Kq)
            Kv.append(jac.Kv)
            if jac.entries is not None:
                ei, ej, eq, ev = (np.asarray(a) for a in jac.entries)
                extra_i.append(ei)
                extra_j.append(ej)
                extra_q.append(eq)
                extra_v.append(ev)
        for ei, ej, eq, ev in self._flexible_jacobian_entries(q, v):
            extra_i.append(ei)
            extra_j.append(ej)
            extra_q.append(eq)
            extra_v.append(ev)
        if self.space.dim == 3 and nb:
            w = v[: nb * 6].reshape(nb, 6)[:, 3:]
            Jw = np.einsum("nij,nj->ni", self._J, w)
            G = np.zeros((nb, 6, 6))
            G[:, 3:, 3:] = -(np.einsum("nij,njk->nik", frames.skew(w), self._J) - frames.skew(Jw))
            idx = np.arange(nb)
            rows.append(idx)
            cols.append(idx)
            Kq.append(np.zeros((nb, 6, 6)))
            Kv.append(G)
        shape = (self.n_v, self.n_v)
        if not rows and not extra_i:
            Z = sp.csr_matrix(shape)
            return Z, Z
        if not rows:
            ii, jj = np.concatenate(extra_i), np.concatenate(extra_j)
            return (sp.csr_matrix((np.concatenate(extra_q), (ii, jj)), shape=shape),
                    sp.csr_matrix((np.concatenate(extra_v), (ii, jj)), shape=shape))
        r = np.concatenate(rows)
        c = np.concatenate(cols)
        keep = (r < nb) & (c < nb)
        r, c = r[keep], c[keep]
        I = (r[:, None, None] * nvb + np.arange(nvb)[None, :, None]) + 0 * np.arange(nvb)[None, None, :]
        Jc = (c[:, None, None] * nvb + np.arange(nvb)[None, None, :]) + 0 * np.arange(nvb)[None, :, None]
        ii, jj = [I.ravel()] + extra_i, [Jc.ravel()] + extra_j
        dq = [np.concatenate(Kq)[keep].ravel()] + extra_q
        dv = [np.concatenate(Kv)[keep].ravel()] + extra_v
        ii, jj = np.concatenate(ii), np.concatenate(jj)
        Qq = sp.csr_matrix((np.concatenate(dq), (ii, jj)), shape=shape)
        Qv = sp.csr_matrix((np.concatenate(dv), (ii, jj)), shape=shape)
        return Qq, Qv

    def Q_q(self, t, q, v):
        jj = self._force_jacobians(t, q, v)
        return super().Q_q(t, q, v) if jj is None else jj[0]

    def Q_v(self, t, q, v):
        jj = self._force_jacobians(t, q, v)
        return super().Q_v(t, q, v) if jj is None else jj[1]

    def Q_jacobians(self, t, q, v):
        """Both ``(Q_q, Q_v)`` in one pass (sparse when analytic)."""
        jj = self._force_jacobians(t, q, v)
        if jj is None:
            return super().Q_q(t, q, v), super().Q_v(t, q, v)
        return jj

    # --- constraints -------------------------------------------------------------------------
    def _eval_kinds(self, t, q, v, what):
        bs = self.body_states(q, v)
        return [k.evaluate(bs, t, what) for k in self.kinds]

    def _select(self, full: Array) -> Array:
        return full if self._active_rows is None else full[self._active_rows]

    def _Phi_all(self, t, q):
        parts = [e.phi.ravel() for e in self._eval_kinds(t, q, None, "p")]
        parts += [np.asarray(uc.phi(t, q), float).ravel() for uc in self.user_constraints]
        return np.concatenate(parts) if parts else np.zeros(0)

    def Phi(self, t: float, q: Array) -> Array:
        return self._select(self._Phi_all(t, q))

    def _Phi_q_all(self, t, q):
        parts = [e.jac.ravel() for e in self._eval_kinds(t, q, None, "j")]
        parts += [np.asarray(uc.jacobian(t, q), float).ravel() for uc in self.user_constraints]
        data = np.concatenate(parts) if parts else np.zeros(0)
        n_kind = self._n_kind_entries
        kd = data[:n_kind][self._jac_mask[:n_kind]]
        data = np.concatenate([kd, data[n_kind:]])[self._jac_order]
        return _make_csr(data, self._jac_indices, self._jac_indptr, (self._n_c_all, self.n_v))

    @property
    def _n_c_all(self):
        return len(self._jac_indptr) - 1

    def Phi_q(self, t: float, q: Array):
        J = self._Phi_q_all(t, q)
        return J if self._active_rows is None else J[self._active_rows]

    def nu(self, t: float, q: Array) -> Array:
        if not self.time_dependent and not self.user_constraints:
            return np.zeros(self.n_c)
        parts = [e.nu.ravel() for e in self._eval_kinds(t, q, None, "n")]
        parts += [np.asarray(uc.nu(t, q), float).ravel() for uc in self.user_constraints]
        return self._select(np.concatenate(parts) if parts else np.zeros(0))

    def gamma(self, t: float, q: Array, v: Array) -> Array:
        parts = [e.gamma.ravel() for e in self._eval_kinds(t, q, v, "g")]
        parts += [np.asarray(uc.gamma(t, q, v), float).ravel() for uc in self.user_constraints]
        return self._select(np.concatenate(parts) if parts else np.zeros(0))

    def constraint_terms(self, t: float, q: Array, v: Array):
        """``(Φ, Φ_q, ν, γ)`` in a single pass over the element kinds (used by integrators)."""
        bs = self.body_states(q, v)
        ev = [k.evaluate(bs, t, "pjng") for k in self.kinds]
        phi = [e.phi.ravel() for e in ev] + [np.asarray(uc.phi(t, q), float).ravel() for uc in self.user_constraints]
        nu = [e.nu.ravel() for e in ev] + [np.asarray(uc.nu(t, q), float).ravel() for uc in self.user_constraints]
        ga = [e.gamma.ravel() for e in ev] + [np.asarray(uc.gamma(t, q, v), float).ravel() for uc in self.user_constraints]
        jd = [e.jac.ravel() for e in ev] + [np.asarray(uc.jacobian(t, q), float).ravel() for uc in self.user_constraints]
        cat = lambda xs: np.concatenate(xs) if xs else np.zeros(0)  # noqa: E731
        data = cat(jd)
        n_kind = self._n_kind_entries
        data = np.concatenate([data[:n_kind][self._jac_mask[:n_kind]], data[n_kind:]])[self._jac_order]
        J = _make_csr(data, self._jac_indices, self._jac_indptr, (self._n_c_all, self.n_v))
        if self._active_rows is not None:
            J = J[self._active_rows]
        return self._select(cat(phi)), J, self._select(cat(nu)), self._select(cat(ga))

    # --- many frames at once (analyses of a prescribed motion) -------------------------------
    def _frames_args(self, t, q, v=None):
        t = np.atleast_1d(np.asarray(t, float))
        q = np.atleast_2d(np.asarray(q, float))
        if q.shape != (len(t), self.n_q):
            raise InputError(f"model {self.name!r}: q has shape {q.shape} for {len(t)} frames, expected "
                             f"({len(t)}, {self.n_q})")
        if v is not None:
            v = np.atleast_2d(np.asarray(v, float))
            if v.shape != (len(t), self.n_v):
                raise InputError(f"model {self.name!r}: v has shape {v.shape} for {len(t)} frames, expected "
                                 f"({len(t)}, {self.n_v})")
        return t, q, v

    @property
    def frames_vectorised(self) -> bool:
        """True when :meth:`constraint_terms_frames` evaluates every frame in one call per element
        (no joint kinds, and every user constraint offers ``phi_frames``); otherwise it loops over
        the frames (same numbers, slower)."""
        return not self.kinds and all(hasattr(uc, "phi_frames") for uc in self.user_constraints)

    def constraint_terms_frames(self, t, q, v=None):
        r"""``(Φ, Φ_q, ν, γ)`` at many states: ``t`` (n_f,), ``q`` (n_f, n_q), ``v`` (n_f, n_v) or None.

        Returns Φ (n_f, n_c), a *dense* Φ_q (n_f, n_c, n_v), ν (n_f, n_c) and γ (n_f, n_c) (None
        without ``v``): the same rows as :meth:`constraint_terms`.  User constraints that offer
        ``phi_frames``, ``jacobian_frames``, ``nu_frames`` and ``gamma_frames``
        (:class:`core.joints.UserConstraint`) are evaluated for all frames in one call; anything
        else frame by frame.  For analyses of a prescribed motion, whose frames are independent
        (:func:`core.analysis.kinematic_analysis` with a guess per frame,
        :func:`core.analysis.inverse_dynamics`).
        """
        t, q, v = self._frames_args(t, q, v)
        nf = len(t)
        if not self.frames_vectorised:
            out = [self.constraint_terms(t[i], q[i], np.zeros(self.n_v) if v is None else v[i]) for i in range(nf)]
            phi = np.array([o[0] for o in out]).reshape(nf, self.n_c)
            J = np.array([as_dense(o[1]) for o in out]).reshape(nf, self.n_c, self.n_v)
            nu = np.array([o[2] for o in out]).reshape(nf, self.n_c)
            ga = None if v is None else np.array([o[3] for o in out]).reshape(nf, self.n_c)
            return phi, J, nu, ga
        n_all = self._n_c_all
        phi, nu = np.zeros((nf, n_all)), np.zeros((nf, n_all))
        ga = None if v is None else np.zeros((nf, n_all))
        J = np.zeros((nf, n_all, self.n_v))
        r0 = 0
        for uc in self.user_constraints:
            rows = slice(r0, r0 + uc.rows)
            phi[:, rows] = uc.phi_frames(t, q)
            J[:, rows, uc.v_index] = uc.jacobian_frames(t, q)
            nu[:, rows] = uc.nu_frames(t, q)
            if v is not None:
                ga[:, rows] = uc.gamma_frames(t, q, v)
            r0 += uc.rows
        if self._active_rows is not None:
            a = self._active_rows
            phi, J, nu = phi[:, a], J[:, a], nu[:, a]
            ga = None if ga is None else ga[:, a]
        return phi, J, nu, ga

    def Q_frames(self, t, q, v) -> Array:
        """Generalized forces ``Q(t, q, v)`` at many states, shape (n_f, n_v).

        Gravity and the gyroscopic terms for all frames at once; force kinds that offer
        ``evaluate_frames`` (:class:`core.forces.protocol.ForceKind`) in one call, the others frame
        by frame; flexible bodies frame by frame.
        """
        t, q, v = self._frames_args(t, q, v)
        nf, nb = len(t), self.n_bodies
        nvb = self.space.n_v
        Q = np.repeat(self._Qg[None, :], nf, axis=0)
        if self.space.dim == 3 and nb:
            w = v[:, : nb * 6].reshape(nf, nb, 6)[:, :, 3:]
            gyro = np.zeros((nf, nb, 6))
            gyro[:, :, 3:] = -np.cross(w, np.einsum("nij,fnj->fni", self._J, w))
            Q[:, : nb * 6] += gyro.reshape(nf, nb * 6)
        if self.force_kinds:
            acc = np.zeros((nb + 1, nf, nvb))
            accx = np.zeros((len(self.extra_names), nf))
            bsf = None
            for fk in self.force_kinds:
                if hasattr(fk, "evaluate_frames"):
                    if bsf is None:
                        bsf = BodyStates.from_frames(self.space, nb, q, v)
                    ev = fk.evaluate_frames(bsf, t)
                    np.add.at(acc, ev.bodies, np.swapaxes(ev.Qb, 0, 1))
                    if len(ev.coords):
                        np.add.at(accx, ev.coords, np.swapaxes(ev.Qx, 0, 1))
                    continue
                for i in range(nf):
                    ev = fk.evaluate(self.body_states(q[i], v[i]), t[i])
                    np.add.at(acc[:, i], ev.bodies, ev.Qb)
                    if len(ev.coords):
                        np.add.at(accx[:, i], ev.coords, ev.Qx)
            Q[:, : nb * nvb] += np.swapaxes(acc[:nb], 0, 1).reshape(nf, nb * nvb)
            Q[:, nb * nvb:] += accx.T
        if self.flexible:
            for i in range(nf):
                for f, (_, Qb) in zip(self.flexible, self._flexible_terms(q[i], v[i])):
                    Q[i, f.vi] += Qb
        return Q

    def M_frames(self, t, q) -> Array:
        """Mass matrices at many configurations, dense (n_f, n_v, n_v) (one shared matrix,
        broadcast, unless the model has flexible bodies)."""
        t, q, _ = self._frames_args(t, q)
        if not self.flexible:
            return np.broadcast_to(as_dense(self._M), (len(t), self.n_v, self.n_v))
        return np.array([as_dense(self.M(t[i], q[i])) for i in range(len(t))])

    def reactions_frames(self, t, q, lam, J=None) -> dict[str, Array]:
        """:meth:`reactions` at many frames: per joint an array (n_f, 3) planar or (n_f, 6)
        spatial.  ``J`` the dense Φ_q of the frames (n_f, n_c, n_v) if already computed."""
        t, q, _ = self._frames_args(t, q)
        lam = np.atleast_2d(np.asarray(lam, float))
        if J is None:
            J = self.constraint_terms_frames(t, q)[1]
        groups = self.reaction_groups()
        A = BodyStates.from_frames(self.space, self.n_bodies, q, None).A
        d, nvb = self.space.dim, self.space.n_v
        out = {}
        for name, (kb, sloc) in self._reaction_points.items():
            rows = groups.get(name)
            if rows is None or len(rows) == 0 or kb >= self.n_bodies:
                continue
            Qc = -np.einsum("frc,fr->fc", J[:, rows, kb * nvb:(kb + 1) * nvb], lam[:, rows])
            F = Qc[:, :d]
            arm = np.einsum("fij,j->fi", A[:, kb], sloc)
            if d == 2:
                Mp = Qc[:, 2] - (arm[:, 0] * F[:, 1] - arm[:, 1] * F[:, 0])
                out[name] = np.column_stack([F, Mp])
            else:
                Mp = np.einsum("fij,fj->fi", A[:, kb], Qc[:, 3:]) - np.cross(arm, F)
                out[name] = np.concatenate([F, Mp], axis=1)
        return out

    # --- energy and reactions ------------------------------------------------------------------
    def energy(self, t: float, q: Array, v: Array) -> float:
        T = 0.5 * float(v @ (self.M(t, q) @ v))
        nb = self.n_bodies
        r = q[: nb * self.space.n_q].reshape(nb, self.space.n_q)[:, : self.space.dim]
        V = -float(np.sum(self._masses * (r @ self.gravity)))
        for f in self.flexible:
            qb = q[f.qi]
            A = self.space.rotation(qb[None, :self.space.n_q])[0]
            V += f.data.potential(qb[:self.space.dim], A, qb[self.space.n_q:], self.gravity)
        if self.force_kinds:
            bs = self.body_states(q, v)
            V += sum(fk.potential(bs) for fk in self.force_kinds)
        return T + V

    def reaction_groups(self) -> dict[str, NDArray[np.int64]]:
        if self._active_rows is None:
            return dict(self._rows_of_joint)
        pos = {int(r): k for k, r in enumerate(self._active_rows)}
        return {n: np.array([pos[int(r)] for r in rows if int(r) in pos], np.int64) for n, rows in self._rows_of_joint.items()}

    def reaction_names(self) -> dict[str, list[str]]:
        if self.space.dim == 2:
            cols = ["Fx [N]", "Fy [N]", "Mz [N m]"]
        else:
            cols = ["Fx [N]", "Fy [N]", "Fz [N]", "Mx [N m]", "My [N m]", "Mz [N m]"]
        return {n: cols for n in self._reaction_points}

    def reactions(self, t: float, q: Array, lam: Array) -> dict[str, Array]:
        r"""Joint reactions on the reporting body at the joint point, global axes.

        The constraint force on body ``b`` is ``Q^c_b = −(Φ_q)_{rows,b}ᵀ λ_rows``: a force at the
        body origin plus a moment (planar scalar / spatial body-frame).  Transferred to the joint
        point P: ``M_P = M_cm − (r_P − r_cm) × F``.
        """
        J = self.Phi_q(t, q)
        J = J.toarray() if sp.issparse(J) else np.asarray(J, float)  # dense rows: sparse slicing ~0.1 ms a joint
        q = np.asarray(q, float)
        out = self.reactions_frames([t], q[None, :], np.asarray(lam, float)[None, :], J=J[None])
        return {name: val[0] for name, val in out.items()}

    # --- build-time checks -------------------------------------------------------------------
    def _check_initial(self, tol: float) -> None:
        check_initial_state(self, 0.0, self.q0, self.v0, tol, owner=f"model {self.name!r}",
                            remedy="Fix the initial configuration or velocities, or build(assemble=True).")

    def dependent_constraints(self, q: Array | None = None, tol: float = 1e-9) -> list[int]:
        """Indices of constraint rows that are linear combinations of earlier-pivoted rows.

        Rank-revealing QR with column pivoting of ``Φ_qᵀ`` (Businger & Golub 1965): the first
        ``rank`` pivots are an independent row set; the others are dependent.
        """
        if self.n_c == 0:
            return []
        J = self._Phi_q_all(0.0, self.q0 if q is None else q).toarray()
        Rm, piv = sla.qr(J.T, mode="r", pivoting=True)
        diag = np.abs(np.diag(Rm)) if Rm.size else np.zeros(0)
        smax = diag[0] if len(diag) else 0.0
        rank = int(np.sum(diag > tol * max(1.0, smax) * max(J.shape)))
        return sorted(int(i) for i in piv[rank:])

    def _check_redundancy(self, mode: str, tol: float) -> None:
        dep = self.dependent_constraints(tol=tol)
        self.redundant_constraints = [self.constraint_names[i] for i in dep]
        self.redundant_rows = np.asarray(dep, np.int64)
        if not dep:
            return
        msg = (
            f"model {self.name!r}: {len(dep)} redundant constraint equation(s) at the initial configuration: "
            + ", ".join(self.redundant_constraints)
        )
        if mode == "raise":
            raise RedundantConstraintError(msg + ". Use build(redundant='remove') or 'keep'.", self.redundant_constraints)
        if mode == "remove":
            warnings.warn(msg + " (removed)", stacklevel=3)
            keep = np.setdiff1d(np.arange(self._n_c_all), dep)
            self._active_rows = keep
            self.n_c = len(keep)
            self.constraint_names = [self.constraint_names[i] for i in keep]
        else:
            warnings.warn(msg + " (kept; multipliers are minimum-norm)", stacklevel=3)

    @property
    def degrees_of_freedom(self) -> int:
        """``n_v − rank(Φ_q)`` at the initial configuration."""
        return self.n_v - (self.n_c - len(getattr(self, "redundant_rows", [])) if self._active_rows is None else self.n_c)

    def with_state(self, q0: Array, v0: Array) -> Model:
        """A copy of the model with another initial state (used by assembly)."""
        import copy

        m = copy.copy(self)
        object.__setattr__(m, "_frozen", False)
        m.q0 = np.asarray(q0, float).copy()
        m.v0 = np.asarray(v0, float).copy()
        if self._frozen:
            m._freeze()
        return m
