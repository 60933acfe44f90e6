"""Creep curves: tangential forces and spin moment against one creepage, for any creep model.

The swept creepage (xi, eta or phi) takes the given values while the other two are held fixed;
the contact is given by its normal load and semi-axes, or by the curvatures and elastic constants
(the semi-axes then follow from Hertz, :func:`core.contact_laws.hertz_from_load`).

References
----------
See :mod:`railway.contact.creep` (Kalker 1990; Polach 2000, 2005; Shen, Hedrick & Elkins 1983; Kalker 1982).
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from core.contact_laws import hertz_from_load
from core.errors import InputError
from core.inputs import checked_options, closest

from .creep import get_creep_model

__all__ = ["SEMI_AXIS_RANGE", "creep_curve", "plot_creep_curve", "semi_axes_from_curvatures"]

_CREEPAGES = {"xi": "xi [-]", "eta": "eta [-]", "phi": "phi [1/m]"}

#: Plausible semi-axes (m) of a wheel-rail contact given by hand: from 0.05 mm (a lightly
#: loaded flange tip) to 0.1 m (a fully conformal worn contact is below 20 mm); a value outside
#: is taken for a unit slip (micrometres: metres given where mm are expected, or the reverse).
SEMI_AXIS_RANGE = (5e-5, 0.1)


def semi_axes_from_curvatures(normal_force, A, B, E, nu):
    """Hertz semi-axes (a rolling, b lateral) [m] for equal materials (E [Pa], nu) on both bodies.

    Returns
    -------
    a, b : float
    """
    h = hertz_from_load(normal_force, A, B, E, nu, E, nu)
    return float(h.a[0]), float(h.b[0])


@checked_options
def creep_curve(models="polach2000", creepage: str = "xi", values=None, *, normal_force,
                a=None, b=None, A=None, B=None, E=None, G=None, nu=0.28, mu=0.3,
                xi=0.0, eta=0.0, phi=0.0, model_params=None, accept=()) -> pd.DataFrame:
    """Creep forces along a sweep of one creepage, for one or several creep models.

    Parameters
    ----------
    models : str or sequence of str / CreepModel
        Registered model names (see :data:`railway.contact.creep.CREEP_MODELS`) or instances.
    creepage : {"xi", "eta", "phi"}
        The swept creepage.
    values : (k,) array_like, optional
        Swept values ([-] for xi, eta; [1/m] for phi); default 101 points over +-0.01 (xi, eta) or
        +-2 1/m (phi).
    normal_force : float
        Normal load N [N], > 0.
    a, b : float, optional
        Semi-axes along the rolling direction and lateral [m], within :data:`SEMI_AXIS_RANGE`
        (an InputError names a value outside, e.g. micrometres from a unit slip).  If omitted,
        computed by Hertz from ``A``, ``B`` [1/m] and ``E`` [Pa], ``nu`` (same material for
        wheel and rail).
    G : float, optional
        Shear modulus [Pa]; default E/(2(1 + nu)) (E required then).
    nu, mu : float
        Poisson ratio and friction coefficient.
    xi, eta, phi : float
        The creepages held fixed (the swept one is ignored).
    model_params : dict, optional
        ``{model_name: {param: value}}`` constructor parameters.
    accept : iterable of str
        Quantities of ``data/railway/plausible_ranges.csv`` whose range is not enforced
        (``wheel_normal_load``, ``friction_coefficient``, ``poisson_ratio``, ``youngs_modulus``,
        ``shear_modulus``, ``creepage``, ``spin_creepage``): a deliberate outlier.

    Raises
    ------
    core.inputs.ImplausibleValueError
        A value outside its plausible range (the likely unit slip named), e.g. ``mu = 30`` (per
        cent) or ``E = 210`` (GPa given as Pa).

    Returns
    -------
    DataFrame
        Long format, one row per model and value: "model", "xi [-]", "eta [-]", "phi [1/m]",
        "Fx [N]", "Fy [N]", "Mz [N m]", "Fx/(mu N) [-]", "Fy/(mu N) [-]", plus the contact
        "N [N]", "a [m]", "b [m]", "G [Pa]", "nu [-]", "mu [-]".
    """
    if creepage not in _CREEPAGES:
        raise InputError(f"creep curve: creepage {creepage!r} is not one of {sorted(_CREEPAGES)}"
                         f"{closest(str(creepage), sorted(_CREEPAGES))}")
    try:
        N = float(normal_force)
    except (TypeError, ValueError):
        raise InputError(f"creep curve: normal_force = {normal_force!r} N is not a number") from None
    if not (np.isfinite(N) and N > 0):
        raise InputError(f"creep curve: normal_force = {normal_force!r} N must be positive (the "
                         "curve is normalised by mu N; a creep curve of an unloaded contact is "
                         "zero)")
    from ..ranges import ranges

    R = ranges()
    R.check("wheel_normal_load", N, where="creep curve: normal_force", accept=accept)
    R.check("friction_coefficient", mu, where="creep curve: mu", accept=accept)
    R.check("poisson_ratio", nu, where="creep curve: nu", accept=accept)
    for key, val in (("E", E), ("G", G)):
        if val is not None:
            R.check("youngs_modulus" if key == "E" else "shear_modulus", val, where=f"creep curve: {key}",
                    accept=accept)
    for key, val in (("xi", xi), ("eta", eta), ("phi", phi)):
        if key != creepage:
            R.check("spin_creepage" if key == "phi" else "creepage", val, where=f"creep curve: {key}",
                    accept=accept)
    if a is None or b is None:
        if A is None or B is None or E is None:
            raise InputError(f"creep curve: give the semi-axes a and b, or the curvatures A and B with Young's "
                             f"modulus E (got a={a!r}, b={b!r}, A={A!r}, B={B!r}, E={E!r})")
        a, b = semi_axes_from_curvatures(normal_force, A, B, E, nu)
    else:
        for key, val in (("a", a), ("b", b)):
            v = float(val)
            if not (SEMI_AXIS_RANGE[0] <= v <= SEMI_AXIS_RANGE[1]):
                raise InputError(
                    f"creep curve: semi-axis {key} = {val!r} m is implausible for a wheel-rail "
                    f"contact (expected {SEMI_AXIS_RANGE[0]:g} to {SEMI_AXIS_RANGE[1]:g} m, e.g. "
                    f"0.006); semi-axes are in metres"
                    + (" -- was it given in millimetres?" if v > SEMI_AXIS_RANGE[1] else ""))
    if G is None:
        if E is None:
            raise InputError("creep curve: give the shear modulus G or Young's modulus E (both are None), e.g. "
                             "G=8e10 (Pa) for steel")
        G = E / (2.0 * (1.0 + nu))
    if values is None:
        lim = 2.0 if creepage == "phi" else 0.01
        values = np.linspace(-lim, lim, 101)
    values = np.asarray(values, dtype=float)
    if values.ndim != 1 or values.size == 0:
        raise InputError(f"creep curve: values (the swept {creepage}) must be a non-empty 1-D array, got shape "
                         f"{values.shape}")
    if values.size:
        R.check("spin_creepage" if creepage == "phi" else "creepage", [values.min(), values.max()],
                where=f"creep curve: swept {creepage} (smallest, largest)", accept=accept)
    if isinstance(models, (str, bytes)) or not np.iterable(models):
        models = [models]
    model_params = model_params or {}
    fixed = {"xi": xi, "eta": eta, "phi": phi}
    cols = {k: np.full(values.size, float(v)) for k, v in fixed.items()}
    cols[creepage] = values
    frames = []
    for m in models:
        params = model_params.get(m, {}) if isinstance(m, str) else {}
        model = get_creep_model(m, **params)
        f = model(cols["xi"], cols["eta"], cols["phi"], normal_force, a, b, G, nu, mu)
        frames.append(pd.DataFrame({
            "model": model.name,
            "xi [-]": cols["xi"], "eta [-]": cols["eta"], "phi [1/m]": cols["phi"],
            "Fx [N]": f.Fx, "Fy [N]": f.Fy, "Mz [N m]": f.Mz,
            "Fx/(mu N) [-]": f.Fx / (mu * normal_force), "Fy/(mu N) [-]": f.Fy / (mu * normal_force),
            "N [N]": float(normal_force), "a [m]": float(a), "b [m]": float(b), "G [Pa]": float(G),
            "nu [-]": float(nu), "mu [-]": float(mu),
        }))
    df = pd.concat(frames, ignore_index=True)
    df.attrs["swept"] = _CREEPAGES[creepage]
    return df


def plot_creep_curve(df: pd.DataFrame, creepage: str | None = None, ax=None):
    """Plot Fx, Fy and Mz of a :func:`creep_curve` table against the swept creepage.

    Parameters
    ----------
    df : DataFrame
        Output of :func:`creep_curve`.
    creepage : {"xi", "eta", "phi"}, optional
        Swept creepage; default from ``df.attrs["swept"]``.
    ax : sequence of 2 matplotlib Axes, optional
        Axes for the forces and the moment; a new Figure (Agg, no pyplot) is created if None.

    Returns
    -------
    matplotlib.figure.Figure
    """
    from matplotlib.figure import Figure

    xcol = _CREEPAGES[creepage] if creepage else df.attrs.get("swept", "xi [-]")
    if ax is None:
        fig = Figure(figsize=(9, 4), layout="constrained")
        ax = fig.subplots(1, 2)
    else:
        fig = ax[0].figure
    for name, sub in df.groupby("model", sort=False):
        ax[0].plot(sub[xcol], sub["Fx [N]"] / 1e3, label=f"{name} Fx")
        ax[0].plot(sub[xcol], sub["Fy [N]"] / 1e3, "--", label=f"{name} Fy")
        ax[1].plot(sub[xcol], sub["Mz [N m]"], label=name)
    ax[0].set_xlabel(xcol)
    ax[0].set_ylabel("force on wheel [kN]")
    ax[0].legend(fontsize="small")
    ax[0].grid(True, alpha=0.3)
    ax[1].set_xlabel(xcol)
    ax[1].set_ylabel("Mz [N m]")
    ax[1].grid(True, alpha=0.3)
    ax[1].legend(fontsize="small")
    r = df.iloc[0]
    fig.suptitle(f"creep curves — N = {r['N [N]'] / 1e3:.1f} kN, a = {r['a [m]'] * 1e3:.2f} mm, "
                 f"b = {r['b [m]'] * 1e3:.2f} mm, mu = {r['mu [-]']:.2f}", fontsize="medium")
    return fig
