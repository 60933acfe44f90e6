"""Railway vehicle speed and work-precision (issue 10's benchmarks).

1. Work-precision on 5 s of the curving run (Manchester coach, 200 m curve, 20 m/s, Polach 2000,
   from the straight into the full curve): error of the leading wheelset's lateral displacement
   and of the leading outer wheel's lateral force Y, max over 100 Hz outputs, against a tight
   reference (jit-dop853, rtol 1e-9), for the compiled explicit (jit-rk45, jit-dop853) and
   implicit (jit-radau) integrators over a tolerance grid; wall time of each run.
2. Real-time factor (simulated time / wall time) of 30 s of running on the 200 m curve (a 400 m
   long curve so that 30 s at 10 m/s stay in it) with the recommended integrator, and where the
   time goes: right-hand sides (contact kernel and the rest) and accepted-step updates, each
   kernel timed in a compiled loop (no Python call in the timing).
3. Real-time factor against accuracy on the same 30 s: jit-dop853 and jit-radau at rtol 1e-3 and
   1e-4, each against a reference at rtol 1e-7: the leading wheelset's lateral displacement at every output
   and the quasi-static curving values (the scene's table: means per wheel while the whole
   vehicle is in the full curve, 30 m from both transitions); and, for jit-dop853, the same with
   the cross-section scan every 5 accepted steps instead of every step (a trade-off the scenes do not take: between
   two scans a new contact is not searched for, so the force at a state depends on when the last
   scan was).
4. The flying wheelset and the linear critical-speed sweep, timed.

Run:  .venv/bin/python benchmarks/railway_vehicle.py [--quick]
Writes benchmarks/results/railway_vehicle.md (and .csv tables), headed by the processor it ran on
(wall times belong to a processor).  One process, one core (numba is single-threaded here); run it
on an otherwise idle machine.
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")

import numpy as np
import pandas as pd

RESULTS = Path(__file__).resolve().parent / "results"


def _errors(res, ref, veh):
    from railway.vehicles.wheel_rail import contact_history

    ws = veh.wheelsets[0]
    y = res.coordinates()[f"{ws}.y [m]"].to_numpy()
    yr = ref.coordinates()[f"{ws}.y [m]"].to_numpy()
    return float(np.max(np.abs(y - yr)))


def work_precision(quick=False):
    from core.integrators import simulate
    from railway.vehicles.curving import run_curving

    V, T = 20.0, 5.0
    ref, veh = run_curving("polach2000", V, T=T, rtol=1e-9, n_output_per_s=100)
    assert ref.success, ref.message
    rows = []
    grids = {"jit-dop853": [1e-3, 1e-4, 1e-5, 1e-6, 1e-7], "jit-rk45": [1e-3, 1e-4, 1e-5, 1e-6],
             "jit-radau": [1e-3, 1e-4, 1e-5]}
    if quick:
        grids = {k: v[:2] for k, v in grids.items()}
    q0, v0 = veh.initial_state()
    for method, tols in grids.items():
        for rtol in tols:
            simulate(veh.model, (0.0, 0.01), method, q0=q0, v0=v0, rtol=rtol, atol=rtol * 1e-2)  # compile
            t0 = time.perf_counter()
            res = simulate(veh.model, (0.0, T), method, q0=q0, v0=v0, rtol=rtol, atol=rtol * 1e-2,
                           n_output=int(T * 100) + 1)
            wall = time.perf_counter() - t0
            err = _errors(res, ref, veh) if res.success else np.nan
            rows.append({"method": method, "rtol": rtol, "status": res.status, "wall time [s]": wall,
                         "error lateral displacement, leading wheelset [m]": err,
                         "steps": res.counters["n_steps"], "rejected": res.counters["n_rejected"],
                         "rhs": res.counters["n_rhs"]})
            print(rows[-1], flush=True)
    return pd.DataFrame(rows)


def _kernel_loops():
    """Compiled loops that call a kernel n times (the timing holds no Python call overhead)."""
    import numba

    from core.compiled import dynamics as D

    @numba.njit
    def rhs_loop(n, cd, st, ws, t, q, v, vd, lam):
        for _ in range(n):
            D.accelerations(cd, st, ws, t, q, v, 0.0, 0.0, vd, lam)

    @numba.njit
    def accept_loop(n, cd, st0, st, ws, t, q, v):
        for _ in range(n):
            st[:] = st0
            D.accept(cd, st, ws, t, q, v)

    def force_loop(kernel):
        @numba.njit
        def loop(n, t, q, v, r, A, rd, w, lay, fd, ix, sk, Q, err):
            for _ in range(n):
                kernel(t, q, v, r, A, rd, w, lay, fd, ix, sk, Q, err)
        return loop

    return rhs_loop, accept_loop, force_loop


def real_time(method="jit-dop853", rtol=1e-4, V=10.0, T=30.0):
    from core.compiled import dynamics as D
    from core.compiled.layout import compile_model
    from core.integrators import simulate
    from railway.vehicles.curving import curving_track
    from railway.vehicles.curving import run_curving

    track = curving_track(curve_length=REAL_TIME_CURVE)
    run_curving("polach2000", V, T=0.05, track=track, method=method, rtol=rtol)  # compile and cache
    t0 = time.perf_counter()
    res, veh = run_curving("polach2000", V, T=T, track=track, method=method, rtol=rtol, n_output_per_s=10)
    wall_all = time.perf_counter() - t0
    # the integration alone (the run above also built the model and solved the preload)
    q0, v0 = veh.initial_state()
    t0 = time.perf_counter()
    res = simulate(veh.model, (0.0, T), method, q0=q0, v0=v0, rtol=rtol, atol=rtol * 1e-2, n_output=int(T * 10) + 1)
    wall = time.perf_counter() - t0
    # where the time goes: at 10 states along the run (every 3 s), the accepted-step update and
    # the right-hand side one mean step h later (the state integrated over h; the search state
    # of the state before, as in the stages of a step), each in a compiled loop
    m = veh.model
    c = res.counters
    h = T / c["n_steps"]
    rhs_loop, accept_loop, force_loop = _kernel_loops()
    rhs_t, contact_t, accept_t = [], [], []
    cm = contact_loop = None
    for k in range(15, len(res.t), 30):
        q, v, tk = np.array(res.q[k]), np.array(res.v[k]), float(res.t[k])
        m.begin_run(tk, q, v)
        cm = compile_model(m) if cm is None else cm
        ws = D.make_workspace(cm)
        st = cm.initial_states()
        for _ in range(3):
            D.accept(cm.data, st, ws, tk, q, v)
        vd, lam = np.zeros(m.n_v), np.zeros(max(1, cm.data.act.shape[0]))
        r1 = simulate(m, (tk, tk + h), method, q0=q, v0=v, rtol=rtol, atol=rtol * 1e-2, n_output=2)
        q1, v1 = np.array(r1.q[-1]), np.array(r1.v[-1])
        n = 2000
        rhs_loop(1, cm.data, st, ws, tk + h, q1, v1, vd, lam)
        t0 = time.perf_counter()
        rhs_loop(n, cm.data, st, ws, tk + h, q1, v1, vd, lam)
        rhs_t.append((time.perf_counter() - t0) / n)
        kc = next(i for i, r in enumerate(cm.force_kinds) if r.what == "wheel-rail contact")
        rec = cm.force_kinds[kc]
        sk = st[cm._st_off[kc]:cm._st_off[kc + 1]].reshape(cm._st_n[kc], cm._st_w[kc])
        err = np.zeros(3, np.int64)
        Q = np.zeros(m.n_v)
        D.body_states(cm.fields["lay"], q1, v1, ws)
        contact_loop = contact_loop or force_loop(rec.forces.dispatcher)
        args = (tk + h, q1, v1, ws.r, ws.A, ws.rd, ws.w, cm.fields["lay"], rec.fd, rec.ix, sk, Q, err)
        contact_loop(1, *args)
        t0 = time.perf_counter()
        contact_loop(n, *args)
        contact_t.append((time.perf_counter() - t0) / n)
        na = 200
        s2 = st.copy()
        accept_loop(1, cm.data, st, s2, ws, tk + h, q1, v1)
        t0 = time.perf_counter()
        accept_loop(na, cm.data, st, s2, ws, tk + h, q1, v1)
        accept_t.append((time.perf_counter() - t0) / na)
    rhs, contact, accept = float(np.mean(rhs_t)), float(np.mean(contact_t)), float(np.mean(accept_t))
    shares = {"share: contact in rhs [-]": c["n_rhs"] * contact / wall,
              "share: rest of the rhs (other kinds, solve) [-]": c["n_rhs"] * (rhs - contact) / wall,
              "share: accepted-step updates [-]": c["n_steps"] * accept / wall}
    shares["not accounted for (integrator, memory) [-]"] = 1.0 - sum(shares.values())
    return {"method": method, "rtol": rtol, "speed [m/s]": V, "simulated [s]": T, "status": res.status,
            "wall time, integration [s]": wall, "real-time factor [-]": T / wall,
            "wall time incl. build and preload [s]": wall_all, "steps": c["n_steps"], "rejected": c["n_rejected"],
            "rhs": c["n_rhs"], "rhs per step [-]": c["n_rhs"] / c["n_steps"],
            "wall time per step [us]": wall / c["n_steps"] * 1e6,
            "rhs incl. solve, mean of 10 states [us]": rhs * 1e6, "contact kernel, mean of 10 states [us]": contact * 1e6,
            "accept update, mean of 10 states [us]": accept * 1e6, **shares}


#: curve length (m) of the real-time runs: 30 s at 10 m/s stay in the 200 m-radius curve
REAL_TIME_CURVE = 400.0
#: quasi-static columns compared in :func:`accuracy_against_speed` (the scene's curving table)
QS_COLUMNS = ("Q [N]", "Y [N]", "Y/Q [-]", "flange force [N]", "lateral displacement [m]", "angle of attack [rad]")


def _full_curve_means(H, curve_length):
    """Means per wheel of the quasi-static columns in the full curve (railway.vehicles.curving.curve_window)
    and the number of output times they average."""
    from railway.vehicles.curving import curve_window

    W = curve_window(H, curve_length)
    return W.groupby("wheel", sort=False)[list(QS_COLUMNS)].mean(), int(W["t [s]"].nunique())


def accuracy_against_speed(V=10.0, T=30.0, rtols=(1e-3, 1e-4), reseeds=(1, 5), rtol_ref=1e-7):
    """Real-time factor and error of jit-dop853 and jit-radau on the 30 s run at each tolerance
    (module docstring, item 3): one row per (method, rtol, scan every N accepted steps); jit-radau
    with the scenes' scan at every accepted step only."""
    from core.integrators import simulate
    from railway.vehicles.curving import curving_track
    from railway.vehicles.curving import run_curving
    from railway.vehicles.wheel_rail import contact_history

    track = curving_track(curve_length=REAL_TIME_CURVE)
    ref, veh = run_curving("polach2000", V, T=T, track=track, rtol=rtol_ref, n_output_per_s=10)
    assert ref.success, ref.message
    H_ref = contact_history(veh.model, ref)
    qs_ref, n_rows = _full_curve_means(H_ref, REAL_TIME_CURVE)
    ws0 = veh.wheelsets[0]
    y_ref = ref.coordinates()[f"{ws0}.y [m]"].to_numpy()
    rows = []
    cases = [("jit-dop853", reseed) for reseed in reseeds] + [("jit-radau", 1)]
    for method, reseed in cases:
        for rtol in rtols:
            _, veh = run_curving("polach2000", V, T=0.05, track=track, method=method, rtol=rtol,
                                 reseed_every=reseed)
            q0, v0 = veh.initial_state()
            t0 = time.perf_counter()
            res = simulate(veh.model, (0.0, T), method, q0=q0, v0=v0, rtol=rtol, atol=rtol * 1e-2,
                           n_output=int(T * 10) + 1)
            wall = time.perf_counter() - t0
            row = {"method": method, "rtol": rtol, "scan every N accepted steps": reseed, "status": res.status,
                   "wall time, integration [s]": wall, "real-time factor [-]": T / wall,
                   "steps": res.counters["n_steps"]}
            if res.success:
                y = res.coordinates()[f"{ws0}.y [m]"].to_numpy()
                row["max error, lateral displacement of the leading wheelset, every output [m]"] = float(
                    np.max(np.abs(y - y_ref)))
                qs, _ = _full_curve_means(contact_history(veh.model, res), REAL_TIME_CURVE)
                for col in QS_COLUMNS:
                    row[f"max error of the full-curve mean, {col}"] = float((qs[col] - qs_ref[col]).abs().max())
            rows.append(row)
            print(rows[-1], flush=True)
    out = pd.DataFrame(rows)
    out.attrs["reference"] = (f"jit-dop853 rtol {rtol_ref:g}: {ref.counters['n_steps']} steps; full-curve means over "
                              f"{n_rows} outputs; largest reference values: "
                              + ", ".join(f"{c} {qs_ref[c].abs().max():.4g}" for c in QS_COLUMNS))
    return out


def timed_cases():
    from core.integrators import simulate
    from railway.contact.two_point import conical_wheel
    from railway.vehicles.critical_speed import linear_critical_speed
    from railway.vehicles.wheelset_models import free_wheelset

    rows = []
    m = free_wheelset(5.0, 0.002, wheel=conical_wheel(), track_length=130.0)
    simulate(m, (0.0, 0.01), "jit-dop853", rtol=1e-7, atol=1e-9)
    t0 = time.perf_counter()
    res = simulate(m, (0.0, 14.0), "jit-dop853", rtol=1e-7, atol=1e-9, n_output=2801)
    w = time.perf_counter() - t0
    rows.append({"case": "flying wheelset, cone 1:40, 5 m/s, 14 s, jit-dop853 rtol 1e-7", "wall time [s]": w,
                 "real-time factor [-]": 14.0 / w, "status": res.status})
    m = free_wheelset(20.0, 0.001, creep_law="polach2000", track_length=300.0)
    t0 = time.perf_counter()
    res = simulate(m, (0.0, 12.0), "jit-dop853", rtol=1e-6, atol=1e-8, n_output=4801)
    w = time.perf_counter() - t0
    rows.append({"case": "flying wheelset, S1002, 20 m/s, 12 s, jit-dop853 rtol 1e-6", "wall time [s]": w,
                 "real-time factor [-]": 12.0 / w, "status": res.status})
    t0 = time.perf_counter()
    lin = linear_critical_speed()
    rows.append({"case": f"linear critical speed (bisection of eigenvalues, V_c = {lin['V_core']:.3f} m/s)",
                 "wall time [s]": time.perf_counter() - t0, "real-time factor [-]": np.nan, "status": "finished"})
    return pd.DataFrame(rows)


def write_test_states(path=None, rows=range(8, 51)):
    """States of the curving run (FASTSIM, 10 m/s, 5 outputs per s to t = 12.5 s) for
    tests/railway/test_wheel_rail.py::test_curving_forces_are_the_same_fresh_and_after_any_history."""
    from railway.vehicles.curving import run_curving

    path = Path(path or Path(__file__).resolve().parents[1] / "tests" / "railway" / "curving_states_fastsim_10ms.npz")
    res, _ = run_curving("fastsim", 10.0, T=12.5, n_output_per_s=5)
    assert res.success, res.message
    idx = np.array(list(rows))
    np.savez_compressed(path, t=np.asarray(res.t)[idx], q=np.asarray(res.q)[idx], v=np.asarray(res.v)[idx])
    return path


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="two tolerances per method")
    ap.add_argument("--write-test-states", action="store_true",
                    help="only write the curving states of the history test (tests/railway)")
    args = ap.parse_args(argv)
    from _host import host_line
    from core.results import markdown_table

    if args.write_test_states:
        print(write_test_states())
        return 0

    from _calibration import calibrate, calibration_line, with_calibration

    RESULTS.mkdir(exist_ok=True)
    load0 = os.getloadavg()[0]
    cal = calibrate()
    wp = with_calibration(work_precision(args.quick), cal, ["wall time [s]"])
    # jit-radau beside jit-dop853: with its stages' Euler parameters on the unit sphere it runs the
    # coach without the stability warning (core.integrators.compiled_radau, docs/benchmarks.md, issue 24)
    rt = with_calibration(pd.DataFrame([real_time(), real_time("jit-radau")]), cal, ["wall time, integration [s]"])
    acc = accuracy_against_speed()
    acc = with_calibration(acc, cal, ["wall time, integration [s]"])
    tc = timed_cases()
    load1 = os.getloadavg()[0]
    for name, df in (("railway_vehicle_work_precision", wp), ("railway_vehicle_real_time", rt),
                     ("railway_vehicle_real_time_accuracy", acc), ("railway_vehicle_timed", tc)):
        df.to_csv(RESULTS / f"{name}.csv", index=False)
    text = ["# Railway vehicle benchmarks", "", f"host: {host_line()}", "", f"{calibration_line(cal)}.", "",
            f"load average {load0:.2f} -> {load1:.2f}", "",
            "## Work-precision, 5 s of curving (20 m/s, Polach 2000)", "", markdown_table(wp, floatfmt=".4g"), "",
            "## Real-time factor, 30 s on the 200 m curve", "", markdown_table(rt.T.reset_index(), floatfmt=".4g"), "",
            "## Real-time factor against accuracy, the same 30 s", "", f"Reference: {acc.attrs['reference']}.", "",
            markdown_table(acc.T.reset_index(), floatfmt=".4g"), "",
            "## Timed cases", "", markdown_table(tc, floatfmt=".4g"), ""]
    (RESULTS / "railway_vehicle.md").write_text("\n".join(text), encoding="utf-8")
    print("\n".join(text))
    return 0


if __name__ == "__main__":
    sys.exit(main())
