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
                   help="'S1002' or a two-column profile file (lateral, radius increase in mm; "
                        "flange at negative lateral coordinate)")
    p.add_argument("--rail", default="UIC60",
                   help="'UIC60' or a two-column profile file (lateral from the rail axis, field "
                        "side positive; height in mm)")
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


def _load_wheel(spec, r0):
    from .profiles import WheelProfile

    if spec.upper() == "S1002":
        return WheelProfile.s1002(r0=r0)
    return WheelProfile.from_file(spec, r0=r0)


def _load_rail(spec):
    from .profiles import RailProfile

    if spec.upper() == "UIC60":
        return RailProfile.uic60()
    return RailProfile.from_file(spec)


def run_contact_table(args) -> int:
    """Compute the table, print a summary, and write CSV/Markdown/PNG when ``--out`` is given."""
    from .contact_geometry import conicity_table, contact_geometry_table, flange_contact_onset

    if args.n < 5:
        raise ValueError(f"--n {args.n}: at least 5 lateral shifts are needed")
    if not (args.y_max_mm > 0):
        raise ValueError(f"--y-max-mm {args.y_max_mm!r} must be positive")
    try:
        amps = np.array([float(a) for a in args.amplitudes_mm.split(",")]) * 1e-3
    except ValueError:
        raise ValueError(f"--amplitudes-mm {args.amplitudes_mm!r}: expected e.g. 2,3,4") from None
    load = getattr(args, "load_kN", None)
    if load is not None and not (np.isfinite(load) and load > 0):
        raise ValueError(f"--load-kN {load!r}: the vertical wheel load must be positive")
    wheel = _load_wheel(args.wheel, args.r0_mm * 1e-3)
    rail = _load_rail(args.rail)
    y = np.linspace(-args.y_max_mm, args.y_max_mm, args.n) * 1e-3
    df = contact_geometry_table(y, yaw=args.yaw_mrad * 1e-3, wheel=wheel, rail=rail,
                                gauge=args.gauge_mm * 1e-3, inclination=args.inclination,
                                flange_back_spacing=args.flange_back_mm * 1e-3)
    con = conicity_table(df, amps[amps <= args.y_max_mm * 1e-3])
    y_f, g_f = flange_contact_onset(df)
    summary = [
        f"wheel {wheel.name}, rail {rail.name}, gauge {args.gauge_mm:g} mm, inclination "
        f"{args.inclination}, flange-back {args.flange_back_mm:g} mm, r0 {args.r0_mm:g} mm",
        f"flange contact from lateral shift {y_f * 1e3:.2f} mm, contact angle "
        f"{np.degrees(g_f):.1f} deg",
    ]
    if "lead_L [m]" in df.columns and np.isfinite(y_f):
        row = df.loc[(df["y [m]"] - y_f).abs().idxmin()]
        summary.append(f"yaw {args.yaw_mrad:g} mrad: contact lead (ahead of the wheel centre) at "
                       f"flange onset {row['lead_L [m]'] * 1e3:.2f} mm (left wheel)")
    for _, row in con.iterrows():
        summary.append(
            f"equivalent conicity at {row['amplitude [m]'] * 1e3:g} mm: "
            f"{row['conicity wavelength [-]']:.4f} (wavelength), "
            f"{row['conicity harmonic [-]']:.4f} (harmonic), dr/2y {row['delta_r/2y [-]']:.4f}")
    qs = None
    if load is not None:
        from .quasi_static import quasi_static_contact

        qs = quasi_static_contact(y, load * 1e3, yaw=args.yaw_mrad * 1e-3, wheel=wheel, rail=rail,
                                  gauge=args.gauge_mm * 1e-3, inclination=args.inclination,
                                  flange_back_spacing=args.flange_back_mm * 1e-3)
        two = qs.groupby(["y [m]", "side"]).size()
        two = two[two > 1]
        summary.append(f"quasi-static contact under {load:g} kN per wheel: max normal force "
                       f"{qs['N [N]'].max() / 1e3:.1f} kN, max |lateral force| "
                       f"{qs['Fy [N]'].abs().max() / 1e3:.1f} kN"
                       + (f", two-point contact at {len(two)} (shift, side) pairs from "
                          f"{two.index[0][0] * 1e3:.2f} mm" if len(two) else ", no two-point contact"))
    print("\n".join(summary))
    if args.out:
        out = Path(args.out)
        _write_table(df, out, "contact_table")
        _write_table(con, out, "equivalent_conicity")
        if qs is not None:
            _write_table(qs, out, "quasi_static")
        (out / "summary.md").write_text("\n".join(f"- {s}" for s in summary) + "\n", encoding="utf-8")
        fig = plot_contact_table(df)
        fig.savefig(out / "contact_table.png", dpi=120)
        print(f"wrote {out}/contact_table.csv, .md, equivalent_conicity.csv, .md, contact_table.png")
    return 0


def plot_contact_table(df, ax=None):
    """Delta r and contact angles against lateral shift; returns the Figure."""
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
