"""CollvoidLocalPlanner in a kinematic loop (unicycles, a shared costmap in the map frame, the
robots' states on /position_share): swaps and crossings without contact, walls respected,
deadlocks broken by priority, bad parameters refused, move_base finds the plugin by name."""

import dataclasses
import math
from types import SimpleNamespace

import numpy as np
import pytest

from fleetsim.errors import ParameterError
from fleetsim.msgs import collvoid_msgs, geometry_msgs
from fleetsim.msgs.builtin_interfaces import Time
from fleetsim.nav.controllers.collvoid_params import CollvoidParams
from fleetsim.nav.controllers.collvoid_planner import CollvoidLocalPlanner
from fleetsim.nav.costmap.costmap_2d import LETHAL_OBSTACLE, NO_INFORMATION, Costmap2D
from fleetsim.nav.costmap.footprint import footprint_at, padded_footprint, polygon_cells
from fleetsim.nav.move_base_plugins import LOCAL_PLANNERS
from fleetsim.nav.multirobot.deadlock import DeadlockRule, priority_key
from fleetsim.nav.multirobot.holonomic import (
    detour_velocity,
    gaps_closed,
    obstacle_points,
    rotated,
    tracking_command,
    without_robots,
)
from fleetsim.nav.multirobot.position_share import XY_COVARIANCE
from fleetsim.nav.multirobot.uncertainty import widest_spread
from fleetsim.runtime import Node, Runtime

LIZI = np.array([[-0.19, -0.16], [-0.19, 0.16], [0.19, 0.16], [0.19, -0.16]])
BODY = math.hypot(0.19, 0.16)
LIMITS = {"max_vel_x": 0.5, "min_vel_x": 0.1, "xy_goal_tolerance": 0.2, "yaw_goal_tolerance": 3.2}


def empty_map(walls=()):
    cm = Costmap2D(400, 400, 0.05, -10.0, -10.0)
    for x0, y0, x1, y1 in walls:
        c0, c1 = int((x0 + 10) / 0.05), int((x1 + 10) / 0.05)
        r0, r1 = int((y0 + 10) / 0.05), int((y1 + 10) / 0.05)
        cm.costs[r0:r1, c0:c1] = LETHAL_OBSTACLE
    return cm


class Fleet:
    """N unicycles, each with its own node and planner, sharing positions every cycle."""

    def __init__(
        self, starts, goals, walls=(), footprint=LIZI, padding=0.0, covariances=None, **params
    ):
        self.footprint = np.asarray(footprint, dtype=float)  # padded by ``padding`` m
        # each robot's localization spread (2, 2) m^2, map frame, or None: its own, and shared
        # with the footprint padded by its widest spread, as me_publisher does
        self.covariances = covariances or [None] * len(starts)
        self.rt = Runtime()
        self.cm = empty_map(walls)
        self.pub = Node(self.rt, "sim", "/").create_publisher(
            collvoid_msgs.PoseTwistWithCovariance, "/position_share"
        )
        self.state = np.array(starts, dtype=float)  # (N, 3)
        self.vel = np.zeros((len(starts), 3))
        self.goals = goals
        self.planners = []
        for i, (g, s) in enumerate(zip(goals, starts)):
            node = Node(self.rt, "move_base", f"/robot{i + 1}")
            costmap_ros = SimpleNamespace(
                costmap=self.cm,
                footprint=self.footprint,
                unpadded_footprint=padded_footprint(self.footprint, -padding),
                global_frame="map",
            )
            pl = CollvoidLocalPlanner.from_namespace(
                node, costmap_ros, {**LIMITS, **params}, f"robot{i + 1}"
            )
            line = np.linspace(s[:2], g[:2], 50)
            pl.set_plan(np.c_[line, np.full(50, g[2])])
            pl._covariance = self.covariances[i]
            self.planners.append(pl)
        self.min_gap = math.inf
        self.min_wall = math.inf
        self.paths = np.zeros(len(starts))
        self.backed = np.zeros(len(starts))  # m driven backwards

    def share(self):
        for i, (x, y, yaw) in enumerate(self.state):
            radius = float(np.hypot(*self.footprint.T).max())
            m = collvoid_msgs.PoseTwistWithCovariance(robot_id=f"robot{i + 1}", radius=radius)
            m.header.stamp = Time.from_sec(self.rt.now())
            m.pose.pose.position = geometry_msgs.Point(x=x, y=y)
            m.pose.pose.orientation = geometry_msgs.Quaternion(
                z=math.sin(yaw / 2), w=math.cos(yaw / 2)
            )
            v = self.vel[i, 0]
            m.holonomic_velocity = geometry_msgs.Vector3(x=v * math.cos(yaw), y=v * math.sin(yaw))
            footprint, cov = self.footprint, self.covariances[i]
            if cov is not None:
                m.pose.covariance[XY_COVARIANCE] = np.asarray(cov, dtype=float).reshape(-1)
                footprint = padded_footprint(footprint, widest_spread(cov, 0.1, 2 * radius))
                m.radius = float(np.hypot(*footprint.T).max())
            m.footprint.polygon.points = [geometry_msgs.Point32(x=a, y=b) for a, b in footprint]
            self.pub.publish(m)

    def see(self):
        """Before each cycle: what the robots' local costmaps hold besides the walls."""

    def run(self, seconds, dt=0.1):
        for _ in range(int(seconds / dt)):
            self.share()
            self.rt.run(duration=dt)
            self.see()
            for i, pl in enumerate(self.planners):
                if pl.is_goal_reached():
                    self.vel[i] = 0
                    continue
                cmd = pl.compute_velocity_commands(tuple(self.state[i]), tuple(self.vel[i]))
                self.vel[i] = (cmd.vx, cmd.vy, cmd.vtheta)
            x, y, yaw = self.state.T
            v, w = self.vel[:, 0], self.vel[:, 2]
            self.state = np.stack(
                [x + v * np.cos(yaw) * dt, y + v * np.sin(yaw) * dt, yaw + w * dt], 1
            )
            self.paths += np.abs(v) * dt
            self.backed += np.maximum(-v, 0.0) * dt
            xy = self.state[:, :2]
            d = np.linalg.norm(xy[:, None] - xy[None], axis=-1)
            d[np.diag_indices(len(xy))] = np.inf
            self.min_gap = min(self.min_gap, float(d.min()) - 2 * BODY)
            if all(pl.is_goal_reached() for pl in self.planners):
                return True
        return False


class SeeingFleet(Fleet):
    """A Fleet whose robots see each other: each one's local costmap holds the walls and the
    other robots' bodies as lethal cells, as a laser at body height marks them (a pioneer3at's;
    a lizi's sweeps above the other lizis)."""

    def __init__(self, starts, goals, walls=(), **params):
        super().__init__(starts, goals, walls, **params)
        for pl in self.planners:
            pl.costmap = empty_map(walls)
        self.walls = self.cm.costs.copy()

    def see(self):
        for i, pl in enumerate(self.planners):
            pl.costmap.costs[:] = self.walls
            for j, (x, y, yaw) in enumerate(self.state):
                if j != i:
                    rows, cols = polygon_cells(pl.costmap, footprint_at(LIZI, x, y, yaw))
                    pl.costmap.costs[rows, cols] = LETHAL_OBSTACLE


@pytest.mark.parametrize("fleet", [Fleet, SeeingFleet])
def test_head_on_swap_with_or_without_the_others_in_the_costmap(fleet):
    """Robots whose lasers see each other pass as those that do not: the others' images in
    the local costmap are cleared where /position_share puts them, instead of being taken for
    walls with all the responsibility (two pioneer3ats stood face to face for 40-55 s)."""
    f = fleet([(-3, 0, 0), (3, 0, math.pi)], [(3, 0, 0), (-3, 0, math.pi)])
    assert f.run(20.0) and f.min_gap > 0.0


def test_a_standing_robot_in_view_is_an_obstacle_of_its_shared_shape():
    """A robot that has stood still for a second where our sensors see it (a few lethal cells
    of its near face in our costmap) leaves ORCA and is drawn into the walls with the footprint
    it shares, wheels and all (a pioneer3at passing one parked in a corridor scraped the wheels
    its laser had not seen); one we do not see stays an ORCA disc."""
    for seen in (True, False):
        f = Fleet([(-1.0, 0, 0), (0.0, 0.0, math.pi)], [(3.0, 0, 0), (0.0, 0.0, math.pi)])
        pl = f.planners[0]
        pl.costmap = empty_map()
        if seen:
            pl.costmap.costs[199:201, 195:197] = LETHAL_OBSTACLE  # its west face, (-0.2, 0.0)
        for _ in range(12):  # it counts as parked once it has stood still for 1 s
            f.share()
            f.rt.run(duration=0.1)
            pl.compute_velocity_commands(tuple(f.state[0]), (0.0, 0.0, 0.0))
            if _ == 8:
                assert pl.lines[0].shape[0] - pl.lines[2] == 1  # still in ORCA after 0.9 s
        costs, n_obst = pl.grid[0], pl.lines[2]
        rows, cols = polygon_cells(pl.costmap, footprint_at(LIZI, 0.0, 0.0, math.pi))
        robots = pl.lines[0].shape[0] - n_obst  # the robot half-planes
        if seen:
            assert np.all(costs[rows, cols] == LETHAL_OBSTACLE) and robots == 0 and n_obst > 0
        else:
            assert costs is pl.costmap.costs and robots == 1 and n_obst == 0


@pytest.mark.parametrize("seen", [True, False])
def test_a_parked_robot_our_laser_marks_enters_the_costmap_by_its_body_not_its_spread(seen):
    """robot2 parked at the origin with amcl's spread (std 0.12 m across, 0.3 m along). Where
    robot1's laser marks it, its body, not its body grown by the spread, enters robot1's
    costmap: the laser shows where it is (the jackals' corridor of 4 with amcl jammed when a
    jackal parked in the corridor's middle was drawn grown, leaving no room beside it). One no
    sensor of ours marks, counted once robot1 is blocked, is drawn grown by its spread."""
    cov = np.diag([0.3**2, 0.12**2])
    f = Fleet([(-1.5, 0.0, 0.0), (0.0, 0.0, 0.0)], [(3.0, 0.0, 0.0), (0.0, 0.0, 0.0)],
              covariances=[None, cov], deadlock_time=0.5)  # fmt: skip
    pl = f.planners[0]
    pl.costmap = empty_map()
    if seen:
        pl.costmap.costs[199:201, 195:197] = LETHAL_OBSTACLE  # its west face, (-0.2, 0.0)
    for _ in range(12):  # parked once it has stood still for 1 s (and robot1 blocked)
        f.share()
        f.rt.run(duration=0.1)
        pl.compute_velocity_commands(tuple(f.state[0]), (0.0, 0.0, 0.0))
    costs = pl.grid[0]
    body = polygon_cells(pl.costmap, footprint_at(LIZI, 0.0, 0.0, 0.0))
    assert np.all(costs[body] == LETHAL_OBSTACLE)
    grown = pl.near_robots[0].outline(pl.params.eps)
    assert grown[:, 1].max() > 0.16 + 0.2  # the spread grows it well past the body's side
    strip = np.array([[-0.1, 0.25], [0.1, 0.25], [0.1, 0.3], [-0.1, 0.3]])  # 9-14 cm beside
    beside = costs[polygon_cells(pl.costmap, strip)]
    assert np.all(beside < LETHAL_OBSTACLE) if seen else np.all(beside == LETHAL_OBSTACLE)


def test_without_robots_clears_lethal_cells_in_the_discs_only():
    cm = empty_map([(1.0, -5, 1.05, 5)])  # a wall at x = 1
    cm.costs[200:204, 180:184] = LETHAL_OBSTACLE  # a robot's image around (-0.9, 0.05)
    cm.costs[190, 170] = NO_INFORMATION  # unknown inside the disc stays unknown
    origin = (cm.origin_x, cm.origin_y)
    out = without_robots(cm.costs, origin, 0.05, np.array([[-0.9, 0.05]]), np.array([0.3]))
    assert out is not cm.costs and np.all(out[200:204, 180:184] == 0)
    assert out[190, 170] == NO_INFORMATION
    assert np.array_equal(out[:, 220], cm.costs[:, 220])  # the wall is kept
    assert np.count_nonzero(out != cm.costs) == 16
    far = without_robots(cm.costs, origin, 0.05, np.array([[-5.0, -5.0]]), np.array([0.3]))
    assert far is cm.costs  # nothing to clear: no copy


def test_head_on_swap_in_the_open_without_contact():
    f = Fleet([(-3, 0, 0), (3, 0, math.pi)], [(3, 0, 0), (-3, 0, math.pi)])
    assert f.run(40.0)
    assert f.min_gap > 0.0
    assert np.all(f.paths < 6.0 * 1.3)


def test_crossing_four_robots_without_contact():
    starts = [(-3, 0, 0), (3, 0, math.pi), (0, -3, math.pi / 2), (0, 3, -math.pi / 2)]
    goals = [(3, 0, 0), (-3, 0, 0), (0, 3, 0), (0, -3, 0)]
    f = Fleet(starts, goals)
    assert f.run(60.0)
    assert f.min_gap > 0.0


def test_corridor_swap_keeps_off_the_walls():
    walls = [(-8, 1.0, 8, 1.2), (-8, -1.2, 8, -1.0)]  # a 2 m wide corridor
    f = Fleet([(-4, 0, 0), (4, 0, math.pi)], [(4, 0, 0), (-4, 0, math.pi)], walls=walls)
    assert f.run(60.0)
    assert f.min_gap > 0.0
    assert np.all(np.abs(f.state[:, 1]) < 1.0 - BODY)


def test_in_a_corridor_too_narrow_to_pass_the_lower_priority_robot_backs_off():
    """0.9 m between the walls: the lizis cannot pass, ORCA slows them to a standstill nose
    to nose. Without the rule they stay put; with it robot2 (lower priority) backs away along
    its plan once they have faced each other across the narrow passage for
    ``narrow_deadlock_time`` (from ~3 m apart), and robot1 advances (test_yielding.py: the
    whole swap, with wide ends to back out into)."""
    walls = [(-8, 0.45, 8, 0.65), (-8, -0.65, 8, -0.45)]
    swap = ([(-3, 0, 0), (3, 0, math.pi)], [(3, 0, 0), (-3, 0, math.pi)])

    def standoff(deadlock_time):
        f = Fleet(
            *swap,
            walls=walls,
            deadlock_time=deadlock_time,
            narrow_deadlock_time=deadlock_time,
            standoff_time=deadlock_time,
            yield_time=4.0,
        )
        f.run(10.0)  # facing each other within 3 m from ~1 s, nearly stopped by 10 s
        before = f.state[:, 0].copy()
        f.run(6.0)
        assert f.min_gap > 0.0
        return f, f.state[:, 0] - before

    stalled, moved = standoff(1000.0)
    assert np.all(np.abs(moved) < 0.25)  # a creep towards each other, ~0.03 m/s
    f, moved = standoff(8.0)
    assert moved[1] > 0.5 and moved[0] > 0.3  # robot2 retreats east, robot1 follows
    assert f.planners[1].deadlock.yields >= 1 and f.planners[0].deadlock.yields == 0


@pytest.mark.parametrize("detour", [True, False])
def test_robots_parked_in_the_way_are_gone_round(detour, monkeypatch):
    """robot2 stands on robot1's straight path, robot3 beside it on the right, too close for
    robot1 to pass between (their goals are where they stand): ORCA alone leads robot1 into the
    gap and stops it there; the preferred velocity turned onto the nearest clear tangent takes
    it round on the left. (Without the detour, the stuck robot's later remedies, parked robots
    by their bodies and a new plan, `test_collvoid_replan`, are put out of reach.)"""
    extra = {}
    if not detour:
        monkeypatch.setattr("fleetsim.nav.controllers.collvoid_preference.DETOUR_REACH", 0.0)
        extra = {"deadlock_time": 1e3}
    parked = [(0.0, 0.0, math.pi / 2), (0.0, -0.62, math.pi / 2)]
    f = Fleet([(-3, 0, 0), *parked], [(3, 0, 0), *parked], **extra)
    assert f.run(30.0) is detour
    assert f.min_gap > 0.0
    if detour:
        assert f.paths[0] < 6.0 * 1.15
        assert f.state[1:] == pytest.approx(np.array(parked))


def test_detour_velocity_takes_the_tangent_on_the_side_the_ray_leans_to():
    pref = np.array([0.5, 0.0])
    ahead = np.array([[1.0, 0.05]])  # a disc just left of the ray: pass it on the right
    v, k = detour_velocity(pref, ahead, np.array([0.6]), 1.5)
    assert k == 0 and np.hypot(*v) == pytest.approx(0.5)
    assert v[1] < 0 and math.atan2(v[1], v[0]) == pytest.approx(
        math.atan2(0.05, 1.0) - math.asin(0.6 / math.hypot(1.0, 0.05)), abs=2e-3
    )
    v, k = detour_velocity(pref, np.array([[1.0, -0.05]]), np.array([0.6]), 1.5)
    assert v[1] > 0  # leans right: pass on the left
    # a second disc closing the right-hand way: the left tangent, though farther round
    pair = np.array([[1.0, 0.05], [1.0, -1.0]])
    v, k = detour_velocity(pref, pair, np.array([0.6, 0.6]), 1.5)
    assert k == 0 and v[1] > 0
    # walled in: unchanged
    ring = np.array([[math.cos(a), math.sin(a)] for a in np.linspace(0, 2 * math.pi, 9)[:-1]])
    v, k = detour_velocity(pref, ring, np.full(8, 0.6), 1.5)
    assert k == -1 and v is pref
    # beyond reach, behind, or off the ray: unchanged
    for rel in ([[2.5, 0.0]], [[-1.0, 0.0]], [[1.0, 0.8]]):
        v, k = detour_velocity(pref, np.array(rel), np.array([0.6]), 1.5)
        assert k == -1 and v is pref


def test_detour_velocity_keeps_the_side_taken_and_starts_on_the_side_it_is_heading_for():
    """willow_swap: lizi1, under way east-south-east, met lizi3 parked on its plan's far side;
    the tangent nearest the carrot made it turn 1.5-2 rad on the spot to go round on the plan's
    side (2-3 s for a lizi), and a carrot swinging from one side to the other flipped it."""
    pref = np.array([0.5, 0.0])
    ahead = np.array([[1.0, 0.05]])  # leans left: the right tangent is nearest pref
    v, _ = detour_velocity(pref, ahead, np.array([0.6]), 1.5, keep=np.array([1]))
    assert v[1] > 0  # the left side, kept
    v, _ = detour_velocity(pref, ahead, np.array([0.6]), 1.5, keep=np.array([-1]))
    assert v[1] < 0
    shut = np.array([[False, True]])  # the kept side closed by a wall: the other one
    v, _ = detour_velocity(pref, ahead, np.array([0.6]), 1.5, shut, keep=np.array([1]))
    assert v[1] < 0
    # under way north-east: the left tangent first; standing (or creeping): nearest pref
    v, _ = detour_velocity(pref, ahead, np.array([0.6]), 1.5, moving=np.array([0.3, 0.3]))
    assert v[1] > 0
    v, _ = detour_velocity(pref, ahead, np.array([0.6]), 1.5, moving=np.array([0.05, 0.05]))
    assert v[1] < 0


def make_rule(robot_id: str, **params) -> DeadlockRule:
    """A deadlock rule with the planner's parameter defaults, ``params`` changed."""
    return DeadlockRule.from_params(robot_id, dataclasses.replace(CollvoidParams(), **params))


def test_the_deadlock_rule_takes_the_planners_defaults_declared_once():
    p = CollvoidParams()
    r = DeadlockRule.from_params("lizi1", p)
    assert (r.deadlock_time, r.deadlock_progress, r.deadlock_radius, r.yield_time) == (
        p.deadlock_time, p.deadlock_progress, p.deadlock_radius, p.yield_time,
    )  # fmt: skip
    assert r.narrow_time == p.narrow_deadlock_time == 1.0
    with pytest.raises(TypeError):
        DeadlockRule("lizi1")  # no second set of defaults


def test_deadlock_rule_yields_to_the_lower_id_only_after_no_progress():
    rule = make_rule("lizi10", deadlock_time=5.0, deadlock_progress=0.2, yield_time=4.0)
    assert rule.update(0.0, 5.0, {"lizi2": 1.0}) is None
    assert rule.update(4.9, 4.95, {"lizi2": 1.0}) is None
    assert rule.update(5.1, 4.95, {"lizi2": 1.0, "lizi11": 0.5}) == "lizi2"
    assert rule.update(8.0, 4.95, {"lizi2": 1.0}) == "lizi2"  # still yielding
    assert rule.update(9.2, 4.95, {"lizi2": 1.0}) is None  # done; the clock restarts
    top = make_rule("lizi2")
    top.update(0.0, 5.0, {"lizi10": 1.0})
    assert top.update(6.0, 5.0, {"lizi10": 1.0}) is None  # priority: never yields
    assert priority_key("lizi2") < priority_key("lizi10")


def test_tracking_turns_first_then_drives_along_the_arc():
    assert tracking_command(np.array([0.0, 0.4]), 0.0, 0.4, 0.5, 1.0) == (0.0, 1.0)
    v, w = tracking_command(np.array([0.4, 0.0]), 0.0, 0.4, 0.5, 1.0)
    assert (v, w) == (pytest.approx(0.4), 0.0)
    v, w = tracking_command(
        np.array([0.4 * math.cos(0.3), 0.4 * math.sin(0.3)]), 0.0, 0.4, 0.5, 1.0
    )
    assert 0.0 < v < 0.4 and w == pytest.approx(0.75)


def test_obstacle_points_are_the_nearest_lethal_cell_per_sector():
    cm = empty_map([(1.0, -5, 1.05, 5)])  # a wall at x = 1
    pts = obstacle_points(cm.costs, (cm.origin_x, cm.origin_y), 0.05, np.zeros(2), 2.0, 24)
    assert pts[0][0] == pytest.approx(1.025) and abs(pts[0][1]) < 0.03
    assert np.all(pts[:, 0] == pytest.approx(1.025))
    sectors = ((np.arctan2(pts[:, 1], pts[:, 0]) + math.pi) / (2 * math.pi) * 24).astype(int)
    assert len(set(sectors.tolist())) == len(pts)  # one point per bearing sector
    # the wall spans bearings -63..63 deg within 2 m: about a third of the 24 sectors
    assert 7 <= len(pts) <= 10
    assert len(pts) <= 24 and np.all(np.hypot(*pts.T) <= 2.0)


@pytest.mark.parametrize(
    "params, words",
    [({"clearpath": True}, "only collvoid's ORCA solver"), ({"orca": False}, "orca false"),
     ({"type_vo": 5}, "type_vo"), ({"time_horizon": 0.0}, "time_horizon")],
)  # fmt: skip
def test_bad_parameters_are_refused_by_name(params, words):
    rt = Runtime()
    node = Node(rt, "move_base", "/r")
    cmr = SimpleNamespace(costmap=empty_map(), footprint=LIZI, global_frame="map")
    with pytest.raises((ParameterError, ValueError), match=words):
        CollvoidLocalPlanner.from_namespace(node, cmr, params, "r/CollvoidLocalPlanner")


def test_a_planner_told_to_avoid_no_robot_says_so(caplog):
    """max_neighbors 0 (or neighbor_dist 0): collvoid takes it, and robots drive into each
    other at crossings with no word of why (a new user's four lizis: 6 contacts)."""
    import logging

    rt = Runtime()
    node = Node(rt, "move_base", "/r")
    cmr = SimpleNamespace(costmap=empty_map(), footprint=LIZI, global_frame="map")
    with caplog.at_level(logging.WARNING):
        CollvoidLocalPlanner.from_namespace(node, cmr, {}, "r/CollvoidLocalPlanner")
        assert "avoids no other robot" not in caplog.text
        CollvoidLocalPlanner.from_namespace(
            node, cmr, {"max_neighbors": 0}, "r/CollvoidLocalPlanner"
        )
    assert "r/CollvoidLocalPlanner: max_neighbors 0, neighbor_dist 3: the planner avoids" in (
        caplog.text
    )


def test_move_base_knows_the_plugin_by_its_ros_name():
    assert LOCAL_PLANNERS["collvoid_local_planner/CollvoidLocalPlanner"] == "CollvoidLocalPlanner"


def test_a_narrow_meeting_is_stuck_after_narrow_deadlock_time_progress_or_not():
    """Facing each other across a passage too narrow for two, ORCA slows the pair to a creep
    that still makes progress; the meeting itself starts the clock, and a robot met there
    counts beyond deadlock_radius."""
    rule = make_rule("lizi2", deadlock_time=10.0, deadlock_radius=2.0, narrow_deadlock_time=1.0)
    assert rule.update(0.0, 6.0, {"lizi1": 2.8}, narrow=["lizi1"]) is None
    # 0.3 m of progress (a creep), still facing across the passage: stuck after 1 s
    assert rule.update(0.6, 5.7, {"lizi1": 2.4}, narrow=["lizi1"]) is None
    assert rule.update(1.1, 5.4, {"lizi1": 2.1}, narrow=["lizi1"]) == "lizi1"
    # not a narrow meeting: progress resets the clock, and 2.1 m is beyond deadlock_radius
    plain = make_rule("lizi2", deadlock_time=10.0, deadlock_radius=2.0, narrow_deadlock_time=1.0)
    plain.update(0.0, 6.0, {"lizi1": 2.8})
    assert plain.update(1.1, 5.4, {"lizi1": 2.1}) is None
    assert plain.update(11.5, 5.4, {"lizi1": 2.1}) is None  # too far to take part
    assert plain.update(11.6, 5.4, {"lizi1": 1.9}) == "lizi1"
    # the meeting over, its clock is forgotten
    top = make_rule("lizi3", deadlock_time=10.0, narrow_deadlock_time=1.0)
    top.update(0.0, 6.0, {"lizi1": 2.8}, narrow=["lizi1"])
    top.update(0.5, 5.7, {"lizi1": 2.8})
    assert top.update(1.2, 5.7, {"lizi1": 2.8}, narrow=["lizi1"]) is None


def test_the_way_round_a_parked_robot_takes_the_side_a_wall_leaves_room_on():
    """A 2 m corridor, a robot parked 0.16 m off its middle (as lizi3 on its goal in the
    held-out corridor of 4): the way past it on the narrow side is closed by the wall, so the
    detour takes the wide side even where the narrow side's tangent is nearer."""
    cm = empty_map([(-8, 1.0, 8, 1.2), (-8, -1.2, 8, -1.0)])
    grid = (cm.costs, (cm.origin_x, cm.origin_y), cm.resolution)
    me = np.array([-1.0, 0.45])
    parked = np.array([[1.0, -0.29]])  # at (0, 0.16), relative to us
    closed = gaps_closed(grid, me, parked, np.array([0.65]), BODY + 0.035)
    assert closed.tolist() == [[False, True]]  # its right (south) open, its left shut
    pref = np.array([0.5, 0.0])  # the left tangent is the nearer turn
    v, _ = detour_velocity(pref, parked, np.array([0.65]), 1.5)
    assert v[1] > 0
    v, k = detour_velocity(pref, parked, np.array([0.65]), 1.5, closed)
    assert k == 0 and v[1] < 0
    # in the open both ways are open
    assert not gaps_closed(
        (empty_map().costs, grid[1], grid[2]), me, parked, np.array([0.65]), BODY + 0.035
    ).any()


def test_a_robot_passes_one_parked_off_the_middle_of_a_corridor():
    walls = [(-8, 1.0, 8, 1.2), (-8, -1.2, 8, -1.0)]
    parked = (0.0, 0.16, 0.0)
    f = Fleet([(-3, 0.4, 0), parked], [(3, 0.0, 0), parked], walls=walls)
    assert f.run(40.0)
    assert f.min_gap > 0.0 and np.all(np.abs(f.state[:, 1]) < 1.0 - BODY)


def test_the_room_beside_a_standing_robot_is_judged_by_the_passage_not_orcas_leg():
    """The lizis' corridor of 4 with amcl, seed 1: lizi4 parked on its goal in the 2 m
    corridor's middle, lizi2 0.48 m above its line heading past it, its plan above it (0.8 m
    of room there, 1.0 m below). ORCA's combined radius with both amcl spreads is the spread
    across the leg the relative velocity passes: 0.71-0.81 m as the preferred velocity turned.
    Judged by it the room above was shut one cycle (the way round went below it, and was kept)
    and both sides the next, and lizi2 turned to and fro for 20 s. Judged by the passage's
    width (the spreads across the line between the two) the side above is open, and taken."""
    f = Fleet([(0.82, 0.48, math.pi)], [(-1.6, 0.48, math.pi)],
              walls=[(-8, 0.96, 8, 1.2), (-8, -1.2, 8, -0.96)])  # fmt: skip
    pl = f.planners[0]
    pl.grid = (f.cm.costs, (f.cm.origin_x, f.cm.origin_y), f.cm.resolution)
    xy, vel, pref = np.array([0.82, 0.48]), np.array([-0.4, 0.0]), np.array([-0.5, 0.0])
    rel, standing = np.array([[-0.82, -0.48]]), np.zeros((1, 2))  # lizi4 at the origin

    def way(radii, passage=None):
        return pl._around_still(pref, xy, vel, rel, standing, np.array([radii]),
                                np.array([True]), ["lizi4"], passage)  # fmt: skip

    assert way(0.76)[1] < 0.0  # ORCA's radius, one leg: above shut, below open: it turns down
    assert pl.detour_sides == {"lizi4": 1}
    assert (way(0.80) == pref).all()  # the other leg: both shut, nothing to go round by
    pl.detour_sides.clear()
    assert way(0.76, np.array([0.62]))[1] > 0.0  # above, where its plan runs
    assert pl.detour_sides == {"lizi4": 0}
    assert way(0.80, np.array([0.62]))[1] > 0.0  # whichever leg ORCA pads by


def test_the_planner_hands_the_room_beside_a_standing_robot_to_the_way_round(monkeypatch):
    """The wiring of the test above: with amcl's spreads the way round a robot standing in the
    way gets the combined radius for the room beside it (`neighbour_radii`'s third array,
    through `pair_radii`), narrower than ORCA's for a lizi parked along the corridor; without
    any spread it gets ORCA's, the same array's values."""
    seen = []
    plain = CollvoidLocalPlanner._around_still

    def spy(self, pref, xy, vel, rel, nvel, radii, controlled, ids, passage=None):
        seen.append((radii.copy(), None if passage is None else passage.copy()))
        return plain(self, pref, xy, vel, rel, nvel, radii, controlled, ids, passage)

    monkeypatch.setattr(CollvoidLocalPlanner, "_around_still", spy)
    walls = [(-8, 0.96, 8, 1.2), (-8, -1.2, 8, -0.96)]
    parked = (0.0, 0.0, math.pi)
    along = np.diag([0.0144, 0.0016])  # amcl's in a corridor: 0.12 m along it, 0.04 m across
    for covs in ([along, along], None):
        seen.clear()
        f = Fleet([(1.5, 0.48, math.pi), parked], [(-1.6, 0.48, math.pi), parked],
                  walls=walls, covariances=covs)  # fmt: skip
        f.run(0.5)
        radii, passage = seen[-1]
        assert passage is not None and passage.shape == radii.shape == (1,)
        if covs is None:
            assert passage.tolist() == radii.tolist()
        else:
            assert passage[0] < radii[0] - 0.03, (passage, radii)


def test_a_goal_nudged_by_localization_is_the_same_goal_to_the_deadlock_rule():
    """move_base hands the plan over every cycle in odom, where each amcl correction moves the
    goal a few cm: the no-progress clock and the trail survive that, not a new goal."""
    fleet = Fleet([(0.0, 0.0, 0.0)], [(4.0, 0.0, 0.0)])
    pl = fleet.planners[0]
    fleet.run(1.0)
    pl.deadlock.best_time = -7.0  # progress last made long ago
    pl.retreat.extend(np.array([0.3, 0.0]))
    trail = len(pl.retreat.trail)
    line = np.linspace((0.0, 0.05), (4.0, 0.05), 50)
    pl.set_plan(np.c_[line, np.zeros(50)])  # the same goal, 5 cm aside
    assert pl.deadlock.best_time == -7.0
    assert len(pl.retreat.trail) == trail
    assert not pl.is_goal_reached()
    line = np.linspace((0.0, 0.0), (0.0, 3.0), 50)
    pl.set_plan(np.c_[line, np.zeros(50)])  # a new goal
    assert pl.deadlock.best_time == pytest.approx(fleet.rt.now())


@pytest.mark.parametrize("overlap_time", [0.0, 1.0])
def test_overlap_time_parts_overlapping_discs_without_stalling_the_robot(overlap_time):
    """A robot driving east whose disc overlaps a robot parked beside it (0.4 m to its right,
    inside their combined radius): ORCA parts them within ``overlap_time``. RVO2's one control
    period (0) asks for (r - d) / 0.1 s, more than the top speed, so the velocity points
    straight away from the parked robot (a differential drive stops and turns round); within
    1 s the robot keeps most of its speed along its way and they part as it drives on."""
    fleet = Fleet([(0.0, 0.0, 0.0), (0.0, -0.4, 0.0)], [(5.0, 0.0, 0.0), (0.0, -0.4, 0.0)],
                  overlap_time=overlap_time)  # fmt: skip
    fleet.share()
    fleet.rt.run(duration=0.1)
    pl = fleet.planners[0]
    pl.compute_velocity_commands((0.0, 0.0, 0.0), (0.3, 0.0, 0.0))
    away, along = float(pl.last_holo[1]), float(pl.last_holo[0])
    if overlap_time == 0.0:
        assert along < 0.1 and away > 0.4
    else:
        assert along > 0.3
        # and 1 s on they are farther apart than the 0.4 m they are now
        assert math.hypot(along, away + 0.4) > 0.5


def test_a_standoff_yields_to_the_robot_met_head_on_only():
    """Two pairs abreast in a corridor wide enough for two by its walls meet front to front and
    creep at a few cm/s: after standoff_time without deadlock_progress the robot met head-on
    with priority is yielded to, not a teammate beside us, and without one nobody yields."""
    rule = make_rule("pioneer4", deadlock_time=10.0, deadlock_progress=0.2, standoff_time=3.0)
    around = {"pioneer3": 0.9, "pioneer2": 0.8, "pioneer1": 1.6}
    assert rule.update(0.0, 5.0, around, facing=["pioneer3"]) is None
    assert rule.update(2.9, 4.85, around, facing=["pioneer3"]) is None  # a creep: 0.15 m
    # pioneer2 (beside us) is nearer and has priority too, but only the robot met counts
    assert rule.update(3.1, 4.85, around, facing=["pioneer3"]) == "pioneer3"
    # the same creep with nobody met head-on: the no-progress clock alone, deadlock_time
    plain = make_rule("pioneer4", deadlock_time=10.0, deadlock_progress=0.2, standoff_time=3.0)
    plain.update(0.0, 5.0, around)
    assert plain.update(3.1, 4.85, around) is None
    assert plain.update(9.9, 4.85, around) is None
    assert plain.update(10.1, 4.85, around) == "pioneer2"
    # progress restarts the clock; the robot met with no priority over us is not yielded to,
    # and keeping our right of way there does not restart the no-progress clock
    top = make_rule("pioneer3", deadlock_time=10.0, deadlock_progress=0.2, standoff_time=3.0)
    near = {"pioneer4": 0.9, "pioneer1": 1.0}
    top.update(0.0, 5.0, near, facing=["pioneer4"])
    assert top.update(2.0, 4.7, near, facing=["pioneer4"]) is None
    assert top.update(4.9, 4.6, near, facing=["pioneer4"]) is None
    assert top.update(5.1, 4.6, near, facing=["pioneer4"]) is None
    assert top.update(12.1, 4.6, near, facing=["pioneer4"]) == "pioneer1"


def test_a_standoff_with_several_robots_met_yields_to_the_one_with_the_highest_priority():
    """Four jackals in two lanes of a corridor, a head-on pair in each (the corridor of 4 with
    amcl, seed 1): jackal4 meets jackal3 (diagonally, in the other lane, nearer) and jackal1
    (in its own lane). Yielding to the nearer one, jackal3, which is itself blocked, freed
    nobody for 13 s; the robot the group lets through first is the one with the highest
    priority, so that is the one yielded to. Without a standoff (the no-progress rule) the
    nearest robot with priority is still the one yielded to."""
    rule = make_rule("jackal4", deadlock_time=10.0, deadlock_progress=0.2, standoff_time=3.0)
    around = {"jackal3": 1.1, "jackal2": 1.2, "jackal1": 1.38}
    met = ["jackal3", "jackal1"]
    assert rule.update(0.0, 5.0, around, facing=met) is None
    assert rule.update(3.1, 4.9, around, facing=met) == "jackal1"
    # the highest priority among the robots met, not around: jackal1 beside us is not met
    beside = make_rule("jackal4", deadlock_time=10.0, deadlock_progress=0.2, standoff_time=3.0)
    met = ["jackal3", "jackal2"]
    beside.update(0.0, 5.0, around, facing=met)
    assert beside.update(3.1, 4.9, around, facing=met) == "jackal2"
    plain = make_rule("jackal4", deadlock_time=10.0, deadlock_progress=0.2, standoff_time=3.0)
    plain.update(0.0, 5.0, around)
    assert plain.update(10.1, 4.9, around) == "jackal3"


def test_a_yield_ends_once_the_robot_yielded_to_is_out_of_our_way():
    """A robot we yield to that has gone off to the side, beyond deadlock_radius and clear of
    our plan ahead, is out of our way though not behind us: the yield ends there
    (`_out_of_our_way`). Pioneers' circle of 16, seed 1: pioneer7 waited 27 s for pioneer5,
    3 m to its side, turning onto its goal."""
    f = Fleet([(-3.0, 0.0, 0.0)], [(3.0, 0.0, 0.0)], deadlock_radius=2.0)
    pl, me = f.planners[0], np.array([-3.0, 0.0])
    radii = 2 * BODY
    assert pl._out_of_our_way(me, np.array([0.0, 0.3]), radii) is False  # on our way ahead
    assert pl._out_of_our_way(me, np.array([0.0, 2.5]), radii) is True  # 2.5 m to the side
    assert pl._out_of_our_way(me, np.array([-2.0, 1.5]), radii) is False  # within 2 m of us
    assert pl._out_of_our_way(me, np.array([0.0, 0.8]), radii) is False  # beside the way


def test_robots_are_met_head_on_along_the_plans_way_as_the_yield_is_released(monkeypatch):
    """Who is met head-on (ahead, `head_on`) and when a yield ends (the robot yielded to is
    behind us, `has_passed`) are judged along the same direction, the plan's way where the
    robot is. Judged from the robot's position to its carrot, a robot 1 m off its plan counted
    a neighbour behind it along the plan as met, and the yield to it ended the next cycle."""
    import fleetsim.nav.controllers.collvoid_planner as planner_module

    f = Fleet([(0.0, 1.0, 0.0), (-0.6, 0.2, 0.0)], [(5.0, 0.0, 0.0), (-3.0, 0.2, 0.0)])
    pl = f.planners[0]
    line = np.linspace((0.0, 0.0), (5.0, 0.0), 50)
    pl.set_plan(np.c_[line, np.zeros(50)])  # along y = 0; the robot stands 1 m off it
    ways, original = [], planner_module.head_on

    def spy(way, *args):
        ways.append(np.array(way, dtype=float))
        return original(way, *args)

    monkeypatch.setattr(planner_module, "head_on", spy)
    f.share()
    f.rt.run(duration=0.1)
    pl.compute_velocity_commands((0.0, 1.0, 0.0), (0.0, 0.0, 0.0))
    assert ways, "robot2 navigating 1 m away: the head-on test ran"
    way = ways[-1] / np.hypot(*ways[-1])
    assert abs(way[1]) < 0.05, way  # the plan's way (east), not down to the carrot
    rel = np.array([-0.6, 0.2]) - np.array([0.0, 1.0])
    assert float(rel @ way) < 0.0  # robot2 is behind along it: not met, and passed


@pytest.mark.parametrize(
    "walls, y, kept",
    [
        ((), 0.0, True),  # open floor: kept right
        ([(-8, 1.0, 8, 1.2), (-8, -1.2, 8, -1.0)], -0.55, True),  # a 2 m corridor's right lane
        ([(0.3, -0.45, 3.0, -0.25)], 0.0, False),  # a wall 0.25 m to the right, ahead
    ],
)
def test_keeping_right_is_dropped_where_a_wall_closes_the_right(walls, y, kept):
    """Keeping right of an oncoming robot turns the preferred velocity by left_pref; where a
    wall closes that side (a door's jamb, approached diagonally) it would press the robot into
    the wall, so the velocity is left as it is. In a 2 m corridor's lane it is still kept."""
    f = Fleet([(0.0, y, 0.0)], [(5.0, y, 0.0)], walls=walls)
    pl = f.planners[0]
    f.share()
    f.rt.run(duration=0.1)
    pl.compute_velocity_commands((0.0, y, 0.0), (0.3, 0.0, 0.0))  # this cycle's walls
    pref = np.array([0.5, 0.0])
    got = pl._kept_right(np.array([0.0, y]), pref, BODY)
    turned = rotated(pref, pl.params.left_pref)
    assert np.allclose(got, turned if kept else pref), got


@pytest.mark.parametrize(
    "walls, kept",
    [((), True), ([(0.3, -0.45, 3.0, -0.25)], False)],  # open floor; a wall 0.25 m to the right
)
def test_a_robot_met_head_on_is_kept_right_of_unless_a_wall_closes_the_right(walls, kept):
    """The planner's cycle itself: robot2 comes head-on along robot1's way, so robot1's
    preferred velocity is turned by left_pref before ORCA, except where a wall closes the
    right side (then the velocity it wanted goes on unturned)."""
    f = Fleet([(0.0, 0.0, 0.0), (2.5, 0.0, math.pi)], [(5.0, 0.0, 0.0), (-2.5, 0.0, math.pi)],
              walls=walls)  # fmt: skip
    f.vel[:, 0] = 0.3
    pl = f.planners[0]
    seen = {}
    around, give = pl._around_still, pl._give_way

    def spy_around(pref, *args):
        seen["pref"] = np.array(pref)
        return around(pref, *args)

    def spy_give(pref, wanted, *args):
        seen["wanted"] = np.array(wanted)
        return give(pref, wanted, *args)

    pl._around_still, pl._give_way = spy_around, spy_give
    f.share()
    f.rt.run(duration=0.1)
    pl.compute_velocity_commands((0.0, 0.0, 0.0), (0.3, 0.0, 0.0))
    assert seen, "robot2 was in robot1's view"
    wanted = seen["wanted"]
    assert np.hypot(*wanted) > 0.1 and abs(wanted[1]) < 0.05, wanted  # east, along the plan
    expected = rotated(wanted, pl.params.left_pref) if kept else wanted
    assert np.allclose(seen["pref"], expected), (seen["pref"], expected)
