"""URDF files checked before Pinocchio's parser sees them.

Pinocchio's URDF parser trusts its input: a link with two parent joints sends it round a cycle
until the process dies (a segmentation fault), and nothing bounds a file's size or its number
of joints. :func:`read_urdf` reads a file once, at most :data:`MAX_BYTES`, parses it with
``defusedxml`` (no DTD, hence no entity expansion and no external entity) and checks what the
parser and dvqp rely on; only the text it accepted is handed to Pinocchio. The rules are listed
in ``docs/scenes.md``.
"""

from __future__ import annotations

import io
import math
import re
from dataclasses import dataclass
from pathlib import Path
from xml.etree.ElementTree import Element, ParseError

from defusedxml import DefusedXmlException
from defusedxml.ElementTree import iterparse

from dvqp._inputs import read_bounded
from dvqp.errors import InputFileError, RobotFileError

MAX_BYTES = 1 << 20
"""Largest URDF file read, bytes (1 MiB; the bundled 13-joint arm takes 6 kB)."""
MAX_DEPTH = 16
"""Deepest element nesting (a URDF needs 5: robot, link, visual, geometry, mesh)."""
MAX_LINKS = 256
MAX_ACTUATED = 64
"""At most this many links, and this many revolute, continuous and prismatic joints."""
MAX_NAME = 200
"""Longest name of the robot, a link or a joint, characters."""
MAX_OFFSET = 1e3
"""Largest coordinate of an ``origin``, m (farther, the kinematics could overflow)."""
ACTUATED = ("revolute", "continuous", "prismatic")
JOINT_TYPES = (*ACTUATED, "fixed")
"""The joint types dvqp accepts (``floating`` and ``planar`` are refused)."""
NUMBERS = {
    "origin": {"xyz": 3, "rpy": 3},
    "axis": {"xyz": 3},
    "limit": {"lower": 1, "upper": 1, "effort": 1, "velocity": 1},
    "mimic": {"multiplier": 1, "offset": 1},
    "mass": {"value": 1},
    "inertia": {k: 1 for k in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")},
}
"""Numeric attributes checked in every link and joint: element -> attribute -> count."""
REQUIRED = {"limit": ("effort", "velocity"), "mass": ("value",), "inertia": (*NUMBERS["inertia"],)}
"""Of these, the attributes the URDF parser requires."""
_NUMBER = re.compile(r"[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?")
"""A decimal number as the URDF parser reads one (no ``nan``, ``inf``, ``_`` or hex)."""


class _Refused(Exception):
    """Why a file is refused (becomes a :class:`~dvqp.errors.RobotFileError`)."""


@dataclass(frozen=True)
class Mimic:
    """A joint that follows another: its coordinate is ``multiplier · q + offset``, ``q`` the
    coordinate of ``master``; its own limits (``lower``, ``upper`` and ``velocity``)."""

    joint: str
    master: str
    multiplier: float
    offset: float
    lower: float
    upper: float
    velocity: float


@dataclass(frozen=True)
class UrdfText:
    """A URDF file that passed the checks: its ``path``, its ``text`` (to hand to the parser,
    not read again), its number of ``actuated`` joints (the model's nq: the revolute,
    continuous and prismatic joints that mimic none) and its ``mimics``."""

    path: str
    text: str
    actuated: int
    mimics: tuple[Mimic, ...] = ()


def read_urdf(path: str | Path) -> UrdfText:
    """Read and check the URDF file ``path``.

    Raises
    ------
    RobotFileError
        ``<path>: <reason>``: unreadable, too large, not well-formed XML, a DTD, not one tree of
        links, too many links or joints, a joint type dvqp does not take, a bad name or number.
    """
    try:
        data = _read(Path(path))
        try:
            text = data.decode("utf-8")
        except UnicodeDecodeError as exc:
            raise _Refused(f"not UTF-8 text (byte {exc.start})") from None
        return UrdfText(str(path), text, *_check(_parse(data)))
    except _Refused as exc:
        raise RobotFileError(str(path), str(exc)) from None


def _read(path: Path) -> bytes:
    """At most :data:`MAX_BYTES` of the file; refused if it is larger."""
    try:
        return read_bounded(path, MAX_BYTES, "a robot description")
    except InputFileError as exc:
        raise _Refused(exc.reason) from None


def _parse(data: bytes) -> Element:
    """The document's root element; nesting deeper than :data:`MAX_DEPTH` is refused as it is
    read."""
    depth, root = 0, None
    try:
        for event, element in iterparse(io.BytesIO(data), ("start", "end"), forbid_dtd=True):
            depth += 1 if event == "start" else -1
            root = element if root is None else root
            if depth > MAX_DEPTH:
                raise _Refused(f"elements nested more than {MAX_DEPTH} deep")
    except ParseError as exc:
        raise _Refused(f"not well-formed XML: {exc}") from None
    except DefusedXmlException:
        raise _Refused("a DOCTYPE (DTD, entities) is not allowed in a URDF file") from None
    if root is None or root.tag != "robot":
        raise _Refused(f"the root element is <{getattr(root, 'tag', '')}>, not <robot>")
    return root


def _check(root: Element) -> tuple[int, tuple[Mimic, ...]]:
    """Check the robot's names, counts, joints, tree and numbers; its actuated joint count
    (mimic joints not counted) and its mimic joints."""
    _name(root.get("name"), "the robot")
    links, joints = root.findall("link"), root.findall("joint")
    actuated = sum(j.get("type") in ACTUATED and j.find("mimic") is None for j in joints)
    if len(links) > MAX_LINKS:
        raise _Refused(f"{len(links)} links: dvqp takes at most {MAX_LINKS}")
    if actuated > MAX_ACTUATED:
        raise _Refused(
            f"{actuated} revolute, continuous and prismatic joints: dvqp takes at "
            f"most {MAX_ACTUATED}"
        )
    if actuated == 0:
        raise _Refused("no revolute, continuous or prismatic joint: nothing moves")
    names = [_name(link.get("name"), f"link number {i + 1}") for i, link in enumerate(links)]
    _unique(names, "link")
    parents = {}
    for i, joint in enumerate(joints):
        parents[i] = _joint(joint, _name(joint.get("name"), f"joint number {i + 1}"), set(names))
    joint_names = _unique([joint.get("name", "") for joint in joints], "joint")
    _tree(names, [(joint_names[i], *parents[i]) for i in range(len(joints))])
    for owner, what in [*zip(links, names, strict=True), *zip(joints, joint_names, strict=True)]:
        _numbers(owner, f"{owner.tag} {what!r}")
    by_name = dict(zip(joint_names, joints, strict=True))
    mimics = tuple(_mimic(j, by_name) for j in joints if j.findall("mimic"))
    return actuated, mimics


MIMICKING = ("revolute", "prismatic")
"""The joint types that may mimic, or be mimicked (Pinocchio's mimic joints: one coordinate)."""


def _mimic(joint: Element, joints: dict[str, Element]) -> Mimic:
    """The ``<mimic>`` of ``joint`` (its numbers already checked): one, of a revolute or
    prismatic joint, naming another revolute or prismatic joint that mimics none, with a
    multiplier that is not 0."""
    name, found = joint.get("name", ""), joint.findall("mimic")
    if len(found) != 1:
        raise _Refused(f"joint {name!r} has {len(found)} <mimic> elements, not one")
    kinds = " or ".join(MIMICKING)
    if joint.get("type") not in MIMICKING:
        raise _Refused(f"joint {name!r} is {joint.get('type')} and mimics: only a {kinds} can")
    element = found[0]
    master = element.get("joint")
    if master not in joints or master == name:
        raise _Refused(f"joint {name!r} mimics {master!r}: not another joint of the file")
    if joints[master].get("type") not in MIMICKING or joints[master].find("mimic") is not None:
        raise _Refused(
            f"joint {name!r} mimics {master!r}, which is not a {kinds} joint that mimics none"
        )
    what = f"joint {name!r}"
    multiplier = (_floats(element, "multiplier", 1, what) or [1.0])[0]
    if multiplier == 0.0:
        raise _Refused(f"joint {name!r}: mimic multiplier 0 (a fixed joint is type 'fixed')")
    limit = joint.find("limit")
    assert limit is not None  # _joint: a revolute or prismatic joint has one
    lower, upper, velocity = (
        (_floats(limit, key, 1, what) or [0.0])[0] for key in ("lower", "upper", "velocity")
    )
    offset = (_floats(element, "offset", 1, what) or [0.0])[0]
    return Mimic(name, master, multiplier, offset, lower, upper, velocity)


def _name(name: str | None, what: str) -> str:
    """``name`` if it is non-empty, printable and at most :data:`MAX_NAME` long."""
    if not name:
        raise _Refused(f"{what} has no name")
    if len(name) > MAX_NAME or not name.isprintable():
        shown = repr(name[:MAX_NAME]) + ("..." if len(name) > MAX_NAME else "")
        raise _Refused(f"{what}: the name {shown} is not {MAX_NAME} printable characters or fewer")
    return name


def _unique(names: list[str], what: str) -> list[str]:
    """``names``, refused if one is given twice."""
    seen: set[str] = set()
    for name in names:
        if name in seen:
            raise _Refused(f"two {what}s are named {name!r}")
        seen.add(name)
    return names


def _joint(joint: Element, name: str, links: set[str]) -> tuple[str, str]:
    """A joint's type and limits checked; its ``(parent link, child link)``."""
    kind = joint.get("type")
    if kind not in JOINT_TYPES:
        raise _Refused(
            f"joint {name!r} has type {kind!r}: dvqp takes only revolute, continuous, "
            "prismatic and fixed joints"
        )
    ends = []
    for end in ("parent", "child"):
        found = joint.findall(end)
        if len(found) != 1:
            raise _Refused(f"joint {name!r} has {len(found)} <{end}> elements, not one")
        link = found[0].get("link")
        if link not in links:
            raise _Refused(f"joint {name!r}: {end} link {link!r} is not a link of the file")
        ends.append(link)
    if kind in ("revolute", "prismatic"):
        limit = joint.find("limit")
        if limit is None:
            raise _Refused(f"joint {name!r} is {kind} but has no <limit>")
        what = f"joint {name!r}"
        lower, upper = (_floats(limit, k, 1, what) or [0.0] for k in ("lower", "upper"))
        if lower[0] > upper[0]:  # either absent: 0, as the parser reads it
            raise _Refused(f"joint {name!r}: limit lower {lower[0]:g} > upper {upper[0]:g}")
    return ends[0], ends[1]


def _tree(links: list[str], joints: list[tuple[str, str, str]]) -> None:
    """The links form one tree: each has at most one parent joint, there is no cycle and one
    root. ``joints`` are ``(name, parent link, child link)``."""
    up: dict[str, tuple[str, str]] = {}  # child link -> (joint, parent link)
    for name, parent, child in joints:
        if child in up:
            raise _Refused(
                f"joint {name!r}: link {child!r} already has parent joint "
                f"{up[child][0]!r} (a link has at most one parent)"
            )
        up[child] = (name, parent)
    done: set[str] = set()
    for start in links:
        chain: list[str] = []
        link = start
        while link in up and link not in done:
            if link in chain:
                loop = chain[chain.index(link) :]
                named = ", ".join(repr(up[c][0]) for c in loop[:6])
                raise _Refused(
                    f"the joints {named}{', ...' if len(loop) > 6 else ''} form a "
                    "cycle: the links must form a tree"
                )
            chain.append(link)
            link = up[link][1]
        done.update(chain)
    roots = [link for link in links if link not in up]
    if len(roots) != 1:
        named = ", ".join(map(repr, roots[:4])) + (", ..." if len(roots) > 4 else "")
        raise _Refused(
            f"{len(roots)} links have no parent joint ({named}): the links must form one tree"
        )


def _numbers(owner: Element, what: str) -> None:
    """Every numeric attribute of :data:`NUMBERS` below ``owner`` is finite, of its count; an
    axis is not zero, an origin within :data:`MAX_OFFSET`."""
    for tag, attributes in NUMBERS.items():
        for element in owner.iter(tag):
            for key, count in attributes.items():
                found = _floats(element, key, count, what)
                if not found and key in REQUIRED.get(tag, ()):
                    raise _Refused(f"{what}: <{tag}> has no {key}")
                if tag == "axis" and found and math.hypot(*found) < 1e-6:
                    raise _Refused(f"{what}: axis xyz {element.get(key)!r} has no direction")
                far = [v for v in found if abs(v) > MAX_OFFSET]
                if (tag, key) == ("origin", "xyz") and far:
                    raise _Refused(
                        f"{what}: origin xyz {element.get(key)!r}: a coordinate "
                        f"beyond {MAX_OFFSET:g} m"
                    )


def _floats(element: Element, key: str, count: int, what: str) -> list[float]:
    """The attribute ``key`` as ``count`` finite numbers ([] if it is absent)."""
    text = element.get(key)
    if text is None:
        return []
    parts = text.split()
    values = [float(p) for p in parts if _NUMBER.fullmatch(p)]
    if len(parts) != count or len(values) != count or not all(map(math.isfinite, values)):
        shown = repr(text[:40]) + ("..." if len(text) > 40 else "")
        raise _Refused(
            f"{what}: {element.tag} {key} = {shown}: expected {count} finite "
            f"number{'s' if count > 1 else ''}"
        )
    return values
