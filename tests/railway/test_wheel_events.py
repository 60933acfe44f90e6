"""Wheel lift, peaks and exceedances from every accepted step (railway.assessment.
wheel_event_statistics, railway.vehicles.wheel_rail.contact_history at="steps"), and the failure
messages of the compiled path in the element's own words.

Oracles: a wheelset dropped 1 mm onto its rails bounces (Lankarani-Nikravesh damping,
restitution 0.9): its flights are lifts of both wheels (Q = 0) a few ms long, between the
outputs of a 20 Hz grid.  The same run summarised on 20 Hz and 100 Hz outputs must report the
same lifts and peaks; a method that lands on the outputs makes a different run per grid, whose
difference is bounded by what rtol allows (tolerances derived below).
"""

import dataclasses
import re
import warnings

import numpy as np
import pytest

from core.errors import InputError
from core.integrators import simulate
from core.signals import GridResolutionWarning
from railway.assessment import wheel_event_statistics
from railway.track import Track
from railway.vehicles.vehicle import GRAVITY, VehicleDefinition, build_vehicle
from railway.vehicles.wheel_rail import contact_history

T_END = 0.1


def wheelset_model(sink=6e-5, speed=20.0, creep_law="kalker_linear"):
    """One S1002 wheelset at s = 10 m on straight UIC60 track, pressed ``sink`` (m) into the rails
    (negative: above them), rolling at ``speed`` (tests/railway/test_wheel_rail.py)."""
    from core import frames
    from core.model import ModelBuilder
    from railway.contact.geometry import rigid_contact
    from railway.vehicles.wheel_rail import WheelRailContact

    z0, roll0, _, _ = rigid_contact([0.0])
    b = ModelBuilder(3, "wheelset", gravity=(0.0, 0.0, -GRAVITY))
    p = frames.rotation_vector_to_euler(np.array([roll0[0], 0.0, 0.0]))
    b.add_body("ws", mass=1813.0, inertia=(1120.0, 112.0, 1120.0), position=(10.0, 0.0, z0[0] - sink),
               orientation=p, velocity=(speed, 0.0, 0.0), angular_velocity=(0.0, speed / 0.46, 0.0))
    b.add_force(WheelRailContact("wr", ["ws"], Track.straight(400.0), creep_law=creep_law))
    return b.build()


def _summary(method, fs, rtol):
    m = wheelset_model(sink=-1e-3)  # 1 mm above the rails
    res = simulate(m, (0.0, T_END), method, rtol=rtol, atol=rtol * 1e-2, n_output=int(T_END * fs) + 1,
                   record_steps=True)
    assert res.status == "finished"
    H = contact_history(m, res, at="steps")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        S = wheel_event_statistics(H, output_times=res.t)
    return m, res, H, S.set_index("wheel"), caught


def _lifts(H, wheel):
    from core.signals import level_intervals

    g = H[H["wheel"] == wheel]
    loc = H.attrs["lift crossings"][wheel]
    return level_intervals(g["t [s]"].to_numpy(), g["Q [N]"].to_numpy(), 0.0, "below",
                           lambda ta, tb: loc.get(tb, tb))


def test_a_run_summarised_at_20_and_100_hz_reports_the_same_lifts_and_peaks():
    """dop853 (scipy) takes the same steps whatever the outputs: the same run, the same summary
    (to round-off); the 20 Hz grid does not show two of the five lifts, the table says so."""
    rtol = 1e-7
    _, r20, H20, S20, w20 = _summary("dop853", 20, rtol)
    _, r100, H100, S100, _ = _summary("dop853", 100, rtol)
    np.testing.assert_array_equal(r20.steps.t, r100.steps.t)
    cols = ["lifts", "lifted [s]", "shortest lift [s]", "Q max [N]", "t at Q max [s]", "|Y| max [N]",
            "Y/Q max [-]"]
    for c in cols:
        np.testing.assert_allclose(S20[c].to_numpy(float), S100[c].to_numpy(float), rtol=rtol, atol=0)
    # free fall of 1 mm: sqrt(2 h / g) = 14.28 ms (the run starts in the air: an open lift)
    iv = _lifts(H20, "ws left")
    assert iv["open start"].iloc[0] and iv["end [s]"].iloc[0] == pytest.approx(np.sqrt(2e-3 / GRAVITY), rel=2e-3)
    assert len(iv) == S20.loc["ws left", "lifts"] == 5
    # the grid: at 20 Hz two flights fall between outputs (named in a column and a warning)
    assert S20.loc["ws left", "lifts between outputs"] == 2 and S100.loc["ws left", "lifts between outputs"] == 0
    assert any(issubclass(w.category, GridResolutionWarning) and "'ws left'" in str(w.message) for w in w20)
    Hg = contact_history(wheelset_model(sink=-1e-3), r20)  # the outputs alone
    g = Hg[Hg["wheel"] == "ws left"]
    assert int(np.sum(np.diff((g["Q [N]"].to_numpy() <= 0).astype(int)) == 1)) < 4  # lift-offs the grid sees


def test_a_method_landing_on_the_outputs_agrees_to_what_rtol_allows():
    """jit-dop853 shortens a step to land on every output, so 20 and 100 Hz are two runs; they
    differ by the integration error.  Derived bounds: a lift boundary moves by the height error
    over the vertical speed there, δt ≤ 10 (rtol |z| + atol) / |ż|, with |ż| ≥ 0.9⁴ sqrt(2 g h)
    for the fifth impact; a Hertz peak Q ∝ δ^1.5 moves by 1.5 δz / δ_max relative, ×3."""
    rtol = 1e-6
    m, r20, H20, S20, _ = _summary("jit-dop853", 20, rtol)
    _, r100, H100, S100, _ = _summary("jit-dop853", 100, rtol)
    z_max = float(np.max(np.abs(r20.steps.q[:, 2])))
    dz = rtol * z_max + rtol * 1e-2
    dt_tol = 10.0 * dz / (0.9**4 * np.sqrt(2.0 * GRAVITY * 1e-3))
    for wheel in ("ws left", "ws right"):
        a, b = _lifts(H20, wheel), _lifts(H100, wheel)
        assert len(a) == len(b) == 5
        np.testing.assert_allclose(a[["start [s]", "end [s]"]].to_numpy(), b[["start [s]", "end [s]"]].to_numpy(),
                                   atol=dt_tol, rtol=0)
        assert S20.loc[wheel, "lifted [s]"] == pytest.approx(S100.loc[wheel, "lifted [s]"], abs=2 * 5 * dt_tol)
    # peak Q of the first impact: Hertz penetration below the rigid contact height z0
    z_rigid = m.q0[2] - 1e-3
    delta_max = float(np.max(z_rigid - r100.steps.q[:, 2]))
    assert delta_max > 0
    q_tol = 3.0 * 1.5 * dz / delta_max
    assert S20.loc["ws left", "Q max [N]"] == pytest.approx(S100.loc["ws left", "Q max [N]"], rel=q_tol)


def test_the_event_table_refuses_a_table_on_the_output_grid():
    m = wheelset_model(sink=-1e-3)
    res = simulate(m, (0.0, 0.02), "jit-dop853", rtol=1e-6, atol=1e-8, n_output=3)
    with pytest.raises(InputError, match="record_steps=True"):
        contact_history(m, res, at="steps")
    with pytest.raises(InputError, match="statistics of the output grid change with the output step"):
        wheel_event_statistics(contact_history(m, res))


# ---------------------------------------------------------------------------------------------
# failure messages: the compiled path in the element's own words
# ---------------------------------------------------------------------------------------------
def test_compiled_and_numpy_paths_refuse_a_standing_wheelset_with_the_same_words():
    """At speed 0 the creepages are undefined; the numpy element names itself and the rolling
    speed, and the compiled kernel, which can only return a status code, passes on the numpy
    element's message evaluated at the failing state."""
    m = wheelset_model(speed=0.0)
    said = {}
    for method in ("rk45", "jit-dop853", "jit-radau"):
        with pytest.raises(InputError) as exc:
            simulate(m, (0.0, 0.01), method, rtol=1e-4, atol=1e-6)
        said[method] = str(exc.value)
    cause = "wheel-rail contact 'wr': ContactForces: rolling speed 0.0 m/s at a loaded contact is below 1e-3 m/s"
    for method, text in said.items():
        assert cause in text, (method, text)
        assert "an element could not be evaluated" not in text


def test_a_wheelset_braked_to_a_stop_ends_with_the_elements_words_on_the_compiled_path():
    """A wheelset at 0.5 m/s pushed back by 30 kN stops after ~0.03 s; the compiled kernel refuses
    the stage whose rolling speed fell below 1e-3 m/s, and the run ends failed with the numpy
    element's message at that stage state (the numpy path itself raises it)."""
    from core import frames
    from core.model import ModelBuilder
    from railway.contact.geometry import rigid_contact
    from railway.vehicles.wheel_rail import WheelRailContact

    z0, roll0, _, _ = rigid_contact([0.0])
    b = ModelBuilder(3, "wheelset", gravity=(0.0, 0.0, -GRAVITY))
    b.add_body("ws", mass=1813.0, inertia=(1120.0, 112.0, 1120.0), position=(10.0, 0.0, z0[0] - 6e-5),
               orientation=frames.rotation_vector_to_euler(np.array([roll0[0], 0.0, 0.0])),
               velocity=(0.5, 0.0, 0.0), angular_velocity=(0.0, 0.5 / 0.46, 0.0))
    b.add_force(WheelRailContact("wr", ["ws"], Track.straight(400.0), creep_law="polach2000"))
    b.add_applied_force("brake", "ws", (0.0, 0.0, 0.0), (-30e3, 0.0, 0.0))
    m = b.build()
    cause = r"wheel-rail contact 'wr': ContactForces: rolling speed [0-9.e-]+ m/s at a loaded contact is below 1e-3 m/s"
    r = simulate(m, (0.0, 0.3), "jit-dop853", rtol=1e-5, atol=1e-7, n_output=31)
    assert r.status == "failed" and 0.02 < r.t[-1] < 0.05
    assert re.search(r"jit-dop853 failed at t = [0-9.]+ s: " + cause, r.message), r.message
    with pytest.raises(InputError, match=cause):
        simulate(m, (0.0, 0.3), "rk45", rtol=1e-5, atol=1e-7, n_output=31)


def test_a_zero_primary_vertical_stiffness_is_named():
    D = VehicleDefinition.manchester()
    k = tuple(D.primary["stiffness"])
    bad = dataclasses.replace(D, primary=dict(D.primary, stiffness=(k[0], k[1], 0.0)))
    with pytest.raises(InputError, match=r"primary suspension vertical stiffness k_z = 0.0 N/m"):
        build_vehicle(bad, Track.straight(200.0), s0=30.0, speed=10.0)
