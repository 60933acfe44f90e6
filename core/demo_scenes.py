"""Core demo scenes: canonical models run through the integrators and analyses.

Each scene checks its numbers against an independent oracle (closed form, published value or
minimal-coordinate reference) and puts the comparison into its tables, so the output folder is
a small validation report.  Importing this module registers the scenes
(:func:`core.scenes.all_scenes` imports it lazily).
"""

from __future__ import annotations

import numpy as np
import pandas as pd
from scipy.special import ellipk

from . import analysis, models, plot
from .benchmarks.references import n_link_chain_reference
from .benchmarks.testset import AndrewsSqueezer
from .integrators import simulate
from .scenes import Scene, SceneContext, SceneResult, register_scene

G = models.G_EARTH


def _summary_row(label: str, res, **extra) -> dict:
    row = {
        "integrator": label,
        "status": res.status,
        "wall time [s]": res.meta["wall_time_s"],
        "steps [-]": res.counters.get("n_steps", 0),
        "max |Φ| [m]": float(np.max(res.position_violation)),
        "max |Φ_q v − ν| [m/s]": float(np.max(res.velocity_violation)),
    }
    if res.energy is not None:
        e = res.energy
        row["max |E − E0| [J]"] = float(np.max(np.abs(e - e[0])))
    row.update(extra)
    # why a run is "finished with warnings" or "failed", in the table itself
    row["remarks"] = "; ".join(res.warnings) if res.success else res.message
    return row


# --------------------------------------------------------------------------------------------
def _pendulum(ctx: SceneContext) -> SceneResult:
    """Point-mass pendulum (IFToMM A01 geometry) at small amplitude: period and rod tension."""
    length, mass, theta0 = 1.0, 1.0, 0.1
    model = models.simple_pendulum(length=length, mass=mass, angle0=theta0)
    k = np.sin(theta0 / 2)
    period_exact = 4.0 * np.sqrt(length / G) * ellipk(k * k)
    t_end = 2.0 * period_exact if ctx.fast else 10.0 * period_exact
    rows, results = [], {}
    for label, method, kw in ctx.progress(
        [
            ("radau-ggl rtol=1e-8", "radau-ggl", dict(rtol=1e-8, atol=1e-10)),
            ("generalized-alpha h=1e-3", "generalized-alpha", dict(h=1e-3, rtol=1e-4, atol=1e-6)),  # the accuracy h gives
            ("dop853-projection rtol=1e-8", "dop853-projection", dict(rtol=1e-8, atol=1e-10)),
        ],
        desc="pendulum",
    ):
        res = simulate(model, (0.0, t_end), method, n_output=int(400 * t_end / period_exact) + 1, **kw)
        results[label] = res
        x = res.q[:, 0]
        # period from successive upward zero crossings of x (linear interpolation)
        s = np.flatnonzero((x[:-1] < 0) & (x[1:] >= 0))
        tc = res.t[s] - x[s] * (res.t[s + 1] - res.t[s]) / (x[s + 1] - x[s])
        period = float(np.mean(np.diff(tc))) if len(tc) > 1 else np.nan
        # rod tension at the lowest point: T = m g + m v²/l with v from energy conservation
        v_bottom = np.sqrt(2 * G * length * (1 - np.cos(theta0)))
        tension_exact = mass * G + mass * v_bottom**2 / length
        F = next(iter(res.reactions.values()), None)  # the pendulum's only joint
        ib = int(np.argmin(np.abs(x)))
        tension = float(np.hypot(*F[ib, :2])) if F is not None else np.nan
        rows.append(_summary_row(label, res, **{
            "period [s]": period, "period error [s]": period - period_exact,
            "tension at bottom [N]": tension, "tension error [N]": tension - tension_exact,
        }))
    table = pd.DataFrame(rows)
    table.attrs["reference"] = "exact period 4√(l/g)K(sin²(θ0/2)); tension m g + m v²/l at the bottom"
    res = results["radau-ggl rtol=1e-8"]
    hist = res.coordinates().iloc[:: max(1, res.n_t // 20)]
    # angle from the downward vertical, from the bob position (first two coordinates x, y)
    angle = pd.DataFrame({"t [s]": res.t, "angle from vertical [rad]": np.arctan2(res.q[:, 0], -res.q[:, 1])})
    angle.attrs.update(meta=res.meta, status=res.status)
    subject = f"pendulum (l = {length:g} m, θ0 = {theta0:g} rad)"
    return SceneResult(
        tables={"summary": table, "time_history_excerpt": hist},
        figures={
            "angle": plot.plot_time_history(angle, ["angle from vertical [rad]"], title=subject),
            "violations": plot.plot_violations(res, title=subject),
            "energy": plot.plot_energy(res, title=subject),
        },
        notes=(f"Point mass 1 kg on a massless 1 m link, released at θ0 = {theta0} rad from the vertical. "
               f"Exact period {period_exact:.9f} s (complete elliptic integral); exact rod tension at the bottom "
               f"{mass * G + 2.0 * mass * G * (1.0 - np.cos(theta0)):.9f} N (m g + m v²/l, v from energy)."),
    )


# --------------------------------------------------------------------------------------------
def _slider_crank(ctx: SceneContext) -> SceneResult:
    """Driven slider crank: kinematic analysis vs closed form, inverse dynamics driver torque."""
    model = models.slider_crank(driven=True)
    kin_model = model
    omega = 150.0
    n = 61 if ctx.fast else 361
    times = np.linspace(0.0, 2 * np.pi / omega, n)
    kin = analysis.kinematic_analysis(kin_model, times)
    # closed form: slider x = r cosθ + sqrt(l² − r² sin²θ)
    x_col = [c for c in kin.columns if c.startswith("slider.x")][0]
    r, l = _crank_geometry(model)
    th = omega * times
    x_exact = r * np.cos(th) + np.sqrt(l**2 - (r * np.sin(th)) ** 2)
    kin_table = pd.DataFrame({"t [s]": times, "crank angle [rad]": th, "slider x [m]": kin[x_col].to_numpy(),
                              "closed form [m]": x_exact, "error [m]": kin[x_col].to_numpy() - x_exact})
    inv = analysis.inverse_dynamics_from_kinematics(kin_model, kin)
    eff = [c for c in inv.columns if "effort" in c][0]
    torque = pd.DataFrame({"t [s]": times, "crank angle [rad]": th, "driver torque [N m]": inv[eff].to_numpy()})
    subject = f"slider crank, crank driven at {omega:g} rad/s"
    fig = plot.plot_time_history(kin_table, ["slider x [m]", "closed form [m]"], ylabel="slider x [m]",
                                 title=f"{subject} — kinematic analysis (Newton–Raphson) vs closed form")
    fig2 = plot.plot_time_history(torque, ["driver torque [N m]"], ylabel="driver torque [N m]",
                                  title=f"{subject} — inverse dynamics (driver multiplier)")
    return SceneResult(
        tables={"kinematics": kin_table.iloc[:: max(1, n // 24)], "driver_torque": torque.iloc[:: max(1, n // 24)],
                "max_error": pd.DataFrame({"max |x − x_exact| [m]": [float(np.max(np.abs(kin_table['error [m]'])))]})},
        figures={"slider_position": fig, "driver_torque": fig2},
        notes=("Crank driven at 150 rad/s (Simeon's slider-crank geometry); positions from Newton–Raphson "
               "kinematic analysis compared with x = r cosθ + √(l² − r² sin²θ). The driver torque is the "
               "inverse-dynamics multiplier of the angle driver."),
    )


def _crank_geometry(model) -> tuple[float, float]:
    """Crank radius and rod length recovered from the joint markers of :func:`models.slider_crank`."""
    pts = {}
    for j in model.joints:
        if type(j).__name__ == "Revolute":
            pts[j.name] = np.asarray(j.at, float)
    names = sorted(pts)
    # crank pivot at origin; crank-rod joint and rod-slider joint are the other two revolutes
    origin = np.zeros(2)
    others = [pts[n] for n in names if np.linalg.norm(pts[n] - origin) > 1e-12]
    a = min(others, key=lambda p: np.linalg.norm(p))
    b = max(others, key=lambda p: np.linalg.norm(p))
    return float(np.linalg.norm(a)), float(np.linalg.norm(b - a))


# --------------------------------------------------------------------------------------------
def _chain(ctx: SceneContext) -> SceneResult:
    """N-link whip chain (N = 8): integrators against the minimal-coordinate reference."""
    n = 4 if ctx.fast else 8
    ref = n_link_chain_reference(n, 1.0)
    tip_ref = np.asarray(ref["tip"] if isinstance(ref, dict) else ref[0])
    rows, last = [], None
    for planar in (True, False):
        model = models.n_link_chain(n, planar=planar)
        for label, method, kw in [
            ("radau-ggl rtol=1e-8", "radau-ggl", dict(rtol=1e-8, atol=1e-10)),
            ("generalized-alpha h=1e-4", "generalized-alpha", dict(h=1e-4)),
            ("dop853-projection rtol=1e-8", "dop853-projection", dict(rtol=1e-8, atol=1e-10)),
        ]:
            res = simulate(model, (0.0, 1.0), method, n_output=101, **kw)
            tip = models.chain_tip(model, res.q[-1])
            err = float(np.linalg.norm(tip[:2] - tip_ref[:2])) if res.success else np.nan
            rows.append(_summary_row(label, res, model="planar" if planar else "spatial", **{"tip error [m]": err}))
            if planar and method == "radau-ggl":
                last = (model, res)
    model, res = last
    tips = np.array([models.chain_tip(model, q) for q in res.q])
    path = pd.DataFrame({"t [s]": res.t, "tip x [m]": tips[:, 0], "tip y [m]": tips[:, 1]})
    path.attrs.update(meta=res.meta, status=res.status)
    subject = f"{n}-link chain (planar)"
    return SceneResult(
        tables={"tip_error": pd.DataFrame(rows)},
        figures={"tip_path": plot.plot_xy_path(path, "tip x [m]", "tip y [m]", title=subject),
                 "violations": plot.plot_violations(res, title=subject)},
        notes=(f"N = {n} uniform links, total 1 m and 1 kg, released horizontally (core_benchmarks.md §1). "
               "Reference: minimal-coordinate ODE, DOP853 at rtol = atol = 1e-13. The planar and spatial "
               "(Euler parameter) models must give the same tip error."),
    )


# --------------------------------------------------------------------------------------------
def _four_bar(ctx: SceneContext) -> SceneResult:
    """Four-bar under gravity: static equilibrium, then modes of the linearised constrained system."""
    model = models.four_bar(crank_rate0=0.0)
    eq = analysis.static_equilibrium(model, method="energy")
    table, _modes = analysis.eigen(model, q=eq.q)
    res = simulate(model, (0.0, 0.5 if ctx.fast else 3.0), "radau-ggl", rtol=1e-8, atol=1e-10, n_output=301)
    return SceneResult(
        tables={"equilibrium": eq.coordinates() if hasattr(eq, "coordinates") else pd.DataFrame({"q": eq.q}),
                "modes": table},
        figures={"violations": plot.plot_violations(res, title="four-bar under gravity"),
                 "energy": plot.plot_energy(res, title="four-bar under gravity")},
        notes="Static equilibrium by energy descent on Φ = 0, then eigenvalues of the linearisation about it.",
    )


# --------------------------------------------------------------------------------------------
def _bouncing_ball(ctx: SceneContext) -> SceneResult:
    """Sphere on a plane with the Lankarani–Nikravesh contact force: rebound heights vs e²."""
    e, h0 = 0.9, 1.0
    model = models.bouncing_ball(restitution=e, height0=h0)
    t_end = 1.5 if ctx.fast else 3.5
    res = simulate(model, (0.0, t_end), "radau", rtol=1e-9, atol=1e-11, n_output=4001, max_step=1e-3)
    y = res.q[:, 1]
    r = 0.1
    # apexes: local maxima of y after the first impact
    k = np.flatnonzero((y[1:-1] > y[:-2]) & (y[1:-1] >= y[2:])) + 1
    apex = y[k] - r
    rows = [{"bounce [-]": i + 1, "apex height [m]": float(a), "e^(2i) h0 [m]": h0 * e ** (2 * (i + 1)),
             "ratio to previous [-]": float(a / (apex[i - 1] if i else h0))} for i, a in enumerate(apex)]
    df = res.coordinates()
    height = df.columns[2]  # the ball's y coordinate
    return SceneResult(
        tables={"rebounds": pd.DataFrame(rows)},
        figures={"height": plot.plot_time_history(df, [height], ylabel=f"ball centre {height}",
                                                  title=f"bouncing ball (e = {e:g}, h0 = {h0:g} m)")},
        notes=("Each rebound height ratio equals e² for an exact restitution law; the Lankarani–Nikravesh "
               "force reproduces e to within a few per cent for e close to 1 (Lankarani & Nikravesh 1990)."),
    )


# --------------------------------------------------------------------------------------------
def _andrews(ctx: SceneContext) -> SceneResult:
    """Andrews' squeezer in its seven angles through the core's integrators vs the published solution."""
    sys_ = AndrewsSqueezer()
    ref = np.asarray(sys_.reference["q"])
    rows, results = [], {}
    for label, method, kw in [
        ("radau-ggl rtol=1e-10", "radau-ggl", dict(rtol=1e-10, atol=1e-12)),
        ("radau-projection rtol=1e-10", "radau-projection", dict(rtol=1e-10, atol=1e-12)),
        ("generalized-alpha h=1e-6", "generalized-alpha", dict(h=1e-6 if not ctx.fast else 1e-5)),
    ]:
        res = simulate(sys_, (0.0, 0.03), method, n_output=301, **kw)
        qe = res.q[-1]
        rel = float(np.max(np.abs(qe - ref) / np.maximum(np.abs(ref), 1e-300))) if res.success else np.nan
        rows.append(_summary_row(label, res, **{"max rel. angle error at 0.03 s [-]": rel}))
        results[label] = res
    shown = results["radau-ggl rtol=1e-10"]  # the index-2 (GGL) run: its violations are the method's
    return SceneResult(
        tables={"andrews_at_0.03s": pd.DataFrame(rows)},
        figures={"violations": plot.plot_violations(shown, title="Andrews' squeezer (seven angles)")},
        notes="Reference: Test Set for IVP Solvers (Mazzia & Magherini), andrews.f; see core/benchmarks/testset.py.",
    )


SCENES = [
    Scene("pendulum", "Simple pendulum: period and rod tension vs closed form",
          "IFToMM A01 geometry at small amplitude; exact elliptic-integral period.", _pendulum),
    Scene("slider-crank", "Slider crank: kinematic analysis and driver torque",
          "Closed-form slider position; inverse dynamics of the driven crank.", _slider_crank),
    Scene("n-link-chain", "N-link whip chain vs minimal-coordinate reference",
          "core_benchmarks.md §1, planar and spatial models.", _chain),
    Scene("four-bar-modes", "Four-bar: static equilibrium and modes", "Linearised constrained system.", _four_bar),
    Scene("bouncing-ball", "Bouncing ball with Lankarani–Nikravesh contact", "Rebound heights vs e².", _bouncing_ball),
    Scene("andrews", "Andrews' squeezer (seven angles) vs published reference",
          "Hairer & Wanner II §VII.7; Test Set for IVP Solvers.", _andrews),
]

for _s in SCENES:
    register_scene(_s)

# the work-precision report is part of the main job (issue: "the README's main command includes
# the work-precision report"); it lives in core.benchmarks.scenes
from .benchmarks.scenes import work_precision_scenes  # noqa: E402

for _s in work_precision_scenes():
    register_scene(_s)
