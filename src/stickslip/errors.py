"""Typed exceptions of the public API.

Every error a user can provoke with bad input is a :class:`StickslipError`;
the command line turns it into a one-line message and exit status 2.
"""

from __future__ import annotations


class StickslipError(Exception):
    """Base class of every error raised on purpose by stickslip."""


class ParameterError(StickslipError, ValueError):
    """A parameter (or a parameter file) is unknown, malformed or out of range."""


class UnitError(ParameterError):
    """A value carries a unit of the wrong dimension, or an unknown unit."""


class DataError(StickslipError, ValueError):
    """A data file (CSV of measurements or traces) cannot be used."""


class ModelError(StickslipError, ArithmeticError):
    """The model has no finite answer for these inputs (e.g. a divergent integral)."""


class RunFailed(ModelError):
    """A run started and could not go on (e.g. its state went non-finite): a failed run (exit 3), not bad input.

    ``partial`` is what the solver computed up to there (a result whose status is "failed" and whose message says
    where it stopped), or None where the solver cannot give it."""

    def __init__(self, message: str, partial: object = None) -> None:
        super().__init__(message)
        self.partial = partial

    def __reduce__(self) -> tuple[object, ...]:  # pickled (a sweep's worker) with what it computed
        return (type(self), (str(self), self.partial))


def as_written(message: str, written: str) -> str:
    """A refusal that ends ", got <SI value>" ending instead with the value as the user wrote it ("got '-5 mm'",
    not "got -0.005"); other messages unchanged."""
    if ", got " not in message:
        return message
    return f"{message.rsplit(', got ', 1)[0]}, got {written.strip()!r}"
