"""The neighbours of ``CollvoidLocalPlanner`` as ORCA sees them: the robots on
/position_share around it, in its local costmap's frame, with their radii against it (its own
body and tracking allowance, both robots' localization spreads) and their responsibilities.

`CollvoidNeighbours` is mixed into the planner, which owns the state it reads (``params``,
``node``, ``frame``, ``share``, ``body_radius``, ``_covariance``, ``costmap_ros``). With
``use_polygon_footprint`` it also gives each pair's polygons (`_pair_polygons`) and the
robots' half widths for passing side by side (`_sides`).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from fleetsim.errors import TransformError
from fleetsim.nav.controllers.collvoid_preference import STILL_SPEED
from fleetsim.nav.costmap.footprint import footprint_at
from fleetsim.nav.multirobot.holonomic import rotated
from fleetsim.nav.multirobot.polygon_vo import disc_polygon, pair_shapes
from fleetsim.nav.multirobot.uncertainty import pair_padding, side_by_side_padding

MAP_FRAME = "map"


class CollvoidNeighbours:
    """Neighbours and radii for the collvoid planner (see the module doc)."""

    def own_radius(self, speed: float) -> float:
        """Own safety radius: body + margin + allowed tracking error, m (the localization
        spread is the pair's, `pair_padding`)."""
        p = self.params
        err = p.min_error_holo
        if not p.holonomic_robot:
            err += (p.max_error_holo - p.min_error_holo) * min(1.0, speed / p.max_vel_x)
        return self.body_radius + p.safety_margin + err

    def pair_radii(self, own_r: float, radii: np.ndarray, dist: np.ndarray) -> np.ndarray:
        """The combined radii (N,) m of this robot (``own_r`` m, `own_radius`) and each
        neighbour (``radii`` (N,) m, `neighbour_radii`; ``dist`` (N,) m away): our tracking
        allowance (``own_r`` past body and margin) no larger than the gap between the two
        (never below ``min_error_holo``).

        collvoid shrinks its allowed tracking error as the nearest robot comes close
        (``ROSAgent::addNHConstraints``, down to ``min_error_holo`` in contact). With the whole
        allowance two lizis running side by side 2-5 cm apart (the crowd of the circle of 16)
        were inside each other's velocity obstacle, and ORCA's collision branch shoved them
        apart at up to a full step's speed, out of the crowd and off their ways (2 m off the
        plan, then round a robot parked on its goal and a turn on the spot there): circle of 16,
        seeds 10-14, makespan 20.6 / 24.6 s mean / max with the whole allowance, 18.0 / 21.3 s
        with it shrunk; seeds 0-4 16.3 / 17.4 against 16.4 / 17.7 s. The allowance is for where
        the base may stray from the holonomic velocity; a command's motion along the heading
        is held to the same half-planes (`speed_along_heading`) whatever the allowance."""
        base = self.body_radius + self.params.safety_margin
        gap = dist - base - radii
        return self.bodies_radii(radii) + np.minimum(
            own_r - base, np.maximum(self.params.min_error_holo, gap)
        )

    def bodies_radii(self, radii: np.ndarray) -> np.ndarray:
        """The combined radii (N,) m of this robot's body and margin and each neighbour's
        (``radii`` (N,) m): `pair_radii` without the tracking allowance, what two robots'
        bodies must not come inside (`fleetsim.nav.multirobot.orca.contact_halfplanes`)."""
        return self.body_radius + self.params.safety_margin + radii

    def neighbour_radii(
        self, own_r: float, map_xy: np.ndarray, near: Any, map_vel: Any = (0.0, 0.0)
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The others' radii (N,) m against this robot (``own_r`` m, at ``map_xy``, moving at
        ``map_vel`` m/s): for ORCA, each one's body grown by both robots' localization spreads
        across the leg of the pair's velocity obstacle the relative velocity passes
        (`pair_padding`); for the width of a passage, by half the
        spreads across the line between the two (`side_by_side_padding`: the spreads part the
        two robots, not a robot from its walls, which it sees itself); for the room beside it
        (the way round a robot standing in the way, `_around_still`), as the passage's but a
        robot standing still that shares its spread by its body's extent across that line, not
        its disc. The radius as sent for a robot that shares no covariance; with no spread
        anywhere (fake_localization) the radii as sent, exactly, all three."""
        covs = near.covariances
        self.near_spreads = {}  # robot id -> the pair's spread padding (`pair_padding`), m
        if self._covariance is None and not covs.any():
            return near.radii, near.radii, near.radii
        shared = covs.reshape(-1, 4).any(axis=1)
        body = np.where(shared, near.body_radii, near.radii)
        rel, cap, eps = near.positions - map_xy, 2.0 * self.body_radius, self.params.eps
        vrel = np.asarray(map_vel, dtype=np.float64) - near.velocities
        pad = pair_padding(rel, own_r + body, self._covariance, cap, covs, 2.0 * body, eps, vrel)
        self.near_spreads = dict(zip(near.ids, pad.tolist(), strict=True))
        orca = body + pad
        # a robot standing still that shares its spread: by its body's outline, not its disc
        # (the lizis' corridor of 4 with amcl, seeds 1-8: 2 robots 20 s without progress, 7
        # with the disc; parked robots only, no goal left: 7). Their disc rows above are
        # computed and dropped: leaving them out of the batch changes the others' last bits
        # (the bisection's einsum), and with them the measured runs
        still = np.hypot(near.velocities[:, 0], near.velocities[:, 1]) < STILL_SPEED
        k = np.flatnonzero(shared & still)
        across = side_by_side_padding(rel, self._covariance, cap, covs, 2.0 * body, eps)
        wide = body + 0.5 * across
        room = wide.copy()
        if k.size:
            shapes = [near.robots[i].body_in_map() for i in k]
            most = max(len(o) for o in shapes)  # other robots' footprints: repeat a corner
            outlines = np.stack(
                [np.concatenate([o, o[-1:].repeat(most - len(o), 0)]) for o in shapes]
            )
            orca[k] = pair_padding(
                rel[k], np.full(k.size, own_r), self._covariance, cap, covs[k],
                2.0 * body[k], eps, vrel[k], bodies=outlines,
            )  # fmt: skip
            # the room beside it: its body's extent across the line between the two (a lizi
            # parked along a corridor is 0.16 m from its centre to its side, its disc 0.25 m)
            d = np.maximum(np.hypot(rel[k, 0], rel[k, 1]), 1e-12)
            perp = np.stack((-rel[k, 1] / d, rel[k, 0] / d), axis=1)
            extent = np.abs(np.einsum("nkd,nd->nk", outlines, perp)).max(axis=1)
            room[k] = extent + 0.5 * across[k]
        return orca, wide, room

    def _map_to_local(self) -> tuple[float, float, float]:
        if self.frame == MAP_FRAME:
            return 0.0, 0.0, 0.0
        return self.node.tf_buffer.lookup_pose2d(self.frame, MAP_FRAME, 0.0)

    def _neighbours(self, xy: np.ndarray, own_r: float, vel: np.ndarray) -> tuple:
        """The robots around ``xy`` (m, local costmap frame) on /position_share, in that frame:
        (own position in map (2,), ids, positions (N, 2), velocities (N, 2), radii (N,) against
        this robot of radius ``own_r`` moving at ``vel`` (`neighbour_radii`), ORCA
        responsibilities (N,): all of it for a robot not ``controlled`` or standing still, half
        otherwise; controlled (N,) bool, yaws (N,), radii (N,) for the width of a passage and
        for the room beside each, `neighbour_radii`).
        None around without tf."""
        p, now = self.params, self.node.now()
        ids: list[str] = []
        pos, nvel, radii = np.zeros((0, 2)), np.zeros((0, 2)), np.zeros(0)
        resp, controlled, yaws = np.zeros(0), np.zeros(0, dtype=bool), np.zeros(0)
        try:
            tx, ty, tyaw = self._map_to_local()
        except TransformError:
            self.near_robots = []
            self.near_by_id = {}
            return xy, ids, pos, nvel, radii, resp, controlled, yaws, radii, radii
        map_xy = rotated(xy - [tx, ty], -tyaw)
        near = self.share.table.near(
            now, (map_xy[0], map_xy[1]), p.neighbor_dist, p.max_neighbors, self.robot_id
        )
        cr, sr = math.cos(tyaw), math.sin(tyaw)
        rot = np.array([[cr, -sr], [sr, cr]])
        pos = near.positions @ rot.T + [tx, ty]
        nvel = near.velocities @ rot.T
        still = np.hypot(nvel[:, 0], nvel[:, 1]) < STILL_SPEED
        resp = np.where(~near.controlled | still, 1.0, 0.5)
        yaws = np.array([r.yaw for r in near.robots]) + tyaw
        radii, wide, room = self.neighbour_radii(own_r, map_xy, near, rotated(vel, -tyaw))
        self.near_robots = near.robots  # their outlines when parked (`_near_outline`)
        self.near_by_id = dict(zip(near.ids, near.robots, strict=True))
        return map_xy, near.ids, pos, nvel, radii, resp, near.controlled, yaws, wide, room

    def _sides(self, own_r, ids, wide) -> tuple[np.ndarray, np.ndarray]:
        """Our half width and each neighbour's, m, for passing side by side ((N,) each, ours
        the same against every neighbour): ``own_r`` and ``wide`` (N,) m as they are (discs),
        or with ``use_polygon_footprint`` each less its circumscribed radius and plus its
        body's half width across its own axis (what it keeps of margins, allowance and
        spread): two jackals meeting head-on (0.54 m wide padded, discs of 0.41 m) fit a 1.6 m
        corridor side by side, their discs do not.

        Across its own axis, as a differential drive passes another driving along it. Not
        across the line between the two: two robots about to pass stand slanted to each
        other, and a rectangle's extent across that line grows towards its disc (measured,
        the jackals with amcl, seeds 1-5: corridor of 4 12/20 goals and 2 wall contacts
        against 19/20 and 0; corridor of 2 27.6 s against 21.5 s)."""
        n = len(ids)
        if not self.params.use_polygon_footprint:
            return np.full(n, float(own_r)), np.asarray(wide, dtype=np.float64)
        own = own_r
        if self.params.footprint_radius <= 0.0:
            fp = np.asarray(self.costmap_ros.footprint, dtype=np.float64)
            own = own_r - self.body_radius + float(np.abs(fp[:, 1]).max())
        side = np.empty(n)
        for k, rid in enumerate(ids):
            body = self.near_by_id[rid].body
            circumscribed = float(np.hypot(body[:, 0], body[:, 1]).max())
            side[k] = wide[k] - circumscribed + float(np.abs(body[:, 1]).max())
        return np.full(n, own), side

    def _pair_polygons(self, yaw, rel, ids, yaws, pair, hard) -> tuple | None:
        """With ``use_polygon_footprint``: each pair's shapes for ORCA and for contact, as
        (shapes (2, N, M, 2), sizes (2, N)) (`fleetsim.nav.multirobot.polygon_vo.pair_shapes`,
        local costmap frame): our footprint
        at our ``yaw`` and each neighbour's at its heading (its body: its footprint as sent
        when it shares no covariance, padded by its spread), grown by what the pair's
        disc radii (``pair``, ``hard`` (N,) m) hold beyond the two circumscribed discs: the
        safety margin, the tracking allowance and the localization spreads. Else None.

        The spread is the pair's padding for discs (`pair_padding` without the bodies: both
        spreads across the leg of the discs' velocity obstacle), grown round the polygon
        alike, also for a robot standing still whose disc radius came from its outline."""
        p = self.params
        if not p.use_polygon_footprint:
            return None
        own = self._own_polygon(yaw)
        others = [
            footprint_at(self.near_by_id[r].body, 0.0, 0.0, float(y))
            for r, y in zip(ids, yaws, strict=True)
        ]
        spreads = np.array([self.near_spreads.get(r, 0.0) for r in ids])
        hard_pads = p.safety_margin + spreads
        pads = hard_pads + (np.asarray(pair) - np.asarray(hard))
        return pair_shapes(rel, own, others, np.stack((pads, hard_pads)))

    def _own_polygon(self, yaw: float) -> np.ndarray:
        """Our footprint at ``yaw`` about our centre, (K, 2) m (with ``footprint_radius`` set,
        a polygon holding that disc, `disc_polygon`)."""
        if self.params.footprint_radius > 0.0:
            return disc_polygon(self.params.footprint_radius)
        return footprint_at(self.costmap_ros.footprint, 0.0, 0.0, yaw)
