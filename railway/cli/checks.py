"""Checks of the ``mbsuite railway`` options: plausible ranges in the option's unit, profile
files, ``--accept``.

A number given on the command line is checked against ``data/railway/plausible_ranges.csv``
(:func:`railway.ranges.ranges`) in the unit the option's name carries (``--load-kN``: kN); a
value outside its range is refused in one line naming the option, the value, the range and the
likely unit slip, e.g. ::

    --load-kN 100000: the wheel-rail normal load must lie in 0.5 ... 500 kN: did you mean
    100000 N, i.e. --load-kN 100? (to use it deliberately: --accept wheel_normal_load)

``--accept QUANTITY`` (repeatable) lets a deliberate outlier through.
"""

from __future__ import annotations

from pathlib import Path

from core.errors import InputError
from core.inputs import closest

from ..ranges import ranges

__all__ = ["add_accept_option", "check_file_option", "option"]


def option(quantity, value, name, unit=None, accept=()):
    """``value`` of option ``name`` (in ``unit``) checked against the range of ``quantity``; SI."""
    from core.cli import check_option
    from core.inputs import ImplausibleValueError

    try:
        return check_option(ranges(), quantity, value, name, unit, accept)
    except ImplausibleValueError as exc:
        if quantity == "nominal_wheel_radius" and not exc.suggestion and ranges()[quantity].contains(exc.value / 2):
            # a wheel is named by its diameter (920 mm): the likeliest slip of all
            text = str(exc).replace(" (to use it deliberately",
                                    f": is {value:g} the wheel diameter? {name} takes the radius, "
                                    f"{name} {value / 2:g} (to use it deliberately", 1)
            raise ImplausibleValueError(text, exc.quantity, exc.value, "diameter") from None
        raise


def _accept_name(text: str) -> str:
    names = [r.quantity for r in ranges()]
    if text not in names:
        import argparse

        raise argparse.ArgumentTypeError(f"{text!r} is not a quantity of the plausible-range table"
                                         f"{closest(text, names)} (see data/railway/plausible_ranges.csv)")
    return text


def add_accept_option(parser) -> None:
    """Add ``--accept QUANTITY`` (repeatable): quantities whose plausible range is not enforced."""
    parser.add_argument("--accept", action="append", type=_accept_name, default=None, metavar="QUANTITY",
                        help="do not enforce the plausible range of QUANTITY (a deliberate outlier; "
                             "names as in the error message, e.g. wheel_normal_load); repeatable")


def check_file_option(name: str, spec: str, builtin=()) -> Path:
    """A profile file given to option ``name``: it must exist, be a file and be readable text.

    ``builtin`` lists the built-in profile names, suggested for a near miss (``S1O02``).
    """
    path = Path(spec)
    hint = closest(spec.upper(), builtin)
    if not path.exists():
        what = f" and not a built-in profile ({', '.join(builtin)})" if builtin else ""
        raise InputError(f"{name} {spec!r}: no such file{what}{hint}")
    if path.is_dir():
        raise InputError(f"{name} {spec!r}: is a folder, not a profile file")
    try:
        raw = path.read_bytes()
    except OSError as exc:
        raise InputError(f"{name} {spec!r}: cannot be read ({exc.strerror or exc})") from None
    try:
        raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise InputError(f"{name} {spec!r}: not a text profile file (byte {raw[exc.start]:#04x} at "
                         f"offset {exc.start} is not UTF-8; expected two columns, lateral and vertical "
                         "in mm)") from None
    if not raw.strip():
        raise InputError(f"{name} {spec!r}: the file is empty (expected two columns, lateral and "
                         "vertical in mm)")
    return path
