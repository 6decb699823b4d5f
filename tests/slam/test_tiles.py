"""Tests for fleetsim.slam.tiles: copy-on-write tiles shared by resampled particles."""

import numpy as np

from fleetsim.slam.render import cast_counts, occupancy_from_counts
from fleetsim.slam.scan_match import add_hits, endpoint_cells
from fleetsim.slam.tiles import COUNT_CELL, FAR, TILE, CowTiles


def dense(maps, p):
    """Particle p's cells, assembled tile by tile (the reference for CowTiles.dense)."""
    out = np.empty((*maps.shape_cells, *maps.pool.shape[3:]), dtype=maps.pool.dtype)
    out[...] = maps.blank
    for ty, tx in np.argwhere(maps.table[p] >= 0):
        out[ty * TILE : (ty + 1) * TILE, tx * TILE : (tx + 1) * TILE] = maps.pool[
            maps.table[p, ty, tx]
        ]
    return out


def add(maps, poses, r, a):
    cells, hits = endpoint_cells(np.asarray(poses, float), np.zeros(3), r, a, maps.geom)
    maps.write(add_hits, cells, hits)


def test_resampled_particles_share_tiles_until_one_writes():
    maps = CowTiles(3, -5.0, -5.0, 5.0, 5.0, 0.05)
    a = np.linspace(-np.pi, np.pi, 90, endpoint=False)
    r = np.full(90, 2.0)
    add(maps, np.zeros((3, 3)), r, a)
    used = maps.tiles_in_use
    maps.resample(np.array([0, 0, 0]))
    assert maps.tiles_in_use == used // 3  # the copies hold particle 0's tiles
    before = [dense(maps, p) for p in range(3)]
    # every particle writes the same scan: the tiles it writes to are copied, once each
    poses = np.zeros((3, 3))
    add(maps, poses, r, a)
    assert maps.tiles_in_use == used
    assert np.array_equal(dense(maps, 0), dense(maps, 2))
    assert np.array_equal(dense(maps, 0)[..., 0], 2 * before[0][..., 0])
    # unshared tiles are written in place, no new tiles
    add(maps, poses, r, a)
    assert maps.tiles_in_use == used
    for p in range(3):
        assert np.array_equal(maps.dense(p), dense(maps, p))


def test_hits_keep_counts_and_mean_positions_and_survive_growth():
    maps = CowTiles(1, 0.0, 0.0, 2.0, 2.0, 0.05)
    add(maps, [[0.0, 0.0, 0.0]], np.array([1.0125, 1.0175]), np.array([0.0, 0.0]))
    cell = dense(maps, 0)[0, 20]
    assert cell[0] == 2 and abs(cell[1] - 1.015) < 1e-6 and cell[2] == 0.0
    assert tuple(dense(maps, 0)[0, 19]) == (0, np.float32(FAR), np.float32(FAR))  # never hit
    assert maps.growth_for(-1.0, 0.0, 1.0, 1.0, 10.0) == (14, 0, 0, 0)
    maps.grow(2, 1, 0, 0)
    assert tuple(maps.geom[:2]) == (-1.6, -0.8) and maps.shape_cells == (4 * TILE, 5 * TILE)
    assert dense(maps, 0)[TILE, 2 * TILE + 20][0] == 2


def test_the_pool_grows_when_a_kernel_runs_out_of_free_tiles():
    maps = CowTiles(4, -20.0, -20.0, 20.0, 20.0, 0.05)
    a = np.linspace(-np.pi, np.pi, 720, endpoint=False)
    r = np.full(720, 15.0)  # a ring of ~150 tiles per particle, 4 particles: > 64 tiles
    poses = np.array([[0.0, 0.0, 0.0], [0.3, 0.0, 0.0], [0.0, 0.3, 0.0], [0.3, 0.3, 0.0]])
    add(maps, poses, r, a)
    assert len(maps.pool) > 64 and maps.tiles_in_use > 4 * 100
    for p in range(4):
        assert dense(maps, p)[..., 0].sum() == 720


def test_count_tiles_are_uint16_pairs():
    maps = CowTiles(2, 0.0, 0.0, 1.0, 1.0, 0.05, COUNT_CELL)
    assert maps.pool.dtype == np.uint16 and maps.pool.shape[1:] == (TILE, TILE, 2)
    assert maps.dense(1).shape == (*maps.shape_cells, 2)


def test_dense_of_is_fn_of_the_dense_cells():
    """The map read tile by tile (`dense_of`) equals the function of every cell (`dense`)."""
    maps = CowTiles(2, -6.0, -6.0, 6.0, 6.0, 0.05, COUNT_CELL)
    a = np.linspace(-np.pi, np.pi, 360, endpoint=False)
    poses = np.array([[0.0, 0.0, 0.0], [1.0, 0.5, 0.3]])
    rng = np.random.default_rng(0)
    for _ in range(3):
        ranges = rng.uniform(0.5, 4.0, 360)
        maps.write(cast_counts, poses, np.zeros(3), ranges, a, 5.0, maps.geom)

    def occ(c):
        return occupancy_from_counts(c[..., 0], c[..., 1], 0.25)

    for p in range(2):
        want = occ(maps.dense(p))
        got = maps.dense_of(p, occ, np.int8)
        assert got.dtype == np.int8 and np.array_equal(got, want)
        assert (got == -1).any() and (got == 100).any() and (got == 0).any()
