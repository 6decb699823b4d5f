"""The demo office map: drawn by make_office_map.py, loads as a map world, rays hit its walls."""

import importlib.util
from pathlib import Path

import numpy as np
import pytest

from fleetsim.sim import Engine
from fleetsim.sim.mapworld import load_map
from fleetsim.sim.plugins.laser import LaserPlugin

MAPS = Path(__file__).resolve().parents[2] / "src" / "fleetsim" / "assets" / "maps"


def script():
    spec = importlib.util.spec_from_file_location("make_office_map", MAPS / "make_office_map.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_committed_map_is_what_the_script_draws(tmp_path):
    pgm, yml = script().write(tmp_path)
    assert pgm.read_bytes() == (MAPS / "office.pgm").read_bytes()
    assert yml.read_text() == (MAPS / "office.yaml").read_text()


def test_office_geometry():
    grid = load_map(MAPS / "office.yaml")
    assert grid.occupied.shape == (400, 600) and grid.resolution == 0.05

    def occ(x, y):
        return bool(grid.occupied[int(y / 0.05), int(x / 0.05)])

    assert occ(0.05, 10.0) and occ(29.95, 10.0)  # outer walls
    assert occ(1.0, 8.5) and not occ(3.0, 8.5)  # corridor wall, office door
    assert not occ(15.0, 10.0)  # corridor is free
    assert occ(15.0, 15.0)  # meeting table


def test_laser_in_the_corridor_sees_the_walls(diffbot):
    e = Engine(MAPS / "office.yaml")
    ent = e.spawn_robot("r", diffbot, (15.0, 10.0, 0, 0, 0, np.pi / 2))
    laser = next(p for p in ent.plugins if isinstance(p, LaserPlugin))
    ranges = e.lasers.measure(e, [laser], 0.0)[0].ranges
    origin, angles, _ = laser.rays(e)
    ahead = int(np.argmin(np.abs(np.angle(np.exp(1j * (angles - np.pi / 2))))))
    behind = int(np.argmin(np.abs(np.angle(np.exp(1j * (angles + np.pi / 2))))))
    grid = load_map(MAPS / "office.yaml")
    col = int(origin[0, 0] / 0.05)
    rows = np.nonzero(grid.occupied[:, col])[0]
    north = rows[rows * 0.05 > origin[0, 1]].min() * 0.05  # lower edge of the wall above
    south = (rows[rows * 0.05 < origin[0, 1]].max() + 1) * 0.05  # upper edge of the wall below
    assert ranges[ahead] == pytest.approx(north - origin[0, 1], abs=2e-3)
    assert ranges[behind] == pytest.approx(origin[0, 1] - south, abs=2e-3)


def test_demo_warehouse_world_loads():
    worlds = MAPS.parent / "worlds"
    e = Engine(worlds / "warehouse.world")
    assert {"crate_0", "shelf_1", "north"} <= set(e.models)
    assert not e.models["crate_0"].static
    e.advance(0.5)
    assert e.model_pose("crate_0")[0][2] == pytest.approx(0.15, abs=0.01)  # resting
    assert e.world.plugins[0].filename == "libgazebo_ros_link_attacher.so"
