"""Drive a diff-drive robot open loop; encoder odometry vs p3d ground truth."""

import math

import mujoco
import numpy as np
import pytest

from fleetsim.description import parse_urdf
from fleetsim.errors import SimulationError
from fleetsim.sim import Engine
from fleetsim.sim.plugins.base import JointStateReading, OdometryReading

from ..conftest import robot_text


def yaw_of(q_xyzw):
    x, y, z, w = q_xyzw
    return math.atan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))


def run(engine, entry, commands):
    readings = []
    for vx, wz, seconds in commands:
        for _ in range(round(seconds / 0.05)):
            entry.plugins[0].command(vx, wz, engine.time)
            readings += engine.advance(0.05)
    return readings


def last(readings, topic):
    return [r for r in readings if isinstance(r, OdometryReading) and r.topic == topic][-1]


def test_encoder_odometry_follows_ground_truth(diffbot):
    e = Engine(None)
    r = e.spawn_robot("r", diffbot, (0, 0, 0, 0, 0, 0))
    readings = run(e, r, [(0.4, 0.0, 2.0), (0.3, 0.6, 2.0), (0.4, -0.3, 2.0)])
    odom, truth = last(readings, "odom"), last(readings, "base_pose_ground_truth")
    assert odom.frame_id == "r/odom" and odom.child_frame_id == "r/base_footprint"
    assert truth.frame_id == "map" and truth.child_frame_id == "r/base_footprint"
    travelled = np.linalg.norm(truth.position[:2])
    assert travelled > 1.5
    err = np.linalg.norm(odom.position[:2] - truth.position[:2])
    assert err < 0.05 * travelled  # drifts, but stays near the truth on flat ground
    assert abs(yaw_of(odom.orientation) - yaw_of(truth.orientation)) < 0.1
    assert odom.linear[0] == pytest.approx(0.4, abs=0.05)
    # encoder odometry is not the ground truth: it has drifted a little
    assert err > 1e-5


def test_world_odometry_source_is_the_true_pose():
    text = robot_text("diffbot.urdf").replace("<odometrySource>encoder", "<odometrySource>world")
    e = Engine(None)
    r = e.spawn_robot("r", parse_urdf(text), (1.0, 2.0, 0, 0, 0, 0.5))
    readings = run(e, r, [(0.3, 0.2, 1.0)])
    odom, truth = last(readings, "odom"), last(readings, "base_pose_ground_truth")
    np.testing.assert_allclose(odom.position, truth.position, atol=1e-9)


def test_odometry_source_defaults_to_world_as_gazebo():
    """gazebo_ros_diff_drive (Kinetic to Noetic: ``odometrySource`` default WORLD; ROS 2:
    ``odometry_source`` default 1, world) reports the true pose unless told ``encoder``."""
    text = robot_text("diffbot.urdf").replace("<odometrySource>encoder</odometrySource>", "")
    assert "odometrySource" not in text
    e = Engine(None)
    r = e.spawn_robot("r", parse_urdf(text), (1.0, 2.0, 0, 0, 0, 0.5))
    readings = run(e, r, [(0.3, 0.6, 1.0)])
    odom, truth = last(readings, "odom"), last(readings, "base_pose_ground_truth")
    np.testing.assert_allclose(odom.position, truth.position, atol=1e-9)
    assert yaw_of(odom.orientation) == pytest.approx(yaw_of(truth.orientation), abs=1e-9)


def test_torque_limit_bounds_acceleration():
    weak = robot_text("diffbot.urdf").replace("<wheelTorque>1<", "<wheelTorque>0.05<")
    e = Engine(None)
    strong = e.spawn_robot("s", parse_urdf(robot_text("diffbot.urdf")), (0, 0, 0, 0, 0, 0))
    slow = e.spawn_robot("w", parse_urdf(weak), (0, 3, 0, 0, 0, 0))
    for _ in range(10):
        strong.plugins[0].command(1.0, 0.0, e.time)
        slow.plugins[0].command(1.0, 0.0, e.time)
        e.advance(0.05)
    assert e.model_twist("s")[0][0] > 0.9
    assert e.model_twist("w")[0][0] < 0.3


def test_wheel_acceleration_ramps_the_speed():
    text = robot_text("diffbot.urdf").replace(
        "<wheelTorque>1</wheelTorque>",
        "<wheelTorque>1</wheelTorque><wheelAcceleration>0.5</wheelAcceleration>",
    )
    e = Engine(None)
    r = e.spawn_robot("r", parse_urdf(text))
    run(e, r, [(1.0, 0.0, 0.5)])
    assert e.model_twist("r")[0][0] == pytest.approx(0.25, abs=0.05)


def test_commands_and_odometry_survive_a_rebuild_of_the_world(diffbot):
    """Spawning and deleting recompile the world; the drives' batched state (commands, servo,
    odometry) is carried over, and a deleted robot's plugin no longer drives anything."""

    def history(rebuild: bool):
        e = Engine(None)
        r = e.spawn_robot("r", diffbot)
        r.plugins[0].command(0.4, 0.3, e.time)
        out = e.advance(0.2)
        if rebuild:
            gone = e.spawn_robot("tmp", diffbot, (0, 3, 0, 0, 0, 0))
            e.delete_model("tmp")
            gone.plugins[0].command(1.0, 1.0, e.time)  # must not reach robot "r"
        return out + e.advance(0.2)

    plain, rebuilt = history(False), history(True)
    odom = [(o.stamp, o.position.tolist()) for o in plain if o.topic == "odom"]
    assert odom == [(o.stamp, o.position.tolist()) for o in rebuilt if o.topic == "odom"]
    assert odom[-1][1][0] > 0.05


def test_odometry_of_many_drives_at_once_equals_one_by_one(diffbot):
    world = parse_urdf(
        robot_text("diffbot.urdf").replace("<odometrySource>encoder", "<odometrySource>world")
    )

    def engine():
        e = Engine(None)
        for i, robot in enumerate([diffbot, world, diffbot]):
            e.spawn_robot(f"r{i}", robot, (0, i, 0, 0, 0, 0)).plugins[0].command(0.3, i - 1, 0.0)
        return e, [en.plugins[0] for en in e.models.values() if en.kind == "robot"]

    (e1, d1), (e2, d2) = engine(), engine()
    for _ in range(5):
        e1.advance(0.06)
        e2.advance(0.06)
        many = type(d1[0]).measure_each(e1, d1, e1.time)
        for m, p in zip(many, d2):
            one = p.measure(e2, e2.time)
            for field in ("position", "orientation", "linear", "angular"):
                np.testing.assert_array_equal(getattr(m, field), getattr(one, field))
            assert (m.frame_id, m.child_frame_id, m.namespace) == (
                one.frame_id,
                one.child_frame_id,
                p.ctx.namespace,
            )
    assert many[2].position[1] > 0.005 and many[0].position[1] < -0.005  # turned left, right
    other = Engine(None)
    with pytest.raises(SimulationError, match="the drive is not spawned in this engine"):
        d1[0].measure(other, 0.0)


def test_true_odometries_equal_mj_object_velocity_bit_for_bit(diffbot, skidbot):
    """The batched world-source odometry is MuJoCo's own mj_objectVelocity (local frame at the
    body's origin) for each robot, to the last bit, while the robots drive, turn and rock."""
    import mujoco

    from fleetsim.sim.plugins.diff_drive import true_odometries

    e = Engine(None)
    robots = [diffbot, skidbot, diffbot, skidbot]
    for i, robot in enumerate(robots):
        pose = (0.0, 1.5 * i, 0.0, 0.0, 0.0, 0.4 * i)
        e.spawn_robot(f"r{i}", robot, pose).plugins[0].command(0.4, 0.8 * (i - 1.5), 0.0)
    roots = np.array([e.root_body(f"r{i}") for i in range(len(robots))], np.int64)
    for _ in range(6):
        e.advance(0.07)
        pos, quat, lin, ang = true_odometries(e.model, e.data, roots)
        for k, b in enumerate(roots):
            vel = np.zeros(6)
            mujoco.mj_objectVelocity(e.model, e.data, mujoco.mjtObj.mjOBJ_XBODY, b, vel, 1)
            assert lin[k].tobytes() == vel[3:].tobytes() and ang[k].tobytes() == vel[:3].tobytes()
            assert pos[k].tobytes() == e.data.xpos[b].tobytes()
            w, x, y, z = e.data.xquat[b]
            assert quat[k].tolist() == [x, y, z, w]
    assert np.abs(ang[:, 2]).min() > 0.05 and np.abs(lin[:, 0]).min() > 0.05  # all moving
    assert [w.number for w in e.data.warning] == [0] * len(e.data.warning)


@pytest.mark.parametrize(
    ("tag", "value", "words"),
    [
        ("wheelSeparation", "30", "wheelSeparation 30 m, but the joints"),
        ("wheelDiameter", "10", "wheelDiameter 10 m, but the wheel of joint"),
    ],
)
def test_a_wheel_geometry_in_the_wrong_unit_is_warned_about(tag, value, words, caplog):
    """30 for 0.30 m: Gazebo drives with it as given; fleetsim says it differs from the
    model's wheels, and a right value (the fixture's) is not warned about."""
    text = robot_text("diffbot.urdf")
    Engine(None).spawn_robot("ok", parse_urdf(text), (0, 0, 0, 0, 0, 0))
    assert "but the" not in caplog.text
    bad = text.replace(f"<{tag}>0.", f"<{tag}>{value}<!-- -->0.", 1)
    bad = bad.replace(f"<{tag}>{value}<!-- -->0.30<", f"<{tag}>{value}<")
    bad = bad.replace(f"<{tag}>{value}<!-- -->0.10<", f"<{tag}>{value}<")
    assert f"<{tag}>{value}<" in bad
    Engine(None).spawn_robot("bad", parse_urdf(bad), (0, 0, 0, 0, 0, 0))
    assert words in caplog.text and "is in metres" in caplog.text, caplog.text


@pytest.mark.parametrize("publish", [True, False])
def test_publish_wheel_joint_state_publishes_the_wheels_on_joint_states(publish):
    """gazebo_ros_diff_drive's publishWheelJointState: the two wheels' joint states on the
    robot's joint_states at the drive's updateRate (turtlebot3_gazebo runs no
    joint_state_publisher and relies on it)."""
    text = robot_text("diffbot.urdf")
    text = text.replace(  # only the drive may publish joint states here
        "<jointName>left_wheel_joint, right_wheel_joint</jointName>",
        "<jointName>left_wheel_joint</jointName><topicName>other</topicName>",
    ).replace(
        '<updateRate>50</updateRate>\n    </plugin>\n    <plugin name="p3d"',
        f"<updateRate>50</updateRate><publishWheelJointState>{str(publish).lower()}"
        '</publishWheelJointState>\n    </plugin>\n    <plugin name="p3d"',
    )
    assert "publishWheelJointState" in text
    e = Engine(None)
    entry = e.spawn_robot("bot", parse_urdf(text))
    readings = run(e, entry, [(0.3, 0.6, 1.0)])
    wheels = [r for r in readings if isinstance(r, JointStateReading) and r.topic == "joint_states"]
    if not publish:
        assert wheels == []
        return
    assert len(wheels) == pytest.approx(50, abs=2)  # 1 s at updateRate 50
    last_one = wheels[-1]
    assert last_one.names == ["left_wheel_joint", "right_wheel_joint"]
    assert last_one.namespace == "/bot"
    d = e.data
    jid = [
        mujoco.mj_name2id(e.model, mujoco.mjtObj.mjOBJ_JOINT, f"bot/{j}") for j in last_one.names
    ]
    # the last reading is at most one period (0.02 s) old: the wheels turn ~6-10 rad/s
    now = d.qpos[e.model.jnt_qposadr[jid]]
    np.testing.assert_allclose(last_one.position, now, atol=0.25)
    assert min(now) > 3.0  # 1 s of rolling at ~0.3 m/s on 0.05 m wheels
    left, right = last_one.velocity
    assert right > left > 0.0  # turning left while driving forward
