"""``mbsuite railway contact-table``: rigid contact-geometry table, conicity and flange onset.

Registered with the other ``mbsuite railway`` sub-commands by :func:`railway.cli.register`.

Units at this edge: lengths in mm and angles in degrees on the command line and in the
Markdown summary; the CSV tables keep SI units (column names carry the unit).

Every option is checked before anything is computed (issue 21): against its plausible range in
``data/railway/plausible_ranges.csv``, in the unit its name carries (:mod:`railway.cli.checks`;
``--accept QUANTITY`` lets a deliberate outlier through), profile files for existence and text,
the wheelset for fitting the track, the lateral step for the smallest conicity amplitude
(:data:`POINTS_PER_AMPLITUDE`) and the largest shift for the flangeway clearance plus the flange
climb.  Bad input raises a :class:`core.errors.MbsuiteError` whose one-line message
:func:`core.cli.main` prints.

Example::

    mbsuite railway contact-table --gauge-mm 1435 --inclination 1:40 --flange-back-mm 1360 \\
        --r0-mm 460 --y-max-mm 10 --n 401 -o out/contact
"""

from __future__ import annotations

import math
import warnings
from pathlib import Path

import numpy as np

from core.errors import InputError, NumericalFailure

from .checks import add_accept_option, check_file_option, option
from ..ranges import RailwayInputWarning

__all__ = ["add_contact_table_parser", "run_contact_table", "ConicityResolutionWarning", "POINTS_PER_AMPLITUDE"]

#: Lateral steps per conicity amplitude at least: the step of the table must not exceed
#: A / POINTS_PER_AMPLITUDE for the smallest amplitude A.  On S1002 / UIC60 1:40 the equivalent
#: conicity at 1-4 mm is within 2 % of the 0.05 mm-step value with 2 steps per amplitude and
#: within 0.3 % with 4 (the error comes from locating the contact jumps between rows); 5 leaves a
#: margin for worn profiles with more jumps.
POINTS_PER_AMPLITUDE = 5


class ConicityResolutionWarning(RailwayInputWarning):
    """The lateral step of a contact table is too coarse for an equivalent-conicity amplitude:
    that conicity is not computed (NaN); the message names --n and the value needed."""




def _write_table(df, out_dir, stem):
    from core.results import write_table

    write_table(df, out_dir, stem)


# ---------------------------------------------------------------------------------------------
# contact-table
# ---------------------------------------------------------------------------------------------
def add_contact_table_parser(sub):
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
    p.add_argument("--gauge-mm", type=float, default=1435.0,
                   help="track gauge (14 mm below top; 600 ... 1700 mm)")
    p.add_argument("--inclination", default="1:40", help="rail inclination: 1:40, 1:20, vertical")
    p.add_argument("--flange-back-mm", type=float, default=1360.0,
                   help="flange-back spacing (500 ... 1650 mm; the wheelset must fit the track)")
    p.add_argument("--r0-mm", type=float, default=460.0, help="nominal rolling radius (150 ... 800 mm)")
    p.add_argument("--y-max-mm", type=float, default=10.0,
                   help="largest lateral shift (0.5 ... 50 mm, and at most the flangeway clearance "
                        "plus the flange climb)")
    p.add_argument("--n", type=int, default=401,
                   help=f"number of lateral shifts (5 ... 10001; a step of at most 1/{POINTS_PER_AMPLITUDE} "
                        "of the smallest amplitude for the conicity)")
    p.add_argument("--yaw-mrad", type=float, default=0.0, help="wheelset yaw angle (-50 ... 50 mrad)")
    p.add_argument("--amplitudes-mm", default=None,
                   help="comma-separated amplitudes for the equivalent conicity (0.1 ... 20 mm, "
                        "default 2,3,4)")
    p.add_argument("--load-kN", type=float, default=None,
                   help="also solve the quasi-static elastic contact under this vertical load per "
                        "wheel (Hertz normal forces balance the load) and report normal and "
                        "lateral forces per contact (0.5 ... 500 kN)")
    p.add_argument("-o", "--out", default=None, help="output folder (default: print only)")
    add_accept_option(p)
    p.set_defaults(func=run_contact_table)
    return p


def _load_wheel(args, r0):
    from ..contact.profiles import WheelProfile

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
    check_file_option("--wheel", spec, builtin=["S1002"])
    back = args.wheel_back_mm
    if back is None:
        back = -70.0 if args.wheel_flange_side == "negative" else 70.0
    elif not math.isfinite(back):
        raise InputError(f"--wheel-back-mm {back!r}: not a finite number (mm in the wheel file's "
                         "lateral coordinate, e.g. -70)")
    return WheelProfile.from_file(spec, r0=r0, y_back=back, flange_side=args.wheel_flange_side,
                                  vertical=args.wheel_vertical)


def _load_rail(args):
    from ..contact.profiles import RailProfile

    spec = args.rail
    if spec.upper() == "UIC60":
        given = [opt for opt, val, default in (
            ("--rail-field-side", args.rail_field_side, "positive"),
            ("--rail-vertical", args.rail_vertical, "height")) if val != default]
        if given:
            raise InputError(f"{', '.join(given)}: only for a rail profile file, not the built-in UIC60")
        return RailProfile.uic60()
    check_file_option("--rail", spec, builtin=["UIC60"])
    return RailProfile.from_file(spec, field_side=args.rail_field_side, vertical=args.rail_vertical)


def _check_contact_table_options(args):
    """Every option of contact-table against its plausible range (one line naming the option,
    the value and the likely unit slip); returns the values in SI as a dict."""
    from ..track import parse_inclination

    acc = args.accept or ()
    from core.inputs import ImplausibleValueError

    v = {"n": int(option("contact_table_points", args.n, "--n", accept=acc)), "y_max_error": None}
    try:
        v["y_max"] = option("contact_table_lateral_shift", args.y_max_mm, "--y-max-mm", "mm", acc)
    except ImplausibleValueError as exc:
        if not (exc.value > 0 and not exc.suggestion):
            raise
        # too large, and not a unit slip: the flangeway clearance names the limit (_check_fit)
        v["y_max"], v["y_max_error"] = exc.value, exc
    v.update({
        "gauge": option("gauge", args.gauge_mm, "--gauge-mm", "mm", acc),
        "flange_back": option("flange_back_spacing", args.flange_back_mm, "--flange-back-mm", "mm", acc),
        "r0": option("nominal_wheel_radius", args.r0_mm, "--r0-mm", "mm", acc),
        "yaw": option("wheelset_yaw_angle", args.yaw_mrad, "--yaw-mrad", "mrad", acc),
    })
    try:
        v["inclination"] = parse_inclination(args.inclination)
    except InputError as exc:
        raise InputError(f"--inclination {args.inclination}: {exc}") from None
    option("rail_inclination", v["inclination"], "--inclination", accept=acc)
    if args.load_kN is not None:
        v["load"] = option("wheel_normal_load", args.load_kN, "--load-kN", "kN", acc)
    if v["flange_back"] >= v["gauge"]:
        raise InputError(f"--flange-back-mm {args.flange_back_mm:g} is not below --gauge-mm "
                         f"{args.gauge_mm:g}: the flanges run inside the rails (standard gauge: 1435 "
                         "and 1360)")
    explicit = args.amplitudes_mm is not None
    text = args.amplitudes_mm if explicit else "2,3,4"
    try:
        amps_mm = [float(a) for a in text.split(",") if a.strip()]
    except ValueError:
        raise InputError(f"--amplitudes-mm {text!r}: expected numbers in mm separated by commas, "
                         "e.g. 2,3,4") from None
    if not amps_mm:
        raise InputError(f"--amplitudes-mm {text!r}: give at least one amplitude, e.g. 2,3,4")
    amps = [option("conicity_amplitude", a, "--amplitudes-mm", "mm", acc) for a in amps_mm]
    too_big = [a for a, si in zip(amps_mm, amps) if si > v["y_max"] and v["y_max_error"] is None]
    if too_big and explicit:
        raise InputError(f"--amplitudes-mm {text}: the amplitude {too_big[0]:g} mm exceeds --y-max-mm "
                         f"{args.y_max_mm:g} (the table must cover the amplitude; give --y-max-mm "
                         f">= {max(amps_mm):g})")
    v["amplitudes"] = np.array(sorted(set(amps)))
    v["amplitudes_explicit"] = explicit
    return v


def _flange_geometry(wheel):
    """Flange thickness Sd (m; at 10 mm above the tread datum, 70 mm from the back face, EN 15313),
    flange height (m; tip above the datum), the largest flange angle (rad) and the flange climb
    (m): the lateral travel from flange contact until the tip reaches the rail top, height/tan(angle)."""
    datum = wheel.y_back + 0.070 if wheel.y_back < wheel.y_tip else wheel.y_back - 0.070
    ys = np.linspace(wheel.y_tip, datum, 4001)  # from the tip to the datum
    F, dF, _ = wheel.evaluate(ys)
    F0 = float(wheel.evaluate(np.array([datum]))[0][0])
    height = float(F[0] - F0)
    above = np.nonzero(F - F0 >= 0.010)[0]
    sd = float(abs(ys[above[-1]] - wheel.y_back)) if above.size else math.nan
    angle = float(np.max(np.arctan(np.abs(dF))))
    climb = height / math.tan(angle) if angle > 0 else math.inf
    return sd, height, angle, climb


def _check_fit(wheel, rail, v, args):
    """The centred wheelset must stand on both rails with its flanges clear of them."""
    from ..contact.geometry import contact_geometry_table

    sd, _, _, _ = _flange_geometry(wheel)
    play = (v["gauge"] - v["flange_back"] - 2.0 * sd) / 2.0 if math.isfinite(sd) else math.nan
    detail = (f"gauge {args.gauge_mm:g} mm - flange-back {args.flange_back_mm:g} mm - 2 x flange "
              f"thickness {sd * 1e3:.1f} mm leaves {play * 1e3:.1f} mm each side"
              if math.isfinite(play) else f"gauge {args.gauge_mm:g} mm, flange-back {args.flange_back_mm:g} mm")
    typical = f"{(v['gauge'] - 2 * sd - 0.010) * 1e3:.0f}" if math.isfinite(sd) else "gauge - 75"
    from core.errors import RUN_FAILURES

    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            row = contact_geometry_table(np.array([0.0]), yaw=v["yaw"], wheel=wheel, rail=rail,
                                         gauge=v["gauge"], inclination=v["inclination"],
                                         flange_back_spacing=v["flange_back"],
                                         accept=args.accept or ()).iloc[0]
    except RUN_FAILURES as exc:
        # the centred wheelset on nominal track: a failure here comes from the profiles
        raise InputError(f"--wheel {args.wheel}, --rail {args.rail}: the centred wheelset cannot be placed "
                         f"on the rails ({type(exc).__name__}: {exc}); check that the rail file is a rail "
                         "head (a convex crown, heights up) and the wheel file a wheel (flange, tread)") from None
    if row["status"] != "ok" or bool(row["flange_L"]) or bool(row["flange_R"]):
        raise InputError(f"--flange-back-mm {args.flange_back_mm:g}: the wheelset does not fit the track: "
                         f"centred, its flanges touch the rails ({detail}); for this wheel and gauge "
                         f"the flange-back spacing is about {typical} mm")
    if math.isfinite(play) and play > 0.030 and "flange_back_spacing" not in (args.accept or ()):
        raise InputError(f"--flange-back-mm {args.flange_back_mm:g}: the wheelset has {play * 1e3:.0f} mm of "
                         f"play each side ({detail}; track and wheel limits allow some 5-30 mm); for this "
                         f"wheel and gauge the flange-back spacing is about {typical} mm "
                         "(to use it deliberately: --accept flange_back_spacing)")
    # the largest shift: at most the flangeway clearance (flange contact onset, from a table of
    # 0.25 mm steps located by bisection) plus the flange climb, beyond which the wheelset derails
    from ..contact.geometry import flange_contact_onset

    _, height, angle, climb = _flange_geometry(wheel)
    play_ = play if math.isfinite(play) else 0.01
    # the estimate play_ is within about 1-2 mm of the onset (gauge and flange thickness are
    # measured at different heights): locate the onset exactly only when the limit is near
    if v["y_max"] > play_ + climb - 0.005 or v["y_max_error"] is not None:
        ys = np.arange(0.0, max(play_, 0.0) + 0.005 + 1e-9, 2.5e-4)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            t = contact_geometry_table(ys, yaw=v["yaw"], wheel=wheel, rail=rail, gauge=v["gauge"],
                                       inclination=v["inclination"], flange_back_spacing=v["flange_back"],
                                       accept=args.accept or ())
        try:
            y_f, _ = flange_contact_onset(t, wheel=wheel, rail=rail)
        except NumericalFailure:  # the bisection stopped: the first table row is near enough here
            y_f, _ = flange_contact_onset(t, wheel=wheel, rail=rail, exact=False)
        if np.isfinite(y_f) and v["y_max"] > y_f + climb:
            raise InputError(
                f"--y-max-mm {args.y_max_mm:g}: beyond the flangeway clearance {y_f * 1e3:.2f} mm (flange "
                f"contact from there) plus the flange climb {climb * 1e3:.1f} mm (flange height "
                f"{height * 1e3:.1f} mm at {math.degrees(angle):.0f} deg) the wheelset has derailed; give "
                f"--y-max-mm <= {math.floor((y_f + climb) * 1e3):g}, e.g. 10")
    if v["y_max_error"] is not None:
        raise v["y_max_error"]


def _regime(df, wheel):
    """Per row: "tread", "flange" (flange contact on the flank or the root) or "flange climb"
    (the contact has passed the top of the flank: the wheel is climbing its flange); other
    statuses are kept."""
    top = wheel.y_flank_top
    out = np.where(df["status"] == "ok", "tread", df["status"].astype(str))
    fl = (df["status"] == "ok") & (df["flange_L"].astype(bool) | df["flange_R"].astype(bool))
    out = np.where(fl, "flange", out)
    climb = (df["status"] == "ok") & (
        (df["flange_L"].astype(bool) & (df["y_wheel_L [m]"] < top))
        | (df["flange_R"].astype(bool) & (df["y_wheel_R [m]"] < top)))
    return np.where(climb, "flange climb", out)


def run_contact_table(args) -> int:
    """Compute the table, print a summary, and write CSV/Markdown/PNG when ``--out`` is given.

    Every option is checked first (plausible ranges of ``data/railway/plausible_ranges.csv`` in
    the option's unit, the profile files, the wheelset fitting the track); then the table's
    lateral step against the smallest conicity amplitude (:data:`POINTS_PER_AMPLITUDE`; a
    conicity it cannot resolve is NaN with a :class:`ConicityResolutionWarning`), and the largest
    shift against the flangeway clearance plus the flange climb (refused beyond: the wheelset
    would have derailed).  Rows with the wheel climbing its flange are marked in the column
    ``regime`` and counted in the summary.
    """
    from ..contact.geometry import (
        conicity_table,
        contact_geometry_table,
        contact_transitions,
        flange_contact_onset,
    )

    v = _check_contact_table_options(args)
    if args.out:  # a path that is a file is refused before the computation, not after it
        from core.paths import output_folder

        output_folder(args.out)
    amps = v["amplitudes"]
    load = args.load_kN
    wheel = _load_wheel(args, v["r0"])
    rail = _load_rail(args)
    _check_fit(wheel, rail, v, args)
    n, y_max = v["n"], v["y_max"]
    step = 2.0 * y_max / (n - 1)
    resolved = amps >= POINTS_PER_AMPLITUDE * step * (1 - 1e-12)
    coarse = ~resolved & (amps <= y_max)  # (a default amplitude beyond y_max: noted in the summary)
    if np.any(coarse):
        a_min = float(amps[coarse].min())
        need = math.ceil(2.0 * y_max * POINTS_PER_AMPLITUDE / a_min * (1 - 1e-12)) + 1
        warnings.warn(ConicityResolutionWarning(
            f"--n {n}: the lateral step {step * 1e3:.3g} mm is too coarse for the conicity at "
            + ", ".join(f"{a * 1e3:g}" for a in amps[coarse])
            + f" mm (at least {POINTS_PER_AMPLITUDE} steps per amplitude); not computed: give --n >= "
            f"{need} for --y-max-mm {args.y_max_mm:g}"), stacklevel=2)
    y = np.linspace(-y_max, y_max, n)
    geo = dict(yaw=v["yaw"], wheel=wheel, rail=rail, gauge=v["gauge"], inclination=v["inclination"],
               flange_back_spacing=v["flange_back"], accept=args.accept or ())
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # rows out of reach: reported by status
        df = contact_geometry_table(y, **geo)
    trans = contact_transitions(df, wheel=wheel, rail=rail)
    onset_note = ""
    try:
        y_f, g_f = flange_contact_onset(df, wheel=wheel, rail=rail, transitions=trans)
    except NumericalFailure as exc:  # the bisection between two rows failed: report the row
        y_f, g_f = flange_contact_onset(df, wheel=wheel, rail=rail, exact=False)
        onset_note = f" (at the first table row: {exc})"
    angle = _flange_geometry(wheel)[2]
    df["regime"] = _regime(df, wheel)
    con = conicity_table(df, amps[(amps <= y_max) & resolved])
    con = con.set_index("amplitude [m]").reindex(amps).rename_axis("amplitude [m]").reset_index()
    summary = [
        (f"wheel {wheel.name}, rail {rail.name}, gauge {args.gauge_mm:g} mm, inclination "
         f"{args.inclination}, flange-back {args.flange_back_mm:g} mm, r0 {args.r0_mm:g} mm"),
    ]
    bad = df[df["status"] != "ok"]
    if len(bad):
        summary.append(f"{len(bad)} of {len(df)} lateral shifts have no rigid contact and are left "
                       f"out of every figure below (from {bad['y [m]'].min() * 1e3:.3f} to "
                       f"{bad['y [m]'].max() * 1e3:.3f} mm; first: {bad['status'].iloc[0]})")
    if np.isfinite(y_f) and onset_note:
        summary.append(f"flange contact from lateral shift {y_f * 1e3:.4f} mm{onset_note}")
    elif np.isfinite(y_f):
        summary.append(f"flange contact from lateral shift {y_f * 1e3:.4f} mm (located by "
                       f"bisection to 0.1 um), contact angle {np.degrees(g_f):.2f} deg")
    climbing = df[df["regime"] == "flange climb"]
    if len(climbing):
        ay = climbing["y [m]"].abs() * 1e3
        text = (f"{len(climbing)} of {len(df)} lateral shifts (|y| from {ay.min():.3f} mm) have a wheel "
                f"past the top of its flange flank ({math.degrees(angle):.0f} deg): climbing its "
                "flange, not a position a running wheelset holds (column regime = 'flange climb')")
        summary.append(text)
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
        a = row["amplitude [m]"]
        if a > y_max:
            summary.append(f"equivalent conicity at {a * 1e3:g} mm: not computed (beyond --y-max-mm "
                           f"{args.y_max_mm:g})")
            continue
        if a < POINTS_PER_AMPLITUDE * step * (1 - 1e-12):
            summary.append(f"equivalent conicity at {a * 1e3:g} mm: not computed (lateral step "
                           f"{step * 1e3:.3g} mm; give --n >= "
                           f"{math.ceil(2 * y_max * POINTS_PER_AMPLITUDE / a * (1 - 1e-12)) + 1})")
            continue
        summary.append(
            f"equivalent conicity at {row['amplitude [m]'] * 1e3:g} mm: "
            f"{row['conicity wavelength [-]']:.4f} (wavelength), "
            f"{row['conicity harmonic [-]']:.4f} (harmonic), dr/2y {row['delta_r/2y [-]']:.4f}")
    qs = None
    if load is not None:
        from ..contact.quasi_static import quasi_static_contact, quasi_static_summary

        qs = quasi_static_contact(y, v["load"], **geo)
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
