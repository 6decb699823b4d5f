"""The collvoid planner's neighbours and radii (`collvoid_neighbours`): the tracking allowance
shrinks to the gap between two robots, so robots side by side are not shoved apart."""

import math
from types import SimpleNamespace

import numpy as np
import pytest

from fleetsim.msgs import collvoid_msgs, geometry_msgs
from fleetsim.msgs.builtin_interfaces import Time
from fleetsim.nav.controllers.collvoid_planner import CollvoidLocalPlanner
from fleetsim.nav.costmap.costmap_2d import Costmap2D
from fleetsim.runtime import Node, Runtime

LIZI = np.array([[-0.19, -0.16], [-0.19, 0.16], [0.19, 0.16], [0.19, -0.16]])
BODY = math.hypot(0.19, 0.16)
LIZI_PARAMS = {
    "max_vel_x": 0.5,
    "min_vel_x": 0.1,
    "min_error_holo": 0.01,
    "max_error_holo": 0.05,
    "safety_margin": 0.0,
}


def _planner(rt):
    node = Node(rt, "move_base", "/lizi1")
    costmap = SimpleNamespace(
        costmap=Costmap2D(80, 80, 0.05, -2.0, -2.0), footprint=LIZI, global_frame="map"
    )
    return CollvoidLocalPlanner.from_namespace(node, costmap, LIZI_PARAMS, "lizi1")


def test_the_tracking_allowance_is_at_most_the_gap_between_the_two():
    pl = _planner(Runtime())
    own_r = pl.own_radius(0.5)
    assert own_r == pytest.approx(BODY + 0.05)
    radii = np.full(4, BODY)
    dist = 2 * BODY + np.array([1.0, 0.03, 0.005, -0.02])  # far, 3 cm, 5 mm, overlapping
    pair = pl.pair_radii(own_r, radii, dist)
    assert pair == pytest.approx(2 * BODY + np.array([0.05, 0.03, 0.01, 0.01]))
    assert np.all(pair[:2] <= dist[:2])  # robots that do not touch are not inside each other


def test_two_robots_side_by_side_a_few_cm_apart_are_not_shoved_apart():
    """lizi2 runs beside us 3 cm from our body, both east at 0.5 m/s, our plan east: ORCA keeps
    our velocity (the whole 5 cm allowance put lizi2 inside our velocity obstacle and its
    collision branch pushed us off sideways at ~0.1 m/s)."""
    rt = Runtime()
    pl = _planner(rt)
    pl.set_plan(np.c_[np.linspace(0.0, 3.0, 30), np.zeros(30), np.zeros(30)])
    pub = Node(rt, "sim", "/").create_publisher(
        collvoid_msgs.PoseTwistWithCovariance, "/position_share"
    )
    for _ in range(5):
        m = collvoid_msgs.PoseTwistWithCovariance(robot_id="lizi2", radius=BODY, controlled=True)
        m.header.stamp = Time.from_sec(rt.now())
        m.pose.pose.position = geometry_msgs.Point(x=0.0, y=2 * BODY + 0.03)
        m.pose.pose.orientation = geometry_msgs.Quaternion(w=1.0)
        m.holonomic_velocity = geometry_msgs.Vector3(x=0.5)
        m.footprint.polygon.points = [geometry_msgs.Point32(x=a, y=b) for a, b in LIZI]
        pub.publish(m)
        rt.run(duration=0.1)
        pl.compute_velocity_commands((0.0, 0.0, 0.0), (0.5, 0.0, 0.0))
    # lizi2's half-plane and, the discs touching, its contact line (contact_halfplanes); no walls
    assert len(pl.lines[0]) == 2 and pl.lines[2] == 0
    assert abs(pl.last_holo[1]) < 0.01
    assert pl.last_holo[0] == pytest.approx(0.5, abs=0.01)
