"""Tests for fleetsim.slam.tiles: copy-on-write tiles shared by resampled particles."""

import numpy as np

from fleetsim.slam.scan_match import endpoint_cells
from fleetsim.slam.tiles import TILE, TiledHitMaps


def dense(maps, p):
    out = np.zeros((*maps.shape_cells, 3), dtype=np.float32)
    for ty, tx in np.argwhere(maps.table[p] >= 0):
        out[ty * TILE : (ty + 1) * TILE, tx * TILE : (tx + 1) * TILE] = maps.pool[
            maps.table[p, ty, tx]
        ]
    return out


def add(maps, poses, r, a):
    cells, hits = endpoint_cells(np.asarray(poses, float), np.zeros(3), r, a, maps.geom)
    maps.add_scan(cells, hits)


def test_resampled_particles_share_tiles_until_one_writes():
    maps = TiledHitMaps(3, -5.0, -5.0, 5.0, 5.0, 0.05)
    a = np.linspace(-np.pi, np.pi, 90, endpoint=False)
    r = np.full(90, 2.0)
    add(maps, np.zeros((3, 3)), r, a)
    used = maps.tiles_in_use
    maps.resample(np.array([0, 0, 0]))
    assert maps.tiles_in_use == used // 3  # the copies hold particle 0's tiles
    before = [dense(maps, p) for p in range(3)]
    # particle 1 alone sees a new wall: only the tiles it writes to are copied
    poses = np.zeros((3, 3))
    add(maps, poses, r, a)
    assert np.array_equal(dense(maps, 0), dense(maps, 2))
    assert np.array_equal(dense(maps, 0)[..., 0], 2 * before[0][..., 0])
    # unshared tiles are written in place, no new tiles
    n = maps.tiles_in_use
    add(maps, poses, r, a)
    assert maps.tiles_in_use == n


def test_hits_accumulate_counts_and_offsets_and_survive_growth():
    maps = TiledHitMaps(1, 0.0, 0.0, 2.0, 2.0, 0.05)
    add(maps, [[0.0, 0.0, 0.0]], np.array([1.0125, 1.0175]), np.array([0.0, 0.0]))
    cell = dense(maps, 0)[0, 20]
    assert cell[0] == 2 and cell[1] == np.float32(0.0125 + 0.0175) and cell[2] == 0.0
    assert maps.growth_for(-1.0, 0.0, 1.0, 1.0, 10.0) == (14, 0, 0, 0)
    maps.grow(2, 1, 0, 0)
    assert tuple(maps.geom[:2]) == (-1.6, -0.8) and maps.shape_cells == (4 * TILE, 5 * TILE)
    assert dense(maps, 0)[TILE, 2 * TILE + 20][0] == 2
