"""
SAR antenna unfolding: rigid and flexible panels
================================================

A satellite unfolds its synthetic-aperture-radar antenna: three panels, stowed accordion-wise
against one face of the bus, turn about parallel hinges into a straight 6 m antenna.  Each hinge
has an actuator that drives its angle by the cycloidal rest-to-rest law, then holds it.  The
example follows Anantharaman & Hiller (Int. J. Numer. Meth. Eng. 32 (1991) 1531–1542) and the
flexible variant in Ambrósio's review (its Figs 27–28), where the rigid model mispredicts the
actuator moments.

**Every number of the model is assumed** (their data are not public):
:data:`core.flexible.models.SAR_ANTENNA` lists them.  The bus floats free: no gravity and no
external force, so the bus turns as the antenna unfolds, and the model's total momentum must stay
zero.

The actuator moment is the Lagrange multiplier of the hinge's angle driver: the moment on the
outboard panel.  A flexible panel is a floating-frame body (:mod:`core.flexible.body`).  Its frame is
clamped at the root hinge.  Its modes are Craig–Bampton's: two static constraint modes of the tip
hinge (transverse translation and rotation), plus fixed-interface modes.

What is computed:

* the panel's reduced frequencies against the Euler–Bernoulli closed form;
* one panel on a fixed base against an independent model: the exact cantilever modes, integrated by
  scipy;
* the deployment in orbit, rigid against flexible panels: actuator moments, panel deflections, the
  bus attitude and the momentum check;
* the deployment time below which the flexible actuator moments exceed the rigid ones by 10 %,
  bracketed by two independent single-cantilever estimates (bisected with ``--full``).

This script is the scene ``sar-antenna``: ``mbsuite run sar-antenna`` runs this very file.
"""

# %%
# The assumed data
# ----------------
import time

import numpy as np
import pandas as pd
from scipy.optimize import brentq

from core.drivers import cycloidal
from core.flexible import FEModel, craig_bampton, straight_beam
from core.flexible.models import (SAR_ANTENNA, cantilever_roots, driven_cantilever, momenta, panel_tip_deflection,
                                  sar_antenna, sar_antenna_section)
from core.integrators import simulate
from core.scenes import scene_run

scene = scene_run("sar-antenna")
# every run: Radau IIA with coordinate projection on the compiled path (the flexible panels are mass
# groups there, core.flexible.compiled)
METHOD = "jit-radau-projection"
p = SAR_ANTENNA
L, mu, EI = p["panel_length"], p["mass_per_length"], p["EI"]
data = pd.DataFrame([
    ("bus mass [kg]", p["bus_mass"]), ("bus moment of inertia about the hinge axis [kg m²]", p["bus_inertia"]),
    ("hinge face from the bus centre [m]", p["bus_face"]), ("panels", p["n_panels"]),
    ("panel length, hinge to hinge [m]", L), ("panel width along the hinge [m]", p["panel_width"]),
    ("panel sandwich thickness [m]", p["panel_thickness"]), ("panel mass per length [kg/m]", mu),
    ("panel bending stiffness EI [N m²]", EI), ("modal damping ratio [-]", p["damping_ratio"]),
    ("nominal deployment time [s]", p["deployment_time"])], columns=["quantity", "value (assumed)"])
scene.table("data", data)

# %%
# The panel's modes
# -----------------
# The reduced panel (8 Euler–Bernoulli elements, frame clamped at the root hinge) against the
# clamped–free closed form f_k = (β_k L)² √(EI/μ) / (2π L²).  The two static constraint modes of
# the tip hinge already give the first cantilever mode to 0.1 %.
beta_L = cantilever_roots(3)
closed = beta_L**2 * np.sqrt(EI / mu) / (2 * np.pi * L**2)
fe = FEModel.from_beam(straight_beam(L, 8, dim=2), sar_antenna_section())
rows = []
for n_fixed in (0, 1, 2):
    f = craig_bampton(fe.M, fe.K, fe.dofs(8, [1, 2]), n_fixed, fixed_dofs=fe.dofs(0)).orthonormalized().frequencies()
    row = {"fixed-interface modes": n_fixed, "modal coordinates": f.size}
    for k in range(2):
        row[f"f{k + 1} [Hz]"] = f[k]
        row[f"f{k + 1} closed form [Hz]"] = closed[k]
        row[f"f{k + 1} error [%]"] = 100 * (f[k] / closed[k] - 1)
    row["highest [Hz]"] = f[-1]
    rows.append(row)
scene.table("panel_modes", pd.DataFrame(rows))

# %%
# One panel on a fixed base against the exact cantilever modes
# -------------------------------------------------------------
# A fast unfolding (π/2 in 2 s) of one panel whose bus is held.  The reference
# (:func:`core.flexible.models.driven_cantilever`) uses the exact Euler–Bernoulli cantilever modes,
# linear in the deflection, without the centrifugal terms θ̇² (at most (θ̇/ω₁)² = 1.6e-3 here).
T1 = 2.0
t1 = np.linspace(0.0, 2 * T1, 401)
single = {"t [s]": t1}
for flexible in (False, True):
    model = sar_antenna(flexible=flexible, n_panels=1, bus="fixed", deployment_time=T1)
    res = simulate(model, (0.0, 2 * T1), METHOD, rtol=1e-6, atol=1e-8, t_eval=t1)
    if res.status != "finished":  # a partial or doubtful record would make a wrong comparison
        raise RuntimeError(f"the single-panel run ({model.name}) ended '{res.status}': {res.message}")
    kind = "flexible" if flexible else "rigid"
    single[f"moment, {kind} [N m]"] = res.reactions_table("actuator1")["Mz [N m]"].to_numpy()
    if flexible:
        single["tip deflection, flexible [mm]"] = 1e3 * panel_tip_deflection(model, res.q, "panel1")
ref_moment, ref_tip = driven_cantilever(cycloidal(-np.pi / 2, T1), t1, L, mu, EI, p["damping_ratio"], n_modes=6)
single["moment, exact modes [N m]"] = ref_moment
single["tip deflection, exact modes [mm]"] = 1e3 * ref_tip
single = scene.table("single_panel", pd.DataFrame(single))
peak_m, peak_d = np.abs(ref_moment).max(), np.abs(1e3 * ref_tip).max()
single_check = scene.table("single_panel_check", pd.DataFrame([{
    "peak moment, exact modes [N m]": peak_m,
    "max |moment − exact| / peak [%]": 100 * np.abs(single["moment, flexible [N m]"] - ref_moment).max() / peak_m,
    "max |rigid − exact| / peak [%]": 100 * np.abs(single["moment, rigid [N m]"] - ref_moment).max() / peak_m,
    "peak tip deflection, exact modes [mm]": peak_d,
    "max |tip − exact| / peak [%]":
        100 * np.abs(single["tip deflection, flexible [mm]"] - 1e3 * ref_tip).max() / peak_d,
}]))
single_check

# %%
# The deployment in orbit, rigid against flexible panels
# ------------------------------------------------------
# The nominal deployment (10 s) and a fast one (3 s), each followed by half its duration with the
# hinges held.  Radau IIA with coordinate projection at rtol 1e-5 (the modes reach 190 Hz), on the
# compiled path (the panels are mass groups: core.flexible.compiled).
durations = (3.0,) if scene.fast else (3.0, p["deployment_time"])
actuators = [f"actuator{k + 1}" for k in range(p["n_panels"])]
panels = [f"panel{k + 1}" for k in range(p["n_panels"])]


def deploy(flexible, T, n_modes=1, n_output=601):
    """One deployment run: the model, its result and its wall time.  A run that did not finish
    cleanly stops the scene, saying where: its peaks would be those of a partial record."""
    model = sar_antenna(flexible=flexible, deployment_time=T, n_modes=n_modes)
    t0 = time.perf_counter()
    res = simulate(model, (0.0, 1.5 * T), METHOD, rtol=1e-5, atol=1e-7,
                   t_eval=np.linspace(0.0, 1.5 * T, n_output))
    if res.status != "finished":
        raise RuntimeError(f"the deployment of {model.name} in {T:g} s ended '{res.status}': {res.message}")
    return model, res, time.perf_counter() - t0


def moments(res):
    return np.column_stack([res.reactions_table(a)["Mz [N m]"].to_numpy() for a in actuators])


def peak_excess(T):
    """Largest peak actuator moment, flexible over rigid, minus one (over all actuators)."""
    peaks = [np.abs(moments(deploy(flexible, T)[1])).max(axis=0) for flexible in (False, True)]
    return float(np.max(peaks[1] / peaks[0]) - 1.0)


rows, runs, histories = [], [], {}
for T in scene.progress(durations, desc="deployments"):
    out = {}
    for flexible in (False, True):
        model, res, wall = deploy(flexible, T)
        kind = "flexible" if flexible else "rigid"
        runs.append(res.summary_row(f"{kind} panels, deployment {T:g} s", {"wall [s]": wall}))
        H = momenta(model, res.q, res.v)
        bus_spin = p["bus_inertia"] * np.abs(res.v[:, model.q_slice("bus")][:, 2]).max()
        out[kind] = dict(t=res.t, M=moments(res), bus=res.q[:, model.q_slice("bus")][:, 2],
                         tips=np.column_stack([panel_tip_deflection(model, res.q, s) for s in panels]) if flexible
                         else None, momentum=np.abs(H[:, 2]).max() / bus_spin,
                         antenna_tip=model.point_position(res.q, f"{panels[-1]}.tip" if flexible else panels[-1],
                                                          (0.0, 0.0) if flexible else (L / 2, 0.0)))
    r, f = out["rigid"], out["flexible"]
    after = r["t"] > T
    common = {"bus attitude change, rigid [deg]": np.degrees(r["bus"][-1] - r["bus"][0]),
              "bus attitude change, flexible [deg]": np.degrees(f["bus"][-1] - f["bus"][0]),
              "antenna tip, flexible − rigid at the end [mm]":
                  1e3 * np.linalg.norm(f["antenna_tip"][-1] - r["antenna_tip"][-1]),
              "max |H| / bus's peak J ω, rigid [-]": r["momentum"],
              "max |H| / bus's peak J ω, flexible [-]": f["momentum"]}
    for k, a in enumerate(actuators):
        peak_r, peak_f = np.abs(r["M"][:, k]).max(), np.abs(f["M"][:, k]).max()
        rows.append({"deployment [s]": T, "actuator": a, "peak moment, rigid [N m]": peak_r,
                     "peak moment, flexible [N m]": peak_f, "peak excess [%]": 100 * (peak_f / peak_r - 1),
                     "max |flexible − rigid| / rigid peak [%]":
                         100 * np.abs(f["M"][:, k] - r["M"][:, k]).max() / peak_r,
                     "held-hinge moment after deployment, flexible [N m]": np.abs(f["M"][after, k]).max(),
                     "peak tip deflection of the panel [mm]": 1e3 * np.abs(f["tips"][:, k]).max(), **common})
    histories[T] = out
deployment = scene.table("deployment", pd.DataFrame(rows))
scene.table("runs", pd.DataFrame(runs))
deployment

if scene.full:  # the same fast deployment with two fixed-interface modes per panel
    model2, res2, wall2 = deploy(True, 3.0, n_modes=2)
    M1, M2 = histories[3.0]["flexible"]["M"], moments(res2)
    scene.table("mode_convergence", pd.DataFrame([{
        "actuator": a, "peak moment, 1 fixed-interface mode [N m]": np.abs(M1[:, k]).max(),
        "peak moment, 2 fixed-interface modes [N m]": np.abs(M2[:, k]).max(),
        "max |difference| / peak [%]": 100 * np.abs(M2[:, k] - M1[:, k]).max() / np.abs(M2[:, k]).max(),
        "wall, 2 modes [s]": wall2} for k, a in enumerate(actuators)]))

# %%
# Figures: actuator moments and panel deflections
# ------------------------------------------------
import matplotlib.pyplot as plt  # noqa: E402

for T, out in histories.items():
    fig, axes = plt.subplots(2, 1, figsize=(7.0, 6.5), sharex=True)
    for k, a in enumerate(actuators):
        line, = axes[0].plot(out["flexible"]["t"], out["flexible"]["M"][:, k], label=f"{a}, flexible")
        axes[0].plot(out["rigid"]["t"], out["rigid"]["M"][:, k], "--", color=line.get_color(), label=f"{a}, rigid")
        axes[1].plot(out["flexible"]["t"], 1e3 * out["flexible"]["tips"][:, k], color=line.get_color(),
                     label=f"{panels[k]} tip")
    for ax in axes:
        ax.axvline(T, color="0.6", lw=0.8)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7, ncol=2)
    axes[0].set_ylabel("actuator moment on the panel [N m]")
    axes[1].set_ylabel("panel tip deflection [mm]")
    axes[1].set_xlabel("t [s]")
    axes[0].set_title(f"SAR antenna unfolding in {T:g} s (assumed data): rigid (dashed) and flexible panels")
    fig.tight_layout()
    scene.figure(f"deployment_{T:g}s", fig)

# %%
# When the flexibility matters
# ----------------------------
# The peak excess falls as the deployment slows, not quite monotonically: a cycloidal move leaves
# almost no residual vibration when it lasts a whole number of the structure's periods.  The
# criterion is the longest deployment time at which the largest peak excess still reaches 10 %.
# Two single cantilevers bracket it: one stowed panel (2 m, 5.6 Hz), and the deployed antenna as
# one 6 m cantilever on a held bus (0.62 Hz).  Both use the exact modes (driven_cantilever) and the
# same criterion.  ``--full`` finds it for the full model on a grid from 15 s down and bisects it to
# 0.01 s.
THRESHOLD = 0.10


def cantilever_excess(T, length):
    t = np.linspace(0.0, 1.5 * T, 3001)
    law = cycloidal(1.0, T)
    moment, _ = driven_cantilever(law, t, length, mu, EI, p["damping_ratio"], n_modes=6)
    rigid = mu * length**3 / 3.0 * np.array([law(x)[2] for x in t])
    return np.abs(moment).max() / np.abs(rigid).max() - 1.0




def slowest_crossing(length):
    """The longest deployment time where the excess passes the threshold: a scan from 30 s down, then
    Brent's method in the first bracket (far below it the excess falls again: a very fast drive
    moves only the root of the panel)."""
    grid = np.geomspace(30.0, 0.5, 24)
    above = [cantilever_excess(T, length) > THRESHOLD for T in grid]
    k = above.index(True)
    return brentq(lambda T: cantilever_excess(T, length) - THRESHOLD, grid[k], grid[k - 1], xtol=1e-4)


bounds = {length: slowest_crossing(length) for length in (L, p["n_panels"] * L)}
when = [{"model": "one stowed panel (2 m cantilever, exact modes)", "deployment time at 10 % excess [s]": bounds[L]},
        {"model": "deployed antenna as one 6 m cantilever (exact modes)",
         "deployment time at 10 % excess [s]": bounds[p["n_panels"] * L]}]
for T, out in histories.items():
    ratio = np.abs(out["flexible"]["M"]).max(axis=0) / np.abs(out["rigid"]["M"]).max(axis=0)
    when.append({"model": f"full model at {T:g} s", "peak excess [%]": 100 * (ratio.max() - 1)})
if scene.full:
    # the longest deployment time where the excess passes 10 %: a grid from long to short, then bisection
    grid = {T: peak_excess(T) for T in scene.progress((15.0, 12.0, 10.0, 8.0, 7.0, 6.0, 5.0, 4.0, 3.0),
                                                      desc="deployment grid")}
    for T, x in grid.items():
        if T not in histories:
            when.append({"model": f"full model at {T:g} s", "peak excess [%]": 100 * x})
    times = list(grid)
    k = next(i for i, T in enumerate(times) if grid[T] > THRESHOLD)
    lo, hi = times[k], times[k - 1]  # excess above the threshold at lo, below at hi
    steps = 0
    while hi - lo > 0.01:
        mid = 0.5 * (lo + hi)
        if peak_excess(mid) > THRESHOLD:
            lo = mid
        else:
            hi = mid
        steps += 1
    when.append({"model": f"full model, bisected ({steps} steps)",
                 "deployment time at 10 % excess [s]": 0.5 * (lo + hi)})
when = scene.table("flexibility_matters", pd.DataFrame(when))
when

# %%
# Notes
# -----
nominal = histories.get(p["deployment_time"], histories[durations[-1]])
scene.note(
    "All data assumed (their source's data are not public): a 2000 kg free-floating bus, three 2 m × 1 m panels "
    "of 25 kg with EI = 2e4 N m² (cantilever 5.6 Hz), 0.5 % modal damping, every hinge driven by the cycloidal law "
    "at once and held after. The flexible panels' actuator moments exceed the rigid ones most at the start of the "
    "motion, where the jerk steps, and oscillate about zero after the deployment (the held hinges carry the "
    "antenna's vibration), where the rigid model gives none. H is the model's total angular momentum "
    "(core.flexible.models.momenta), zero in the exact motion; it is compared with the largest angular momentum "
    "of the bus alone. "
    + ("`--full` bisects the deployment time where the peak excess passes 10 %." if not scene.full else
       "The bisected time lies between the two single-cantilever estimates, as it must: the folded antenna is "
       "stiffer than the deployed one."))
scene.done()
