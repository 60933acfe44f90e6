"""``mbsuite railway creep-curve``: creep force curves of any creep model (tables + PNG).

Units at this command-line edge: load in kN, lengths in mm, moduli in GPa, spin creepage in 1/m;
everything is converted to SI before :func:`railway.contact.creep_curve.creep_curve` is called.

Example::

    mbsuite railway creep-curve --model polach2000 --model fastsim --creepage xi \\
        --max 0.01 --load-kN 100 --a-mm 6 --b-mm 4 --mu 0.3 -o out/creep
"""

from __future__ import annotations

import argparse
import math
import sys
import warnings
from pathlib import Path

import numpy as np

from core.errors import InputError

from .checks import add_accept_option, option
from ..ranges import RailwayInputWarning

__all__ = ["add_creep_curve_parser", "run_creep_curve", "ElasticConstantsWarning"]


def add_creep_curve_parser(railway_subparsers) -> argparse.ArgumentParser:
    """Add the ``creep-curve`` sub-command to the ``railway`` sub-parsers.

    Parameters
    ----------
    railway_subparsers : argparse._SubParsersAction
        The object returned by ``railway_parser.add_subparsers(...)``.

    Returns
    -------
    argparse.ArgumentParser
        The new sub-parser (``func`` set to :func:`run_creep_curve`).
    """
    from ..contact.creep import CREEP_MODELS

    p = railway_subparsers.add_parser(
        "creep-curve",
        help="creep forces against one creepage for any creep model (CSV, Markdown, PNG)",
        description="Tangential forces Fx, Fy and spin moment Mz on the wheel against one creepage, "
                    "the other creepages held fixed. Give the semi-axes (--a-mm, --b-mm) or the radii "
                    "(Hertz computes the ellipse). Models: " + ", ".join(sorted(CREEP_MODELS)) + ".",
    )
    p.add_argument("--model", action="append", default=None,
                   help="creep model name (repeatable; default polach2000)")
    p.add_argument("--creepage", choices=("xi", "eta", "phi"), default="xi", help="swept creepage")
    p.add_argument("--min", type=float, default=None, help="start of the sweep (default -max)")
    p.add_argument("--max", type=float, default=None,
                   help="end of the sweep (default 0.01, or 2 1/m for phi; |xi|, |eta| <= 1, "
                        "|phi| <= 10 1/m)")
    p.add_argument("--n", type=int, default=101, help="number of points (2 ... 100001)")
    p.add_argument("--xi", type=float, default=0.0, help="fixed longitudinal creepage [-] (-1 ... 1)")
    p.add_argument("--eta", type=float, default=0.0, help="fixed lateral creepage [-] (-1 ... 1)")
    p.add_argument("--phi", type=float, default=0.0, help="fixed spin creepage [1/m] (-10 ... 10)")
    p.add_argument("--load-kN", type=float, default=100.0, help="normal load [kN] (0.5 ... 500)")
    p.add_argument("--a-mm", type=float, default=None, help="semi-axis along rolling [mm] (0.05 ... 100)")
    p.add_argument("--b-mm", type=float, default=None, help="lateral semi-axis [mm] (0.05 ... 100)")
    p.add_argument("--wheel-radius-mm", type=float, default=None,
                   help="wheel rolling radius [mm] (150 ... 800, default 460; not with --a-mm/--b-mm)")
    p.add_argument("--wheel-lateral-radius-mm", type=float, default=None,
                   help="wheel profile radius [mm] (negative: concave; default inf = conical; "
                        "|R| 5 ... 100000)")
    p.add_argument("--rail-lateral-radius-mm", type=float, default=None,
                   help="rail head radius [mm] (default 300; |R| 5 ... 100000)")
    p.add_argument("--E-GPa", dest="E_GPa", type=float, default=None,
                   help="Young's modulus [GPa] (50 ... 450, default 210)")
    p.add_argument("--nu", type=float, default=0.28, help="Poisson ratio (0.1 ... 0.49)")
    p.add_argument("--G-GPa", dest="G_GPa", type=float, default=None,
                   help="shear modulus [GPa] (20 ... 180; default E/(2(1+nu)))")
    p.add_argument("--mu", type=float, default=0.3,
                   help="friction coefficient (0.01 ... 1; mu0 for polach2005)")
    g = p.add_argument_group("Polach 2005 (only with --model polach2005)")
    g.add_argument("--k-A", dest="k_A", type=float, default=None, help="reduction factor k_A (0.01 ... 1, default 1)")
    g.add_argument("--k-S", dest="k_S", type=float, default=None, help="reduction factor k_S <= k_A (default 1)")
    g.add_argument("--A-ratio", dest="A_ratio", type=float, default=None,
                   help="mu_inf/mu0 (0.05 ... 1, default 1)")
    g.add_argument("--B", dest="B", type=float, default=None, help="friction decay [s/m] (0 ... 10, default 0)")
    g.add_argument("--speed", type=float, default=None, help="rolling speed [m/s] (0 ... 150, default 20)")
    f = p.add_argument_group("FASTSIM (only with --model fastsim)")
    f.add_argument("--nx", type=int, default=None, help="strips (4 ... 400, default 40)")
    f.add_argument("--ny", type=int, default=None, help="elements per strip (4 ... 400, default 40)")
    p.add_argument("-o", "--out", default="out/creep_curve", help="output folder")
    p.add_argument("--stem", default="creep_curve", help="file name stem")
    add_accept_option(p)
    p.set_defaults(func=run_creep_curve, _creep_parser=p)
    return p


class ElasticConstantsWarning(RailwayInputWarning):
    """--E-GPa, --G-GPa and --nu given together disagree with G = E / (2 (1 + nu)) by more than
    5 %: G sets the creep forces, E the Hertz ellipse."""


def _check_models(names):
    from core.errors import UnknownNameError
    from core.inputs import closest

    from ..contact.creep import CREEP_MODELS, get_creep_model

    out = []
    for m in names:
        try:
            out.append(get_creep_model(m).name)
        except UnknownNameError:
            raise UnknownNameError(f"--model {m!r}: not a creep model{closest(m, sorted(CREEP_MODELS))} "
                                   f"(registered: {', '.join(sorted(CREEP_MODELS))})") from None
    return out


def _check_options(args):
    """Every option in SI, checked against its plausible range (in the option's unit), and the
    options that contradict one another; returns ``(models, values, kw, params)``."""
    from ..contact.creep_curve import _CREEPAGES

    acc = args.accept or ()
    if args.out is not None:
        from core.paths import output_folder

        output_folder(args.out)  # a file in the way is refused before the computation
    if not args.stem or any(c in args.stem for c in "/\\") or args.stem in (".", ".."):
        raise InputError(f"--stem {args.stem!r}: a file name without a folder, e.g. creep_curve")
    models = _check_models(args.model or ["polach2000"])
    n = int(option("creep_curve_points", args.n, "--n", accept=acc))
    sweep_q, sweep_unit = ("spin_creepage", " 1/m") if args.creepage == "phi" else ("creepage", "")
    hi = args.max if args.max is not None else (2.0 if args.creepage == "phi" else 0.01)
    lo = args.min if args.min is not None else -hi
    if args.max is not None:
        option(sweep_q, args.max, "--max", accept=acc)
    if args.min is not None:
        option(sweep_q, args.min, "--min", accept=acc)
    if not lo < hi:
        raise InputError(f"--min {lo:g} is not below --max {hi:g}{sweep_unit}: the sweep of {args.creepage} "
                         "runs from --min to --max")
    fixed = {"xi": option("creepage", args.xi, "--xi", accept=acc),
             "eta": option("creepage", args.eta, "--eta", accept=acc),
             "phi": option("spin_creepage", args.phi, "--phi", accept=acc)}
    swept_given = getattr(args, args.creepage) != 0.0
    if swept_given:
        raise InputError(f"--{args.creepage} {getattr(args, args.creepage):g}: {args.creepage} is the swept "
                         "creepage (--creepage); give its range with --min/--max")
    N = option("wheel_normal_load", args.load_kN, "--load-kN", "kN", acc)
    nu = option("poisson_ratio", args.nu, "--nu", accept=acc)
    mu = option("friction_coefficient", args.mu, "--mu", accept=acc)
    E = option("youngs_modulus", 210.0 if args.E_GPa is None else args.E_GPa, "--E-GPa", "GPa", acc)
    G = option("shear_modulus", args.G_GPa, "--G-GPa", "GPa", acc) if args.G_GPa is not None else None
    if args.E_GPa is not None and G is not None:
        G_E = E / (2.0 * (1.0 + nu))
        if abs(G - G_E) > 0.05 * G_E:
            warnings.warn(ElasticConstantsWarning(
                f"--G-GPa {args.G_GPa:g} disagrees with --E-GPa {args.E_GPa:g} and --nu {args.nu:g} "
                f"(E/(2(1+nu)) = {G_E / 1e9:.1f} GPa): G sets the creep forces, E the Hertz ellipse"),
                stacklevel=2)
    kw = dict(normal_force=N, E=E, G=G, nu=nu, mu=mu, **fixed)
    radii = {"--wheel-radius-mm": args.wheel_radius_mm, "--wheel-lateral-radius-mm": args.wheel_lateral_radius_mm,
             "--rail-lateral-radius-mm": args.rail_lateral_radius_mm}
    if (args.a_mm is None) != (args.b_mm is None):
        raise InputError("give both --a-mm and --b-mm, or neither (then Hertz computes them from the radii)")
    if args.a_mm is not None:
        given = [k for k, r in radii.items() if r is not None]
        if given:
            raise InputError(f"{', '.join(given)} with --a-mm/--b-mm: the semi-axes are given, the radii "
                             "would not be used; give one or the other")
        kw.update(a=option("contact_semi_axis", args.a_mm, "--a-mm", "mm", acc),
                  b=option("contact_semi_axis", args.b_mm, "--b-mm", "mm", acc))
    else:
        from ..contact.forces import wheel_rail_curvatures

        R_w = option("nominal_wheel_radius", 460.0 if args.wheel_radius_mm is None else args.wheel_radius_mm,
                     "--wheel-radius-mm", "mm", acc)
        lat = []
        for name, r, default in (("--wheel-lateral-radius-mm", args.wheel_lateral_radius_mm, math.inf),
                                 ("--rail-lateral-radius-mm", args.rail_lateral_radius_mm, 300.0)):
            r = default if r is None else r
            if math.isnan(r):
                raise InputError(f"{name} nan: not a number (mm; inf for a straight profile)")
            if math.isinf(r):
                lat.append(math.inf)
                continue
            if r == 0:
                raise InputError(f"{name} 0: a radius of zero is a sharp edge, not a Hertz contact "
                                 "(mm; inf for a straight profile)")
            mag = option("profile_lateral_radius", abs(r), name, "mm", acc)
            lat.append(math.copysign(mag, r))
        try:
            A, B = wheel_rail_curvatures(R_w, lat[0], lat[1])
        except InputError as exc:
            raise InputError(f"--wheel-lateral-radius-mm {_mm(lat[0])}, --rail-lateral-radius-mm "
                             f"{_mm(lat[1])}: {exc}") from None
        kw.update(A=float(A[0]), B=float(B[0]))
    params = {}
    pol = {"--k-A": args.k_A, "--k-S": args.k_S, "--A-ratio": args.A_ratio, "--B": args.B, "--speed": args.speed}
    fast = {"--nx": args.nx, "--ny": args.ny}
    for group, model in ((pol, "polach2005"), (fast, "fastsim")):
        given = [k for k, val in group.items() if val is not None]
        if given and model not in models:
            raise InputError(f"{', '.join(given)}: only for --model {model} (the models are "
                             f"{', '.join(models)})")
    if "polach2005" in models:
        k_A = option("polach_reduction_factor", 1.0 if args.k_A is None else args.k_A, "--k-A", accept=acc)
        k_S = option("polach_reduction_factor", 1.0 if args.k_S is None else args.k_S, "--k-S", accept=acc)
        if k_S > k_A:
            raise InputError(f"--k-S {k_S:g} is larger than --k-A {k_A:g}: Polach (2005) has k_S <= k_A <= 1 "
                             "(the slip area reduces the creep stiffness more than the adhesion area)")
        params["polach2005"] = dict(
            k_A=k_A, k_S=k_S,
            A=option("polach_friction_ratio", 1.0 if args.A_ratio is None else args.A_ratio, "--A-ratio", accept=acc),
            B=option("polach_friction_decay", 0.0 if args.B is None else args.B, "--B", accept=acc),
            speed=option("speed", 20.0 if args.speed is None else args.speed, "--speed", accept=acc))
    if "fastsim" in models:
        params["fastsim"] = dict(
            n_x=int(option("fastsim_grid_points", 40 if args.nx is None else args.nx, "--nx", accept=acc)),
            n_y=int(option("fastsim_grid_points", 40 if args.ny is None else args.ny, "--ny", accept=acc)))
    values = np.linspace(lo, hi, n)
    assert args.creepage in _CREEPAGES
    return models, values, kw, params


def _mm(r_m: float) -> str:
    return "inf" if math.isinf(r_m) else f"{r_m * 1e3:g}"


def run_creep_curve(args: argparse.Namespace) -> int:
    """Run the ``creep-curve`` command; returns the exit code (0 ok, 2 bad input).

    Every option is checked first (:func:`_check_options`: plausible ranges in the option's
    unit, contradictory options); bad input raises (via the parser's ``error``: a one-line
    ``mbsuite: error: ...`` from :func:`core.cli.main`).
    """
    from core.errors import MbsuiteError
    from core.plot import save_figure
    from core.results import markdown_table, write_table

    from ..contact.creep_curve import creep_curve, plot_creep_curve

    parser = getattr(args, "_creep_parser", None)
    try:
        models, values, kw, params = _check_options(args)
        df = creep_curve(models, args.creepage, values, model_params=params,
                         accept=tuple(args.accept or ()), **kw)
    except (MbsuiteError, ValueError) as exc:
        from core.cli import Parser

        if isinstance(parser, Parser):
            raise  # core.cli.main: one line, exit 2
        if parser is not None:  # a plain argparse parser (library use): its usage and the message, exit 2
            parser.error(" ".join(str(exc).split()))
        print(f"mbsuite railway creep-curve: error: {exc}", file=sys.stderr)
        return 2
    N, nu, mu = kw["normal_force"], kw["nu"], kw["mu"]
    out = Path(args.out)
    paths = write_table(df, out, args.stem)
    fig = plot_creep_curve(df, args.creepage)
    png = save_figure(fig, out, args.stem)
    swept = df.attrs["swept"]
    pick = np.unique(np.linspace(0, args.n - 1, 5).round().astype(int))
    rows = df.groupby("model", sort=False).nth(pick)
    cols = ["model", swept, "Fx [N]", "Fy [N]", "Mz [N m]"]
    print(markdown_table(rows[cols], floatfmt=".4g"))
    r = df.iloc[0]
    print(f"contact: N = {N:g} N, a = {r['a [m]']:.4g} m, b = {r['b [m]']:.4g} m, "
          f"G = {r['G [Pa]']:.4g} Pa, nu = {nu:g}, mu = {mu:g}")
    print(f"wrote {paths['csv']}, {paths['md']}, {png}")
    return 0
