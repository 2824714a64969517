"""The names of an arm's guarded parts in labels and reports.

The guarded points are the k body points, the probe (the tool point) and, if the arm has one,
its lead point: the rail point, or the base of an arm that stands on the pipe; the guarded
links are the k−1 body links, the probe holder (last body point to the tool) and the lead
link (the carriage link from the rail point, or the base link, to body point 1), as
:func:`~dvqp.workspace.link_ends` lays them out. dvqp's own arms number them (``point3``,
``probe``, ``link2``, ``holder``, ``carriage``: :meth:`PartNames.numbered`); an arm read from a
URDF file names them by its frames (:meth:`PartNames.of_frames`: ``panda_link4``, a link
``panda_link4-panda_link6`` from one guarded frame to the next).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from itertools import pairwise

from dvqp.errors import ParameterError

LINK_JOIN = "-"
"""Between the names of a link's two ends in the link's name (``"panda_link4-panda_link6"``)."""


@dataclass(frozen=True)
class PartNames:
    """The names of the guarded points and links of an arm with k body points.

    Attributes
    ----------
    points : tuple of str
        k + 1 or k + 2 names: the body points, the probe (tool), the rail point (if any).
    links : tuple of str
        k or k + 1 names: the body links, the probe holder, the carriage link (if a rail).
    rail : bool
        Whether the arm has a lead point (the last point: a rail point, or its base) and a
        lead link from it to the first body point (the last link).
    base : bool
        Whether that lead point is the arm's base, fixed on the pipe, rather than a rail point
        (its link keeps the surface, not ``min_height``).
    """

    points: tuple[str, ...]
    links: tuple[str, ...]
    rail: bool = False
    base: bool = False

    def __post_init__(self) -> None:
        if len(self.points) < 3 + self.rail or len(self.links) != len(self.points) - 1:
            raise ParameterError("names", "k + 1 points (k >= 2; + 1 with a rail), one link fewer")
        if self.base and not self.rail:
            raise ParameterError("names", "a base is a lead point: rail must be True with base")

    @classmethod
    def numbered(cls, k: int, rail: bool = False) -> PartNames:
        """dvqp's numbering: ``point1`` … ``pointk``, ``probe`` (and ``rail``); ``link1`` …
        ``link(k−1)``, ``holder`` (and ``carriage``)."""
        points = (*(f"point{i + 1}" for i in range(k)), "probe", *(("rail",) if rail else ()))
        links = (*(f"link{i + 1}" for i in range(k - 1)), "holder", *(("carriage",) * rail))
        return cls(points, links, rail)

    @classmethod
    def of_frames(
        cls, points: Sequence[str], tool: str, rail: str | None = None, base: bool = False
    ) -> PartNames:
        """The frames' own names: each guarded point is its frame's name, each link the names
        of its two ends, ``"<from>-<to>"``, base to tip (the lead link ``"<rail>-<first body
        point>"``; ``rail`` the lead frame, the arm's base if ``base``)."""
        names = (*points, tool, *(() if rail is None else (rail,)))
        chain = (*points, tool)
        links = [f"{a}{LINK_JOIN}{b}" for a, b in pairwise(chain)]
        if rail is not None:
            links.append(f"{rail}{LINK_JOIN}{points[0]}")
        return cls(tuple(names), tuple(links), rail is not None, base and rail is not None)

    @property
    def k(self) -> int:
        """Number of body points."""
        return len(self.points) - 1 - self.rail

    @property
    def probe(self) -> str:
        """The tool point's name."""
        return self.points[self.k]

    @property
    def holder(self) -> str:
        """The probe holder's name."""
        return self.links[self.k - 1]

    @property
    def base_link(self) -> int:
        """The index of a standing arm's base link (its lead link, k), which keeps the surface,
        not ``min_height``; −1 for an arm without such a base."""
        return self.k if self.base else -1

    @property
    def lead(self) -> str:
        """The lead point's name (the rail point or the base; "" if none)."""
        return self.points[self.k + 1] if self.rail else ""

    def point(self, i: int) -> str:
        """Guarded point i (0-based): a body point (i < k), the probe (i = k), the lead point."""
        return self.points[i]

    def link(self, i: int) -> str:
        """Guarded link i (0-based): a body link (i < k − 1), the holder, the carriage link."""
        return self.links[i]
