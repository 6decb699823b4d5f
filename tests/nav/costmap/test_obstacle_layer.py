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
