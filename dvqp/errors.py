"""The exception hierarchy of dvqp.

Every error a library call raises on bad input or an impossible request derives from
:class:`DvqpError`, carries the offending data as attributes, and has a one-line message
that names what was wrong. The command line turns these into ``dvqp: <message>`` and exit
code 2 without a traceback.
"""

from __future__ import annotations

from collections.abc import Sequence


def one_line(text: str) -> str:
    """``text`` with line breaks and other unprintable characters escaped (``\\n``).

    Messages quote what the user wrote (keys, file names, parser output): this keeps each on
    one line.
    """
    return "".join(c if c.isprintable() else repr(c)[1:-1] for c in str(text))


class DvqpError(Exception):
    """Base class of every error raised by dvqp."""


class ShapeError(DvqpError, ValueError):
    """An array has the wrong shape.

    Parameters
    ----------
    name
        Name of the argument or field.
    expected
        Expected shape; ``-1`` stands for "any length".
    actual
        Shape that was given.
    """

    def __init__(self, name: str, expected: Sequence[int], actual: Sequence[int]) -> None:
        self.name = name
        self.expected = tuple(expected)
        self.actual = tuple(actual)
        exp = "(" + ", ".join("n" if e < 0 else str(e) for e in self.expected)
        exp += ",)" if len(self.expected) == 1 else ")"
        super().__init__(f"{name}: expected shape {exp}, got {self.actual}")


class ParameterError(DvqpError, ValueError):
    """A parameter has an invalid value (negative radius, dt <= 0, NaN, ...).

    Parameters
    ----------
    name
        Name of the parameter or field.
    reason
        What is wrong with it, e.g. ``"must be > 0"``.
    """

    def __init__(self, name: str, reason: str) -> None:
        self.name = name
        self.reason = reason
        super().__init__(f"{name}: {reason}")


class SingularConfigurationError(DvqpError, ArithmeticError):
    """The developed view or the task Jacobian is singular at this configuration.

    Parameters
    ----------
    what
        Which quantity is singular (``"tool: rho = 0"``, ``"task Jacobian"``...).
    q
        The joint configuration, rad, shape (n,), if known.
    """

    def __init__(self, what: str, q: object = None) -> None:
        self.what = what
        self.q = q
        super().__init__(f"singular configuration: {what}")


class UnreachableTargetError(DvqpError):
    """A commanded motion cannot be executed (task error beyond the allowed bound)."""

    def __init__(self, message: str, step: int | None = None, error: float | None = None) -> None:
        self.step = step
        self.error = error
        super().__init__(message)


class BackendError(DvqpError):
    """A QP backend is unknown, not installed, or failed in a way that ends the run.

    The underlying :mod:`solvers` error, if any, is chained as ``__cause__``.
    """


class SceneError(DvqpError, ValueError):
    """A scene file is malformed; the message is ``<file>: <field>: <reason>``.

    Parameters
    ----------
    path
        The scene file (or ``"<string>"``).
    field
        Dotted path of the field, e.g. ``"obstacles[1].radius"``.
    reason
        What is wrong.
    """

    def __init__(self, path: str, field: str, reason: str) -> None:
        self.path = path
        self.field = field
        self.reason = reason
        where = f"{one_line(field)}: " if field else ""
        super().__init__(f"{one_line(path)}: {where}{one_line(reason)}")


class OutputError(DvqpError, OSError):
    """An output file could not be written (a directory in the way, a full disk, ...).

    Nothing is left behind: the file is written to a temporary name and renamed only when
    complete. Also an :class:`OSError`, so code that catches those still does.

    Parameters
    ----------
    path
        The file that was to be written.
    reason
        Why it could not be, e.g. ``"No space left on device"``.
    errno
        The operating system's error number, if there was one.
    """

    def __init__(self, path: object, reason: str, errno: int | None = None) -> None:
        self.path = str(path)
        self.reason = reason
        super().__init__(f"output: {one_line(self.path)}: cannot write: {one_line(reason)}")
        self.errno = errno

    def __reduce__(self) -> tuple[type[OutputError], tuple[str, str, int | None]]:
        return (OutputError, (self.path, self.reason, self.errno))

    def __str__(self) -> str:  # OSError's own __str__ would show its errno fields
        return str(self.args[0])


class LimitViolationError(DvqpError):
    """A planned motion breaks a limit (the baseline holds none; a QP run that could not keep
    one fails its step instead).

    Parameters
    ----------
    message
        One line naming the limit, the part and the amount.
    sample
        Index of the worst sample.
    excess
        How far past the limit, in its unit (m or rad).
    """

    def __init__(self, message: str, sample: int, excess: float) -> None:
        self.sample = sample
        self.excess = excess
        super().__init__(message)
