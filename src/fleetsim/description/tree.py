"""Text and diagrams of a robot's kinematic tree, in the formats of ROS's urdfdom tools.

``check_report`` prints what ``check_urdf`` prints; ``graphviz_source`` writes what
``urdf_to_graphiz`` writes (links as boxes, joints as blue ellipses labelled with the joint origin
``xyz`` and ``rpy``); ``write_graph`` also runs Graphviz's ``dot`` to make the PDF.
"""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

from fleetsim.description.model import Robot
from fleetsim.errors import DescriptionError


def tree_lines(robot: Robot, link: str, depth: int = 1) -> list[str]:
    """``child(i):  name`` lines below ``link``, depth first in document order, 4 spaces a level."""
    lines: list[str] = []
    for i, joint in enumerate(robot.children(link), start=1):
        lines.append(f"{'    ' * depth}child({i}):  {joint.child}")
        lines.extend(tree_lines(robot, joint.child, depth + 1))
    return lines


def check_report(robot: Robot) -> str:
    """The text ``check_urdf`` prints for a valid robot (newline-terminated)."""
    root = robot.root_link()
    lines = [
        f"robot name is: {robot.name}",
        "---------- Successfully Parsed XML ---------------",
        f"root Link: {root} has {len(robot.children(root))} child(ren)",
        *tree_lines(robot, root),
    ]
    return "\n".join(lines) + "\n"


def _g(v: float) -> str:
    """A number as C++ ``std::ostream`` prints a double by default (``%g``, 6 digits)."""
    return f"{v:g}"


def graphviz_source(robot: Robot) -> str:
    """Graphviz ``dot`` source of the kinematic tree, as ``urdf_to_graphiz`` writes it."""
    root = robot.root_link()
    order: list[str] = []

    def walk(link: str) -> None:
        order.append(link)
        for j in robot.children(link):
            walk(j.child)

    walk(root)
    out = ["digraph G {", "node [shape=box];"]
    out += [f'"{name}" [label="{name}"];' for name in order]
    out.append("node [shape=ellipse, color=blue, fontcolor=blue];")
    for link in order:
        for j in robot.children(link):
            x, y, z = (_g(v) for v in j.origin.xyz)
            r, p, yaw = (_g(v) for v in j.origin.rpy)
            out.append(f'"{link}" -> "{j.name}" [label="xyz: {x} {y} {z} \\nrpy: {r} {p} {yaw}"]')
            out.append(f'"{j.name}" -> "{j.child}"')
    out.append("}")
    return "\n".join(out) + "\n"


def dot_executable() -> str:
    """Path of Graphviz's ``dot``; a clear error when Graphviz is not installed."""
    exe = shutil.which("dot")
    if exe is None:
        raise DescriptionError(
            "Graphviz 'dot' was not found on PATH; install graphviz "
            "(apt-get install graphviz, brew install graphviz) to make the PDF"
        )
    return exe


def write_graph(robot: Robot, out_dir: str | Path) -> tuple[Path, Path]:
    """Write ``NAME.gv`` and ``NAME.pdf`` into ``out_dir``; return both paths."""
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    gv = out_dir / f"{robot.name}.gv"
    pdf = out_dir / f"{robot.name}.pdf"
    source = graphviz_source(robot)
    exe = dot_executable()
    gv.write_text(source)
    proc = subprocess.run(
        [exe, "-Tpdf", str(gv), "-o", str(pdf)], capture_output=True, text=True, check=False
    )
    if proc.returncode != 0:
        raise DescriptionError(f"{gv}: graphviz dot failed: {proc.stderr.strip()}")
    return gv, pdf
