"""Tests for fleetsim.localization.amcl.grid_map: states, distance field, free cells, errors."""

from types import SimpleNamespace

import numpy as np
import pytest

from fleetsim.localization.amcl.grid_map import (
    FREE,
    OCCUPIED,
    UNKNOWN,
    AmclMap,
    LocalizationError,
    distances_to_obstacles,
)


def small_map():
    data = np.zeros((6, 8), dtype=np.int8)
    data[2, 3] = 100
    data[5, 7] = 100
    data[0, 0] = -1
    data[1, 1] = 50
    return AmclMap.from_occupancy(data.ravel(), 8, 6, 0.5, (-1.0, 2.0, 0.0))


def test_states_follow_amcl_convert_map():
    m = small_map()
    assert m.occ_state[2, 3] == OCCUPIED and m.occ_state[5, 7] == OCCUPIED
    assert m.occ_state[0, 0] == UNKNOWN and m.occ_state[1, 1] == UNKNOWN
    assert m.occ_state[4, 4] == FREE
    assert (m.width, m.height) == (8, 6)


def test_distance_field_matches_brute_force_and_clips():
    rng = np.random.default_rng(0)
    occ = rng.random((30, 40)) < 0.02
    d = distances_to_obstacles(occ, 0.1, 0.7)
    oj, oi = np.nonzero(occ)
    jj, ii = np.mgrid[0:30, 0:40]
    brute = np.sqrt((ii[..., None] - oi) ** 2 + (jj[..., None] - oj) ** 2).min(axis=-1) * 0.1
    np.testing.assert_allclose(d, np.minimum(brute, 0.7), atol=1e-12)
    assert np.all(distances_to_obstacles(np.zeros((3, 3), bool), 0.1, 2.0) == 2.0)


def test_distance_field_is_cached_and_read_only():
    m = small_map()
    a = m.distance_field(2.0)
    assert a is m.distance_field(2.0)
    assert not a.flags.writeable
    assert a[2, 3] == 0.0 and a[2, 4] == pytest.approx(0.5)


def test_cells_and_contains():
    m = small_map()
    i, j = m.cells_from_points(np.array([[-1.0, 2.0], [-0.01, 2.49], [2.99, 4.99]]))
    assert list(i) == [0, 1, 7] and list(j) == [0, 0, 5]
    assert m.contains(0.0, 3.0) and not m.contains(-1.01, 3.0) and not m.contains(0.0, 5.0)


def test_random_free_poses_lie_in_free_cells():
    m = small_map()
    poses = m.random_free_poses(2000, np.random.default_rng(1))
    i, j = m.cells_from_points(poses[:, :2])
    assert np.all(m.occ_state[j, i] == FREE)
    assert poses[:, 2].min() >= -np.pi and poses[:, 2].max() < np.pi


def test_from_grid_msg_duck_typed():
    info = SimpleNamespace(
        width=2,
        height=1,
        resolution=0.1,
        origin=SimpleNamespace(
            position=SimpleNamespace(x=1.0, y=2.0, z=0.0),
            orientation=SimpleNamespace(x=0.0, y=0.0, z=0.0, w=1.0),
        ),
    )
    m = AmclMap.from_grid_msg(SimpleNamespace(info=info, data=np.array([0, 100], np.int8)))
    assert m.origin_x == 1.0 and m.origin_y == 2.0 and list(m.occ_state[0]) == [FREE, OCCUPIED]


def test_bad_maps_raise():
    with pytest.raises(
        LocalizationError, match=r"willow\.yaml: data has 3 cells but info says 2 x 2"
    ):
        AmclMap.from_occupancy(np.zeros(3), 2, 2, 0.1, source="willow.yaml")
    with pytest.raises(LocalizationError, match=r"origin yaw 0\.5 rad is not supported"):
        AmclMap.from_occupancy(np.zeros(4), 2, 2, 0.1, (0.0, 0.0, 0.5))
    with pytest.raises(LocalizationError, match=r"resolution must be > 0 m, got 0\.0"):
        AmclMap(np.zeros((2, 2), np.int8), 0.0)
    full = AmclMap.from_occupancy(np.full(4, 100), 2, 2, 0.1)
    with pytest.raises(LocalizationError, match="no free cell"):
        full.random_free_poses(3, np.random.default_rng(0))


def test_amcls_given_the_same_map_message_share_one_map():
    from fleetsim.msgs import nav_msgs

    info = nav_msgs.MapMetaData(resolution=0.5, width=3, height=2)
    msg = nav_msgs.OccupancyGrid(info=info, data=np.array([0, 100, 0, -1, 0, 0], np.int8))
    a = AmclMap.shared_from_grid_msg(msg)
    assert AmclMap.shared_from_grid_msg(msg) is a  # the latched map, as each amcl gets it
    assert a.distance_field(1.0) is AmclMap.shared_from_grid_msg(msg).distance_field(1.0)
    assert not a.free_cells.flags.writeable
    other = nav_msgs.OccupancyGrid(info=info, data=msg.data.copy())  # equal, not the same
    b = AmclMap.shared_from_grid_msg(other)
    assert b is not a and np.array_equal(b.occ_state, a.occ_state)
    moved = nav_msgs.OccupancyGrid(info=nav_msgs.MapMetaData(resolution=0.25, width=3, height=2))
    moved.data = msg.data  # same cells, another geometry
    assert AmclMap.shared_from_grid_msg(moved).resolution == 0.25
