"""Tests for fleetsim.slam.map_merge: two robots' maps merged by their known initial poses."""

import logging
import math

import numpy as np
import pytest

from fleetsim.errors import ParameterError
from fleetsim.launch.registry import resolve_node
from fleetsim.msgs import nav_msgs
from fleetsim.nav.map_io import OccupancyMap
from fleetsim.nav.map_server import grid_msg_from_map, map_from_grid_msg
from fleetsim.runtime import Node, Runtime
from fleetsim.slam.map_merge import MapMerge, merged_frame

RES = 0.1


def world():
    """(40, 60) cells: unknown border, free inside, an L-shaped wall."""
    d = np.full((40, 60), -1, dtype=np.int8)
    d[5:35, 5:55] = 0
    d[10, 10:40] = 100
    d[10:30, 40] = 100
    return d


def robot_view(truth, init, x_range):
    """The part of ``truth`` with x in ``x_range`` (cells), as seen from a map frame placed at
    ``init`` (x, y, yaw) in the world: a grid in that frame (yaw 0 or pi/2 only)."""
    part = np.full(truth.shape, -1, dtype=np.int8)
    part[:, x_range[0] : x_range[1]] = truth[:, x_range[0] : x_range[1]]
    x, y, yaw = init
    if abs(yaw) < 1e-9:
        return OccupancyMap(part, RES, (-x, -y, 0.0))
    # yaw = pi/2: world (u, v) -> map (v - y, x - u): map column = world row, map row k =
    # world column W - 1 - k
    rotated = np.ascontiguousarray(part[:, ::-1].T)
    return OccupancyMap(rotated, RES, (-y, x - truth.shape[1] * RES, 0.0))


class Robots(Node):
    def __init__(self, rt, maps):
        super().__init__(rt, "robots")
        for ns, (occupancy, init) in maps.items():
            pub = self.create_publisher(nav_msgs.OccupancyGrid, f"{ns}/map", 1, latch=True)
            pub.publish(grid_msg_from_map(occupancy, f"{ns.strip('/')}/map"))
            for key, value in zip(("init_pose_x", "init_pose_y", "init_pose_yaw"), init):
                rt.params.set(f"{ns}/map_merge/{key}", value)


def test_registered_under_both_package_names():
    assert resolve_node("multirobot_map_merge", "map_merge") is MapMerge
    assert resolve_node("map_merge", "map_merge") is MapMerge


def test_two_maps_merge_back_into_the_world_by_their_initial_poses():
    truth = world()
    inits = {"/robot1": (1.0, 2.0, 0.0), "/robot2": (3.0, 1.0, math.pi / 2)}
    views = {
        "/robot1": (robot_view(truth, inits["/robot1"], (0, 35)), inits["/robot1"]),
        "/robot2": (robot_view(truth, inits["/robot2"], (30, 60)), inits["/robot2"]),
    }
    rt = Runtime()
    Robots(rt, views)
    rt.params.set("/map_merge/world_frame", "map")
    merge = MapMerge(rt)
    got = []
    rt.graph.subscribe("/map", nav_msgs.OccupancyGrid, got.append)
    rt.run(duration=0.5)
    merged = map_from_grid_msg(got[-1])
    assert got[-1].header.frame_id == "map" and merge.merged is got[-1]
    ox, oy = merged.origin[:2]
    i0, j0 = round(-oy / RES), round(-ox / RES)  # the world's cell (0, 0) in the merged grid
    window = merged.data[i0 : i0 + 40, j0 : j0 + 60]
    assert window.shape == truth.shape
    assert np.array_equal(window, truth)


def test_a_robot_without_an_initial_pose_is_left_out_and_estimation_is_refused(caplog):
    rt = Runtime()
    occupancy = OccupancyMap(world(), RES, (0.0, 0.0, 0.0))
    pub = Node(rt, "r").create_publisher(nav_msgs.OccupancyGrid, "/robot3/map", 1, latch=True)
    pub.publish(grid_msg_from_map(occupancy))
    merge = MapMerge(rt)
    with caplog.at_level(logging.WARNING):
        rt.run(duration=0.5)
    assert "leaving /robot3/map out: /robot3/map_merge/init_pose_x is not set" in caplog.text
    assert merge.merged is None
    rt.params.set("/map_merge2/known_init_poses", False)
    with pytest.raises(ParameterError, match="known_init_poses false"):
        MapMerge(rt, "map_merge2")


def test_the_first_merged_map_goes_out_when_the_first_map_arrives():
    rt = Runtime()
    rt.params.set("/map_merge/merging_rate", 0.1)  # every 10 s
    rt.params.set("/robot1/map_merge/init_pose_x", 0.0)
    rt.params.set("/robot1/map_merge/init_pose_y", 0.0)
    rt.params.set("/robot1/map_merge/init_pose_yaw", 0.0)
    pub = Node(rt, "r").create_publisher(nav_msgs.OccupancyGrid, "/robot1/map", 1, latch=True)
    merge = MapMerge(rt)
    rt.run(duration=0.5)
    assert merge.merged is None  # the robot has published nothing yet
    pub.publish(grid_msg_from_map(OccupancyMap(world(), RES, (0.0, 0.0, 0.0))))
    rt.run(duration=0.1)
    assert merge.merged is not None and rt.now() < 1.0


def _merged_grid_reference(grids):
    """merged_grid's placement as first written, every merged cell placed in 2-D (meshgrids):
    the reference the separable form must give bit for bit (the maps' frame is merged_grid's
    own, `merged_frame`)."""
    placed, res, x0, y0, width, height = merged_frame(grids)
    out = np.full((height, width), -1, dtype=np.int8)
    gx, gy = np.meshgrid(x0 + (np.arange(width) + 0.5) * res, y0 + (np.arange(height) + 0.5) * res)
    for data, r, wx, wy, wyaw in placed:
        cw, sw = math.cos(wyaw), math.sin(wyaw)
        dx, dy = gx - wx, gy - wy
        lx, ly = cw * dx + sw * dy, -sw * dx + cw * dy
        cx, cy = np.floor(lx / r).astype(int), np.floor(ly / r).astype(int)
        inside = (cx >= 0) & (cy >= 0) & (cx < data.shape[1]) & (cy < data.shape[0])
        values = np.full(out.shape, -1, dtype=np.int8)
        values[inside] = data[cy[inside], cx[inside]]
        np.maximum(out, values, out=out)
    return out, res, (float(x0), float(y0))


@pytest.mark.parametrize("yaws", [(0.0, 0.0), (0.0, math.pi / 2), (0.3, -2.0), (0.0, math.pi)])
def test_merged_grid_matches_the_cell_by_cell_placement(yaws):
    """Maps of different sizes, resolutions and origins (cell fractions apart), placed with
    and without rotation, merge exactly as placing every merged cell on its own does."""
    from fleetsim.slam.map_merge import merged_grid

    rng = np.random.default_rng(7)
    for trial in range(6):
        grids = []
        for k, yaw in enumerate(yaws):
            h, w = (int(v) for v in rng.integers(20, 90, 2))
            data = rng.choice(np.array([-1, 0, 100], np.int8), size=(h, w), p=[0.5, 0.4, 0.1])
            r = 0.05 if trial % 2 == 0 or k == 0 else 0.1
            origin = (float(rng.uniform(-3, 0)), float(rng.uniform(-3, 0)), 0.0)
            init = (float(rng.uniform(-2, 2)), float(rng.uniform(-2, 2)), yaw)
            grids.append((data, r, origin, init))
        got, want = merged_grid(grids), _merged_grid_reference(grids)
        assert got[1:] == want[1:]
        np.testing.assert_array_equal(got[0], want[0])
