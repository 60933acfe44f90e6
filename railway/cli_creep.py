"""``mbsuite railway creep-curve``: creep force curves of any creep model (tables + PNG).

Units at this command-line edge: load in kN, lengths in mm, moduli in GPa, spin creepage in 1/m;
everything is converted to SI before :func:`railway.creep_curve.creep_curve` is called.

Example::

    mbsuite railway creep-curve --model polach2000 --model fastsim --creepage xi \\
        --max 0.01 --load-kN 100 --a-mm 6 --b-mm 4 --mu 0.3 -o out/creep
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path

import numpy as np

__all__ = ["add_creep_curve_parser", "run_creep_curve"]


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
    from .creep import CREEP_MODELS

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
                   help="end of the sweep (default 0.01, or 2 1/m for phi)")
    p.add_argument("--n", type=int, default=101, help="number of points")
    p.add_argument("--xi", type=float, default=0.0, help="fixed longitudinal creepage [-]")
    p.add_argument("--eta", type=float, default=0.0, help="fixed lateral creepage [-]")
    p.add_argument("--phi", type=float, default=0.0, help="fixed spin creepage [1/m]")
    p.add_argument("--load-kN", type=float, default=100.0, help="normal load [kN]")
    p.add_argument("--a-mm", type=float, default=None, help="semi-axis along rolling [mm]")
    p.add_argument("--b-mm", type=float, default=None, help="lateral semi-axis [mm]")
    p.add_argument("--wheel-radius-mm", type=float, default=460.0, help="wheel rolling radius [mm]")
    p.add_argument("--wheel-lateral-radius-mm", type=float, default=math.inf,
                   help="wheel profile radius [mm] (negative: concave; default inf = conical)")
    p.add_argument("--rail-lateral-radius-mm", type=float, default=300.0, help="rail head radius [mm]")
    p.add_argument("--E-GPa", dest="E_GPa", type=float, default=210.0, help="Young's modulus [GPa]")
    p.add_argument("--nu", type=float, default=0.28, help="Poisson ratio")
    p.add_argument("--G-GPa", dest="G_GPa", type=float, default=None,
                   help="shear modulus [GPa] (default E/(2(1+nu)))")
    p.add_argument("--mu", type=float, default=0.3, help="friction coefficient (mu0 for polach2005)")
    g = p.add_argument_group("Polach 2005")
    g.add_argument("--k-A", dest="k_A", type=float, default=1.0)
    g.add_argument("--k-S", dest="k_S", type=float, default=1.0)
    g.add_argument("--A-ratio", dest="A_ratio", type=float, default=1.0, help="mu_inf/mu0")
    g.add_argument("--B", dest="B", type=float, default=0.0, help="friction decay [s/m]")
    g.add_argument("--speed", type=float, default=20.0, help="rolling speed [m/s]")
    f = p.add_argument_group("FASTSIM")
    f.add_argument("--nx", type=int, default=40)
    f.add_argument("--ny", type=int, default=40)
    p.add_argument("-o", "--out", default="out/creep_curve", help="output folder")
    p.add_argument("--stem", default="creep_curve", help="file name stem")
    p.set_defaults(func=run_creep_curve, _creep_parser=p)
    return p


def run_creep_curve(args: argparse.Namespace) -> int:
    """Run the ``creep-curve`` command; returns the exit code (0 ok, 2 bad input)."""
    from core.plot import save_figure
    from core.results import markdown_table, write_table

    from .creep_curve import SEMI_AXIS_RANGE, creep_curve, plot_creep_curve
    from .forces import wheel_rail_curvatures

    parser = getattr(args, "_creep_parser", None)
    models = args.model or ["polach2000"]
    hi = args.max if args.max is not None else (2.0 if args.creepage == "phi" else 0.01)
    lo = args.min if args.min is not None else -hi
    try:
        if args.n < 2:
            raise ValueError(f"--n must be >= 2, got {args.n}")
        values = np.linspace(lo, hi, args.n)
        N = args.load_kN * 1e3
        E = args.E_GPa * 1e9
        G = args.G_GPa * 1e9 if args.G_GPa is not None else None
        kw = dict(normal_force=N, E=E, G=G, nu=args.nu, mu=args.mu,
                  xi=args.xi, eta=args.eta, phi=args.phi)
        if not (np.isfinite(args.load_kN) and args.load_kN > 0):
            raise ValueError(f"--load-kN {args.load_kN!r}: the normal load must be positive (kN)")
        if (args.a_mm is None) != (args.b_mm is None):
            raise ValueError("give both --a-mm and --b-mm, or neither")
        if args.a_mm is not None:
            for opt, v in (("--a-mm", args.a_mm), ("--b-mm", args.b_mm)):
                lo, hi = SEMI_AXIS_RANGE[0] * 1e3, SEMI_AXIS_RANGE[1] * 1e3
                if not (np.isfinite(v) and lo <= v <= hi):
                    raise ValueError(f"{opt} {v!r}: the semi-axis is given in millimetres and must "
                                     f"lie in [{lo:g}, {hi:g}] mm (e.g. 6)"
                                     + (" -- it looks like metres" if np.isfinite(v) and 0 < v < lo
                                        else ""))
            kw.update(a=args.a_mm * 1e-3, b=args.b_mm * 1e-3)
        else:
            A, B = wheel_rail_curvatures(args.wheel_radius_mm * 1e-3, args.wheel_lateral_radius_mm * 1e-3,
                                       args.rail_lateral_radius_mm * 1e-3)
            kw.update(A=float(A[0]), B=float(B[0]))
        params = {"polach2005": dict(k_A=args.k_A, k_S=args.k_S, A=args.A_ratio, B=args.B,
                                     speed=args.speed),
                  "fastsim": dict(n_x=args.nx, n_y=args.ny)}
        df = creep_curve(models, args.creepage, values, model_params=params, **kw)
    except ValueError as exc:
        if parser is not None:
            parser.error(str(exc))  # exits with status 2
        print(f"mbsuite railway creep-curve: error: {exc}")
        return 2
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
          f"G = {r['G [Pa]']:.4g} Pa, nu = {args.nu}, mu = {args.mu}")
    print(f"wrote {paths['csv']}, {paths['md']}, {png}")
    return 0
