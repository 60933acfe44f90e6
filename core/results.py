r"""Result containers and table writers.

Every integrator run ends in a :class:`SimulationResult`: the sampled time history
of the coordinates ``q``, velocities ``v`` and Lagrange multipliers ``lam``, the
constraint violations at position and velocity level, the energy where the system
is conservative, joint reactions, the final status and the run metadata. Its
methods return pandas DataFrames with SI units in the column names, one row per
output time, which :func:`write_table` writes as CSV (full precision, for
spreadsheets and scripts) and Markdown (formatted, for reports).

The violations are defined as

.. math::

    e_\Phi(t_k) = \lVert \Phi(t_k, q_k) \rVert_\infty, \qquad
    e_\nu(t_k) = \lVert \Phi_q(t_k, q_k)\, v_k - \nu(t_k, q_k) \rVert_\infty ,

and the energy drift as :math:`E(t_k) - E(t_0)`, made relative by
:math:`|E(t_0)|` (or by :math:`\max_k |E(t_k)|` when :math:`E(t_0) = 0`).
"""

from __future__ import annotations

import functools
import importlib.metadata
import re
from dataclasses import dataclass, field
from pathlib import Path
from collections.abc import Sequence
from typing import Any, Literal, NamedTuple

import numpy as np
import pandas as pd

from .paths import output_folder, write_atomically

__all__ = [
    "AcceptedSteps",
    "FinalState",
    "SimulationResult",
    "environment_versions",
    "run_metadata",
    "markdown_table",
    "write_table",
]

TIME_COLUMN = "t [s]"
#: Final statuses of a run (:attr:`SimulationResult.status`): reached the end time; reached it but a
#: check found the result doubtful; stopped early.  Defined here, used by the integrators.
STATUS_FINISHED, STATUS_WARNED, STATUS_FAILED = "finished", "finished with warnings", "failed"
RUN_STATUSES = (STATUS_FINISHED, STATUS_WARNED, STATUS_FAILED)
FINISHED_STATUSES = (STATUS_FINISHED, STATUS_WARNED)
POSITION_VIOLATION_COLUMN = "position violation [m]"
VELOCITY_VIOLATION_COLUMN = "velocity violation [m/s]"
_VIOLATION_UNITS_NOTE = (
    "Max-abs over all constraint equations. Rows of Phi that are angles (or "
    "dimensionless, e.g. Euler-parameter normalisation) contribute in rad (rad/s) "
    "or 1 (1/s); the [m] and [m/s] labels are nominal."
)
_STEM_RE = re.compile(r"^[A-Za-z0-9][A-Za-z0-9_.\-]*$")


# ----------------------------------------------------------------------------------
# Table writers
# ----------------------------------------------------------------------------------
def _check_stem(stem: str) -> str:
    if not isinstance(stem, str) or not _STEM_RE.match(stem) or stem.endswith("."):
        raise ValueError(
            f"table/figure stem {stem!r} must be a plain file name (letters, digits, '_', '-', '.')"
        )
    return stem


def write_table(
    df: pd.DataFrame, out_dir: str | Path, stem: str, floatfmt: str = ".6g", record=None
) -> dict[str, Path]:
    """Write a DataFrame as ``<stem>.csv`` and ``<stem>.md`` into ``out_dir``.

    The CSV keeps full floating-point precision (shortest repr, so ``pd.read_csv``
    of pandas >= 3 reads back the identical floats; with pandas 2 pass
    ``float_precision="round_trip"``); only the Markdown table is formatted with
    ``floatfmt``. A default ``RangeIndex`` is not written; any other
    index is written as the first column(s).

    Parameters
    ----------
    df : pandas.DataFrame
        Table to write; units belong in the column names, e.g. ``"Fx [N]"``.
    out_dir : str or Path
        Output folder, created if missing.
    stem : str
        File name without suffix.
    floatfmt : str, optional
        Format spec for floats in the Markdown table (passed to tabulate).
    record : core.provenance.RunRecord, optional
        How the table was computed: written as ``<stem>.csv-metadata.json`` (CSVW) and as a line
        under the Markdown table.

    Returns
    -------
    dict of str to Path
        ``{"csv": path, "md": path}``, and ``"metadata"`` when ``record`` is given.
    """
    if not isinstance(df, pd.DataFrame):
        raise TypeError(f"write_table({stem!r}): expected a pandas DataFrame, got {type(df).__name__}")
    _check_stem(stem)
    out = output_folder(out_dir)
    keep_index = not (isinstance(df.index, pd.RangeIndex) and df.index.name is None)
    csv_path = out / f"{stem}.csv"
    md_path = out / f"{stem}.md"
    md = markdown_table(df, index=keep_index, floatfmt=floatfmt) + "\n"
    if record is not None:
        md += "\n" + record.markdown_line() + "\n"
    write_atomically(csv_path, lambda p: df.to_csv(p, index=keep_index))
    write_atomically(md_path, lambda p: p.write_text(md, encoding="utf-8"))
    paths = {"csv": csv_path, "md": md_path}
    if record is not None:
        import json

        meta = json.dumps(record.csvw(csv_path.name, title=stem), indent=2, ensure_ascii=False) + "\n"
        paths["metadata"] = write_atomically(out / f"{stem}.csv-metadata.json",
                                             lambda p: p.write_text(meta, encoding="utf-8"))
    return paths


def _escape_cell(x):
    """A cell or header as GitHub-flavoured Markdown table text: ``|`` escaped, line breaks as spaces."""
    if isinstance(x, str):
        return x.replace("\\|", "|").replace("|", "\\|").replace("\r\n", " ").replace("\n", " ")
    if isinstance(x, tuple):  # MultiIndex labels
        return tuple(_escape_cell(v) for v in x)
    return x


def markdown_table(df: pd.DataFrame, index: bool = False, floatfmt: str = ".6g") -> str:
    """A DataFrame as a GitHub-flavoured Markdown table that renders as the table it is.

    A ``|`` inside a header or a cell (``max |Φ| [m]``) would end the cell; it is written ``\\|``
    (GitHub Flavored Markdown spec, "Tables (extension)"), and a line break inside a cell becomes a space.  Numbers are
    formatted with ``floatfmt``.

    Parameters
    ----------
    df : pandas.DataFrame
    index : bool
        Write the index as the first column(s).
    floatfmt : str
        Format spec for floats (passed to tabulate).

    Returns
    -------
    str
    """
    out = df.copy()
    out.columns = [_escape_cell(c) for c in out.columns]
    if index:
        out.index = out.index.map(_escape_cell)
        out.index.names = [_escape_cell(n) for n in out.index.names]
    for c in out.columns:
        if out[c].dtype == object or pd.api.types.is_string_dtype(out[c].dtype):
            out[c] = out[c].map(_escape_cell)
    return out.to_markdown(index=index, floatfmt=floatfmt)


# ----------------------------------------------------------------------------------
# Metadata helpers
# ----------------------------------------------------------------------------------
def environment_versions() -> dict[str, str]:
    """Return the versions of mbsuite, Python, numpy, scipy and pandas.

    Returns
    -------
    dict of str to str
        Package name -> version; ``"unknown"`` for mbsuite when it is not installed.
    """
    return dict(_environment_versions())


@functools.lru_cache(maxsize=1)
def _environment_versions() -> dict[str, str]:
    """Looked up once per process (the package metadata query costs ~1 ms per result otherwise)."""
    import platform

    import scipy

    try:
        mbsuite_version = importlib.metadata.version("mbsuite")
    except importlib.metadata.PackageNotFoundError:
        mbsuite_version = "unknown"
    return {
        "mbsuite": mbsuite_version,
        "python": platform.python_version(),
        "numpy": np.__version__,
        "scipy": scipy.__version__,
        "pandas": pd.__version__,
    }


def run_metadata(
    *,
    method: str,
    system: str = "",
    rtol: float | None = None,
    atol: float | None = None,
    h: float | None = None,
    wall_time_s: float | None = None,
    **extra: Any,
) -> dict[str, Any]:
    """Build the ``meta`` dict of a :class:`SimulationResult` (the one definition of its keys).

    :func:`core.simulation.simulate` writes its metadata with this function, so every result
    carries the same keys.

    Parameters
    ----------
    method : str
        Integrator registry name, e.g. ``"radau-ggl"``.
    system : str, optional
        Name of the simulated system.
    rtol, atol : float, optional
        Requested relative and absolute tolerances.
    h : float, optional
        Fixed (or initial) step size [s]; None for error-controlled runs without one.
    wall_time_s : float, optional
        Time spent inside the integrator's steps [s].
    **extra
        Further entries stored verbatim (``simulate`` adds ``total_time_s``, ``t_end_reached``,
        ``max_invariant_violation``).

    Returns
    -------
    dict
        ``system, method, rtol, atol, h, wall_time_s``, the extra entries, and ``"versions"``
        from :func:`environment_versions`.
    """
    meta: dict[str, Any] = {
        "system": system,
        "method": method,
        "rtol": rtol,
        "atol": atol,
        "h": h,
        "wall_time_s": wall_time_s,
    }
    meta.update(extra)
    meta["versions"] = environment_versions()
    return meta


def _flatten(mapping: dict[str, Any], prefix: str = "") -> dict[str, Any]:
    flat: dict[str, Any] = {}
    for key, value in mapping.items():
        name = f"{prefix}{key}"
        if isinstance(value, dict):
            flat.update(_flatten(value, prefix=f"{name}."))
        else:
            flat[name] = value
    return flat


# ----------------------------------------------------------------------------------
# SimulationResult
# ----------------------------------------------------------------------------------
class FinalState(NamedTuple):
    """State at the last output time of a run (copies, safe to modify)."""

    t: float
    q: np.ndarray
    v: np.ndarray
    lam: np.ndarray | None


class AcceptedSteps(NamedTuple):
    r"""The state at every accepted step of a run (``simulate(..., record_steps=True)``).

    The output grid ``t_k`` samples the motion; the accepted steps ``t_0 < t_1 < … < t_N`` are
    where the integrator's error control held it to the tolerance, so a quantity evaluated
    there (and located between them, :mod:`core.signals`) does not depend on the output step.

    Attributes
    ----------
    t : ndarray, shape (n_steps + 1,)
        Start time and the end time of every accepted step [s], strictly increasing.
    q : ndarray, shape (n_steps + 1, n_q)
        Coordinates there.
    v : ndarray, shape (n_steps + 1, n_v)
        Velocities there.
    """

    t: np.ndarray
    q: np.ndarray
    v: np.ndarray


def search_states_at_steps(result, names: Sequence[str]) -> np.ndarray | None:
    """The search state a stateful force kind had after every accepted step of a compiled run.

    ``simulate(..., record_steps=True)`` on a compiled integrator keeps, beside
    :class:`AcceptedSteps`, the search state of every force kind that keeps one (a contact
    search's tracked points), in ``result.step_search_states`` by the kind's element names.  A quantity evaluated afterwards at step ``k`` with the state of row ``k`` sees the
    contacts the run used from that step on, with no need to carry the search along the run again.

    Parameters
    ----------
    result : SimulationResult
    names : sequence of str
        The element names of the kind (its compiled record's ``names``).

    Returns
    -------
    ndarray, shape (n_steps + 1, n_elements, width), or None
        None when the run recorded no states (numpy integrators, or ``record_steps=False``).
    """
    states = getattr(result, "step_search_states", None)
    if not states:
        return None
    return states.get(tuple(names))


def _readonly(name: str, value: Any, ndim: int) -> np.ndarray:
    try:
        arr = np.asarray(value, dtype=float)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"SimulationResult.{name} must be numeric: {exc}") from exc
    if arr.ndim != ndim:
        raise ValueError(f"SimulationResult.{name} must be {ndim}-D, got shape {arr.shape}")
    view = arr.view()
    view.flags.writeable = False
    return view


@dataclass(frozen=True, eq=False, kw_only=True)
class SimulationResult:
    r"""Time history and diagnostics of one integrator run.

    Parameters
    ----------
    t : ndarray, shape (n_t,)
        Output times [s], strictly increasing.
    q : ndarray, shape (n_t, n_q)
        Generalized coordinates at the output times (m, rad, or 1 for Euler parameters).
    v : ndarray, shape (n_t, n_v)
        Generalized velocities (m/s, rad/s).
    status : {"finished", "finished with warnings", "failed"}
        Final status: reached the end time; reached it but a check found the result doubtful
        (see ``warnings``); or stopped early (the message says where and why).
    message : str, optional
        Human-readable reason for the status (where and why a failed run stopped; the warnings).
    warnings : tuple of str, optional
        What the checks of the integrator and of :func:`core.simulation.simulate` found doubtful.
    lam : ndarray, shape (n_t, n_c), optional
        Lagrange multipliers; None if the formulation does not produce them.
    counters : dict of str to int, optional
        Work counters: right-hand sides, Jacobians, factorizations, Newton iterations,
        rejected steps, ...
    meta : dict, optional
        Run metadata (see :func:`run_metadata`): method, rtol, atol, step size, wall
        time, model name, versions. ``"versions"`` is added if missing.
    coordinate_names, velocity_names : list of str, optional
        Column names for ``q`` and ``v``, ideally with units, e.g. ``"crank.x [m]"``.
        Default ``"q[i]"`` / ``"v[i]"``.
    constraint_names : list of str, optional
        Names of the ``n_c`` constraint equations (columns of ``lam``). Default ``"lam[i]"``.
    position_violation : ndarray, shape (n_t,)
        :math:`\lVert\Phi(t, q)\rVert_\infty`. Required when ``n_c > 0``; zeros otherwise.
    velocity_violation : ndarray, shape (n_t,)
        :math:`\lVert\Phi_q v - \nu\rVert_\infty`. Required when ``n_c > 0``.
    energy : ndarray, shape (n_t,), optional
        Total mechanical energy [J] for conservative systems.
    reactions : dict of str to ndarray of shape (n_t, k), optional
        Joint reaction forces/torques per joint name.
    reaction_names : dict of str to list of str, optional
        Column names per joint, e.g. ``["Fx [N]", "Fy [N]", "Mz [N m]"]``.
    steps : AcceptedSteps, optional
        The state at every accepted step (``simulate(..., record_steps=True)``): the dense
        record from which statistics that must not depend on the output grid are taken.
    step_search_states : dict, optional
        With ``steps`` on a compiled integrator: the search state of every stateful force kind
        after every accepted step, by the kind's element names
        (:func:`search_states_at_steps`).

    Notes
    -----
    ``n_c`` is taken from ``lam`` if given, else from ``constraint_names``, else 0.
    Arrays are stored as read-only views; the instance is immutable.
    """

    t: np.ndarray
    q: np.ndarray
    v: np.ndarray
    status: Literal["finished", "finished with warnings", "failed"]
    message: str = ""
    warnings: tuple[str, ...] = ()
    lam: np.ndarray | None = None
    counters: dict[str, int] = field(default_factory=dict)
    meta: dict[str, Any] = field(default_factory=dict)
    coordinate_names: list[str] | None = None
    velocity_names: list[str] | None = None
    constraint_names: list[str] | None = None
    position_violation: np.ndarray | None = None
    velocity_violation: np.ndarray | None = None
    energy: np.ndarray | None = None
    reactions: dict[str, np.ndarray] = field(default_factory=dict)
    reaction_names: dict[str, list[str]] = field(default_factory=dict)
    steps: AcceptedSteps | None = None
    step_search_states: dict[tuple[str, ...], np.ndarray] | None = None

    # -- validation ---------------------------------------------------------------
    def __post_init__(self) -> None:  # noqa: C901 - one check per field, in order
        put = object.__setattr__
        if self.status not in RUN_STATUSES:
            raise ValueError(f"SimulationResult.status must be one of {RUN_STATUSES}, got {self.status!r}")
        put(self, "message", str(self.message))
        put(self, "warnings", tuple(str(w) for w in self.warnings))
        if self.warnings and self.status == STATUS_FINISHED:
            put(self, "status", STATUS_WARNED)

        t = _readonly("t", self.t, 1)
        n_t = t.shape[0]
        if n_t == 0:
            raise ValueError("SimulationResult.t is empty; a run records at least the initial time")
        steps = np.diff(t)
        bad = np.flatnonzero(~(steps > 0) & np.isfinite(steps))
        if bad.size:
            i = int(bad[0])
            raise ValueError(
                f"SimulationResult.t must be strictly increasing: t[{i}]={t[i]!r}, t[{i + 1}]={t[i + 1]!r}"
            )
        put(self, "t", t)

        for name in ("q", "v"):
            arr = _readonly(name, getattr(self, name), 2)
            if arr.shape[0] != n_t:
                raise ValueError(
                    f"SimulationResult.{name} has {arr.shape[0]} rows but t has {n_t} samples "
                    f"(expected shape ({n_t}, n_{name}))"
                )
            put(self, name, arr)

        if self.lam is not None:
            lam = _readonly("lam", self.lam, 2)
            if lam.shape[0] != n_t:
                raise ValueError(f"SimulationResult.lam has {lam.shape[0]} rows but t has {n_t} samples")
            put(self, "lam", lam)
            n_c = lam.shape[1]
        else:
            n_c = len(self.constraint_names) if self.constraint_names is not None else 0

        self._set_names("coordinate_names", self.q.shape[1], "q")
        self._set_names("velocity_names", self.v.shape[1], "v")
        self._set_names("constraint_names", n_c, "lam")

        for name in ("position_violation", "velocity_violation"):
            value = getattr(self, name)
            if value is None:
                if n_c > 0:
                    raise ValueError(
                        f"SimulationResult.{name} is required for a system with {n_c} constraint equations"
                    )
                value = np.zeros(n_t)  # no constraints: violation is exactly zero
            arr = _readonly(name, value, 1)
            if arr.shape != (n_t,):
                raise ValueError(f"SimulationResult.{name} has shape {arr.shape}, expected ({n_t},)")
            put(self, name, arr)

        if self.energy is not None:
            energy = _readonly("energy", self.energy, 1)
            if energy.shape != (n_t,):
                raise ValueError(f"SimulationResult.energy has shape {energy.shape}, expected ({n_t},)")
            put(self, "energy", energy)

        counters: dict[str, int] = {}
        for key, value in dict(self.counters).items():
            if isinstance(value, bool) or int(value) != value or value < 0:
                raise ValueError(f"SimulationResult.counters[{key!r}] must be a non-negative integer, got {value!r}")
            counters[str(key)] = int(value)
        put(self, "counters", counters)

        meta = dict(self.meta)
        meta.setdefault("versions", environment_versions())
        put(self, "meta", meta)

        reactions: dict[str, np.ndarray] = {}
        reaction_names: dict[str, list[str]] = {}
        unknown = set(self.reaction_names) - set(self.reactions)
        if unknown:
            raise ValueError(f"SimulationResult.reaction_names has joints without reactions: {sorted(unknown)}")
        for joint, value in dict(self.reactions).items():
            arr = _readonly(f"reactions[{joint!r}]", value, 2)
            if arr.shape[0] != n_t:
                raise ValueError(
                    f"SimulationResult.reactions[{joint!r}] has {arr.shape[0]} rows but t has {n_t} samples"
                )
            names = self.reaction_names.get(joint)
            names = [f"{joint}[{k}]" for k in range(arr.shape[1])] if names is None else list(names)
            if len(names) != arr.shape[1]:
                raise ValueError(
                    f"SimulationResult.reaction_names[{joint!r}] has {len(names)} names "
                    f"for {arr.shape[1]} reaction columns"
                )
            reactions[joint] = arr
            reaction_names[joint] = names
        put(self, "reactions", reactions)
        put(self, "reaction_names", reaction_names)

        if self.steps is not None:
            st_t = _readonly("steps.t", self.steps[0], 1)
            st_q = _readonly("steps.q", self.steps[1], 2)
            st_v = _readonly("steps.v", self.steps[2], 2)
            if st_q.shape != (st_t.size, self.q.shape[1]) or st_v.shape != (st_t.size, self.v.shape[1]):
                raise ValueError(f"SimulationResult.steps: q {st_q.shape} and v {st_v.shape} must have one row per "
                                 f"step time ({st_t.size}) and the columns of q and v")
            if np.any(np.diff(st_t) <= 0):
                raise ValueError("SimulationResult.steps.t must be strictly increasing")
            put(self, "steps", AcceptedSteps(st_t, st_q, st_v))

    def _set_names(self, attr: str, n: int, prefix: str) -> None:
        names = getattr(self, attr)
        names = [f"{prefix}[{i}]" for i in range(n)] if names is None else [str(s) for s in names]
        if len(names) != n:
            raise ValueError(f"SimulationResult.{attr} has {len(names)} names for {n} columns")
        if len(set(names)) != n:
            dupes = sorted({s for s in names if names.count(s) > 1})
            raise ValueError(f"SimulationResult.{attr} has duplicate names: {dupes}")
        object.__setattr__(self, attr, names)

    # -- scalar properties ---------------------------------------------------------
    @property
    def success(self) -> bool:
        """True if the integrator reached the end time, with or without warnings (read :attr:`status`)."""
        return self.status in FINISHED_STATUSES

    @property
    def has_warnings(self) -> bool:
        """True if the run reached the end time but a check found it doubtful (:attr:`warnings`)."""
        return self.status == STATUS_WARNED

    @property
    def n_t(self) -> int:
        """Number of output times."""
        return int(self.t.shape[0])

    def final_state(self) -> FinalState:
        """Return time, coordinates, velocities and multipliers at the last output time."""
        lam = None if self.lam is None else self.lam[-1].copy()
        return FinalState(float(self.t[-1]), self.q[-1].copy(), self.v[-1].copy(), lam)

    # -- tables ----------------------------------------------------------------------
    def _frame(self, data: np.ndarray | dict[str, np.ndarray], columns: list[str] | None = None) -> pd.DataFrame:
        body = pd.DataFrame(data, columns=columns) if columns is not None else pd.DataFrame(data)
        body.insert(0, TIME_COLUMN, np.array(self.t))
        body.attrs["meta"] = dict(self.meta)
        body.attrs["status"] = self.status
        return body

    def coordinates(self) -> pd.DataFrame:
        """Return the coordinates ``q`` as a DataFrame (``"t [s]"`` + one column per coordinate)."""
        return self._frame(np.array(self.q), self.coordinate_names)

    def velocities(self) -> pd.DataFrame:
        """Return the velocities ``v`` as a DataFrame (``"t [s]"`` + one column per velocity)."""
        return self._frame(np.array(self.v), self.velocity_names)

    def multipliers(self) -> pd.DataFrame:
        """Return the Lagrange multipliers ``lam`` as a DataFrame.

        Raises
        ------
        ValueError
            If the run did not record multipliers.
        """
        if self.lam is None:
            raise ValueError(
                f"this run (method {self.meta.get('method', '?')!r}) did not record Lagrange multipliers"
            )
        df = self._frame(np.array(self.lam), self.constraint_names)
        df.attrs["units"] = (
            "Units follow the constraint row: N for rows of Phi in m, N m for rows in rad "
            "(Phi_q^T lam is a generalized force)."
        )
        return df

    def violations(self) -> pd.DataFrame:
        """Return the position- and velocity-level constraint violations over time."""
        df = self._frame(
            {
                POSITION_VIOLATION_COLUMN: np.array(self.position_violation),
                VELOCITY_VIOLATION_COLUMN: np.array(self.velocity_violation),
            }
        )
        df.attrs["units"] = _VIOLATION_UNITS_NOTE
        return df

    def energy_table(self) -> pd.DataFrame:
        """Return the energy, its drift ``E - E0`` and the relative drift over time.

        The relative drift is ``(E - E0) / |E0|``, or ``(E - E0) / max|E|`` if
        ``E0 == 0`` (zero if the energy is identically zero); the scale used is stored
        in ``attrs["energy scale [J]"]``.

        Raises
        ------
        ValueError
            If the run did not record the energy.
        """
        if self.energy is None:
            raise ValueError(
                f"this run (model {self.meta.get('model', '?')!r}) did not record the energy "
                "(only conservative systems do)"
            )
        energy = np.array(self.energy)
        drift = energy - energy[0]
        scale = abs(energy[0]) if energy[0] != 0 else float(np.max(np.abs(energy)))
        relative = drift / scale if scale > 0 else np.zeros_like(drift)
        df = self._frame(
            {"energy [J]": energy, "energy drift [J]": drift, "relative energy drift [-]": relative}
        )
        df.attrs["energy scale [J]"] = scale
        return df

    def reactions_table(self, joint_name: str) -> pd.DataFrame:
        """Return the reaction forces/torques of one joint over time.

        Parameters
        ----------
        joint_name : str
            Name of the joint as given in ``reactions``.
        """
        if joint_name not in self.reactions:
            known = ", ".join(sorted(self.reactions)) or "none recorded"
            raise ValueError(f"no reactions for joint {joint_name!r}; available: {known}")
        df = self._frame(np.array(self.reactions[joint_name]), self.reaction_names[joint_name])
        df.attrs["joint"] = joint_name
        return df

    def summary_row(self, label: str, checks: dict[str, Any] | None = None) -> dict[str, Any]:
        """One row of an integrator comparison table, as a dict: ``integrator`` (``label``), status,
        wall time, steps, max position and velocity violation, max energy drift (conservative
        systems), the run's own ``checks`` (``{"period error [s]": ...}``) and last ``remarks``
        (the warnings of a finished run, or why it failed; "none" if there are none).  Collect
        the rows into a DataFrame."""
        row: dict[str, Any] = {
            "integrator": label,
            "status": self.status,
            "wall time [s]": self.meta.get("wall_time_s", np.nan),
            "steps [-]": self.counters.get("n_steps", 0),
            "max |Φ| [m]": float(np.max(self.position_violation)),
            "max |Φ_q v − ν| [m/s]": float(np.max(self.velocity_violation)),
        }
        if self.energy is not None:
            row["max |E − E0| [J]"] = float(np.max(np.abs(self.energy - self.energy[0])))
        row.update(checks or {})
        row["remarks"] = ("; ".join(self.warnings) or "none") if self.success else self.message
        return row

    def summary(self) -> pd.DataFrame:
        """Return a one-row DataFrame: status, metadata, counters, final and max violations, energy drift.

        Energy (conservative systems): ``max |E − E0|`` [J], the scale of :meth:`energy_table`
        (``|E0|``, or ``max |E|`` when ``E0 = 0``) and the relative drift ``max |E − E0| / |E0|``,
        which is NaN when ``E0 = 0`` (read the absolute drift against the scale then).
        """
        row: dict[str, Any] = {
            "status": self.status,
            "message": self.message,
            "n warnings": len(self.warnings),
            "n_t": self.n_t,
            "t_end [s]": float(self.t[-1]),
        }
        row.update(_flatten(self.meta))
        row.update({f"n {key}": value for key, value in self.counters.items()})
        row["final " + POSITION_VIOLATION_COLUMN] = float(self.position_violation[-1])
        row["final " + VELOCITY_VIOLATION_COLUMN] = float(self.velocity_violation[-1])
        row["max " + POSITION_VIOLATION_COLUMN] = float(np.nanmax(self.position_violation))
        row["max " + VELOCITY_VIOLATION_COLUMN] = float(np.nanmax(self.velocity_violation))
        if self.energy is not None:
            # the absolute drift always, with its scale; the relative drift only against a non-zero E0
            # (against the run's own max |E| a drift from E0 = 0 would always read 1)
            energy_df = self.energy_table()
            row["max |energy drift| [J]"] = float(np.nanmax(np.abs(energy_df["energy drift [J]"])))
            row["energy scale [J]"] = float(energy_df.attrs["energy scale [J]"])
            row["max |relative energy drift| [-]"] = (
                float(np.nanmax(np.abs(energy_df["relative energy drift [-]"]))) if self.energy[0] != 0 else np.nan)
        df = pd.DataFrame([row])
        df.attrs["meta"] = dict(self.meta)
        return df

    def to_frame(self) -> pd.DataFrame:
        """Return one DataFrame with time, coordinates, velocities, multipliers, violations, energy.

        Raises
        ------
        ValueError
            If two parts share a column name (e.g. a coordinate named like a velocity).
        """
        parts = [self.coordinates(), self.velocities()]
        if self.lam is not None:
            parts.append(self.multipliers())
        parts.append(self.violations())
        if self.energy is not None:
            parts.append(self.energy_table())
        columns: list[str] = []
        for part in parts:
            columns.extend(part.columns[1:])
        dupes = sorted({c for c in columns if columns.count(c) > 1})
        if dupes:
            raise ValueError(f"SimulationResult.to_frame: duplicate column names {dupes}")
        df = pd.concat([parts[0]] + [p.drop(columns=TIME_COLUMN) for p in parts[1:]], axis=1)
        df.attrs = {"meta": dict(self.meta), "status": self.status, "units": _VIOLATION_UNITS_NOTE}
        return df
