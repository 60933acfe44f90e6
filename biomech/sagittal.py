r"""A sagittal-plane OpenSim model as a Cartesian core model driven by measured joint angles.

The paper's method (Silva & Ambrósio 2003): every segment is a rigid body with absolute
coordinates, every anatomical joint a set of constraint equations, and the measured joint
angles enter as *driving* constraints, so that the mechanism has no degree of freedom left and
inverse dynamics is core's (:func:`core.analysis.inverse_dynamics`): the Lagrange multipliers of
the driving constraints are the joint moments.

Which models
------------
Planar OpenSim models whose joints move in the x–y plane of ground (gait10dof18musc: pelvis
tilt, tx, ty; hips, knees and ankles in flexion; lumbar extension): every rotation axis of a
joint is ±z, every translation axis lies in the x–y plane (a translation along z with a
constant value is an out-of-plane offset and is dropped), offset frames are rotated about z
only.  Anything else is refused naming the joint and the axis (:class:`core.errors.ModelError`):
use the spatial pipeline.  Out-of-plane offsets (hip joint centres at ±z, the pelvis
translation3 offset) do not enter the in-plane equations: every mobility of such a model is
in-plane, so the generalized forces of its coordinates see only in-plane force components and
moments about z (Euler's equation about z: I_zz θ̈; the products of inertia I_xz, I_yz load
only the constraints).

Bodies and joints
-----------------
Body b of the core model has coordinates (x_b, y_b, θ_b) of its *centre of mass*; a point with
OpenSim body-frame coordinates u (in-plane part) is at ``r_b + R(θ_b)(u − c_b)``, c_b the mass
centre in the body frame.  An OpenSim joint from parent P to child C has the frame F on P
(location l_P, angle β_P about z) and M on C (l_C, β_C); its spatial transform gives the
rotation φ(q) = Σ s_k f_k(q) of the rotation axes (s_k = ±1 the z-component of axis k) and the
translation t(q) = Σ a_k f_k(q) of the translation axes (a_k the in-plane part of axis k),
expressed in F (Simbody's function-based mobilizer, as OpenSim's ``CustomJoint`` uses it).
With the joint's coordinates prescribed, q = q_m(t), the joint is three equations

.. math::

    \Phi = \begin{bmatrix}
        r_C + R_C s_C - r_P - R_P s_P - R_F\, t(q_m(t)) \\
        \theta_C + \beta_C - \theta_P - \beta_P - \varphi(q_m(t))
    \end{bmatrix} = 0,
    \qquad s_b = l_b - c_b,\quad R_b = R(\theta_b),\quad R_F = R(\theta_P + \beta_P)

with the Jacobian ``[I, B_C s_C; −I, −B_P s_P − B_F t]`` and ``[0, 1; 0, −1]`` (B = dR/dθ), the
velocity right-hand side ``ν = [R_F t_q q̇_m; φ_q q̇_m]`` and, from Φ̈ = 0,

.. math::

    \gamma_{pos} = \dot\theta_C^2 R_C s_C - \dot\theta_P^2 R_P s_P - \dot\theta_P^2 R_F t
      + 2\dot\theta_P B_F t_q \dot q_m + R_F\,(t_{qq}[\dot q_m, \dot q_m] + t_q \ddot q_m),
    \qquad \gamma_{ang} = \varphi_{qq}[\dot q_m, \dot q_m] + \varphi_q \ddot q_m .

A weld joint (no coordinate) is the same with constant φ and t.

Joint moments from the multipliers
----------------------------------
Write the joint as Φ = g(x) − h(x, q) with h = [R_F t(q); φ(q)] and treat q as a massless
coordinate held by the actuator force τ: Lagrange's equation for q gives 0 = τ − (∂Φ/∂q)ᵀ λ,
so the generalized force of the joint's coordinates is

.. math::  \tau = -\left(\frac{\partial h}{\partial q}\right)^T \lambda ,

the OpenSim inverse-dynamics quantity (``<coordinate>_moment`` [N m] for a rotation,
``<coordinate>_force`` [N] for a translation: at the pelvis these are the residual forces and
moment).  For a pin joint it is minus the multiplier of the angle row, core's "driver effort".

Ground reaction forces
----------------------
Each external force acts on its body (the calcaneus) at the centre of pressure p(t), a point
moving over the foot.  It enters the core model as an :class:`core.forces.AppliedForce` F(t) at
the body's centre of mass and an :class:`core.forces.AppliedTorque`
``M(t) = ((p(t) − r_b(t)) × F(t))_z + T_z(t)`` whose arm uses the body's centre r_b(t) along
the prescribed motion (forward kinematics of the measured coordinates, below), tabulated at the
frames: exact at the frames, where inverse dynamics is evaluated.

References
----------
Silva, M. P. T. and Ambrósio, J. A. C. (2003). Solution of redundant muscle forces in human
locomotion with multibody dynamics and optimization tools. Mech. Based Des. Struct. Mach.
31(3):381–411.  Nikravesh, P. E. (1988). Computer-Aided Analysis of Mechanical Systems, ch. 5
(planar absolute coordinates, B = dR/dθ).  Seth, A. et al. (2011). Minimal formulation of joint
motion for biomechanisms. Nonlinear Dyn. 62:291–303 (OpenSim's CustomJoint).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from core.errors import InputError, ModelError
from core.joints import UserConstraint

__all__ = ["SagittalModel", "build_sagittal_model", "planar_forward_kinematics"]

GROUND = "ground"


def _R(a):
    """Planar rotation matrices, shape (..., 2, 2)."""
    if np.ndim(a) == 0:
        c, s = np.cos(a), np.sin(a)
        return np.array([[c, -s], [s, c]])
    c, s = np.cos(a), np.sin(a)
    return np.stack([np.stack([c, -s], -1), np.stack([s, c], -1)], -2)


def _B(a):
    """dR/dθ, shape (..., 2, 2)."""
    if np.ndim(a) == 0:
        c, s = np.cos(a), np.sin(a)
        return np.array([[-s, -c], [c, -s]])
    c, s = np.cos(a), np.sin(a)
    return np.stack([np.stack([-s, -c], -1), np.stack([c, -s], -1)], -2)


@dataclass(frozen=True)
class _PlanarJoint:
    """One OpenSim joint reduced to the plane (see the module docstring)."""

    name: str
    parent: str
    child: str
    l_parent: np.ndarray  # (2,) F origin in the parent's OpenSim body frame
    beta_parent: float
    l_child: np.ndarray
    beta_child: float
    coordinates: tuple[str, ...]
    rot: tuple  # ((sign, coordinate index or -1, function), ...)
    trans: tuple  # ((axis (2,), coordinate index or -1, function), ...)

    def phi(self, q, order=0):
        """φ(q) (order 0), ∂φ/∂q_j (order 1, shape (n,)), ∂²φ/∂q_j² (order 2, diagonal)."""
        n = len(self.coordinates)
        out = 0.0 if order == 0 else np.zeros(n)
        for sign, j, f in self.rot:
            if order == 0:
                out = out + sign * float(f.value(q[j] if j >= 0 else 0.0))
            elif j >= 0:
                out[j] += sign * float(f.derivative(q[j], order))
        return out

    def terms(self, q):
        """φ, ∂φ/∂q, ∂²φ/∂q², t, ∂t/∂q, ∂²t/∂q² for many frames at once: ``q`` (n_f, n) the
        joint's coordinates; shapes (n_f,), (n_f, n), (n_f, n), (n_f, 2), (n_f, 2, n), (n_f, 2, n)
        (the second derivatives are diagonal: each axis is a function of one coordinate)."""
        nf, n = q.shape[0], len(self.coordinates)
        ph, ph1, ph2 = np.zeros(nf), np.zeros((nf, n)), np.zeros((nf, n))
        tt, t1, t2 = np.zeros((nf, 2)), np.zeros((nf, 2, n)), np.zeros((nf, 2, n))
        for sign, j, f in self.rot:
            if j < 0:
                ph += sign * float(f.value(0.0))
                continue
            x = q[:, j]
            ph += sign * f.value(x)
            ph1[:, j] += sign * f.derivative(x, 1)
            ph2[:, j] += sign * f.derivative(x, 2)
        for a, j, f in self.trans:
            if j < 0:
                tt += a * float(f.value(0.0))
                continue
            x = q[:, j]
            tt += np.outer(f.value(x), a)
            t1[:, :, j] += np.outer(f.derivative(x, 1), a)
            t2[:, :, j] += np.outer(f.derivative(x, 2), a)
        return ph, ph1, ph2, tt, t1, t2

    def t(self, q, order=0):
        """t(q) (2,); order 1: ∂t/∂q_j as (2, n); order 2: ∂²t/∂q_j² as (2, n)."""
        n = len(self.coordinates)
        out = np.zeros(2) if order == 0 else np.zeros((2, n))
        for a, j, f in self.trans:
            if order == 0:
                out = out + a * float(f.value(q[j] if j >= 0 else 0.0))
            elif j >= 0:
                out[:, j] += a * float(f.derivative(q[j], order))
        return out


def _planar_joints(osim):
    """The model's joints in the plane; ModelError for anything out of plane."""
    out = []
    for jt in osim.joints:
        where = f"{osim.path or osim.name}: joint {jt.name!r}"
        for fr, side in ((jt.parent_frame, "parent"), (jt.child_frame, "child")):
            o = np.asarray(fr.orientation, float)
            if abs(o[0]) > 1e-12 or abs(o[1]) > 1e-12:
                raise ModelError(f"{where}: the {side} offset frame is rotated about x or y ({o.tolist()} rad); "
                                 "not a sagittal-plane model (use the spatial pipeline)")
        coords = tuple(jt.coordinates)
        rot, trans = [], []
        for ax in jt.transform_axes:
            a = np.asarray(ax.axis, float)
            j = coords.index(ax.coordinates[0]) if ax.coordinates else -1
            if len(ax.coordinates) > 1:
                raise ModelError(f"{where}: axis {ax.name} is a function of several coordinates; not supported")
            constant = j < 0
            if ax.is_rotation:
                if constant and float(ax.function.value(0.0)) == 0.0:
                    continue
                if abs(abs(a[2]) - 1.0) > 1e-9:
                    raise ModelError(f"{where}: rotation axis {ax.name} = {a.tolist()} is not the z axis; "
                                     "not a sagittal-plane model (use the spatial pipeline)")
                rot.append((float(np.sign(a[2])), j, ax.function))
            else:
                if constant and float(ax.function.value(0.0)) == 0.0:
                    continue
                if abs(a[2]) > 1e-9:
                    if constant:  # an out-of-plane offset: does not enter the in-plane equations
                        continue
                    raise ModelError(f"{where}: translation axis {ax.name} = {a.tolist()} moves out of the "
                                     "x-y plane; not a sagittal-plane model (use the spatial pipeline)")
                trans.append((a[:2].copy(), j, ax.function))
        out.append(_PlanarJoint(jt.name, jt.parent_body, jt.child_body,
                                np.asarray(jt.parent_frame.location, float)[:2].copy(),
                                float(jt.parent_frame.orientation[2]),
                                np.asarray(jt.child_frame.location, float)[:2].copy(),
                                float(jt.child_frame.orientation[2]), coords, tuple(rot), tuple(trans)))
    return out


def planar_forward_kinematics(osim, coordinates):
    """Body-frame origins, angles and centres of mass for coordinate values (no core involved).

    Parameters
    ----------
    osim : biomech.osim.OsimModel
    coordinates : dict of str to float or (n,) arrays
        Values of the model's coordinates [rad, m]; missing ones take their default.

    Returns
    -------
    dict of str to (origin (n, 2), angle (n,), centre of mass (n, 2))
        Per body, in ground (x forward, y up).
    """
    joints = _planar_joints(osim)
    qv = {c.name: np.atleast_1d(np.asarray(coordinates.get(c.name, c.default_value), float))
          for c in osim.coordinates}
    n = max(len(v) for v in qv.values()) if qv else 1
    pose = {GROUND: (np.zeros((n, 2)), np.zeros(n))}
    remaining = list(joints)
    while remaining:
        progressed = False
        for jt in list(remaining):
            if jt.parent not in pose:
                continue
            oP, thP = pose[jt.parent]
            thF = thP + jt.beta_parent
            oF = oP + np.einsum("nij,j->ni", _R(thP), jt.l_parent)
            qj = np.column_stack([np.broadcast_to(qv[c], (n,)) for c in jt.coordinates]) if jt.coordinates \
                else np.zeros((n, 0))
            phi, _, _, tt, _, _ = jt.terms(qj)
            thM = thF + phi
            oM = oF + np.einsum("nij,nj->ni", _R(thF), tt)
            thC = thM - jt.beta_child
            oC = oM - np.einsum("nij,j->ni", _R(thC), jt.l_child)
            pose[jt.child] = (oC, thC)
            remaining.remove(jt)
            progressed = True
        if not progressed:
            raise ModelError(f"{osim.path or osim.name}: joints {[j.name for j in remaining]} are not connected to ground")
    out = {}
    for b in osim.bodies:
        o, th = pose[b.name]
        c = np.asarray(b.mass_center, float)[:2]
        out[b.name] = (o, th, o + np.einsum("nij,j->ni", _R(th), c))
    return out


class _DrivenPlanarJoint(UserConstraint):
    """Φ of one joint with its coordinates prescribed (module docstring, Bodies and joints)."""

    def __init__(self, jt: _PlanarJoint, motion, c_parent, c_child):
        self.name = jt.name
        self.rows = 3
        self.jt = jt
        self.bodies = tuple(b for b in (jt.parent, jt.child))
        self.body_i, self.body_j = jt.parent, jt.child
        self.at = None
        self.coordinates = ()
        self.motion = motion  # callable t -> (q, qd, qdd) of the joint's coordinates
        self.s_parent = jt.l_parent - np.asarray(c_parent, float)
        self.s_child = jt.l_child - np.asarray(c_child, float)
        self.ground_parent = jt.parent == GROUND
        self._t_cached, self._cached = None, None

    # coordinates of the two bodies (the ground has none)
    def _poses(self, q, v=None):
        qi = q[self.q_index]
        if self.ground_parent:
            rP, thP, rC, thC = np.zeros(2), 0.0, qi[0:2], qi[2]
        else:
            rP, thP, rC, thC = qi[0:2], qi[2], qi[3:5], qi[5]
        if v is None:
            return rP, thP, rC, thC
        vi = v[self.v_index]
        wP, wC = (0.0, vi[2]) if self.ground_parent else (vi[2], vi[5])
        return rP, thP, rC, thC, wP, wC

    def _q(self, t):
        """(q, q̇, q̈, φ, φ_q, φ_qq, t, t_q, t_qq) of the joint at time t, cached per time (Φ,
        Φ_q, ν and γ at one time share them)."""
        if t != self._t_cached:
            jt = self.jt
            if jt.coordinates:
                qm, qd, qdd = self.motion(t)
            else:
                qm = qd = qdd = np.zeros(0)
            self._cached = (qm, qd, qdd, jt.phi(qm), jt.phi(qm, 1), jt.phi(qm, 2), jt.t(qm), jt.t(qm, 1), jt.t(qm, 2))
            self._t_cached = t
        return self._cached

    def phi(self, t, q):
        rP, thP, rC, thC = self._poses(q)
        _, _, _, ph, _, _, tq, _, _ = self._q(t)
        jt = self.jt
        thF = thP + jt.beta_parent
        pos = rC + _R(thC) @ self.s_child - rP - _R(thP) @ self.s_parent - _R(thF) @ tq
        ang = thC + jt.beta_child - thP - jt.beta_parent - ph
        return np.array([pos[0], pos[1], ang])

    def jacobian(self, t, q):
        rP, thP, rC, thC = self._poses(q)
        tq = self._q(t)[6]
        jt = self.jt
        thF = thP + jt.beta_parent
        JC = np.zeros((3, 3))
        JC[:2, :2] = np.eye(2)
        JC[:2, 2] = _B(thC) @ self.s_child
        JC[2, 2] = 1.0
        if self.ground_parent:
            return JC
        JP = np.zeros((3, 3))
        JP[:2, :2] = -np.eye(2)
        JP[:2, 2] = -_B(thP) @ self.s_parent - _B(thF) @ tq
        JP[2, 2] = -1.0
        return np.hstack([JP, JC])

    def nu(self, t, q):
        rP, thP, rC, thC = self._poses(q)
        qm, qd, _, _, ph1, _, _, t1, _ = self._q(t)
        jt = self.jt
        if not jt.coordinates:
            return np.zeros(3)
        RF = _R(thP + jt.beta_parent)
        return np.concatenate([RF @ (t1 @ qd), [ph1 @ qd]])

    def gamma(self, t, q, v):
        rP, thP, rC, thC, wP, wC = self._poses(q, v)
        qm, qd, qdd, _, ph1, ph2, tq, t1, t2 = self._q(t)
        jt = self.jt
        thF = thP + jt.beta_parent
        RF, BF = _R(thF), _B(thF)
        g = wC**2 * (_R(thC) @ self.s_child) - wP**2 * (_R(thP) @ self.s_parent) - wP**2 * (RF @ tq)
        ga = 0.0
        if jt.coordinates:
            g = g + 2.0 * wP * (BF @ (t1 @ qd)) + RF @ (t2 @ (qd * qd) + t1 @ qdd)
            ga = ph2 @ (qd * qd) + ph1 @ qdd
        return np.array([g[0], g[1], ga])

    def generalized_forces(self, q, t, lam):
        """τ = −(∂h/∂q)ᵀ λ for the joint's coordinates (module docstring)."""
        if not self.jt.coordinates:
            return np.zeros(0)
        rP, thP, rC, thC = self._poses(q)
        _, _, _, _, ph1, _, _, t1, _ = self._q(t)
        RF = _R(thP + self.jt.beta_parent)
        dh = np.vstack([RF @ t1, ph1[None, :]])  # (3, n)
        return -dh.T @ lam


class _DrivenPlanarJoints(UserConstraint):
    """All joints of the model as one constraint kind (3 rows per joint, vectorised over joints).

    The same equations as :class:`_DrivenPlanarJoint` (module docstring), evaluated for every
    joint and every frame in one numpy call (a Python constraint per joint costs its call overhead
    in every Newton iteration of core's kinematic analysis); one time is one frame.  The functions
    of the coordinates are evaluated once per array of times.
    """

    name = "driven joints"

    def __init__(self, joints, body_names):
        self.joints = list(joints)
        self.bodies = tuple(body_names)
        self.coordinates = ()
        self.rows = 3 * len(self.joints)
        self.body_i = self.body_j = GROUND
        self.at = None
        index = {b: k for k, b in enumerate(self.bodies)}
        self.P = np.array([index.get(j.jt.parent, -1) for j in self.joints])
        self.C = np.array([index[j.jt.child] for j in self.joints])
        self.sP = np.array([j.s_parent for j in self.joints])
        self.sC = np.array([j.s_child for j in self.joints])
        self.bP = np.array([j.jt.beta_parent for j in self.joints])
        self.bC = np.array([j.jt.beta_child for j in self.joints])
        self.has_parent = self.P >= 0
        self._tf = None  # (times, terms) of _time_terms_frames

    @staticmethod
    def _rot(th, u):
        """R(θ) u for arrays of angles (...) and vectors (..., 2)."""
        c, s = np.cos(th), np.sin(th)
        return np.stack([c * u[..., 0] - s * u[..., 1], s * u[..., 0] + c * u[..., 1]], axis=-1)

    @staticmethod
    def _drot(th, u):
        """B(θ) u = dR/dθ u, shapes as :meth:`_rot`."""
        c, s = np.cos(th), np.sin(th)
        return np.stack([-s * u[..., 0] - c * u[..., 1], c * u[..., 0] - s * u[..., 1]], axis=-1)

    # --- all frames at once (core.model.Model.constraint_terms_frames) --------------------------
    def _time_terms_frames(self, t):
        """Per frame and joint: φ, t(q), R_F-free parts of ν and γ (module docstring), shapes
        (n_f, n_j), (n_f, n_j, 2), (n_f, n_j, 2), (n_f, n_j), (n_f, n_j, 2), (n_f, n_j); kept
        for the last array of times (Newton's iterations and ν, γ share them)."""
        if self._tf is not None and len(self._tf[0]) == len(t) and np.array_equal(self._tf[0], t):
            return self._tf[1]
        nf, n = len(t), len(self.joints)
        PH, TQ, V1, W1 = np.zeros((nf, n)), np.zeros((nf, n, 2)), np.zeros((nf, n, 2)), np.zeros((nf, n))
        A2, G2 = np.zeros((nf, n, 2)), np.zeros((nf, n))
        for k, j in enumerate(self.joints):
            if not j.jt.coordinates:
                ph, _, _, tq, _, _ = j.jt.terms(np.zeros((nf, 0)))
                PH[:, k], TQ[:, k] = ph, tq
                continue
            qm, qd, qdd = j.motion(t)
            ph, ph1, ph2, tq, t1, t2 = j.jt.terms(qm)
            PH[:, k], TQ[:, k] = ph, tq
            V1[:, k], W1[:, k] = np.einsum("fin,fn->fi", t1, qd), np.sum(ph1 * qd, axis=1)
            A2[:, k] = np.einsum("fin,fn->fi", t2, qd * qd) + np.einsum("fin,fn->fi", t1, qdd)
            G2[:, k] = np.sum(ph2 * qd * qd, axis=1) + np.sum(ph1 * qdd, axis=1)
        out = (PH, TQ, V1, W1, A2, G2)
        self._tf = (np.array(t, float), out)
        return out

    def _poses_frames(self, q, v=None):
        nf = q.shape[0]
        x = q[:, self.q_index].reshape(nf, -1, 3)
        hp = self.has_parent
        Pi = np.where(hp, self.P, 0)
        rP = np.where(hp[None, :, None], x[:, Pi, :2], 0.0)
        thP = np.where(hp[None, :], x[:, Pi, 2], 0.0)
        rC, thC = x[:, self.C, :2], x[:, self.C, 2]
        if v is None:
            return rP, thP, rC, thC
        w = v[:, self.v_index].reshape(nf, -1, 3)[:, :, 2]
        return rP, thP, rC, thC, np.where(hp[None, :], w[:, Pi], 0.0), w[:, self.C]

    def phi_frames(self, t, q):
        PH, TQ, *_ = self._time_terms_frames(t)
        rP, thP, rC, thC = self._poses_frames(q)
        thF = thP + self.bP
        pos = rC + self._rot(thC, self.sC) - rP - self._rot(thP, self.sP) - self._rot(thF, TQ)
        ang = thC + self.bC - thP - self.bP - PH
        return np.concatenate([pos, ang[:, :, None]], axis=2).reshape(len(t), -1)

    def jacobian_frames(self, t, q):
        PH, TQ, *_ = self._time_terms_frames(t)
        rP, thP, rC, thC = self._poses_frames(q)
        thF = thP + self.bP
        nf, n = len(t), len(self.joints)
        J = np.zeros((nf, 3 * n, 3 * len(self.bodies)))
        r0 = 3 * np.arange(n)
        c0 = 3 * self.C
        J[:, r0, c0] = 1.0
        J[:, r0 + 1, c0 + 1] = 1.0
        dC = self._drot(thC, self.sC)
        J[:, r0, c0 + 2] = dC[..., 0]
        J[:, r0 + 1, c0 + 2] = dC[..., 1]
        J[:, r0 + 2, c0 + 2] = 1.0
        k = np.nonzero(self.has_parent)[0]
        p0 = 3 * self.P[k]
        dP = -self._drot(thP[:, k], self.sP[k]) - self._drot(thF[:, k], TQ[:, k])
        J[:, r0[k], p0] = -1.0
        J[:, r0[k] + 1, p0 + 1] = -1.0
        J[:, r0[k], p0 + 2] = dP[..., 0]
        J[:, r0[k] + 1, p0 + 2] = dP[..., 1]
        J[:, r0[k] + 2, p0 + 2] = -1.0
        return J

    def nu_frames(self, t, q):
        _, _, V1, W1, _, _ = self._time_terms_frames(t)
        rP, thP, rC, thC = self._poses_frames(q)
        return np.concatenate([self._rot(thP + self.bP, V1), W1[:, :, None]], axis=2).reshape(len(t), -1)

    def gamma_frames(self, t, q, v):
        _, TQ, V1, _, A2, G2 = self._time_terms_frames(t)
        rP, thP, rC, thC, wP, wC = self._poses_frames(q, v)
        thF = thP + self.bP
        wP2, wC2 = (wP**2)[:, :, None], (wC**2)[:, :, None]
        g = (wC2 * self._rot(thC, self.sC) - wP2 * self._rot(thP, self.sP) - wP2 * self._rot(thF, TQ)
             + 2.0 * wP[:, :, None] * self._drot(thF, V1) + self._rot(thF, A2))
        return np.concatenate([g, G2[:, :, None]], axis=2).reshape(len(t), -1)

    # one time is one frame (the terms of a time stay cached for the Newton iterations, ν and γ
    # at that time)
    def phi(self, t, q):
        return self.phi_frames(np.array([float(t)]), np.asarray(q, float)[None, :])[0]

    def jacobian(self, t, q):
        return self.jacobian_frames(np.array([float(t)]), np.asarray(q, float)[None, :])[0]

    def nu(self, t, q):
        return self.nu_frames(np.array([float(t)]), np.asarray(q, float)[None, :])[0]

    def gamma(self, t, q, v):
        return self.gamma_frames(np.array([float(t)]), np.asarray(q, float)[None, :],
                                 np.asarray(v, float)[None, :])[0]


class SagittalModel:
    """A built core model of a sagittal OpenSim model with its coordinates driven.

    Attributes
    ----------
    model : core.model.Model
    osim : biomech.osim.OsimModel
    coordinates : list of str
        The driven coordinates, in the model file's order.
    joints : list of _DrivenPlanarJoint
        One per OpenSim joint, each bound to the model's coordinates of its two bodies; the model
        holds them as one vectorised constraint (:class:`_DrivenPlanarJoints`).
    rows : dict of str to (3,) int arrays
        The model's constraint rows of each joint (position x, y, angle).
    q_frames : ndarray, shape (n_frames, n_q)
        The model's Cartesian coordinates at the kinematics' frames from the forward kinematics of
        the measured coordinates (:func:`planar_forward_kinematics`): the guess per frame with
        which core's kinematic analysis solves all frames at once.
    """

    def __init__(self, model, osim, joints, coordinates, kinematics, q_frames=None):
        self.model, self.osim, self.joints, self.coordinates = model, osim, joints, coordinates
        self.kinematics = kinematics
        self.q_frames = q_frames
        all_rows = model.reaction_groups()[_DrivenPlanarJoints.name]
        if len(all_rows) != 3 * len(joints):
            raise ModelError(f"{osim.name}: dependent joint equations were removed at build; the driven "
                             "model must have independent constraints")
        self.rows = {uc.name: all_rows[3 * k:3 * k + 3] for k, uc in enumerate(joints)}
        for uc in joints:  # the per-joint objects evaluate on the model's coordinates
            blocks = [b for b in (uc.jt.parent, uc.jt.child) if b != GROUND]
            qi = np.concatenate([np.arange(model.n_q)[model.q_slice(b)] for b in blocks])
            vi = np.concatenate([np.arange(model.n_v)[model.v_slice(b)] for b in blocks])
            uc.bind(qi, vi, model.space)

    def generalized_forces(self, t, q, lam) -> pd.DataFrame:
        """OpenSim-named generalized forces per frame from core's multipliers.

        ``t`` (n,), ``q`` (n, n_q) Cartesian coordinates, ``lam`` (n, n_c) multipliers.
        Columns ``time [s]`` and ``<coordinate>_moment [N m]`` / ``<coordinate>_force [N]``.
        """
        t = np.atleast_1d(np.asarray(t, float))
        q, lam = np.atleast_2d(q), np.atleast_2d(lam)
        cols = {"time [s]": t}
        ctype = {c.name: c.motion_type for c in self.osim.coordinates}
        vals = {c: np.zeros(len(t)) for c in self.coordinates}
        for uc in self.joints:  # τ = −(∂h/∂q)ᵀ λ, every frame at once
            if not uc.jt.coordinates:
                continue
            lj = lam[:, self.rows[uc.name]]
            _, ph1, _, _, t1, _ = uc.jt.terms(uc.motion(t)[0])
            thF = uc.jt.beta_parent + (0.0 if uc.ground_parent else q[:, uc.q_index[2]])
            c, s_ = np.cos(thF), np.sin(thF)
            Ft = np.stack([c * lj[:, 0] + s_ * lj[:, 1], -s_ * lj[:, 0] + c * lj[:, 1]], axis=1)  # R_Fᵀ λ_pos
            tau = -(np.einsum("fin,fi->fn", t1, Ft) + ph1 * lj[:, 2:3])
            for k, name in enumerate(uc.jt.coordinates):
                vals[name] = tau[:, k]
        for c in self.coordinates:
            unit = "N m" if ctype[c] == "rotational" else "N"
            kind = "moment" if ctype[c] == "rotational" else "force"
            cols[f"{c}_{kind} [{unit}]"] = vals[c]
        return pd.DataFrame(cols)

    def joint_reactions(self, t, q, lam) -> pd.DataFrame:
        """Joint reaction forces per frame: the force the parent exerts on the child at the joint
        (the origin of the child's joint frame M), in ground axes.

        The constraint force on the child body is −Φ_qᵀλ over its block; the position rows have
        the identity there, so the force is −λ_pos, applied at the joint point (the angle row's
        multiplier is the moment, reported by :meth:`generalized_forces`).  Columns
        ``<joint>_on_<child>_Fx [N]``, ``_Fy [N]`` (OpenSim's JointReaction analysis reports the same
        force, child side, when expressed in ground).
        """
        cols = {"time [s]": np.asarray(t, float)}
        for uc in self.joints:
            rows = self.rows[uc.name]
            F = -np.asarray(lam)[:, rows[:2]]
            cols[f"{uc.name}_on_{uc.jt.child}_Fx [N]"] = F[:, 0]
            cols[f"{uc.name}_on_{uc.jt.child}_Fy [N]"] = F[:, 1]
        return pd.DataFrame(cols)


def build_sagittal_model(osim, kinematics, loads=None, name=None):
    """The core model of a sagittal OpenSim model with its coordinates driven by ``kinematics``.

    Parameters
    ----------
    osim : biomech.osim.OsimModel
    kinematics : biomech.kinematics.CoordinateKinematics
        Processed coordinates: ``q``, ``qdot``, ``qddot`` DataFrames with a ``time [s]`` column
        and one column per coordinate (SI).  Every coordinate of the model must be there.
    loads : biomech.storage.ExternalLoads, optional
        External forces (resampled onto the kinematics' times), applied as described in the
        module docstring.

    Returns
    -------
    SagittalModel
    """
    from scipy.interpolate import CubicSpline

    from core.drivers import tabulated
    from core.forces import AppliedForce, AppliedTorque
    from core.model import ModelBuilder

    Qd, Vd, Ad = kinematics.q, kinematics.qdot, kinematics.qddot
    tcol = _time_column(Qd)
    times = Qd[tcol].to_numpy(float)
    coords = [c.name for c in osim.coordinates]
    missing = [c for c in coords if _col(Qd, c) is None]
    if missing:
        raise InputError(f"{osim.path or osim.name}: the kinematics lack the coordinates {missing}")
    qmat = np.column_stack([Qd[_col(Qd, c)].to_numpy(float) for c in coords])
    vmat = np.column_stack([Vd[_col(Vd, c)].to_numpy(float) for c in coords])
    amat = np.column_stack([Ad[_col(Ad, c)].to_numpy(float) for c in coords])
    splines = [CubicSpline(times, m, axis=0) for m in (qmat, vmat, amat)]
    cindex = {c: k for k, c in enumerate(coords)}

    fk = planar_forward_kinematics(osim, {c: qmat[:, k] for k, c in enumerate(coords)})
    g = np.asarray(osim.gravity, float)
    if abs(g[2]) > 1e-12:
        raise ModelError(f"{osim.path or osim.name}: gravity {g.tolist()} has a z component; not a sagittal model")
    b = ModelBuilder(2, name or f"{osim.name} (sagittal, driven)", gravity=g[:2])
    for body in osim.bodies:
        _, th, com = fk[body.name]
        Izz = float(np.asarray(body.inertia, float)[2, 2])
        b.add_body(body.name, body.mass, Izz, com[0], float(th[0]))
    bodies = {body.name: body for body in osim.bodies}
    joints = []
    for jt in _planar_joints(osim):
        idx = np.array([cindex[c] for c in jt.coordinates], int)

        def motion(t, idx=idx):  # t a time, or an array of times: then (n_f, n) each
            return splines[0](t)[..., idx], splines[1](t)[..., idx], splines[2](t)[..., idx]

        cP = np.zeros(2) if jt.parent == GROUND else np.asarray(bodies[jt.parent].mass_center, float)[:2]
        cC = np.asarray(bodies[jt.child].mass_center, float)[:2]
        joints.append(_DrivenPlanarJoint(jt, motion, cP, cC))
    b.add_joint(_DrivenPlanarJoints(joints, [body.name for body in osim.bodies]))
    if loads is not None:
        if len(loads.time) != len(times) or not np.allclose(loads.time, times, rtol=0.0, atol=1e-9):
            raise InputError(f"external loads {loads.source}: sampled at {len(loads.time)} times, the kinematics at "
                             f"{len(times)}; resample them onto the kinematics' times first "
                             "(biomech.storage.resample_external_loads)")
        for f in loads.forces:
            sp = f.spec
            if not sp.applies_force:
                continue
            if sp.applied_to_body not in bodies:
                raise ModelError(f"external force {sp.name!r} ({loads.source}) acts on {sp.applied_to_body!r}, "
                                 f"which model {osim.name!r} lacks")
            for what, frame in (("force", sp.force_expressed_in_body), ("point", sp.point_expressed_in_body)):
                if frame != GROUND:
                    raise InputError(f"external force {sp.name!r} ({loads.source}): {what} expressed in {frame!r}; "
                                     "only 'ground' is supported")
            F = np.asarray(f.force, float)
            p = np.zeros_like(F) if f.point is None else np.asarray(f.point, float)
            T = np.zeros_like(F) if f.torque is None else np.asarray(f.torque, float)
            com = fk[sp.applied_to_body][2]
            arm = p[:, :2] - com
            Mz = arm[:, 0] * F[:, 1] - arm[:, 1] * F[:, 0] + T[:, 2]
            b.add_force(AppliedForce(sp.name, sp.applied_to_body, com[0],
                                     [tabulated(times, F[:, 0], label=f"{sp.name} Fx ({loads.source})"),
                                      tabulated(times, F[:, 1], label=f"{sp.name} Fy ({loads.source})")]))
            b.add_force(AppliedTorque(f"{sp.name} moment", sp.applied_to_body,
                                      tabulated(times, Mz, label=f"{sp.name} Mz ({loads.source})")))
    # bodies are placed at the first frame; velocities (and, for a window not starting at t = 0,
    # the positions at t = 0 where core checks the initial state) by core's assembly
    model = b.build(assemble=True)
    q_frames = np.concatenate([np.column_stack([fk[body.name][2], fk[body.name][1]]) for body in osim.bodies], axis=1)
    return SagittalModel(model, osim, joints, coords, kinematics, q_frames)


def _time_column(df):
    for c in df.columns:
        if str(c).split(" ")[0] == "time":
            return c
    raise InputError("kinematics table without a time column")


def _col(df, name):
    for c in df.columns:
        if c == name or str(c).split(" [")[0] == name:
            return c
    return None
