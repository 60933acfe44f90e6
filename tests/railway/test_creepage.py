"""Creepages from rigid-body kinematics: closed-form cases and invariance properties."""

import numpy as np
import pytest

from railway.contact.creepage import contact_frame, creepages

R0 = 0.46
V = 30.0


def _rolling_wheel(omega_y, yaw=0.0, lateral_velocity=0.0):
    """Wheel of radius R0 centred at (0, 0, R0) over a rail at z = 0, travelling along +x."""
    axle = np.array([-np.sin(yaw), np.cos(yaw), 0.0])
    return dict(contact_point=[0.0, 0.0, 0.0], normal=[0.0, 0.0, 1.0], rolling_direction=[1.0, 0.0, 0.0],
                wheel_position=[0.0, 0.0, R0], wheel_velocity=[V, lateral_velocity, 0.0],
                wheel_angular_velocity=omega_y * axle)


def test_pure_rolling_has_no_creepage():
    xi, eta, phi = creepages(**_rolling_wheel(V / R0))
    np.testing.assert_allclose([xi[0], eta[0], phi[0]], 0.0, atol=1e-15)


def test_longitudinal_creepage_from_wheel_spin_speed():
    # traction: wheel turns faster than rolling: xi = (V - R0 omega)/V
    for xi0 in (-0.01, 0.003):
        xi, eta, phi = creepages(**_rolling_wheel(V * (1.0 - xi0) / R0))
        assert xi[0] == pytest.approx(xi0, rel=1e-12)
        assert eta[0] == 0.0 and phi[0] == 0.0


def test_lateral_creepage_from_yaw_and_lateral_velocity():
    # yawed wheelset: slip velocity of the contact point is (V(1 - cos psi), -V sin psi), so
    # eta = ydot/V - sin(psi) (Wickens' linear eta = ydot/V - psi), xi = 1 - cos(psi)
    psi, ydot = 4e-3, 0.06
    xi, eta, phi = creepages(**_rolling_wheel(V / R0, yaw=psi, lateral_velocity=ydot))
    assert eta[0] == pytest.approx(ydot / V - np.sin(psi), rel=1e-12)
    assert xi[0] == pytest.approx(1.0 - np.cos(psi), rel=1e-9)
    assert phi[0] == pytest.approx(0.0, abs=1e-15)


def test_spin_of_a_conical_tread():
    # contact normal tilted by the contact angle gamma in the y-z plane: phi = -sin(gamma)/R0
    # (n = (0, -sin g, cos g) for the left wheel, omega = (0, V/R0, 0))
    gamma = np.radians([2.0, 30.0, 60.0])
    n = np.stack([np.zeros(3), -np.sin(gamma), np.cos(gamma)], axis=1)
    xi, eta, phi = creepages(np.zeros((3, 3)), n, [1.0, 0.0, 0.0], [0.0, 0.0, R0], [V, 0.0, 0.0],
                             [0.0, V / R0, 0.0])
    np.testing.assert_allclose(phi, -np.sin(gamma) / R0, rtol=1e-12)
    np.testing.assert_allclose(xi, 0.0, atol=1e-15)


def test_invariance_under_rigid_motion_and_common_translation():
    rng = np.random.default_rng(7)
    n = 50
    rc = rng.normal(size=(n, 3))
    nrm = rng.normal(size=(n, 3))
    td = rng.normal(size=(n, 3))
    rW = rc + rng.normal(size=(n, 3))
    vW = rng.normal(size=(n, 3)) * 10 + td * 20
    wW = rng.normal(size=(n, 3)) * 30
    vR = rng.normal(size=(n, 3))
    wR = rng.normal(size=(n, 3))
    rR = rng.normal(size=(n, 3))
    base = creepages(rc, nrm, td, rW, vW, wW, vR, wR, rR, rolling_speed=25.0)
    # (1) a common translation velocity u added to both bodies changes nothing (Galilean)
    u = rng.normal(size=3) * 5
    shifted = creepages(rc, nrm, td, rW, vW + u, wW, vR + u, wR, rR, rolling_speed=25.0)
    np.testing.assert_allclose(shifted, base, rtol=1e-10, atol=1e-12)
    # (2) rotating the whole scene by a rotation Q changes nothing
    Qm, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    if np.linalg.det(Qm) < 0:
        Qm[:, 0] *= -1
    rot = lambda x: np.asarray(x) @ Qm.T
    rotated = creepages(rot(rc), rot(nrm), rot(td), rot(rW), rot(vW), rot(wW), rot(vR), rot(wR), rot(rR),
                        rolling_speed=25.0)
    np.testing.assert_allclose(rotated, base, rtol=1e-10, atol=1e-12)


def test_roller_rig_equals_track():
    # wheel held, roller surface moving backwards at V: same creepages as the wheel on track
    track = creepages(**_rolling_wheel(V * 0.99 / R0, yaw=1e-3))
    kw = _rolling_wheel(V * 0.99 / R0, yaw=1e-3)
    kw["wheel_velocity"] = [0.0, 0.0, 0.0]
    rig = creepages(**kw, rail_velocity=[-V, 0.0, 0.0])
    np.testing.assert_allclose(rig, track, rtol=1e-12, atol=1e-15)


def test_frame_is_right_handed_and_orthonormal():
    rng = np.random.default_rng(1)
    t, l, n = contact_frame(rng.normal(size=(20, 3)), rng.normal(size=(20, 3)))
    M = np.stack([t, l, n], axis=2)
    np.testing.assert_allclose(np.einsum("kij,kil->kjl", M, M), np.broadcast_to(np.eye(3), (20, 3, 3)),
                               atol=1e-14)
    np.testing.assert_allclose(np.linalg.det(M), 1.0, rtol=1e-13)


def test_as_frame_columns():
    df = creepages(**_rolling_wheel(V / R0), as_frame=True)
    assert list(df.columns) == ["xi [-]", "eta [-]", "phi [1/m]", "V [m/s]"]
    assert df["V [m/s]"].iloc[0] == pytest.approx(V)


def test_bad_input():
    kw = _rolling_wheel(V / R0)
    with pytest.raises(ValueError, match="rolling speed V=0.0 m/s at contact 0"):
        creepages(**{**kw, "wheel_velocity": [0.0, 0.0, 0.0]})
    with pytest.raises(ValueError, match="wheel_angular_velocity has a non-finite value at contact 0"):
        creepages(**{**kw, "wheel_angular_velocity": [np.nan, 1.0, 0.0]})
    with pytest.raises(ValueError, match="rolling_direction is \\(nearly\\) parallel"):
        creepages(**{**kw, "rolling_direction": [0.0, 0.0, 2.0]})
    with pytest.raises(ValueError, match="contact_point must have shape"):
        creepages(**{**kw, "contact_point": [0.0, 0.0]})
