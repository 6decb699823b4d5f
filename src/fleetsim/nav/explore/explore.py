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
count it as a failed goal, and one move_base aborted (its frontier blacklisted) in
``handled_goals``, so that it does not fail a run whose exploration finished.

Explorers sharing one map (slam_explore ``robots:=2``) would all head for the same frontier;
fleetsim's additions share the frontiers out (`fleetsim.nav.explore.peers` gives the rules and
why): each announces its goal on ``~goal`` and its blacklist on ``~blacklist``
(geometry_msgs/PoseArray) and reads its peers' (``peer_goals``, ``peer_blacklists``); frontiers
near a peer's goal (``peer_radius``) or nearer to a peer (``peer_frames``, through tf) are the
peer's; ``switch_distance`` keeps the frontier it heads for unless another is clearly cheaper
(and keeps the progress clock running while that frontier only creeps); ``path_costs``
measures frontiers by the distance driven (`fleetsim.nav.explore.path_costs`).

With ``view_points`` (a fleetsim addition, off by default; slam_explore sets it) each frontier's
goal is the nearest point the robot can drive to that sees it (within ``view_range``) instead of
its centroid, progress is measured as the distance driven to that point, and a frontier still
there after the robot has stood at its view point is *observed as far as it can be*: left, and
not counted as given up, so exploration that ends with only such frontiers left finished
(``succeeded``; ``observed`` counts them); one left because move_base aborted, or made no
progress to, its view point is still given up. Each explorer publishes the view points it stood
at on ``~observed`` (geometry_msgs/PoseArray) and reads its peers' (``peer_observed``). Why and
how: `fleetsim.nav.explore.view_points`. With ``blacklist_retries`` (a fleetsim addition, 0 by
default) the frontiers left, all blacklisted, are tried again that many times before it gives up.

``costmap_updates_topic`` is accepted but fleetsim's costmaps publish whole grids only (see
`fleetsim.nav.costmap.costmap_ros`), so it is not subscribed. ``orientation_scale`` is accepted
and, as in explore_lite, unused.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import replace
from typing import Any

import numpy as np

from fleetsim.errors import FleetsimError
from fleetsim.msgs import move_base_msgs, nav_msgs, std_msgs, visualization_msgs
from fleetsim.nav.move_base_support import pose_stamped
from fleetsim.runtime import Node
from fleetsim.tf.names import resolve_frame_once

from .frontier_search import Frontier, frontiers_from_grid, known_window
from .markers import frontier_markers
from .params import ExploreParams
from .path_costs import by_path, path_distance_field
from .peers import PeerLink, frontier_for_robot, tracked_frontier
from .view_points import cell_value, view_point

BLACKLIST_RADIUS_CELLS = 5  # explore_lite's goalOnBlacklist tolerance
SUCCEEDED, ABORTED = 3, 4
#: m: a way to the goal this much longer than at the last plan was blocked by the map
#: (view_points; fleetsim.nav.explore.view_points)
REROUTE_JUMP = 1.0


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
        self.handled_goals: set[str] = set()  # aborted by move_base, blacklisted, moved on
        self.goals_sent = 0
        #: times the blacklist was cleared (blacklist_retries)
        self.retries = 0
        #: view points move_base reached (view_points), and the peers' (peer_observed), with
        #: when (sim s; a peer's list at the time it was published)
        self.stood_at: list[tuple[float, float, float]] = []
        #: with peers: goals whose frontier closed in this robot's own costmap on the way (told
        #: to the peers with the view points stood at; see `make_plan`)
        self.closed_at: list[tuple[float, float]] = []
        self._grid_time = 0.0
        #: frontiers left when it stopped that were observed as far as they can be
        self.observed = 0
        self._handle: Any = None
        self._best_distance = math.inf
        self._last_distance = math.inf
        self._last_progress = 0.0
        self.frontiers: list[Frontier] = []
        self.link = PeerLink(self, p)  # what it tells its peers, and what they tell it
        _ = self.tf_buffer  # subscribe the runtime's buffer to /tf now
        self._costmap_sub = self.create_subscription(
            nav_msgs.OccupancyGrid, p.costmap_topic, self.on_costmap, 1
        )
        # explore_lite says "Waiting for costmap to become available"; a costmap_topic nobody
        # publishes (the default 'costmap' beside move_base's) had waited unsaid
        self.warn_while_silent(
            self._costmap_sub,
            lambda: self.grid is not None,
            "no costmap",
            "not exploring until one comes (set costmap_topic, e.g. "
            "move_base/global_costmap/costmap)",
        )
        self._seen_unknown = False  # a costmap it read had unknown space (see make_plan)
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
        self._grid_time = self.now()

    def _publish_observed(self) -> None:
        stood = [(x, y) for x, y, _ in self.stood_at]
        self._publish_points(self.link.observed_pub, [*stood, *self.closed_at])

    def _blacklist(self, goal: tuple[float, float]) -> None:
        """Blacklist a goal and tell the peers (~blacklist)."""
        self.blacklist.append(goal)
        self._publish_points(self.link.blacklist_pub, self.blacklist)

    def _publish_points(self, pub, points: list[tuple[float, float]]) -> None:
        frame = self.grid.header.frame_id if self.grid is not None else ""
        self.link.publish_points(pub, points, frame)

    def _withdraw_goal(self) -> None:
        """Cancel the active goal, if any, as no longer wanted: listed in ``withdrawn_goals``
        so that the run monitor does not count the cancel as a failed goal."""
        if self._handle is not None:
            self.withdrawn_goals.add(self._handle.id)
            self.move_base.cancel_all_goals()
            self._handle = None

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
        self._seen_unknown = self._seen_unknown or bool((data == -1).any())
        if not self._seen_unknown:
            # a costmap without unknown space has no frontier from the start: explore_lite
            # would stop at once as if the world were explored, and the run had looked done
            self._warn_once(
                "no unknown",
                f"the costmap on {self._costmap_sub.topic.name} has no unknown cell: there is no "
                "frontier to explore; unless the map is known already, the costmap does not keep "
                "unknown space (set track_unknown_space: true, as explore_lite requires)",
            )
            self.stop("stopping: nothing unknown to explore", failed=True)
            return
        positions = self._peer_positions(frame)
        # the grid's known part, not gmapping's whole xmin..ymax (known_window says why)
        data, origin = known_window(
            data,
            info.resolution,
            (info.origin.position.x, info.origin.position.y),
            [robot, *positions],
        )
        self.frontiers = frontiers_from_grid(
            data,
            info.resolution,
            origin,
            robot,
            p.potential_scale,
            p.gain_scale,
            p.min_frontier_size,
        )
        if self.marker_pub is not None:
            self._publish_markers(frame)
        if (
            self.goal is not None
            and self.link.goals
            and self.goal not in self.closed_at
            and tracked_frontier(self.frontiers, self.goal) is None
        ):
            # the frontier it heads for closed in its own costmap, whose obstacle layer clears
            # and marks from its own laser; the merged map a peer's costmap reads may never
            # show it (gmapping's map), and the peer then drove to it (office pair, seed 7:
            # hunter2's last two desk-strip frontiers closed for it at 344 and 356 s, stayed
            # open for hunter1, which drove 12 m to them at 392 s and ended the run at 468 s).
            # Told to the peers as observed, as a view point stood at is
            self.closed_at.append(self.goal)
            self._publish_observed()
        field = None
        if p.view_points:
            field = path_distance_field(data, info.resolution, origin, robot, allow_unknown=True)
            self.frontiers = [
                replace(f, view_point=view_point(field, data, info.resolution, origin, f,
                                                 p.view_range))
                for f in self.frontiers
            ]  # fmt: skip
        tolerance = BLACKLIST_RADIUS_CELLS * info.resolution
        blacklist = [*self.blacklist, *itertools.chain(*self.link.blacklists.values())]
        # view points stood at long enough ago for this map to show what was seen from there
        settled = self._grid_time - p.observe_delay
        stood = [
            (x, y)
            for x, y, t in itertools.chain(self.stood_at, *self.link.stood_at.values())
            if t <= settled
        ]
        observed = [
            f
            for f in self.frontiers
            if f.view_point is not None and any(math.dist(f.goal, s) < tolerance for s in stood)
        ]
        candidates = [
            f
            for f in self.frontiers
            if not any(math.dist(f.goal, b) < tolerance for b in blacklist)
            and not any(f is o for o in observed)
        ]
        if not candidates:
            if any(g is not None for g in self.link.goals.values()):
                # a peer still explores: the merged map it makes may open a way or move a view
                # point (a frontier "observed" from inside a room whose door the map had not yet
                # opened; office, two hunters with the hunter's outline as footprint: hunter2
                # stopped 30 s in and stood in its room while hunter1 explored the rest), so
                # wait for it rather than stop, as when the peers have every frontier left
                self._wait()
                return
            given_up = len(self.frontiers) - len(observed)
            if given_up and self.retries < p.blacklist_retries:
                # blacklisted on the way by a robot stuck at a door for progress_timeout, or a
                # goal move_base aborted while the map was wrong: tried again once nothing
                # else is left (office seed 1: the north-west room's last frontier, given up
                # at 584 s, 30 s in a door, was all that was left at 1080 s)
                self.retries += 1
                self.get_logger().info(f"trying the {given_up} blacklisted frontiers again")
                self.blacklist.clear()
                self._publish_points(self.link.blacklist_pub, self.blacklist)
                self.link.blacklists.update(dict.fromkeys(self.link.blacklists, ()))
                self.make_plan()
                return
            self.stop("all frontiers traversed/tried out, stopping", len(observed))
            return
        distances = None
        if p.path_costs:
            candidates, distances = by_path(
                data, info.resolution, origin, candidates, [robot, *positions],
                p.potential_scale, p.gain_scale,
            )  # fmt: skip
        chosen = frontier_for_robot(
            candidates,
            robot,
            self.goal,
            [g for g in self.link.goals.values() if g is not None],
            positions,
            p.peer_radius,
            p.potential_scale * info.resolution * p.switch_distance,
            distances,
        )
        if chosen is None:  # the peers have every frontier left: wait for them
            self._wait()
            return
        target = chosen.goal
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
        # centroid may lie behind a wall the robot has to go round); with view_points, along
        # the way navfn plans to the view point (the straight line grows on the way out of one
        # room and into the next: see fleetsim.nav.explore.view_points)
        distance = chosen.min_distance
        rerouted = False
        if field is not None and chosen.view_point is not None:
            along = cell_value(field, info.resolution, origin, chosen.view_point)
            distance = along if math.isfinite(along) else distance
            # the map blocked the planned way (view_points): restart from the new way's length
            rerouted = kept and distance > self._last_distance + REROUTE_JUMP
        self._last_distance = distance
        now = self.now()
        if not kept or rerouted or distance < self._best_distance:
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
        # a view point apart from its frontier faces it (for a robot whose move_base turns to
        # the goal's yaw; explore_lite's goals have yaw 0)
        toward = chosen.centroid
        yaw = 0.0
        if chosen.view_point is not None and math.dist(toward, target) > info.resolution:
            yaw = math.atan2(toward[1] - target[1], toward[0] - target[0])
        self._send(target, frame, yaw)

    def _wait(self) -> None:
        """No goal of its own while the peers explore: the one under way is withdrawn."""
        self._withdraw_goal()
        if self.goal is not None:
            self.goal = None
            self.link.announce(None)

    def _send(self, target: tuple[float, float], frame: str, yaw: float = 0.0) -> None:
        if not self.move_base.wait_for_server():
            self._warn_once("move_base", f"waiting for move_base at {self.move_base.name}")
            return
        self.goal = target
        self.link.announce(target, frame)
        pose = pose_stamped(target[0], target[1], yaw, frame, self.now_msg())
        self.goals_sent += 1
        self._handle = self.move_base.send_goal(
            move_base_msgs.MoveBaseGoal(target_pose=pose),
            done_cb=lambda h, goal=target: self._on_done(h, goal),
        )

    def _on_done(self, handle: Any, goal: tuple[float, float]) -> None:
        # only the goal in force counts (a withdrawn or replaced one's handle is not
        # ``_handle``); told apart by its handle, not its coordinates: the same point sent again
        # - every frontier blacklisted, the list cleared and retried - pre-empts the first send,
        # whose PREEMPTED then looked like the new goal's end, which replanned at once and sent
        # it again: thousands of sends without sim time advancing
        if handle is not self._handle:
            return
        status = handle.status
        self._handle = None
        if status == ABORTED:
            self.get_logger().info(f"move_base aborted the goal {goal}; blacklisting it")
            self.handled_goals.add(handle.id)
            self._blacklist(goal)
        elif status == SUCCEEDED and self.params.view_points:
            self.stood_at.append((*goal, self.now()))  # what it sees from here is observed
            self._publish_observed()
        self.goal = None
        self.link.announce(None)
        self.runtime.call_later(0.0, self.make_plan)  # explore_lite replans on reaching a goal

    def stop(self, why: str, observed: int = 0, failed: bool = False) -> None:
        """Stop exploring; ``observed`` of the frontiers left were observed as far as they can
        be (view_points), the rest are blacklisted: given up (``failed``: given up whatever
        is left, e.g. a costmap with nothing unknown)."""
        self.finished = True
        self.observed = observed
        given_up = len(self.frontiers) - observed
        self.gave_up = given_up > 0 or failed
        if observed:
            why += f" ({observed} frontiers left observed as far as they can be)"
        if given_up > 0:
            why += f" (gave up: {given_up} frontiers left, blacklisted)"
        self._withdraw_goal()
        self.timer.cancel()
        self.link.announce(None)
        self.get_logger().info(why)

    def _publish_markers(self, frame: str) -> None:
        header = std_msgs.Header(stamp=self.now_msg(), frame_id=frame)
        self.marker_pub.publish(frontier_markers(self.frontiers, header))
