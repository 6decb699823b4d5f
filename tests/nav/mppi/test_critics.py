"""MPPI critics: each one's sign and scale on crafted trajectories."""

import math

import numpy as np
import pytest

from fleetsim.nav.controllers.mppi import critic_kernels as k
from fleetsim.nav.controllers.mppi import critic_params as cp
from fleetsim.nav.controllers.mppi.critics import CRITICS, CriticData
from fleetsim.nav.controllers.mppi.kernels import DIFF_DRIVE
from fleetsim.nav.costmap import Costmap2D
from fleetsim.nav.costmap.footprint import footprint_from_radius, outline_points
from fleetsim.nav.costmap.inflation_layer import squared_distances_to

DT = 0.05


def straight(y0, yaw=0.0, n=20, v=0.5, x0=0.0):
    """(n, 3) poses along +x (or along ``yaw``) from (x0, y0)."""
    s = v * DT * np.arange(1, n + 1)
    return np.stack([x0 + s * math.cos(yaw), y0 + s * math.sin(yaw), np.full(n, yaw)], axis=1)


def data_for(trajs, vels=None, robot=(0.0, 0.0, 0.0), goal=(5.0, 0.0, 0.0), path=None, m=None):
    poses = np.ascontiguousarray(np.stack(trajs), dtype=float)
    b, t = poses.shape[:2]
    if vels is None:
        vels = np.zeros((b, t, 3))
        vels[:, :, 0] = 0.5
    if path is None:
        xs = np.arange(0.0, 1.51, 0.05)
        path = np.stack([xs, np.zeros_like(xs), np.zeros_like(xs)], axis=1)
    m = m or Costmap2D(200, 100, 0.05, -2.5, -2.5)
    return CriticData(
        poses=poses,
        headings=np.stack([np.cos(poses[..., 2]), np.sin(poses[..., 2])], axis=-1),
        vels=np.ascontiguousarray(vels, dtype=float),
        robot=np.array(robot, float),
        goal=np.array(goal, float),
        path=path,
        blocked=np.zeros(path.shape[0], bool),
        furthest=path.shape[0] - 1,
        dt=DT,
        limits=(-0.35, 0.5, 0.5, 1.9),
        model=DIFF_DRIVE,
        min_turning_r=0.2,
        costmap=m,
        outline=outline_points(footprint_from_radius(0.2), 0.05),
        clearance2=squared_distances_to(m.costs == 254),
        inside2=(0.2 / 0.05 - math.sqrt(2)) ** 2,
        outside2=(0.2 / 0.05 + math.sqrt(2)) ** 2,
        inscribed_radius=0.2,
        costs=np.zeros(b),
    )


def score(name, data, **params):
    cls = CRITICS[name]
    cls(cls.Params(**params)).score(data)
    return data.costs


def test_constraint_critic_charges_velocity_beyond_the_limits():
    vels = np.zeros((2, 20, 3))
    vels[0, :, 0] = 0.5
    vels[1, :, 0] = 0.7
    c = score("ConstraintCritic", data_for([straight(0)] * 2, vels))
    assert c[0] == 0.0 and c[1] == pytest.approx(4.0 * 0.2 * DT * 20)


def test_cost_critic_prefers_free_space_and_charges_collisions():
    m = Costmap2D(200, 100, 0.05, -2.5, -2.5)
    m.costs[55:60, :] = 100  # y 0.25..0.5: inflated, not lethal
    m.costs[70:75, :] = 254  # y 1.0..1.25: lethal
    trajs = [straight(-0.5), straight(0.3), straight(1.1)]
    d = data_for(trajs, m=m)
    c = score("CostCritic", d, trajectory_point_step=1)
    assert c[0] == 0.0
    assert c[1] == pytest.approx(3.81 / 254.0 * 100.0)
    assert c[2] == pytest.approx(1e6) and not d.fail
    d = data_for([straight(1.1)] * 2, m=m)
    score("CostCritic", d)
    assert d.fail  # every sample collides
    # with the footprint: a centre in inflated space whose outline touches the lethal row
    m.costs[66:70, :] = 50
    d = data_for([straight(0.85)], m=m)
    assert score("CostCritic", d, consider_footprint=True)[0] == pytest.approx(1e6)
    d = data_for([straight(0.85)], m=m)
    assert score("CostCritic", d, consider_footprint=False)[0] < 1.0


def test_obstacles_critic_repels_from_inflation_and_charges_collisions():
    m = Costmap2D(200, 100, 0.05, -2.5, -2.5)
    m.costs[55:60, :] = 30
    m.costs[60:65, :] = 200
    m.costs[70:75, :] = 254
    d = data_for([straight(-0.5), straight(0.3), straight(0.6), straight(1.1)], m=m)
    c = score("ObstaclesCritic", d)
    assert c[0] == 0.0 and 0.0 < c[1] < c[2] < 1e4 and c[3] >= 1e4


def test_goal_critics_score_only_near_the_goal():
    trajs = [straight(0.0), straight(0.5)]
    far = data_for(trajs, goal=(5.0, 0.0, 0.0))
    assert np.all(score("GoalCritic", far) == 0.0)
    near = data_for(trajs, goal=(1.0, 0.0, 0.0))
    c = score("GoalCritic", near)
    mean0 = np.mean(np.hypot(trajs[0][:, 0] - 1.0, trajs[0][:, 1]))
    assert c[0] == pytest.approx(5.0 * mean0) and c[1] > c[0]
    near = data_for([straight(0.0, 0.1), straight(0.0, 0.5)], goal=(0.3, 0.0, 0.0))
    c = score("GoalAngleCritic", near)
    assert c[0] == pytest.approx(3.0 * 0.1) and c[1] == pytest.approx(3.0 * 0.5)
    assert np.all(score("GoalAngleCritic", data_for(trajs)) == 0.0)


def test_path_align_critic_charges_distance_from_the_path():
    # 1 m/s: the poses fall on the path's 5 cm points (the distance is to the nearest point)
    d = data_for([straight(0.0, v=1.0), straight(0.1, v=1.0), straight(-0.3, v=1.0)])
    c = score("PathAlignCritic", d, trajectory_point_step=1)
    assert c[0] == pytest.approx(0.0, abs=1e-12)
    assert c[1] == pytest.approx(10.0 * 0.1) and c[2] == pytest.approx(10.0 * 0.3)
    d = data_for([straight(0.1)])
    d.furthest = 5  # not yet tracking the path: offset_from_furthest 20
    assert score("PathAlignCritic", d)[0] == 0.0
    d = data_for([straight(0.1)])
    d.blocked[:5] = True  # 5 of 31 points blocked > 7 %
    assert score("PathAlignCritic", d)[0] == 0.0


def test_path_follow_critic_pulls_towards_a_point_ahead():
    d = data_for([straight(0.0), straight(0.4)])
    d.furthest = 10
    c = score("PathFollowCritic", d)
    target = d.path[16]
    ends = d.poses[:, -1, :2]
    assert c == pytest.approx(5.0 * np.hypot(*(ends - target[:2]).T))
    assert c[0] < c[1]
    d.blocked[16:20] = True  # a blocked target moves on past the obstacle
    d.costs[:] = 0.0
    c2 = score("PathFollowCritic", d)
    assert c2[0] == pytest.approx(5.0 * np.hypot(*(ends[0] - d.path[20, :2])))


def test_path_angle_critic_turns_a_robot_facing_away():
    toward = data_for([straight(0.0, 0.0), straight(0.0, 1.2)], robot=(0.0, 0.0, 0.0))
    assert np.all(score("PathAngleCritic", toward) == 0.0)  # robot already faces the path
    away = data_for([straight(0.0, 0.0), straight(0.0, 1.2)], robot=(0.0, 0.0, 1.5))
    c = score("PathAngleCritic", away)
    assert 0.0 <= c[0] < c[1]
    c = score("PathAngleCritic", data_for([straight(0.0, math.pi)], robot=(0.0, 0.0, math.pi)),
              forward_preference=False)  # fmt: skip
    assert c[0] == 0.0  # reversing along the path is fine without a forward preference


def test_prefer_forward_and_twirling_critics():
    vels = np.zeros((2, 20, 3))
    vels[0, :, 0] = 0.3
    vels[1, :, 0] = -0.2
    vels[1, :, 2] = 0.5
    d = data_for([straight(0.0)] * 2, vels)
    c = score("PreferForwardCritic", d)
    assert c[0] == 0.0 and c[1] == pytest.approx(5.0 * 0.2 * 20 * DT)
    d = data_for([straight(0.0)] * 2, vels)
    c = score("TwirlingCritic", d)
    assert c[0] == 0.0 and c[1] == pytest.approx(10.0 * 0.5)
    d = data_for([straight(0.0)] * 2, vels)
    c = score("TwirlingCritic", d, cost_power=2)
    assert c[1] == pytest.approx((10.0 * 0.5) ** 2)


def test_every_critic_has_nav2_defaults_declared():
    assert set(CRITICS) == {
        "ConstraintCritic", "CostCritic", "ObstaclesCritic", "GoalCritic", "GoalAngleCritic",
        "PathAlignCritic", "PathFollowCritic", "PathAngleCritic", "PreferForwardCritic",
        "TwirlingCritic",
    }  # fmt: skip
    assert cp.CostCriticParams().critical_cost == 300.0
    assert cp.CostCriticParams().collision_cost == 1e6
    assert cp.PathAlignCriticParams().max_path_occupancy_ratio == 0.07
    assert cp.GoalCriticParams().threshold_to_consider == 1.4


def test_a_free_centre_with_a_corner_on_an_obstacle_collides():
    m = Costmap2D(200, 100, 0.05, -2.5, -2.5)
    m.costs[70:75, :] = 254  # y 1.0..1.25: lethal, no inflation around it
    corner = np.array([[-0.3, -0.3], [-0.3, 0.3], [0.3, 0.3], [0.3, -0.3]])

    def square_robot(d):
        d.outline = outline_points(corner, 0.05)
        d.inside2 = (0.3 / 0.05 - math.sqrt(2)) ** 2
        d.outside2 = (math.hypot(0.3, 0.3) / 0.05 + math.sqrt(2)) ** 2
        return d

    d = square_robot(data_for([straight(0.75, 0.5)], m=m))  # turned: a corner reaches y 1.0
    assert score("CostCritic", d, consider_footprint=True)[0] == pytest.approx(1e6)
    d = square_robot(data_for([straight(0.75, 0.5)], m=m))
    assert score("CostCritic", d, consider_footprint=False)[0] == 0.0  # its centre is free


def test_with_the_footprint_an_inscribed_centre_is_graded_not_critical():
    # the footprint decides collisions; an INSCRIBED centre it finds clear is a tight fit, not
    # a near collision worth critical_cost per pose (which kept MPPI out of gaps navfn takes)
    m = Costmap2D(200, 100, 0.05, -2.5, -2.5)
    m.costs[70:75, :] = 254  # y 1.0..1.25
    m.costs[60:70, :] = 253  # an inscribed band below it, out of the round robot's reach
    traj = [straight(0.55)]  # cell row 61: 253, the outline (r 0.2) reaches y 0.75 < 1.0
    graded = score("CostCritic", data_for(traj, m=m), consider_footprint=True)[0]
    assert graded == pytest.approx(3.81 / 254 * 252)
    strict = score("CostCritic", data_for(traj, m=m), consider_footprint=False)[0]
    assert strict == pytest.approx(1e6)  # the centre rule: inscribed is a collision
    near = score("CostCritic", data_for(traj, m=m), consider_footprint=True,
                 near_collision_cost=200)[0]  # fmt: skip
    assert near == pytest.approx(3.81 / 254 * 300)  # a lower threshold still applies


@pytest.mark.parametrize("seed", range(3))
def test_footprint_collisions_match_the_outline_or_an_obstacle_inside(seed):
    rng = np.random.default_rng(seed)
    m = Costmap2D(60, 60, 0.05)
    m.costs[rng.random((60, 60)) < 0.01] = 254
    rect = np.array([[-0.31, -0.27], [-0.31, 0.27], [0.31, 0.27], [0.31, -0.27]])
    outline = outline_points(rect, 0.05)
    clear2 = squared_distances_to(m.costs == 254)
    inside2 = (0.27 / 0.05 - math.sqrt(2)) ** 2
    outside2 = (math.hypot(0.31, 0.27) / 0.05 + math.sqrt(2)) ** 2
    lethal = np.argwhere(m.costs == 254)[:, ::-1] * 0.05 + 0.025  # cell centres (x, y)
    for x, y, yaw in rng.uniform((0.5, 0.5, -math.pi), (2.5, 2.5, math.pi), (300, 3)):
        c, s = math.cos(yaw), math.sin(yaw)
        got = k.strict_pose_cost(m.costs, clear2, 0.0, 0.0, 0.05, outline, True, inside2, outside2,
                          x, y, c, s)  # fmt: skip
        pts = np.column_stack([x + c * outline[:, 0] - s * outline[:, 1],
                               y + s * outline[:, 0] + c * outline[:, 1]])  # fmt: skip
        cells = np.floor(pts / 0.05).astype(int)
        on_outline = (m.costs[cells[:, 1], cells[:, 0]] == 254).any()
        centre_lethal = m.costs[int(y / 0.05), int(x / 0.05)] == 254
        local = (lethal - (x, y)) @ np.array([[c, -s], [s, c]])  # into the robot frame
        inside = ((np.abs(local[:, 0]) < 0.31) & (np.abs(local[:, 1]) < 0.27)).any()
        if on_outline or centre_lethal:
            assert got == k.COLLISION
        elif got == k.COLLISION:
            assert inside  # only an obstacle within the footprint, not under its outline


@pytest.mark.parametrize("seed", range(3))
def test_centre_only_batches_score_as_the_general_pose_cost(seed):
    """CostCritic's and ObstaclesCritic's loops take `centre_cost` when neither the footprint
    nor an escape applies; every pose, on and off the grid, scores as `pose_cost` says."""
    rng = np.random.default_rng(seed)
    m = Costmap2D(40, 40, 0.05, origin_x=-0.3, origin_y=0.2)
    m.costs[:] = rng.choice(
        [0, 40, 120, 252, 253, 254, 255], size=(40, 40), p=[0.5, 0.2, 0.1, 0.1, 0.01, 0.01, 0.08]
    )
    clear2 = squared_distances_to(m.costs == 254)
    outline = outline_points(footprint_from_radius(0.2), 0.05)
    poses = rng.uniform((-0.4, 0.1, -3.0), (1.8, 2.3, 3.0), (64, 12, 3))  # some off the grid
    headings = np.stack([np.cos(poses[..., 2]), np.sin(poses[..., 2])], axis=-1)
    grid = (m.costs, clear2, m.origin_x, m.origin_y, 0.05, outline, False, 1.0, 50.0, -1.0)
    each = np.array([[k.pose_cost(*grid, *poses[b, t, :2], *headings[b, t]) for t in range(12)]
                     for b in range(64)])  # fmt: skip
    collides = each == k.COLLISION
    assert 0 < collides.any(axis=1).sum() < 64
    # the kernels' sums, pose by pose in their order, in Python's floats (the same IEEE
    # doubles: the results must be equal bit for bit, not merely close)
    terms, critical, repulsive = [], [], []
    for b in range(64):
        acc = crit = rep = 0.0
        for c in each[b]:
            if c == k.COLLISION:
                break
            acc += 300.0 if c >= 200.0 else c
            if c > 0.0:
                dist = (10.0 * 0.2 - math.log(min(c, 253.0)) + math.log(253.0)) / 10.0
                if dist < 0.1:
                    crit += 0.1 - dist
                else:
                    rep += max(0.5 - dist, 0.0)
        terms.append(acc / 12)
        critical.append(crit)
        repulsive.append(rep / 12)
    term, hit = k.cost_terms(poses, headings, *grid, 1, 200.0, 300.0, False)
    assert np.array_equal(hit, collides.any(axis=1))
    assert np.array_equal(term, terms)
    got = k.obstacle_terms(poses, headings, *grid, 0.2, 10.0, 0.1, 0.5, False)
    assert np.array_equal(got[2], collides.any(axis=1))
    assert np.array_equal(got[0], critical) and np.array_equal(got[1], repulsive)
