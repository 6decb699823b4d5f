"""Robots parked around ``CollvoidLocalPlanner``, and when its global plan goes back to
move_base: which standing neighbours leave ORCA for the local costmap with their true shape
(`CollvoidParked._parked_in_view`), the robot's own progress clock (`_stuck_for`), and the two
cases in which the planner hands the plan back (`NoValidTrajectory`: move_base plans again
from where the robot stands), a plan out of the local costmap's reach (`_plan_in_reach`) and
one through a parked robot while the robot is stuck (`_plan_through_parked`).

`CollvoidParked` is mixed into the planner, which owns the state it reads (``params``,
``node``, ``costmap``, ``plan``, ``plan_index``, ``wall_radius``, ``near_robots``,
``still_since``, ``as_bodies``, ``replanned_for``, ``progress``, ``where``).
"""

from __future__ import annotations

import math

import numpy as np

from fleetsim.nav.controllers.base import NoValidTrajectory
from fleetsim.nav.controllers.collvoid_preference import STILL_SPEED
from fleetsim.nav.costmap.costmap_2d import LETHAL_OBSTACLE
from fleetsim.nav.costmap.footprint import (
    footprint_at,
    inside_polygon,
    padded_footprint,
    polygon_cells,
)

#: lethal cells inside a standing robot's body that make it seen by this robot's own sensors
SEEN_CELLS = 3
#: s a robot has stood still before it counts as parked (a robot stopping for a moment in a
#: crowd, or turning on the spot, stays in ORCA)
PARKED_TIME = 1.0
#: s before a plan through the same parked robot asks for a new plan again (a new plan that
#: still runs through it, where no other way is known, is driven as far as it goes)
REPLAN_AGAIN = 5.0
#: s without ``deadlock_progress`` towards the goal before a plan through a parked robot is
#: planned again (a robot that gets round it on its own keeps its plan: in the pioneers'
#: corridor of 4, seed 0, a new plan round pioneer3 led pioneer1 into the corridor's corner)
BLOCKED_TIME = 3.0
#: s a parked robot no sensor of ours sees counts with its outline once we are stuck
BODIES_TIME = 10.0
#: m round a parked robot's body at its shared pose within which our laser's marks show it
#: (`_parked_shape`): two cells, about amcl's error on the jackals in a corridor (7-11 cm)
SEEN_BODY_MARGIN = 0.1


class CollvoidParked:
    """Parked neighbours and handing the plan back, for the collvoid planner (see the module
    doc)."""

    def _stuck_for(self, now: float, remaining: float) -> float:
        """s since the robot last came ``deadlock_progress`` m nearer its goal (``remaining``
        m away now). The planner's own clock: the deadlock rule's restarts whenever the robot
        keeps the right of way, so it does not measure progress alone."""
        best, since = self.progress
        if remaining < best - self.params.deadlock_progress or now < since:
            self.progress = (remaining, now)
        return now - self.progress[1]

    def _parked_in_view(
        self, ids, pos, nvel, yaws, blocked=False
    ) -> tuple[np.ndarray, list[np.ndarray]]:
        """(N,) bool, and the shapes they enter the costmap with (polygons, costmap frame,
        `_parked_shape`): the neighbours ``ids`` that have stood still for ``PARKED_TIME``
        where this robot's own sensors see them (``SEEN_CELLS`` lethal cells or more under
        `_near_outline` grown by a cell, at ``pos`` (N, 2) m and ``yaws`` (N,) rad; wall
        cells under it count too).
        They are left out of ORCA and stay in the
        local costmap: the wall half-planes and the footprint check then take them with their
        true shape, as collvoid puts standing robots into the costmap (its
        ``stationary_robots``). A disc of the circumscribed radius is too wide beside them: a
        pioneer3at (0.54 x 0.50 m, a 0.37 m disc) could not pass another one parked in the
        middle of a 2 m corridor, with 0.75 m free on either side. A robot no sensor of ours
        sees (a lizi's laser sweeps above the others) stays in ORCA, unless this robot is
        ``blocked`` (no progress for ``deadlock_time`` s, the deadlock rule's patience): then
        every robot parked within ``neighbor_dist`` counts with its `_near_outline` for
        `BODIES_TIME` s (mixed circle of 16, seed 10: pioneer10 went to and fro for 80 s
        before a gap between two parked lizis that their discs closed and their bodies left
        0.85 m wide). Not sooner: in the lizis' corridor of 4, parked lizis taken by their
        footprints from the start slowed every run (24.7 -> 33.2 s mean), and a lizi 3 s into
        going round two parked lizis 0.8 m apart turned into the gap between them and stuck
        there."""
        still = np.hypot(nvel[:, 0], nvel[:, 1]) < STILL_SPEED
        now, since = self.node.now(), self.still_since
        for k in [k for k in since if k not in ids]:
            del since[k]
        for k, s in zip(ids, still.tolist()):
            if not s:
                since.pop(k, None)
            else:
                since.setdefault(k, now)
        out = np.array([s and now - since[k] >= PARKED_TIME for k, s in zip(ids, still.tolist())])
        out = out.astype(bool).reshape(len(ids))
        as_bodies = self.as_bodies
        for k in [k for k in as_bodies if now >= as_bodies[k]]:
            del as_bodies[k]
        if blocked:
            for k in np.flatnonzero(out):
                as_bodies[ids[k]] = now + BODIES_TIME
        cell, bodies = self.costmap.resolution, []
        for k in np.flatnonzero(out):
            seen = self._marked(footprint_at(self._near_outline(k, cell), *pos[k], yaws[k]))
            out[k] = seen or ids[k] in as_bodies
            if out[k]:
                bodies.append(self._parked_shape(k, pos[k], yaws[k]))
        return out, bodies

    def _parked_shape(self, k: int, xy: np.ndarray, yaw: float) -> np.ndarray:
        """The polygon (costmap frame) parked neighbour ``k``, at ``xy`` (2,) m and ``yaw``
        rad, enters the local costmap as: its body where our laser marks it (``SEEN_CELLS`` lethal
        cells or more within `SEEN_BODY_MARGIN` of its body at its shared pose), else its body
        grown by its localization spread (`_near_outline`, where it probably is). Its laser
        image stays in the costmap either way (parked robots are not cleared, `_walls`), so
        the spread is needed only where nothing shows the robot. With amcl, a jackal parked on
        its goal in the middle of the 2 m corridor, drawn grown by its spread, left the jackal
        bound past it no room between it and the wall, and the jackals' corridor of 4 jammed
        (seed 1). `_plan_through_parked` still judges a plan by the grown outline. Without a
        covariance the two shapes are the same."""
        shape = self._near_outline(k)
        body = self.near_robots[k].body
        if shape is not body:
            near = footprint_at(padded_footprint(body, SEEN_BODY_MARGIN), xy[0], xy[1], yaw)
            if self._marked(near):
                shape = body
        return footprint_at(shape, xy[0], xy[1], yaw)

    def _marked(self, polygon: np.ndarray) -> bool:
        """``SEEN_CELLS`` lethal cells or more of the local costmap lie under ``polygon``
        (costmap frame): our sensors mark something there."""
        rows, cols = polygon_cells(self.costmap, polygon)
        return np.count_nonzero(self.costmap.costs[rows, cols] == LETHAL_OBSTACLE) >= SEEN_CELLS

    def _near_outline(self, k: int, pad: float = 0.0) -> np.ndarray:
        """Neighbour ``k``'s body where it probably is, padded by ``pad`` m (robot frame):
        its footprint as shared, or, when it shares a covariance, its body grown by its spread
        by direction (`Neighbour.outline`; its shared footprint is padded by its widest spread
        all round: a lizi parked with amcl closed a 2 m corridor)."""
        return self.near_robots[k].outline(self.params.eps, pad=pad)

    def _plan_in_reach(self, xy: np.ndarray) -> None:
        """Raise `NoValidTrajectory` (move_base plans again, from where the robot stands) when
        no point of the global plan lies within the local costmap's reach of ``xy`` (half its
        larger side): collvoid's planner then fails as base_local_planner's
        ``transformGlobalPlan`` leaves it no plan (mixed circle of 16, seed 7: pioneer16, pushed
        out of the circle 2.8 m from its plan, went to and fro outside the ring of parked robots
        from 25 s to the end, steering at the nearest point of a plan it could not reach)."""
        cm = self.costmap
        reach = max(cm.size_x, cm.size_y) * cm.resolution / 2.0
        off = float(np.hypot(*(self.plan[self.plan_index, :2] - xy)))
        if off > reach:
            raise NoValidTrajectory(
                f"{self.where}: the global plan lies {off:.2f} m away, beyond the local "
                f"costmap's {reach:.2f} m; planning again"
            )

    def _plan_through_parked(self, now, ids, pos, yaws, parked) -> None:
        """Raise `NoValidTrajectory` (move_base then plans again, as when
        TrajectoryPlannerROS finds no valid trajectory) when the global plan, within
        ``carrot_distance`` ahead, runs through a robot ``parked`` (N,) (`_parked_in_view`,
        seen or counted by its body while we are stuck): its shared
        footprint at ``pos`` (N, 2) m, ``yaws`` (N,) rad, grown by our inscribed radius. A plan
        made before that robot parked there leads into it for good (the caller asks only after
        `BLOCKED_TIME` s without progress): the footprint check holds
        us off it, ORCA no longer counts it, and move_base's default ``planner_frequency`` 0
        plans only when the local planner fails (mixed circle of 16, seed 3: pioneer10, pushed
        back to its start, where pioneer14 had parked on its goal, stood there from 60 s to
        the end, 120 s). The global costmap's ``robots_layer`` marks robots that stand still,
        so the new plan goes round it. Not for a robot standing on our goal (no plan gets
        past it), nor again for the same robot within `REPLAN_AGAIN` s."""
        pts = self.plan[self.plan_index :, :2]
        along = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(pts, axis=0).T))])
        ahead = pts[along <= self.params.carrot_distance]
        goal = self.plan[-1:, :2]
        for k in np.flatnonzero(parked):
            rid = ids[k]
            if now < self.replanned_for.get(rid, -math.inf):
                continue
            body = footprint_at(self._near_outline(k, self.wall_radius), *pos[k], yaws[k])
            inside = inside_polygon(np.concatenate([goal, ahead]), body)  # one polygon
            if inside[0]:  # standing on our goal
                continue
            hit = inside[1:]
            if hit.any():
                self.replanned_for[rid] = now + REPLAN_AGAIN
                x, y = ahead[int(np.argmax(hit))]
                raise NoValidTrajectory(
                    f"{self.where}: the global plan runs through {rid}, standing at "
                    f"({x:.2f}, {y:.2f}); planning again"
                )
