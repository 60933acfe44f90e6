r"""The Manchester wheel-rail contact benchmark, Case A-2.2, against CONTACT's reference results.

Case A-2.2 of Shackleton & Iwnicki (2008) as defined in CONTACT's example (user guide sect. 5.7,
``examples/mbench_a22_{left,right}.inp``): new S1002 wheels (r0 = 460 mm, flange-back distance
1360 mm) on new UIC60 rails inclined 1:40, gauge 1435 mm measured 14 mm below the top, steady
rolling at V = 2 m/s with mu = 0.3, G = 82 GPa, nu = 0.28, a vertical force of 10 kN per wheel,
lateral shifts y = 0 ... 10 mm in 0.5 mm steps with the yaw angle psi = 2.4 mrad per mm of y.

CONTACT's frame is x forward, y to the right, z down, and it reports forces on the rail; ours is
x forward, y to the left, z up, with forces on the wheel.  The same physical case is therefore
our shift -y and yaw -psi (a shift to the right, nose turned right: the RIGHT wheel climbs its
flange in both codes); roll about x has the same sign in both frames and the pitch velocity
flips sign (ours is the spin Omega about the axle pointing left).  Per wheel, with sigma = +1
left and -1 right, CONTACT's values map to ours as::

    Fy on the wheel (track, left +)  =  FY(TR)          Fz on the wheel (up +)  =  FZ(TR)
    Fx on the wheel (forward +)      = -FX(TR)          Y (wheel on rail, field side +) = -sigma FY(TR)
    contact angle (towards the track centre +) = sigma DELTCP(TR)
    y_wheel (negative towards the flange)      = -sigma YCP(W)
    p_max = PMAX,  N = FN,  Omega = -VPITCH

:func:`compare_with_contact` puts both side by side per case and wheel.  CONTACT solves the
exact (non-Hertzian, boundary-element) normal and tangential problem on a 0.2 mm grid and
combines regions closer than 4 mm into one patch; we solve one Hertz ellipse per contact
candidate (tread, flange) with a creep law, so the comparison measures the Hertz + creep-law
approximation, not two implementations of one method.

The reference numbers are CONTACT's own results for its example (open-source CONTACT, Revision
2447, Apache-2.0), stored in ``data/railway/manchester_contact_a22_contact_rev2447.csv``; they
are not the tables printed in the 2008 paper, which were not available.

References
----------
Shackleton, P. and Iwnicki, S. (2008). Comparison of wheel-rail contact codes for railway
vehicle simulation: an introduction to the Manchester Contact Benchmark and initial results.
Vehicle System Dynamics 46(1-2):91-120 (Case A-2.2; its tables were not available here).
Vollebregt, E. A. H. CONTACT user guide, sect. 5.7 "The Manchester wheel-rail benchmark"
(repository eve70a/CONTACT, ``doc/user-guide.tex``), and the example files named above.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from core.errors import DataFileError

__all__ = [
    "MANCHESTER_A22",
    "manchester_cases",
    "load_contact_reference",
    "contact_reference_per_wheel",
    "run_manchester_a22",
    "compare_with_contact",
    "rail_profile_check",
]

#: The setting of Case A-2.2 as in CONTACT's example (SI units).
MANCHESTER_A22 = dict(
    wheel_load=10e3,            # N per wheel (FZ = 10 kN)
    speed=2.0,                  # m/s (VS = 2000 mm/s)
    mu=0.3,                     # FSTAT = FKIN
    G=82e9, nu=0.28,            # GG, POISS of both bodies
    gauge=1.435, gauge_depth=0.014, inclination=1 / 40, flange_back_spacing=1.360, r0=0.46,
    y_step=0.5e-3, n_cases=21, yaw_per_shift=2.4,  # psi = 2.4 mrad per mm of y
)

_REF_FILE = ("railway", "manchester_contact_a22_contact_rev2447.csv")
_RAIL_FILE = ("railway", "manchester_uic60_v3_canted_points.csv")


def manchester_cases():
    """The 21 cases in CONTACT's numbering and in our frame.

    Returns
    -------
    DataFrame
        ``case`` (1 ... 21), ``y CONTACT [m]`` (0 ... 10 mm, to the right), ``yaw CONTACT [rad]``
        (0 ... 24 mrad), and ours: ``lateral [m]`` = -y, ``yaw [rad]`` = -psi.
    """
    s = MANCHESTER_A22
    y = np.arange(s["n_cases"]) * s["y_step"]
    psi = y * s["yaw_per_shift"]
    return pd.DataFrame({"case": np.arange(1, s["n_cases"] + 1), "y CONTACT [m]": y,
                         "yaw CONTACT [rad]": psi, "lateral [m]": -y, "yaw [rad]": -psi})


def load_contact_reference():
    """CONTACT's reference results as stored (CONTACT's conventions and units, see the file).

    Returns
    -------
    DataFrame
        42 rows (``wheel`` left/right, ``case`` 1 ... 21) with the columns of the file.

    Raises
    ------
    core.errors.DataFileError
        Missing columns or cases (names the file).
    """
    from core.paths import data_path

    path = data_path(*_REF_FILE)
    df = pd.read_csv(path, comment="#")
    need = {"wheel", "case", "y_ws [mm]", "yaw_ws [mrad]", "roll_ws [rad]", "vpitch_ws [rad/s]",
            "FX(TR) [N]", "FY(TR) [N]", "FZ(TR) [N]", "DELTCP(TR) [rad]", "YCP(TR) [mm]",
            "ZCP(TR) [mm]", "YCP(R) [mm]", "YCP(W) [mm]", "FN [N]", "FX [N]", "FS [N]", "PMAX [N/mm2]",
            "CKSI [-]", "CETA [-]", "CPHI [1/mm]", "MN [N mm]", "FRIC.POWER [W]", "VELOC [mm/s]",
            "NADH [-]"}
    if not need <= set(df.columns):
        raise DataFileError(f"{path}: missing columns {sorted(need - set(df.columns))}")
    for w in ("left", "right"):
        cases = sorted(df.loc[df["wheel"] == w, "case"])
        if cases != list(range(1, 22)):
            raise DataFileError(f"{path}: wheel {w!r} must have cases 1..21, has {cases}")
    return df


def contact_reference_per_wheel():
    """CONTACT's results mapped to our frame and SI units (module docstring), per case and wheel.

    Returns
    -------
    DataFrame
        ``case``, ``side``, ``N [N]``, ``Fx track [N]``, ``Fy track [N]``, ``Fz track [N]``
        (force on the wheel), ``Y [N]``, ``Y/Q [-]``, ``contact angle [rad]``,
        ``y_wheel [m]``, ``y field [m]`` (lateral position of the patch from the track
        centre towards the field side of its rail), ``z_contact [m]`` (height, up +),
        ``p_max [Pa]``, ``roll [rad]``, ``omega [rad/s]``, ``xi [-]``, ``eta [-]``,
        ``phi [1/m]``, ``Fs [N]``, ``T_gamma [N]`` (``|FX CKSI|`` + ``|FS CETA|``),
        ``dissipation [N]`` (``|FRIC.POWER|`` / VELOC: CONTACT's frictional power per metre),
        ``full slip`` (no element in adhesion).
    """
    ref = load_contact_reference()
    sig = np.where(ref["wheel"] == "left", 1.0, -1.0)
    Fy = ref["FY(TR) [N]"].to_numpy()
    Fz = ref["FZ(TR) [N]"].to_numpy()
    out = pd.DataFrame({
        "case": ref["case"].to_numpy(), "side": ref["wheel"].to_numpy(),
        "N [N]": ref["FN [N]"].to_numpy(), "Fx track [N]": -ref["FX(TR) [N]"].to_numpy(),
        "Fy track [N]": Fy, "Fz track [N]": Fz, "Y [N]": -sig * Fy, "Y/Q [-]": -sig * Fy / Fz,
        "contact angle [rad]": sig * ref["DELTCP(TR) [rad]"].to_numpy(),
        "y_wheel [m]": -sig * ref["YCP(W) [mm]"].to_numpy() * 1e-3,
        "y field [m]": -sig * ref["YCP(TR) [mm]"].to_numpy() * 1e-3,
        "z_contact [m]": -ref["ZCP(TR) [mm]"].to_numpy() * 1e-3,
        "p_max [Pa]": ref["PMAX [N/mm2]"].to_numpy() * 1e6,
        "roll [rad]": ref["roll_ws [rad]"].to_numpy(), "omega [rad/s]": -ref["vpitch_ws [rad/s]"].to_numpy(),
        "xi [-]": ref["CKSI [-]"].to_numpy(), "eta [-]": ref["CETA [-]"].to_numpy(),
        "phi [1/m]": ref["CPHI [1/mm]"].to_numpy() * 1e3, "Fs [N]": ref["FS [N]"].to_numpy(),
        "T_gamma [N]": np.abs(ref["FX [N]"] * ref["CKSI [-]"]).to_numpy()
        + np.abs(ref["FS [N]"] * ref["CETA [-]"]).to_numpy(),
        "dissipation [N]": np.abs(ref["FRIC.POWER [W]"]).to_numpy() / (ref["VELOC [mm/s]"].to_numpy() * 1e-3),
        "full slip": (ref["NADH [-]"] == 0).to_numpy(),
    })
    return out.sort_values(["case", "side"]).reset_index(drop=True)


def run_manchester_a22(creep_law="fastsim", cases=None, creep_params=None, **kw):
    """Our quasi-static rolling solution of Case A-2.2 (:func:`railway.contact.quasi_static.quasi_static_rolling`).

    Parameters
    ----------
    creep_law : str, CreepModel class or CreepModel
        Creep law of :data:`railway.contact.creep.CREEP_MODELS`.
    cases : sequence of int, optional
        CONTACT case numbers (1 ... 21); default all.
    creep_params : dict, optional
        Constructor parameters of the creep law.
    **kw
        Further arguments of :func:`railway.contact.quasi_static.quasi_static_rolling` (e.g. ``tol``).

    Returns
    -------
    contacts, wheels : DataFrame
        The per-contact table and the per-wheel table (:func:`quasi_static_wheel_table`),
        with ``case`` in CONTACT's numbering.
    """
    from .quasi_static import quasi_static_rolling, quasi_static_wheel_table

    s = MANCHESTER_A22
    cs = manchester_cases()
    if cases is not None:
        cs = cs[cs["case"].isin(list(cases))].reset_index(drop=True)
    E = 2.0 * s["G"] * (1.0 + s["nu"])
    df = quasi_static_rolling(cs["lateral [m]"].to_numpy(), cs["yaw [rad]"].to_numpy(),
                              s["wheel_load"], s["speed"], creep_law=creep_law, mu=s["mu"], E=E,
                              nu=s["nu"], creep_params=creep_params, gauge=s["gauge"],
                              inclination=s["inclination"],
                              flange_back_spacing=s["flange_back_spacing"], **kw)
    df["case"] = cs["case"].to_numpy()[df["case"].to_numpy()]
    w = quasi_static_wheel_table(df)
    w["y field [m]"] = np.where(w["side"] == "left", 1.0, -1.0) * w["y_contact [m]"]
    return df, w


#: Quantities compared per case and wheel: (ours, CONTACT, kind) with kind "rel" (difference in
#: per cent of CONTACT's value) or "abs".
_COMPARED = (("N [N]", "rel"), ("Fy track [N]", "abs"), ("contact angle [rad]", "abs"),
             ("p_max [Pa]", "rel"))


def compare_with_contact(wheels, reference=None):
    """Side-by-side table of our per-wheel results and CONTACT's, with differences.

    Parameters
    ----------
    wheels : DataFrame
        Per-wheel table of :func:`run_manchester_a22`.
    reference : DataFrame, optional
        :func:`contact_reference_per_wheel` (read when not given).

    Returns
    -------
    DataFrame
        Per case and wheel: ``y CONTACT [m]``, ``contacts`` (our loaded candidates), for each
        of N, Fy track, contact angle and p_max the columns ``<q> ours``, ``<q> CONTACT`` and
        the difference ``d<q>`` (ours - CONTACT) -- in per cent for N and p_max, in N for
        Fy and in rad for the contact angle -- plus ``Y/Q ours``, ``Y/Q CONTACT``,
        ``converged`` and ``status``.  N is that of our contact with the largest normal force
        (CONTACT reports one combined patch); Fy is the sum over our contacts.
    """
    ref = contact_reference_per_wheel() if reference is None else reference
    m = wheels.merge(ref, on=["case", "side"], suffixes=(" ours", " CONTACT"), how="left")
    cs = manchester_cases().set_index("case")
    out = pd.DataFrame({"case": m["case"], "side": m["side"],
                        "y CONTACT [m]": cs.loc[m["case"], "y CONTACT [m]"].to_numpy(),
                        "contacts": m["contacts"]})
    for q, kind in _COMPARED:
        name, unit = q[:-1].rsplit(" [", 1)
        ours = m["N main [N]"] if q == "N [N]" else m[f"{q} ours"]
        theirs = m[f"{q} CONTACT"]
        out[f"{name} ours [{unit}]"] = ours.to_numpy()
        out[f"{name} CONTACT [{unit}]"] = theirs.to_numpy()
        if kind == "rel":
            out[f"d{name} [%]"] = (100.0 * (ours / theirs - 1.0)).to_numpy()
        else:
            out[f"d{name} [{unit}]"] = (ours - theirs).to_numpy()
    out["Y/Q ours [-]"] = m["Y/Q [-] ours"].to_numpy()
    out["Y/Q CONTACT [-]"] = m["Y/Q [-] CONTACT"].to_numpy()
    out["converged"] = m["converged"].to_numpy()
    out["status"] = m["status"].to_numpy()
    return out.sort_values(["case", "side"]).reset_index(drop=True)


def rail_profile_check(mounting=None):
    """CONTACT's canted UIC60 against our UIC60 mounted 1:40 (:class:`railway.track.RailMounting`).

    CONTACT's rail file holds the rail already canted, with its origin at the highest point;
    ours inclines the UIC60 arcs by 1:40 itself.  Each stored point (``data/railway/
    manchester_uic60_v3_canted_points.csv``, file convention: y outwards from the highest point
    is -gauge side, z down) is placed relative to our highest point and its shortest distance
    to our mounted profile is measured; the lateral position of the highest point is compared
    with CONTACT's (YCP(TR) - YCP(R) of the right rail, the same in every case).

    Parameters
    ----------
    mounting : RailMounting, optional
        Default UIC60, 1:40, gauge 1435 mm at 14 mm.

    Returns
    -------
    points : DataFrame
        ``y [m]``, ``z [m]`` (file convention), ``inside`` (within our mounted profile's lateral
        range), ``distance [m]`` (shortest distance to our profile, NaN outside).
    top : dict
        ``ours [m]`` and ``CONTACT [m]``: lateral position of the highest rail point from the
        track centre; ``difference [m]``.
    """
    from core.paths import data_path

    from ..track import RailMounting

    m = mounting if mounting is not None else RailMounting()
    pts = pd.read_csv(data_path(*_RAIL_FILE), comment="#")
    u = np.linspace(m.u_min, m.u_max, 200001)
    Yo, Z = m.mounted(u)[:2]
    i = int(np.argmax(Z))
    Yt, Zt = Yo[i], Z[i]
    P = np.stack([Yt + pts["y [mm]"].to_numpy() * 1e-3, Zt - pts["z [mm]"].to_numpy() * 1e-3], axis=1)
    inside = (P[:, 0] >= Yo.min()) & (P[:, 0] <= Yo.max())
    curve = np.stack([Yo, Z], axis=1)
    dist = np.full(len(P), np.nan)
    for k in np.flatnonzero(inside):  # 60 points against the sampled curve
        dist[k] = np.min(np.hypot(curve[:, 0] - P[k, 0], curve[:, 1] - P[k, 1]))
    ref = load_contact_reference()
    right = ref[ref["wheel"] == "right"]
    top_c = float(np.median(right["YCP(TR) [mm]"] - right["YCP(R) [mm]"])) * 1e-3
    out = pd.DataFrame({"y [m]": pts["y [mm]"] * 1e-3, "z [m]": pts["z [mm]"] * 1e-3,
                        "inside": inside, "distance [m]": dist})
    return out, {"ours [m]": float(Yt), "CONTACT [m]": top_c, "difference [m]": float(Yt) - top_c}
