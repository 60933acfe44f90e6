"""``mbsuite railway ...`` sub-commands.

Registered through the entry point ``mbsuite.commands: railway = "railway.cli:register"``.
One module per sub-command, each with an ``add_<name>_parser(subparsers)`` function listed in
``_SUBCOMMANDS``; adding a command means writing one such module and appending its function:

* :mod:`railway.cli.contact_table` -- ``contact-table``: rigid contact-geometry table,
  equivalent conicity and flange-contact onset of a wheel and rail profile pair;
* :mod:`railway.cli.creep_curve` -- ``creep-curve``: creep force curves of any creep law;
* :mod:`railway.cli.checks` -- the checks every option passes (plausible ranges in the option's
  unit, profile files, ``--accept``).

The command line is an edge over both halves of the package (:mod:`railway.contact`,
:mod:`railway.vehicles`), so it is a sub-package of its own beside them.
"""

from __future__ import annotations

import sys

from .checks import add_accept_option, check_file_option, option
from .contact_table import (
    POINTS_PER_AMPLITUDE,
    ConicityResolutionWarning,
    add_contact_table_parser,
    run_contact_table,
)
from .creep_curve import ElasticConstantsWarning, add_creep_curve_parser, run_creep_curve

__all__ = [
    "POINTS_PER_AMPLITUDE",
    "ConicityResolutionWarning",
    "ElasticConstantsWarning",
    "add_accept_option",
    "add_contact_table_parser",
    "add_creep_curve_parser",
    "check_file_option",
    "main",
    "option",
    "register",
    "run_contact_table",
    "run_creep_curve",
]

_SUBCOMMANDS = [add_contact_table_parser, add_creep_curve_parser]


def register(subparsers):
    """Add the ``railway`` sub-parser with its sub-commands (entry point ``mbsuite.commands``)."""
    p = subparsers.add_parser("railway", help="wheel-rail geometry, contact and creep tools",
                              description="Railway tools.")
    sub = p.add_subparsers(dest="railway_command", metavar="COMMAND")
    sub.required = True
    for add in _SUBCOMMANDS:
        add(sub)
    return p


def main(argv=None) -> int:
    """Stand-alone entry: ``python -m railway.cli contact-table ...`` (the same as ``mbsuite
    railway contact-table ...``: one-line errors, exit 2 on bad input)."""
    from core.cli import main as core_main

    return core_main(["railway"] + list(sys.argv[1:] if argv is None else argv))
