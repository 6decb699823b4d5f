"""Skid steer: straight runs track the truth, turning slips as Coulomb friction predicts;
odometry is the true world pose (as Gazebo's plugin), encoder odometry (opt-in) drifts."""

import math
from pathlib import Path

import numpy as np
import pytest

from fleetsim.description import load_robot, parse_urdf
from fleetsim.description.urdf import urdf_text
from fleetsim.errors import FleetsimError
from fleetsim.sim import Engine
from fleetsim.sim.build import rpy_from_quat
from fleetsim.sim.plugins.base import DrivePlugin, OdometryReading

from ..conftest import replace_plugin_param, robot_text
from .test_diff_drive import last, run, yaw_of

ENCODER = "<broadcastTF>1</broadcastTF><odometrySource>encoder</odometrySource>"


def with_encoder_odometry(text: str) -> str:
    return replace_plugin_param(text, "<broadcastTF>1</broadcastTF>", ENCODER)


def test_skid_steer_odometry_is_the_world_pose_by_default(skidbot):
    """gazebo_ros_skid_steer_drive publishes ``parent->WorldPose()``: no drift, no slip, and
    the pose is in the world, not relative to where the robot started."""
    e = Engine(None)
    r = e.spawn_robot("jackal", skidbot, (1.0, -2.0, 0.1, 0, 0, 0.7))
    readings = run(e, r, [(0.5, 0.0, 1.0), (0.2, 0.8, 2.0)])
    odom, truth = last(readings, "odom"), last(readings, "base_pose_ground_truth")
    assert odom.frame_id == "jackal/odom" and odom.child_frame_id == "jackal/base_link"
    assert yaw_of(truth.orientation) - 0.7 > 0.15  # it turned, and its wheels scrubbed
    np.testing.assert_allclose(odom.position, truth.position, atol=1e-9)
    assert yaw_of(odom.orientation) == pytest.approx(yaw_of(truth.orientation), abs=1e-9)
    assert odom.angular[2] == pytest.approx(truth.angular[2], abs=1e-4)
    assert [w.number for w in e.data.warning] == [0] * len(e.data.warning)  # MuJoCo warnings


def test_skid_steer_odometry_source_is_validated():
    text = replace_plugin_param(
        robot_text("skidbot.urdf"),
        "<broadcastTF>1</broadcastTF>",
        "<broadcastTF>1</broadcastTF><odometrySource>wheels</odometrySource>",
    )
    with pytest.raises(FleetsimError, match="odometrySource.*wheels"):
        Engine(None).spawn_robot("jackal", parse_urdf(text))


def test_skid_steer_encoder_odometry_drifts_when_turning():
    e = Engine(None)
    robot = parse_urdf(with_encoder_odometry(robot_text("skidbot.urdf")))
    r = e.spawn_robot("jackal", robot, (0, 0, 0.1, 0, 0, 0))
    assert [type(p).__name__ for p in r.plugins] == ["SkidSteerPlugin", "P3dPlugin"]
    readings = run(e, r, [(0.5, 0.0, 2.0)])
    odom, truth = last(readings, "odom"), last(readings, "base_pose_ground_truth")
    assert odom.child_frame_id == "jackal/base_link" and odom.publish_tf
    assert truth.position[0] > 0.8
    assert abs(odom.position[0] - truth.position[0]) < 0.05 * truth.position[0]
    readings = run(e, r, [(0.2, 0.8, 3.0)])
    odom, truth = last(readings, "odom"), last(readings, "base_pose_ground_truth")
    turned_truth = yaw_of(truth.orientation)
    turned_odom = yaw_of(odom.orientation)
    assert turned_truth > 0.15  # it does turn
    assert abs(turned_odom - turned_truth) > 0.2  # but the wheels slip: odometry drifts
    assert np.linalg.norm(odom.position[:2] - truth.position[:2]) > 0.02


# ---------------------------------------------------------------- turning on flat ground
ROBOTS = Path(__file__).resolve().parents[3] / "src" / "fleetsim" / "assets" / "robots"


def spawn(name, encoder=False):
    e = Engine(None)
    path = ROBOTS / name / "urdf" / f"{name}.urdf.xacro"
    if encoder:
        text = with_encoder_odometry(urdf_text(path, None, None)[0])
        robot = parse_urdf(text, str(path), base_dir=path.parent)
    else:
        robot = load_robot(path)
    entry = e.spawn_robot("r", robot)
    return e, next(p for p in entry.plugins if isinstance(p, DrivePlugin))


def drive(e, plugin, vx, wz, seconds):
    """Command (vx, wz) for ``seconds``; returns the true yaw rate (rad/s) and speed (m/s)."""
    yaw0, pos0, t0 = yaw_of_model(e), e.model_pose("r")[0].copy(), e.time
    turned, prev = 0.0, yaw0
    for _ in range(round(seconds / 0.05)):
        plugin.command(vx, wz, e.time)
        e.advance(0.05)
        yaw = yaw_of_model(e)
        turned += (yaw - prev + math.pi) % (2 * math.pi) - math.pi
        prev = yaw
    dt = e.time - t0
    return turned / dt, float(np.linalg.norm((e.model_pose("r")[0] - pos0)[:2])) / dt


def yaw_of_model(e):
    return rpy_from_quat(e.model_pose("r")[1])[2]


def coulomb_turn_factor(e, plugin):
    """b^2 / (a^2 + b^2): the true/commanded yaw rate of four equally loaded wheels under
    isotropic Coulomb friction (a half wheelbase, b half track, from the model's wheels)."""
    m = e.model
    root = plugin.root
    offsets = np.array(
        [e.data.xpos[m.dof_bodyid[dof]] - e.data.xpos[root] for _, dof in plugin.wheels]
    )
    local = offsets @ e.data.xmat[root].reshape(3, 3)
    a, b = np.abs(local[:, 0]).mean(), np.abs(local[:, 1]).mean()
    return b * b / (a * a + b * b)


@pytest.mark.parametrize("name", ["lizi", "pioneer3at", "jackal"])
def test_skid_steer_robot_turns_as_coulomb_friction_predicts(name):
    e, plugin = spawn(name)
    factor = coulomb_turn_factor(e, plugin)  # lizi 0.60, pioneer3at 0.68, jackal 0.67
    drive(e, plugin, 0.0, 1.0, 1.0)
    wz, _ = drive(e, plugin, 0.0, 1.0, 2.0)
    assert wz >= 0.4  # it was 0.10-0.20 rad/s before the wheels had a held rotor
    assert 0.85 * factor <= wz <= 1.05 * factor
    drive(e, plugin, 0.3, 0.5, 1.0)
    wz, speed = drive(e, plugin, 0.3, 0.5, 2.0)
    assert speed == pytest.approx(0.3, rel=0.05)
    # lizi's Coulomb bound for this arc is 0.298 rad/s, just below the 0.3 asked for
    assert wz >= min(0.3, 0.8 * factor * 0.5)
    assert wz <= 1.05 * factor * 0.5
    drive(e, plugin, 0.5, 0.0, 1.0)
    wz, speed = drive(e, plugin, 0.5, 0.0, 2.0)
    assert speed == pytest.approx(0.5, rel=0.02) and abs(wz) < 0.02
    roll, pitch, _ = rpy_from_quat(e.model_pose("r")[1])
    assert max(abs(roll), abs(pitch)) < 0.05


@pytest.mark.parametrize("name", ["turtlebot3_burger"])
def test_diff_drive_robot_still_tracks_its_commands(name):
    e, plugin = spawn(name)
    for vx, wz in [(0.0, 1.0), (0.3, 0.5), (0.2, 0.0)]:
        drive(e, plugin, vx, wz, 1.0)
        true_wz, speed = drive(e, plugin, vx, wz, 1.5)
        assert true_wz == pytest.approx(wz, rel=0.1, abs=0.01)
        assert speed == pytest.approx(vx, rel=0.1, abs=0.01)


def test_encoder_odometry_reports_the_commanded_rotation():
    """Wheel odometry (``odometrySource encoder``) assumes rolling wheels, so it reports about
    1/0.57 of lizi's true rotation in place (the slip factor documented in the plugin)."""
    e, plugin = spawn("lizi", encoder=True)
    e.advance(0.2)
    readings = []
    for _ in range(60):
        plugin.command(0.0, 1.0, e.time)
        readings += e.advance(0.05)
    odom = [r for r in readings if isinstance(r, OdometryReading) and r.topic == "odom"]
    t = [r.stamp for r in odom]
    late = [k for k in range(len(odom)) if t[k] >= t[-1] - 1.0]
    odom_wz = np.mean([odom[k].angular[2] for k in late])
    true_wz, _ = drive(e, plugin, 0.0, 1.0, 1.0)
    assert odom_wz == pytest.approx(1.0, rel=0.05)
    assert 0.5 < true_wz / odom_wz < 0.65


def test_turning_is_deterministic():
    runs = []
    for _ in range(2):
        e, plugin = spawn("pioneer3at")
        drive(e, plugin, 0.2, 0.7, 1.0)
        runs.append((e.data.qpos.copy(), e.data.qvel.copy()))
    assert np.array_equal(runs[0][0], runs[1][0]) and np.array_equal(runs[0][1], runs[1][1])
