"""The base side of ``collvoid_local_planner/CollvoidLocalPlanner``: from the cycle's
holonomic ORCA velocity to the command a base can follow.

* a holonomic base takes the velocity as it is (in its own frame);
* a differential drive tracks it (`tracking_command`, ``time_to_holo``), its forward speed cut
  to what the cycle's half-planes admit along its heading (`speed_along_heading`); a yielding
  robot backs out, one waiting in its refuge only moves as ORCA requires
  (`speed_nearest_still`), and so does one giving way at a crossing, turning on the spot
  towards its way; then the command's rollout over ``time_horizon_obst`` is checked
  with the real footprint on the local costmap and, if it touches an obstacle, replaced by the
  clear command that best follows the holonomic velocity (`footprint_safe_command`; it holds
  the direction, ahead or back, of the last cycle's replacement unless the other way ends
  `REVERSE_MARGIN` nearer); a robot wedged (the best clear command is to stand) backs out a
  little, on a curve towards the holonomic velocity where that is clear, else straight, or
  where it cannot, goes ahead a little the same way; wedged again where that escape began, it
  takes the clear command its body (the footprint without ``footprint_padding``) allows, and
  its body is checked until its padded footprint is clear again (the way out of the padding;
  the next wedge there escapes again);
* every command within ``acc_lim_x``/``acc_lim_y``/``acc_lim_theta`` of the last;
* within the goal's xy tolerance, the turn in place to the goal yaw (base_local_planner's).

`CollvoidDrive` is mixed into the planner, which owns the state it reads and writes
(``params``, ``lines``, ``contact_lines``, ``grid``, ``last_holo``, ``last_w``, ``yielding_to``,
``waiting``, ``turning_to``, ``outline``, ``body_outline``, ``horizon_obst``, ``dt``,
``replaced``, ``local_plan``, ``escape_from``, ``escape_sign``, ``escape_turn``, ``escapes``,
``escaped_at``, ``peeling``, ``way_outs``, ``fallback_v``, ``rotating_to_goal``,
``reached_goal``, ``xy_tolerance_latch``).
"""

from __future__ import annotations

import math

import numpy as np

from fleetsim.nav.controllers.base import VelocityCommand
from fleetsim.nav.multirobot.footprint_check import collides_at, footprint_safe_command
from fleetsim.nav.multirobot.holonomic import (
    rotated,
    speed_along,
    speed_along_heading,
    speed_interval,
    speed_nearest_still,
    tracking_command,
)

#: m/s and m: the escape of a robot wedged nose first (base_local_planner's escape_vel and
#: escape_reset_dist, 0.1 and 0.1; a little farther here, the room an arc needs to turn off)
ESCAPE_SPEED = 0.1
ESCAPE_DISTANCE = 0.15
#: share of the fastest turn an escape may turn at (`CollvoidDrive._escape_turns`)
ESCAPE_TURN = 0.5
#: m/s: a holonomic velocity slower than this is content to stand still (no escape)
STILL_HOLO = 0.02
#: no truncation: the velocity obstacle's horizon, s
UNTRUNCATED = 1e3


def _clamp(v: float, lo: float, hi: float) -> float:
    return max(lo, min(hi, v))


class CollvoidDrive:
    """The command side of the collvoid planner (see the module doc)."""

    def _track(self, holo: np.ndarray, pose, velocity) -> VelocityCommand:
        p, yaw = self.params, pose[2]
        standing = not p.holonomic_robot and (self.waiting or self.turning_to is not None)
        # a robot standing moves along its heading only as ORCA requires (None: not at all)
        along = None
        if standing:
            back = min(p.max_vel_x, p.max_vel_x_backwards)
            along = speed_nearest_still(*self.lines[:2], yaw, p.max_vel_x, back)
        if self.waiting and along is not None:
            # in the refuge: ORCA's nudge away from the robot going by is not worth a turn on
            # the spot (turning back when the yield ends takes a lizi seconds)
            cmd = (along, 0.0, 0.0)
        elif standing and self.turning_to is not None:
            # giving way at a crossing (`fleetsim.nav.multirobot.crossing`): it stands and
            # turns on the spot towards its way
            way = math.atan2(self.turning_to[1], self.turning_to[0])
            w = math.remainder(way - yaw, 2 * math.pi) / p.time_to_holo
            cmd = (
                0.0 if along is None else along,
                0.0,
                _clamp(w, p.min_vel_theta, p.max_vel_theta),
            )
        elif p.holonomic_robot:
            body = rotated(holo, -yaw)
            cmd = (float(body[0]), float(body[1]), 0.0)
        else:
            # a yielding robot backs out (its way back is behind it, and two half-turns on the
            # spot cost a skid-steer lizi ~6 s each)
            back = (
                self.yielding_to is not None
                and p.max_vel_x_backwards > 0.0
                and holo[0] * math.cos(yaw) + holo[1] * math.sin(yaw) < 0.0
            )
            top = min(p.max_vel_x, p.max_vel_x_backwards) if back else p.max_vel_x
            heading = yaw + math.pi if back else yaw
            v, w = tracking_command(holo, heading, p.time_to_holo, top, p.max_vel_theta)
            v = speed_along_heading(*self.lines, heading, v, top, self.contact_lines)
            cmd = (-v if back else v, 0.0, _clamp(w, p.min_vel_theta, p.max_vel_theta))
        self.replaced = False
        if not p.holonomic_robot:
            cmd = self._footprint_clear(cmd, pose, velocity)
        v0, vy0 = float(velocity[0]), float(velocity[1])
        dv, dw = p.acc_lim_x * self.dt, p.acc_lim_theta * self.dt
        dvy = p.acc_lim_y * self.dt
        vx = _clamp(cmd[0], v0 - dv, v0 + dv)
        vy = _clamp(cmd[1], vy0 - dvy, vy0 + dvy)
        w = _clamp(cmd[2], self.last_w - dw, self.last_w + dw)
        self.last_w = w
        self.local_plan = self._rollout(pose, vx, vy, w)
        return VelocityCommand(vx, vy, w)

    def _footprint_clear(self, cmd, pose, velocity) -> tuple[float, float, float]:
        """``cmd``, or the command nearest it whose footprint rollout over ``time_horizon_obst``
        is clear of the local costmap's obstacles (`footprint_safe_command` on this cycle's
        ``grid``, set by `holonomic_velocity`), at speeds the
        robots' half-planes admit along the heading (when they admit none there, the contact
        half-planes of the robots whose bodies' discs overlap ours, as `speed_along_heading`).

        When the clear command nearest the holonomic velocity is to stand still while that
        velocity is not (wedged nose first where no arc is clear and a turn on the spot hits a
        corner), the robot escapes as base_local_planner does: back at `ESCAPE_SPEED` until
        `ESCAPE_DISTANCE` from where it stuck, while that stays clear and the robots'
        half-planes admit it, on a curve towards the holonomic velocity where that is clear
        (`_escape_turns`), else straight; where it cannot back out, ahead the same way (a robot
        wedged tail first: mixed circle of 16, seed 3, pioneer16 stood 0.4 m from its goal
        from 45 s to the end, its goal to its right, a parked pioneer behind its left corner,
        so every turn towards the goal hit that robot, while straight ahead was clear).

        Wedged again where its last escape began (backing out did not free it: a rectangle
        flush on a wall, where each turn swings a wall-side corner into the wall and straight
        on ends at the next wall; the jackals' corridor of 4, seed 27), the robot takes the
        clear command its body allows, as TrajectoryPlannerROS's padding way out does, and
        its body is checked until its padded footprint is clear again. No way out is tried
        where no escape was (a robot that cannot back out or go ahead stands, as before)."""
        p, yaw = self.params, pose[2]
        points, dirs, n_obst = self.lines
        u = np.array([math.cos(yaw), math.sin(yaw)])
        back_top = min(p.max_vel_x, p.max_vel_x_backwards)
        caps = []
        for sign, top in ((1.0, p.max_vel_x), (-1.0, back_top)):
            # the robots' half-planes' top speed (none admitted: as speed_along_heading)
            caps.append(
                speed_along(points[n_obst:], dirs[n_obst:], 0, sign * u, top, top,
                            self.contact_lines)
            )  # fmt: skip
        horizon = self.horizon_obst if self.horizon_obst < UNTRUNCATED else p.time_horizon_obst

        outline = self.outline
        if self.peeling:  # off a wall within its padding: the body is checked until it is out
            self.peeling = collides_at(self.grid, outline, pose)
            if self.peeling:
                outline = self.body_outline

        # the way the last fallback command went (held while it serves, `REVERSE_MARGIN`)
        direction = math.copysign(1.0, self.fallback_v) if abs(self.fallback_v) > 1e-3 else 0.0
        self.fallback_v = 0.0

        def clear(wanted, holo, outline=outline):
            return footprint_safe_command(
                wanted,
                holo,
                tuple(float(a) for a in pose),
                (float(velocity[0]), float(velocity[2])),
                self.grid,  # this cycle's local costmap, the other robots' images cleared
                outline,
                (-caps[1], caps[0], p.min_vel_theta, p.max_vel_theta, p.acc_lim_x, p.acc_lim_theta),
                horizon,
                direction,
            )

        xy = np.array(pose[:2], dtype=np.float64)
        escape = min(ESCAPE_SPEED, back_top)

        def may_escape(sign: float, turn: float = 0.0) -> bool:
            """Whether escaping back (``sign`` -1) or ahead (+1), turning at ``turn`` rad/s, is
            clear. The costmap's check has the other robots' images cleared: it is for walls,
            and the robots' half-planes must admit the motion too (mixed circle of 16, seed 6:
            a pioneer wedged nose first backed into a lizi standing behind it)."""
            lo, hi = speed_interval(points[n_obst:], dirs[n_obst:], sign * u, escape)
            if not (lo <= hi and hi >= escape):
                return False
            return not clear((sign * escape, turn), sign * escape * u)[2]

        if self.escape_from is not None:
            near = float(np.hypot(*(xy - self.escape_from))) < ESCAPE_DISTANCE
            sign, turn = self.escape_sign, self.escape_turn
            if near and escape > 0.0 and may_escape(sign, turn):
                self.replaced = True
                return sign * escape, 0.0, turn
            self.escape_from = None
        v, w, self.replaced = clear((cmd[0], cmd[2]), self.last_holo)
        if self.replaced:
            self.fallback_v = v
        still = abs(v) < 1e-3 and abs(w) < 1e-3
        wants = float(np.hypot(*self.last_holo)) > STILL_HOLO
        if not (self.replaced and still and wants and not self.waiting):
            return v, 0.0, w
        # wedged again where its last escape began: backing out did not free it (a rectangle
        # flush on a wall, which no turn leaves without swinging a corner into the wall, and
        # straight on only ends at the next wall); its padding is the room it peels off in.
        # Then the next wedge here escapes again: escapes and way outs take turns
        escaped = self.escaped_at
        self.escaped_at = None
        again = escaped is not None and float(np.hypot(*(xy - escaped))) < ESCAPE_DISTANCE
        if again and self.body_outline is not None:
            bv, bw, _ = clear((cmd[0], cmd[2]), self.last_holo, self.body_outline)
            if abs(bv) >= 1e-3 or abs(bw) >= 1e-3:
                self.way_outs += 1
                self.peeling = True
                self.fallback_v = bv  # the way it goes is held, as a fallback's
                return bv, 0.0, bw
        if escape > 0.0:
            for sign in (-1.0, 1.0):
                for turn in self._escape_turns(yaw, escape):
                    if may_escape(sign, turn):
                        self.escape_from, self.escape_sign = xy, sign
                        self.escaped_at = xy
                        self.escape_turn = turn
                        self.escapes += 1
                        return sign * escape, 0.0, turn
        return v, 0.0, w

    def _escape_turns(self, yaw: float, speed: float) -> list[float]:
        """The turn rates an escape at ``speed`` m/s tries, best first: the one that leaves
        the robot facing the holonomic velocity at the escape's end (at most
        ``ESCAPE_TURN`` of the fastest turn), then straight. base_local_planner escapes straight;
        a jackal wedged with its nose 13 degrees towards a robot parked beside the way (the
        jackals' corridor of 4, seed 3) backed out straight, and every clear move from there
        (each right turn swung its front corner into that robot) turned it back in, for good.
        fleetsim's TrajectoryPlannerROS backs on such a curve too (`escape`)."""
        holo = self.last_holo
        # the wrap as measured (math.remainder differs in the last bits, and the jackals'
        # corridor of 4, seed 3, then ends flush on the wall instead: see docs/multi_robot.md,
        # stop 43)
        err = (math.atan2(holo[1], holo[0]) - yaw + math.pi) % (2.0 * math.pi) - math.pi
        p = self.params
        fastest = ESCAPE_TURN * max(0.0, min(p.max_vel_theta, -p.min_vel_theta))
        turn = _clamp(err * speed / ESCAPE_DISTANCE, -fastest, fastest)
        return [turn, 0.0] if abs(turn) > 1e-3 else [0.0]

    @staticmethod
    def _rollout(pose, vx: float, vy: float, w: float, steps: int = 10) -> np.ndarray:
        """The command held for one second, (steps, 3) poses in the local frame (local_plan)."""
        dt = 1.0 / (steps - 1)
        out = np.empty((steps, 3))
        x, y, th = pose
        for k in range(steps):
            out[k] = x, y, th
            c, s = math.cos(th), math.sin(th)
            x, y, th = x + (c * vx - s * vy) * dt, y + (s * vx + c * vy) * dt, th + w * dt
        return out

    def _at_goal(self, yaw: float, goal_yaw: float) -> VelocityCommand:
        p = self.params
        self.fallback_v = 0.0  # no fallback direction carried past the goal
        ang = math.remainder(goal_yaw - yaw, 2 * math.pi)
        if abs(ang) <= p.yaw_goal_tolerance:
            self.rotating_to_goal = False
            self.xy_tolerance_latch = False
            self.reached_goal = True
            self.local_plan = np.zeros((0, 3))
            self.last_w = 0.0
            return VelocityCommand()
        self.rotating_to_goal = True
        # max_vel_theta, slowed only as far as acc_lim_theta needs to stop on the goal yaw (Nav2
        # RegulatedPurePursuit's rotateToHeading); base_local_planner's rate |ang| (a gain of
        # 1/s) made the last 0.8 rad of a lizi's turn take 1.8 s (its skid steer turns at ~0.57
        # of the command): willow_swap's last robot arrived sideways and crept round
        v = p.max_vel_theta
        ramp = max(0.0, self.last_w if ang > 0 else -self.last_w) + p.acc_lim_theta * self.dt
        v = min(v, math.sqrt(2 * p.acc_lim_theta * abs(ang)), ramp)
        v = max(v, p.min_in_place_vel_theta)
        self.last_w = math.copysign(v, ang)
        return VelocityCommand(0.0, 0.0, self.last_w)
