"""A parked robot makes room: collvoid's ``active_collision_avoidance``, inside the planner.

Once move_base has reached its goal it stops calling the local planner, and the robot stands
where it stopped: the others go round it as a static obstacle (all the responsibility theirs).
collvoid's standalone mode (``active_collision_avoidance.py``: toggled by a service, it asks the
planner for ``get_collvoid_twist`` towards the pose it was toggled at, 10 Hz) keeps such a
robot running ORCA with the preferred velocity towards that *home* pose, ``home - position``
capped at ``max_vel_x`` (zero at home): it takes its share of avoiding a robot that comes at it
and returns home afterwards.

`CollvoidHold` does that with ``active_collision_avoidance: true``, on a timer of the planner's
own at ``controller_frequency``, from the first cycle after the goal is reached (the home pose
is where the robot stopped) until move_base hands over a new goal; it publishes on
``cmd_vel`` itself, as collvoid's node does (move_base publishes nothing while it has no goal).

A differential drive moves only along its heading, forwards or backwards, at the speed the
half-planes admit nearest the ORCA velocity's component along it (as a robot waiting for
another to go by): a lizi turns on the spot at ~0.85 rad/s, so turning to step aside and back
and then to its goal yaw again would take seconds, while a step along its heading is enough to
open a way (and leaves its yaw as it was). The step is checked with the real footprint on the
local costmap; one that would touch an obstacle is not taken.

`CollvoidHold` is mixed into the planner, which owns the state it reads (``params``, ``node``,
``costmap_ros``, ``costmap``, ``outline``, ``dt``, ``reached_goal``, ``lines``,
``body_radius``, ``horizon_obst``) and provides ``_neighbours``, ``own_radius`` and ``_orca``.
"""

from __future__ import annotations

import math

import numpy as np

from fleetsim.msgs import geometry_msgs, nav_msgs
from fleetsim.nav.multirobot.footprint_check import footprint_safe_command
from fleetsim.nav.multirobot.holonomic import speed_on_line

#: m: nearer home than this a parked robot wants to stay where it is (preferred velocity 0)
HOME_SLACK = 0.02
#: m/s: commands slower than this are not sent (a parked robot at rest stays silent)
HOLD_STILL = 1e-3


class CollvoidHold:
    """The parked side of the collvoid planner (see the module doc)."""

    def _start_hold(self) -> None:
        """Declare the hold's subscription, publisher and timer (called from ``__init__``)."""
        self.home: np.ndarray | None = None  # where the robot stopped at its goal, local frame
        self.last_cycle = -math.inf  # when move_base last asked for a command
        self.held = 0.0  # the last command the hold sent, m/s
        self.holds = 0  # cycles in which the hold moved the robot
        self._odom_v = 0.0
        if not self.params.active_collision_avoidance:
            return
        node = self.node
        node.create_subscription(nav_msgs.Odometry, "odom", self._on_odom, 1)
        self._hold_pub = node.create_publisher(geometry_msgs.Twist, "cmd_vel", 1)
        node.create_timer(self.dt, self._hold_cycle)

    def _on_odom(self, msg) -> None:
        self._odom_v = float(msg.twist.twist.linear.x)

    def _hold_cycle(self) -> None:
        now = self.node.now()
        if not self.reached_goal or now - self.last_cycle < 1.5 * self.dt:
            self.home = None
            return
        pose = self.costmap_ros.robot_pose()
        if pose is None:
            return
        v = self.hold_speed(pose, self._odom_v)
        if abs(v) < HOLD_STILL and abs(self.held) < HOLD_STILL:
            return
        self.held = v
        self.holds += abs(v) >= HOLD_STILL
        self._hold_pub.publish(geometry_msgs.Twist(linear=geometry_msgs.Vector3(x=v)))

    def hold_speed(self, pose, v0: float) -> float:
        """The parked robot's command along its heading, m/s (negative: backwards).

        pose : (x, y, yaw) m, rad in the local costmap's frame; v0 : its forward speed, m/s.
        The first call takes ``pose`` as home."""
        p = self.params
        x, y, yaw = (float(a) for a in pose)
        xy = np.array([x, y])
        if self.home is None:
            self.home = xy.copy()
        u = np.array([math.cos(yaw), math.sin(yaw)])
        to_home = self.home - xy
        d = float(np.hypot(*to_home))
        pref = np.zeros(2) if d < HOME_SLACK else to_home * min(1.0, p.max_vel_x / d)
        map_xy, ids, pos, nvel, radii, resp, _, _ = self._neighbours(xy)
        vel = v0 * u
        own_r = self.own_radius(abs(v0), map_xy)
        holo = self._orca(xy, vel, pref, pos - xy, nvel, own_r + radii, resp)
        back = min(p.max_vel_x, p.max_vel_x_backwards)
        v = speed_on_line(*self.lines[:2], yaw, float(holo @ u), p.max_vel_x, back)
        dv = p.acc_lim_x * self.dt
        v = max(v0 - dv, min(v0 + dv, v))
        if abs(v) >= HOLD_STILL:
            cm = self.costmap
            _, _, blocked = footprint_safe_command(
                (v, 0.0),
                v * u,
                (x, y, yaw),
                (v0, 0.0),
                (cm.costs, (cm.origin_x, cm.origin_y), cm.resolution),
                self.outline,
                (-back, p.max_vel_x, 0.0, 0.0, p.acc_lim_x, p.acc_lim_theta),
                self.horizon_obst if self.horizon_obst < 1e3 else p.time_horizon_obst,
            )
            if blocked:
                v = 0.0
        return v
