"""Random robot files for the fuzz tests: random trees of links, and the edits people (and
attackers) make to them — a second parent, a cycle, a dangling link name, a bad number, a name
with a control character, a joint type dvqp does not take, junk text, a dropped element.

:func:`arms` draws a valid URDF tree (as an ElementTree element) with its expected joints
(:func:`joints_of` reads those of a file); :func:`edit` applies one edit (those of
:data:`REFUSED_EDITS` must be refused).
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from dataclasses import dataclass

from hypothesis import strategies as st

TYPES = ("revolute", "continuous", "prismatic", "fixed")
REFUSED_EDITS = ("second parent", "cycle", "dangling", "number", "name", "type")
"""Edits after which the file must be refused before the parser sees it."""
EDITS = (*REFUSED_EDITS, "splice", "drop")
BAD_NUMBERS = (
    "nan",
    "NaN",
    "inf",
    "-inf",
    "1e999",
    "-1e400",
    "1_0",
    "0x10",
    "abc",
    "1,5",
    "--1",
    "1e",
    ".",
    "",
)
UNPRINTABLE = tuple(
    map(chr, (0x85, 0x7F, 0x9, 0xA, 0xD, 0x2028, 0x2029, 0xAD, 0x200B, 0xFEFF, 0x9F, 0x1B))
)
"""Not printable; all but the last (which XML forbids) pass the XML parser."""
AXES = ("1 0 0", "0 1 0", "0 0 1", "0 0 -1", "0.6 0.8 0", "0 0.7071 0.7071", "1 1 1")


@dataclass
class Joint:
    """A generated joint: its name, type, parent and child links, limits (m or rad)."""

    name: str
    kind: str
    parent: str
    child: str
    lower: float
    upper: float


def joints_of(root: ET.Element) -> list[Joint]:
    """The joints of a URDF document (limits as given, 0 where absent)."""
    found = []
    for e in root.findall("joint"):
        limit = e.find("limit")
        lower, upper = (
            float(limit.get(k, 0)) if limit is not None else 0.0 for k in ("lower", "upper")
        )
        ends = [e.find(end).get("link", "") for end in ("parent", "child")]  # type: ignore[union-attr]
        found.append(Joint(e.get("name", ""), e.get("type", ""), *ends, lower, upper))
    return found


NUMBER = st.integers(-2000, 2000).map(lambda v: v / 1000)


@st.composite
def arms(draw: st.DrawFn) -> tuple[ET.Element, list[Joint]]:
    """A URDF tree of 2 to 10 links (document order shuffled), at least one joint that moves."""
    count = draw(st.integers(2, 10), label="links")
    joints = []
    for i in range(1, count):
        kind = draw(st.sampled_from(TYPES)) if i > 1 else draw(st.sampled_from(TYPES[:3]))
        lower = draw(NUMBER)
        upper = lower + draw(st.integers(0, 3000)) / 1000
        parent = f"l{draw(st.integers(0, i - 1))}"
        joints.append(Joint(f"j{i}", kind, parent, f"l{i}", lower, upper))
    root = ET.Element("robot", name="fuzz")
    elements = [ET.Element("link", name=f"l{i}") for i in range(count)]
    for joint in joints:
        element = ET.Element("joint", name=joint.name, type=joint.kind)
        ET.SubElement(element, "parent", link=joint.parent)
        ET.SubElement(element, "child", link=joint.child)
        xyz, rpy = (" ".join(repr(draw(NUMBER)) for _ in range(3)) for _ in range(2))
        ET.SubElement(element, "origin", xyz=xyz, rpy=rpy)
        if joint.kind != "fixed":
            ET.SubElement(element, "axis", xyz=draw(st.sampled_from(AXES)))
            ET.SubElement(
                element,
                "limit",
                lower=repr(joint.lower),
                upper=repr(joint.upper),
                effort="1",
                velocity=repr(draw(st.integers(1, 30)) / 10),
            )
        elements.append(element)
    for element in draw(st.permutations(elements), label="order"):
        root.append(element)
    return root, joints


def edit(root: ET.Element, joints: list[Joint], kind: str, data: st.DataObject) -> str:
    """The file's text after the edit ``kind`` (one of :data:`EDITS`, or ``"none"``)."""
    links = [e.get("name", "") for e in root.findall("link")]
    elements = {e.get("name"): e for e in root.findall("joint")}
    joint = data.draw(st.sampled_from(joints), label="joint")
    element = elements[joint.name]
    if kind == "second parent":
        extra = ET.SubElement(root, "joint", name="extra", type="fixed")
        ET.SubElement(extra, "parent", link=data.draw(st.sampled_from(links), label="parent"))
        ET.SubElement(extra, "child", link=joint.child)
    elif kind == "cycle":  # the joint's parent becomes its child or one of the child's links
        below, grew = {joint.child}, True
        while grew:
            more = {j.child for j in joints if j.parent in below} - below
            below, grew = below | more, bool(more)
        parent = data.draw(st.sampled_from(sorted(below)), label="below")
        element.find("parent").set("link", parent)  # type: ignore[union-attr]
    elif kind == "dangling":
        end = data.draw(st.sampled_from(["parent", "child"]), label="end")
        element.find(end).set("link", "nope")  # type: ignore[union-attr]
    elif kind == "number":
        _bad_number(element, data)
    elif kind == "name":
        _bad_name(root, data)
    elif kind == "type":
        element.set(
            "type",
            data.draw(
                st.sampled_from(["planar", "floating", "bogus", "", "Revolute"]), label="type"
            ),
        )
    elif kind == "drop":
        every = [(p, c) for p in root.iter() for c in p]
        parent, child = data.draw(st.sampled_from(every), label="drop")
        parent.remove(child)
    text = ET.tostring(root, encoding="unicode")
    if kind == "splice":
        at = data.draw(st.integers(0, len(text)), label="at")
        text = text[:at] + data.draw(st.text(min_size=1, max_size=8), label="junk") + text[at:]
    return text


def _bad_number(element: ET.Element, data: st.DataObject) -> None:
    """One numeric attribute of ``element`` made bad: a bad token, a count off by one, a zero
    axis or an origin a kilometre and more away."""
    places = [
        (e, key)
        for e in element
        for key in ("xyz", "rpy", "lower", "upper", "velocity")
        if e.get(key) is not None
    ]
    target, key = data.draw(st.sampled_from(places), label="number")
    values = target.get(key, "").split()
    how = data.draw(st.sampled_from(["token", "count", "zero", "far"]), label="how")
    if how == "zero" and target.tag == "axis":
        values = ["0", "0", "0"]
    elif how == "far" and target.tag == "origin" and key == "xyz":
        values[0] = data.draw(st.sampled_from(["1000.5", "-1e5", "1e300"]), label="far")
    elif how == "count":
        values = values[:-1] if len(values) > 1 and data.draw(st.booleans()) else [*values, "1"]
    else:
        at = data.draw(st.integers(0, len(values) - 1), label="at")
        values[at] = data.draw(st.sampled_from(BAD_NUMBERS), label="token")
    target.set(key, " ".join(values))


def _bad_name(root: ET.Element, data: st.DataObject) -> None:
    """A link or joint renamed (every reference too): an unprintable character, empty, long."""
    element = data.draw(st.sampled_from([*root.findall("link"), *root.findall("joint")]))
    old = element.get("name", "")
    how = data.draw(st.sampled_from(["char", "char", "empty", "long"]), label="name")
    if how == "char":
        at = data.draw(st.integers(0, len(old)), label="at")
        new = old[:at] + data.draw(st.sampled_from(UNPRINTABLE), label="char") + old[at:]
    else:
        new = "" if how == "empty" else old * 101  # over 200 characters
    element.set("name", new)
    if element.tag == "link":
        for end in [*root.iter("parent"), *root.iter("child")]:
            if end.get("link") == old:
                end.set("link", new)
