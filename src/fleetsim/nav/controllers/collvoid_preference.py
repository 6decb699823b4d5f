"""The preferred velocity's rules around other robots, for ``CollvoidLocalPlanner``: keeping
right in a meeting (`_oncoming`), going round robots that stand in the way (`_around_still`),
giving way at a crossing (`_give_way`, `fleetsim.nav.multirobot.crossing`) and the velocity
of a robot that yields (`_yield_velocity`).

`CollvoidPreference` is mixed into the planner, which owns the state it reads (``params``,
``node``, ``plan``, ``plan_index``, ``costmap``, ``body_radius``, ``deadlock``, ``retreat``,
``yielding_to``, ``detour_sides``, ``give_way``, ``turning_to``).
"""

from __future__ import annotations

import numpy as np

from fleetsim.nav.multirobot.crossing import (
    GIVE_WAY_SPEED,
    REACH,
    across_way,
    carried_by,
    collision_course,
    room_to_turn,
)
from fleetsim.nav.multirobot.holonomic import detour_velocity, gaps_closed, rotated
from fleetsim.nav.multirobot.yielding import clear_distance, has_passed, out_of_way

#: m/s: a neighbour slower than this is treated as standing still (full responsibility)
STILL_SPEED = 0.02
#: share of acc_lim_x used to slow down towards the goal
DECELERATION = 0.25
#: m added to the combined radius of a robot standing in the way when going round it
DETOUR_MARGIN = 0.05
#: m: a robot standing in the way nearer than this is gone round
DETOUR_REACH = 1.0
#: m: closer to the goal than this, no more keeping right (it only pushed arriving robots off
#: their goal, to come back to it from the side and turn there); circle of 16, seeds 0-4: 1.5 m
#: 21.0 / 24.0 s mean / max makespan, 1.0 m 20.3 / 23.6 s, 2.5 m 24.7 / 28.4 s
KEEP_RIGHT_UNTIL = 1.0
#: m beyond the robot's radius the way kept right must be free of walls (in a 2 m corridor a
#: lizi keeping right runs ~0.45 m off the wall, 0.8 m along its turned way: still kept right)
KEEP_RIGHT_ROOM = 0.25


class CollvoidPreference:
    """The preferred velocity's rules around other robots (see the module doc)."""

    def _kept_right(self, xy, pref, own_r) -> np.ndarray:
        """``pref`` turned by ``left_pref`` (keeping right of an oncoming robot), unless a wall
        closes that side: the turned way meets a lethal cell of this cycle's walls within
        ``own_r`` + `KEEP_RIGHT_ROOM` m. Then ``pref`` as it is: two lizis bound through a
        1.6 m doorway from either side, diagonally across it, each kept right into the wall
        beside the door and stood there 26 s (a new user's world, never tuned on)."""
        turned = rotated(pref, self.params.left_pref)
        n = float(np.hypot(*turned))
        if n < 1e-9:
            return turned
        reach = own_r + KEEP_RIGHT_ROOM
        if clear_distance(*self.grid, xy, turned / n, reach) < reach:
            return pref
        return turned

    def _yield_velocity(self, xy, to_goal, other, own_r, other_r, remaining, pref):
        """Yielding (`fleetsim.nav.multirobot.yielding`): to the refuge back along the plan,
        then wait there; the yield ends (``pref`` again) as soon as the other robot is level
        with us (beside us in the refuge, out of the passage; ORCA keeps us apart from there)
        or out of our way (`_out_of_our_way`)."""
        p, now = self.params, self.node.now()
        if has_passed(other - xy, to_goal, 0.0) or self._out_of_our_way(xy, other, own_r + other_r):
            self.deadlock.release(now, remaining)
            self.yielding_to = None
            return pref
        decel = DECELERATION * p.acc_lim_x
        return self.retreat.velocity(self.grid, xy, own_r, other_r, p.max_vel_x, decel)

    def _out_of_our_way(self, xy, other, radii) -> bool:
        """The robot we yield to (at ``other``, m) is farther than ``deadlock_radius`` from us
        and more than twice the pair's combined radius ``radii`` (m) from our plan still
        ahead (`out_of_way`)."""
        ahead = self.plan[self.plan_index :, :2]
        return out_of_way(xy, other, ahead, self.params.deadlock_radius, 2.0 * radii)

    def _around_still(
        self, pref, xy, vel, rel, nvel, radii, controlled, ids, passage=None
    ) -> np.ndarray:
        """``pref`` turned round the nearest robot standing in its way (`detour_velocity`) on a
        side a wall leaves room on (`gaps_closed`), unless that robot stands on the goal (then
        ORCA stops us short of it); a robot once gone round on one side is kept on that side
        while it is within reach (`detour_sides`). ``radii`` (N,) m combined, ORCA's;
        ``passage`` (N,) m combined for the room beside each robot (None: ``radii``): with
        amcl, ORCA's padding is the spread across the leg the relative velocity passes, which
        turns with the preferred velocity, so a side judged by it opened and shut from one
        cycle to the next. The lizis' corridor of 4 with amcl, seed 1: lizi2 stood 20 s before
        lizi4 parked in the corridor's middle, 0.82 m of room above it, heading down and back
        each cycle."""
        still = (np.hypot(nvel[:, 0], nvel[:, 1]) < STILL_SPEED) | ~controlled
        if not still.any():
            return pref
        r = radii[still] + DETOUR_MARGIN
        to_goal = self.plan[-1, :2] - xy
        free = np.hypot(*(rel[still] - to_goal).T) > r
        idx = np.flatnonzero(still)[free]
        r = radii[idx] + DETOUR_MARGIN
        room = r if passage is None else passage[idx] + DETOUR_MARGIN
        grid = self.grid
        closed = gaps_closed(grid, xy, rel[idx], room, self.body_radius + grid[2] * 0.71)
        near = [ids[k] for k in idx]
        sides = self.detour_sides
        for k in [k for k in sides if k not in near]:
            del sides[k]
        keep = np.array([sides.get(k, -1) for k in near], dtype=int)
        out, k = detour_velocity(pref, rel[idx], r, DETOUR_REACH, closed, keep, vel)
        if k >= 0:
            bearing = rel[idx[k]]
            sides[near[k]] = int(bearing[0] * out[1] - bearing[1] * out[0] > 0.0)
        return out

    def _give_way(self, pref, wanted, vel, rel, nvel, radii, resp, controlled, ids, meeting):
        """``pref``, or its `GIVE_WAY_SPEED` share while this robot gives way at a crossing
        (`fleetsim.nav.multirobot.crossing`; then ``giving_way_to`` names the robot and its
        responsibility ``resp`` (N,) becomes all of it). ``wanted`` (2,) m/s: the way to the
        carrot before keeping right; ``radii`` (N,) m combined; ``meeting`` (N,) bool: the
        robots keeping right turns for (`_oncoming`): while one of them, other than a robot
        carrying us, is there, no robot carries us (robots coming against us are keeping
        right's, not a crossing; the carrier itself, drifting into us as the pair's lanes
        converge, closes in as `_oncoming` counts it, and alone it kept the rule off for good:
        circle of 16, seed 26, lizi14 carried 1.6 m off its plan by lizi6 for 6 s, 21.7 s
        makespan). A differential drive with room to turn (`room_to_turn`) stands and turns
        towards ``wanted`` instead (``turning_to``, the command's side: `CollvoidDrive._track`)."""
        moving = (np.hypot(nvel[:, 0], nvel[:, 1]) >= STILL_SPEED) & controlled
        carrying = carried_by(rel, nvel, radii, vel, wanted, REACH) & moving
        if (meeting & ~carrying).any():
            carrying[:] = False
        # in our way: across it, and met going our way within ORCA's horizon (a robot
        # crossing it is out of our way before its disc has left the ray)
        in_the_way = across_way(rel, radii, wanted, REACH) & collision_course(
            wanted, rel, nvel, radii, self.params.time_horizon
        )
        against = np.einsum("ij,ij->i", rel, rel) <= radii * radii
        to = self.give_way.update(
            self.node.now(), list(ids), carrying, in_the_way, controlled, against
        )
        self.giving_way_to = to
        if to is None:
            return pref
        k = list(ids).index(to)
        resp[k] = 1.0  # ORCA moves us out of its way, all of it ours
        if not self.params.holonomic_robot and room_to_turn(rel, radii, k):
            self.turning_to = np.asarray(wanted, dtype=np.float64)
        return GIVE_WAY_SPEED * pref

    @staticmethod
    def _oncoming(rel, nvel, vel, pref, dist, reach) -> np.ndarray:
        """(N,) robots ahead (along ``pref``), nearer than ``reach`` m, moving and closing in:
        the meetings keeping right resolves (a robot standing still ahead is gone round,
        `_around_still`)."""
        rel_vel = nvel - vel
        moving = np.hypot(nvel[:, 0], nvel[:, 1]) >= STILL_SPEED
        closing = np.einsum("ij,ij->i", rel, rel_vel) < 0.0
        return (rel @ pref > 0) & (dist < reach) & moving & closing
