"""fleetsim's aruco_marker model: DICT_4X4_50 id 0 that a camera reads from +x, hidden behind."""

import cv2
import numpy as np
import pytest
from PIL import Image

from fleetsim.sim import Engine
from fleetsim.sim.sdf import ASSET_MODELS, load_sdf_model

from .test_textures import assert_no_mujoco_warnings, render_from

#: what grobot's spawn_marker_on_robot sends to /gazebo/spawn_sdf_model
SPAWN_XML = (
    '<sdf version="1.6"><world name="default"><include><uri>model://aruco_marker</uri>'
    "</include></world></sdf>"
)


pytestmark = pytest.mark.usefixtures("in_tmp_dir")


def detect(image_rgb):
    detector = cv2.aruco.ArucoDetector(cv2.aruco.getPredefinedDictionary(cv2.aruco.DICT_4X4_50))
    corners, ids, _ = detector.detectMarkers(cv2.cvtColor(image_rgb, cv2.COLOR_RGB2BGR))
    return corners, ids


def test_texture_generator_draws_id_0_with_a_white_margin(tmp_path):
    import importlib.util

    spec = importlib.util.spec_from_file_location(
        "make_aruco_marker", ASSET_MODELS.parent / "make_aruco_marker.py"
    )
    gen = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(gen)
    gen.main(tmp_path / "m.png")
    drawn = cv2.imread(str(tmp_path / "m.png"), cv2.IMREAD_GRAYSCALE)
    shipped = cv2.imread(
        str(ASSET_MODELS / "aruco_marker/materials/textures/marker.png"), cv2.IMREAD_GRAYSCALE
    )
    np.testing.assert_array_equal(drawn, shipped)  # the committed texture is the script's
    cell = drawn.shape[0] // 8
    assert np.all(drawn[:cell] == 255) and np.all(drawn[:, -cell:] == 255)  # white margin
    assert np.all(drawn[cell : 2 * cell, cell:-cell] == 0)  # black border
    _, ids = detect(cv2.cvtColor(drawn, cv2.COLOR_GRAY2RGB))
    assert ids is not None and ids.ravel().tolist() == [0]
    assert pytest.approx(0.20) == gen.FACE_SIDE


def test_marker_reads_from_the_front_upright_and_is_hidden_from_behind(tmp_path):
    e = Engine(None)
    model = load_sdf_model(SPAWN_XML)
    assert model.name == "aruco_marker" and [g.name for g in model.links[0].geoms] == [
        "collision",
        "front_visual",
        "rear_visual",
    ]
    e.spawn_sdf("karl_marker", model, (0, 0, 0.3, 0, 0, 0))
    front = render_from(e, (0, 0, 0.3), 180.0, 0.8, (320, 240))  # from +x
    back = render_from(e, (0, 0, 0.3), 0.0, 0.8, (320, 240))  # from -x
    Image.fromarray(np.hstack([front, back])).save(tmp_path / "marker_front_back.png")
    assert_no_mujoco_warnings(e)
    corners, ids = detect(front)
    assert ids is not None and ids.ravel().tolist() == [0]
    c = corners[0][0]  # OpenCV's order: the marker's top left, top right, bottom right, left
    assert c[0, 0] < c[1, 0] and c[0, 1] < c[3, 1]  # upright, not mirrored
    # the black square is 0.15 m: its side in pixels at 0.8 m with MuJoCo's 45 degree view
    px = 240 / (2 * 0.8 * np.tan(np.radians(e.model.vis.global_.fovy) / 2))
    assert np.linalg.norm(c[1] - c[0]) == pytest.approx(0.15 * px, rel=0.05)
    # black and white cells, not the image's mean grey
    x0, y0 = c.min(axis=0).astype(int)
    x1, y1 = c.max(axis=0).astype(int)
    face = front[y0:y1, x0:x1].mean(axis=2)
    assert (face < 50).mean() > 0.4 and (face > 170).mean() > 0.1
    # from behind: a plain face, no marker
    _, back_ids = detect(back)
    assert back_ids is None
    plate = back[120 - 20 : 120 + 20, 160 - 20 : 160 + 20].mean(axis=2)
    assert plate.min() > 120 and np.ptp(plate) < 30
