r"""OpenSim storage and motion files (``.sto``, ``.mot``) and external loads, in SI units.

Storage / motion file format
----------------------------
Text.  A header of lines up to a line ``endheader``: usually a name line (e.g. ``Coordinates``),
then ``key=value`` lines -- ``version``, ``nRows``, ``nColumns`` (time included), ``inDegrees=yes|no``
-- and free text.  The old SIMM form ``datarows N`` / ``datacolumns N`` is read as nRows/nColumns.
After ``endheader`` one line of column labels (tab-separated; whitespace if there is no tab)
starting with ``time``, then one row of numbers per sample, whitespace-separated.  Times are in
seconds, lengths in metres, forces in newtons, moments in N·m; angles in degrees when
``inDegrees=yes``, radians when ``inDegrees=no`` (OpenSim documentation, "Storage (.sto) Files" and
"Motion (.mot) Files", OpenSim User's Guide 4.x; ``Storage.cpp``).

:func:`read_storage` returns a :class:`pandas.DataFrame` with a ``time`` column first and the data
columns in file order, angles converted to radians.  Which columns are angles:

1. ``angle_columns`` if given;
2. else, with a ``model``: the coordinates whose motion type is *rotational* (as OpenSim's
   ``SimbodyEngine::convertDegreesToRadians`` does; translational and coupled coordinates and
   columns that are not coordinates stay as they are);
3. else every data column except those whose name ends in ``_tx``, ``_ty`` or ``_tz`` (OpenSim's
   naming of translational coordinates, e.g. ``pelvis_tx``).  This rule is meant for coordinate
   files; for other storage files pass ``convert_angles=False`` (force-plate ``.mot`` files carry
   ``inDegrees=yes`` although they hold no angles; :func:`read_external_loads` reads them so).

``DataFrame.attrs`` holds ``source`` (the file), ``header`` (the key=value pairs), ``in_degrees``
(the file's flag), ``angle_columns`` (the columns taken as angles) and ``units`` (column → unit
string, ``""`` where unknown).

Checks, each an error naming the file (and line or column): a missing ``endheader`` or label
line, a missing ``time`` column, a row with the wrong number of values or a value that is not a
number (line and column named), fewer or more rows than ``nRows`` says (a truncated file), a label
count different from ``nColumns``, times that do not strictly increase (line named), a gap of
missing (NaN) values (column and time range named; ``allow_nan=True`` reads it).  An implausible
``inDegrees`` flag, in both directions (:func:`biomech.checks.angle_unit_slip`):

* with ``inDegrees=no`` (or no flag) an angle column that reaches beyond 2π rad or spans more than
  2π rad is degrees written as radians (the known pitfall of RRA output, which makes static
  optimisation fail with NaN fibre lengths);
* with ``inDegrees=yes``, every angle column within ±π while the largest span is at least 0.8
  (46° of motion if radians, under 1° if degrees) is radians written under a degrees flag (a
  walking knee spans 60-75°).

Either is raised as :class:`core.errors.DataFileError` naming the file, the flag and the column
(``check_degrees="warn"`` warns instead, ``"off"`` skips the check).  A motion whose values are
degrees below 2π in magnitude, or radians of a motion spanning less than 0.8 rad, cannot be told
apart; the check does not guess there.  Translation coordinates (``*_tx``, ``*_ty``, ``*_tz``, or the
model's translational coordinates) are checked against their plausible ranges
(``data/biomech/plausible_ranges.csv``: pelvis_ty -0.5 ... 2.5 m, others ±100 m); values in mm or
cm are named as such (:class:`biomech.checks.ImplausibleDataError`; ``accept=[...]`` lets them
through).  :func:`read_external_loads` checks the centre of pressure (±10 m), the free torque
(±500 N m) and the largest force (50 N ... 20 kN: ground reactions in body weights or N/kg are named).

External loads
--------------
An ``ExternalLoads`` XML file lists ``ExternalForce`` entries: ``applied_to_body``,
``force_expressed_in_body``, ``point_expressed_in_body``, and the *identifiers* of the data
columns: the three columns whose labels start with ``force_identifier`` (e.g. ``ground_force_v`` →
``ground_force_vx``, ``_vy``, ``_vz``), likewise ``point_identifier`` (centre of pressure) and
``torque_identifier``, in the storage file named by ``<datafile>`` (relative to the XML file).  An
empty identifier means none (force at the body origin, no free torque).  Values are SI as in the
file (N, m, N·m), as OpenSim assumes.  :func:`resample_external_loads` interpolates them onto other
times (the kinematics' samples) with a natural cubic spline -- OpenSim's ``ExternalForce`` uses an
interpolating ``GCVSpline`` of degree 3, i.e. the natural cubic interpolating spline -- or linearly,
and raises :class:`core.errors.DataRangeError` naming the file when the force data do not cover
the requested times.

References
----------
OpenSim User's Guide 4.x, "Storage (.sto) Files", "Motion (.mot) Files", "External Loads"
(simtk-confluence.stanford.edu/display/OpenSim/...); OpenSim source ``Storage.cpp``,
``ExternalForce.cpp`` (getDataForIdentifier, GCVSpline(3, ...)), ``SimbodyEngine.cpp``
(convertDegreesToRadians), github.com/opensim-org/opensim-core.
Woltring H.J. (1986) A Fortran package for generalized, cross-validatory spline smoothing and
differentiation. Adv. Eng. Softw. 8(2):104-113 (GCVSPL: with zero error variance the interpolating
natural spline).
"""

from __future__ import annotations

import warnings
from collections.abc import Sequence
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
import pandas as pd
from scipy.interpolate import CubicSpline

from core.errors import DataFileError, DataRangeError, InputError

from .checks import angle_unit_slip, check_column_magnitude, checked_options, nan_gaps, name_hint
from .osim import OsimModel, parse_xml

__all__ = [
    "StorageWarning",
    "read_storage",
    "check_motion_against_model",
    "ExternalForceSpec",
    "ExternalLoadsSpec",
    "ExternalForceData",
    "ExternalLoads",
    "read_external_loads_xml",
    "read_external_loads",
    "resample_external_loads",
]

_TRANSLATION_SUFFIXES = ("_tx", "_ty", "_tz")


class StorageWarning(UserWarning):
    """A storage file was read, but something about it is doubtful (the message says what)."""


# =============================================================================================
# storage files
# =============================================================================================


def _read_text(path: Path) -> str:
    try:
        raw = path.read_bytes()
    except FileNotFoundError:
        raise DataFileError(f"{path}: file does not exist") from None
    except OSError as exc:
        raise DataFileError(f"{path}: cannot be read ({exc.strerror or exc})") from None
    try:
        return raw.decode("utf-8")
    except UnicodeDecodeError:
        return raw.decode("latin-1")


def _parse_header(lines: list[str], path: Path) -> tuple[int, dict[str, str], str]:
    """Index of the ``endheader`` line, the key=value pairs (keys lower-cased) and the name line."""
    header: dict[str, str] = {}
    name = ""
    for i, line in enumerate(lines):
        text = line.strip()
        if text.lower() == "endheader":
            return i, header, name
        if "=" in text:
            key, value = text.split("=", 1)
            header[key.strip().lower()] = value.strip()
        else:
            tokens = text.split()
            if len(tokens) == 2 and tokens[0].lower() in ("datarows", "datacolumns"):
                header[tokens[0].lower()] = tokens[1]
            elif text and not name and i == 0:
                name = text
    raise DataFileError(f"{path}: no 'endheader' line (not an OpenSim storage/motion file, or its header is cut off)")


def _header_int(header: dict[str, str], keys: Sequence[str], path: Path) -> int | None:
    for key in keys:
        if key in header:
            try:
                return int(header[key])
            except ValueError:
                raise DataFileError(f"{path}: header {key}={header[key]!r} is not an integer") from None
    return None


def _in_degrees(header: dict[str, str], path: Path) -> bool | None:
    raw = header.get("indegrees")
    if raw is None:
        return None
    low = raw.strip().lower()
    if low in ("yes", "true", "1"):
        return True
    if low in ("no", "false", "0"):
        return False
    raise DataFileError(f"{path}: header inDegrees={raw!r} must be yes or no")


def _parse_rows(lines: list[str], first: int, labels: list[str], path: Path) -> tuple[np.ndarray, np.ndarray]:
    n = len(labels)
    rows: list[np.ndarray] = []
    line_numbers: list[int] = []
    for k in range(first, len(lines)):
        text = lines[k].strip()
        if not text:
            continue
        tokens = text.split()
        lineno = k + 1
        if len(tokens) != n:
            last = all(not s.strip() for s in lines[k + 1:])
            hint = " (the file ends inside this row: truncated?)" if last and len(tokens) < n else ""
            raise DataFileError(f"{path}, line {lineno}: {len(tokens)} values, expected {n} (one per column label)"
                                f"{hint}")
        try:
            rows.append(np.array(tokens, dtype=float))
        except ValueError:
            for j, tok in enumerate(tokens):
                try:
                    float(tok)
                except ValueError:
                    raise DataFileError(f"{path}, line {lineno}, column {labels[j]!r}: value {tok!r} is not a number") \
                        from None
            raise  # pragma: no cover - numpy refused a token float() accepts
        line_numbers.append(lineno)
    if not rows:
        raise DataFileError(f"{path}: no data rows after the column labels")
    return np.vstack(rows), np.array(line_numbers)


def _angle_columns(data_cols: list[str], model: OsimModel | None, angle_columns, convert_angles: bool,
                   path: Path) -> list[str]:
    if not convert_angles:
        return []
    if angle_columns is not None:
        unknown = [c for c in angle_columns if c not in data_cols]
        if unknown:
            raise InputError(f"{path}: angle_columns {unknown} are not columns of the file")
        return list(angle_columns)
    if model is not None:
        rot = {c.name for c in model.coordinates if c.motion_type == "rotational"}
        return [c for c in data_cols if c in rot]
    return [c for c in data_cols if not c.endswith(_TRANSLATION_SUFFIXES)]


@checked_options
def read_storage(path: str | Path, model: OsimModel | None = None, *, convert_angles: bool = True,
                 angle_columns: Sequence[str] | None = None, check_degrees: str = "raise",
                 allow_nan: bool = False, accept: Sequence[str] = ()) -> pd.DataFrame:
    """Read an OpenSim ``.sto`` / ``.mot`` file into a DataFrame in SI units.

    Parameters
    ----------
    path : str or Path
    model : OsimModel, optional
        Decides which columns are angles (its rotational coordinates) and their units.
    convert_angles : bool
        If False no column is treated as an angle (no conversion, no degree check).
    angle_columns : sequence of str, optional
        Columns that are angles, overriding the model and the naming rule.
    check_degrees : {"raise", "warn", "off"}
        What to do about an implausible ``inDegrees`` flag, in either direction: degrees under
        ``inDegrees=no`` or radians under ``inDegrees=yes`` (see the module docstring and
        :func:`biomech.checks.angle_unit_slip` for the heuristic and its thresholds).
    allow_nan : bool
        If False (default) a missing (NaN) value in a data column is refused, naming the column and
        the gap's time range; True reads it as NaN.
    accept : sequence of str
        Plausible-range quantities not to enforce (``"pelvis_height"``, ``"translation_coordinate"``;
        ``data/biomech/plausible_ranges.csv``).

    Returns
    -------
    pandas.DataFrame
        ``time`` [s] first, then the data columns; angle columns in radians.  ``attrs``:
        ``source``, ``header``, ``in_degrees``, ``angle_columns``, ``units``.

    Raises
    ------
    core.errors.DataFileError
        Missing file, no ``endheader``, no time column, wrong value counts, non-numeric values,
        fewer or more rows than ``nRows``, label count not ``nColumns``, non-increasing times,
        implausible ``inDegrees`` flag (with ``check_degrees="raise"``), NaN gaps (unless
        ``allow_nan``).
    biomech.checks.ImplausibleDataError
        A translation coordinate (``*_tx``, ``*_ty``, ``*_tz``, or the model's translational
        coordinates) beyond its plausible range, e.g. in mm ("the values look like mm").
    """
    if check_degrees not in ("raise", "warn", "off"):
        raise InputError(f"check_degrees must be 'raise', 'warn' or 'off', got {check_degrees!r}"
                         f"{name_hint(str(check_degrees), ['raise', 'warn', 'off'])}")
    p = Path(path)
    lines = _read_text(p).splitlines()
    end, header, name = _parse_header(lines, p)
    k = end + 1
    while k < len(lines) and not lines[k].strip():
        k += 1
    if k >= len(lines):
        raise DataFileError(f"{p}: no column-label line after 'endheader' (file truncated?)")
    label_line = lines[k]
    raw_labels = label_line.split("\t") if "\t" in label_line else label_line.split()
    labels = [s.strip() for s in raw_labels]
    while labels and not labels[-1]:
        labels.pop()
    if any(not s for s in labels):
        raise DataFileError(f"{p}, line {k + 1}: an empty column label")
    dup = sorted({s for s in labels if labels.count(s) > 1})
    if dup:
        raise DataFileError(f"{p}, line {k + 1}: repeated column labels {dup}")
    time_idx = [i for i, s in enumerate(labels) if s.lower() == "time"]
    if not time_idx:
        raise DataFileError(f"{p}, line {k + 1}: no 'time' column (labels: {labels[:6]}{' ...' if len(labels) > 6 else ''})")
    n_columns = _header_int(header, ("ncolumns", "nc", "datacolumns"), p)
    if n_columns is not None and n_columns != len(labels):
        raise DataFileError(f"{p}, line {k + 1}: the header says nColumns={n_columns} but there are {len(labels)} "
                            f"column labels")
    values, line_numbers = _parse_rows(lines, k + 1, labels, p)
    n_rows = _header_int(header, ("nrows", "nr", "datarows"), p)
    if n_rows is not None and n_rows != values.shape[0]:
        if values.shape[0] < n_rows:
            raise DataFileError(f"{p}: truncated: the header says nRows={n_rows} but the file has only "
                                f"{values.shape[0]} data rows (last at line {line_numbers[-1]})")
        raise DataFileError(f"{p}: the header says nRows={n_rows} but the file has {values.shape[0]} data rows")
    ti = time_idx[0]
    t = values[:, ti]
    if not np.all(np.isfinite(t)):
        bad = int(np.flatnonzero(~np.isfinite(t))[0])
        raise DataFileError(f"{p}, line {line_numbers[bad]}: time is {t[bad]}")
    dt = np.diff(t)
    if np.any(dt <= 0):
        bad = int(np.flatnonzero(dt <= 0)[0]) + 1
        raise DataFileError(f"{p}, line {line_numbers[bad]}: time {float(t[bad])!r} does not increase (previous row "
                            f"{float(t[bad - 1])!r})")
    data_cols = [s for i, s in enumerate(labels) if i != ti]
    df = pd.DataFrame(values[:, [i for i in range(len(labels)) if i != ti]], columns=data_cols)
    df.insert(0, "time", t)

    if not allow_nan:
        gap = nan_gaps(t, df[data_cols].to_numpy(float), data_cols)
        if gap:
            raise DataFileError(f"{p}: {gap}: fill the gap (e.g. interpolate it) or cut the trial before it "
                                f"(allow_nan=True reads it as NaN)")
    in_degrees = _in_degrees(header, p)
    angles = _angle_columns(data_cols, model, angle_columns, convert_angles, p)
    if angles and check_degrees != "off":
        slip = angle_unit_slip({c: df[c].to_numpy() for c in angles}, in_degrees)
        if slip:
            really = "radians" if not in_degrees else "degrees"
            msg = f"{p}: {slip} (or pass check_degrees='warn' / 'off' if they really are {really})"
            if check_degrees == "raise":
                raise DataFileError(msg)
            warnings.warn(msg, StorageWarning, stacklevel=2)
    if angles and in_degrees:
        df[angles] = np.deg2rad(df[angles].to_numpy())
    if model is not None and in_degrees and convert_angles and angle_columns is None:
        coupled = [c.name for c in model.coordinates if c.motion_type == "coupled" and c.name in data_cols]
        if coupled:
            warnings.warn(f"{p}: inDegrees=yes, and coupled coordinates {coupled} of model {model.name!r} were "
                          f"left unconverted (as OpenSim does: only rotational coordinates are converted)",
                          StorageWarning, stacklevel=2)
    units = {"time": "s"}
    motion = {c.name: c.motion_type for c in model.coordinates} if model is not None else {}
    for col in data_cols:
        if col in angles:
            units[col] = "rad"
        elif model is not None:
            units[col] = "m" if motion.get(col) == "translational" else ""
        elif convert_angles and col.endswith(_TRANSLATION_SUFFIXES):
            units[col] = "m"
        else:
            units[col] = ""
    for col in data_cols:
        if units[col] == "m" and col not in angles:
            quantity = "pelvis_height" if col == "pelvis_ty" else "translation_coordinate"
            check_column_magnitude(quantity, df[col].to_numpy(), where=str(p), column=col, accept=accept,
                                   typical=(0.5, 1.5) if quantity == "pelvis_height" else None)
    df.attrs.update(source=str(p), name=name, header=dict(header), in_degrees=in_degrees,
                    angle_columns=list(angles), units=units)
    return df


@checked_options
def check_motion_against_model(motion: pd.DataFrame, model: OsimModel, *, source: str | None = None) -> tuple[str, ...]:
    """Check that every data column of a motion is a coordinate of ``model``.

    Parameters
    ----------
    motion : DataFrame
        From :func:`read_storage` (``attrs["source"]`` names the file in messages).
    model : OsimModel
    source : str, optional
        File name for messages if ``motion.attrs`` has none.

    Returns
    -------
    tuple of str
        The model's coordinates that the motion lacks (OpenSim's inverse-dynamics tool holds them
        at their default values); empty when the motion is complete.

    Raises
    ------
    core.errors.DataFileError
        A column that is not a coordinate of the model (the file and column named).
    """
    src = source or motion.attrs.get("source", "<motion>")
    names = set(model.coordinate_names)
    cols = [c for c in motion.columns if c != "time"]
    unknown = [c for c in cols if c not in names]
    if unknown:
        hints = {c: name_hint(c, model.coordinate_names)[len("; did you mean "):-1] for c in unknown
                 if name_hint(c, model.coordinate_names)}
        more = "".join(f"; {k!r}: did you mean {v}?" for k, v in hints.items())
        raise DataFileError(f"{src}: column{'s' if len(unknown) > 1 else ''} {unknown} {'are' if len(unknown) > 1 else 'is'} "
                            f"not {'coordinates' if len(unknown) > 1 else 'a coordinate'} of model {model.name!r} "
                            f"({model.path}); its coordinates are {list(model.coordinate_names)}{more}")
    return tuple(c for c in model.coordinate_names if c not in cols)


# =============================================================================================
# external loads
# =============================================================================================


@dataclass(frozen=True)
class ExternalForceSpec:
    """One ``ExternalForce`` entry of an external-loads file.

    Attributes
    ----------
    name, applied_to_body, force_expressed_in_body, point_expressed_in_body : str
    force_identifier : str
        Prefix of the three force columns.
    point_identifier, torque_identifier : str or None
        Prefixes of the point (centre of pressure) and torque columns; None if not given.
    data_source_name : str or None
    applies_force : bool
        False when the entry is disabled (``isDisabled=true`` / ``appliesForce=false``).
    """

    name: str
    applied_to_body: str
    force_expressed_in_body: str
    point_expressed_in_body: str
    force_identifier: str
    point_identifier: str | None
    torque_identifier: str | None
    data_source_name: str | None
    applies_force: bool


@dataclass(frozen=True)
class ExternalLoadsSpec:
    """The contents of an ``ExternalLoads`` XML file.

    ``datafile`` is resolved relative to the XML file's folder; ``model_kinematics_file`` and
    ``lowpass_cutoff_for_load_kinematics`` are the (3.x) properties for points expressed in a moving
    body, kept when present.
    """

    name: str
    path: str
    datafile: Path | None
    forces: tuple[ExternalForceSpec, ...]
    model_kinematics_file: str | None = None
    lowpass_cutoff_for_load_kinematics: float | None = None


@dataclass(frozen=True, eq=False)
class ExternalForceData:
    """Time series of one external force (SI: N, m, N·m).

    Attributes
    ----------
    spec : ExternalForceSpec
    time : ndarray, shape (n,)
    force : ndarray, shape (n, 3)
    point : ndarray, shape (n, 3) or None
    torque : ndarray, shape (n, 3) or None
    columns : dict
        ``"force"``, ``"point"``, ``"torque"`` → the three column labels used.
    """

    spec: ExternalForceSpec
    time: np.ndarray
    force: np.ndarray
    point: np.ndarray | None
    torque: np.ndarray | None
    columns: dict

    @property
    def name(self) -> str:
        return self.spec.name


@dataclass(frozen=True, eq=False)
class ExternalLoads:
    """External forces with their data (see :func:`read_external_loads`).

    Attributes
    ----------
    spec : ExternalLoadsSpec
    source : str
        The data file.
    time : ndarray, shape (n,)
    forces : tuple of ExternalForceData
    """

    spec: ExternalLoadsSpec
    source: str
    time: np.ndarray
    forces: tuple[ExternalForceData, ...]

    def __getitem__(self, name: str) -> ExternalForceData:
        for f in self.forces:
            if f.name == name:
                return f
        raise KeyError(f"{self.spec.path}: no external force {name!r} (have {[f.name for f in self.forces]})")

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(f.name for f in self.forces)


def _identifier(text: str | None) -> str | None:
    if text is None:
        return None
    t = text.strip()
    return None if t in ("", "Unassigned") else t


def read_external_loads_xml(path: str | Path) -> ExternalLoadsSpec:
    """Read an ``ExternalLoads`` XML file (OpenSim 2.x-4.x).

    Raises
    ------
    core.errors.DataFileError
        Missing or malformed file; an entry that is not an ``ExternalForce`` (e.g. the 2.x
        ``PrescribedForce`` form, which OpenSim 4 no longer reads either); an ExternalForce without
        ``applied_to_body`` or ``force_identifier``.
    """
    doc = parse_xml(path)
    root = doc.root
    el = root.find("ExternalLoads") if root.tag == "OpenSimDocument" else (root if root.tag == "ExternalLoads" else None)
    if el is None:
        raise DataFileError(f"{doc.where(root)}: no <ExternalLoads> element")
    objects = el.find("objects")
    forces = []
    for fel in (objects if objects is not None else []):
        if not isinstance(fel.tag, str):
            continue
        if fel.tag != "ExternalForce":
            raise DataFileError(f"{doc.where(fel)}: only ExternalForce entries are supported (a {fel.tag} would "
                                f"be an external load left out)")

        def prop(tag, default=None, _fel=fel):
            child = _fel.find(tag)
            return default if child is None or child.text is None else child.text.strip()

        body = prop("applied_to_body")
        force_id = _identifier(prop("force_identifier"))
        if not body or not force_id:
            raise DataFileError(f"{doc.where(fel)}: needs <applied_to_body> and <force_identifier>")
        disabled = (prop("isDisabled", "false") or "false").lower() == "true"
        applies = (prop("appliesForce", "true") or "true").lower() == "true"
        forces.append(ExternalForceSpec(
            name=fel.get("name", ""), applied_to_body=body,
            force_expressed_in_body=prop("force_expressed_in_body", "ground") or "ground",
            point_expressed_in_body=prop("point_expressed_in_body", "ground") or "ground",
            force_identifier=force_id, point_identifier=_identifier(prop("point_identifier")),
            torque_identifier=_identifier(prop("torque_identifier")),
            data_source_name=_identifier(prop("data_source_name")), applies_force=applies and not disabled))
    if not forces:
        raise DataFileError(f"{doc.where(el)}: no ExternalForce entries")
    names = [f.name for f in forces]
    if len(set(names)) != len(names):
        raise DataFileError(f"{doc.where(el)}: repeated ExternalForce names {names}")

    def top(tag):
        child = el.find(tag)
        return None if child is None or child.text is None or not child.text.strip() else child.text.strip()

    datafile = top("datafile")
    cutoff = top("lowpass_cutoff_frequency_for_load_kinematics")
    try:
        cutoff_value = None if cutoff is None else float(cutoff)
    except ValueError:
        raise DataFileError(f"{doc.where(el)}: lowpass_cutoff_frequency_for_load_kinematics {cutoff!r} is not a number") \
            from None
    kin = _identifier(top("external_loads_model_kinematics_file"))
    return ExternalLoadsSpec(name=el.get("name", ""), path=str(doc.path),
                             datafile=(doc.path.parent / datafile) if datafile else None, forces=tuple(forces),
                             model_kinematics_file=kin, lowpass_cutoff_for_load_kinematics=cutoff_value)


def _three_columns(df: pd.DataFrame, identifier: str, what: str, spec: ExternalForceSpec, source: str) -> list[str]:
    cols = [c for c in df.columns if c != "time" and c.startswith(identifier)]
    if len(cols) != 3:
        raise DataFileError(f"{source}: external force {spec.name!r}: {what} identifier {identifier!r} must match "
                            f"exactly 3 columns, matches {len(cols)}: {cols}")
    order = {"x": 0, "y": 1, "z": 2}
    suffixes = [c[len(identifier):].lower() for c in cols]
    if sorted(suffixes) == ["x", "y", "z"]:
        cols = [c for _, c in sorted(zip((order[s] for s in suffixes), cols))]
    return cols


@checked_options
def read_external_loads(path: str | Path, datafile: str | Path | None = None, *,
                        accept: Sequence[str] = ()) -> ExternalLoads:
    """Read an external-loads XML file and its force-plate data.

    Parameters
    ----------
    path : str or Path
        The ``ExternalLoads`` XML file.
    datafile : str or Path, optional
        The data file, overriding the XML's ``<datafile>``.
    accept : sequence of str
        Plausible-range quantities not to enforce (``"ground_reaction_force"``,
        ``"centre_of_pressure"``, ``"free_torque"``; ``data/biomech/plausible_ranges.csv``).

    Returns
    -------
    ExternalLoads
        Per external force the force, point and torque series (SI, as in the file).

    Raises
    ------
    core.errors.DataFileError
        Problems of either file (see :func:`read_external_loads_xml`, :func:`read_storage`); an
        identifier that does not match exactly three columns (file, force and identifier named).
    biomech.checks.ImplausibleDataError
        Forces whose largest magnitude is below 50 N (body weights or N/kg rather than N), a centre
        of pressure beyond 10 m (mm), a free torque beyond 500 N m (N mm).
    """
    spec = read_external_loads_xml(path)
    data_path = Path(datafile) if datafile is not None else spec.datafile
    if data_path is None:
        raise DataFileError(f"{spec.path}: no <datafile> given, and no datafile argument")
    df = read_storage(data_path, convert_angles=False)
    src = str(data_path)
    t = df["time"].to_numpy()
    forces = []
    for f in spec.forces:
        fc = _three_columns(df, f.force_identifier, "force", f, src)
        pc = _three_columns(df, f.point_identifier, "point", f, src) if f.point_identifier else None
        tc = _three_columns(df, f.torque_identifier, "torque", f, src) if f.torque_identifier else None
        arrays = {}
        for key, cols in (("force", fc), ("point", pc), ("torque", tc)):
            if cols is None:
                arrays[key] = None
                continue
            a = df[cols].to_numpy(dtype=float)
            a.flags.writeable = False
            arrays[key] = a
        forces.append(ExternalForceData(f, t, arrays["force"], arrays["point"], arrays["torque"],
                                        {"force": fc, "point": pc, "torque": tc}))
    for f in forces:
        for key, quantity, slips in (("point", "centre_of_pressure", ("mm", "cm")),
                                     ("torque", "free_torque", ("N*mm",))):
            a = getattr(f, key)
            if a is not None:
                k = int(np.argmax(np.max(np.abs(a), axis=0)))
                check_column_magnitude(quantity, a[:, k], where=src, column=f.columns[key][k], accept=accept,
                                       slips=slips)
    _check_force_magnitude(forces, src, accept)
    t = t.copy()
    t.flags.writeable = False
    return ExternalLoads(spec, src, t, tuple(forces))


def _check_force_magnitude(forces, src: str, accept) -> None:
    """Refuse force data whose largest magnitude is below a plausible ground reaction (N)."""
    from .checks import ImplausibleDataError, ranges

    if "ground_reaction_force" in set(accept) or not forces:
        return
    peaks = [(float(np.max(np.linalg.norm(f.force, axis=1))), f) for f in forces if f.spec.applies_force]
    if not peaks:
        return
    peak, f = max(peaks, key=lambda x: x[0])
    r = ranges()["ground_reaction_force"]
    if peak == 0 or r.contains(peak):
        return
    cols = f.columns["force"]
    if peak < r.low:
        slip = (f"the values look like body weights (or N/kg, or kN); ground reactions must be in N "
                f"(multiply body weights by m·g)")
    else:
        slip = f"the values look like mN or another unit; ground reactions must be in N"
    raise ImplausibleDataError(f"{src}: the largest ground reaction force ({cols[0]}..{cols[-1][-1]}) is "
                               f"{peak:.4g} N, outside the plausible range {r.describe()}: {slip} "
                               f"(to use it deliberately, accept='ground_reaction_force')",
                               "ground_reaction_force", peak, slip)


@checked_options
def resample_external_loads(loads: ExternalLoads, times, *, method: str = "spline") -> ExternalLoads:
    """Interpolate external loads onto other times (e.g. the kinematics' samples).

    Parameters
    ----------
    loads : ExternalLoads
    times : array_like, shape (m,)
        Target times [s], increasing.
    method : {"spline", "linear"}
        ``"spline"``: natural cubic interpolating spline per component (OpenSim's ``ExternalForce``,
        interpolating ``GCVSpline`` of degree 3); ``"linear"``: straight lines between samples.

    Returns
    -------
    ExternalLoads
        Same forces, sampled at ``times``.

    Raises
    ------
    core.errors.DataRangeError
        Target times outside the data's time range (tolerance 1e-9 s); the file, the data range and
        the requested range are named.
    """
    if method not in ("spline", "linear"):
        raise InputError(f"method must be 'spline' or 'linear', got {method!r}{name_hint(str(method), ['spline', 'linear'])}")
    tq = np.asarray(times, dtype=float)
    if tq.ndim != 1 or tq.size == 0 or not np.all(np.isfinite(tq)):
        raise InputError(f"times must be a non-empty 1-D array of finite values, got shape {tq.shape}")
    t = loads.time
    lo, hi = float(t[0]), float(t[-1])
    tol = 1e-9
    if tq.min() < lo - tol or tq.max() > hi + tol:
        raise DataRangeError(f"{loads.source}: the force data cover t = {lo:g} … {hi:g} s, but times "
                             f"{tq.min():g} … {tq.max():g} s are requested (the kinematics extend beyond the "
                             f"force-plate record)")
    tq_c = np.clip(tq, lo, hi)

    def interp(a):
        if a is None:
            return None
        if method == "linear" or t.size < 4:
            out = np.column_stack([np.interp(tq_c, t, a[:, k]) for k in range(a.shape[1])])
        else:
            out = CubicSpline(t, a, axis=0, bc_type="natural")(tq_c)
        out.flags.writeable = False
        return out

    forces = tuple(replace(f, time=tq_c, force=interp(f.force), point=interp(f.point), torque=interp(f.torque))
                   for f in loads.forces)
    tq_c = tq_c.copy()
    tq_c.flags.writeable = False
    return ExternalLoads(loads.spec, loads.source, tq_c, forces)
