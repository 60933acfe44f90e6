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
  gap scan; the quasi-static elastic case under a wheel load;
* ``railway-manchester-contact`` -- the Manchester contact benchmark, Case A-2.2, as defined in
  CONTACT's example: our quasi-static rolling solution (Hertz + FASTSIM, Polach 2000, Kalker
  linear, creep forces in the vertical balance) side by side with CONTACT's reference results.

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
_REF_MANCHESTER = (
    "References: Shackleton & Iwnicki (2008), VSD 46(1-2):91-120 (Manchester contact benchmark, "
    "Case A-2.2; its tables were not available here); Vollebregt, CONTACT user guide sect. 5.7 and "
    "the example files examples/mbench_a22_{left,right}.inp/.ref_out of eve70a/CONTACT (Apache-2.0, "
    "Revision 2447), the source of every CONTACT value shown; Kalker (1982), VSD 11:1-13 (FASTSIM); "
    "Polach (2000), VSD 33 Suppl.:728-739; Kalker (1990), Table E.3; Johnson (1985), ch. 4 (Hertz); "
    "Nadal (1908, quoted second-hand).")

#: creep laws of the Manchester comparison: (registry name, label, constructor parameters)
_MANCHESTER_LAWS = (("fastsim", "FASTSIM", None), ("polach2000", "Polach 2000", None),
                    ("kalker_linear", "Kalker linear", None))


#: count columns of the Manchester tables, given the unit [-] in the written files
_COUNTS = {"case": "case [-]", "contacts": "contacts [-]", "cases": "cases [-]",
           "loaded contacts": "loaded contacts [-]"}


def _man_table(df):
    """A Manchester table in display units, count columns with the unit [-]."""
    return _display_units(df.rename(columns=_COUNTS))


def _run_manchester(ctx):
    from .contact_geometry import rigid_contact
    from .manchester_contact import (
        MANCHESTER_A22,
        compare_with_contact,
        contact_reference_per_wheel,
        manchester_cases,
        rail_profile_check,
        run_manchester_a22,
    )

    S = MANCHESTER_A22
    cases = [1, 2, 6, 11, 13, 14, 17, 21] if ctx.fast else None
    grid = 20 if ctx.fast else 40
    ref = contact_reference_per_wheel()
    tables, comps, wheels, raws = {}, {}, {}, {}
    for name, label, params in _MANCHESTER_LAWS:
        pars = {"n_x": grid, "n_y": grid} if name == "fastsim" else params
        df, w = run_manchester_a22(name, cases=cases, creep_params=pars)
        comps[name] = compare_with_contact(w, ref)
        wheels[name], raws[name] = w, df
        tables[f"contacts_{name}"] = _man_table(df)
        tables[f"comparison_{name}"] = _man_table(comps[name])
    # the flange cases of the benchmark (y >= 6.5 mm): the excerpt of the README
    fs = comps["fastsim"]
    flange = fs[(fs["y CONTACT [m]"] >= 6.5e-3 - 1e-9)]
    tables["flange_cases_fastsim"] = _man_table(flange[[
        "case", "side", "y CONTACT [m]", "N ours [N]", "N CONTACT [N]", "dN [%]",
        "Fy track ours [N]", "Fy track CONTACT [N]", "dFy track [N]", "contact angle ours [rad]",
        "contact angle CONTACT [rad]", "dcontact angle [rad]", "p_max ours [Pa]",
        "p_max CONTACT [Pa]", "dp_max [%]", "Y/Q ours [-]", "Y/Q CONTACT [-]"]].reset_index(drop=True))
    # largest differences per law, wheel and regime (converged rows only)
    regimes = (("tread (y <= 4.5 mm)", 0.0, 4.5e-3), ("flange root (5.0-6.0 mm)", 5.0e-3, 6.0e-3),
               ("flange (y >= 6.5 mm)", 6.5e-3, 10.0e-3))
    rows = []
    for name, label, _ in _MANCHESTER_LAWS:
        c = comps[name]
        c = c[c["converged"].astype(bool)]
        for side in ("left", "right"):
            for rname, lo, hi in regimes:
                sub = c[(c["side"] == side) & (c["y CONTACT [m]"] >= lo - 1e-9) & (c["y CONTACT [m]"] <= hi + 1e-9)]
                if not len(sub):
                    continue
                rows.append({"creep law": label, "wheel": side, "regime": rname, "cases": len(sub),
                             "max |dN| [%]": sub["dN [%]"].abs().max(),
                             "max |dFy track| [N]": sub["dFy track [N]"].abs().max(),
                             "max |dFy track| / |Fy CONTACT| [%]":
                                 (100 * sub["dFy track [N]"].abs() / sub["Fy track CONTACT [N]"].abs()).max(),
                             "max |dcontact angle| [rad]": sub["dcontact angle [rad]"].abs().max(),
                             "max |dp_max| [%]": sub["dp_max [%]"].abs().max()})
    summary = _man_table(pd.DataFrame(rows))
    tables["summary_differences"] = summary
    # rail geometry: CONTACT's canted UIC60 against our UIC60 mounted 1:40
    pts, top = rail_profile_check()
    tables["rail_profile_check"] = _man_table(pts)
    # where our flange contact starts (right wheel; yaw 2.4 mrad per mm as in the benchmark)
    step = 0.05e-3 if ctx.fast else 0.01e-3
    y_on = np.arange(6.0e-3, 6.5e-3 + 1e-9, step)
    from .quasi_static import quasi_static_rolling, quasi_static_wheel_table

    E = 2.0 * S["G"] * (1.0 + S["nu"])
    qs = quasi_static_wheel_table(quasi_static_rolling(
        -y_on, -S["yaw_per_shift"] * y_on, S["wheel_load"], S["speed"], creep_law="fastsim",
        mu=S["mu"], E=E, nu=S["nu"], creep_params={"n_x": grid, "n_y": grid}))
    qs = qs[qs["side"] == "right"].reset_index(drop=True)
    z_r, roll_r, rig, act = rigid_contact(-y_on, -S["yaw_per_shift"] * y_on, errors="mark")
    ang_rig = np.take_along_axis(rig.contact_angle[1::2], np.asarray(act)[:, 1:2], axis=1)[:, 0]
    onset = pd.DataFrame({"y CONTACT [m]": y_on, "yaw CONTACT [rad]": S["yaw_per_shift"] * y_on,
                          "rigid contact angle [rad]": ang_rig,
                          "loaded contacts": qs["contacts"], "contact angle [rad]": qs["contact angle [rad]"],
                          "N [N]": qs["N [N]"], "converged": qs["converged"]})
    tables["flange_onset_right_wheel"] = _man_table(onset)
    fl_rig = y_on[np.argmax(ang_rig > np.radians(45.0))] if np.any(ang_rig > np.radians(45.0)) else np.nan
    okq = onset["converged"].astype(bool) & (onset["contact angle [rad]"] > np.radians(45.0))
    fl_qs = float(onset.loc[okq, "y CONTACT [m]"].min()) if okq.any() else np.nan
    # figure: N, Fy, contact angle, p_max against y, both wheels, three laws, CONTACT's points
    fig, ax = _fig(2, 2, size=(11, 8))
    quantities = (("N", "N ours [N]", "N CONTACT [N]", 1e-3, "normal force N [kN]"),
                  ("Fy", "Fy track ours [N]", "Fy track CONTACT [N]", 1e-3,
                   "lateral force on the wheel Fy (track, + left) [kN]"),
                  ("angle", "contact angle ours [rad]", "contact angle CONTACT [rad]", 180.0 / np.pi,
                   "contact angle [deg]"),
                  ("pmax", "p_max ours [Pa]", "p_max CONTACT [Pa]", 1e-9, "maximum pressure p_max [GPa]"))
    styles = {"fastsim": "-", "polach2000": "--", "kalker_linear": ":"}
    colors = {"left": "C0", "right": "C3"}
    for k, (key, qo, qc, f, lab) in enumerate(quantities):
        a = ax[k // 2, k % 2]
        for name, label, _ in _MANCHESTER_LAWS:
            c = comps[name]
            for side in ("left", "right"):
                sub = c[(c["side"] == side)]
                good = sub["converged"].astype(bool)
                a.plot(sub.loc[good, "y CONTACT [m]"] * 1e3, sub.loc[good, qo] * f, styles[name],
                       c=colors[side], lw=1.2, label=f"{label}, {side}" if k == 0 else None)
        for side in ("left", "right"):
            r = ref[ref["side"] == side]
            a.plot(manchester_cases().set_index("case").loc[r["case"], "y CONTACT [m]"] * 1e3,
                   r[qc.replace(" CONTACT", "")] * f, "o", mfc="none", c=colors[side], ms=5,
                   label=f"CONTACT rev. 2447, {side}" if k == 0 else None)
        if key == "Fy":
            a.set_ylim(-8, 16)  # Kalker linear leaves the range (down to -68 kN): clipped
        if key == "N":
            a.set_ylim(0, 20)
        a.set(xlabel="lateral shift y to the right (CONTACT's y) [mm]", ylabel=lab)
        a.grid(True, alpha=0.3)
    ax[0, 0].legend(fontsize=7, ncol=2)
    fig.suptitle("railway-manchester-contact — Case A-2.2: ours (lines: FASTSIM solid, Polach 2000 "
                 "dashed, Kalker linear dotted) vs CONTACT (circles)\nS1002 / UIC60 1:40, gauge "
                 "1435 mm, r0 460 mm, Q = 10 kN per wheel, V = 2 m/s, mu = 0.3, G = 82 GPa, "
                 "nu = 0.28, yaw 2.4 mrad/mm; right wheel climbs its flange; Kalker linear leaves the N "
                 "and Fy ranges (clipped)"
                 + (f"; fast run: cases {cases}" if cases else ""), fontsize=9)
    notes = _manchester_notes(comps, wheels, raws, ref, summary, pts, top, grid, step, fl_rig, fl_qs,
                              onset)
    return dict(tables=tables, figures={"manchester_N_Fy_angle_pmax": fig}, notes=notes)


def _manchester_notes(comps, wheels, raws, ref, summary, pts, top, grid, step, fl_rig, fl_qs, onset):
    """The notes of ``railway-manchester-contact``: every number taken from this run's tables."""
    from .manchester_contact import manchester_cases

    def row(tab, name, case, side):
        t = tab[name]
        r = t[(t["case"] == case) & (t["side"] == side)]
        return r.iloc[0] if len(r) else None

    def rng(x, fmt="{:.1f}"):
        x = np.asarray(x, dtype=float)
        x = x[np.isfinite(x)]
        return "n/a" if not x.size else f"{fmt.format(x.min())} to {fmt.format(x.max())}"

    def flange(name, side):
        c = comps[name]
        return c[(c["side"] == side) & (c["y CONTACT [m]"] >= 6.5e-3 - 1e-9) & c["converged"].astype(bool)]

    rf = ref.set_index(["case", "side"])
    out = [
        "Manchester contact benchmark, Case A-2.2, as defined in CONTACT's example (user guide "
        "sect. 5.7): new S1002 wheels (r0 = 460 mm, flange-back 1360 mm) on UIC60 rails inclined "
        "1:40 (gauge 1435 mm at 14 mm), 10 kN per wheel, V = 2 m/s, mu = 0.3, G = 82 GPa, "
        "nu = 0.28, lateral shifts 0...10 mm to the right with yaw 2.4 mrad per mm (the right "
        "wheel climbs its flange). Ours: railway.quasi_static.quasi_static_rolling -- axle "
        "height, roll and spin rate such that the vertical force of each wheel (normal and "
        "creep-force components) is 10 kN and the net axle moment is zero; one Hertz ellipse per "
        f"contact candidate; creep laws FASTSIM ({grid}x{grid}), Polach 2000 and Kalker linear. "
        "CONTACT: exact (boundary-element) normal and tangential contact on a 0.2 mm grid, "
        "regions closer than 4 mm combined into one patch; its roll and pitch velocity are "
        "Vollebregt's iteration (we solve our own). CONTACT's values are its results for its "
        "example (Revision 2447), not the tables of the 2008 paper. Frames: CONTACT y to the "
        "right, z down, forces on the rail; here forces on the wheel in the track frame (Fy + to "
        "the left, numerically equal to CONTACT's FY(TR)), contact angle + towards the track "
        "centre; N of ours is that of the contact with the largest normal force.",
        f"Rail geometry: CONTACT's 'already canted' UIC60 and our UIC60 inclined 1:40 by "
        f"RailMounting agree to {np.nanmax(pts['distance [m]']) * 1e6:.1f} um (shortest distance "
        f"of {int(pts['inside'].sum())} profile points); highest rail point "
        f"{top['ours [m]'] * 1e3:.4f} mm (ours) vs {top['CONTACT [m]'] * 1e3:.4f} mm (CONTACT) "
        "from the track centre."]
    fr = flange("fastsim", "right")
    if len(fr):
        out.append(
            f"Flange cases (y >= 6.5 mm), FASTSIM, climbing (right) wheel: dN {rng(fr['dN [%]'], '{:.2f}')} %, "
            f"dFy {rng(fr['dFy track [N]'], '{:.0f}')} N, dcontact angle "
            f"{rng(np.degrees(fr['dcontact angle [rad]']), '{:.3f}')} deg, dp_max "
            f"{rng(fr['dp_max [%]'], '{:.2f}')} %.")
    expl = ["Where the codes differ and why:"]
    d = raws["fastsim"]
    dfl = d[(d["side"] == "right") & d["case"].isin(fr["case"]) & (d["N [N]"] > 0)]
    ab_fl = (dfl["a [m]"] / dfl["b [m]"]).to_numpy()
    if len(fr):
        expl.append(
            f"(1) p_max in the flange cases differs by {rng(fr['dp_max [%]'])} %: CONTACT's flange "
            "patch is a long, narrow non-Hertzian patch on the curved flange and gauge corner "
            f"(our ellipse has a/b = {rng(ab_fl, '{:.0f}')}), ours one Hertz ellipse from the "
            "curvatures at the contact point.")
    w1, c1 = row(wheels, "fastsim", 1, "right"), row(comps, "fastsim", 1, "right")
    if w1 is not None:
        expl.append(
            f"(2) Case 1 (y = 0): our contact lies at {w1['y_wheel [m]'] * 1e3:+.2f} mm on the wheel, "
            f"CONTACT's patch reference at {rf.loc[(1, 'right'), 'y_wheel [m]'] * 1e3:+.2f} mm: the "
            "S1002/UIC60 gap is nearly flat across the tread there (near-equal minima), so the "
            "Hertz point and the reference of CONTACT's wide patch differ: contact angle "
            f"{np.degrees(c1['dcontact angle [rad]']):+.2f} deg, p_max {c1['dp_max [%]']:+.1f} %.")
    w2, c2 = row(wheels, "fastsim", 2, "right"), row(comps, "fastsim", 2, "right")
    if w2 is not None:
        expl.append(
            "(3) Case 2 (0.5 mm), right wheel, just past the jump of the contact across the "
            f"tread: our contact at {w2['y_wheel [m]'] * 1e3:+.2f} mm on the wheel, "
            f"CONTACT's at {rf.loc[(2, 'right'), 'y_wheel [m]'] * 1e3:+.2f} mm: contact angle "
            f"{np.degrees(c2['dcontact angle [rad]']):+.2f} deg, p_max {c2['dp_max [%]']:+.1f} %, "
            f"Fy {c2['dFy track [N]']:+.0f} N.")
    c11 = row(comps, "fastsim", 11, "right")
    if c11 is not None:
        expl.append(
            "(4) Cases 11-13 (5.0-6.0 mm) load the conformal flange root (our B/A clipped: an "
            "elongated ellipse). At 5.0 mm CONTACT finds two regions (tread and root) and combines "
            "them into one patch, we load the root alone: p_max "
            f"{c11['dp_max [%]']:+.1f} %, Fy {c11['dFy track [N]']:+.0f} N.")
    fl = flange("fastsim", "left")
    if len(fl):
        d = raws["fastsim"]
        dl = d[(d["side"] == "left") & d["case"].isin(fl["case"])]
        xr = rf.loc[[(int(c), "left") for c in dl["case"]], "xi [-]"].to_numpy()
        wr = wheels["fastsim"]
        wr = wr[(wr["side"] == "left") & wr["case"].isin(fl["case"])]
        om = 100 * (wr["omega [rad/s]"].to_numpy()
                    / rf.loc[[(int(c), "left") for c in wr["case"]], "omega [rad/s]"].to_numpy() - 1)
        expl.append(
            f"(5) The left wheel in the flange cases: Fy differs by {rng(fl['dFy track [N]'], '{:.0f}')} N "
            f"({rng(100 * fl['dFy track [N]'] / fl['Fy track CONTACT [N]'].abs())} % of CONTACT's): "
            "combined large longitudinal and lateral creepage, where the simplified theory's force "
            "direction departs from the exact theory's; our solved spin rate differs from "
            f"CONTACT's by {rng(om, '{:.2f}')} %, so |xi| differs by "
            f"{rng(np.abs(dl['xi [-]'].to_numpy()) - np.abs(xr), '{:.4f}')} while the forces stay close.")
    pr = flange("polach2000", "right")
    if len(pr):
        dp = raws["polach2000"]
        phi = dp[(dp["side"] == "right") & dp["case"].isin(pr["case"]) & (dp["N [N]"] > 0)]["phi [1/m]"]
        expl.append(
            f"(6) Polach 2000 overestimates the flange contact: dN {rng(pr['dN [%]'])} %, dFy "
            f"{rng(pr['dFy track [N]'] / 1e3, '{:.2f}')} kN: its spin correction at the flange (spin "
            f"{rng(np.abs(phi), '{:.2f}')} 1/m on a long narrow ellipse) adds lateral force that "
            "FASTSIM and CONTACT do not have.")
    kr = comps["kalker_linear"]
    kr = kr[(kr["side"] == "right") & (kr["y CONTACT [m]"] >= 6.5e-3 - 1e-9)]
    dk = raws["kalker_linear"]
    dk = dk[dk["N [N]"] > 0]
    over = dk[np.hypot(dk["Fx [N]"], dk["Fs [N]"]) > dk.attrs.get("mu", 0.3) * dk["N [N]"]]
    y_over = np.nan
    if len(over):
        y_over = float(manchester_cases().set_index("case").loc[over["case"], "y CONTACT [m]"].min())
    if len(kr):
        expl.append(
            "(7) Kalker linear does not saturate: its creep force exceeds mu N from "
            f"y = {y_over * 1e3:.1f} mm on, and in flange contact the vertical balance is met by creep forces, "
            f"leaving N = {rng(kr['N ours [N]'] / 1e3, '{:.2f}')} kN on the flange: a known property "
            "of the linear law, shown for completeness.")
    expl.append(
        f"Flange contact (contact angle > 45 deg) starts, rigid, at y = {fl_rig * 1e3:.2f} mm and "
        f"under 10 kN with FASTSIM at {fl_qs * 1e3:.2f} mm (first grid point, {step * 1e3:g} mm "
        "grid, table flange_onset_right_wheel); CONTACT's cases have the root at 6.0 mm "
        f"({np.degrees(rf.loc[(13, 'right'), 'contact angle [rad]']):.1f} deg) and the flange at "
        f"6.5 mm ({np.degrees(rf.loc[(14, 'right'), 'contact angle [rad]']):.1f} deg): both codes "
        "place the jump in the same interval.")
    two = onset[(onset["loaded contacts"] == 2) & onset["converged"].astype(bool)]["y CONTACT [m]"]
    bad = onset[~onset["converged"].astype(bool)]["y CONTACT [m]"]
    if len(two):
        txt = ("Two-patch cases of ours: at y = " + ", ".join(f"{v * 1e3:.2f}" for v in two)
               + " mm the flange root and the flank carry load together (two Hertz contacts) just "
               "after the jump")
        if len(bad):
            txt += ("; at y = " + ", ".join(f"{v * 1e3:.2f}" for v in bad)
                    + " mm, on the jump itself, the balance did not converge (flagged)")
        expl.append(txt + ".")
    out.append(" ".join(expl))
    out.append("Rows whose balance did not converge are flagged (converged = False) and left out of "
               "the summary and the figure. Tables in mm, deg, mrad (yaw, roll), kN, GPa.")
    out.append(_REF_MANCHESTER)
    return "\n\n".join(out)


# ---------------------------------------------------------------------------------------------
def _wrap(fn):
    def run(ctx):
        from core.scenes import SceneResult

        return SceneResult(**fn(ctx))

    return run


def railway_scenes():
    """The railway scenes (entry point ``mbsuite.scenes: railway``)."""
    from core.scenes import Scene

    from .vehicle_scenes import vehicle_scenes

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
        Scene("railway-manchester-contact",
              "Manchester contact benchmark, Case A-2.2, against CONTACT's reference results",
              "S1002 / UIC60 1:40, 10 kN per wheel, V = 2 m/s, mu = 0.3, y = 0..10 mm with yaw "
              "2.4 mrad/mm (Shackleton & Iwnicki 2008, VSD 46:91-120, as in CONTACT's example): "
              "quasi-static rolling with FASTSIM, Polach 2000 and Kalker linear vs CONTACT rev. 2447.",
              _wrap(_run_manchester)),
    ] + vehicle_scenes()
