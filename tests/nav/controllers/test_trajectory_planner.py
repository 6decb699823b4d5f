"""TrajectoryPlannerROS: parameters, scoring, goal handling, driving a corridor."""

import logging
import math

import numpy as np
import pytest

from fleetsim.errors import ParameterError
from fleetsim.nav.controllers import (
    EmptyPlan,
    NoValidTrajectory,
    TrajectoryPlanner,
    TrajectoryPlannerParams,
)
from fleetsim.nav.controllers.map_grid import distances_from_targets
from fleetsim.nav.costmap import Costmap2D
from fleetsim.nav.costmap.footprint import footprint_from_radius, padded_footprint


def corridor():
    m = Costmap2D(120, 40, 0.05)
    m.costs[0:8, :] = 254
    m.costs[32:, :] = 254
    return m


def make(m, **kw):
    p = TrajectoryPlannerParams(holonomic_robot=False, **kw)
    return TrajectoryPlanner(m, footprint_from_radius(0.2), p)


def test_old_names_accepted_with_warning(caplog):
    with caplog.at_level(logging.WARNING):
        tp = TrajectoryPlanner.from_namespace(
            corridor(),
            footprint_from_radius(0.2),
            {
                "max_rotational_vel": 1.5,
                "min_in_place_rotational_vel": 1.0,
                "acc_lim_th": 2.0,
                "max_vel_y": 0.0,
            },
        )
    assert tp.params.max_vel_theta == 1.5 and tp.params.min_in_place_vel_theta == 1.0
    assert tp.params.acc_lim_theta == 2.0
    assert "'acc_lim_th' is deprecated, use 'acc_lim_theta'" in caplog.text
    assert "'max_rotational_vel' is deprecated, use 'max_vel_theta'" in caplog.text
    assert "unknown parameter 'max_vel_y'" in caplog.text
    with pytest.raises(ParameterError, match="'vx_samples' = 0 is out of range"):
        TrajectoryPlanner.from_namespace(corridor(), footprint_from_radius(0.2), {"vx_samples": 0})


def test_bfs_distances():
    costs = np.zeros((5, 5), np.uint8)
    costs[:, 2] = 254
    costs[4, 2] = 0
    d = distances_from_targets(costs, np.array([[0, 0]]), np.zeros((5, 5), bool))
    assert d[0, 1] == 1 and d[4, 2] == 6 and d[0, 3] == 11 and d[0, 2] == 25.0


@pytest.mark.parametrize("dwa", [False, True])
def test_drives_down_a_corridor_to_the_goal(dwa):
    m = corridor()
    tp = make(
        m,
        max_vel_x=0.5,
        vx_samples=6,
        vtheta_samples=20,
        xy_goal_tolerance=0.1,
        yaw_goal_tolerance=0.1,
        dwa=dwa,
    )
    xs = np.linspace(0.5, 5.0, 50)
    tp.set_plan(np.stack([xs, np.full(50, 1.0), np.full(50, math.pi / 2)], axis=1))
    x, y, th, v, dt = 0.5, 1.0, 0.0, (0.0, 0.0, 0.0), 0.05
    top = 0.0
    for _ in range(1000):
        cmd = tp.compute_velocity_commands((x, y, th), v)
        v = cmd
        top = max(top, cmd.vx)
        x += cmd.vx * math.cos(th) * dt
        y += cmd.vx * math.sin(th) * dt
        th += cmd.vtheta * dt
        assert 0.4 + 0.2 < y < 1.6 - 0.2 + 0.2  # never touches the walls
        if tp.is_goal_reached():
            break
    assert tp.is_goal_reached()
    assert math.hypot(x - 5.0, y - 1.0) <= 0.1
    assert abs((th - math.pi / 2 + math.pi) % (2 * math.pi) - math.pi) <= 0.1
    assert top == pytest.approx(0.5, abs=1e-9)


def test_speed_limit_changes_commands():
    m = corridor()
    xs = np.linspace(0.5, 5.5, 60)
    plan = np.stack([xs, np.full(60, 1.0), np.zeros(60)], axis=1)
    tops = []
    for vmax in (0.3, 0.8):
        tp = make(m, max_vel_x=vmax, acc_lim_x=10.0)
        tp.set_plan(plan)
        tops.append(tp.compute_velocity_commands((0.5, 1.0, 0.0), (vmax, 0, 0)).vx)
    assert tops[0] == pytest.approx(0.3) and tops[1] == pytest.approx(0.8)


def test_blocked_and_empty():
    m = corridor()
    tp = make(m)
    with pytest.raises(EmptyPlan, match="no plan"):
        tp.compute_velocity_commands((1.0, 1.0, 0.0), (0, 0, 0))
    m.costs[:, :] = 254
    m.costs[18:22, 18:22] = 0
    tp.set_plan(np.array([[1.0, 1.0, 0.0], [4.0, 1.0, 0.0]]))
    cmd = tp.compute_velocity_commands((1.0, 1.0, 0.0), (0, 0, 0))
    assert cmd.vx == tp.params.escape_vel  # backs up as base_local_planner does
    assert tp.escaping
    m.costs[:, :] = 0
    m.costs[:, 50] = 254  # a wall between the robot and its whole plan: no path at all
    tp = make(m)
    tp.set_plan(np.array([[4.0, 1.0, 0.0], [5.0, 1.0, 0.0]]))
    with pytest.raises(NoValidTrajectory, match="no valid trajectory"):
        tp.compute_velocity_commands((1.0, 1.0, 0.0), (0, 0, 0))


def test_a_replan_to_the_same_goal_keeps_goal_reached():
    # move_base may hand over a fresh plan before every control cycle (planner_frequency);
    # the reached flag must survive until move_base reads it
    planner = make(corridor())
    goal = [[1.0, 1.0, 0.0], [1.2, 1.0, 0.0]]
    planner.set_plan(goal)
    planner.compute_velocity_commands((1.2, 1.0, 0.0), (0.0, 0.0, 0.0))
    assert planner.is_goal_reached()
    planner.set_plan([[1.1, 1.0, 0.0], [1.2, 1.0, 0.0]])
    assert planner.is_goal_reached()
    planner.set_plan([[1.1, 1.0, 0.0], [2.0, 1.0, 0.0]])
    assert not planner.is_goal_reached()


def _drive_to_corridor_end(tp, steps: int = 1200) -> tuple[bool, float]:
    """Unicycle kinematics at the control period; (goal reached, final distance to goal)."""
    xs = np.linspace(0.5, 5.0, 50)
    tp.set_plan(np.stack([xs, np.full(50, 1.0), np.zeros(50)], axis=1))
    x, y, th, v, dt = 0.5, 1.0, 0.0, (0.0, 0.0, 0.0), 0.1
    for _ in range(steps):
        v = tp.compute_velocity_commands((x, y, th), v)
        x += v.vx * math.cos(th) * dt
        y += v.vx * math.sin(th) * dt
        th += v.vtheta * dt
        if tp.is_goal_reached():
            return True, math.hypot(x - 5.0, y - 1.0)
    return False, math.hypot(x - 5.0, y - 1.0)


def test_a_min_vel_x_that_overshoots_the_tolerance_is_warned_about_and_does_circle(caplog):
    lesson = {"max_vel_x": 1.5, "min_vel_x": 0.5, "max_vel_theta": 1.5}
    lesson |= {"min_in_place_vel_theta": 1.0, "holonomic_robot": False}
    with caplog.at_level(logging.WARNING, logger="fleetsim.nav"):
        tp = TrajectoryPlanner.from_namespace(
            corridor(), footprint_from_radius(0.2), lesson, where="/lizi1/TrajectoryPlannerROS"
        )
    assert "/lizi1/TrajectoryPlannerROS: min_vel_x 0.5 m/s over sim_time 1 s" in caplog.text
    assert "set xy_goal_tolerance >= 0.25" in caplog.text
    reached, dist = _drive_to_corridor_end(tp)
    assert not reached and 0.1 < dist < 0.5  # what the warning says: it turns short of the goal
    caplog.clear()
    with caplog.at_level(logging.WARNING, logger="fleetsim.nav"):
        tp = TrajectoryPlanner.from_namespace(
            corridor(), footprint_from_radius(0.2), lesson | {"xy_goal_tolerance": 0.3}
        )
    assert "min_vel_x" not in caplog.text
    reached, dist = _drive_to_corridor_end(tp)
    assert reached and dist <= 0.3


def test_the_default_limits_are_not_warned_about(caplog):
    with caplog.at_level(logging.WARNING, logger="fleetsim.nav"):
        TrajectoryPlanner.from_namespace(corridor(), footprint_from_radius(0.2), {})
    assert caplog.text == ""


def test_an_escape_that_cannot_turn_yet_backs_on_past_escape_reset_dist():
    from fleetsim.nav.controllers.escape import ESCAPE_ROOM, _end_escape_when_clear

    tp = make(corridor())
    reset = tp.params.escape_reset_dist
    for dist, can_turn, still in (
        (0.5 * reset, True, True),  # not far enough yet
        (2.0 * reset, True, False),  # far enough and it can turn: base_local_planner's rule
        (2.0 * reset, False, True),  # far enough but wedged in a gap: back on
        ((ESCAPE_ROOM + 0.5) * reset, False, False),  # but not for ever
    ):
        tp.escaping, tp.escape_pose = True, (1.0, 1.0, 0.0)
        _end_escape_when_clear(tp, 1.0 - dist, 1.0, 0.0, can_turn)
        assert tp.escaping is still, (dist, can_turn)
    tp.escaping = True
    _end_escape_when_clear(tp, 1.0, 1.0, tp.params.escape_reset_theta + 0.1, False)
    assert not tp.escaping  # turned far enough


def test_dwa_offers_in_place_rotations_either_way_while_turning():
    from fleetsim.nav.controllers.selection import velocity_samples

    pose, turning = (1.0, 1.0, 0.0), (0.0, 0.0, 0.3)  # faster than one period can stop
    for dwa in (True, False):
        tp = make(corridor(), dwa=dwa, acc_lim_theta=3.0, sim_time=1.5)
        tp.set_plan(np.array([[1.0, 1.0, 0.0], [5.0, 1.0, 0.0]]))
        samples, groups, dvth = velocity_samples(tp, pose, turning)
        in_place = samples[groups["in_place"], 2]
        forward = samples[groups["forward"], 2]
        # the in-place window is sim_time's either way (DWA's one-period window [0, 0.6]
        # held only left turns, the slowest raised to min_in_place_vel_theta)
        assert in_place.min() == pytest.approx(-1.0) and in_place.max() == pytest.approx(1.0)
        assert dvth == pytest.approx(2.0 / 19)
        if dwa:  # the forward samples keep DWA's window of one control period
            assert forward.min() >= 0.0 and forward.max() <= 0.6 + 1e-12


def _turn_to_a_near_goal(th0: float, bearing: float) -> tuple[bool, float]:
    """A burger (turtlebot3's DWA limits) 0.2 m from its goal in open space, facing ``th0``;
    the goal lies at ``bearing`` and faces along it. (reached, largest |net turn| on the way)."""
    p = TrajectoryPlannerParams(
        holonomic_robot=False, max_vel_x=0.22, min_vel_x=0.05, max_vel_theta=2.75,
        min_in_place_vel_theta=1.37, acc_lim_x=2.5, acc_lim_theta=3.2, xy_goal_tolerance=0.05,
        yaw_goal_tolerance=0.17, sim_time=2.0, vx_samples=20, vtheta_samples=40, dwa=True,
        meter_scoring=True, occdist_scale=0.02, heading_lookahead=0.325,
    )  # fmt: skip
    tp = TrajectoryPlanner(Costmap2D(120, 120, 0.05), footprint_from_radius(0.1), p)
    gx, gy = 3.0 + 0.2 * math.cos(bearing), 3.0 + 0.2 * math.sin(bearing)
    tp.set_plan(
        np.stack([np.linspace(3.0, gx, 10), np.linspace(3.0, gy, 10), np.full(10, bearing)], 1)
    )
    x, y, th, v, dt = 3.0, 3.0, th0, (0.0, 0.0, 0.0), 0.1
    worst = 0.0
    for _ in range(400):
        v = tp.compute_velocity_commands((x, y, th), v)
        x += v.vx * math.cos(th) * dt
        y += v.vx * math.sin(th) * dt
        th += v.vtheta * dt
        worst = max(worst, abs(th - th0))
        if tp.is_goal_reached():
            return True, worst
    return False, worst


@pytest.mark.parametrize(("th0", "bearing"), [(-45, -60), (90, 49), (135, 120), (-90, 0)])
def test_an_in_place_rotation_turns_the_short_way_to_a_near_goal(th0, bearing):
    """Rotations sampled over sim_time's window can turn past a half turn in their rollout;
    judged by where their end points, a burger beside its goal spun 300 degrees the long way
    round (the building patrol's karl); judged by the best heading passed, and how soon, not."""
    reached, worst = _turn_to_a_near_goal(math.radians(th0), math.radians(bearing))
    need = abs(math.remainder(math.radians(bearing - th0), 2 * math.pi))
    assert reached
    assert worst < need + math.radians(35), f"turned {math.degrees(worst):.0f} degrees"


def test_the_escape_backs_on_a_curve_that_faces_the_robot_along_its_way():
    from fleetsim.nav.controllers.escape import _escape_choice
    from fleetsim.nav.controllers.selection import velocity_samples

    tp = make(corridor(), dwa=True, acc_lim_theta=3.0, sim_time=1.5, escape_vel=-0.1)
    tp.set_plan(np.array([[x, 1.0, 0.0] for x in np.arange(1.0, 5.0, 0.05)]))
    pose, vel = (1.5, 1.0, 0.6), (0.0, 0.0, 0.0)  # 0.6 rad off the corridor's axis
    tp._update_maps(tp.plan, pose, vel)
    samples, g, dvth = velocity_samples(tp, pose, vel)
    costs = tp._score(samples, pose, vel)
    turns = samples[g["escape_turn"]]
    assert np.all(turns[:, 0] == -0.1) and turns[:, 2].min() < 0 < turns[:, 2].max()
    i = _escape_choice(tp, costs, g, dvth)
    # backing while turning right leaves it facing down the corridor: better than straight
    assert g["escape_turn"].start <= i < g["escape_turn"].stop and samples[i, 2] < 0
    assert tp._poses[i, tp._steps[i] - 1, 2] < 0.6 - 0.3
    # no legal turning back-up: base_local_planner's straight one (taken even when illegal)
    costs[g["escape_turn"]] = -1.0
    assert _escape_choice(tp, costs, g, dvth) == g["escape"].start
    costs[g["escape"]] = -1.0
    assert _escape_choice(tp, costs, g, dvth) == g["escape"].start


def _off_axis_in_corridor(**kw):
    """A dwa planner in the corridor with its plan along the axis, the robot 0.6 rad off it."""
    tp = make(corridor(), dwa=True, acc_lim_theta=3.0, sim_time=1.5, escape_vel=-0.1, **kw)
    tp.set_plan(np.array([[x, 1.0, 0.0] for x in np.arange(1.0, 5.0, 0.05)]))
    pose, vel = (1.5, 1.0, 0.6), (0.0, 0.0, 0.0)
    tp._update_maps(tp.plan, pose, vel)
    return tp, pose, vel


def test_alignment_cost_penalises_ending_pointed_off_the_path():
    samples = np.array([[0.3, 0.0, -0.4], [0.3, 0.0, 0.4]])  # back toward the axis, away
    added = []
    for scale in (0.0, 0.6):
        tp, pose, vel = _off_axis_in_corridor(alignment_scale=scale, meter_scoring=True)
        added.append(tp._score(samples, pose, vel))
    extra = added[1] - added[0]
    assert np.all(added[0] >= 0) and np.all(extra >= 0)
    assert extra[1] > extra[0] + 0.01  # the one ending pointed away pays more
    # near the goal the alignment cost is off (dwa_local_planner's rule)
    tp, _, vel = _off_axis_in_corridor(alignment_scale=0.6)
    assert tp._alignment((4.9, 1.0, 0.6))[0] == 0.0 < tp._alignment((1.5, 1.0, 0.6))[0]


def test_alignment_cost_kernel_on_off_and_beside_the_path():
    from fleetsim.nav.controllers.rollout import alignment_cost

    m = corridor()
    targets = np.array([[i, 20] for i in range(120)], dtype=np.int64)  # the axis, y = 1.0
    dist = distances_from_targets(m.costs, targets, np.zeros(m.costs.shape, bool))
    origin = np.array([0.0, 0.0])
    along = alignment_cost(dist, origin, 0.05, 1.0, 1.0, 0.0, 0.325, 0.0)
    across = alignment_cost(dist, origin, 0.05, 1.0, 1.0, 0.5, 0.325, 0.0)
    assert along == 0.0 and 2.0 <= across <= 0.325 / 0.05
    # pointing into the wall or off the map: the farthest the point can be, not a rejection
    assert alignment_cost(dist, origin, 0.05, 1.0, 1.0, math.pi / 2, 0.65, 1.0) == 1.0 + 13.0
    assert alignment_cost(dist, origin, 0.05, 0.1, 1.0, math.pi, 0.325, 0.0) == 6.5


@pytest.mark.parametrize("aligning", [False, True])
def test_escaping_with_alignment_backs_on_rather_than_turn_away_from_the_path(aligning):
    from fleetsim.nav.controllers.lookahead import path_heading
    from fleetsim.nav.controllers.selection import choose_trajectory

    tp, pose, vel = _off_axis_in_corridor(alignment_scale=0.6 if aligning else 0.0)
    assert path_heading(tp, pose) == pytest.approx(0.0, abs=1e-9)  # along the axis
    score = tp._score

    def wedged(samples, pose, vel):  # every forward rollout and every turn toward the axis
        costs = score(samples, pose, vel)
        costs[samples[:, 0] > 0] = -1.0
        costs[(samples[:, 0] == 0) & (samples[:, 2] < 0)] = -1.0
        return costs

    tp._score = wedged
    # escaping, already escape_reset_dist back from where it was wedged
    tp.escaping, tp.escape_pose = (
        True,
        (1.5 + 0.15 * math.cos(0.6), 1.0 + 0.15 * math.sin(0.6), 0.6),
    )
    (vx, _, vth), cost, _ = choose_trajectory(tp, pose, vel)
    assert cost >= 0
    if aligning:  # turning further off the axis leads nowhere: back on
        assert vx == -0.1 and tp.escaping
    else:  # base_local_planner: the escape ends and the robot turns away, the only legal way
        assert vx == 0.0 and vth > 0 and not tp.escaping


class _CostmapROS:
    """What `GlobalCostmapGuard` reads of a Costmap2DROS: the grid, its frame, the robot's pose, the
    (padded) footprint and the body without its padding."""

    def __init__(self, costmap, pose, frame, footprint=None, padding=0.0):
        self.costmap, self._pose, self.global_frame = costmap, pose, frame
        self.footprint = footprint
        body = None if footprint is None else padded_footprint(footprint, -padding)
        self.unpadded_footprint = body

    def robot_pose(self):
        return self._pose


def _wedged_box_robot():
    """A 0.6 x 0.3 m robot at (1.5, 1.0) facing +x in a 0.4 m wide dead end of its local
    costmap: forward moves hit the end wall, in-place rotations the side walls, so only the
    escape is left; behind it the local costmap is free."""
    m = Costmap2D(120, 40, 0.05)
    m.costs[:16, :] = 254
    m.costs[24:, :] = 254
    m.costs[:, 37:] = 254  # the end wall, x >= 1.85
    box = np.array([[0.3, 0.15], [0.3, -0.15], [-0.3, -0.15], [-0.3, 0.15]])
    p = TrajectoryPlannerParams(holonomic_robot=False, escape_vel=-0.1, dwa=False)
    tp = TrajectoryPlanner(m, box, p)
    tp.set_plan(np.array([[x, 1.0, math.pi] for x in np.arange(1.5, 0.4, -0.05)]))
    return tp


def _escape_with_global_map(
    lethal_rows=(), lethal_cols=(), lethal_cell=None, padding=0.0, local_wall=False
):
    """Run one cycle of the wedged robot with the global costmap guard on a global costmap
    whose frame differs from the local one: the robot is at (2.02, -1.02) facing +y there, so
    backing up moves it toward -y (its body's rear edge starts at y = -1.32, its sides at
    x = 1.87 and 2.17)."""
    from fleetsim.nav.controllers.global_guard import GlobalCostmapGuard

    tp = _wedged_box_robot()
    if local_wall:  # the global rows 71-72 in the local costmap (local x 1.07-1.17)
        tp.costmap.costs[:, 21:24] = 254
    g = Costmap2D(200, 200, 0.05, origin_x=-5.0, origin_y=-5.0)
    for r in lethal_rows:
        g.costs[r, :] = 254
    for c in lethal_cols:
        g.costs[:, c] = 254
    if lethal_cell is not None:
        g.costs[lethal_cell] = 254
    local = _CostmapROS(tp.costmap, (1.5, 1.0, 0.0), "odom", tp.footprint, padding)
    glob = _CostmapROS(g, (2.02, -1.02, math.pi / 2), "map")
    tp.global_guard = GlobalCostmapGuard(glob, local)
    return tp, tp.compute_velocity_commands((1.5, 1.0, 0.0), (0.0, 0.0, 0.0))


def test_the_escape_does_not_back_onto_what_the_global_costmap_knows(monkeypatch):
    # nothing behind in either map: a back-up (straight or on a curve, see `_escape_choice`)
    tp, cmd = _escape_with_global_map()
    assert cmd.vx == -0.1 and tp.escaping
    # a wall behind the rear edge in the global costmap only (rows 71-72: y -1.45 to -1.35):
    # every back-up refused; the way out of the padding moves the robot on (a creep forward
    # or a turn in place) as far as its body clears the walls (here the footprint is
    # unpadded: the body is it), not back
    _, cmd = _escape_with_global_map(lethal_rows=(71, 72))
    assert cmd.vx >= 0.0 and (cmd.vx, cmd.vtheta) != (0.0, 0.0)
    # without that way out: no valid trajectory, and the error says why
    from fleetsim.nav.controllers import selection

    monkeypatch.setattr(selection, "_padding_way_out", lambda *a: -1)
    why = r"robot on a lethal cell of the global costmap at \(.*, -1\.3[78]\) in map"
    with pytest.raises(NoValidTrajectory, match=why):
        _escape_with_global_map(lethal_rows=(71, 72))
    monkeypatch.undo()
    # a wall the local costmap holds too is the planner's to judge: ROS's blind escape
    _, cmd = _escape_with_global_map(lethal_rows=(71, 72), local_wall=True)
    assert cmd.vx == -0.1
    # the body is what counts, not the padded footprint: padded by 0.1 m, the body's rear edge
    # starts at -1.22 and backs to about -1.32, clear of the wall
    _, cmd = _escape_with_global_map(lethal_rows=(71, 72), padding=0.1)
    assert cmd.vx == -0.1
    # padded, with the wall 3 cm behind the body (row 74: y -1.30 to -1.25): every back-up
    # refused, and every forward move and turn illegal on the padded footprint; the turn its
    # body clears (0.15 m from the side walls) is the way out, where without it the robot
    # would stand with no valid trajectory
    tp, cmd = _escape_with_global_map(lethal_rows=(74,), padding=0.1)
    assert cmd.vx == 0.0 and cmd.vtheta != 0.0 and not tp.escaping
    monkeypatch.setattr(selection, "_padding_way_out", lambda *a: -1)
    with pytest.raises(NoValidTrajectory, match=r"global costmap at \(.*, -1\.27\) in map"):
        _escape_with_global_map(lethal_rows=(74,), padding=0.1)
    monkeypatch.undo()
    # the same wall where the local frame's -x would be without the frames' rotation (global x
    # 1.60-1.75): not behind the robot, so the escape goes ahead
    _, cmd = _escape_with_global_map(lethal_cols=(132, 133, 134))
    assert cmd.vx == -0.1
    # a lethal cell the body touches already (the map a little off, under its rear edge): no
    # reason to refuse moving off it
    _, cmd = _escape_with_global_map(lethal_cell=(73, 140))
    assert cmd.vx == -0.1


def test_the_global_costmap_guard_passes_over_a_forward_move_onto_a_known_post():
    """Open space in the local costmap; a post the global costmap knows 0.2 m ahead of the
    robot's front, slightly left: the straight move at speed would touch it, so another is
    taken (the local costmap alone gives the same choice with or without the post)."""
    from fleetsim.nav.controllers.global_guard import GlobalCostmapGuard

    m = Costmap2D(120, 120, 0.05)
    box = np.array([[0.3, 0.15], [0.3, -0.15], [-0.3, -0.15], [-0.3, 0.15]])
    p = TrajectoryPlannerParams(holonomic_robot=False, dwa=False, sim_time=1.5)
    plan = np.array([[x, 3.0, 0.0] for x in np.arange(3.0, 5.5, 0.05)])
    cmds = []
    for post in (False, True):
        tp = TrajectoryPlanner(m, box, p)
        tp.set_plan(plan)
        g = Costmap2D(120, 120, 0.05)
        if post:
            g.costs[60:63, 70:72] = 254  # x 3.50-3.60, y 3.00-3.15
        frame = _CostmapROS(g, (3.0, 3.0, 0.0), "map")
        tp.global_guard = GlobalCostmapGuard(frame, _CostmapROS(m, (3.0, 3.0, 0.0), "map", box))
        cmd = tp.compute_velocity_commands((3.0, 3.0, 0.0), (0.3, 0.0, 0.0))
        cmds.append(cmd)
    assert cmds[0].vx > 0.3 and abs(cmds[0].vtheta) < 0.1  # straight at the goal
    # another forward move (slower or turning away), whose rollout the guard accepts
    assert cmds[1].vx > 0.0 and (cmds[1].vx, cmds[1].vtheta) != (cmds[0].vx, cmds[0].vtheta)


def test_a_blind_escape_publishes_the_rollout_it_drives():
    tp = _wedged_box_robot()
    tp.costmap.costs[:, :23] = 254  # a wall 0.05 m behind the rear edge in the local map too
    tp.set_plan(np.array([[x, 1.0, math.pi] for x in (1.5, 1.45, 1.4, 1.35, 1.3)]))
    cmd = tp.compute_velocity_commands((1.5, 1.0, 0.0), (0.0, 0.0, 0.0))
    assert cmd.vx == -0.1  # ROS backs up even when the map says it is blocked
    # the whole rollout, past the step the map calls a collision (not uninitialised values)
    plan = tp.local_plan
    assert plan.shape[0] >= 3 and np.isfinite(plan).all()
    assert plan[0, 0] == 1.5 and np.all(np.diff(plan[:, 0]) < 0) and plan[-1, 0] < 1.45


def velocity_samples_reference(tp, pose, vel):
    """The sample table as NumPy built it before it was compiled (createTrajectories' order)."""
    p = tp.params
    max_vx = p.max_vel_x
    if tp.plan.shape[0]:
        gx, gy = tp.plan[-1, 0], tp.plan[-1, 1]
        max_vx = min(max_vx, math.hypot(gx - pose[0], gy - pose[1]) / p.sim_time)
    window = tp.sim_period if p.dwa else p.sim_time
    max_vx = max(min(max_vx, vel[0] + p.acc_lim_x * window), p.min_vel_x)
    min_vx = max(p.min_vel_x, vel[0] - p.acc_lim_x * window)
    max_vth = min(p.max_vel_theta, vel[2] + p.acc_lim_theta * window)
    min_vth = max(p.min_vel_theta, vel[2] - p.acc_lim_theta * window)
    dvx = (max_vx - min_vx) / (p.vx_samples - 1) if p.vx_samples > 1 else 0.0
    dvth = (max_vth - min_vth) / (p.vtheta_samples - 1) if p.vtheta_samples > 1 else 0.0
    vxs = min_vx + np.arange(p.vx_samples) * dvx
    vths = min_vth + np.arange(p.vtheta_samples) * dvth
    forward = np.zeros((p.vx_samples, p.vtheta_samples, 3))
    forward[:, :, 0] = vxs[:, None]
    forward[:, 1:, 2] = vths[None, :-1]
    parts = [forward.reshape(-1, 3)]
    if p.holonomic_robot:
        parts.append(np.array([[0.1, 0.1, 0.0], [0.1, -0.1, 0.0]]))
    in_place_vths, in_place_dvth = vths, dvth
    if p.dwa:
        lo = max(p.min_vel_theta, vel[2] - p.acc_lim_theta * p.sim_time)
        hi = min(p.max_vel_theta, vel[2] + p.acc_lim_theta * p.sim_time)
        in_place_dvth = (hi - lo) / (p.vtheta_samples - 1) if p.vtheta_samples > 1 else 0.0
        in_place_vths = lo + np.arange(p.vtheta_samples) * in_place_dvth
    in_place = np.zeros((p.vtheta_samples, 3))
    mn = p.min_in_place_vel_theta
    in_place[:, 2] = np.where(
        in_place_vths > 0, np.maximum(in_place_vths, mn), np.minimum(in_place_vths, -mn)
    )
    parts.append(in_place)
    if p.holonomic_robot:
        sideways = np.zeros((len(p.y_vels), 3))
        sideways[:, 1] = np.asarray(p.y_vels, dtype=np.float64)
        parts.append(sideways)
    parts.append(np.array([[p.escape_vel, 0.0, 0.0]]))
    escape_turn = np.zeros((p.vtheta_samples, 3))
    escape_turn[:, 0] = p.escape_vel
    escape_turn[:, 2] = in_place_vths
    parts.append(escape_turn)
    return np.concatenate(parts, axis=0), in_place_vths, in_place_dvth


def test_velocity_samples_match_the_numpy_table_bit_for_bit():
    """The compiled sample table holds the values (signs of zero included) of the NumPy one,
    over random limits, velocities and goal distances, holonomic or not, dwa or not, and
    min_in_place_vel_theta 0."""
    from fleetsim.nav.controllers.selection import velocity_samples

    rng = np.random.default_rng(5)
    for k in range(300):
        kw = dict(
            dwa=bool(k % 2),
            vx_samples=int(rng.integers(1, 8)),
            vtheta_samples=int(rng.integers(1, 25)),
            min_in_place_vel_theta=0.0 if k % 5 == 0 else float(rng.uniform(0.0, 0.6)),
            acc_lim_theta=float(rng.uniform(0.5, 4.0)),
            sim_time=float(rng.uniform(0.5, 2.5)),
        )
        p = TrajectoryPlannerParams(holonomic_robot=bool(k % 3 == 0), **kw)
        tp = TrajectoryPlanner(corridor(), footprint_from_radius(0.2), p)
        tp.set_plan(np.array([[1.0, 1.0, 0.0], [1.0 + rng.uniform(0.0, 3.0), 1.0, 0.0]]))
        vel = (float(rng.uniform(-0.2, 0.6)), 0.0, float(rng.choice([0.0, rng.uniform(-1, 1)])))
        samples, groups, dvth = velocity_samples(tp, (1.0, 1.0, 0.0), vel)
        want, raw, want_dvth = velocity_samples_reference(tp, (1.0, 1.0, 0.0), vel)
        assert samples.view(np.uint64).tolist() == want.view(np.uint64).tolist(), kw
        assert tp._in_place_raw.view(np.uint64).tolist() == raw.view(np.uint64).tolist()
        assert dvth == want_dvth
        assert sum(g.stop - g.start for g in groups.values()) == want.shape[0]
        assert groups["escape_turn"].stop == want.shape[0]


def _lizi_along_a_wall(
    back_along_plan: bool, th0: float = math.pi, y0: float = 2.78, steps: int = 900, post=None
) -> tuple[list, bool]:
    """The office's two-lizi wedge (seed 1), drawn (the lizi's slam_explore set, alignment
    cost included, with ``back_along_plan`` or without): a room whose north wall (y >= 3.0) has a
    1 m door at x 6-7; a lizi (the lesson's TrajectoryPlannerROS set) 0.22 m from that wall
    at (4.0, 2.78), facing west along it (``th0``, ``y0``: another heading or distance),
    too near it to turn in place; its plan goes east along the wall, then north through the
    door. Driven kinematically for 90 s; returns the poses and whether the goal was
    reached."""
    m = Costmap2D(160, 100, 0.05)
    m.costs[60:62, :120] = 254  # the north wall, with the door at x 6.0-7.0
    m.costs[60:62, 140:] = 254
    m.costs[:62, :2] = 254  # the room's west wall
    if post is not None:  # a post at x = post (m), along the wall, 0.3 m deep
        m.costs[54:60, int(post / 0.05) : int(post / 0.05) + 2] = 254
    p = TrajectoryPlannerParams(
        holonomic_robot=False, max_vel_x=0.5, min_vel_x=0.1, max_vel_theta=1.0,
        min_in_place_vel_theta=0.4, acc_lim_theta=3.2, acc_lim_x=2.5, xy_goal_tolerance=0.2,
        yaw_goal_tolerance=3.14, sim_time=1.5, vx_samples=6, vtheta_samples=20,
        meter_scoring=True, pdist_scale=0.6, gdist_scale=0.8, occdist_scale=0.02,
        dwa=True, alignment_scale=0.6, back_along_plan=back_along_plan,
    )  # fmt: skip
    box = np.array([[-0.19, -0.16], [-0.19, 0.16], [0.19, 0.16], [0.19, -0.16]])
    tp = TrajectoryPlanner(m, box, p)
    east = [[x, y0, 0.0] for x in np.arange(4.0, 6.5, 0.05)]
    north = [[6.5, y, math.pi / 2] for y in np.arange(y0, 4.5, 0.05)]
    tp.set_plan(np.array(east + north))
    x, y, th, v, dt = 4.0, y0, th0, (0.0, 0.0, 0.0), 0.1
    poses = []
    for _ in range(steps):
        try:
            cmd = tp.compute_velocity_commands((x, y, th), v)
            v = (cmd.vx, 0.0, cmd.vtheta)
        except NoValidTrajectory:
            v = (0.0, 0.0, 0.0)
        x += v[0] * math.cos(th) * dt
        y += v[0] * math.sin(th) * dt
        th += v[2] * dt
        poses.append((x, y, th))
        if tp.is_goal_reached():
            return poses, True
    return poses, False


def _past_the_wall(poses) -> float:
    """m, how far `_lizi_along_a_wall`'s lizi reached past the north wall's face (y = 3.0),
    beside the door excepted."""
    box = np.array([[-0.19, -0.16], [-0.19, 0.16], [0.19, 0.16], [0.19, -0.16]])
    worst = -np.inf
    for x, y, th in poses:
        if 5.75 < x < 7.25:
            continue
        c, s = math.cos(th), math.sin(th)
        worst = max(worst, max(y + s * bx + c * by for bx, by in box) - 3.0)
    return worst


def test_a_robot_that_cannot_turn_backs_along_its_plan_rather_than_drive_away():
    poses, reached = _lizi_along_a_wall(back_along_plan=True)
    assert reached, poses[-1]
    # its body kept off the wall (the outline may sit on the cell next to it, as ROS's
    # footprint check allows; a millimetre between the rollout and this integration)
    assert _past_the_wall(poses) < 0.005
    assert min(p[0] for p in poses) > 3.9  # it never drove off west, away from its plan
    # without back_along_plan, base_local_planner's choice: any legal forward move first, so
    # west along the wall into the corner, back 0.1 m, and west again
    poses, reached = _lizi_along_a_wall(back_along_plan=False)
    assert not reached and min(p[0] for p in poses) < 3.0


@pytest.mark.parametrize(("th0", "y0"), [(math.pi, 0.22), (-2.9, 0.22), (2.9, 0.24), (-2.8, 0.24)])
def test_a_robot_facing_away_along_a_wall_turns_round_where_it_has_room(th0, y0):
    """Nearly parallel to the wall (slanted toward it or away), 0.22-0.24 m from it: it backs
    along the plan to the door, where it turns round, and goes through, well within 30 s."""
    poses, reached = _lizi_along_a_wall(back_along_plan=True, th0=th0, y0=3.0 - y0)
    assert reached and len(poses) < 300, poses[-1]
    assert _past_the_wall(poses) < 0.005  # backing toward the wall at a slant, it kept off


def test_a_robot_facing_away_with_no_room_behind_drives_on_as_ros_does():
    """A post 0.25 m behind the lizi (its back 0.06 m from it): no back-up is legal, so
    base_local_planner's forward move stands, and keeps standing until the robot is 0.5 m
    away (backing a few centimetres and driving as far forward by turns held a lizi for
    240 s in the office's corridor end, seed 1)."""
    poses, _ = _lizi_along_a_wall(back_along_plan=True, post=4.25, steps=60)
    xs = [p[0] for p in poses]
    assert max(xs) <= 4.0 + 1e-6  # never backed
    assert xs[-1] < 3.6  # drove on west, 0.4 m or more in 6 s


def test_back_along_plan_without_the_alignment_cost_is_warned_about(caplog):
    with caplog.at_level(logging.WARNING, logger="fleetsim.nav"):
        TrajectoryPlanner.from_namespace(
            corridor(), footprint_from_radius(0.2), {"back_along_plan": True}, "lizi1/tp"
        )
    assert "lizi1/tp: back_along_plan is true but alignment_scale is 0" in caplog.text
    caplog.clear()
    with caplog.at_level(logging.WARNING, logger="fleetsim.nav"):
        TrajectoryPlanner.from_namespace(
            corridor(),
            footprint_from_radius(0.2),
            {"back_along_plan": True, "alignment_scale": 0.6},
        )
    assert "back_along_plan" not in caplog.text
