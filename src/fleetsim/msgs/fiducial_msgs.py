"""fiducial_msgs: what ``aruco_detect`` publishes (UbiquityRobotics/fiducials, as of 2017).

``FiducialArray`` on ``fiducial_vertices`` gives each detected marker's four corner pixels in
OpenCV order (top-left, top-right, bottom-right, bottom-left); ``FiducialTransformArray`` on
``fiducial_transforms`` gives each marker's pose in the camera's optical frame (x right, y down,
z forward) with its reprojection errors. Both are published for every processed image, empty
when nothing was seen; ``image_seq`` is the image's sequence number (ROS 1 ``header.seq``).
"""

from __future__ import annotations

from fleetsim.msgs.fields import Seq, float64, int32
from fleetsim.msgs.geometry_msgs import Transform
from fleetsim.msgs.registry import message
from fleetsim.msgs.std_msgs import Header


@message("fiducial_msgs/msg/Fiducial")
class Fiducial:
    """One marker's image corners in pixels; ``direction`` is never set by aruco_detect."""

    fiducial_id: int32
    direction: int32
    x0: float64
    y0: float64
    x1: float64
    y1: float64
    x2: float64
    y2: float64
    x3: float64
    y3: float64


@message("fiducial_msgs/msg/FiducialArray")
class FiducialArray:
    header: Header
    image_seq: int32
    fiducials: Seq[Fiducial]


@message("fiducial_msgs/msg/FiducialTransform")
class FiducialTransform:
    """Camera-to-marker transform; errors in px^2 (image) and m (object), area in px^2."""

    fiducial_id: int32
    transform: Transform
    image_error: float64
    object_error: float64
    fiducial_area: float64


@message("fiducial_msgs/msg/FiducialTransformArray")
class FiducialTransformArray:
    header: Header
    image_seq: int32
    transforms: Seq[FiducialTransform]
