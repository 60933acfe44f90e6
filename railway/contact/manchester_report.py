"""The report of the Manchester contact benchmark (Case A-2.2) against CONTACT: the tables and
the notes of the example ``examples/railway/manchester_contact.py`` (scene
``railway-manchester-contact``) that summarise :mod:`railway.contact.manchester_contact`.

* :func:`manchester_table` -- a table of the comparison in the units of the railway tables;
* :func:`difference_summary` -- the largest differences to CONTACT per creep law, wheel and
  regime (tread, flange root, flange);
* :func:`flange_onset_scan` -- where the flange contact of the climbing (right) wheel starts,
  rigid and under the benchmark's wheel load;
* :func:`manchester_notes` -- the README text of the comparison, every number from the tables.

References
----------
Shackleton, P. and Iwnicki, S. (2008). Vehicle System Dynamics 46(1-2):91-120 (Case A-2.2).
Vollebregt, E. A. H. CONTACT user guide, sect. 5.7 (eve70a/CONTACT, Revision 2447).
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from ..tables import display_units
from .manchester_contact import MANCHESTER_A22, manchester_cases

__all__ = ["MANCHESTER_LAWS", "REFERENCES", "REGIMES", "manchester_table", "difference_summary",
           "flange_onset_scan", "manchester_notes"]

#: References of the comparison, as quoted in the notes.
REFERENCES = (
    "References: Shackleton & Iwnicki (2008), VSD 46(1-2):91-120 (Manchester contact benchmark, "
    "Case A-2.2; its tables were not available here); Vollebregt, CONTACT user guide sect. 5.7 and "
    "the example files examples/mbench_a22_{left,right}.inp/.ref_out of eve70a/CONTACT (Apache-2.0, "
    "Revision 2447), the source of every CONTACT value shown; Kalker (1982), VSD 11:1-13 (FASTSIM); "
    "Polach (2000), VSD 33 Suppl.:728-739; Kalker (1990), Table E.3; Johnson (1985), ch. 4 (Hertz); "
    "Nadal (1908, quoted second-hand).")

#: Creep laws of the comparison: registry name -> label.
MANCHESTER_LAWS = {"fastsim": "FASTSIM", "polach2000": "Polach 2000", "kalker_linear": "Kalker linear"}

#: Regimes of the lateral shift (CONTACT's y, m): (label, lowest, highest).
REGIMES = (("tread (y <= 4.5 mm)", 0.0, 4.5e-3), ("flange root (5.0-6.0 mm)", 5.0e-3, 6.0e-3),
           ("flange (y >= 6.5 mm)", 6.5e-3, 10.0e-3))

#: count columns of the Manchester tables, given the unit [-] in the written files
_COUNTS = {"case": "case [-]", "contacts": "contacts [-]", "cases": "cases [-]",
           "loaded contacts": "loaded contacts [-]"}


def manchester_table(df: pd.DataFrame) -> pd.DataFrame:
    """``df`` in the units of the railway tables (:func:`railway.tables.display_units`), its count
    columns (case, contacts, cases, loaded contacts) with the unit ``[-]``."""
    return display_units(df.rename(columns=_COUNTS))


def difference_summary(comparisons: dict[str, pd.DataFrame]) -> pd.DataFrame:
    """The largest differences to CONTACT per creep law, wheel and regime (:data:`REGIMES`).

    Parameters
    ----------
    comparisons : dict
        Creep-law name (a key of :data:`MANCHESTER_LAWS`) -> :func:`compare_with_contact` table.

    Returns
    -------
    DataFrame
        One row per law, wheel and regime with rows: ``creep law``, ``wheel``, ``regime``,
        ``cases`` and the largest ``|dN|`` (%), ``|dFy track|`` (N), ``|dFy track|`` / ``|Fy CONTACT|`` (%),
        ``|dcontact angle|`` (rad) and ``|dp_max|`` (%) over the converged rows (SI units).
    """
    rows = []
    for name, c in comparisons.items():
        c = c[c["converged"].astype(bool)]
        for side in ("left", "right"):
            for regime, lo, hi in REGIMES:
                sub = c[(c["side"] == side) & (c["y CONTACT [m]"] >= lo - 1e-9) & (c["y CONTACT [m]"] <= hi + 1e-9)]
                if not len(sub):
                    continue
                rows.append({"creep law": MANCHESTER_LAWS.get(name, name), "wheel": side, "regime": regime,
                             "cases": len(sub), "max |dN| [%]": sub["dN [%]"].abs().max(),
                             "max |dFy track| [N]": sub["dFy track [N]"].abs().max(),
                             "max |dFy track| / |Fy CONTACT| [%]":
                                 (100 * sub["dFy track [N]"].abs() / sub["Fy track CONTACT [N]"].abs()).max(),
                             "max |dcontact angle| [rad]": sub["dcontact angle [rad]"].abs().max(),
                             "max |dp_max| [%]": sub["dp_max [%]"].abs().max()})
    return pd.DataFrame(rows)


def flange_onset_scan(y, grid=40):
    """Where the flange contact of the climbing (right) wheel starts, rigid and under load.

    At each lateral shift ``y`` to the right (CONTACT's y, with the benchmark's yaw 2.4 mrad per
    mm) the rigid contact (:func:`railway.contact.geometry.rigid_contact`) and the quasi-static
    rolling solution under 10 kN per wheel with FASTSIM on a ``grid`` x ``grid`` grid
    (:func:`railway.contact.quasi_static.quasi_static_rolling`), both in :data:`MANCHESTER_A22`.

    Returns
    -------
    DataFrame
        ``y CONTACT [m]``, ``yaw CONTACT [rad]``, ``rigid contact angle [rad]`` and, of the
        loaded right wheel, ``loaded contacts``, ``contact angle [rad]``, ``N [N]`` and
        ``converged``.  Flange contact: a contact angle above 45 deg.
    """
    from .geometry import rigid_contact
    from .quasi_static import quasi_static_rolling, quasi_static_wheel_table

    S = MANCHESTER_A22
    y = np.asarray(y, dtype=float)
    E = 2.0 * S["G"] * (1.0 + S["nu"])
    qs = quasi_static_wheel_table(quasi_static_rolling(
        -y, -S["yaw_per_shift"] * y, S["wheel_load"], S["speed"], creep_law="fastsim",
        mu=S["mu"], E=E, nu=S["nu"], creep_params={"n_x": grid, "n_y": grid}))
    qs = qs[qs["side"] == "right"].reset_index(drop=True)
    _, _, rig, act = rigid_contact(-y, -S["yaw_per_shift"] * y, errors="mark")
    ang_rig = np.take_along_axis(rig.contact_angle[1::2], np.asarray(act)[:, 1:2], axis=1)[:, 0]
    return pd.DataFrame({"y CONTACT [m]": y, "yaw CONTACT [rad]": S["yaw_per_shift"] * y,
                         "rigid contact angle [rad]": ang_rig,
                         "loaded contacts": qs["contacts"], "contact angle [rad]": qs["contact angle [rad]"],
                         "N [N]": qs["N [N]"], "converged": qs["converged"]})


def manchester_notes(comparisons, wheels, contacts, reference, rail_check, onset, grid, step):
    """The notes of the comparison (Markdown paragraphs), every number taken from the tables.

    Parameters
    ----------
    comparisons, wheels, contacts : dict
        Creep-law name (the keys of :data:`MANCHESTER_LAWS`) -> :func:`compare_with_contact`
        table, and the per-wheel and per-contact tables of :func:`run_manchester_a22`.
    reference : DataFrame
        :func:`contact_reference_per_wheel`.
    rail_check : tuple
        ``(points, top)`` of :func:`rail_profile_check`.
    onset : DataFrame
        :func:`flange_onset_scan`.
    grid : int
        FASTSIM's grid (``grid`` x ``grid``).
    step : float
        Spacing (m) of the shifts of ``onset``.
    """
    comps, raws, ref = comparisons, contacts, reference
    pts, top = rail_check
    flange_angle = np.radians(45.0)
    ang_rig = onset["rigid contact angle [rad]"].to_numpy()
    fl_rig = onset["y CONTACT [m]"].to_numpy()[np.argmax(ang_rig > flange_angle)] if np.any(ang_rig > flange_angle) \
        else np.nan
    okq = onset["converged"].astype(bool) & (onset["contact angle [rad]"] > flange_angle)
    fl_qs = float(onset.loc[okq, "y CONTACT [m]"].min()) if okq.any() else np.nan

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
    out.append(REFERENCES)
    return "\n\n".join(out)
