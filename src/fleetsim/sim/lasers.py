"""All planar lasers of the world in one batched ray cast.

Static world: in a map world the extruded walls are the occupied cells themselves, so rays
walk the occupancy grid (``occupancy_cast.ranges_from_occupancy``); every other static geom is
sliced into primitives binned once per compile (``raycast.ranges_from_primitives``). Movable
models (robots, loose objects) are sliced at every sweep and tested only by the beams that fall
inside their bounding circle (``raycast.ranges_with_bodies``), skipping the robot that carries
the laser.
"""

from __future__ import annotations

import mujoco
import numpy as np

from fleetsim.sim import occupancy_cast, raycast
from fleetsim.sim.slices import primitives_of

STATIC_CELL = 0.5  # m


class LaserBatch:
    def __init__(self) -> None:
        self.static_grid: raycast.PrimitiveGrid | None = None
        self.dynamic_ids = np.zeros(0, np.int64)
        self.occupancy = None
        self.wall_height = 0.0

    def bind(self, engine) -> None:
        m = engine.model
        collide = (m.geom_contype != 0) | (m.geom_conaffinity != 0)
        real = m.geom_type != mujoco.mjtGeom.mjGEOM_PLANE
        static = m.body_weldid[m.geom_bodyid] == 0
        grid = engine.world.occupancy
        use_grid = grid is not None and grid.origin[2] == 0.0 and "map_walls" in engine.models
        if not use_grid:
            self.occupancy = None
        else:
            walls = engine._model_names.index("map_walls")
            static = static & (engine.geom_model != walls)
            if self.occupancy is not grid:
                self.clearance = occupancy_cast.clearance_from_occupancy(grid.occupied)
            self.occupancy = grid
            self.wall_height = engine.wall_height
        sid = np.flatnonzero(collide & real & static)
        self.dynamic_ids = np.flatnonzero(collide & real & (m.body_weldid[m.geom_bodyid] != 0))
        prims, _ = primitives_of(m, engine.data, sid)
        self.static_grid = raycast.grid_from_primitives(prims, None, STATIC_CELL)

    def bodies(self, engine):
        """Movable primitives grouped by model: centres (B, 2), radii (B,), owners (B,),
        CSR starts (B + 1,) and primitives (P, 7) sorted by owner."""
        prims, geoms = primitives_of(engine.model, engine.data, self.dynamic_ids)
        owner = engine.geom_model[geoms]
        order = np.argsort(owner, kind="stable")
        prims, owner = prims[order], owner[order]
        ids, start = np.unique(owner, return_index=True)
        start = np.append(start, len(owner)).astype(np.int64)
        seg = prims[:, 0] == raycast.SEGMENT
        lo = np.where(
            seg[:, None], np.minimum(prims[:, 1:3], prims[:, 3:5]), prims[:, 1:3] - prims[:, 3:4]
        )
        hi = np.where(
            seg[:, None], np.maximum(prims[:, 1:3], prims[:, 3:5]), prims[:, 1:3] + prims[:, 3:4]
        )
        lo_b = np.minimum.reduceat(lo, start[:-1], axis=0) if len(ids) else np.zeros((0, 2))
        hi_b = np.maximum.reduceat(hi, start[:-1], axis=0) if len(ids) else np.zeros((0, 2))
        centres = (lo_b + hi_b) / 2
        radii = np.linalg.norm(hi_b - lo_b, axis=1) / 2
        return centres, radii, ids.astype(np.int64), start, np.ascontiguousarray(prims)

    def measure(self, engine, lasers: list, t: float) -> list:
        """Readings of ``lasers`` (``LaserPlugin``) from one batched cast."""
        n = len(lasers)
        inc = np.array([lz.increment for lz in lasers])
        nb = np.array([lz.samples for lz in lasers], np.int64)
        owner = np.array([lz.owner for lz in lasers], np.int64)
        body = np.array([lz.body for lz in lasers], np.int64)
        R = engine.data.xmat[body].reshape(n, 3, 3)
        origins = engine.data.xpos[body] + np.einsum("nij,nj->ni", R, [lz.pos for lz in lasers])
        xaxis = np.einsum("nij,nj->ni", R, [lz.xaxis for lz in lasers])  # sensor x, world
        angle0 = np.arctan2(xaxis[:, 1], xaxis[:, 0]) + [lz.angle_min for lz in lasers]
        offsets = np.concatenate([[0], np.cumsum(nb)[:-1]]).astype(np.int64)
        rmin = np.array([lz.range_min for lz in lasers])
        rmax = np.array([lz.range_max for lz in lasers])
        beam = np.concatenate([np.arange(k) for k in nb])
        which = np.repeat(np.arange(n), nb)
        ray_o = origins[which]
        ray_a = angle0[which] + beam * inc[which]
        ray_min, ray_max, ray_owner = rmin[which], rmax[which], owner[which]
        if len(self.static_grid.prims):
            ranges = raycast.cast(self.static_grid, ray_o, ray_a, ray_min, ray_max, ray_owner)
        else:
            ranges = np.full(len(ray_a), np.inf)
        if self.occupancy is not None:
            g = self.occupancy
            walls = occupancy_cast.ranges_from_occupancy(
                ray_o,
                ray_a,
                ray_min,
                ray_max,
                g.occupied,
                self.clearance,
                g.origin[0],
                g.origin[1],
                g.resolution,
                self.wall_height,
            )
            ranges = np.minimum(ranges, walls)
        if len(self.dynamic_ids):
            centres, radii, ids, start, prims = self.bodies(engine)
            raycast.ranges_with_bodies(
                ranges,
                origins,
                angle0,
                inc,
                nb,
                offsets,
                owner,
                rmin,
                rmax,
                centres,
                radii,
                ids,
                start,
                prims,
            )
        return [
            lz.reading(ranges[o : o + k], t, engine.rng) for lz, o, k in zip(lasers, offsets, nb)
        ]
