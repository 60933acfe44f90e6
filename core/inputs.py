r"""Checked inputs: declared schemas, quantities with units, plausible ranges.

Every domain validates what a user gives it — a vehicle file, a track, a trial, a command-line
option, a keyword argument — once, at the boundary, with the three tools of this module; inside,
the data are trusted.

**Schemas** (:class:`InputModel`, :func:`validate`).  A file's tables are declared as pydantic v2
models with unknown keys forbidden.  :func:`validate` turns pydantic's error list into one line
that names the file, the table and the key, and for a misspelt key suggests the closest valid one
(``vehicle.toml [secondary] yaw_stifness: unknown key; did you mean 'yaw_stiffness'?``).
pydantic is the ecosystem's usual validation library (typed fields, nested models, ``extra =
"forbid"``, error locations as paths); it is used for the structure, this module for units and
ranges.

**Units** (:func:`parse_quantity`).  A bare number is in the unit the field declares (SI unless
the format itself declares another, e.g. the mm of a profile file).  A string carries its unit,
``"32 t"``, ``"1.2 MN/m"``, ``"1800 mm"``, ``"20 deg"``, ``"80 km/h"``, and is converted by pint;
a string of the wrong dimension (``"1800 mm"`` for a mass) is refused with both dimensions named.
Lists are converted element by element.  Booleans are never numbers.

**Plausible ranges** (:class:`RangeTable`).  Every physical input has a documented range, kept as
data in ``data/<domain>/plausible_ranges.csv`` with its rationale.  A value outside it is refused
with an :class:`ImplausibleValueError` that names the value, the range and the likely slip — the
unit of the same dimension in which the number the user wrote would lie inside the range::

    car body mass 32 kg is outside the plausible range 1 t ... 200 t: did you mean 32 t?

A deliberate outlier is accepted by naming its quantity in ``accept`` (a keyword argument of the
reading function, or the ``[checks] accept = [...]`` list of a file).

The range table's columns: ``quantity`` (the key, e.g. ``car_body_mass``), ``label`` (the words
used in messages), ``unit`` (the SI unit of the bounds and of a bare number), ``low``, ``high``
(inclusive; empty for no bound) and ``rationale``.
"""

from __future__ import annotations

import csv
import difflib
import functools
import math
import numbers
import tokenize
from dataclasses import dataclass
from pathlib import Path
from typing import Annotated, Any, Iterable

import numpy as np

from .errors import DataFileError, InputError, UnknownOptionError

__all__ = [
    "ImplausibleValueError",
    "UnitError",
    "InputModel",
    "PlausibleRange",
    "RangeTable",
    "parse_quantity",
    "validate",
    "closest",
    "check_choice",
    "check_keywords",
    "checked_options",
    "unit_registry",
]


class ImplausibleValueError(InputError):
    """A physical value outside its documented plausible range.

    Attributes: ``quantity`` (the range key), ``value`` (SI), ``suggestion`` (the likely slip as
    text, or "").  Accept a deliberate outlier with ``accept=[quantity]``.
    """

    def __init__(self, message: str, quantity: str = "", value: float = math.nan, suggestion: str = ""):
        super().__init__(message)
        self.quantity = quantity
        self.value = value
        self.suggestion = suggestion


class UnitError(InputError):
    """A quantity written with a unit that is unknown or of the wrong dimension."""


# ---------------------------------------------------------------------------------------------
# units
# ---------------------------------------------------------------------------------------------
@functools.cache
def unit_registry():
    """The one pint registry of mbsuite (created on first use: importing pint takes ~0.3 s)."""
    import pint

    ureg = pint.UnitRegistry(autoconvert_offset_to_baseunit=True)
    return ureg


def _is_number(x) -> bool:
    return isinstance(x, numbers.Real) and not isinstance(x, bool)


def _fmt(x: float) -> str:
    """A float as a short plain number (no numpy repr)."""
    x = float(x)
    if x == 0 or 1e-4 <= abs(x) < 1e7:
        return f"{x:.6g}"
    return f"{x:.4g}"


def _convert_one(value, unit: str, where: str) -> float:
    if _is_number(value):
        v = float(value)
    elif isinstance(value, str):
        text = value.strip()
        if "," in text:  # pint would read "1,435 m" as 1435 m
            raise UnitError(f"{where}: {value!r} has a comma; write a decimal point (1.435 m) and no "
                            f"thousands separator")
        try:
            v = float(text)  # a bare number written as a string: in the declared unit
        except ValueError:
            ureg = unit_registry()
            import pint

            try:
                q = ureg.Quantity(text)
            except (pint.errors.UndefinedUnitError, pint.errors.DefinitionSyntaxError, ValueError,
                    AttributeError, TypeError, AssertionError, SyntaxError, tokenize.TokenError) as exc:
                raise UnitError(f"{where}: cannot read {value!r} as a quantity in {unit} ({_short(exc)})") from None
            if not isinstance(q, ureg.Quantity):  # a pure number such as "2*3"
                v = float(q)
            else:
                try:
                    v = float(q.to(unit).magnitude)
                except pint.errors.DimensionalityError:
                    raise UnitError(
                        f"{where}: {value!r} is a {_dimension_words(q)}, expected {_dimension_words(ureg.Quantity(1, unit))} "
                        f"(in {unit})") from None
    else:
        raise InputError(f"{where}: {value!r} is not a number (a number in {unit}, or a string with its unit)")
    if not math.isfinite(v):
        raise InputError(f"{where}: {value!r} is not a finite number")
    return v


def _short(exc) -> str:
    s = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
    return s[:120]


def _dimension_words(q) -> str:
    dims = str(q.dimensionality)
    names = {
        "[mass]": "mass", "[length]": "length", "[time]": "time", "dimensionless": "pure number or angle",
        "[length] / [time]": "speed", "[mass] / [time] ** 2": "stiffness (force per length)",
        "[length] * [mass] / [time] ** 2": "force", "[mass] / [length] / [time] ** 2": "pressure",
        "[length] ** 2 * [mass]": "moment of inertia", "[mass] / [time]": "damping (force per speed)",
        "[length] ** 2 * [mass] / [time] ** 2": "moment or energy", "1 / [time]": "frequency",
        "[length] / [time] ** 2": "acceleration",
    }
    return f"{names.get(dims, dims)} ({dims})"


def parse_quantity(value, unit: str, *, where: str = "value"):
    """Convert a number, a string with a unit, or a list of them to floats in ``unit``.

    Parameters
    ----------
    value : float, str, or sequence of them
        A bare number is taken in ``unit``; a string such as ``"1.2 MN/m"`` is converted by pint.
    unit : str
        The unit the result is expressed in (pint syntax: ``"kg"``, ``"N/m"``, ``"rad"``).
    where : str
        What the value is, for the message (``"vehicle.toml [car_body] mass"``).

    Returns
    -------
    float or ndarray
        A float for a scalar input, a 1-D array for a sequence.

    Raises
    ------
    UnitError
        An unknown unit or one of another dimension.
    InputError
        Not a number (including booleans and None), or not finite.
    """
    if isinstance(value, (list, tuple, np.ndarray)):
        arr = np.asarray(value, dtype=object).ravel()
        return np.array([_convert_one(x, unit, f"{where}[{i}]") for i, x in enumerate(arr)], dtype=float)
    return _convert_one(value, unit, where)


# ---------------------------------------------------------------------------------------------
# plausible ranges
# ---------------------------------------------------------------------------------------------
#: in a range that contains zero, a slip is named only if the corrected value is at least this
#: fraction of the range's largest bound: every tiny value lies in such a range, and a 0.3 m
#: cant against a 0.2 m limit is no 0.3 mm cant
SLIP_MIN_FRACTION = 0.02

#: units a slip is usually made in, by SI unit of the quantity (the likely-slip suggestions)
_SLIP_UNITS: dict[str, tuple[str, ...]] = {
    "kg": ("t", "g", "lb"),
    "m": ("mm", "cm", "km"),
    "m/s": ("km/h", "mm/s"),
    "m/s^2": ("mm/s^2",),
    "N": ("kN", "MN"),
    "N/m": ("kN/m", "MN/m", "N/mm"),
    "N*s/m": ("kN*s/m",),
    "N*m/rad": ("kN*m/rad", "MN*m/rad"),
    "N*m": ("kN*m",),
    "kg*m^2": ("t*m^2", "g*m^2"),
    "Pa": ("kPa", "MPa", "GPa"),
    "s": ("ms", "min"),
    "Hz": ("kHz",),
    "rad": ("deg", "mrad"),
    "rad/s": ("deg/s", "rpm"),
    "1/m": ("1/mm", "1/km"),
    "1": ("percent",),
    "m^2": ("mm^2", "cm^2"),
    "m^4": ("mm^4", "cm^4"),
    "kg/m^3": ("g/cm^3", "t/m^3"),
}


@dataclass(frozen=True)
class PlausibleRange:
    """The documented plausible range of one physical input (bounds inclusive, in ``unit``)."""

    quantity: str
    label: str
    unit: str
    low: float
    high: float
    rationale: str = ""

    def describe(self) -> str:
        lo = "" if not math.isfinite(self.low) else _with_unit(self.low, self.unit)
        hi = "" if not math.isfinite(self.high) else _with_unit(self.high, self.unit)
        if lo and hi:
            return f"{lo} ... {hi}"
        return f">= {lo}" if lo else f"<= {hi}"

    def contains(self, v: float) -> bool:
        return self.low <= v <= self.high

    def likely_slip(self, written: float, read_in: str | None = None) -> str:
        """The unit of the same dimension in which the number as written lies in the range
        (``read_in``: the unit the number was taken in, default the range's own)."""
        if not _is_number(written) or written == 0:
            return ""
        read_in = read_in or self.unit

        ureg = unit_registry()
        for u in (self.unit,) + _SLIP_UNITS.get(self.unit, ()):
            if u == read_in:
                continue
            factor = float(ureg.Quantity(1.0, u).to(self.unit).magnitude)
            guess = written * factor
            if self.low <= 0 <= self.high and abs(guess) < SLIP_MIN_FRACTION * max(abs(self.low), abs(self.high)):
                continue
            if self.contains(guess):
                return f"did you mean {_fmt(written)} {_pretty(u)}?"
        return ""


def _pretty(unit: str) -> str:
    return unit.replace("*", " ").replace("^2", "²").replace("percent", "%")


#: units printed with an SI prefix when their value is large (1.2 MN/m rather than 1.2e+06 N/m)
_PREFIXED = ("N", "N/m", "N*s/m", "N*m/rad", "N*m", "Pa")


def _with_unit(v: float, unit: str) -> str:
    """A value written in a unit an engineer reads easily (1 t rather than 1000 kg, 1.2 MN/m
    rather than 1.2e+06 N/m)."""
    if unit == "kg" and abs(v) >= 1000:
        return f"{_fmt(v / 1000)} t"
    if unit == "kg*m^2" and abs(v) >= 1e4:
        return f"{_fmt(v / 1000)} t m²"
    if unit == "1":
        return _fmt(v)
    if unit in _PREFIXED:
        for prefix, f in (("G", 1e9), ("M", 1e6), ("k", 1e3)):
            if abs(v) >= f:
                return f"{_fmt(v / f)} {prefix}{_pretty(unit)}"
    return f"{_fmt(v)} {_pretty(unit)}"


class RangeTable:
    """Plausible ranges of one domain's physical inputs, read from a CSV file.

    Parameters
    ----------
    ranges : iterable of PlausibleRange
    source : str
        The file the table came from (for messages).
    """

    def __init__(self, ranges: Iterable[PlausibleRange], source: str = ""):
        self._ranges = {r.quantity: r for r in ranges}
        self.source = source

    @classmethod
    def from_csv(cls, path) -> RangeTable:
        """Read ``quantity, label, unit, low, high, rationale`` rows (``#`` lines are comments)."""
        path = Path(path)
        try:
            text = path.read_text(encoding="utf-8")
        except FileNotFoundError:
            raise DataFileError(f"range table {path} does not exist") from None
        rows = csv.DictReader(line for line in text.splitlines() if line.strip() and not line.startswith("#"))
        out = []
        for i, row in enumerate(rows, start=2):
            try:
                lo = float(row["low"]) if row["low"].strip() else -math.inf
                hi = float(row["high"]) if row["high"].strip() else math.inf
                out.append(PlausibleRange(row["quantity"].strip(), row["label"].strip(), row["unit"].strip(),
                                          lo, hi, row.get("rationale", "").strip()))
            except (KeyError, ValueError, AttributeError) as exc:
                raise DataFileError(f"range table {path}, data row {i}: {_short(exc)}") from None
            if not lo <= hi:
                raise DataFileError(f"range table {path}: {row['quantity']} has low > high")
            if any(r.quantity == out[-1].quantity for r in out[:-1]):
                raise DataFileError(f"range table {path}: quantity {out[-1].quantity!r} appears twice")
        return cls(out, source=str(path))

    def __getitem__(self, quantity: str) -> PlausibleRange:
        try:
            return self._ranges[quantity]
        except KeyError:
            raise KeyError(f"no plausible range {quantity!r} in {self.source}") from None

    def __contains__(self, quantity: str) -> bool:
        return quantity in self._ranges

    def __iter__(self):
        return iter(self._ranges.values())

    def to_frame(self):
        """The table as a DataFrame (for the README and the docs)."""
        import pandas as pd

        return pd.DataFrame([{"quantity": r.quantity, "label": r.label, "unit": r.unit, "low": r.low,
                              "high": r.high, "rationale": r.rationale} for r in self])

    def check(self, quantity: str, value, *, where: str = "", accept: Iterable[str] = (), unit: str | None = None):
        """Parse ``value`` (number, string with unit, or list) and check it against the range.

        Returns the value in SI (float, or an array for a list).  ``where`` prefixes the message
        (the file and key, or the argument); ``accept`` lists quantities whose range is not
        enforced (deliberate outliers).  ``unit`` is the unit of a bare number when it is not the
        range's own (a command-line option in mm).
        """
        r = self[quantity]
        label = where or r.label
        if unit is not None and unit != r.unit:
            v = parse_quantity(value, unit, where=label)
            ureg = unit_registry()
            v = np.asarray(v) * float(ureg.Quantity(1.0, unit).to(r.unit).magnitude)
            v = float(v) if v.ndim == 0 else v
        else:
            v = parse_quantity(value, r.unit, where=label)
        if isinstance(accept, str):  # accept="speed" means ["speed"], not its letters
            accept = [accept]
        if quantity in set(accept):
            return v
        vals = np.atleast_1d(v)
        written = np.atleast_1d(np.asarray(value, dtype=object))
        for i, x in enumerate(vals):
            if r.contains(float(x)):
                continue
            w = written[i] if written.size == vals.size else None
            slip = r.likely_slip(float(w), unit) if _is_number(w) else ""
            pos = f"[{i}] " if vals.size > 1 or np.ndim(v) > 0 else ""
            lead = f"{where}: " if where else ""
            shown = _with_unit(float(x), r.unit) if r.unit in ("kg", "1") else f"{_fmt(x)} {_pretty(r.unit)}"
            msg = (f"{lead}{r.label} {pos}{shown} is outside the plausible range "
                   f"{r.describe()}")
            msg += f": {slip}" if slip else f" ({r.rationale})" if r.rationale else ""
            msg += f" (to use it deliberately, accept={quantity!r})"
            raise ImplausibleValueError(msg, quantity=quantity, value=float(x), suggestion=slip)
        return v

    def to_markdown(self) -> str:
        """The table as GitHub Markdown (quantity, what, low, high, why), bounds with readable
        units: the README's tables are this output, and a test keeps them equal."""
        lines = ["| quantity | what | low | high | why |", "|---|---|---|---|---|"]
        for r in self:
            lo = _with_unit(r.low, r.unit) if math.isfinite(r.low) else "—"
            hi = _with_unit(r.high, r.unit) if math.isfinite(r.high) else "—"
            why = r.rationale.replace("|", "/")
            lines.append(f"| `{r.quantity}` | {r.label} | {lo} | {hi} | {why} |")
        return "\n".join(lines)

    def quantity(self, name: str, shape: int | None = None):
        """A pydantic field type for quantity ``name``: parses units and checks the range.

        ``shape`` n gives a tuple of n floats (a scalar is broadcast to all n).  The range check
        honours ``context={"accept": [...]}`` of :func:`validate`.
        """
        from pydantic import BeforeValidator, ValidationInfo

        rng = self[name]

        def _check(value, info: ValidationInfo):
            accept = (info.context or {}).get("accept", ()) if info is not None else ()
            if shape is not None:
                if _is_number(value) or isinstance(value, str):
                    value = [value] * shape
                if not isinstance(value, (list, tuple, np.ndarray)) or len(value) != shape:
                    raise ValueError(f"{rng.label} must be {shape} numbers, got {value!r}")
            v = self.check(name, value, accept=accept)
            return tuple(float(x) for x in v) if shape is not None else float(v)

        if shape is None:
            return Annotated[float, BeforeValidator(_check)]
        return Annotated[tuple[(float,) * shape], BeforeValidator(_check)]


# ---------------------------------------------------------------------------------------------
# schemas
# ---------------------------------------------------------------------------------------------
def _input_model_base():
    from pydantic import BaseModel, ConfigDict

    class InputModel(BaseModel):
        """Base of every input schema: unknown keys forbidden, frozen, no coercion of bool to number."""

        model_config = ConfigDict(extra="forbid", frozen=True, strict=False, arbitrary_types_allowed=True,
                                  populate_by_name=True)

    return InputModel


InputModel = _input_model_base()


def closest(name: str, candidates: Iterable[str]) -> str:
    """``"; did you mean 'x'?"`` for the closest candidate, or ``""`` (difflib ratio >= 0.6)."""
    m = difflib.get_close_matches(str(name), [str(c) for c in candidates], n=1, cutoff=0.6)
    return f"; did you mean {m[0]!r}?" if m else ""


def check_choice(value, choices: Iterable[str], *, where: str) -> str:
    """``value`` if it is one of ``choices`` (exact), else an InputError with the closest one."""
    choices = list(choices)
    if value in choices:
        return value
    raise InputError(f"{where}: {value!r} is not one of {choices}{closest(value, choices)}")


def check_keywords(given: Iterable[str], accepted: Iterable[str], *, where: str) -> None:
    """Refuse unknown keyword names (UnknownOptionError naming them, with the closest accepted)."""
    accepted = list(accepted)
    for k in given:
        if k not in accepted:
            raise UnknownOptionError(f"{where}: unknown option {k!r}{closest(k, accepted)} "
                                     f"(accepted: {', '.join(accepted)})")


def checked_options(func):
    """Decorator: refuse unknown keyword arguments of ``func`` with :class:`UnknownOptionError`
    naming the closest accepted one (instead of Python's bare ``TypeError``).  A function that
    takes ``**kwargs`` is returned unchanged."""
    import inspect

    sig = inspect.signature(func)
    params = sig.parameters
    if any(p.kind is inspect.Parameter.VAR_KEYWORD for p in params.values()):
        return func
    names = [n for n, p in params.items() if p.kind in (inspect.Parameter.POSITIONAL_OR_KEYWORD,
                                                          inspect.Parameter.KEYWORD_ONLY) and n != "self"]
    qual = func.__qualname__.replace(".__init__", "")

    @functools.wraps(func)
    def wrapper(*args, **kwargs):
        if kwargs:
            unknown = [k for k in kwargs if k not in params]
            if unknown:
                check_keywords(unknown, names, where=f"{qual}()")
        return func(*args, **kwargs)

    return wrapper


def _fields_at(schema, loc) -> list[str]:
    """Field names of the (nested) model that holds ``loc[-1]``."""
    from pydantic import BaseModel
    import typing

    model = schema
    for part in loc[:-1]:
        if isinstance(part, int):
            continue
        if not (isinstance(model, type) and issubclass(model, BaseModel)) or part not in model.model_fields:
            return []
        ann = model.model_fields[part].annotation
        # unwrap Optional[...] / list[...] / tuple[...] to the model inside
        for _ in range(3):
            args = [a for a in typing.get_args(ann) if isinstance(a, type) and issubclass(a, BaseModel)]
            if isinstance(ann, type) and issubclass(ann, BaseModel):
                break
            if args:
                ann = args[0]
                break
            inner = [a for a in typing.get_args(ann) if typing.get_args(a)]
            if not inner:
                break
            ann = inner[0]
        model = ann
    if isinstance(model, type) and issubclass(model, BaseModel):
        return [f.alias or n for n, f in model.model_fields.items()]
    return []


def _where(source: str, loc) -> str:
    """``file [table] #2 key`` from a pydantic location."""
    parts = []
    for p in loc:
        if isinstance(p, int):
            parts.append(f"#{p + 1}")
        else:
            parts.append(str(p))
    if not parts:
        return source
    if len(parts) == 1:
        return f"{source} {parts[0]}".strip()
    return f"{source} [{'.'.join(parts[:-1])}] {parts[-1]}".strip().replace(".#", " #")


def validate(schema, data, *, source: str = "", context: dict | None = None, error=None):
    """Validate ``data`` (a dict from a file or from keyword arguments) against ``schema``.

    Parameters
    ----------
    schema : type of InputModel
    data : mapping
    source : str
        The file (or function) the data came from; every message starts with it.
    context : dict, optional
        ``{"accept": [...]}``: quantities whose plausible range is not enforced.
    error : type, optional
        Exception class for structural errors (default :class:`DataFileError` when ``source``
        looks like a file, else :class:`InputError`).

    Returns
    -------
    schema instance

    Raises
    ------
    ImplausibleValueError, UnitError, InputError
        One line: where (file, table, key), what, and the closest valid key for a misspelt one;
        further errors of the same input are counted at the end.
    """
    from pydantic import ValidationError

    if error is None:
        error = DataFileError if any(source.endswith(s) for s in (".toml", ".csv", ".osim", ".mot", ".sto",
                                                                    ".trc", ".json", ".txt")) else InputError
    try:
        return schema.model_validate(data, context=context or {})
    except ValidationError as exc:
        errs = exc.errors(include_url=False)
        # a misspelt key shows as an unknown key *and* a missing one: report the unknown key first
        errs.sort(key=lambda e: e["type"] != "extra_forbidden")
        first = errs[0]
        more = f" (and {len(errs) - 1} more error{'s' if len(errs) > 2 else ''})" if len(errs) > 1 else ""
        loc = tuple(first["loc"])
        where = _where(source, loc)
        typ = first["type"]
        cause = (first.get("ctx") or {}).get("error")
        if isinstance(cause, InputError):
            msg = str(cause)
            cls = type(cause)
            if isinstance(cause, ImplausibleValueError):
                new = ImplausibleValueError(f"{where}: {msg}{more}", cause.quantity, cause.value, cause.suggestion)
                raise new from None
            raise cls(f"{where}: {msg}{more}") from None
        if typ == "extra_forbidden":
            key = loc[-1]
            fields = _fields_at(schema, loc)
            hint = closest(key, fields) or (f"; valid keys: {', '.join(fields)}" if fields else "")
            missing = [str(e["loc"][-1]) for e in errs if e["type"] == "missing" and tuple(e["loc"][:-1]) == loc[:-1]]
            if missing and closest(key, missing):
                hint = closest(key, missing)
                more = f" (and {len(errs) - 2} more error{'s' if len(errs) > 3 else ''})" if len(errs) > 2 else ""
            raise error(f"{where}: unknown key{hint}{more}") from None
        if typ == "missing":
            raise error(f"{where}: missing key{more}") from None
        if isinstance(cause, ValueError):
            raise error(f"{where}: {cause}{more}") from None
        raise error(f"{where}: {first['msg']} (got {first.get('input')!r}){more}") from None
