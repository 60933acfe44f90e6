"""Issue 21: the ``mbsuite railway`` commands given careless input by a hurried user.

Every case runs the command line in-process (``core.cli.main([...])``) and asserts the exact
outcome: exit status 2, no traceback, ONE line on stderr, ``mbsuite: error: ...``, naming the
option, the value and the likely slip (a unit, a typo, a contradiction); or a finished run with a
named warning (``mbsuite: warning: ... [ConicityResolutionWarning]``).  The README's examples and
the defaults must pass without a false alarm.
"""

from __future__ import annotations

import re

import numpy as np
import pandas as pd
import pytest

from core.cli import check_option, main
from core.inputs import ImplausibleValueError
from railway.contact.creep_curve import creep_curve
from railway.ranges import ranges


@pytest.fixture
def files(tmp_path):
    """Paths a hurried user gives by mistake: missing, a folder, a binary, an empty and a
    garbled profile file, and a file where an output folder should be."""
    (tmp_path / "folder").mkdir()
    (tmp_path / "binary.png").write_bytes(b"\x89PNG\r\n\x1a\n\x00\x00\x00\rIHDR\xff\xfe")
    (tmp_path / "empty.txt").write_text("   \n")
    (tmp_path / "garbled.txt").write_text("y z\n1.0 2.0\nthree four\n")
    (tmp_path / "afile").write_text("not a folder")
    (tmp_path / "flat_rail.txt").write_text("".join(f"{u} 0\n" for u in range(-36, 37)))
    (tmp_path / "v_wheel.txt").write_text("".join(f"{y} {abs(y)}\n" for y in range(-68, 61)))
    return tmp_path


def _run(argv, capsys, files=None):
    argv = [a.replace("{tmp}", str(files)) if files is not None else a for a in argv]
    code = main(argv)
    cap = capsys.readouterr()
    return code, cap.out, cap.err


def _assert_one_line_error(code, err, pattern):
    assert "Traceback" not in err, err
    lines = err.strip().splitlines()
    assert code == 2, err
    assert len(lines) == 1, err
    assert lines[0].startswith("mbsuite: error: "), err
    assert re.search(pattern, lines[0]), f"{pattern!r} not in {lines[0]!r}"


CT = ["railway", "contact-table"]
CC = ["railway", "creep-curve"]

# ---------------------------------------------------------------------------------------------
# contact-table
# ---------------------------------------------------------------------------------------------
CONTACT_TABLE_CASES = [
    # the tracebacks
    ("yaw 500 mrad (issue 21 traceback)", ["--yaw-mrad", "500"],
     r"--yaw-mrad 500: the wheelset yaw angle must lie in -50 \.\.\. 50 mrad .*--accept wheelset_yaw_angle"),
    ("flange-back equal to the gauge (issue 21 traceback)", ["--flange-back-mm", "1435"],
     r"--flange-back-mm 1435 is not below --gauge-mm 1435: the flanges run inside the rails"),
    ("yaw negative beyond range", ["--yaw-mrad", "-80"], r"--yaw-mrad -80: the wheelset yaw angle must lie in"),
    ("yaw in degrees written as mrad", ["--yaw-mrad", "nan"], r"--yaw-mrad nan: .*not a finite number"),
    # the wheelset must fit the track
    ("flange-back too wide: flanges touch", ["--flange-back-mm", "1400"],
     r"--flange-back-mm 1400: the wheelset does not fit the track: centred, its flanges touch the rails "
     r"\(gauge 1435 mm - flange-back 1400 mm - 2 x flange thickness 32\.5 mm leaves -15\.0 mm each side\); "
     r"for this wheel and gauge the flange-back spacing is about 1360 mm"),
    ("flange-back too narrow: 35 mm play", ["--flange-back-mm", "1300"],
     r"--flange-back-mm 1300: the wheelset has 35 mm of play each side .*about 1360 mm "
     r"\(to use it deliberately: --accept flange_back_spacing\)"),
    ("flange-back in metres", ["--flange-back-mm", "1.36"],
     r"--flange-back-mm 1.36: the flange-back spacing must lie in 500 \.\.\. 1650 mm: did you mean 1.36 m, "
     r"i\.e\. --flange-back-mm 1360\?"),
    # unit slips of the millimetre options
    ("gauge in metres", ["--gauge-mm", "1.435"],
     r"--gauge-mm 1.435: the track gauge must lie in 600 \.\.\. 1700 mm: did you mean 1.435 m, i\.e\. --gauge-mm 1435\?"),
    ("gauge in centimetres", ["--gauge-mm", "143.5"], r"did you mean 143.5 cm, i\.e\. --gauge-mm 1435\?"),
    ("gauge zero", ["--gauge-mm", "0"], r"--gauge-mm 0: the track gauge must lie in 600 \.\.\. 1700 mm \(narrow gauges"),
    ("gauge infinite", ["--gauge-mm", "inf"], r"--gauge-mm inf: .*not a finite number"),
    ("r0 in metres", ["--r0-mm", "0.46"], r"--r0-mm 0.46: the nominal wheel rolling radius must lie in 150 \.\.\. 800 mm: "
                                          r"did you mean 0.46 m, i\.e\. --r0-mm 460\?"),
    ("r0 given as the diameter", ["--r0-mm", "920"],
     r"--r0-mm 920: .*is 920 the wheel diameter\? --r0-mm takes the radius, --r0-mm 460"),
    ("r0 negative", ["--r0-mm", "-460"], r"--r0-mm -460: the nominal wheel rolling radius must lie in 150"),
    # lateral range and resolution
    ("y-max far beyond the flangeway (issue 21)", ["--y-max-mm", "100"],
     r"--y-max-mm 100: beyond the flangeway clearance 6\.25 mm \(flange contact from there\) plus the flange climb "
     r"10\.2 mm \(flange height 28\.0 mm at 70 deg\) the wheelset has derailed; give --y-max-mm <= 16"),
    ("y-max beyond the flange climb", ["--y-max-mm", "20", "--n", "101"],
     r"--y-max-mm 20: beyond the flangeway clearance 6\.25 mm .*give --y-max-mm <= 16"),
    ("y-max in metres", ["--y-max-mm", "0.01"],
     r"--y-max-mm 0.01: the largest lateral shift of a contact table must lie in 0.5 \.\.\. 50 mm: did you mean "
     r"0.01 m, i\.e\. --y-max-mm 10\?"),
    ("y-max negative", ["--y-max-mm", "-5"], r"--y-max-mm -5: the largest lateral shift of a contact table must lie in"),
    ("y-max zero", ["--y-max-mm", "0"], r"--y-max-mm 0: the largest lateral shift"),
    ("n too small", ["--n", "3"], r"--n 3: the number of lateral shifts of a contact table must lie in 5 \.\.\. 10001"),
    ("n huge", ["--n", "1000000"], r"--n 1e\+06: the number of lateral shifts of a contact table must lie in 5 \.\.\. 10001"),
    ("n negative", ["--n", "-401"], r"--n -401: the number of lateral shifts"),
    ("n not an integer", ["--n", "401.5"],
     r"railway contact-table: argument --n: invalid int value: '401.5' \(see `mbsuite railway contact-table --help`\)"),
    # amplitudes
    ("amplitude beyond y-max", ["--amplitudes-mm", "12"],
     r"--amplitudes-mm 12: the amplitude 12 mm exceeds --y-max-mm 10 .*give --y-max-mm >= 12"),
    ("amplitude in metres", ["--amplitudes-mm", "0.003"],
     r"--amplitudes-mm 0.003: the equivalent-conicity amplitude must lie in 0.1 \.\.\. 20 mm: did you mean 0.003 m"),
    ("amplitudes not numbers", ["--amplitudes-mm", "2,x"], r"--amplitudes-mm '2,x': expected numbers in mm separated by commas"),
    ("amplitudes empty", ["--amplitudes-mm", ","], r"--amplitudes-mm ',': give at least one amplitude"),
    # inclination
    ("inclination as the denominator", ["--inclination", "40"], r"--inclination 40: .*did you mean '1:40'"),
    ("inclination typo O for 0", ["--inclination", "1:4O"], r"--inclination 1:4O: rail inclination '1:4O': expected e\.g\. '1:40'"),
    ("inclination negative", ["--inclination=-1:40"], r"--inclination -1:40: .*is negative: rails are inclined towards"),
    ("inclination negative without =", ["--inclination", "-1:40"],
     r"railway contact-table: argument --inclination: expected one argument"),
    # load
    ("load in newtons", ["--load-kN", "100000"],
     r"--load-kN 100000: the wheel-rail normal load must lie in 0.5 \.\.\. 500 kN: did you mean 100000 N, i\.e\. --load-kN 100\?"),
    ("load zero", ["--load-kN", "0"], r"--load-kN 0: the wheel-rail normal load must lie in 0.5 \.\.\. 500 kN"),
    ("load negative", ["--load-kN", "-100"], r"--load-kN -100: the wheel-rail normal load"),
    # profiles
    ("built-in wheel misspelt", ["--wheel", "S1O02"],
     r"--wheel 'S1O02': no such file and not a built-in profile \(S1002\); did you mean 'S1002'\?"),
    ("built-in rail misspelt", ["--rail", "UIC6O"], r"--rail 'UIC6O': no such file .*did you mean 'UIC60'\?"),
    ("wheel file missing", ["--wheel", "{tmp}/missing.txt"], r"--wheel '.*missing.txt': no such file"),
    ("wheel is a folder", ["--wheel", "{tmp}/folder"], r"--wheel '.*folder': is a folder, not a profile file"),
    ("wheel file binary", ["--wheel", "{tmp}/binary.png"],
     r"--wheel '.*binary.png': not a text profile file \(byte 0x89 at offset 0 is not UTF-8"),
    ("wheel file empty", ["--wheel", "{tmp}/empty.txt"], r"--wheel '.*empty.txt': the file is empty"),
    ("wheel file garbled", ["--wheel", "{tmp}/garbled.txt"], r"garbled.txt:3: non-numeric value in 'three four'"),
    ("rail file missing", ["--rail", "{tmp}/rail.txt"], r"--rail '.*rail.txt': no such file"),
    ("rail file without a crown", ["--rail", "{tmp}/flat_rail.txt"],
     r"flat_rail.txt: rail head has no crown: it is flat \(its heights vary by 0 mm over its width of 72 mm\)"),
    ("wheel file with a 60 mm flange", ["--wheel", "{tmp}/v_wheel.txt"],
     r"--flange-back-mm 1360: the wheelset does not fit the track: .*2 x flange thickness 60.0 mm leaves "
     r"-22.5 mm each side\); for this wheel and gauge the flange-back spacing is about 1305 mm"),
    ("wheel-back with the built-in wheel", ["--wheel-back-mm", "70"],
     r"--wheel-back-mm: only for a wheel profile file, not the built-in S1002"),
    ("flange side misspelt", ["--wheel-flange-side", "negatve"],
     r"argument --wheel-flange-side: invalid choice: 'negatve'; did you mean 'negative'\?"),
    ("rail vertical misspelt", ["--rail-vertical", "hieght"],
     r"argument --rail-vertical: invalid choice: 'hieght'; did you mean 'height'\?"),
    # output, options, names
    ("output folder is a file", ["-o", "{tmp}/afile"], r"output folder '.*afile' cannot be created: it is a file"),
    ("output folder under a file", ["-o", "{tmp}/afile/sub"], r"cannot be created: a parent is a file"),
    ("accept misspelt", ["--accept", "gauj", "--gauge-mm", "3000"],
     r"argument --accept: 'gauj' is not a quantity of the plausible-range table; did you mean 'gauge'\?"),
    ("yaw with a unit in the number", ["--yaw-mrad", "5deg"], r"argument --yaw-mrad: invalid float value: '5deg'"),
    ("option misspelt", ["--yaw-mard", "5"], r"unrecognized arguments: --yaw-mard 5"),
]


@pytest.mark.parametrize("argv,pattern", [c[1:] for c in CONTACT_TABLE_CASES],
                         ids=[c[0] for c in CONTACT_TABLE_CASES])
def test_contact_table_careless_input(argv, pattern, capsys, files):
    code, out, err = _run(CT + argv, capsys, files)
    _assert_one_line_error(code, err, pattern)


def test_misspelt_subcommand_suggests_the_closest(capsys):
    code, _, err = _run(["railway", "contact-tabel"], capsys)
    _assert_one_line_error(code, err, r"railway: argument COMMAND: invalid choice: 'contact-tabel'; "
                                      r"did you mean 'contact-table'\? \(choose from contact-table, creep-curve\)")


def test_too_few_shifts_for_the_conicity_is_a_named_warning(capsys, tmp_path):
    """``--n 5`` gave one conicity for every amplitude: now the conicities that the 5 mm step
    cannot resolve are not computed (NaN), the warning names --n and the value needed."""
    code, out, err = _run(CT + ["--n", "5", "-o", str(tmp_path)], capsys)
    assert code == 0 and "Traceback" not in err
    assert err.strip().splitlines() == [
        "mbsuite: warning: --n 5: the lateral step 5 mm is too coarse for the conicity at 2, 3, 4 mm (at least "
        "5 steps per amplitude); not computed: give --n >= 51 for --y-max-mm 10 [ConicityResolutionWarning]"]
    assert "equivalent conicity at 2 mm: not computed (lateral step 5 mm; give --n >= 51)" in out
    assert "equivalent conicity at 4 mm: not computed (lateral step 5 mm; give --n >= 26)" in out
    con = pd.read_csv(tmp_path / "equivalent_conicity.csv")
    assert con["conicity wavelength [-]"].isna().all()


def test_resolution_rule_keeps_resolved_amplitudes(capsys):
    """--n 13 over +-6 mm (1 mm steps): 5 mm is resolved, 2 mm is not (it needs 0.4 mm steps)."""
    code, out, err = _run(CT + ["--n", "13", "--y-max-mm", "6", "--amplitudes-mm", "2,5"], capsys)
    assert code == 0
    assert "[ConicityResolutionWarning]" in err and "conicity at 2 mm" in err and "--n >= 31" in err
    assert re.search(r"equivalent conicity at 5 mm: 0\.\d+ \(wavelength\)", out)


def test_flange_climb_rows_are_marked(capsys, tmp_path):
    """Rows where the wheel has passed the top of its flank (rigid geometry beyond the flange
    contact) are marked in the column regime and counted in the summary; no false alarm on stderr."""
    code, out, err = _run(CT + ["--n", "81", "--y-max-mm", "8", "-o", str(tmp_path)], capsys)
    assert code == 0 and err == ""
    assert ("16 of 81 lateral shifts (|y| from 6.600 mm) have a wheel past the top of its flange flank (70 deg): "
            "climbing its flange") in out
    df = pd.read_csv(tmp_path / "contact_table.csv")
    climbing = df.loc[df["regime"] == "flange climb", "y [m]"].abs()
    assert climbing.min() == pytest.approx(0.0066) and len(climbing) == 16
    assert set(df.loc[df["y [m]"].abs() < 0.006, "regime"]) == {"tread"}
    assert re.search(r"equivalent conicity at 3 mm: 0\.18\d\d \(wavelength\)", out)


def test_accept_lets_a_deliberate_outlier_through(capsys):
    code, out, err = _run(CT + ["--yaw-mrad", "60", "--accept", "wheelset_yaw_angle", "--n", "13",
                                "--y-max-mm", "6", "--amplitudes-mm", "5"], capsys)
    assert code == 0 and "Traceback" not in err and "yaw 60 mrad" in out


# ---------------------------------------------------------------------------------------------
# creep-curve
# ---------------------------------------------------------------------------------------------
CREEP_CURVE_CASES = [
    # the silent acceptances
    ("mu as per cent (issue 21)", ["--mu", "30"],
     r"--mu 30: the wheel-rail friction coefficient must lie in 0.01 \.\.\. 1: did you mean 30 %, i\.e\. --mu 0.3\? "
     r"\(to use it deliberately: --accept friction_coefficient\)"),
    ("load in newtons (issue 21)", ["--load-kN", "100000"],
     r"--load-kN 100000: the wheel-rail normal load must lie in 0.5 \.\.\. 500 kN: did you mean 100000 N, i\.e\. --load-kN 100\?"),
    ("E in pascals (issue 21)", ["--E-GPa", "210e9"],
     r"--E-GPa 2.1e\+11: the Young's modulus of wheel and rail must lie in 50 \.\.\. 450 GPa: did you mean 2.1e\+11 Pa, "
     r"i\.e\. --E-GPa 210\?"),
    ("E in megapascals", ["--E-GPa", "210000"], r"did you mean 210000 MPa, i\.e\. --E-GPa 210\?"),
    ("G in pascals", ["--G-GPa", "80e9"], r"--G-GPa 8e\+10: the shear modulus .*did you mean 8e\+10 Pa, i\.e\. --G-GPa 80\?"),
    ("load in meganewtons", ["--load-kN", "0.1"], r"--load-kN 0.1: .*did you mean 0.1 MN, i\.e\. --load-kN 100\?"),
    ("load infinite", ["--load-kN", "inf"], r"--load-kN inf: .*not a finite number"),
    ("mu zero", ["--mu", "0"], r"--mu 0: the wheel-rail friction coefficient must lie in 0.01 \.\.\. 1 \(0.01 \(contaminated"),
    ("mu negative", ["--mu", "-0.1"], r"--mu -0.1: the wheel-rail friction coefficient must lie in"),
    ("mu not a number", ["--mu", "nan"], r"--mu nan: .*not a finite number"),
    ("nu as per cent", ["--nu", "28"], r"--nu 28: the Poisson ratio must lie in 0.1 \.\.\. 0.49: did you mean 28 %, i\.e\. --nu 0.28\?"),
    ("nu of an incompressible solid", ["--nu", "0.5"], r"--nu 0.5: the Poisson ratio must lie in 0.1 \.\.\. 0.49"),
    ("nu negative", ["--nu", "-0.3"], r"--nu -0.3: the Poisson ratio"),
    # creepages
    ("sweep end as per cent", ["--max", "5"],
     r"--max 5: the longitudinal or lateral creepage must lie in -1 \.\.\. 1: did you mean 5 %, i\.e\. --max 0.05\?"),
    ("fixed creepage as per cent", ["--creepage", "eta", "--xi", "2"], r"--xi 2: .*did you mean 2 %, i\.e\. --xi 0.02\?"),
    ("spin per km", ["--phi", "2000"], r"--phi 2000: the spin creepage must lie in -10 \.\.\. 10 1/m: did you mean 2000 1/km, i\.e\. --phi 2\?"),
    ("sweep reversed", ["--min", "0.02", "--max", "0.01"], r"--min 0.02 is not below --max 0.01: the sweep of xi runs from --min to --max"),
    ("fixed value of the swept creepage", ["--xi", "0.001"],
     r"--xi 0.001: xi is the swept creepage \(--creepage\); give its range with --min/--max"),
    ("creepage misspelt", ["--creepage", "eat"], r"argument --creepage: invalid choice: 'eat'; did you mean 'eta'\?"),
    ("n one point", ["--n", "1"], r"--n 1: the number of points of a creep curve must lie in 2 \.\.\. 100001"),
    # ellipse and radii
    ("only one semi-axis", ["--a-mm", "6"], r"give both --a-mm and --b-mm, or neither"),
    ("semi-axis in metres", ["--a-mm", "0.006", "--b-mm", "4"],
     r"--a-mm 0.006: the contact ellipse semi-axis must lie in 0.05 \.\.\. 100 mm: did you mean 0.006 m, i\.e\. --a-mm 6\?"),
    ("semi-axes and radii together", ["--a-mm", "6", "--b-mm", "4", "--rail-lateral-radius-mm", "300"],
     r"--rail-lateral-radius-mm with --a-mm/--b-mm: the semi-axes are given, the radii would not be used"),
    ("wheel radius in metres", ["--wheel-radius-mm", "0.46"], r"--wheel-radius-mm 0.46: .*did you mean 0.46 m, i\.e\. --wheel-radius-mm 460\?"),
    ("wheel diameter for the radius", ["--wheel-radius-mm", "920"], r"is 920 the wheel diameter\? --wheel-radius-mm takes the radius"),
    ("rail radius zero", ["--rail-lateral-radius-mm", "0"], r"--rail-lateral-radius-mm 0: a radius of zero is a sharp edge"),
    ("rail radius in metres", ["--rail-lateral-radius-mm", "0.3"], r"--rail-lateral-radius-mm 0.3: .*did you mean 0.3 m"),
    ("concave wheel tighter than the rail", ["--wheel-lateral-radius-mm", "-200"],
     r"--wheel-lateral-radius-mm -200, --rail-lateral-radius-mm 300: .*non-Hertzian contact"),
    # models and their parameters
    ("model misspelt", ["--model", "polach200"],
     r"--model 'polach200': not a creep model; did you mean 'polach2005'\? \(registered: fastsim, kalker_linear"),
    ("Polach factor without polach2005", ["--k-A", "0.5"], r"--k-A: only for --model polach2005 \(the models are polach2000\)"),
    ("FASTSIM grid without fastsim", ["--nx", "20"], r"--nx: only for --model fastsim"),
    ("k_S above k_A", ["--model", "polach2005", "--k-A", "0.3", "--k-S", "0.5"],
     r"--k-S 0.5 is larger than --k-A 0.3: Polach \(2005\) has k_S <= k_A <= 1"),
    ("Polach A as per cent", ["--model", "polach2005", "--A-ratio", "40"], r"--A-ratio 40: .*did you mean 40 %, i\.e\. --A-ratio 0.4\?"),
    ("speed in km/h", ["--model", "polach2005", "--speed", "300"],
     r"--speed 300: the vehicle speed must lie in 0 \.\.\. 150 m/s: did you mean 300 km/h, i\.e\. --speed 83.3333\?"),
    ("FASTSIM grid huge", ["--model", "fastsim", "--nx", "1000"], r"--nx 1000: the FASTSIM strips or elements per strip must lie in 4 \.\.\. 400"),
    # files
    ("output folder is a file", ["-o", "{tmp}/afile"], r"output folder '.*afile' cannot be created: it is a file"),
    ("stem with a folder", ["--stem", "a/b"], r"--stem 'a/b': a file name without a folder"),
]


@pytest.mark.parametrize("argv,pattern", [c[1:] for c in CREEP_CURVE_CASES],
                         ids=[c[0] for c in CREEP_CURVE_CASES])
def test_creep_curve_careless_input(argv, pattern, capsys, files):
    if "-o" not in argv:
        argv = argv + ["-o", "{tmp}/out"]
    code, out, err = _run(CC + argv, capsys, files)
    _assert_one_line_error(code, err, pattern)
    assert not (files / "out").exists() or not any((files / "out").iterdir())  # nothing written


def test_inconsistent_elastic_constants_are_a_named_warning(capsys, tmp_path):
    code, out, err = _run(CC + ["--E-GPa", "210", "--G-GPa", "30", "--n", "5", "-o", str(tmp_path)], capsys)
    assert code == 0
    assert err.strip().splitlines() == [
        "mbsuite: warning: --G-GPa 30 disagrees with --E-GPa 210 and --nu 0.28 (E/(2(1+nu)) = 82.0 GPa): G sets "
        "the creep forces, E the Hertz ellipse [ElasticConstantsWarning]"]


def test_creep_curve_accept_lets_a_deliberate_outlier_through(capsys, tmp_path):
    code, out, err = _run(CC + ["--mu", "1.5", "--accept", "friction_coefficient", "--n", "5", "-o", str(tmp_path)],
                          capsys)
    assert code == 0 and err == "" and "mu = 1.5" in out


# ---------------------------------------------------------------------------------------------
# the library behind the command (creep_curve's keyword arguments)
# ---------------------------------------------------------------------------------------------
_CONTACT = dict(normal_force=100e3, a=0.006, b=0.004, G=80e9, nu=0.28, mu=0.3)  # railway.scenes


@pytest.mark.parametrize("change,pattern", [
    (dict(mu=30), r"creep curve: mu: wheel-rail friction coefficient 30 is outside the plausible range 0.01 \.\.\. 1: "
                  r"did you mean 30 %\?"),
    (dict(G=80), r"creep curve: G: shear modulus of wheel and rail 80 Pa is outside .*did you mean 80 GPa\?"),
    (dict(normal_force=1e8), r"creep curve: normal_force: wheel-rail normal load 1e\+08 N is outside .*did you mean 1e\+08 mN\?|"
                             r"creep curve: normal_force: wheel-rail normal load 1e\+08 N is outside the plausible range"),
    (dict(eta=3.0), r"creep curve: eta: longitudinal or lateral creepage 3 is outside .*did you mean 3 %\?"),
], ids=["mu per cent", "G in GPa as Pa", "load 100 MN", "eta per cent"])
def test_creep_curve_library_checks(change, pattern):
    with pytest.raises(ImplausibleValueError, match=pattern):
        creep_curve("polach2000", "xi", [0.0, 0.001], **{**_CONTACT, **change})


def test_creep_curve_library_accept_and_sweep_check():
    df = creep_curve("polach2000", "xi", [0.001], **{**_CONTACT, "mu": 1.2}, accept=["friction_coefficient"])
    assert df["mu [-]"].iloc[0] == 1.2
    with pytest.raises(ImplausibleValueError, match=r"creep curve: swept xi \(smallest, largest\): .*\[1\] 5 .*5 %"):
        creep_curve("polach2000", "xi", np.linspace(0, 5, 3), **_CONTACT)


# ---------------------------------------------------------------------------------------------
# no false alarms: the README's examples, the defaults, the scenes' contact
# ---------------------------------------------------------------------------------------------
def test_readme_creep_curve_example_passes(capsys, tmp_path):
    # README: mbsuite railway creep-curve --model polach2000 --model fastsim --creepage xi --min 0
    #         --max 0.004 --n 5 --load-kN 100 --a-mm 6 --b-mm 4 --mu 0.3 -o out/creep
    code, out, err = _run(CC + ["--model", "polach2000", "--model", "fastsim", "--creepage", "xi", "--min", "0",
                                "--max", "0.004", "--n", "5", "--load-kN", "100", "--a-mm", "6", "--b-mm", "4",
                                "--mu", "0.3", "-o", str(tmp_path)], capsys)
    assert code == 0 and err == ""
    assert (tmp_path / "creep_curve.csv").is_file()


def test_creep_curve_defaults_pass(capsys, tmp_path):
    code, out, err = _run(CC + ["-o", str(tmp_path)], capsys)
    assert code == 0 and err == "" and "contact: N = 100000 N" in out


def test_scene_creep_contact_passes_the_library_checks():
    df = creep_curve("polach2000", "phi", np.linspace(0.0, 2.0, 3), **_CONTACT)
    assert len(df) == 3


def test_contact_table_defaults_pass(capsys):
    code, out, err = _run(CT, capsys)
    assert code == 0 and err == ""
    assert "flange contact from lateral shift 6.2518 mm" in out
    assert re.search(r"equivalent conicity at 3 mm: 0\.18\d\d \(wavelength\)", out)


def test_a_unit_string_gives_the_si_number():
    """The option helper parses a number with its unit exactly as the bare number in the option's unit."""
    R = ranges()
    assert check_option(R, "wheel_normal_load", "100 kN", "--load-kN", "kN") == check_option(
        R, "wheel_normal_load", 100.0, "--load-kN", "kN") == 100e3
    assert check_option(R, "gauge", "1.435 m", "--gauge-mm", "mm") == pytest.approx(
        check_option(R, "gauge", 1435.0, "--gauge-mm", "mm"))
    assert check_option(R, "wheelset_yaw_angle", "0.286 deg", "--yaw-mrad", "mrad") == pytest.approx(
        check_option(R, "wheelset_yaw_angle", 4.99164, "--yaw-mrad", "mrad"), rel=1e-4)


def test_a_negative_number_in_exponent_notation_is_a_value(capsys, tmp_path):
    """argparse took ``--min -1e-3`` for an option ("expected one argument"); it is a value."""
    code, out, err = _run(CC + ["--min", "-1e-3", "--max", "2e-3", "--n", "3", "-o", str(tmp_path)], capsys)
    assert code == 0 and err == ""
    assert pd.read_csv(tmp_path / "creep_curve.csv")["xi [-]"].min() == -1e-3
