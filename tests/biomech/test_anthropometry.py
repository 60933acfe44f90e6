"""Anthropometric segment parameters and the planar gait model built from them (biomech.anthropometry).

Tables: read, checked against their own arithmetic (mass fractions of a partition of the body add
up to 1 within the printed rounding; compound rows of Winter's Table 4.1 are sums of their parts;
the parallel-axis theorem catches the known misprint).  Model: the subject's mass, the reference's
coordinates and joint topology, runs through biomech.inverse_dynamics on subject01's walk.  The
joint moments of the two models over the right gait cycle are *results* (printed by
``test_comparison_table``); the assertions are the physics that can be argued before looking:

* hip, knee and ankle moments do not depend on how the HAT is split between pelvis and torso
  (with every joint driven, a joint's moment is fixed by the subtree beyond it);
* in stance the ankle moment is the ground reaction's moment plus the foot's small inertial and
  gravitational terms, so the two models agree to a few per cent (estimate in the test).
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pandas as pd
import pytest

from core.errors import DataFileError, InputError, ModelError, UnknownOptionError
from core.paths import data_path
from biomech.anthropometry import (
    DELEVA_PARTITION,
    WINTER_FINE_PARTITION,
    WINTER_PARTITION,
    anthropometric_sagittal_model,
    fit_pin_centre,
    mass_fraction_sum,
    moment_differences,
    read_deleva_table,
    read_winter_table,
    segment_parameters,
)
from biomech.inverse_dynamics import gait_events, inverse_dynamics, load_trial
from biomech.osim import read_osim
from biomech.sagittal import planar_forward_kinematics
from biomech.storage import check_motion_against_model, read_storage

ANTHRO = data_path("biomech", "anthropometry")
TRIAL = data_path("biomech", "opensim", "gait10dof18musc_subject01_walk")
CYCLE = (0.618, 1.853)  # right heel strike to right heel strike (data/biomech notes)
LEG = ("hip_flexion_r", "knee_angle_r", "ankle_angle_r")


# ---------------------------------------------------------------------------------------------
# tables
# ---------------------------------------------------------------------------------------------


@pytest.mark.parametrize("reader, partition", [(read_winter_table, WINTER_PARTITION),
                                               (read_winter_table, WINTER_FINE_PARTITION),
                                               (read_deleva_table, DELEVA_PARTITION)])
def test_mass_fractions_of_a_partition_sum_to_one(reader, partition):
    # tolerance: every fraction is printed to d decimals, so it is within 0.5e-d of its true value;
    # the sum of n_k P_k is within sum n_k 0.5e-d_k of 1 (Winter HAT + legs: 0.0017, Winter's single
    # segments: 0.0062, de Leva's 14 segments at 4 decimals: 0.0007)
    table = reader()
    total, bound = mass_fraction_sum(table, partition)
    assert bound <= 0.0062 + 1e-15
    assert abs(total - 1.0) <= bound + 1e-12


def test_winter_compound_rows_are_sums_of_their_parts():
    w = read_winter_table()
    P = w["mass_fraction"]
    # compound rows are printed to 3 decimals, their parts to 3 or 4: the sums agree within 0.0015
    for whole, parts in {"forearm_and_hand": ["forearm", "hand"], "total_arm": ["upper_arm", "forearm", "hand"],
                         "foot_and_leg": ["leg_shank", "foot"], "total_leg": ["thigh", "leg_shank", "foot"],
                         "thorax_and_abdomen": ["thorax", "abdomen"], "abdomen_and_pelvis": ["abdomen", "pelvis"],
                         "trunk": ["thorax", "abdomen", "pelvis"],
                         "trunk_head_neck": ["thorax", "abdomen", "pelvis", "head_and_neck"],
                         "HAT": ["thorax", "abdomen", "pelvis", "head_and_neck", "total_arm", "total_arm"]}.items():
        assert abs(P[whole] - sum(P[p] for p in parts)) <= 0.0015, whole


def test_tables_are_si_fractions():
    w, d = read_winter_table(), read_deleva_table()
    assert w.loc["thigh", "density [kg/m^3]"] == pytest.approx(1050.0)
    assert w.loc["head_and_neck", "rg_about_proximal"] == pytest.approx(1.116)  # the corrected misprint
    assert d.attrs["stature [m]"] == pytest.approx(1.741)
    assert d.loc["thigh", "length [m]"] == pytest.approx(0.4222)
    assert ((d[["com_from_proximal", "rg_sagittal", "rg_transverse", "rg_longitudinal"]] > 0)
            & (d[["com_from_proximal", "rg_sagittal", "rg_transverse", "rg_longitudinal"]] < 1)).all().all()


def _copy_with(tmp_path, name, old, new):
    text = (ANTHRO / name).read_text(encoding="utf-8")
    assert old in text
    p = tmp_path / name
    p.write_text(text.replace(old, new, 1), encoding="utf-8")
    return p


def test_the_printed_head_neck_radius_is_refused(tmp_path):
    p = _copy_with(tmp_path, "winter_dempster_table4_1.csv", "0.495,1.116", "0.495,0.116")
    with pytest.raises(DataFileError, match=r"winter_dempster_table4_1\.csv, line \d+ \(segment 'head_and_neck'\)"):
        read_winter_table(p)


def test_reader_errors_name_file_line_and_segment(tmp_path):
    p = _copy_with(tmp_path, "deleva1996_male_table4.csv", "0.1416,0.4095", "0.1416,abc")
    with pytest.raises(DataFileError, match=r"deleva1996_male_table4\.csv, line 7 \(segment 'thigh'\), "
                                            r"column 'com_from_proximal': 'abc' is not a number"):
        read_deleva_table(p)
    p = _copy_with(tmp_path, "winter_dempster_table4_1.csv", "0.016,0.430,0.570", "0.016,0.430,0.580")
    with pytest.raises(DataFileError, match=r"segment 'forearm'.*not 1"):
        read_winter_table(p)
    p = _copy_with(tmp_path, "deleva1996_male_table4_lengths.csv", "foot,heel / tip of longest toe,258.1\n", "")
    with pytest.raises(DataFileError, match=r"lengths\.csv: no length for segment 'foot'"):
        read_deleva_table(lengths_path=p)
    p = _copy_with(tmp_path, "deleva1996_male_table4.csv", "rg_longitudinal", "rg_long")
    with pytest.raises(DataFileError, match=r"line 1: missing column\(s\) \['rg_longitudinal'\]"):
        read_deleva_table(p)
    with pytest.raises(DataFileError, match="does not exist"):
        read_winter_table(tmp_path / "nope.csv")


# ---------------------------------------------------------------------------------------------
# segment parameters
# ---------------------------------------------------------------------------------------------


def test_deleva_parameters_from_stature():
    M, H = 72.6, 1.80
    p = segment_parameters(M, stature=H)
    d = read_deleva_table()
    k = H / 1.741
    assert p.loc["thigh", "length [m]"] == pytest.approx(0.4222 * k)
    assert p.loc["foot", "length [m]"] == pytest.approx(0.2581 * k)
    assert p.loc["HAT", "length [m]"] == pytest.approx((0.6033 + 0.2429) * k)
    # masses add up to the body mass exactly (the fractions are normalised, and sum to 1 anyway)
    assert p["mass [kg]"] @ p["count"] == pytest.approx(M, rel=1e-14)
    # thigh: m = P M, d = c L, I = m (rho L)^2 with the transverse (medio-lateral) radius
    L = 0.4222 * k
    assert p.loc["thigh", "mass [kg]"] == pytest.approx(0.1416 * M)
    assert p.loc["thigh", "com_from_proximal [m]"] == pytest.approx(0.4095 * L)
    assert p.loc["thigh", "inertia_com [kg m^2]"] == pytest.approx(0.1416 * M * (0.329 * L) ** 2)
    assert p.loc["shank", "inertia_com [kg m^2]"] == pytest.approx(d.loc["shank", "mass_fraction"] * M
                                                                  * (0.249 * 0.4340 * k) ** 2)
    ps = segment_parameters(M, stature=H, deleva_rg="sagittal")
    assert ps.loc["shank", "inertia_com [kg m^2]"] / p.loc["shank", "inertia_com [kg m^2]"] == pytest.approx(
        (0.255 / 0.249) ** 2)


def test_deleva_hat_is_the_lumped_trunk_head_and_arms():
    # written out from Table 4 (male, mm): trunk CERV-MIDH 603.3 (COM 51.38 % from CERV),
    # head VERT-CERV 242.9 (50.02 % from VERT), shoulders 515.5 above MIDH, arms hanging:
    # upper arm 281.7 (57.72 %), forearm 268.9 (45.74 %), hand 86.2 (79.00 %); transverse radii
    M = 80.0
    parts = [(0.4346, 603.3 * (1 - 0.5138), 0.306 * 603.3),
             (0.0694, 603.3 + 242.9 * (1 - 0.5002), 0.315 * 242.9),
             (2 * 0.0271, 515.5 - 0.5772 * 281.7, 0.269 * 281.7),
             (2 * 0.0162, 515.5 - 281.7 - 0.4574 * 268.9, 0.265 * 268.9),
             (2 * 0.0061, 515.5 - 281.7 - 268.9 - 0.79 * 86.2, 0.513 * 86.2)]
    m = sum(P for P, _, _ in parts)
    s = sum(P * x for P, x, _ in parts) / m
    inertia = sum(P * (r**2 + (x - s) ** 2) for P, x, r in parts) * M * 1e-6
    p = segment_parameters(M, stature=1.741)
    assert p.loc["HAT", "mass [kg]"] == pytest.approx(m * M)
    assert p.loc["HAT", "com_from_proximal [m]"] == pytest.approx(s / 1000)
    assert p.loc["HAT", "inertia_com [kg m^2]"] == pytest.approx(inertia)
    # the parallel-axis terms only add: the lumped inertia exceeds the sum of the parts' own
    assert inertia > sum(P * r**2 for P, _, r in parts) * M * 1e-6


def test_winter_parameters_need_measured_lengths():
    lengths = {"HAT": 0.52, "thigh": 0.47, "shank": 0.41, "foot": 0.14}
    p = segment_parameters(70.0, table="winter", segment_lengths=lengths)
    assert p.loc["HAT", "mass [kg]"] == pytest.approx(0.678 * 70.0)
    assert p.loc["HAT", "com_from_proximal [m]"] == pytest.approx(0.626 * 0.52)
    assert p.loc["shank", "inertia_com [kg m^2]"] == pytest.approx(0.0465 * 70.0 * (0.302 * 0.41) ** 2)
    assert p["mass [kg]"] @ p["count"] == pytest.approx(70.0, rel=1e-14)
    with pytest.raises(InputError, match="Winter's Table 4.1 gives no segment lengths"):
        segment_parameters(70.0, stature=1.75, table="winter")
    with pytest.raises(UnknownOptionError, match="unknown segment"):
        segment_parameters(70.0, stature=1.75, segment_lengths={"arm": 0.3})
    with pytest.raises(InputError, match="body mass"):
        segment_parameters(-1.0, stature=1.75)
    with pytest.raises(InputError, match="unknown anthropometric table"):
        segment_parameters(70.0, stature=1.75, table="dempster")


# ---------------------------------------------------------------------------------------------
# the model
# ---------------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def reference():
    return read_osim(TRIAL / "subject01.osim")


@pytest.fixture(scope="module", params=["deleva", "winter"])
def model(request, reference):
    return anthropometric_sagittal_model(reference, request.param)


def test_model_has_the_subjects_mass_and_the_reference_topology(model, reference):
    assert model.total_mass == pytest.approx(reference.total_mass, rel=1e-13)
    assert reference.total_mass == pytest.approx(72.6, abs=1e-9)
    assert model.coordinate_names == reference.coordinate_names
    assert {b.name for b in model.bodies} == {"pelvis", "torso", "femur_r", "tibia_r", "calcn_r",
                                              "femur_l", "tibia_l", "calcn_l"}
    links = {j.name: (j.parent_body, j.child_body, j.type) for j in model.joints}
    for s in "rl":
        assert links[f"hip_{s}"][:2] == ("pelvis", f"femur_{s}")
        assert links[f"knee_{s}"] == (f"femur_{s}", f"tibia_{s}", "PinJoint")
        assert links[f"ankle_{s}"] == (f"tibia_{s}", f"calcn_{s}", "PinJoint")
        knee = model.joint(f"knee_{s}")
        assert all(not ax.coordinates for ax in knee.transform_axes if not ax.is_rotation)
    assert links["back"][:2] == ("pelvis", "torso")
    motion = read_storage(TRIAL / "subject01_walk_IK.mot", model=model)
    assert check_motion_against_model(motion, model) == ()


def test_joint_locations_are_the_reference(model, reference):
    # hip, ankle and lumbar joint locations are the reference's; the ankle centre expressed in the
    # calcaneus frame is where the reference's talus-calcaneus weld puts it
    q = {c.name: 0.3 * math.sin(k + 1.0) for k, c in enumerate(reference.coordinates)}
    q.update(pelvis_ty=1.0, knee_angle_r=-0.5, knee_angle_l=-1.0)  # inside the knee's range (the fit's)
    fa, fr = planar_forward_kinematics(model, q), planar_forward_kinematics(reference, q)
    for b in ("pelvis", "femur_r", "femur_l", "torso"):
        np.testing.assert_allclose(fa[b][0], fr[b][0], atol=1e-12)
        np.testing.assert_allclose(fa[b][1], fr[b][1], atol=1e-12)
    for s in "rl":
        # the tibia follows the pin: within the fit's deviation of the reference's moving knee
        d = np.linalg.norm(fa[f"tibia_{s}"][0] - fr[f"tibia_{s}"][0])
        assert d <= 3.5e-3
        np.testing.assert_allclose(fa[f"calcn_{s}"][1], fr[f"calcn_{s}"][1], atol=1e-12)


def test_pin_fit(reference):
    # a pin joint is its own best pin: centre = its frame origins, no residual
    hip = reference.joint("hip_r")
    f = fit_pin_centre(hip, (-1.0, 1.0))
    np.testing.assert_allclose(f["parent"], hip.parent_frame.location[:2], atol=1e-12)
    np.testing.assert_allclose(f["child"], hip.child_frame.location[:2], atol=1e-12)
    assert f["max_residual"] < 1e-12
    # the knee: the least-squares centre beats the extended knee's centre, which is one candidate
    knee = reference.joint("knee_r")
    rng = tuple(reference.coordinate("knee_angle_r").range)
    f = fit_pin_centre(knee, rng)
    q = np.linspace(*rng, 261)
    tx = np.array([knee.transform_axes[3].function(v) for v in q])
    ty = np.array([knee.transform_axes[4].function(v) for v in q])
    extended = np.hypot(tx - tx[np.argmin(abs(q))], ty - ty[np.argmin(abs(q))])  # pin at t(0), child at origin
    assert f["rms_residual"] <= np.sqrt(np.mean(extended**2))
    with pytest.raises(ModelError, match="hardly rotates"):
        fit_pin_centre(knee, (0.0, 1e-5))


def test_model_errors_name_the_element(reference):
    bad = dataclasses.replace(reference, markers=tuple(m for m in reference.markers if m.name != "Top.Head"))
    with pytest.raises(ModelError, match="no marker 'Top.Head'"):
        anthropometric_sagittal_model(bad)
    with pytest.raises(InputError, match="hat_body"):
        anthropometric_sagittal_model(reference, hat_body="head")


# ---------------------------------------------------------------------------------------------
# inverse dynamics over the right gait cycle
# ---------------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def trial():
    return load_trial(TRIAL / "subject01.osim", TRIAL / "subject01_walk_IK.mot", TRIAL / "subject01_walk_grf.xml",
                      window=CYCLE)


@pytest.fixture(scope="module")
def moments(trial, reference):
    out = {"reference": inverse_dynamics(trial)}
    # one model through load_trial with an in-memory model, the others on the same processed trial
    deleva = anthropometric_sagittal_model(reference, "deleva")
    t = load_trial(deleva, TRIAL / "subject01_walk_IK.mot", TRIAL / "subject01_walk_grf.xml", window=CYCLE)
    out["deleva"] = inverse_dynamics(t)
    for key, kw in (("winter", dict(table="winter")), ("deleva_hat_pelvis", dict(hat_body="pelvis"))):
        out[key] = inverse_dynamics(dataclasses.replace(trial, osim=anthropometric_sagittal_model(reference, **kw)))
    return out


def test_models_run_through_inverse_dynamics(moments):
    n = len(moments["reference"])
    for key, df in moments.items():
        assert len(df) == n
        assert df.attrs["max_residual"] < 1e-6, key
        assert df.attrs["body_mass"] == pytest.approx(72.6)
        assert np.isfinite(df.drop(columns="time [s]").to_numpy()).all()
    assert moments["deleva"].attrs["model"] == "walk_subject01_anthropometric_deleva"


def test_leg_moments_do_not_depend_on_where_the_hat_sits(moments):
    # every joint is driven: a joint's moment is fixed by the subtree beyond it (the leg and its
    # ground reaction), so moving the HAT from the torso to the pelvis changes only the pelvis
    # residuals and the lumbar moment (which vanishes: the torso is then massless)
    a, b = moments["deleva"], moments["deleva_hat_pelvis"]
    for c in LEG + ("hip_flexion_l", "knee_angle_l", "ankle_angle_l"):
        np.testing.assert_allclose(b[f"{c}_moment [N m]"], a[f"{c}_moment [N m]"], atol=1e-8, rtol=0)
    assert np.abs(b["lumbar_extension_moment [N m]"]).max() < 1e-8
    assert np.abs(b["pelvis_tilt_moment [N m]"] - a["pelvis_tilt_moment [N m]"]).max() > 1.0


@pytest.mark.parametrize("table", ["deleva", "winter"])
def test_stance_ankle_moment_is_dominated_by_the_ground_reaction(moments, trial, table):
    """In stance tau_ankle = -(moment of the GRF about the ankle) + foot terms, the foot terms being
    I alpha + (r_G - r_A) x m (a_G - g).  Estimate, made from the reference alone before comparing:
    the reference's foot terms in stance (tau + M_GRF) reach 2.5 N m (rms 1.2 N m) for a 1.51 kg
    foot; the tables' feet (0.99 and 1.05 kg, centres of mass at similar distances ahead of the ankle)
    give at most as much; the pin knee moves the ankle by at most the fit's 3.2 mm, which under
    the stance GRF (|F| <= 776 N) changes the GRF's moment by <= 2.5 N m.  Worst case at one instant
    2.5 + 2.5 + 2.5 = 7.5 N m of a 130 N m peak (6 %); in rms (1.2 + 1.2 + 2.5) = 4.9 N m (4 %)."""
    ref, other = moments["reference"], moments[table]
    _, toe_offs = gait_events(trial.loads, "calcn_r")
    stance = (CYCLE[0], float(toe_offs[toe_offs > CYCLE[0]][0]))
    d = moment_differences(ref, other, ["ankle_angle_r"], window=stance).loc["ankle_angle_r"]
    peak = moment_differences(ref, other, ["ankle_angle_r"]).loc["ankle_angle_r", "peak reference [N m]"]
    assert d["rms difference [N m]"] <= 0.04 * peak
    assert d["max difference [N m]"] <= 0.06 * peak


def test_comparison_table(moments, trial):
    """Not an assertion of agreement: the rms differences of the right-leg moments over the gait
    cycle, printed for the report (pytest -s)."""
    _, toe_offs = gait_events(trial.loads, "calcn_r")
    to = float(toe_offs[toe_offs > CYCLE[0]][0])
    rows = []
    for table in ("deleva", "winter"):
        for phase, window in (("cycle", CYCLE), ("stance", (CYCLE[0], to)), ("swing", (to, CYCLE[1]))):
            d = moment_differences(moments["reference"], moments[table], LEG, window=window)
            d.insert(0, "phase", phase)
            d.insert(0, "table", table)
            rows.append(d)
    out = pd.concat(rows)
    with pd.option_context("display.width", 200, "display.max_columns", 20, "display.precision", 3):
        print("\nright-leg joint moments, anthropometric model vs gait10dof18musc (subject01, 72.6 kg):")
        print(out)
    assert np.isfinite(out.drop(columns=["table", "phase"]).to_numpy(float)).all()
