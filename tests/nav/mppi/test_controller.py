"""MPPIController on a costmap with a simulated unicycle: driving, goal, determinism, failure."""

import itertools
import math

import numpy as np
import pytest

from fleetsim.nav.controllers import EmptyPlan, NoValidTrajectory
from fleetsim.nav.controllers.mppi import MPPIController, load_mppi
from fleetsim.nav.costmap import Costmap2D
from fleetsim.nav.costmap.footprint import footprint_from_radius

CRITICS = [
    "ConstraintCritic", "CostCritic", "GoalCritic", "GoalAngleCritic", "PathAlignCritic",
    "PathFollowCritic", "PathAngleCritic", "PreferForwardCritic",
]  # fmt: skip
DT = 0.05


def corridor():
    m = Costmap2D(120, 40, 0.05)
    m.costs[0:8, :] = 254
    m.costs[32:, :] = 254
    m.costs[8:12, :] = 253
    m.costs[28:32, :] = 253
    return m


def make(m, seed=0, **params):
    p, ack, critics = load_mppi({"critics": CRITICS, "controller_frequency": 1 / DT, **params})
    return MPPIController(
        m, footprint_from_radius(0.2), p, critics, np.random.default_rng(seed), ack
    )


def drive(c, start, steps, omni=False):
    """Integrate the commands as the base would; returns the poses and commands."""
    x, y, th = start
    v = (0.0, 0.0, 0.0)
    poses, cmds = [], []
    for _ in range(steps):
        cmd = c.compute_velocity_commands((x, y, th), v)
        v = cmd
        cmds.append(tuple(cmd))
        vy = cmd.vy if omni else 0.0
        x += (cmd.vx * math.cos(th) - vy * math.sin(th)) * DT
        y += (cmd.vx * math.sin(th) + vy * math.cos(th)) * DT
        th += cmd.vtheta * DT
        poses.append((x, y, th))
        if c.is_goal_reached():
            break
    return np.array(poses), cmds


def line(x0, x1, y, yaw=0.0, n=100):
    xs = np.linspace(x0, x1, n)
    return np.stack([xs, np.full(n, y), np.full(n, yaw)], axis=1)


def test_drives_down_a_corridor_and_stops_within_the_goal_tolerances():
    c = make(corridor())
    c.set_plan(line(0.5, 5.0, 1.0))
    poses, cmds = drive(c, (0.5, 1.0, 0.0), 600)
    assert c.is_goal_reached()
    assert math.hypot(poses[-1, 0] - 5.0, poses[-1, 1] - 1.0) <= 0.25
    assert abs(math.remainder(poses[-1, 2], 2 * math.pi)) <= 0.25
    assert np.all(np.abs(poses[:, 1] - 1.0) < 0.4 - 0.2)  # never reaches the lethal rows
    vx = np.array(cmds)[:, 0]
    assert vx.max() <= 0.5 + 1e-12 and vx.max() > 0.3
    assert cmds[-1] == (0.0, 0.0, 0.0)
    assert c.local_plan.shape == (0, 3)


def test_a_plan_handed_over_again_every_cycle_is_followed_to_its_end():
    # move_base re-expresses the plan in odom and hands it over each cycle; the nearest-point
    # search must go on from where it was, not from the plan's first point (it would search
    # only max_robot_pose_search_dist = 1.5 m of plan and the robot would stop near 3.2 m)
    c = make(corridor(), max_robot_pose_search_dist=1.5)
    plan = line(0.3, 5.7, 1.0, n=300)
    x, y, th, v = 0.3, 1.0, 0.0, (0.0, 0.0, 0.0)
    for k in range(500):
        c.set_plan(plan + np.array([0.001 * (k % 3), 0.0, 0.0]))  # odom drifts by 1 mm
        v = c.compute_velocity_commands((x, y, th), v)
        x, y, th = x + v.vx * math.cos(th) * DT, y + v.vx * math.sin(th) * DT, th + v.vtheta * DT
        if c.is_goal_reached():
            break
    assert c.is_goal_reached(), (x, y)
    assert math.hypot(x - 5.7, y - 1.0) <= 0.25


def detour():
    """A plan around the box as navfn draws it: along y 2, over the box at y 2.8, back."""
    pts = np.array([[0.5, 2.0], [1.8, 2.0], [2.4, 2.8], [3.0, 2.8], [3.6, 2.0], [5.0, 2.0]])
    out = [np.linspace(a, b, max(2, int(np.hypot(*(b - a)) / 0.025)), endpoint=False)
           for a, b in itertools.pairwise(pts)]  # fmt: skip
    xy = np.vstack([*out, pts[-1:]])
    return np.column_stack([xy, np.zeros(len(xy))])


def test_goes_around_an_obstacle_beside_the_path():
    m = Costmap2D(120, 80, 0.05)
    m.costs[36:44, 50:58] = 254  # a 0.4 m box at x 2.5..2.9, y 1.8..2.2
    yy, xx = np.mgrid[0:80, 0:120]
    d = np.hypot(np.clip(np.abs(xx - 53.5) - 4, 0, None), np.clip(np.abs(yy - 39.5) - 4, 0, None))
    inflated = np.where(d * 0.05 <= 0.2, 253, 252 * np.exp(-5.0 * (d * 0.05 - 0.2)))
    m.costs[:] = np.maximum(m.costs, np.where(d * 0.05 < 0.7, inflated, 0)).astype(np.uint8)
    c = make(m, batch_size=1000, CostCritic={"consider_footprint": True})
    c.set_plan(detour())
    poses, _ = drive(c, (0.5, 2.0, 0.0), 800)
    assert c.is_goal_reached()
    cells = np.floor(poses[:, :2] / 0.05).astype(int)
    assert np.all(m.costs[cells[:, 1], cells[:, 0]] < 253)  # never on an inscribed cell
    box = np.hypot(np.clip(np.abs(poses[:, 0] - 2.7) - 0.2, 0, None),
                   np.clip(np.abs(poses[:, 1] - 2.0) - 0.2, 0, None))  # fmt: skip
    assert box.min() > 0.2  # the 0.2 m robot never touched the box


def test_same_seed_same_commands_other_seed_other_commands():
    runs = []
    for seed in (7, 7, 8):
        c = make(corridor(), seed=seed)
        c.set_plan(line(0.5, 5.0, 1.0))
        runs.append(drive(c, (0.5, 1.0, 0.2), 40)[1])
    assert runs[0] == runs[1]
    assert runs[0] != runs[2]


def test_regenerated_noise_is_also_reproducible():
    runs = []
    for _ in range(2):
        c = make(corridor(), seed=3, regenerate_noises=True, iteration_count=2)
        c.set_plan(line(0.5, 5.0, 1.0))
        runs.append(drive(c, (0.5, 1.0, 0.0), 20)[1])
    assert runs[0] == runs[1]


def test_omni_strafes_to_a_goal_beside_it():
    few = ["ConstraintCritic", "CostCritic", "GoalCritic", "GoalAngleCritic"]
    c = make(corridor(), motion_model="Omni", critics=few)
    c.set_plan(np.array([[1.0, 1.0, 0.0], [1.0, 1.25, 0.0], [1.0, 1.5, 0.0]]))
    poses, cmds = drive(c, (1.0, 1.0, 0.0), 300, omni=True)
    assert c.is_goal_reached()
    assert max(abs(v[1]) for v in cmds) > 0.1  # it strafed
    assert np.abs(poses[:, 2]).max() < 0.5  # rather than turning towards it


def test_on_a_lethal_cell_is_no_valid_trajectory_and_no_plan_is_empty():
    m = Costmap2D(40, 40, 0.05)
    m.costs[:] = 254  # every pose, the robot's own too, is on an obstacle
    c = make(m, batch_size=50)
    with pytest.raises(EmptyPlan):
        c.compute_velocity_commands((1.0, 1.0, 0.0), (0, 0, 0))
    c.set_plan(line(1.0, 1.9, 1.0, n=10))
    with pytest.raises(NoValidTrajectory, match="every one of 50 sampled trajectories collides"):
        c.compute_velocity_commands((1.0, 1.0, 0.0), (0, 0, 0))


def test_a_robot_whose_footprint_touches_a_post_backs_away_instead_of_failing():
    m = Costmap2D(80, 80, 0.05)
    m.costs[40, 45] = 254  # a post 0.25 m ahead of the robot at (2.0, 2.0)
    c = make(m, CostCritic={"consider_footprint": True})
    c.set_plan(line(2.0, 3.5, 2.0, n=30))  # through the post (the costmap changed under it)
    pose = (2.0, 2.0, 0.0)  # facing the post, its 0.2 m radius outline 5 cm from it
    assert c._escape_clearance(np.array(pose)) == -1.0  # not yet touching
    pose = (2.06, 2.025, 0.0)  # now the outline is on the post
    poses, cmds = drive(c, pose, 30)
    post = np.array([45.5, 40.5]) * 0.05
    gaps = np.hypot(*(poses[:, :2] - post).T)
    start = math.hypot(2.06 - post[0], 2.025 - post[1])
    assert gaps[-1] > start + 0.03 and gaps.min() > start - 1e-3  # out, never nearer
