"""Careless inputs to the railway domain (issue 21): each ends in one clear line or a named warning.

The vehicle file (railway.vehicles.vehicle_file), the keyword arguments of build_vehicle, the track and its
irregularities (railway.track) and the profile readers (railway.contact.profiles) are given the inputs a
hurried user writes -- units slipped (tonnes, kN/m, mm), keys misspelt, geometry that contradicts
itself, values out of range, names mistyped -- and every case asserts the exact outcome: the error
type and a message naming the file / table / key / argument and the likely slip.  Then the shipped
data and the scenes' inputs pass without a false alarm, and a value with a unit gives the same
result as the SI number.
"""

import importlib
import re
import warnings
from pathlib import Path

import numpy as np
import pytest

from core.errors import (
    DataFileError,
    InputError,
    UnknownNameError,
    UnknownOptionError,
)
from core.inputs import ImplausibleValueError, UnitError
from railway.ranges import IrregularityStepWarning, SuspensionGeometryWarning, ranges
from railway.track import Curve, Irregularities, Straight, Track, Transition, parse_inclination
from railway.vehicles.vehicle import VehicleDefinition, build_vehicle

COACH = Path(VehicleDefinition.manchester().path)
TEXT = COACH.read_text(encoding="utf-8")


@pytest.fixture(scope="module")
def coach():
    return VehicleDefinition.manchester()


def _edit(text, old, new):
    assert text.count(old) == 1, f"{old!r} occurs {text.count(old)} times in the coach file"
    return text.replace(old, new)


def _write(tmp_path, *edits, append=""):
    text = TEXT
    for old, new in edits:
        text = _edit(text, old, new)
    f = tmp_path / "coach.toml"
    f.write_text(text + append, encoding="utf-8")
    return f


# ---------------------------------------------------------------------------------------------
# the vehicle file: (id, edits, text appended, error type, message pattern)
# ---------------------------------------------------------------------------------------------
F = r"coach\.toml"
FILE_CASES = [
    # unit slips: tonnes, t m², kN/m, kN s/m, kN m/rad, mm
    ("car body mass in tonnes", [("mass = 32000.0", "mass = 32")], "", ImplausibleValueError,
     rf"{F} \[car_body\] mass: car body mass 32 kg is outside the plausible range 1 t \.\.\. 200 t: "
     r"did you mean 32 t\? \(to use it deliberately, accept='car_body_mass'\)"),
    ("bogie mass in tonnes", [("mass = 2615.0", "mass = 2.615")], "", ImplausibleValueError,
     rf"{F} \[bogie\] mass: bogie frame mass 2\.615 kg .*did you mean 2\.615 t\?"),
    ("wheelset mass in tonnes", [("mass = 1813.0", "mass = 1.813")], "", ImplausibleValueError,
     rf"{F} \[wheelset\] mass: wheelset mass 1\.813 kg .*did you mean 1\.813 t\?"),
    ("car body inertia in t m2", [("[56800.0, 1970000.0, 1970000.0]", "[56.8, 1970, 1970]")], "",
     ImplausibleValueError, rf"{F} \[car_body\] inertia: car body roll inertia 56\.8 kg m² .*did you mean 56\.8 t m²\?"),
    ("wheelset spin inertia in t m2", [("[1120.0, 112.0, 1120.0]", "[1120.0, 0.112, 1120.0]")], "",
     ImplausibleValueError, rf"{F} \[wheelset\] inertia: wheelset spin inertia 0\.112 kg m² .*did you mean 0\.112 t m²\?"),
    ("primary stiffness in kN/m", [("[31391e3, 3884e3, 1220e3]", "[31391, 3884, 1220]")], "",
     ImplausibleValueError, rf"{F} \[primary\] stiffness: primary longitudinal stiffness 31391 N/m .*did you mean 31391 kN/m\?"),
    ("secondary vertical stiffness in kN/m", [("[160e3, 160e3, 430e3]", "[160e3, 160e3, 430]")], "",
     ImplausibleValueError, rf"{F} \[secondary\] stiffness: secondary vertical stiffness 430 N/m .*did you mean 430 kN/m\?"),
    ("zero primary vertical stiffness", [("[31391e3, 3884e3, 1220e3]", "[31391e3, 3884e3, 0.0]")], "",
     ImplausibleValueError, rf"{F} \[primary\] stiffness: primary vertical stiffness 0 N/m is outside the plausible "
     r"range 100 kN/m \.\.\. 20 MN/m \(per axlebox.*zero is refused"),
    ("kN/m stiffnesses accepted: 37 m static deflection",
     [("[31391e3, 3884e3, 1220e3]", "[31391, 3884, 1220]")],
     '\n[checks]\naccept = ["primary_stiffness_x", "primary_stiffness_y", "primary_stiffness_z"]\n',
     ImplausibleValueError, rf"{F}: the primary static deflection implied by the file, .* = 37\.42 m, is outside "
     r"the plausible range 0\.001 m \.\.\. 0\.2 m: are the stiffnesses in N/m \(not kN/m\)\?"),
    ("primary damping in kN s/m", [("[15e3, 2e3, 4e3]", "[15, 2, 4]")], "", ImplausibleValueError,
     rf"{F} \[primary\] damping: primary damping 15 N s/m .*did you mean 15 kN s/m\?"),
    ("secondary damping in kN s/m", [("[0.0, 32e3, 20e3]", "[0.0, 32, 20]")], "", ImplausibleValueError,
     rf"{F} \[secondary\] damping: secondary damping 32 N s/m .*did you mean 32 kN s/m\?"),
    ("negative damping", [("[15e3, 2e3, 4e3]", "[15e3, -2e3, 4e3]")], "", DataFileError,
     rf"{F} \[primary\] damping: primary damping \[1\] \(y\) = -2000\.0 must be >= 0"),
    ("yaw stiffness in kN m/rad", [("yaw_stiffness = 10.5e3", "yaw_stiffness = 10.5")], "", ImplausibleValueError,
     rf"{F} \[secondary\] yaw_stiffness: secondary yaw stiffness 10\.5 N m/rad .*did you mean 10\.5 kN m/rad\?"),
    ("anti-roll bar in kN m/rad", [("stiffness = 940e3", "stiffness = 940")], "", ImplausibleValueError,
     rf"{F} \[anti_roll_bar\] stiffness: anti-roll bar stiffness 940 N m/rad .*did you mean 940 kN m/rad\?"),
    ("car body cg height in mm", [("car_body_cg_height = 1.8 ", "car_body_cg_height = 1800 ")], "",
     ImplausibleValueError, rf"{F} \[geometry\] car_body_cg_height: car body centre-of-gravity height 1800 m .*"
     r"did you mean 1800 mm\?"),
    ("bogie centre distance in mm", [("bogie_centre_semi_distance = 9.5 ", "bogie_centre_semi_distance = 9500 ")], "",
     ImplausibleValueError, rf"{F} \[geometry\] bogie_centre_semi_distance: .* 9500 m .*did you mean 9500 mm\?"),
    ("gauge in mm", [("gauge = 1.435 ", "gauge = 1435 ")], "", ImplausibleValueError,
     rf"{F} \[profiles\] gauge: track gauge 1435 m .*did you mean 1435 mm\?"),
    ("flange-back spacing in mm", [("flange_back_spacing = 1.360", "flange_back_spacing = 1360")], "",
     ImplausibleValueError, rf"{F} \[profiles\] flange_back_spacing: flange-back spacing 1360 m .*did you mean 1360 mm\?"),
    ("wheel diameter in mm for the radius", [("nominal_wheel_radius = 0.46 ", "nominal_wheel_radius = 920 ")], "",
     ImplausibleValueError, rf"{F} \[profiles\] nominal_wheel_radius: .* 920 m is outside .*: it looks like a wheel "
     r"diameter in mm; the radius is 0\.46 m"),
    ("wheel diameter in m for the radius", [("nominal_wheel_radius = 0.46 ", "nominal_wheel_radius = 0.92 ")], "",
     ImplausibleValueError, r"it looks like a wheel diameter; the radius is 0\.46 m"),
    ("wheel radius in mm", [("nominal_wheel_radius = 0.46 ", "nominal_wheel_radius = 460 ")], "",
     ImplausibleValueError, r"it looks like a radius in mm; the radius is 0\.46 m, or a wheel diameter in mm; the radius is 0\.23 m"),
    ("negative car body mass", [("mass = 32000.0", "mass = -32000.0")], "", DataFileError,
     rf"{F} \[car_body\] mass: car body mass = -32000\.0 must be > 0"),
    ("NaN mass", [("mass = 32000.0", "mass = nan")], "", InputError,
     rf"{F} \[car_body\] mass: car body mass: nan is not a finite number"),
    ("boolean mass", [("mass = 32000.0", "mass = true")], "", InputError,
     rf"{F} \[car_body\] mass: car body mass: True is not a number"),
    ("mass with a length unit", [("mass = 32000.0", 'mass = "32 m"')], "", UnitError,
     rf"{F} \[car_body\] mass: .*'32 m' is a length \(\[length\]\), expected mass"),
    ("mass with an unknown unit", [("mass = 32000.0", 'mass = "32 tonns"')], "", UnitError,
     rf"{F} \[car_body\] mass: .*cannot read '32 tonns' as a quantity in kg"),
    ("inertia of two values", [("[56800.0, 1970000.0, 1970000.0]", "[56800.0, 1970000.0]")], "", DataFileError,
     rf"{F} \[car_body\] inertia: must be 3 values \(roll, pitch, yaw\) or one for all three"),
    ("stiffness of four values", [("[160e3, 160e3, 430e3]", "[160e3, 160e3, 430e3, 1.0]")], "", DataFileError,
     rf"{F} \[secondary\] stiffness: must be 3 values \(x, y, z\)"),
    # misspelt keys and tables, missing ones
    ("misspelt yaw_stiffness", [("yaw_stiffness = 10.5e3", "yaw_stifness = 10.5e3")], "", DataFileError,
     rf"{F} \[secondary\] yaw_stifness: unknown key; did you mean 'yaw_stiffness'\?"),
    ("misspelt anti-roll bar stiffness", [("stiffness = 940e3", "stiffnes = 940e3")], "", DataFileError,
     rf"{F} \[anti_roll_bar\] stiffnes: unknown key; did you mean 'stiffness'\?"),
    ("misspelt geometry key", [("bogie_semi_wheelbase = 1.28", "bogie_semi_wheelbse = 1.28")], "", DataFileError,
     rf"{F} \[geometry\] bogie_semi_wheelbse: unknown key; did you mean 'bogie_semi_wheelbase'\?"),
    ("misspelt table", [("[primary]", "[primery]")], "", DataFileError,
     r"unknown table\(s\) \['primery'\]; did you mean 'primary'\?"),
    ("missing table", [("[secondary]", "[secondary_suspension]")], "", DataFileError,
     r"unknown table\(s\) \['secondary_suspension'\]"),
    ("missing key", [("secondary_height = 0.8275", "")], "", DataFileError,
     rf"{F} \[geometry\] secondary_height: missing key"),
    ("yaw damper without x", [], "\n[[yaw_damper]]\ndamping = 300e3\nseries_stiffness = 6e6\nnode_mass = 5.0\n"
     "y = 1.2\nz = 0.8\n", DataFileError, rf"{F} \[yaw_damper #1\] x: missing key"),
    ("yaw damper as a table", [], "\n[yaw_damper]\ndamping = 300e3\n", DataFileError,
     r"yaw_damper must be an array of tables \[\[yaw_damper\]\]"),
    ("yaw damper damping in kN s/m", [], "\n[[yaw_damper]]\ndamping = 300\nseries_stiffness = 6e6\nnode_mass = 5.0\n"
     "x = 1.5\ny = 1.2\nz = 0.8\n", ImplausibleValueError,
     rf"{F} \[yaw_damper #1\] damping: yaw damper damping 300 N s/m .*did you mean 300 kN s/m\?"),
    ("yaw damper without node mass", [], "\n[[yaw_damper]]\ndamping = 300e3\nseries_stiffness = 6e6\nnode_mass = 0\n"
     "x = 1.5\ny = 1.2\nz = 0.8\n", ImplausibleValueError,
     rf"{F} \[yaw_damper #1\] node_mass: yaw damper node mass 0 kg is outside the plausible range"),
    # contradictory geometry
    ("wheelsets of two bogies cross", [("bogie_centre_semi_distance = 9.5 ", "bogie_centre_semi_distance = 1.6 "),
                                       ("bogie_semi_wheelbase = 1.28", "bogie_semi_wheelbase = 1.8")], "", DataFileError,
     rf"{F} \[geometry\]: bogie_semi_wheelbase 1\.8 m >= bogie_centre_semi_distance 1\.6 m: the wheelsets of the two "
     r"bogies cross"),
    ("inner wheelsets overlap", [("bogie_centre_semi_distance = 9.5 ", "bogie_centre_semi_distance = 1.6 ")], "",
     DataFileError, rf"{F} \[geometry\]: the inner wheelsets of the two bogies are 0\.64 m apart .* less than a wheel "
     r"diameter 0\.92 m"),
    ("flange-back spacing equal to the gauge", [("flange_back_spacing = 1.360", "flange_back_spacing = 1.435")], "",
     DataFileError, rf"{F} \[profiles\]: flange_back_spacing 1\.435 m >= gauge 1\.435 m: the flange backs must lie "
     r"inside the rails"),
    ("flange-back spacing far inside", [("flange_back_spacing = 1.360", "flange_back_spacing = 1.20")], "",
     DataFileError, rf"{F} \[profiles\]: gauge - flange_back_spacing = 235 mm is outside 30 \.\.\. 200 mm"),
    ("secondary spacing beyond the loading gauge",
     [("secondary_lateral_semi_spacing = 1.0 ", "secondary_lateral_semi_spacing = 2.0 ")], "",
     ImplausibleValueError, rf"{F} \[geometry\] secondary_lateral_semi_spacing: secondary lateral semi-spacing 2 m is "
     r"outside the plausible range 0\.4 m \.\.\. 1\.6 m"),
    ("bogie cg above car body cg", [("car_body_cg_height = 1.8 ", "car_body_cg_height = 0.55 ")], "", DataFileError,
     rf"{F} \[geometry\]: bogie_cg_height 0\.6 m >= car_body_cg_height 0\.55 m"),
    ("all masses in tonnes, ranges waived: axle load", [("mass = 32000.0", "mass = 32"), ("mass = 2615.0", "mass = 2.615"), ("mass = 1813.0", "mass = 1.813")],
     '\n[checks]\naccept = ["car_body_mass", "bogie_mass", "wheelset_mass"]\n', ImplausibleValueError,
     rf"{F}: the axle load \(total mass per axle\) implied by the file, .* = 0\.01112 t, .*are the masses in kg\?"),
    # profiles and names
    ("unknown wheel profile name", [('wheel = "S1002"', 'wheel = "S1003"')], "", DataFileError,
     rf"{F} \[profiles\] wheel: 'S1003' is neither a built-in wheel profile \(S1002\) nor a profile file .*; "
     r"did you mean 'S1002'\?"),
    ("unknown rail profile name", [('rail = "UIC60"', 'rail = "UIC 60"')], "", DataFileError,
     rf"{F} \[profiles\] rail: 'UIC 60' is neither a built-in rail profile .*did you mean 'UIC60'\?"),
    ("inclination 40 for 1:40", [('inclination = "1:40"', "inclination = 40")], "", InputError,
     rf"{F} \[profiles\] inclination: rail inclination 40\.0 is implausibly large .*did you mean '1:40'"),
    ("inclination with the wrong sign", [('inclination = "1:40"', 'inclination = "-1:40"')], "", InputError,
     r"rail inclination -0\.025 \(given as '-1:40'\) is negative"),
    # bump stop table
    ("bump stop in mm", [("displacement = [0.025, 0.030,", "displacement = [25, 30,")], "", ImplausibleValueError,
     rf"{F} \[lateral_bump_stop\] displacement: lateral bump-stop displacement 25 m .*did you mean 25 mm\?"),
    ("bump stop without clearance row", [("force = [0.0, 600.0,", "force = [100.0, 600.0,")], "", DataFileError,
     r"\[lateral_bump_stop\]: the first row is the clearance, at force 0 N; got force\[0\] = 100 N"),
    ("bump stop lists of unequal length", [("force = [0.0, 600.0,", "force = [600.0,")], "", DataFileError,
     r"\[lateral_bump_stop\]: displacement and force must be lists of equal length, got 9 and 8"),
    # the [checks] table itself
    ("misspelt accepted quantity", [], '\n[checks]\naccept = ["car_body_mas"]\n', DataFileError,
     rf"{F} \[checks\] accept: 'car_body_mas' is not a quantity or rule name; did you mean 'car_body_mass'\?"),
]


@pytest.mark.parametrize("edits,append,err,pattern", [c[1:] for c in FILE_CASES], ids=[c[0] for c in FILE_CASES])
def test_careless_vehicle_file(tmp_path, edits, append, err, pattern):
    f = _write(tmp_path, *edits, append=append)
    with pytest.raises(err, match=pattern) as info:
        VehicleDefinition.from_toml(f)
    assert "\n" not in str(info.value)  # one line


def test_secondary_suspension_above_the_car_body_cg_is_a_named_warning(tmp_path):
    f = _write(tmp_path, ("secondary_height = 0.8275", "secondary_height = 2.0"))
    with pytest.warns(SuspensionGeometryWarning, match=r"secondary_height 2 m is above car_body_cg_height 1\.8 m"):
        D = VehicleDefinition.from_toml(f)
    assert D.geometry["secondary_height"] == 2.0


def test_not_toml_and_no_file(tmp_path):
    f = tmp_path / "coach.toml"
    f.write_text(TEXT.replace("[car_body]", "[car_body"), encoding="utf-8")
    with pytest.raises(DataFileError, match=r"coach\.toml: not valid TOML"):
        VehicleDefinition.from_toml(f)
    with pytest.raises(DataFileError, match=r"vehicle file .*none\.toml does not exist"):
        VehicleDefinition.from_toml(tmp_path / "none.toml")


def test_wheel_profile_file_in_metres(tmp_path):
    from railway.contact.profiles import s1002_exact

    y = np.linspace(-60.0, 55.0, 231)
    (tmp_path / "wheel_m.txt").write_text("\n".join(f"{a * 1e-3:.7f} {b * 1e-3:.7f}" for a, b in
                                                    zip(y, s1002_exact(y)[0])), encoding="utf-8")
    f = _write(tmp_path, ('wheel = "S1002"', 'wheel = "wheel_m.txt"'))
    with pytest.raises(InputError, match=r"wheel_m\.txt: values look like metres .*; profile files are in mm"):
        VehicleDefinition.from_toml(f)


def test_missing_profile_file(tmp_path):
    f = _write(tmp_path, ('wheel = "S1002"', 'wheel = "my_wheel.txt"'))
    with pytest.raises(DataFileError, match=r"\[profiles\] wheel: 'my_wheel.txt' is neither a built-in wheel profile "
                                            r"\(S1002\) nor a profile file \(.*my_wheel.txt does not exist\)"):
        VehicleDefinition.from_toml(f)


# ---------------------------------------------------------------------------------------------
# resolution: deliberate outliers, units equal to SI, no false alarms
# ---------------------------------------------------------------------------------------------
def test_accept_in_the_file_and_as_argument(tmp_path):
    edits = [("mass = 32000.0", "mass = 32")]
    f = _write(tmp_path, *edits, append='\n[checks]\naccept = ["car_body_mass", "secondary_static_deflection"]\n')
    assert VehicleDefinition.from_toml(f).car_body["mass"] == 32.0
    g = _write(tmp_path, *edits)
    with pytest.raises(ImplausibleValueError, match="secondary static deflection"):  # the next check still runs
        VehicleDefinition.from_toml(g, accept=["car_body_mass"])
    D = VehicleDefinition.from_toml(g, accept=["car_body_mass", "secondary_static_deflection"])
    assert D.car_body["mass"] == 32.0
    with pytest.raises(ImplausibleValueError, match="secondary static deflection"):  # one name as a string
        VehicleDefinition.from_toml(g, accept="car_body_mass")


def test_values_with_units_equal_the_si_numbers(tmp_path, coach):
    f = _write(tmp_path, ("mass = 32000.0", 'mass = "32 t"'),
               ("[31391e3, 3884e3, 1220e3]", '["31.391 MN/m", "3884 kN/m", "1220 N/mm"]'),
               ("car_body_cg_height = 1.8 ", 'car_body_cg_height = "1800 mm" '),
               ("[56800.0, 1970000.0, 1970000.0]", '["56.8 t m^2", 1970000.0, "1970 t*m**2"]'),
               ("[15e3, 2e3, 4e3]", '["15 kN*s/m", "2 kN s/m", 4e3]'),
               ("nominal_wheel_radius = 0.46 ", 'nominal_wheel_radius = "460 mm" '),
               ('inclination = "1:40"', 'inclination = "1/40"'))
    D = VehicleDefinition.from_toml(f)
    for part in ("car_body", "primary"):
        for k, v in getattr(coach, part).items():
            np.testing.assert_allclose(getattr(D, part)[k], v, rtol=1e-12)
    assert D.geometry == coach.geometry and D.r0 == coach.r0
    assert D.rails().inclination == coach.rails().inclination == 0.025


def test_shipped_vehicle_file_and_ranges_pass(coach):
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        D = VehicleDefinition.from_toml(COACH)
    assert D.total_mass == coach.total_mass == 32000.0 + 2 * 2615.0 + 4 * 1813.0
    assert D.static_deflections() == pytest.approx((0.03744, 0.18247), rel=1e-3)
    R = ranges()
    # every quantity has a rationale and one row; every range the code uses exists
    assert all(r.rationale for r in R)
    rows = [line.split(",")[0] for line in Path(R.source).read_text(encoding="utf-8").splitlines()
            if line.strip() and not line.startswith("#")][1:]
    assert len(rows) == len(set(rows)), sorted({q for q in rows if rows.count(q) > 1})
    from railway.vehicles.vehicle_file import VehicleFile  # noqa: F401  (importing builds the schema: names resolve)

    for q in ("speed", "friction_coefficient", "vehicle_lateral_offset", "curve_radius", "cant", "cant_base",
              "transition_length", "track_segment_length", "irregularity_amplitude", "irregularity_sample_spacing",
              "axle_load", "primary_static_deflection", "secondary_static_deflection"):
        assert q in R


def test_vehicle_from_dict_names_the_function():
    import tomllib

    d = tomllib.loads(TEXT)
    d["car_body"]["mass"] = 32
    with pytest.raises(ImplausibleValueError, match=r"^VehicleDefinition\.from_dict\(\) \[car_body\] mass: .*did you "
                                                     r"mean 32 t\?"):
        VehicleDefinition.from_dict(d)


# ---------------------------------------------------------------------------------------------
# build_vehicle's keyword arguments
# ---------------------------------------------------------------------------------------------
BUILD_CASES = [
    ("speed with a typo in the unit", dict(speed="72 kmh"), UnitError,
     r"build_vehicle\(speed=\.\.\.\): cannot read '72 kmh' as a quantity in m/s"),
    ("speed in km/h as m/s", dict(speed=200), ImplausibleValueError,
     r"build_vehicle\(speed=\.\.\.\): vehicle speed 200 m/s is outside the plausible range 0 m/s \.\.\. 150 m/s: "
     r"did you mean 200 km/h\?"),
    ("negative speed", dict(speed=-20), ImplausibleValueError, r"vehicle speed -20 m/s is outside the plausible range"),
    ("speed NaN", dict(speed=float("nan")), InputError, r"build_vehicle\(speed=\.\.\.\): nan is not a finite number"),
    ("speed as words", dict(speed="fast"), UnitError, r"build_vehicle\(speed=\.\.\.\): cannot read 'fast'"),
    ("speed as a list", dict(speed=[20.0]), InputError,
     r"build_vehicle\(speed=\.\.\.\): one number \(or a string with a unit\), got \[20\.0\]"),
    ("rear wheelsets before the track start", dict(s0=5.0), InputError,
     r"build_vehicle: the rear wheelset at s = -5\.78 m lies before the start of the track \[0, 100\] m \(car body at "
     r"s0 = 5 m\): place the car body at 10\.78 m <= s0 <= 89\.22 m"),
    ("leading wheelset beyond the track end", dict(s0="95 m"), InputError,
     r"the leading wheelset at s = 105\.78 m lies beyond the end of the track"),
    ("s0 with a wrong unit", dict(s0="30 s"), UnitError, r"build_vehicle\(s0=\.\.\.\): '30 s' is a time"),
    ("misspelt creep law", dict(creep_law="kalker_linaer"), UnknownNameError,
     r"build_vehicle\(creep_law=\.\.\.\): unknown creep law 'kalker_linaer'; did you mean 'kalker_linear'\?"),
    ("friction in percent", dict(mu=30), ImplausibleValueError,
     r"build_vehicle\(mu=\.\.\.\): wheel-rail friction coefficient 30 is outside .*did you mean 30 %\?"),
    ("lateral offset in mm", dict(lateral=2.0), ImplausibleValueError,
     r"build_vehicle\(lateral=\.\.\.\): initial lateral offset 2 m .*did you mean 2 mm\?"),
    ("three wheelset offsets", dict(wheelset_lateral=[0.0, 0.0, 0.001]), InputError,
     r"build_vehicle\(wheelset_lateral=\.\.\.\): must be 4 values"),
    ("wheelset offset in mm", dict(wheelset_lateral=[3.0, 0, 0, 0]), ImplausibleValueError,
     r"build_vehicle\(wheelset_lateral=\.\.\.\): initial lateral offset \[0\] 3 m .*did you mean 3 mm\?"),
    ("misspelt contact option", dict(contact_options={"reseed": 2}), UnknownOptionError,
     r"build_vehicle\(contact_options=\.\.\.\): unknown option 'reseed'; did you mean 'reseed_every'\?"),
    ("speed control in km/h as m/s", dict(speed_control=300), ImplausibleValueError,
     r"build_vehicle\(speed_control=\.\.\.\): vehicle speed 300 m/s .*did you mean 300 km/h\?"),
    ("misspelt accept", dict(accept=["sped"]), InputError,
     r"build_vehicle\(accept=\.\.\.\): 'sped' is not a quantity .*did you mean 'speed'\?"),
    ("negative control gain", dict(control_gain=-1.0), InputError, r"build_vehicle\(control_gain=\.\.\.\): -1 N s/m"),
]


@pytest.mark.parametrize("kw,err,pattern", [c[1:] for c in BUILD_CASES], ids=[c[0] for c in BUILD_CASES])
def test_careless_build_arguments(coach, kw, err, pattern):
    args = dict(s0=30.0, speed=20.0)
    args.update(kw)
    with pytest.raises(err, match=pattern):
        build_vehicle(coach, Track.straight(100.0), **args)


def test_definition_given_as_a_path():
    with pytest.raises(InputError, match=r"definition must be a VehicleDefinition, got PosixPath \(read the file with "
                                         r"VehicleDefinition\.from_toml\(path\)\)"):
        build_vehicle(COACH, Track.straight(100.0), s0=30.0)


def test_track_shorter_than_the_vehicle(coach):
    with pytest.raises(InputError, match=r"the track \(15 m\) is shorter than the vehicle's wheelbase \(21\.56 m\)"):
        build_vehicle(coach, Track.straight(15.0), s0=7.5)


def test_speed_with_a_unit_equals_the_si_number(coach):
    tr = Track.straight(100.0)
    a = build_vehicle(coach, tr, s0="30 m", speed="72 km/h", speed_control="72 km/h", mu="30 %")
    b = build_vehicle(coach, tr, s0=30.0, speed=20.0, speed_control=20.0, mu=0.3)
    assert a.speed == b.speed == pytest.approx(20.0, rel=1e-14) and a.s0 == b.s0 == 30.0
    np.testing.assert_allclose(a.model.v0, b.model.v0, rtol=1e-14)
    # a deliberate outlier
    c = build_vehicle(coach, tr, s0=30.0, speed=200.0, accept=["speed"])
    assert c.speed == 200.0


@pytest.mark.parametrize("method", ["dop853", "jit-dop853"])
def test_a_run_past_the_end_of_an_open_track_fails_naming_the_end(coach, method):
    """The track is not extrapolated: the run ends 'failed' when the leading wheelset leaves, on
    the Python and on the compiled path."""
    from core.integrators import simulate

    tr = Track.straight(40.0)
    veh = build_vehicle(coach, tr, s0=28.5, speed=20.0, speed_control=20.0)
    veh.preload()
    q0, v0 = veh.initial_state()
    res = simulate(veh.model, (0.0, 0.2), method, q0=q0, v0=v0, rtol=1e-5, atol=1e-7)
    assert res.status == "failed"
    assert re.search(r"wheelset 'wheelset 1' \(wheel-rail\) ran past the end of the track at s = 40 m: the track is "
                     r"open and is not extrapolated", res.message)
    assert res.t[-1] == pytest.approx((40.0 - 28.5 - 9.5 - 1.28) / 20.0, abs=2e-3)


def test_a_wheelset_past_the_end_has_no_rail_under_it(coach):
    """The search's projection (with a guess, as during a run) gives no arc length beyond the end."""
    from core.errors import DataRangeError

    tr = Track.straight(40.0)
    veh = build_vehicle(coach, tr, s0=20.0, speed=0.0)
    st = veh.contact_kind.sets[0]
    s = st._project(np.array([[41.0, 0.0, 0.46], [20.0, 0.0, 0.46]]), np.array([39.9, 20.0]))
    assert np.isnan(s[0]) and s[1] == pytest.approx(20.0)
    assert "end of the track at s = 40 m" in st.off_track_message(0, np.zeros(3), 39.99)
    assert issubclass(DataRangeError, InputError)  # raised during a run it ends the run as failed


# ---------------------------------------------------------------------------------------------
# track, curves, irregularities
# ---------------------------------------------------------------------------------------------
TRACK_CASES = [
    ("cant in mm", lambda: Track([Straight(50.0), Curve(100.0, 300.0, 150)]), InputError,
     r"track: segment 1 cant 150\.0 m must be in \[0, 1\.5\): did you mean 150 mm\?"),
    ("cant too high", lambda: Track([Curve(100.0, 300.0, 0.35)]), ImplausibleValueError,
     r"track: segment 0 \(Curve\) cant: cant height 0\.35 m is outside the plausible range 0 m \.\.\. 0\.2 m"),
    ("negative cant for a right-hand curve", lambda: Track([Curve(100.0, 300.0, -0.1)]), InputError,
     r"cant -0\.1 m must be in \[0, 1\.5\): the cant is the height of the outer rail \(>= 0\), the direction of the "
     r"curve the sign of the radius"),
    ("radius in km", lambda: Track([Curve(100.0, 2.0, 0.1)]), ImplausibleValueError,
     r"track: segment 0 \(Curve\) radius: curve radius \(magnitude\) 2 m .*did you mean 2 km\?"),
    ("radius in mm", lambda: Track([Curve(100.0, -300000.0, 0.1)]), ImplausibleValueError,
     r"curve radius \(magnitude\) 300000 m .*did you mean 300000 mm\?"),
    ("zero radius", lambda: Track([Straight(10.0), Curve(10.0, 0.0)]), InputError,
     r"track: segment 1 radius 0\.0 must be finite, non-zero"),
    ("transition length in km", lambda: Track([Straight(10.0), Transition(0.05), Curve(50.0, 300.0)]),
     ImplausibleValueError, r"track: segment 1 \(Transition\) length: transition length 0\.05 m .*did you mean 0\.05 km\?"),
    ("segment length as words", lambda: Straight("long"), UnitError, r"Straight\(length=\.\.\.\): cannot read 'long'"),
    ("radius with a wrong unit", lambda: Curve(100.0, "300 s"), UnitError, r"Curve\(radius=\.\.\.\): '300 s' is a time"),
    ("negative length", lambda: Track([Straight(-10.0)]), InputError, r"track: segment 0 length -10\.0 must be positive"),
    ("cant base in mm", lambda: Track([Straight(10.0)], cant_base=1500), ImplausibleValueError,
     r"track: cant_base: cant base 1500 m .*did you mean 1500 mm\?"),
    ("irregularities as a bare array", lambda: Track([Straight(10.0)], irregularities=np.zeros((4, 3))), InputError,
     r"track: irregularities must be an Irregularities table"),
    ("inclination in degrees", lambda: parse_inclination(1.43), InputError,
     r"rail inclination 1\.43 is implausibly large .*did you mean 1\.43 degrees"),
]


@pytest.mark.parametrize("make,err,pattern", [c[1:] for c in TRACK_CASES], ids=[c[0] for c in TRACK_CASES])
def test_careless_track(make, err, pattern):
    with pytest.raises(err, match=pattern):
        make()


def _irr_csv(tmp_path, s_head="s [m]", lat_head="lateral [m]", scale_s=1.0, scale_amp=1.0, taper=True):
    import pandas as pd

    s = np.linspace(0.0, 100.0, 401)
    w = np.sin(np.pi * s / 100.0) ** 2 if taper else 1.0
    f = tmp_path / "irr.csv"
    pd.DataFrame({s_head: s * scale_s, lat_head: 2e-3 * np.cos(s / 4.0) * w * scale_amp,
                  "vertical [m]": 1e-3 * np.sin(s / 7.0) * w}).to_csv(f, index=False)
    return f


IRR_CASES = [
    ("amplitudes in mm under a header in m", dict(scale_amp=1e3), ImplausibleValueError,
     r"irr\.csv \(column 'lateral \[m\]'\) lateral\[\d+\]: irregularity amplitude -?1\.99\d* m is outside the "
     r"plausible range -0\.05 m \.\.\. 0\.05 m: did you mean -?1\.99\d* mm\?"),
    ("arc length in mm under a header in m", dict(scale_s=1e3), ImplausibleValueError,
     r"irr\.csv \(column 's \[m\]'\) s step\[\d+\]: irregularity sample spacing 250 m .*did you mean 250 mm\?"),
    ("column without unit", dict(lat_head="lateral"), DataFileError,
     r"irr\.csv: missing column 'lateral \[m\]' \(or \[mm\]\); column 'lateral' has no unit: name it 'lateral \[m\]'"),
    ("misspelt column", dict(lat_head="lateal [m]"), DataFileError,
     r"irr\.csv: missing column 'lateral \[m\]' \(or \[mm\]\); did you mean 'lateal \[m\]'\?"),
    ("amplitudes in m under a header in mm", dict(lat_head="lateral [mm]", scale_amp=1e5), ImplausibleValueError,
     r"\(column 'lateral \[mm\]'\) lateral\[\d+\]: irregularity amplitude -?0\.199\d* m is outside"),
]


@pytest.mark.parametrize("kw,err,pattern", [c[1:] for c in IRR_CASES], ids=[c[0] for c in IRR_CASES])
def test_careless_irregularity_file(tmp_path, kw, err, pattern):
    with pytest.raises(err, match=pattern):
        Irregularities.from_csv(_irr_csv(tmp_path, **kw))


def test_irregularities_in_arrays():
    s = np.linspace(0.0, 100.0, 101)
    w = np.sin(np.pi * s / 100.0) ** 2
    with pytest.raises(ImplausibleValueError, match=r"irregularities vertical\[\d+\]: irregularity amplitude 3 m .*did "
                                                    r"you mean 3 mm\?"):
        Irregularities(s, 0 * s, 3.0 * w)
    with pytest.raises(InputError, match=r"irregularities: column lateral must be 1-D of length 101, got shape \(100,\)"):
        Irregularities(s, s[:-1] * 0, 0 * s)
    with pytest.raises(InputError, match=r"irregularities: s must increase strictly; s\[5\]"):
        Irregularities(np.r_[s[:5], s[4:-1]], 0 * s, 0 * s)
    ok = Irregularities(s, 0 * s, 3.0 * w, accept=("irregularity_amplitude",))  # deliberately
    assert ok.vertical.max() == pytest.approx(3.0)


def test_untapered_irregularities_are_a_named_warning(tmp_path):
    with pytest.warns(IrregularityStepWarning, match=r"irr\.csv: lateral irregularity is 2 mm at s = 0 m, the start of "
                                                     r"the table .*the centreline steps"):
        ir = Irregularities.from_csv(_irr_csv(tmp_path, taper=False))
    assert ir.lateral[0] == pytest.approx(2e-3)


def test_irregularities_in_mm_equal_those_in_m(tmp_path):
    import pandas as pd

    a = Irregularities.from_csv(_irr_csv(tmp_path))
    df = pd.read_csv(tmp_path / "irr.csv")
    df["lateral [m]"] *= 1e3
    df = df.rename(columns={"lateral [m]": "lateral [mm]"})
    g = tmp_path / "irr_mm.csv"
    df.to_csv(g, index=False)
    b = Irregularities.from_csv(g)
    np.testing.assert_allclose(b.lateral, a.lateral, rtol=1e-14, atol=1e-18)


def test_curves_with_units_equal_the_si_numbers():
    a = Track([Straight("50 m"), Transition("0.04 km"), Curve("200 m", "1.2 km", cant="150 mm")])
    b = Track([Straight(50.0), Transition(40.0), Curve(200.0, 1200.0, cant=0.150)])
    s = np.linspace(0.0, a.length, 57)
    np.testing.assert_array_equal(a.evaluate(s).position, b.evaluate(s).position)
    # a deliberate outlier
    assert Track([Curve(100.0, 5.0)], accept=["curve_radius"]).length == 100.0


def test_scene_tracks_raise_no_false_alarm():
    from railway.vehicles.curving import curving_track
    from railway.vehicles.ride import irregularities

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        curving_track()
        Track.straight(160.0, irregularities=irregularities(160.0, seed=3))


# ---------------------------------------------------------------------------------------------
# profile readers
# ---------------------------------------------------------------------------------------------
def test_rail_profile_in_metres(tmp_path):
    from railway.contact.profiles import RailProfile

    u = np.linspace(-0.035, 0.035, 71)
    f = tmp_path / "rail_m.txt"
    f.write_text("\n".join(f"{a:.6f} {-(a * a) / 0.6:.8f}" for a in u), encoding="utf-8")
    with pytest.raises(InputError, match=r"rail_m\.txt: values look like metres \(the lateral coordinate spans 0\.07, "
                                         r"the heights .*\); profile files are in mm: multiply by 1000"):
        RailProfile.from_file(f)


def test_wheel_profile_points_in_metres_are_not_answered_with_the_flange_side():
    from railway.contact.profiles import WheelProfile, s1002_exact

    y = np.linspace(-60.0, 55.0, 231)
    with pytest.raises(InputError, match=r"values look like metres") as info:
        WheelProfile.from_points(y * 1e-3, s1002_exact(y)[0] * 1e-3, r0=0.46, y_back=-70.0)
    assert "flange_side" not in str(info.value)


def test_definition_changed_in_code_with_impossible_values(coach):
    """A definition made or changed in code is not read through the file checks: build_vehicle
    refuses the values no model can be built from, naming the field (a zero vertical stiffness is
    named by VehicleDefinition.static_deflections, tests/railway/test_wheel_events.py)."""
    import dataclasses

    bad = dataclasses.replace(coach, secondary={**coach.secondary, "damping": np.array([0.0, -32e3, 20e3])})
    with pytest.raises(InputError, match=r"build_vehicle: definition\.secondary\['damping'\]\[1\] = -32000\.0 must be "
                                         r">= 0 and finite"):
        build_vehicle(bad, Track.straight(100.0), s0=30.0)
    bad = dataclasses.replace(coach, car_body={**coach.car_body, "mass": float("nan")})
    with pytest.raises(InputError, match=r"definition\.car_body\['mass'\] = nan must be > 0"):
        build_vehicle(bad, Track.straight(100.0), s0=30.0)


def test_misspelt_creep_parameter(coach):
    with pytest.raises(UnknownOptionError, match=r"build_vehicle\(creep_params=\.\.\.\) of Polach2005: unknown option "
                                                 r"'kA'; did you mean 'k_A'\?"):
        build_vehicle(coach, Track.straight(100.0), s0=30.0, speed=20.0, creep_law="polach2005",
                      creep_params={"kA": 0.5})


# ---------------------------------------------------------------------------------------------
# follow-ups: flange-contact onset, rail crowns, profile files, library checks, gauge, track ends
# ---------------------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def onset_table():
    from railway.contact.geometry import contact_geometry_table, contact_transitions

    t = contact_geometry_table(np.linspace(0.0, 0.008, 17))
    return t, contact_transitions(t)


def test_flange_onset_bisection_failure_is_a_numerical_failure(onset_table):
    from core.errors import NumericalFailure
    from railway.contact.geometry import flange_contact_onset

    t, tr = onset_table
    y_f, _ = flange_contact_onset(t, transitions=tr)
    assert 0.004 < y_f < 0.008
    bad = tr.copy()
    bad["status"] = "not located: no convergence: largest gap 1e-06 m after 40 iterations at lateral shift 0.006 m"
    with pytest.raises(NumericalFailure, match=r"flange contact onset of wheel S1002 on rail UIC60, gauge 1435 mm, "
                                               r"flange-back spacing 1360 mm: not located between the table rows "
                                               r"y = \d\.\d{4} and \d\.\d{4} mm: the rigid contact within them "
                                               r"failed \(no convergence: largest gap .*\); the onset lies between "
                                               r".* \(exact=False gives the first row with flange contact") as info:
        flange_contact_onset(t, transitions=bad)
    assert not isinstance(info.value, RuntimeError) and "\n" not in str(info.value)
    assert flange_contact_onset(t, transitions=bad, exact=False)[0] >= y_f  # the fallback still works


def test_flange_onset_with_transitions_of_another_table(onset_table):
    from railway.contact.geometry import flange_contact_onset

    t, tr = onset_table
    with pytest.raises(InputError, match=r"flange contact onset of wheel S1002 on rail UIC60, gauge 1435 mm.*: the "
                                         r"transitions given have no flange-contact transition of the left wheel "
                                         r"between the table rows y = .* mm: pass contact_transitions\(\) of this "
                                         r"table, or none"):
        flange_contact_onset(t, transitions=tr.iloc[0:0])


RAIL_CROWN_CASES = [
    ("flat", lambda u: 0.0 * u, r"rail head has no crown: it is flat \(its heights vary by 0 mm over its width of 72 mm\)"),
    ("V-shaped", lambda u: -np.abs(u), r"rail head has no crown: it comes to a point \(V-shaped\): within \+-3 mm of "
                                        r"its highest point \(u = 0 mm\) it falls by 3 mm on average \(crown radius "
                                        r"1\.5 mm, below 5 mm\)"),
    ("flat crown", lambda u: -20.0 * (u / 36.0) ** 6,
     r"rail head has no crown: it is flat at the top: within \+-3 mm of its highest point \(u = -?[\d.]+ mm\) it falls "
     r"by .* mm on average \(crown radius .* m, above 100 m\)"),
    ("depths read as heights", lambda u: u * u / 60,
     r"rail head has no crown: its highest point, u = -?36 mm, lies within 3 mm of its (first|last) point: .*"
     r"read the file with vertical='depth'"),
]


@pytest.mark.parametrize("shape,pattern", [c[1:] for c in RAIL_CROWN_CASES], ids=[c[0] for c in RAIL_CROWN_CASES])
def test_rail_profile_without_a_crown_is_refused_naming_the_file(tmp_path, shape, pattern):
    from railway.contact.profiles import RailProfile

    u = np.arange(-36.0, 37.0)
    f = tmp_path / "rail.txt"
    f.write_text("".join(f"{a:g} {b:.6f}\n" for a, b in zip(u, shape(u))), encoding="utf-8")
    with pytest.raises(InputError, match=re.escape(str(f)) + ": " + pattern) as info:
        RailProfile.from_file(f)
    assert not isinstance(info.value, ZeroDivisionError) and "\n" not in str(info.value)


def test_rail_mounting_refuses_a_profile_without_a_crown():
    """A profile made in code (not read through the reader) is checked by RailMounting itself:
    no ZeroDivisionError from the Newton iterations on the top and the gauge point."""
    from core.curves import PiecewisePoly
    from railway.contact.profiles import RailProfile
    from railway.track import RailMounting

    flat = RailProfile(PiecewisePoly(np.array([-0.036, 0.036]), np.zeros((1, 1))), name="flat head")
    with pytest.raises(InputError, match=r"rail mounting: profile flat head: rail head has no crown: it is flat"):
        RailMounting(flat)
    with pytest.raises(InputError, match=r"rail mounting: profile flat head: rail head has no crown"):
        RailMounting(flat, inclination="1:20")
    RailMounting()  # UIC60 has its crown (R300)


def test_profile_file_with_nan_names_the_line_with_plain_floats(tmp_path):
    from railway.contact.profiles import RailProfile, WheelProfile

    f = tmp_path / "rail_nan.txt"
    f.write_text("# u v\n-3 -0.1\n-1 0.0\n0 nan\n1 0.0\n3 -0.1\n", encoding="utf-8")
    with pytest.raises(DataFileError, match=r"rail_nan\.txt:4: point \(0\.0, nan\) is not finite \(in '0 nan'\)") as info:
        RailProfile.from_file(f)
    assert "np.float64" not in str(info.value)
    with pytest.raises(InputError, match=r"mine: vertical coordinate of point 2 is nan \(not finite\)") as info:
        RailProfile.from_points([-3.0, -1.0, 0.0, 1.0, 3.0], [0.0, 0.1, np.nan, 0.1, 0.0], name="mine")
    assert "np.float64" not in str(info.value)
    g = tmp_path / "wheel_back.txt"
    g.write_text("-10 1\n-5 0.5\n-7.25 0.3\n0 0\n5 -0.1\n", encoding="utf-8")
    with pytest.raises(InputError, match=r"wheel_back\.txt: lateral coordinate is not strictly monotonic at point 2 "
                                         r"\(value -7\.25 after -5\.0\)") as info:
        WheelProfile.from_file(g, r0=0.46)
    assert "np.float64" not in str(info.value)


@pytest.mark.parametrize("reader", ["rail", "wheel"])
def test_binary_profile_file_is_named(tmp_path, reader):
    from railway.contact.profiles import RailProfile, WheelProfile

    f = tmp_path / "scan.png"
    f.write_bytes(b"\x89PNG\r\n\x1a\n\x00\x00\x00\rIHDR\xff\xfe")
    with pytest.raises(DataFileError, match=re.escape(str(f)) + r": not a text profile file \(byte 0x89 at offset 0 "
                                            r"is not UTF-8; expected two columns, lateral and vertical in mm\)"):
        RailProfile.from_file(f) if reader == "rail" else WheelProfile.from_file(f, r0=0.46)
    g = tmp_path / "nul.txt"
    g.write_bytes(b"1 2\n\x00\x00\x00\n")
    with pytest.raises(DataFileError, match=r"nul\.txt: not a text profile file \(it contains NUL bytes"):
        RailProfile.from_file(g) if reader == "rail" else WheelProfile.from_file(g, r0=0.46)


from railway.contact.creep import Polach2005  # noqa: E402
from railway.contact.creep_curve import creep_curve  # noqa: E402
from railway.contact.creepage import creepages  # noqa: E402
from railway.contact.two_point import conical_wheel_points  # noqa: E402

LIBRARY_CASES = [
    ("creep curve without G or E",
     lambda: creep_curve("kalker_linear", normal_force=1e5, a=6e-3, b=4e-3),
     InputError, r"creep curve: give the shear modulus G or Young's modulus E \(both are None\), e\.g\. G=8e10"),
    ("creep curve without semi-axes or curvatures",
     lambda: creep_curve("kalker_linear", normal_force=1e5, G=8e10),
     InputError, r"creep curve: give the semi-axes a and b, or the curvatures A and B with Young's modulus E "
                 r"\(got a=None, b=None, A=None, B=None, E=None\)"),
    ("creep curve misspelt creepage",
     lambda: creep_curve("kalker_linear", creepage="xii", normal_force=1e5, a=6e-3, b=4e-3, G=8e10),
     InputError, r"creep curve: creepage 'xii' is not one of \['eta', 'phi', 'xi'\]; did you mean 'xi'\?"),
    ("creep curve values as a matrix",
     lambda: creep_curve("kalker_linear", normal_force=1e5, a=6e-3, b=4e-3, G=8e10, values=np.zeros((2, 2))),
     InputError, r"creep curve: values \(the swept xi\) must be a non-empty 1-D array, got shape \(2, 2\)"),
    ("Polach k_S above k_A", lambda: Polach2005(k_A=np.float64(0.3), k_S=0.5),
     InputError, r"Polach 2005 needs 0 < k_S <= k_A <= 1 \(reduction factors of Kalker's slope\), got k_A=0\.3, "
                 r"k_S=0\.5$"),
    ("Polach A above 1", lambda: Polach2005(A=1.5),
     InputError, r"Polach 2005 friction ratio A must lie in \(0, 1\], got 1\.5 \(A = mu_inf / mu_0"),
    ("Polach B NaN", lambda: Polach2005(B=float("nan")),
     InputError, r"Polach 2005 friction decay B must be >= 0 s/m and finite, got nan$"),
    ("Polach speed as text", lambda: Polach2005(speed="20 m/s"),
     InputError, r"Polach 2005 parameter speed = '20 m/s' is not a number"),
    ("conical wheel cone in degrees",
     lambda: conical_wheel_points(cone=2.0),
     InputError, r"two-point wheel: cone = 2\.0 must lie in \(0, 0\.5\)"),
    ("creepages of a zero normal",
     lambda: creepages(np.zeros(3), np.zeros(3), np.array([1.0, 0, 0]), np.array([0, 0, 0.46]), np.array([20.0, 0, 0]),
         np.array([0, -20 / 0.46, 0])),
     InputError, r"creepages: normal has zero length at contact 0"),
]


@pytest.mark.parametrize("call,err,pattern", [c[1:] for c in LIBRARY_CASES], ids=[c[0] for c in LIBRARY_CASES])
def test_library_checks_raise_input_errors_naming_the_value(call, err, pattern):
    with pytest.raises(err, match=pattern) as info:
        call()
    assert type(info.value) is not ValueError and isinstance(info.value, ValueError)  # old tests still hold
    assert "np.float64" not in str(info.value) and "\n" not in str(info.value)


def test_rigid_contact_failure_is_a_numerical_failure(monkeypatch):
    """A shift whose iteration does not converge (forced here by one iteration) ends in a
    NumericalFailure naming the profiles, the gauge and the shift, not a RuntimeError."""
    from core.errors import NumericalFailure
    from railway.contact.geometry import rigid_contact

    with pytest.raises(NumericalFailure, match=r"rigid contact of wheel S1002 on rail UIC60, gauge 1435 mm: no "
                                               r"convergence: largest gap .* m after 1 iterations at lateral shift "
                                               r"0\.003 m"):
        rigid_contact([0.003], max_iter=1, tol=1e-15)


def test_rail_mounting_gauge_uses_the_range_table():
    """One source of truth: RailMounting refuses a gauge outside the `gauge` row of
    plausible_ranges.csv (0.6-1.7 m), with the slip named, and lets a deliberate one through."""
    from railway.contact.geometry import contact_geometry_table
    from railway.track import RailMounting

    g = ranges()["gauge"]
    assert (g.low, g.high) == (0.6, 1.7)
    with pytest.raises(ImplausibleValueError, match=r"rail mounting: gauge: track gauge 1435 m is outside the "
                                                    r"plausible range 0\.6 m \.\.\. 1\.7 m: did you mean 1435 mm\? "
                                                    r"\(to use it deliberately, accept='gauge'\)"):
        RailMounting(gauge=1435)
    for gauge in (0.5, 1.8):  # inside the old 0.3-2.0 m of RailMounting, outside the table
        with pytest.raises(ImplausibleValueError, match=rf"track gauge {gauge:g} m is outside the plausible range"):
            RailMounting(gauge=gauge)
        assert RailMounting(gauge=gauge, accept=["gauge"]).gauge == gauge
    assert RailMounting(gauge=1.0).gauge == 1.0  # metre gauge
    # the accepted gauge reaches the mounting through the table and its attrs
    t = contact_geometry_table([0.0], gauge=1.8, flange_back_spacing=1.725, accept="gauge")
    assert t.attrs["accept"] == ("gauge",) and t["status"].iloc[0] == "ok"
    with pytest.raises(ImplausibleValueError, match=r"track gauge 1\.8 m"):
        contact_geometry_table([0.0], gauge=1.8, flange_back_spacing=1.725)


def test_accepted_gauge_of_a_vehicle_file_reaches_its_rails(tmp_path):
    f = _write(tmp_path, ("gauge = 1.435 ", "gauge = 1.8 "), ("flange_back_spacing = 1.360", "flange_back_spacing = 1.725"))
    with pytest.raises(ImplausibleValueError, match=r"coach\.toml \[profiles\] gauge: track gauge 1\.8 m is outside"):
        VehicleDefinition.from_toml(f, accept=["flange_back_spacing"])
    D = VehicleDefinition.from_toml(f, accept=["gauge", "flange_back_spacing"])
    assert "gauge" in D.accept and D.rails().gauge == 1.8


def test_open_track_is_not_evaluated_beyond_its_ends():
    from core.errors import DataRangeError

    tr = Track([Straight(50.0), Curve(50.0, 300.0)])
    with pytest.raises(DataRangeError, match=r"track: evaluated at s\[1\] = 100\.5 m, beyond its end at s = 100 m: "
                                             r"the track is open \(0 <= s <= 100 m\) and is not extrapolated"):
        tr.evaluate([99.0, 100.5])
    with pytest.raises(DataRangeError, match=r"track: evaluated at s\[0\] = -0\.25 m, before its start at s = 0 m"):
        tr.evaluate(-0.25)
    with pytest.raises(InputError, match=r"track: non-finite arc length s\[0\] = nan"):
        tr.evaluate([np.nan])
    # the ends themselves (and round-off past them) are on the track; internal callers extrapolate
    assert tr.evaluate([0.0, 100.0, 100.0 + 1e-12]).position.shape == (3, 3)
    ext = tr.evaluate([100.5], extrapolate=True)
    np.testing.assert_allclose(ext.position, tr.evaluate_raw(np.array([100.5]))[0], atol=1e-9)


def test_speed_control_past_the_end_of_an_open_track_names_the_end(coach):
    """The speed control's own projection (the Python path) gives no arc length beyond the end:
    a DataRangeError, which ends a run as failed (the compiled path returns NaN)."""
    from types import SimpleNamespace

    from core.errors import RUN_FAILURES, DataRangeError

    tr = Track.straight(40.0)
    veh = build_vehicle(coach, tr, s0=20.0, speed=20.0, speed_control=20.0)
    kind = next(k for k in veh.model.force_kinds if type(k).__name__ == "TrackSpeedControlKind")
    r = np.zeros((max(kind.b) + 1, 3))
    r[kind.b[0]] = [41.5, 0.0, 1.8]
    with pytest.raises(DataRangeError, match=r"track speed control '.*': body '.*' ran past the end of the track at "
                                             r"s = 40 m \(s = 41\.5 m\): the track is open and is not extrapolated") as info:
        kind._arc(SimpleNamespace(r=r), np.array([39.0]))
    assert isinstance(info.value, RUN_FAILURES)
    r[kind.b[0]] = [-0.5, 0.0, 1.8]
    with pytest.raises(DataRangeError, match=r"ran off the start of the track at s = 0 m \(s = -0\.5 m\)"):
        kind._arc(SimpleNamespace(r=r), np.array([1.0]))
    r[kind.b[0]] = [20.0, 0.0, 1.8]
    assert kind._arc(SimpleNamespace(r=r), np.array([20.0]))[0] == pytest.approx(20.0)


# ---------------------------------------------------------------------------------------------
# misspelt keyword arguments of the public functions: the closest accepted one is named
# ---------------------------------------------------------------------------------------------
@pytest.mark.parametrize("call, pattern", [
    (lambda: importlib.import_module("railway.vehicles.vehicle").build_vehicle(None, None, 30.0, sped=20.0),
     r"build_vehicle\(\): unknown option 'sped'; did you mean 'speed'\?"),
    (lambda: importlib.import_module("railway.contact.geometry").rigid_contact([0.0], gage=1.435),
     r"rigid_contact\(\): unknown option 'gage'; did you mean 'gauge'\?"),
    (lambda: importlib.import_module("railway.contact.geometry").contact_geometry_table([0.0], inclinaton=0.025),
     r"contact_geometry_table\(\): unknown option 'inclinaton'; did you mean 'inclination'\?"),
    (lambda: importlib.import_module("railway.contact.quasi_static").quasi_static_contact([0.0], 5e4, yaww=0.0),
     r"quasi_static_contact\(\): unknown option 'yaww'; did you mean 'yaw'\?"),
    (lambda: importlib.import_module("railway.vehicles.wheel_rail").contact_history(None, None, at_="steps"),
     r"contact_history\(\): unknown option 'at_'; did you mean 'at'\?"),
], ids=["build_vehicle sped", "rigid_contact gage", "contact_geometry_table inclinaton", "quasi_static yaww",
        "contact_history at_"])
def test_misspelt_keyword_names_the_closest(call, pattern):
    from core.errors import UnknownOptionError

    with pytest.raises(UnknownOptionError, match=pattern):
        call()


# ---------------------------------------------------------------------------------------------
# the "Checked inputs" snippets of the documentation (docs/user-guide/checked-inputs.md) run
# here, so they cannot go stale
# ---------------------------------------------------------------------------------------------
def _readme_block(lang, after):
    from core.paths import repo_root

    text = (repo_root() / "docs" / "user-guide" / "checked-inputs.md").read_text(encoding="utf-8")
    i = text.index(f"```{lang}\n", text.index(after)) + len(lang) + 4
    return text[i:text.index("```", i)]


def test_readme_units_snippet_equals_the_manchester_file_in_si():
    """The docs' TOML snippet (values with units) laid over the Manchester file gives the same
    vehicle as the SI file, to the digits the snippet writes."""
    import tomllib

    from core.paths import data_path
    from railway.vehicles.vehicle import VehicleDefinition

    path = data_path("railway", "vehicles", "manchester_coach.toml")
    base = tomllib.loads(path.read_text(encoding="utf-8"))
    snippet = tomllib.loads(_readme_block("toml", "## Railway vehicles and track"))
    for table, keys in snippet.items():
        base[table].update(keys)
    with_units = VehicleDefinition.from_dict(base, base_dir=path.parent)
    si = VehicleDefinition.manchester()
    assert with_units.car_body["mass"] == si.car_body["mass"] == 32000.0
    np.testing.assert_allclose(with_units.car_body["inertia"], si.car_body["inertia"], rtol=1e-12)
    np.testing.assert_allclose(with_units.primary["stiffness"], si.primary["stiffness"], rtol=3e-4)  # 31.4 of 31.391 MN/m
    np.testing.assert_allclose(with_units.primary["damping"], si.primary["damping"], rtol=1e-12)
    assert with_units.geometry["car_body_cg_height"] == pytest.approx(si.geometry["car_body_cg_height"], rel=1e-12)


def test_readme_example_message_is_the_one_the_code_writes(tmp_path):
    """The intro's example line of the docs' "Checked inputs" page is the message a 32 kg car body gets."""
    from core.paths import data_path
    from railway.vehicles.vehicle import VehicleDefinition

    text = data_path("railway", "vehicles", "manchester_coach.toml").read_text(encoding="utf-8")
    f = tmp_path / "coach.toml"
    f.write_text(text.replace("mass = 32000.0 ", "mass = 32 ", 1), encoding="utf-8")
    line = _readme_block("text", "# Checked inputs").strip()
    with pytest.raises(ImplausibleValueError) as info:
        VehicleDefinition.from_toml(f)
    assert str(info.value) == f"{tmp_path}/{line}"
