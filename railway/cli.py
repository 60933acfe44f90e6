"""``mbsuite railway ...`` sub-commands.

Registered through the entry point ``mbsuite.commands: railway = "railway.cli:register"``.
Each sub-command is one ``_add_<name>(subparsers)`` function listed in ``_SUBCOMMANDS``; adding a
command means writing one such function and appending it to the list.

Units at this edge: lengths in mm and angles in degrees on the command line and in the
Markdown summary; the CSV tables keep SI units (column names carry the unit).

Example::

    mbsuite railway contact-table --gauge-mm 1435 --inclination 1:40 --flange-back-mm 1360 \\
        --r0-mm 460 --y-max-mm 10 --n 401 -o out/contact
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

from core.errors import InputError

from .cli_creep import add_creep_curve_parser

__all__ = ["register", "run_contact_table"]


def _write_table(df, out_dir, stem):
    from core.results import write_table

    write_table(df, out_dir, stem)


# ---------------------------------------------------------------------------------------------
# contact-table
# ---------------------------------------------------------------------------------------------
def _add_contact_table(sub):
    p = sub.add_parser(
        "contact-table",
        help="rigid wheel-rail contact-geometry table and equivalent conicity (CSV, Markdown, PNG)",
        description="Rigid (zero-penetration) contact geometry of a wheelset on straight track over "
                    "a range of lateral shifts: contact positions, rolling radii, contact angles, "
                    "delta r, roll, height, flange contact; equivalent conicity (EN 15302, "
                    "kinematic-wavelength and harmonic-linearisation methods).")
    p.add_argument("--wheel", default="S1002",
                   help="'S1002' or a two-column profile file (lateral, vertical in mm; signs set "
                        "by --wheel-flange-side and --wheel-vertical)")
    p.add_argument("--wheel-flange-side", choices=("negative", "positive"), default="negative",
                   help="side of the flange in the wheel file's lateral coordinate (default "
                        "negative: S1002 / EN 13715 convention)")
    p.add_argument("--wheel-vertical", choices=("radius_increase", "height"),
                   default="radius_increase",
                   help="vertical column of the wheel file: radius increase (grows towards the "
                        "flange, default) or height (z up on a wheel standing on the rail)")
    p.add_argument("--wheel-back-mm", type=float, default=None,
                   help="flange back face in the wheel file's lateral coordinate (mm, default 70 "
                        "on the flange side: -70, or +70 with --wheel-flange-side positive)")
    p.add_argument("--rail", default="UIC60",
                   help="'UIC60' or a two-column profile file (lateral from the rail axis, "
                        "vertical in mm; signs set by --rail-field-side and --rail-vertical)")
    p.add_argument("--rail-field-side", choices=("positive", "negative"), default="positive",
                   help="side of the field in the rail file's lateral coordinate (default positive)")
    p.add_argument("--rail-vertical", choices=("height", "depth"), default="height",
                   help="vertical column of the rail file: height (up, default) or depth (down)")
    p.add_argument("--gauge-mm", type=float, default=1435.0, help="track gauge (14 mm below top)")
    p.add_argument("--inclination", default="1:40", help="rail inclination: 1:40, 1:20, vertical")
    p.add_argument("--flange-back-mm", type=float, default=1360.0, help="flange-back spacing")
    p.add_argument("--r0-mm", type=float, default=460.0, help="nominal rolling radius")
    p.add_argument("--y-max-mm", type=float, default=10.0, help="largest lateral shift")
    p.add_argument("--n", type=int, default=401, help="number of lateral shifts")
    p.add_argument("--yaw-mrad", type=float, default=0.0, help="wheelset yaw angle")
    p.add_argument("--amplitudes-mm", default="2,3,4",
                   help="comma-separated amplitudes for the equivalent conicity")
    p.add_argument("--load-kN", type=float, default=None,
                   help="also solve the quasi-static elastic contact under this vertical load per "
                        "wheel (Hertz normal forces balance the load) and report normal and "
                        "lateral forces per contact")
    p.add_argument("-o", "--out", default=None, help="output folder (default: print only)")
    p.set_defaults(func=run_contact_table)
    return p


def _load_wheel(args, r0):
    from .profiles import WheelProfile

    spec = args.wheel
    if spec.upper() == "S1002":
        given = [opt for opt, val, default in (
            ("--wheel-flange-side", args.wheel_flange_side, "negative"),
            ("--wheel-vertical", args.wheel_vertical, "radius_increase"),
            ("--wheel-back-mm", args.wheel_back_mm, None)) if val != default]
        if given:
            raise InputError(f"{', '.join(given)}: only for a wheel profile file, not the "
                             "built-in S1002")
        return WheelProfile.s1002(r0=r0)
    back = args.wheel_back_mm
    if back is None:
        back = -70.0 if args.wheel_flange_side == "negative" else 70.0
    return WheelProfile.from_file(spec, r0=r0, y_back=back, flange_side=args.wheel_flange_side,
                                  vertical=args.wheel_vertical)


def _load_rail(args):
    from .profiles import RailProfile

    spec = args.rail
    if spec.upper() == "UIC60":
        given = [opt for opt, val, default in (
            ("--rail-field-side", args.rail_field_side, "positive"),
            ("--rail-vertical", args.rail_vertical, "height")) if val != default]
        if given:
            raise InputError(f"{', '.join(given)}: only for a rail profile file, not the built-in UIC60")
        return RailProfile.uic60()
    return RailProfile.from_file(spec, field_side=args.rail_field_side, vertical=args.rail_vertical)


#: Plausible ranges of the millimetre options (a value outside is taken for a unit slip).
_MM_RANGES = {
    "--r0-mm": ("r0_mm", 50.0, 2000.0, "nominal rolling radius", "460 for a 920 mm wheel"),
    "--gauge-mm": ("gauge_mm", 300.0, 2000.0, "track gauge", "1435 for standard gauge"),
    "--flange-back-mm": ("flange_back_mm", 250.0, 2000.0, "flange-back spacing",
                         "1360 for standard gauge"),
}


def _check_mm_options(args):
    """InputError naming the option, its value and the unit for a value outside its plausible
    range (e.g. --gauge-mm 1.435: metres given where millimetres are expected)."""
    for opt, (attr, lo, hi, what, example) in _MM_RANGES.items():
        v = getattr(args, attr)
        if not np.isfinite(v) or not (lo <= v <= hi):
            hint = " (it looks like metres)" if np.isfinite(v) and 0 < v < lo / 100.0 else ""
            raise InputError(f"{opt} {v!r}: the {what} is given in millimetres and must lie in "
                             f"[{lo:g}, {hi:g}] mm{hint}; e.g. {example}")


def run_contact_table(args) -> int:
    """Compute the table, print a summary, and write CSV/Markdown/PNG when ``--out`` is given."""
    from .contact_geometry import (
        conicity_table,
        contact_geometry_table,
        contact_transitions,
        flange_contact_onset,
    )

    if args.n < 5:
        raise InputError(f"--n {args.n}: at least 5 lateral shifts are needed")
    if not (args.y_max_mm > 0):
        raise InputError(f"--y-max-mm {args.y_max_mm!r} must be positive")
    _check_mm_options(args)
    if args.out:  # a path that is a file is refused before the computation, not after it
        from core.paths import output_folder

        output_folder(args.out)
    try:
        amps = np.array([float(a) for a in args.amplitudes_mm.split(",")]) * 1e-3
    except ValueError:
        raise InputError(f"--amplitudes-mm {args.amplitudes_mm!r}: expected e.g. 2,3,4") from None
    load = getattr(args, "load_kN", None)
    if load is not None and not (np.isfinite(load) and load > 0):
        raise InputError(f"--load-kN {load!r}: the vertical wheel load must be positive")
    wheel = _load_wheel(args, args.r0_mm * 1e-3)
    rail = _load_rail(args)
    y = np.linspace(-args.y_max_mm, args.y_max_mm, args.n) * 1e-3
    df = contact_geometry_table(y, yaw=args.yaw_mrad * 1e-3, wheel=wheel, rail=rail,
                                gauge=args.gauge_mm * 1e-3, inclination=args.inclination,
                                flange_back_spacing=args.flange_back_mm * 1e-3)
    con = conicity_table(df, amps[amps <= args.y_max_mm * 1e-3])
    trans = contact_transitions(df, wheel=wheel, rail=rail)
    y_f, g_f = flange_contact_onset(df, wheel=wheel, rail=rail, transitions=trans)
    summary = [
        (f"wheel {wheel.name}, rail {rail.name}, gauge {args.gauge_mm:g} mm, inclination "
         f"{args.inclination}, flange-back {args.flange_back_mm:g} mm, r0 {args.r0_mm:g} mm"),
    ]
    bad = df[df["status"] != "ok"]
    if len(bad):
        summary.append(f"{len(bad)} of {len(df)} lateral shifts have no rigid contact and are left "
                       f"out of every figure below (from {bad['y [m]'].min() * 1e3:.3f} to "
                       f"{bad['y [m]'].max() * 1e3:.3f} mm; first: {bad['status'].iloc[0]})")
    if np.isfinite(y_f):
        summary.append(f"flange contact from lateral shift {y_f * 1e3:.4f} mm (located by "
                       f"bisection to 0.1 um), contact angle {np.degrees(g_f):.2f} deg")
    else:
        summary.append("no flange contact on the left wheel in the table's range")
    if "lead_L [m]" in df.columns and np.isfinite(y_f):
        ok = df[(df["status"] == "ok") & df["flange_L"] & (df["y [m]"] >= y_f)]
        if len(ok):
            row = ok.iloc[0]
            summary.append(f"yaw {args.yaw_mrad:g} mrad: contact lead (ahead of the wheel centre) "
                           f"{row['lead_L [m]'] * 1e3:.2f} mm at the first flange-contact row, "
                           f"{row['y [m]'] * 1e3:.3f} mm (left wheel)")
    jumps = trans[(trans["kind"] == "contact jump") & (trans["side"] == "left")]
    if len(jumps):
        summary.append("contact jumps of the left wheel at lateral shifts "
                       + ", ".join(f"{v * 1e3:.4f}" for v in jumps["y [m]"]) + " mm")
    for _, row in con.iterrows():
        summary.append(
            f"equivalent conicity at {row['amplitude [m]'] * 1e3:g} mm: "
            f"{row['conicity wavelength [-]']:.4f} (wavelength), "
            f"{row['conicity harmonic [-]']:.4f} (harmonic), dr/2y {row['delta_r/2y [-]']:.4f}")
    qs = None
    if load is not None:
        from .quasi_static import quasi_static_contact, quasi_static_summary

        qs = quasi_static_contact(y, load * 1e3, yaw=args.yaw_mrad * 1e-3, wheel=wheel, rail=rail,
                                  gauge=args.gauge_mm * 1e-3, inclination=args.inclination,
                                  flange_back_spacing=args.flange_back_mm * 1e-3)
        sm = quasi_static_summary(qs)
        head = f"quasi-static contact under {load:g} kN per wheel"
        if sm["converged shifts"] == 0:
            summary.append(f"{head}: no shift reached the force balance")
        else:
            summary.append(
                f"{head} ({sm['converged shifts']} of {sm['shifts']} shifts converged): max "
                f"normal force {sm['max N [N]'] / 1e3:.1f} kN, max |lateral force| "
                f"{sm['max |Fy| [N]'] / 1e3:.1f} kN"
                + (f", two-point contact at {sm['two-point pairs']} (shift, side) pairs from "
                   f"{sm['first two-point shift [m]'] * 1e3:.2f} mm" if sm["two-point pairs"]
                   else ", no two-point contact"))
        if sm["excluded shifts [m]"]:
            summary.append("left out of the quasi-static figures (not converged): lateral shifts "
                           + ", ".join(f"{v * 1e3:.3f}" for v in sm["excluded shifts [m]"]) + " mm")
    print("\n".join(summary))
    if args.out:
        out = Path(args.out)
        _write_table(df, out, "contact_table")
        _write_table(con, out, "equivalent_conicity")
        _write_table(trans, out, "contact_transitions")
        if qs is not None:
            _write_table(qs, out, "quasi_static")
        from core.paths import write_atomically
        from core.plot import save_figure

        text = "\n".join(f"- {s}" for s in summary) + "\n"
        write_atomically(out / "summary.md", lambda p: p.write_text(text, encoding="utf-8"))
        title = (f"contact geometry: {wheel.name} on {rail.name} {args.inclination}, gauge "
                 f"{args.gauge_mm:g} mm, flange-back {args.flange_back_mm:g} mm, r0 "
                 f"{args.r0_mm:g} mm, yaw {args.yaw_mrad:g} mrad")
        save_figure(plot_contact_table(df, title=title), out, "contact_table", dpi=120)
        print(f"wrote {out}/contact_table.csv, .md, equivalent_conicity.csv, .md, "
              "contact_transitions.csv, .md, contact_table.png")
    return 0


def plot_contact_table(df, ax=None, title=None):
    """Delta r and contact angles against lateral shift; returns the Figure.

    Rows without a rigid contact (status other than "ok") are NaN and leave gaps in the lines.
    """
    from matplotlib.figure import Figure

    if ax is None:
        fig = Figure(figsize=(7, 6))
        ax = fig.subplots(2, 1, sharex=True)
    else:
        fig = ax[0].figure
    y = df["y [m]"] * 1e3
    ax[0].plot(y, df["delta_r [m]"] * 1e3, lw=1)
    ax[0].set_ylabel("delta r [mm]")
    ax[0].grid(True, alpha=0.3)
    ax[1].plot(y, np.degrees(df["gamma_L [rad]"]), lw=1, label="left")
    ax[1].plot(y, np.degrees(df["gamma_R [rad]"]), lw=1, label="right")
    ax[1].set_ylabel("contact angle [deg]")
    ax[1].set_xlabel("lateral shift [mm]")
    ax[1].legend()
    ax[1].grid(True, alpha=0.3)
    if title:
        ax[0].set_title(title, fontsize=9)
    return fig


# ---------------------------------------------------------------------------------------------
# registration
# ---------------------------------------------------------------------------------------------
_SUBCOMMANDS = [_add_contact_table, add_creep_curve_parser]


def register(subparsers):
    """Add the ``railway`` sub-parser with its sub-commands (entry point ``mbsuite.commands``)."""
    p = subparsers.add_parser("railway", help="wheel-rail geometry, contact and creep tools",
                              description="Railway tools.")
    sub = p.add_subparsers(dest="railway_command", metavar="COMMAND")
    sub.required = True
    for add in _SUBCOMMANDS:
        add(sub)
    return p


def main(argv=None) -> int:
    """Stand-alone entry: ``python -m railway.cli contact-table ...``."""
    parser = argparse.ArgumentParser(prog="mbsuite-railway")
    sub = parser.add_subparsers(dest="cmd")
    register(sub)
    args = parser.parse_args(["railway"] + list(sys.argv[1:] if argv is None else argv))
    return args.func(args)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
