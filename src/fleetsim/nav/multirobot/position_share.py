"""What a robot knows about the others: the ``/position_share`` table (collvoid's
position_share_controller).

Every robot publishes a `collvoid_msgs.PoseTwistWithCovariance` about itself on the global
topic ``/position_share`` (`fleetsim.nav.multirobot.me_publisher`); each consumer (the collvoid
local planner, the robots costmap layer) keeps the newest message per ``robot_id`` in a
`NeighbourTable`:

* entries older than ``last_seen_threshold`` (collvoid's name, 2 s) by their header stamp are
  dropped, and so are entries stamped more than ``FUTURE_TOLERANCE`` (2 s) ahead of the
  listener's clock (a publisher on another clock: its messages would never go stale);
* a message with a NaN or infinite pose, velocity or radius, a radius <= 0, an empty or
  non-finite footprint, a ``header.frame_id`` other than the shared frame (``map``; an empty
  one is taken as the shared frame), or no ``robot_id`` is rejected (`neighbour_from_msg` says
  why); `PositionShare` keeps the others and warns once per robot and reason in a process (a
  runtime), whichever of its listening nodes hears it first (the warning names that node):
  ten robots' move_bases hearing one broken robot give one warning, not ten;
* the pose's x/y covariance (``pose.covariance`` entries 0, 1, 6, 7; me_publisher's amcl
  particle spread) is kept with the robot's body: ``footprint`` and ``radius`` are padded by
  the widest spread (`uncertainty.widest_spread`, at the consumer's ``eps``, which must be the
  fleet's), so the body is that padding taken off again (`uncertainty.shared_padding`); a
  consumer pads a pair by the spreads in the direction that matters
  (`uncertainty.pair_padding`). An all-zero covariance (fake_localization, or a publisher that
  shares none) leaves the radius as sent; a non-finite, asymmetric or not positive
  semi-definite one is ignored (the radius as sent) with one warning naming the robot;
* `NeighbourTable.near` gives the robots within a radius, nearest first, at most
  ``max_neighbors``, as arrays in the map frame.

The topic is an ordinary graph topic, so robots whose stacks run in another process see each
other through the Zenoh bridge like any other topic (the message is CDR-able).
"""

from __future__ import annotations

import math
import weakref
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from fleetsim.msgs import collvoid_msgs
from fleetsim.nav.costmap.footprint import padded_footprint
from fleetsim.nav.multirobot.uncertainty import shared_padding, spread_outline, widest_spread
from fleetsim.tf.names import normalize_frame
from fleetsim.tf.quaternions import yaw_from_quaternion

TOPIC = "/position_share"
#: collvoid's ``~last_seen_threshold``: s after which a silent robot is forgotten
LAST_SEEN_THRESHOLD = 2.0
#: s a message may be stamped ahead of the listener's clock (beyond: the sender's clock is wrong)
FUTURE_TOLERANCE = 2.0
#: the frame every robot shares its pose in
SHARED_FRAME = "map"
#: collvoid's ``eps`` (me_publisher's and the planner's default)
EPS = 0.1
#: pose.covariance entries of the x/y block (row-major 6 x 6)
XY_COVARIANCE = [0, 1, 6, 7]


class Rejection(str):
    """Why a message is unusable (the text), with the robot it came from and the kind of fault
    (the key of the one warning)."""

    robot_id: str
    kind: str

    def __new__(cls, robot_id: str, kind: str, text: str) -> Rejection:
        out = super().__new__(cls, text)
        out.robot_id, out.kind = robot_id, kind
        return out


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
    #: (2, 2) x/y covariance of its localization, m^2; None: the radius as sent is the robot
    covariance: np.ndarray | None = None
    #: m, the radius without the localization padding (``radius`` without a covariance)
    body_radius: float = 0.0
    #: why a covariance it sent was ignored (warned about once), else None
    covariance_fault: Rejection | None = None
    #: (K, 2) the footprint without the localization padding (``footprint`` without a
    #: covariance)
    body_footprint: np.ndarray | None = None

    @property
    def body(self) -> np.ndarray:
        """(K, 2) the footprint without the localization padding, robot frame, m."""
        return self.footprint if self.body_footprint is None else self.body_footprint

    def body_in_map(self) -> np.ndarray:
        """`body` turned into the map frame about the robot's centre, (K, 2) m."""
        c, s = math.cos(self.yaw), math.sin(self.yaw)
        return self.body @ np.array([[c, s], [-s, c]])

    def outline(self, eps: float, scale: float = 1.0, pad: float = 0.0) -> np.ndarray:
        """The body, scaled by ``scale``, grown by where it probably is, by direction, and by
        ``pad`` m: (K, 2) robot frame, m (`uncertainty.spread_outline`, the spread capped at
        twice its body radius as the pair padding caps it). Without a covariance the footprint
        as sent, scaled and padded as costmap_2d pads a footprint (`padded_footprint`)."""
        body = self.body
        if scale != 1.0:
            body = body * scale
        if self.covariance is None:
            return padded_footprint(body, pad) if pad else body
        c, s = math.cos(self.yaw), math.sin(self.yaw)
        to_robot = np.array([[c, s], [-s, c]])  # map -> robot frame
        cov = to_robot @ self.covariance @ to_robot.T
        return spread_outline(body, cov, 2.0 * self.body_radius, eps, pad)

    def polygon(self) -> np.ndarray:
        """The footprint at the robot's pose: (K, 2) map frame, m."""
        c, s = math.cos(self.yaw), math.sin(self.yaw)
        fp = self.footprint
        return np.stack(
            (self.x + c * fp[:, 0] - s * fp[:, 1], self.y + s * fp[:, 0] + c * fp[:, 1]), axis=1
        )


def shared_covariance(msg: Any, rid: str) -> np.ndarray | Rejection | None:
    """The message's (2, 2) x/y pose covariance; None when it is all zero (none shared); the
    reason when it is unusable."""
    c = np.array([float(msg.pose.covariance[i]) for i in XY_COVARIANCE]).reshape(2, 2)
    if not c.any():
        return None
    if not np.isfinite(c).all():
        return Rejection(rid, "covariance", f"robot '{rid}' shared a non-finite covariance {c}")
    scale = float(np.abs(c).max())
    if abs(c[0, 1] - c[1, 0]) > 1e-9 * scale or np.linalg.eigvalsh(c)[0] < -1e-12 * scale:
        return Rejection(
            rid,
            "covariance",
            f"robot '{rid}' shared a covariance that is not symmetric positive semi-definite "
            f"(x/y block {c.tolist()})",
        )
    return c


def neighbour_from_msg(
    msg: Any, frame: str = SHARED_FRAME, eps: float = EPS
) -> Neighbour | Rejection:
    """The `Neighbour` a position_share message describes, or the reason it is unusable
    (``frame``: the shared frame its pose must be in; ``eps``: the fleet's, with which the
    publisher padded its footprint by its covariance)."""
    rid = str(msg.robot_id or "")
    if not rid:
        return Rejection("", "robot_id", "a message without robot_id")
    given = str(msg.header.frame_id or "")
    if given and given.lstrip("/") != normalize_frame(frame):
        return Rejection(
            rid,
            "frame",
            f"robot '{rid}' shared its pose in frame '{given}', not the shared frame "
            f"'{normalize_frame(frame)}'",
        )
    p = msg.pose.pose
    pose = (p.position.x, p.position.y)
    q = p.orientation
    v = msg.holonomic_velocity
    numbers = (*pose, q.x, q.y, q.z, q.w, v.x, v.y, msg.radius)
    if not all(math.isfinite(float(x)) for x in numbers):
        return Rejection(
            rid,
            "non-finite",
            f"robot '{rid}' shared a non-finite pose, velocity or radius "
            f"(pose {pose[0]}, {pose[1]}; velocity {v.x}, {v.y}; radius {msg.radius})",
        )
    if not float(msg.radius) > 0.0:
        return Rejection(
            rid, "radius", f"robot '{rid}' shared radius {msg.radius} m (it must be > 0)"
        )
    pts = msg.footprint.polygon.points
    fp = np.array([[pt.x, pt.y] for pt in pts], dtype=np.float64).reshape(-1, 2)
    if fp.shape[0] < 3 or not np.isfinite(fp).all():
        return Rejection(
            rid,
            "footprint",
            f"robot '{rid}' shared an empty or invalid footprint ({fp.shape[0]} points; a "
            "polygon needs at least 3 finite points)",
        )
    stamp = msg.header.stamp.sec + msg.header.stamp.nanosec * 1e-9
    yaw = yaw_from_quaternion((q.x, q.y, q.z, q.w))
    radius = float(msg.radius)
    cov = shared_covariance(msg, rid)
    fault = cov if isinstance(cov, Rejection) else None
    body, unpadded = radius, fp
    if isinstance(cov, np.ndarray):
        pad = shared_padding(fp, widest_spread(cov, eps, math.inf))
        unpadded = fp - np.sign(fp) * pad
        body = float(np.max(np.hypot(unpadded[:, 0], unpadded[:, 1])))
    else:
        cov = None
    return Neighbour(
        rid, *pose, yaw, v.x, v.y, radius, fp, bool(msg.controlled), stamp, cov, body, fault,
        unpadded,
    )  # fmt: skip


@dataclass(frozen=True)
class NeighbourArrays:
    """The robots near one point, nearest first (map frame)."""

    ids: list[str]
    positions: np.ndarray  # (N, 2) m
    velocities: np.ndarray  # (N, 2) m/s
    radii: np.ndarray  # (N,) m
    controlled: np.ndarray  # (N,) bool
    robots: list[Neighbour]
    #: (N,) m: without the localization padding where a covariance came, else ``radii``
    body_radii: np.ndarray | None = None
    #: (N, 2, 2) m^2, zeros where none came
    covariances: np.ndarray | None = None


class NeighbourTable:
    """The newest state of every robot on ``/position_share`` (see the module doc).

    ``on_bad``: called with the `Rejection` of an entry `fresh` or `get` drop for being stamped
    in the future (messages rejected on arrival are returned by `update` instead)."""

    def __init__(
        self,
        last_seen_threshold: float = LAST_SEEN_THRESHOLD,
        frame: str = SHARED_FRAME,
        on_bad: Callable[[Rejection], None] | None = None,
        eps: float = EPS,
    ) -> None:
        self.last_seen_threshold = last_seen_threshold
        self.frame = frame
        self.eps = eps
        self.on_bad = on_bad
        self.robots: dict[str, Neighbour] = {}

    def update(self, msg: Any) -> Rejection | None:
        """Store a message; returns the reason when it was rejected."""
        got = neighbour_from_msg(msg, self.frame, self.eps)
        if isinstance(got, str):
            return got
        self.robots[got.robot_id] = got
        if got.covariance_fault is not None and self.on_bad is not None:
            self.on_bad(got.covariance_fault)
        return None

    def _usable(self, r: Neighbour, now: float) -> bool:
        """Fresh: not older than last_seen_threshold, not stamped beyond FUTURE_TOLERANCE."""
        if r.stamp - now > FUTURE_TOLERANCE:
            if self.on_bad is not None:
                self.on_bad(
                    Rejection(
                        r.robot_id,
                        "future",
                        f"robot '{r.robot_id}' shared a message stamped {r.stamp:.3f} s, "
                        f"{r.stamp - now:.3f} s ahead of this clock ({now:.3f} s; more than "
                        f"{FUTURE_TOLERANCE:g} s: its clock is not this one)",
                    )
                )
            return False
        return now - r.stamp <= self.last_seen_threshold

    def get(self, robot_id: str, now: float) -> Neighbour | None:
        """One robot's fresh entry, or None."""
        r = self.robots.get(robot_id)
        if r is None or not self._usable(r, now):
            return None
        return r

    def fresh(self, now: float) -> list[Neighbour]:
        """Every robot heard from within ``last_seen_threshold`` (and not stamped in the
        future); the others are dropped."""
        bad = [k for k, r in self.robots.items() if not self._usable(r, now)]
        for k in bad:
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
            body_radii=np.array([r.body_radius for r in rs], dtype=np.float64),
            covariances=np.array(
                [np.zeros((2, 2)) if r.covariance is None else r.covariance for r in rs],
                dtype=np.float64,
            ).reshape(-1, 2, 2),
        )


#: per runtime (one process of robots), the (robot, kind of fault) already warned about
_WARNED: weakref.WeakKeyDictionary[Any, set[tuple[str, str]]] = weakref.WeakKeyDictionary()


class PositionShare:
    """A node's subscription to ``/position_share`` feeding a `NeighbourTable`; a robot whose
    message is rejected is ignored, and warned about once per robot and kind of fault in the
    node's runtime (not once per listening node)."""

    def __init__(
        self, node: Any, last_seen_threshold: float = LAST_SEEN_THRESHOLD, eps: float = EPS
    ) -> None:
        self.node = node
        self.table = NeighbourTable(last_seen_threshold, on_bad=self.warn, eps=eps)
        self.rejected = 0
        self.sub = node.create_subscription(
            collvoid_msgs.PoseTwistWithCovariance, TOPIC, self.on_message, queue_size=0
        )

    def warn(self, problem: Rejection) -> None:
        """Warn about ``problem`` unless this runtime already has."""
        warned = _WARNED.setdefault(self.node.runtime, set())
        key = (problem.robot_id, problem.kind)
        if key not in warned:
            warned.add(key)
            self.node.get_logger().warning(f"{TOPIC}: ignoring {problem}")

    def on_message(self, msg: Any) -> None:
        problem = self.table.update(msg)
        if problem is not None:
            self.rejected += 1
            self.table.robots.pop(str(msg.robot_id or ""), None)
            self.warn(problem)
