"""Wheel and rail profiles: S1002 definition, UIC60 arcs, measured profiles, bad input."""

import numpy as np
import pytest

from railway.contact.profiles import (
    DATA_DIR,
    RailProfile,
    WheelProfile,
    _load_s1002,
    _s1002_section,
    _uic60_half_sections,
    s1002_exact,
    uic60_exact,
)
from railway.track import RailMounting, parse_inclination


@pytest.fixture(scope="module")
def s1002():
    return WheelProfile.s1002(r0=0.46)


def test_s1002_reference_points(s1002):
    # EN 13715: F(0) = 0 at the taping line, flange height F(-55) = 28 mm
    F, _, _ = s1002_exact(np.array([0.0, -55.0]))
    assert abs(F[0]) < 1e-9
    assert abs(F[1] - 28.0) < 1e-6
    Ft = s1002.evaluate(np.array([0.0, -0.055]))[0]
    assert abs(Ft[0]) < 1e-9 and abs(Ft[1] - 0.028) < 1e-9
    assert s1002.radius(0.0) == pytest.approx(0.46, abs=1e-12)


def test_s1002_continuity_at_section_joints():
    # The standard prints joint abscissae and coefficients to 4-10 digits: the sections meet to
    # 2e-4 mm in value and 1e-3 in slope (C1 up to the printed precision).
    rows = _load_s1002()
    for (n1, _, hi1, c1), (n2, lo2, _, c2) in zip(rows[:-1], rows[1:]):
        assert hi1 == pytest.approx(lo2)
        a = _s1002_section(n1, c1, np.array([hi1]))
        b = _s1002_section(n2, c2, np.array([lo2]))
        assert abs(a[0][0] - b[0][0]) < 2e-4, (n1, n2)
        assert abs(a[1][0] - b[1][0]) < 1e-3, (n1, n2)


def test_s1002_table_matches_exact_definition(s1002):
    # quintic Hermite table from exact (F, F', F'') with <= 0.25 mm arc-length nodes:
    # interpolation error O(h^6 F^(6)) far below 1e-4 mm away from the printed joint mismatch
    y_mm = np.linspace(-68.0, 60.0, 20001)
    F, d1, d2 = s1002.evaluate(y_mm * 1e-3)
    Fe, d1e, d2e = s1002_exact(y_mm)
    assert np.max(np.abs(F * 1e3 - Fe)) < 1e-4
    assert np.max(np.abs(d1 - d1e)) < 1e-4
    # curvature (for Hertz) within 0.1 % of the largest value
    assert np.max(np.abs(d2 * 1e-3 - d2e)) < 1e-3 * np.max(np.abs(d2e))


def test_s1002_zones(s1002):
    # flange tip at the maximum F (y = -55 mm); the convex flange zone starts at the joint of
    # the concave R13 root (section D) and the 70 deg flank (section E) at y = -38.4267 mm
    assert s1002.y_tip == pytest.approx(-0.055, abs=1e-5)
    assert s1002.y_split == pytest.approx(-0.0384267, abs=5e-5)
    _, d1, d2 = s1002.evaluate(np.linspace(s1002.y_tip, s1002.y_split - 1e-5, 200))
    assert np.all(d2 <= 1e-6)  # convex flange
    # the top of the 70 deg flank: the end of section E of the definition (y = -39.7642 mm),
    # to the 0.01 deg tolerance of WheelProfile.y_flank_top (1.2 um on the R20 arc F, plus
    # the 3.8 um grid of the search)
    assert s1002.y_flank_top == pytest.approx(-0.0397642, abs=6e-6)
    # 5 mm above it: on arc F, F(y) - F(top) = 5 mm from the section's closed form
    y5 = s1002.climb_limit(5e-3)
    def arc_f(y):  # section F, mm
        return 8.834924130 + np.sqrt(20.0**2 - (y + 58.558326413) ** 2)
    assert arc_f(y5 * 1e3) - arc_f(-39.7642) == pytest.approx(5.0, abs=0.02)  # 2.75 x 6 um


def test_uic60_arc_tangency():
    rows = (DATA_DIR / "uic60_head_arcs.csv").read_text(encoding="utf-8").strip().splitlines()
    # centres (u, depth) from the data file: internally tangent arcs have |c1 - c2| = R1 - R2
    c300, c80, c13 = np.array([0.0, 300.0]), np.array([7.7, 80.135]), np.array([23.016, 14.909])
    assert np.linalg.norm(c300 - c80) == pytest.approx(300 - 80, abs=2e-3)
    assert np.linalg.norm(c80 - c13) == pytest.approx(80 - 13, abs=2e-3)
    assert len(rows) == 6 and rows[2].startswith("shoulder arc,10.500 .. 25.988,+-7.700,80.135,80")
    # value and slope continuous at the tangency points of the exact profile, to the precision
    # of the centres printed in the data file (1e-3 mm)
    half, _ = _uic60_half_sections()
    for lo, hi, _, _ in half[:-1]:
        a = uic60_exact(np.array([hi - 1e-7, hi + 1e-7]))
        assert abs(a[0][0] - a[0][1]) < 1e-3
        assert abs(a[1][0] - a[1][1]) < 1e-3
    # crown curvature 1/300 mm
    assert uic60_exact(np.array([0.0]))[2][0] == pytest.approx(-1 / 300.0)


def test_uic60_table_and_symmetry():
    r = RailProfile.uic60()
    u = np.linspace(-0.035, 0.035, 7001)
    v, v1, _ = r.evaluate(u)
    ve, v1e, _ = uic60_exact(u * 1e3)
    assert np.max(np.abs(v * 1e3 - ve)) < 1e-5
    assert np.allclose(v, v[::-1], atol=1e-12)
    assert np.allclose(v1, -v1[::-1], atol=1e-9)


def test_rail_mounting_gauge_point_and_top():
    m = RailMounting(gauge=1.435, inclination="1:40")
    Yo, Z = m.mounted(np.array([m.u_top, m.u_gauge]))[:2]
    assert Z[0] == pytest.approx(0.0, abs=1e-12)  # top of rail at z = 0
    assert Z[1] == pytest.approx(-0.014, abs=1e-12)  # gauge point 14 mm below
    assert Yo[1] == pytest.approx(0.7175, abs=1e-12)  # half gauge
    # the highest point of the R300 crown inclined by atan(1/40) lies 300 sin(alpha) mm
    # to the field side of the rail axis
    assert m.u_top == pytest.approx(0.300 * np.sin(np.arctan(1 / 40)), abs=1e-9)
    assert m.gauge_depth == 0.014


@pytest.mark.parametrize("spec,val", [("1:40", 0.025), ("1:20", 0.05), ("vertical", 0.0),
                                      (0.025, 0.025)])
def test_parse_inclination(spec, val):
    assert parse_inclination(spec) == pytest.approx(val)


def test_wrong_inclination_sign_is_rejected():
    with pytest.raises(ValueError, match="-0.025"):
        RailMounting(inclination=-1 / 40)
    with pytest.raises(ValueError, match="1:x"):
        parse_inclination("1:x")
    # the CLI form with the wrong sign names the string as given
    with pytest.raises(ValueError, match="given as '-1:40'"):
        parse_inclination("-1:40")


def test_measured_wheel_profile_from_file(tmp_path):
    y = np.linspace(-60.0, 55.0, 461)
    F = s1002_exact(y)[0]
    f = tmp_path / "wheel.txt"
    f.write_text("lateral_mm vertical_mm\n" + "\n".join(f"{a:.9f} {b:.9f}" for a, b in zip(y, F)))
    w = WheelProfile.from_file(f, r0=0.46)
    yy = np.linspace(-54.0, 50.0, 3001)
    # cubic spline through 0.25 mm spaced exact points: the curvature jumps at section joints
    # dominate, error ~ dF'' h^2 / 16 with dF'' up to 0.8 /mm near the flank: 3e-3 mm
    assert np.max(np.abs(w.evaluate(yy * 1e-3)[0] * 1e3 - s1002_exact(yy)[0])) < 5e-3
    # mirrored file with the flange on the positive side and decreasing lateral coordinate
    f2 = tmp_path / "wheel_mirrored.csv"
    f2.write_text("\n".join(f"{-a:.9f},{b:.9f}" for a, b in zip(y, F)))
    w2 = WheelProfile.from_file(f2, r0=0.46, y_back=70.0, flange_side="positive")
    assert np.allclose(w2.evaluate(yy * 1e-3)[0], w.evaluate(yy * 1e-3)[0], atol=1e-12)
    assert w2.y_split == pytest.approx(w.y_split, abs=1e-4)


def test_measured_rail_profile_from_points():
    u = np.linspace(-35.0, 35.0, 281)
    v = uic60_exact(u)[0]
    r = RailProfile.from_points(u, -v, vertical="depth")
    uu = np.linspace(-34.0, 34.0, 500)
    assert np.max(np.abs(r.evaluate(uu * 1e-3)[0] * 1e3 - uic60_exact(uu)[0])) < 2e-3


def test_non_monotonic_profile_file_names_the_value(tmp_path):
    f = tmp_path / "bad.txt"
    f.write_text("-10 1\n-5 0.5\n-7.25 0.3\n0 0\n5 -0.1\n")
    with pytest.raises(ValueError, match=r"-7\.25"):
        WheelProfile.from_file(f, r0=0.46)


def test_nan_in_profile_names_the_point():
    with pytest.raises(ValueError, match="point 2"):
        RailProfile.from_points([-3.0, -1.0, 0.0, 1.0, 3.0], [0.0, 0.1, np.nan, 0.1, 0.0])
    with pytest.raises(ValueError, match="r0"):
        WheelProfile.s1002(r0=float("nan"))
