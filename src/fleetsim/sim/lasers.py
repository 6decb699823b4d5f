"""All planar lasers of the world in one batched ray cast.

The static world (geoms welded to the world) is sliced into primitives and binned once per
compile; movable geoms (robots, loose models) are sliced and binned again at every sweep (they
are few). Each ray is cast against the static grid, then against the movable grid up to the
static hit, skipping the geoms of the robot that carries the laser.
"""

from __future__ import annotations

import mujoco
import numpy as np

from fleetsim.sim import raycast
from fleetsim.sim.slices import primitives_of

STATIC_CELL = 0.5  # m
DYNAMIC_CELL = 1.0  # m


class LaserBatch:
    def __init__(self) -> None:
        self.static_grid: raycast.PrimitiveGrid | None = None
        self.dynamic_ids = np.zeros(0, np.int64)

    def bind(self, engine) -> None:
        m = engine.model
        collide = (m.geom_contype != 0) | (m.geom_conaffinity != 0)
        real = m.geom_type != mujoco.mjtGeom.mjGEOM_PLANE
        static = m.body_weldid[m.geom_bodyid] == 0
        sid = np.flatnonzero(collide & real & static)
        self.dynamic_ids = np.flatnonzero(collide & real & ~static)
        prims, _ = primitives_of(m, engine.data, sid)
        self.static_grid = raycast.grid_from_primitives(prims, None, STATIC_CELL)

    def dynamic_grid(self, engine) -> raycast.PrimitiveGrid:
        prims, geoms = primitives_of(engine.model, engine.data, self.dynamic_ids)
        return raycast.grid_from_primitives(prims, engine.geom_model[geoms], DYNAMIC_CELL)

    def ranges(self, engine, origins, angles, range_min, range_max, owner) -> np.ndarray:
        """(R,) ranges (m, inf: no hit) of rays from ``origins`` (R, 3) at world yaws ``angles``."""
        r = raycast.cast(self.static_grid, origins, angles, range_min, range_max, owner)
        if len(self.dynamic_ids):
            limit = np.minimum(r, range_max)
            r2 = raycast.cast(self.dynamic_grid(engine), origins, angles, range_min, limit, owner)
            r = np.minimum(r, r2)
        return r

    def measure(self, engine, lasers: list, t: float) -> list:
        """Readings of ``lasers`` (``LaserPlugin``) from one batched cast."""
        parts = [lz.rays(engine) for lz in lasers]
        origins = np.concatenate([p[0] for p in parts])
        angles = np.concatenate([p[1] for p in parts])
        rmin = np.concatenate([np.full(len(p[1]), lz.range_min) for p, lz in zip(parts, lasers)])
        rmax = np.concatenate([np.full(len(p[1]), lz.range_max) for p, lz in zip(parts, lasers)])
        owner = np.concatenate([np.full(len(p[1]), p[2], np.int64) for p in parts])
        ranges = self.ranges(engine, origins, angles, rmin, rmax, owner)
        out = []
        k = 0
        for p, lz in zip(parts, lasers):
            n = len(p[1])
            out.append(lz.reading(ranges[k : k + n], t, engine.rng))
            k += n
        return out
