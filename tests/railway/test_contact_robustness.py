"""A contact wherever the surfaces touch: micrometre scans through every contact jump, exported
(sampled) profiles, rows out of reach, transitions located exactly, honest summaries.

Oracle (independent of the contact search): the rigid contact in the cross-section of a
wheelset on straight track without yaw, from dense samples of the wheel and rail profiles.
For the wheel profile line y (sampled at 10 um of arc) at axle height 0 and roll phi, the
vertical gap to the mounted rail (sampled at 1 um of arc, linear interpolation in the lateral
coordinate) is g_v(y) = Z_w(y) - Z_r(Y_w(y)); a(phi) = min_y g_v is the approach of that wheel,
and a vertical translation z adds z to every gap.  The rigid contact therefore solves
a_L(phi) = a_R(phi) (Brent's method on phi) with z = -a_L, and each wheel touches at the
argmin of its g_v.  At a pose from :func:`railway.contact.geometry.rigid_contact` both
minima must be zero (touching, no hidden penetration anywhere on the profile).

Sampling error of the oracle: the minimum over samples 10 um apart exceeds the true minimum
by at most k_rel h^2 / 8 < 1e-9 m (k_rel <= 1/13 mm), times 1/cos(gamma) < 3 for a vertical gap
on the 70 deg flank; the rail interpolation error is below 1e-11 m.
"""

import argparse

import numpy as np
import pandas as pd
import pytest
from scipy.optimize import brentq

from core.errors import InputError
from railway.cli import ConicityResolutionWarning, register
from railway.contact.geometry import (
    conicity_table,
    contact_geometry_table,
    contact_transitions,
    flange_contact_onset,
    rigid_contact,
)
from railway.contact.search import ContactSearch, wheelset_pose
from railway.contact.creep_curve import creep_curve
from railway.contact.profiles import (
    RailProfile,
    WheelProfile,
    data_resolution,
    s1002_exact,
    uic60_exact,
)
from railway.contact.quasi_static import quasi_static_contact, quasi_static_summary
from railway.track import RailMounting, Track

L_WHEEL = 0.5 * 1.360 + 0.070  # taping line from the wheelset centre (m)


class Oracle:
    """Sampled cross-section of a wheelset on its rails (see the module docstring)."""

    def __init__(self, wheel, mount, dw=1e-5, dr=1e-6):
        yd = np.linspace(wheel.x_min + 1e-6, wheel.x_max - 1e-6, 400001)
        F1 = wheel.evaluate(yd)[1]
        ds = np.sqrt(1.0 + F1**2)
        arc = np.concatenate([[0.0], np.cumsum(0.5 * (ds[1:] + ds[:-1]) * np.diff(yd))])
        self.y = np.interp(np.arange(0.0, arc[-1], dw), arc, yd)
        self.r = wheel.r0 + wheel.evaluate(self.y)[0]
        ud = np.linspace(mount.u_min, mount.u_max, 200001)
        Yo, Z = mount.mounted(ud)[:2]
        arc = np.concatenate([[0.0], np.cumsum(np.hypot(np.diff(Yo), np.diff(Z)))])
        self.Yo, self.Z = mount.mounted(np.interp(np.arange(0.0, arc[-1], dr), arc, ud))[:2]

    def gap(self, shift, z, roll, side):
        """(min vertical gap, y at it) of one wheel (side +1 left, -1 right)."""
        c, s = np.cos(roll), np.sin(roll)
        lat = side * (self.y + L_WHEEL)
        zr = np.interp(side * (shift + c * lat + s * self.r), self.Yo, self.Z,
                       left=np.nan, right=np.nan)
        g = np.where(np.isfinite(zr), z + s * lat - c * self.r - zr, np.inf)
        k = int(np.argmin(g))
        return float(g[k]), float(self.y[k])

    def normal_gap(self, shift, z, roll, side):
        """(min signed distance along the rail normal, y at it) of one wheel: the wheel samples'
        distances to the nearest rail sample, projected on that sample's normal."""
        from scipy.spatial import cKDTree

        c, s = np.cos(roll), np.sin(roll)
        lat = side * (self.y + L_WHEEL)
        P = np.column_stack([side * (shift + c * lat + s * self.r), z + s * lat - c * self.r])
        t = np.gradient(np.column_stack([self.Yo, self.Z]), axis=0)
        n = np.column_stack([-t[:, 1], t[:, 0]]) / np.hypot(t[:, 0], t[:, 1])[:, None]
        pts = np.column_stack([self.Yo, self.Z])
        _, j = cKDTree(pts).query(P)
        g = np.einsum("ij,ij->i", P - pts[j], n[j])
        k = int(np.argmin(g))
        return float(g[k]), float(self.y[k])

    def rigid(self, shift):
        """Independent rigid contact: (z, roll, y touching left, y touching right)."""
        def f(roll):
            return self.gap(shift, 0.0, roll, 1)[0] - self.gap(shift, 0.0, roll, -1)[0]

        roll = brentq(f, -0.02, 0.02, xtol=1e-13)
        z = -self.gap(shift, 0.0, roll, 1)[0]
        return z, roll, self.gap(shift, z, roll, 1)[1], self.gap(shift, z, roll, -1)[1]


def assert_touching(oracle, y, z, roll, tol):
    """Both wheels touch at every shift: no gap and no hidden penetration beyond tol."""
    worst = 0.0
    for k in range(len(y)):
        for side in (1, -1):
            g = oracle.gap(y[k], z[k], roll[k], side)[0]
            worst = max(worst, abs(g))
            assert abs(g) <= tol, (y[k], side, g)
    return worst


# ---------------------------------------------------------------------------------------------
# S1002 / UIC60 1:40: every contact jump, in micrometre steps
# ---------------------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def s1002():
    wheel, mount = WheelProfile.s1002(), RailMounting()
    table = contact_geometry_table(np.linspace(-0.010, 0.010, 401), wheel=wheel)
    return dict(wheel=wheel, oracle=Oracle(wheel, mount), table=table,
                transitions=contact_transitions(table, wheel=wheel))


def test_table_has_a_contact_at_every_shift(s1002):
    t = s1002["table"]
    assert (t["status"] == "ok").all()
    assert t["max |gap| [m]"].max() < 1e-10
    # independent check at every 10th row
    rows = t.iloc[::10]
    assert_touching(s1002["oracle"], rows["y [m]"].to_numpy(), rows["z [m]"].to_numpy(),
                    rows["roll [rad]"].to_numpy(), 1e-8)


def test_transitions_of_s1002_are_found_on_both_sides(s1002):
    tr = s1002["transitions"]
    assert (tr["status"] == "ok").all()
    left = tr[tr["side"] == "left"].sort_values("y [m]")
    right = tr[tr["side"] == "right"].sort_values("y [m]")
    # mirror symmetry: the right wheel's transitions at the opposite shifts
    np.testing.assert_allclose(np.sort(-right["y [m]"].to_numpy()), left["y [m]"].to_numpy(),
                               atol=1e-7)
    # three on the left wheel: near the centre, tread -> flange root, root -> 70 deg flank
    assert len(left) == 3
    y = left["y [m]"].to_numpy()
    assert 0.0 < y[0] < 0.0005 and 0.0045 < y[1] < 0.0050 and 0.0060 < y[2] < 0.0065
    # each is a real jump of the contact point on the wheel (several mm) in an interval of
    # at most xtol = 0.1 um
    assert np.all(np.abs(left["y_wheel_after [m]"] - left["y_wheel_before [m]"]) > 0.003)
    assert np.all(left["y_after [m]"] - left["y_before [m]"] <= 1e-7 + 1e-15)
    assert list(left["kind"]) == ["contact jump", "contact jump", "flange contact"]


@pytest.mark.parametrize("k", [0, 1, 2])
@pytest.mark.parametrize("side", ["left", "right"])
def test_contact_found_in_micrometre_steps_through_each_jump(s1002, k, side):
    tr = s1002["transitions"]
    tr = tr[tr["side"] == side].sort_values("y [m]", key=np.abs).reset_index(drop=True)
    y0 = float(tr["y [m]"].iloc[k])
    y = y0 + 1e-6 * np.arange(-25, 26)
    z, roll, res, _ = rigid_contact(y, errors="mark")
    assert list(res.extra["status"]) == ["ok"] * y.size
    assert_touching(s1002["oracle"], y, z, roll, 2e-8)
    # the contact point jumps inside the scanned band
    si = 0 if side == "left" else 1
    c = np.argmin(res.gap.reshape(-1, 2, 2)[:, si], axis=1)
    yw = res.y_wheel.reshape(-1, 2, 2)[np.arange(y.size), si, c]
    assert np.max(np.abs(np.diff(yw))) > 0.003


def test_formerly_failing_band_at_the_flange_onset():
    # the shifts 6.252, 6.255, 6.257 mm ended in "no contact found" / "no convergence": the
    # contact sits at the joint of the R13 root and the 70 deg flank (a slope step of 1e-5 and
    # a root conformal with the rail's R13 corner), where Newton does not converge
    y = np.array([6.252e-3, 6.255e-3, 6.257e-3])
    z, roll, _, _ = rigid_contact(y)  # errors="raise": raises if any fails
    assert_touching(Oracle(WheelProfile.s1002(), RailMounting()), y, z, roll, 2e-8)


def test_search_at_the_formerly_failing_pose_equals_brute_force():
    # the pose rigid_contact reached at 6.252 mm before, where both candidates of the left
    # wheel failed (tread: Newton diverged; flange: no convergence at the root/flank joint)
    wheel, mount, track = WheelProfile.s1002(), RailMounting(), Track.straight(20.0)
    y, z, roll = 6.252e-3, 0.460320384435, 7.629167e-04
    r, A = wheelset_pose(track, 10.0, y, z, roll, 0.0)
    for compiled in (False, "auto"):
        res = ContactSearch(track, wheel=wheel, rails=mount, compiled=compiled).search(
            r, A, [10.0], warm=False)
        g = np.min(res.gap[0])
        gn, yn = Oracle(wheel, mount).normal_gap(y, z, roll, 1)
        assert np.isfinite(g)
        assert g == pytest.approx(gn, abs=1e-9)
        assert res.y_wheel[0, np.argmin(res.gap[0])] == pytest.approx(yn, abs=2e-5)


def test_flange_onset_is_exact_and_agrees_with_the_oracle(s1002):
    t = s1002["table"]
    y_grid, _ = flange_contact_onset(t, exact=False)
    y_f, g_f = flange_contact_onset(t)
    assert y_grid == pytest.approx(0.0063, abs=1e-9)  # the table's row (50 um grid)
    assert y_grid - 5e-5 < y_f < y_grid
    assert np.degrees(g_f) == pytest.approx(70.0, abs=0.5)  # onto the 70 deg flank
    tr = s1002["transitions"]
    onset = tr[(tr["side"] == "left") & (tr["kind"] == "flange contact")]
    assert y_f == pytest.approx(float(onset["y [m]"].iloc[0]), abs=1e-15)


def test_every_transition_agrees_with_the_oracle(s1002):
    # independent: bisect the oracle's rigid contact between the two table rows around each
    # transition, on "touches beyond the midpoint of the two contact positions", to 10 nm
    oracle = s1002["oracle"]
    tr = s1002["transitions"]
    for _, row in tr[tr["side"] == "left"].iterrows():
        mid = 0.5 * (row["y_wheel_before [m]"] + row["y_wheel_after [m]"])
        before = row["y_wheel_before [m]"] > mid

        def side_of(y, mid=mid):
            return oracle.rigid(y)[2] > mid

        a = np.floor(row["y [m]"] / 5e-5) * 5e-5  # the table's rows (50 um grid)
        b = a + 5e-5
        assert side_of(a) == before and side_of(b) != before
        while b - a > 1e-8:
            m = 0.5 * (a + b)
            a, b = (m, b) if side_of(m) == before else (a, m)
        # the search's transition lies in its final interval (0.1 um), which holds the
        # oracle's to the oracle's sampling error (a few nm)
        assert row["y_before [m]"] - 2e-8 <= 0.5 * (a + b) <= row["y_after [m]"] + 2e-8


# ---------------------------------------------------------------------------------------------
# out of reach: beyond the flange, the row says so and the table continues
# ---------------------------------------------------------------------------------------------
def test_shift_beyond_the_flange_is_out_of_reach_and_the_table_goes_on():
    y = np.array([-0.055, -0.002, 0.0, 0.002, 0.030, 0.055])
    t = contact_geometry_table(y)
    st = t.set_index("y [m]")["status"]
    assert st[0.0] == st[0.002] == st[-0.002] == st[0.030] == "ok"
    for v in (0.055, -0.055):
        assert st[v].startswith("out of reach:") and "beyond the flange" in st[v]
    bad = t[t["status"] != "ok"]
    num = [c for c in t.columns if c.endswith("]") and c != "y [m]" and c != "yaw [rad]"]
    assert bad[num].isna().all().all()
    assert not bad[["flange_L", "flange_R", "two_point_L", "two_point_R"]].any().any()
    # the conicity uses the run of rows with a contact around y = 0 only, [-2, 30] mm here:
    # an amplitude of 2 mm is covered, 3 mm is not (no interpolation across -55 mm)
    con = conicity_table(t, [0.002, 0.003])
    assert np.isfinite(con["conicity wavelength [-]"].iloc[0])
    assert np.isnan(con["conicity wavelength [-]"].iloc[1])
    with pytest.raises(InputError, match="out of reach: lateral shift 0.055 m"):
        rigid_contact([0.0, 0.055])


# ---------------------------------------------------------------------------------------------
# exported (sampled, rounded) profiles
# ---------------------------------------------------------------------------------------------
def _export(path, x, v, header):
    path.write_text(f"# {header}\n" + "\n".join(f"{a:.4f} {b:.4f}" for a, b in zip(x, v)) + "\n",
                    encoding="utf-8")
    return path


@pytest.fixture(scope="module", params=[0.25, 0.5])
def exported(request, tmp_path_factory):
    """S1002 and UIC60 sampled at 0.25 or 0.5 mm and written with 4 decimals (0.1 um)."""
    h = request.param
    d = tmp_path_factory.mktemp(f"exported_{h}")
    yw = np.arange(-68.0, 60.0 + 1e-9, h)
    ur = np.arange(-36.0, 36.0 + 1e-9, h)
    wf = _export(d / "s1002.txt", yw, s1002_exact(yw)[0], "lateral_mm radius_increase_mm")
    rf = _export(d / "uic60.txt", ur, uic60_exact(ur)[0], "lateral_mm height_mm")
    wheel = WheelProfile.from_file(wf, r0=0.46)
    rail = RailProfile.from_file(rf)
    return dict(h=h, wheel=wheel, rail=rail, wheel_file=wf, rail_file=rf)


def test_exported_profiles_carry_their_resolution(exported):
    assert exported["wheel"].resolution == pytest.approx(1e-7)
    assert exported["rail"].resolution == pytest.approx(1e-7)
    assert data_resolution([1.25, 2.5, -0.75]) == pytest.approx(0.01)
    assert data_resolution([np.pi, np.e]) == 0.0
    # the split between tread and flange zones lies at the S1002 root/flank joint (-38.43 mm)
    # to within the spline's ringing (not 1 mm into the flank, as the first F'' > 0 would give)
    assert abs(exported["wheel"].y_split + 0.0384267) < 5e-4


@pytest.mark.parametrize("rail_too", [False, True])
def test_exported_profiles_have_a_contact_at_every_shift(exported, rail_too):
    # the formerly failing shifts (0.25 mm: -8.95 mm, 0.5 mm: -7.65 mm) and a coarse table;
    # the rigid contact is exact to the data's resolution (0.1 um of each profile)
    y = np.concatenate([[-8.95e-3, -7.65e-3, 6.252e-3], np.linspace(-0.010, 0.010, 21)])
    wheel = exported["wheel"]
    rail = exported["rail"] if rail_too else None
    z, roll, res, _ = rigid_contact(y, wheel=wheel, rail=rail, errors="mark")
    assert list(res.extra["status"]) == ["ok"] * y.size
    q = wheel.resolution + (rail.resolution if rail_too else 0.0)
    oracle = Oracle(wheel, RailMounting(rail))
    # vertical gap: up to 3 x the normal gap on the flank
    assert_touching(oracle, y, z, roll, 3 * q)


@pytest.mark.slow
@pytest.mark.parametrize("inclination", ["1:40", "1:20"])
def test_exported_profile_tables_and_jumps_in_micrometre_steps(exported, inclination):
    wheel, rail = exported["wheel"], exported["rail"]
    t = contact_geometry_table(np.linspace(-0.010, 0.010, 401), wheel=wheel, rail=rail,
                               inclination=inclination)
    assert (t["status"] == "ok").all()
    oracle = Oracle(wheel, RailMounting(rail, inclination=inclination))
    q = wheel.resolution + rail.resolution
    assert_touching(oracle, t["y [m]"].to_numpy(), t["z [m]"].to_numpy(),
                    t["roll [rad]"].to_numpy(), 3 * q)
    tr = contact_transitions(t, wheel=wheel, rail=rail)
    assert (tr["status"] == "ok").all()
    for y0 in tr["y [m]"]:
        y = y0 + 1e-6 * np.arange(-10, 11)
        z, roll, res, _ = rigid_contact(y, wheel=wheel, rail=rail, inclination=inclination,
                                        errors="mark")
        assert list(res.extra["status"]) == ["ok"] * y.size
        assert_touching(oracle, y, z, roll, 3 * q)


# ---------------------------------------------------------------------------------------------
# the command line
# ---------------------------------------------------------------------------------------------
def _cli(argv):
    parser = argparse.ArgumentParser(prog="mbsuite")
    sub = parser.add_subparsers(dest="cmd")
    register(sub)
    args = parser.parse_args(["railway", "contact-table", *argv])
    return args.func(args)


def test_readme_example_with_yaw_and_an_exported_wheel(tmp_path, capsys):
    # README: mbsuite railway contact-table --inclination 1:20 --wheel my_wheel.txt
    #         --yaw-mrad 5 -o out/w   (here 41 shifts over +-8 mm with the wheel exported at
    # 0.5 mm; the full 401 shifts and both exports in the slow test)
    yw = np.arange(-68.0, 60.0 + 1e-9, 0.5)
    wheel_file = _export(tmp_path / "my_wheel.txt", yw, s1002_exact(yw)[0], "exported")
    out = tmp_path / "w"
    assert _cli(["--inclination", "1:20", "--wheel", str(wheel_file),
                 "--yaw-mrad", "5", "--n", "41", "--y-max-mm", "8", "-o", str(out)]) == 0
    text = capsys.readouterr().out
    assert "no rigid contact" not in text
    assert "flange contact from lateral shift" in text and "yaw 5 mrad" in text
    t = pd.read_csv(out / "contact_table.csv")
    assert (t["status"] == "ok").all() and t["lead_L [m]"].notna().all()
    tr = pd.read_csv(out / "contact_transitions.csv")
    assert (tr["status"] == "ok").all()


@pytest.mark.slow
def test_readme_example_full_table(exported, tmp_path, capsys):
    out = tmp_path / "w"
    assert _cli(["--inclination", "1:20", "--wheel", str(exported["wheel_file"]),
                 "--yaw-mrad", "5", "-o", str(out)]) == 0
    assert "no rigid contact" not in capsys.readouterr().out
    assert (pd.read_csv(out / "contact_table.csv")["status"] == "ok").all()
    assert (pd.read_csv(out / "contact_transitions.csv")["status"] == "ok").all()


def test_cli_profile_sign_options(tmp_path, capsys):
    # the same S1002 and UIC60 written with the flange / field side mirrored and the vertical
    # axis flipped: the options restore the library's conventions, so the tables agree
    yw = np.arange(-68.0, 60.0 + 1e-9, 0.25)
    ur = np.arange(-36.0, 36.0 + 1e-9, 0.25)
    F, v = s1002_exact(yw)[0], uic60_exact(ur)[0]
    std_w = _export(tmp_path / "w.txt", yw, F, "standard")
    std_r = _export(tmp_path / "r.txt", ur, v, "standard")
    mir_w = _export(tmp_path / "w_mirrored.txt", -yw, -F, "flange positive, height")
    mir_r = _export(tmp_path / "r_mirrored.txt", -ur, -v, "field negative, depth")
    common = ["--n", "5", "--y-max-mm", "4", "--amplitudes-mm", "2"]
    # 5 shifts cannot carry the conicity at 2 mm (issue 21): a named warning, the table is written
    with pytest.warns(ConicityResolutionWarning, match="--n 5: the lateral step 2 mm"):
        assert _cli(["--wheel", str(std_w), "--rail", str(std_r), "-o", str(tmp_path / "a"),
                     *common]) == 0
    with pytest.warns(ConicityResolutionWarning):
        assert _cli(["--wheel", str(mir_w), "--wheel-flange-side", "positive", "--wheel-vertical",
                     "height", "--rail", str(mir_r), "--rail-field-side", "negative",
                     "--rail-vertical", "depth", "-o", str(tmp_path / "b"), *common]) == 0
    capsys.readouterr()
    a = pd.read_csv(tmp_path / "a" / "contact_table.csv")
    b = pd.read_csv(tmp_path / "b" / "contact_table.csv")
    np.testing.assert_allclose(a["delta_r [m]"], b["delta_r [m]"], atol=1e-12)
    np.testing.assert_allclose(a["gamma_L [rad]"], b["gamma_L [rad]"], atol=1e-9)
    # without the options the mirrored wheel is refused (no flange at negative y) ...
    with pytest.raises(InputError, match="w_mirrored.txt: no flange at negative lateral"):
        _cli(["--wheel", str(mir_w), *common])
    with pytest.raises(InputError, match="no flange at negative lateral"):
        _cli(["--wheel", str(std_w), "--wheel-vertical", "height", *common])
    # ... and the options are refused for the built-in profiles
    with pytest.raises(InputError, match="--wheel-flange-side.*built-in S1002"):
        _cli(["--wheel-flange-side", "positive", *common])
    with pytest.raises(InputError, match="--rail-vertical.*built-in UIC60"):
        _cli(["--rail-vertical", "depth", *common])


@pytest.mark.parametrize("argv,match", [
    # issue 21: the plausible ranges of data/railway/plausible_ranges.csv, in the option's unit
    (["--gauge-mm", "1.435"], r"--gauge-mm 1.435: the track gauge must lie in 600 \.\.\. 1700 mm: "
                              r"did you mean 1.435 m, i\.e\. --gauge-mm 1435\?"),
    (["--r0-mm", "0.46"], r"--r0-mm 0.46: the nominal wheel rolling radius .* did you mean 0.46 m"),
    (["--flange-back-mm", "1.36"], r"--flange-back-mm 1.36: the flange-back spacing"),
    (["--load-kN", "0"], r"--load-kN 0: the wheel-rail normal load must lie in 0.5 \.\.\. 500 kN"),
])
def test_cli_unit_slips_name_the_option_and_value(argv, match):
    with pytest.raises(InputError, match=match):
        _cli(["--n", "5", *argv])


# ---------------------------------------------------------------------------------------------
# plausibility of library inputs
# ---------------------------------------------------------------------------------------------
def test_unit_slips_in_the_library_name_the_value():
    with pytest.raises(InputError, match=r"r0 = 460 m is implausible.*millimetres"):
        WheelProfile.s1002(r0=460)
    with pytest.raises(InputError, match=r"r0 = 0.00046 m is implausible"):
        WheelProfile.s1002(r0=0.00046)
    with pytest.raises(InputError, match=r"rail mounting: gauge: track gauge 1435 m is outside the plausible "
                                         r"range 0\.6 m \.\.\. 1\.7 m: did you mean 1435 mm\?"):
        RailMounting(gauge=1435)
    with pytest.raises(InputError, match=r"track gauge 0\.001435 m is outside the plausible range"):
        RailMounting(gauge=0.001435)
    with pytest.raises(InputError, match=r"flange-back spacing 1360 m is implausible"):
        ContactSearch(Track.straight(20.0), flange_back_spacing=1360)
    with pytest.raises(InputError, match=r"semi-axis a = 6e-06 m is implausible"):
        creep_curve("kalker_linear", normal_force=1e5, a=6e-6, b=4e-3, G=8e10)
    with pytest.raises(InputError, match=r"semi-axis b = 4 m .*millimetres"):
        creep_curve("kalker_linear", normal_force=1e5, a=6e-3, b=4, G=8e10)
    with pytest.raises(InputError, match=r"normal_force = 0 N must be positive"):
        creep_curve("kalker_linear", normal_force=0, a=6e-3, b=4e-3, G=8e10)
    with pytest.raises(InputError, match=r"wheel load 50.0 N is implausibly small"):
        quasi_static_contact([0.0], 50.0)
    # plausible values pass (metre gauge, small and large wheels)
    RailMounting(gauge=1.0)
    WheelProfile.s1002(r0=0.3)
    ContactSearch(Track.straight(20.0), rails=RailMounting(gauge=1.0), flange_back_spacing=0.925)


def test_creep_curve_cli_unit_slips(tmp_path):
    parser = argparse.ArgumentParser(prog="mbsuite")
    sub = parser.add_subparsers(dest="cmd")
    register(sub)
    for argv, match in ((["--a-mm", "0.006", "--b-mm", "4"], "--a-mm 0.006: .* looks like metres"),
                        (["--load-kN", "0", "--a-mm", "6", "--b-mm", "4"], "--load-kN 0.0")):
        args = parser.parse_args(["railway", "creep-curve", *argv, "-o", str(tmp_path)])
        args._creep_parser = None  # report instead of exiting
        assert args.func(args) == 2


# ---------------------------------------------------------------------------------------------
# quasi-static: rows that did not converge stay out of every summary figure
# ---------------------------------------------------------------------------------------------
def test_quasi_static_summary_leaves_out_unconverged_rows():
    # +-6.4 mm: the left (right) wheel on the flank; the force balance does not converge there
    # (the contact jumps between root and flank of the conformal S1002 root); the rows carry
    # the last iterate with a normal force of several MN
    df = quasi_static_contact([-6.4e-3, 0.0, 6.4e-3], 100e3)
    bad = df[~df["converged"]]
    assert set(bad["y [m]"]) == {-6.4e-3, 6.4e-3}
    assert bad["status"].str.startswith("no force balance").all()
    assert df[df["converged"]]["status"].eq("ok").all()
    s = quasi_static_summary(df)
    assert s["shifts"] == 3 and s["converged shifts"] == 1
    assert sorted(s["excluded shifts [m]"]) == [-6.4e-3, 6.4e-3]
    good = df[df["y [m]"] == 0.0]
    assert s["max N [N]"] == pytest.approx(good["N [N]"].max())
    assert s["max N [N]"] < 1.01e5 < bad["N [N]"].max()  # the MN rows are not in the summary
    assert s["max |Fy| [N]"] == pytest.approx(good["Fy [N]"].abs().max())


def test_cli_quasi_static_headline_uses_converged_rows_only(tmp_path, capsys):
    # the case: at +-6.4 mm the force balance does not converge and the rows carry a
    # normal force of 4.6 MN on a 100 kN wheel; the headline must come from the other rows
    with pytest.warns(ConicityResolutionWarning):  # 5 shifts: no conicity at 2 mm (issue 21)
        assert _cli(["--n", "5", "--y-max-mm", "6.4", "--load-kN", "100", "--amplitudes-mm", "2",
                     "-o", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    df = pd.read_csv(tmp_path / "quasi_static.csv")
    bad = df[~df["converged"]]
    assert sorted(bad["y [m]"].unique()) == [-0.0064, 0.0064]
    assert bad["N [N]"].max() > 1e6  # the unconverged iterate
    good = df[df["converged"]]
    line = next(s for s in out.splitlines() if s.startswith("quasi-static contact under 100 kN"))
    assert "(3 of 5 shifts converged)" in line
    assert f"max normal force {good['N [N]'].max() / 1e3:.1f} kN" in line
    assert f"max |lateral force| {good['Fy [N]'].abs().max() / 1e3:.1f} kN" in line
    assert ("left out of the quasi-static figures (not converged): lateral shifts -6.400, "
            "6.400 mm") in out
    summary = (tmp_path / "summary.md").read_text(encoding="utf-8")
    assert f"{good['N [N]'].max() / 1e3:.1f} kN" in summary and "4617" not in summary


# ---------------------------------------------------------------------------------------------
# implementations agree
# ---------------------------------------------------------------------------------------------
def test_compiled_scan_brackets_equal_numpy():
    pytest.importorskip("numba")
    track = Track.straight(40.0)
    cs = ContactSearch(track, n_wheelsets=2)
    ref = ContactSearch(track, n_wheelsets=2, compiled=False)
    for k in range(6):
        s = np.array([10.0, 12.5])
        r, A = wheelset_pose(track, s, [0.0062 * np.sin(0.9 * k), -0.004], 0.4602, 0.0, 0.003)
        a = cs._seed_scan(cs._problems, r, A, s, brackets=True, ranks=4)
        b = ref._seed_scan(ref._problems, r, A, s, brackets=True, ranks=4)
        for x, y in zip(a, b):
            np.testing.assert_allclose(x, y, rtol=0, atol=1e-12)
