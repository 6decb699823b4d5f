"""Vision: the ``aruco_detect`` node, ArUco detection and pose, image transport helpers."""

from fleetsim.vision.aruco_detect import ArucoDetect
from fleetsim.vision.aruco_params import ArucoDetectParams, detector_parameters
from fleetsim.vision.errors import VisionError
from fleetsim.vision.fiducials import (
    DICTIONARIES,
    aruco_dictionary,
    fiducial_areas,
    marker_object_points,
    marker_poses,
    object_errors,
    parse_id_list,
    parse_len_override,
    quaternions_from_rotvecs,
)
from fleetsim.vision.image_transport import (
    compress_image,
    decompressed_array,
    gray_array,
    image_array,
    image_message,
)

__all__ = [
    "DICTIONARIES",
    "ArucoDetect",
    "ArucoDetectParams",
    "VisionError",
    "aruco_dictionary",
    "compress_image",
    "decompressed_array",
    "detector_parameters",
    "fiducial_areas",
    "gray_array",
    "image_array",
    "image_message",
    "marker_object_points",
    "marker_poses",
    "object_errors",
    "parse_id_list",
    "parse_len_override",
    "quaternions_from_rotvecs",
]
