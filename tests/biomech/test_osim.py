"""Reading OpenSim 4.x models and force sets without OpenSim (biomech.osim).

Counts and numbers are checked against an independent reading of the same files (ElementTree
queries or regular expressions on the text), not against values copied from the reader.  Bad and
unsupported inputs are written to tmp_path as modified copies of subject01.osim; each must give
an error or warning naming the file, the element and (where the parser knows it) the line.
"""

from __future__ import annotations

import pickle
import re
import xml.etree.ElementTree as ET

import numpy as np
import pytest

from core.errors import DataFileError, ModelError
from core.paths import data_path
from biomech.functions import MultiplierFunction, SimmSpline
from biomech.osim import (
    ConditionalPathPoint,
    CoordinateActuator,
    MovingPathPoint,
    OsimReaderWarning,
    PathPoint,
    PointActuator,
    TorqueActuator,
    read_force_set,
    read_osim,
)

OPENSIM = data_path("biomech", "opensim")
GAIT10 = OPENSIM / "gait10dof18musc_subject01_walk" / "subject01.osim"
GAIT2392 = OPENSIM / "gait2392_subject01_walk" / "subject01_simbody_adjusted.osim"
MODELS = {
    "gait10dof_subject01": (GAIT10, 18),
    "gait2392_subject01": (GAIT2392, 92),
    "gait10dof_generic": (OPENSIM / "gait10dof18musc.osim", 18),
    "gait2392_generic": (OPENSIM / "gait2392_thelen2003muscle.osim", 92),
}

_cache: dict = {}


def model(key):
    if key not in _cache:
        _cache[key] = read_osim(MODELS[key][0])
    return _cache[key]


def et_model(path):
    return ET.parse(path).getroot().find("Model")


def line_of(text: str, token: str, start: int = 0) -> int:
    return text[: text.index(token, start)].count("\n") + 1


# ---- the four models --------------------------------------------------------------------


@pytest.mark.parametrize("key", list(MODELS))
def test_counts_match_an_independent_reading_of_the_file(key):
    path, n_muscles = MODELS[key]
    m = model(key)
    root = et_model(path)
    assert len(m.bodies) == len(root.findall("BodySet/objects/Body"))
    assert len(m.joints) == len(list(root.find("JointSet/objects")))
    assert len(m.coordinates) == len(root.findall("JointSet/objects/*/coordinates/Coordinate"))
    muscles_in_file = [f for f in root.find("ForceSet/objects") if f.tag.endswith("Muscle")]
    assert len(m.muscles) == len(muscles_in_file) == n_muscles
    assert [mu.name for mu in m.muscles] == [f.get("name") for f in muscles_in_file]
    text = path.read_text()
    assert len(m.markers) == len(re.findall(r"<Marker name=", text))
    assert m.ignored == ()  # no wrapping, constraints or other forces in these files (and no warning)


@pytest.mark.parametrize("key", list(MODELS))
def test_total_mass_is_the_sum_of_the_body_masses(key):
    path, _ = MODELS[key]
    masses = [float(v) for v in re.findall(r"<mass>\s*([^<\s]+)\s*</mass>", path.read_text())]
    m = model(key)
    assert m.total_mass == pytest.approx(sum(masses), rel=1e-14)
    expected = 72.6 if "subject01" in key else 75.2  # subject01 scaled mass; generic models 75.2 kg (README)
    assert m.total_mass == pytest.approx(expected, abs=0.05)


@pytest.mark.parametrize("key", ["gait10dof_subject01", "gait2392_subject01"])
@pytest.mark.parametrize("axis_name", ["translation1", "translation2"])
def test_knee_translation_functions_are_scaled_splines_with_the_file_points(key, axis_name):
    path, _ = MODELS[key]
    root = et_model(path)
    knee_el = next(j for j in root.find("JointSet/objects") if j.get("name") == "knee_r")
    ax_el = next(a for a in knee_el.find("SpatialTransform") if a.get("name") == axis_name)
    x = np.array(ax_el.find(".//SimmSpline/x").text.split(), float)
    y = np.array(ax_el.find(".//SimmSpline/y").text.split(), float)
    scale = float(ax_el.find(".//scale").text)
    axis = next(a for a in model(key).joint("knee_r").transform_axes if a.name == axis_name)
    assert axis.coordinates == ("knee_angle_r",)
    assert isinstance(axis.function, MultiplierFunction) and isinstance(axis.function.function, SimmSpline)
    assert axis.function.function.n_points == x.size and axis.function.scale == scale
    np.testing.assert_allclose(axis.function(x), scale * y, rtol=0, atol=1e-15)
    assert axis.value({"knee_angle_r": x[2]}) == pytest.approx(scale * y[2], abs=1e-15)


def test_gait10dof_knee_splines_have_12_and_7_points():
    axes = {a.name: a for a in model("gait10dof_subject01").joint("knee_r").transform_axes}
    assert axes["translation1"].function.function.n_points == 12
    assert axes["translation2"].function.function.n_points == 7


def test_joints_frames_and_motion_types():
    m = model("gait10dof_subject01")
    hip = m.joint("hip_r")
    assert (hip.type, hip.parent_body, hip.child_body, hip.coordinates) == ("PinJoint", "pelvis", "femur_r",
                                                                             ("hip_flexion_r",))
    # the parent offset frame's translation, read independently
    hip_el = next(j for j in et_model(GAIT10).find("JointSet/objects") if j.get("name") == "hip_r")
    frame_el = next(f for f in hip_el.find("frames") if f.get("name") == "pelvis_offset")
    np.testing.assert_array_equal(hip.parent_frame.location, np.array(frame_el.find("translation").text.split(), float))
    np.testing.assert_array_equal(hip.parent_frame.rotation, np.eye(3))
    rot1 = hip.transform_axes[0]  # a PinJoint is a rotation about the common z axis
    assert rot1.name == "rotation1" and rot1.coordinates == ("hip_flexion_r",)
    np.testing.assert_array_equal(rot1.axis, [0, 0, 1])
    assert m.joint("subtalar_r").type == "WeldJoint" and m.joint("subtalar_r").coordinates == ()
    ground = m.joint("ground_pelvis")
    assert (ground.type, ground.parent_body, ground.child_body) == ("CustomJoint", "ground", "pelvis")
    z_offset = ground.transform_axes[5]  # translation3: MultiplierFunction(Constant 0.02), no coordinate
    assert z_offset.coordinates == () and z_offset.value({}) == 0.02
    types = {c.name: c.motion_type for c in m.coordinates}
    assert types["pelvis_tx"] == types["pelvis_ty"] == "translational"
    assert types["knee_angle_r"] == types["pelvis_tilt"] == "rotational"
    # gait2392 scaled: translations are MultiplierFunction(LinearFunction(1, 0)) -> still translational
    types = {c.name: c.motion_type for c in model("gait2392_subject01").coordinates}
    assert {types[f"pelvis_t{a}"] for a in "xyz"} == {"translational"}
    assert sum(t == "rotational" for t in types.values()) == 20


def test_coordinates_bodies_and_muscle_parameters_are_the_file_values():
    m = model("gait2392_subject01")
    root = et_model(GAIT2392)
    knee = root.find(".//Coordinate[@name='knee_angle_r']")
    c = m.coordinate("knee_angle_r")
    np.testing.assert_array_equal(c.range, np.array(knee.find("range").text.split(), float))
    assert (c.joint, c.locked, c.clamped, c.default_value) == ("knee_r", False, False, 0.0)
    femur = root.find("BodySet/objects/Body[@name='femur_r']")
    six = np.array(femur.find("inertia").text.split(), float)
    b = m.body("femur_r")
    assert b.mass == float(femur.find("mass").text)
    np.testing.assert_array_equal(np.diag(b.inertia), six[:3])
    np.testing.assert_array_equal(b.inertia, b.inertia.T)
    assert (b.inertia[0, 1], b.inertia[0, 2], b.inertia[1, 2]) == tuple(six[3:])
    mel = root.find("ForceSet/objects/Thelen2003Muscle[@name='glut_med1_r']")
    mu = m.muscle("glut_med1_r")
    for tag, attr in [("max_isometric_force", "max_isometric_force"), ("optimal_fiber_length", "optimal_fiber_length"),
                      ("tendon_slack_length", "tendon_slack_length"),
                      ("pennation_angle_at_optimal", "pennation_angle_at_optimal"),
                      ("FmaxTendonStrain", "fmax_tendon_strain"), ("FmaxMuscleStrain", "fmax_muscle_strain"),
                      ("KshapeActive", "kshape_active"), ("KshapePassive", "kshape_passive"), ("Af", "af"),
                      ("Flen", "flen"), ("max_contraction_velocity", "max_contraction_velocity")]:
        assert getattr(mu, attr) == float(mel.find(tag).text), tag
    assert mu.type == "Thelen2003Muscle" and mu.applies_force
    assert [p.body for p in mu.path] == ["pelvis", "femur_r"]
    assert "R_hip_flex" in m.force_groups and "glut_med1_r" in m.force_groups["R_hip_flex"]
    # Millard muscles: no Thelen parameters; their curve parameters are kept verbatim
    ham = model("gait10dof_subject01").muscle("hamstrings_r")
    assert ham.type == "Millard2012EquilibriumMuscle" and ham.kshape_active is None
    assert ham.properties["ForceVelocityCurve.max_eccentric_velocity_force_multiplier"] == "1.3999999999999999"


def test_path_point_kinds_of_rect_fem():
    m = model("gait10dof_subject01")
    p1, p2, p3 = m.muscle("rect_fem_r").path
    assert type(p1) is PathPoint and p1.body == "pelvis"
    assert isinstance(p2, ConditionalPathPoint) and p2.coordinate == "knee_angle_r" and p2.body == "femur_r"
    lo, hi = p2.range
    assert p2.is_active({"knee_angle_r": 0.5 * (lo + hi)})
    assert p2.is_active({"knee_angle_r": hi + 0.9e-5}) and not p2.is_active({"knee_angle_r": hi + 1.1e-5})
    assert not p2.is_active({"knee_angle_r": 0.0})
    assert isinstance(p3, MovingPathPoint) and p3.coordinates == ("knee_angle_r",) * 3 and p3.body == "tibia_r"
    el = ET.parse(GAIT10).getroot().find(".//MovingPathPoint[@name='rect_fem_r-P3']")
    x = np.array(el.find("x_location//x").text.split(), float)
    y = np.array(el.find("x_location//y").text.split(), float)
    scale = float(el.find("x_location//scale").text)
    assert p3.location_at({"knee_angle_r": x[5]})[0] == pytest.approx(scale * y[5], abs=1e-15)
    # clamped to the coordinate's range, as MovingPathPoint::getLocation does
    q_max = m.coordinate("knee_angle_r").range[1]
    np.testing.assert_array_equal(p3.location_at({"knee_angle_r": q_max + 0.5}), p3.location_at({"knee_angle_r": q_max}))
    assert not np.any(p3.location_derivative({"knee_angle_r": q_max + 0.5}, "knee_angle_r"))
    q = {"knee_angle_r": -0.8}
    h = 1e-6
    fd = (p3.location_at({"knee_angle_r": -0.8 + h}) - p3.location_at({"knee_angle_r": -0.8 - h})) / (2 * h)
    np.testing.assert_allclose(p3.location_derivative(q, "knee_angle_r"), fd, rtol=0, atol=1e-8)


def test_model_pickles():
    m = model("gait10dof_subject01")
    m2 = pickle.loads(pickle.dumps(m))
    assert m2.coordinate_names == m.coordinate_names and m2.total_mass == m.total_mass
    knee = m2.joint("knee_r").transform_axes[3]
    assert knee.value({"knee_angle_r": -1.0}) == m.joint("knee_r").transform_axes[3].value({"knee_angle_r": -1.0})


# ---- force sets -----------------------------------------------------------------------------


def test_reserve_actuators_of_gait10dof():
    path = OPENSIM / "gait10dof18musc_subject01_walk" / "gait10dof_Reserve_Actuators.xml"
    fs = read_force_set(path, model("gait10dof_subject01"))
    text = path.read_text()
    for cls, tag in [(CoordinateActuator, "CoordinateActuator"), (PointActuator, "PointActuator"),
                     (TorqueActuator, "TorqueActuator")]:
        assert sum(isinstance(a, cls) for a in fs.actuators) == len(re.findall(rf'<{tag} name="(?!default")', text))
    hip = fs.actuator("hip_flexion_r_reserve")
    assert (hip.coordinate, hip.optimal_force, hip.min_control, hip.max_control) == ("hip_flexion_r", 1.0, -np.inf, np.inf)
    fy = fs.actuator("FY")
    assert fy.body == "pelvis" and fy.optimal_force == 2.0 and fy.force_is_global and not fy.point_is_global
    np.testing.assert_array_equal(fy.direction, [0, 1, 0])


def test_residual_actuators_of_gait2392_skip_the_defaults_section():
    path = OPENSIM / "gait2392_subject01_walk" / "gait2392_SO_weak_Residual_Actuators.xml"
    fs = read_force_set(path, model("gait2392_subject01"))
    assert [a.name for a in fs.actuators] == ["FX", "FY", "FZ", "MX", "MY", "MZ"]
    assert all(a.min_control == -1000.0 and a.max_control == 1000.0 for a in fs.actuators)
    mz = fs.actuator("MZ")
    assert isinstance(mz, TorqueActuator) and (mz.body_a, mz.body_b) == ("pelvis", "ground")
    np.testing.assert_array_equal(mz.axis, [0, 0, -1])
    assert fs.ignored == ()


def test_force_set_checked_against_the_model(tmp_path):
    path = OPENSIM / "gait10dof18musc_subject01_walk" / "gait10dof_Reserve_Actuators.xml"
    bad = tmp_path / "reserves.xml"
    bad.write_text(path.read_text().replace("<coordinate>knee_angle_r</coordinate>", "<coordinate>knee_r_beta</coordinate>"))
    with pytest.raises(ModelError, match=rf"{re.escape(str(bad))}, line \d+: <CoordinateActuator "
                                         r"name='knee_angle_r_reserve'>.*'knee_r_beta' is not in the model"):
        read_force_set(bad, model("gait10dof_subject01"))


# ---- bad and unsupported files --------------------------------------------------------------


@pytest.fixture(scope="module")
def gait10_text():
    return GAIT10.read_text()


def _write(tmp_path, text, name="model.osim"):
    p = tmp_path / name
    p.write_text(text)
    return p


def test_missing_truncated_and_malformed_files_name_the_file_and_line(tmp_path, gait10_text):
    with pytest.raises(DataFileError, match=r"nothere\.osim: file does not exist"):
        read_osim(tmp_path / "nothere.osim")
    cut = _write(tmp_path, gait10_text[: len(gait10_text) // 2], "truncated.osim")
    n_lines = gait10_text[: len(gait10_text) // 2].count("\n") + 1
    with pytest.raises(DataFileError, match=rf"{re.escape(str(cut))}, line {n_lines}, column \d+: not well-formed XML"
                                            r".*truncated\?"):
        read_osim(cut)
    bad_line = line_of(gait10_text, "</mass>")
    bad = _write(tmp_path, gait10_text.replace("</mass>", "</mas>", 1), "malformed.osim")
    with pytest.raises(DataFileError, match=rf"{re.escape(str(bad))}, line {bad_line}, column \d+: not well-formed "
                                            r"XML: mismatched tag"):
        read_osim(bad)
    with pytest.raises(DataFileError, match=r"line 3, column \d+: not well-formed XML: mismatched tag$"):
        read_osim(_write(tmp_path, "<?xml version='1.0'?>\n<OpenSimDocument Version='40000'>\n<Model></Mod>", "x.osim"))


def test_an_opensim_3_file_is_refused_with_advice(tmp_path, gait10_text):
    p = _write(tmp_path, gait10_text.replace('Version="40000"', 'Version="30000"', 1))
    with pytest.raises(DataFileError, match=r"OpenSim 3\.x model file \(Version=30000\).*open and save the model once"):
        read_osim(p)


def test_unknown_joint_type_is_an_error_naming_file_line_and_joint(tmp_path, gait10_text):
    start = gait10_text.index('<PinJoint name="ankle_r">')
    end = gait10_text.index("</PinJoint>", start)
    text = (gait10_text[:start] + '<GimbalJoint name="ankle_r">' + gait10_text[start + len('<PinJoint name="ankle_r">'):end]
            + "</GimbalJoint>" + gait10_text[end + len("</PinJoint>"):])
    p = _write(tmp_path, text)
    line = line_of(gait10_text, '<PinJoint name="ankle_r">')
    with pytest.raises(ModelError, match=rf"{re.escape(str(p))}, line {line}: <GimbalJoint name='ankle_r'>: "
                                         r"unsupported joint type 'GimbalJoint'.*supported: CustomJoint, PinJoint"):
        read_osim(p)


def test_unsupported_function_in_a_joint_is_an_error_naming_the_axis(tmp_path, gait10_text):
    knee = gait10_text.index('<CustomJoint name="knee_r">')
    s = gait10_text.index("<SimmSpline>", knee)
    e = gait10_text.index("</SimmSpline>", s)
    text = gait10_text[:s] + "<GCVSpline>" + gait10_text[s + 12:e] + "</GCVSpline>" + gait10_text[e + 13:]
    p = _write(tmp_path, text)
    with pytest.raises(DataFileError, match=rf"{re.escape(str(p))}, joint 'knee_r', TransformAxis 'translation1', "
                                            rf"line {line_of(gait10_text, '<SimmSpline>', knee)}: <GCVSpline>: "
                                            r"unsupported function type"):
        read_osim(p)


def test_references_to_missing_bodies_and_unconnected_bodies_are_errors(tmp_path, gait10_text):
    forces = gait10_text.index("<ForceSet")
    token = "<socket_parent_frame>/bodyset/tibia_r</socket_parent_frame>"
    k = gait10_text.index(token, forces)
    p = _write(tmp_path, gait10_text[:k] + token.replace("tibia_r", "tibia_x") + gait10_text[k + len(token):])
    with pytest.raises(ModelError, match=r"<PathPoint name='bifemlh_r-P2'>: muscle 'hamstrings_r', PathPoint "
                                         r"'bifemlh_r-P2': parent frame '/bodyset/tibia_x' is neither ground nor a body"):
        read_osim(p)
    s = gait10_text.index('<WeldJoint name="mtp_r">')
    e = gait10_text.index("</WeldJoint>", s) + len("</WeldJoint>")
    p = _write(tmp_path, gait10_text[:s] + gait10_text[e:], "unconnected.osim")
    with pytest.raises(ModelError, match=r"body 'toes_r' is not connected to 'ground' by joints"):
        read_osim(p)


def _insert_after(text, anchor, token, payload):
    """Replace the first ``token`` after ``anchor`` by ``payload``."""
    a = text.index(anchor)
    k = text.index(token, a)
    return text[:k] + payload + text[k + len(token):]


def test_unsupported_elements_are_warned_about_listed_and_refused_when_strict(tmp_path, gait10_text):
    text = _insert_after(gait10_text, '<Body name="femur_r">', "<objects />",
                         '<objects><WrapCylinder name="KnAx_r"><radius>0.03</radius></WrapCylinder></objects>')
    text = _insert_after(text, '<Millard2012EquilibriumMuscle name="gastroc_r">', "<objects />",
                         '<objects><PathWrap name="gastroc_r-wrap"><wrap_object>KnAx_r</wrap_object></PathWrap></objects>')
    text = _insert_after(text, '<ConstraintSet name="constraintset">', "<objects />",
                         '<objects><WeldConstraint name="weld_feet"/>'
                         '<CoordinateCouplerConstraint name="knees_coupled"><isEnforced>true</isEnforced>'
                         '<coupled_coordinates_function><LinearFunction><coefficients>0.5 0</coefficients>'
                         '</LinearFunction></coupled_coordinates_function>'
                         '<independent_coordinate_names>knee_angle_r</independent_coordinate_names>'
                         '<dependent_coordinate_name>knee_angle_l</dependent_coordinate_name>'
                         '</CoordinateCouplerConstraint></objects>')
    text = text.replace('<PinJoint name="hip_r">', '<PinJoint name="hip_r"><damping>0.1</damping>', 1)
    text = _insert_after(text, '<ForceSet name="forceset">', "<objects>",
                         '<objects><CoordinateLimitForce name="knee_limit"><coordinate>knee_angle_r</coordinate>'
                         '<upper_stiffness>10</upper_stiffness></CoordinateLimitForce>')
    p = _write(tmp_path, text)
    with pytest.warns(OsimReaderWarning) as record:
        m = read_osim(p)
    messages = [str(w.message) for w in record]
    assert len(messages) == 5
    expected = {
        "wrap object": r"1 wrap object ignored: WrapCylinder 'KnAx_r' on body 'femur_r' \(line \d+\): wrap surface",
        "path wrap": r"1 path wrap ignored: PathWrap 'gastroc_r-wrap' on muscle 'gastroc_r' \(line \d+\): wrapping over "
                     r"'KnAx_r' not modelled",
        "constraint": r"1 constraint ignored: WeldConstraint 'weld_feet' \(line \d+\): constraint not modelled",
        "force": r"1 force ignored: CoordinateLimitForce 'knee_limit' \(line \d+\): listed in model.other_forces",
        "property": r"1 property ignored: damping on joint 'hip_r' \(line \d+\): property the reader does not know",
    }
    for kind, pattern in expected.items():
        assert any(re.search(re.escape(str(p)) + ": " + pattern, msg) for msg in messages), (kind, messages)
    # in file order (the limit force was inserted first in the ForceSet)
    assert [i.kind for i in m.ignored] == ["wrap object", "property", "constraint", "force", "path wrap"]
    assert [i.name for i in m.ignored] == ["KnAx_r", "", "weld_feet", "knee_limit", "gastroc_r-wrap"]
    assert m.other_forces[0].type == "CoordinateLimitForce" and m.other_forces[0].properties["upper_stiffness"] == "10"
    (cc,) = m.constraints  # a CoordinateCouplerConstraint is read, not ignored
    assert (cc.independent_coordinate, cc.dependent_coordinate, cc.enforced) == ("knee_angle_r", "knee_angle_l", True)
    assert cc.function(0.4) == 0.2
    assert len(m.muscles) == 18
    with pytest.raises(ModelError, match=r"5 element\(s\) not supported \(strict=True\): WrapCylinder 'KnAx_r'"):
        read_osim(p, strict=True)
