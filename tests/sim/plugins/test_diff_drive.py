"""Drive a diff-drive robot open loop; encoder odometry vs p3d ground truth."""

import math

import numpy as np
import pytest

from fleetsim.description import parse_urdf
from fleetsim.sim import Engine
from fleetsim.sim.plugins.base import OdometryReading

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
