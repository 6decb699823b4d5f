"""The ``aruco_detect`` node (UbiquityRobotics/fiducials): ArUco markers in camera images.

Subscribes to ``camera`` through image_transport (``~image_transport``: ``raw`` reads
``camera`` as sensor_msgs/Image, ``compressed`` reads ``camera/compressed``, so the tutorial's
remap of ``/camera/compressed`` works) and to ``camera_info``, whose first message gives the
intrinsics K, D and the frame every output is stamped in. For every image it publishes
``fiducial_vertices`` (FiducialArray: each marker's corners) and, with ``do_pose_estimation``,
``fiducial_transforms`` (FiducialTransformArray: each marker's pose in the optical frame), both
with the image's stamp and both also when nothing was seen: followers detect a lost marker from
the empty arrays. Ids listed in ``ignore_fiducials`` (or later on the ``ignore_fiducials``
topic, std_msgs/String) are left out. With ``publish_fiducial_tf`` each pose also goes to tf as
``<camera frame> -> fiducial_<id>``; with ``publish_images`` the image with the markers and
their axes drawn goes to ``/fiducial_images``. The ``enable_detections`` service
(std_srvs/SetBool) switches the processing off and on.

Unlike the package, a camera_info whose K is all zeros (or has a zero focal length) is an error
naming the topic, not a warning repeated for every frame; malformed id lists and overrides, and
ids the dictionary does not hold, are errors naming the parameter.

Cost (figures: ``benchmarks/visual_servoing.py``, README): about 94 % of a frame's CPU is
OpenCV's detection, which with the package's 13 adaptive-threshold windows (3..53 px) thresholds
the image and traces its contours 13 times. OpenCV runs the windows as a parallel_for on every
core (its default thread count, which the node leaves alone): on 2 idle cores that divides the
wall time by 1.85 for 7 % more CPU. A compressed image is decoded straight to grey (libjpeg's
luma, which can differ from cv_bridge's BGR-to-grey by up to 14 levels at colour edges; corners
moved by at most 0.02 px on 1,200 rendered frames), and to colour only while
``/fiducial_images`` has a subscriber; a frame without markers skips the pose arrays.
"""

from __future__ import annotations

from typing import Any

import cv2
import numpy as np

from fleetsim.errors import ParameterError
from fleetsim.msgs import fiducial_msgs, geometry_msgs, sensor_msgs, std_msgs, std_srvs
from fleetsim.runtime import Node
from fleetsim.tf import TransformBroadcaster, make_transform_stamped
from fleetsim.vision.aruco_params import ArucoDetectParams, detector_parameters
from fleetsim.vision.errors import VisionError
from fleetsim.vision.fiducials import (
    DICTIONARIES,
    aruco_dictionary,
    dictionary_size,
    fiducial_areas,
    marker_poses,
    object_errors,
    parse_id_list,
    parse_len_override,
    quaternions_from_rotvecs,
)
from fleetsim.vision.image_transport import bgr_array, decompressed_array, gray_array, image_message

#: images before a missing camera_info is reported (the package's frameNum > 5)
FRAMES_BEFORE_NO_INTRINSICS = 5
#: s of sim time without any image before that is reported (and again every NO_IMAGES_AGAIN s)
NO_IMAGES_TIME, NO_IMAGES_AGAIN = 5.0, 30.0

#: what a frame without markers yields (empty, so sharing them between frames is safe)
_NO_CORNERS = np.zeros((0, 4, 2), np.float32)
_NO_IDS = np.zeros(0, np.int64)
_NO_VECS = np.zeros((0, 3))


#: images in a row without a marker after which the other dictionaries are tried, once each
DICTIONARY_CHECKS = (30, 300, 3000)


class ArucoDetect(Node):
    """Detects ArUco markers and estimates their poses, one image at a time."""

    Params = ArucoDetectParams

    def __init__(self, runtime, name: str = "aruco_detect", namespace: str = "/", **kw: Any):
        super().__init__(runtime, name, namespace, **kw)
        p: ArucoDetectParams = self.params
        where = self.full_name
        if p.adaptiveThreshWinSizeMax < p.adaptiveThreshWinSizeMin:
            raise ParameterError(
                f"{where}: parameter 'adaptiveThreshWinSizeMax' ({p.adaptiveThreshWinSizeMax}) "
                f"is below 'adaptiveThreshWinSizeMin' ({p.adaptiveThreshWinSizeMin})"
            )
        self.dictionary = aruco_dictionary(p.dictionary, f"{where}: parameter 'dictionary'")
        self.dictionary_size = dictionary_size(p.dictionary)
        self.ignore_ids = self._parsed("ignore_fiducials", parse_id_list)
        self.len_override = self._parsed("fiducial_len_override", parse_len_override)
        self.detector = cv2.aruco.ArucoDetector(self.dictionary, detector_parameters(p))
        self.enabled = True
        self.frames = 0  # images processed (image_seq)
        self.camera_matrix: np.ndarray | None = None
        self.dist_coeffs = np.zeros(5)
        self.frame_id = ""
        self._warned_intrinsics = False
        self._empty = 0  # images in a row without a marker
        self._warned_dictionary = False

        self.vertices_pub = self.create_publisher(
            fiducial_msgs.FiducialArray, "fiducial_vertices", 1
        )
        self.transforms_pub = self.create_publisher(
            fiducial_msgs.FiducialTransformArray, "fiducial_transforms", 1
        )
        self.images_pub = (
            self.create_publisher(sensor_msgs.Image, "/fiducial_images", 1)
            if p.publish_images
            else None
        )
        self.tf_pub = TransformBroadcaster(self) if p.publish_fiducial_tf else None
        base = self.resolve_name("camera")
        if p.image_transport == "compressed":
            self.image_topic = self.resolve_name(f"{base}/compressed")
            self._image_sub = self.create_subscription(
                sensor_msgs.CompressedImage, self.image_topic, self.on_compressed, 1
            )
        else:
            self.image_topic = base
            self._image_sub = self.create_subscription(sensor_msgs.Image, base, self.on_image, 1)
        self.info_topic = self.resolve_name("camera_info")
        self._info_sub = self.create_subscription(
            sensor_msgs.CameraInfo, self.info_topic, self.on_camera_info, 1
        )
        self.create_subscription(std_msgs.String, "ignore_fiducials", self.on_ignore, 1)
        self.create_service(std_srvs.SetBool, "enable_detections", self.on_enable)
        self._got_image = False
        self._no_image_ticks = 0
        self._no_images = self.create_timer(NO_IMAGES_TIME, self._check_images)

    def _parsed(self, name: str, parse: Any) -> Any:
        """Parameter ``name`` (a string of ids) parsed against the dictionary by ``parse``; an
        error names the file and line that set it."""
        where = f"{self.full_name}: parameter '{name}'"
        try:
            return parse(getattr(self.params, name), self.dictionary_size, where)
        except ParameterError as e:
            raise ParameterError(f"{e}{self.param_origin(name)}") from None

    def _check_images(self) -> None:
        """Say so while no image has come, at NO_IMAGES_TIME s and every NO_IMAGES_AGAIN s (the
        package waits in silence: a follower on a robot without a camera, or a remap that misses
        it, then never acts and nothing tells why)."""
        if self._got_image:
            self._no_images.cancel()
            return
        self._no_image_ticks += 1
        if (self._no_image_ticks - 1) % round(NO_IMAGES_AGAIN / NO_IMAGES_TIME):
            return
        self.get_logger().warning(
            f"no image on {self.image_topic} for {self._no_image_ticks * NO_IMAGES_TIME:.0f} s"
            f"{self.unpublished_hint(self._image_sub)}: does this robot have a camera, and do the "
            "remaps (and ~image_transport) lead to it?"
        )

    # -- inputs --------------------------------------------------------------------------------
    def on_camera_info(self, msg: sensor_msgs.CameraInfo) -> None:
        """Latch K, D and the frame from the first camera_info (as the package does)."""
        if self.camera_matrix is not None:
            return
        k = np.asarray(msg.k, dtype=np.float64).reshape(3, 3)
        if not np.all(np.isfinite(k)) or k[0, 0] <= 0 or k[1, 1] <= 0 or k[2, 2] == 0:
            state = "all zeros" if not np.any(k) else f"fx={k[0, 0]}, fy={k[1, 1]}, {k[2, 2]}"
            raise VisionError(
                f"{self.full_name}: camera_info on {self.info_topic} (frame "
                f"'{msg.header.frame_id}') has invalid intrinsics: K is {state}; the camera "
                "plugin must publish a calibrated K (fx, fy > 0)"
            )
        d = np.asarray(msg.d, dtype=np.float64)[:5]
        self.dist_coeffs = np.concatenate([d, np.zeros(5 - len(d))])
        self.camera_matrix = k
        self.frame_id = msg.header.frame_id

    def on_ignore(self, msg: std_msgs.String) -> None:
        """A new ``ignore_fiducials`` list at run time (a malformed one is logged and skipped)."""
        try:
            ids = parse_id_list(
                msg.data, self.dictionary_size, f"{self.full_name}: ignore_fiducials"
            )
        except ParameterError as err:
            self.get_logger().error(str(err))
            return
        self.ignore_ids = ids
        self.set_param("~ignore_fiducials", msg.data)

    def on_enable(self, req: Any) -> Any:
        self.enabled = bool(req.data)
        text = f"{'Enabled' if self.enabled else 'Disabled'} aruco detections."
        self.get_logger().info(text)
        return std_srvs.SetBool.Response(success=True, message=text)

    def on_image(self, msg: sensor_msgs.Image) -> None:
        self._got_image = True
        if self.enabled:
            gray = gray_array(msg, self.image_topic)
            self.process(gray, msg.header.stamp, lambda: bgr_array(msg, self.image_topic))

    def on_compressed(self, msg: sensor_msgs.CompressedImage) -> None:
        self._got_image = True
        if self.enabled:
            # detection always reads the JPEG decoded straight to grey: decoding to colour and
            # converting gives grey levels up to 14 apart, so deriving it from the colour image
            # when someone watches /fiducial_images (a recorder, a viewer) changed detections
            # and the whole run; the colour decode is for drawing only
            gray = decompressed_array(msg, self.image_topic, gray=True)
            self.process(gray, msg.header.stamp, lambda: decompressed_array(msg, self.image_topic))

    # -- processing ----------------------------------------------------------------------------
    def detect(self, gray: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Markers in a grey image: (N, 4, 2) float32 corners and (N,) ids, ignored ids left out."""
        corners, ids, _ = self.detector.detectMarkers(gray)
        if ids is None or len(ids) == 0:
            return _NO_CORNERS, _NO_IDS
        ids = ids.reshape(-1).astype(np.int64)
        corners = np.asarray(corners, dtype=np.float32).reshape(-1, 4, 2)
        if not self.ignore_ids:
            return corners, ids
        keep = np.array([i not in self.ignore_ids for i in ids], dtype=bool)
        return corners[keep], ids[keep]

    def _other_dictionaries(self, gray: np.ndarray) -> None:
        """After `DICTIONARY_CHECKS` images in a row without a marker, look for markers of the
        other dictionaries in this one: aruco_detect finds nothing of a marker printed from
        another dictionary, and says nothing (a DICT_6X6 marker with ``dictionary`` 0)."""
        p: ArucoDetectParams = self.params
        for i, name in enumerate(DICTIONARIES):
            if i == p.dictionary:
                continue
            other = cv2.aruco.ArucoDetector(aruco_dictionary(i), detector_parameters(p))
            _, ids, _ = other.detectMarkers(gray)
            if ids is not None and len(ids):
                self._warned_dictionary = True
                found = ", ".join(str(int(k)) for k in sorted(set(ids.reshape(-1).tolist())))
                self.get_logger().warning(
                    f"no marker of dictionary {p.dictionary} ({DICTIONARIES[p.dictionary]}) in "
                    f"{self._empty} images, but this one holds markers of dictionary {i} "
                    f"({name}), ids {found}: is the 'dictionary' parameter the markers'?"
                )
                return

    def process(self, gray: np.ndarray, stamp: Any, colour) -> None:
        """Detect, publish vertices, estimate and publish poses, for one image."""
        self.frames += 1
        p: ArucoDetectParams = self.params
        header = std_msgs.Header(stamp=stamp, frame_id=self.frame_id)
        corners, ids = self.detect(gray)
        self._empty = 0 if len(ids) else self._empty + 1
        if self._empty in DICTIONARY_CHECKS and not self._warned_dictionary:
            self._other_dictionaries(gray)
        self.vertices_pub.publish(
            fiducial_msgs.FiducialArray(
                header=header,
                image_seq=self.frames,
                fiducials=[_fiducial(int(i), c) for i, c in zip(ids, corners)],
            )
        )
        if p.verbose:
            self.get_logger().info(f"image {self.frames}: detected {len(ids)} markers")
        poses = None
        if p.do_pose_estimation:
            if self.camera_matrix is None:
                if self.frames > FRAMES_BEFORE_NO_INTRINSICS and not self._warned_intrinsics:
                    self._warned_intrinsics = True
                    self.get_logger().error(
                        f"No camera intrinsics: nothing on {self.info_topic} after "
                        f"{self.frames} images on {self.image_topic}"
                        f"{self.unpublished_hint(self._info_sub)}; no fiducial_transforms"
                    )
                self._publish_image(colour, corners, ids, None, header)
                return
            poses = self._estimate(corners, ids)
        self.transforms_pub.publish(
            fiducial_msgs.FiducialTransformArray(
                header=header, image_seq=self.frames, transforms=poses[0] if poses else []
            )
        )
        if poses and self.tf_pub is not None and poses[0]:
            self.tf_pub.send_transform(
                [
                    make_transform_stamped(
                        self.frame_id,
                        f"fiducial_{ft.fiducial_id}",
                        stamp,
                        _xyz(ft.transform.translation),
                        _xyzw(ft.transform.rotation),
                    )
                    for ft in poses[0]
                ]
            )
        self._publish_image(colour, corners, ids, poses, header)

    def _estimate(self, corners: np.ndarray, ids: np.ndarray):
        if len(ids) == 0:  # most frames: nothing to solve, skip the array work
            return [], _NO_VECS, _NO_VECS
        p: ArucoDetectParams = self.params
        lengths = np.array([self.len_override.get(int(i), p.fiducial_len) for i in ids])
        rvecs, tvecs, img_err = marker_poses(corners, lengths, self.camera_matrix, self.dist_coeffs)
        ok = np.isfinite(img_err)
        obj_err = object_errors(img_err, corners, tvecs, p.fiducial_len)
        areas = fiducial_areas(corners)
        quats = quaternions_from_rotvecs(rvecs)
        out = [
            fiducial_msgs.FiducialTransform(
                fiducial_id=int(ids[i]),
                transform=geometry_msgs.Transform(
                    translation=geometry_msgs.Vector3(*map(float, tvecs[i])),
                    rotation=geometry_msgs.Quaternion(*map(float, quats[i])),
                ),
                image_error=float(img_err[i]),
                object_error=float(obj_err[i]),
                fiducial_area=float(areas[i]),
            )
            for i in range(len(ids))
            if ok[i]
        ]
        return out, rvecs, tvecs

    def _publish_image(self, colour, corners, ids, poses, header) -> None:
        if self.images_pub is None or colour is None or self.images_pub.get_num_connections() == 0:
            return
        img = colour()
        if len(ids):
            cv2.aruco.drawDetectedMarkers(
                img, list(corners.reshape(-1, 1, 4, 2)), ids.reshape(-1, 1)
            )
        if poses is not None:
            # OpenCV writes a WARN line to stderr for every axis drawn past the image's edge (a
            # marker near the edge, every frame): the drawing is clipped as it should be
            level = cv2.utils.logging.getLogLevel()
            cv2.utils.logging.setLogLevel(cv2.utils.logging.LOG_LEVEL_ERROR)
            try:
                for rvec, tvec in zip(poses[1], poses[2]):
                    cv2.drawFrameAxes(
                        img, self.camera_matrix, self.dist_coeffs, rvec, tvec,
                        self.params.fiducial_len,
                    )  # fmt: skip
            finally:
                cv2.utils.logging.setLogLevel(level)
        self.images_pub.publish(image_message(img, "bgr8", header))


def _fiducial(fid: int, c: np.ndarray) -> fiducial_msgs.Fiducial:
    c = c.astype(np.float64)
    return fiducial_msgs.Fiducial(
        fiducial_id=fid,
        x0=c[0, 0], y0=c[0, 1], x1=c[1, 0], y1=c[1, 1],
        x2=c[2, 0], y2=c[2, 1], x3=c[3, 0], y3=c[3, 1],
    )  # fmt: skip


def _xyz(v) -> tuple[float, float, float]:
    return (v.x, v.y, v.z)


def _xyzw(q) -> tuple[float, float, float, float]:
    return (q.x, q.y, q.z, q.w)
