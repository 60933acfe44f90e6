"""Railway scenes for ``mbsuite run`` (entry point ``mbsuite.scenes: railway``).

* ``railway-contact-geometry`` -- rigid contact geometry of new S1002 wheels on UIC60 rails
  inclined 1:40 (gauge 1435 mm, flange-back spacing 1360 mm, r0 = 460 mm): Delta r and contact
  angles against lateral shift, flange-contact onset, equivalent conicity (EN 15302) at 2, 3 and
  4 mm;
* ``railway-creep-curves`` -- creep curves of every creep law for one representative contact
  (N = 100 kN, a = 6 mm, b = 4 mm, mu = 0.3, G = 80 GPa, nu = 0.28): Fx(xi), Fy(eta) and the
  spin effect Fy(phi);
* ``railway-two-point-contact`` -- two-point (tread + flange) contact of a conical wheel with a
  tight flange root on UIC60 1:40, with and without yaw (flange lead), checked by a brute-force
  gap scan; the quasi-static elastic case under a wheel load.

Units of the written tables: the railway command line's (``mbsuite railway ...``) -- lengths in mm,
contact angles in deg, wheelset yaw and roll in mrad, forces in kN, moments in kN m, moduli in GPa,
creepages [-] and spin [1/m] -- in every table of a scene, so one quantity never appears in two
units (:func:`_display_units` converts the SI tables of the library functions).
"""

from __future__ import annotations

import numpy as np
import pandas as pd

__all__ = ["railway_scenes"]

_REF_GEOMETRY = (
    "References: Pombo, Ambrosio & Silva (2007), VSD 45:165-189 (four-condition contact search); "
    "EN 15302:2008+A1:2010 (equivalent conicity); EN 13715 (S1002); EN 13674-1 (60E1/UIC60); "
    "Wickens (2003), Fundamentals of Rail Vehicle Dynamics, ch. 2.")
_REF_CREEP = (
    "References: Kalker (1990), Three-dimensional elastic bodies in rolling contact, Table E.3; "
    "Kalker (1982), VSD 11:1-13 (FASTSIM); Shen, Hedrick & Elkins (1983), VSD 12 Suppl.:79-83; "
    "Polach (2000), VSD 33 Suppl.:728-739; Polach (2005), Wear 258:992-1000.")


#: SI unit -> (unit of the railway tables, factor): lengths mm, forces kN, moduli GPa.
_DISPLAY = {"m": ("mm", 1e3), "um": ("mm", 1e-3), "N": ("kN", 1e-3), "N m": ("kN m", 1e-3),
            "Pa": ("GPa", 1e-9)}
#: Angles [rad] of the wheelset's attitude go to mrad (as ``--yaw-mrad``); other angles to deg.
_ATTITUDE = ("yaw", "roll")
#: Columns renamed on the way: the lateral shift of the wheelset has one name in every table.
_RENAME = {"y": "lateral shift", "shift": "lateral shift"}


def _display_units(df: pd.DataFrame) -> pd.DataFrame:
    """A table of SI columns (``"name [unit]"``) in the units of the railway tables (module docstring)."""
    out = {}
    for col in df.columns:
        name, unit = col, ""
        if isinstance(col, str) and col.endswith("]") and " [" in col:
            name, unit = col[:-1].rsplit(" [", 1)
        name = _RENAME.get(name, name)
        if unit == "rad":
            to, factor = ("mrad", 1e3) if name.startswith(_ATTITUDE) else ("deg", 180.0 / np.pi)
        else:
            to, factor = _DISPLAY.get(unit, (unit, 1.0))
        new = f"{name} [{to}]" if unit else name
        out[new] = df[col] * factor if factor != 1.0 else df[col]
    res = pd.DataFrame(out, index=df.index)
    res.attrs = dict(df.attrs)
    return res


def _fig(nrows=1, ncols=1, size=(7, 4)):
    from matplotlib.figure import Figure

    fig = Figure(figsize=size, layout="constrained")
    return fig, fig.subplots(nrows, ncols, squeeze=False)


# ---------------------------------------------------------------------------------------------
def _run_contact_geometry(ctx):
    from .contact_geometry import (
        conicity_table,
        contact_geometry_table,
        contact_transitions,
        flange_contact_onset,
    )

    n = 101 if ctx.fast else 401
    y = np.linspace(-0.010, 0.010, n)
    df = contact_geometry_table(y)
    con = conicity_table(df, [0.002, 0.003, 0.004])
    trans = contact_transitions(df)  # jumps and flange onset, by bisection to 0.1 um
    y_f, g_f = flange_contact_onset(df, transitions=trans)  # exact, between the rows
    # excerpt rows: 1 ... 6 mm and the first row with flange contact (y_f lies between rows)
    first_flange = float(df[(df["y [m]"] > 0) & df["flange_L"]]["y [m]"].min())
    picks = [0.001, 0.002, 0.003, 0.004, 0.005, 0.006, first_flange]
    idx = [int(np.argmin(np.abs(df["y [m]"].to_numpy() - p))) for p in picks]
    table = _display_units(df)
    excerpt = table.iloc[idx][["lateral shift [mm]", "delta_r [mm]", "gamma_L [deg]", "gamma_R [deg]",
                               "y_wheel_L [mm]", "u_rail_L [mm]", "flange_L"]].reset_index(drop=True)
    amps = con["amplitude [m]"].to_numpy() * 1e3
    summary = pd.DataFrame(
        [("flange-contact onset, lateral shift", y_f * 1e3, "mm"),
         ("contact angle at onset", np.degrees(g_f), "deg")]
        + [(f"equivalent conicity at {a:g} mm (EN 15302 wavelength)", v, "-")
           for a, v in zip(amps, con["conicity wavelength [-]"])]
        + [(f"equivalent conicity at {a:g} mm (harmonic linearisation)", v, "-")
           for a, v in zip(amps, con["conicity harmonic [-]"])],
        columns=["quantity", "value", "unit"])
    setting = (f"S1002 (r0 460 mm) / UIC60 1:40, gauge 1435 mm, flange-back 1360 mm, "
               f"{n} shifts")
    ys = table["lateral shift [mm]"]
    f1, ax = _fig()
    ax = ax[0, 0]
    ax.plot(ys, table["delta_r [mm]"], lw=1.2)
    ax.axvline(y_f * 1e3, ls=":", c="k", lw=0.8, label=f"flange contact from {y_f * 1e3:.4f} mm")
    ax.set(xlabel="lateral shift y [mm]", ylabel=r"$\Delta r = r_L - r_R$ [mm]",
           title=f"contact geometry — rolling-radius difference\n{setting}")
    ax.title.set_fontsize(9)
    ax.legend(fontsize=8)
    ax.grid(True, alpha=0.3)
    f2, ax = _fig()
    ax = ax[0, 0]
    ax.plot(ys, table["gamma_L [deg]"], lw=1.2, label="left wheel")
    ax.plot(ys, table["gamma_R [deg]"], lw=1.2, label="right wheel")
    ax.set(xlabel="lateral shift y [mm]", ylabel="contact angle [deg]",
           title=f"contact geometry — contact angles\n{setting}")
    ax.title.set_fontsize(9)
    ax.legend()
    ax.grid(True, alpha=0.3)
    f3, ax = _fig(1, 2, size=(10, 4))
    ax[0, 0].plot(ys, table["y_wheel_L [mm]"], ".", ms=2, label="left")
    ax[0, 0].plot(ys, table["y_wheel_R [mm]"], ".", ms=2, label="right")
    ax[0, 0].set(xlabel="lateral shift y [mm]", ylabel="wheel contact y from taping line [mm]")
    ax[0, 1].plot(ys, table["u_rail_L [mm]"], ".", ms=2, label="left")
    ax[0, 1].plot(ys, table["u_rail_R [mm]"], ".", ms=2, label="right")
    ax[0, 1].set(xlabel="lateral shift y [mm]", ylabel="rail contact u from rail axis [mm]")
    f3.suptitle(f"contact geometry — contact positions on wheel and rail\n{setting}", fontsize=10)
    for a in ax[0]:
        a.legend()
        a.grid(True, alpha=0.3)
    notes = (
        f"Rigid (zero-penetration) contact of new S1002 wheels (r0 = 460 mm) on UIC60 rails "
        f"inclined 1:40, gauge 1435 mm (14 mm below the top), flange-back spacing 1360 mm, "
        f"{n} lateral shifts over +-10 mm. Flange contact starts at {y_f * 1e3:.4f} mm (located "
        f"between the table's rows by bisection to 0.1 um) with a contact angle of "
        f"{np.degrees(g_f):.2f} deg; equivalent conicity (EN 15302, exact "
        f"kinematic wavelength) {con['conicity wavelength [-]'].iloc[0]:.3f} / "
        f"{con['conicity wavelength [-]'].iloc[1]:.3f} / {con['conicity wavelength [-]'].iloc[2]:.3f}"
        f" at 2 / 3 / 4 mm. The contact point jumps across the S1002 tread (near-equal minima of "
        f"the gap), hence the steps in the contact positions; table 'transitions' gives every "
        f"jump, located by bisection. Tables in mm, deg (contact angles) "
        f"and mrad (roll, yaw).\n\n" + _REF_GEOMETRY)
    return dict(tables={"contact_geometry": table, "excerpt": excerpt, "summary": summary,
                        "equivalent_conicity": _display_units(con),
                        "transitions": _display_units(trans)},
                figures={"delta_r": f1, "contact_angle": f2, "contact_positions": f3}, notes=notes)


# ---------------------------------------------------------------------------------------------
_CREEP_CONTACT = dict(normal_force=100e3, a=0.006, b=0.004, G=80e9, nu=0.28, mu=0.3)


def _run_creep_curves(ctx):
    from .creep import Fastsim, Polach2005
    from .creep_curve import creep_curve

    n = 21 if ctx.fast else 101
    fast_grid = 20 if ctx.fast else 40
    models = ["kalker_linear", "shen_hedrick_elkins", "polach2000",
              Polach2005(k_A=1.0, k_S=1.0, A=0.38, B=0.7, speed=20.0), Fastsim(fast_grid, fast_grid)]
    c = _CREEP_CONTACT
    xi_df = creep_curve(models, "xi", np.linspace(0.0, 0.01, n), **c)
    eta_df = creep_curve(models, "eta", np.linspace(0.0, 0.01, n), **c)
    phi_df = creep_curve(models, "phi", np.linspace(0.0, 2.0, n), **c)
    eta_spin = creep_curve(models, "eta", np.linspace(0.0, 0.01, n), phi=0.5, **c)
    ex = []
    for v in (0.001, 0.002, 0.004):
        row = {"xi [-]": v}
        sub = creep_curve(models, "xi", [v], **c)
        for name, fx in zip(sub["model"], sub["Fx [N]"]):
            row[f"Fx {name} [kN]"] = fx / 1e3
        ex.append(row)
    excerpt = pd.DataFrame(ex)
    figs = {}
    mu_n = c["mu"] * c["normal_force"]
    setting = (f"N = {c['normal_force'] / 1e3:g} kN, a = {c['a'] * 1e3:g} mm, b = {c['b'] * 1e3:g} mm, "
               f"mu = {c['mu']:g}, G = {c['G'] / 1e9:g} GPa, nu = {c['nu']:g}; FASTSIM {fast_grid}x{fast_grid}")
    for stem, df, col, fcol, xl, what in (
            ("Fx_vs_xi", xi_df, "xi [-]", "Fx [N]", r"longitudinal creepage $\xi$ [-]",
             r"$F_x(\xi)$, $\eta = \varphi = 0$"),
            ("Fy_vs_eta", eta_df, "eta [-]", "Fy [N]", r"lateral creepage $\eta$ [-]",
             r"$F_y(\eta)$, $\xi = \varphi = 0$"),
            ("Fy_vs_phi", phi_df, "phi [1/m]", "Fy [N]", r"spin $\varphi$ [1/m] ($\xi=\eta=0$)",
             r"$F_y(\varphi)$, $\xi = \eta = 0$")):
        fig, ax = _fig()
        ax = ax[0, 0]
        for name, sub in df.groupby("model", sort=False):
            ax.plot(sub[col], -sub[fcol] / mu_n, label=name)
        ax.set(xlabel=xl, ylabel=f"-{fcol.split()[0]} / (mu N) [-]",
               title=f"creep curves — {what}\n{setting}")
        ax.title.set_fontsize(9)
        ax.legend(fontsize=8)
        ax.grid(True, alpha=0.3)
        figs[stem] = fig
    fig, ax = _fig()
    ax = ax[0, 0]
    for (name, s0), (_, s1) in zip(eta_df.groupby("model", sort=False),
                                   eta_spin.groupby("model", sort=False)):
        line, = ax.plot(s0["eta [-]"], -s0["Fy [N]"] / mu_n, label=f"{name}")
        ax.plot(s1["eta [-]"], -s1["Fy [N]"] / mu_n, ls="--", c=line.get_color())
    ax.set(xlabel=r"lateral creepage $\eta$ [-]", ylabel="-Fy / (mu N) [-]",
           title=r"creep curves — spin effect on $F_y(\eta)$: solid $\varphi = 0$, dashed "
                 r"$\varphi = 0.5$ 1/m" + f"\n{setting}")
    ax.title.set_fontsize(9)
    ax.legend(fontsize=8)
    ax.grid(True, alpha=0.3)
    figs["spin_effect"] = fig
    notes = (
        "Creep curves of every creep law at one contact: N = 100 kN, a = 6 mm (rolling), b = 4 mm, "
        "mu = 0.3, G = 80 GPa, nu = 0.28. Forces on the wheel oppose the creepage (plotted as "
        "-F/(mu N)). Kalker linear does not saturate; FASTSIM on a "
        f"{fast_grid}x{fast_grid} grid; Polach 2005 with falling friction A = 0.38, B = 0.7 s/m at "
        "V = 20 m/s (the parameter set quoted in the project notes from Spiryagin, Polach & Cole "
        "2013 for a locomotive; not checked against Polach 2005, Table 2). Spin: Fy(phi) at "
        "xi = eta = 0 and Fy(eta) with phi = 0.5 1/m; Shen-Hedrick-Elkins saturates the linear spin "
        "force to mu N, a known weakness of the heuristic. Tables in kN (forces, load), kN m (spin "
        "moment), mm (semi-axes) and GPa (G).\n\n" + _REF_CREEP)
    return dict(tables={"Fx_vs_xi": _display_units(xi_df), "Fy_vs_eta": _display_units(eta_df),
                        "Fy_vs_phi": _display_units(phi_df),
                        "Fy_vs_eta_with_spin": _display_units(eta_spin), "excerpt_Fx": excerpt},
                figures=figs, notes=notes)


# ---------------------------------------------------------------------------------------------
def _run_two_point(ctx):
    from .quasi_static import quasi_static_contact
    from .two_point import conical_wheel, gap_scan, local_minima, two_point_contact

    wheel = conical_wheel(ctx.out_dir / "cone40_root8_profile.txt", r0=0.46, cone=1 / 40,
                          root_radius_mm=8.0)
    yaws = (0.0, 0.010) if ctx.fast else (0.0, 0.005, 0.010, 0.015)
    rows, checks = [], []
    scans = {}
    for psi in yaws:
        df = two_point_contact(wheel, yaw=psi)
        t = df.iloc[0]
        scan = gap_scan(wheel, t["shift [m]"], t["z [m]"], t["roll [rad]"], psi,
                        dy=1e-5 if ctx.fast else 5e-6, theta_max=0.06, n_theta=301)
        mins = local_minima(scan, max_gap=1e-6)
        scans[psi] = scan
        for _, r in df.iterrows():
            rows.append({
                "yaw [mrad]": psi * 1e3, "contact": r["contact"],
                "lateral shift [mm]": r["shift [m]"] * 1e3, "gap [mm]": r["gap [m]"] * 1e3,
                "contact angle [deg]": np.degrees(r["contact angle [rad]"]),
                "y_wheel [mm]": r["y_wheel [m]"] * 1e3, "u_rail [mm]": r["u_rail [m]"] * 1e3,
                "rolling radius [mm]": r["rolling radius [m]"] * 1e3,
                "lead [mm]": r["lead [m]"] * 1e3,
                "lead estimate r tan(gamma) tan(psi) [mm]":
                    r["rolling radius [m]"] * np.tan(r["contact angle [rad]"]) * np.tan(psi) * 1e3,
            })
        for _, m in mins.iterrows():
            checks.append({"yaw [mrad]": psi * 1e3, "brute-force minimum y_wheel [mm]":
                           m["y_wheel [m]"] * 1e3, "vertical gap [mm]": m["gap [m]"] * 1e3,
                           "lead [mm]": m["lead [m]"] * 1e3})
        checks.append({"yaw [mrad]": psi * 1e3, "brute-force minimum y_wheel [mm]": np.nan,
                       "vertical gap [mm]": scan["gap [m]"].min() * 1e3, "lead [mm]": np.nan})
    table = pd.DataFrame(rows)
    check = pd.DataFrame(checks)
    # quasi-static elastic contact under a wheel load: both contacts carry load past the onset
    y0 = table["lateral shift [mm]"].iloc[0] * 1e-3
    shifts = y0 + np.array([-0.5, -0.05, 0.0, 0.05, 0.1, 0.15, 0.2, 0.3]) * 1e-3
    qs = quasi_static_contact(shifts, 100e3, wheel=wheel)
    setting = f"{wheel.name} / UIC60 1:40, gauge 1435 mm, flange-back 1360 mm"
    f1, ax = _fig()
    ax = ax[0, 0]
    floor_mm = 1e-6  # the vertical gap at the contacts is zero to round-off (~1e-12 mm): floored
    for psi, scan in scans.items():
        # gaps below the floor (zero or negative to round-off at the contacts) are drawn below the
        # visible range, so the line runs off the bottom edge there instead of breaking
        ax.semilogy(scan["y_wheel [m]"] * 1e3, np.maximum(scan["gap [m]"] * 1e3, 1e-3 * floor_mm), lw=0.8,
                    label=f"yaw {psi * 1e3:g} mrad")
    ax.set(xlabel="wheel profile coordinate y [mm] (flange < 0)",
           ylabel="min over theta of vertical gap [mm]",
           title=(f"two-point contact — brute-force gap scan at the rigid two-point configuration\n"
                  f"{setting}; y-range floored at {floor_mm:g} mm (zero gap at the contacts)"),
           ylim=(floor_mm, 30))
    ax.title.set_fontsize(9)
    ax.legend()
    ax.grid(True, alpha=0.3)
    f2, ax = _fig(size=(7, 5))
    ax = ax[0, 0]
    _plot_cross_section(ax, wheel, table)
    notes = (
        "Two-point contact does not occur with new S1002 on UIC60 1:40 (the contact runs across "
        "the conformal flange root). It does with a conical 1:40 tread joined to the S1002 70 deg "
        "flank by a concave root of radius 8 mm, tighter than the 13 mm gauge corner of the rail "
        "(profile written to cone40_root8_profile.txt and read back by the measured-profile "
        "reader). The rigid onset is the lateral shift where tread and flange gaps of the "
        "left wheel are both zero (Brent's method on g_F - g_T); with yaw the flange contact "
        "leads the wheel centre ('lead', along the track). check: dense brute-force vertical "
        "gap scan over (theta, y), independent of the Newton search: two local minima with zero "
        "gap, no penetration (last row per yaw: global minimum). quasi_static: elastic Hertz "
        "contact under 100 kN vertical load per wheel (yaw 0): the flange takes load from the "
        "onset on, with both contacts loaded. Tables in mm, deg (contact angles), mrad (yaw, roll) "
        "and kN.\n\n"
        "References: Pombo, Ambrosio & Silva (2007), VSD 45:165-189; Shabana, Zaazaa & "
        "Sugiyama (2008), Railroad Vehicle Dynamics, ch. 5; Johnson (1985), Contact Mechanics, "
        "ch. 4.")
    return dict(tables={"two_point": table, "brute_force_check": check, "quasi_static": _display_units(qs)},
                figures={"gap_scan": f1, "cross_section": f2}, notes=notes)


def _plot_cross_section(ax, wheel, table):
    """Wheel and rail cross-sections (left side, yaw 0) at the rigid two-point configuration."""
    from .track import RailMounting

    r0 = table[(table["yaw [mrad]"] == 0.0)]
    mount = RailMounting()
    u = np.linspace(mount.u_min, mount.u_max, 600)
    Yo, Z, *_ = mount.mounted(u)
    ax.plot(Yo * 1e3, Z * 1e3, c="k", lw=1.5, label="UIC60 1:40 (left rail)")
    shift = r0["lateral shift [mm]"].iloc[0] * 1e-3
    L = 0.68 - wheel.y_back
    yw = np.linspace(wheel.x_min, wheel.x_max, 800)
    # profile in the wheelset frame, small roll neglected in the drawing (< 0.3 mrad)
    Yw = shift + yw + L
    Zw = 0.46 - 0.46 - wheel.evaluate(yw)[0]
    ax.plot(Yw * 1e3, Zw * 1e3, c="C0", lw=1.5, label=f"{wheel.name}, shift {shift * 1e3:.2f} mm")
    for _, r in r0.iterrows():
        yc = r["y_wheel [mm]"] * 1e-3
        ax.plot((shift + yc + L) * 1e3, -wheel.evaluate(yc)[0] * 1e3, "o", c="C3")
    ax.set(xlabel="lateral position from track centre [mm]", ylabel="height [mm]",
           xlim=(680, 800), ylim=(-35, 10), aspect="equal",
           title=(f"two-point contact — cross-section at the rigid onset (contacts: dots), yaw 0\n"
                  f"{wheel.name} / UIC60 1:40, lateral shift {shift * 1e3:.2f} mm"))
    ax.title.set_fontsize(9)
    ax.legend(fontsize=8)
    ax.grid(True, alpha=0.3)


# ---------------------------------------------------------------------------------------------
def _wrap(fn):
    def run(ctx):
        from core.scenes import SceneResult

        return SceneResult(**fn(ctx))

    return run


def railway_scenes():
    """The railway scenes (entry point ``mbsuite.scenes: railway``)."""
    from core.scenes import Scene

    return [
        Scene("railway-contact-geometry",
              "Wheel-rail contact geometry: S1002 / UIC60 1:40, delta r, contact angles, conicity",
              "Rigid contact-geometry table of new S1002 wheels on UIC60 rails inclined 1:40 "
              "(gauge 1435, flange-back 1360, r0 460 mm) and the equivalent conicity after EN 15302.",
              _wrap(_run_contact_geometry)),
        Scene("railway-creep-curves",
              "Creep curves of all creep laws (Kalker linear, SHE, Polach 2000/2005, FASTSIM)",
              "Fx(xi), Fy(eta) and the spin effect at N = 100 kN, a = 6 mm, b = 4 mm, mu = 0.3, "
              "G = 80 GPa, nu = 0.28.", _wrap(_run_creep_curves)),
        Scene("railway-two-point-contact",
              "Two-point (tread + flange) wheel-rail contact and flange lead under yaw",
              "Conical 1:40 wheel with a tight flange root on UIC60 1:40: rigid two-point onset "
              "with and without yaw, brute-force gap check, quasi-static elastic case.",
              _wrap(_run_two_point)),
    ]
