import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from fleetsim.errors import SimulationError
from fleetsim.sim.mapworld import load_map, rectangles_from_occupancy, wall_boxes

from .conftest import WILLOW


@settings(max_examples=60, deadline=None)
@given(arrays(np.bool_, st.tuples(st.integers(1, 25), st.integers(1, 25))))
def test_rectangles_cover_exactly_the_occupied_cells(occ):
    rects = rectangles_from_occupancy(occ)
    cover = np.zeros(occ.shape, np.int64)
    for r0, c0, r1, c1 in rects:
        assert r1 > r0 and c1 > c0
        cover[r0:r1, c0:c1] += 1
    np.testing.assert_array_equal(cover, occ.astype(np.int64))  # disjoint and exact


def write_map(tmp_path, pixels, origin=(0.0, 0.0, 0.0), res=0.5):
    from PIL import Image

    Image.fromarray(pixels.astype(np.uint8)).save(tmp_path / "m.pgm")
    (tmp_path / "m.yaml").write_text(
        f"image: m.pgm\nresolution: {res}\norigin: [{origin[0]}, {origin[1]}, {origin[2]}]\n"
        "negate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n"
    )
    return tmp_path / "m.yaml"


def test_walls_sit_where_map_server_puts_the_cells(tmp_path):
    px = np.full((4, 6), 254)
    px[0, 5] = 0  # top row, last column -> highest y, highest x
    grid = load_map(write_map(tmp_path, px, origin=(-1.0, 2.0, 0.0)))
    assert grid.occupied.shape == (4, 6) and grid.occupied[3, 5]
    (box,) = wall_boxes(grid, height=2.0)
    np.testing.assert_allclose(
        box, [-1.0 + 5.5 * 0.5, 2.0 + 3 * 0.5 + 0.25, 1.0, 0.25, 0.25, 1.0, 0]
    )


def test_willow_map_merges_into_few_boxes():
    grid = load_map(WILLOW)
    boxes = wall_boxes(grid)
    assert grid.occupied.sum() > 2 * len(boxes)
    cells = np.sum(4 * boxes[:, 3] * boxes[:, 4]) / grid.resolution**2
    assert round(cells) == grid.occupied.sum()


def test_bad_map_files_are_named(tmp_path):
    (tmp_path / "a.yaml").write_text("image: nothere.pgm\nresolution: 0.1\n")
    with pytest.raises(SimulationError, match=r"a.yaml: map image 'nothere.pgm' not found"):
        load_map(tmp_path / "a.yaml")
    (tmp_path / "b.yaml").write_text("resolution: 0.1\n")
    with pytest.raises(SimulationError, match=r"b.yaml: map YAML lacks the field 'image'"):
        load_map(tmp_path / "b.yaml")
    (tmp_path / "c.yaml").write_text("image: x.pgm\nresolution: fast\n")
    with pytest.raises(SimulationError, match=r"c.yaml: bad number"):
        load_map(tmp_path / "c.yaml")


@pytest.mark.parametrize("origin", [(0.0, 0.0, 0.0), (-40.0, 25.0, 0.5)])
def test_a_map_with_no_occupied_cell_builds_a_world_with_floor_under_it(tmp_path, origin):
    """It used to fail on the empty wall list (the floor was centred on the walls)."""
    from fleetsim.sim.world import world_from_map

    world = world_from_map(write_map(tmp_path, np.full((8, 12), 254), origin=origin))
    ground = world.models[0]
    middle = (
        origin[0] + np.cos(origin[2]) * 3.0 - np.sin(origin[2]) * 2.0,
        origin[1] + np.sin(origin[2]) * 3.0 + np.cos(origin[2]) * 2.0,
    )  # the 12 x 8 cells of 0.5 m: 6 x 4 m
    assert ground.name == "ground_plane"
    assert np.hypot(ground.pose[0] - middle[0], ground.pose[1] - middle[1]) < 1e-9


@pytest.mark.parametrize("origin", [(0.0, 0.0, 0.0), (-3.0, 1.0, 0.7)])
def test_a_map_world_is_bounded_as_stage_floorplans_are(tmp_path, origin):
    """Willow's grey surround reads as free: without a boundary a robot pushed past the map's
    edge drove off every costmap (the soak's warnings). A ray from the middle of an all-free
    map hits a wall just outside each edge and each corner; ``boundary=False`` leaves it open."""
    import mujoco

    from fleetsim.sim.engine import Engine
    from fleetsim.sim.world import world_from_map

    path = write_map(tmp_path, np.full((8, 12), 254), origin=origin)  # 6 x 4 m of free cells
    ox, oy, yaw = origin
    c, s = np.cos(yaw), np.sin(yaw)
    middle = np.array([ox + c * 3.0 - s * 2.0, oy + s * 3.0 + c * 2.0, 0.5])
    # local directions and the distance to the map's edge along them
    cases = [((1, 0), 3.0), ((-1, 0), 3.0), ((0, 1), 2.0), ((0, -1), 2.0)]
    cases.append(((3 / np.hypot(3, 2), 2 / np.hypot(3, 2)), np.hypot(3, 2)))
    for bounded in (True, False):
        e = Engine(world_from_map(path, boundary=bounded))
        for (dx, dy), edge in cases:
            vec = np.array([c * dx - s * dy, s * dx + c * dy, 0.0])
            geomid = np.zeros(1, np.int32)
            d = mujoco.mj_ray(e.model, e.data, middle, vec, None, 1, -1, geomid)
            if bounded:
                assert edge - 1e-6 <= d <= edge + 0.5 * np.sqrt(2) + 1e-6, (dx, dy, d)
            else:
                assert d == -1, (dx, dy, d)
