"""The compiled step: a run's parts laid out on one set of buffers and run stage by stage.

:class:`Stepper` is a resolver's step for one arm and pipe; :func:`advance` is one verified
step of a run (split into substeps where a limit would break).
"""

from dvqp.step.advance import JOINT_STRIDE, MAX_HALVINGS, Advance, advance, straight_excess
from dvqp.step.engine import Stepper

__all__ = ["JOINT_STRIDE", "MAX_HALVINGS", "Advance", "Stepper", "advance", "straight_excess"]
