r"""Railway vehicle scenes for ``mbsuite run``: the wheel–rail contact in motion on the core.

* ``railway-flying-wheelset`` — a free wheelset released with a lateral offset: conical wheels
  (cone 1:40), the kinematic wavelength against Klingel's closed form; S1002 / UIC60, the growth
  into a limit cycle bounded by flange contact, its frequency against V / L at the equivalent
  conicity of its amplitude.
* ``railway-critical-speed`` — the linear critical speed of a wheelset on springs to a moving
  frame from the eigenvalues of core's linearisation against the closed form
  (:mod:`railway.hunting`); the nonlinear critical speed of the Manchester coach on S1002 / UIC60 by a
  speed run-down from a hunting limit cycle for each creep law, refined by bisection of constant-
  speed runs, with the bifurcation figure.
* ``railway-curving`` — the Manchester coach (stand-in for the ML95 metro trailer, whose data are
  not public) through a 200 m curve with transitions and cant at 10 and 20 m/s for each creep
  law: per wheel Q, Y, Y/Q, ΣY, flange contact and force, ΔQ/Q0, lateral displacement, angle of
  attack, creepages, creep forces, Tγ and the Nadal limit, along the track and as a quasi-static
  table in the full curve; the lateral equilibrium check.
* ``railway-irregular-track`` — the coach on straight track with lateral and vertical
  irregularities at several speeds (a sweep through :func:`core.sweep.run_sweep`): car-body
  accelerations (r.m.s. and spectra) and wheel forces at 1 kHz, filtered and as percentiles as a
  track test reads them (:func:`railway.assessment.wheel_force_statistics`).

Every run is integrated by ``jit-dop853`` (compiled; the recommended integrator, see the
benchmark ``benchmarks/railway_vehicle.py``) and checked for its status; a failed run (e.g. a
derailment) stays in the tables with its message.  Tables are written in the units of the
``mbsuite railway`` commands (mm, kN, deg, mrad; :func:`railway.scenes._display_units`).
"""

from __future__ import annotations

import numpy as np
import pandas as pd

__all__ = ["vehicle_scenes", "curving_track", "run_curving", "run_down", "CREEP_LAWS",
           "creep_law_spec"]

#: the creep laws compared by the scenes: (label, registry name, parameters)
CREEP_LAWS = ("kalker_linear", "shen_hedrick_elkins", "polach2000", "polach2005", "fastsim")
METHOD = "jit-dop853"
RTOL = 1e-4


def creep_law_spec(law, speed):
    """(creep_law, creep_params) for a scene's law name: Polach 2005 with the published "dry"
    set (railway/creep.py: second-hand, see data/railway/polach2005_parameters.csv) at the
    run's speed; FASTSIM on a 10 x 10 grid (the dynamic runs call it for every contact at every
    right-hand side)."""
    from .creep import Fastsim, Polach2005

    if law == "polach2005":
        return Polach2005.from_parameter_set("dry", speed=speed), None
    if law == "fastsim":
        return Fastsim(10, 10), None
    return law, None


def _fig(nrows=1, ncols=1, size=(7, 4)):
    from .scenes import _fig as f

    return f(nrows, ncols, size)


def _units(df):
    from .scenes import _display_units

    return _display_units(df)


def _crossings(x, y):
    """Positions where y changes sign (linear interpolation)."""
    i = np.nonzero((np.sign(y[:-1]) != np.sign(y[1:])) & (y[:-1] != 0))[0]
    return x[i] - y[i] * (x[i + 1] - x[i]) / (y[i + 1] - y[i])


# =============================================================================================
# 1. flying wheelset
# =============================================================================================
def _run_flying(ctx):
    from core.integrators import simulate

    from .contact_geometry import contact_geometry_table, equivalent_conicity
    from .hunting import klingel_wavelength
    from .two_point import conical_wheel
    from .wheelset_models import free_wheelset

    rows = []
    figs = {}
    # (a) conical wheels: the kinematic oscillation
    cone = conical_wheel()
    V, y0 = 5.0, 0.002
    T = 6.0 if ctx.fast else 14.0
    m = free_wheelset(V, y0, wheel=cone, track_length=V * T + 60.0)
    res = simulate(m, (0.0, T), METHOD, rtol=1e-7, atol=1e-9, n_output=int(T * 200) + 1)
    C = res.coordinates()
    x, y = C["wheelset.x [m]"].to_numpy(), C["wheelset.y [m]"].to_numpy()
    xc = _crossings(x, y)
    L_sim = 2.0 * float(np.mean(np.diff(xc)))
    # the closed form's inputs: nominal cone, and the equivalent conicity of the profile pair
    tab = contact_geometry_table(np.linspace(-0.002, 0.002, 41), wheel=cone)
    lam_e = float(np.polyfit(tab["y [m]"], tab["delta_r [m]"], 1)[0] / 2.0)
    kind = next(k for k in m.force_kinds if type(k).__name__ == "WheelRailKind")
    st = kind.sets[0]
    bs = m.body_states(m.q0, m.v0)
    kind.reset_state(bs, 0.0)
    r, A, v, w = st.states(bs)
    cres = st.contacts(r, A, v, w)[0]
    l = 0.5 * abs(cres.point_wheel[0, 0, 1] - cres.point_wheel[1, 0, 1])
    r0 = float(np.mean(cres.rolling_radius[:, 0]))
    L_k = float(klingel_wavelength(r0, l, 1.0 / 40.0))
    L_e = float(klingel_wavelength(r0, l, lam_e))
    rows.append({"case": "cone 1:40, Kalker linear", "speed [m/s]": V, "release offset [m]": y0,
                 "status": res.status, "wavelength simulated [m]": L_sim,
                 "Klingel, cone 1:40 [m]": L_k, "difference cone [-]": L_sim / L_k - 1.0,
                 "Klingel, equivalent conicity [m]": L_e, "difference equivalent [-]": L_sim / L_e - 1.0,
                 "conicity [-]": 1.0 / 40.0, "equivalent conicity [-]": lam_e, "r0 [m]": r0,
                 "half contact spacing [m]": l, "zero crossings": len(xc)})
    fig, ax = _fig(size=(8, 3.6))
    ax = ax[0, 0]
    ax.plot(x - x[0], y * 1e3, lw=1.2, label="simulated (jit-dop853, rtol 1e-7)")
    ax.plot(x - x[0], y0 * 1e3 * np.cos(2 * np.pi * (x - x[0]) / L_k), "--", lw=1,
            label=f"Klingel, λ = 1/40: L = {L_k:.3f} m")
    ax.set(xlabel="distance travelled [m]", ylabel="lateral displacement [mm]",
           title=f"railway-flying-wheelset — free wheelset, cone 1:40 on UIC60 1:40, V = {V:g} m/s, "
                 f"Kalker linear\nsimulated wavelength {L_sim:.3f} m")
    ax.title.set_fontsize(9)
    ax.legend(fontsize=8)
    ax.grid(True, alpha=0.3)
    figs["cone_kinematic_oscillation"] = fig

    # (b) S1002 / UIC60: growth into a limit cycle bounded by flange contact
    V, y0 = 20.0, 0.001
    T = 4.0 if ctx.fast else 12.0
    m = free_wheelset(V, y0, creep_law="polach2000", track_length=V * T + 60.0)
    res = simulate(m, (0.0, T), METHOD, rtol=1e-6, atol=1e-8, n_output=int(T * 400) + 1)
    C = res.coordinates()
    t, y = res.t, C["wheelset.y [m]"].to_numpy()
    half = t >= 0.5 * t[-1]
    tc = _crossings(t[half], y[half])
    f_sim = 1.0 / (2.0 * float(np.mean(np.diff(tc)))) if tc.size > 2 else np.nan
    # amplitude: mean of the lateral extremes between the crossings of the second half
    ext = [np.max(np.abs(y[half][(t[half] >= a) & (t[half] <= b)])) for a, b in zip(tc[:-1], tc[1:])]
    amp = float(np.mean(ext)) if ext else np.nan
    geo = contact_geometry_table(np.linspace(-0.010, 0.010, 401))
    lam = float(equivalent_conicity(geo["y [m]"].to_numpy(), geo["delta_r [m]"].to_numpy(), [amp])[0])
    L_eq = float(klingel_wavelength(0.46, 0.75, lam))
    rows.append({"case": "S1002 / UIC60 1:40, Polach 2000", "speed [m/s]": V, "release offset [m]": y0,
                 "status": res.status, "limit-cycle amplitude [m]": amp, "largest excursion [m]":
                 float(np.max(np.abs(y[half]))), "frequency simulated [Hz]": f_sim,
                 "equivalent conicity at the amplitude [-]": lam, "V / L(equivalent) [Hz]": V / L_eq,
                 "frequency ratio [-]": f_sim * L_eq / V})
    fig, ax = _fig(size=(8, 3.6))
    ax = ax[0, 0]
    ax.plot(t * V, y * 1e3, lw=0.9)
    for s_ in (1, -1):
        ax.axhline(s_ * 6.2518, ls=":", c="k", lw=0.8)
    ax.set(xlabel="distance travelled [m]", ylabel="lateral displacement [mm]",
           title=f"railway-flying-wheelset — free S1002 wheelset on UIC60 1:40, V = {V:g} m/s, Polach 2000, "
                 f"jit-dop853 rtol 1e-6 [{res.status}]\nlimit cycle {amp * 1e3:.2f} mm, {f_sim:.3f} Hz; "
                 f"dotted: rigid flange-contact onset ±6.2518 mm")
    ax.title.set_fontsize(9)
    ax.grid(True, alpha=0.3)
    figs["s1002_limit_cycle"] = fig
    cone_tab, s1002_tab = (pd.DataFrame([r]).dropna(axis=1, how="all") for r in rows)
    notes = (
        f"Free wheelset (Manchester coach wheelset, 1813 kg), absolute coordinates with the spin as a "
        f"full coordinate. Cone 1:40 (conical tread joined to the S1002 flank, railway.two_point): "
        f"simulated kinematic wavelength {L_sim:.3f} m against Klingel's 2 pi sqrt(r0 l / lambda) = "
        f"{L_k:.3f} m with the nominal cone ({(L_sim / L_k - 1) * 100:+.2f} %) and {L_e:.3f} m with the "
        f"equivalent conicity {lam_e:.5f} of the rigid contact-geometry table, whose roll of the wheelset "
        f"changes the rolling-radius difference ({(L_sim / L_e - 1) * 100:+.2f} %). S1002: the motion "
        f"grows from {y0 * 1e3:g} mm into a limit cycle of {amp * 1e3:.2f} mm (mean extreme) bounded by "
        f"flange contact at {f_sim:.3f} Hz; the kinematic frequency V/L at the equivalent conicity "
        f"{lam:.3f} of that amplitude (EN 15302, exact wavelength) is {V / L_eq:.3f} Hz: the limit "
        f"cycle with flange impacts is not the kinematic sinusoid (ratio {f_sim * L_eq / V:.3f}).\n\n"
        "References: Klingel (1883); Wickens (2003), Fundamentals of Rail Vehicle Dynamics, ch. 2; "
        "EN 15302; the flying wheelset of Simeon, Führer & Rentrop (1991).")
    return dict(tables={"cone_kinematic_wavelength": _units(cone_tab), "s1002_limit_cycle": _units(s1002_tab)},
                figures=figs, notes=notes)


# =============================================================================================
# 2. critical speed
# =============================================================================================
def linear_critical_speed(k_y=3e5, k_psi=3e5, xtol=1e-3):
    """The suspended wheelset (cone 1:40, Kalker linear), like for like.

    Core's eigenvalue critical speed of the multibody wheelset (Brent's method on the real part
    of the hunting mode), the same wheelset with the terms the classical two-degree-of-freedom
    model neglects switched off (:data:`railway.wheelset_models.TEXTBOOK`), and the closed forms
    of :class:`railway.hunting.LinearWheelset` from the rigid contact geometry and Hertz: complete
    (every term of :data:`railway.hunting.TERMS`) and classical (none).  Returns a dict.
    """
    from scipy.optimize import brentq

    from .hunting import TERMS
    from .two_point import conical_wheel
    from .wheelset_models import TEXTBOOK, eigen_critical_speed, hunting_mode, linear_wheelset, suspended_wheelset

    cone = conical_wheel()

    def real(V):
        return hunting_mode(suspended_wheelset(V, k_y, k_psi, wheel=cone, nominal_spin=True))[0]

    V_core = brentq(real, 20.0, 120.0, xtol=xtol)
    w_core = hunting_mode(suspended_wheelset(V_core, k_y, k_psi, wheel=cone, nominal_spin=True))[1]
    V_tb, w_tb = eigen_critical_speed(k_y, k_psi, (20.0, 120.0), wheel=cone, xtol=xtol, **TEXTBOOK)
    lw = linear_wheelset(k_y, k_psi, wheel=cone)
    V_cf, w_cf = lw.critical_speed()
    V_plain, w_plain = lw.critical_speed(**{t: False for t in TERMS})
    return dict(V_core=V_core, w_core=w_core, V_textbook=V_tb, w_textbook=w_tb, V_cf=V_cf, w_cf=w_cf,
                V_plain=V_plain, w_plain=w_plain, lam=lw.conicity, rho=lw.roll_per_lateral, f11=lw.f11,
                f22=lw.f22, l=lw.l, r0=lw.r0, k_y=k_y, k_psi=k_psi, real=real)


def run_down(law, V0=90.0, V1=40.0, rate=2.0, kick=0.008, definition=None, n_output_per_s=100,
             reseed_every=1):
    """A speed run-down of the vehicle on straight S1002 / UIC60 track from a hunting limit
    cycle: the car body is pulled at V(t) = V0 - rate t (speed control), all wheelsets start
    ``kick`` (m) off centre.  Returns (result, vehicle)."""
    from core.drivers import polynomial
    from core.integrators import simulate

    from .track import Track
    from .vehicle import VehicleDefinition, build_vehicle

    D = definition or VehicleDefinition.manchester()
    T = (V0 - V1) / rate
    track = Track.straight(V0 * T + 100.0)
    cl, cp = creep_law_spec(law, 0.5 * (V0 + V1))
    veh = build_vehicle(D, track, s0=30.0, speed=V0, creep_law=cl, creep_params=cp,
                        speed_control=polynomial([V0, -rate]), contact_options=dict(reseed_every=reseed_every))
    veh.preload()
    q0, v0 = veh.initial_state(wheelset_lateral=[kick] * 4)
    res = simulate(veh.model, (0.0, T), METHOD, q0=q0, v0=v0, rtol=RTOL, atol=RTOL * 1e-2,
                   n_output=int(T * n_output_per_s) + 1)
    return res, veh


def _envelope(res, veh, V0, rate, window=0.5):
    """Limit-cycle amplitude of the leading wheelset (max |y| over a sliding window) against the
    prescribed speed."""
    t = res.t
    y = np.abs(res.coordinates()[f"{veh.wheelsets[0]}.y [m]"].to_numpy())
    n = max(1, int(round(window / (t[1] - t[0]))))
    amp = np.array([y[max(0, k - n):k + 1].max() for k in range(len(t))])
    return V0 - rate * t, amp


#: hunting: the leading wheelset's lateral amplitude (max |y| over 0.5 s) above this (m)
HUNTING_AMPLITUDE = 0.5e-3


def _persists(law, res, veh, V_test, V0, rate, T_check=3.0, D=None):
    """Does the hunting limit cycle persist at the constant speed V_test?  The run starts from the
    run-down state at V_test; persists when the leading wheelset's amplitude over the last
    second is at least 0.8 times that over the first and above HUNTING_AMPLITUDE."""
    from core.integrators import simulate

    from .track import Track
    from .vehicle import build_vehicle

    k = int(np.argmin(np.abs((V0 - rate * res.t) - V_test)))
    q0, v0 = res.q[k], res.v[k]
    cl, cp = creep_law_spec(law, V_test)
    track = veh.track
    veh2 = build_vehicle(veh.definition, track, s0=veh.s0, speed=V_test, creep_law=cl, creep_params=cp,
                         speed_control=V_test)
    r = simulate(veh2.model, (res.t[k], res.t[k] + T_check), METHOD, q0=q0, v0=v0, rtol=RTOL,
                 atol=RTOL * 1e-2, n_output=int(T_check * 100) + 1)
    y = np.abs(r.coordinates()[f"{veh.wheelsets[0]}.y [m]"].to_numpy())
    n1 = len(y) // T_check if T_check >= 1 else len(y) // 2
    first, last = y[: int(n1)].max(), y[-int(n1):].max()
    return bool(r.success and last >= 0.8 * first and last > HUNTING_AMPLITUDE), r


def _run_critical(ctx):
    lin = linear_critical_speed()
    rows_lin = [{"quantity": "critical speed, eigenvalues of core's linearisation", "value": lin["V_core"],
                 "unit": "m/s"},
                {"quantity": "critical speed, complete linear wheelset (closed form, every term)",
                 "value": lin["V_cf"], "unit": "m/s"},
                {"quantity": "difference", "value": lin["V_core"] / lin["V_cf"] - 1.0, "unit": "-"},
                {"quantity": "critical speed, eigenvalues, classical model's terms only (TEXTBOOK)",
                 "value": lin["V_textbook"], "unit": "m/s"},
                {"quantity": "critical speed, classical two-degree-of-freedom closed form",
                 "value": lin["V_plain"], "unit": "m/s"},
                {"quantity": "difference (classical)", "value": lin["V_textbook"] / lin["V_plain"] - 1.0, "unit": "-"},
                {"quantity": "hunting frequency at V_c, eigenvalues", "value": lin["w_core"] / (2 * np.pi),
                 "unit": "Hz"},
                {"quantity": "hunting frequency at V_c, complete closed form", "value": lin["w_cf"] / (2 * np.pi),
                 "unit": "Hz"},
                {"quantity": "hunting frequency, eigenvalues (TEXTBOOK)", "value": lin["w_textbook"] / (2 * np.pi),
                 "unit": "Hz"},
                {"quantity": "hunting frequency, classical closed form", "value": lin["w_plain"] / (2 * np.pi),
                 "unit": "Hz"},
                {"quantity": "equivalent conicity (rigid table)", "value": lin["lam"], "unit": "-"},
                {"quantity": "roll per lateral displacement (rigid table)", "value": lin["rho"], "unit": "rad/m"},
                {"quantity": "f11 = G a b C11 (Hertz at the static load)", "value": lin["f11"], "unit": "N"},
                {"quantity": "f22 = G a b C22", "value": lin["f22"], "unit": "N"},
                {"quantity": "half contact spacing l", "value": lin["l"], "unit": "m"},
                {"quantity": "rolling radius r0", "value": lin["r0"], "unit": "m"},
                {"quantity": "lateral spring k_y", "value": lin["k_y"], "unit": "N/m"},
                {"quantity": "yaw spring k_psi", "value": lin["k_psi"], "unit": "N m/rad"}]
    Vg = np.linspace(0.6 * lin["V_core"], 1.3 * lin["V_core"], 8 if ctx.fast else 16)
    re_core = [lin["real"](V) for V in Vg]
    figs = {}
    fig, ax = _fig(size=(7, 3.8))
    ax = ax[0, 0]
    ax.plot(Vg, re_core, "o-", label="core: eigenvalues of the linearised model")
    from .two_point import conical_wheel
    from .wheelset_models import linear_wheelset

    lw = linear_wheelset(lin["k_y"], lin["k_psi"], wheel=conical_wheel())
    re_cf = []
    for V in Vg:
        M, C, K = lw.matrices(V)
        Am = np.block([[np.zeros((2, 2)), np.eye(2)], [-np.linalg.solve(M, K), -np.linalg.solve(M, C)]])
        re_cf.append(float(np.max(np.linalg.eigvals(Am).real)))
    ax.plot(Vg, re_cf, "--", label="complete linear wheelset (closed form, railway.hunting)")
    ax.axhline(0.0, c="k", lw=0.8)
    ax.set(xlabel="speed V [m/s]", ylabel="real part of the hunting eigenvalue [1/s]",
           title=f"railway-critical-speed — wheelset on springs (k_y = {lin['k_y']:.3g} N/m, k_psi = "
                 f"{lin['k_psi']:.3g} N m/rad), cone 1:40, Kalker linear\nV_c = {lin['V_core']:.3f} m/s "
                 f"(eigenvalues) vs {lin['V_cf']:.3f} m/s (closed form)")
    ax.title.set_fontsize(9)
    ax.legend(fontsize=8)
    ax.grid(True, alpha=0.3)
    figs["linear_critical_speed"] = fig

    # nonlinear critical speed of the coach, per creep law
    laws = ("polach2000",) if ctx.fast else CREEP_LAWS
    V0, V1, rate = (90.0, 60.0, 3.0) if ctx.fast else (90.0, 40.0, 2.0)
    rows, curves = [], {}
    for law in ctx.progress(laws, desc="run-down"):
        res, veh = run_down(law, V0=V0, V1=V1, rate=rate)
        Vt, amp = _envelope(res, veh, V0, rate)
        curves[law] = (Vt, amp, res)
        row = {"creep law": law, "status": res.status, "message": "" if res.status == "finished" else res.message}
        hunting = amp > HUNTING_AMPLITUDE
        # the run-down estimate: the lowest speed at which the leading wheelset still hunts;
        # then bisection of constant-speed runs started from the run-down's state: the decay
        # of the limit cycle lags the falling speed, so the bracket reaches 4 m/s above it
        # (widened upwards until hunting persists at its top)
        if res.success and hunting[: len(hunting) // 10].all() and not hunting.all():
            k = int(np.nonzero(hunting)[0].max())
            row["run-down estimate [m/s]"] = float(Vt[k])
            V_lo, V_hi = float(Vt[k]) - 1.0, min(float(Vt[k]) + 4.0, V0 - 1.0)
            n_runs = 0
            top_ok = True
            if not ctx.fast:
                while not (top_ok := _persists(law, res, veh, V_hi, V0, rate)[0]) and V_hi < V0 - 1.0:
                    V_lo, V_hi = V_hi, min(V_hi + 4.0, V0 - 1.0)
                    n_runs += 1
                n_runs += 1
                while top_ok and V_hi - V_lo > 0.1:
                    Vm = 0.5 * (V_hi + V_lo)
                    ok, _ = _persists(law, res, veh, Vm, V0, rate)
                    V_hi, V_lo = (Vm, V_lo) if ok else (V_hi, Vm)
                    n_runs += 1
            row["nonlinear critical speed [m/s]"] = 0.5 * (V_hi + V_lo) if top_ok else np.nan
            row["bracket [m/s]"] = (f"{V_lo:.3f} .. {V_hi:.3f}" if top_ok
                                    else f"no persisting limit cycle below {V0 - 1.0:g} m/s")
            row["constant-speed runs"] = n_runs
            row["amplitude at 1.1 V_nc [m]"] = float(np.interp(1.1 * row["nonlinear critical speed [m/s]"],
                                                               Vt[::-1], amp[::-1]))
        else:
            row["run-down estimate [m/s]"] = np.nan
            row["nonlinear critical speed [m/s]"] = np.nan
            row["bracket [m/s]"] = ("run failed" if not res.success else "hunting over the whole run-down"
                                    if hunting.all() else f"no limit cycle at {V0:g} m/s")
        rows.append(row)
    fig, ax = _fig(size=(7.5, 4.2))
    ax = ax[0, 0]
    for law, (Vt, amp, res) in curves.items():
        ax.plot(Vt, amp * 1e3, lw=1.2, label=f"{law} [{res.status}]")
    ax.set(xlabel="speed V [m/s] (run-down, decreasing)", ylabel="hunting amplitude, leading wheelset [mm]",
           title=f"railway-critical-speed — Manchester coach on S1002 / UIC60 1:40, run-down {V0:g} → {V1:g} m/s at "
                 f"{rate:g} m/s², {METHOD} rtol {RTOL:g}\nbifurcation diagram: limit-cycle amplitude (max |y| over 0.5 s)")
    ax.title.set_fontsize(9)
    ax.invert_xaxis()
    ax.legend(fontsize=8)
    ax.grid(True, alpha=0.3)
    figs["bifurcation"] = fig
    nonlin = pd.DataFrame(rows)
    notes = (
        f"Linear: a wheelset with conical wheels (1:40) held by a lateral spring and a yaw spring (two "
        f"longitudinal springs at ±1 m) to a frame driven at V, Kalker linear creep. Core's `linearize`/"
        f"`eigen` about steady running in the non-rotating wheelset formulation (nominal spin, "
        f"railway.wheel_rail) give V_c = {lin['V_core']:.3f} m/s (Brent's method on the hunting "
        f"eigenvalue's real part to 1 mm/s); the complete linear wheelset of railway.hunting "
        f"(LinearWheelset: equivalent conicity {lin['lam']:.5f} and roll {lin['rho']:.5f} rad/m of the "
        f"rigid contact-geometry table, Hertz creep coefficients at the static load, gyroscopic moment, "
        f"roll-rate creepage, gravitational stiffness, contact angle, spin creepage) gives "
        f"{lin['V_cf']:.3f} m/s ({(lin['V_core'] / lin['V_cf'] - 1) * 100:+.3f} %). Like for like with the "
        f"classical two-degree-of-freedom model: the multibody wheelset with those five terms switched off "
        f"(railway.wheelset_models.TEXTBOOK) gives {lin['V_textbook']:.3f} m/s against the classical closed "
        f"form's {lin['V_plain']:.3f} m/s ({(lin['V_textbook'] / lin['V_plain'] - 1) * 100:+.4f} %). "
        f"A linearisation of the absolute (spinning) formulation is not valid: its body frames turn with "
        f"the spin, so it is the snapshot of a periodic system.\n\n"
        f"Nonlinear: the Manchester coach (stand-in for the ML95 trailer) on straight track, all wheelsets "
        f"released 8 mm off centre at {V0:g} m/s (above the critical speed: the flange-bounded limit cycle "
        f"forms within the first second), speed lowered at {rate:g} m/s² by the speed control; the "
        f"nonlinear critical speed is the lowest speed at which the hunting limit cycle of the leading "
        f"wheelset persists: the run-down gives the speed where its amplitude (max |y| over 0.5 s) falls "
        f"below {HUNTING_AMPLITUDE * 1e3:g} mm, and bisection of 3 s constant-speed runs started from the "
        f"run-down's state refines it to 0.1 m/s (hunting persists when the last second's amplitude is at "
        f"least 0.8 times the first second's and above {HUNTING_AMPLITUDE * 1e3:g} mm). Polach 2005 uses the 'dry' parameter set (second-hand, see data/railway), FASTSIM "
        f"a 10 x 10 grid.\n\nReferences: Wickens (2003), ch. 2 and 6; Polach (2006), VSD 44 Suppl. "
        f"(nonlinear critical speed by run-down).")
    return dict(tables={"linear_critical_speed": pd.DataFrame(rows_lin), "nonlinear_critical_speed": _units(nonlin)},
                figures=figs, notes=notes)


# =============================================================================================
# 3. curving
# =============================================================================================
#: the curve: 200 m radius (left), cant 150 mm, 40 m clothoid transitions
CURVE = dict(radius=200.0, cant=0.150, transition=40.0, curve_length=200.0, lead=60.0, tail=100.0)


def curving_track(curve_length=None):
    """Straight, transition, the 200 m curve (cant 150 mm), transition, straight (module CURVE)."""
    from .track import Curve, Straight, Track, Transition

    c = CURVE
    return Track([Straight(c["lead"]), Transition(c["transition"]),
                  Curve(c["curve_length"] if curve_length is None else curve_length, c["radius"], cant=c["cant"]),
                  Transition(c["transition"]), Straight(c["tail"])])


def run_curving(law, V, T=None, definition=None, track=None, method=METHOD, rtol=RTOL, n_output_per_s=20,
                reseed_every=1, record_steps=False):
    """The coach through the curve at constant speed V (speed control); returns (result, vehicle).

    ``record_steps``: keep the state at every accepted step (``result.steps``) for the wheel
    events and peaks of :func:`railway.assessment.wheel_event_statistics`; the outputs and the
    step sequence are the same either way."""
    from core.integrators import simulate

    from .vehicle import VehicleDefinition, build_vehicle

    D = definition or VehicleDefinition.manchester()
    track = track or curving_track()
    cl, cp = creep_law_spec(law, V)
    veh = build_vehicle(D, track, s0=35.0, speed=V, creep_law=cl, creep_params=cp, speed_control=V,
                        contact_options=dict(reseed_every=reseed_every))
    veh.preload()
    q0, v0 = veh.initial_state()
    if T is None:  # until the car body is 30 m past the middle of the curve
        c = CURVE
        T = (c["lead"] + c["transition"] + 0.5 * c["curve_length"] + 30.0 - 35.0) / V
    res = simulate(veh.model, (0.0, T), method, q0=q0, v0=v0, rtol=rtol, atol=rtol * 1e-2,
                   n_output=int(T * n_output_per_s) + 1, record_steps=record_steps)
    return res, veh


def curve_window(H, curve_length=None):
    """Rows of a contact history at the times when every wheelset is in the full curve, at
    least 30 m from both transitions (quasi-static curving of the whole vehicle); the track of
    :func:`curving_track` with its curve ``curve_length`` long (default: the scene's)."""
    c = CURVE
    length = c["curve_length"] if curve_length is None else curve_length
    lo = c["lead"] + c["transition"] + 30.0
    hi = c["lead"] + c["transition"] + length - 30.0
    g = H.groupby("t [s]")["s [m]"]
    inside = (g.min() >= lo) & (g.max() <= hi)
    return H[H["t [s]"].isin(inside.index[inside.to_numpy()])]


def _run_curving(ctx):
    from .assessment import wheel_event_statistics
    from .vehicle import GRAVITY, VehicleDefinition
    from .wheel_rail import contact_history

    D = VehicleDefinition.manchester()
    laws = ("polach2000", "kalker_linear") if ctx.fast else CREEP_LAWS
    speeds = (10.0,) if ctx.fast else (10.0, 20.0)
    Q0 = D.total_mass * GRAVITY / 8.0
    qs_rows, eq_rows, ev_rows, runs = [], [], [], {}
    for V in speeds:
        for law in ctx.progress(laws, desc=f"curving {V:g} m/s"):
            T = None
            if ctx.fast:
                T = 8.0
            res, veh = run_curving(law, V, T=T, definition=D, record_steps=True)
            H = contact_history(veh.model, res)
            H["dQ/Q0 [-]"] = (Q0 - H["Q [N]"]) / Q0
            # wheel lift, peaks and Y/Q exceedances from every accepted step (Q = 0 located by
            # bisection), not from the 20 Hz outputs: they do not change with the output step
            Hs = contact_history(veh.model, res, at="steps")
            ev = wheel_event_statistics(Hs, output_times=res.t, warn=False)
            s_of = {w: g for w, g in Hs.groupby("wheel", sort=False)}
            ev.insert(1, "lift-off first, s [m]", [
                float(np.interp(t0, s_of[w]["t [s]"], s_of[w]["s [m]"])) if np.isfinite(t0) else np.nan
                for w, t0 in zip(ev["wheel"], ev["lift-off first [s]"])])
            for _, r in ev.iterrows():
                ev_rows.append({"speed [m/s]": V, "creep law": law, "status": res.status, **r.to_dict()})
            runs[(law, V)] = (res, veh, H, ev)
            W = curve_window(H)
            base = {"speed [m/s]": V, "creep law": law, "status": res.status}
            if res.status == "failed":
                base["message"] = res.message
            if len(W) == 0:
                qs_rows.append(dict(base, wheel="(no full-curve rows)"))
                continue
            g = W.groupby("wheel", sort=False)
            cols = ["Q [N]", "Y [N]", "Y/Q [-]", "sum Y [N]", "flange force [N]", "dQ/Q0 [-]",
                    "lateral displacement [m]", "angle of attack [rad]", "contact angle [rad]", "Nadal limit [-]",
                    "T gamma [N]", "xi_tread [-]", "eta_tread [-]", "phi_tread [1/m]", "Fx_tread [N]", "Fy_tread [N]",
                    "Fx_flange [N]", "Fy_flange [N]", "p_max [Pa]"]
            mean = g[cols].mean()
            mean["flange contact [-]"] = g["flange contact"].mean()
            for wheel, r in mean.iterrows():
                qs_rows.append(dict(base, wheel=wheel, **r.to_dict()))
            # lateral equilibrium over the vehicle in the full curve: rail forces against
            # m (a_c - g) . n in the canted track plane
            t_in = np.unique(W["t [s]"])
            if len(t_in) >= 3 and res.success:
                Htin = W
                sumY = Htin.groupby("t [s]")["sum Y [N]"].sum() / 2.0  # sum Y repeated on both wheels
                tr = veh.track
                sc = 0.5 * (CURVE["lead"] + CURVE["transition"] + 30.0
                            + CURVE["lead"] + CURVE["transition"] + CURVE["curve_length"] - 30.0)
                fr = tr.evaluate(np.array([sc]))
                n = fr.R[0][:, 1]
                kappa = 1.0 / CURVE["radius"]
                Vm = float(Htin["speed [m/s]"].mean())
                # the centre of the (left) curve in the horizontal plane: the heading turned left
                t_h = fr.R[0][:, 0]
                c_dir = np.array([-t_h[1], t_h[0], 0.0]) / np.hypot(t_h[0], t_h[1])
                a_c = Vm**2 * kappa * c_dir
                need = D.total_mass * (a_c - np.array([0.0, 0.0, -GRAVITY])) @ n
                got = float(-sumY.mean())
                eq_rows.append({"speed [m/s]": V, "creep law": law, "mean speed [m/s]": Vm,
                                "rail forces on the vehicle along the track's lateral axis [N]": got,
                                "m (a_c - g) . n [N]": need, "relative difference [-]": got / need - 1.0,
                                "unbalanced lateral acceleration [m/s2]": need / D.total_mass,
                                "std of the rail forces [N]": float(sumY.std()),
                                "quasi-static": bool(sumY.std() < 0.05 * abs(need))})
    qs = pd.DataFrame(qs_rows)
    eq = pd.DataFrame(eq_rows)
    figs = {}
    for V in speeds:
        fig, ax = _fig(2, 1, size=(8, 6))
        for law in laws:
            res, veh, H, _ = runs[(law, V)]
            lead = H[H["wheel"] == f"{veh.wheelsets[0]} right"]
            ax[0, 0].plot(lead["s [m]"], lead["flange force [N]"] * 1e-3, lw=1, label=f"{law} [{res.status}]")
            ax[1, 0].plot(lead["s [m]"], lead["lateral displacement [m]"] * 1e3, lw=1, label=law)
        c = CURVE
        for a in ax[:, 0]:
            for s_ in (c["lead"], c["lead"] + c["transition"], c["lead"] + c["transition"] + c["curve_length"]):
                a.axvline(s_, ls=":", c="k", lw=0.7)
            a.grid(True, alpha=0.3)
        ax[0, 0].set(ylabel="flange force [kN]\n(leading outer wheel)",
                     title=f"railway-curving — Manchester coach, R = {c['radius']:g} m, cant {c['cant'] * 1e3:g} mm, "
                           f"V = {V:g} m/s, {METHOD} rtol {RTOL:g}\nleading wheelset (dotted: transition, full curve)")
        ax[0, 0].title.set_fontsize(9)
        ax[0, 0].legend(fontsize=7)
        ax[1, 0].set(xlabel="track arc length of the leading wheelset [m]",
                     ylabel="lateral displacement [mm]\n(leading wheelset)")
        figs[f"leading_wheelset_{int(V)}ms"] = fig
        # Q of the leading wheels: lift-off
        fig, ax = _fig(size=(8, 3.6))
        ax = ax[0, 0]
        for law in laws:
            res, veh, H, _ = runs[(law, V)]
            for side, ls in (("left", "--"), ("right", "-")):
                w = H[H["wheel"] == f"{veh.wheelsets[0]} {side}"]
                ax.plot(w["s [m]"], w["Q [N]"] * 1e-3, ls, lw=0.9, label=f"{law} {side}")
        ax.set(xlabel="track arc length of the leading wheelset [m]", ylabel="wheel load Q [kN]",
               title=f"railway-curving — wheel loads of the leading wheelset (left = inner), V = {V:g} m/s")
        ax.title.set_fontsize(9)
        ax.legend(fontsize=6, ncol=2)
        ax.grid(True, alpha=0.3)
        figs[f"leading_wheel_loads_{int(V)}ms"] = fig
    lifted = []
    for (law, V), (res, veh, H, ev) in runs.items():
        for side, where in (("left", "inner"), ("right", "outer")):
            r = ev[ev["wheel"] == f"{veh.wheelsets[0]} {side}"].iloc[0]
            if r["lifts"] > 0:
                n = int(r["lifts"])
                lifted.append(f"{where} wheel with {law} at {V:g} m/s (first at s = "
                              f"{r['lift-off first, s [m]']:.1f} m, t = {r['lift-off first [s]']:.4f} s; "
                              f"{n} lift{'s' if n > 1 else ''}, {r['lifted [s]'] * 1e3:.3g} ms in all, shortest "
                              f"{r['shortest lift [s]'] * 1e3:.3g} ms; {int(r['lifts between outputs'])} of them "
                              f"between two {1e3 * float(np.max(np.diff(res.t))):.0f} ms outputs)")
    c = CURVE
    nq = eq[~eq["quasi-static"].astype(bool)] if len(eq) and "quasi-static" in eq else eq.iloc[0:0]
    not_qs = ", ".join(f"{r['creep law']} at {r['speed [m/s]']:g} m/s" for _, r in nq.iterrows()) or "none"
    notes = (
        f"The Manchester benchmark coach (data/railway/vehicles/manchester_coach.toml; stand-in for the "
        f"ML95 metro trailer of Pombo & Ambrosio, whose data are not public) through a left curve of "
        f"radius {c['radius']:g} m with {c['cant'] * 1e3:g} mm cant and {c['transition']:g} m clothoid "
        f"transitions (cant ramped linearly). Cant choice: 150 mm puts the equilibrium speed "
        f"sqrt(g R h / 1.5 m) = {np.sqrt(9.81 * c['radius'] * c['cant'] / 1.5):.1f} m/s between the two "
        f"scene speeds, so 10 m/s runs with cant excess and 20 m/s with cant deficiency. The car body is "
        f"held at the speed by a proportional speed control (the train's pull). Quasi-static table: means "
        f"over the output times at which every wheelset is in the full curve at least 30 m from both "
        f"transitions. Lateral "
        f"equilibrium: the rail forces on the whole vehicle along the track's lateral axis against "
        f"m (a_c - g) . n (centripetal acceleration and gravity in the canted plane). Wheel lift (Q = 0) "
        f"of the leading wheelset (from every accepted step, the lift located by bisection to 0.1 us; "
        f"table wheel_events, all wheels): {'; '.join(lifted) if lifted else 'none'}. Kalker's linear law "
        f"does not saturate: in the curve its creep forces exceed mu N many times, which is what unloads (or "
        f"lifts) the wheels in the paper's Kalker-linear results; the saturating laws keep Y/Q of the "
        f"inner wheel near mu. Flange contact flag: contact angle above 45 deg. A row of the lateral "
        f"equilibrium table is 'quasi-static' when the standard deviation of the rail forces over the "
        f"window is below 5 % of m (a_c - g) . n; rows that are not: {not_qs}. There a wheelset keeps "
        f"moving on a contact jump of the S1002 tread and the means over the outputs are not a steady "
        f"state; such rows are not results to quote (README, Railway vehicles)."
        f"\n\nReferences: Pombo & "
        f"Ambrosio (2008), Multibody Syst. Dyn. 19:91-114 (curving of the ML95 trailer, not available "
        f"here); Nadal (1908); Wickens (2003), ch. 7.")
    events = pd.DataFrame(ev_rows)
    events.attrs["source"] = ("every accepted step of each run (railway.assessment.wheel_event_statistics); "
                              "'lifts between outputs': lifts no output time falls in")
    tables = {"curving_quasi_static": _units(qs), "lateral_equilibrium": _units(eq), "wheel_events": _units(events)}
    return dict(tables=tables, figures=figs, notes=notes)


# =============================================================================================
# 4. irregular track
# =============================================================================================
#: One-sided PSD of track irregularities, S(Ω) = A Ω_c² / ((Ω² + Ω_r²)(Ω² + Ω_c²)) [m² / (rad/m)]:
#: the form and "low level" parameters of ORE B176 / ERRI as quoted in the vehicle-dynamics
#: literature; NOT checked against the ORE report in this project (data/railway/README.md).
PSD = dict(A_lateral=2.119e-7, A_vertical=4.032e-7, omega_c=0.8246, omega_r=0.0206)


def irregularities(length, seed=1, wavelengths=(3.0, 70.0), dx=0.25, level=1.0):
    """Lateral and vertical irregularities (m) sampled from :data:`PSD` by a sum of harmonics
    with random phases (``np.random.default_rng(seed)``), band-limited to ``wavelengths`` (m),
    tapered to zero over 20 m at both ends."""
    from .track import Irregularities

    rng = np.random.default_rng(seed)
    s = np.arange(0.0, length + dx / 2, dx)
    Om = np.linspace(2 * np.pi / wavelengths[1], 2 * np.pi / wavelengths[0], 400)
    dOm = Om[1] - Om[0]
    out = []
    for key in ("A_lateral", "A_vertical"):
        S = PSD[key] * PSD["omega_c"] ** 2 / ((Om**2 + PSD["omega_r"] ** 2) * (Om**2 + PSD["omega_c"] ** 2))
        amp = np.sqrt(2.0 * S * dOm) * level
        ph = rng.uniform(0, 2 * np.pi, Om.size)
        out.append(np.sum(amp[None, :] * np.cos(Om[None, :] * s[:, None] + ph[None, :]), axis=1))
    taper = np.clip(np.minimum(s, length - s) / 20.0, 0.0, 1.0)
    return Irregularities(s, out[0] * taper, out[1] * taper)


def irregular_case(case):
    """One speed of the sweep (module-level so that process pools can run it): the coach over
    ``case['length']`` m of irregular straight track; returns a row dict and the spectra."""
    from scipy.signal import welch

    from core.integrators import simulate

    from .track import Track
    from .vehicle import GRAVITY, VehicleDefinition, build_vehicle
    from core.errors import InputError

    from .assessment import wheel_event_statistics, wheel_force_statistics
    from .wheel_rail import contact_history

    V, length, law = case["speed"], case["length"], case.get("law", "polach2000")
    D = VehicleDefinition.manchester()
    irr = irregularities(length + 60.0, seed=case.get("seed", 1))
    track = Track.straight(length + 60.0, irregularities=irr)
    cl, cp = creep_law_spec(law, V)
    veh = build_vehicle(D, track, s0=20.0, speed=V, creep_law=cl, creep_params=cp, speed_control=V)
    veh.preload()
    q0, v0 = veh.initial_state()
    T = (length - 20.0) / V
    fs, fs_force = 200.0, 1000.0  # car-body accelerations; wheel forces (the ~200 Hz bounce resolved)
    sub = int(round(fs_force / fs))
    res = simulate(veh.model, (0.0, T), METHOD, q0=q0, v0=v0, rtol=RTOL, atol=RTOL * 1e-2,
                   n_output=int(T * fs) * sub + 1, record_steps=True)
    t_acc = res.t[::sub]
    Vel = res.velocities()
    acc_y = np.gradient(Vel[f"{veh.car_body}.vy [m/s]"].to_numpy()[::sub], t_acc)
    acc_z = np.gradient(Vel[f"{veh.car_body}.vz [m/s]"].to_numpy()[::sub], t_acc)
    t_skip = min(2.0, 0.25 * T)  # the start transient
    keep = t_acc >= t_skip
    f, Py = welch(acc_y[keep], fs=fs, nperseg=min(1024, int(keep.sum())))
    _, Pz = welch(acc_z[keep], fs=fs, nperseg=min(1024, int(keep.sum())))
    # wheel forces as the run applied them, at 1 kHz; filtered and as percentiles as a track test
    # evaluates them (railway.assessment.wheel_force_statistics): raw extremes of a force that
    # carries the wheelsets' bounce are samples of that oscillation, not a statistic
    H = contact_history(veh.model, res)
    H = H[H["t [s]"] >= t_skip]
    # the unfiltered extremes and wheel lift from every accepted step (railway.assessment.
    # wheel_event_statistics), not from the 1 kHz samples of the bounce
    Hs = contact_history(veh.model, res, at="steps")
    E = wheel_event_statistics(Hs[Hs["t [s]"] >= t_skip], warn=False)
    Q0 = D.total_mass * GRAVITY / 8.0
    try:
        W = wheel_force_statistics(H)
        note = ""
    except InputError as exc:  # e.g. a run that failed before a 2 m window of signal: keep its row
        cols = ["Q high [N]", "Q low [N]", "Q max, unfiltered [N]", "Q min, unfiltered [N]", "|Y| high [N]",
                "(Y/Q) 2 m high [-]", "(sum Y) 2 m high [N]"]
        W = pd.DataFrame([{c: np.nan for c in cols}])
        note = f"no wheel-force statistics: {exc}"
    row = {"speed [m/s]": V, "creep law": law, "status": res.status,
           "car body lateral acceleration rms [m/s2]": float(np.sqrt(np.mean(acc_y[keep] ** 2))),
           "car body vertical acceleration rms [m/s2]": float(np.sqrt(np.mean(acc_z[keep] ** 2))),
           "car body lateral acceleration max [m/s2]": float(np.max(np.abs(acc_y[keep]))),
           "car body vertical acceleration max [m/s2]": float(np.max(np.abs(acc_z[keep]))),
           "Q high, 20 Hz [N]": float(W["Q high [N]"].max()), "Q low, 20 Hz [N]": float(W["Q low [N]"].min()),
           "dQ/Q0 high, 20 Hz [-]": float((Q0 - W["Q low [N]"].min()) / Q0),
           "Q max, unfiltered [N]": float(E["Q max [N]"].max()),
           "Q min, unfiltered [N]": float(E["Q min [N]"].min()),
           "wheels lifted": int((E["lifts"] > 0).sum()), "lifted, longest wheel [s]": float(E["lifted [s]"].max()),
           "|Y| high, 20 Hz [N]": float(W["|Y| high [N]"].max()),
           "(Y/Q) 2 m high [-]": float(W["(Y/Q) 2 m high [-]"].max()),
           "(sum Y) 2 m high [N]": float(W["(sum Y) 2 m high [N]"].max()), "n_rhs": res.counters["n_rhs"],
           "message": "; ".join(m for m in (res.message if not res.success else "", note) if m)}
    return row, (f, Py, Pz)


def _run_irregular(ctx):
    from core.sweep import run_sweep

    speeds = (30.0,) if ctx.fast else (20.0, 30.0, 40.0)
    length = 120.0 if ctx.fast else 320.0
    cases = [dict(speed=V, length=length, law="polach2000", seed=1) for V in speeds]
    out = run_sweep(irregular_case, cases, executor=ctx.executor)
    table = pd.DataFrame([r for r, _ in out])
    fig, ax = _fig(2, 1, size=(7.5, 6))
    for (row, (f, Py, Pz)) in out:
        ax[0, 0].semilogy(f, Py, lw=1, label=f"{row['speed [m/s]']:g} m/s")
        ax[1, 0].semilogy(f, Pz, lw=1, label=f"{row['speed [m/s]']:g} m/s")
    ax[0, 0].set(ylabel="lateral PSD [(m/s2)^2/Hz]",
                 title=f"railway-irregular-track — Manchester coach on straight track with ORE B176 low-level "
                       f"irregularities (wavelengths 3-70 m), Polach 2000, {METHOD} rtol {RTOL:g}\ncar-body "
                       f"acceleration spectra at the centre of mass (Welch)")
    ax[0, 0].title.set_fontsize(9)
    ax[1, 0].set(xlabel="frequency [Hz]", ylabel="vertical PSD [(m/s2)^2/Hz]")
    for a in ax[:, 0]:
        a.set_xlim(0, 30)
        a.grid(True, alpha=0.3)
        a.legend(fontsize=8)
    notes = (
        f"The coach on {length:g} m of straight track whose centreline carries lateral (alignment) and "
        f"vertical (level) irregularities sampled from the ORE B176 low-level spectrum (form and "
        f"parameters as quoted in the literature, not checked against the ORE report; harmonics with "
        f"random phases, seed 1, wavelengths 3-70 m, tapered over 20 m at the ends), at "
        f"{', '.join(f'{v:g}' for v in speeds)} m/s, Polach 2000. The speed sweep runs through "
        f"core.sweep.run_sweep (serial by default; `mbsuite run ... --workers N` or `--dask ADDRESS` "
        f"give the same table: tests/railway/test_vehicle_scenes.py). Car-body accelerations from the "
        f"centre-of-mass velocities (200 Hz output) after a 2 s start transient. Wheel forces at 1 kHz "
        f"(the wheelsets bounce on the Hertz springs at about 200 Hz), those the run applied "
        f"(railway.wheel_rail.contact_history replays the contact search state along the run), "
        f"evaluated as a track test does (EN 14363 / UIC 518 processing as quoted second-hand, "
        f"railway.assessment): Q low-pass 20 Hz, its 99.85 % ('high') and 0.15 % ('low') percentiles "
        f"over the wheels; |Y| at 20 Hz, 99.85 %; Y/Q and sum Y as 2 m sliding means every 0.5 m, "
        f"99.85 %. The unfiltered extremes of Q and the wheel lift (Q = 0) are taken from every accepted "
        f"step of the run (railway.assessment.wheel_event_statistics), not from the 1 kHz outputs; the "
        f"extremes are peaks of the bounce and change from run to run with the rounding (README, "
        f"Railway vehicles).")
    return dict(tables={"irregular_track": _units(table)}, figures={"carbody_acceleration_spectra": fig}, notes=notes)


# =============================================================================================
def _wrap(fn):
    def run(ctx):
        from core.scenes import SceneResult

        return SceneResult(**fn(ctx))

    return run


def vehicle_scenes():
    """The railway vehicle scenes (registered with railway.scenes.railway_scenes)."""
    from core.scenes import Scene

    return [
        Scene("railway-flying-wheelset",
              "Free (flying) wheelset: Klingel wavelength of a cone, S1002 limit cycle",
              "A free wheelset released with a lateral offset: kinematic wavelength of conical wheels "
              "against Klingel; S1002/UIC60 growth into a flange-bounded limit cycle against V/L at the "
              "equivalent conicity (Klingel 1883; Wickens 2003, ch. 2).", _wrap(_run_flying)),
        Scene("railway-critical-speed",
              "Critical speed: suspended wheelset eigenvalues vs closed form; vehicle run-down per creep law",
              "Linear critical speed of a wheelset on springs from core's eigenvalues against the closed "
              "form; nonlinear critical speed of the Manchester coach by a run-down from a hunting limit "
              "cycle, each creep law, bifurcation diagram.", _wrap(_run_critical)),
        Scene("railway-curving",
              "Manchester coach through a 200 m curve at 10 and 20 m/s, every creep law",
              "Curving of the stand-in for the ML95 metro trailer (Pombo & Ambrosio 2008): Q, Y, Y/Q, "
              "sum Y, flange force, dQ/Q0, displacement, angle of attack, creepages, T gamma, Nadal "
              "limit; lateral equilibrium in the full curve.", _wrap(_run_curving)),
        Scene("railway-irregular-track",
              "Manchester coach on irregular straight track: car-body accelerations and wheel forces",
              "ORE B176 low-level irregularities, speed sweep through core.sweep: car-body acceleration "
              "r.m.s. and spectra, wheel forces.", _wrap(_run_irregular)),
    ]
