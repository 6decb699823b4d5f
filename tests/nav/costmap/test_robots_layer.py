"""robots_layer: still robots from /position_share become high-cost footprints (padded by this
robot's inscribed radius), moving ones and the robot itself do not, a robot that leaves is
cleared, and navfn plans around a parked robot but still through one standing on the goal."""

import math
from types import SimpleNamespace

import numpy as np
import pytest

from fleetsim.msgs import collvoid_msgs, geometry_msgs
from fleetsim.msgs.builtin_interfaces import Time
from fleetsim.nav.costmap.costmap_2d import INSCRIBED_INFLATED_OBSTACLE, LETHAL_OBSTACLE
from fleetsim.nav.costmap.layered_costmap import LayeredCostmap
from fleetsim.nav.errors import GoalOccupied
from fleetsim.nav.multirobot.uncertainty import widest_spread
from fleetsim.runtime import Node, Runtime

SQUARE = [[-0.2, -0.2], [-0.2, 0.2], [0.2, 0.2], [0.2, -0.2]]
PARAMS = {
    "global_frame": "/map",
    "width": 10.0,
    "height": 10.0,
    "resolution": 0.05,
    "footprint": [[-0.2, -0.2], [-0.2, 0.2], [0.2, 0.2], [0.2, -0.2]],
    "plugins": [
        {"name": "robots_layer", "type": "fleetsim::RobotsLayer"},
        {"name": "inflation_layer", "type": "costmap_2d::InflationLayer"},
    ],
    "inflation_layer": {"inflation_radius": 0.5},
}


def shared(rid, x, y, t, vx=0.0):
    msg = collvoid_msgs.PoseTwistWithCovariance(robot_id=rid, radius=0.3)
    msg.header.stamp = Time.from_sec(t)
    msg.pose.pose.position = geometry_msgs.Point(x=x, y=y)
    msg.holonomic_velocity.x = vx
    msg.footprint.polygon.points = [geometry_msgs.Point32(x=a, y=b) for a, b in SQUARE]
    return msg


def cost_at(cm, x, y):
    m = cm.costmap
    return int(m.costs[int((y - m.origin_y) / m.resolution), int((x - m.origin_x) / m.resolution)])


def test_still_robots_are_marked_and_inflated_moving_ones_and_self_are_not():
    rt = Runtime()
    rt.params.set("/lizi1/tf_prefix", "lizi1")
    node = Node(rt, "move_base", "/lizi1")
    cm = LayeredCostmap.from_params(PARAMS, "/lizi1/move_base/global_costmap")
    layer = cm.layer("robots_layer")
    layer.connect(SimpleNamespace(node=node, global_frame="map"))
    pub = Node(rt, "talker", "/").create_publisher(
        collvoid_msgs.PoseTwistWithCovariance, "/position_share"
    )
    pub.publish(shared("lizi2", 3.0, 3.0, 0.0))  # parked
    pub.publish(shared("lizi3", 7.0, 7.0, 0.0, vx=0.4))  # driving
    pub.publish(shared("lizi1", 5.0, 5.0, 0.0))  # this robot
    rt.run(duration=0.05)
    cm.update_map(5.0, 5.0, 0.0)
    assert cost_at(cm, 3.0, 3.0) == 252
    # the square's half-width 0.2 x 0.95, padded by this robot's inscribed radius 0.2
    assert cost_at(cm, 3.0 + 0.36, 3.0) == 252
    assert cost_at(cm, 3.0 + 0.45, 3.0) == 0  # below lethal: not inflated
    assert cost_at(cm, 7.0, 7.0) == 0 and cost_at(cm, 5.0, 5.0) == 0
    # lizi2 drives off: its old cells are cleared at the next update
    pub.publish(shared("lizi2", 3.0, 3.0, 0.1, vx=0.3))
    rt.run(duration=0.05)
    cm.update_map(5.0, 5.0, 0.0)
    assert cost_at(cm, 3.0, 3.0) == 0


def test_a_silent_robot_is_dropped_after_two_seconds():
    rt = Runtime()
    node = Node(rt, "move_base", "/lizi1")
    cm = LayeredCostmap.from_params(PARAMS, "/lizi1/move_base/global_costmap")
    cm.layer("robots_layer").connect(SimpleNamespace(node=node, global_frame="map"))
    pub = Node(rt, "talker", "/").create_publisher(
        collvoid_msgs.PoseTwistWithCovariance, "/position_share"
    )
    pub.publish(shared("lizi2", 3.0, 3.0, 0.0))
    rt.run(duration=1.0)
    cm.update_map(5.0, 5.0, 0.0)
    assert cost_at(cm, 3.0, 3.0) == 252
    rt.run(duration=1.5)
    cm.update_map(5.0, 5.0, 0.0)
    assert cost_at(cm, 3.0, 3.0) == 0


def test_set_robots_marks_given_polygons_lethal_ones_inflated():
    params = {**PARAMS, "robots_layer": {"cost": LETHAL_OBSTACLE}}
    cm = LayeredCostmap.from_params(params, "gc")
    poly = np.array(SQUARE) + np.array([2.0, 8.0])
    cm.layer("robots_layer").set_robots([poly])
    cm.update_map(5.0, 5.0, 0.0)
    assert cost_at(cm, 2.0, 8.0) == LETHAL_OBSTACLE
    assert cost_at(cm, 2.0 + 0.3, 8.0) == INSCRIBED_INFLATED_OBSTACLE  # within inscribed r
    assert 0 < cost_at(cm, 2.0 + 0.55, 8.0) < INSCRIBED_INFLATED_OBSTACLE  # inflated
    assert math.isclose(cost_at(cm, 8.0, 2.0), 0)


def test_navfn_plans_around_a_parked_robot_and_through_one_on_the_goal():
    from fleetsim.nav.costmap.costmap_2d import Costmap2D
    from fleetsim.nav.planners import NavFn, NavfnParams

    params = {**PARAMS, "width": 6.0, "height": 2.0}
    cm = LayeredCostmap.from_params(params, "gc")
    layer = cm.layer("robots_layer")
    # a 2 m wide strip, a robot parked in its middle at (3, 0.6): room to pass above it
    layer.set_robots([np.array(SQUARE) + np.array([3.0, 0.6])])
    cm.update_map(0.0, 0.0, 0.0)
    assert isinstance(cm.costmap, Costmap2D)
    planner = NavFn(cm.costmap, NavfnParams(), "map")
    path = planner.create_plan((0.5, 0.6, 0.0), (5.5, 0.6, 0.0)).poses
    near = np.hypot(path[:, 0] - 3.0, path[:, 1] - 0.6).min()
    assert near > 0.3  # around it
    layer.set_robots([np.array(SQUARE) + np.array([5.5, 0.6])])  # now on the goal
    cm.update_map(0.0, 0.0, 0.0)
    path = planner.create_plan((0.5, 0.6, 0.0), (5.5, 0.6, 0.0)).poses
    assert np.hypot(*(path[-1, :2] - [5.5, 0.6])) < 0.1


def lethal_costmap(ns, layer_params):
    """(runtime, a costmap of the robots layer with ``layer_params`` listening as the robot in
    ``ns``, a /position_share publisher)."""
    rt = Runtime()
    node = Node(rt, "move_base", ns)
    cm = LayeredCostmap.from_params({**PARAMS, "robots_layer": layer_params}, "lc")
    cm.layer("robots_layer").connect(SimpleNamespace(node=node, global_frame="map"))
    pub = Node(rt, "talker", "/").create_publisher(
        collvoid_msgs.PoseTwistWithCovariance, "/position_share"
    )
    return rt, cm, pub


def test_a_local_costmap_marks_every_robot_with_its_own_padding():
    """A laser above the other robots' bodies does not see them: a local costmap marks them
    from /position_share, moving ones too, lethal, padded by ``padding`` m instead of this
    robot's inscribed radius (its planner checks the footprint itself)."""
    layer_params = {"cost": LETHAL_OBSTACLE, "still_speed": 100.0, "padding": 0.05}
    rt, cm, pub = lethal_costmap("/hunter1", layer_params)
    pub.publish(shared("hunter2", 3.0, 3.0, 0.0, vx=0.5))
    rt.run(duration=0.05)
    cm.update_map(5.0, 5.0, 0.0)
    assert cost_at(cm, 3.0, 3.0) == LETHAL_OBSTACLE
    assert cost_at(cm, 3.0 + 0.22, 3.0) == LETHAL_OBSTACLE  # 0.2 x 0.95 + 0.05
    assert cost_at(cm, 3.0 + 0.27, 3.0) == INSCRIBED_INFLATED_OBSTACLE  # inflated, not marked


def test_a_robot_sharing_its_spread_is_marked_by_its_outline_by_direction():
    """A robot parked with amcl, uncertain 0.25 m along x and 0.03 m across, shares its
    square padded by its widest spread (0.54 m all round); the
    layer marks its body plus the spread in each direction, so the way beside it stays open
    (`uncertainty.spread_outline`)."""
    layer_params = {"cost": LETHAL_OBSTACLE, "padding": 0.0, "static_scale": 1.0}
    rt, cm, pub = lethal_costmap("/lizi1", layer_params)
    cov = np.diag([0.25**2, 0.03**2])
    pad = widest_spread(cov, 0.1, 2 * math.hypot(0.2, 0.2))
    msg = shared("lizi2", 3.0, 3.0, 0.0)
    msg.footprint.polygon.points = [
        geometry_msgs.Point32(x=a + math.copysign(pad, a), y=b + math.copysign(pad, b))
        for a, b in SQUARE
    ]
    msg.pose.covariance[[0, 1, 6, 7]] = cov.reshape(-1)
    pub.publish(msg)
    rt.run(duration=0.05)
    cm.update_map(5.0, 5.0, 0.0)
    assert pad > 0.45
    assert cost_at(cm, 3.0 + 0.2 + pad - 0.03, 3.0) == LETHAL_OBSTACLE  # along: all of it
    assert cost_at(cm, 3.0, 3.0 + 0.2 + 0.06) == LETHAL_OBSTACLE  # across: body and spread
    assert cost_at(cm, 3.0, 3.0 + 0.2 + 0.12) < LETHAL_OBSTACLE  # not the 0.49 m padding


# -- clear_robots: the other robots' bodies, as a laser saw them, are erased ------------------


def _seen_costmap(order, **robots):
    """A 10 x 10 m costmap with an obstacle (or voxel) layer fed one observation source and a
    robots layer, in ``order``; returns it and a /position_share publisher."""
    rt = Runtime()
    node = Node(rt, "move_base", "/lizi1")
    kinds = {
        "obstacle_layer": "costmap_2d::ObstacleLayer",
        "voxel_layer": "costmap_2d::VoxelLayer",
        "inflation_layer": "costmap_2d::InflationLayer",
    }
    params = {
        "global_frame": "/map",
        "width": 10.0,
        "height": 10.0,
        "resolution": 0.05,
        "footprint": SQUARE,
        "plugins": [{"name": n, "type": kinds.get(n, "fleetsim::RobotsLayer")} for n in order],
        "robots_layer": robots,
    }
    for n in set(kinds) & set(order) - {"inflation_layer"}:
        params[n] = {
            "observation_sources": "scan",
            "scan": {"data_type": "LaserScan", "marking": True, "clearing": False},
            "obstacle_range": 8.0,
        }
    cm = LayeredCostmap.from_params(params, "/lizi1/move_base/global_costmap")
    cm.layer("robots_layer").connect(SimpleNamespace(node=node, global_frame="map"))
    pub = Node(rt, "talker", "/").create_publisher(
        collvoid_msgs.PoseTwistWithCovariance, "/position_share"
    )
    return rt, cm, pub


def _hits(cm, name, points):
    pts = np.array([[x, y, 0.1] for x, y in points])
    cm.layer(name).add_observation("scan", [5.0, 5.0, 0.1], pts)


# a laser's hits on the near side of lizi2's square body centred at (x, 3), and on a wall
def _body(x):
    return [(x - 0.2, 2.9), (x - 0.2, 3.0), (x - 0.2, 3.1), (x - 0.1, 2.8), (x, 2.8)]


WALL = [(1.0, 1.0), (1.05, 1.0), (2.0, 2.55)]  # the last a cell beyond the padding


@pytest.mark.parametrize(
    "order",
    [
        ("obstacle_layer", "robots_layer"),
        ("robots_layer", "obstacle_layer"),
        ("voxel_layer", "robots_layer"),
    ],
)
def test_a_moving_robot_leaves_no_image_and_no_wake(order):
    layer = next(n for n in order if n != "robots_layer")
    rt, cm, pub = _seen_costmap(order)
    pub.publish(shared("lizi2", 2.0, 3.0, 0.0, vx=0.2))
    rt.run(duration=0.05)
    _hits(cm, layer, _body(2.0) + WALL)
    cm.update_map(5.0, 5.0, 0.0)
    for x, y in _body(2.0):
        assert cost_at(cm, x, y) == 0, (x, y)
        assert cm.layer(layer).grid.costs[int(y / 0.05), int(x / 0.05)] == 0
        if layer == "voxel_layer":  # the column's voxels too, or a later mark counts them
            assert cm.layer(layer).marked[int(y / 0.05), int(x / 0.05)] == 0
    for x, y in WALL:
        assert cost_at(cm, x, y) == LETHAL_OBSTACLE, (x, y)
    # lizi2 drives 0.6 m east: the next scan sees it there; where it was stays free
    pub.publish(shared("lizi2", 2.6, 3.0, 0.1, vx=0.2))
    rt.run(duration=0.05)
    _hits(cm, layer, _body(2.6))
    cm.update_map(5.0, 5.0, 0.0)
    for x, y in _body(2.0) + _body(2.6):
        assert cost_at(cm, x, y) == 0, (x, y)


def test_without_clear_robots_the_image_stays_as_a_wake():
    rt, cm, pub = _seen_costmap(("obstacle_layer", "robots_layer"), clear_robots=False)
    pub.publish(shared("lizi2", 2.0, 3.0, 0.0, vx=0.2))
    rt.run(duration=0.05)
    _hits(cm, "obstacle_layer", _body(2.0))
    cm.update_map(5.0, 5.0, 0.0)
    pub.publish(shared("lizi2", 2.6, 3.0, 0.1, vx=0.2))
    rt.run(duration=0.05)
    cm.update_map(5.0, 5.0, 0.0)
    assert all(cost_at(cm, x, y) == LETHAL_OBSTACLE for x, y in _body(2.0))


def test_the_padding_grows_with_the_robots_speed():
    # a hit 0.14 m outside a parked robot's outline stays (0.1 m padding); the same hit
    # beside a robot at 0.5 m/s (0.1 + 0.3 s x 0.5 m/s) is its image, erased
    for vx, expected in ((0.0, LETHAL_OBSTACLE), (0.5, 0)):
        rt, cm, pub = _seen_costmap(("obstacle_layer", "robots_layer"), still_speed=0.0)
        pub.publish(shared("lizi2", 2.0, 3.0, 0.0, vx=vx))
        rt.run(duration=0.05)
        _hits(cm, "obstacle_layer", [(2.34, 3.0)])
        cm.update_map(5.0, 5.0, 0.0)
        assert cost_at(cm, 2.34, 3.0) == expected, vx


def test_a_robot_standing_still_keeps_its_image():
    """What the laser sees of a parked robot is where it is: it stays (the collvoid planner
    tells the parked robots its sensors see by it), and the layer marks the robot too."""
    rt, cm, pub = _seen_costmap(("obstacle_layer", "robots_layer"))
    pub.publish(shared("lizi2", 2.0, 3.0, 0.0))
    rt.run(duration=0.05)
    _hits(cm, "obstacle_layer", _body(2.0))
    cm.update_map(5.0, 5.0, 0.0)
    assert all(cost_at(cm, x, y) == LETHAL_OBSTACLE for x, y in _body(2.0))
    assert cost_at(cm, 2.1, 3.0) == 252
    # it drives off: its image goes at the next update
    pub.publish(shared("lizi2", 2.1, 3.0, 0.1, vx=0.3))
    rt.run(duration=0.05)
    cm.update_map(5.0, 5.0, 0.0)
    assert all(cost_at(cm, x, y) == 0 for x, y in _body(2.0))


def test_clear_still_robots_erases_a_parked_robots_image_so_navfn_takes_its_goal():
    """In a global costmap (clear_still_robots) a parked robot's laser image goes and only the
    layer's mark (252, below navfn's obstacle) stays: a goal where another robot stands gets a
    plan (three jackals in Willow, each sent to another's start, had none for 11-16 s)."""
    from fleetsim.nav.planners import NavFn, NavfnParams

    order = ("obstacle_layer", "robots_layer", "inflation_layer")
    for clear_still, expected in ((False, LETHAL_OBSTACLE), (True, 252)):
        rt, cm, pub = _seen_costmap(order, clear_still_robots=clear_still)
        pub.publish(shared("lizi2", 2.0, 3.0, 0.0))
        rt.run(duration=0.05)
        _hits(cm, "obstacle_layer", _body(2.0) + WALL)
        cm.update_map(5.0, 5.0, 0.0)
        assert cost_at(cm, 1.8, 3.0) == expected, clear_still
        assert cost_at(cm, 2.0, 2.55) == LETHAL_OBSTACLE  # the wall's hit beside it is kept
        planner = NavFn(cm.costmap, NavfnParams(), "map")
        if clear_still:
            path = planner.create_plan((5.0, 5.0, 0.0), (2.0, 3.0, 0.0)).poses
            assert np.hypot(*(path[-1, :2] - [2.0, 3.0])) < 0.1
        else:
            with pytest.raises(GoalOccupied):
                planner.create_plan((5.0, 5.0, 0.0), (2.0, 3.0, 0.0))


@pytest.mark.parametrize(
    "order", [("obstacle_layer", "robots_layer"), ("robots_layer", "obstacle_layer")]
)
def test_clear_still_robots_erases_only_under_the_mark(order):
    """Only the cells the layer marks (the body scaled by static_scale, here unpadded) lose
    their hits: a hit 5 cm outside the mark stays lethal, one inside becomes the mark's cost."""
    rt, cm, pub = _seen_costmap(order, clear_still_robots=True, padding=0.0)
    pub.publish(shared("lizi2", 2.0, 3.0, 0.0))
    rt.run(duration=0.05)
    inside, outside = (2.0, 2.85), (2.0, 2.76)  # the mark reaches 2.81 (0.95 x 0.2 m)
    _hits(cm, order[0] if order[0] != "robots_layer" else order[1], [inside, outside])
    cm.update_map(5.0, 5.0, 0.0)
    assert cost_at(cm, *inside) == 252
    assert cost_at(cm, *outside) == LETHAL_OBSTACLE
