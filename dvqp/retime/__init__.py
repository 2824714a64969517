"""Retiming: a planned path, as fast as the joints' velocity and acceleration limits allow,
sampled at a controller's rate, verified exactly, exported for a controller.

:func:`retime` (or :meth:`dvqp.Trajectory.retimed`) gives a :class:`Retimed`; the
parameterisation is toppra's (``pip install 'dvqp[retime]'``).
"""

from dvqp.retime.retimed import DEFAULT_RATE, FORMATS, Retimed, RunScene, retime

__all__ = ["DEFAULT_RATE", "FORMATS", "Retimed", "RunScene", "retime"]
