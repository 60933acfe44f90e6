r"""Kinematics of OpenSim models in generalized coordinates (biomech.skeleton).

Known values come from outside the module under test: the spline knots of the model file (read
here with ElementTree), closed-form rotations (scipy ``Rotation``), and a handful of numbers computed
by OpenSim 4.6 itself (pip package ``opensim`` 4.6, ``Body.getPositionInGround``,
``Muscle.getLength``, ``Muscle.computeMomentArm``, coordinates loaded from the ``.mot`` with
``SimbodyEngine.convertDegreesToRadians``).  Everything else is a property: orthonormality,
Jacobians and moment arms against central differences, virtual power, invariance under rigid
motion of the whole model, signs of anatomical moment arms.

Central-difference tolerances, derived
--------------------------------------
D_h f = (f(q + h e_j) − f(q − h e_j)) / (2h) differs from f'(q) by at most

    h²/6 · max|f'''|  (truncation)   +   k ε |f| / h  (rounding of f, k ≈ 10 operations),

with ε = 2.2e-16.  For path lengths and body positions, f''' is bounded by a geometric part G
(points within ~1 m of every joint axis: |d³/dθ³| of a distance or position is below ~1 m per rad³;
G = 10 m is taken for margin) plus the third derivatives of the SimmSplines the coordinate drives
(joint translations and moving path points), which are computed here from the splines' public
second derivatives at their knots (S''' is constant between knots).  The quadriceps insertions
(MovingPathPoints of the knee angle) have spline knots 1.7e-4 rad apart near 0, where |S'''|
reaches 3e4 m/rad³: that is why the bound is computed per muscle and coordinate, not fixed.
"""

from __future__ import annotations

import dataclasses
import xml.etree.ElementTree as ET

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from core.errors import InputError, ModelError
from core.paths import data_path
from biomech.functions import MultiplierFunction, SimmSpline
from biomech.osim import IgnoredItem, MovingPathPoint, read_osim
from biomech.skeleton import Skeleton, axis_rotation
from biomech.storage import read_storage

OPENSIM = data_path("biomech", "opensim")
G10_DIR = OPENSIM / "gait10dof18musc_subject01_walk"
G10 = G10_DIR / "subject01.osim"
G10_MOT = G10_DIR / "subject01_walk_IK.mot"
G2392 = OPENSIM / "gait2392_subject01_walk" / "subject01_simbody_adjusted.osim"
G2392_MOT = OPENSIM / "gait2392_subject01_walk" / "subject01_walk1_ik.mot"

EPS = np.finfo(float).eps
GEOMETRIC_BOUND = 10.0   # G [m per rad³], see the module docstring
ROUNDING_OPS = 10        # k

_cache: dict = {}


def skeleton(which: str) -> Skeleton:
    if which not in _cache:
        _cache[which] = Skeleton(read_osim(G10 if which == "g10" else G2392))
    return _cache[which]


def motion(which: str):
    key = which + "_mot"
    if key not in _cache:
        sk = skeleton(which)
        _cache[key] = read_storage(G10_MOT if which == "g10" else G2392_MOT, model=sk.model)
    return _cache[key]


# ---- tolerance helpers -------------------------------------------------------------------------


def spline_third_derivative_bound(fn) -> float:
    """max |f'''| of a SimmSpline (possibly scaled by MultiplierFunctions); 0 for other functions."""
    scale = 1.0
    while isinstance(fn, MultiplierFunction):
        scale *= fn.scale
        fn = fn.function
    if not isinstance(fn, SimmSpline) or fn.x.size < 3:
        return 0.0
    s2 = fn.second_derivative(fn.x)
    return abs(scale) * float(np.max(np.abs(np.diff(s2) / np.diff(fn.x))))


def joint_spline_bounds(sk: Skeleton) -> np.ndarray:
    """Σ over joint axes driven by each coordinate of max|f'''|, shape (n_coordinates,)."""
    out = np.zeros(sk.n_coordinates)
    for j in sk.model.joints:
        for ax in j.transform_axes:
            if ax.coordinates:
                out[sk.coordinate_index(ax.coordinates[0])] += spline_third_derivative_bound(ax.function)
    return out


def moment_arm_tolerance(sk: Skeleton, step: float, length_max: float) -> np.ndarray:
    """Per muscle and coordinate: h²/6 · (G + joint splines + moving-point splines) + k ε L / h."""
    b3 = np.tile(GEOMETRIC_BOUND + joint_spline_bounds(sk), (sk.n_muscles, 1))
    for m, mus in enumerate(sk.model.muscles):
        for pt in mus.path:
            if isinstance(pt, MovingPathPoint):
                for c, fn in zip(pt.coordinates, pt.functions):
                    if c is not None:
                        b3[m, sk.coordinate_index(c)] += spline_third_derivative_bound(fn)
    return step**2 / 6.0 * b3 + ROUNDING_OPS * EPS * length_max / step


def rotation_vee(skew):
    """Axial vector of the (nearly) skew-symmetric 3x3 matrices ``skew`` (..., 3, 3)."""
    a = 0.5 * (skew - np.swapaxes(skew, -1, -2))
    return np.stack([a[..., 2, 1], a[..., 0, 2], a[..., 1, 0]], axis=-1)


def sample_poses(which: str, n_walk: int, n_random: int, seed: int = 7) -> np.ndarray:
    """Frames of the walking trial spread over its length plus random poses inside the ranges."""
    sk = skeleton(which)
    q, _ = sk.coordinate_array(motion(which))
    walk = q[np.linspace(0, len(q) - 1, n_walk).astype(int)]
    lo = np.array([max(c.range[0], -1.2) for c in sk.model.coordinates])
    hi = np.array([min(c.range[1], 1.2) for c in sk.model.coordinates])
    rnd = np.random.default_rng(seed).uniform(lo, hi, size=(n_random, sk.n_coordinates))
    return np.vstack([walk, rnd])


# non-zero joint offset frames (all offsets of these models' knees are zero): a modified copy
KNEE_OFFSETS = (("0.01 -0.02 0.005", "0.1 -0.2 0.3"),      # femur_r_offset: translation, orientation
                ("-0.015 0.03 0.01", "-0.25 0.15 0.05"))   # tibia_r_offset


def write_model_with_knee_offsets(folder, reverse: bool = False):
    """subject01.osim with non-zero parent and child offset frames at knee_r (and OpenSim's
    ``reverse`` flag set on it if asked), written to ``folder``."""
    text = G10.read_text()
    start = text.index('<CustomJoint name="knee_r">')
    end = text.index("</CustomJoint>", start)
    block = text[start:end]
    for translation, orientation in KNEE_OFFSETS:
        block = block.replace("<translation>0 0 0</translation>", f"<translation>{translation}</translation>", 1)
        block = block.replace("<orientation>0 0 0</orientation>", f"<orientation>{orientation}</orientation>", 1)
    if reverse:
        block = block.replace("<SpatialTransform>", "<reverse>true</reverse>\n<SpatialTransform>", 1)
    path = folder / f"subject01_knee_offsets{'_reversed' if reverse else ''}.osim"
    path.write_text(text[:start] + block + text[end:])
    return path


# ---- transforms ------------------------------------------------------------------------------


@pytest.mark.parametrize("which", ["g10", "g2392"])
def test_rotation_matrices_are_proper_orthonormal_over_the_trial(which):
    sk = skeleton(which)
    kin = sk.forward_kinematics(motion(which))
    R = kin.rotation
    err = np.abs(np.swapaxes(R, -1, -2) @ R - np.eye(3)).max()
    assert err < 20 * EPS, err
    assert np.allclose(np.linalg.det(R), 1.0, atol=20 * EPS)
    assert kin.time is not None and kin.time.shape == (len(motion(which)),)


def test_axis_rotation_is_rodrigues():
    rng = np.random.default_rng(3)
    a = rng.normal(size=3)
    th = rng.uniform(-3, 3, size=5)
    expected = Rotation.from_rotvec(th[:, None] * (a / np.linalg.norm(a))).as_matrix()
    assert np.allclose(axis_rotation(a, th), expected, atol=1e-15)


def _knee_splines_from_xml(path, joint="knee_r"):
    """(x, y, scale) of translation1 and translation2 of the knee, read directly from the XML."""
    root = ET.parse(path).getroot()
    cj = next(e for e in root.iter("CustomJoint") if e.get("name") == joint)
    out = {}
    for ax in cj.iter("TransformAxis"):
        if ax.get("name") in ("translation1", "translation2"):
            spline = next(ax.iter("SimmSpline"))
            x = np.array(spline.find("x").text.split(), float)
            y = np.array(spline.find("y").text.split(), float)
            scale = float(next(ax.iter("MultiplierFunction")).find("scale").text)
            out[ax.get("name")] = (x, y, scale)
    return out


def test_knee_translates_with_the_spline_of_the_knee_angle_in_the_femur_frame():
    """Tibia origin in the femur frame = (s1(q), s2(q), 0): the translations are along the
    parent-frame axes, not rotated with the knee (Simbody MobilizedBodyImpl.h, X.updP())."""
    sk = skeleton("g10")
    splines = _knee_splines_from_xml(G10)
    lo, hi = sk.model.coordinate("knee_angle_r").range
    # at the knots the spline interpolates the XML values exactly
    for name, k in (("translation1", 0), ("translation2", 1)):
        x, y, scale = splines[name]
        inside = (x >= lo) & (x <= hi)
        kin = sk.forward_kinematics({"knee_angle_r": x[inside], "hip_flexion_r": 0.3, "pelvis_tilt": -0.2})
        f, t = sk.body_index("femur_r"), sk.body_index("tibia_r")
        rel = np.einsum("nji,nj->ni", kin.rotation[:, f], kin.origin[:, t] - kin.origin[:, f])
        assert np.allclose(rel[:, k], scale * y[inside], rtol=0, atol=1e-15), name
        assert np.allclose(rel[:, 2], 0.0, atol=1e-15)
    # between the knots: the reader's function values, and the relative rotation is R_z(q)
    q = np.linspace(lo, hi, 23)
    kin = sk.forward_kinematics({"knee_angle_r": q, "hip_flexion_r": -0.4})
    f, t = sk.body_index("femur_r"), sk.body_index("tibia_r")
    rel = np.einsum("nji,nj->ni", kin.rotation[:, f], kin.origin[:, t] - kin.origin[:, f])
    axes = sk.model.joint("knee_r").transform_axes
    assert np.allclose(rel[:, 0], axes[3].function(q), atol=1e-15)
    assert np.allclose(rel[:, 1], axes[4].function(q), atol=1e-15)
    R_rel = np.swapaxes(kin.rotation[:, f], -1, -2) @ kin.rotation[:, t]
    assert np.allclose(R_rel, Rotation.from_euler("z", q[:, None]).as_matrix(), atol=1e-15)
    # knee flexion is negative in these models: the range runs from -120 deg to +10 deg
    assert lo == pytest.approx(-2.0943951, abs=1e-7) and hi == pytest.approx(0.17453293, abs=1e-8)


def test_three_rotation_axes_form_a_body_fixed_sequence():
    """gait2392 hip: rotation1 z (flexion), rotation2 x (adduction), rotation3 y (rotation):
    R_FM = R_z(θ1) R_x(θ2) R_y(θ3), the intrinsic z-x'-y'' sequence; the left hip's axes are -x, -y."""
    sk = skeleton("g2392")
    rng = np.random.default_rng(11)
    th = rng.uniform(-1.0, 1.0, size=(6, 3))
    for side, sign in (("r", 1.0), ("l", -1.0)):
        q = {f"hip_flexion_{side}": th[:, 0], f"hip_adduction_{side}": th[:, 1], f"hip_rotation_{side}": th[:, 2]}
        R, p = sk.joint_transform(f"hip_{side}", q)
        expected = Rotation.from_euler("ZXY", np.c_[th[:, 0], sign * th[:, 1], sign * th[:, 2]]).as_matrix()
        assert np.allclose(R, expected, atol=1e-15)
        extrinsic = Rotation.from_euler("zxy", np.c_[th[:, 0], sign * th[:, 1], sign * th[:, 2]]).as_matrix()
        assert not np.allclose(R, extrinsic, atol=1e-3)   # the test tells the two orders apart
        assert np.allclose(p, 0.0)
    # ground-pelvis: the translations are the coordinates along ground's axes whatever the rotation
    q = {"pelvis_tilt": 0.7, "pelvis_list": -0.4, "pelvis_rotation": 1.1,
         "pelvis_tx": 0.3, "pelvis_ty": 0.9, "pelvis_tz": -0.2}
    kin = sk.forward_kinematics(q)
    assert np.allclose(kin.origin[0, sk.body_index("pelvis")], [0.3, 0.9, -0.2], atol=1e-15)


def test_oblique_ankle_axis_rotates_by_the_angle_about_the_file_axis():
    sk = skeleton("g2392")
    axis = sk.model.joint("ankle_r").transform_axes[0].axis
    q = np.linspace(-0.8, 0.6, 9)
    R, p = sk.joint_transform("ankle_r", {"ankle_angle_r": q})
    assert np.allclose(R @ axis, axis, atol=1e-15)
    assert np.allclose(np.trace(R, axis1=1, axis2=2), 1 + 2 * np.cos(q), atol=1e-14)
    # sense: right-handed about the axis
    assert np.allclose(rotation_vee(R) / np.sin(q)[:, None], axis, atol=1e-12)


def test_offset_frames_compose_as_parent_pose_offset_joint_and_inverse_child_offset(tmp_path):
    """X_GC = X_GP X_PF X_FM(q) X_CM⁻¹ (Eq. 2) with non-zero offsets: the joint frames built from
    each body's pose and its offset, X_GF = X_GP X_PF and X_GM = X_GC X_CM, are related by X_FM."""
    sk = Skeleton(read_osim(write_model_with_knee_offsets(tmp_path)))
    joint = sk.model.joint("knee_r")
    pf, cf = joint.parent_frame, joint.child_frame
    assert np.allclose(pf.location, [0.01, -0.02, 0.005]) and np.allclose(cf.orientation, [-0.25, 0.15, 0.05])
    Q = sample_poses("g10", 3, 2)
    kin = sk.forward_kinematics(Q)
    R_FM, p_FM = sk.joint_transform("knee_r", Q)
    P, C = sk.body_index("femur_r"), sk.body_index("tibia_r")
    R_GF = kin.rotation[:, P] @ pf.rotation
    x_F = kin.origin[:, P] + kin.rotation[:, P] @ pf.location
    R_GM = kin.rotation[:, C] @ cf.rotation
    x_M = kin.origin[:, C] + kin.rotation[:, C] @ cf.location
    assert np.allclose(np.swapaxes(R_GF, -1, -2) @ R_GM, R_FM, atol=1e-14)
    assert np.allclose(np.einsum("nji,nj->ni", R_GF, x_M - x_F), p_FM, atol=1e-15)
    # the PhysicalOffsetFrame orientation is the body-fixed X-Y-Z sequence
    assert np.allclose(pf.rotation, Rotation.from_euler("XYZ", [0.1, -0.2, 0.3]).as_matrix())
    # and the Jacobians still match differences with the offsets
    kin = sk.forward_kinematics(Q, jacobians=True)
    h, j = 1e-5, sk.coordinate_index("knee_angle_r")
    qp, qm = Q.copy(), Q.copy()
    qp[:, j] += h
    qm[:, j] -= h
    dx = (sk.forward_kinematics(qp).origin - sk.forward_kinematics(qm).origin) / (2 * h)
    assert np.abs(dx - kin.origin_jacobian[..., j]).max() < 1e-9


# ---- Jacobians ---------------------------------------------------------------------------------


@pytest.mark.parametrize("which", ["g10", "g2392"])
def test_jacobians_against_central_differences(which):
    sk = skeleton(which)
    Q = sample_poses(which, 3, 2)
    kin = sk.forward_kinematics(Q, jacobians=True)
    h = 1e-5
    b3 = GEOMETRIC_BOUND + joint_spline_bounds(sk)            # per coordinate
    x_max = np.abs(kin.origin).max() + 1.0
    tol_x = h**2 / 6 * b3 + ROUNDING_OPS * EPS * x_max / h
    tol_w = h**2 / 6 * b3 + ROUNDING_OPS * EPS / h
    err_x = np.zeros(sk.n_coordinates)
    err_w = np.zeros(sk.n_coordinates)
    for j in range(sk.n_coordinates):
        qp, qm = Q.copy(), Q.copy()
        qp[:, j] += h
        qm[:, j] -= h
        kp, km = sk.forward_kinematics(qp), sk.forward_kinematics(qm)
        dx = (kp.origin - km.origin) / (2 * h)
        dR = (kp.rotation - km.rotation) / (2 * h)
        w = rotation_vee(dR @ np.swapaxes(kin.rotation, -1, -2))     # [ω]× = Ṙ Rᵀ
        err_x[j] = np.abs(dx - kin.origin_jacobian[..., j]).max()
        err_w[j] = np.abs(w - kin.angular_jacobian[..., j]).max()
    assert np.all(err_x <= tol_x), (err_x, tol_x)
    assert np.all(err_w <= tol_w), (err_w, tol_w)


def test_body_frame_angular_velocity_and_virtual_power():
    sk = skeleton("g2392")
    Q = sample_poses("g2392", 2, 1)
    qdot = np.random.default_rng(5).normal(size=Q.shape)
    kin = sk.forward_kinematics(Q, jacobians=True)
    h = 1e-6
    Rp = sk.forward_kinematics(Q + h * qdot).rotation
    Rm = sk.forward_kinematics(Q - h * qdot).rotation
    w_body_fd = rotation_vee(np.swapaxes(kin.rotation, -1, -2) @ (Rp - Rm) / (2 * h))   # [ω_B]× = Rᵀ Ṙ
    w_body = kin.angular_velocity(qdot, expressed_in="body")
    assert np.abs(w_body - w_body_fd).max() < 1e-7
    assert np.allclose(np.einsum("nbji,nbj->nbi", kin.rotation, kin.angular_velocity(qdot, "ground")), w_body)
    # Q·q̇ = f·v_S + m·ω for a load at a point of the right calcaneus
    station = np.array([0.05, -0.01, 0.02])
    force = np.array([30.0, 700.0, -20.0])
    torque = np.array([1.0, -2.0, 5.0])
    Qf = sk.generalized_forces("calcn_r", station, force, Q, torque=torque)
    v_fd = (sk.station_positions("calcn_r", station, Q + h * qdot)
            - sk.station_positions("calcn_r", station, Q - h * qdot))[:, 0] / (2 * h)
    w = kin.angular_velocity(qdot, "ground")[:, sk.body_index("calcn_r")]
    power = v_fd @ force + w @ torque
    assert np.allclose(np.einsum("nj,nj->n", Qf, qdot), power, rtol=1e-7, atol=1e-6)
    J = sk.station_jacobian("calcn_r", station, Q)
    assert np.allclose(np.einsum("nij,nj->ni", J, qdot), v_fd, atol=1e-7)


# ---- muscle paths ------------------------------------------------------------------------------


def test_vectorised_path_points_match_the_readers_point_methods():
    """Active set, local locations and their derivatives agree with PathPoint.is_active /
    location_at / location_derivative of biomech.osim, frame by frame."""
    sk = skeleton("g10")
    Q = sample_poses("g10", 4, 3)
    pt = sk._points
    loc, active, dloc = sk._point_locals(Q, True)
    points = [p for mus in sk.model.muscles for p in mus.path]
    for f in range(len(Q)):
        qd = dict(zip(sk.coordinate_names, Q[f]))
        for i, p in enumerate(points):
            assert active[f, i] == p.is_active(qd)
            assert np.array_equal(loc[f, i], p.location_at(qd))
        for i, k, c, d in dloc:
            assert d[f] == points[i].location_derivative(qd, sk.coordinate_names[c])[k]
    assert len(pt.moving) > 0 and pt.cond_points.size > 0


def test_muscle_path_lists_active_points_and_its_length():
    sk = skeleton("g10")
    bent = sk.muscle_path("vasti_r", {"knee_angle_r": -1.8})   # conditional point active below -1.42
    straight = sk.muscle_path("vasti_r", {"knee_angle_r": -0.2})
    assert len(bent.point_names) == len(straight.point_names) + 1
    assert bent.bodies[-1] == "tibia_r"
    for path, q in ((bent, -1.8), (straight, -0.2)):
        assert path.length == pytest.approx(np.linalg.norm(np.diff(path.positions, axis=0), axis=1).sum())
        assert path.length == pytest.approx(sk.muscle_geometry({"knee_angle_r": q}).of("vasti_r")[0], abs=1e-15)


def test_moment_arms_of_all_18_muscles_against_central_differences_over_the_walk():
    sk = skeleton("g10")
    mot = motion("g10")
    Q = sk.coordinate_array(mot)[0][::10]                          # 16 frames over 2.5 s
    step = 1e-5
    check = sk.moment_arm_check(Q, step=step)
    tol = moment_arm_tolerance(sk, step, length_max=1.0)
    assert check.valid.mean() > 0.95                                # few stencils cross a switch
    err = check.error
    assert np.all((err <= tol[None]) | ~check.valid), np.nanmax(err - tol[None])
    # the error is far below the tolerance except where the knee splines have close knots
    assert np.nanmax(err) < 1e-6
    # musculotendon lengths are plausible (tens of centimetres)
    L = sk.muscle_lengths(Q)
    assert np.all((L > 0.1) & (L < 0.7))


def test_moment_arms_vanish_for_the_rigid_motion_of_the_whole_model():
    """Pelvis translations and tilt move every body rigidly: no length changes (exact)."""
    sk = skeleton("g10")
    geo = sk.muscle_geometry(motion("g10"))
    cols = [sk.coordinate_index(c) for c in ("pelvis_tilt", "pelvis_tx", "pelvis_ty")]
    assert np.abs(geo.moment_arm[:, :, cols]).max() < 1e-15


def test_moment_arm_signs_at_the_neutral_pose():
    """OpenSim conventions: hip_flexion positive = flexion, knee_angle positive = extension (flexion
    negative), ankle_angle positive = dorsiflexion.  A muscle's moment arm has the sign of the motion
    its tension produces."""
    sk = skeleton("g10")
    neutral = {c: 0.0 for c in sk.coordinate_names}
    geo = sk.muscle_geometry(neutral)
    for side in ("r", "l"):
        assert geo.of(f"iliopsoas_{side}", f"hip_flexion_{side}")[0] > 0.02       # hip flexor
        assert geo.of(f"hamstrings_{side}", f"hip_flexion_{side}")[0] < -0.02     # hip extensor
        assert geo.of(f"glut_max_{side}", f"hip_flexion_{side}")[0] < -0.02
        assert geo.of(f"hamstrings_{side}", f"knee_angle_{side}")[0] < -0.01      # knee flexor
        assert geo.of(f"vasti_{side}", f"knee_angle_{side}")[0] > 0.02            # knee extensor
        assert geo.of(f"rect_fem_{side}", f"hip_flexion_{side}")[0] > 0.02
        assert geo.of(f"gastroc_{side}", f"ankle_angle_{side}")[0] < -0.02        # plantarflexors
        assert geo.of(f"soleus_{side}", f"ankle_angle_{side}")[0] < -0.02
        assert geo.of(f"tib_ant_{side}", f"ankle_angle_{side}")[0] > 0.02         # dorsiflexor
        assert abs(geo.of(f"vasti_{side}", f"hip_flexion_{side}")[0]) < 1e-15      # one-joint muscle
    # with the knee flexed (negative angle) the vasti lengthen
    flexed = sk.muscle_geometry({**neutral, "knee_angle_r": -1.0})
    assert flexed.of("vasti_r")[0] > geo.of("vasti_r")[0]


def test_gait2392_moment_arms_of_92_muscles_against_central_differences():
    sk = skeleton("g2392")
    assert sk.n_muscles == 92 and sk.n_coordinates == 23
    Q = sample_poses("g2392", 3, 1)
    step = 1e-5
    check = sk.moment_arm_check(Q, step=step)
    tol = moment_arm_tolerance(sk, step, length_max=1.0)
    assert check.valid.mean() > 0.95
    assert np.all((check.error <= tol[None]) | ~check.valid), np.nanmax(check.error - tol[None])
    assert np.all(sk.muscle_lengths(Q) > 0.02)


def test_moment_arm_check_marks_stencils_that_switch_a_conditional_point():
    sk = skeleton("g10")
    edge = -1.42 + 1e-5          # upper end of vasti_r's conditional range [-2.61799, -1.42] plus tolerance
    check = sk.moment_arm_check({"knee_angle_r": edge}, step=1e-4, coordinates=["knee_angle_r"])
    m, j = sk.muscle_names.index("vasti_r"), sk.coordinate_index("knee_angle_r")
    assert not check.valid[0, m, j]
    assert check.valid[0, sk.muscle_names.index("soleus_r"), j]
    assert not check.valid[0, :, sk.coordinate_index("hip_flexion_r")].any()   # not differenced
    # a moving point's coordinate at its clamp limit (knee range ends at +10 deg)
    hi = sk.model.coordinate("knee_angle_r").range[1]
    check = sk.moment_arm_check({"knee_angle_r": hi}, step=1e-4, coordinates=["knee_angle_r"])
    assert not check.valid[0, sk.muscle_names.index("rect_fem_r"), j]
    assert check.valid[0, sk.muscle_names.index("hamstrings_r"), j]


def test_muscles_whose_wrapping_was_ignored_are_listed():
    model = read_osim(G10)
    assert Skeleton(model).unwrapped_muscles == ()
    item = IgnoredItem("path wrap", "PathWrap", "pw", "muscle 'gastroc_r'", 1, "wrapping not modelled")
    assert Skeleton(dataclasses.replace(model, ignored=(item,))).unwrapped_muscles == ("gastroc_r",)


# ---- values computed by OpenSim 4.6 ----------------------------------------------------------

# (row of the .mot, time) -> {body: origin in ground}, {(muscle, coordinate): (length, moment arm)}
OPENSIM_G10 = {
    (30, 0.5): (
        {"tibia_r": [0.699474809777004, 0.5385926496622856, 0.1055524],
         "calcn_l": [0.29402819548266096, 0.0543818870825372, -0.07437511999999999],
         "torso": [0.47457301805654073, 1.10543401108288, 0.02]},
        {("vasti_r", "knee_angle_r"): (0.2268257910894946, 0.04646437874495632),
         ("rect_fem_r", "hip_flexion_r"): (0.47167388161787566, 0.05062467508563902),
         ("rect_fem_r", "knee_angle_r"): (0.47167388161787566, 0.05072849431356402),
         ("hamstrings_r", "hip_flexion_r"): (0.48492744892629347, -0.06549221419202902),
         ("hamstrings_r", "knee_angle_r"): (0.48492744892629347, -0.03245787107309632),
         ("gastroc_r", "ankle_angle_r"): (0.44388250998878487, -0.05301638248386111),
         ("iliopsoas_l", "hip_flexion_l"): (0.28670201549279833, 0.03646281895808447),
         ("tib_ant_l", "ankle_angle_l"): (0.2990365694069388, 0.045762259185677945)}),
    (90, 1.5): (
        {"tibia_r": [0.6246795535039771, 0.5019734495358581, 0.1055524],
         "calcn_l": [0.5544970497249493, 0.044613254795643466, -0.07437511999999999],
         "torso": [0.4840227405388405, 1.106320339827474, 0.02]},
        {("vasti_r", "knee_angle_r"): (0.26407828243471076, 0.03743716108767394),
         ("rect_fem_r", "hip_flexion_r"): (0.5237870545595823, 0.04337457870827521),
         ("rect_fem_r", "knee_angle_r"): (0.5237870545595823, 0.038743654542687134),
         ("hamstrings_r", "hip_flexion_r"): (0.44283785207479565, -0.059199938175241586),
         ("hamstrings_r", "knee_angle_r"): (0.44283785207479565, -0.025381292233649683),
         ("gastroc_r", "ankle_angle_r"): (0.42121660394580235, -0.053824093786619884),
         ("iliopsoas_l", "hip_flexion_l"): (0.27159716874261364, 0.04191112566491999),
         ("tib_ant_l", "ankle_angle_l"): (0.3022515324735672, 0.045021454075940597)}),
}
OPENSIM_G2392 = {
    (60, 1.5): (
        {"tibia_r": [0.6258833098774746, 0.507889154899968, 0.1540288259312695],
         "calcn_l": [0.5545101226078951, 0.047221710625427515, -0.04474540992748219],
         "toes_r": [0.29713859240928303, 0.13653823547534705, 0.12137828392152514]},
        {("vas_int_r", "knee_angle_r"): (0.26486109618886716, 0.0370491402734773),
         ("glut_med1_r", "hip_adduction_r"): (0.12612215365524476, -0.04798652608638966),
         ("per_brev_r", "subtalar_angle_r"): (0.21310804857075336, -0.027436490049061495),
         ("tib_post_l", "ankle_angle_l"): (0.3426522252642329, -0.015729984571222412),
         ("ercspn_r", "lumbar_bending"): (0.17545014191479366, 0.03499612169046227)}),
}


@pytest.mark.parametrize("which, table", [("g10", OPENSIM_G10), ("g2392", OPENSIM_G2392)])
def test_agrees_with_values_computed_by_opensim(which, table):
    """OpenSim 4.6 (no wrapping in these models): body origins, lengths and computeMomentArm.
    The .mot rows were converted by OpenSim; the files print 8 significant digits (degrees),
    the same numbers enter both programs, so agreement is to rounding (1e-12 m)."""
    sk = skeleton(which)
    mot = motion(which)
    for (row, t), (bodies, muscles) in table.items():
        assert mot["time"].iloc[row] == pytest.approx(t, abs=1e-9)
        q = mot.iloc[[row]]
        kin = sk.forward_kinematics(q)
        for body, origin in bodies.items():
            assert np.allclose(kin.origin[0, sk.body_index(body)], origin, rtol=0, atol=1e-12), body
        geo = sk.muscle_geometry(q)
        for (mus, coord), (length, arm) in muscles.items():
            assert geo.of(mus)[0] == pytest.approx(length, abs=1e-12), mus
            assert geo.of(mus, coord)[0] == pytest.approx(arm, abs=1e-12), (mus, coord)


def test_agrees_with_opensim_everywhere_when_it_is_installed(tmp_path):
    """Optional peer run: every body transform, length and moment arm at trial and random poses,
    also for the model with non-zero knee offset frames, and with the knee's ``reverse`` flag (which
    changes Simbody's tree direction but not the kinematics)."""
    osim = pytest.importorskip("opensim")
    offsets = write_model_with_knee_offsets(tmp_path)
    reversed_ = write_model_with_knee_offsets(tmp_path, reverse=True)
    for path, which in ((G10, "g10"), (G2392, "g2392"), (offsets, "g10"), (reversed_, "g10")):
        sk = skeleton(which) if path in (G10, G2392) else Skeleton(read_osim(path))
        assert path != reversed_ or sk.model.joint("knee_r").reverse
        Q = sample_poses(which, 4, 2)
        model = osim.Model(str(path))
        state = model.initSystem()
        cs, bs, ms = model.getCoordinateSet(), model.getBodySet(), model.getMuscles()
        kin = sk.forward_kinematics(Q)
        geo = sk.muscle_geometry(Q)
        for f, q in enumerate(Q):
            for name, v in zip(sk.coordinate_names, q):
                cs.get(name).setValue(state, float(v), False)
            model.realizePosition(state)
            for b in range(bs.getSize()):
                body = bs.get(b)
                X = body.getTransformInGround(state)
                i = sk.body_index(body.getName())
                R = np.array([[X.R().get(r, c) for c in range(3)] for r in range(3)])
                assert np.allclose(kin.rotation[f, i], R, atol=1e-12)
                assert np.allclose(kin.origin[f, i], [X.p().get(k) for k in range(3)], atol=1e-12)
            for m in range(ms.getSize()):
                mus = ms.get(m)
                i = sk.muscle_names.index(mus.getName())
                assert geo.length[f, i] == pytest.approx(mus.getLength(state), abs=1e-12)
                for j, name in enumerate(sk.coordinate_names):
                    ref = mus.computeMomentArm(state, cs.get(name))
                    assert geo.moment_arm[f, i, j] == pytest.approx(ref, abs=1e-12)


# ---- plausibility ----------------------------------------------------------------------------


def test_standing_default_pose_is_plausible_for_a_1_8_m_subject():
    """Default pose: feet on the ground plane (within 5 cm), below the pelvis; heel-to-top-of-head
    1.755 m in gait2392 (markers R.Heel and Top.Head); hip joint centre 0.947 m above ground in
    gait10dof, i.e. 0.53 of a 1.79 m stature (greater trochanter height 0.530 H, Winter 2009,
    Fig. 4.1, after Drillis & Contini 1966)."""
    for which in ("g10", "g2392"):
        sk = skeleton(which)
        kin = sk.forward_kinematics()
        y = {b: kin.origin[0, sk.body_index(b), 1] for b in sk.body_names}
        for side in ("r", "l"):
            for foot in (f"calcn_{side}", f"toes_{side}"):
                assert y[foot] < y["pelvis"] - 0.8
                assert abs(y[foot]) < 0.05
            assert y["pelvis"] > y[f"femur_{side}"] > y[f"tibia_{side}"] > y[f"talus_{side}"]
        stature_from_hip = y["femur_r"] / 0.530
        assert 1.7 < stature_from_hip < 1.9, stature_from_hip
    sk = skeleton("g2392")
    mk = sk.marker_positions()
    height = mk["Top.Head"][0, 1] - min(mk["R.Heel"][0, 1], mk["L.Heel"][0, 1])
    assert 1.70 < height < 1.85, height


# ---- inputs and errors -----------------------------------------------------------------------


def test_a_muscle_on_a_body_the_model_lacks_is_a_model_error_naming_it():
    model = read_osim(G10)
    mus = model.muscle("soleus_r")
    bad_point = dataclasses.replace(mus.path[0], body="humerus_r")
    bad = dataclasses.replace(mus, path=(bad_point, *mus.path[1:]))
    muscles = tuple(bad if m.name == "soleus_r" else m for m in model.muscles)
    with pytest.raises(ModelError, match=r"soleus_r.*humerus_r"):
        Skeleton(dataclasses.replace(model, muscles=muscles))


def test_coordinate_inputs():
    sk = skeleton("g10")
    q0, t = sk.coordinate_array()
    assert q0.shape == (1, 10) and t is None
    assert q0[0, sk.coordinate_index("pelvis_ty")] == sk.model.coordinate("pelvis_ty").default_value
    q, _ = sk.coordinate_array({"knee_angle_r": [-0.1, -0.2, -0.3]})
    assert q.shape == (3, 10) and np.all(q[:, sk.coordinate_index("hip_flexion_r")] == 0.0)
    with pytest.raises(InputError, match="knee_r"):
        sk.coordinate_array({"knee_r": 0.1})
    with pytest.raises(InputError, match=r"\(n_frames, 10\)"):
        sk.coordinate_array(np.zeros((2, 9)))
    with pytest.raises(InputError, match="knee_angle_l.*frame 1"):
        bad = np.zeros((2, 10))
        bad[1, sk.coordinate_index("knee_angle_l")] = np.nan
        sk.coordinate_array(bad)
    mot = motion("g10").drop(columns=["lumbar_extension"])
    with pytest.raises(InputError, match="lumbar_extension"):
        sk.forward_kinematics(mot)
    with pytest.raises(InputError, match="jacobians=True"):
        sk.forward_kinematics().angular_velocity(np.zeros(10))


def test_motion_table_gives_one_pose_per_frame_with_its_time():
    sk = skeleton("g10")
    mot = motion("g10")
    kin = sk.forward_kinematics(mot)
    table = kin.origins_table()
    assert len(table) == len(mot) and np.array_equal(table["time"], mot["time"])
    one = sk.forward_kinematics(mot.iloc[[40]])
    assert np.array_equal(one.origin[0], kin.origin[40])
    geo = sk.muscle_geometry(mot)
    assert geo.length.shape == (len(mot), 18) and geo.moment_arm.shape == (len(mot), 18, 10)
    assert np.array_equal(geo.time, mot["time"].to_numpy())
