"""MoveIt SRDF files: planning groups, named group states (``home``), end effectors, virtual
joints and disabled collision pairs.

``load_srdf(path, robot=...)`` also checks every joint, link and group name against the URDF.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from lxml import etree

from fleetsim.description.model import Robot
from fleetsim.errors import DescriptionError, did_you_mean


@dataclass
class Group:
    """A planning group: joints, links, ``(base_link, tip_link)`` chains and subgroup names."""

    joints: list[str] = field(default_factory=list)
    links: list[str] = field(default_factory=list)
    chains: list[tuple[str, str]] = field(default_factory=list)
    subgroups: list[str] = field(default_factory=list)


@dataclass(frozen=True)
class EndEffector:
    name: str
    group: str
    parent_link: str
    parent_group: str | None = None


@dataclass(frozen=True)
class VirtualJoint:
    name: str
    type: str
    parent_frame: str
    child_link: str


@dataclass
class Srdf:
    name: str
    groups: dict[str, Group] = field(default_factory=dict)
    group_states: dict[tuple[str, str], dict[str, float]] = field(default_factory=dict)
    end_effectors: list[EndEffector] = field(default_factory=list)
    disabled_collisions: list[tuple[str, str, str]] = field(default_factory=list)
    virtual_joints: list[VirtualJoint] = field(default_factory=list)
    source: str = "<string>"

    def group_joints(self, group: str, robot: Robot | None = None) -> list[str]:
        """The joints of ``group``, its chains (needs ``robot``) and subgroups, in order."""
        if group not in self.groups:
            raise DescriptionError(
                f"{self.source}: no group '{group}'{did_you_mean(group, self.groups)}"
            )
        g = self.groups[group]
        out = list(g.joints)
        for base, tip in g.chains:
            if robot is None:
                raise DescriptionError(f"{self.source}: group '{group}' has a chain; pass robot=")
            chain: list[str] = []
            link = tip
            while link != base:
                joint = robot.parent_joint(link)
                if joint is None:
                    raise DescriptionError(
                        f"{self.source}: chain {base} -> {tip} of group '{group}': "
                        f"'{base}' is not an ancestor of '{tip}'"
                    )
                chain.append(joint.name)
                link = joint.parent
            out.extend(reversed(chain))
        for sub in g.subgroups:
            out.extend(self.group_joints(sub, robot))
        return list(dict.fromkeys(out))


_VIRTUAL_TYPES = ("fixed", "floating", "planar")


class _SrdfParser:
    def __init__(self, source: str, robot: Robot | None):
        self.source = source
        self.robot = robot

    def fail(self, el, msg: str):
        raise DescriptionError(f"{self.source}:{el.sourceline}: {msg}")

    def attr(self, el, name: str) -> str:
        value = el.get(name)
        if value is None:
            self.fail(el, f"<{el.tag}> is missing the required attribute '{name}'")
        return value

    def link(self, el, name: str) -> str:
        if self.robot is not None and name not in self.robot.links:
            self.fail(
                el,
                f"link '{name}' is not in robot '{self.robot.name}'"
                f"{did_you_mean(name, self.robot.links)}",
            )
        return name

    def joint(self, el, name: str) -> str:
        if self.robot is not None and name not in self.robot.joints:
            self.fail(
                el,
                f"joint '{name}' is not in robot '{self.robot.name}'"
                f"{did_you_mean(name, self.robot.joints)}",
            )
        return name

    def parse(self, text: str) -> Srdf:
        try:
            root = etree.fromstring(text.encode(), etree.XMLParser(remove_comments=True))
        except etree.XMLSyntaxError as exc:
            msg = f"{self.source}:{exc.lineno}: XML syntax error: {exc.msg}"
            raise DescriptionError(msg) from None
        if root.tag != "robot":
            self.fail(root, f"the root element is <{root.tag}>; an SRDF starts with <robot>")
        srdf = Srdf(name=self.attr(root, "name"), source=self.source)
        if self.robot is not None and srdf.name != self.robot.name:
            self.fail(root, f"SRDF is for robot '{srdf.name}' but the URDF is '{self.robot.name}'")
        for g in root.findall("group"):
            srdf.groups[self.attr(g, "name")] = self.group(g)
        for g in root.findall("group"):
            for sub in srdf.groups[g.get("name")].subgroups:
                if sub not in srdf.groups:
                    self.fail(g, f"group '{g.get('name')}' names unknown subgroup '{sub}'")
        for vj in root.findall("virtual_joint"):
            vtype = self.attr(vj, "type")
            if vtype not in _VIRTUAL_TYPES:
                self.fail(vj, f"virtual_joint type '{vtype}' is not one of {_VIRTUAL_TYPES}")
            srdf.virtual_joints.append(
                VirtualJoint(
                    self.attr(vj, "name"),
                    vtype,
                    self.attr(vj, "parent_frame"),
                    self.link(vj, self.attr(vj, "child_link")),
                )
            )
        for gs in root.findall("group_state"):
            name, group = self.attr(gs, "name"), self.attr(gs, "group")
            if group not in srdf.groups:
                self.fail(
                    gs,
                    f"group_state '{name}' names unknown group '{group}'"
                    f"{did_you_mean(group, srdf.groups)}",
                )
            values: dict[str, float] = {}
            for j in gs.findall("joint"):
                jname = self.joint(j, self.attr(j, "name"))
                try:
                    values[jname] = float(self.attr(j, "value").split()[0])
                except (ValueError, IndexError):
                    self.fail(
                        j,
                        f"group_state '{name}': joint '{jname}' value "
                        f"'{j.get('value')}' is not a number",
                    )
            srdf.group_states[(group, name)] = values
        for ee in root.findall("end_effector"):
            group = self.attr(ee, "group")
            if group not in srdf.groups:
                self.fail(ee, f"end_effector names unknown group '{group}'")
            srdf.end_effectors.append(
                EndEffector(
                    self.attr(ee, "name"),
                    group,
                    self.link(ee, self.attr(ee, "parent_link")),
                    ee.get("parent_group"),
                )
            )
        for dc in root.findall("disable_collisions"):
            srdf.disabled_collisions.append(
                (
                    self.link(dc, self.attr(dc, "link1")),
                    self.link(dc, self.attr(dc, "link2")),
                    dc.get("reason", ""),
                )
            )
        return srdf

    def group(self, el) -> Group:
        g = Group()
        for child in el:
            if not isinstance(child.tag, str):
                continue
            if child.tag == "joint":
                g.joints.append(self.joint(child, self.attr(child, "name")))
            elif child.tag == "link":
                g.links.append(self.link(child, self.attr(child, "name")))
            elif child.tag == "chain":
                g.chains.append(
                    (
                        self.link(child, self.attr(child, "base_link")),
                        self.link(child, self.attr(child, "tip_link")),
                    )
                )
            elif child.tag == "group":
                g.subgroups.append(self.attr(child, "name"))
            else:
                self.fail(child, f"unknown element <{child.tag}> in group '{el.get('name')}'")
        return g


def parse_srdf(text: str, source: str = "<string>", robot: Robot | None = None) -> Srdf:
    """Parse SRDF text; with ``robot`` every link and joint name is checked against it."""
    return _SrdfParser(source, robot).parse(text)


def load_srdf(path: str | Path, robot: Robot | None = None) -> Srdf:
    """Load an SRDF file (see :func:`parse_srdf`)."""
    path = Path(path)
    if not path.is_file():
        raise DescriptionError(f"{path}: no such SRDF file")
    return parse_srdf(path.read_text(), str(path), robot)
