"""Rigid contact-geometry table and equivalent conicity (EN 15302)."""

import argparse

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.spatial import cKDTree

from railway.cli import register, run_contact_table
from railway.contact.geometry import (
    conicity_table,
    contact_geometry_table,
    equivalent_conicity,
    flange_contact_onset,
    rigid_contact,
)
from railway.contact.search import wheelset_pose
from railway.contact.profiles import WheelProfile
from railway.track import RailMounting, Track


@pytest.fixture(scope="module")
def table():
    # S1002 / UIC60 1:40, gauge 1435, flange-back 1360, r0 = 0.46 m (the reference case)
    return contact_geometry_table(np.linspace(-0.010, 0.010, 401))


@pytest.mark.parametrize("method", ["wavelength", "harmonic", "simple"])
def test_cone_has_its_own_conicity(method):
    lam = 0.15
    y = np.linspace(-0.01, 0.01, 201)
    got = equivalent_conicity(y, 2 * lam * y, [0.002, 0.003, 0.005], method=method)
    np.testing.assert_allclose(got, lam, rtol=1e-6)


def test_harmonic_linearisation_of_a_cubic():
    # Delta r = 2 lam y + c y^3: describing function lam + 3 c A^2 / 8 (closed form)
    lam, c = 0.1, 2000.0
    y = np.linspace(-0.01, 0.01, 4001)
    A = np.array([0.002, 0.004, 0.006])
    got = equivalent_conicity(y, 2 * lam * y + c * y**3, A, method="harmonic")
    np.testing.assert_allclose(got, lam + 3 * c * A**2 / 8, rtol=1e-5)


def test_wavelength_method_against_ode_integration():
    # independent oracle: integrate the kinematic equation y'' = -Delta r(y) / 2 (r0 e = 1) and
    # measure the wavelength L between two upward zero crossings; tan(gamma_e) = 4 pi^2 / L^2
    lam, c = 0.1, 3000.0
    dr = lambda q: 2 * lam * q + c * q**3  # noqa: E731
    y = np.linspace(-0.01, 0.01, 8001)
    for A in (0.002, 0.005):
        ev = lambda t, u: u[0]  # noqa: E731
        ev.direction = 1
        sol = solve_ivp(lambda t, u: [u[1], -dr(u[0]) / 2], [0, 100], [-A, 0.0], events=ev,
                        rtol=1e-11, atol=1e-14)
        t0 = sol.t_events[0]
        L = t0[1] - t0[0]
        got = equivalent_conicity(y, dr(y), [A], method="wavelength")[0]
        assert got == pytest.approx(4 * np.pi**2 / L**2, rel=2e-4)


def test_table_is_antisymmetric(table):
    # a centred symmetric wheelset on a symmetric track: Delta r(-y) = -Delta r(y)
    dr = table["delta_r [m]"].to_numpy()
    roll = table["roll [rad]"].to_numpy()
    z = table["z [m]"].to_numpy()
    np.testing.assert_allclose(dr, -dr[::-1], atol=1e-9)
    np.testing.assert_allclose(roll, -roll[::-1], atol=1e-9)
    np.testing.assert_allclose(z, z[::-1], atol=1e-10)
    np.testing.assert_allclose(table["r_L [m]"], table["r_R [m]"][::-1], atol=1e-9)


def test_rigid_contact_touches_without_penetration():
    # independent check: the dense sampled distance between each wheel and rail is ~0
    y = np.array([-0.006, -0.001, 0.0, 0.0025, 0.0068])
    z, roll, _, _ = rigid_contact(y)
    wheel, mount, track = WheelProfile.s1002(), RailMounting(), Track.straight(20.0)
    u = np.arange(mount.u_min, mount.u_max, 2e-6)
    Yo, Z, a1, b1, _, _ = mount.mounted(u)
    yw = np.arange(wheel.x_min + 1e-4, wheel.x_max, 5e-6)
    rw = wheel.radius(yw)
    for k in range(y.size):
        r, A = wheelset_pose(track, 10.0, y[k], z[k], roll[k], 0.0)
        for side in (1, -1):
            P = (np.stack([0 * yw, side * (yw + 0.75), -rw], -1) @ A[0].T + r[0])[:, 1:]
            pts = np.column_stack([side * Yo, Z])
            nrm = np.column_stack([-side * b1, a1]) / np.hypot(a1, b1)[:, None]
            d, j = cKDTree(pts).query(P)
            g = np.min(np.sign(np.einsum("ij,ij->i", P - pts[j], nrm[j])) * d)
            # touching curves sampled at <= 15 um arc spacing: |g| below 4 um^2/(2 R) + 2 um
            assert abs(g) < 3e-6, (y[k], side, g)


def test_reference_case_is_plausible(table):
    # Published ranges for new S1002 / UIC60 1:40 at standard gauge (issue acceptance band):
    # equivalent conicity about 0.15-0.2 at 3 mm, flange contact at about 6-8 mm lateral shift,
    # flange contact angle close to the 70 deg flank (plus the 1:40 inclination)
    con = conicity_table(table, [0.002, 0.003, 0.004])
    lam3 = con["conicity wavelength [-]"].iloc[1]
    assert 0.12 < lam3 < 0.25
    y_f, g_f = flange_contact_onset(table)
    assert 0.005 < y_f < 0.008
    assert np.radians(60) < g_f < np.radians(72)
    # at the centre the contact lies near the taping line on the rail crown
    c = table.iloc[200]
    assert abs(c["y_wheel_L [m]"]) < 0.005 and abs(c["u_rail_L [m]"]) < 0.0105


def test_yawed_table_runs_and_keeps_contact():
    df = contact_geometry_table(np.linspace(-0.004, 0.004, 21), yaw=0.005)
    assert np.all(np.isfinite(df["delta_r [m]"]))
    assert (df["yaw [rad]"] == 0.005).all()


def test_bad_input_is_named():
    with pytest.raises(ValueError, match="lateral shift"):
        contact_geometry_table([0.0, np.nan])
    with pytest.raises(ValueError, match="-0.025"):
        contact_geometry_table([0.0, 0.001], inclination=-0.025)
    with pytest.raises(ValueError, match="exceeds"):
        equivalent_conicity([-0.002, 0.0, 0.002], [-1e-4, 0, 1e-4], [0.003])


def test_cli_contact_table(tmp_path, capsys):
    parser = argparse.ArgumentParser(prog="mbsuite")
    sub = parser.add_subparsers(dest="cmd")
    register(sub)
    args = parser.parse_args(["railway", "contact-table", "--n", "41", "--y-max-mm", "8",
                              "-o", str(tmp_path)])
    assert args.func is run_contact_table
    assert args.func(args) == 0
    for name in ("contact_table.csv", "contact_table.md", "equivalent_conicity.csv",
                 "contact_table.png", "summary.md"):
        assert (tmp_path / name).exists()
    assert "equivalent conicity at 3 mm" in capsys.readouterr().out
