"""``collvoid_local_planner/CollvoidLocalPlanner``: multi-robot collision avoidance in move_base.

After collvoid (Claes, Hennes, Tuyls), each control cycle:

1. the robot's own radius is its footprint's circumscribed radius (or ``footprint_radius``),
   plus ``safety_margin`` and the tracking error allowed for a differential drive
   (``min_error_holo`` growing to ``max_error_holo`` at full speed); each pair's combined
   radius grows by both robots' localization spreads (its own amcl ``particlecloud``'s
   covariance, the other's from /position_share; ``eps``) across the legs of the pair's
   velocity obstacle (`uncertainty.pair_padding`): two robots uncertain along a corridor are
   not kept apart across it. A robot that shares no covariance counts with its radius as sent
   (collvoid's, padded in every direction);
2. the preferred velocity points at a carrot ``carrot_distance`` m along the global plan, at
   ``max_vel_x``, slowing at a quarter of ``acc_lim_x`` (not below ``min_vel_x``) to stop at
   the goal; while another robot ahead, nearer than the goal, is closing in, it is turned by
   ``left_pref`` rad (negative: keep right), which breaks the symmetry of head-on meetings that
   plain ORCA cannot; outside a meeting, a robot carried off its way by a higher-priority robot
   beside it that moves the same way drops back behind it (`fleetsim.nav.multirobot.crossing`);
3. the `DeadlockRule` may make the robot yield (at once when a robot faces it across a
   passage too narrow for two): it backs out along the way it came (``max_vel_x_backwards``)
   to a place wide enough, aside to the right, taking full responsibility for avoiding the
   robot with priority, and waits there without turning until that robot is level with it
   or out of its way (`CollvoidPreference._out_of_our_way`);
4. ORCA half-planes (`fleetsim.nav.multirobot.orca`): one per robot on ``/position_share``
   within ``neighbor_dist`` (at most ``max_neighbors``, horizon ``time_horizon``, half the
   responsibility, all of it for a robot that is not ``controlled``, stands still or is yielded
   to; two discs that already overlap are parted within ``overlap_time``, a fleetsim addition:
   RVO2 and collvoid part them within one control period, see `CollvoidParams`; then a second
   half-plane along the line of centres keeps them from closing in on their bodies' discs
   faster than in that time, `contact_halfplanes`), and one per
   static obstacle point of the local costmap (the nearest lethal cell per bearing sector,
   horizon ``time_horizon_obst``, full responsibility, kept hard when the program is
   infeasible; the robot's circumscribed disc, or its inscribed one where the walls leave that
   disc no way on); with ``use_polygon_footprint`` (collvoid's polygon mode) each robot's
   half-plane and contact line come from the two footprints' Minkowski sum instead of their
   discs (`fleetsim.nav.multirobot.polygon_vo`, `CollvoidNeighbours._pair_polygons`), and a
   passage is judged by the robots' half widths (`CollvoidNeighbours._sides`);
5. the linear program gives the holonomic velocity nearest the preferred one; a differential
   drive tracks it (`tracking_command`, ``time_to_holo``) within ``acc_lim_x``/``acc_lim_theta``,
   its forward speed cut to what the same half-planes admit along its heading
   (`speed_along_heading`), so that turning towards a safe velocity never drives it somewhere
   unsafe; a differential drive's command is then rolled out for ``time_horizon_obst`` with
   the real footprint on the local costmap and, if that touches a lethal cell, replaced by
   the clear command that best follows the holonomic velocity
   (`fleetsim.nav.multirobot.footprint_check`: collvoid checks static obstacles with the
   footprint, base_local_planner-style, and keeps its velocity obstacles for the robots),
   holding the last replacement's direction; a wedged robot escapes, and wedged again there,
   turns off the wall within its ``footprint_padding`` (`collvoid_drive`);
6. within ``xy_goal_tolerance`` the robot stops and turns in place to the goal yaw, as
   base_local_planner does (at ``max_vel_theta``, slowed only to stop on the yaw);
7. the plan goes back to move_base (`NoValidTrajectory`: it plans again from where the robot
   stands) when none of it lies within the local costmap's reach, as collvoid's planner fails
   when base_local_planner's ``transformGlobalPlan`` leaves it no plan, and when it runs
   through a robot parked in view while the robot has made no progress for `BLOCKED_TIME` s
   (the global costmap's ``robots_layer`` holds that robot, so the new plan goes round it);
   after ``deadlock_time`` s without progress, the robots parked around count by their shared
   footprints, seen or not (`collvoid_parked`);

The rules that shape the preferred velocity around other robots (keeping right, going round
robots standing in the way on the side the robot heads for and keeping that side, yielding)
are in `collvoid_preference`; the neighbours and their radii in `collvoid_neighbours`; the
robots parked around and handing the plan back in `collvoid_parked`; the base's command in
`collvoid_drive`.

Neighbours arrive in the ``map`` frame; the local costmap's frame (often ``odom``) is reached
through tf. Only ORCA is available: ``clearpath: true`` or ``orca: false`` is an error, and
``type_vo`` (collvoid's choice of VO for its sampling and ClearPath solvers) has no effect.
"""

from __future__ import annotations

import logging
import math
from typing import Any

import numpy as np

from fleetsim.errors import ParameterError
from fleetsim.msgs import geometry_msgs
from fleetsim.nav.controllers.base import EmptyPlan, LocalPlanner, VelocityCommand
from fleetsim.nav.controllers.collvoid_drive import UNTRUNCATED, CollvoidDrive
from fleetsim.nav.controllers.collvoid_halfplanes import CollvoidHalfplanes
from fleetsim.nav.controllers.collvoid_neighbours import MAP_FRAME, CollvoidNeighbours
from fleetsim.nav.controllers.collvoid_params import CollvoidParams
from fleetsim.nav.controllers.collvoid_parked import BLOCKED_TIME, CollvoidParked
from fleetsim.nav.controllers.collvoid_preference import (
    DECELERATION,
    KEEP_RIGHT_UNTIL,
    CollvoidPreference,
)
from fleetsim.nav.costmap.footprint import (
    footprint_radii,
    outline_points,
)
from fleetsim.nav.multirobot.crossing import GiveWay
from fleetsim.nav.multirobot.deadlock import DeadlockRule
from fleetsim.nav.multirobot.holonomic import (
    plan_carrot,
    preferred_velocity,
    rotated,
)
from fleetsim.nav.multirobot.position_share import PositionShare
from fleetsim.nav.multirobot.uncertainty import cloud_covariance
from fleetsim.nav.multirobot.yielding import Retreat, head_on, narrow_between
from fleetsim.runtime import load_params

_log = logging.getLogger("fleetsim.nav.collvoid")
__all__ = ["MAP_FRAME", "CollvoidLocalPlanner"]
#: m; a goal that moved less than this is the same goal to the deadlock rule and the retreat.
#: move_base hands the plan over every cycle in the local costmap's frame (odom), where every
#: amcl map -> odom correction moves the goal by a few cm; taken as a new goal each time (~1 Hz)
#: the no-progress clock restarted and the deadlock rule could never fire under amcl
SAME_GOAL_SHIFT = 0.5


class CollvoidLocalPlanner(
    CollvoidNeighbours,
    CollvoidParked,
    CollvoidPreference,
    CollvoidHalfplanes,
    CollvoidDrive,
    LocalPlanner,
):
    """ORCA among the robots on /position_share, for one move_base (see the module doc)."""

    Params = CollvoidParams

    def __init__(self, node: Any, costmap_ros: Any, params: CollvoidParams, where: str = ""):
        p = self.params = params
        where = where or "CollvoidLocalPlanner"
        if p.clearpath or not p.orca:
            raise ParameterError(
                f"{where}: clearpath {str(p.clearpath).lower()}, orca {str(p.orca).lower()}: "
                "only collvoid's ORCA solver is available; set orca: true and clearpath: false"
            )
        if p.type_vo != 0:
            _log.warning("%s: type_vo %d has no effect with orca: true", where, p.type_vo)
        if p.max_neighbors == 0 or p.neighbor_dist == 0:  # collvoid takes it; robots collide
            _log.warning(
                "%s: max_neighbors %d, neighbor_dist %g: the planner avoids no other robot "
                "(as the plain local planner, robots meet only as laser obstacles)",
                where, p.max_neighbors, p.neighbor_dist,
            )  # fmt: skip
        self.node = node
        self.where = where
        self.costmap_ros = costmap_ros
        self.costmap = costmap_ros.costmap
        self.frame = costmap_ros.global_frame
        self.robot_id = p.robot_id or node.tf_prefix or node.namespace.strip("/")
        inscribed, circumscribed = footprint_radii(costmap_ros.footprint)
        self.body_radius = p.footprint_radius or circumscribed
        # walls: a differential drive's footprint is checked on its command's rollout
        # (`footprint_check`); where the walls block its circumscribed disc, ORCA's static
        # half-planes steer with the inscribed one (`_wall_halfplanes`)
        self.wall_radius = p.footprint_radius or inscribed
        if p.holonomic_robot:
            self.wall_radius = self.body_radius
        self.outline = outline_points(costmap_ros.footprint, self.costmap.resolution)
        # the body (the footprint without its padding): what a robot within its padding of a
        # wall is checked with, and how a robot flush on a wall peels off it (`CollvoidDrive`)
        body = getattr(costmap_ros, "unpadded_footprint", costmap_ros.footprint)
        padded = not np.array_equal(body, costmap_ros.footprint)
        self.body_outline = outline_points(body, self.costmap.resolution) if padded else None
        #: where the last escape began (a way out is taken when wedged there again)
        self.escaped_at: np.ndarray | None = None
        self.way_outs = 0  # how often it peeled off within its padding
        self.peeling = False  # from a way out until its padded footprint is clear again
        self.replaced = False  # this cycle's command was replaced by a footprint-clear one
        self.walls_blocked = False  # this cycle the walls left the circumscribed disc no way
        self.escape_from: np.ndarray | None = None  # where a wedged robot began backing out
        self.escape_sign = -1.0  # backing out (-1) or ahead (+1)
        self.escape_turn = 0.0  # rad/s, its turn (`_escape_turns`)
        self.escapes = 0  # how often it did
        self.fallback_v = 0.0  # m/s, last cycle's footprint-clear replacement's speed (or 0)
        self.share = PositionShare(node, eps=p.eps)
        self.deadlock = DeadlockRule.from_params(self.robot_id, p)
        self._covariance: np.ndarray | None = None  # own localization's, map frame
        node.create_subscription(geometry_msgs.PoseArray, "particlecloud", self._on_cloud, 1)
        self.dt = 1.0 / p.controller_frequency
        #: s within which ORCA parts two robots whose discs overlap (RVO2: one time step)
        self.overlap_t = max(self.dt, p.overlap_time)
        self.horizon = p.time_horizon if p.use_truncation else UNTRUNCATED
        self.horizon_obst = p.time_horizon_obst if p.use_truncation else UNTRUNCATED
        self.plan = np.zeros((0, 3))
        self.local_plan = np.zeros((0, 3))
        self.reached_goal = False
        self.xy_tolerance_latch = False
        self.rotating_to_goal = False
        #: rad/s last commanded: the reference of the turn-rate limit (a skid-steer base turns
        #: slower than commanded, its wheels slip; limited from the measured rate, the command
        #: settled near measured + acc_lim_theta * dt, ~0.4 rad/s for a lizi asked for 1.0)
        self.last_w = 0.0
        self.last_holo = np.zeros(2)
        self.yielding_to: str | None = None
        self.give_way = GiveWay(self.robot_id)  # the crossing rule's state
        self.giving_way_to: str | None = None  # this cycle's robot given way to
        #: (2,) the way a robot giving way turns to on the spot this cycle, or None
        self.turning_to: np.ndarray | None = None
        self.waiting = False  # yielding, in the refuge: stands still while ORCA lets it
        #: robot id -> until when a plan through it asks for no new plan again
        self.replanned_for: dict[str, float] = {}
        #: robot id -> until when a parked robot no sensor of ours sees counts with its
        #: footprint (`_parked_in_view`)
        self.as_bodies: dict[str, float] = {}
        #: (least m to the goal so far, when it was last cut by ``deadlock_progress``)
        self.progress = (math.inf, 0.0)
        self.plan_index = 0
        self.retreat = Retreat()  # the way back and the refuge of a yield
        self.lines = (np.zeros((0, 2)), np.zeros((0, 2)), 0)  # this cycle's half-planes
        #: this cycle's `contact_halfplanes` of the robots whose bodies' discs overlap ours
        #: (also in ``lines``): what a differential drive's speed along its heading keeps to
        #: when the robots' half-planes admit none there
        self.contact_lines = (np.zeros((0, 2)), np.zeros((0, 2)))
        self.grid = None  # this cycle's local costmap without the other robots (`_walls`)
        self.still_since: dict[str, float] = {}  # neighbour -> since when it stands still
        self.feasible = True
        #: robot id -> the side (0 right, 1 left) a robot standing in the way is gone round on
        self.detour_sides: dict[str, int] = {}

    @classmethod
    def from_namespace(cls, node: Any, costmap_ros: Any, ns: dict | None, where: str):
        return cls(node, costmap_ros, load_params(CollvoidParams, ns, where, logger=_log), where)

    def _on_cloud(self, msg: Any) -> None:
        self._covariance = cloud_covariance(
            np.array([[q.position.x, q.position.y] for q in msg.poses], dtype=np.float64)
        )

    # -- the plugin interface ------------------------------------------------------------------
    def set_plan(self, plan: Any) -> None:
        poses = np.asarray(getattr(plan, "poses", plan), dtype=np.float64)
        if poses.ndim != 2 or poses.shape[1] not in (2, 3) or poses.shape[0] == 0:
            raise EmptyPlan(f"set_plan: a plan must be (N, 3) x, y, yaw poses, got {poses.shape}")
        if poses.shape[1] == 2:
            poses = np.concatenate([poses, np.zeros((poses.shape[0], 1))], axis=1)
        shift = math.hypot(*(self.plan[-1, :2] - poses[-1, :2])) if self.plan.shape[0] else math.inf
        moved = shift > 1e-6 or not np.isclose(self.plan[-1, 2], poses[-1, 2], atol=1e-6)
        self.plan = poses
        if moved:  # as TrajectoryPlannerROS::setPlan: the goal is judged afresh
            self.reached_goal = False
            self.xy_tolerance_latch = False
        if shift > SAME_GOAL_SHIFT:
            self.detour_sides.clear()
            self.deadlock.reset(self.node.now())
            self.retreat.reset()
            self.give_way.reset()
            self.escape_from = None
            self.escaped_at = None
            self.peeling = False
            self.fallback_v = 0.0
            self.replanned_for.clear()
            self.progress = (math.inf, self.node.now())

    def is_goal_reached(self) -> bool:
        return self.reached_goal

    def compute_velocity_commands(self, pose, velocity) -> VelocityCommand:
        p = self.params
        x, y, yaw = (float(v) for v in pose)
        if self.plan.shape[0] == 0:
            raise EmptyPlan("CollvoidLocalPlanner: no plan; call set_plan first")
        xy = np.array([x, y])
        gx, gy, gyaw = self.plan[-1]
        if self.xy_tolerance_latch or math.hypot(gx - x, gy - y) <= p.xy_goal_tolerance:
            if p.latch_xy_goal_tolerance:
                self.xy_tolerance_latch = True
            return self._at_goal(yaw, gyaw)
        self.rotating_to_goal = False
        carrot, self.plan_index, remaining = plan_carrot(self.plan[:, :2], xy, p.carrot_distance)
        self._plan_in_reach(xy)
        if self.yielding_to is None:
            self.retreat.extend(xy)
        vel_body = np.array([float(velocity[0]), float(velocity[1])])
        vel = rotated(vel_body, yaw)
        holo = self.holonomic_velocity(xy, yaw, vel, carrot, remaining)
        return self._track(holo, (x, y, yaw), velocity)

    # -- the cycle -----------------------------------------------------------------------------
    def holonomic_velocity(self, xy, yaw, vel, carrot, remaining) -> np.ndarray:
        """The ORCA velocity for this cycle, (2,) m/s in the local costmap's frame."""
        p, now = self.params, self.node.now()
        pref = preferred_velocity(
            carrot, xy, remaining, p.max_vel_x, p.min_vel_x, DECELERATION * p.acc_lim_x
        )
        own_r = self.own_radius(float(np.hypot(*vel)))
        map_xy, ids, pos, nvel, radii, resp, controlled, yaws, wide, room = self._neighbours(
            xy, own_r, vel
        )
        stuck = self._stuck_for(now, remaining)
        parked, bodies = self._parked_in_view(ids, pos, nvel, yaws, stuck >= p.deadlock_time)
        if parked.any():  # obstacles of their true shape, as the walls (see _parked_in_view)
            if stuck >= BLOCKED_TIME:
                self._plan_through_parked(now, ids, pos, yaws, parked)
            keep = ~parked
            ids = [i for i, k in zip(ids, keep.tolist()) if k]
            pos, nvel, radii, resp, controlled, yaws, wide, room = (
                a[keep] for a in (pos, nvel, radii, resp, controlled, yaws, wide, room)
            )
        self.grid = self._walls(pos, nvel, wide, bodies)
        dist = np.hypot(pos[:, 0] - xy[0], pos[:, 1] - xy[1])
        pair = self.pair_radii(own_r, radii, dist)
        # how wide two robots are side by side (a passage, a refuge, out of the way): their
        # discs, or with ``use_polygon_footprint`` their bodies' half widths across their axes
        own_side, side = self._sides(own_r, ids, wide)
        active = {k: d for k, d, c in zip(ids, dist.tolist(), controlled) if c}
        narrow: list[str] = []
        facing: list[str] = []
        # the plan's way here: who is met ahead (head_on) and when a yield ends (has_passed)
        along = carrot - self.plan[self.plan_index, :2]
        if float(np.hypot(*along)) < 1e-6:  # at the plan's last point: the way to the carrot
            along = carrot - xy
        if active and self.yielding_to is None:
            met = head_on(along, pos - xy, nvel, yaws, controlled)
            facing = [ids[k] for k in met]
            narrow = [
                ids[k] for k in met if narrow_between(*self.grid, xy, pos[k], own_side[k], side[k])
            ]
        self.yielding_to = self.deadlock.update(now, remaining, active, narrow, facing)
        self.waiting = False
        if self.yielding_to is not None:
            k = ids.index(self.yielding_to)
            pref = self._yield_velocity(xy, along, pos[k], own_side[k], side[k], remaining, pref)
            if self.yielding_to is not None:
                resp[k] = 1.0
                self.waiting = not pref.any()
        self.giving_way_to = None
        self.turning_to = None
        if self.yielding_to is None and ids:
            wanted = pref
            near_goal = remaining < KEEP_RIGHT_UNTIL
            meeting = self._oncoming(pos - xy, nvel, vel, pref, dist, remaining)
            if not near_goal and meeting.any():
                pref = self._kept_right(xy, pref, own_r)
            # the way past a standing robot: the room beside it (`neighbour_radii`: the
            # spreads across the line between the two, its body's extent across it), not
            # ORCA's leg (the same with no spread)
            passage = self.pair_radii(own_r, room, dist)
            pref = self._around_still(pref, xy, vel, pos - xy, nvel, pair, controlled, ids, passage)
            pref = self._give_way(
                pref, wanted, vel, pos - xy, nvel, pair, resp, controlled, ids, meeting
            )
        hard = self.bodies_radii(radii)
        shapes = self._pair_polygons(yaw, pos - xy, ids, yaws, pair, hard) if ids else None
        return self._orca(xy, vel, pref, pos - xy, nvel, pair, resp, hard, shapes)
