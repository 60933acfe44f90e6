"""Two-point (tread + flange) contact and the flange lead, checked against a brute-force scan.

Oracles: the analytic contact angles of the constructed profile (cone angle atan(c) and the
S1002 flank angle atan(2.747477) plus the wheelset roll), a dense brute-force vertical-gap scan
of the wheel surface over (theta, y) that is independent of the four-condition Newton search,
and the classical flange-lead estimate r tan(gamma) tan(psi).
"""

import numpy as np
import pytest

from railway.contact.geometry import contact_geometry_table
from railway.contact.profiles import WheelProfile
from railway.contact.two_point import conical_wheel, conical_wheel_points, gap_scan, local_minima, two_point_contact

B_FLANK = 2.747477419  # slope of S1002 section E (70 deg flank)
DY = 5e-6
# brute-force vertical-gap resolution: d2g/dy2 <= kappa_rel (1 + tan^2 gamma)^1.5 ~ 2e3 1/m at
# the 70 deg flank on the R13 gauge corner, so sampling at DY misses the minimum by < 2e3 (DY/2)^2/2
GRID_TOL = 2e3 * (DY / 2) ** 2 / 2 * 3


@pytest.fixture(scope="module")
def cone_wheel(tmp_path_factory):
    # built from a two-column profile file through the measured-profile reader
    path = tmp_path_factory.mktemp("profiles") / "cone40_root8.txt"
    return conical_wheel(path, r0=0.46, cone=1 / 40, root_radius_mm=8.0)


def test_profile_construction_is_tangent():
    # the root arc R joins the cone and the flank tangentially (C1): across both joints the
    # slope changes by no more than the arc curvature allows over one step,
    # |dF'| <= step (1 + F'^2)^1.5 / R, whereas a kink would jump by O(0.1)
    R = 8.0
    _, _, y_joint = conical_wheel_points(cone=1 / 20, root_radius_mm=R)
    for lo, hi, step in ((y_joint - 0.01, y_joint + 0.01, 1e-4), (-32.0, -25.0, 1e-3)):
        y, F, _ = conical_wheel_points(cone=1 / 20, root_radius_mm=R, y_min_mm=lo, y_max_mm=hi,
                                       step_mm=step)
        dF = np.diff(F) / np.diff(y)
        bound = step * (1.0 + dF[:-1] ** 2) ** 1.5 / R
        assert np.all(np.abs(np.diff(dF)) <= 1.05 * bound + 1e-9)
    assert -39.77 < y_joint < -30.0


def test_two_point_contact_rigid(cone_wheel):
    df = two_point_contact(cone_wheel, yaw=0.0)
    tread, flange = df.iloc[0], df.iloc[1]
    roll = tread["roll [rad]"]
    # both candidates touch (rigid: zero gap) at the same shift
    assert abs(tread["gap [m]"]) < 1e-9 and abs(flange["gap [m]"]) < 1e-9
    assert 0.004 < tread["shift [m]"] < 0.009
    # contact angles: cone and flank angles of the profile plus the roll of the wheelset
    assert tread["contact angle [rad]"] == pytest.approx(np.arctan(1 / 40) + roll, abs=1e-6)
    assert flange["contact angle [rad]"] == pytest.approx(np.arctan(B_FLANK) + roll, abs=2e-5)
    # no lead without yaw
    assert abs(flange["lead [m]"]) < 1e-9
    # independent brute-force scan: exactly two local minima, both zero gap, no penetration
    scan = gap_scan(cone_wheel, tread["shift [m]"], tread["z [m]"], roll, 0.0, dy=DY, n_theta=3)
    mins = local_minima(scan, max_gap=1e-6)
    assert len(mins) == 2
    assert np.all(np.abs(mins["gap [m]"]) < GRID_TOL)
    assert scan["gap [m]"].min() > -GRID_TOL
    ys = np.sort(mins["y_wheel [m]"].to_numpy())
    np.testing.assert_allclose(ys, [flange["y_wheel [m]"], tread["y_wheel [m]"]], atol=2 * DY)


def test_yawed_wheelset_flange_lead(cone_wheel):
    psi = 0.010  # angle of attack of a leading wheelset in a tight curve
    df = two_point_contact(cone_wheel, yaw=psi)
    tread, flange = df.iloc[0], df.iloc[1]
    assert abs(tread["gap [m]"]) < 1e-9 and abs(flange["gap [m]"]) < 1e-9
    # the flange contact leads the axle by about r tan(gamma) tan(psi) (13 mm here); the
    # classical estimate neglects the lateral offset of the point, so 5 %
    est = flange["rolling radius [m]"] * np.tan(flange["contact angle [rad]"]) * np.tan(psi)
    assert flange["lead [m]"] == pytest.approx(est, rel=0.05)
    assert flange["lead [m]"] > 0.01 > abs(tread["lead [m]"])
    # brute force over (theta, y): two zero minima over the whole wheel (coarse theta grid) ...
    r = flange["rolling radius [m]"]
    pose = (cone_wheel, tread["shift [m]"], tread["z [m]"], tread["roll [rad]"], psi)
    dth = 4e-4
    scan = gap_scan(*pose, dy=DY, theta_max=0.04, n_theta=201)
    mins = local_minima(scan, max_gap=1e-6)
    assert len(mins) == 2
    # (the theta grid adds at most (r dth/2)^2 / (2 r_min) ~ r dth^2 / 8 to the vertical gap)
    assert np.all(np.abs(mins["gap [m]"]) < GRID_TOL + r * dth**2)
    assert scan["gap [m]"].min() > -GRID_TOL
    # ... and, on a fine theta grid near the flange, the minimum sits at the same lead
    dth = 2e-5
    yf = flange["y_wheel [m]"]
    scan = gap_scan(*pose, dy=DY, theta_max=0.04, n_theta=int(0.08 / dth) + 1,
                    y_range=(yf - 2e-4, yf + 2e-4))
    fl = local_minima(scan, max_gap=1e-6).iloc[0]
    # resolution of the brute-force lead: the theta step, plus the drift of the minimising theta
    # along y over half a y step (the contact ellipse of a yawed flange is skewed), measured
    # from the scan's own neighbouring rows
    i = int(np.argmin(np.abs(scan["y_wheel [m]"].to_numpy() - fl["y_wheel [m]"])))
    drift = np.max(np.abs(np.diff(scan["lead [m]"].to_numpy()[i - 2:i + 3])))
    assert fl["lead [m]"] == pytest.approx(flange["lead [m]"], abs=r * dth + drift)
    assert abs(fl["gap [m]"]) < GRID_TOL + r * dth**2


def test_lead_column_only_with_yaw(cone_wheel):
    t0 = contact_geometry_table(np.linspace(-0.002, 0.002, 5), wheel=cone_wheel)
    assert not any(c.startswith("lead") for c in t0.columns)
    t1 = contact_geometry_table(np.linspace(-0.002, 0.002, 5), yaw=0.005, wheel=cone_wheel)
    assert {"lead_L [m]", "lead_R [m]"} <= set(t1.columns)
    assert np.all(np.isfinite(t1["lead_L [m]"]))


def test_s1002_has_no_two_point_contact():
    with pytest.raises(ValueError, match="S1002"):
        two_point_contact(WheelProfile.s1002(), yaw=0.0, y_max=0.009, n_bracket=19)
