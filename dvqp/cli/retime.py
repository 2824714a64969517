"""``dvqp plan --retime [--rate HZ]``: the planned path retimed, summed up and saved."""

from __future__ import annotations

import sys
from pathlib import Path

from dvqp import _validate
from dvqp.errors import ParameterError, one_line
from dvqp.motion.trajectory import Trajectory
from dvqp.retime import DEFAULT_RATE, FORMATS
from dvqp.retime.parameterise import toppra
from dvqp.scenes import Scene

__all__ = ["FORMATS", "checked_rate", "retimed"]


def checked_rate(retime: bool, rate: float | None) -> float | None:
    """The controller rate, Hz, of ``--retime`` (None: no retiming), checked before the run,
    as is toppra's presence.

    Raises
    ------
    ParameterError
        ``--rate`` not > 0, or given without ``--retime``.
    RetimingError
        toppra is not installed.
    """
    if not retime:
        if rate is not None:
            raise ParameterError("--rate", "is the rate of --retime: give --retime too")
        return None
    rate = _validate.positive("--rate", DEFAULT_RATE if rate is None else rate)
    toppra()
    return rate


def retimed(scene: Scene, traj: Trajectory, rate: float, output: Path | None) -> int:
    """Retime a run that is safe to send, print ``retimed  2.31 s (planned 4.00 s), 1156
    samples at 500 Hz, limits kept`` (and ``saved  FILE``), save it to ``output``; a warning
    line on stderr if the samples miss most of the path (:attr:`Retimed.drops_path`: too low
    a rate). The exit code: 1 if a retimed sample breaks a limit (the file is still written,
    to look at)."""
    motion = traj.retimed(scene, rate)
    if output is not None:
        motion.save(output)
    print(f"retimed         {motion.summary()}")
    if output is not None:
        print(f"saved           {output}")
    if motion.drops_path:
        print(
            f"dvqp: warning: {one_line(scene.source)}: retimed at {rate:g} Hz, its "
            f"{motion.t.shape[0]} samples trace {motion.path_share:.0%} of the planned path "
            "(a controller going straight from one to the next leaves it): use a higher --rate",
            file=sys.stderr,
        )
    if not motion.kept:
        print(f"dvqp: {one_line(scene.source)}: retimed: {motion.summary()}", file=sys.stderr)
        return 1
    return 0
