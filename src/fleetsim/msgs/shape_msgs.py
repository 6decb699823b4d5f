"""shape_msgs: SolidPrimitive (boxes, spheres, cylinders, cones of collision objects)."""

from __future__ import annotations

from typing import ClassVar

from fleetsim.msgs.fields import Seq, float64, uint8
from fleetsim.msgs.geometry_msgs import Polygon
from fleetsim.msgs.registry import message


@message("shape_msgs/msg/SolidPrimitive")
class SolidPrimitive:
    """``dimensions`` (ROS 2: at most 3), m: BOX [x, y, z]; SPHERE [radius]; CYLINDER and
    CONE [height, radius]."""

    BOX: ClassVar[uint8] = 1
    SPHERE: ClassVar[uint8] = 2
    CYLINDER: ClassVar[uint8] = 3
    CONE: ClassVar[uint8] = 4
    PRISM: ClassVar[uint8] = 5
    BOX_X: ClassVar[uint8] = 0
    BOX_Y: ClassVar[uint8] = 1
    BOX_Z: ClassVar[uint8] = 2
    SPHERE_RADIUS: ClassVar[uint8] = 0
    CYLINDER_HEIGHT: ClassVar[uint8] = 0
    CYLINDER_RADIUS: ClassVar[uint8] = 1
    CONE_HEIGHT: ClassVar[uint8] = 0
    CONE_RADIUS: ClassVar[uint8] = 1
    PRISM_HEIGHT: ClassVar[uint8] = 0

    type: uint8
    dimensions: Seq[float64, 3]
    polygon: Polygon  # PRISM (ROS 2 only)
