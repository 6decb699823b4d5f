"""URDF and xacro → :class:`Robot`, with the checks ROS's urdfdom and check_urdf make.

Public API (the simulator codes against it)::

    robot = load_robot("hunter.urdf.xacro", args={"use_arm": "true"})
    robot = parse_urdf(text, source="robot.urdf")
    robot.root_link(); robot.children("base_link"); robot.to_urdf()

Every invalid input raises :class:`DescriptionError` with the file, the line (the line in the
xacro file that defines the element when it can be found there) and what would fix it.
"""

from __future__ import annotations

import math
import re
from collections.abc import Iterable, Mapping
from pathlib import Path

from lxml import etree

from fleetsim.description.gazebo import parse_gazebo, parse_transmission
from fleetsim.description.model import (
    JOINT_TYPES,
    Box,
    Collision,
    Cylinder,
    Dynamics,
    GazeboBlock,
    Inertial,
    Joint,
    Limit,
    Link,
    Material,
    Mesh,
    Mimic,
    Origin,
    PluginSpec,
    Robot,
    SensorSpec,
    Sphere,
    Transmission,
    Visual,
)
from fleetsim.description.packages import PackageIndex
from fleetsim.description.urdf_links import LinkElements
from fleetsim.description.xacro import expand_xacro, is_xacro
from fleetsim.errors import DescriptionError, did_you_mean

__all__ = [
    "Box",
    "Collision",
    "Cylinder",
    "Dynamics",
    "GazeboBlock",
    "Inertial",
    "Joint",
    "Limit",
    "Link",
    "Material",
    "Mesh",
    "Mimic",
    "Origin",
    "PluginSpec",
    "Robot",
    "SensorSpec",
    "Sphere",
    "Transmission",
    "Visual",
    "load_robot",
    "parse_urdf",
    "urdf_text",
]


def urdf_text(
    path: str | Path,
    args: Mapping[str, str] | None = None,
    package_path: Iterable[Path] | None = None,
) -> tuple[str, list[Path]]:
    """The URDF text of ``path`` (xacro expanded) and the files it was made from."""
    path = Path(path).resolve()
    if not path.is_file():
        raise DescriptionError(f"{path}: no such robot description file")
    text = path.read_text()
    if not is_xacro(path, text):
        return text, [path]
    index = PackageIndex(package_path, near=path)
    return expand_xacro(path, args, index)


def load_robot(
    path: str | Path,
    args: Mapping[str, str] | None = None,
    package_path: Iterable[Path] | None = None,
) -> Robot:
    """Load a ``.urdf`` or ``.xacro`` file into a :class:`Robot`.

    ``args`` are xacro arguments (``$(arg name)``); ``package_path`` lists extra folders searched
    for packages (before ``FLEETSIM_PACKAGE_PATH``, ``ROS_PACKAGE_PATH`` and fleetsim's own
    ``assets/robots``) to resolve ``$(find pkg)`` and ``package://`` URIs.
    """
    path = Path(path).resolve()
    text, files = urdf_text(path, args, package_path)
    index = PackageIndex(package_path, near=path)
    expanded = len(files) > 1 or is_xacro(path, text)
    return _Parser(
        text, str(path), index, base_dir=path.parent, files=files if expanded else None
    ).robot()


def parse_urdf(
    text: str,
    source: str = "<string>",
    package_path: Iterable[Path] | None = None,
    base_dir: Path | None = None,
) -> Robot:
    """Parse URDF XML text. ``source`` names it in errors; relative mesh paths use ``base_dir``."""
    index = PackageIndex(package_path)
    return _Parser(text, source, index, base_dir=base_dir, files=None).robot()


_FLOAT = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?"


class _Parser(LinkElements):
    def __init__(self, text, source, index, base_dir=None, files=None):
        self.text = text
        self.source = source
        self.index = index
        self.base_dir = Path(base_dir) if base_dir else None
        self.files = files  # source files of an expanded xacro, for error locations

    # -- locations -------------------------------------------------------------------------
    def where(self, elem) -> str:
        """``file:line`` of ``elem`` (for xacro: the line in the xacro file defining it)."""
        line = getattr(elem, "sourceline", None)
        if self.files:
            found = self._find_in_sources(elem)
            if found:
                return found
            return f"{self.source} (line {line} of the expanded xacro)"
        return f"{self.source}:{line}" if line else self.source

    def _find_in_sources(self, elem) -> str | None:
        target = elem
        while target is not None and target.get("name") is None:
            target = target.getparent()
        if target is None:
            return None
        name = re.escape(target.get("name"))
        pat = re.compile(rf"<{target.tag}\b[^>]*\bname\s*=\s*[\"']{name}[\"']", re.S)
        for f in self.files:
            try:
                content = f.read_text()
            except OSError:
                continue
            m = pat.search(content)
            if m:
                return f"{f}:{content.count(chr(10), 0, m.start()) + 1}"
        return None

    def fail(self, elem, msg: str):
        raise DescriptionError(f"{self.where(elem)}: {msg}")

    # -- attribute helpers -----------------------------------------------------------------
    def attr(self, elem, name: str, required: bool = True, default: str | None = None):
        value = elem.get(name)
        if value is None:
            if required:
                self.fail(elem, f"<{elem.tag}> is missing the required attribute '{name}'")
            return default
        return value

    def floats(self, elem, name: str, n: int, default=None):
        raw = elem.get(name)
        if raw is None:
            if default is None:
                self.fail(elem, f"<{elem.tag}> is missing the required attribute '{name}'")
            return default
        parts = raw.split()
        try:
            values = tuple(float(p) for p in parts)
        except ValueError:
            values = ()
        if len(values) != n or not all(math.isfinite(v) for v in values):
            self.fail(
                elem,
                f'<{elem.tag}> attribute {name}="{raw}" is not {n} finite number(s) '
                f'(write e.g. {name}="{" ".join(["0"] * n)}")',
            )
        return values

    def number(self, elem, name: str, default: float | None = None, minimum=None) -> float:
        value = self.floats(elem, name, 1, None if default is None else (default,))[0]
        if minimum is not None and value < minimum:
            self.fail(elem, f'<{elem.tag}> attribute {name}="{value:g}" must be >= {minimum:g}')
        return value

    def origin(self, parent) -> Origin:
        o = parent.find("origin")
        if o is None:
            return Origin()
        return Origin(
            self.floats(o, "xyz", 3, (0.0, 0.0, 0.0)), self.floats(o, "rpy", 3, (0.0, 0.0, 0.0))
        )

    # -- the robot -------------------------------------------------------------------------
    def robot(self) -> Robot:
        try:
            parser = etree.XMLParser(remove_comments=True, huge_tree=True)
            root = etree.fromstring(self.text.encode(), parser)
        except etree.XMLSyntaxError as exc:
            line = exc.lineno if not self.files else f"{exc.lineno} of the expanded xacro"
            raise DescriptionError(f"{self.source}:{line}: XML syntax error: {exc.msg}") from None
        if root.tag != "robot":
            self.fail(root, f"the root element is <{root.tag}>; a URDF starts with <robot>")
        robot = Robot(name=self.attr(root, "name"), source=self.source)
        for m in root.findall("material"):
            mat = self.material(m, robot.materials, top=True)
            robot.materials[mat.name] = mat
        for el in root.findall("link"):
            link = self.link(el, robot.materials)
            if link.name in robot.links:
                self.fail(el, f"link '{link.name}' is defined twice; link names must be unique")
            robot.links[link.name] = link
        if not robot.links:
            self.fail(root, f"robot '{robot.name}' has no <link>; a URDF needs at least one")
        joint_elems = {}
        for el in root.findall("joint"):
            joint = self.joint(el, robot)
            if joint.name in robot.joints:
                self.fail(el, f"joint '{joint.name}' is defined twice; joint names must be unique")
            robot.joints[joint.name] = joint
            joint_elems[joint.name] = el
        self.check_tree(robot, root, joint_elems)
        for el in root.findall("gazebo"):
            robot.gazebo.append(parse_gazebo(el, self))
        for el in root.findall("transmission"):
            robot.transmissions.append(parse_transmission(el, self, robot))
        for el, block in zip(root.findall("gazebo"), robot.gazebo):
            ref = block.reference
            if ref is not None and ref not in robot.links and ref not in robot.joints:
                self.fail(
                    el,
                    f'<gazebo reference="{ref}"> names no link or joint'
                    f"{did_you_mean(ref, [*robot.links, *robot.joints])}",
                )
        return robot

    def check_tree(self, robot: Robot, root, joint_elems) -> None:
        parent_of: dict[str, str] = {}
        for j in robot.joints.values():
            el = joint_elems[j.name]
            for role, link in (("parent", j.parent), ("child", j.child)):
                if link not in robot.links:
                    self.fail(
                        el,
                        f"joint '{j.name}' names {role} link '{link}', which is not defined"
                        f'{did_you_mean(link, robot.links)}; add <link name="{link}"/> '
                        f"or fix the joint's <{role} link=...>",
                    )
            if j.parent == j.child:
                self.fail(el, f"joint '{j.name}' has link '{j.child}' as both parent and child")
            if j.child in parent_of:
                self.fail(
                    el,
                    f"link '{j.child}' has two parent joints ('{parent_of[j.child]}' and "
                    f"'{j.name}'); a URDF is a tree, each link has at most one parent",
                )
            parent_of[j.child] = j.name
        roots = [n for n in robot.links if n not in parent_of]
        if len(roots) > 1:
            self.fail(
                root,
                f"robot '{robot.name}' has {len(roots)} root links ({', '.join(roots)}); "
                "a URDF tree has exactly one: connect the others with joints",
            )
        reached = {roots[0]} if roots else set()
        stack = list(reached)
        while stack:
            link = stack.pop()
            for j in robot.joints.values():
                if j.parent == link and j.child not in reached:
                    reached.add(j.child)
                    stack.append(j.child)
        loop = [n for n in robot.links if n not in reached]
        if loop:
            start = loop[0]
            cycle, link = [start], robot.joints[parent_of[start]].parent
            while link not in cycle:
                cycle.append(link)
                link = robot.joints[parent_of[link]].parent
            cycle = cycle[cycle.index(link) :]
            path = " -> ".join([*reversed(cycle), cycle[-1]])
            self.fail(
                joint_elems[parent_of[cycle[0]]],
                f"the joints form a cycle ({path}); a URDF is a tree: remove one joint of the loop",
            )

    def joint(self, el, robot: Robot) -> Joint:
        name = self.attr(el, "name")
        jtype = self.attr(el, "type")
        if jtype not in JOINT_TYPES:
            self.fail(
                el,
                f"joint '{name}' has type=\"{jtype}\"{did_you_mean(jtype, JOINT_TYPES)}; "
                f"valid types: {', '.join(JOINT_TYPES)}",
            )
        ends = {}
        for role in ("parent", "child"):
            e = el.find(role)
            if e is None or not e.get("link"):
                self.fail(el, f"joint '{name}' has no <{role} link=\"...\"/>; add the {role} link")
            ends[role] = e.get("link")
        axis = (1.0, 0.0, 0.0)
        ax = el.find("axis")
        if ax is not None:
            axis = self.floats(ax, "xyz", 3)
            norm = math.sqrt(sum(a * a for a in axis))
            if norm == 0:
                self.fail(ax, f"joint '{name}' has a zero axis; give a unit vector like '0 0 1'")
            axis = tuple(a / norm for a in axis)
        limit = None
        lim = el.find("limit")
        if lim is not None:
            limit = Limit(
                lower=self.number(lim, "lower", 0.0),
                upper=self.number(lim, "upper", 0.0),
                effort=self.number(lim, "effort", None if jtype != "continuous" else 0.0, 0.0),
                velocity=self.number(lim, "velocity", None if jtype != "continuous" else 0.0, 0.0),
            )
            if limit.upper < limit.lower:
                self.fail(lim, f"joint '{name}': limit upper={limit.upper:g} < lower")
        elif jtype in ("revolute", "prismatic"):
            self.fail(
                el,
                f"joint '{name}' of type {jtype} has no <limit>; add "
                '<limit lower="..." upper="..." effort="..." velocity="..."/>',
            )
        dynamics = None
        dyn = el.find("dynamics")
        if dyn is not None:
            dynamics = Dynamics(
                self.number(dyn, "damping", 0.0, 0.0), self.number(dyn, "friction", 0.0, 0.0)
            )
        mimic = None
        mim = el.find("mimic")
        if mim is not None:
            mimic = Mimic(
                self.attr(mim, "joint"),
                self.number(mim, "multiplier", 1.0),
                self.number(mim, "offset", 0.0),
            )
        return Joint(
            name,
            jtype,
            ends["parent"],
            ends["child"],
            self.origin(el),
            axis,
            limit,
            dynamics,
            mimic,
            el.sourceline,
        )
