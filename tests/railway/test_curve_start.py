"""Vehicles start in equilibrium anywhere on the track (railway.vehicles.curving_start, issue 21).

The start of a run in a curve or a transition is the quasi-static curving state of the model
itself (:func:`railway.vehicles.curving_start.quasi_static_curving`): checked here by running the model
from it (it must stay there), by the lateral force balance of the whole vehicle against the
closed form m (V^2 kappa cos(phi) + g sin(phi)), and on straight track against the static
preload.  The runs use the scenes' integrator and tolerance (jit-dop853, rtol 1e-4).
"""

import numpy as np
import pytest

from core.errors import InputError
from core.integrators import simulate
from railway.track import Curve, Straight, Track, Transition
from railway.vehicles.vehicle import GRAVITY, VehicleDefinition, build_vehicle
from railway.vehicles.wheel_rail import contact_history

RADIUS, V, RTOL, T_RUN = 200.0, 20.0, 1e-4, 0.3


@pytest.fixture(scope="module")
def coach():
    return VehicleDefinition.manchester()


def curve_track(cant):
    """Straight, 40 m clothoid, 200 m curve (R = 200 m, cant h), 40 m clothoid, straight."""
    return Track([Straight(60.0), Transition(40.0), Curve(200.0, RADIUS, cant=cant), Transition(40.0),
                  Straight(60.0)])


def vehicle(coach, track, s0, speed=V, **kw):
    kw.setdefault("creep_law", "polach2000")
    return build_vehicle(coach, track, s0=s0, speed=speed, speed_control=speed if speed > 0 else None, **kw)


@pytest.fixture(scope="module")
def starts(coach):
    """The quasi-static starts (car body in the middle of the full curve, and in a transition)."""
    out = {}
    for key, cant, s0 in (("uncanted", 0.0, 200.0), ("canted", 0.150, 200.0), ("transition", 0.150, 80.0)):
        veh = vehicle(coach, curve_track(cant), s0)
        table = veh.equilibrium()
        out[key] = (veh, table)
    return out


def run(veh, T=T_RUN):
    q0, v0 = veh.initial_state()
    return simulate(veh.model, (0.0, T), "jit-dop853", q0=q0, v0=v0, rtol=RTOL, atol=RTOL * 1e-2,
                    n_output=7, record_steps=True)


def relative_poses(veh, res):
    """Lateral displacement and yaw (relative to the track at the body's arc length) of every
    body at every output time: the body's nominal arc length moves at the start's speed."""
    st = veh.start
    C = res.coordinates()
    out = {}
    for _, b in st.bodies.iterrows():
        nm = b["body"]
        r = C[[f"{nm}.x [m]", f"{nm}.y [m]", f"{nm}.z [m]"]].to_numpy()
        s = veh.track.project(r, b["s [m]"] + st.speed * res.t)
        fr = veh.track.evaluate(s)
        y = np.einsum("ni,ni->n", r - fr.position, fr.R[:, :, 1])
        A = np.array([veh.model.body_frame(q, nm) for q in res.q])
        y_b = A[:, :, 1]  # the body's lateral axis (a wheelset's axle: independent of its spin)
        yaw = np.arctan2(-np.einsum("ni,ni->n", y_b, fr.R[:, :, 0]), np.einsum("ni,ni->n", y_b, fr.R[:, :, 1]))
        out[nm] = (y, yaw)
    return out


# ---------------------------------------------------------------------------------------------
# (1) straight track: the quasi-static state is the static preload; the published start unchanged
# ---------------------------------------------------------------------------------------------
def test_on_straight_track_the_quasi_static_state_is_the_static_preload(coach):
    veh = vehicle(coach, Track.straight(300.0), s0=30.0)
    assert veh.on_straight_track
    pre = veh.preload()
    eq = veh.equilibrium()
    # the speed adds only the creep forces of free rolling (no net force): loads within 2e-5 Q
    np.testing.assert_allclose(eq["Q [N]"], pre["Q [N]"], rtol=2e-5)
    m = veh.model
    for name in [veh.car_body] + veh.bogies + veh.wheelsets:
        a, b = veh.q_static[m.q_slice(name)], veh.start.q[m.q_slice(name)]
        # longitudinal: the rolling resistance (a few N) on the longitudinal springs; else 1 um
        assert np.all(np.abs(b[:3] - a[:3]) <= [3e-5, 1e-6, 1e-6]), (name, b[:3] - a[:3])
        if name not in veh.wheelsets:  # (a wheelset's spin angle is a free gauge)
            np.testing.assert_allclose(b[3:], a[3:], rtol=0, atol=1e-6, err_msg=name)
    assert abs(veh.start.speed - V) < 1e-3
    # the start of a run on straight track is still the static preload (published numbers)
    q0, v0 = veh.initial_state()
    np.testing.assert_array_equal(q0, veh.q_static)


def test_the_curving_scene_still_starts_on_straight_track_from_the_same_model(coach):
    """railway-curving builds at s0 = 35 m, on the straight before the curve: the model and its
    start are those of a straight track, bit for bit (the straight reference geometry of the
    suspension applies only under a curved vehicle)."""
    from railway.vehicles.curving import curving_track

    a = vehicle(coach, curving_track(), 35.0)
    b = vehicle(coach, Track.straight(curving_track().length), 35.0)
    assert a.on_straight_track
    np.testing.assert_array_equal(a.model.q0, b.model.q0)
    np.testing.assert_array_equal(a.model.v0, b.model.v0)


def test_the_suspension_of_a_vehicle_built_in_a_curve_is_unloaded_in_its_straight_design_geometry(coach):
    """Built in a curve, the springs keep the reference geometry of the straight vehicle (the
    wheelsets are not 'set' radial, the bogies not set yawed against the car body)."""
    a = vehicle(coach, curve_track(0.150), 200.0)
    b = vehicle(coach, Track.straight(400.0), 200.0)
    for ka, kb in zip(a.model.force_kinds, b.model.force_kinds):
        if type(ka).__name__ == "BushingKind":
            np.testing.assert_allclose(ka.x0, kb.x0, rtol=0, atol=1e-9)
            np.testing.assert_allclose(ka.si, kb.si, rtol=0, atol=1e-9)
            np.testing.assert_allclose(ka.sj, kb.sj, rtol=0, atol=1e-9)
            np.testing.assert_allclose(ka.Mi, kb.Mi, rtol=0, atol=1e-12)
            np.testing.assert_allclose(ka.Mj, kb.Mj, rtol=0, atol=1e-12)


# ---------------------------------------------------------------------------------------------
# (2) in the full curve: a run from the start stays there; the lateral balance in closed form
# ---------------------------------------------------------------------------------------------
@pytest.mark.parametrize("key", ["uncanted", "canted"])
def test_the_start_balances_the_lateral_forces_in_closed_form(starts, coach, key):
    veh, table = starts[key]
    fr = veh.track.evaluate(np.array([veh.s0]))
    kappa, phi = float(fr.curvature[0]), float(fr.cant_angle[0])
    assert kappa == pytest.approx(1.0 / RADIUS) and phi == pytest.approx(0.0 if key == "uncanted" else
                                                                         -np.arcsin(0.150 / 1.5))
    # rails on the vehicle along the lateral axis: -sum Y over the wheelsets (table: per wheel)
    rails = -table["sum Y [N]"].to_numpy()[::2].sum()
    need = coach.total_mass * (veh.start.speed**2 * kappa * np.cos(phi) + GRAVITY * np.sin(phi))
    # the axles' lateral axes lie +-3 deg from the car body's (10.8 m of a 200 m curve), and the
    # bodies' heights change their radius: 0.3 % covers both (measured 0.06 %)
    assert rails == pytest.approx(need, rel=3e-3)
    assert (table["Q [N]"] > 0).all()
    assert veh.start.residual <= 1e-9


@pytest.mark.parametrize("key", ["uncanted", "canted"])
def test_a_run_started_in_the_curve_stays_in_the_quasi_static_state(starts, key):
    veh, table = starts[key]
    res = run(veh)
    assert res.status == "finished", res.message
    # the wheel forces as the run applied them (replayed at every accepted step)
    H = contact_history(veh.model, res, at="steps")
    assert (H["Q [N]"] > 0).all(), "no wheel lifts"
    g = H.groupby("wheel", sort=False)
    Q0 = table.set_index("wheel")["Q [N]"]
    Y0 = table.set_index("wheel")["Y [N]"]
    scale = coach_weight_share(veh)
    # drift bounds from the integrator's tolerance: every force within rtol of the wheel load's
    # scale m g / 8, every displacement and yaw within rtol of 10 mm / 10 mrad (measured over
    # 0.3 s: forces 7e-6 of m g / 8, i.e. 0.4 N; displacements 6e-11 m, yaw 3e-11 rad)
    dQ = (g["Q [N]"].max() - g["Q [N]"].min()).max()
    dY = (g["Y [N]"].max() - g["Y [N]"].min()).max()
    assert dQ <= RTOL * scale and dY <= RTOL * scale, (dQ, dY)
    np.testing.assert_allclose(g["Q [N]"].first().reindex(Q0.index), Q0, rtol=1e-6)
    np.testing.assert_allclose(g["Y [N]"].first().reindex(Y0.index), Y0, rtol=0, atol=1e-6 * scale)
    drift = {}
    for name, (y, yaw) in relative_poses(veh, res).items():
        drift[name] = (np.ptp(y), np.ptp(yaw))
        assert np.ptp(y) <= RTOL * 0.01, (name, np.ptp(y))
        assert np.ptp(yaw) <= RTOL * 0.01, (name, np.ptp(yaw))
    print(f"\n{key}: drift over {T_RUN} s: Q {dQ:.3g} N, Y {dY:.3g} N, lateral/yaw "
          + ", ".join(f"{k} {a * 1e6:.3g} um/{b * 1e6:.3g} urad" for k, (a, b) in drift.items()))


def coach_weight_share(veh):
    return veh.definition.total_mass * GRAVITY / 8.0


def test_in_the_curve_the_leading_wheelsets_lean_on_the_outer_flange(starts):
    """The classical curving state of a two-axle bogie (Wickens 2003, ch. 7): the leading
    wheelset of each bogie shifted outwards to flange contact with a negative yaw (angle of
    attack) against the track, the trailing one near the centre."""
    for key in ("uncanted", "canted"):
        veh, table = starts[key]
        t = table.set_index("wheel")
        for lead, trail in (("wheelset 1", "wheelset 2"), ("wheelset 3", "wheelset 4")):
            assert t.loc[f"{lead} right", "lateral displacement [m]"] < -5e-3, key  # outwards (right)
            assert t.loc[f"{lead} right", "angle of attack [rad]"] < -5e-3, key
            assert abs(t.loc[f"{trail} right", "lateral displacement [m]"]) < 5e-3, key
            assert t.loc[f"{lead} right", "Y [N]"] > t.loc[f"{trail} right", "Y [N]"], key


def test_a_coasting_vehicle_decelerates_by_the_curving_resistance_the_speed_control_balances(starts, coach):
    """Without speed control the longitudinal unknown is the deceleration a_t at the speed V; with
    it, the speed at which the control force balances the curving resistance.  Both measure the
    same resistance: m_total a_t = -F_control (within 2 %: the two states differ by 2 mm/s)."""
    veh, _ = starts["canted"]
    kind = next(k for k in veh.model.force_kinds if type(k).__name__ == "TrackSpeedControlKind")
    bs = veh.model.body_states(veh.start.q, veh.start.v)
    F_control = float(kind.outputs(bs, 0.0)["F [N]"][0])
    assert veh.start.tangential_acceleration == 0.0
    assert 0.0 < F_control < 0.02 * coach.total_mass * GRAVITY  # a resistance, below 2 % of the weight
    free = build_vehicle(coach, veh.track, s0=veh.s0, speed=V, creep_law="polach2000")
    free.equilibrium()
    assert free.start.speed == V
    assert coach.total_mass * free.start.tangential_acceleration == pytest.approx(-F_control, rel=2e-2)


def test_initial_state_offsets_are_added_to_the_curving_start(starts):
    veh, _ = starts["canted"]
    q0, v0 = veh.initial_state()
    q1, v1 = veh.initial_state(lateral=0.001, wheelset_lateral=[0.002, 0.0, 0.0, 0.0])
    m = veh.model
    np.testing.assert_array_equal(v1, v0)
    for name in [veh.car_body] + veh.bogies + veh.wheelsets:
        d = q1[m.q_slice(name)][:3] - q0[m.q_slice(name)][:3]
        assert np.linalg.norm(d) == pytest.approx(0.003 if name == "wheelset 1" else 0.001, rel=1e-9)


# ---------------------------------------------------------------------------------------------
# (3) in a transition
# ---------------------------------------------------------------------------------------------
def test_a_start_in_a_transition_is_finite_and_the_run_finishes(starts):
    veh, table = starts["transition"]
    assert not veh.on_straight_track
    st = veh.start
    assert np.all(np.isfinite(st.q)) and np.all(np.isfinite(st.v))
    assert st.residual <= 1e-9
    assert (table["Q [N]"] > 0).all()
    # the track frame's rates are in the start: the car body turns at V kappa(s0) about the up
    # axis and rolls at V phi'(s0) (the cant rate)
    fr = veh.track.evaluate(np.array([veh.s0]))
    w = veh.model.body_frame(st.q, veh.car_body) @ st.v[veh.model.v_slice(veh.car_body)][3:]
    np.testing.assert_allclose(w, st.speed * fr.omega[0], rtol=0, atol=2e-3 * st.speed * abs(fr.curvature[0]))
    res = run(veh, T=0.2)
    assert res.status == "finished", res.message


# ---------------------------------------------------------------------------------------------
# (4) the cases that used to end in a RuntimeError, and starts that are impossible
# ---------------------------------------------------------------------------------------------
def test_preload_in_a_canted_curve_or_a_transition_is_the_quasi_static_state(starts):
    for key in ("canted", "transition"):
        veh, table = starts[key]
        pre = veh.preload()
        np.testing.assert_array_equal(pre["Q [N]"], table["Q [N]"])
        assert np.all(np.isfinite(pre["Q [N]"])) and len(pre.attrs["deflections"]) > 0
        q0, _ = veh.initial_state()
        np.testing.assert_array_equal(q0, veh.start.q)


def test_a_speed_beyond_overturning_is_refused_naming_s0_and_the_speed(coach):
    veh = vehicle(coach, curve_track(0.0), 200.0, speed=45.0)
    with pytest.raises(InputError, match=r"s0 = 200 m, speed = 45 m/s: .*overturn"):
        veh.initial_state()


def test_a_curving_start_without_creep_forces_is_refused(coach):
    veh = vehicle(coach, curve_track(0.150), 200.0, creep_law=None)
    with pytest.raises(InputError, match=r"s0 = 200 m, speed = 20 m/s: the model has no creep law"):
        veh.equilibrium()


def test_a_start_off_the_track_is_refused_naming_s0(coach):
    with pytest.raises(InputError, match=r"s0 = 395 m"):
        vehicle(coach, curve_track(0.150), 395.0)


@pytest.mark.slow
def test_a_vehicle_at_rest_in_a_canted_curve_is_refused_not_a_traceback(coach):
    """At rest (speed 0) the start is the static preload, which has no creep forces to hold the
    vehicle on the cant: the old RuntimeError from inside the static solver is now an InputError
    naming s0 and the speed (the static Newton iteration fails first: ~20 s)."""
    veh = vehicle(coach, curve_track(0.150), 200.0, speed=0.0)
    with pytest.raises(InputError, match=r"s0 = 200 m, speed = 0 m/s: a vehicle at rest in a curve"):
        veh.preload()
