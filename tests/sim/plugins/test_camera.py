"""Camera and depth camera rendered with MuJoCo's EGL backend."""

from pathlib import Path

import numpy as np
import pytest

from fleetsim.description import parse_urdf
from fleetsim.errors import SimulationError
from fleetsim.sim import Engine
from fleetsim.sim.plugins.base import ImageReading
from fleetsim.sim.world import GeomDesc, LinkDesc, ModelDesc, WorldDesc, ground_plane

from ..conftest import robot_text

CAMERA = """
  <gazebo reference="laser_link">
    <sensor type="{kind}" name="cam">
      <update_rate>5</update_rate>
      <camera><horizontal_fov>1.2</horizontal_fov>
        <image><width>64</width><height>48</height><format>R8G8B8</format></image>
        <clip><near>0.05</near><far>20</far></clip></camera>
      <plugin name="cam_plugin" filename="{filename}">
        <cameraName>front_camera</cameraName>
        <frameName>camera_optical</frameName>
      </plugin>
    </sensor>
  </gazebo>
</robot>"""


def camera_robot(kind, filename):
    text = robot_text("diffbot.urdf").replace(
        "</robot>", CAMERA.format(kind=kind, filename=filename)
    )
    return parse_urdf(text)


def red_wall_world():
    wall = ModelDesc(
        "wall",
        (2.0, 0, 0.5, 0, 0, 0),
        True,
        [
            LinkDesc(
                "link",
                geoms=[
                    GeomDesc("box", (0.1, 4, 1)),
                    GeomDesc("box", (0.1, 4, 1), collide=False, rgba=(1.0, 0.0, 0.0, 1.0)),
                ],
            )
        ],
    )
    return WorldDesc("w", [ground_plane(), wall])


def test_camera_sees_the_red_wall_ahead():
    e = Engine(red_wall_world())
    ent = e.spawn_robot("r", camera_robot("camera", "libgazebo_ros_camera.so"))
    images = [x for x in e.advance(0.3) if isinstance(x, ImageReading)]
    assert len(images) == 2  # 5 Hz over 0.3 s: t = 0, 0.2
    img = images[-1]
    assert img.image.shape == (48, 64, 3) and img.image.dtype == np.uint8
    assert img.topic == "front_camera/image_raw" and img.info_topic == "front_camera/camera_info"
    assert img.frame_id == "r/camera_optical"
    centre = img.image[20:28, 28:36].reshape(-1, 3).mean(axis=0)
    assert centre[0] > 100 and centre[0] > 2 * centre[1] and centre[0] > 2 * centre[2]
    assert img.K[0, 0] == pytest.approx(32 / np.tan(0.6))
    cam = next(p for p in ent.plugins if p.name == "cam_plugin")
    # turned around, the wall is out of view
    e.set_model_state("r", orientation=[0, 0, 0, 1])
    back = cam.render(e)
    assert back[20:28, 28:36, 0].mean() < centre[0] - 50


def test_depth_camera_measures_the_wall_distance():
    e = Engine(red_wall_world())
    e.spawn_robot("r", camera_robot("depth", "libgazebo_ros_openni_kinect.so"))
    (img,) = [x for x in e.advance(0.1) if isinstance(x, ImageReading)]
    assert img.depth is not None and img.depth.dtype == np.float32
    # camera at x = 0.1 (laser_link); the wall face at 2.0 - 0.05
    assert float(np.nanmedian(img.depth[20:28, 28:36])) == pytest.approx(1.85, abs=0.02)
    assert img.depth_topic == "front_camera/depth/image_raw"


def test_texture_reads_correctly_on_the_plus_x_face(tmp_path):
    from PIL import Image

    tex = np.zeros((64, 64, 3), np.uint8)
    tex[:, 32:] = 255  # right half white
    tex[:16, :32, 0] = 255  # top-left red
    Image.fromarray(tex).save(tmp_path / "tex.png")
    marker = ModelDesc(
        "marker",
        (1.0, 0, 0.3, 0, 0, np.pi),
        True,
        [
            LinkDesc(
                "link",
                geoms=[
                    GeomDesc(
                        "box", (0.01, 0.4, 0.4), collide=False, texture=str(tmp_path / "tex.png")
                    )
                ],
            )
        ],
    )
    e = Engine(WorldDesc("w", [ground_plane(), marker]))
    ent = e.spawn_robot("r", camera_robot("camera", "libgazebo_ros_camera.so"))
    img = next(p for p in ent.plugins if p.name == "cam_plugin").render(e).astype(float)
    # the marker covers columns ~24-44 and rows ~4-27 of the 64 x 48 image
    left, right = img[14:26, 25:31].mean(), img[14:26, 34:42].mean()
    assert right > left + 150
    top_left = img[7:10, 25:31].mean(axis=(0, 1))
    assert top_left[0] > 150 and top_left[1] < 80


WAFFLE = (
    Path(__file__).resolve().parents[3]
    / "src/fleetsim/assets/robots/turtlebot3_waffle/urdf/turtlebot3_waffle.urdf.xacro"
)
MARKER_XML = (
    '<sdf version="1.6"><world name="default"><include><uri>model://aruco_marker</uri>'
    "</include></world></sdf>"
)


def waffle_facing_a_marker(args=None):
    """A waffle in the root namespace (as the tutorial's follower) 1.5 m behind a marker that
    faces it; returns the runtime, the simulator node and the waffle's camera plugin."""
    from fleetsim.description import load_robot
    from fleetsim.runtime import Runtime
    from fleetsim.sim.node import Simulator
    from fleetsim.sim.plugins.camera import DepthCameraPlugin
    from fleetsim.sim.sdf import load_sdf_model

    rt = Runtime(seed=1)
    sim = Simulator(rt, "gazebo")
    entry = sim.spawn_robot("turtlebot3_waffle", load_robot(WAFFLE, args), namespace="/")
    marker = load_sdf_model(MARKER_XML)
    marker.static = True  # held in the air, facing the camera
    sim.engine.spawn_sdf("m", marker, (1.5, -0.05, 0.12, 0, 0, np.pi))
    cam = next(p for p in entry.plugins if isinstance(p, DepthCameraPlugin))
    return rt, sim, cam


def test_waffle_camera_topics_as_the_tutorial_reads_them(monkeypatch, tmp_path):
    import cv2

    from fleetsim.msgs import sensor_msgs
    from fleetsim.vision import image_transport

    monkeypatch.chdir(tmp_path)
    rt, sim, cam = waffle_facing_a_marker()
    assert (cam.width, cam.height, cam.rate) == (640, 360, 10.0)  # the xacro's defaults
    depth_renders, encodes = [], []
    original_render = cam.render
    cam.render = lambda e, depth=False: depth_renders.append(depth) or original_render(e, depth)
    original_encode = image_transport.compress_image
    monkeypatch.setattr(
        image_transport,
        "compress_image",
        lambda *a, **k: encodes.append(1) or original_encode(*a, **k),
    )
    raw, infos, jpegs = [], [], []
    rt.graph.subscribe("/camera/rgb/image_raw", sensor_msgs.Image, raw.append)
    rt.graph.subscribe("/camera/rgb/camera_info", sensor_msgs.CameraInfo, infos.append)
    rt.run(duration=0.25)
    assert len(raw) == 3 and encodes == []  # 10 Hz; no JPEG without a compressed subscriber
    assert not any(depth_renders)  # nor a depth image without a depth subscriber
    rt.graph.subscribe(
        "/camera/rgb/image_raw/compressed", sensor_msgs.CompressedImage, jpegs.append
    )
    rt.run(duration=0.2)
    assert len(jpegs) == 2 and len(encodes) == 2
    msg = jpegs[-1]
    assert msg.format == "rgb8; jpeg compressed bgr8"
    assert msg.header.frame_id == "camera_rgb_optical_frame"
    assert msg.header.stamp == raw[-1].header.stamp == infos[-1].header.stamp
    bgr = cv2.imdecode(np.asarray(msg.data, np.uint8), cv2.IMREAD_COLOR)
    rgb = np.asarray(raw[-1].data).reshape(360, 640, 3)
    assert bgr.shape == (360, 640, 3)
    assert np.abs(bgr[..., ::-1].astype(int) - rgb).mean() < 4  # JPEG of the same image
    cv2.imwrite(str(tmp_path / "waffle_view.png"), bgr)
    detector = cv2.aruco.ArucoDetector(cv2.aruco.getPredefinedDictionary(cv2.aruco.DICT_4X4_50))
    _, ids, _ = detector.detectMarkers(bgr)
    assert ids is not None and ids.ravel().tolist() == [0]  # the marker, read through JPEG
    k = np.asarray(infos[-1].k).reshape(3, 3)
    assert k[0, 0] == pytest.approx(320 / np.tan(1.3439 / 2))
    assert {i: w.number for i, w in enumerate(sim.engine.data.warning) if w.number} == {}
    assert not (tmp_path / "MUJOCO_LOG.TXT").exists()


def test_waffle_camera_resolution_and_rate_are_xacro_args():
    _, _, cam = waffle_facing_a_marker(
        {"camera_width": "1920", "camera_height": "1080", "camera_rate": "30"}
    )
    assert (cam.width, cam.height, cam.rate) == (1920, 1080, 30.0)  # the real camera


def test_gaussian_image_noise_as_the_sensor_declares_it():
    noisy_cam = CAMERA.replace(
        "<clip>", "<noise><type>gaussian</type><mean>0.0</mean><stddev>0.02</stddev></noise><clip>"
    )

    def robot(template):
        text = robot_text("diffbot.urdf").replace(
            "</robot>", template.format(kind="camera", filename="libgazebo_ros_camera.so")
        )
        return parse_urdf(text)

    images = []
    for _ in range(2):  # same seed, same noise
        e = Engine(red_wall_world(), rng=np.random.default_rng(7))
        ent = e.spawn_robot("r", robot(noisy_cam))
        cam = next(p for p in ent.plugins if p.name == "cam_plugin")
        (reading,) = [x for x in e.advance(0.1) if isinstance(x, ImageReading)]
        images.append(reading.image)
        clean = cam.render(e).astype(float)
    np.testing.assert_array_equal(images[0], images[1])
    diff = images[0].astype(float) - clean
    inside = (clean > 20) & (clean < 235)  # not clipped at 0 or 255
    assert diff[inside].std() == pytest.approx(0.02 * 255, rel=0.15)
    assert abs(diff[inside].mean()) < 0.5
    bad = CAMERA.replace("<clip>", "<noise><type>gaussian</type><stddev>-1</stddev></noise><clip>")
    with pytest.raises(SimulationError, match=r"camera noise stddev must be >= 0, got -1.0"):
        Engine(red_wall_world()).spawn_robot("r", robot(bad))


@pytest.mark.parametrize("mean", [0.0, 0.03, -0.02])
def test_noise_in_place_equals_the_reference_formula(mean):
    """`CameraPlugin.noisy` works in place for speed; it must equal the plain formula (draws
    scaled, the image and the mean added, rounded, clipped) byte for byte."""
    from types import SimpleNamespace

    from fleetsim.sim.plugins.camera import CameraPlugin

    image = np.random.default_rng(1).integers(0, 256, (48, 64, 3), dtype=np.uint8)
    cam = SimpleNamespace(noise_std=0.02, noise_mean=mean)
    got = CameraPlugin.noisy(cam, image, np.random.default_rng(5))
    draws = np.random.default_rng(5).standard_normal(image.shape, dtype=np.float32)
    want = np.clip(np.rint(draws * np.float32(255.0 * 0.02) + image + 255.0 * mean), 0, 255)
    assert got.dtype == np.uint8 and np.array_equal(got, want.astype(np.uint8))
    assert (got == 0).any() or (got == 255).any()  # the clip is exercised


def test_every_shipped_robots_cameras_render_without_a_mujoco_warning(tmp_path, monkeypatch):
    """The physics tests mark sensors unread; here every camera of every shipped robot renders
    (and is noised) once, with no MuJoCo warning (a scene out of geometry slots, for one) and
    no MUJOCO_LOG.TXT."""
    from fleetsim.description import load_robot
    from fleetsim.sim.plugins.camera import CameraPlugin

    monkeypatch.chdir(tmp_path)
    robots = Path(__file__).resolve().parents[3] / "src" / "fleetsim" / "assets" / "robots"
    seen = 0
    for path in sorted(robots.glob("*/urdf/*.urdf.xacro")):
        e = Engine(WorldDesc("w", [ground_plane()]))
        entry = e.spawn_robot("r", load_robot(path))
        cams = [p for p in entry.plugins if isinstance(p, CameraPlugin)]
        images = [x for x in e.advance(0.1) if isinstance(x, ImageReading)]
        assert len({r.topic for r in images}) >= len(cams), path.parts[-3]
        assert not e.data.warning.number.any(), path.parts[-3]
        seen += len(cams)
        e.close()
    assert seen >= 4  # the hunter's four, at least
    assert not (tmp_path / "MUJOCO_LOG.TXT").exists()
