"""Careless inputs to the biomech domain (issue 21): each one refused with one line naming the
file, key or argument, the value and the likely slip -- or a finished run with a named warning.

The slipped files are the shipped subject01 trial (``data/biomech/opensim``) copied to tmp_path
and edited: translations or centre of pressure in mm, radians under ``inDegrees=yes``, ground
reactions in body weights, masses in grams or pounds, muscle parameters in mm or degrees, times
in ms, NaN gaps, misspelt names.  OpenSim is not needed.
"""

from __future__ import annotations

import re
import shutil
import warnings
from pathlib import Path

import numpy as np
import pytest

from biomech.checks import RADIANS_AS_DEGREES_MIN_SPAN, ImplausibleDataError, SamplingRateWarning, ranges
from biomech.inverse_dynamics import inverse_dynamics, load_trial
from biomech.kinematics import process_coordinates
from biomech.muscle_forces import muscle_inputs, muscle_redundancy, reserve_optimal_forces
from biomech.osim import read_force_set, read_osim
from biomech.storage import StorageWarning, check_motion_against_model, read_external_loads, read_storage
from core.errors import DataFileError, DataRangeError, InputError, ModelError, UnknownOptionError
from core.inputs import ImplausibleValueError
from core.paths import data_path

G10 = data_path("biomech", "opensim", "gait10dof18musc_subject01_walk")
G2392 = data_path("biomech", "opensim", "gait2392_subject01_walk")
MODEL, IK, GRF_XML, GRF_MOT = (G10 / "subject01.osim", G10 / "subject01_walk_IK.mot", G10 / "subject01_walk_grf.xml",
                               G10 / "subject01_walk_grf.mot")
RESERVES = G10 / "gait10dof_Reserve_Actuators.xml"


# ---------------------------------------------------------------------------------------------
# helpers: read a storage file as (header lines, labels, values), write it back
# ---------------------------------------------------------------------------------------------
def _split(path: Path):
    lines = path.read_text().splitlines()
    end = next(i for i, s in enumerate(lines) if s.strip().lower() == "endheader")
    labels = lines[end + 1].split("\t") if "\t" in lines[end + 1] else lines[end + 1].split()
    labels = [s.strip() for s in labels if s.strip()]
    values = np.array([[float(x) for x in s.split()] for s in lines[end + 2:] if s.strip()])
    return lines[:end + 1], labels, values


def _write(path: Path, header, labels, values) -> Path:
    body = ["\t".join(labels)] + ["\t".join(f"{x:.10g}" for x in row) for row in values]
    path.write_text("\n".join(list(header) + body) + "\n")
    return path


def slipped_ik(tmp_path, edit, name="ik.mot", header_edit=None) -> Path:
    """The shipped IK file with ``edit(labels, values)`` applied (in place) and the header edited."""
    header, labels, values = _split(IK)
    edit(labels, values)
    if header_edit is not None:
        header = [header_edit(s) for s in header]
    return _write(tmp_path / name, header, labels, values)


def slipped_grf(tmp_path, edit, xml_edit=None) -> Path:
    """A copy of the external-loads XML and its data file with ``edit(labels, values)`` applied."""
    header, labels, values = _split(GRF_MOT)
    edit(labels, values)
    _write(tmp_path / "subject01_walk_grf.mot", header, labels, values)
    text = GRF_XML.read_text()
    if xml_edit is not None:
        text = xml_edit(text)
    out = tmp_path / "grf.xml"
    out.write_text(text)
    return out


def cols(labels, *names):
    return [labels.index(n) for n in names]


def scale(*names, by):
    def edit(labels, values):
        values[:, cols(labels, *names)] *= by
    return edit


def slipped_model(tmp_path, pattern, repl, name="model.osim", count=0) -> Path:
    text = MODEL.read_text()
    new, n = re.subn(pattern, repl, text, count=count, flags=re.S)
    assert n > 0, pattern
    out = tmp_path / name
    out.write_text(new)
    return out


@pytest.fixture(scope="module")
def model():
    return read_osim(MODEL)


@pytest.fixture(scope="module")
def short_trial():
    return load_trial(MODEL, IK, GRF_XML, window=(0.8, 1.0))


@pytest.fixture(scope="module")
def short_inputs(short_trial):
    moments = inverse_dynamics(short_trial)
    return short_trial, moments, muscle_inputs(short_trial, moments)


def deg_to_rad_angles(labels, values):
    """Write the angles in radians (the header keeps inDegrees=yes)."""
    for j, c in enumerate(labels):
        if c != "time" and not c.endswith(("_tx", "_ty", "_tz")):
            values[:, j] = np.deg2rad(values[:, j])


# =============================================================================================
# 1. motion files: unit slips the header does not declare
# =============================================================================================
MOTION_SLIPS = [
    pytest.param(scale("pelvis_tx", "pelvis_ty", by=1000.0), ImplausibleDataError,
                 r"ik\.mot: column 'pelvis_tx' reaches 628\.\d* m, outside the plausible range -100 m \.\.\. 100 m "
                 r"of the translation coordinate: the values look like mm", id="pelvis-translations-in-mm"),
    pytest.param(scale("pelvis_ty", by=1000.0), ImplausibleDataError,
                 r"column 'pelvis_ty' reaches 104\d\.?\d* m, outside the plausible range -0\.5 m \.\.\. 2\.5 m of the pelvis "
                 r"vertical translation \(pelvis_ty\): the values look like mm \(104\d\.?\d* mm = 1\.04\d* m\)",
                 id="pelvis-height-in-mm"),
    pytest.param(scale("pelvis_ty", by=100.0), ImplausibleDataError,
                 r"column 'pelvis_ty' reaches 104\.\d* m, .*: the values look like cm \(104\.\d* cm = 1\.04\d* m\)",
                 id="pelvis-height-in-cm"),
    pytest.param(deg_to_rad_angles, DataFileError,
                 r"ik\.mot: the header has inDegrees=yes, but every angle column stays within ±π \(largest \|value\| "
                 r"1\.2\d*; 'knee_angle_\w' spans 1\.\d+.*the values look like radians; correct the header to inDegrees=no",
                 id="radians-under-inDegrees-yes"),
]


@pytest.mark.parametrize("edit, error, pattern", MOTION_SLIPS)
def test_motion_slips_are_named(tmp_path, model, edit, error, pattern):
    p = slipped_ik(tmp_path, edit)
    with pytest.raises(error, match=pattern):
        read_storage(p, model)


def test_degrees_under_inDegrees_no_is_still_caught(tmp_path, model):
    p = slipped_ik(tmp_path, lambda labels, values: None, header_edit=lambda s: s.replace("inDegrees=yes", "inDegrees=no"))
    with pytest.raises(DataFileError, match=r"the header has inDegrees=no, but angle column 'pelvis_tilt' reaches "
                                            r"10\.\d+ and spans .* the values look like degrees; correct the header to "
                                            r"inDegrees=yes \(or pass check_degrees='warn' / 'off' if they really are radians\)"):
        read_storage(p, model)


def test_degrees_without_a_flag_are_caught(tmp_path, model):
    p = slipped_ik(tmp_path, lambda labels, values: None, header_edit=lambda s: "" if s.startswith("inDegrees") else s)
    with pytest.raises(DataFileError, match=r"no inDegrees flag \(taken as no\), but angle column 'pelvis_tilt'"):
        read_storage(p, model)


def test_radians_under_inDegrees_yes_warn_and_off(tmp_path, model):
    p = slipped_ik(tmp_path, deg_to_rad_angles)
    with pytest.warns(StorageWarning, match=r"the values look like radians.*if they really are degrees"):
        df = read_storage(p, model, check_degrees="warn")
    # the flag is obeyed: degrees converted again (the user was warned)
    assert df["knee_angle_r"].abs().max() < 0.03
    df = read_storage(p, model, check_degrees="off")
    assert df.attrs["in_degrees"] is True


def test_radians_without_a_model_by_the_naming_rule(tmp_path):
    p = slipped_ik(tmp_path, deg_to_rad_angles)
    with pytest.raises(DataFileError, match="the values look like radians"):
        read_storage(p)


def test_a_standing_trial_in_degrees_is_not_taken_for_radians(tmp_path, model):
    """Small degree values that barely move (quiet standing) stay below the span threshold."""
    def standing(labels, values):
        rng = np.random.default_rng(0)
        for j, c in enumerate(labels):
            if c != "time" and not c.endswith(("_tx", "_ty")):
                values[:, j] = 2.0 + 0.1 * rng.standard_normal(len(values))
    p = slipped_ik(tmp_path, standing)
    df = read_storage(p, model)
    assert df["knee_angle_r"].max() < np.deg2rad(3.0)
    assert RADIANS_AS_DEGREES_MIN_SPAN == 0.8


def test_translations_in_mm_can_be_accepted(tmp_path, model):
    p = slipped_ik(tmp_path, scale("pelvis_tx", "pelvis_ty", by=1000.0))
    df = read_storage(p, model, accept=["translation_coordinate", "pelvis_height"])
    assert df["pelvis_ty"].max() > 1000


# =============================================================================================
# 2. time columns and gaps
# =============================================================================================
def _swap_rows(labels, values):
    values[[10, 11], 0] = values[[11, 10], 0]


def _repeat_time(labels, values):
    values[21, 0] = values[20, 0]


def _nan_gap(labels, values):
    values[30:35, labels.index("knee_angle_r")] = np.nan


TIME_SLIPS = [
    pytest.param(_swap_rows, r"ik\.mot, line 23: time 0\.1666\d* does not increase \(previous row 0\.1833\d*\)",
                 id="time-rows-swapped"),
    pytest.param(_repeat_time, r"ik\.mot, line 33: time 0\.3333\d* does not increase \(previous row 0\.3333\d*\)",
                 id="time-repeated"),
    pytest.param(_nan_gap, r"ik\.mot: column 'knee_angle_r' has a gap of 5 missing \(NaN\) values at t = 0\.5 \.\.\. "
                           r"0\.5666\d* s: fill the gap", id="nan-gap"),
]


@pytest.mark.parametrize("edit, pattern", TIME_SLIPS)
def test_time_and_gap_slips(tmp_path, model, edit, pattern):
    p = slipped_ik(tmp_path, edit)
    with pytest.raises(DataFileError, match=pattern):
        read_storage(p, model)


def test_nan_gap_can_be_read_on_request(tmp_path, model):
    p = slipped_ik(tmp_path, _nan_gap)
    df = read_storage(p, model, allow_nan=True)
    assert df["knee_angle_r"].isna().sum() == 5
    with pytest.raises(InputError, match=r"column 'knee_angle_r' is nan at t = 0\.5 s"):
        process_coordinates(df)


# =============================================================================================
# 3. ground reactions: units and names
# =============================================================================================
def _grf_cols(labels, kind):
    return [j for j, c in enumerate(labels) if re.fullmatch(rf"(1_)?ground_{kind}[xyz]", c)]


def grf_scale(kind, by):
    def edit(labels, values):
        values[:, _grf_cols(labels, kind)] *= by
    return edit


GRF_SLIPS = [
    pytest.param(grf_scale("force_p", 1000.0), None,
                 r"subject01_walk_grf\.mot: column 'ground_force_px' reaches 808\.\d* m, outside the plausible range "
                 r"-10 m \.\.\. 10 m of the centre of pressure: the values look like mm", id="cop-in-mm"),
    pytest.param(lambda labels, values: values.__setitem__((slice(None), cols(labels, "1_ground_force_px", "1_ground_force_pz")),
                                                           values[:, cols(labels, "1_ground_force_px", "1_ground_force_pz")] * 1000),
                 None, r"column '1_ground_force_px' reaches 810\.\d* m, .*: the values look like mm \(810\.\d* mm = "
                       r"0\.810\d* m\); write them in m \(to use it deliberately, accept='centre_of_pressure'\)",
                 id="cop-of-one-foot-in-mm"),
    pytest.param(grf_scale("force_v", 1 / (72.6 * 9.80665)), None,
                 r"the largest ground reaction force \(1_ground_force_vx\.\.z\) is 1\.1\d* N, outside the plausible range "
                 r"50 N \.\.\. 20 kN: the values look like body weights \(or N/kg, or kN\)", id="grf-in-body-weights"),
    pytest.param(grf_scale("force_v", 1 / 72.6), None,
                 r"is 11\.\d* N, outside the plausible range 50 N .*body weights \(or N/kg", id="grf-in-N-per-kg"),
    pytest.param(grf_scale("torque_", 1000.0), None,
                 r"column 'ground_torque_y' reaches 13537\.8 N m, outside the plausible range -500 N m \.\.\. 500 N m "
                 r"of the free moment of a force plate: the values look like N\*mm \(13537\.8 N\*mm = 13\.5378 N m\)",
                 id="free-torque-in-N-mm"),
]


@pytest.mark.parametrize("edit, xml_edit, pattern", GRF_SLIPS)
def test_ground_reaction_slips(tmp_path, edit, xml_edit, pattern):
    p = slipped_grf(tmp_path, edit, xml_edit)
    with pytest.raises(ImplausibleDataError, match=pattern):
        read_external_loads(p)


def test_grf_in_body_weights_accepted_deliberately(tmp_path):
    p = slipped_grf(tmp_path, grf_scale("force_v", 1 / (72.6 * 9.80665)))
    loads = read_external_loads(p, accept=["ground_reaction_force"])
    assert np.abs(loads["right"].force).max() < 2


BODY_SLIPS = [
    pytest.param("<applied_to_body>calcn_r</applied_to_body>", "<applied_to_body>calcn_R</applied_to_body>",
                 r"grf\.xml: external force 'right': applied_to_body 'calcn_R' is not a body of model "
                 r"'walk_subject01'; did you mean 'calcn_r'\?", id="applied-to-body-wrong-case"),
    pytest.param("<applied_to_body>calcn_l</applied_to_body>", "<applied_to_body>calcaneus_l</applied_to_body>",
                 r"external force 'left': applied_to_body 'calcaneus_l' .*; did you mean 'calcn_l'\?",
                 id="applied-to-body-misspelt"),
    pytest.param("<force_expressed_in_body>ground</force_expressed_in_body>",
                 "<force_expressed_in_body>groud</force_expressed_in_body>",
                 r"external force 'right': force_expressed_in_body 'groud' .*; did you mean 'ground'\?",
                 id="force-expressed-in-misspelt"),
]


@pytest.mark.parametrize("old, new, pattern", BODY_SLIPS)
def test_external_force_bodies_must_exist(tmp_path, old, new, pattern):
    xml = slipped_grf(tmp_path, lambda labels, values: None, lambda text: text.replace(old, new, 1))
    with pytest.raises(ModelError, match=pattern):
        load_trial(MODEL, IK, xml, window=(0.8, 1.0))


# =============================================================================================
# 4. model files: masses and muscle parameters
# =============================================================================================
def _grams(m):
    return f"<mass>{float(m.group(1)) * 1000:.10g}</mass>"


MODEL_SLIPS = [
    pytest.param(r"<mass>\s*([0-9.eE+-]+)\s*</mass>", _grams, 0, ImplausibleDataError,
                 r"model\.osim, line \d+: body 'pelvis' <mass>: segment mass 11\.3752 t is outside the plausible "
                 r"range 0 kg \.\.\. 150 kg: did you mean 11375\.2 g\? \(to use it deliberately, accept='segment_mass'\)",
                 id="segment-masses-in-grams"),
    pytest.param(r"(<Millard2012EquilibriumMuscle name=\"hamstrings_r\">.*?<max_isometric_force>)[^<]*",
                 r"\g<1>2.594", 1, ImplausibleDataError,
                 r"muscle 'hamstrings_r' <max_isometric_force>: max isometric force 2\.594 N is outside the plausible "
                 r"range 10 N \.\.\. 10 kN: did you mean 2\.594 kN\?", id="max-isometric-force-in-kN"),
    pytest.param(r"(<Millard2012EquilibriumMuscle name=\"soleus_r\">.*?<optimal_fiber_length>)[^<]*",
                 r"\g<1>55", 1, ImplausibleDataError,
                 r"muscle 'soleus_r' <optimal_fiber_length>: optimal fibre length 55 m is outside the plausible range "
                 r"0\.01 m \.\.\. 0\.6 m: did you mean 55 mm\?", id="optimal-fibre-length-in-mm"),
    pytest.param(r"(<Millard2012EquilibriumMuscle name=\"soleus_r\">.*?<optimal_fiber_length>)[^<]*",
                 r"\g<1>5.5", 1, ImplausibleDataError,
                 r"muscle 'soleus_r' <optimal_fiber_length>: optimal fibre length 5\.5 m .*: did you mean 5\.5 cm\?",
                 id="optimal-fibre-length-in-cm"),
    pytest.param(r"(<Millard2012EquilibriumMuscle name=\"soleus_r\">.*?<tendon_slack_length>)[^<]*",
                 r"\g<1>268", 1, ImplausibleDataError,
                 r"muscle 'soleus_r' <tendon_slack_length>: tendon slack length 268 m .*: did you mean 268 mm\?",
                 id="tendon-slack-length-in-mm"),
    pytest.param(r"(<Millard2012EquilibriumMuscle name=\"soleus_r\">.*?<pennation_angle_at_optimal>)[^<]*",
                 r"\g<1>25", 1, ImplausibleDataError,
                 r"muscle 'soleus_r' <pennation_angle_at_optimal>: pennation angle at optimal fibre length 25 rad is "
                 r"outside the plausible range 0 rad \.\.\. 0\.7 rad: did you mean 25 deg\?", id="pennation-in-degrees"),
    pytest.param(r"(<Millard2012EquilibriumMuscle name=\"soleus_r\">.*?<max_contraction_velocity>)[^<]*",
                 r"\g<1>100", 1, ImplausibleDataError,
                 r"muscle 'soleus_r' <max_contraction_velocity>: max contraction velocity 100 1/s is outside the "
                 r"plausible range 1 1/s \.\.\. 30 1/s \(in optimal fibre lengths per second", id="max-contraction-velocity"),
    pytest.param(r"<socket_parent>/bodyset/femur_r</socket_parent>", "<socket_parent>/bodyset/femur_R</socket_parent>",
                 1, ModelError, r"'/bodyset/femur_R' is neither ground nor a body of the model; did you mean 'femur_r'\?",
                 id="joint-frame-body-wrong-case"),
    pytest.param(r"<socket_coordinate>/jointset/knee_r/knee_angle_r</socket_coordinate>",
                 "<socket_coordinate>/jointset/knee_r/knee_angel_r</socket_coordinate>", 1, ModelError,
                 r"coordinate '/jointset/knee_r/knee_angel_r' is not a coordinate of the model; did you mean 'knee_angle_r'\?",
                 id="path-point-coordinate-misspelt"),
]


@pytest.mark.parametrize("pattern_, repl, count, error, pattern", MODEL_SLIPS)
def test_model_file_slips(tmp_path, pattern_, repl, count, error, pattern):
    p = slipped_model(tmp_path, pattern_, repl, count=count)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        with pytest.raises(error, match=pattern):
            read_osim(p)


def test_pennation_in_degrees_can_be_accepted(tmp_path):
    p = slipped_model(tmp_path, r"(<Millard2012EquilibriumMuscle name=\"soleus_r\">.*?<pennation_angle_at_optimal>)[^<]*",
                      r"\g<1>25", count=1)
    assert read_osim(p, accept=["pennation_angle"]).muscle("soleus_r").pennation_angle_at_optimal == 25.0


def test_model_lookup_suggests_the_closest_name(model):
    with pytest.raises(ModelError, match=r"has no body 'femur_R'; did you mean 'femur_r'\?"):
        model.body("femur_R")
    with pytest.raises(ModelError, match=r"has no coordinate 'hip_flexion'; did you mean 'hip_flexion_r'\?"):
        model.coordinate("hip_flexion")
    with pytest.raises(ModelError, match=r"has no muscle 'soleus'; did you mean 'soleus_r'\?"):
        model.muscle("soleus")


def test_model_in_pounds_is_caught_against_the_ground_reactions(tmp_path):
    p = slipped_model(tmp_path, r"<mass>\s*([0-9.eE+-]+)\s*</mass>",
                      lambda m: f"<mass>{float(m.group(1)) / 0.45359237:.10g}</mass>")
    with pytest.raises(ImplausibleValueError, match=r"subject01_walk_grf\.mot: the peak vertical ground reaction 925\.4 N "
                                                    r"is 0\.59 body weights of .*model\.osim's 160\.1 kg, outside the "
                                                    r"plausible range 0\.7 \.\.\. 6: .*a mass in pounds \(160\.1 lb = 72\.6 kg\)"):
        load_trial(p, IK, GRF_XML, window=(0.8, 1.0))


def test_model_in_grams_accepted_segment_by_segment_is_still_caught_as_a_body_mass(tmp_path):
    p = slipped_model(tmp_path, r"<mass>\s*([0-9.eE+-]+)\s*</mass>", _grams)
    with pytest.raises(ImplausibleValueError, match=r"model\.osim: total mass of the bodies: body mass 72\.6 t is outside "
                                                    r"the plausible range 20 kg \.\.\. 250 kg: did you mean 72600 g\?"):
        load_trial(p, IK, GRF_XML, window=(0.8, 1.0), accept=["segment_mass"])


# =============================================================================================
# 5. motion against model: names
# =============================================================================================
def test_misspelt_coordinate_column(tmp_path, model):
    header, labels, values = _split(IK)
    labels[labels.index("knee_angle_r")] = "knee_angel_r"
    p = _write(tmp_path / "ik.mot", header, labels, values)
    with pytest.raises(DataFileError, match=r"ik\.mot: column \['knee_angel_r'\] is not a coordinate of model "
                                            r"'walk_subject01' .*; 'knee_angel_r': did you mean 'knee_angle_r'\?"):
        load_trial(MODEL, p, GRF_XML, window=(0.8, 1.0))


def test_coordinate_column_in_other_case(tmp_path, model):
    header, labels, values = _split(IK)
    labels[labels.index("hip_flexion_l")] = "Hip_Flexion_L"
    p = _write(tmp_path / "ik.mot", header, labels, values)
    df = read_storage(p, model, check_degrees="off")
    with pytest.raises(DataFileError, match=r"'Hip_Flexion_L': did you mean 'hip_flexion_l'\?"):
        check_motion_against_model(df, model)


def test_reserve_on_a_misspelt_coordinate(tmp_path, model):
    text = RESERVES.read_text()
    assert "<coordinate>hip_flexion_r</coordinate>" in text
    p = tmp_path / "reserves.xml"
    p.write_text(text.replace("<coordinate>hip_flexion_r</coordinate>", "<coordinate>hip_flexion_R</coordinate>", 1))
    with pytest.raises(ModelError, match=r"reserves\.xml, line \d+.*coordinate 'hip_flexion_R' is not in the model; "
                                         r"did you mean 'hip_flexion_r'\?"):
        read_force_set(p, model)
    fs = read_force_set(p)
    with pytest.raises(InputError, match=r"acts on 'hip_flexion_R', which the model lacks; did you mean 'hip_flexion_r'\?"):
        reserve_optimal_forces(fs, list(model.coordinate_names))


# =============================================================================================
# 6. filter, windows, sampling
# =============================================================================================
CUTOFFS = [
    pytest.param(0.06, ImplausibleValueError,
                 r"load_trial\(cutoff=\.\.\.\): low-pass cut-off of the coordinates 0\.06 Hz is outside the plausible range "
                 r"2 Hz \.\.\. 30 Hz \(gait kinematics: 4-20 Hz typical.*\); a cut-off normalised by the Nyquist "
                 r"frequency \(scipy's Wn\)\? give it in Hz", id="cutoff-0.06-Hz"),
    pytest.param(0.2, ImplausibleValueError, r"cut-off of the coordinates 0\.2 Hz is outside .* normalised by the Nyquist",
                 id="cutoff-normalised"),
    pytest.param(1.5, ImplausibleValueError, r"1\.5 Hz is outside the plausible range 2 Hz \.\.\. 30 Hz \(gait kinematics",
                 id="cutoff-below-stride-harmonics"),
    pytest.param(60.0, InputError, r"cut-off 60\.0 Hz must lie between 0 and the Nyquist frequency 30 Hz \(half the "
                                   r"sampling rate 60 Hz\)", id="cutoff-at-sampling-rate"),
    pytest.param(45.0, InputError, r"cut-off 45\.0 Hz must lie between 0 and the Nyquist frequency 30 Hz",
                 id="cutoff-above-nyquist"),
    pytest.param(-6.0, InputError, r"cut-off -6\.0 Hz must lie between 0 and the Nyquist", id="cutoff-negative"),
    pytest.param("6 kHz", InputError, r"cut-off 6000\.0 Hz must lie between 0 and the Nyquist", id="cutoff-in-kHz"),
    pytest.param("6 m", InputError, r"'6 m' is a length .*expected frequency", id="cutoff-wrong-dimension"),
]


@pytest.mark.parametrize("cutoff, error, pattern", CUTOFFS)
def test_filter_cutoff_slips(cutoff, error, pattern):
    with pytest.raises(error, match=pattern):
        if error is ImplausibleValueError:
            load_trial(MODEL, IK, GRF_XML, window=(0.8, 1.0), cutoff=cutoff)
        else:
            process_coordinates(read_storage(IK), cutoff=cutoff)


def test_cutoff_with_a_unit_equals_the_number():
    motion = read_storage(IK)
    a = process_coordinates(motion, cutoff="6 Hz")
    b = process_coordinates(motion, cutoff=6.0)
    np.testing.assert_array_equal(a.qddot.to_numpy(), b.qddot.to_numpy())


def test_a_low_cutoff_can_be_accepted():
    k = process_coordinates(read_storage(IK), cutoff=1.5, accept=["filter_cutoff"])
    assert k.settings["cutoff_hz"] == 1.5


WINDOWS = [
    pytest.param((0, 100), DataRangeError,
                 r"window \(0, 100\) s is outside the data's time range 0 \.\.\. 2\.5 s: it looks like per cent of the "
                 r"gait cycle; give the window in seconds", id="window-in-percent"),
    pytest.param((60, 100), DataRangeError, r"window \(60, 100\) s .* looks like per cent of the gait cycle",
                 id="window-late-percent"),
    pytest.param((618, 1853), DataRangeError, r"window \(618, 1853\) s is outside the data's time range 0 \.\.\. 2\.5 s: "
                                              r"it looks like milliseconds \(0\.618, 1\.853\) s\?", id="window-in-ms"),
    pytest.param((0.5, 3.0), DataRangeError, r"subject01_walk_IK\.mot \(0-2\.5 s\) and .*: window \(0\.5, 3\) s is outside "
                                             r"the data's time range 0 \.\.\. 2\.5 s$", id="window-past-the-end"),
    pytest.param((1.8, 0.6), InputError, r"window \(1\.8, 0\.6\) s must have start < end", id="window-reversed"),
    pytest.param((0.6,), InputError, r"window \(0\.6,\) must be two times \(start, end\) in seconds", id="window-one-number"),
]


@pytest.mark.parametrize("window, error, pattern", WINDOWS)
def test_trial_window_slips(window, error, pattern):
    with pytest.raises(error, match=pattern):
        load_trial(MODEL, IK, GRF_XML, window=window)


@pytest.mark.parametrize("window, pattern", [
    pytest.param((0, 100), r"muscle_inputs: trial .*subject01_walk_IK\.mot: window \(0, 100\) s is outside the data's time "
                           r"range 0\.8 \.\.\. 1 s: it looks like per cent of the gait cycle", id="muscle-window-in-percent"),
    pytest.param((0.9, 1.5), r"window \(0\.9, 1\.5\) s is outside the data's time range 0\.8 \.\.\. 1 s$",
                 id="muscle-window-beyond-trial"),
])
def test_muscle_force_window_slips(short_inputs, window, pattern):
    trial, moments, _ = short_inputs
    with pytest.raises(DataRangeError, match=pattern):
        muscle_inputs(trial, moments, window=window)


def _ms(labels, values):
    values[:, 0] *= 1000.0


def _frames(labels, values):
    values[:, 0] = np.arange(len(values))


def test_force_times_in_ms(tmp_path):
    xml = slipped_grf(tmp_path, _ms)
    with pytest.raises(ImplausibleValueError, match=r"subject01_walk_grf\.mot: time column: sampling rate of the force "
                                                    r"data 0\.588235 Hz is outside the plausible range 10 Hz \.\.\. 20000 Hz: the "
                                                    r"time column looks like milliseconds or frame numbers; times must be in "
                                                    r"seconds \(to use it deliberately, accept='force_sample_rate'\)"):
        load_trial(MODEL, IK, xml)


def test_kinematics_times_in_frame_numbers(tmp_path):
    p = slipped_ik(tmp_path, _frames)
    with pytest.raises(ImplausibleValueError, match=r"ik\.mot: time column: sampling rate of the kinematics 1 Hz is outside "
                                                    r"the plausible range 10 Hz \.\.\. 2000 Hz.*milliseconds or frame numbers"):
        load_trial(MODEL, p, GRF_XML)


def test_forces_sampled_below_the_kinematics_finish_with_a_named_warning(tmp_path):
    header, labels, values = _split(GRF_MOT)
    coarse = values[::20]  # 30 Hz
    header = [re.sub(r"nRows=\d+", f"nRows={len(coarse)}", s) for s in header]
    _write(tmp_path / "subject01_walk_grf.mot", header, labels, coarse)
    (tmp_path / "grf.xml").write_text(GRF_XML.read_text())
    with pytest.warns(SamplingRateWarning, match=r"sampled at 30\.0\d* Hz, more coarsely than the kinematics .* \(60 Hz\)"):
        trial = load_trial(MODEL, IK, tmp_path / "grf.xml", window=(0.8, 1.0))
    assert len(inverse_dynamics(trial)) == 13


# =============================================================================================
# 7. misspelt options of the public functions
# =============================================================================================
def _call(name):
    from biomech.anthropometry import segment_parameters
    from biomech.static_optimization import StaticOptimization

    return {
        "load_trial": lambda: load_trial(MODEL, IK, GRF_XML, cutof=6.0),
        "read_storage": lambda: read_storage(IK, check_degree="off"),
        "read_osim": lambda: read_osim(MODEL, strickt=True),
        "process_coordinates": lambda: process_coordinates(read_storage(IK), cuttoff=6.0),
        "read_external_loads": lambda: read_external_loads(GRF_XML, acept=["free_torque"]),
        "segment_parameters": lambda: segment_parameters(72.6, statue=1.75),
        "StaticOptimization": lambda: StaticOptimization(["m"], ["q"], [100.0], reserve_weigth=2.0),
    }[name]


@pytest.mark.parametrize("name, pattern", [
    pytest.param("load_trial", r"load_trial\(\): unknown option 'cutof'; did you mean 'cutoff'\?", id="load_trial-cutof"),
    pytest.param("read_storage", r"read_storage\(\): unknown option 'check_degree'; did you mean 'check_degrees'\?",
                 id="read_storage-check_degree"),
    pytest.param("read_osim", r"read_osim\(\): unknown option 'strickt'; did you mean 'strict'\?", id="read_osim-strickt"),
    pytest.param("process_coordinates", r"unknown option 'cuttoff'; did you mean 'cutoff'\?", id="process_coordinates-cuttoff"),
    pytest.param("read_external_loads", r"unknown option 'acept'; did you mean 'accept'\?", id="read_external_loads-acept"),
    pytest.param("segment_parameters", r"segment_parameters\(\): unknown option 'statue'; did you mean 'stature'\?",
                 id="segment_parameters-statue"),
    pytest.param("StaticOptimization", r"StaticOptimization\(\): unknown option 'reserve_weigth'; did you mean "
                                       r"'reserve_weight'\?", id="StaticOptimization-reserve_weigth"),
])
def test_misspelt_options(name, pattern):
    with pytest.raises(UnknownOptionError, match=pattern):
        _call(name)()


def test_misspelt_options_of_muscle_redundancy(short_inputs):
    trial, moments, inputs = short_inputs
    reserves = reserve_optimal_forces(read_force_set(RESERVES, trial.osim), inputs["coordinates"])
    with pytest.raises(UnknownOptionError, match=r"muscle_redundancy\(\): unknown option 'critrion'; did you mean "
                                                 r"'criterion'\?"):
        muscle_redundancy(inputs, reserves, critrion="stress")
    with pytest.raises(UnknownOptionError, match=r"criterion 'stres' is not one of \['activation', 'stress'\]; did you "
                                                 r"mean 'stress'\?"):
        muscle_redundancy(inputs, reserves, criterion="stres")
    with pytest.raises(UnknownOptionError, match=r"unknown option 'pasive'; did you mean 'passive'\?"):
        muscle_redundancy(inputs, reserves, pasive=False)
    with pytest.raises(UnknownOptionError, match=r"muscle_inputs\(\): unknown option 'windw'; did you mean 'window'\?"):
        muscle_inputs(trial, moments, windw=(0.8, 0.9))


# =============================================================================================
# 8. subject: body mass, stature, segment lengths
# =============================================================================================
SUBJECT_SLIPS = [
    pytest.param(dict(mass=72600, stature=1.75),
                 r"segment_parameters\(mass=\.\.\.\): body mass 72\.6 t is outside the plausible range 20 kg \.\.\. 250 kg: "
                 r"did you mean 72600 g\?", id="body-mass-in-grams"),
    pytest.param(dict(mass=160, stature=1.75),
                 r"segment_parameters\(mass=160 kg, stature=1\.75 m\): body-mass index \(mass / stature²\) 52\.2\d* kg/m² is "
                 r"outside the plausible range 13 kg/m² \.\.\. 45 kg/m² .*a body mass in pounds \(160 lb = 72\.57 kg",
                 id="body-mass-in-pounds"),
    pytest.param(dict(mass=260, stature=1.75), r"body mass 260 kg is outside .*: did you mean 260 lb\?",
                 id="heavy-body-mass-in-pounds"),
    pytest.param(dict(mass=7.26, stature=1.75), r"body mass 7\.26 kg is outside the plausible range 20 kg \.\.\. 250 kg "
                                                r"\(adult and adolescent", id="body-mass-decimal-slip"),
    pytest.param(dict(mass=72.6, stature=175), r"segment_parameters\(stature=\.\.\.\): stature 175 m is outside the "
                                               r"plausible range 0\.9 m \.\.\. 2\.3 m: did you mean 175 cm\?",
                 id="stature-in-cm"),
    pytest.param(dict(mass=72.6, stature=1750), r"stature 1750 m is outside .*: did you mean 1750 mm\?", id="stature-in-mm"),
    pytest.param(dict(mass=72.6, stature=1.75, segment_lengths={"thigh": 420}),
                 r"segment_parameters\(segment_lengths\['thigh'\]\): segment length 420 m is outside the plausible range "
                 r"0\.02 m \.\.\. 1\.5 m: did you mean 420 mm\?", id="segment-length-in-mm"),
    pytest.param(dict(mass="72.6 m", stature=1.75), r"'72\.6 m' is a length .*expected mass", id="mass-wrong-dimension"),
]


@pytest.mark.parametrize("kwargs, pattern", SUBJECT_SLIPS)
def test_subject_slips(kwargs, pattern):
    from biomech.anthropometry import segment_parameters

    with pytest.raises(InputError, match=pattern):
        segment_parameters(**kwargs)


def test_subject_units_equal_si():
    from biomech.anthropometry import segment_parameters

    a = segment_parameters("160 lb", stature="175 cm")
    b = segment_parameters(160 * 0.45359237, stature=1.75)
    np.testing.assert_allclose(a["mass [kg]"].to_numpy(float), b["mass [kg]"].to_numpy(float), rtol=1e-14)
    np.testing.assert_allclose(a["inertia_com [kg m^2]"].to_numpy(float), b["inertia_com [kg m^2]"].to_numpy(float),
                               rtol=1e-14)


def test_a_heavy_subject_accepted_deliberately():
    from biomech.anthropometry import segment_parameters

    p = segment_parameters(160, stature=1.75, accept=["body_mass_index"])
    assert p.attrs["body_mass [kg]"] == 160


# =============================================================================================
# 9. small items: reserve units, exports; no false alarms on the shipped data
# =============================================================================================
def test_pelvis_translation_reserves_are_in_newtons(short_inputs):
    trial, moments, inputs = short_inputs
    reserves = reserve_optimal_forces(read_force_set(RESERVES, trial.osim), inputs["coordinates"])
    df = muscle_redundancy(inputs, reserves, criterion="activation")
    assert "reserve_pelvis_tx [N]" in df.columns and "reserve_pelvis_ty [N]" in df.columns
    assert "reserve_pelvis_tilt [N m]" in df.columns and "reserve_hip_flexion_r [N m]" in df.columns
    assert not any(c.startswith("reserve_pelvis_t") and c.endswith("[N m]") and "tilt" not in c for c in df.columns)
    assert inputs["coordinate_units"][inputs["coordinates"].index("pelvis_tx")] == "N"


def test_reserve_optimal_forces_is_exported():
    import biomech.muscle_forces as mf

    assert "reserve_optimal_forces" in mf.__all__


def test_range_table_has_a_rationale_for_every_row():
    rows = list(ranges())
    assert len(rows) >= 15
    assert all(r.rationale and r.low <= r.high for r in rows)


@pytest.mark.parametrize("path", [
    pytest.param(G10 / "subject01.osim", id="gait10dof18musc-subject01"),
    pytest.param(G2392 / "subject01_simbody_adjusted.osim", id="gait2392-subject01"),
    pytest.param(data_path("biomech", "opensim", "gait10dof18musc.osim"), id="gait10dof18musc-generic"),
    pytest.param(data_path("biomech", "opensim", "gait2392_thelen2003muscle.osim"), id="gait2392-generic"),
])
def test_shipped_models_raise_no_false_alarm(path):
    assert read_osim(path).total_mass > 70


def test_shipped_trials_raise_no_false_alarm():
    m10 = read_osim(G10 / "subject01.osim")
    m23 = read_osim(G2392 / "subject01_simbody_adjusted.osim")
    read_storage(IK, m10)
    read_storage(G2392 / "subject01_walk1_ik.mot", m23)
    read_external_loads(GRF_XML)
    read_external_loads(G2392 / "subject01_walk1_grf.xml")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        trial = load_trial(MODEL, IK, GRF_XML)  # the paper scene's inputs
    assert trial.window == (0.0, 2.5)


def test_copied_trial_is_accepted(tmp_path):
    """A byte-identical copy of the shipped trial passes every check (the helpers are faithful)."""
    for f in (GRF_MOT, GRF_XML):
        shutil.copy(f, tmp_path / f.name)
    p = slipped_ik(tmp_path, lambda labels, values: None)
    load_trial(MODEL, p, tmp_path / GRF_XML.name, window=(0.8, 1.0))


# =============================================================================================
# 10. more of a hurried user's slips: choices, columns, tables
# =============================================================================================
def _more(name, short_inputs):
    from biomech.anthropometry import segment_parameters
    from biomech.inverse_dynamics import gait_events

    trial, moments, inputs = short_inputs
    return {
        "check-degrees-choice": lambda: read_storage(IK, check_degrees="warning"),
        "column-misspelt": lambda: process_coordinates(read_storage(IK), columns=["knee_angel_r"]),
        "table-misspelt": lambda: segment_parameters(72.6, 1.75, table="delva"),
        "segment-misspelt": lambda: segment_parameters(72.6, 1.75, segment_lengths={"tigh": 0.4}),
        "foot-body-misspelt": lambda: gait_events(trial.loads, "calcn_R"),
        "filter-order-zero": lambda: load_trial(MODEL, IK, GRF_XML, order=0),
        "moments-table-wrong": lambda: muscle_inputs(trial, moments.drop(columns=["knee_angle_r_moment [N m]"])),
        "reserves-too-short": lambda: muscle_redundancy(inputs, np.ones(len(inputs["coordinates"]) - 1)),
        "window-with-nan": lambda: muscle_inputs(trial, moments, window=(0.8, float("nan"))),
        "muscle-override-misspelt": lambda: _thelen().from_muscles(trial.osim.muscles, kshape_activ=0.45),
    }[name]


def _thelen():
    from biomech.muscles import ThelenMuscleSet

    return ThelenMuscleSet


@pytest.mark.parametrize("name, error, pattern", [
    pytest.param("check-degrees-choice", InputError, r"check_degrees must be 'raise', 'warn' or 'off', got 'warning'; did "
                                                     r"you mean 'warn'\?", id="check-degrees-choice"),
    pytest.param("column-misspelt", InputError, r"columns \['knee_angel_r'\] are not in the motion; did you mean "
                                                r"'knee_angle_r'\?", id="column-misspelt"),
    pytest.param("table-misspelt", InputError, r"unknown anthropometric table 'delva'; did you mean 'deleva'\?",
                 id="table-misspelt"),
    pytest.param("segment-misspelt", UnknownOptionError, r"segment_lengths: unknown segment\(s\) \['tigh'\]; did you mean "
                                                         r"'thigh'\?", id="segment-misspelt"),
    pytest.param("foot-body-misspelt", InputError, r"no external force acts on 'calcn_R' \(they act on \['calcn_r', "
                                                   r"'calcn_l'\]\); did you mean 'calcn_r'\?", id="foot-body-misspelt"),
    pytest.param("filter-order-zero", InputError, r"load_trial\(order=0\): the Butterworth order per pass must be an "
                                                  r"integer 1\.\.10", id="filter-order-zero"),
    pytest.param("moments-table-wrong", InputError, r"muscle_inputs: moments lack \['knee_angle_r'\]: pass the table of "
                                                    r"biomech\.inverse_dynamics\.inverse_dynamics\(trial\)",
                 id="moments-table-wrong"),
    pytest.param("reserves-too-short", InputError, r"reserve_optimal_force must be a scalar or have shape \(10,\), got "
                                                   r"shape \(9,\)", id="reserves-too-short"),
    pytest.param("window-with-nan", InputError, r"window \(0\.8, nan\) s must be finite", id="window-with-nan"),
    pytest.param("muscle-override-misspelt", UnknownOptionError, r"ThelenMuscleSet\.from_muscles\(\): unknown option "
                                                                  r"'kshape_activ'; did you mean 'kshape_active'\?",
                 id="muscle-override-misspelt"),
])
def test_more_hurried_slips(short_inputs, name, error, pattern):
    with pytest.raises(error, match=pattern):
        _more(name, short_inputs)()


def test_ground_reactions_too_large_for_the_model(tmp_path):
    """Forces ten times too large (a gain slip of the force-plate amplifier) are 13 body weights."""
    xml = slipped_grf(tmp_path, grf_scale("force_v", 10.0))
    with pytest.raises(ImplausibleValueError, match=r"the peak vertical ground reaction 9254 N is 13 body weights of "
                                                    r".*subject01\.osim's 72\.6 kg, outside the plausible range 0\.7 \.\.\. 6: "
                                                    r"the forces are too large for the model's mass"):
        load_trial(MODEL, IK, xml)
