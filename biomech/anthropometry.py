r"""Segment parameters from anthropometric tables, and a planar gait model built from them.

The "second, smaller model" of a gait trial: instead of the segment masses, centres of mass and
inertias of a scaled OpenSim model, take them from population tables scaled to the subject's body
mass, and take the segment *lengths* (joint centres) from the subject's OpenSim model, so that the
same measured joint angles drive it.  The two sets of joint moments then differ only through the
inertial parameters (and a pin knee instead of OpenSim's moving knee centre), which is what the
comparison in ``tests/biomech/test_anthropometry.py`` measures.

Tables
------
Both tables give, per segment s, the mass fraction P_s = m_s / M (M the body mass), the position of
the centre of mass along the segment, c_s = d_s / L_s (d_s its distance from the proximal endpoint,
L_s the segment length between the table's endpoints), and radii of gyration ρ_s / L_s:

* Winter (2009), Table 4.1, after Dempster (1955): ρ about the centre of mass, the proximal and the
  distal endpoint, one value per segment (a transverse axis; the table is used for planar models).
  The head-and-neck radius about the proximal end is printed 0.116; the parallel-axis theorem
  ρ_p² = ρ_G² + c² gives 1.116 (0.495² + 1.000²), which the data file holds.
  :func:`read_winter_table` checks ρ_p and ρ_d of every row against the parallel-axis values and
  refuses a row that disagrees by more than 0.02 segment lengths (twice the largest disagreement of
  the printed table itself, 0.008 for the total leg, where Dempster's three radii were measured
  separately): a misprint like the 0.116 is caught, the table's own scatter is not.
* de Leva (1996), Table 4 (male, joint-centre endpoints): ρ about the sagittal (antero-posterior),
  transverse (medio-lateral) and longitudinal axes through the centre of mass, and the sample's mean
  segment lengths (mm) with its mean stature 1741 mm (``deleva1996_male_table4_lengths.csv``).
  Rotation in the sagittal plane is about the *transverse* axis: the table agrees (the trunk, wider
  than deep, has ρ_sag 0.328 > ρ_trans 0.306; the hand 0.628 > 0.513; the head, deeper than wide,
  0.303 < 0.315), so the planar model uses ``rg_transverse`` unless ``deleva_rg="sagittal"``.

Segment parameters
------------------
With a partition of the body into segments k counted n_k times (left and right), the masses are
normalised to add up to the body mass exactly,

.. math::

    m_s = \frac{P_s\, M}{\sum_k n_k P_k}, \qquad d_s = c_s L_s, \qquad I_{G,s} = m_s (\rho_s L_s)^2 ,

(Σ n_k P_k is 1.000 for both tables to their printed rounding, see :func:`mass_fraction_sum`), and
the segments of the planar model are the HAT (head, arms and trunk), thigh, shank and foot.

HAT
    Winter: Table 4.1's own HAT row (greater trochanter to glenohumeral joint, P = 0.678,
    c = 0.626, ρ_G = 0.496).  de Leva gives no HAT: it is lumped here from the trunk (cervicale to
    mid-hip), the head and neck (vertex to cervicale) and both arms hanging at the sides (upper arm,
    forearm, hand from the shoulder joint centres, which lie on the trunk 515.5 mm above mid-hip,
    de Leva's alternative trunk endpoint), all on one axis from mid-hip (s = 0) to the vertex
    (s = L_HAT), in the standing posture the table describes:

    .. math::

        m = \sum_i m_i, \qquad s_G = \frac{1}{m}\sum_i m_i s_i, \qquad
        I_G = \sum_i \left[ m_i (\rho_i L_i)^2 + m_i (s_i - s_G)^2 \right] ,

    with the part lengths L_i in de Leva's mean proportions scaled to L_HAT.  One rigid HAT is the
    classical planar gait model (Winter 2009, ch. 4 and 5); it leaves the lumbar joint without a
    mass of its own on one side (see the model below).

Lengths
    de Leva: from the stature (mean lengths × stature / 1.741 m) or measured; Winter's table has no
    lengths (its Fig. 4.1 proportions are not in the data), so they must be measured.

The planar model
----------------
:func:`anthropometric_sagittal_model` builds an :class:`biomech.osim.OsimModel` with the topology,
body frames, coordinate names and joint locations of a gait10dof18musc-type reference model: ground
→ pelvis (pelvis_tilt, _tx, _ty), pelvis → femur (hip pins), femur → tibia (knee pins), tibia →
calcn (ankle pins; the foot is one segment, talus and toes are absorbed, and it keeps the name
``calcn_r``/``calcn_l`` so that an external-loads file written for the reference applies unchanged),
pelvis → torso (lumbar pin).  Every coordinate of the reference is a coordinate of the model, so the
reference's motion files are accepted (:func:`biomech.storage.check_motion_against_model`) and every
coordinate is driven.

Knee
    The reference moves the tibia along splines of the knee angle.  The pin is put at the fixed
    centre that reproduces that motion best in the least-squares sense (:func:`fit_pin_centre`):
    with φ(q) the joint rotation and t(q) the translation of the child joint frame in the parent's,
    find p_F (parent frame) and p_T (child frame) minimising Σ_j ``|p_F − t(q_j) − R(φ(q_j)) p_T|²``
    over the coordinate's range, a linear least-squares problem.  The thigh and shank lengths are the
    hip–p_F and p_T–ankle distances.  For gait10dof18musc the fitted pin stays within 3.2 mm of the
    reference tibia over the whole range, against 15 mm at 60° flexion for a pin at the extended
    knee's centre.
Segment axes (all points in the reference's body frames at its default pose, lumbar extension 0)
    thigh: hip centre → knee pin; shank: knee pin → ankle centre; foot: heel → toe-tip markers
    (de Leva's HEEL–TTIP) or ankle centre → metatarsophalangeal joint centre (Winter's lateral
    malleolus – head of metatarsal II); HAT: mid-hip (hip centres' midpoint, the greater trochanters'
    level) → vertex marker for de Leva, and for Winter → the shoulder centre on that line at
    515.5 / 846.2 = 0.609 of it (de Leva's mean lengths; Winter's Fig. 4.1 proportions give
    (0.818 − 0.530) / (1 − 0.530) = 0.613).  The centre of mass lies on the axis at d_s from the
    proximal point.
HAT body and the lumbar joint
    The HAT is one rigid segment, carried by the torso (``hat_body="torso"``, default: about four
    fifths of its mass lie above the lumbar joint, so the measured trunk orientation moves it) or by
    the pelvis (``hat_body="pelvis"``, the lumbar joint then locked in effect: its angle moves a
    massless torso).  The other body is massless; the lumbar coordinate stays driven, so the motion
    file's ``lumbar_extension`` is used either way.  The choice changes only the pelvis residuals and
    the lumbar moment: with every joint driven the moment at a joint is fixed by the subtree beyond
    it (the leg and its ground reaction), so hip, knee and ankle moments are the same for both.
Inertia tensor
    Only I_zz enters the sagittal equations (:mod:`biomech.sagittal`); the body's tensor is set to
    I_zz times the identity (a valid placeholder for the two out-of-plane moments, which the tables
    give only partly).  Do not use this model in three dimensions.

References
----------
Winter, D. A. (2009). Biomechanics and Motor Control of Human Movement, 4th ed., Wiley.  Table 4.1
(segment mass fractions, centre-of-mass and radius-of-gyration ratios, after Dempster 1955),
Fig. 4.1 (segment lengths as fractions of height, after Drillis & Contini 1966), ch. 5 (planar
inverse dynamics with a HAT segment).
de Leva, P. (1996). Adjustments to Zatsiorsky–Seluyanov's segment inertia parameters. J. Biomech.
29(9):1223–1230.  Table 4 (male: longitudinal lengths, mass fractions, centre-of-mass positions,
sagittal/transverse/longitudinal radii of gyration; the alternative trunk endpoints in its lower half).
Dempster, W. T. (1955). Space requirements of the seated operator. WADC-TR-55-159.
Delp, S. L. et al. (2007). OpenSim. IEEE Trans. Biomed. Eng. 54:1940–1950 (the reference model).
"""

from __future__ import annotations

import csv
import math
from collections.abc import Mapping
from pathlib import Path

import numpy as np
import pandas as pd

from core.errors import DataFileError, InputError, ModelError, UnknownOptionError

from .checks import RANGES, check_value, checked_options, name_hint
from .functions import Constant, LinearFunction
from .osim import Body, Joint, OffsetFrame, OsimModel, TransformAxis

__all__ = [
    "read_winter_table",
    "read_deleva_table",
    "WINTER_PARTITION",
    "WINTER_FINE_PARTITION",
    "DELEVA_PARTITION",
    "mass_fraction_sum",
    "segment_parameters",
    "fit_pin_centre",
    "anthropometric_sagittal_model",
    "moment_differences",
    "DEFAULT_MARKERS",
]

#: Winter Table 4.1 rows that make up the whole body once (n_k = 1) or per side (n_k = 2):
#: HAT + two total legs (thigh, leg, foot).
WINTER_PARTITION: dict[str, int] = {"HAT": 1, "thigh": 2, "leg_shank": 2, "foot": 2}
#: The same body from Table 4.1's single segments (head-neck, thorax, abdomen, pelvis, arms, legs).
WINTER_FINE_PARTITION: dict[str, int] = {"head_and_neck": 1, "thorax": 1, "abdomen": 1, "pelvis": 1,
                                         "upper_arm": 2, "forearm": 2, "hand": 2,
                                         "thigh": 2, "leg_shank": 2, "foot": 2}
#: de Leva Table 4 (male) segments that make up the whole body.
DELEVA_PARTITION: dict[str, int] = {"head_neck": 1, "trunk": 1, "upper_arm": 2, "forearm": 2, "hand": 2,
                                    "thigh": 2, "shank": 2, "foot": 2}

#: Marker names of the reference model used as landmarks (gait10dof18musc subject01).
DEFAULT_MARKERS: dict[str, str] = {"vertex": "Top.Head", "heel_r": "R.Heel", "toe_tip_r": "R.Toe.Tip",
                                   "heel_l": "L.Heel", "toe_tip_l": "L.Toe.Tip"}

_SEGMENTS = ("HAT", "thigh", "shank", "foot")


# =============================================================================================
# reading the tables
# =============================================================================================


def _fmt(x: float) -> str:
    return f"{float(x):.4g}"


def _default_path(name: str) -> Path:
    from core.paths import data_path

    return data_path("biomech", "anthropometry", name)


def _read_rows(path, required: tuple[str, ...]):
    """(path, [(line, {column: text})]) of a small CSV; DataFileError naming the file and line."""
    p = Path(path)
    try:
        text = p.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise DataFileError(f"{p}: file does not exist") from None
    except OSError as exc:
        raise DataFileError(f"{p}: cannot be read ({exc.strerror or exc})") from None
    lines = text.splitlines()
    rows = list(csv.reader(lines))
    if not rows or not any(c.strip() for c in rows[0]):
        raise DataFileError(f"{p}: empty file (no header line)")
    header = [h.strip() for h in rows[0]]
    missing = [c for c in required if c not in header]
    if missing:
        raise DataFileError(f"{p}, line 1: missing column(s) {missing}; the header has {header}")
    out = []
    seen: dict[str, int] = {}
    for lineno, row in enumerate(rows[1:], start=2):
        if not row or all(not c.strip() for c in row):
            continue
        if len(row) != len(header):
            raise DataFileError(f"{p}, line {lineno}: {len(row)} fields, the header has {len(header)}")
        rec = dict(zip(header, (c.strip() for c in row)))
        seg = rec.get("segment", "")
        if not seg:
            raise DataFileError(f"{p}, line {lineno}: no segment name")
        if seg in seen:
            raise DataFileError(f"{p}, line {lineno}: segment {seg!r} repeated (first on line {seen[seg]})")
        seen[seg] = lineno
        out.append((lineno, rec))
    if not out:
        raise DataFileError(f"{p}: no data rows")
    return p, out


def _number(p: Path, lineno: int, seg: str, col: str, text: str, *, required: bool,
            lo: float = -math.inf, hi: float = math.inf, lo_open: bool = False) -> tuple[float, int]:
    """(value, number of printed decimals) of one cell; NaN for an allowed empty cell."""
    where = f"{p}, line {lineno} (segment {seg!r}), column {col!r}"
    if text == "":
        if required:
            raise DataFileError(f"{where}: empty")
        return math.nan, 0
    try:
        v = float(text)
    except ValueError:
        raise DataFileError(f"{where}: {text!r} is not a number") from None
    if not math.isfinite(v) or v < lo or v > hi or (lo_open and v <= lo):
        bound = f"({lo:g}, {hi:g}]" if lo_open else f"[{lo:g}, {hi:g}]"
        raise DataFileError(f"{where}: {text} is outside {bound}")
    decimals = len(text.split(".", 1)[1]) if "." in text and "e" not in text.lower() else 0
    return v, decimals


def read_winter_table(path=None) -> pd.DataFrame:
    """Winter (2009) Table 4.1 (Dempster's segment parameters) as fractions.

    Parameters
    ----------
    path : path-like, optional
        Default ``data/biomech/anthropometry/winter_dempster_table4_1.csv``.

    Returns
    -------
    DataFrame
        Indexed by segment: ``endpoints`` (proximal / distal), ``mass_fraction`` (of body mass),
        ``com_from_proximal``, ``com_from_distal`` (of segment length), ``rg_about_com``,
        ``rg_about_proximal``, ``rg_about_distal`` (of segment length; NaN where the table has
        none), ``density [kg/m^3]``.  ``attrs``: ``source``, ``lines`` (segment → line) and
        ``decimals`` (segment → column → printed decimals, for rounding bounds).

    Raises
    ------
    core.errors.DataFileError
        Missing file or column, a non-numeric or out-of-range value, a repeated segment,
        ``com_from_proximal + com_from_distal`` not 1 within the rounding of two 3-decimal values
        (0.001), or a radius of gyration about an end that disagrees with the parallel-axis value
        √(ρ_G² + c²) by more than 0.02 (module docstring): the message names the file, line and
        segment.
    """
    cols = ("segment", "mass_fraction", "com_from_proximal", "com_from_distal", "rg_about_com",
            "rg_about_proximal", "rg_about_distal", "density_kg_per_l")
    p, rows = _read_rows(path if path is not None else _default_path("winter_dempster_table4_1.csv"), cols)
    recs, lines, decimals = {}, {}, {}
    for lineno, r in rows:
        seg = r["segment"]
        d, rec = {}, {"endpoints": r.get("definition_proximal_to_distal", "")}
        rec["mass_fraction"], d["mass_fraction"] = _number(p, lineno, seg, "mass_fraction", r["mass_fraction"],
                                                           required=True, lo=0.0, hi=1.0, lo_open=True)
        for c in ("com_from_proximal", "com_from_distal"):
            rec[c], d[c] = _number(p, lineno, seg, c, r[c], required=c == "com_from_proximal", lo=0.0, hi=2.0)
        for c in ("rg_about_com", "rg_about_proximal", "rg_about_distal"):
            rec[c], d[c] = _number(p, lineno, seg, c, r[c], required=False, lo=0.0, hi=3.0, lo_open=True)
        dens, _ = _number(p, lineno, seg, "density_kg_per_l", r["density_kg_per_l"], required=False,
                          lo=0.5, hi=2.0)
        rec["density [kg/m^3]"] = 1000.0 * dens
        cp, cd = rec["com_from_proximal"], rec["com_from_distal"]
        if not math.isnan(cd) and abs(cp + cd - 1.0) > 0.001 + 1e-12:
            raise DataFileError(f"{p}, line {lineno} (segment {seg!r}): com_from_proximal {cp} + com_from_distal "
                                f"{cd} = {cp + cd:.4f}, not 1 within the rounding (0.001)")
        rg = rec["rg_about_com"]
        if not math.isnan(rg):
            for c, arm in (("rg_about_proximal", cp), ("rg_about_distal", 1.0 - cp)):
                v = rec[c]
                if math.isnan(v):
                    continue
                pa = math.hypot(rg, arm)
                if abs(v - pa) > 0.02:
                    raise DataFileError(
                        f"{p}, line {lineno} (segment {seg!r}): {c} = {v} disagrees with the parallel-axis value "
                        f"sqrt(rg_about_com^2 + {arm:.3f}^2) = {pa:.3f} by more than 0.02 (a misprint? Winter's "
                        "printed head-neck radius about the proximal end, 0.116, should read 1.116)")
        recs[seg], lines[seg], decimals[seg] = rec, lineno, d
    df = pd.DataFrame.from_dict(recs, orient="index")
    df.index.name = "segment"
    df.attrs.update(source=str(p), lines=lines, decimals=decimals,
                    reference="Winter (2009) Biomechanics and Motor Control of Human Movement, 4th ed., Table 4.1")
    return df


def read_deleva_table(path=None, lengths_path=None) -> pd.DataFrame:
    """de Leva (1996) Table 4 (male) as fractions, with the sample's mean segment lengths in metres.

    Parameters
    ----------
    path : path-like, optional
        Default ``data/biomech/anthropometry/deleva1996_male_table4.csv``.
    lengths_path : path-like, optional
        Default ``data/biomech/anthropometry/deleva1996_male_table4_lengths.csv`` (the same table's
        mean longitudinal lengths in mm, the mean stature as row ``stature``, and the alternative
        trunk endpoint row ``trunk_mid_shoulder``).

    Returns
    -------
    DataFrame
        Indexed by segment: ``endpoints``, ``mass_fraction``, ``com_from_proximal`` (of segment
        length, from the first endpoint), ``rg_sagittal``, ``rg_transverse``, ``rg_longitudinal``
        (about the centre of mass, of segment length), ``length [m]`` (sample mean).
        ``attrs``: ``stature [m]`` (sample mean, 1.741), ``lengths [m]`` (every row of the
        lengths file), ``source``, ``lines``, ``decimals``.

    Raises
    ------
    core.errors.DataFileError
        Missing file or column, non-numeric or out-of-range value, repeated segment, a segment
        without a length, no ``stature`` row (file, line and segment named).
    """
    cols = ("segment", "mass_fraction", "com_from_proximal", "rg_sagittal", "rg_transverse", "rg_longitudinal")
    p, rows = _read_rows(path if path is not None else _default_path("deleva1996_male_table4.csv"), cols)
    lp, lrows = _read_rows(lengths_path if lengths_path is not None
                           else _default_path("deleva1996_male_table4_lengths.csv"), ("segment", "length_mm"))
    lengths = {}
    for lineno, r in lrows:
        v, _ = _number(lp, lineno, r["segment"], "length_mm", r["length_mm"], required=True, lo=0.0, hi=3000.0,
                       lo_open=True)
        lengths[r["segment"]] = v / 1000.0
    if "stature" not in lengths:
        raise DataFileError(f"{lp}: no 'stature' row (the sample's mean stature the lengths belong to)")
    recs, lines, decimals = {}, {}, {}
    for lineno, r in rows:
        seg = r["segment"]
        d, rec = {}, {"endpoints": r.get("endpoints_proximal_to_distal", "")}
        rec["mass_fraction"], d["mass_fraction"] = _number(p, lineno, seg, "mass_fraction", r["mass_fraction"],
                                                           required=True, lo=0.0, hi=1.0, lo_open=True)
        rec["com_from_proximal"], d["com_from_proximal"] = _number(p, lineno, seg, "com_from_proximal",
                                                                   r["com_from_proximal"], required=True,
                                                                   lo=0.0, hi=1.0)
        for c in ("rg_sagittal", "rg_transverse", "rg_longitudinal"):
            rec[c], d[c] = _number(p, lineno, seg, c, r[c], required=True, lo=0.0, hi=1.0, lo_open=True)
        if seg not in lengths:
            raise DataFileError(f"{lp}: no length for segment {seg!r} of {p} (line {lineno})")
        rec["length [m]"] = lengths[seg]
        recs[seg], lines[seg], decimals[seg] = rec, lineno, d
    df = pd.DataFrame.from_dict(recs, orient="index")
    df.index.name = "segment"
    df.attrs.update(source=f"{p}; {lp}", lines=lines, decimals=decimals, **{"stature [m]": lengths["stature"],
                                                                             "lengths [m]": dict(lengths)},
                    reference="de Leva (1996) J. Biomech. 29(9):1223-1230, Table 4 (male)")
    return df


def mass_fraction_sum(table: pd.DataFrame, partition: Mapping[str, int]) -> tuple[float, float]:
    """Σ n_k P_k over a partition of the body, and the bound its rounding allows.

    Each fraction printed with d decimals is within 0.5·10⁻ᵈ of its unrounded value, so the sum is
    within Σ n_k 0.5·10^(−d_k) of the sum of unrounded fractions (1 for a true partition).

    Parameters
    ----------
    table : DataFrame
        From :func:`read_winter_table` or :func:`read_deleva_table`.
    partition : mapping of segment → count
        E.g. :data:`WINTER_PARTITION`, :data:`DELEVA_PARTITION`.

    Returns
    -------
    (float, float)
        The sum and its rounding bound.
    """
    missing = [s for s in partition if s not in table.index]
    if missing:
        raise InputError(f"{table.attrs.get('source', 'table')}: no segment(s) {missing}; it has {list(table.index)}")
    total = float(sum(n * table.at[s, "mass_fraction"] for s, n in partition.items()))
    dec = table.attrs.get("decimals", {})
    bound = float(sum(n * 0.5 * 10.0 ** -dec.get(s, {}).get("mass_fraction", 4) for s, n in partition.items()))
    return total, bound


# =============================================================================================
# segment parameters
# =============================================================================================


def _deleva_hat(tab: pd.DataFrame, L_hat: float, rg_col: str):
    """(mass fraction, COM from mid-hip [m], radius of gyration about the COM [m]) of the lumped HAT
    of length L_hat (mid-hip to vertex), module docstring."""
    lengths = tab.attrs["lengths [m]"]
    L0 = lengths["trunk"] + lengths["head_neck"]
    k = L_hat / L0
    Lt, Lh = k * lengths["trunk"], k * lengths["head_neck"]
    s_sh = k * lengths["trunk_mid_shoulder"]
    parts = []  # (mass fraction, s of the COM, radius of gyration about the COM [m])

    def row(seg, L):
        return tab.at[seg, "mass_fraction"], tab.at[seg, "com_from_proximal"], tab.at[seg, rg_col] * L

    P, c, r = row("trunk", Lt)  # proximal end cervicale, at s = Lt
    parts.append((P, Lt - c * Lt, r))
    P, c, r = row("head_neck", Lh)  # proximal end vertex, at s = Lt + Lh
    parts.append((P, Lt + Lh - c * Lh, r))
    s = s_sh
    for seg in ("upper_arm", "forearm", "hand"):  # hanging from the shoulder, proximal end up
        L = k * lengths[seg]
        P, c, r = row(seg, L)
        parts.append((2 * P, s - c * L, r))
        s -= L
    m = sum(P for P, _, _ in parts)
    sG = sum(P * si for P, si, _ in parts) / m
    IG = sum(P * (r * r + (si - sG) ** 2) for P, si, r in parts)  # per unit body mass
    return m, sG, math.sqrt(IG / m)


@checked_options
def segment_parameters(mass, stature=None, table="deleva", segment_lengths=None, *,
                       deleva_rg="transverse", accept=()) -> pd.DataFrame:
    r"""Mass, centre of mass and moment of inertia of the HAT, thigh, shank and foot.

    .. math::

        m_s = \frac{P_s M}{\sum_k n_k P_k}, \quad d_s = c_s L_s, \quad I_{G,s} = m_s (\rho_s L_s)^2

    (module docstring; the HAT of de Leva is lumped from trunk, head-neck and arms).

    Parameters
    ----------
    mass : float or str
        Body mass M [kg] (a string with its unit, ``"160 lb"``, is converted); plausible 20-250 kg.
    stature : float or str, optional
        [m] (or a string with its unit, ``"175 cm"``); plausible 0.9-2.3 m.  de Leva only: segment lengths are the table's male means × stature / 1.741 m.
    table : {"deleva", "winter"}
    segment_lengths : mapping, optional
        Measured lengths [m] of ``"HAT"`` (de Leva: mid-hip to vertex; Winter: greater trochanter to
        glenohumeral joint), ``"thigh"`` (hip to knee centre), ``"shank"`` (knee to ankle),
        ``"foot"`` (de Leva: heel to toe tip; Winter: lateral malleolus to head of metatarsal II).
        They override the stature-scaled ones; with Winter all four are required.
    deleva_rg : {"transverse", "sagittal"}
        Which de Leva radius of gyration is used for rotation in the sagittal plane: about the
        medio-lateral (transverse) axis (default, module docstring) or the antero-posterior one.
    accept : sequence of str
        Plausible-range quantities not to enforce (``"body_mass"``, ``"stature"``,
        ``"body_mass_index"``, ``"segment_length"``; ``data/biomech/plausible_ranges.csv``).

    Returns
    -------
    DataFrame
        Indexed ``HAT``, ``thigh``, ``shank``, ``foot`` (one of each side for the legs, ``count``
        2): ``mass [kg]``, ``length [m]``, ``com_from_proximal [m]``, ``radius_of_gyration [m]``
        (about the centre of mass), ``inertia_com [kg m^2]``, ``proximal``, ``distal``,
        ``count``.  ``attrs``: ``table``, ``reference``, ``source``, ``mass_fraction_sum``,
        ``body_mass [kg]``, ``stature [m]``, ``rg_column``.

    Raises
    ------
    core.errors.InputError
        A non-positive mass, stature or length; no way to get a length (Winter without measured
        lengths); an unknown table; :class:`core.errors.UnknownOptionError` for an unknown
        segment in ``segment_lengths`` or an unknown ``deleva_rg``.
    core.inputs.ImplausibleValueError
        A body mass, stature or segment length outside its plausible range (in grams, pounds, cm,
        mm: the slip is named), or a body-mass index outside 13-45 kg/m² (a mass in pounds).

    Examples
    --------
    >>> p = segment_parameters(72.6, stature=1.75)
    >>> round(float(p.loc["HAT", "mass [kg]"] + 2 * p.loc[["thigh", "shank", "foot"], "mass [kg]"].sum()), 6)
    72.6
    """
    from core.inputs import parse_quantity

    accept = tuple([accept] if isinstance(accept, str) else accept)
    M = parse_quantity(mass, "kg", where="segment_parameters(mass=...)")
    if not (math.isfinite(M) and M > 0):
        raise InputError(f"body mass must be a positive number of kg, got {mass!r}")
    M = check_value("body_mass", mass, where="segment_parameters(mass=...)", accept=accept)
    if stature is not None:
        h = parse_quantity(stature, "m", where="segment_parameters(stature=...)")
        if not (math.isfinite(h) and h > 0):
            raise InputError(f"stature must be a positive number of metres, got {stature!r}")
        stature = check_value("stature", stature, where="segment_parameters(stature=...)", accept=accept)
        bmi = M / stature ** 2
        lb = M * 0.45359237
        rng = RANGES["body_mass_index"]
        hint = (f"a body mass in pounds ({_fmt(M)} lb = {_fmt(lb)} kg, body-mass index {_fmt(lb / stature ** 2)})?"
                if not rng.contains(bmi) and rng.contains(lb / stature ** 2) else "")
        check_value("body_mass_index", bmi,
                    where=f"segment_parameters(mass={_fmt(M)} kg, stature={_fmt(stature)} m)", accept=accept, hint=hint)
    given = dict(segment_lengths or {})
    unknown = [k for k in given if k not in _SEGMENTS]
    if unknown:
        raise UnknownOptionError(f"segment_lengths: unknown segment(s) {unknown}"
                                 f"{name_hint(unknown[0], _SEGMENTS)} (accepted: {list(_SEGMENTS)})")
    for k, v in given.items():
        v_si = parse_quantity(v, "m", where=f"segment_lengths[{k!r}]")
        if not (math.isfinite(v_si) and v_si > 0):
            raise InputError(f"segment_lengths[{k!r}] must be a positive length in metres, got {v!r}")
        given[k] = check_value("segment_length", v, where=f"segment_parameters(segment_lengths[{k!r}])", accept=accept)
    if table == "deleva":
        if deleva_rg not in ("transverse", "sagittal"):
            raise UnknownOptionError(f"deleva_rg must be 'transverse' or 'sagittal', got {deleva_rg!r}")
        tab = read_deleva_table()
        rg_col = f"rg_{deleva_rg}"
        total, _ = mass_fraction_sum(tab, DELEVA_PARTITION)
        L0 = tab.attrs["lengths [m]"]
        mean = {"HAT": L0["trunk"] + L0["head_neck"], "thigh": L0["thigh"], "shank": L0["shank"], "foot": L0["foot"]}
        lengths = {}
        for s in _SEGMENTS:
            if s in given:
                lengths[s] = float(given[s])
            elif stature is not None:
                lengths[s] = mean[s] * float(stature) / tab.attrs["stature [m]"]
            else:
                raise InputError(f"segment_parameters: no length for {s!r}: give the stature or segment_lengths[{s!r}]")
        P_hat, sG, rG = _deleva_hat(tab, lengths["HAT"], rg_col)
        rows = {"HAT": (P_hat, sG / lengths["HAT"], rG / lengths["HAT"], "mid-hip (midpoint of hip joint centres)",
                        "vertex")}
        for s in ("thigh", "shank", "foot"):
            prox, dist = (x.strip() for x in tab.at[s, "endpoints"].split("/", 1))
            rows[s] = (tab.at[s, "mass_fraction"], tab.at[s, "com_from_proximal"], tab.at[s, rg_col], prox, dist)
    elif table == "winter":
        tab = read_winter_table()
        rg_col = "rg_about_com"
        total, _ = mass_fraction_sum(tab, WINTER_PARTITION)
        missing = [s for s in _SEGMENTS if s not in given]
        if missing:
            raise InputError(f"segment_parameters(table='winter'): no length for {missing}; Winter's Table 4.1 gives "
                             "no segment lengths (its Fig. 4.1 proportions are not in data/biomech/anthropometry): "
                             "pass segment_lengths measured on the subject, or use table='deleva' with the stature")
        lengths = {s: float(given[s]) for s in _SEGMENTS}
        rows = {}
        for s, row in (("HAT", "HAT"), ("thigh", "thigh"), ("shank", "leg_shank"), ("foot", "foot")):
            prox, dist = (x.strip() for x in tab.at[row, "endpoints"].split("/", 1))
            rows[s] = (tab.at[row, "mass_fraction"], tab.at[row, "com_from_proximal"], tab.at[row, rg_col], prox, dist)
    else:
        raise InputError(f"unknown anthropometric table {table!r}{name_hint(str(table), ['deleva', 'winter'])} "
                         f"(use 'deleva' or 'winter')")
    out = {}
    for s in _SEGMENTS:
        P, c, r, prox, dist = rows[s]
        L = lengths[s]
        m = P * M / total
        out[s] = {"mass [kg]": m, "length [m]": L, "com_from_proximal [m]": c * L, "radius_of_gyration [m]": r * L,
                  "inertia_com [kg m^2]": m * (r * L) ** 2, "proximal": prox, "distal": dist,
                  "count": 1 if s == "HAT" else 2}
    df = pd.DataFrame.from_dict(out, orient="index")
    df.index.name = "segment"
    df.attrs.update(table=table, reference=tab.attrs["reference"], source=tab.attrs["source"],
                    mass_fraction_sum=total, rg_column=rg_col, **{"body_mass [kg]": M, "stature [m]": stature})
    return df


# =============================================================================================
# geometry of the reference model
# =============================================================================================


def _rot(a):
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, -s], [s, c]])


def _planar_joint_motion(joint: Joint, q: np.ndarray, where: str):
    """φ(q) (n,) and t(q) (n, 2) of a one-coordinate joint in the plane (module docstring of
    :mod:`biomech.sagittal`: rotation about ±z, translation of the child frame in the parent's)."""
    phi = np.zeros(len(q))
    t = np.zeros((len(q), 2))
    for ax in joint.transform_axes:
        a = np.asarray(ax.axis, float)
        f = ax.function
        vals = np.asarray(f.value(q if ax.coordinates else np.zeros(len(q))), float)
        if not ax.coordinates and np.all(vals == 0.0):
            continue
        if ax.is_rotation:
            if abs(abs(a[2]) - 1.0) > 1e-9:
                raise ModelError(f"{where}: joint {joint.name!r}, axis {ax.name} = {a.tolist()} is not the z axis; "
                                 "not a sagittal-plane joint")
            phi += a[2] * vals
        else:
            if abs(a[2]) > 1e-9:
                if not ax.coordinates:
                    continue  # an out-of-plane offset
                raise ModelError(f"{where}: joint {joint.name!r}, axis {ax.name} = {a.tolist()} moves out of the x-y "
                                 "plane; not a sagittal-plane joint")
            t += np.outer(vals, a[:2])
    return phi, t


@checked_options
def fit_pin_centre(joint: Joint, q_range, n: int = 261, where: str = ""):
    r"""The fixed centre that best reproduces a one-coordinate planar joint's motion.

    With φ(q) the rotation and t(q) the translation of the child joint frame M in the parent joint
    frame F, a pin at p_F (in F) = p_T (in M) would give t(q) = p_F − R(φ(q)) p_T.  Over n values
    q_j evenly spread on ``q_range`` solve the linear least-squares problem

    .. math::  \min_{p_F, p_T} \sum_j \left| p_F - R(\varphi(q_j))\, p_T - t(q_j) \right|^2 .

    The residual ``|p_F − R p_T − t|`` at q is the distance between the child's position under the pin
    and under the original joint (both rotated alike), so it bounds the kinematic difference.

    Parameters
    ----------
    joint : biomech.osim.Joint
        One coordinate, rotations about z only.
    q_range : (float, float)
        [rad].
    n : int
        Number of samples.

    Returns
    -------
    dict
        ``parent`` (2,) and ``child`` (2,): the centre in the parent and child *body* frames [m];
        ``max_residual``, ``rms_residual`` [m]; ``q_range``.
    """
    where = where or "model"
    if len(joint.coordinates) != 1:
        raise ModelError(f"{where}: joint {joint.name!r} has {len(joint.coordinates)} coordinates; a pin fit needs one")
    lo, hi = map(float, q_range)
    if not (math.isfinite(lo) and math.isfinite(hi) and hi > lo):
        raise InputError(f"{where}: joint {joint.name!r}: fit range [{lo}, {hi}] must be finite with max > min")
    q = np.linspace(lo, hi, int(n))
    phi, t = _planar_joint_motion(joint, q, where)
    if np.ptp(phi) < 1e-3:
        raise ModelError(f"{where}: joint {joint.name!r} hardly rotates over [{lo:g}, {hi:g}] rad; no centre to fit")
    c, s = np.cos(phi), np.sin(phi)
    A = np.zeros((2 * len(q), 4))
    A[0::2, 0] = 1.0
    A[1::2, 1] = 1.0
    A[0::2, 2], A[0::2, 3] = -c, s
    A[1::2, 2], A[1::2, 3] = -s, -c
    x, *_ = np.linalg.lstsq(A, t.reshape(-1), rcond=None)
    res = np.hypot(*(A @ x - t.reshape(-1)).reshape(-1, 2).T)
    pf, pt = x[:2], x[2:]
    fr, fc = joint.parent_frame, joint.child_frame
    parent = np.asarray(fr.location, float)[:2] + _rot(float(fr.orientation[2])) @ pf
    child = np.asarray(fc.location, float)[:2] + _rot(float(fc.orientation[2])) @ pt
    return {"parent": parent, "child": child, "max_residual": float(res.max()),
            "rms_residual": float(np.sqrt(np.mean(res**2))), "q_range": (lo, hi)}


class _Pose:
    """Body-frame ↔ ground transforms of the reference at its default pose (planar)."""

    def __init__(self, osim):
        from .sagittal import planar_forward_kinematics

        fk = planar_forward_kinematics(osim, {c.name: c.default_value for c in osim.coordinates})
        self.o = {b: v[0][0] for b, v in fk.items()}
        self.th = {b: float(v[1][0]) for b, v in fk.items()}
        self.o["ground"], self.th["ground"] = np.zeros(2), 0.0

    def to_ground(self, body, u):
        return self.o[body] + _rot(self.th[body]) @ np.asarray(u, float)[:2]

    def to_body(self, body, p):
        return _rot(-self.th[body]) @ (np.asarray(p, float) - self.o[body])


def _joint_by_coordinate(osim, coordinate: str) -> Joint:
    return osim.joint(osim.coordinate(coordinate).joint)


def _check_link(jt: Joint, parent: str, child: str | None, where: str):
    if jt.parent_body != parent or (child is not None and jt.child_body != child):
        raise ModelError(f"{where}: joint {jt.name!r} connects {jt.parent_body!r} → {jt.child_body!r}; expected "
                         f"{parent!r} → {child or 'a foot body'!r} (a gait10dof18musc-type model)")


def _rotation_only(jt: Joint, where: str):
    for ax in jt.transform_axes:
        if not ax.is_rotation and ax.coordinates:
            raise ModelError(f"{where}: joint {jt.name!r} translates with {ax.coordinates[0]!r}; expected a pin")


def _marker(osim, name: str, where: str):
    for mk in osim.markers:
        if mk.name == name:
            return mk
    raise ModelError(f"{where}: no marker {name!r} (landmark of the anthropometric model; pass markers=...); "
                     f"the model has {[m.name for m in osim.markers]}")


def _pin_axes(coordinate: str):
    e = np.eye(3)
    zero = Constant(0.0)
    names = ("rotation1", "rotation2", "rotation3", "translation1", "translation2", "translation3")
    axes = [TransformAxis("rotation1", e[2].copy(), (coordinate,), LinearFunction(1.0, 0.0))]
    for i, v in zip(range(1, 6), (e[0], e[1], e[0], e[1], e[2])):
        axes.append(TransformAxis(names[i], v.copy(), (), zero))
    return tuple(axes)


def _is_plain_pin(jt: Joint) -> bool:
    """Whether the joint's rotations are one rotation q about +z (its translations are dropped)."""
    rot = [ax for ax in jt.transform_axes if ax.is_rotation
           and (ax.coordinates or float(ax.function.value(0.0)) != 0.0)]
    if len(rot) != 1 or not rot[0].coordinates:
        return False
    f = rot[0].function
    return (isinstance(f, LinearFunction) and f.slope == 1.0 and f.intercept == 0.0
            and np.allclose(rot[0].axis, [0.0, 0.0, 1.0]))


def _body(name, mass, com2, Izz):
    return Body(name, float(mass), np.array([com2[0], com2[1], 0.0]), float(Izz) * np.eye(3))


# =============================================================================================
# the model
# =============================================================================================


@checked_options
def anthropometric_sagittal_model(osim_reference, table="deleva", *, hat_body="torso", deleva_rg="transverse",
                                  knee_fit_range=None, markers=None, name=None) -> OsimModel:
    """A planar gait model with the reference's joints and the table's segment inertias.

    See the module docstring (The planar model) for the bodies, joints, landmarks and choices.

    Parameters
    ----------
    osim_reference : biomech.osim.OsimModel
        A gait10dof18musc-type model (coordinates ``pelvis_tilt/_tx/_ty``, ``hip_flexion_r/l``,
        ``knee_angle_r/l``, ``ankle_angle_r/l``, ``lumbar_extension``; bodies ``pelvis``,
        ``femur_*``, ``tibia_*``, ``calcn_*``, ``torso``): its joint locations give the segment
        lengths, its total mass the body mass.
    table : {"deleva", "winter"}
    hat_body : {"torso", "pelvis"}
        The body that carries the HAT; the other is massless.
    deleva_rg : {"transverse", "sagittal"}
        See :func:`segment_parameters`.
    knee_fit_range : (float, float), optional
        Knee angles [rad] over which the pin knee is fitted (:func:`fit_pin_centre`); default the
        knee coordinate's range in the reference.
    markers : mapping, optional
        Landmark marker names, keys as :data:`DEFAULT_MARKERS` (``vertex``; for de Leva also
        ``heel_r``, ``toe_tip_r``, ``heel_l``, ``toe_tip_l``).
    name : str, optional

    Returns
    -------
    biomech.osim.OsimModel
        Bodies pelvis, femur_r, tibia_r, calcn_r, femur_l, tibia_l, calcn_l, torso; the reference's
        coordinates (same objects, same order); no muscles.  Its ``credits`` state the source, its
        ``path`` is empty (the model is not read from a file).

    Raises
    ------
    core.errors.ModelError
        The reference lacks a coordinate, joint, body or landmark marker, or its joints are not
        connected as in gait10dof18musc (the element is named).
    core.errors.InputError
        Unknown table or ``hat_body``.

    Examples
    --------
    >>> from core.paths import data_path
    >>> from biomech.osim import read_osim
    >>> ref = read_osim(data_path("biomech", "opensim", "gait10dof18musc_subject01_walk", "subject01.osim"))
    >>> m = anthropometric_sagittal_model(ref, "winter")
    >>> round(m.total_mass, 6), [b.name for b in m.bodies][:4]
    (72.6, ['pelvis', 'femur_r', 'tibia_r', 'calcn_r'])
    """
    ref = osim_reference
    where = ref.path or ref.name
    if table not in ("deleva", "winter"):
        raise InputError(f"unknown anthropometric table {table!r}{name_hint(str(table), ['deleva', 'winter'])} "
                         f"(use 'deleva' or 'winter')")
    if hat_body not in ("torso", "pelvis"):
        raise InputError(f"hat_body must be 'torso' or 'pelvis', got {hat_body!r}")
    mk = dict(DEFAULT_MARKERS)
    if markers:
        unknown = [k for k in markers if k not in DEFAULT_MARKERS]
        if unknown:
            raise UnknownOptionError(f"markers: unknown landmark(s) {unknown}; accepted: {list(DEFAULT_MARKERS)}")
        mk.update(markers)
    pose = _Pose(ref)

    ground_joint = _joint_by_coordinate(ref, "pelvis_tilt")
    _check_link(ground_joint, ref.ground, "pelvis", where)
    back = _joint_by_coordinate(ref, "lumbar_extension")
    _check_link(back, "pelvis", "torso", where)
    _rotation_only(back, where)

    legs = {}
    for s in ("r", "l"):
        femur, tibia, calcn = f"femur_{s}", f"tibia_{s}", f"calcn_{s}"
        ref.body(calcn)  # ModelError naming it if absent
        hip = _joint_by_coordinate(ref, f"hip_flexion_{s}")
        _check_link(hip, "pelvis", femur, where)
        _rotation_only(hip, where)
        knee = _joint_by_coordinate(ref, f"knee_angle_{s}")
        _check_link(knee, femur, tibia, where)
        ankle = _joint_by_coordinate(ref, f"ankle_angle_{s}")
        _check_link(ankle, tibia, None, where)
        _rotation_only(ankle, where)
        talus = ankle.child_body
        if talus != calcn:  # the bodies between the ankle and the calcaneus must be welded
            b = calcn
            while b != talus:
                jt = next((j for j in ref.joints if j.child_body == b), None)
                if jt is None or jt.coordinates:
                    raise ModelError(f"{where}: {calcn!r} is not welded to {talus!r} (joint "
                                     f"{None if jt is None else jt.name!r} has coordinates "
                                     f"{() if jt is None else jt.coordinates}); the foot cannot be one segment")
                b = jt.parent_body
        rng = knee_fit_range if knee_fit_range is not None else tuple(ref.coordinate(f"knee_angle_{s}").range)
        fit = fit_pin_centre(knee, rng, where=where)
        hip_f = np.asarray(hip.child_frame.location, float)[:2]
        knee_f, knee_t = fit["parent"], fit["child"]
        ankle_t = np.asarray(ankle.parent_frame.location, float)[:2]
        ankle_g = pose.to_ground(talus, np.asarray(ankle.child_frame.location, float)[:2])
        ankle_c = pose.to_body(calcn, ankle_g)
        beta_c = float(ankle.child_frame.orientation[2]) + pose.th[talus] - pose.th[calcn]
        if table == "deleva":
            heel, toe = (_marker(ref, mk[f"{k}_{s}"], where) for k in ("heel", "toe_tip"))
            foot_p, foot_d = (pose.to_body(calcn, pose.to_ground(m.body, m.location)) for m in (heel, toe))
        else:
            mtp = next((j for j in ref.joints if j.parent_body == calcn), None)
            if mtp is None:
                raise ModelError(f"{where}: no joint on {calcn!r} (the metatarsophalangeal joint, distal end of "
                                 "Winter's foot segment)")
            foot_p, foot_d = ankle_c, np.asarray(mtp.parent_frame.location, float)[:2]
        legs[s] = dict(hip=hip, knee=knee, ankle=ankle, fit=fit, femur=femur, tibia=tibia, calcn=calcn,
                       thigh=(hip_f, knee_f), shank=(knee_t, ankle_t), foot=(foot_p, foot_d),
                       ankle_c=ankle_c, beta_c=beta_c)

    # HAT axis: mid-hip → vertex (de Leva) or → shoulder centre on that line (Winter)
    hips_p = [np.asarray(legs[s]["hip"].parent_frame.location, float)[:2] for s in ("r", "l")]
    midh = pose.to_body(hat_body, pose.to_ground("pelvis", 0.5 * (hips_p[0] + hips_p[1])))
    vtx = _marker(ref, mk["vertex"], where)
    vert = pose.to_body(hat_body, pose.to_ground(vtx.body, vtx.location))
    if table == "deleva":
        hat_p, hat_d = midh, vert
    else:
        L = read_deleva_table().attrs["lengths [m]"]
        hat_p, hat_d = midh, midh + L["trunk_mid_shoulder"] / (L["trunk"] + L["head_neck"]) * (vert - midh)

    def length(pd_):
        return float(np.linalg.norm(pd_[1] - pd_[0]))

    lengths_r = {"HAT": length((hat_p, hat_d)), "thigh": length(legs["r"]["thigh"]),
                 "shank": length(legs["r"]["shank"]), "foot": length(legs["r"]["foot"])}
    M = ref.total_mass
    params = {s: segment_parameters(M, table=table, deleva_rg=deleva_rg,
                                    segment_lengths={**lengths_r, **{k: length(legs[s][k])
                                                                     for k in ("thigh", "shank", "foot")}})
              for s in ("r", "l")}

    def com(seg, pd_, p):
        a, b = pd_
        return a + p.loc[seg, "com_from_proximal [m]"] * (b - a) / np.linalg.norm(b - a)

    pr = params["r"]
    hat = _body(hat_body, pr.loc["HAT", "mass [kg]"], com("HAT", (hat_p, hat_d), pr),
                pr.loc["HAT", "inertia_com [kg m^2]"])
    other = "pelvis" if hat_body == "torso" else "torso"
    bodies = {hat_body: hat, other: _body(other, 0.0, (0.0, 0.0), 0.0)}
    joints = [ground_joint]
    for s in ("r", "l"):
        g, p = legs[s], params[s]
        for seg, body in (("thigh", g["femur"]), ("shank", g["tibia"]), ("foot", g["calcn"])):
            bodies[body] = _body(body, p.loc[seg, "mass [kg]"], com(seg, g[seg], p), p.loc[seg, "inertia_com [kg m^2]"])
        kn = g["knee"]
        zF = float(np.asarray(kn.parent_frame.location, float)[2])
        zT = float(np.asarray(kn.child_frame.location, float)[2])
        plain = _is_plain_pin(kn)
        axes = _pin_axes(kn.coordinates[0]) if plain else tuple(
            ax if ax.is_rotation else TransformAxis(ax.name, np.asarray(ax.axis, float), (), Constant(0.0))
            for ax in kn.transform_axes)
        # the fitted centre is in body coordinates: frames placed there, orientations kept
        knee = Joint(kn.name, "PinJoint" if plain else "CustomJoint", g["femur"], g["tibia"],
                     OffsetFrame(kn.parent_frame.name, g["femur"], np.array([*g["fit"]["parent"], zF]),
                                 np.asarray(kn.parent_frame.orientation, float).copy()),
                     OffsetFrame(kn.child_frame.name, g["tibia"], np.array([*g["fit"]["child"], zT]),
                                 np.asarray(kn.child_frame.orientation, float).copy()),
                     kn.coordinates, axes, kn.reverse)
        ak = g["ankle"]
        ankle = Joint(ak.name, ak.type, g["tibia"], g["calcn"], ak.parent_frame,
                      OffsetFrame(f"{g['calcn']}_offset", g["calcn"], np.array([*g["ankle_c"], 0.0]),
                                  np.array([0.0, 0.0, g["beta_c"]])),
                      ak.coordinates, ak.transform_axes, ak.reverse)
        joints += [g["hip"], knee, ankle]
    joints.append(back)
    order = ["pelvis", "femur_r", "tibia_r", "calcn_r", "femur_l", "tibia_l", "calcn_l", "torso"]
    body_t = tuple(bodies[b] for b in order)
    keep = set(order)
    label = ("de Leva (1996) Table 4, male" if table == "deleva" else "Winter (2009) Table 4.1 (Dempster)")
    credits = (f"Generated by biomech.anthropometry from {where}: joint locations, frames, coordinates and landmarks "
               f"of the reference; segment masses, centres of mass and moments of inertia from {label} scaled to "
               f"{M:g} kg; HAT on {hat_body!r}; pin knees fitted to the reference knee motion "
               f"(max deviation {max(legs[s]['fit']['max_residual'] for s in legs) * 1000:.1f} mm).")
    return OsimModel(
        name=name or f"{ref.name}_anthropometric_{table}",
        path="",
        version=ref.version,
        gravity=np.asarray(ref.gravity, float).copy(),
        credits=credits,
        publications=label,
        ground=ref.ground,
        bodies=body_t,
        joints=tuple(joints),
        coordinates=tuple(ref.coordinates),
        muscles=(),
        actuators=(),
        other_forces=(),
        constraints=(),
        markers=tuple(m for m in ref.markers if m.body in keep),
        force_groups={},
        ignored=(),
    )


# =============================================================================================
# comparison
# =============================================================================================


@checked_options
def moment_differences(reference: pd.DataFrame, other: pd.DataFrame, coordinates=None, window=None) -> pd.DataFrame:
    """Root-mean-square and peak differences of two inverse-dynamics results.

    Parameters
    ----------
    reference, other : DataFrame
        From :func:`biomech.inverse_dynamics.inverse_dynamics` at the same times.
    coordinates : sequence of str, optional
        Default every ``*_moment [N m]`` column.
    window : (float, float), optional
        Time range [s] (inclusive); default all rows.

    Returns
    -------
    DataFrame
        Indexed by coordinate: ``rms difference [N m]``, ``rms difference [% of peak]`` (of the
        reference's peak ``|moment|`` in the window), ``max difference [N m]``,
        ``peak reference [N m]``, ``peak other [N m]`` (max ``|moment|``), ``n_frames``.
    """
    ta, tb = reference["time [s]"].to_numpy(float), other["time [s]"].to_numpy(float)
    if len(ta) != len(tb) or not np.allclose(ta, tb, rtol=0.0, atol=1e-9):
        raise InputError(f"moment_differences: the two results are at different times ({len(ta)} and {len(tb)} rows)")
    keep = np.ones(len(ta), bool) if window is None else (ta >= window[0] - 1e-9) & (ta <= window[1] + 1e-9)
    if coordinates is None:
        coordinates = [c.split("_moment [")[0] for c in reference.columns if c.endswith("_moment [N m]")]
    out = {}
    for c in coordinates:
        col = f"{c}_moment [N m]"
        if col not in reference.columns or col not in other.columns:
            raise InputError(f"moment_differences: no column {col!r} in both results")
        a, b = reference[col].to_numpy(float)[keep], other[col].to_numpy(float)[keep]
        d = b - a
        rms = float(np.sqrt(np.mean(d**2)))
        peak = float(np.max(np.abs(a)))
        out[c] = {"rms difference [N m]": rms, "rms difference [% of peak]": 100.0 * rms / peak,
                  "max difference [N m]": float(np.max(np.abs(d))), "peak reference [N m]": peak,
                  "peak other [N m]": float(np.max(np.abs(b))), "n_frames": int(keep.sum())}
    df = pd.DataFrame.from_dict(out, orient="index")
    df.index.name = "coordinate"
    return df
