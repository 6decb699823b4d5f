"""Rollout kernels: the footprint bound map and the footprint skip against brute force."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from fleetsim.nav.controllers.map_grid import densified_plan
from fleetsim.nav.controllers.rollout import (
    footprint_cost_bounds,
    footprint_cost_bounds_near,
    num_steps_of,
    reach_offsets,
    trajectory_costs,
)
from fleetsim.nav.costmap.footprint import footprint_cost_at, footprint_from_radius, outline_points


def bounds_reference(costs, offsets):
    h, w = costs.shape
    out = np.zeros_like(costs)
    for y in range(h):
        for x in range(w):
            v = 0
            for dx, dy in offsets:
                if not (0 <= x + dx < w and 0 <= y + dy < h):
                    v = 255
                    break
                v = max(v, int(costs[y + dy, x + dx]))
            out[y, x] = v
    return out


@settings(max_examples=25, deadline=None)
@given(
    seed=st.integers(0, 2**31),
    radius=st.floats(0.02, 0.4),
    shape=st.tuples(st.integers(1, 30), st.integers(1, 30)),
)
def test_bounds_match_brute_force(seed, radius, shape):
    rng = np.random.default_rng(seed)
    costs = rng.integers(0, 256, shape).astype(np.uint8)
    offsets = reach_offsets(outline_points(footprint_from_radius(radius), 0.05), 0.05)
    assert np.array_equal(footprint_cost_bounds(costs, offsets), bounds_reference(costs, offsets))


@settings(max_examples=25, deadline=None)
@given(
    seed=st.integers(0, 2**31),
    shape=st.tuples(st.integers(1, 40), st.integers(1, 40)),
    centre=st.tuples(st.integers(-5, 45), st.integers(-5, 45)),
    radius=st.integers(0, 12),
)
def test_bounds_near_a_cell_are_exact_there_and_never_too_low(seed, shape, centre, radius):
    """Within ``radius`` of the cell the windowed bounds equal the full ones; elsewhere they
    may only be higher (a higher bound only sends the pose to the exact footprint check)."""
    rng = np.random.default_rng(seed)
    costs = rng.integers(0, 256, shape).astype(np.uint8)
    offsets = reach_offsets(outline_points(footprint_from_radius(0.2), 0.05), 0.05)
    full = footprint_cost_bounds(costs, offsets)
    near = footprint_cost_bounds_near(costs, offsets, centre[0], centre[1], radius)
    assert (near >= full).all()
    rows = slice(max(centre[1] - radius, 0), max(centre[1] + radius + 1, 0))
    cols = slice(max(centre[0] - radius, 0), max(centre[0] + radius + 1, 0))
    assert np.array_equal(near[rows, cols], full[rows, cols])


@settings(max_examples=40, deadline=None)
@given(
    seed=st.integers(0, 2**31),
    x=st.floats(0.0, 2.0),
    y=st.floats(0.0, 2.0),
    yaw=st.floats(-4.0, 4.0),
)
def test_outline_points_land_within_reach(seed, x, y, yaw):
    """Every outline cell at any pose is the centre cell plus one of the reach offsets."""
    rng = np.random.default_rng(seed)
    fp = footprint_from_radius(0.1 + 0.3 * rng.random()) * rng.uniform(0.5, 1.5, (16, 1))
    outline = outline_points(fp, 0.05)
    offsets = {tuple(o) for o in reach_offsets(outline, 0.05)}
    c, s = np.cos(yaw), np.sin(yaw)
    px = (x + c * outline[:, 0] - s * outline[:, 1]) / 0.05
    py = (y + s * outline[:, 0] + c * outline[:, 1]) / 0.05
    cx, cy = np.floor(x / 0.05), np.floor(y / 0.05)
    for dx, dy in zip(np.floor(px) - cx, np.floor(py) - cy):
        assert (int(dx), int(dy)) in offsets


def random_map(rng, h=60, w=70):
    costs = np.zeros((h, w), np.uint8)
    for _ in range(6):
        cy, cx = rng.integers(0, h), rng.integers(0, w)
        yy, xx = np.mgrid[:h, :w]
        d = np.hypot(yy - cy, xx - cx)
        costs = np.maximum(costs, np.clip(253 - 25 * (d - 2), 0, 253).astype(np.uint8))
        costs[d < 2] = 254
    costs[rng.random((h, w)) < 0.005] = 255
    return costs


@pytest.mark.parametrize("seed", range(4))
def test_skipping_footprints_changes_no_cost(seed):
    """With the real bounds and with bounds that force every footprint: the same costs."""
    rng = np.random.default_rng(seed)
    costs = random_map(rng)
    res, origin = 0.05, np.array([-0.5, 0.25])
    outline = outline_points(footprint_from_radius(0.15), res)
    samples = np.stack(
        [rng.uniform(-0.1, 0.8, 300), np.zeros(300), rng.uniform(-1.0, 1.0, 300)], axis=1
    )
    steps = num_steps_of(samples, 2.0, 0.025, 0.025, False)
    dist = rng.integers(0, 50, costs.shape).astype(np.float64)
    seen = set()
    for _ in range(5):
        pose = np.array([origin[0] + 0.5, origin[1] + 0.5, 0.3])
        while footprint_cost_at(costs, origin[0], origin[1], res, outline, *pose) < 0:
            pose[:2] = origin + rng.uniform(0.3, 3.0, 2)
        args = (
            samples, pose, np.array([0.2, 0.0, 0.1]), np.array([2.5, 2.5, 3.2]), 2.0, steps,
            costs, origin, res, outline, dist, dist, np.array([0.6, 0.8, 0.01]),
            np.array([0.0, 0.8]), np.zeros((0, 2), np.int64), False, np.zeros(2),
        )  # fmt: skip
        poses_a = np.zeros((300, int(steps.max()), 3))
        poses_b = np.zeros_like(poses_a)
        bounds = footprint_cost_bounds(costs, reach_offsets(outline, res))
        a = trajectory_costs(*args, poses_a, bounds, np.zeros(2))
        b = trajectory_costs(*args, poses_b, np.full(costs.shape, 255, np.uint8), np.zeros(2))
        assert np.array_equal(a, b)
        assert np.array_equal(poses_a[a >= 0], poses_b[a >= 0])
        seen |= {float(np.sign(c)) for c in a}
        legal = a >= 0
        if not legal.any():
            continue
        # a legal rollout's footprint is legal at each of its poses
        i = int(np.flatnonzero(legal)[0])
        for k in range(int(steps[i])):
            x, y, th = poses_a[i, k]
            assert footprint_cost_at(costs, origin[0], origin[1], res, outline, x, y, th) >= 0
    assert seen >= {-1.0, 1.0}  # both collisions and legal rollouts were compared


def rollout_reference(samples, pose, vel, acc, sim_time, steps, costs, origin, res, outline, dist):
    """generateTrajectory in plain Python, the footprint laid and the heading's cosine and
    sine taken at every pose (vy = 0, no heading scoring, no alignment)."""
    h, w = costs.shape
    out, poses = np.empty(samples.shape[0]), np.zeros((samples.shape[0], int(steps.max()), 3))

    def toward(vg, vi, a, dt):
        return min(vg, vi + a * dt) if vg - vi >= 0 else max(vg, vi - a * dt)

    for s in range(samples.shape[0]):
        n = int(steps[s])
        dt = sim_time / n
        x, y, th = (float(v) for v in pose)
        vx, vth = float(vel[0]), float(vel[2])
        occ = path_d = goal_d = 0.0
        cost = 0.0
        for i in range(n):
            fx, fy = (x - origin[0]) / res, (y - origin[1]) / res
            if cost < 0.0:
                pass  # found illegal: followed to its end, unscored
            elif fx < 0.0 or fy < 0.0 or fx >= w or fy >= h:
                cost = -1.0
            else:
                cx, cy = int(fx), int(fy)
                occ = max(occ, float(costs[cy, cx]))
                fp = footprint_cost_at(costs, origin[0], origin[1], res, outline, x, y, th)
                if fp < 0.0:
                    cost = -1.0
                else:
                    occ = max(occ, fp)
                    path_d = goal_d = dist[cy, cx]
            poses[s, i] = x, y, th
            vx = toward(samples[s, 0], vx, acc[0], dt)
            vth = toward(samples[s, 2], vth, acc[2], dt)
            x = x + vx * math.cos(th) * dt
            y = y + vx * math.sin(th) * dt
            th = th + vth * dt
        out[s] = cost if cost < 0.0 else 0.6 * path_d + 0.8 * goal_d + 0.01 * occ
    return out, poses


@pytest.mark.parametrize("seed", range(4))
def test_rollouts_match_a_plain_reference_bit_for_bit(seed):
    """The kernel's shortcuts (the first pose's footprint laid once, a heading's cosine and
    sine kept while it does not change, no motion at rest, footprints skipped under the
    bounds) give the costs and poses of the plain rollout exactly: rotations in place from
    rest and from motion, straight rollouts, turning ones."""
    rng = np.random.default_rng(seed)
    costs = random_map(rng)
    res, origin = 0.05, np.array([-0.5, 0.25])
    outline = outline_points(footprint_from_radius(0.15), res)
    vx = np.r_[np.zeros(20), rng.uniform(0.1, 0.8, 60), np.full(20, 0.4), -0.1]
    vth = np.r_[rng.uniform(-1.0, 1.0, 80), np.zeros(20), 0.0]
    samples = np.stack([vx, np.zeros(vx.shape[0]), vth], axis=1)
    steps = num_steps_of(samples, 1.5, 0.025, 0.025, False)
    dist = rng.integers(0, 50, costs.shape).astype(np.float64)
    bounds = footprint_cost_bounds(costs, reach_offsets(outline, res))
    compared = 0
    for vel in ([0.0, 0.0, 0.0], [0.3, 0.0, 0.0], [0.2, 0.0, -0.4]):
        pose = np.array([origin[0] + 0.5, origin[1] + 0.5, rng.uniform(-3.0, 3.0)])
        while footprint_cost_at(costs, origin[0], origin[1], res, outline, *pose) < 0:
            pose[:2] = origin + rng.uniform(0.3, 3.0, 2)
        vel = np.array(vel)
        acc = np.array([2.5, 2.5, 3.2])
        poses = np.zeros((samples.shape[0], int(steps.max()), 3))
        got = trajectory_costs(
            samples, pose, vel, acc, 1.5, steps, costs, origin, res, outline, dist, dist,
            np.array([0.6, 0.8, 0.01]), np.array([0.0, 0.8]), np.zeros((0, 2), np.int64), False,
            np.zeros(2), poses, bounds, np.zeros(2),
        )  # fmt: skip
        want, want_poses = rollout_reference(
            samples, pose, vel, acc, 1.5, steps, costs, origin, res, outline, dist
        )
        assert np.array_equal(got, want)
        assert np.array_equal(poses.view(np.uint64), want_poses.view(np.uint64))
        compared += int((got >= 0).sum())
    assert compared > 0  # legal rollouts were compared, not only collisions


def test_densified_plan_matches_per_segment_reference():
    rng = np.random.default_rng(3)
    for _ in range(50):
        p = rng.normal(size=(int(rng.integers(2, 20)), 2)) * rng.uniform(0.01, 3.0)
        seg = np.diff(p, axis=0)
        n = np.maximum(1, np.ceil(np.hypot(seg[:, 0], seg[:, 1]) / 0.05).astype(int))
        ref = [a + (np.arange(k) / k)[:, None] * d for a, d, k in zip(p[:-1], seg, n)]
        assert np.array_equal(densified_plan(p, 0.05), np.concatenate([*ref, p[-1:]]))


@pytest.mark.parametrize("y", [0.62, 0.75, 1.0])
def test_path_distances_match_the_full_passable_mask(y):
    """Skipping the footprint mask away from obstacles gives the MapGrid of the full method."""
    from fleetsim.nav.controllers import TrajectoryPlanner, TrajectoryPlannerParams
    from fleetsim.nav.controllers.map_grid import distances_from_targets
    from fleetsim.nav.costmap import Costmap2D
    from fleetsim.nav.costmap.footprint import footprint_at, polygon_cells

    m = Costmap2D(120, 40, 0.05)
    m.costs[0:8, :] = 254
    m.costs[8:12, :] = 253  # inscribed band along the wall
    m.costs[32:, :] = 254
    fp = footprint_from_radius(0.2)
    tp = TrajectoryPlanner(m, fp, TrajectoryPlannerParams(holonomic_robot=False))
    xs = np.linspace(0.5, 5.0, 50)
    plan = np.stack([xs, np.full(50, 1.0), np.zeros(50)], axis=1)
    tp.set_plan(plan)
    pose = (1.0, y, 0.3)
    tp.compute_velocity_commands(pose, (0.0, 0.0, 0.0))
    passable = np.zeros(m.costs.shape, bool)
    rows, cols = polygon_cells(m, footprint_at(fp, *pose))
    passable[rows, cols] = True
    assert np.array_equal(tp.path_dist, distances_from_targets(m.costs, tp.plan_cells, passable))
    assert tp._obstacle_near(footprint_at(fp, *pose)) == (y < 0.8)
    without = distances_from_targets(m.costs, tp.plan_cells, np.zeros_like(passable))
    assert np.array_equal(tp.path_dist, without) == (y > 0.9)  # the mask matters near walls
