"""Storage/motion files and external loads (biomech.storage).

Values are compared with an independent reading of the files (numpy.loadtxt after the header);
every bad file is a modified copy written to tmp_path and must give an error naming the file and,
where it applies, the line, the column or the header flag.
"""

from __future__ import annotations

import re

import numpy as np
import pytest

from core.errors import DataFileError, DataRangeError
from core.paths import data_path
from biomech.osim import read_osim
from biomech.storage import (
    StorageWarning,
    check_motion_against_model,
    read_external_loads,
    read_external_loads_xml,
    read_storage,
    resample_external_loads,
)

OPENSIM = data_path("biomech", "opensim")
G10 = OPENSIM / "gait10dof18musc_subject01_walk"
G2392 = OPENSIM / "gait2392_subject01_walk"
IK10 = G10 / "subject01_walk_IK.mot"
IK2392 = G2392 / "subject01_walk1_ik.mot"
GRF = G10 / "subject01_walk_grf.mot"

_models: dict = {}


def model(name):
    if name not in _models:
        _models[name] = read_osim(G10 / "subject01.osim" if name == "gait10dof" else G2392 / "subject01_simbody_adjusted.osim")
    return _models[name]


def raw(path):
    """Independent reading: labels and numbers after the line 'endheader'."""
    lines = path.read_text().splitlines()
    end = next(i for i, s in enumerate(lines) if s.strip() == "endheader")
    labels = [s for s in lines[end + 1].strip().split("\t") if s.strip()]
    return labels, np.loadtxt(path, skiprows=end + 2, ndmin=2)


# ---- motions ----------------------------------------------------------------------------------


@pytest.mark.parametrize("path, key", [(IK10, "gait10dof"), (IK2392, "gait2392")])
def test_ik_motion_in_si_units_rotational_columns_converted(path, key):
    m = model(key)
    labels, values = raw(path)
    df = read_storage(path, m)
    assert list(df.columns) == labels and df.shape == values.shape
    rotational = {c.name for c in m.coordinates if c.motion_type == "rotational"}
    for j, col in enumerate(labels):
        expected = np.deg2rad(values[:, j]) if col in rotational else values[:, j]
        np.testing.assert_array_equal(df[col].to_numpy(), expected)
    assert df.attrs["in_degrees"] is True and df.attrs["source"] == str(path)
    assert df.attrs["units"]["pelvis_tx"] == "m" and df.attrs["units"]["knee_angle_r"] == "rad"
    assert set(df.attrs["angle_columns"]) == rotational & set(labels)
    assert check_motion_against_model(df, m) == ()
    # without a model the naming rule (all but *_tx/_ty/_tz are angles) gives the same frame
    np.testing.assert_array_equal(read_storage(path).to_numpy(), df.to_numpy())


def test_grf_file_is_read_without_conversion():
    labels, values = raw(GRF)
    df = read_storage(GRF, convert_angles=False)
    assert list(df.columns) == labels and len(df) == 1501
    np.testing.assert_array_equal(df.to_numpy(), values)
    assert df.attrs["angle_columns"] == []


def test_motion_against_model(tmp_path):
    m = model("gait10dof")
    df = read_storage(IK10, m)
    assert check_motion_against_model(df.drop(columns=["lumbar_extension"]), m) == ("lumbar_extension",)
    text = IK10.read_text().replace("nColumns=11", "nColumns=12")
    lines = text.splitlines()
    end = next(i for i, s in enumerate(lines) if s.strip() == "endheader")
    lines[end + 1] += "\tpatella_angle_r"
    lines[end + 2:] = [s + "\t 1.0" for s in lines[end + 2:]]
    p = tmp_path / "ik_extra.mot"
    p.write_text("\n".join(lines) + "\n")
    extra = read_storage(p, m)
    with pytest.raises(DataFileError, match=rf"{re.escape(str(p))}: column \['patella_angle_r'\] is not a coordinate "
                                            r"of model 'walk_subject01'"):
        check_motion_against_model(extra, m)
    # the gait2392 trial has coordinates the planar model lacks
    with pytest.raises(DataFileError, match=r"subject01_walk1_ik\.mot: columns \['pelvis_list', 'pelvis_rotation'"):
        check_motion_against_model(read_storage(IK2392), m)


# ---- bad storage files ----------------------------------------------------------------------------


@pytest.fixture(scope="module")
def ik_lines():
    return IK10.read_text().splitlines()


def _write(tmp_path, lines, name="bad.mot"):
    p = tmp_path / name
    p.write_text("\n".join(lines) + "\n")
    return p


def test_truncated_files_are_named(tmp_path, ik_lines):
    p = _write(tmp_path, ik_lines[:-10], "rows_missing.mot")
    with pytest.raises(DataFileError, match=rf"{re.escape(str(p))}: truncated: the header says nRows=151 but the file "
                                            rf"has only 141 data rows \(last at line {len(ik_lines) - 10}\)"):
        read_storage(p)
    half_row = ik_lines[:-1] + [ik_lines[-1][: len(ik_lines[-1]) // 2]]
    p = _write(tmp_path, half_row, "cut_in_row.mot")
    with pytest.raises(DataFileError, match=rf"{re.escape(str(p))}, line {len(ik_lines)}: \d+ values, expected 11 .*"
                                            r"truncated\?"):
        read_storage(p)
    p = _write(tmp_path, ik_lines[:5], "header_only.mot")
    with pytest.raises(DataFileError, match=r"header_only\.mot: no 'endheader' line"):
        read_storage(p)


def test_non_numeric_value_names_line_and_column(tmp_path, ik_lines):
    lines = list(ik_lines)
    k = 20
    tokens = lines[k].split()
    tokens[5] = "12.3x"
    lines[k] = "\t".join(tokens)
    p = _write(tmp_path, lines)
    with pytest.raises(DataFileError, match=rf"{re.escape(str(p))}, line {k + 1}, column 'knee_angle_r': value '12\.3x' "
                                            r"is not a number"):
        read_storage(p)


def test_missing_time_column_and_time_going_backwards(tmp_path, ik_lines):
    end = ik_lines.index("endheader")
    lines = list(ik_lines)
    lines[end + 1] = lines[end + 1].replace("time", "t")
    with pytest.raises(DataFileError, match=rf"line {end + 2}: no 'time' column"):
        read_storage(_write(tmp_path, lines, "no_time.mot"))
    lines = list(ik_lines)
    k = end + 2 + 30
    tokens = lines[k].split()
    tokens[0] = lines[k - 1].split()[0]  # repeats the previous time
    lines[k] = "\t".join(tokens)
    with pytest.raises(DataFileError, match=rf"back\.mot, line {k + 1}: time .* does not increase"):
        read_storage(_write(tmp_path, lines, "back.mot"))
    lines = [s.replace("nColumns=11", "nColumns=12") for s in ik_lines]
    with pytest.raises(DataFileError, match=r"the header says nColumns=12 but there are 11 column labels"):
        read_storage(_write(tmp_path, lines, "ncol.mot"))


def test_implausible_in_degrees_flag_is_caught(tmp_path, ik_lines):
    """The RRA pitfall: a header saying inDegrees=no over values in degrees."""
    p = _write(tmp_path, [s.replace("inDegrees=yes", "inDegrees=no") for s in ik_lines], "rra_like.mot")
    m = model("gait10dof")
    with pytest.raises(DataFileError, match=rf"{re.escape(str(p))}: the header has inDegrees=no, but angle column "
                                            r"'pelvis_tilt' reaches .* the values look like degrees"):
        read_storage(p, m)
    with pytest.warns(StorageWarning, match="inDegrees=no"):
        df = read_storage(p, m, check_degrees="warn")
    np.testing.assert_array_equal(df["knee_angle_r"], raw(IK10)[1][:, 5])  # unconverted, as the flag says
    read_storage(p, m, check_degrees="off")
    # the same motion written in radians with inDegrees=no passes the check
    rad = read_storage(IK10, m)
    end = ik_lines.index("endheader")
    lines = [s.replace("inDegrees=yes", "inDegrees=no") for s in ik_lines[: end + 2]]
    lines += ["\t".join(f"{v:.17g}" for v in row) for row in rad.to_numpy()]
    back = read_storage(_write(tmp_path, lines, "radians.mot"), m)
    np.testing.assert_array_equal(back.to_numpy(), rad.to_numpy())


# ---- external loads -----------------------------------------------------------------------------


def test_external_loads_of_both_trials():
    labels, values = raw(GRF)
    col = {c: values[:, j] for j, c in enumerate(labels)}
    loads = read_external_loads(G10 / "subject01_walk_grf.xml")
    assert loads.names == ("right", "left") and loads.source == str(GRF)
    right = loads["right"]
    spec = right.spec
    assert (spec.applied_to_body, spec.force_expressed_in_body, spec.point_expressed_in_body) == ("calcn_r", "ground", "ground")
    assert (spec.force_identifier, spec.point_identifier, spec.torque_identifier) == ("ground_force_v", "ground_force_p",
                                                                                      "ground_torque_")
    np.testing.assert_array_equal(right.force, np.column_stack([col[f"ground_force_v{a}"] for a in "xyz"]))
    np.testing.assert_array_equal(right.point, np.column_stack([col[f"ground_force_p{a}"] for a in "xyz"]))
    np.testing.assert_array_equal(loads["left"].torque, np.column_stack([col[f"1_ground_torque_{a}"] for a in "xyz"]))
    # the gait2392 file is an OpenSim 2.x document with a <defaults> section and padded values
    spec2 = read_external_loads_xml(G2392 / "subject01_walk1_grf.xml")
    assert [(f.name, f.applied_to_body, f.force_identifier) for f in spec2.forces] == [
        ("ExternalForce_1", "calcn_r", "ground_force_v"), ("ExternalForce_2", "calcn_l", "1_ground_force_v")]
    assert spec2.datafile == G2392 / "subject01_walk1_grf.mot" and all(f.applies_force for f in spec2.forces)


def test_resampling_onto_the_kinematics_times():
    loads = read_external_loads(G10 / "subject01_walk_grf.xml")
    at_samples = resample_external_loads(loads, loads.time[5:-5:7])  # interpolation is exact at the samples
    np.testing.assert_allclose(at_samples["right"].force, loads["right"].force[5:-5:7], rtol=0, atol=1e-9)
    t_ik = read_storage(IK10)["time"].to_numpy()
    lin = resample_external_loads(loads, t_ik, method="linear")
    expected = np.interp(t_ik, loads.time, loads["left"].force[:, 1])
    np.testing.assert_allclose(lin["left"].force[:, 1], expected, rtol=0, atol=1e-12)
    spl = resample_external_loads(loads, t_ik)
    assert spl["left"].force.shape == (len(t_ik), 3) and spl.time[0] == t_ik[0]
    # a natural cubic through 600 Hz data stays close to the straight lines between samples
    assert np.max(np.abs(spl["left"].force - lin["left"].force)) < 0.05 * np.max(np.abs(lin["left"].force))


def test_force_data_not_covering_the_kinematics_is_a_data_range_error():
    """gait2392 trial: kinematics 0.5-4.0 s, ground reactions 0-2.5 s."""
    loads = read_external_loads(G2392 / "subject01_walk1_grf.xml")
    t_ik = read_storage(IK2392)["time"].to_numpy()
    with pytest.raises(DataRangeError, match=rf"{re.escape(str(G2392 / 'subject01_walk1_grf.mot'))}: the force data "
                                             r"cover t = 0 … 2\.5 s, but times 0\.5 … 4 s are requested"):
        resample_external_loads(loads, t_ik)
    inside = t_ik[t_ik <= 2.5]
    assert resample_external_loads(loads, inside).time[-1] == pytest.approx(2.5)


def test_bad_external_loads_files(tmp_path):
    text = (G10 / "subject01_walk_grf.xml").read_text()
    p = tmp_path / "grf.xml"
    p.write_text(text.replace("<force_identifier>1_ground_force_v</force_identifier>",
                              "<force_identifier>ground_force_</force_identifier>").replace(
        "<datafile>subject01_walk_grf.mot</datafile>", f"<datafile>{GRF}</datafile>"))
    with pytest.raises(DataFileError, match=r"subject01_walk_grf\.mot: external force 'left': force identifier "
                                            r"'ground_force_' must match exactly 3 columns, matches 6"):
        read_external_loads(p)
    p.write_text(text.replace("<ExternalForce name=\"right\">", "<PrescribedForce name=\"right\">").replace(
        "</ExternalForce>\n\t\t\t<ExternalForce", "</PrescribedForce>\n\t\t\t<ExternalForce", 1))
    with pytest.raises(DataFileError, match=r"grf\.xml, line \d+: <PrescribedForce name='right'>: only ExternalForce "
                                            r"entries are supported"):
        read_external_loads_xml(p)
