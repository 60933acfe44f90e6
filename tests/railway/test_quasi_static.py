"""Quasi-static elastic wheel-rail contact under vertical wheel loads (railway.contact.quasi_static).

Oracles: the vertical force balance itself; Hertz's approach for the load along the normal
(hertz_from_load, independent of the penetration-driven Newton iteration); mirror symmetry;
the rigid two-point onset of the conical wheel (both contacts carry load just past it).
"""

import argparse

import numpy as np
import pytest

from core.contact_laws import hertz_from_load
from railway.cli import register
from railway.contact.quasi_static import quasi_static_contact
from railway.contact.two_point import conical_wheel, two_point_contact

Q = 100e3


def test_centred_s1002_balances_the_load_and_matches_hertz():
    df = quasi_static_contact([0.0, 0.002, -0.002], Q)
    assert df["converged"].all()
    per_wheel = df.groupby(["y [m]", "side"])["Fz [N]"].sum()
    np.testing.assert_allclose(per_wheel, Q, rtol=1e-6)
    c = df[df["y [m]"] == 0.0]
    # symmetric: equal normal forces, opposite lateral forces
    assert c["N [N]"].iloc[0] == pytest.approx(c["N [N]"].iloc[1], rel=1e-6)
    assert c["Fy [N]"].iloc[0] == pytest.approx(-c["Fy [N]"].iloc[1], rel=1e-6)
    # the force acts along the normal: lateral/vertical = -tan(contact angle) on the left wheel
    left = c[c["side"] == "left"].iloc[0]
    assert left["Fy [N]"] / left["Fz [N]"] == pytest.approx(-np.tan(left["contact angle [rad]"]), rel=1e-6)
    # mirror: +2 mm left == -2 mm right
    p = df[(df["y [m]"] == 0.002) & (df["side"] == "left")]["N [N]"].to_numpy()
    m = df[(df["y [m]"] == -0.002) & (df["side"] == "right")]["N [N]"].to_numpy()
    np.testing.assert_allclose(p, m, rtol=1e-6)


def test_penetration_equals_hertz_approach():
    # the tread of a conical wheel on the R300 crown: flat wheel profile (B from the rail only)
    wheel = conical_wheel(None)
    df = quasi_static_contact([0.0], Q, wheel=wheel)
    row = df[df["side"] == "left"].iloc[0]
    # relative curvatures recomputed independently: rolling radius r0 + F at the contact, rail
    # crown radius 300 mm, cone straight in the lateral direction
    r = 0.46 + (-row["y_wheel [m]"] / 40.0)
    A = 0.5 * np.cos(np.arctan(1 / 40)) / r
    B = 0.5 / 0.300
    h = hertz_from_load(row["N [N]"], A, B, 2.1e11, 0.28, 2.1e11, 0.28)
    assert row["penetration [m]"] == pytest.approx(h.delta[0], rel=2e-3)
    assert row["a [m]"] == pytest.approx(h.a[0], rel=2e-3)


def test_cone_two_point_contact_under_load():
    wheel = conical_wheel(None)
    y_star = two_point_contact(wheel)["shift [m]"].iloc[0]
    df = quasi_static_contact([y_star - 5e-4, y_star + 5e-5], Q, wheel=wheel)
    assert df["converged"].all()
    before = df[(df["y [m]"] < y_star) & (df["side"] == "left")]
    after = df[(df["y [m]"] > y_star) & (df["side"] == "left")]
    assert list(before["contact"]) == ["tread"]
    assert sorted(after["contact"]) == ["flange", "tread"]  # both contacts carry load
    fl = after[after["contact"] == "flange"].iloc[0]
    assert fl["contact angle [rad]"] > np.radians(65)
    assert fl["Fy [N]"] < 0  # the flange pushes the wheel back towards the track centre
    np.testing.assert_allclose(after["Fz [N]"].sum(), Q, rtol=1e-6)


@pytest.mark.parametrize("load", [-5.0, 0.0, float("nan")])
def test_bad_load_names_the_value(load):
    with pytest.raises(ValueError, match=f"wheel load {load!r} N"):
        quasi_static_contact([0.0], load)


def test_cli_load_flag(tmp_path, capsys):
    parser = argparse.ArgumentParser(prog="mbsuite")
    sub = parser.add_subparsers(dest="cmd")
    register(sub)
    args = parser.parse_args(["railway", "contact-table", "--n", "5", "--y-max-mm", "2",
                              "--load-kN", "100", "-o", str(tmp_path)])
    from railway.cli import ConicityResolutionWarning

    with pytest.warns(ConicityResolutionWarning):  # 1 mm steps carry no conicity (issue 21)
        assert args.func(args) == 0
    assert (tmp_path / "quasi_static.csv").exists()
    assert "quasi-static contact under 100 kN" in capsys.readouterr().out
    args = parser.parse_args(["railway", "contact-table", "--n", "5", "--load-kN", "-3"])
    with pytest.raises(ValueError, match="--load-kN -3: the wheel-rail normal load must lie in"):
        args.func(args)
