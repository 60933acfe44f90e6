"""Railway tables in the units railway engineers read.

The computations are SI (m, N, rad, Pa); the tables the scenes and examples write show lengths
in mm, forces in kN, moduli and pressures in GPa, the wheelset's attitude angles (yaw, roll) in
mrad and other angles in degrees.  The lateral shift of the wheelset has one name in every table.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

__all__ = ["display_units"]

#: SI unit -> (unit of the railway tables, factor): lengths mm, forces kN, moduli GPa.
DISPLAY = {"m": ("mm", 1e3), "um": ("mm", 1e-3), "N": ("kN", 1e-3), "N m": ("kN m", 1e-3), "Pa": ("GPa", 1e-9)}
#: Angles [rad] of the wheelset's attitude go to mrad (as ``--yaw-mrad``); other angles to deg.
ATTITUDE = ("yaw", "roll")
#: Columns renamed on the way: the lateral shift of the wheelset has one name in every table.
RENAME = {"y": "lateral shift", "shift": "lateral shift"}


def display_units(df: pd.DataFrame) -> pd.DataFrame:
    """A table of SI columns (``"name [unit]"``) in the units of the railway tables (module
    docstring); other columns pass unchanged, ``attrs`` are kept."""
    out = {}
    for col in df.columns:
        name, unit = col, ""
        if isinstance(col, str) and col.endswith("]") and " [" in col:
            name, unit = col[:-1].rsplit(" [", 1)
        name = RENAME.get(name, name)
        if unit == "rad":
            to, factor = ("mrad", 1e3) if name.startswith(ATTITUDE) else ("deg", 180.0 / np.pi)
        else:
            to, factor = DISPLAY.get(unit, (unit, 1.0))
        new = f"{name} [{to}]" if unit else name
        out[new] = df[col] * factor if factor != 1.0 else df[col]
    res = pd.DataFrame(out, index=df.index)
    res.attrs = dict(df.attrs)
    return res
