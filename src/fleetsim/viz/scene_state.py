"""What a top-down view shows at one instant, built by feeding it recorded messages in order.

`SceneState.handle` takes messages one by one (any topic; unknown kinds are ignored) and keeps
the latest of each kind: the map, each robot's pose (through tf), its footprint, laser scans,
planned paths, particle clouds and goals, plus a trail of past positions. `SceneState.snapshot`
gives everything in the fixed frame as NumPy arrays, ready to draw.

tf is kept as the latest transform per frame (what a viewer shows, not tf's history), so
lookups never fail for being out of a time window.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from fleetsim.tf.transforms import matrix_from_transform
from fleetsim.viz.robots import BASE_FRAMES, footprint_from_params, robot_of_frame, robot_of_topic

#: seconds of sim time between two trail points
TRAIL_PERIOD = 0.2


class LatestTf:
    """Latest transform of every frame; lookups compose along the tree (no time travel)."""

    def __init__(self) -> None:
        self.parent: dict[str, str] = {}
        self.matrix: dict[str, np.ndarray] = {}

    def set(self, parent: str, child: str, translation: Any, rotation: Any) -> None:
        self.parent[child.lstrip("/")] = parent.lstrip("/")
        self.matrix[child.lstrip("/")] = matrix_from_transform(translation, rotation)

    def _to_root(self, frame: str) -> tuple[str, np.ndarray]:
        m = np.eye(4)
        seen = 0
        while frame in self.parent and seen < 64:  # 64: a loop guard
            m = self.matrix[frame] @ m
            frame = self.parent[frame]
            seen += 1
        return frame, m

    def lookup(self, target: str, source: str) -> np.ndarray | None:
        """The 4x4 matrix mapping points in ``source`` into ``target``, or None."""
        root_t, m_t = self._to_root(target.lstrip("/"))
        root_s, m_s = self._to_root(source.lstrip("/"))
        if root_t != root_s:
            return None
        return np.linalg.solve(m_t, m_s)


def planar_points(m: np.ndarray, xy: np.ndarray) -> np.ndarray:
    """Points (N, 2) in a source frame (z = 0) mapped by the 4x4 ``m``: (N, 2) in the target."""
    return xy @ m[:2, :2].T + m[:2, 3]


def _pose_xy_yaw(pose: Any) -> tuple[float, float, float]:
    q = pose.orientation
    yaw = np.arctan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))
    return pose.position.x, pose.position.y, float(yaw)


def _poses_array(poses: list) -> np.ndarray:
    """(N, 3) of x, y, yaw for a list of geometry_msgs/Pose."""
    return np.array([_pose_xy_yaw(p) for p in poses], dtype=float).reshape(-1, 3)


def transform_poses(m: np.ndarray, poses: np.ndarray) -> np.ndarray:
    """(N, 3) planar poses (x, y, yaw) mapped by the 4x4 ``m`` into its target frame."""
    xy = planar_points(m, poses[:, :2])
    dyaw = np.arctan2(m[1, 0], m[0, 0])
    return np.column_stack([xy, poses[:, 2] + dyaw])


@dataclass
class RobotView:
    """One robot at one instant, in the fixed frame: pose, footprint outline, trail."""

    name: str
    index: int
    pose: np.ndarray  # (3,) x, y, yaw
    outline: np.ndarray  # (K, 2) footprint polygon, fixed frame
    trail: np.ndarray  # (T, 2)


@dataclass
class Snapshot:
    """Everything to draw at one instant, in the fixed frame; arrays in metres and radians."""

    time_s: float
    map: Any = None  # nav_msgs/OccupancyGrid or None
    robots: list[RobotView] = field(default_factory=list)
    scans: dict[str, np.ndarray] = field(default_factory=dict)  # robot -> (N, 2)
    paths: dict[str, np.ndarray] = field(default_factory=dict)  # topic -> (N, 2)
    particles: dict[str, np.ndarray] = field(default_factory=dict)  # topic -> (N, 3)
    goals: dict[str, np.ndarray] = field(default_factory=dict)  # robot -> (3,)


class SceneState:
    """Accumulates recorded messages into the latest scene.

    Parameters
    ----------
    fixed_frame : the frame everything is drawn in (``map``).
    params : the run's parameter tree (for footprints), e.g. ``BagReader.params()``.
    map_topic : the OccupancyGrid drawn as the background.
    """

    def __init__(self, fixed_frame: str = "map", params: dict | None = None, map_topic="/map"):
        self.fixed_frame = fixed_frame
        self.params = params or {}
        self.map_topic = map_topic
        self.tf = LatestTf()
        self.map: Any = None
        self.robots: dict[str, str] = {}  # robot -> base frame
        self.robot_index: dict[str, int] = {}
        self.footprints: dict[str, np.ndarray] = {}  # robot -> (K, 2) base frame
        self.footprint_topics: dict[str, tuple[str, np.ndarray]] = {}  # robot -> (frame, pts)
        self.scans: dict[str, tuple[str, np.ndarray]] = {}  # topic -> (frame, (N, 2))
        self.paths: dict[str, tuple[str, np.ndarray]] = {}
        self.particles: dict[str, tuple[str, np.ndarray]] = {}
        self.goals: dict[str, tuple[str, np.ndarray]] = {}  # robot -> (frame, (1, 3))
        self.trails: dict[str, list[tuple[float, float]]] = {}
        self.time_ns = 0
        self._next_trail_ns = 0

    # -- feeding ----------------------------------------------------------------------------
    def handle(self, topic: str, typename: str, msg: Any, log_time_ns: int) -> None:
        """Take one message (in log-time order)."""
        self.time_ns = max(self.time_ns, log_time_ns)
        handler = _HANDLERS.get(typename)
        if handler is not None:
            handler(self, topic, msg)
        elif hasattr(msg, "goal") and hasattr(msg.goal, "target_pose"):  # MoveBaseActionGoal
            self._on_goal(topic, msg.goal.target_pose)
        if self.time_ns >= self._next_trail_ns:
            self._sample_trails()
            self._next_trail_ns = self.time_ns + round(TRAIL_PERIOD * 1e9)

    def _on_tf(self, topic: str, msg: Any) -> None:
        for t in msg.transforms:
            tr, q = t.transform.translation, t.transform.rotation
            child = t.child_frame_id.lstrip("/")
            self.tf.set(t.header.frame_id, child, (tr.x, tr.y, tr.z), (q.x, q.y, q.z, q.w))
            robot = robot_of_frame(child)
            if robot is not None:
                have = self.robots.get(robot)
                if have is None or BASE_FRAMES.index(child.rpartition("/")[2]) < BASE_FRAMES.index(
                    have.rpartition("/")[2]
                ):
                    self.robots[robot] = child
                if robot not in self.robot_index:
                    self.robot_index[robot] = len(self.robot_index)
                    self.footprints[robot] = footprint_from_params(self.params, robot)

    def _on_grid(self, topic: str, msg: Any) -> None:
        if topic == self.map_topic:
            self.map = msg

    def _on_scan(self, topic: str, msg: Any) -> None:
        r = np.asarray(msg.ranges, dtype=float)
        a = msg.angle_min + msg.angle_increment * np.arange(r.shape[0])
        ok = np.isfinite(r) & (r >= msg.range_min) & (r <= msg.range_max)
        pts = np.column_stack([r[ok] * np.cos(a[ok]), r[ok] * np.sin(a[ok])])
        self.scans[topic] = (msg.header.frame_id, pts)

    def _on_path(self, topic: str, msg: Any) -> None:
        frame, pts = msg.header.frame_id, _poses_array([p.pose for p in msg.poses])[:, :2]
        # placed with the tf of its own time (as rviz does with the stamp), so a plan in a
        # drifting frame (odom) stays where it was planned instead of following later drift
        xy = self._in_fixed(frame, pts)
        self.paths[topic] = (frame, pts) if xy is None else (self.fixed_frame, xy)

    def _on_pose_array(self, topic: str, msg: Any) -> None:
        self.particles[topic] = (msg.header.frame_id, _poses_array(msg.poses))

    def _on_pose_stamped(self, topic: str, msg: Any) -> None:
        if topic.rstrip("/").endswith("goal"):
            self._on_goal(topic, msg)

    def _on_goal(self, topic: str, msg: Any) -> None:
        self.goals[robot_of_topic(topic)] = (msg.header.frame_id, _poses_array([msg.pose]))

    def _on_polygon(self, topic: str, msg: Any) -> None:
        if topic.rstrip("/").endswith("footprint") and len(msg.polygon.points) >= 3:
            pts = np.array([(p.x, p.y) for p in msg.polygon.points], dtype=float)
            self.footprint_topics[robot_of_topic(topic)] = (msg.header.frame_id, pts)

    def _sample_trails(self) -> None:
        for robot, base in self.robots.items():
            m = self.tf.lookup(self.fixed_frame, base)
            if m is not None:
                self.trails.setdefault(robot, []).append((m[0, 3], m[1, 3]))

    # -- reading ----------------------------------------------------------------------------
    def _in_fixed(self, frame: str, pts: np.ndarray, poses: bool = False) -> np.ndarray | None:
        m = self.tf.lookup(self.fixed_frame, frame) if frame else np.eye(4)
        if m is None:
            return None
        return transform_poses(m, pts) if poses else planar_points(m, pts)

    def snapshot(self) -> Snapshot:
        """The scene now, in the fixed frame (things whose frame is not connected are left out)."""
        snap = Snapshot(self.time_ns / 1e9, self.map)
        for robot, base in self.robots.items():
            m = self.tf.lookup(self.fixed_frame, base)
            if m is None:
                continue
            pose = transform_poses(m, np.zeros((1, 3)))[0]
            outline = None
            if robot in self.footprint_topics:  # costmap footprints are already placed
                frame, pts = self.footprint_topics[robot]
                outline = self._in_fixed(frame, pts)
            if outline is None:
                outline = planar_points(m, self.footprints[robot])
            trail = np.array(self.trails.get(robot, []), dtype=float).reshape(-1, 2)
            snap.robots.append(RobotView(robot, self.robot_index[robot], pose, outline, trail))
        for frame, pts in self.scans.values():
            xy = self._in_fixed(frame, pts)
            if xy is not None:
                robot = robot_of_frame_prefix(frame)
                prev = snap.scans.get(robot)
                snap.scans[robot] = xy if prev is None else np.vstack([prev, xy])
        for topic, (frame, pts) in self.paths.items():
            if (xy := self._in_fixed(frame, pts)) is not None:
                snap.paths[topic] = xy
        for topic, (frame, poses) in self.particles.items():
            if (p := self._in_fixed(frame, poses, poses=True)) is not None:
                snap.particles[topic] = p
        for robot, (frame, pose) in self.goals.items():
            if (p := self._in_fixed(frame, pose, poses=True)) is not None:
                snap.goals[robot] = p[0]
        return snap

    def bounds(self) -> tuple[float, float, float, float] | None:
        """(xmin, xmax, ymin, ymax) of the map, else of trails and goals so far; None if empty."""
        if self.map is not None:
            info = self.map.info
            x0, y0 = info.origin.position.x, info.origin.position.y
            return x0, x0 + info.width * info.resolution, y0, y0 + info.height * info.resolution
        pts = [np.asarray(t, dtype=float).reshape(-1, 2) for t in self.trails.values()]
        snap = self.snapshot()
        pts += [g[None, :2] for g in snap.goals.values()] + [r.outline for r in snap.robots]
        pts = [p for p in pts if p.size]
        if not pts:
            return None
        allp = np.vstack(pts)
        lo, hi = allp.min(axis=0), allp.max(axis=0)
        return float(lo[0]), float(hi[0]), float(lo[1]), float(hi[1])


_HANDLERS = {
    "tf2_msgs/msg/TFMessage": SceneState._on_tf,
    "nav_msgs/msg/OccupancyGrid": SceneState._on_grid,
    "sensor_msgs/msg/LaserScan": SceneState._on_scan,
    "nav_msgs/msg/Path": SceneState._on_path,
    "geometry_msgs/msg/PoseArray": SceneState._on_pose_array,
    "geometry_msgs/msg/PoseStamped": SceneState._on_pose_stamped,
    "geometry_msgs/msg/PolygonStamped": SceneState._on_polygon,
}


def robot_of_frame_prefix(frame: str) -> str:
    """The tf prefix of a frame (``lizi1/base_laser`` -> ``lizi1``; ``laser`` -> ``""``)."""
    return frame.lstrip("/").rpartition("/")[0]
