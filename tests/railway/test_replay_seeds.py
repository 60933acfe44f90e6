"""The replay of a run's contact search state between its output rows (issue 21, "statistics from
dense data"): :func:`railway.vehicles.wheel_rail.contact_history` at coarse outputs reports the forces the
run applied.

A vehicle started mid-curve at 20 m/s (the quasi-static start of :mod:`railway.vehicles.curving_start`)
runs steadily: replayed at every accepted step, no wheel load moves by more than 0.6 N in 0.3 s.
Replayed at 50 ms outputs with the seeds carried between the rows through *chords* (positions
interpolated linearly), the rear bogie's leading outer wheel (wheelset 3 right) showed a
13.9 kN jump that the run never applied: the chord cut the arc by up to 0.53 mm and 1.5 mrad, the
scan there flagged a second stationary point of the gap at the flange root (y = -38.4 mm on the
wheel profile; at the run's states a penetrating minimum, -50 µm, that the run's scan never
flags), and once tracked it was kept.  A roll of that wheelset by 2e-5 rad is enough to flag it,
so the Hermite of the Euler parameters (which tilts a spinning axle by 7e-5 rad between rows 50 ms
apart) found it as well.  The replay now carries the state through the recorded accepted steps,
as the run did (``seed_path="steps"``), or, without them, through the cubic Hermite of positions
and of the axle directions (``seed_path="hermite"``).
"""

from types import SimpleNamespace

import numpy as np
import pytest

from core import frames
from core.integrators import simulate
from core.model import ModelBuilder
from railway.track import Curve, Straight, Track, Transition
from railway.vehicles.vehicle import GRAVITY, VehicleDefinition, build_vehicle
from railway.vehicles.wheel_rail import _hermite_state, contact_history

RTOL, SPEED = 1e-4, 20.0


def test_the_seed_interpolant_keeps_a_spinning_yawing_axle_on_its_path():
    """A wheelset spinning at V/r0 = 43.5 rad/s about its axle while yawing at V/R = 0.1 rad/s
    (20 m/s in a 200 m curve), A(t) = R_z(Ωt) A0 R_y(σt): between states 50 ms apart (2.2 rad of
    spin) the axle of the interpolated state is on the exact one to 1e-9 rad; the Hermite of the
    Euler parameters alone misses it by more than the 2e-5 rad of roll that changed the patch set
    of the curving run below."""
    b = ModelBuilder(3, "spinning wheelset")
    b.add_body("ws", mass=1813.0, inertia=(1120.0, 112.0, 1120.0), position=(0.0, 0.0, 0.0))
    m = b.build()
    Om, sig, R = 0.1, SPEED / 0.46, 200.0
    A0 = frames.euler_to_matrix(frames.rotation_vector_to_euler(np.array([1e-3, 0.0, 0.3])))

    def Rz(a):
        return frames.euler_to_matrix(frames.rotation_vector_to_euler(np.array([0.0, 0.0, a])))

    def Ry(a):
        return frames.euler_to_matrix(frames.rotation_vector_to_euler(np.array([0.0, a, 0.0])))

    def state(t):
        A = Rz(Om * t) @ A0 @ Ry(sig * t)
        w = np.array([0.0, 0.0, Om]) + sig * (Rz(Om * t) @ A0)[:, 1]  # global axes
        r = R * np.array([np.sin(Om * t), 1.0 - np.cos(Om * t), 0.0])
        rd = R * Om * np.array([np.cos(Om * t), np.sin(Om * t), 0.0])
        q = np.concatenate([r, frames.matrix_to_euler(A)])
        return q, np.concatenate([rd, A.T @ w]), A

    h = 0.05
    qa, va, _ = state(0.0)
    qb, vb, _ = state(h)
    # the Euler parameters as a run carries them: sign-continuous along the motion
    steps = [state(t)[0][3:] for t in np.linspace(0.0, h, 51)]
    for k in range(1, len(steps)):
        if steps[k] @ steps[k - 1] < 0.0:
            steps[k] = -steps[k]
    qb[3:] = steps[-1] if steps[-1] @ qb[3:] > 0.0 else -qb[3:]
    err_axle, err_quat, err_r = 0.0, 0.0, 0.0
    for s_ in np.linspace(0.0, 1.0, 11)[1:-1]:
        A_true = state(s_ * h)[2]
        q1, _ = _hermite_state(m, qa, va, qb, vb, h, s_, axle_bodies=[0])
        q0, _ = _hermite_state(m, qa, va, qb, vb, h, s_)
        err_axle = max(err_axle, np.abs(frames.euler_to_matrix(q1[3:])[:, 1] - A_true[:, 1]).max())
        err_quat = max(err_quat, np.abs(frames.euler_to_matrix(q0[3:])[:, 1] - A_true[:, 1]).max())
        err_r = max(err_r, np.abs(q1[:3] - state(s_ * h)[0][:3]).max())
    assert err_axle < 1e-9
    assert err_quat > 2e-5
    assert err_r < 1e-9  # the chord's sagitta: 0.6 mm


@pytest.fixture(scope="module")
def curving_run():
    """The Manchester coach started mid-curve (R = 200 m, no cant, s0 = 200 m) at 20 m/s, 0.3 s,
    outputs every 50 ms, accepted steps recorded (/tmp/cs/replay.py of issue 21)."""
    D = VehicleDefinition.manchester()
    track = Track([Straight(60.0), Transition(40.0), Curve(200.0, 200.0, cant=0.0), Transition(40.0),
                   Straight(60.0)])
    veh = build_vehicle(D, track, s0=200.0, speed=SPEED, creep_law="polach2000", speed_control=SPEED)
    q0, v0 = veh.initial_state()
    res = simulate(veh.model, (0.0, 0.3), "jit-dop853", q0=q0, v0=v0, rtol=RTOL, atol=RTOL * 1e-2, n_output=7,
                   record_steps=True)
    assert res.status == "finished"
    return veh, res, D.total_mass * GRAVITY / 8.0


def _spread(H):
    g = H.groupby("wheel", sort=False)["Q [N]"]
    return g.max() - g.min()


def test_a_replay_at_coarse_outputs_equals_the_replay_at_every_step(curving_run):
    """The rows at 50 ms equal the rows of the replay at every accepted step at the same times,
    and no wheel load moves more over the run than it does at the steps (the run is steady: 0.6 N
    at the steps; the chord replay reported 13.9 kN), within rtol Q0 (8.5 N)."""
    veh, res, Q0 = curving_run
    tol = RTOL * Q0
    Hs = contact_history(veh.model, res, at="steps")
    Ho = contact_history(veh.model, res)
    assert Ho.attrs["seed path"] == "steps"
    assert len(Ho) == 8 * res.t.size
    s = Hs.set_index(["t [s]", "wheel"])["Q [N]"]
    o = Ho.set_index(["t [s]", "wheel"])["Q [N]"]
    common = o.index.intersection(s.index)
    assert len(common) >= 2 * 8  # at least the first and the last row
    assert np.abs(o.loc[common] - s.loc[common]).max() <= tol
    assert _spread(Hs).max() < tol
    assert (_spread(Ho) <= _spread(Hs) + tol).all(), _spread(Ho).to_dict()


@pytest.mark.parametrize("stride", [1, 2, 6])  # rows 50, 100 and 300 ms apart
def test_without_recorded_steps_the_hermite_seed_path_reports_the_same_loads(curving_run, stride):
    """Without ``result.steps`` the seeds move through the Hermite of positions and axles between
    the rows: the loads equal those of the step replay at the same stored states within rtol Q0,
    up to rows 300 ms apart (6 m of track; the wheelsets spin 13 rad from row to row)."""
    veh, res, Q0 = curving_run
    sub = SimpleNamespace(t=res.t[::stride], q=res.q[::stride], v=res.v[::stride])  # no .steps
    H = contact_history(veh.model, sub)
    assert H.attrs["seed path"] == "hermite"
    ref = contact_history(veh.model, res).set_index(["t [s]", "wheel"])["Q [N]"]
    got = H.set_index(["t [s]", "wheel"])["Q [N]"]
    assert np.abs(got - ref.loc[got.index]).max() <= RTOL * Q0


@pytest.mark.slow
def test_the_curving_scene_replayed_at_20_hz_equals_its_replay_at_every_step():
    """railway-curving, Polach 2000 at 20 m/s, the first 2.6 s (the leading wheelset into the
    entry transition): the 20 Hz rows, carried through the accepted steps or (without them) through
    the Hermite, equal the replay at every step at the same times within rtol Q0.  The chord replay
    reported the leading outer wheel in flange contact at 2.40-2.55 s (s = 93.8-96.8 m; Q 8.6-12.1 kN
    too high) where the run had no flange contact (~25 s)."""
    from railway.vehicles.curving import RTOL as SCENE_RTOL
    from railway.vehicles.curving import run_curving

    res, veh = run_curving("polach2000", 20.0, T=2.6, record_steps=True)
    assert res.success, res.message
    tol = SCENE_RTOL * veh.definition.total_mass * GRAVITY / 8.0
    s = contact_history(veh.model, res, at="steps").set_index(["t [s]", "wheel"])["Q [N]"]
    for H in (contact_history(veh.model, res),
              contact_history(veh.model, SimpleNamespace(t=res.t, q=res.q, v=res.v))):
        o = H.set_index(["t [s]", "wheel"])["Q [N]"]
        common = o.index.intersection(s.index)
        assert len(common) == len(o)  # the scene's method lands on every output
        assert np.abs(o - s.loc[o.index]).max() <= tol, H.attrs["seed path"]
