"""``patrol_route``: a patrol through the building on move_base goals, with stops (issue 19).

The tutorial's patrol drives an open-loop circle; this one is harder to follow: the robot drives
``~waypoints`` in order through its own ``move_base`` action (relative: ``/karl/move_base`` in
karl's namespace), stopping ``stop`` seconds at each before the next, and starts over after the
last (``~loop``). A goal move_base aborts is logged and the route goes on with the next one.

Parameters::

    waypoints: [[x, y, yaw, stop], ...]   # m, m, rad, s (in frame_id)
    frame_id: /map
    start_delay: 2.0                      # sim s before the first goal (as patrol_client's)
    loop: true
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from fleetsim.errors import ParameterError
from fleetsim.msgs import move_base_msgs
from fleetsim.nav.navigator import pose_stamped
from fleetsim.runtime import Node, param

#: how often the node checks whether the next goal is due, Hz
TICK_RATE = 10.0
SUCCEEDED = 3


@dataclass(frozen=True)
class PatrolRouteParams:
    waypoints: list = param([], help="[[x, y, yaw, stop], ...] (m, m, rad, s)")
    frame_id: str = param("/map", help="frame of the waypoints")
    start_delay: float = param(2.0, unit="s", range=(0.0, None), help="sim time before the first")
    loop: bool = param(True, help="start over after the last waypoint")


def waypoints_from_param(raw: list, where: str) -> list[tuple[float, float, float, float]]:
    """The waypoints as (x, y, yaw, stop) tuples; an error names the bad entry."""
    if not raw:
        raise ParameterError(f"{where}: 'waypoints' is empty; give [[x, y, yaw, stop], ...]")
    out = []
    for i, w in enumerate(raw):
        try:
            x, y, yaw, stop = (float(v) for v in w)
        except (TypeError, ValueError):
            raise ParameterError(
                f"{where}: waypoints[{i}] must be [x, y, yaw, stop] numbers, got {w!r}"
            ) from None
        if not all(math.isfinite(v) for v in (x, y, yaw, stop)) or stop < 0:
            raise ParameterError(f"{where}: waypoints[{i}] = {w!r} must be finite, stop >= 0")
        out.append((x, y, yaw, stop))
    return out


class PatrolRoute(Node):
    """State: the index of the current waypoint, its goal handle, when the next is due."""

    Params = PatrolRouteParams

    def __init__(self, runtime, name: str = "patrol_route", namespace: str = "/", **kw) -> None:
        super().__init__(runtime, name, namespace, **kw)
        p: PatrolRouteParams = self.params
        self.waypoints = waypoints_from_param(p.waypoints, f"{self.full_name}/waypoints")
        self.frame_id = self.frame(p.frame_id)
        self.client = self.create_action_client(move_base_msgs.MoveBase, "move_base")
        self.index = -1
        self.handle = None
        self.due = self.now() + p.start_delay
        self.outcomes: list[tuple[int, int, float]] = []  # index, status, sim time done
        self.create_timer(1.0 / TICK_RATE, self._tick)

    def _tick(self) -> None:
        if self.handle is not None or self.now() < self.due - 1e-9:
            return
        if not self.client.wait_for_server():
            return
        nxt = self.index + 1
        if nxt >= len(self.waypoints):
            if not self.params.loop:
                return
            nxt = 0
        self.index = nxt
        x, y, yaw, _ = self.waypoints[nxt]
        goal = move_base_msgs.MoveBaseGoal(
            target_pose=pose_stamped(x, y, yaw, self.frame_id, self.now())
        )
        self.handle = self.client.send_goal(goal, done_cb=self._done)

    def _done(self, handle) -> None:
        if handle is not self.handle:
            return
        self.handle = None
        self.outcomes.append((self.index, int(handle.status), self.now()))
        if handle.status != SUCCEEDED:
            self.get_logger().info(
                "waypoint %d not reached (status %d%s); going on",
                self.index,
                handle.status,
                f": {handle.text}" if handle.text else "",
            )
        self.due = self.now() + self.waypoints[self.index][3]
