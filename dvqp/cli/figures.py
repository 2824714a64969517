"""What every figure of the command line shares: a pyplot-free figure and atomic saving.

matplotlib is imported only when :func:`new_figure` is called (``pip install 'dvqp[plot]'``).
The figure is drawn on a :class:`matplotlib.figure.Figure` with the Agg canvas, never through
``pyplot``: no display and no backend setting are needed. Files are written atomically: a
temporary file in the same folder, renamed once complete.
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
    """A constrained-layout figure on the Agg canvas (no pyplot, no display).

    Parameters
    ----------
    size
        ``(width, height)``, inches.

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
    """Call ``write(tmp)`` on a temporary file beside ``target``, then rename it to ``target``.

    On any error the temporary file is removed and an existing ``target`` is left as it was.

    Returns
    -------
    Path
        ``target``.
    """
    with atomic_file(target) as tmp:
        write(str(tmp))
    return target


def save_figure(fig: Figure, target: Path, dpi: int) -> Path:
    """Save ``fig`` atomically in the format of ``target``'s suffix (one of FIGURE_FORMATS).

    Parameters
    ----------
    fig
        The figure.
    target
        Output file, already checked (``dvqp._files.output_path``).
    dpi
        Resolution of raster formats, dots per inch.

    Returns
    -------
    Path
        ``target``.
    """
    fmt = target.suffix.lower()[1:]
    return write_atomic(target, lambda tmp: fig.savefig(tmp, format=fmt, dpi=dpi))
