from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from fleetsim.apps.spawn_marker_on_robot import SpawnMarkerOnRobot
from fleetsim.description.urdf import urdf_text
from fleetsim.errors import ServiceError
from fleetsim.msgs import gazebo_msgs, geometry_msgs
from fleetsim.runtime import Node, Runtime
from fleetsim.sim.build import quat_from_rpy
from fleetsim.sim.node import Simulator

ROBOTS = Path(__file__).resolve().parents[2] / "src" / "fleetsim" / "assets" / "robots"
BURGER = ROBOTS / "turtlebot3_burger/urdf/turtlebot3_burger.urdf.xacro"


@pytest.fixture(autouse=True)
def in_tmp_dir(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)  # where MuJoCo would write MUJOCO_LOG.TXT
    yield
    assert not (tmp_path / "MUJOCO_LOG.TXT").exists()


def spawn_burger(probe: Node, name: str, x: float, y: float, yaw: float) -> None:
    w, qx, qy, qz = quat_from_rpy(0.0, 0.0, yaw)
    resp = probe.create_client(gazebo_msgs.SpawnModel, "/gazebo/spawn_urdf_model").call(
        gazebo_msgs.SpawnModel.Request(
            model_name=name,
            model_xml=urdf_text(BURGER)[0],
            robot_namespace=f"/{name}",
            initial_pose=geometry_msgs.Pose(
                position=geometry_msgs.Point(x=x, y=y),
                orientation=geometry_msgs.Quaternion(x=qx, y=qy, z=qz, w=w),
            ),
        )
    )
    assert resp.success, resp.status_message


def relative_state(probe: Node, model: str, ref: str) -> tuple[np.ndarray, float]:
    st = probe.create_client(gazebo_msgs.GetModelState, "/gazebo/get_model_state").call(
        gazebo_msgs.GetModelState.Request(model_name=model, relative_entity_name=ref)
    )
    assert st.success, st.status_message
    q = st.pose.orientation
    yaw = np.arctan2(2 * (q.w * q.z + q.x * q.y), 1 - 2 * (q.y**2 + q.z**2))
    p = st.pose.position
    return np.array([p.x, p.y, p.z]), float(yaw)


def test_waits_for_the_robot_then_marker_rides_at_the_tutorials_pose():
    rt = Runtime(seed=1)
    sim = Simulator(rt, "gazebo")
    probe = Node(rt, "probe")
    node = SpawnMarkerOnRobot(rt, namespace="/karl")
    rt.run(duration=0.5)
    assert not node.done  # no karl yet: it waits
    spawn_burger(probe, "karl", -2.0, 2.0, 0.7)  # turned: the pose is relative to the robot
    rt.run(duration=0.5)
    assert node.done
    assert sim.engine.models["karl_marker"].namespace == "/karl"
    cmd = probe.create_publisher(geometry_msgs.Twist, "/karl/cmd_vel", 1)
    twist = geometry_msgs.Twist(
        linear=geometry_msgs.Vector3(x=0.15), angular=geometry_msgs.Vector3(z=0.6)
    )
    probe.create_timer(0.1, lambda: cmd.publish(twist))
    rt.run(duration=3.0)
    pos, yaw = relative_state(probe, "karl_marker", "karl")
    np.testing.assert_allclose(pos, [-0.05, 0.0, 0.30], atol=0.01)
    assert abs(abs(yaw) - np.pi) < np.radians(1.0)
    robot, _ = sim.engine.model_pose("karl")
    assert np.hypot(robot[0] + 2.0, robot[1] - 2.0) > 0.2  # it drove, marker on its back
    assert not sim.engine.paused
    assert {i: w.number for i, w in enumerate(sim.engine.data.warning) if w.number} == {}


def test_a_robot_that_never_comes_names_the_service_and_robot():
    rt = Runtime(seed=1)
    Simulator(rt, "gazebo")
    SpawnMarkerOnRobot(rt, namespace="/hank", params={"wait_timeout": 1.0})
    with pytest.raises(ServiceError, match=r"robot 'hank'.*/gazebo/get_model_state does not know"):
        rt.run(duration=2.0)


def test_no_simulator_names_the_missing_services():
    rt = Runtime(seed=1)
    SpawnMarkerOnRobot(rt, namespace="/hank", params={"wait_timeout": 0.5})
    with pytest.raises(ServiceError, match=r"/gazebo/pause_physics.*is the simulator running"):
        rt.run(duration=1.0)


def test_a_refused_spawn_names_the_service_and_reason():
    rt = Runtime(seed=1)
    Simulator(rt, "gazebo")
    probe = Node(rt, "probe")
    spawn_burger(probe, "karl", 0.0, 0.0, 0.0)
    SpawnMarkerOnRobot(rt, namespace="/karl", params={"marker_model": "no_such_marker"})
    with pytest.raises(ServiceError, match=r"/gazebo/spawn_sdf_model refused for karl_marker: .*"):
        rt.run(duration=0.5)
