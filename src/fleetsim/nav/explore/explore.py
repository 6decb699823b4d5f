"""The ``explore_lite/explore`` node: greedy frontier exploration over move_base.

Every ``1 / planner_frequency`` s the node finds the frontiers of the costmap it subscribes to
(``costmap_topic``, usually ``move_base/global_costmap/costmap``), drops those on its blacklist
(within 5 cells of a goal that failed), and sends the cheapest frontier's centroid to
``move_base``. A goal move_base aborts is blacklisted; so is one the robot makes no progress
towards (its distance to the frontier's nearest cell does not shrink) for ``progress_timeout``
s. When no frontier is left the node stops (``finished``), as explore_lite does ("All
frontiers traversed/tried out, stopping"). With ``visualize`` it publishes ``~frontiers``
(visualization_msgs/MarkerArray).

For ``fleetsim launch --until-goals`` the node is a goal sender (`fleetsim.launch.monitor.
GoalSender`: ``sends_goals``, ``done`` once it has stopped): the run ends when exploration
does. Exploration *finished* (``succeeded``, exit status 0) when it stopped because the map has
no frontier left; it *gave up* (``gave_up``, exit status 1) when it stopped with frontiers left,
every one of them blacklisted, by it or (``peer_blacklists``) by a peer (move_base aborted the
goal, or no progress for ``progress_timeout``). A frontier blacklisted on the way that the
robot's laser later maps from elsewhere is no longer a frontier and does not count.
explore_lite stops either way; a goal it cancels itself (on stopping, or to wait while a peer
takes the frontiers left) is listed in ``withdrawn_goals``, so that the run monitor does not
count it as a failed goal.

Explorers sharing one map (slam_explore ``robots:=2``) would all head for the same best
frontier; fleetsim adds ``peer_goals``: each explorer announces its goal on ``~goal`` and leaves
frontiers within ``peer_radius`` of a peer's goal to that peer, unless every frontier is; with
``peer_frames`` (the peers' base frames, found in the shared map through tf) it also leaves to
a peer every frontier whose centroid is nearer to that peer than to itself, so that each
robot takes the frontiers on its side instead of both heading for the same region (the pair of
hunters crossed the office's corridor to each other's end); ``switch_distance`` keeps it on the
frontier it heads for unless another is clearly cheaper; each explorer publishes its blacklist
on ``~blacklist`` (geometry_msgs/PoseArray) and skips the frontiers its peers blacklisted
(``peer_blacklists``: two hunters each gave up on a corner of the office and then crossed the
office to the corner the other had given up on); ``path_costs`` measures a frontier by the
distance the robot drives to it (navfn's wavefront over the costmap,
`fleetsim.nav.explore.path_costs`), for ranking and, with peers, for which robot is nearer
(a straight line through a wall gave a robot the next room's frontiers). With
``switch_distance`` the progress clock keeps running while the frontier it heads for only
shrinks (its centroid creeping); explore_lite restarts it whenever the goal point moves. The
rules: `fleetsim.nav.explore.peers`.

``costmap_updates_topic`` is accepted but fleetsim's costmaps publish whole grids only (see
`fleetsim.nav.costmap.costmap_ros`), so it is not subscribed. ``orientation_scale`` is accepted
and, as in explore_lite, unused.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from fleetsim.errors import FleetsimError
from fleetsim.msgs import geometry_msgs, move_base_msgs, nav_msgs, std_msgs, visualization_msgs
from fleetsim.nav.move_base_support import pose_stamped
from fleetsim.runtime import Node, param
from fleetsim.tf.names import resolve_frame_once

from .frontier_search import Frontier, frontiers_from_grid
from .path_costs import by_path
from .peers import frontier_for_robot, tracked_frontier

BLACKLIST_RADIUS_CELLS = 5  # explore_lite's goalOnBlacklist tolerance
SUCCEEDED, ABORTED = 3, 4


@dataclass(frozen=True)
class ExploreParams:
    """explore_lite's parameters (ROS names and defaults)."""

    robot_base_frame: str = param("base_link", help="robot base frame (tf_prefix applied)")
    costmap_topic: str = param("costmap", help="nav_msgs/OccupancyGrid to explore")
    costmap_updates_topic: str = param(
        "costmap_updates", help="accepted; fleetsim's costmaps publish whole grids"
    )
    visualize: bool = param(False, help="publish frontiers as markers on ~frontiers")
    planner_frequency: float = param(1.0, unit="Hz", range=(1e-3, None), help="replanning rate")
    progress_timeout: float = param(
        30.0, unit="s", range=(0.0, None), help="blacklist a goal without progress this long"
    )
    potential_scale: float = param(1e-3, range=(0.0, None), help="weight of frontier distance")
    orientation_scale: float = param(0.0, range=(0.0, None), help="unused, as in explore_lite")
    gain_scale: float = param(1.0, range=(0.0, None), help="weight of frontier size")
    transform_tolerance: float = param(
        0.3, unit="s", range=(0.0, None), help="oldest robot pose (tf) used to plan"
    )
    min_frontier_size: float = param(
        0.5, unit="m", range=(0.0, None), help="smallest frontier considered"
    )
    # fleetsim additions: explorers that share a map leave each other's frontiers alone
    peer_goals: list = param([], help="other explorers' ~goal topics (geometry_msgs/PointStamped)")
    peer_radius: float = param(
        3.0, unit="m", range=(0.0, None), help="frontiers this close to a peer's goal are its"
    )
    peer_frames: list = param(
        [], help="other explorers' base frames: frontiers nearer to one of them are its"
    )
    peer_blacklists: list = param(
        [], help="other explorers' ~blacklist topics (geometry_msgs/PoseArray): skipped too"
    )
    switch_distance: float = param(
        0.0,
        unit="m",
        range=(0.0, None),
        help="keep the frontier it heads for unless another is cheaper by this much distance",
    )
    path_costs: bool = param(
        False,
        help="measure frontiers by the distance driven (navfn's wavefront), not straight lines",
    )


class Explore(Node):
    """Frontier exploration for one robot namespace."""

    Params = ExploreParams
    sends_goals = True  # the run monitor waits for `done`

    def __init__(self, runtime, name: str = "explore", namespace: str = "/", **kw: Any) -> None:
        super().__init__(runtime, name, namespace, **kw)
        p: ExploreParams = self.params
        self.base_frame = resolve_frame_once(self.tf_prefix, p.robot_base_frame)
        self.grid: nav_msgs.OccupancyGrid | None = None
        self.blacklist: list[tuple[float, float]] = []
        self.goal: tuple[float, float] | None = None
        self.finished = False
        #: stopped with frontiers left, all blacklisted (see the module docstring)
        self.gave_up = False
        #: ids of the goals it canceled itself: on stopping, or to wait while a peer takes the
        #: frontiers left (for the run monitor, which does not count them as failed)
        self.withdrawn_goals: set[str] = set()
        self.goals_sent = 0
        self._handle: Any = None
        self._best_distance = math.inf
        self._last_progress = 0.0
        self.frontiers: list[Frontier] = []
        self.peers: dict[str, tuple[float, float] | None] = {}
        self.goal_pub = self.create_publisher(geometry_msgs.PointStamped, "~goal", 1, latch=True)
        self.blacklist_pub = self.create_publisher(
            geometry_msgs.PoseArray, "~blacklist", 1, latch=True
        )
        self.peer_blacklists: dict[str, list[tuple[float, float]]] = {}
        for topic in p.peer_blacklists:
            self.peer_blacklists[str(topic)] = []
            self.create_subscription(
                geometry_msgs.PoseArray,
                str(topic),
                lambda m, t=str(topic): self.on_peer_blacklist(t, m),
                1,
            )
        for topic in p.peer_goals:
            self.peers[str(topic)] = None
            self.create_subscription(
                geometry_msgs.PointStamped,
                str(topic),
                lambda m, t=str(topic): self.on_peer(t, m),
                1,
            )
        _ = self.tf_buffer  # subscribe the runtime's buffer to /tf now
        self.create_subscription(nav_msgs.OccupancyGrid, p.costmap_topic, self.on_costmap, 1)
        self.move_base = self.create_action_client(move_base_msgs.MoveBase, "move_base")
        self.marker_pub = (
            self.create_publisher(visualization_msgs.MarkerArray, "~frontiers", 1)
            if p.visualize
            else None
        )
        self.timer = self.create_timer(1.0 / p.planner_frequency, self.make_plan)

    @property
    def done(self) -> bool:
        return self.finished

    @property
    def succeeded(self) -> bool:
        """Stopped with no frontier left (False while exploring, or when it gave up)."""
        return self.finished and not self.gave_up

    def on_costmap(self, msg: nav_msgs.OccupancyGrid) -> None:
        self.grid = msg

    def on_peer(self, topic: str, msg: geometry_msgs.PointStamped) -> None:
        x, y = msg.point.x, msg.point.y
        self.peers[topic] = (x, y) if math.isfinite(x) and math.isfinite(y) else None

    def on_peer_blacklist(self, topic: str, msg: geometry_msgs.PoseArray) -> None:
        self.peer_blacklists[topic] = [(q.position.x, q.position.y) for q in msg.poses]

    def _blacklist(self, goal: tuple[float, float]) -> None:
        """Blacklist a goal and tell the peers (~blacklist)."""
        self.blacklist.append(goal)
        frame = self.grid.header.frame_id if self.grid is not None else ""
        self.blacklist_pub.publish(
            geometry_msgs.PoseArray(
                header=std_msgs.Header(stamp=self.now_msg(), frame_id=frame),
                poses=[
                    geometry_msgs.Pose(position=geometry_msgs.Point(x=float(x), y=float(y)))
                    for x, y in self.blacklist
                ],
            )
        )

    def _withdraw_goal(self) -> None:
        """Cancel the active goal, if any, as no longer wanted: listed in ``withdrawn_goals``
        so that the run monitor does not count the cancel as a failed goal."""
        if self._handle is not None:
            self.withdrawn_goals.add(self._handle.id)
            self.move_base.cancel_all_goals()
            self._handle = None

    def _announce(self, goal: tuple[float, float] | None, frame: str = "") -> None:
        """Publish the goal on ~goal for peer explorers (NaN: none)."""
        x, y = goal if goal is not None else (math.nan, math.nan)
        self.goal_pub.publish(
            geometry_msgs.PointStamped(
                header=std_msgs.Header(stamp=self.now_msg(), frame_id=frame),
                point=geometry_msgs.Point(x=float(x), y=float(y), z=0.0),
            )
        )

    def _robot_position(self, frame: str) -> tuple[float, float] | None:
        """The robot's newest x, y in ``frame``; None (warned) when tf does not know it, or when
        that pose is older than ``transform_tolerance`` (explore_lite's getRobotPose: a stale
        pose would pick frontiers, and measure progress, from where the robot was)."""
        buf = self.tf_buffer
        try:
            x, y, _ = buf.lookup_pose2d(frame, self.base_frame, 0.0)
            stamp = buf.latest_common_time(frame, self.base_frame)
        except FleetsimError as err:
            self._warn_once("tf", f"cannot find the robot ({self.base_frame}) in {frame}: {err}")
            return None
        now, tolerance = self.now(), self.params.transform_tolerance
        if stamp > 0 and now - stamp > tolerance:  # stamp 0: static transforms only
            self._warn_once(
                "tf timeout",
                f"robot pose ({self.base_frame} in {frame}) is {now - stamp:.3f} s old, more "
                f"than transform_tolerance {tolerance} s: not exploring until tf catches up",
            )
            return None
        self._warned.discard("tf timeout")
        return x, y

    def _peer_positions(self, frame: str) -> list[tuple[float, float]]:
        """Where the peers in ``peer_frames`` are in ``frame`` (those tf knows)."""
        out = []
        for peer in self.params.peer_frames:
            try:
                x, y, _ = self.tf_buffer.lookup_pose2d(frame, str(peer).lstrip("/"), 0.0)
            except FleetsimError as err:
                self._warn_once(f"peer {peer}", f"cannot find the peer {peer} in {frame}: {err}")
                continue
            out.append((x, y))
        return out

    def make_plan(self) -> None:
        """explore_lite's makePlan: pick the best frontier, watch progress, send the goal."""
        if self.finished or self.grid is None:
            return
        grid = self.grid
        frame = grid.header.frame_id
        robot = self._robot_position(frame)
        if robot is None:
            return
        info = grid.info
        data = np.asarray(grid.data, dtype=np.int8).reshape(info.height, info.width)
        p = self.params
        self.frontiers = frontiers_from_grid(
            data,
            info.resolution,
            (info.origin.position.x, info.origin.position.y),
            robot,
            p.potential_scale,
            p.gain_scale,
            p.min_frontier_size,
        )
        if self.marker_pub is not None:
            self._publish_markers(frame)
        tolerance = BLACKLIST_RADIUS_CELLS * info.resolution
        blacklist = [*self.blacklist, *itertools.chain(*self.peer_blacklists.values())]
        candidates = [
            f
            for f in self.frontiers
            if not any(math.dist(f.centroid, b) < tolerance for b in blacklist)
        ]
        if not candidates:
            self.stop("all frontiers traversed/tried out, stopping")
            return
        positions = self._peer_positions(frame)
        distances = None
        if p.path_costs:
            origin = (info.origin.position.x, info.origin.position.y)
            candidates, distances = by_path(
                data, info.resolution, origin, candidates, [robot, *positions],
                p.potential_scale, p.gain_scale,
            )  # fmt: skip
        chosen = frontier_for_robot(
            candidates,
            robot,
            self.goal,
            [g for g in self.peers.values() if g is not None],
            positions,
            p.peer_radius,
            p.potential_scale * info.resolution * p.switch_distance,
            distances,
        )
        if chosen is None:  # the peers have every frontier left: wait for them
            self._withdraw_goal()
            if self.goal is not None:
                self.goal = None
                self._announce(None)
            return
        target = chosen.centroid
        same = self.goal is not None and math.dist(target, self.goal) < 1e-6
        # with switch_distance the frontier it heads for is tracked as its centroid moves
        # (peers.tracked_frontier); explore_lite restarts the progress clock whenever the goal point
        # moves, and a frontier whose centroid crept a few cm every plan then kept a robot
        # that could not get to it busy indefinitely (office, two hunters, seed 2: hunter1
        # 112 s at a door, resent six goals on one frontier, each restarting move_base too)
        kept = same or (
            p.switch_distance > 0.0
            and self.goal is not None
            and chosen is tracked_frontier(candidates, self.goal)
        )
        # progress as explore_lite measures it: towards the frontier's nearest cell (its
        # centroid may lie behind a wall the robot has to go round)
        distance = chosen.min_distance
        now = self.now()
        if not kept or distance < self._best_distance:
            self._best_distance = distance
            self._last_progress = now
        if kept and now - self._last_progress > p.progress_timeout:
            self.get_logger().info(f"no progress towards {target} for {p.progress_timeout} s")
            self._blacklist(target)
            self.goal = None
            self.make_plan()
            return
        if same and self._handle is not None:
            return
        self._send(target, frame)

    def _send(self, target: tuple[float, float], frame: str) -> None:
        if not self.move_base.wait_for_server():
            self._warn_once("move_base", f"waiting for move_base at {self.move_base.name}")
            return
        self.goal = target
        self._announce(target, frame)
        pose = pose_stamped(target[0], target[1], 0.0, frame, self.now_msg())
        self.goals_sent += 1
        self._handle = self.move_base.send_goal(
            move_base_msgs.MoveBaseGoal(target_pose=pose),
            done_cb=lambda h, goal=target: self._on_done(goal, h.status),
        )

    def _on_done(self, goal: tuple[float, float], status: int) -> None:
        if self.goal != goal:
            return  # an older goal, replaced meanwhile
        self._handle = None
        if status == ABORTED:
            self.get_logger().info(f"move_base aborted the goal {goal}; blacklisting it")
            self._blacklist(goal)
        self.goal = None
        self._announce(None)
        self.runtime.call_later(0.0, self.make_plan)  # explore_lite replans on reaching a goal

    def stop(self, why: str) -> None:
        self.finished = True
        self.gave_up = bool(self.frontiers)  # what is left is all blacklisted
        if self.gave_up:
            why += f" (gave up: {len(self.frontiers)} frontiers left, all blacklisted)"
        self._withdraw_goal()
        self.timer.cancel()
        self._announce(None)
        self.get_logger().info(why)

    def _publish_markers(self, frame: str) -> None:
        header = std_msgs.Header(stamp=self.now_msg(), frame_id=frame)
        markers = [
            visualization_msgs.Marker(header=header, action=visualization_msgs.Marker.DELETEALL)
        ]
        for i, f in enumerate(self.frontiers):
            markers.append(
                visualization_msgs.Marker(
                    header=header,
                    ns="frontiers",
                    id=i,
                    type=visualization_msgs.Marker.POINTS,
                    scale=geometry_msgs.Vector3(x=0.1, y=0.1, z=0.1),
                    color=std_msgs.ColorRGBA(r=1.0, g=0.0, b=0.0, a=1.0),
                    points=[
                        geometry_msgs.Point(x=float(x), y=float(y), z=0.0) for x, y in f.points
                    ],
                )
            )
        self.marker_pub.publish(visualization_msgs.MarkerArray(markers=markers))
