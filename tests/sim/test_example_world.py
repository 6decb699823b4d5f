"""fleetsim's copy of the tutorial's example world and its map: drawn by one committed script,
so that a laser sees the same walls and obstacles in the SDF world and in the map."""

import importlib.util
import sys

import numpy as np
import pytest

from fleetsim.description import load_robot
from fleetsim.sim import Engine
from fleetsim.sim.mapworld import load_map
from fleetsim.sim.plugins.base import ScanReading
from fleetsim.sim.sdf import ASSET_MODELS

ASSETS = ASSET_MODELS.parents[1]
WORLD = ASSETS / "worlds/example.world"
MAP = ASSETS / "maps/example_world.yaml"
BURGER = ASSETS / "robots/turtlebot3_burger/urdf/turtlebot3_burger.urdf.xacro"
#: the tutorial's start poses: the follower (waffle), karl and hank, and one more
POSES = [(4.95, 1.10, -2.65), (-2.0, 2.0, 0.0), (0.0, -4.0, 0.0), (-2.0, -1.0, 1.0)]


pytestmark = pytest.mark.usefixtures("in_tmp_dir")


def generator():
    spec = importlib.util.spec_from_file_location(
        "make_example_world", ASSETS / "worlds/make_example_world.py"
    )
    mod = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = mod  # its dataclasses look their module up
    spec.loader.exec_module(mod)
    return mod


def test_committed_world_and_map_are_the_scripts_output(tmp_path):
    written = generator().write(tmp_path)
    assert len(written) == 7
    for path in written:
        committed = ASSETS / path.relative_to(tmp_path)
        assert committed.read_bytes() == path.read_bytes(), committed


def test_map_has_the_tutorial_layout():
    grid = load_map(MAP)
    assert grid.occupied.shape == (384, 384) and grid.resolution == 0.05
    assert tuple(grid.origin[:2]) == (-10.0, -10.0)

    def cell(x, y):  # rows bottom-up, as OccupancyGrid
        return int((y + 10) / 0.05), int((x + 10) / 0.05)

    assert grid.occupied[cell(0.94, 5.66)]  # Wall_1, on y = 6 in the building frame
    assert grid.occupied[cell(-3.26, 4.03)]  # the 1 m box
    assert grid.occupied[cell(4.1, -1.1)]  # a jersey barrier
    for x, y, _ in POSES:  # the robots start in free space
        assert not grid.occupied[cell(x, y)]


def scans(world):
    e = Engine(world)
    burger = load_robot(BURGER)
    for i, (x, y, yaw) in enumerate(POSES):
        e.spawn_robot(f"b{i}", burger, (x, y, 0, 0, 0, yaw))
    readings = [r for r in e.advance(0.25) if isinstance(r, ScanReading)]
    assert {i: w.number for i, w in enumerate(e.data.warning) if w.number} == {}
    return e, {r.namespace: np.asarray(r.ranges, float) for r in readings}


def test_a_laser_sees_the_same_surroundings_in_the_world_and_in_the_map():
    e, in_world = scans(WORLD)
    assert {"building", "box_z_0_5m", "oak_tree", "jersey_barrier_1"} <= set(e.models)
    walls = [i for i in range(e.model.ngeom) if "Wall_1_Visual" in e.model.geom(i).name]
    assert walls and all(e.model.geom_matid[i] >= 0 for i in walls)  # bricks texture
    _, in_map = scans(MAP)
    assert len(in_world) == len(POSES)
    for ns, a in in_world.items():
        b = in_map[ns]
        hit_a, hit_b = np.isfinite(a) & (a < 3.4), np.isfinite(b) & (b < 3.4)
        assert hit_a.sum() > 50, ns  # walls and obstacles in range
        both = hit_a & hit_b
        diff = np.abs(a[both] - b[both])
        # the map's 5 cm cells and the laser's 1 cm noise
        assert np.median(diff) < 0.05, ns
        disagree = np.count_nonzero(diff > 0.1) + np.count_nonzero(hit_a != hit_b)
        assert disagree <= 0.05 * len(a), ns
