"""World services as grobot's spawn_marker_on_robot uses them: model_states, pause, spawn an SDF
model in a robot's namespace, attach it, unpause; the marker then rides on the driving robot."""

from pathlib import Path

import numpy as np
import pytest

from fleetsim.description import load_robot
from fleetsim.description.urdf import urdf_text
from fleetsim.msgs import gazebo_msgs, gazebo_ros_link_attacher, geometry_msgs, std_srvs
from fleetsim.runtime import Node, Runtime
from fleetsim.sim.build import quat_from_rpy
from fleetsim.sim.node import Simulator

ROBOTS = Path(__file__).resolve().parents[2] / "src" / "fleetsim" / "assets" / "robots"
BURGER = ROBOTS / "turtlebot3_burger/urdf/turtlebot3_burger.urdf.xacro"
MARKER_XML = (
    '<sdf version="1.6"><world name="default"><include><uri>model://aruco_marker</uri>'
    "</include></world></sdf>"
)


pytestmark = pytest.mark.usefixtures("in_tmp_dir")


def pose_msg(x, y, z, yaw):
    w, qx, qy, qz = quat_from_rpy(0.0, 0.0, yaw)
    return geometry_msgs.Pose(
        position=geometry_msgs.Point(x=x, y=y, z=z),
        orientation=geometry_msgs.Quaternion(x=qx, y=qy, z=qz, w=w),
    )


def yaw_of(q) -> float:
    return float(np.arctan2(2 * (q.w * q.z + q.x * q.y), 1 - 2 * (q.y**2 + q.z**2)))


def test_marker_spawned_and_attached_as_grobot_does_rides_through_turns_and_stops():
    rt = Runtime(seed=1)
    sim = Simulator(rt, "gazebo")
    probe = Node(rt, "probe")
    urdf = probe.create_client(gazebo_msgs.SpawnModel, "/gazebo/spawn_urdf_model")
    assert urdf.call(
        gazebo_msgs.SpawnModel.Request(
            model_name="karl",
            model_xml=urdf_text(BURGER)[0],
            robot_namespace="/karl",
            initial_pose=pose_msg(-2.0, 2.0, 0.0, 0.0),
        )
    ).success
    states = []
    probe.create_subscription(
        gazebo_msgs.ModelStates, "/gazebo/model_states", states.append, queue_size=5
    )
    rt.run(duration=1.0)
    # 1. the robot's pose from /gazebo/model_states
    robot = states[-1].pose[states[-1].name.index("karl")]
    empty = std_srvs.Empty.Request()
    # 2. pause, spawn the marker 5 cm behind the robot, 0.3 m up, facing backwards
    probe.create_client(std_srvs.Empty, "/gazebo/pause_physics").call(empty)
    spawn = probe.create_client(gazebo_msgs.SpawnModel, "/gazebo/spawn_sdf_model")
    resp = spawn.call(
        gazebo_msgs.SpawnModel.Request(
            model_name="karl_marker",
            model_xml=MARKER_XML,
            robot_namespace="karl",
            initial_pose=pose_msg(robot.position.x - 0.05, robot.position.y, 0.3, np.pi),
        )
    )
    assert resp.success, resp.status_message
    assert sim.engine.models["karl_marker"].namespace == "/karl"
    attach = probe.create_client(gazebo_ros_link_attacher.Attach, "/link_attacher_node/attach")
    req = gazebo_ros_link_attacher.Attach.Request(
        model_name_1="karl", link_name_1="base_footprint",
        model_name_2="karl_marker", link_name_2="link",
    )  # fmt: skip
    assert attach.call(req).ok
    assert attach.call(req).ok  # asked twice: still one joint, as the Gazebo plugin answers
    probe.create_client(std_srvs.Empty, "/gazebo/unpause_physics").call(empty)
    # 3. drive: straight, a left circle, stop, a tight right turn, stop
    plan = [(1.0, 0.2, 0.0), (5.0, 0.2, 0.8), (1.0, 0.0, 0.0), (2.0, 0.1, -1.5), (1.0, 0.0, 0.0)]
    cmd = probe.create_publisher(geometry_msgs.Twist, "/karl/cmd_vel", queue_size=1)
    get = probe.create_client(gazebo_msgs.GetModelState, "/gazebo/get_model_state")
    start = rt.now()
    relative = []

    def command_at(t):
        for seconds, v, w in plan:
            if t < seconds:
                return v, w
            t -= seconds
        return 0.0, 0.0

    def tick():
        v, w = command_at(rt.now() - start)
        cmd.publish(
            geometry_msgs.Twist(
                linear=geometry_msgs.Vector3(x=v), angular=geometry_msgs.Vector3(z=w)
            )
        )
        st = get.call(
            gazebo_msgs.GetModelState.Request(model_name="karl_marker", relative_entity_name="karl")
        )
        assert st.success, st.status_message
        p = st.pose.position
        relative.append((p.x, p.y, p.z, yaw_of(st.pose.orientation)))

    probe.create_timer(0.05, tick)
    rt.run(duration=sum(s for s, _, _ in plan))
    rel = np.array(relative)
    assert len(rel) >= 180
    # the robot went round: it turned through more than a full circle and moved
    pos, _ = sim.engine.model_pose("karl")
    assert np.hypot(pos[0] + 2.0, pos[1] - 2.0) > 0.3
    # where the marker was put: (-0.05, 0, 0.30) with yaw pi in base_footprint
    np.testing.assert_allclose(rel[0, :3], [-0.05, 0.0, 0.30], atol=0.005)
    drift = np.linalg.norm(rel[:, :3] - rel[0, :3], axis=1).max()
    turn = np.abs(np.angle(np.exp(1j * (rel[:, 3] - rel[0, 3])))).max()
    assert drift < 0.01 and np.degrees(turn) < 1.0
    assert abs(abs(rel[0, 3]) - np.pi) < np.radians(1.0)
    warnings = {i: w.number for i, w in enumerate(sim.engine.data.warning) if w.number}
    assert warnings == {}
    # the marker is a model of /gazebo/model_states, riding with the robot
    last = states[-1]
    assert {"karl", "karl_marker"} <= set(last.name)


def test_spawn_sdf_model_errors_are_answered_with_the_reason():
    rt = Runtime(seed=1)
    Simulator(rt, "gazebo")
    probe = Node(rt, "probe")
    spawn = probe.create_client(gazebo_msgs.SpawnModel, "/gazebo/spawn_sdf_model")
    no_model = spawn.call(
        gazebo_msgs.SpawnModel.Request(model_name="m", model_xml="<sdf><world/></sdf>")
    )
    assert not no_model.success and "no <model> element" in no_model.status_message
    missing = spawn.call(
        gazebo_msgs.SpawnModel.Request(
            model_name="m",
            model_xml="<sdf><world><include><uri>model://no_such_marker</uri></include></world></sdf>",
        )
    )
    assert not missing.success and "model://no_such_marker not found" in missing.status_message
    bad_ns = spawn.call(
        gazebo_msgs.SpawnModel.Request(model_name="m2", model_xml=MARKER_XML, robot_namespace="a b")
    )
    assert not bad_ns.success and "a b" in bad_ns.status_message


def test_spawn_relative_to_a_model_or_a_link_as_gazebo_ros_composes_it():
    rt = Runtime(seed=1)
    sim = Simulator(rt, "gazebo")
    sim.spawn_robot("karl", load_robot(BURGER), (1.0, 2.0, 0.0, 0.0, 0.0, np.pi / 2), "/karl")
    probe = Node(rt, "probe")
    spawn = probe.create_client(gazebo_msgs.SpawnModel, "/gazebo/spawn_sdf_model")
    for name, frame in (("m1", "karl"), ("m2", "karl::base_footprint")):
        resp = spawn.call(
            gazebo_msgs.SpawnModel.Request(
                model_name=name,
                model_xml=MARKER_XML,
                initial_pose=pose_msg(-0.05, 0.0, 0.3, np.pi),
                reference_frame=frame,
            )
        )
        assert resp.success, resp.status_message
        pos, quat = sim.engine.model_pose(name)
        # 5 cm behind a robot facing +y is 5 cm towards -y; facing back is yaw -pi/2
        np.testing.assert_allclose(pos, [1.0, 1.95, 0.3], atol=1e-3)
        yaw = np.arctan2(
            2 * (quat[0] * quat[3] + quat[1] * quat[2]), 1 - 2 * (quat[2] ** 2 + quat[3] ** 2)
        )
        assert abs(np.angle(np.exp(1j * (yaw + np.pi / 2)))) < 1e-3
    bad = spawn.call(
        gazebo_msgs.SpawnModel.Request(
            model_name="m3", model_xml=MARKER_XML, reference_frame="hank"
        )
    )
    assert not bad.success
    assert "reference_frame 'hank' is not the world, a model or 'model::link'" in bad.status_message
