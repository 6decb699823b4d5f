"""Obstacle layer: marking, clearing (vs a slow ray reference), ranges, heights."""

import numpy as np
import pytest

from fleetsim.nav.costmap import (
    FREE_SPACE,
    LETHAL_OBSTACLE,
    NO_INFORMATION,
    LayeredCostmap,
    laser_scan_points,
)
from fleetsim.nav.costmap.raytrace import trace_rays
from fleetsim.nav.errors import CostmapError


def local_costmap(**extra):
    ns = {
        "static_map": False,
        "rolling_window": True,
        "width": 6.0,
        "height": 6.0,
        "resolution": 0.05,
        "robot_radius": 0.1,
        "track_unknown_space": True,
        "observation_sources": "scan",
        "scan": {"data_type": "LaserScan", "marking": True, "clearing": True},
        "obstacle_range": 2.5,
        "raytrace_range": 3.0,
    }
    ns.update(extra)
    return LayeredCostmap.from_params(ns, "local_costmap")


def test_trace_rays_matches_dense_sampling_reference():
    rng = np.random.default_rng(3)
    for _ in range(50):
        grid = np.zeros((40, 40), np.uint8)
        x0, y0 = rng.integers(0, 40, 2)
        end = rng.integers(0, 40, (1, 2))
        trace_rays(grid, int(x0), int(y0), end, 10**6, 7)
        # every traced cell lies within half a cell of the segment along the minor axis
        ys, xs = np.nonzero(grid == 7)
        dx, dy = end[0, 0] - x0, end[0, 1] - y0
        if abs(dx) >= abs(dy) and dx != 0:
            off = ys - (y0 + dy * (xs - x0) / dx)
        elif dy != 0:
            off = xs - (x0 + dx * (ys - y0) / dy)
        else:
            off = np.zeros(1)
        assert np.abs(off).max() <= 0.5 + 1e-9
        n_major = max(abs(end[0, 0] - x0), abs(end[0, 1] - y0)) + 1
        assert (grid == 7).sum() == n_major


def test_scan_marks_hits_and_clears_behind():
    lc = local_costmap()
    pts = laser_scan_points(np.full(360, 1.5), -np.pi, 2 * np.pi / 360, 0.1, 10.0)
    lc.add_observation("scan", [0.0, 0.0, 0.0], pts)
    lc.update_map(0.0, 0.0, 0.0)
    layer = lc.layer("obstacle_layer")
    cell = layer.grid.world_to_map(1.5, 0.01)
    assert layer.grid.costs[cell[1], cell[0]] == LETHAL_OBSTACLE
    inner = layer.grid.world_to_map(0.8, 0.3)
    assert layer.grid.costs[inner[1], inner[0]] == FREE_SPACE
    outer = layer.grid.world_to_map(2.5, 0.0)
    assert layer.grid.costs[outer[1], outer[0]] == NO_INFORMATION


def test_obstacle_range_and_height_filters():
    lc = local_costmap(scan={"marking": True, "max_obstacle_height": 0.5, "obstacle_range": 1.0})
    pts = np.array([[0.5, 0.0, 0.2], [0.0, 0.5, 0.9], [1.5, 0.0, 0.2]])
    lc.add_observation("scan", [0.0, 0.0, 0.2], pts)
    lc.update_map(0.0, 0.0, 0.0)
    g = lc.layer("obstacle_layer").grid
    costs = [g.costs[c[1], c[0]] for c in (g.world_to_map(*p[:2]) for p in pts)]
    assert costs == [LETHAL_OBSTACLE, NO_INFORMATION, NO_INFORMATION]


def test_unknown_source_and_bad_source_namespace():
    lc = local_costmap()
    with pytest.raises(CostmapError, match="no obstacle layer has observation source 'kinect'"):
        lc.add_observation("kinect", [0, 0, 0], np.zeros((0, 3)))
    with pytest.raises(CostmapError, match="'bump' is listed in observation_sources"):
        local_costmap(observation_sources="scan bump")


def test_inf_is_valid_turns_inf_into_max_range():
    r = np.array([np.inf, 1.0, 20.0])
    assert laser_scan_points(r, 0.0, 0.1, 0.1, 10.0).shape == (1, 3)
    pts = laser_scan_points(r, 0.0, 0.1, 0.1, 10.0, inf_is_valid=True)
    assert pts.shape == (2, 3) and np.hypot(*pts[0, :2]) == pytest.approx(10.0, abs=1e-3)


def laser_scan_points_reference(ranges, angle_min, angle_increment, range_min, range_max, inf):
    """The projection as NumPy computed it before it was compiled."""
    r = np.asarray(ranges, dtype=np.float64)
    angles = angle_min + angle_increment * np.arange(r.shape[0])
    if inf:
        r = np.where(np.isposinf(r), range_max - 1e-4, r)
    keep = np.isfinite(r) & (r >= range_min) & (r < range_max)
    r, a = r[keep], angles[keep]
    return np.stack((r * np.cos(a), r * np.sin(a), np.zeros_like(r)), axis=1)


def test_scan_points_match_the_numpy_projection_bit_for_bit():
    """Random scans with inf, -inf, NaN and out-of-range readings, float32 or float64, each
    scan geometry twice (its beam directions are kept): NumPy's points exactly."""
    rng = np.random.default_rng(4)
    for k in range(200):
        n = int(rng.integers(0, 720))
        r = rng.uniform(0.0, 12.0, n)
        r[rng.random(n) < 0.1] = np.inf
        r[rng.random(n) < 0.05] = -np.inf
        r[rng.random(n) < 0.05] = np.nan
        if k % 3 == 0:
            r = r.astype(np.float32)
        geometry = (float(rng.uniform(-3.2, 0.0)), float(rng.uniform(0.001, 0.03)), 0.1, 10.0)
        for inf in (False, True):
            got = laser_scan_points(r, *geometry, inf_is_valid=inf)
            want = laser_scan_points_reference(r, *geometry, inf)
            assert got.shape == want.shape and got.flags.c_contiguous
            assert np.array_equal(got.view(np.uint64), want.view(np.uint64))


def test_marking_points_match_the_numpy_filter_bit_for_bit():
    """The compiled marking filter keeps NumPy's points and cells: heights, obstacle range
    (at its edge too), points off the grid, NaN and inf."""
    from fleetsim.nav.costmap.obstacle_layer import Observation, ObstacleLayer

    lc = local_costmap()
    lc.update_map(1.0, 2.0, 0.0)
    layer = next(la for la in lc.layers if isinstance(la, ObstacleLayer))
    g = layer.grid
    rng = np.random.default_rng(6)
    for _ in range(100):
        n = int(rng.integers(0, 500))
        origin = np.array([1.0, 2.0, rng.uniform(0.0, 1.0)])
        pts = origin + rng.uniform(-4.0, 4.0, (n, 3))
        pts[rng.random(n) < 0.05] = np.nan
        pts[rng.random(n) < 0.05, 0] = np.inf
        ring = 2.5 * np.array([np.cos(0.3), np.sin(0.3), 0.0])  # exactly obstacle_range out
        pts = np.concatenate([pts, [origin + ring, origin - ring]])
        obs = Observation(origin, pts, 2.5, 3.0)
        got_pts, got_cells = layer.marking_points(obs)
        d2 = ((pts - origin) ** 2).sum(axis=1)
        want = pts[(pts[:, 2] <= layer.params.max_obstacle_height) & (d2 < 2.5**2)]
        cells, inside = g.cells_of(want[:, :2])
        assert np.array_equal(got_pts.view(np.uint64), want[inside].view(np.uint64))
        assert np.array_equal(got_cells, cells[inside]) and got_cells.dtype == np.int64


def test_clearing_matches_the_step_by_step_rays_bit_for_bit():
    """`clear_along_rays` (one compiled pass) clears the cells that clipping the ends, taking
    their cells and tracing the rays one step after another cleared: ends off the map on every
    side, beyond raytrace_range, at the sensor."""
    from fleetsim.nav.costmap.costmap_2d import Costmap2D
    from fleetsim.nav.costmap.raytrace import clear_along_rays, ray_ends_clipped

    rng = np.random.default_rng(8)
    for _ in range(100):
        g = Costmap2D(int(rng.integers(5, 90)), int(rng.integers(5, 90)), 0.05, -1.3, 0.7)
        g.costs[:] = LETHAL_OBSTACLE
        want = g.costs.copy()
        lo = np.array(g.origin)
        hi = lo + np.array([g.size_x, g.size_y]) * g.resolution
        origin = np.r_[lo + rng.uniform(0.0, 1.0, 2) * (hi - lo), 0.3]
        n = int(rng.integers(0, 400))
        points = np.c_[origin[:2] + rng.uniform(-6.0, 6.0, (n, 2)), np.zeros(n)]
        points = np.concatenate([points, [origin]])  # a zero-length ray
        start = g.world_to_map(origin[0], origin[1])
        ends = ray_ends_clipped(origin, points, lo, hi)
        cells, inside = g.cells_of(ends)
        trace_rays(want, start[0], start[1], np.ascontiguousarray(cells[inside]), 40, FREE_SPACE)
        clear_along_rays(
            g.costs, origin[0], origin[1], points, lo[0], lo[1], hi[0], hi[1], g.resolution,
            start[0], start[1], 40, FREE_SPACE,
        )  # fmt: skip
        assert np.array_equal(g.costs, want)


def test_height_band_keeps_the_numpy_selection():
    from fleetsim.nav.costmap.obstacle_layer import _in_height_band

    rng = np.random.default_rng(10)
    for _ in range(50):
        pts = rng.uniform(-1.0, 3.0, (int(rng.integers(0, 300)), 3))
        pts[rng.random(pts.shape[0]) < 0.1, 2] = np.nan
        pts[rng.random(pts.shape[0]) < 0.1, 2] = 2.0  # on the band's edge
        want = pts[(pts[:, 2] <= 2.0) & (pts[:, 2] >= 0.0)]
        got = _in_height_band(pts, 0.0, 2.0)
        assert np.array_equal(got.view(np.uint64), want.view(np.uint64))
        assert got.flags.c_contiguous
