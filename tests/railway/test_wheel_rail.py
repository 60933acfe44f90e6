"""The wheel-rail contact as a force element of the core (railway.vehicles.wheel_rail) and the vehicle.

Oracles: the analytic linearisation of a centred wheelset on its rails (Hertz stiffness
3N/(2 delta), Kalker's creep coefficients), the share of the weight of a symmetric vehicle,
the static deflections of linear springs, Newton's third law for rails on a body, and the numpy
reference path for the compiled kernels.
"""

from pathlib import Path

import numpy as np
import pytest

from core.integrators import simulate
from core.model import ModelBuilder
from railway.contact.geometry import rigid_contact
from railway.contact.creep import kalker_coefficients
from railway.track import Track
from railway.vehicles.vehicle import GRAVITY, VehicleDefinition, build_vehicle
from railway.vehicles.wheel_rail import WheelRailContact, contact_history

V = 20.0
R0 = 0.46
M_WS, J_WS = 1813.0, (1120.0, 112.0, 1120.0)


def wheelset_model(creep_law="kalker_linear", y0=0.0, sink=6e-5, vy=0.0, rail_body=False, speed=V,
                   track_length=400.0, extra=None, **kw):
    """One wheelset at s = 10 m on straight track, pressed sink (m) into the rails."""
    tr = Track.straight(track_length)
    z0, roll0, _, _ = rigid_contact([y0], wheel=kw.get("wheel"))
    b = ModelBuilder(3, "wheelset", gravity=(0.0, 0.0, -GRAVITY))
    from core import frames

    p = frames.rotation_vector_to_euler(np.array([roll0[0], 0.0, 0.0]))
    b.add_body("ws", mass=M_WS, inertia=J_WS, position=(10.0, y0, z0[0] - sink), orientation=p,
               velocity=(speed, vy, 0.0), angular_velocity=(0.0, speed / R0, 0.0))
    if rail_body:
        b.add_body("track", mass=500.0, inertia=(100.0, 100.0, 100.0), position=(0.0, 0.0, 0.0))
        b.add_fixed("anchor", "ground", "track", at=(0.0, 0.0, 0.0))
    b.add_force(WheelRailContact("wr", ["ws"], tr, creep_law=creep_law,
                                 rail_body="track" if rail_body else None, **kw))
    if extra is not None:
        extra(b)
    return b.build()


def kind_of(model):
    return next(k for k in model.force_kinds if type(k).__name__ == "WheelRailKind")


# ---------------------------------------------------------------------------------------------
# Jacobians against the analytic linearisation
# ---------------------------------------------------------------------------------------------
def test_jacobian_against_the_analytic_linearisation():
    # conical wheels: one contact patch per wheel (the centred S1002 tread has two near-equal
    # minima sharing the load, see railway.vehicles.wheel_rail "Two patches per zone")
    from railway.contact.two_point import conical_wheel

    m = wheelset_model(wheel=conical_wheel())
    kind = kind_of(m)
    bs = m.body_states(m.q0, m.v0)
    kind.reset_state(bs, 0.0)
    out = kind.contact_outputs(bs, 0.0)
    c = out["contacts"]
    tread = c["N [N]"][:, 0]
    assert np.all(tread > 0) and np.all(c["N [N]"][:, 1] == 0)
    delta = c["penetration [m]"][:, 0]
    gam = c["contact angle [rad]"][:, 0]
    J = kind.jacobian(bs, 0.0)
    Kq, Kv = J.Kq[0], J.Kv[0]
    # vertical: Hertz N = K delta^(3/2) of both wheels, normal tilted by the contact angle
    k_vert = np.sum(1.5 * tread / delta * np.cos(gam) ** 2)
    assert Kq[2, 2] == pytest.approx(-k_vert, rel=2e-3)
    # lateral and yaw creep damping of Kalker's linear theory (Wickens 2003, ch. 2):
    # dFy/dydot = -sum f22 cos(gam)^2 / V, dMz/dpsidot = -sum f11 l^2 / V
    a, b_ = c["a [m]"][:, 0], c["b [m]"][:, 0]
    C11, C22, _, _ = kalker_coefficients(a / b_, 0.28)
    G = 2.1e11 / (2 * 1.28)
    f11, f22 = G * a * b_ * C11, G * a * b_ * C22
    assert Kv[1, 1] == pytest.approx(-np.sum(f22 * np.cos(gam) ** 2) / V, rel=1e-2)
    lat = np.abs(out["wheelsets"]["lateral displacement [m]"])  # centred: 0
    assert lat[0] < 1e-9
    l_c = 0.5 * (1.360 + 0.140) + np.abs(c["y_wheel [m]"][:, 0])  # contact lateral spacing
    assert Kv[5, 5] == pytest.approx(-np.sum(f11 * l_c**2) / V, rel=2e-2)


def test_jacobian_matches_finite_differences_of_the_model_forces():
    """The kind's Jacobian against an independent central difference of model.Q (velocity-space
    increments through the model's retraction)."""
    m = wheelset_model(y0=0.004)
    q, v = m.q0, m.v0
    m.begin_run(0.0, q, v)
    Qq, Qv = m.Q_jacobians(0.0, q, v)
    Qq, Qv = np.asarray(Qq.todense()), np.asarray(Qv.todense())
    h = 1e-7
    for j in range(6):
        dv = np.zeros(6)
        dv[j] = h
        col = (m.Q(0.0, m.retract(q, dv), v) - m.Q(0.0, m.retract(q, -dv), v)) / (2 * h)
        np.testing.assert_allclose(Qq[:, j], col, rtol=1e-4, atol=1e-4 * np.abs(Qq).max())
        dvv = np.zeros(6)
        dvv[j] = 1e-6
        colv = (m.Q(0.0, q, v + dvv) - m.Q(0.0, q, v - dvv)) / 2e-6
        np.testing.assert_allclose(Qv[:, j], colv, rtol=1e-4, atol=1e-4 * np.abs(Qv).max())


# ---------------------------------------------------------------------------------------------
# the search state never makes the force depend on history
# ---------------------------------------------------------------------------------------------
def test_same_force_within_a_step_bit_for_bit_and_after_any_history():
    m = wheelset_model(y0=0.003)
    q, v = m.q0.copy(), m.v0.copy()
    m.begin_run(0.0, q, v)
    Q0 = m.Q(0.0, q, v)
    # stages, Newton iterates, rejected steps: evaluations elsewhere, no accepted step
    rng = np.random.default_rng(1)
    for _ in range(5):
        dv = rng.normal(scale=1e-4, size=6)
        m.Q(0.0, m.retract(q, dv), v + rng.normal(scale=1e-2, size=6))
    np.testing.assert_array_equal(m.Q(0.0, q, v), Q0)
    # a history of accepted steps that ends elsewhere, then back to (t, q, v)
    res = simulate(m, (0.0, 0.05), "rk45", q0=q, v0=v, rtol=1e-6, atol=1e-8)
    assert res.success
    m.accept_step(0.05, res.q[-1], res.v[-1])
    np.testing.assert_allclose(m.Q(0.0, q, v), Q0, rtol=1e-9, atol=1e-9 * np.abs(Q0).max())
    # a fresh start at a pose 2 mm away, then back
    q2 = q.copy()
    q2[1] -= 0.002
    m.begin_run(0.0, q2, v)
    np.testing.assert_allclose(m.Q(0.0, q, v), Q0, rtol=1e-9, atol=1e-9 * np.abs(Q0).max())


# ---------------------------------------------------------------------------------------------
# lift-off and derailment are outcomes
# ---------------------------------------------------------------------------------------------
def test_a_lifted_wheelset_has_no_contact_force_and_lands():
    m = wheelset_model(sink=-1e-3)  # 1 mm above the rails
    kind = kind_of(m)
    bs = m.body_states(m.q0, m.v0)
    kind.reset_state(bs, 0.0)
    out = kind.contact_outputs(bs, 0.0)
    assert np.all(out["wheels"]["Q [N]"] == 0.0) and np.all(np.isnan(out["wheels"]["Y/Q [-]"]))
    np.testing.assert_array_equal(m.Q(0.0, m.q0, m.v0)[:3], [0.0, 0.0, -M_WS * GRAVITY])
    # free fall of 1 mm takes sqrt(2 h / g) = 14.3 ms; then the wheels bounce on their rails,
    # losing energy at every impact (Lankarani-Nikravesh damping, restitution 0.9)
    res = simulate(m, (0.0, 0.08), "jit-dop853", rtol=1e-8, atol=1e-10, n_output=801)
    assert res.status == "finished"
    z = res.coordinates()["ws.z [m]"].to_numpy()
    t = res.t
    fall = np.sqrt(2e-3 / GRAVITY)
    before = t < fall - 1e-3
    np.testing.assert_allclose(z[before], m.q0[2] - 0.5 * GRAVITY * t[before] ** 2, atol=1e-9)
    h = z - (m.q0[2] - 1e-3)  # height above the rigid contact
    apex = [h[i] for i in range(1, len(h) - 1) if h[i] >= h[i - 1] and h[i] > h[i + 1] and t[i] > fall]
    assert len(apex) >= 2 and 0.0 < apex[1] < apex[0] < 1e-3  # every bounce lower than the last
    assert h.min() > -2e-4  # Hertz: the impact penetration stays a fraction of a millimetre


@pytest.mark.parametrize("method", ["rk45", "jit-dop853"])
def test_a_wheelset_pushed_off_the_rails_ends_failed_naming_the_wheel(method):
    # a lateral force of 40 kN to the right at the centre of a wheelset carrying 17.8 kN: its
    # moment about the right rail (40 kN x 0.46 m) exceeds the weight's (17.8 kN x 0.75 m), so
    # the wheelset tips over the right rail and leaves it
    m = wheelset_model(y0=0.0, creep_law="polach2000",
                       extra=lambda b: b.add_applied_force("push", "ws", (0.0, 0.0, 0.0), (0.0, -40e3, 0.0)))
    res = simulate(m, (0.0, 1.0), method, rtol=1e-4, atol=1e-6)
    assert res.status == "failed"
    assert "derailment" in res.message and "'ws right'" in res.message and "Y/Q" in res.message
    assert "at t = " in res.message
    # the run keeps what it computed: lateral displacement up to the failure
    y = res.coordinates()["ws.y [m]"].to_numpy()
    assert np.all(np.isfinite(y)) and y[-1] < -0.006


@pytest.mark.parametrize("method", ["rk45", "jit-dop853"])
def test_a_flange_that_has_climbed_ends_the_run_naming_the_wheel(method):
    """Rigid contact with the wheelset 12 mm to the right: the right flange touches its rail
    46.1 mm from the taping line, on the flange tip arc above the 70 deg flank (which ends at
    -39.76 mm), more than the 5 mm criterion higher -- flange climb.  At 5 mm (short of the
    flange onset at 6.25 mm) the same run goes on."""
    from railway.contact.geometry import rigid_contact

    z, _, res0, *_ = rigid_contact([-0.012])
    assert res0.y_wheel[1, 1] < -0.046  # the right wheel's flange contact of the rigid pose
    m = wheelset_model(y0=-0.012, creep_law="polach2000")
    res = simulate(m, (0.0, 0.05), method, rtol=1e-4, atol=1e-6)
    assert res.status == "failed"
    assert "flange climb" in res.message and "'ws right'" in res.message and "Y/Q" in res.message
    # the run's rows up to the failure replay into a contact history (no check raises in the replay)
    H = contact_history(m, res)
    assert len(H) == 2 * len(res.t) and np.isfinite(H["Q [N]"]).all()
    ok = simulate(wheelset_model(y0=-0.005, creep_law="polach2000"), (0.0, 0.05), method, rtol=1e-4, atol=1e-6)
    assert ok.success, ok.message


# ---------------------------------------------------------------------------------------------
# rails on a body: the reaction
# ---------------------------------------------------------------------------------------------
def test_rails_on_a_body_carry_the_reaction():
    ref = wheelset_model(y0=0.002)
    m = wheelset_model(y0=0.002, rail_body=True)
    for model in (ref, m):
        model.begin_run(0.0, model.q0, model.v0)
    Qr = ref.Q(0.0, ref.q0, ref.v0)
    Qm = m.Q(0.0, m.q0, m.v0)
    np.testing.assert_allclose(Qm[:6], Qr[:6], rtol=1e-9, atol=1e-6)
    # the track body: its gravity plus the reaction of the wheelset's contact forces (Newton III);
    # the contact forces are Q_ws minus the wheelset's weight
    contact = Qr[:3] - np.array([0.0, 0.0, -M_WS * GRAVITY])
    np.testing.assert_allclose(Qm[6:9] - np.array([0.0, 0.0, -500.0 * GRAVITY]), -contact, rtol=1e-9, atol=1e-6)


# ---------------------------------------------------------------------------------------------
# compiled kernels equal the numpy path
# ---------------------------------------------------------------------------------------------
@pytest.mark.parametrize("law", ["kalker_linear", "polach2000", "shen_hedrick_elkins", "polach2005", "fastsim"])
def test_compiled_forces_equal_numpy(law):
    from core.compiled import dynamics as D
    from core.compiled import protocol as P
    from core.compiled.layout import compile_model

    params = {"speed": V} if law == "polach2005" else None
    m = wheelset_model(y0=0.004, creep_law=law, creep_params=params)
    q, v = m.q0.copy(), m.v0.copy()
    v[1] = 0.05  # lateral velocity: creepage in every direction
    v[5] = 0.02
    m.begin_run(0.0, q, v)
    cm = compile_model(m)
    ws = D.make_workspace(cm)
    st = cm.initial_states()
    Q = np.zeros(m.n_v)
    D.body_states(cm.fields["lay"], q, v, ws)
    assert D.forces(cm.data, st, ws, 0.0, q, v, Q) == P.OK
    Qn = m.Q(0.0, q, v)
    # the compiled creep law reads Hertz and Kalker coefficients from tables (1e-4 relative)
    np.testing.assert_allclose(Q, Qn, rtol=0, atol=2e-4 * np.abs(Qn).max())


def test_compiled_run_equals_numpy_run():
    """jit-rk45 and scipy's RK45 take the same steps (one output time); the accept kernel must
    update the search state as the numpy kind does for the end states to agree."""
    m = wheelset_model(y0=0.003)
    a = simulate(m, (0.0, 0.02), "rk45", rtol=1e-6, atol=1e-8, n_output=1)
    b = simulate(m, (0.0, 0.02), "jit-rk45", rtol=1e-6, atol=1e-8, n_output=1)
    assert a.success and b.success
    assert a.counters["n_steps"] == b.counters["n_steps"] > 50
    # measured 1e-13 m and 6e-11 m/s after 74 steps (round-off in the step-size control grows
    # later: 1e-10 m and 9e-8 m/s after 0.04 s, with the same number of steps)
    np.testing.assert_allclose(b.q[-1], a.q[-1], rtol=0, atol=1e-11)
    np.testing.assert_allclose(b.v[-1], a.v[-1], rtol=0, atol=1e-9)


# ---------------------------------------------------------------------------------------------
# the vehicle: static preload
# ---------------------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def coach():
    D = VehicleDefinition.manchester()
    veh = build_vehicle(D, Track.straight(300.0), s0=30.0, speed=20.0)
    return veh, veh.preload()


def test_static_preload_gives_each_wheel_its_share_of_the_weight(coach):
    veh, table = coach
    share = veh.definition.total_mass * GRAVITY / 8.0
    np.testing.assert_allclose(table["Q [N]"], share, rtol=1e-3)  # the 0.1 %
    # measured: 1e-10; the force balance of the static equilibrium is solved to 1e-9 relative
    assert np.max(np.abs(table["relative difference [-]"])) < 1e-7


def test_static_preload_deflections_are_those_of_the_springs(coach):
    veh, table = coach
    D = veh.definition
    d = table.attrs["deflections"].set_index("element")
    dz1, dz2 = D.static_deflections()
    prim = d.loc[[e for e in d.index if e.startswith("primary")]]
    sec = d.loc[[e for e in d.index if e.startswith("secondary")]]
    # deflection of the spring below each body: its share of the weight over its stiffness
    np.testing.assert_allclose(-prim["Fz [N]"], (0.5 * D.car_body["mass"] + D.bogie["mass"]) * GRAVITY / 4, rtol=1e-6)
    np.testing.assert_allclose(-sec["Fz [N]"], D.car_body["mass"] * GRAVITY / 4, rtol=1e-6)
    np.testing.assert_allclose(np.abs(prim["dz [m]"]), dz1, rtol=1e-6)
    np.testing.assert_allclose(np.abs(sec["dz [m]"]), dz2, rtol=1e-6)
    parking = d.loc[[e for e in d.index if e.startswith("parking")]]
    assert np.max(np.abs(parking[["Fx [N]", "Fy [N]", "Fz [N]"]].to_numpy())) < 1e-3
    assert np.max(np.abs(parking["My [N m]"])) < 1e-3


def test_wheel_rail_difference_jacobian_by_wheelset_groups_equals_column_by_column(coach):
    """The compiled wheel-rail kind names one body group per wheelset (its forces on a wheelset
    depend on that wheelset's state alone) and the track speed control one per body: the
    difference Jacobian with the four wheelsets perturbed together equals the column-by-column
    one to the forward differences' round-off (ε|Q|/√ε relative), on the coach in contact."""
    from core.compiled.layout import compile_model
    from tests.core.test_compiled import grouped_and_column_jacobians

    veh, _ = coach
    m = veh.model
    q, v = veh.initial_state()
    v = v.copy()
    rng = np.random.default_rng(3)
    v += 0.02 * rng.standard_normal(v.shape)  # creepage in every direction on every wheel
    m.begin_run(0.0, q, v)
    cm = compile_model(m)  # cached per model: its colouring is switched off and back
    k = [r.what for r in cm.force_kinds].index("wheel-rail contact")
    grouped = cm.data.frc_ncol.copy()
    assert grouped[k] == 1  # the four wheelsets share nothing: one colour
    out = grouped_and_column_jacobians(cm, m, 0.0, q, v)
    assert np.array_equal(cm.data.frc_ncol, grouped)  # the colouring is back
    Q = m.Q(0.0, q, v)
    tol = 100 * np.finfo(float).eps / np.sqrt(np.finfo(float).eps) * float(np.max(np.abs(Q)))
    assert np.max(np.abs(out[1][0])) > 1e6  # the contact stiffness is in it
    assert np.max(np.abs(out[0][0] - out[1][0])) <= tol
    assert np.max(np.abs(out[0][1] - out[1][1])) <= tol


def test_vehicle_file_errors_name_the_file_and_key(tmp_path):
    from core.errors import DataFileError

    src = VehicleDefinition.manchester().path
    text = Path(src).read_text(encoding="utf-8")
    bad = tmp_path / "bad.toml"
    bad.write_text(text.replace("mass = 2615.0", "mass = -2615.0"), encoding="utf-8")
    with pytest.raises(DataFileError, match=r"bad.toml \[bogie\] mass: bogie frame mass = -2615.0 must be > 0"):
        VehicleDefinition.from_toml(bad)
    bad.write_text(text.replace("[primary]", "[primery]"), encoding="utf-8")
    with pytest.raises(DataFileError, match=r"unknown table\(s\) \['primery'\]"):
        VehicleDefinition.from_toml(bad)
    with pytest.raises(DataFileError, match="does not exist"):
        VehicleDefinition.from_toml(tmp_path / "none.toml")


def test_a_vehicle_file_with_yaw_dampers_builds_settles_and_runs(tmp_path):
    """The usual extras from the file: yaw dampers with series stiffness (Maxwell elements with
    a node mass), bump stops and the anti-roll bar; the preload still gives each wheel its
    share, and the dampers carry no static force."""
    src = Path(VehicleDefinition.manchester().path).read_text(encoding="utf-8")
    f = tmp_path / "coach_with_yaw_dampers.toml"
    f.write_text(src + "\n[[yaw_damper]]\ndamping = 300e3\nseries_stiffness = 6e6\nnode_mass = 5.0\n"
                 "x = 1.5\ny = 1.2\nz = 0.8\n", encoding="utf-8")
    D = VehicleDefinition.from_toml(f)
    assert len(D.yaw_dampers) == 1
    veh = build_vehicle(D, Track.straight(300.0), s0=30.0, speed=20.0)
    names = [n for k in veh.model.force_kinds for n in k.names]
    assert sum(n.startswith("yaw damper") for n in names) == 4  # two per bogie
    assert sum(n.startswith("lateral bump stop") for n in names) == 2
    table = veh.preload()
    np.testing.assert_allclose(table["Q [N]"], D.total_mass * GRAVITY / 8.0, rtol=1e-6)
    q0, v0 = veh.initial_state(wheelset_lateral=[0.002, 0, 0, 0])
    res = simulate(veh.model, (0.0, 0.2), "jit-radau", q0=q0, v0=v0, rtol=1e-4, atol=1e-6)
    assert res.success, res.message


# ---------------------------------------------------------------------------------------------
# the patch set of a wheel: a function of the geometry, not of the search's history
# ---------------------------------------------------------------------------------------------
def test_patch_shares_never_load_one_point_twice_and_share_only_within_a_zone():
    from railway.vehicles.wheel_rail import BLEND_GAP, patch_shares

    # patches (tread, flange) primary, (tread, flange) second; y [m], gap [m], lateral semi-axis [m]
    y = np.array([[-0.0322, -0.03812, -0.03812, np.nan]])  # the tread zone's second = the flange's primary
    g = np.array([[-70e-6, -8e-6, -8e-6, np.inf]])
    b = np.array([[2.3e-3, 1.0e-3, 1.0e-3, 0.0]])
    sh = patch_shares(y, g, b, np.array([[True, True, True, False]]))
    np.testing.assert_array_equal(sh, [[1.0, 1.0, 0.0, 1.0]])  # the duplicate carries nothing,
    # the tread and the flange (different zones, 5.9 mm apart, overlapping ellipses) both full
    # two overlapping patches of one zone: shares sum to one, the deeper carries more
    y = np.array([[0.0036, np.nan, 0.0030, np.nan]])
    g = np.array([[-40e-6, np.inf, -40e-6 + BLEND_GAP, np.inf]])
    b = np.array([[8e-3, 0.0, 8e-3, 0.0]])
    sh = patch_shares(y, g, b, np.array([[True, False, True, False]]))
    assert sh[0, 0] + sh[0, 2] == pytest.approx(1.0, abs=1e-15)
    assert sh[0, 0] == pytest.approx(0.5 * (1.0 + np.tanh(1.0)), rel=1e-12)
    # two separate patches of one zone (11 mm apart, 2 mm semi-axes) both carry their full load
    y = np.array([[0.0036, np.nan, -0.0075, np.nan]])
    b = np.array([[2e-3, 0.0, 2e-3, 0.0]])
    sh = patch_shares(y, g, b, np.array([[True, False, True, False]]))
    np.testing.assert_array_equal(sh, [[1.0, 1.0, 1.0, 1.0]])


CURVING_STATES = Path(__file__).with_name("curving_states_fastsim_10ms.npz")


def test_curving_forces_are_the_same_fresh_and_after_any_history():
    """States of the Manchester coach in the 200 m curve (scene railway-curving, FASTSIM at
    10 m/s; written by benchmarks/railway_vehicle.py --write-test-states): at each target state the
    wheel-rail forces from a fresh search equal those after a history that started at another
    stored state up to 1 s earlier and took one accepted step to the target.  Those states hold
    the cases that made the forces depend on history: two minima of the flange flank's gap
    0.3 mm apart, two tread minima 11 mm apart with a maximum between them as the scan's second
    lowest stationary point, the tread zone finding the flange zone's contact (tolerance: the
    search's Newton tolerance on the gap, 1e-11 m, times the Hertz stiffness: 1e-6 of the force)."""
    from railway.contact.creep import creep_law_for_runs
    from railway.vehicles.curving import curving_track

    data = np.load(CURVING_STATES)
    cl, cp = creep_law_for_runs("polach2000", 10.0)
    veh = build_vehicle(VehicleDefinition.manchester(), curving_track(), s0=35.0, speed=10.0, creep_law=cl,
                        creep_params=cp, speed_control=10.0)
    m = veh.model
    kind = kind_of(m)
    t, q, v = data["t"], data["q"], data["v"]
    worst = 0.0
    for i in range(5, len(t)):
        bs = m.body_states(q[i], v[i])
        kind.reset_state(bs, float(t[i]))
        fresh = kind.evaluate(bs, float(t[i])).Qb.copy()
        for j in (i - 1, i - 3, i - 5):
            kind.reset_state(m.body_states(q[j], v[j]), float(t[j]))
            kind.accept_step(bs, float(t[i]), check=False)
            after = kind.evaluate(bs, float(t[i])).Qb
            scale = np.abs(fresh).max()
            worst = max(worst, np.abs(after - fresh).max() / scale)
            np.testing.assert_allclose(after, fresh, rtol=0, atol=1e-6 * scale,
                                       err_msg=f"target row {i}, history from row {j}")
    assert worst < 1e-6
