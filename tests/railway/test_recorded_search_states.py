"""The contact search state recorded at every accepted step of a compiled run
(``simulate(..., record_steps=True)`` -> ``result.step_search_states``) and its use by
``contact_history``: the replay evaluates each step with the state the run had there instead of
carrying the search along the run again, and gives the same rows."""

import numpy as np
import pytest

from core.integrators import simulate
from core.results import search_states_at_steps
from railway.vehicles.wheel_rail import WheelRailKind, contact_history
from railway.vehicles.wheelset_models import free_wheelset


@pytest.fixture(scope="module")
def run():
    model = free_wheelset(20.0, 0.004, creep_law="polach2000", track_length=60.0)
    res = simulate(model, (0.0, 0.4), "jit-dop853", rtol=1e-6, atol=1e-8, n_output=41, record_steps=True)
    assert res.status != "failed", res.message
    return model, res


def test_a_compiled_run_records_the_search_state_of_every_accepted_step(run):
    model, res = run
    kind = next(k for k in model.force_kinds if isinstance(k, WheelRailKind))
    states = search_states_at_steps(res, kind.names)
    assert states is not None and states.shape[0] == res.steps.t.size
    # the state moves with the wheelset: its tracked arc length grows with the distance run
    row = WheelRailKind.state_from_compiled(kind.sets[0], states[-1, 0])
    assert row.s_ws[0] == pytest.approx(float(res.steps.q[-1, 0]), abs=0.05)
    # a numpy integrator keeps no compiled states
    res_np = simulate(model, (0.0, 0.01), "dop853", rtol=1e-6, atol=1e-8, n_output=3, record_steps=True)
    assert search_states_at_steps(res_np, kind.names) is None


def test_a_state_row_converts_back_to_the_numpy_search_state(run):
    from railway.vehicles.wheel_rail_compiled import _state_row

    model, res = run
    kind = next(k for k in model.force_kinds if isinstance(k, WheelRailKind))
    st = kind.sets[0]
    kind.reset_state(model.body_states(res.q[-1], res.v[-1]), float(res.t[-1]))
    back = WheelRailKind.state_from_compiled(st, _state_row(st))
    np.testing.assert_array_equal(back.seeds, st.state.seeds)
    np.testing.assert_array_equal(back.s_ws, st.state.s_ws)
    np.testing.assert_array_equal(back.valid, st.state.valid)
    assert back.accepted == st.state.accepted


def test_the_replay_with_the_recorded_states_agrees_with_the_carried_search(run):
    """Row for row the same wheel forces, except where the compiled search, which the run used,
    and the numpy search carried again pick a different patch at a contact jump (the numpy path's
    robust refinement is not compiled, railway.vehicles.wheel_rail_compiled): here 2 rows of 1148,
    at the flange contact of the left wheel.  The recorded states give the run's own patches."""
    model, res = run
    recorded = contact_history(model, res, at="steps")
    carried = contact_history(model, type(res)(**{**res.__dict__, "step_search_states": None}), at="steps")
    assert len(recorded) == len(carried)
    same = np.ones(len(recorded), bool)
    for column in ("Q [N]", "Y [N]", "Y/Q [-]", "flange force [N]", "contact angle [rad]"):
        a, b = recorded[column].to_numpy(), carried[column].to_numpy()
        same &= np.isclose(a, b, rtol=1e-9, atol=1e-6) | (np.isnan(a) & np.isnan(b))
    assert same.mean() > 0.99, f"{(~same).sum()} of {len(same)} rows differ"


@pytest.fixture(scope="module")
def coach_run():
    from railway.vehicles.curving import run_curving

    res, veh = run_curving("polach2000", 20.0, T=0.25, record_steps=True)
    assert res.status == "finished", res.message
    return veh.model, res


def test_the_rows_evaluated_side_by_side_equal_the_rows_evaluated_one_at_a_time(coach_run):
    """contact_history evaluates a recorded run's rows ROW_BATCH at a time, the four wheelsets of
    every row side by side (railway.vehicles.wheel_rail._Set.batched).  The independent
    computation: the element's own contact_outputs at each step, with the state recorded there.
    Problems do not interact, so the two agree to round-off (the vectorised track projection
    iterates every wheelset until the last one converged: a few ulps), wheel and wheelset alike."""
    import railway.vehicles.wheel_rail as wr

    model, res = coach_run
    kind = next(k for k in model.force_kinds if isinstance(k, WheelRailKind))
    st = kind.sets[0]
    states = search_states_at_steps(res, kind.names)
    H = contact_history(model, res, at="steps")
    nw = 2 * st.n_ws
    assert st.n_ws == 4 and len(H) == nw * res.steps.t.size and res.steps.t.size > wr.ROW_BATCH
    saved = st.state
    try:
        for k in (0, 1, wr.ROW_BATCH - 1, wr.ROW_BATCH, res.steps.t.size - 1):  # across a batch boundary
            st.state = WheelRailKind.state_from_compiled(st, states[k, 0])
            out = kind.contact_outputs(model.body_states(res.steps.q[k], res.steps.v[k]), float(res.steps.t[k]))
            rows = H.iloc[k * nw:(k + 1) * nw]
            assert np.all(rows["t [s]"] == res.steps.t[k])
            for column in ("Q [N]", "Y [N]", "flange force [N]", "contact angle [rad]", "T gamma [N]", "y_wheel [m]"):
                np.testing.assert_allclose(rows[column].to_numpy(), out["wheels"][column], rtol=1e-12, atol=1e-12,
                                           err_msg=f"{column} at step {k}")
            np.testing.assert_allclose(rows["angle of attack [rad]"].to_numpy(),
                                       np.repeat(out["wheelsets"]["angle of attack [rad]"], 2), rtol=1e-12, atol=1e-15)
    finally:
        st.state = saved
