"""Occupancy-grid ray casting checked against casting on the map's extruded wall boxes."""

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from fleetsim.sim import occupancy_cast, raycast


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 10_000))
def test_occupancy_cast_matches_its_extruded_boxes(seed):
    """Walking the grid (with clearance jumps) equals casting on the merged wall boxes."""
    from fleetsim.sim.mapworld import OccupancyMap, wall_boxes

    rng = np.random.default_rng(seed)
    occ = rng.random((40, 50)) < 0.04
    occ[10, 5:45] = True  # a long wall
    grid = OccupancyMap(occ, 0.1, (-1.0, 2.0, 0.0), "<test>")
    boxes = wall_boxes(grid, 1.0)
    segs = []
    for cx, cy, _, hx, hy, _, _ in boxes:
        c = [(cx - hx, cy - hy), (cx + hx, cy - hy), (cx + hx, cy + hy), (cx - hx, cy + hy)]
        segs += [[0, *c[k], *c[(k + 1) % 4], 0.0, 1.0] for k in range(4)]
    pgrid = raycast.grid_from_primitives(np.array(segs), cell=0.5)
    n = 300
    free = np.argwhere(~occ)[rng.integers(0, (~occ).sum(), n)]
    origins = np.c_[
        -1.0 + (free[:, 1] + rng.random(n)) * 0.1,
        2.0 + (free[:, 0] + rng.random(n)) * 0.1,
        np.full(n, 0.3),
    ]
    angles = rng.uniform(-np.pi, np.pi, n)
    rmin, rmax = np.zeros(n), np.full(n, 8.0)
    got = occupancy_cast.ranges_from_occupancy(
        origins,
        angles,
        rmin,
        rmax,
        occ,
        occupancy_cast.clearance_from_occupancy(occ),
        -1.0,
        2.0,
        0.1,
        1.0,
    )
    want = raycast.cast(pgrid, origins, angles, rmin, rmax, -1)
    np.testing.assert_allclose(got, want, atol=1e-9)
