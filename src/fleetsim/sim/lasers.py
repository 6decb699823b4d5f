"""All planar lasers of the world in one batched ray cast.

Static world: in a map world the extruded walls are the occupied cells themselves, so each laser
sweeps the wall boxes near it (``occupancy_cast.ranges_from_walls``); every other static geom is
sliced into primitives binned once per compile (``raycast.ranges_from_primitives``). A static
mesh decomposed into convex parts (a building) is seen through its true triangles (the
``RAY_GROUP`` copy), not through its parts (``HULL_GROUP``), which the slicer would reduce to
bounding boxes. Movable
models (robots, loose objects) are sliced at every sweep and tested only by the beams that fall
inside their bounding circle (``raycast.ranges_with_bodies``), skipping the robot that carries
the laser.
"""

from __future__ import annotations

import zlib
from dataclasses import dataclass
from functools import partial

import mujoco
import numba
import numpy as np

from fleetsim.sim import occupancy_cast, raycast
from fleetsim.sim.mesh_assets import HULL_GROUP, RAY_GROUP
from fleetsim.sim.slices import primitives_of, triangle_primitives

STATIC_CELL = 0.5  # m


@dataclass
class _Layout:
    """Constants of one set of lasers (kept in ``Engine.layouts`` until the next compile)."""

    body: np.ndarray  # (L,) int64 link body ids
    pos: np.ndarray  # (L, 3) sensor origins in their links
    xaxis: np.ndarray  # (L, 3) sensor x axes in their links
    zaxis: np.ndarray  # (L, 3) sensor z axes in their links
    angle_min: np.ndarray  # (L,)
    inc: np.ndarray  # (L,)
    nb: np.ndarray  # (L,) int64
    offsets: np.ndarray  # (L,) int64
    owner: np.ndarray  # (L,) int64
    rmin: np.ndarray  # (L,)
    rmax: np.ndarray  # (L,)
    noisy: np.ndarray  # (R,) bool, beams of lasers with noise
    mean: np.ndarray  # (R,) noise mean of each beam, m
    std: np.ndarray  # (R,) noise stddev of each beam, m
    beam_rmin: np.ndarray  # (R,)
    beam_rmax: np.ndarray  # (R,)
    uid: np.ndarray  # (L,) uint64 each laser's noise stream (its namespace, topic and frame)

    @classmethod
    def of(cls, lasers: list) -> _Layout:
        nb = np.array([lz.samples for lz in lasers], np.int64)
        noisy = np.array([lz.noise_std > 0 or lz.noise_mean != 0 for lz in lasers])
        rmin = np.array([lz.range_min for lz in lasers])
        rmax = np.array([lz.range_max for lz in lasers])
        return cls(
            body=np.array([lz.body for lz in lasers], np.int64),
            pos=np.array([lz.pos for lz in lasers], float).reshape(-1, 3),
            xaxis=np.array([lz.xaxis for lz in lasers], float).reshape(-1, 3),
            zaxis=np.array([lz.zaxis for lz in lasers], float).reshape(-1, 3),
            angle_min=np.array([lz.angle_min for lz in lasers]),
            inc=np.array([lz.increment for lz in lasers]),
            nb=nb,
            offsets=np.concatenate([[0], np.cumsum(nb)[:-1]]).astype(np.int64),
            owner=np.array([lz.owner for lz in lasers], np.int64),
            rmin=rmin,
            rmax=rmax,
            noisy=np.repeat(noisy, nb),
            mean=np.repeat([lz.noise_mean for lz in lasers], nb),
            std=np.repeat([lz.noise_std for lz in lasers], nb),
            beam_rmin=np.repeat(rmin, nb),
            beam_rmax=np.repeat(rmax, nb),
            uid=np.array([_uid(lz) for lz in lasers], np.uint64),
        )


def _uid(laser) -> int:
    """A laser's noise stream: stable across runs and respawns, unlike ``id``."""
    name = f"{laser.ctx.namespace}|{laser.params.topicName}|{laser.frame_id}"
    return zlib.crc32(name.encode())


class LaserBatch:
    def __init__(self, noise_key: int = 0) -> None:
        self.noise_key = noise_key  # the world's laser noise, drawn once from its generator
        self.static_grid: raycast.PrimitiveGrid | None = None
        self.dynamic_ids = np.zeros(0, np.int64)
        self.occupancy = None
        self.walls: occupancy_cast.WallTiles | None = None
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
                self.walls = occupancy_cast.wall_tiles(grid.occupied)
            self.occupancy = grid
            self.wall_height = engine.wall_height
        sid = np.flatnonzero(collide & real & static & (m.geom_group != HULL_GROUP))
        self.dynamic_ids = np.flatnonzero(collide & real & (m.body_weldid[m.geom_bodyid] != 0))
        # the movable geoms in model order (geom order within a model), so that their
        # primitives come out grouped by model (a geom's count of primitives varies with its
        # pose: an upright cylinder is one circle, a tipped one a rectangle's four sides)
        owner = engine.geom_model[self.dynamic_ids]
        self._grouped_ids = self.dynamic_ids[np.argsort(owner, kind="stable")]
        prims, _ = primitives_of(m, engine.data, sid)
        rays = np.flatnonzero(static & (m.geom_group == RAY_GROUP))
        tris = triangle_primitives(m, engine.data, rays)
        if len(tris):
            prims = np.vstack([np.pad(prims, ((0, 0), (0, tris.shape[1] - prims.shape[1]))), tris])
        self.static_grid = raycast.grid_from_primitives(prims, None, STATIC_CELL)

    def bodies(self, engine):
        """Movable primitives grouped by model: centres (B, 2), radii (B,), owners (B,),
        CSR starts (B + 1,) and primitives (P, 7) sorted by owner."""
        prims, geoms = primitives_of(engine.model, engine.data, self._grouped_ids)
        owner = engine.geom_model[geoms].astype(np.int64)
        centres, radii, ids, start = bounding_circles(prims, owner)
        return centres, radii, ids, start, np.ascontiguousarray(prims)

    def measure(self, engine, lasers: list, t: float) -> list:
        """Readings of ``lasers`` (``LaserPlugin``) at the current state, cast when read.

        The sensors' poses and the movable bodies are taken now; each laser's beams are cast
        the first time its ``ranges`` are read (``Sweep.ranges_of``), then kept. A reading no
        one reads is never cast: a costmap that updates at 5 Hz reads one scan in eight of a
        40 Hz laser and drops the rest unread. Noise is keyed by the laser, its scan count and
        the beam (``scan_noise``), so a scan's ranges do not depend on which scans were
        read or in what order."""
        key = ("laser", *map(id, lasers))
        lay = engine.layouts.get(key)
        if lay is None:
            lay = engine.layouts[key] = _Layout.of(lasers)
        n = len(lasers)
        R = engine.data.xmat[lay.body].reshape(n, 3, 3)
        origins = engine.data.xpos[lay.body] + np.einsum("nij,nj->ni", R, lay.pos)
        xaxis = np.einsum("nij,nj->ni", R, lay.xaxis)  # sensor x, world
        # a laser mounted upside down sweeps its beams clockwise seen from above
        sign = np.where(np.einsum("nj,nj->n", R[:, 2, :], lay.zaxis) < 0, -1.0, 1.0)
        angle0 = np.arctan2(xaxis[:, 1], xaxis[:, 0]) + sign * lay.angle_min
        inc = sign * lay.inc
        scans = np.empty(n, np.int64)
        for k, lz in enumerate(lasers):
            scans[k] = lz.scans_taken
            lz.scans_taken += 1
        sweep = Sweep(
            self, lay, origins, angle0, inc, scans,
            self.bodies(engine) if len(self.dynamic_ids) else None,
        )  # fmt: skip
        return [lz.reading(partial(sweep.ranges_of, k), t) for k, lz in enumerate(lasers)]


_ZERO = np.zeros(1, np.int64)


class Sweep:
    """One batch of laser readings, taken at one instant and cast laser by laser when read.

    Holds what the cast needs from that instant (origins, first-beam yaws, increments, the
    movable bodies' primitives) and the world's static parts as they were bound then."""

    def __init__(self, batch: LaserBatch, lay: _Layout, origins, angle0, inc, scans, bodies):
        self.static_grid = batch.static_grid
        self.occupancy, self.walls, self.wall_height = (
            batch.occupancy,
            batch.walls,
            batch.wall_height,
        )
        self.noise_key = batch.noise_key
        self.lay, self.origins, self.angle0, self.inc = lay, origins, angle0, inc
        self.scans, self.bodies = scans, bodies

    def ranges_of(self, k: int) -> np.ndarray:
        """Laser ``k``'s ranges ((samples,) float32 m, noise applied), cast now."""
        lay = self.lay
        o, nb = int(lay.offsets[k]), int(lay.nb[k])
        beams = slice(o, o + nb)
        one = slice(k, k + 1)
        ranges = np.full(nb, np.inf)
        if len(self.static_grid.prims):
            ranges = raycast.cast(
                self.static_grid,
                np.repeat(self.origins[one], nb, axis=0),
                self.angle0[k] + np.arange(nb) * self.inc[k],
                lay.beam_rmin[beams],
                lay.beam_rmax[beams],
                lay.owner[k],
            )
        if self.occupancy is not None:
            g, wt = self.occupancy, self.walls
            occupancy_cast.ranges_from_walls(
                self.origins[one], self.angle0[one], self.inc[one], lay.nb[one], _ZERO,
                lay.rmin[one], lay.rmax[one], wt.occupied, wt.boxes, wt.start, wt.items, wt.tile,
                wt.th, wt.tw, g.origin[0], g.origin[1], g.resolution, self.wall_height, ranges,
            )  # fmt: skip
        if self.bodies is not None:
            raycast.ranges_with_bodies(
                ranges, self.origins[one], self.angle0[one], self.inc[one], lay.nb[one], _ZERO,
                lay.owner[one], lay.rmin[one], lay.rmax[one], *self.bodies,
            )  # fmt: skip
        out = np.empty(nb, np.float32)
        if not lay.noisy[o]:
            out[:] = ranges
            return out
        z = scan_noise(self.noise_key, int(lay.uid[k]), int(self.scans[k]), nb)
        noisy_ranges(
            ranges, lay.noisy[beams], lay.mean[beams], lay.std[beams], lay.beam_rmin[beams],
            lay.beam_rmax[beams], z, out,
        )  # fmt: skip
        return out


_M1, _M2 = np.uint64(0xBF58476D1CE4E5B9), np.uint64(0x94D049BB133111EB)
_GOLDEN = np.uint64(0x9E3779B97F4A7C15)
_S30, _S27, _S31, _S11 = np.uint64(30), np.uint64(27), np.uint64(31), np.uint64(11)


@numba.njit(cache=True)
def _mix64(x):
    """SplitMix64's finaliser: a bijective 64-bit hash whose output bits pass BigCrush."""
    x = (x ^ (x >> _S30)) * _M1
    x = (x ^ (x >> _S27)) * _M2
    return x ^ (x >> _S31)


@numba.njit(cache=True)
def scan_noise(noise_key, uid, scan, n):
    """``n`` standard normal draws for scan number ``scan`` of laser ``uid``, one per beam.

    Counter-based: draw ``i`` is a function of (key, laser, scan, i) alone (SplitMix64 over
    the counter, then Box-Muller), so a scan's noise is the same whichever scans were read
    before it, or whether they were read at all. Written here rather than with NumPy's
    counter-based ``Philox``: a Philox generator keyed per scan costs ~30 us to set up and
    draw 720 normals, as much as casting the scan; this is a third of it.

    Parameters
    ----------
    noise_key, uid, scan : int, the world's noise key, the laser's id and its scan number.
    n : int, draws (beams).
    """
    base = _mix64(np.uint64(noise_key) ^ _mix64(np.uint64(uid) ^ _mix64(np.uint64(scan))))
    z = np.empty(n)
    for i in range(n):
        c = base + np.uint64(2 * i) * _GOLDEN
        u1 = (float(_mix64(c) >> _S11) + 0.5) * 2.0**-53  # (0, 1)
        u2 = float(_mix64(c + _GOLDEN) >> _S11) * 2.0**-53  # [0, 1)
        z[i] = np.sqrt(-2.0 * np.log(u1)) * np.cos(2.0 * np.pi * u2)
    return z


@numba.njit(cache=True)
def noisy_ranges(ranges, noisy, mean, std, rmin, rmax, z, out):
    """Ranges with Gaussian noise on the beams that hit, as float32, into ``out``.

    Beam ``i`` of a noisy laser that hits gets ``(range + mean) + std z[i]`` clipped to its
    laser's ``[rmin, rmax]``, in float64 and in that order, then rounded to float32: bit for
    bit what ``np.clip(r[hit] + mean[hit] + std[hit] * z[hit], rmin[hit],
    rmax[hit]).astype(np.float32)`` gives, in one pass instead of seven array operations.

    Parameters
    ----------
    ranges : (R,) float64 m, inf where nothing is hit; noisy : (R,) bool.
    mean, std, rmin, rmax : (R,) float64 m, per beam (its laser's).
    z : (R,) float64 standard normal draws, one per beam (those that miss are unused).
    out : (R,) float32 m.
    """
    for i in range(ranges.shape[0]):
        r = ranges[i]
        if noisy[i] and np.isfinite(r):
            v = (r + mean[i]) + std[i] * z[i]
            out[i] = min(max(v, rmin[i]), rmax[i])
        else:
            out[i] = r


@numba.njit(cache=True)
def bounding_circles(prims, owner):
    """Groups of consecutive primitives with the same owner, and the circle around each
    group's bounding box (of their x, y extent).

    Compiled: done at every laser sweep for every robot, and the NumPy version (a sort,
    ``unique``, masks, ``reduceat``, a norm) cost ~150 us for ten robots in array overhead.

    Parameters
    ----------
    prims : (P, 7+) ``raycast`` primitives; a segment spans its two end points (columns 1-4),
        any other kind its centre (1, 2) plus and minus its radius (3), m.
    owner : (P,) int64 each primitive's model, equal ones consecutive.

    Returns
    -------
    centres : (B, 2) m, the boxes' centres; radii : (B,) m, their half diagonals;
    ids : (B,) int64 the groups' owners; start : (B + 1,) int64 CSR starts into ``prims``.
    """
    n = prims.shape[0]
    nb = 0
    for i in range(n):
        if i == 0 or owner[i] != owner[i - 1]:
            nb += 1
    start = np.empty(nb + 1, np.int64)
    ids = np.empty(nb, np.int64)
    b = 0
    for i in range(n):
        if i == 0 or owner[i] != owner[i - 1]:
            start[b] = i
            ids[b] = owner[i]
            b += 1
    start[nb] = n
    centres = np.empty((nb, 2))
    radii = np.empty(nb)
    for b in range(nb):
        lx = np.inf
        ly = np.inf
        hx = -np.inf
        hy = -np.inf
        for i in range(start[b], start[b + 1]):
            if prims[i, 0] == raycast.SEGMENT:
                x0 = min(prims[i, 1], prims[i, 3])
                y0 = min(prims[i, 2], prims[i, 4])
                x1 = max(prims[i, 1], prims[i, 3])
                y1 = max(prims[i, 2], prims[i, 4])
            else:
                x0 = prims[i, 1] - prims[i, 3]
                y0 = prims[i, 2] - prims[i, 3]
                x1 = prims[i, 1] + prims[i, 3]
                y1 = prims[i, 2] + prims[i, 3]
            lx = min(lx, x0)
            ly = min(ly, y0)
            hx = max(hx, x1)
            hy = max(hy, y1)
        centres[b, 0] = (lx + hx) / 2
        centres[b, 1] = (ly + hy) / 2
        dx = hx - lx
        dy = hy - ly
        radii[b] = np.sqrt(dx * dx + dy * dy) / 2
    return centres, radii, ids, start
