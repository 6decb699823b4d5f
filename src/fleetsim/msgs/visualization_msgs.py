"""visualization_msgs: Marker and MarkerArray (ROS 2 Humble layout)."""

from __future__ import annotations

from typing import ClassVar

from fleetsim.msgs.builtin_interfaces import Duration
from fleetsim.msgs.fields import Seq, bool_, float32, int32, string, uint8
from fleetsim.msgs.geometry_msgs import Point, Pose, Vector3
from fleetsim.msgs.registry import message
from fleetsim.msgs.sensor_msgs import CompressedImage
from fleetsim.msgs.std_msgs import ColorRGBA, Header


@message("visualization_msgs/msg/UVCoordinate")
class UVCoordinate:
    u: float32
    v: float32


@message("visualization_msgs/msg/MeshFile")
class MeshFile:
    filename: string
    data: Seq[uint8]


@message("visualization_msgs/msg/Marker")
class Marker:
    """A shape for viewers: ``type`` and ``action`` take the class constants; ``scale`` in m.

    A ``lifetime`` of zero means forever; (``ns``, ``id``) identifies a marker for MODIFY/DELETE.
    """

    ARROW: ClassVar[int32] = 0
    CUBE: ClassVar[int32] = 1
    SPHERE: ClassVar[int32] = 2
    CYLINDER: ClassVar[int32] = 3
    LINE_STRIP: ClassVar[int32] = 4
    LINE_LIST: ClassVar[int32] = 5
    CUBE_LIST: ClassVar[int32] = 6
    SPHERE_LIST: ClassVar[int32] = 7
    POINTS: ClassVar[int32] = 8
    TEXT_VIEW_FACING: ClassVar[int32] = 9
    MESH_RESOURCE: ClassVar[int32] = 10
    TRIANGLE_LIST: ClassVar[int32] = 11
    ADD: ClassVar[int32] = 0
    MODIFY: ClassVar[int32] = 0
    DELETE: ClassVar[int32] = 2
    DELETEALL: ClassVar[int32] = 3

    header: Header
    ns: string
    id: int32
    type: int32
    action: int32
    pose: Pose
    scale: Vector3
    color: ColorRGBA
    lifetime: Duration
    frame_locked: bool_
    points: Seq[Point]
    colors: Seq[ColorRGBA]
    texture_resource: string
    texture: CompressedImage
    uv_coordinates: Seq[UVCoordinate]
    text: string
    mesh_resource: string
    mesh_file: MeshFile
    mesh_use_embedded_materials: bool_


@message("visualization_msgs/msg/MarkerArray")
class MarkerArray:
    markers: Seq[Marker]
