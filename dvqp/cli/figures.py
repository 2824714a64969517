"""What every figure of the command line shares: a pyplot-free figure and atomic saving.

matplotlib is imported only when :func:`new_figure` is called (``pip install 'dvqp[plot]'``).
Figures are drawn on the Agg canvas, never through ``pyplot``: no display and no backend
setting are needed.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING

from dvqp._files import atomic_file
from dvqp.errors import DvqpError

if TYPE_CHECKING:
    from matplotlib.figure import Figure

FIGURE_FORMATS = (".png", ".svg", ".pdf")
"""Suffixes a still figure is written as (animations are ``.gif``)."""


def new_figure(size: tuple[float, float]) -> Figure:
    """A constrained-layout figure of ``size`` (width, height; inches) on the Agg canvas.

    Raises
    ------
    DvqpError
        matplotlib is not installed.
    """
    try:
        from matplotlib.backends.backend_agg import FigureCanvasAgg
        from matplotlib.figure import Figure
    except ImportError as exc:
        raise DvqpError("plotting needs matplotlib: pip install 'dvqp[plot]'") from exc
    fig = Figure(figsize=size, layout="constrained")
    FigureCanvasAgg(fig)
    return fig


def write_atomic(target: Path, write: Callable[[str], None]) -> Path:
    """Call ``write(tmp)`` on a temporary file beside ``target``, then rename it to ``target``
    (returned); on any error ``tmp`` is removed and an existing ``target`` left as it was."""
    with atomic_file(target) as tmp:
        write(str(tmp))
    return target


def save_figure(fig: Figure, target: Path, dpi: int) -> Path:
    """Save ``fig`` atomically to ``target`` (returned; already checked, a suffix of
    :data:`FIGURE_FORMATS`), raster formats at ``dpi`` dots per inch."""
    fmt = target.suffix.lower()[1:]
    return write_atomic(target, lambda tmp: fig.savefig(tmp, format=fmt, dpi=dpi))
