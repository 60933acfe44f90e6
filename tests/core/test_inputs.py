"""The input layer of every domain (core.inputs): units, plausible ranges, schemas.

Conversions are checked against exact factors (1 t = 1000 kg, 1 deg = pi/180 rad, 1 km/h =
1/3.6 m/s); the messages against the words a user needs: where, what, the range, the likely slip.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from core.errors import DataFileError, InputError, UnknownOptionError
from core.inputs import (ImplausibleValueError, InputModel, PlausibleRange, RangeTable, UnitError,
                         check_choice, check_keywords, closest, parse_quantity, validate)

RANGES = RangeTable([
    PlausibleRange("car_body_mass", "car body mass", "kg", 1e3, 2e5, "metro car to heavy coach"),
    PlausibleRange("stiffness", "primary stiffness", "N/m", 1e4, 1e8, "rubber to steel springs"),
    PlausibleRange("height", "centre-of-gravity height", "m", 0.2, 4.0, "above the rail top"),
    PlausibleRange("bank", "bank angle", "rad", -1.7, 1.7, "within a quarter turn"),
    PlausibleRange("load", "wheel load", "N", 1e3, 3e5, "light rail to 30 t axle load"),
    PlausibleRange("speed", "speed", "m/s", 0.0, math.inf, "non-negative"),
], source="test")


class Body(InputModel):
    mass: RANGES.quantity("car_body_mass")
    stiffness: RANGES.quantity("stiffness", 3) = (1e6, 1e6, 1e6)


class Vehicle(InputModel):
    car_body: Body
    name: str = ""


@pytest.mark.parametrize("text, unit, expected", [
    ("32 t", "kg", 32000.0),
    ("1.2 MN/m", "N/m", 1.2e6),
    ("1800 mm", "m", 1.8),
    ("20 deg", "rad", math.radians(20.0)),
    ("72 km/h", "m/s", 20.0),
    ("10.5 kN m/rad", "N*m/rad", 10.5e3),
    ("15 kN s/m", "N*s/m", 15e3),
    ("210 GPa", "Pa", 210e9),
    ("3.5", "kg", 3.5),
])
def test_quantities_with_units_convert_exactly(text, unit, expected):
    assert parse_quantity(text, unit) == pytest.approx(expected, rel=1e-14)


def test_lists_convert_element_by_element():
    v = parse_quantity([31391e3, "3884 kN/m", "1.22 MN/m"], "N/m")
    np.testing.assert_allclose(v, [31391e3, 3884e3, 1.22e6], rtol=1e-14)


@pytest.mark.parametrize("value, exc, pattern", [
    ("1800 mm", UnitError, r"where: '1800 mm' is a length .*expected mass"),
    ("32 tt", UnitError, r"cannot read '32 tt' as a quantity in kg"),
    (True, InputError, r"True is not a number"),
    (None, InputError, r"None is not a number"),
    (float("nan"), InputError, r"not a finite number"),
    ("inf kg", InputError, r"not a finite number"),
])
def test_unreadable_quantities_are_named(value, exc, pattern):
    with pytest.raises(exc, match=pattern):
        parse_quantity(value, "kg", where="where")


@pytest.mark.parametrize("quantity, value, slip", [
    ("car_body_mass", 32, "did you mean 32 t?"),
    ("height", 1800, "did you mean 1800 mm?"),
    ("bank", 30, "did you mean 30 deg?"),
    ("stiffness", 1220, "did you mean 1220 kN/m?"),
])
def test_out_of_range_names_value_range_and_likely_slip(quantity, value, slip):
    with pytest.raises(ImplausibleValueError) as info:
        RANGES.check(quantity, value, where="f.toml [t] k")
    msg = str(info.value)
    assert msg.startswith("f.toml [t] k: ")
    assert slip in msg and "outside the plausible range" in msg and f"accept={quantity!r}" in msg
    assert info.value.quantity == quantity and info.value.suggestion == slip


def test_deliberate_outlier_is_accepted_by_name():
    assert RANGES.check("car_body_mass", 32, accept=["car_body_mass"]) == 32.0
    assert RANGES.check("car_body_mass", 32, accept="car_body_mass") == 32.0
    with pytest.raises(ImplausibleValueError):
        RANGES.check("car_body_mass", 32, accept=["height"])


def test_option_in_other_unit_is_converted_then_checked():
    assert RANGES.check("load", 100, unit="kN") == pytest.approx(1e5)
    with pytest.raises(ImplausibleValueError, match=r"did you mean 100000 N\?"):
        RANGES.check("load", 100000, unit="kN", where="--load-kN")


def test_range_without_slip_gives_rationale():
    with pytest.raises(ImplausibleValueError, match=r"speed -3 m/s is outside .*\(non-negative\)"):
        RANGES.check("speed", -3)


def test_schema_unknown_key_suggests_closest_and_not_missing():
    with pytest.raises(DataFileError, match=r"^v\.toml \[car_body\] masss: unknown key; did you mean 'mass'\?$"):
        validate(Vehicle, {"car_body": {"masss": 32000}}, source="v.toml")
    with pytest.raises(DataFileError, match=r"v\.toml car_bdy: unknown key; did you mean 'car_body'\?"):
        validate(Vehicle, {"car_bdy": {"mass": 32000}}, source="v.toml")


def test_schema_messages_name_file_table_key():
    with pytest.raises(ImplausibleValueError, match=r"^v\.toml \[car_body\] mass: car body mass 32 kg .*32 t\?"):
        validate(Vehicle, {"car_body": {"mass": 32}}, source="v.toml")
    with pytest.raises(DataFileError, match=r"v\.toml \[car_body\] mass: missing key"):
        validate(Vehicle, {"car_body": {}}, source="v.toml")
    with pytest.raises(DataFileError, match=r"\[car_body\] stiffness: primary stiffness must be 3 numbers"):
        validate(Vehicle, {"car_body": {"mass": 3e4, "stiffness": [1e6, 1e6]}}, source="v.toml")
    with pytest.raises(ImplausibleValueError, match=r"\[car_body\] stiffness: primary stiffness \[1\] 1220 N/m.*1220 kN/m\?"):
        validate(Vehicle, {"car_body": {"mass": 3e4, "stiffness": [1e6, 1220, 1e6]}}, source="v.toml")


def test_schema_converts_units_and_accepts_outliers():
    v = validate(Vehicle, {"car_body": {"mass": "32 t", "stiffness": "1.2 MN/m"}}, source="v.toml")
    assert v.car_body.mass == 32000.0 and v.car_body.stiffness == (1.2e6,) * 3
    v = validate(Vehicle, {"car_body": {"mass": 32}}, source="v.toml", context={"accept": ["car_body_mass"]})
    assert v.car_body.mass == 32.0


def test_api_source_gives_input_error_not_file_error():
    with pytest.raises(InputError) as info:
        validate(Vehicle, {"car_body": {"mas": 1}}, source="build_vehicle()")
    assert not isinstance(info.value, DataFileError)


def test_choices_and_keywords():
    assert closest("S1003", ["S1002", "UIC60"]) == "; did you mean 'S1002'?"
    assert closest("xyz", ["S1002"]) == ""
    assert check_choice("dop853", ["dop853", "rk45"], where="method") == "dop853"
    with pytest.raises(InputError, match=r"method: 'dop835' is not one of .*did you mean 'dop853'\?"):
        check_choice("dop835", ["dop853", "rk45"], where="method")
    with pytest.raises(UnknownOptionError, match=r"f\(\): unknown option 'sped'; did you mean 'speed'\?"):
        check_keywords(["speed", "sped"], ["speed", "s0"], where="f()")


def test_range_table_from_csv(tmp_path):
    p = tmp_path / "r.csv"
    p.write_text("# comment\nquantity,label,unit,low,high,rationale\nm,mass,kg,1,,\"positive, finite\"\n")
    t = RangeTable.from_csv(p)
    assert t["m"].high == math.inf and t["m"].rationale == "positive, finite"
    p.write_text("quantity,label,unit,low,high,rationale\nm,mass,kg,5,1,x\n")
    with pytest.raises(DataFileError, match="low > high"):
        RangeTable.from_csv(p)
    with pytest.raises(DataFileError, match="does not exist"):
        RangeTable.from_csv(tmp_path / "none.csv")


@pytest.mark.parametrize("domain", ["railway", "biomech", "coaster"])
def test_shipped_range_tables_are_consistent(domain):
    """Every shipped table reads, every unit is pint-readable, every row has a rationale."""
    from core.inputs import unit_registry
    from core.paths import data_path

    t = RangeTable.from_csv(data_path(domain, "plausible_ranges.csv"))
    ureg = unit_registry()
    for r in t:
        ureg.Quantity(1.0, r.unit)
        assert r.rationale, f"{r.quantity} has no rationale"
        assert r.low <= r.high


def test_bounds_print_with_si_prefixes_and_commas_are_refused():
    with pytest.raises(ImplausibleValueError, match=r"range 10 kN/m \.\.\. 100 MN/m"):
        RANGES.check("stiffness", 1.0)
    with pytest.raises(UnitError, match=r"has a comma; write a decimal point"):
        parse_quantity("1,435 m", "m")


def test_no_slip_suggested_far_below_a_range_open_to_zero():
    r = PlausibleRange("cant", "cant", "m", 0.0, 0.2, "up to 200 mm")
    assert r.likely_slip(0.3) == ""          # no unit slip (not 0.3 mm, not 0.3 cm)
    assert r.likely_slip(150.0) == "did you mean 150 mm?"
    assert r.likely_slip(-150.0) == ""       # no unit turns -150 into 0 ... 0.2 m


def test_duplicate_quantity_in_range_table_is_refused(tmp_path):
    p = tmp_path / "r.csv"
    p.write_text("quantity,label,unit,low,high,rationale\nm,mass,kg,1,2,x\nm,mass,kg,1,3,y\n")
    with pytest.raises(DataFileError, match="'m' appears twice"):
        RangeTable.from_csv(p)


@pytest.mark.parametrize("domain", ["railway", "biomech", "coaster"])
def test_docs_range_tables_equal_the_data(domain):
    """The "Checked inputs" tables of the documentation (docs/user-guide/checked-inputs.md) are
    RangeTable.to_markdown() of the shipped CSVs: a range changed in the data without the page
    (or the reverse) fails here."""
    from core.paths import data_path, repo_root

    page = (repo_root() / "docs" / "user-guide" / "checked-inputs.md").read_text(encoding="utf-8")
    table = RangeTable.from_csv(data_path(domain, "plausible_ranges.csv")).to_markdown()
    assert table in page, (f"the {domain} range table of docs/user-guide/checked-inputs.md differs from "
                           f"data/{domain}/plausible_ranges.csv")
