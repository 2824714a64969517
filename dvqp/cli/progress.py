"""A one-line progress bar for long runs, drawn only on a terminal."""

from __future__ import annotations

from typing import TextIO


class ProgressBar:
    """A one-line progress bar on a terminal (silent when the stream is not a TTY).

    Parameters
    ----------
    stream
        Where to draw, usually ``sys.stderr``.
    width
        Characters of the bar itself.
    """

    def __init__(self, stream: TextIO, width: int = 30) -> None:
        self.stream, self.width = stream, width
        self.enabled = bool(getattr(stream, "isatty", lambda: False)())
        self._last = -1

    def show(self, done: int, total: int, label: str = "") -> None:
        """Draw ``done`` of ``total`` with a label (redrawn at most every 1 %)."""
        if not self.enabled or total <= 0:
            return
        percent = 100 * done // total
        if percent == self._last and done != total:
            return
        self._last = percent
        filled = self.width * done // total
        bar = "#" * filled + "." * (self.width - filled)
        self.stream.write(f"\r[{bar}] {done}/{total} {label[:40]:<40}")
        self.stream.flush()

    def close(self) -> None:
        """Erase the bar (if one was drawn)."""
        if self.enabled and self._last >= 0:
            self.stream.write("\r" + " " * (self.width + 60) + "\r")
            self.stream.flush()
