"""The flexible car body (railway.vehicles.car_body, vehicle files' [car_body.flexible]; issue 23).

Tier 1: the equivalent beam's rigid body is the file's (mass, inertia about the centre of mass) and
its frame is the mean axes; its frequencies are the file's; with no rotary inertia its bending
stiffness is the Euler–Bernoulli free–free closed form.  Tier 2: the FE beam's static sag on the
two bogie centres under its weight against the closed form of a beam with overhangs; the vehicle's
static preload against the modal static solution of the kept modes (independent of the vehicle
code).  Tier 3: a run with stiff modes approaches the rigid car body.  Inputs: typos, unit slips
and contradictions are refused naming the key.
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse.linalg as spla

from core.errors import DataFileError, InputError
from core.flexible.body import flexible_body_data
from core.integrators import simulate
from railway.track import Track
from railway.vehicles.car_body import car_body_beam
from railway.vehicles.ride_comfort import ASSUMED_FLEXIBLE_CAR_BODY
from railway.vehicles.vehicle import VehicleDefinition, build_vehicle

MASS, INERTIA = 32000.0, np.array([56800.0, 1970000.0, 1970000.0])  # the Manchester coach's car body
L_B = 9.5


def test_equivalent_beam_has_the_files_rigid_body_mean_axes_and_frequencies():
    beam = car_body_beam(MASS, INERTIA, 24.0, [0.0, L_B, -L_B], 9.0, 12.0, 15.0)
    data = flexible_body_data("car body", beam.fe, beam.modes, 0.02, False, 3, "undeformed")
    M0 = data.undeformed_mass()
    assert np.allclose(np.diag(M0)[:3], MASS, rtol=1e-12)
    assert np.allclose(M0[3:6, 3:6], np.diag(INERTIA), rtol=1e-9, atol=1e-9 * INERTIA.max())
    assert np.max(np.abs(data.first_moment)) < 1e-9 * MASS * 24.0
    off = M0 - np.diag(np.diag(M0))
    assert np.max(np.abs(off)) < 1e-9 * np.sqrt(MASS), "mean axes: no inertia coupling of frame and modes"
    assert beam.frequencies == pytest.approx({"vertical bending": 9.0, "torsion": 12.0, "lateral bending": 15.0},
                                             rel=1e-9)
    assert data.frequencies == pytest.approx([9.0, 12.0, 15.0], rel=1e-9)
    assert set(beam.stations) == {0.0, L_B, -L_B}
    assert np.allclose(beam.fe.nodes[[beam.stations[x] for x in (0.0, L_B, -L_B)], 0], [0.0, L_B, -L_B])


def test_bending_stiffness_without_rotary_inertia_is_the_euler_bernoulli_closed_form():
    """I_yy = m L²/12 leaves no rotary inertia: EI of the 9 Hz first free–free bending is
    ρA (2π f L² / 4.73004²)² to the discretisation error of 24 cubic elements (below 1e-4)."""
    L = 24.0
    J = np.array([56800.0, MASS * L**2 / 12.0, MASS * L**2 / 12.0])
    beam = car_body_beam(MASS, J, L, [0.0, L_B, -L_B], 9.0)
    EI = MASS / L * (2 * np.pi * 9.0 * L**2 / 4.730040744862704**2) ** 2
    assert beam.stiffness["EI_y"] == pytest.approx(EI, rel=1e-4)


def test_static_sag_on_the_bogie_centres_against_the_closed_form_and_the_modal_solution():
    """Under its weight w = m g / L on supports 2 L_b apart with overhangs a, the midspan sag of an
    Euler–Bernoulli beam relative to the supports is w l² (5 l² − 24 a²) / (384 EI) (superposition of
    the simply supported span and the overhang moments).  The full FE beam gives it to 1e-8 (cubic
    elements with consistent loads are nodally exact).  The vehicle's static preload, with the kept
    modes only, gives the modal static solution of the same loads (to 2e-3: its supports are springs
    at the secondary suspension points), which is the closed form less the truncation (measured 2.9 %)."""
    D = VehicleDefinition.manchester().with_flexible_car_body(**ASSUMED_FLEXIBLE_CAR_BODY)
    veh = build_vehicle(D, Track.straight(100.0), s0=50.0, speed=0.0)
    veh.preload()
    q, m = veh.q_static, veh.model
    z = {k: q[m.q_slice(v).start + 2] for k, v in veh.car_body_frames.items()}
    sag = z["centre"] - 0.5 * (z["over bogie 1"] + z["over bogie 2"])
    beam = veh.car_body_beam
    L, l = ASSUMED_FLEXIBLE_CAR_BODY["length"], 2 * L_B
    a, w = (L - l) / 2, MASS * 9.81 / L
    closed = -w * l**2 * (5 * l**2 - 24 * a**2) / (384 * beam.stiffness["EI_y"])
    # the full FE beam on two supports
    fe, st = beam.fe, beam.stations
    g = np.zeros(fe.n_dofs)
    g[2::6] = -9.81
    f = fe.M @ g
    c, b1, b2 = st[0.0], st[L_B], st[-L_B]
    fix = [6 * b1 + 2, 6 * b2 + 2, 6 * c, 6 * c + 1, 6 * c + 3, 6 * c + 5]
    free = np.setdiff1d(np.arange(fe.n_dofs), fix)
    K = fe.K.tocsr()
    u = np.zeros(fe.n_dofs)
    u[free] = spla.spsolve(K[free][:, free].tocsc(), f[free])
    sag_fe = u[6 * c + 2] - 0.5 * (u[6 * b1 + 2] + u[6 * b2 + 2])
    assert sag_fe == pytest.approx(closed, rel=1e-8)
    # modal static solution of the kept (free–free) modes under weight and the two support reactions
    load = f.copy()
    load[6 * b1 + 2] += MASS * 9.81 / 2
    load[6 * b2 + 2] += MASS * 9.81 / 2
    T = beam.modes.T
    qm = np.linalg.solve(beam.modes.K, T.T @ load)
    um = T @ qm
    sag_modal = um[6 * c + 2] - 0.5 * (um[6 * b1 + 2] + um[6 * b2 + 2])
    assert sag == pytest.approx(sag_modal, rel=2e-3)
    assert 0.0 < 1.0 - sag / closed < 0.035, "one symmetric bending mode: a few per cent of truncation"


def test_stiff_car_body_approaches_the_rigid_one():
    """Bending at 38 Hz, torsion 38 Hz: over 1 s on irregular track the car body's vertical motion
    differs from the rigid car body's by less than 5 % of its range; at the assumed 9 Hz it differs
    by more (the mode matters)."""
    from railway.contact.creep import creep_law_for_runs
    from railway.vehicles.ride import irregularities

    V = 30.0
    track = Track.straight(160.0, irregularities=irregularities(160.0, seed=1))
    cl, cp = creep_law_for_runs("polach2000", V)
    D0 = VehicleDefinition.manchester()
    z = {}
    for label, D in (("rigid", D0),
                     ("stiff", D0.with_flexible_car_body(length=24.0, vertical_bending_frequency=38.0,
                                                        torsion_frequency=38.0)),
                     ("9 Hz", D0.with_flexible_car_body(**ASSUMED_FLEXIBLE_CAR_BODY))):
        veh = build_vehicle(D, track, s0=40.0, speed=V, creep_law=cl, creep_params=cp, speed_control=V)
        veh.preload()
        q0, v0 = veh.initial_state()
        res = simulate(veh.model, (0.0, 1.5), "jit-dop853", q0=q0, v0=v0, rtol=1e-5, atol=1e-7, n_output=151)
        assert res.success, res.message
        if veh.car_body_frames:  # the node frame over the leading bogie centre
            zz = res.q[:, veh.model.q_slice(veh.car_body_frames["over bogie 1"]).start + 2]
        else:  # the same point of the rigid car body
            zz = veh.model.point_position(res.q, veh.car_body, [L_B, 0.0, 0.0])[:, 2]
        z[label] = zz - zz[0]
    rng = np.ptp(z["rigid"])
    assert np.max(np.abs(z["stiff"] - z["rigid"])) < 0.05 * rng
    assert np.max(np.abs(z["9 Hz"] - z["rigid"])) > np.max(np.abs(z["stiff"] - z["rigid"]))


def _file(tmp_path, flexible: str, car_body_extra: str = "") -> str:
    from core.paths import data_path

    from pathlib import Path

    text = Path(data_path("railway", "vehicles", "manchester_coach.toml")).read_text()
    text = text.replace('inertia = [56800.0, 1970000.0, 1970000.0] # kg m^2 (roll, pitch, yaw)',
                        'inertia = [56800.0, 1970000.0, 1970000.0]' + car_body_extra)
    text = text.replace("[bogie]\n", f"[car_body.flexible]\n{flexible}\n\n[bogie]\n", 1)
    p = tmp_path / "coach.toml"
    p.write_text(text)
    # profiles are built-in: the copy reads anywhere
    return str(p)


def test_vehicle_file_flexible_table(tmp_path):
    D = VehicleDefinition.from_toml(_file(tmp_path, 'length = "24 m"\nvertical_bending_frequency = "9 Hz"\n'
                                                    'damping_ratio = "2 %"'))
    fx = D.car_body["flexible"]
    assert fx["length"] == 24.0 and fx["vertical_bending_frequency"] == 9.0 and fx["damping_ratio"] == 0.02
    assert fx["torsion_frequency"] is None and fx["elements"] == 24


@pytest.mark.parametrize("table,match", [
    ('length = 24.0\nvertical_bending_freqency = 9.0', "did you mean 'vertical_bending_frequency'"),
    ('length = 24.0\nvertical_bending_frequency = "56.5 rad/s"', "in Hz.*2π"),
    ('length = 24.0\nvertical_bending_frequency = 90.0', "first vertical bending frequency.*outside"),
    ('length = 24.0\nvertical_bending_frequency = 9.0\ndamping_ratio = 2', "damping ratio.*outside"),
    ('length = 18.0\nvertical_bending_frequency = 9.0', "does not reach over the bogie centres"),
    ('length = 30.0\nvertical_bending_frequency = 9.0', "pitch inertia.*at most 27.1"),
    ('length = 24.0\nvertical_bending_frequency = 9.0\nelements = 2.5', "whole number of beam elements"),
    ('length = 24.0', "vertical_bending_frequency"),
])
def test_careless_flexible_tables_are_refused_by_key(tmp_path, table, match):
    with pytest.raises((DataFileError, InputError), match=match):
        VehicleDefinition.from_toml(_file(tmp_path, table))


def test_flexible_car_body_in_a_curve_is_refused_by_name():
    from railway.vehicles.curving import curving_track

    D = VehicleDefinition.manchester().with_flexible_car_body(**ASSUMED_FLEXIBLE_CAR_BODY)
    with pytest.raises(InputError, match="flexible car body, which starts on straight track only"):
        build_vehicle(D, curving_track(), s0=150.0, speed=10.0)
    with pytest.raises(InputError, match="with_flexible_car_body.*vertical_bending_frequency"):
        VehicleDefinition.manchester().with_flexible_car_body(length=24.0, vertical_bending_frequncy=9.0)


def test_the_guides_flexible_table_reads(tmp_path):
    """The ```toml block of docs/user-guide/railway-vehicles.md (units as strings, comments) is a
    valid [car_body.flexible] table for the Manchester coach."""
    import re

    from core.paths import repo_root

    page = (repo_root() / "docs" / "user-guide" / "railway-vehicles.md").read_text(encoding="utf-8")
    block = re.search(r"```toml\n\[car_body\.flexible\]\n(.*?)```", page, re.S).group(1)
    fx = VehicleDefinition.from_toml(_file(tmp_path, block)).car_body["flexible"]
    assert fx == {"length": 24.0, "vertical_bending_frequency": 9.0, "torsion_frequency": 12.0,
                  "lateral_bending_frequency": 15.0, "damping_ratio": 0.02, "elements": 24}


# --- an imported car-body FE model ([car_body.flexible] mass_matrix, stiffness_matrix, nodes) -----------

#: the centre of mass in the exported model's coordinates: their origin at the body's rear end, at
#: rail height 1.8 m below the centre of mass (the import must find the centre of mass itself)
OFFSET = np.array([12.0, 0.0, 1.8])


def _export(tmp_path, mass_scale=1.0):
    """The equivalent beam of the assumed 9/12/15 Hz car body written as another FE code would: Matrix
    Market mass and stiffness, a node CSV with a header, the origin at the body's rear end."""
    from scipy.io import mmwrite

    beam = car_body_beam(MASS, INERTIA, 24.0, [0.0, L_B, -L_B], 9.0, 12.0, 15.0)
    mmwrite(str(tmp_path / "carbody_M.mtx"), beam.fe.M * mass_scale, symmetry="symmetric")
    mmwrite(str(tmp_path / "carbody_K.mtx"), beam.fe.K, symmetry="symmetric")
    X = beam.fe.nodes + OFFSET
    (tmp_path / "carbody_nodes.csv").write_text("x,y,z\n" + "\n".join(",".join(f"{v:.17g}" for v in r) for r in X))
    st = beam.stations
    return beam, st[0.0], [st[L_B], st[-L_B]]


def _import_table(centre, bogies, extra=""):
    return (f'mass_matrix = "carbody_M.mtx"\nstiffness_matrix = "carbody_K.mtx"\nnodes = "carbody_nodes.csv"\n'
            f"modes = 3\ncentre_node = {centre}\nbogie_nodes = {bogies}\n{extra}")


def test_an_imported_car_body_is_the_same_body_as_its_equivalent_beam(tmp_path):
    """The equivalent beam exported and read back through a vehicle file: the same mass, inertia and
    free–free frequencies (to round-off), its centre of mass found where the export put it."""
    from railway.vehicles.car_body import imported_car_body

    beam, centre, bogies = _export(tmp_path)
    D = VehicleDefinition.from_toml(_file(tmp_path, _import_table(centre, bogies)))
    fx = D.car_body["flexible"]
    assert fx["modes"] == 3 and "length" not in fx
    body = imported_car_body(fx["mass_matrix"], fx["stiffness_matrix"], fx["nodes"], fx["centre_node"],
                             fx["bogie_nodes"], MASS, INERTIA, L_B, fx["modes"])
    np.testing.assert_allclose(body.centre_of_mass, OFFSET, atol=1e-9)
    assert body.mass == pytest.approx(MASS, rel=1e-12)
    np.testing.assert_allclose(body.inertia, INERTIA, rtol=1e-9)
    np.testing.assert_allclose(sorted(body.frequencies.values()), [9.0, 12.0, 15.0], rtol=1e-9)
    assert body.stations == {"centre": centre, "over bogie 1": bogies[0], "over bogie 2": bogies[1]}


def test_an_imported_car_body_rides_as_its_equivalent_beam(tmp_path):
    """Over 0.6 s of irregular track at 30 m/s, the car body over the leading bogie moves the same with
    the imported model as with the [car_body.flexible] beam table it was exported from (the same modes,
    so the difference is the integration error at rtol 1e-7)."""
    from railway.contact.creep import creep_law_for_runs
    from railway.vehicles.ride import irregularities

    _, centre, bogies = _export(tmp_path)
    V = 30.0
    track = Track.straight(160.0, irregularities=irregularities(160.0, seed=1))
    cl, cp = creep_law_for_runs("polach2000", V)
    z = {}
    for label, D in (("beam", VehicleDefinition.manchester().with_flexible_car_body(**ASSUMED_FLEXIBLE_CAR_BODY)),
                     ("imported", VehicleDefinition.from_toml(_file(
                         tmp_path, _import_table(centre, bogies, 'damping_ratio = "2 %"'))))):
        veh = build_vehicle(D, track, s0=40.0, speed=V, creep_law=cl, creep_params=cp, speed_control=V)
        veh.preload()
        q0, v0 = veh.initial_state()
        res = simulate(veh.model, (0.0, 0.6), "jit-dop853", q0=q0, v0=v0, rtol=1e-7, atol=1e-9, n_output=61)
        assert res.success, res.message
        z[label] = res.q[:, veh.model.q_slice(veh.car_body_frames["over bogie 1"]).start + 2]
    assert np.ptp(z["beam"]) > 1e-4  # the body does move
    assert np.max(np.abs(z["imported"] - z["beam"])) < 1e-4 * np.ptp(z["beam"])


@pytest.mark.parametrize("case,match", [
    ("mass in t", r"mass of 3\.2e\+07 kg.*32000 kg.*mass_unit slip.*10\^3"),
    ("off by one", r"bogie_nodes\[0\] \(over bogie 1\) = .* lies at x = "),
    ("both", "either the equivalent beam .* or an imported FE model .* not both"),
    ("missing key", "missing centre_node"),
    ("missing file", "does not exist"),
    ("seven modes", "modes = 7"),
    ("node out of range", "node 999 is not a row"),
    ("axes swapped", r"roll inertia about its centre of mass .* axes x forward"),
])
def test_careless_imports_are_refused_by_name(tmp_path, case, match):
    _, centre, bogies = _export(tmp_path, mass_scale=1000.0 if case == "mass in t" else 1.0)
    table = {"mass in t": _import_table(centre, bogies),
             "off by one": _import_table(centre, [bogies[0] + 1, bogies[1]]),
             "both": _import_table(centre, bogies, "length = 24.0"),
             "missing key": _import_table(centre, bogies).replace(f"centre_node = {centre}\n", ""),
             "missing file": _import_table(centre, bogies).replace("carbody_K.mtx", "carbody_K2.mtx"),
             "seven modes": _import_table(centre, bogies).replace("modes = 3", "modes = 7"),
             "node out of range": _import_table(centre, [999, bogies[1]]),
             "axes swapped": _import_table(centre, bogies)}[case]
    if case == "axes swapped":  # the body's length written along y
        nodes = tmp_path / "carbody_nodes.csv"
        rows = [r.split(",") for r in nodes.read_text().splitlines()[1:]]
        nodes.write_text("y,x,z\n" + "\n".join(",".join([r[1], r[0], r[2]]) for r in rows))
    with pytest.raises((DataFileError, InputError), match=match):
        VehicleDefinition.from_toml(_file(tmp_path, table))


def test_the_guides_import_table_has_only_valid_keys():
    """The guide's ```toml block for an imported FE model names files this test does not have; its
    keys, units and node numbers pass the table's schema (a renamed key or a typo would not)."""
    import re
    import tomllib

    from core.inputs import validate
    from core.paths import repo_root
    from railway.vehicles.vehicle_file import IMPORT_KEYS, FlexibleCarBody

    page = (repo_root() / "docs" / "user-guide" / "railway-vehicles.md").read_text(encoding="utf-8")
    block = re.search(r"```toml\n(\[car_body\.flexible\]\nmass_matrix.*?)```", page, re.S).group(1)
    table = tomllib.loads(block)["car_body"]["flexible"]
    fx = validate(FlexibleCarBody, table, source="guide", context={"accept": []})
    assert set(table) - {"damping_ratio"} == set(IMPORT_KEYS)
    assert fx.mass_unit == "t" and fx.length_unit == "mm" and fx.bogie_nodes == [35, 205] and fx.damping_ratio == 0.02
