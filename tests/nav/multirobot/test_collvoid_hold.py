"""A parked collvoid robot (``active_collision_avoidance``) makes room along its heading for a
robot coming at it and returns home; the goal turn runs at max_vel_theta until it must slow."""

import math
from types import SimpleNamespace

import numpy as np
import pytest

from fleetsim.msgs import collvoid_msgs, geometry_msgs
from fleetsim.msgs.builtin_interfaces import Time
from fleetsim.nav.controllers.collvoid_planner import CollvoidLocalPlanner
from fleetsim.nav.costmap.costmap_2d import LETHAL_OBSTACLE, Costmap2D
from fleetsim.runtime import Node, Runtime

LIZI = np.array([[-0.19, -0.16], [-0.19, 0.16], [0.19, 0.16], [0.19, -0.16]])
BODY = math.hypot(0.19, 0.16)
PARAMS = {
    "max_vel_x": 0.5,
    "max_vel_theta": 1.5,
    "min_vel_theta": -1.5,
    "xy_goal_tolerance": 0.2,
    "yaw_goal_tolerance": 0.3,
    "controller_frequency": 10.0,
}


def planner(active=True, walls=()):
    rt = Runtime()
    cm = Costmap2D(200, 200, 0.05, -5.0, -5.0)
    for x0, y0, x1, y1 in walls:
        cm.costs[int((y0 + 5) / 0.05) : int((y1 + 5) / 0.05),
                 int((x0 + 5) / 0.05) : int((x1 + 5) / 0.05)] = LETHAL_OBSTACLE  # fmt: skip
    node = Node(rt, "move_base", "/parked")
    pose = [0.0, 0.0, 0.0]  # where the robot is: the hold's timer reads it
    costmap_ros = SimpleNamespace(
        costmap=cm, footprint=LIZI, global_frame="map", robot_pose=lambda: tuple(pose)
    )
    pl = CollvoidLocalPlanner.from_namespace(
        node, costmap_ros, {**PARAMS, "active_collision_avoidance": active}, "parked"
    )
    pl.pose = pose
    pub = Node(rt, "sim", "/").create_publisher(
        collvoid_msgs.PoseTwistWithCovariance, "/position_share"
    )
    return rt, pl, pub


def share(rt, pub, robot_id, x, y, yaw, v, controlled=True):
    m = collvoid_msgs.PoseTwistWithCovariance(robot_id=robot_id, radius=BODY)
    m.controlled = controlled
    m.header.stamp = Time.from_sec(rt.now())
    m.pose.pose.position = geometry_msgs.Point(x=x, y=y)
    m.pose.pose.orientation = geometry_msgs.Quaternion(z=math.sin(yaw / 2), w=math.cos(yaw / 2))
    m.holonomic_velocity = geometry_msgs.Vector3(x=v * math.cos(yaw), y=v * math.sin(yaw))
    m.footprint.polygon.points = [geometry_msgs.Point32(x=a, y=b) for a, b in LIZI]
    pub.publish(m)
    rt.run(duration=0.01)


def parked_at_origin(pl):
    """The planner's goal reached where the robot stands, (0, 0, 0)."""
    pl.set_plan(np.array([[-1.0, 0.0, 0.0], [0.0, 0.0, 0.0]]))
    assert pl.compute_velocity_commands((0.0, 0.0, 0.0), (0.0, 0.0, 0.0)).vx == 0.0
    assert pl.is_goal_reached()


def test_a_parked_robot_backs_away_from_one_coming_at_it_and_goes_home():
    rt, pl, pub = planner()
    parked_at_origin(pl)
    assert pl.hold_speed((0.0, 0.0, 0.0), 0.0) == 0.0  # home; nobody around
    share(rt, pub, "other", 1.3, 0.02, math.pi, 0.5)  # head-on at 0.5 m/s, 0.8 m apart
    v = pl.hold_speed((0.0, 0.0, 0.0), 0.0)
    assert v < -0.1  # its share of the avoidance: backwards along its heading
    share(rt, pub, "other", 1.3, 0.02, math.pi, 0.0, controlled=False)  # it stopped
    rt.run(duration=2.5)  # and then left: its share is stale
    assert pl.hold_speed((-0.3, 0.0, 0.0), 0.0) > 0.0  # back to where it parked
    assert pl.hold_speed((0.3, 0.0, 0.0), 0.0) < 0.0


def test_a_parked_robot_does_not_back_into_a_wall():
    rt, pl, pub = planner(walls=[(-0.45, -1.0, -0.3, 1.0)])  # 0.1 m behind its back
    parked_at_origin(pl)
    share(rt, pub, "other", 1.3, 0.02, math.pi, 0.5)
    assert pl.hold_speed((0.0, 0.0, 0.0), 0.0) == 0.0


@pytest.mark.parametrize("active", [True, False])
def test_the_hold_drives_only_after_the_goal_is_reached_and_move_base_stopped(active):
    rt, pl, pub = planner(active)
    cmds = []
    Node(rt, "listen", "/").create_subscription(
        geometry_msgs.Twist, "/parked/cmd_vel", lambda m: cmds.append(m.linear.x), 10
    )
    parked_at_origin(pl)
    for _ in range(10):
        share(rt, pub, "other", 1.3, 0.02, math.pi, 0.5)
        rt.run(duration=0.09)
    if not active:
        assert cmds == []
        return
    assert cmds and min(cmds) < -0.1
    n = len(cmds)
    pl.set_plan(np.array([[0.0, 0.0, 0.0], [2.0, 0.0, 0.0]]))  # a new goal: move_base drives
    pl.compute_velocity_commands((0.0, 0.0, 0.0), (0.0, 0.0, 0.0))
    rt.run(duration=0.5)
    assert len(cmds) == n


def test_the_goal_turn_runs_at_max_vel_theta_until_it_must_slow_to_stop():
    """base_local_planner's turn rate |yaw error| (1/s) crept through the last radian of a
    lizi's turn; the turn now runs at max_vel_theta, slowed only as acc_lim_theta requires."""
    rt, pl, _ = planner(active=False)
    pl.set_plan(np.array([[-1.0, 0.0, 0.0], [0.0, 0.0, 0.0]]))
    yaw, w, rates = -1.2, 0.0, []
    for _ in range(40):
        cmd = pl.compute_velocity_commands((0.0, 0.0, yaw), (0.0, 0.0, w))
        if pl.is_goal_reached():
            break
        w = cmd.vtheta
        rates.append(w)
        yaw += w * 0.1
    assert pl.is_goal_reached() and abs(yaw) <= 0.3
    assert max(rates) == pytest.approx(1.5)
    assert len(rates) <= 8  # 0.9 rad at up to 1.5 rad/s (ramp 0.32 rad/s per cycle)
