"""What a robot knows about the others: the ``/position_share`` table (collvoid's
position_share_controller).

Every robot publishes a `collvoid_msgs.PoseTwistWithCovariance` about itself on the global
topic ``/position_share`` (`fleetsim.nav.multirobot.me_publisher`); each consumer (the collvoid
local planner, the robots costmap layer) keeps the newest message per ``robot_id`` in a
`NeighbourTable`:

* entries older than ``last_seen_threshold`` (collvoid's name, 2 s) by their header stamp are
  dropped;
* a message with a NaN or infinite pose, velocity or radius, an empty or non-finite footprint,
  or no ``robot_id`` is rejected (`neighbour_from_msg` says why); `PositionShare` warns once per
  robot and keeps the others;
* `NeighbourTable.near` gives the robots within a radius, nearest first, at most
  ``max_neighbors``, as arrays in the map frame.

The topic is an ordinary graph topic, so robots whose stacks run in another process see each
other through the Zenoh bridge like any other topic (the message is CDR-able).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from fleetsim.msgs import collvoid_msgs
from fleetsim.tf.quaternions import yaw_from_quaternion

TOPIC = "/position_share"
#: collvoid's ``~last_seen_threshold``: s after which a silent robot is forgotten
LAST_SEEN_THRESHOLD = 2.0


@dataclass(frozen=True)
class Neighbour:
    """One robot's shared state, in the map frame (m, rad, m/s)."""

    robot_id: str
    x: float
    y: float
    yaw: float
    vx: float
    vy: float
    radius: float
    footprint: np.ndarray  # (K, 2) in the robot's frame, inflated by its uncertainty
    controlled: bool
    stamp: float  # s of sim time

    def polygon(self) -> np.ndarray:
        """The footprint at the robot's pose: (K, 2) map frame, m."""
        c, s = math.cos(self.yaw), math.sin(self.yaw)
        fp = self.footprint
        return np.stack(
            (self.x + c * fp[:, 0] - s * fp[:, 1], self.y + s * fp[:, 0] + c * fp[:, 1]), axis=1
        )


def neighbour_from_msg(msg: Any) -> Neighbour | str:
    """The `Neighbour` a position_share message describes, or the reason it is unusable."""
    rid = str(msg.robot_id or "")
    if not rid:
        return "a message without robot_id"
    p = msg.pose.pose
    pose = (p.position.x, p.position.y)
    q = p.orientation
    v = msg.holonomic_velocity
    numbers = (*pose, q.x, q.y, q.z, q.w, v.x, v.y, msg.radius)
    if not all(math.isfinite(float(x)) for x in numbers):
        return (
            f"robot '{rid}' shared a non-finite pose, velocity or radius "
            f"(pose {pose[0]}, {pose[1]}; velocity {v.x}, {v.y}; radius {msg.radius})"
        )
    pts = msg.footprint.polygon.points
    fp = np.array([[pt.x, pt.y] for pt in pts], dtype=np.float64).reshape(-1, 2)
    if fp.shape[0] < 3 or not np.isfinite(fp).all():
        return (
            f"robot '{rid}' shared an empty or invalid footprint ({fp.shape[0]} points; a "
            "polygon needs at least 3 finite points)"
        )
    stamp = msg.header.stamp.sec + msg.header.stamp.nanosec * 1e-9
    yaw = yaw_from_quaternion((q.x, q.y, q.z, q.w))
    return Neighbour(rid, *pose, yaw, v.x, v.y, float(msg.radius), fp, bool(msg.controlled), stamp)


@dataclass(frozen=True)
class NeighbourArrays:
    """The robots near one point, nearest first (map frame)."""

    ids: list[str]
    positions: np.ndarray  # (N, 2) m
    velocities: np.ndarray  # (N, 2) m/s
    radii: np.ndarray  # (N,) m
    controlled: np.ndarray  # (N,) bool
    robots: list[Neighbour]


class NeighbourTable:
    """The newest state of every robot on ``/position_share`` (see the module doc)."""

    def __init__(self, last_seen_threshold: float = LAST_SEEN_THRESHOLD) -> None:
        self.last_seen_threshold = last_seen_threshold
        self.robots: dict[str, Neighbour] = {}

    def update(self, msg: Any) -> str | None:
        """Store a message; returns the reason when it was rejected."""
        got = neighbour_from_msg(msg)
        if isinstance(got, str):
            return got
        self.robots[got.robot_id] = got
        return None

    def get(self, robot_id: str, now: float) -> Neighbour | None:
        """One robot's fresh entry, or None."""
        r = self.robots.get(robot_id)
        if r is None or now - r.stamp > self.last_seen_threshold:
            return None
        return r

    def fresh(self, now: float) -> list[Neighbour]:
        """Every robot heard from within ``last_seen_threshold``; older ones are dropped."""
        stale = [k for k, r in self.robots.items() if now - r.stamp > self.last_seen_threshold]
        for k in stale:
            del self.robots[k]
        return [self.robots[k] for k in sorted(self.robots)]

    def near(
        self, now: float, xy: tuple[float, float], radius: float, max_n: int, exclude: str = ""
    ) -> NeighbourArrays:
        """Robots (other than ``exclude``) whose centre is within ``radius`` m of ``xy``."""
        rs = [r for r in self.fresh(now) if r.robot_id != exclude]
        pos = np.array([[r.x, r.y] for r in rs], dtype=np.float64).reshape(-1, 2)
        d = np.hypot(pos[:, 0] - xy[0], pos[:, 1] - xy[1])
        order = [i for i in np.argsort(d, kind="stable") if d[i] <= radius][:max_n]
        rs = [rs[i] for i in order]
        return NeighbourArrays(
            ids=[r.robot_id for r in rs],
            positions=pos[order],
            velocities=np.array([[r.vx, r.vy] for r in rs], dtype=np.float64).reshape(-1, 2),
            radii=np.array([r.radius for r in rs], dtype=np.float64),
            controlled=np.array([r.controlled for r in rs], dtype=bool),
            robots=rs,
        )


class PositionShare:
    """A node's subscription to ``/position_share`` feeding a `NeighbourTable`; a robot whose
    message is rejected is warned about once (by robot) and ignored."""

    def __init__(self, node: Any, last_seen_threshold: float = LAST_SEEN_THRESHOLD) -> None:
        self.node = node
        self.table = NeighbourTable(last_seen_threshold)
        self.rejected = 0
        self.sub = node.create_subscription(
            collvoid_msgs.PoseTwistWithCovariance, TOPIC, self.on_message, queue_size=0
        )

    def on_message(self, msg: Any) -> None:
        problem = self.table.update(msg)
        if problem is not None:
            self.rejected += 1
            self.table.robots.pop(str(msg.robot_id or ""), None)
            self.node._warn_once(f"position_share:{msg.robot_id}", f"{TOPIC}: ignoring {problem}")
