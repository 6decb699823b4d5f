"""Robot descriptions: xacro → URDF, the URDF/SRDF model, check and graph tools."""

from fleetsim.description.urdf import load_robot, parse_urdf

__all__ = ["load_robot", "parse_urdf"]
