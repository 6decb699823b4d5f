"""Cameras: RGB (``libgazebo_ros_camera.so``) and depth (``libgazebo_ros_openni_kinect.so``,
``libgazebo_ros_depth_camera.so``), rendered headless by MuJoCo (EGL).

The sensor's ``<camera>`` gives ``horizontal_fov``, ``image`` width/height/format, ``clip``
near/far and Gaussian ``noise`` (mean, stddev in units of full intensity, per pixel and
channel, drawn from the engine's seeded generator). Gazebo cameras look along their link's +x
with +z up; the MuJoCo camera is rotated to match. Images are (H, W, 3) uint8 RGB; depth is
(H, W) float32 metres, NaN outside the point cloud cutoffs (as the Kinect plugin reports);
depth cameras also publish an organised XYZRGB point cloud in the optical convention of
``frameName`` (z along the view, x right, y down).

Beside ``<imageTopicName>`` the simulator node publishes ``<imageTopicName>/compressed`` as
image_transport's ``compressed`` plugin does (``vision.image_transport.compress_image``), so a
node reading ``camera/rgb/image_raw/compressed`` (aruco_detect with ``image_transport:
compressed``) works as on a ROS system. Nothing is rendered or encoded for topics nobody
subscribes to: the RGB image only while one of the camera's topics has a subscriber, the depth
image only while a depth or point cloud topic has one, the JPEG only while the compressed topic
has one.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import mujoco
import numpy as np

from fleetsim.errors import SimulationError
from fleetsim.runtime.params import param
from fleetsim.sim.build import COLLISION_GROUP, quat_from_rpy
from fleetsim.sim.plugins.base import ImageReading, SensorPlugin, register, require_link

# MuJoCo camera axes (x right, y up, looking along -z) expressed in a Gazebo camera link frame
_CAM_FROM_LINK = np.array([[0.0, 0.0, -1.0], [-1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])


@dataclass(frozen=True)
class CameraParams:
    cameraName: str = param("", help="namespace of the camera topics")
    imageTopicName: str = param("image_raw", help="image topic under cameraName")
    cameraInfoTopicName: str = param("camera_info", help="camera_info topic under cameraName")
    frameName: str = param("", help="optical frame id (tf_prefix applied)")
    updateRate: float = param(
        0.0, unit="Hz", range=(0.0, None), help="0: the sensor's <update_rate>"
    )
    hackBaseline: float = param(0.0, help="unused")
    distortionK1: float = param(0.0, help="unused")
    distortionK2: float = param(0.0, help="unused")
    distortionK3: float = param(0.0, help="unused")
    distortionT1: float = param(0.0, help="unused")
    distortionT2: float = param(0.0, help="unused")
    CxPrime: float = param(0.0, help="unused")
    Cx: float = param(0.0, help="unused")
    Cy: float = param(0.0, help="unused")
    focalLength: float = param(0.0, help="unused")


@dataclass(frozen=True)
class DepthCameraParams(CameraParams):
    depthImageTopicName: str = param("depth/image_raw", help="depth image topic")
    depthImageCameraInfoTopicName: str = param("depth/camera_info", help="depth camera_info")
    pointCloudTopicName: str = param("points", help="XYZRGB cloud topic (optical frame)")
    pointCloudCutoff: float = param(0.4, unit="m", range=(0.0, None), help="min valid depth")
    pointCloudCutoffMax: float = param(5.0, unit="m", range=(0.0, None), help="max valid depth")
    baseline: float = param(0.1, unit="m", help="unused")


def _get(d: dict | None, path: str, default):
    cur = d or {}
    for k in path.split("/"):
        if not isinstance(cur, dict) or k not in cur:
            return default
        cur = cur[k]
    return cur


@register("libgazebo_ros_camera.so")
class CameraPlugin(SensorPlugin):
    Params = CameraParams
    depth_enabled = False
    #: set by the simulator node: True while the images have subscribers (None: always render)
    wanted = None
    #: set by the simulator node: True while the depth topics have subscribers (None: always)
    depth_wanted = None

    def __init__(self, ctx, spec, sensor=None) -> None:
        super().__init__(ctx, spec, sensor)
        if sensor is None:
            raise SimulationError(f"{self.where}: a camera plugin must sit inside a <sensor>")
        cam = sensor.camera or {}
        w = f"{self.where} sensor '{sensor.name}'"
        try:
            self.hfov = float(_get(cam, "horizontal_fov", 1.047))
            self.width = int(_get(cam, "image/width", 320))
            self.height = int(_get(cam, "image/height", 240))
            self.near = float(_get(cam, "clip/near", 0.1))
            self.far = float(_get(cam, "clip/far", 100.0))
            noise = _get(cam, "noise/type", "none")
            self.noise_mean = float(_get(cam, "noise/mean", 0.0)) if noise == "gaussian" else 0.0
            self.noise_std = float(_get(cam, "noise/stddev", 0.0)) if noise == "gaussian" else 0.0
        except (TypeError, ValueError) as exc:
            raise SimulationError(f"{w}: camera fields must be numbers ({exc})") from None
        if self.noise_std < 0:
            raise SimulationError(f"{w}: camera noise stddev must be >= 0, got {self.noise_std}")
        if not (0 < self.hfov < math.pi) or self.width < 1 or self.height < 1:
            raise SimulationError(
                f"{w}: needs 0 < horizontal_fov < pi and a positive image "
                f"size; got {self.hfov}, {self.width}x{self.height}"
            )
        self.link = require_link(ctx, sensor.reference, "the sensor reference", spec.name)
        self.rate = self.params.updateRate or float(sensor.update_rate)
        self.cam_name = f"{ctx.model}/{sensor.name}"
        fx = (self.width / 2) / math.tan(self.hfov / 2)
        self.K = np.array(
            [[fx, 0, (self.width + 1) / 2], [0, fx, (self.height + 1) / 2], [0, 0, 1.0]]
        )
        base = self.params.cameraName.strip("/")
        self.topic = lambda t: f"{base}/{t}" if base else t
        self.frame_id = ctx.frame(self.params.frameName or self.link)

    @property
    def update_rate(self) -> float:
        return self.rate

    def build(self, spec, engine) -> None:
        body = spec.body(f"{self.ctx.model}/{self.link}")
        q_sensor = quat_from_rpy(*self.sensor.pose.rpy)
        q_cam = np.zeros(4)
        mujoco.mju_mat2Quat(q_cam, _CAM_FROM_LINK.flatten())
        q = np.zeros(4)
        mujoco.mju_mulQuat(q, q_sensor, q_cam)
        fovy = 2 * math.degrees(math.atan(math.tan(self.hfov / 2) * self.height / self.width))
        body.add_camera(name=self.cam_name, pos=list(self.sensor.pose.xyz), quat=q, fovy=fovy)
        w, h = spec.visual.global_.offwidth, spec.visual.global_.offheight
        spec.visual.global_.offwidth = max(w, self.width)
        spec.visual.global_.offheight = max(h, self.height)

    def bind(self, engine) -> None:
        self.cam_id = mujoco.mj_name2id(engine.model, mujoco.mjtObj.mjOBJ_CAMERA, self.cam_name)

    def render(self, engine, depth: bool = False) -> np.ndarray:
        """The current image: (H, W, 3) uint8 RGB, or (H, W) float32 depth in metres."""
        r = engine.renderer(self.width, self.height)
        opt = mujoco.MjvOption()
        opt.geomgroup[COLLISION_GROUP] = 0
        m = engine.model
        m.vis.map.znear = self.near / max(m.stat.extent, 1e-9)
        m.vis.map.zfar = self.far / max(m.stat.extent, 1e-9)
        r.update_scene(engine.data, camera=self.cam_id, scene_option=opt)
        if depth:
            r.enable_depth_rendering()
            img = r.render().astype(np.float32)
            r.disable_depth_rendering()
            return img
        return r.render().copy()

    def noisy(self, image: np.ndarray, rng: np.random.Generator) -> np.ndarray:
        """``image`` with the sensor's ``<noise>``: Gaussian, per pixel and channel, in units of
        full intensity (as Gazebo's camera noise model), rounded and clipped to 0..255."""
        if self.noise_std == 0 and self.noise_mean == 0:
            return image
        n = rng.standard_normal(image.shape, dtype=np.float32)
        n *= 255.0 * self.noise_std
        n += image
        if self.noise_mean:
            n += 255.0 * self.noise_mean
        # in place: the draws themselves are the cost (~12 ms a 640 x 480 RGB frame); copies
        # for each step doubled it
        np.rint(n, out=n)
        np.clip(n, 0, 255, out=n)
        return n.astype(np.uint8)

    def measure(self, engine, t: float) -> ImageReading | None:
        if self.wanted is not None and not self.wanted():
            return None  # nobody looks: skip the (software) rendering
        p = self.params
        reading = ImageReading(
            t,
            self.topic(p.imageTopicName),
            self.topic(p.cameraInfoTopicName),
            self.frame_id,
            "rgb8",
            self.noisy(self.render(engine), engine.rng),
            self.K,
        )
        if self.depth_enabled and (self.depth_wanted is None or self.depth_wanted()):
            d = self.render(engine, depth=True)
            d[(d < p.pointCloudCutoff) | (d > p.pointCloudCutoffMax)] = np.nan
            reading.depth = d
            reading.depth_topic = self.topic(p.depthImageTopicName)
            reading.depth_info_topic = self.topic(p.depthImageCameraInfoTopicName)
            reading.cloud_topic = self.topic(p.pointCloudTopicName)
        return reading


@register("libgazebo_ros_openni_kinect.so", "libgazebo_ros_depth_camera.so")
class DepthCameraPlugin(CameraPlugin):
    Params = DepthCameraParams
    depth_enabled = True
