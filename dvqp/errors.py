"""The exception hierarchy of dvqp.

Every error a library call raises on bad input or an impossible request derives from
:class:`DvqpError`, carries the offending data as attributes, and has a one-line message
that names what was wrong. The command line turns these into ``dvqp: <message>`` and exit
code 2 without a traceback.
"""

from __future__ import annotations

from collections.abc import Sequence


def one_line(text: str) -> str:
    """``text`` with line breaks and other unprintable characters escaped (``\\n``), so that a
    message quoting what the user wrote stays on one line."""
    return "".join(c if c.isprintable() else repr(c)[1:-1] for c in str(text))


class DvqpError(Exception):
    """Base class of every error raised by dvqp."""


class ShapeError(DvqpError, ValueError):
    """An array (argument or field ``name``) has the ``actual`` shape, not the ``expected``
    one (``-1`` in it: any length)."""

    def __init__(self, name: str, expected: Sequence[int], actual: Sequence[int]) -> None:
        self.name = name
        self.expected = tuple(expected)
        self.actual = tuple(actual)
        exp = "(" + ", ".join("n" if e < 0 else str(e) for e in self.expected)
        exp += ",)" if len(self.expected) == 1 else ")"
        super().__init__(f"{name}: expected shape {exp}, got {self.actual}")


class ParameterError(DvqpError, ValueError):
    """A parameter or field ``name`` has an invalid value (negative radius, dt <= 0, NaN...);
    ``reason`` says what is wrong, e.g. ``"must be > 0"``."""

    def __init__(self, name: str, reason: str) -> None:
        self.name = name
        self.reason = reason
        super().__init__(f"{name}: {reason}")


class TaskLevelError(ParameterError):
    """A level of hard tasks cannot be met even alone, whatever the limits: ``level`` (1 the
    highest priority's), its tasks' labels ``tasks`` and ``why`` (more rows than joints, or
    rows dependent at the start). Its ``name`` is ``"tasks"``."""

    def __init__(self, level: int, tasks: str, why: str) -> None:
        self.level, self.tasks, self.why = level, tasks, why
        super().__init__("tasks", f"level {level} ({tasks}) cannot be met even alone: {why}")


class SingularConfigurationError(DvqpError, ArithmeticError):
    """The developed view or the task Jacobian is singular at this configuration.

    ``what`` is singular (``"tool: rho = 0"``, ``"task Jacobian"``...) at the joint
    configuration ``q`` (rad, shape (n,), or None if unknown).
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
    """A scene file is malformed: ``<path>: <field>: <reason>``, ``path`` the file (or
    ``"<string>"``), ``field`` the dotted path of the field (``"obstacles[1].radius"``)."""

    def __init__(self, path: str, field: str, reason: str) -> None:
        self.path = path
        self.field = field
        self.reason = reason
        where = f"{one_line(field)}: " if field else ""
        super().__init__(f"{one_line(path)}: {where}{one_line(reason)}")


class RobotFileError(DvqpError, ValueError):
    """A robot (URDF) file is refused: ``<path>: <reason>``, ``reason`` what is wrong with it
    (``joint 'cyc': link 'link2' already has parent joint 'joint2'``) or why the URDF parser
    could not load it."""

    def __init__(self, path: str, reason: str) -> None:
        self.path = path
        self.reason = reason
        super().__init__(f"{one_line(path)}: {one_line(reason)}")


class InputFileError(DvqpError, ValueError):
    """A file given to read (a trajectory, an export's index) is refused: ``<path>: <reason>``,
    ``reason`` why (``cannot read: No such file or directory``, ``not a dvqp trajectory (…)``,
    ``member 'q': declares 2.1 GB, more than …``). Nothing of a refused file is kept, and no
    more of it is read or inflated than its declared sizes allow."""

    def __init__(self, path: object, reason: str) -> None:
        self.path = str(path)
        self.reason = reason
        super().__init__(f"{one_line(self.path)}: {one_line(reason)}")


class OutputError(DvqpError, OSError):
    """The output file ``path`` could not be written: ``reason`` (``"No space left on
    device"``), with the operating system's ``errno`` if there was one.

    Nothing is left behind: the file is written to a temporary name and renamed only when
    complete. Also an :class:`OSError`, so code that catches those still does.
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
    one fails its step instead): ``message`` names the limit, the part and the amount,
    ``sample`` is the worst sample's index, ``excess`` how far past the limit (m or rad)."""

    def __init__(self, message: str, sample: int, excess: float) -> None:
        self.sample = sample
        self.excess = excess
        super().__init__(message)


class RetimingError(DvqpError, ValueError):
    """A planned path cannot be retimed: it does not move, no parameterisation keeps the joint
    velocity and acceleration limits, or the library that does it (toppra) is missing."""
