"""Tests of :mod:`coaster.train`: the three-car train (Pombo & Ambrósio), its runs and wheel forces.

Tier 2: the rank of the full constraint Jacobian (71 of 71 rows, one degree of freedom) at many
positions on a twisted helix, an S-curve of clothoids and the shared circuit; the compiled
kernels of the path joint and of the track forces equal the numpy path to round-off.
Tier 1 (closed forms, notes/coaster.md "Train invariants"): a train held by the chain at constant
speed on a grade α needs the pull M g sin α and carries M g cos α on its wheelsets; drag alone on
level track v(t) = v0/(1 + k v0 t/M_e); rolling resistance alone v(t) = v0 − c_rr g M/M_e t;
brakes bring the train to the target speed; energy T + V conserved over a lap of the circuit
without dissipation; a train too slow for a hill rolls back and the run says so.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from coaster.frames import Bank, RotationMinimisingFrame
from coaster.track import (CircularArc, Clothoid, CompositeCentreline, Helix, SplineCentreline, Straight, chain)
from coaster.train import (ChainLift, SpeedSection, Train, TrainParameters, chain_force, circuit_frame,
                           circuit_sections, rank_table, run_train, wheel_forces)
from core.errors import InputError

G = 9.81
METHOD = "jit-dop853-projection"


@pytest.fixture(scope="module")
def twisted_helix():
    """Helix R = 20 m, rise 3 m/rad, with a bank oscillating ±0.3 rad (twist up to 0.03 rad/m)."""
    hel = Helix(20.0, 3.0, 6 * np.pi)
    bank = Bank(lambda L: np.vstack([0.3 * np.sin(L / 10), 0.03 * np.cos(L / 10), -0.003 * np.sin(L / 10),
                                     -0.0003 * np.cos(L / 10)]))
    return RotationMinimisingFrame(hel, bank=bank, max_step=1.0)


@pytest.fixture(scope="module")
def s_curve():
    cl = CompositeCentreline(chain([Straight(20), Clothoid(20, 0, 1 / 30), CircularArc(30, 0.6),
                                    Clothoid(40, 1 / 30, -1 / 30), CircularArc(30, 0.6, turn=-1),
                                    Clothoid(20, -1 / 30, 0), Straight(20)]))
    return RotationMinimisingFrame(cl, bank=Bank.constant(0.2), max_step=1.0)


def _straight(grade, length=400.0):
    return RotationMinimisingFrame(Straight(length, grade=grade), max_step=5.0)


# ---------------------------------------------------------------------------------------------
# rank and assembly
# ---------------------------------------------------------------------------------------------
def test_counts_and_assembly(twisted_helix):
    tr = Train(twisted_helix)
    m = tr.model(40.0, 10.0)
    assert m.n_bodies == 11 and m.n_v == 72 and m.n_c == 71 and m.degrees_of_freedom == 1
    assert sorted(tr.bodies) == sorted([f"car{k}" for k in (1, 2, 3)] + ["bar1", "bar2"]
                                       + [f"ws{k}" for k in range(1, 7)])
    assert np.abs(m.Phi(0.0, m.q0)).max() < 1e-9
    assert np.abs(m.Phi_q(0.0, m.q0) @ m.v0).max() < 1e-9
    _, iv = tr.lead_index(m)
    assert m.v0[iv] == pytest.approx(10.0, abs=1e-12)
    L = tr.arc_lengths(40.0)
    assert np.all(np.diff(L) < 0)                       # the wheelsets follow each other backwards
    assert L[0] - L[1] == pytest.approx(tr.p.pivot_spacing, rel=1e-2)  # chord of the pivots' path ≈ arc
    poses = tr.poses(40.0)
    for k in (1, 2, 3):                                      # car pivots on the wheelsets' pivot points
        r, A = poses[f"car{k}"]
        for ws, s in ((f"ws{2 * k - 1}", tr._front), (f"ws{2 * k}", tr._rear)):
            rw, Aw = poses[ws]
            assert np.abs(r + A @ s - (rw + Aw @ tr._ws_pivot)).max() < 1e-9


@pytest.mark.parametrize("track", ["twisted_helix", "s_curve"])
def test_rank_is_full_on_analytic_tracks(track, request):
    """71 independent rows (one degree of freedom) at every tested position; σ_min/σ_max stays
    near its straight-track value (measured 0.091 on both tracks)."""
    fr = request.getfixturevalue(track)
    tr = Train(fr)
    L1 = np.linspace(12.0, fr.length - 1.0, 40)
    tab = rank_table(tr, L1)
    assert (tab["rank"] == 71).all() and (tab["dof"] == 1).all(), tab
    assert (tab["dependent rows"] == "").all()
    assert tab["sigma_min/sigma_max"].min() > 0.05
    assert tab["max|Phi|"].max() < 1e-9


@pytest.fixture(scope="module")
def circuit():
    fr, data, cl = circuit_frame()
    return fr, data, cl


def test_rank_is_full_along_the_circuit(circuit):
    fr, _, cl = circuit
    tr = Train(fr)
    tab = rank_table(tr, np.linspace(0.0, cl.length, 120, endpoint=False))
    assert (tab["rank"] == 71).all() and (tab["dof"] == 1).all()
    assert tab["sigma_min/sigma_max"].min() > 0.05       # measured 0.0909
    assert tab["max|Phi|"].max() < 1e-8


def test_compiled_kernels_equal_numpy(twisted_helix):
    from core.compiled import compile_model, make_workspace
    from core.compiled import dynamics as D
    from core.compiled import protocol as P
    from core.dynamics import accelerations

    tr = Train(twisted_helix)
    sec = SpeedSection("brake", 30.0, 60.0, 3.0, 1e4)
    m = tr.model(45.0, 10.0, forces=tr.forces(rolling=0.003, drag_area=0.8, sections=[sec]))
    cm = compile_model(m)
    ws = make_workspace(cm)
    rng = np.random.default_rng(3)
    q = m.retract(m.q0, 0.01 * rng.standard_normal(m.n_v))
    v = m.v0 + rng.standard_normal(m.n_v)
    D.body_states(cm.fields["lay"], q, v, ws)
    assert D.constraints(cm.data, ws, 0.0, q, v, P.WANT_ALL) == P.OK
    assert np.abs(ws.phi[:m.n_c] - m.Phi(0.0, q)).max() < 1e-12
    assert np.abs(ws.gam[:m.n_c] - m.gamma(0.0, q, v)).max() < 1e-12 * max(1, np.abs(m.gamma(0.0, q, v)).max())
    Q = np.zeros(m.n_v)
    assert D.forces(cm.data, cm.initial_states(), ws, 0.0, q, v, Q) == P.OK
    assert np.abs(Q - m.Q(0.0, q, v)).max() < 1e-9
    a = np.zeros(m.n_v)
    lam = np.zeros(m.n_c)
    assert D.accelerations(cm.data, cm.initial_states(), ws, 0.0, q, v, 0.0, 0.0, a, lam) == P.OK
    a2, l2 = accelerations(m, 0.0, q, v)
    assert np.abs(a - a2).max() < 1e-9 * max(1, np.abs(a2).max())
    assert np.abs(lam - l2).max() < 1e-9 * np.abs(l2).max()


# ---------------------------------------------------------------------------------------------
# closed forms on straight track
# ---------------------------------------------------------------------------------------------
@pytest.mark.parametrize("grade", [0.0, 0.2])
def test_chain_on_a_grade_pulls_M_g_sin_alpha(grade):
    """Constant speed: the pull is M g sin α (zero on level track), the wheelsets carry
    Σ F_b = M g cos α and Σ F_t = M g sin α (the chain acts through the lead coordinate), Σ F_n = 0."""
    tr = Train(_straight(grade))
    M = tr.p.total_mass
    ch = ChainLift(20.0, 60.0, 4.0)
    run = run_train(tr, 20.0, 4.0, 80.0, chain=ch, rtol=1e-10, atol=1e-10, output_step=1.0)
    # released on the grade at 4 m/s the train climbs 4²/(2 g sin α) = 4.1 m further and rolls back
    assert run.status == ("finished" if grade == 0 else "rolled back"), run.message
    if grade:
        assert "L = 64.0" in run.message and run.phases["phase"].tolist() == ["chain lift", "free running"]
    cf = chain_force(run)
    assert len(cf) == 11
    tol = 1e-6 * M * G
    assert np.abs(cf["chain force [N]"] - M * G * math.sin(grade)).max() < tol
    wf = wheel_forces(run)
    sel = run.phase == 0
    Fb = wf.filter(regex=r"F_b").to_numpy()[sel].sum(axis=1)
    Ft = wf.filter(regex=r"F_t").to_numpy()[sel].sum(axis=1)
    Fn = wf.filter(regex=r"F_n").to_numpy()[sel].sum(axis=1)
    assert np.abs(Fb - M * G * math.cos(grade)).max() < tol
    assert np.abs(Ft - M * G * math.sin(grade)).max() < tol
    assert np.abs(Fn).max() < tol
    assert list(wf.columns[:3]) == ["t [s]", "ws1 L [m]", "ws1 F_t [N]"]


def test_drag_alone_on_level_track():
    """M_e v̇ = −k v², k = ½ ρ c_d A, M_e = M + 6 m_s: v = v0/(1 + k v0 t/M_e) (rtol 1e-10; measured 1e-11)."""
    tr = Train(_straight(0.0, 2000.0))
    f = tr.forces(drag_area=1.2, air_density=1.2)
    run = run_train(tr, 20.0, 30.0, 1500.0, forces=f, t_max=20.0, rtol=1e-10, atol=1e-10, output_step=0.5)
    assert run.status == "time limit", run.message
    Me = tr.p.total_mass + tr.p.n_wheelsets * tr.p.wheel_spin_mass
    k = 0.5 * 1.2 * 1.2
    v = 30.0 / (1 + k * 30.0 * run.t / Me)
    assert np.abs(run.Ldot[:, 0] - v).max() < 1e-7


def test_rolling_resistance_alone_on_level_track():
    """v̇ = −c_rr g M/M_e (v ≫ v_ε, tanh(v/v_ε) = 1 to 1e-100)."""
    tr = Train(_straight(0.0, 2000.0))
    f = tr.forces(rolling=0.01)
    run = run_train(tr, 20.0, 10.0, 1500.0, forces=f, t_max=10.0, rtol=1e-10, atol=1e-10, output_step=0.5)
    Me = tr.p.total_mass + tr.p.n_wheelsets * tr.p.wheel_spin_mass
    v = 10.0 - 0.01 * G * tr.p.total_mass / Me * run.t
    assert np.abs(run.Ldot[:, 0] - v).max() < 1e-7


def test_brakes_bring_the_train_to_the_target_speed():
    tr = Train(_straight(0.0, 1000.0))
    sec = SpeedSection("brake", 100.0, 300.0, 5.0, 2.0e4, gain=2.0e4)
    run = run_train(tr, 20.0, 20.0, 400.0, forces=tr.forces(sections=[sec]), rtol=1e-9, atol=1e-9)
    assert run.status == "finished", run.message
    L, v = run.L[:, 0], run.Ldot[:, 0]
    assert np.all(np.abs(v[L < 99.0] - 20.0) < 1e-6)        # no force before the section
    after = v[L > 300.0]
    assert np.all((after >= 5.0 - 1e-6) & (after < 5.05))   # brakes only: never below the target
    # energy balance: the work of the brake force equals the loss of kinetic energy
    Me = tr.p.total_mass + tr.p.n_wheelsets * tr.p.wheel_spin_mass
    E = run.energy()
    assert E[0] - E[-1] == pytest.approx(0.5 * Me * (20.0**2 - v[-1] ** 2), rel=1e-6)


# ---------------------------------------------------------------------------------------------
# rolling back
# ---------------------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def hump():
    x = np.linspace(0.0, 240.0, 49)
    P = np.c_[x, np.zeros_like(x), 6.0 * np.exp(-(((x - 120.0) / 25.0) ** 2))]
    return RotationMinimisingFrame(SplineCentreline(P, kind="quintic"), max_step=2.0)


def test_too_slow_train_rolls_back_and_the_run_says_so(hump):
    tr = Train(hump)
    run = run_train(tr, 30.0, 7.0, 220.0, rtol=1e-9, atol=1e-9, output_step=0.05)
    assert run.status == "rolled back"
    assert "rolls back" in run.message and "L̇_1 = 0" in run.message
    v = run.Ldot[:, 0]
    assert v[0] > 0 and v[-1] < 0 and np.all(v[:-2] > 0)     # stopped at the first reversal
    assert run.L[:, 0].max() < 120.0 + tr.p.pivot_spacing    # it never crested
    # energy conserved up to the reversal (no dissipation)
    E = run.energy()
    assert np.abs(E - E[0]).max() < 1e-6 * 0.5 * tr.p.total_mass * 7.0**2


def test_fast_enough_train_crests_the_hump(hump):
    tr = Train(hump)
    run = run_train(tr, 30.0, 14.0, 220.0, rtol=1e-9, atol=1e-9)
    assert run.status == "finished", run.message
    assert run.L[-1, 0] >= 220.0 and np.all(run.Ldot[:, 0] > 0)


# ---------------------------------------------------------------------------------------------
# energy over a lap of the circuit
# ---------------------------------------------------------------------------------------------
def test_energy_conserved_over_a_lap_of_the_circuit(circuit):
    """Free running over the whole circuit (4945 m, 231 s) without dissipation, rtol = atol = 1e-8:
    max|E − E0| below 1e-6 of the peak kinetic energy (measured 2.3e-10; 17 s of integration)."""
    fr, data, cl = circuit
    tr = Train(fr)
    run = run_train(tr, 10.0, 8.0, 10.0 + cl.length, rtol=1e-8, atol=1e-8, output_step=0.5, chunk=40.0,
                    sections=circuit_sections(data, cl))
    assert run.status == "finished", run.message
    assert run.L[-1, 0] >= 10.0 + cl.length
    E = run.energy()
    Me = tr.p.total_mass + tr.p.n_wheelsets * tr.p.wheel_spin_mass
    T_peak = 0.5 * Me * run.Ldot[:, 0].max() ** 2
    assert np.abs(E - E[0]).max() < 1e-6 * T_peak
    assert run.Ldot[-1, 0] == pytest.approx(8.0, rel=1e-4)   # back at the start height: back at 8 m/s


# ---------------------------------------------------------------------------------------------
# bad input
# ---------------------------------------------------------------------------------------------
def test_bad_input_is_named(twisted_helix):
    with pytest.raises(InputError, match="car_mass"):
        TrainParameters(car_mass=-1.0)
    with pytest.raises(InputError, match="n_cars"):
        TrainParameters(n_cars=0)
    with pytest.raises(InputError, match="'b1'.*mode"):
        SpeedSection("b1", 0.0, 10.0, 1.0, 1.0, mode="stop")
    with pytest.raises(InputError, match="'b2'.*ramp"):
        SpeedSection("b2", 0.0, 3.0, 1.0, 1.0, ramp=2.0)
    with pytest.raises(InputError, match="chain lift: speed"):
        ChainLift(0.0, 10.0, 0.0)
    tr = Train(twisted_helix)
    with pytest.raises(InputError, match="L_stop"):
        run_train(tr, 40.0, 5.0, 30.0)
    with pytest.raises(InputError, match="chain lift starts at L = 40"):
        run_train(tr, 41.0, 5.0, 60.0, chain=ChainLift(40.0, 50.0, 5.0))
    with pytest.raises(InputError, match="FramedCurve"):
        Train(object())
