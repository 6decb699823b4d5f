"""The manual's nav_stack.launch through ``fleetsim launch hunter_run launch_nav_stack:=true``:
slam_gmapping maps the office while move_base drives the hunter to a goal."""

import logging
import math
from pathlib import Path

import numpy as np
import pytest

import fleetsim
from fleetsim.cli.launch import resolve_launch_file
from fleetsim.launch.runner import LaunchSession, load_plan
from fleetsim.msgs import nav_msgs
from fleetsim.nav.map_io import load_map
from fleetsim.nav.navigator import Navigator, TaskResult
from fleetsim.slam import SlamGmapping

pytestmark = pytest.mark.scenario

OFFICE = Path(fleetsim.__file__).parent / "assets" / "maps" / "office.yaml"


def occupied_precision(grid: nav_msgs.OccupancyGrid, truth) -> float:
    """Share of the grid's occupied cells within 0.1 m of an occupied cell of ``truth``."""
    from scipy import ndimage

    data = np.asarray(grid.data).reshape(grid.info.height, grid.info.width)
    iy, ix = np.nonzero(data == 100)
    res, o = grid.info.resolution, grid.info.origin.position
    x, y = o.x + (ix + 0.5) * res, o.y + (iy + 0.5) * res
    dist = ndimage.distance_transform_edt(truth.data != 100) * truth.resolution
    tx = np.floor((x - truth.origin[0]) / truth.resolution).astype(int)
    ty = np.floor((y - truth.origin[1]) / truth.resolution).astype(int)
    inside = (tx >= 0) & (ty >= 0) & (tx < truth.width) & (ty < truth.height)
    near = np.zeros(len(x), dtype=bool)
    near[inside] = dist[ty[inside], tx[inside]] <= 0.1 + truth.resolution
    return float(near.mean())


def test_hunter_run_maps_with_gmapping_while_it_drives(caplog):
    plan = load_plan(resolve_launch_file("hunter_run"), {"launch_nav_stack": "true"})
    with caplog.at_level(logging.WARNING), LaunchSession(plan, seed=1) as s:
        slam = s.nodes["/slam_gmapping"]
        assert isinstance(slam, SlamGmapping) and "/map_server" not in s.nodes
        assert slam.params.particles == 20 and slam.params.temporalUpdate == 3.0
        assert slam.tf_period == pytest.approx(0.01)  # 0.0005 s capped at the simulator's rate
        maps = []
        s.runtime.graph.subscribe("/map", nav_msgs.OccupancyGrid, maps.append)
        nav = Navigator(s.runtime, "/")
        s.runtime.run(duration=1.0)
        nav.go_to_pose(7.0, 10.0, 0.0)
        s.runtime.run(duration=40.0, until=nav.is_task_complete)
        assert nav.get_result() == TaskResult.SUCCEEDED, nav.get_status_text()
        s.runtime.run(duration=6.0)  # one more map_update_interval
        pos, _ = s.monitor.sim.engine.model_pose("robocluedo_robot")
        est = s.runtime.tf_buffer.lookup_pose2d("map", "base_link", 0.0)
    assert math.hypot(est[0] - pos[0], est[1] - pos[1]) < 0.1
    assert len(maps) >= 2 and maps[-1].header.frame_id == "map"
    assert occupied_precision(maps[-1], load_map(OFFICE)) > 0.9
    assert not caplog.records, [r.getMessage() for r in caplog.records]
    assert not Path("MUJOCO_LOG.TXT").exists()
