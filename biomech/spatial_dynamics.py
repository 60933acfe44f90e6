r"""Inverse dynamics of a spatial OpenSim model in its generalized coordinates.

The planar pipeline (:mod:`biomech.inverse_dynamics`, Cartesian core with driving constraints)
handles sagittal models only.  This module computes the generalized forces of every coordinate
of any tree-structured OpenSim model (gait2392: 23 coordinates, 3-D ``CustomJoint``\ s) directly
in the model's own coordinates, from the analytic Jacobians of :class:`biomech.skeleton.Skeleton`,
for the static optimisation of the 92-muscle model.

Equations
---------
For a tree of rigid bodies b with mass m_b, centre of mass c_b and central inertia I_b^B (body
axes) whose configuration is given by the coordinates q, the generalized forces τ that the
actuators (muscles, or OpenSim's "moments") must supply follow from Jourdain's principle of
virtual power, written as Kane's equations F_r + F_r* = 0 (Kane & Levinson 1985, Sec. 6.1, with
the generalized inertia forces of a rigid body of Sec. 4.11): for every virtual rate δq̇, the
power of the inertia forces equals that of gravity, the external loads and τ, so

.. math::

    \tau = \sum_b \Big[ J_{c,b}^T\, m_b\, (a_b - g)
                      + J_{\omega,b}^T\, (I_b\, \alpha_b + \omega_b \times I_b\, \omega_b) \Big]
           - \sum_e \Big[ J_{P,e}^T F_e + J_{\omega,b(e)}^T T_e \Big]          \quad (1)

with, for every body, all vectors in ground,

.. math::

    \omega_b = J_{\omega,b}\,\dot q, \qquad
    \alpha_b = J_{\omega,b}\,\ddot q + \dot J_{\omega,b}\,\dot q, \qquad
    a_b = J_{c,b}\,\ddot q + \dot J_{c,b}\,\dot q,                            \quad (2)

.. math::

    J_{c,b} = J_{x,b} - [\rho_b]_\times J_{\omega,b}, \quad \rho_b = R_{GB}\, c_b^B, \qquad
    I_b = R_{GB}\, I_b^B\, R_{GB}^T                                            \quad (3)

(J_x,b and J_ω,b: the origin and angular Jacobians of :meth:`Skeleton.forward_kinematics`, shape
(3, n_q) per body; [ρ]× the cross-product matrix).  Eq. (1) is the Newton–Euler equation of every
body, m a = f and I α + ω × I ω = n about the centre of mass (Featherstone 2008, Ch. 2, the
rigid-body equation of motion; the recursive Newton–Euler algorithm of Sec. 5.3, Table 5.1,
computes the same τ by a backward pass over the tree), projected on the partial velocities J_c and partial angular velocities J_ω.  An
external load e (OpenSim ``ExternalForce``) is the force F_e acting at the point P_e (the centre
of pressure) of its body plus a free torque T_e; its generalized force uses the Jacobian of the
body point that coincides with P_e,

.. math::

    J_{P,e} = J_{x,b} - [P_e - x_b]_\times J_{\omega,b}.                       \quad (4)

OpenSim's ``ExternalForce::computeForce`` does the same: the force and torque are expressed in
``force_expressed_in_body``, the point in ``point_expressed_in_body`` (both transformed to ground
here), and without a point the force acts at the body origin.

Velocity-product accelerations J̇ q̇ (analytic; the default)
------------------------------------------------------------
With q̈ = 0 in Eq. (2), the bias accelerations (angular α̂_b and linear â of the body origin) are
propagated from ground outwards along the joints of the tree, each joint as Simbody's
function-based mobilizer (:mod:`biomech.skeleton`, Eqs. 1–4).  For a joint from frame F on the
parent P to frame M on the child C, with angles θ_i = f_i(q_{c_i}) about a_i and displacements
s_i = f_{3+i}(q_{c_{3+i}}) along t_i, θ̇_i = f_i' q̇_{c_i} and the velocity-product parts
θ̂_i = f_i'' q̇_{c_i}² (likewise ŝ_i):

.. math::

    w_1 = a_1,\; w_2 = R_1 a_2,\; w_3 = R_1 R_2 a_3, \qquad
    \omega_{FM} = \textstyle\sum_i \dot\theta_i w_i, \qquad
    \hat\alpha_{FM} = \textstyle\sum_i \hat\theta_i w_i
        + \dot\theta_1\dot\theta_2\, w_1\times w_2
        + (\dot\theta_1 w_1 + \dot\theta_2 w_2)\times \dot\theta_3 w_3         \quad (5)

(the w_i turn with the preceding rotations: ẇ_2 = θ̇_1 w_1 × w_2, ẇ_3 = (θ̇_1 w_1 + θ̇_2 w_2) × w_3;
vectors in F), ṗ_FM = Σ ṡ_i t_i, p̂_FM = Σ ŝ_i t_i, and along the tree, in ground (R_GF = R_GP R_PF,
r = x_M − x_P, d = x_C − x_M),

.. math::

    \omega_C &= \omega_P + R_{GF}\,\omega_{FM}, \qquad
    \hat\alpha_C = \hat\alpha_P + \omega_P \times R_{GF}\,\omega_{FM} + R_{GF}\,\hat\alpha_{FM}, \\
    \hat a_M &= \hat a_P + \hat\alpha_P \times r + \omega_P \times (\omega_P \times r)
             + 2\,\omega_P \times R_{GF}\,\dot p_{FM} + R_{GF}\,\hat p_{FM}, \\
    \hat a_C &= \hat a_M + \hat\alpha_C \times d + \omega_C \times (\omega_C \times d), \qquad
    \hat a_{c,b} = \hat a_b + \hat\alpha_b \times \rho_b + \omega_b \times (\omega_b \times \rho_b). \quad (6)

Eq. (6) is exact (the axis functions' second derivatives are analytic, SimmSpline and
polynomial functions included), so τ carries only rounding errors (≈ 1e-12 relative).  At a kink
of a ``PiecewiseLinearFunction`` the one-sided derivative of the interval that holds q is used.

``bias="central"`` replaces Eq. (6) by a central difference of the Jacobians along q̇,

.. math::

    \dot J \dot q \approx \frac{J(q + h\dot q) - J(q - h\dot q)}{2h}\,\dot q,
    \qquad h = \delta / \max_i |\dot q_i|,                                      \quad (7)

whose error is h²/6 · ``|d³(J q̇)/ds³|`` (truncation along the path s = h) plus about
ε ``|J|`` ``|q̇|`` / h (rounding); with the coordinate step δ = 1e-5 (rad or m) both are of order
1e-10 ``|J|`` ``|q̇|²`` — for gait (``|q̇|`` ≲ 10 rad/s, ``|J|`` ≲ 1 m) below 1e-8 m/s².  It costs two more
evaluations of the Jacobians and is kept as the independent check of Eq. (6) (see the tests).

Validation (``tests/biomech/test_spatial_dynamics.py``)
-------------------------------------------------------
* A two-axis pendulum against Lagrange's equations in closed form: 1e-10 N m (analytic J̇q̇),
  1e-7 N m (Eq. 7).
* gait10dof18musc against the Cartesian-core pipeline (driving constraints and multipliers,
  :func:`biomech.inverse_dynamics.inverse_dynamics`): equal to ~1e-12 N m.
* gait2392, subject01 walk, 0.5–2.5 s (121 frames; the force data end at 2.5 s): against OpenSim
  4.6's InverseDynamicsTool (same filter: ``load_trial(..., order=3)``) the largest rms difference
  over the 23 coordinates is 4e-4 N (pelvis_ty_force; moments ≤ 3e-4 N m), the largest single
  difference 2e-3 N m, once ours is evaluated at OpenSim's time stamps (its padded storage sits up
  to 1.5 µs early).  Wall time (2-core shared machine): 0.03 s for Eq. (1) over the 121 frames
  (0.11 s with reading and filtering the trial) against 0.46 s for OpenSim's ``tool.run()``, of
  which 0.2 s is its frame loop.

What is and is not modelled
---------------------------
* The coordinates are independent (tree models; gait10dof18musc and gait2392 have no
  constraints).  ``CoordinateCouplerConstraint``\ s are ignored, as OpenSim's inverse-dynamics
  solver does (``calcResidualForceIgnoringConstraints``); they are listed in ``attrs``.
* No muscle or other force element of the model enters: τ is what all actuators together must
  supply (OpenSim's tool with the muscles excluded).
* q̇ = u: every joint is a function-based mobilizer whose generalized speeds are the coordinate
  rates (OpenSim ``CustomJoint``, ``PinJoint``, ``SliderJoint``), so τ is the generalized force
  conjugate to q, OpenSim's ``<coordinate>_moment`` / ``<coordinate>_force``.

References
----------
Kane T.R., Levinson D.A. (1985) Dynamics: Theory and Applications. McGraw-Hill, New York.
Sec. 4.11 (generalized inertia forces of a rigid body: −m a·v_r − (I·α + ω × I·ω)·ω_r), Sec. 6.1
(Kane's dynamical equations F_r + F_r* = 0).
Featherstone R. (2008) Rigid Body Dynamics Algorithms. Springer, New York.  Ch. 2 (equation of
motion of a rigid body), Sec. 5.3 and Table 5.1 (recursive Newton–Euler inverse dynamics).
Sherman M.A., Seth A., Delp S.L. (2011) Simbody: multibody dynamics for biomedical research.
Procedia IUTAM 2:241–261 (mobilizers; generalized forces in mobility space).
Seth A., Sherman M., Eastman P., Delp S. (2010) Minimal formulation of joint motion for
biomechanisms. Nonlinear Dyn. 62:291–303 (OpenSim's CustomJoint).
Source read for the definitions (not copied): opensim-core ``ExternalForce.cpp``
(``computeForce``: frames of force, point and torque; body origin when no point is given),
``InverseDynamicsTool.cpp``.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
import pandas as pd

from core.errors import InputError, ModelError

from .skeleton import Skeleton, axis_rotation

__all__ = ["BodyMotion", "SpatialInverseDynamics", "spatial_inverse_dynamics", "BIAS_METHODS"]

#: ways to obtain the velocity-product accelerations J̇ q̇ (module docstring, Eqs. 6 and 7)
BIAS_METHODS = ("analytic", "central")

#: default coordinate step δ of the central difference, Eq. (7) [rad or m]
CENTRAL_STEP = 1e-5


def _cross_columns(vectors: np.ndarray, columns: np.ndarray) -> np.ndarray:
    """``columns[..., :, j] × vectors`` for every column j: (..., 3, k) × (..., 3) -> (..., 3, k)."""
    return np.cross(columns, vectors[..., :, None], axisa=-2, axisb=-2, axisc=-2)


@dataclass(frozen=True, eq=False)
class BodyMotion:
    """Motion of the centres of mass of all bodies, frame by frame (Eqs. 2–3).

    Attributes
    ----------
    body_names, coordinate_names : tuple of str
    rotation : ndarray, shape (n_frames, n_bodies, 3, 3)
        R_GB.
    origin : ndarray, shape (n_frames, n_bodies, 3)
        Body origins in ground [m].
    origin_jacobian, angular_jacobian : ndarray, shape (n_frames, n_bodies, 3, n_coordinates)
        J_x and J_ω (ground components).
    com : ndarray, shape (n_frames, n_bodies, 3)
        Centres of mass in ground [m].
    com_jacobian : ndarray, shape (n_frames, n_bodies, 3, n_coordinates)
        J_c = J_x − [ρ]× J_ω.
    angular_velocity, com_velocity : ndarray, shape (n_frames, n_bodies, 3)
        ω = J_ω q̇ [rad/s], v_c = J_c q̇ [m/s] (ground).
    angular_bias, com_bias : ndarray, shape (n_frames, n_bodies, 3)
        J̇_ω q̇ [rad/s²] and J̇_c q̇ [m/s²].
    angular_acceleration, com_acceleration : ndarray, shape (n_frames, n_bodies, 3)
        α = J_ω q̈ + J̇_ω q̇ [rad/s²], a_c = J_c q̈ + J̇_c q̇ [m/s²].
    bias_method : str
        ``"analytic"`` (Eq. 6) or ``"central"`` (Eq. 7).
    """

    body_names: tuple[str, ...]
    coordinate_names: tuple[str, ...]
    rotation: np.ndarray
    origin: np.ndarray
    origin_jacobian: np.ndarray
    angular_jacobian: np.ndarray
    com: np.ndarray
    com_jacobian: np.ndarray
    angular_velocity: np.ndarray
    com_velocity: np.ndarray
    angular_bias: np.ndarray
    com_bias: np.ndarray
    angular_acceleration: np.ndarray
    com_acceleration: np.ndarray
    bias_method: str

    @property
    def n_frames(self) -> int:
        return int(self.origin.shape[0])


class SpatialInverseDynamics:
    """Inverse dynamics of an OpenSim model in its generalized coordinates (module docstring).

    Parameters
    ----------
    model : OsimModel or Skeleton
        The model (:func:`biomech.osim.read_osim`), or its :class:`Skeleton` when one is built.
    bias : {"analytic", "central"}
        How J̇ q̇ is obtained: the recursion of Eq. (6) (exact) or the central difference Eq. (7).
    step : float
        δ of Eq. (7) [rad or m] (``bias="central"`` only).

    Raises
    ------
    core.errors.InputError
        Unknown ``bias`` or a step that is not a positive number.
    core.errors.ModelError
        From :class:`Skeleton` (the joint or body at fault named).

    Examples
    --------
    >>> from core.paths import data_path
    >>> from biomech.osim import read_osim
    >>> sid = SpatialInverseDynamics(read_osim(data_path("biomech", "opensim",
    ...                                          "gait10dof18musc_subject01_walk", "subject01.osim")))
    >>> tau = sid.generalized_forces(sid.skeleton.default_coordinates, 0.0, 0.0)
    >>> tau.shape        # one frame, ten coordinates: the moments that hold the default pose
    (1, 10)
    """

    def __init__(self, model, *, bias: str = "analytic", step: float = CENTRAL_STEP):
        self.skeleton = model if isinstance(model, Skeleton) else Skeleton(model)
        if bias not in BIAS_METHODS:
            raise InputError(f"bias must be one of {BIAS_METHODS}, got {bias!r}")
        if not (isinstance(step, (int, float)) and np.isfinite(step) and step > 0):
            raise InputError(f"step must be a positive number [rad or m], got {step!r}")
        self.bias = bias
        self.step = float(step)
        osim = self.skeleton.model
        self.model = osim
        self.gravity = np.asarray(osim.gravity, float)
        bodies = {b.name: b for b in osim.bodies}
        names = self.skeleton.body_names
        self.mass = np.array([bodies[n].mass for n in names], float)                     # (nb,)
        self.mass_center = np.array([bodies[n].mass_center for n in names], float)       # (nb, 3)
        self.inertia = np.array([bodies[n].inertia for n in names], float)               # (nb, 3, 3)
        self.coordinate_names = self.skeleton.coordinate_names
        self.body_names = names
        self.ignored_constraints = tuple(c.name for c in osim.constraints)

    # ---- inputs ------------------------------------------------------------------------------
    def _rates(self, value, shape, label) -> np.ndarray:
        if isinstance(value, pd.DataFrame):
            missing = [c for c in self.coordinate_names if c not in value.columns]
            if missing:
                raise InputError(f"{value.attrs.get('source', label)}: {label} lacks the coordinates {missing} of "
                                 f"model {self.model.name!r}")
            value = value[list(self.coordinate_names)].to_numpy(float)
        a = np.asarray(value, float)
        if a.ndim <= 1:
            a = np.broadcast_to(a, shape)
        if a.shape != shape:
            raise InputError(f"{label} must have shape {shape} (frames, coordinates "
                             f"{', '.join(self.coordinate_names)}), got {np.shape(value)}")
        bad = ~np.isfinite(a)
        if np.any(bad):
            f, c = np.argwhere(bad)[0]
            raise InputError(f"{label}: coordinate {self.coordinate_names[c]!r} is {a[f, c]} in frame {f}")
        return np.ascontiguousarray(a)

    # ---- kinematics --------------------------------------------------------------------------
    def _com_jacobian(self, fk):
        rho = np.einsum("nbij,bj->nbi", fk.rotation, self.mass_center)
        Jc = fk.origin_jacobian + _cross_columns(rho, fk.angular_jacobian)
        return rho, Jc

    def body_motion(self, q, qdot, qddot) -> BodyMotion:
        """Velocities and accelerations of every body (Eqs. 2, 3 and 6 or 7).

        Parameters
        ----------
        q : array_like, Mapping or DataFrame
            Coordinates (see :meth:`Skeleton.coordinate_array`), SI units.
        qdot, qddot : array_like or DataFrame, shape (n_frames, n_coordinates) or (n_coordinates,)
            Coordinate rates [rad/s, m/s] and accelerations [rad/s², m/s²]; a scalar broadcasts.

        Returns
        -------
        BodyMotion
        """
        sk = self.skeleton
        qq, _ = sk.coordinate_array(q)
        qd = self._rates(qdot, qq.shape, "qdot")
        qdd = self._rates(qddot, qq.shape, "qddot")
        fk = sk.forward_kinematics(qq, jacobians=True)
        rho, Jc = self._com_jacobian(fk)
        Jw = fk.angular_jacobian
        w = np.einsum("nbij,nj->nbi", Jw, qd)
        vc = np.einsum("nbij,nj->nbi", Jc, qd)
        if self.bias == "analytic":
            alpha_b, a_origin_b = self._bias_recursion(qq, qd, fk.rotation, fk.origin)
            ac_b = a_origin_b + np.cross(alpha_b, rho) + np.cross(w, np.cross(w, rho))
        else:
            alpha_b, ac_b = self._bias_central(qq, qd)
        alpha = np.einsum("nbij,nj->nbi", Jw, qdd) + alpha_b
        ac = np.einsum("nbij,nj->nbi", Jc, qdd) + ac_b
        return BodyMotion(self.body_names, self.coordinate_names, fk.rotation, fk.origin, fk.origin_jacobian, Jw,
                          fk.origin + rho, Jc, w, vc, alpha_b, ac_b, alpha, ac, self.bias)

    def _bias_recursion(self, q, qd, R_b, x_b):
        """Eqs. (5)–(6): α̂ and â of every body origin (q̈ = 0), shapes (n, nb, 3)."""
        sk = self.skeleton
        n = q.shape[0]
        nf = sk.n_bodies + 1
        R = np.empty((n, nf, 3, 3))
        x = np.empty((n, nf, 3))
        R[:, 0] = np.eye(3)
        x[:, 0] = 0.0
        R[:, 1:] = R_b
        x[:, 1:] = x_b
        w = np.zeros((n, nf, 3))
        al = np.zeros((n, nf, 3))
        a = np.zeros((n, nf, 3))
        zero = np.zeros(n)
        # the compiled joint table of the Skeleton, parents before children (see skeleton.py)
        for j in sk._joints:
            P, C = j.parent, j.child
            val, rate, quad = [], [], []
            for i in range(6):
                c = j.coords[i]
                fn = j.functions[i]
                if c < 0:
                    val.append(np.full(n, float(fn.value(0.0))))
                    rate.append(zero)
                    quad.append(zero)
                else:
                    xc = q[:, c]
                    vc = qd[:, c]
                    val.append(fn.value(xc))
                    rate.append(fn.first_derivative(xc) * vc)
                    quad.append(fn.second_derivative(xc) * vc * vc)
            R1 = axis_rotation(j.axes[0], val[0])
            R2 = axis_rotation(j.axes[1], val[1])
            w1 = np.broadcast_to(j.axes[0], (n, 3))
            w2 = R1 @ j.axes[1]
            w3 = (R1 @ R2) @ j.axes[2]
            t1, t2, t3 = rate[0][:, None], rate[1][:, None], rate[2][:, None]
            om_FM = t1 * w1 + t2 * w2 + t3 * w3
            al_FM = (quad[0][:, None] * w1 + quad[1][:, None] * w2 + quad[2][:, None] * w3
                     + t1 * t2 * np.cross(w1, w2) + np.cross(t1 * w1 + t2 * w2, t3 * w3))
            pd_FM = rate[3][:, None] * j.axes[3] + rate[4][:, None] * j.axes[4] + rate[5][:, None] * j.axes[5]
            pq_FM = quad[3][:, None] * j.axes[3] + quad[4][:, None] * j.axes[4] + quad[5][:, None] * j.axes[5]
            R_GF = R[:, P] @ j.R_PF
            om = np.einsum("nij,nj->ni", R_GF, om_FM)
            x_M = x[:, C] + np.einsum("nij,j->ni", R[:, C], j.p_CM)
            r = x_M - x[:, P]
            d = x[:, C] - x_M
            wP, alP = w[:, P], al[:, P]
            w[:, C] = wP + om
            al[:, C] = alP + np.cross(wP, om) + np.einsum("nij,nj->ni", R_GF, al_FM)
            a_M = (a[:, P] + np.cross(alP, r) + np.cross(wP, np.cross(wP, r))
                   + 2.0 * np.cross(wP, np.einsum("nij,nj->ni", R_GF, pd_FM)) + np.einsum("nij,nj->ni", R_GF, pq_FM))
            wC = w[:, C]
            a[:, C] = a_M + np.cross(al[:, C], d) + np.cross(wC, np.cross(wC, d))
        return al[:, 1:], a[:, 1:]

    def _bias_central(self, q, qd):
        """Eq. (7): J̇_ω q̇ and J̇_c q̇ by central differences of the Jacobians along q̇."""
        sk = self.skeleton
        speed = np.max(np.abs(qd), axis=1)
        h = np.where(speed > 0, self.step / np.where(speed > 0, speed, 1.0), 1.0)          # (n,)
        fp = sk.forward_kinematics(q + h[:, None] * qd, jacobians=True)
        fm = sk.forward_kinematics(q - h[:, None] * qd, jacobians=True)
        _, Jc_p = self._com_jacobian(fp)
        _, Jc_m = self._com_jacobian(fm)
        scale = (1.0 / (2.0 * h))[:, None, None, None]
        dJw = (fp.angular_jacobian - fm.angular_jacobian) * scale
        dJc = (Jc_p - Jc_m) * scale
        return np.einsum("nbij,nj->nbi", dJw, qd), np.einsum("nbij,nj->nbi", dJc, qd)

    # ---- dynamics ----------------------------------------------------------------------------
    def inertial_forces(self, motion: BodyMotion) -> np.ndarray:
        """First sum of Eq. (1): Σ J_cᵀ m (a − g) + J_ωᵀ (I α + ω × I ω), shape (n_frames, n_coordinates)."""
        R = motion.rotation
        I_G = R @ self.inertia[None] @ np.swapaxes(R, -1, -2)                             # Eq. (3)
        w, al = motion.angular_velocity, motion.angular_acceleration
        Iw = np.einsum("nbij,nbj->nbi", I_G, w)
        moment = np.einsum("nbij,nbj->nbi", I_G, al) + np.cross(w, Iw)
        force = self.mass[None, :, None] * (motion.com_acceleration - self.gravity)
        return (np.einsum("nbij,nbi->nj", motion.com_jacobian, force)
                + np.einsum("nbij,nbi->nj", motion.angular_jacobian, moment))

    def mass_matrix(self, q) -> np.ndarray:
        r"""M(q) = Σ_b J_c,bᵀ m_b J_c,b + J_ω,bᵀ I_b J_ω,b, shape (n_frames, n_coordinates, n_coordinates).

        The q̈-linear part of Eq. (1): τ(q, q̇, q̈) = M(q) q̈ + τ(q, q̇, 0).
        """
        qq, _ = self.skeleton.coordinate_array(q)
        fk = self.skeleton.forward_kinematics(qq, jacobians=True)
        _, Jc = self._com_jacobian(fk)
        R = fk.rotation
        I_G = R @ self.inertia[None] @ np.swapaxes(R, -1, -2)
        Jw = fk.angular_jacobian
        return (np.einsum("nbik,b,nbil->nkl", Jc, self.mass, Jc)
                + np.einsum("nbik,nbij,nbjl->nkl", Jw, I_G, Jw))

    def _frame_pose(self, body: str, motion: BodyMotion, what: str, force_name: str, source: str):
        if body == self.skeleton.ground:
            return None
        try:
            b = self.body_names.index(body)
        except ValueError:
            raise ModelError(f"external force {force_name!r} ({source}): {what} {body!r} is not a body of model "
                             f"{self.model.name!r} (bodies: {', '.join(self.body_names)})") from None
        return b

    def external_forces(self, motion: BodyMotion, loads) -> np.ndarray:
        """Second sum of Eq. (1): Σ J_Pᵀ F + J_ωᵀ T of the external loads, shape (n_frames, n_coordinates).

        Parameters
        ----------
        motion : BodyMotion
        loads : biomech.storage.ExternalLoads
            Sampled at the frames of ``motion`` (:func:`biomech.storage.resample_external_loads`).

        Raises
        ------
        core.errors.InputError
            Loads sampled at a different number of frames (the data file named).
        core.errors.ModelError
            A force on, or expressed in, a body the model lacks (force and file named).
        """
        n = motion.n_frames
        Q = np.zeros((n, len(self.coordinate_names)))
        if loads is None:
            return Q
        src = getattr(loads, "source", "external loads")
        if len(loads.time) != n:
            raise InputError(f"external loads {src}: sampled at {len(loads.time)} times, the motion has {n} frames; "
                             f"resample them onto the kinematics' times (biomech.storage.resample_external_loads)")
        for f in loads.forces:
            sp = f.spec
            if not sp.applies_force:
                continue
            b = self._frame_pose(sp.applied_to_body, motion, "applied_to_body", sp.name, src)
            if b is None:
                raise ModelError(f"external force {sp.name!r} ({src}) is applied to ground; it must act on a body")
            bf = self._frame_pose(sp.force_expressed_in_body, motion, "force_expressed_in_body", sp.name, src)
            bp = self._frame_pose(sp.point_expressed_in_body, motion, "point_expressed_in_body", sp.name, src)
            F = np.asarray(f.force, float)
            if bf is not None:
                F = np.einsum("nij,nj->ni", motion.rotation[:, bf], F)
            x_b = motion.origin[:, b]
            if f.point is None:
                P = x_b                                           # OpenSim: the body origin
            else:
                P = np.asarray(f.point, float)
                if bp is not None:
                    P = motion.origin[:, bp] + np.einsum("nij,nj->ni", motion.rotation[:, bp], P)
            Jw = motion.angular_jacobian[:, b]
            J_P = motion.origin_jacobian[:, b] + _cross_columns(P - x_b, Jw)              # Eq. (4)
            Q += np.einsum("nij,ni->nj", J_P, F)
            if f.torque is not None:
                T = np.asarray(f.torque, float)
                if bf is not None:
                    T = np.einsum("nij,nj->ni", motion.rotation[:, bf], T)
                Q += np.einsum("nij,ni->nj", Jw, T)
        return Q

    def generalized_forces(self, q, qdot, qddot, loads=None) -> np.ndarray:
        """τ of Eq. (1), shape (n_frames, n_coordinates) [N m for rotations, N for translations]."""
        motion = self.body_motion(q, qdot, qddot)
        return self.inertial_forces(motion) - self.external_forces(motion, loads)

    def table(self, times, tau) -> pd.DataFrame:
        """τ as a table: ``time [s]`` then ``<coordinate>_moment [N m]`` / ``<coordinate>_force [N]``
        (OpenSim's names: ``_moment`` for a rotational coordinate, ``_force`` otherwise)."""
        cols = {"time [s]": np.asarray(times, float)}
        for c, coord in enumerate(self.model.coordinates):
            rot = coord.motion_type == "rotational"
            cols[f"{coord.name}_{'moment [N m]' if rot else 'force [N]'}"] = tau[:, c]
        return pd.DataFrame(cols)


def spatial_inverse_dynamics(trial, *, bias: str = "analytic", skeleton: Skeleton | None = None) -> pd.DataFrame:
    """Generalized forces of every coordinate over a trial (Eq. 1), any tree-structured model.

    Parameters
    ----------
    trial : biomech.inverse_dynamics.GaitTrial
        From :func:`biomech.inverse_dynamics.load_trial` (``order=3`` reproduces OpenSim's
        filter): ``trial.osim``, ``trial.kinematics.q/qdot/qddot`` (DataFrames with ``time`` and
        one column per coordinate, SI) and ``trial.loads`` resampled onto the same times (or None).
    bias : {"analytic", "central"}
        J̇ q̇ by Eq. (6) or Eq. (7).
    skeleton : Skeleton, optional
        A Skeleton of ``trial.osim`` already built (saves its compilation).

    Returns
    -------
    DataFrame
        ``time [s]`` and ``<coordinate>_moment [N m]`` / ``<coordinate>_force [N]`` in the model's
        coordinate order, as :func:`biomech.inverse_dynamics.inverse_dynamics`; ``attrs``:
        ``wall_time`` (total), ``wall_time_kinematics`` (poses, Jacobians, accelerations),
        ``wall_time_dynamics`` (Eq. 1), ``n_frames``, ``bias``, ``body_mass``,
        ``ignored_constraints`` and the trial's settings.
    """
    t0 = time.perf_counter()
    if skeleton is not None and skeleton.model is not trial.osim:
        raise InputError(f"skeleton was built from model {skeleton.model.name!r}, not from trial.osim "
                         f"({trial.osim.name!r})")
    sid = SpatialInverseDynamics(skeleton if skeleton is not None else trial.osim, bias=bias)
    K = trial.kinematics
    tcol = "time" if "time" in K.q.columns else next((c for c in K.q.columns if str(c).startswith("time")), None)
    if tcol is None:
        raise InputError("trial.kinematics.q has no time column")
    times = K.q[tcol].to_numpy(float)
    q = K.q.drop(columns=[tcol])
    for label, df in (("qdot", K.qdot), ("qddot", K.qddot)):
        if len(df) != len(times):
            raise InputError(f"trial.kinematics.{label} has {len(df)} rows, q has {len(times)}")
    t1 = time.perf_counter()
    motion = sid.body_motion(q, K.qdot, K.qddot)
    t2 = time.perf_counter()
    loads = getattr(trial, "loads", None)
    if loads is not None and not np.allclose(np.asarray(loads.time, float), times, rtol=0.0, atol=1e-9):
        raise InputError(f"external loads {loads.source}: not sampled at the kinematics' times; resample them "
                         "(biomech.storage.resample_external_loads)")
    tau = sid.inertial_forces(motion) - sid.external_forces(motion, loads)
    t3 = time.perf_counter()
    out = sid.table(times, tau)
    settings = dict(getattr(trial, "settings", {}) or {})
    out.attrs.update(wall_time=t3 - t0, wall_time_setup=t1 - t0, wall_time_kinematics=t2 - t1,
                     wall_time_dynamics=t3 - t2, n_frames=len(times), bias=bias,
                     body_mass=float(np.sum(sid.mass)), ignored_constraints=sid.ignored_constraints, **settings)
    return out
