"""Camera and depth camera rendered with MuJoCo's EGL backend."""

import numpy as np
import pytest

from fleetsim.description import parse_urdf
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
