"""The half-planes of ``CollvoidLocalPlanner``'s cycle and their linear program: the local
costmap without the other robots' images (`CollvoidHalfplanes._walls`), ORCA half-planes of
its walls (`_wall_halfplanes`: the circumscribed disc, or the inscribed one where the walls
leave that disc no way on) and of the robots (discs, or with ``use_polygon_footprint`` the
pairs' polygons), the contact half-planes of robots already touching, and the velocity nearest
the preferred one that they admit (`_orca`).

`CollvoidHalfplanes` is mixed into the planner, which owns the state it reads (``params``,
``costmap``, ``grid``, ``body_radius``, ``wall_radius``, ``horizon``, ``horizon_obst``,
``overlap_t``, ``dt``) and keeps what it sets (``lines``, ``contact_lines``, ``feasible``,
``last_holo``, ``walls_blocked``).
"""

from __future__ import annotations

import numpy as np

from fleetsim.nav.costmap.costmap_2d import LETHAL_OBSTACLE
from fleetsim.nav.costmap.footprint import polygon_cells
from fleetsim.nav.multirobot.holonomic import obstacle_points, without_robots
from fleetsim.nav.multirobot.orca import (
    contact_halfplanes_along,
    disc_gaps,
    orca_halfplanes,
    orca_velocity,
)
from fleetsim.nav.multirobot.polygon_vo import polygon_orca_halfplanes, shape_gaps

#: bearing sectors for static obstacle points
OBSTACLE_SECTORS = 24
#: share of the preferred speed under which the walls block the circumscribed disc (then the
#: inscribed disc steers and the footprint keeps off the walls, `_wall_halfplanes`)
WALLS_BLOCK = 0.25
#: s; how old another robot's image in the local costmap can be against its shared pose (a
#: 5 Hz costmap update and a 10 Hz /position_share message), and the most it moves meanwhile, m
SEEN_LAG, SEEN_LAG_MAX = 0.3, 0.2


class CollvoidHalfplanes:
    """The half-planes and the linear program of the planner's cycle (see the module doc)."""

    def _walls(self, pos, nvel, wide, bodies=()) -> tuple[np.ndarray, tuple[float, float], float]:
        """The local costmap as (costs, origin, resolution) without the other robots' images
        (`without_robots`): each neighbour at ``pos`` (N, 2) m moving at ``nvel`` (N, 2) m/s,
        its body ``wide`` (N,) m grown by how far it moves in ``SEEN_LAG`` (at most
        ``SEEN_LAG_MAX``) and two cells; with the parked robots' shapes ``bodies`` (polygons,
        costmap frame, `CollvoidParked._parked_shape`) drawn in as LETHAL (a laser sees a
        robot's body and not always its wheels). What this cycle's wall half-planes,
        footprint check, passage widths and refuge read."""
        cm = self.costmap
        origin, res = (cm.origin_x, cm.origin_y), cm.resolution
        costs = cm.costs
        if pos.shape[0]:
            lag = np.minimum(SEEN_LAG * np.hypot(nvel[:, 0], nvel[:, 1]), SEEN_LAG_MAX)
            costs = without_robots(costs, origin, res, pos, wide + lag + 2.0 * res)
        for body in bodies:
            if costs is cm.costs:
                costs = costs.copy()
            rows, cols = polygon_cells(cm, body)
            costs[rows, cols] = LETHAL_OBSTACLE
        return costs, origin, res

    def _orca(self, xy, vel, pref, rel, nvel, radii, resp, hard, shapes=None) -> np.ndarray:
        """The velocity nearest ``pref`` (2,) m/s that the half-planes of the local costmap's
        walls and of the robots (``rel`` (N, 2) m, ``nvel`` (N, 2) m/s, combined ``radii`` (N,)
        m, responsibilities ``resp`` (N,); ``hard`` (N,) m the combined radii of the bodies'
        discs, which robots whose ``radii`` overlap close in on no faster than in
        ``overlap_time``) admit; the half-planes are kept in ``lines``. ``shapes``: the pairs'
        polygons (`_pair_polygons`) standing for ``radii`` and ``hard``, or None."""
        p = self.params
        lines_p, lines_d = [], []
        self.contact_lines = (np.zeros((0, 2)), np.zeros((0, 2)))
        obst = obstacle_points(
            *self.grid,
            xy,
            self.body_radius + p.max_vel_x * self.horizon_obst + 0.3,
            OBSTACLE_SECTORS,
        )
        if obst.shape[0]:
            lp, ld = self._wall_halfplanes(obst - xy, vel, pref)
            lines_p.append(lp)
            lines_d.append(ld)
        if rel.shape[0]:
            if shapes is None:
                lp, ld = orca_halfplanes(
                    rel, vel - nvel, radii, vel, self.horizon, self.overlap_t, resp
                )
                touch = np.einsum("ij,ij->i", rel, rel) <= radii * radii
                normals, gaps = disc_gaps(rel, hard)
            else:
                (shape, body), (size, body_size) = shapes
                lp, ld, touch = polygon_orca_halfplanes(
                    shape, size, vel - nvel, vel, self.horizon, self.overlap_t, resp
                )
                normals, gaps = shape_gaps(body, body_size)
            lines_p.append(lp)
            lines_d.append(ld)
            if touch.any():  # parted over overlap_t, never into each other (contact_halfplanes)
                lp, ld = contact_halfplanes_along(
                    normals[touch], gaps[touch], (vel - nvel)[touch], vel, self.overlap_t,
                    resp[touch],
                )  # fmt: skip
                lines_p.append(lp)
                lines_d.append(ld)
                # the drive's last resort: the bodies already overlapping
                deep = gaps[touch] < 0.0
                self.contact_lines = (lp[deep], ld[deep])
        self.lines = (
            np.concatenate(lines_p) if lines_p else np.zeros((0, 2)),
            np.concatenate(lines_d) if lines_d else np.zeros((0, 2)),
            obst.shape[0],
        )
        if not lines_p:
            self.feasible = True
            self.last_holo = pref
            return pref
        holo, self.feasible = orca_velocity(
            self.lines[0], self.lines[1], p.max_vel_x, pref, obst.shape[0]
        )
        self.last_holo = holo
        return holo

    def _wall_halfplanes(self, rel, vel, pref) -> tuple[np.ndarray, np.ndarray]:
        """ORCA half-planes of the static obstacle points ``rel`` (M, 2), m from the robot.

        The robot is its circumscribed disc (``body_radius``) unless the walls leave that disc
        no way on (their program infeasible, its velocity under `WALLS_BLOCK` of the
        preferred speed, or turned back from it): then, for a differential drive, its inscribed
        disc, and the real footprint's rollout (`_footprint_clear`) keeps it off the walls. A
        lizi's disc (0.25 m) does not pass a 0.45 m gap between clutter that its body (0.32 m
        wide) drives through; in open corridors the disc keeps its distance from walls as
        before, so two lizis meeting in a corridor still find it too narrow to pass."""
        cell_r = self.costmap.resolution * 0.71
        n, p = rel.shape[0], self.params
        lines = orca_halfplanes(
            rel, np.broadcast_to(vel, rel.shape), np.full(n, self.body_radius + cell_r),
            vel, self.horizon_obst, self.dt, 1.0,
        )  # fmt: skip
        self.walls_blocked = False
        if self.wall_radius >= self.body_radius:
            return lines
        v, ok = orca_velocity(*lines, p.max_vel_x, pref, n)
        # a velocity the disc's program turns back (away from a gap the body fits through) is
        # no way on either, however fast (a jackal flipped between the two discs beside a
        # parked one at the corridor's end, 1.5 m from its goal, for 90 s)
        fast = float(np.hypot(*v)) >= WALLS_BLOCK * float(np.hypot(*pref))
        if ok and fast and float(v @ pref) >= 0.0:
            return lines
        self.walls_blocked = True
        return orca_halfplanes(
            rel, np.broadcast_to(vel, rel.shape), np.full(n, self.wall_radius + cell_r),
            vel, self.horizon_obst, self.dt, 1.0,
        )  # fmt: skip
