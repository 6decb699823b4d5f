"""The Simulator node on a runtime: topics, tf, /clock, namespaces and world services."""

import numpy as np
import pytest

from fleetsim.msgs import gazebo_msgs, gazebo_ros_link_attacher, geometry_msgs, std_srvs
from fleetsim.runtime import Node, Runtime
from fleetsim.sim.node import Simulator

from .conftest import FIXTURES, WILLOW


def collect(node, msg_type, topic, store):
    node.create_subscription(msg_type, topic, store.append, queue_size=100)


@pytest.fixture
def sim():
    rt = Runtime(seed=3)
    sim = Simulator(rt, args=[str(WILLOW)])
    probe = Node(rt, "probe")
    return rt, sim, probe


def spawn(probe, name, pose, ns="", xml=None):
    client = probe.create_client(gazebo_msgs.SpawnModel, "/gazebo/spawn_urdf_model")
    req = gazebo_msgs.SpawnModel.Request()
    req.model_name = name
    req.model_xml = xml or (FIXTURES / "diffbot.urdf").read_text()
    req.robot_namespace = ns
    req.initial_pose.position.x, req.initial_pose.position.y = pose
    req.initial_pose.orientation.w = 1.0
    return client.call(req)


def test_two_namespaces_do_not_share_commands(sim):
    from fleetsim.msgs import nav_msgs, rosgraph_msgs, sensor_msgs, tf2_msgs

    rt, s, probe = sim
    assert spawn(probe, "lizi1", (22.0, 15.0)).success
    assert spawn(probe, "lizi2", (24.0, 15.0), ns="/lizi2").success
    odom1, scans2, tf, clock = [], [], [], []
    collect(probe, nav_msgs.Odometry, "/lizi1/odom", odom1)
    collect(probe, sensor_msgs.LaserScan, "/lizi2/scan", scans2)
    collect(probe, tf2_msgs.TFMessage, "/tf", tf)
    collect(probe, rosgraph_msgs.Clock, "/clock", clock)
    cmd = probe.create_publisher(geometry_msgs.Twist, "/lizi1/cmd_vel", queue_size=1)
    probe.create_timer(
        0.1, lambda: cmd.publish(geometry_msgs.Twist(linear=geometry_msgs.Vector3(x=0.3)))
    )
    rt.run(duration=2.0)
    p1, _ = s.engine.model_pose("lizi1")
    p2, _ = s.engine.model_pose("lizi2")
    assert p1[0] > 22.4  # lizi1 drove
    assert np.hypot(p2[0] - 24.0, p2[1] - 15.0) < 0.01  # lizi2 did not move
    assert odom1 and odom1[-1].header.frame_id == "lizi1/odom"
    assert odom1[-1].child_frame_id == "lizi1/base_footprint"
    assert odom1[-1].header.stamp.to_sec() <= rt.now() + 1e-9
    assert len(scans2) == pytest.approx(20, abs=1)  # 10 Hz
    assert scans2[-1].header.frame_id == "lizi2/laser_link" and len(scans2[-1].ranges) == 360
    frames = {(t.header.frame_id, t.child_frame_id) for m in tf for t in m.transforms}
    assert ("lizi2/odom", "lizi2/base_footprint") in frames
    assert clock and clock[-1].clock.to_sec() == pytest.approx(rt.now(), abs=0.011)


def test_a_robot_spawned_where_another_is_is_warned_about(sim, caplog):
    """Two robots in one namespace (both spawned in '/'), or two namespaces with one
    tf_prefix: Gazebo spawns them, and their topics or frames are shared without a word."""
    import logging

    rt, s, probe = sim
    rt.params.set("/b/tf_prefix", "a")
    with caplog.at_level(logging.WARNING):
        assert spawn(probe, "a", (22.0, 15.0), ns="/a").success
        assert spawn(probe, "b", (24.0, 15.0), ns="/b").success
        assert spawn(probe, "c", (22.0, 17.0), ns="/c").success
        assert spawn(probe, "d", (24.0, 17.0), ns="/c").success
    said = [r.getMessage() for r in caplog.records if r.levelno >= logging.WARNING]
    assert said == [
        "[0.000] [/gazebo] 'b' is spawned with tf_prefix 'a', as 'a' is: the two publish the same "
        "tf frames; give each robot its own <group ns> and tf_prefix (spawn_model inside the "
        "group)",
        "[0.000] [/gazebo] 'd' is spawned in namespace /c, as 'c' is: the two share their topics "
        "(cmd_vel, odom, the sensors'), each hearing the other's; give each robot its own "
        "<group ns> and tf_prefix (spawn_model inside the group)",
    ]


def test_odometry_tf_arrives_before_the_scan_of_the_same_time(sim):
    from fleetsim.msgs import sensor_msgs, tf2_msgs

    rt, s, probe = sim
    assert spawn(probe, "lizi2", (24.0, 15.0)).success
    log = []
    probe.create_subscription(
        tf2_msgs.TFMessage,
        "/tf",
        lambda m: log.append(
            (
                "tf",
                {
                    t.header.stamp.to_nsec()
                    for t in m.transforms
                    if t.child_frame_id == "lizi2/base_footprint"
                },
            )
        ),
        queue_size=100,
    )
    probe.create_subscription(
        sensor_msgs.LaserScan,
        "/lizi2/scan",
        lambda m: log.append(("scan", m.header.stamp.to_nsec())),
        queue_size=100,
    )
    rt.run(duration=0.5)
    scans = [i for i, (kind, _) in enumerate(log) if kind == "scan"]
    assert len(scans) >= 4
    for i in scans:
        seen = set().union(*(v for kind, v in log[:i] if kind == "tf"))
        assert log[i][1] in seen


@pytest.mark.parametrize("publish", [True, False])
def test_publish_wheel_tf_broadcasts_each_wheel_from_its_parent_link(sim, publish):
    """gazebo_ros_diff_drive's publishWheelTF: each wheel's transform from its joint's parent
    link on /tf at the drive's updateRate, turning with the wheel (the angle the drive's own
    wheel joint states give at the same stamp), with the robot's tf_prefix; none without it."""
    import mujoco

    from fleetsim.msgs import sensor_msgs, tf2_msgs

    rt, s, probe = sim
    xml = (FIXTURES / "diffbot.urdf").read_text()
    flags = f"<publishWheelTF>{str(publish).lower()}</publishWheelTF>"
    flags += "<publishWheelJointState>true</publishWheelJointState>"
    xml = xml.replace("<updateRate>50</updateRate>", f"<updateRate>50</updateRate>{flags}", 1)
    assert spawn(probe, "bot", (22.0, 15.0), ns="/bot", xml=xml).success
    tf, states = [], []
    collect(probe, tf2_msgs.TFMessage, "/tf", tf)
    collect(probe, sensor_msgs.JointState, "/bot/joint_states", states)
    cmd = probe.create_publisher(geometry_msgs.Twist, "/bot/cmd_vel", queue_size=1)
    twist = geometry_msgs.Twist(linear=geometry_msgs.Vector3(x=0.3))
    twist.angular.z = 0.5
    probe.create_timer(0.1, lambda: cmd.publish(twist))
    rt.run(duration=1.0)
    wheels = [
        t
        for m in tf
        for t in m.transforms
        if t.child_frame_id in ("bot/left_wheel", "bot/right_wheel")
    ]
    if not publish:
        assert wheels == []
        return
    assert {t.header.frame_id for t in wheels} == {"bot/base_link"}
    assert len(wheels) == pytest.approx(2 * 50, abs=4)  # two wheels, 1 s at 50 Hz
    drive = [m for m in states if "left_wheel_joint" in m.name and len(m.name) == 2]
    angle = {(m.header.stamp.to_nsec(), n): p for m in drive for n, p in zip(m.name, m.position)}
    checked = 0
    for t in wheels:
        side = t.child_frame_id.split("/")[1].split("_")[0]
        a = angle.get((t.header.stamp.to_nsec(), f"{side}_wheel_joint"))
        if a is None:
            continue
        tr, r = t.transform.translation, t.transform.rotation
        y = 0.15 if side == "left" else -0.15
        np.testing.assert_allclose([tr.x, tr.y, tr.z], [0.0, y, 0.0], atol=1e-9)
        origin = np.array([np.cos(-np.pi / 4), np.sin(-np.pi / 4), 0.0, 0.0])  # rpy -90 0 0
        spin = np.array([np.cos(a / 2), 0.0, 0.0, np.sin(a / 2)])  # about the axle, z
        want = np.zeros(4)
        mujoco.mju_mulQuat(want, origin, spin)
        got = np.array([r.w, r.x, r.y, r.z])
        assert min(np.abs(got - want).max(), np.abs(got + want).max()) < 1e-6, (got, want)
        checked += 1
    assert checked >= 90
    assert max(abs(p) for p in angle.values()) > 3.0  # the wheels turned


def test_world_services(sim):
    rt, s, probe = sim
    assert spawn(probe, "bot", (10.0, 10.0)).success
    dup = spawn(probe, "bot", (11.0, 10.0))
    assert not dup.success and "already exists" in dup.status_message
    client = probe.create_client(gazebo_msgs.SpawnModel, "/gazebo/spawn_urdf_model")
    broken = client.call(
        gazebo_msgs.SpawnModel.Request(
            model_name="broken", model_xml="<robot name='b'>\n<link name='a'>\n</robot>"
        )
    )
    assert not broken.success and ":3" in broken.status_message  # names the line
    get = probe.create_client(gazebo_msgs.GetModelState, "/gazebo/get_model_state")
    setc = probe.create_client(gazebo_msgs.SetModelState, "/gazebo/set_model_state")
    req = gazebo_msgs.SetModelState.Request()
    req.model_state.model_name = "bot"
    req.model_state.pose.position.x, req.model_state.pose.position.y = 11.0, 9.0
    req.model_state.pose.orientation.w = 1.0
    assert setc.call(req).success
    st = get.call(gazebo_msgs.GetModelState.Request(model_name="bot"))
    assert st.success and st.pose.position.x == pytest.approx(11.0)
    missing = get.call(gazebo_msgs.GetModelState.Request(model_name="nobody"))
    assert not missing.success and "no model named 'nobody'" in missing.status_message
    states = []
    probe.create_subscription(
        gazebo_msgs.ModelStates, "/gazebo/model_states", states.append, queue_size=5
    )
    rt.run(duration=0.2)
    assert states and states[-1].name == ["ground_plane", "map_walls", "bot"]
    assert states[-1].pose[2].position.x == pytest.approx(11.0, abs=0.02)
    props = probe.create_client(
        gazebo_msgs.GetWorldProperties, "/gazebo/get_world_properties"
    ).call()
    assert props.model_names == ["ground_plane", "map_walls", "bot"]
    empty = std_srvs.Empty.Request()
    probe.create_client(std_srvs.Empty, "/gazebo/pause_physics").call(empty)
    t0 = s.engine.time
    rt.run(duration=0.5)
    assert s.engine.time == t0
    probe.create_client(std_srvs.Empty, "/gazebo/unpause_physics").call(empty)
    rt.run(duration=0.5)
    assert s.engine.time == pytest.approx(t0 + 0.5, abs=0.011)
    sdf = probe.create_client(gazebo_msgs.SpawnModel, "/gazebo/spawn_sdf_model")
    sreq = gazebo_msgs.SpawnModel.Request(
        model_name="marker",
        model_xml=(
            "<sdf version='1.6'><model name='m'><link name='link'><inertial><mass>0.1</mass>"
            "</inertial><collision name='c'><geometry><box><size>.1 .1 .1</size></box>"
            "</geometry></collision></link></model></sdf>"
        ),
    )
    sreq.initial_pose.position.x, sreq.initial_pose.position.z = 10.0, 0.5
    assert sdf.call(sreq).success
    att = probe.create_client(gazebo_ros_link_attacher.Attach, "/link_attacher_node/attach")
    ok = att.call(
        gazebo_ros_link_attacher.Attach.Request(
            model_name_1="bot", link_name_1="base_link", model_name_2="marker", link_name_2="link"
        )
    )
    assert ok.ok
    bad = att.call(
        gazebo_ros_link_attacher.Attach.Request(
            model_name_1="bot", link_name_1="nope", model_name_2="marker", link_name_2="link"
        )
    )
    assert not bad.ok
    dele = probe.create_client(gazebo_msgs.DeleteModel, "/gazebo/delete_model")
    assert dele.call(gazebo_msgs.DeleteModel.Request(model_name="bot")).success
    rt.run(duration=0.1)
    assert "bot" not in s.engine.models
    probe.create_client(std_srvs.Empty, "/gazebo/reset_simulation").call(empty)
    assert s.engine.time == 0.0


def test_messages_nobody_subscribes_to_are_not_built(sim, monkeypatch):
    from fleetsim.msgs import nav_msgs
    from fleetsim.sim import messages as conv

    rt, s, probe = sim
    assert spawn(probe, "bot", (22.0, 15.0), ns="/lizi1").success
    built = {"odom": 0, "states": 0}

    def counting(name, fn):
        def wrapped(*a, **k):
            built[name] += 1
            return fn(*a, **k)

        return wrapped

    monkeypatch.setattr(conv, "odometry_msg", counting("odom", conv.odometry_msg))
    monkeypatch.setattr(conv, "model_states_msg", counting("states", conv.model_states_msg))
    monkeypatch.setattr(
        s.engine, "contacts", counting("contacts", s.engine.contacts), raising=False
    )
    built["contacts"] = 0
    import fleetsim.sim.node as node_module

    monkeypatch.setitem(
        node_module._READING_MESSAGES,
        node_module.OdometryReading,
        (nav_msgs.Odometry, conv.odometry_msg),
    )
    buf = rt.tf_buffer  # listening from now on
    rt.run(duration=0.3)
    assert built == {"odom": 0, "states": 0, "contacts": 0}  # tf still goes out:
    assert "lizi1/odom" in buf.all_frames(), buf.all_frames()
    odoms, states, contacts = [], [], []
    collect(probe, nav_msgs.Odometry, "/lizi1/odom", odoms)
    collect(probe, gazebo_msgs.ModelStates, "/gazebo/model_states", states)
    collect(probe, gazebo_msgs.ContactsState, "/gazebo/robot_contacts", contacts)
    rt.run(duration=0.3)
    assert odoms and states and built["odom"] >= len(odoms) and built["states"] == len(states)
    assert built["contacts"] > 0  # looked for at every update now (the bot touches nothing)
