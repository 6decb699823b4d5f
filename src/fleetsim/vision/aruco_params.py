"""``aruco_detect``'s parameters: names and defaults of UbiquityRobotics/fiducials.

General parameters as ``aruco_detect.cpp`` reads them (``pnh.param``); the detector parameters
with the node's own defaults (which the package tuned for a Raspberry Pi and which differ from
OpenCV's: 13 adaptive-threshold windows from 3 to 53 px instead of 3, sub-pixel corner
refinement), mapped onto `cv2.aruco.DetectorParameters` by `detector_parameters`.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2

from fleetsim.runtime.params import param
from fleetsim.vision.fiducials import DICTIONARIES


@dataclass(frozen=True)
class ArucoDetectParams:
    """aruco_detect private parameters (ROS names and defaults)."""

    publish_images: bool = param(False, help="publish the annotated image on /fiducial_images")
    fiducial_len: float = param(0.14, unit="m", range=(1e-6, None), help="marker side length")
    dictionary: int = param(
        7,
        choices=tuple(range(len(DICTIONARIES))),
        help="ArUco dictionary: " + ", ".join(f"{i} {n}" for i, n in enumerate(DICTIONARIES)),
    )
    do_pose_estimation: bool = param(True, help="estimate and publish fiducial_transforms")
    publish_fiducial_tf: bool = param(True, help="broadcast tf <camera frame> -> fiducial_<id>")
    ignore_fiducials: str = param("", help="ids not reported, e.g. '1,4,8,9-12'")
    fiducial_len_override: str = param("", help="per-id side lengths, e.g. '1-10: 0.05, 12: 0.06'")
    image_transport: str = param(
        "raw", choices=("raw", "compressed"), help="how 'camera' is read (image_transport's)"
    )
    verbose: bool = param(False, help="log every image and detection")
    # detector parameters (cv::aruco::DetectorParameters), the node's defaults
    adaptiveThreshConstant: float = param(7.0, help="constant subtracted in adaptive threshold")
    adaptiveThreshWinSizeMin: int = param(3, unit="px", range=(3, None), help="smallest window")
    adaptiveThreshWinSizeMax: int = param(53, unit="px", range=(3, None), help="largest window")
    adaptiveThreshWinSizeStep: int = param(4, unit="px", range=(1, None), help="window step")
    cornerRefinementMaxIterations: int = param(30, range=(1, None), help="refinement iterations")
    cornerRefinementMinAccuracy: float = param(
        0.01, unit="px", range=(0.0, None), help="refinement stop criterion"
    )
    cornerRefinementWinSize: int = param(5, unit="px", range=(1, None), help="refinement window")
    doCornerRefinement: bool = param(True, help="refine corners (false: none)")
    cornerRefinementSubPix: bool = param(
        True,
        aliases=("cornerRefinementSubpix",),
        help="sub-pixel refinement (false: contour refinement)",
    )
    errorCorrectionRate: float = param(0.6, range=(0.0, 1.0), help="bits corrected, of maximum")
    minCornerDistanceRate: float = param(0.05, range=(0.0, None), help="of the perimeter")
    markerBorderBits: int = param(1, range=(1, None), help="border width in bits")
    maxErroneousBitsInBorderRate: float = param(0.04, range=(0.0, 1.0), help="of border bits")
    minDistanceToBorder: int = param(3, unit="px", range=(0, None), help="to the image edge")
    minMarkerDistanceRate: float = param(0.05, range=(0.0, None), help="of the perimeter")
    minMarkerPerimeterRate: float = param(0.1, range=(0.0, None), help="of the image's max side")
    maxMarkerPerimeterRate: float = param(4.0, range=(0.0, None), help="of the image's max side")
    minOtsuStdDev: float = param(5.0, range=(0.0, None), help="grey-level spread to decode")
    perspectiveRemoveIgnoredMarginPerCell: float = param(
        0.13, range=(0.0, 0.5), help="cell margin ignored when reading bits"
    )
    perspectiveRemovePixelPerCell: int = param(8, unit="px", range=(1, None), help="per cell")
    polygonalApproxAccuracyRate: float = param(0.01, range=(0.0, None), help="of the perimeter")


#: detector parameters copied as they are onto cv2.aruco.DetectorParameters
_DIRECT = (
    "adaptiveThreshConstant",
    "adaptiveThreshWinSizeMin",
    "adaptiveThreshWinSizeMax",
    "adaptiveThreshWinSizeStep",
    "cornerRefinementMaxIterations",
    "cornerRefinementMinAccuracy",
    "cornerRefinementWinSize",
    "errorCorrectionRate",
    "minCornerDistanceRate",
    "markerBorderBits",
    "maxErroneousBitsInBorderRate",
    "minDistanceToBorder",
    "minMarkerDistanceRate",
    "minMarkerPerimeterRate",
    "maxMarkerPerimeterRate",
    "minOtsuStdDev",
    "perspectiveRemoveIgnoredMarginPerCell",
    "perspectiveRemovePixelPerCell",
    "polygonalApproxAccuracyRate",
)


def detector_parameters(p: ArucoDetectParams) -> cv2.aruco.DetectorParameters:
    """OpenCV detector parameters from the node's (refinement method as aruco_detect picks it)."""
    out = cv2.aruco.DetectorParameters()
    for name in _DIRECT:
        setattr(out, name, getattr(p, name))
    if not p.doCornerRefinement:
        out.cornerRefinementMethod = cv2.aruco.CORNER_REFINE_NONE
    elif p.cornerRefinementSubPix:
        out.cornerRefinementMethod = cv2.aruco.CORNER_REFINE_SUBPIX
    else:
        out.cornerRefinementMethod = cv2.aruco.CORNER_REFINE_CONTOUR
    return out
