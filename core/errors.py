"""Error types of mbsuite: one base for every bad-input error, and the numerical failures of a run.

Two kinds of trouble end a computation, and they are kept apart:

*Bad input* (a model, a parameter, a file or a name that cannot be used) raises an exception
derived from :class:`MbsuiteError`; the message names the element, value or file at fault.
``except MbsuiteError`` catches every such error of building a model or reading its data.
The input errors also derive from the matching built-in type (``ValueError``, ``TypeError``),
so code written against the built-in types keeps working.

*Numerical failure* during a run (a singular matrix, non-finite values, an iteration that does
not converge) is not an exception to the caller: the integrator ends the run with status
``"failed"``, the time and the cause (:mod:`core.simulation`).  Inside a step such failures are
raised as :class:`NumericalFailure` (or arrive as one of :data:`RUN_FAILURES` from numpy and
scipy, or as a :class:`DataRangeError` when a run goes past the end of a measured input); every
other exception, e.g. a programming error in a user's force element, is *not* a run failure and
propagates with its traceback.

================================= ============================= =================================================
class                             also a                        raised when
================================= ============================= =================================================
:class:`MbsuiteError`             ``Exception``                 base class, never raised itself
:class:`InputError`               ``ValueError``                a value, option or argument cannot be used
:class:`UnknownOptionError`       ``ValueError``, ``TypeError`` an option that is not accepted (lists them)
:class:`ModelError`               ``ValueError``                a model definition is invalid (names the element)
:class:`RedundantConstraintError` ``ValueError``                dependent constraint equations (lists them)
:class:`AssemblyError`            ``ValueError``                the configuration cannot be assembled
:class:`DataFileError`            ``ValueError``                a data file is missing or malformed (names it)
:class:`DataRangeError`           ``ValueError``                tabulated input evaluated outside its range
:class:`UnknownNameError`         ``ValueError``                a registry has no entry of that name
:class:`NameTakenError`           ``ValueError``                a registry name is taken by another object
:class:`NotCompilable`            ``TypeError``                 a model has an element without a compiled kernel
:class:`NumericalFailure`         ``ArithmeticError``           inside a step: the step cannot be completed
================================= ============================= =================================================
"""

from __future__ import annotations

import numpy as np

__all__ = [
    "MbsuiteError",
    "InputError",
    "UnknownOptionError",
    "ModelError",
    "RedundantConstraintError",
    "AssemblyError",
    "DataFileError",
    "DataRangeError",
    "UnknownNameError",
    "NameTakenError",
    "NotCompilable",
    "NumericalFailure",
    "RUN_FAILURES",
]


class MbsuiteError(Exception):
    """Base class of every error mbsuite raises on bad input (``except MbsuiteError`` catches them all)."""


class InputError(MbsuiteError, ValueError):
    """A value, option or argument cannot be used; the message names it."""


class UnknownOptionError(InputError, TypeError):
    """An option a function or method does not accept (a ``TypeError`` too, like an unexpected
    keyword argument); the message lists the accepted ones."""


class ModelError(InputError):
    """Invalid model definition; the message names the element at fault."""


class RedundantConstraintError(ModelError):
    """Dependent constraint equations; ``dependent`` lists their names."""

    def __init__(self, message: str, dependent: list[str]):
        super().__init__(message)
        self.dependent = dependent


class AssemblyError(ModelError):
    """The configuration cannot be assembled (Newton on Φ = 0 did not converge)."""


class DataFileError(InputError):
    """A data file is missing, truncated or malformed; the message names the file (and line or column)."""


class DataRangeError(InputError):
    """Tabulated input (a measured motion, a force table) evaluated outside its range.  Raised
    during a run it ends the run as failed, with the time and the table named."""


class UnknownNameError(InputError):
    """A registry (integrators, scenes, problems, creep laws, ...) has no entry of that name."""


class NameTakenError(InputError):
    """A different object is already registered under that name."""


class NotCompilable(MbsuiteError, TypeError):
    """The model contains an element without a compiled kernel (the message names it)."""


class NumericalFailure(MbsuiteError, ArithmeticError):
    """A step cannot be completed for a numerical reason (singular matrix, non-finite values,
    no convergence).  Integrators turn it into status ``"failed"`` with the time and this message."""


#: Exceptions that end a run as failed (status ``"failed"``, what was computed is kept):
#: numerical failures (``LinAlgError`` from numpy/scipy factorisations, the arithmetic errors from
#: ``np.errstate(..., 'raise')`` regions and float arithmetic) and a tabulated input evaluated
#: past its range.  Anything else propagates.
RUN_FAILURES: tuple[type[BaseException], ...] = (
    NumericalFailure,
    DataRangeError,
    np.linalg.LinAlgError,
    FloatingPointError,
    OverflowError,
    ZeroDivisionError,
)
