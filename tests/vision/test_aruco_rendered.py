"""aruco_detect on images the simulator renders: the tutorial's marker (model://aruco_marker,
attached by spawn_marker_on_robot) on burgers 1-3 m in front of the waffle's camera at the real
camera's 1920x1080; every pose within 2 cm and 2 degrees of the simulator's ground truth."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from fleetsim.apps.spawn_marker_on_robot import SpawnMarkerOnRobot
from fleetsim.description.robot_state_publisher import RobotStatePublisher
from fleetsim.description.urdf import urdf_text
from fleetsim.msgs import fiducial_msgs, gazebo_msgs, geometry_msgs
from fleetsim.runtime import Node, Runtime
from fleetsim.sim.build import quat_from_rpy
from fleetsim.sim.node import Simulator
from fleetsim.vision.aruco_detect import ArucoDetect

ROBOTS = Path(__file__).resolve().parents[2] / "src" / "fleetsim" / "assets" / "robots"
WAFFLE = ROBOTS / "turtlebot3_waffle/urdf/turtlebot3_waffle.urdf.xacro"
BURGER = ROBOTS / "turtlebot3_burger/urdf/turtlebot3_burger.urdf.xacro"
OPTICAL = "camera_rgb_optical_frame"
#: the ArUco frame (x right, y up, z out of the face) in the marker model's frame (face on +x)
ARUCO_IN_MODEL = Rotation.from_matrix(np.array([[0, 0, 1], [1, 0, 0], [0, 1, 0]], float))


@pytest.fixture(autouse=True)
def in_tmp_dir(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)  # where MuJoCo would write MUJOCO_LOG.TXT
    yield
    assert not (tmp_path / "MUJOCO_LOG.TXT").exists()


def pose(x: float, y: float, yaw: float) -> geometry_msgs.Pose:
    w, qx, qy, qz = quat_from_rpy(0.0, 0.0, yaw)
    return geometry_msgs.Pose(
        position=geometry_msgs.Point(x=x, y=y),
        orientation=geometry_msgs.Quaternion(x=qx, y=qy, z=qz, w=w),
    )


def world_pose(engine, model: str) -> tuple[np.ndarray, Rotation]:
    pos, q = engine.model_pose(model)  # quaternion w, x, y, z
    return np.asarray(pos, float), Rotation.from_quat([q[1], q[2], q[3], q[0]])


@pytest.mark.parametrize(
    "burgers",
    [
        # (x, y, heading): each burger faces away, its marker toward the camera, seen at an angle
        [(1.0, -0.35, 0.5), (2.0, 0.3, -0.35), (3.0, 1.1, 0.3)],
        [(1.5, -0.2, -0.6), (2.5, 0.35, 0.45)],
    ],
)
def test_rendered_marker_poses_match_ground_truth(burgers):
    rt = Runtime(seed=1)
    sim = Simulator(rt, "gazebo")
    probe = Node(rt, "probe")
    spawn = probe.create_client(gazebo_msgs.SpawnModel, "/gazebo/spawn_urdf_model")
    waffle = urdf_text(WAFFLE, {"camera_width": "1920", "camera_height": "1080"})[0]
    resp = spawn.call(
        gazebo_msgs.SpawnModel.Request(
            model_name="turtlebot3_waffle", model_xml=waffle, robot_namespace="/",
            initial_pose=pose(0.0, 0.0, 0.0),
        )
    )  # fmt: skip
    assert resp.success, resp.status_message
    rt.params.set("/robot_description", waffle)
    _ = rt.tf_buffer  # listening before the static transforms go out
    RobotStatePublisher(rt)
    burger = urdf_text(BURGER)[0]
    names = [f"b{i}" for i in range(len(burgers))]
    for name, (x, y, yaw) in zip(names, burgers):
        resp = spawn.call(
            gazebo_msgs.SpawnModel.Request(
                model_name=name, model_xml=burger, robot_namespace=f"/{name}",
                initial_pose=pose(x, y, yaw),
            )
        )  # fmt: skip
        assert resp.success, resp.status_message
        SpawnMarkerOnRobot(rt, namespace=f"/{name}")
    ArucoDetect(
        rt,
        params={"dictionary": 0, "fiducial_len": 0.15},
        remaps={"camera": "/camera/rgb/image_raw", "camera_info": "/camera/rgb/camera_info"},
    )
    seen: list = []
    probe.create_subscription(
        fiducial_msgs.FiducialTransformArray, "/fiducial_transforms", seen.append, 0
    )
    rt.run(duration=0.45)
    msg = seen[-1]
    assert msg.header.frame_id == OPTICAL
    assert len(msg.transforms) == len(burgers)
    # ground truth: the camera's optical frame and each marker's ArUco frame in the world
    t_wb, r_wb = world_pose(sim.engine, "turtlebot3_waffle")
    t_bc, q_bc = rt.tf_buffer.lookup_arrays("base_footprint", OPTICAL, 0.0)
    r_wc = r_wb * Rotation.from_quat(q_bc)
    t_wc = t_wb + r_wb.apply(t_bc)
    truths = []
    for name in names:
        t_wm, r_wm = world_pose(sim.engine, f"{name}_marker")
        truths.append((r_wc.inv().apply(t_wm - t_wc), r_wc.inv() * r_wm * ARUCO_IN_MODEL))
    for ft in msg.transforms:
        tr, q = ft.transform.translation, ft.transform.rotation
        t = np.array([tr.x, tr.y, tr.z])
        t_true, r_true = min(truths, key=lambda tr_: np.linalg.norm(tr_[0] - t))
        assert 0.9 < np.linalg.norm(t_true) < 3.3
        assert np.linalg.norm(t - t_true) < 0.02, (t, t_true)
        angle = (Rotation.from_quat([q.x, q.y, q.z, q.w]).inv() * r_true).magnitude()
        assert np.degrees(angle) < 2.0, (np.degrees(angle), t_true)
    warnings = {i: w.number for i, w in enumerate(sim.engine.data.warning) if w.number}
    assert warnings == {}
