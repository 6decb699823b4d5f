"""Which frontier an explorer takes when peers explore the same map (fleetsim addition).

explore_lite has no notion of other robots; two explorers on one merged map both head for the
same cheapest frontier. Multi-robot frontier explorers (Burgard et al.'s coordinated
exploration, multirobot_exploration's assigners) give each robot a frontier with the peers'
known goals taken into account; here each robot runs its own explorer and decides for itself
from what its peers announce (their goals, positions and blacklists), so no central planner
is needed:

- a frontier within ``peer_radius`` of a peer's goal is the peer's (it will map it);
- of the others, it prefers those whose centroid (the goal it would send) is nearer to it than
  to every peer (each robot keeps to its side);
- the preference falls back step by step: frontiers on its side that no peer heads for, then
  any that no peer heads for (a robot whose side is done helps with the peer's side, nearest
  first), then one a peer heads for but this robot is nearer to (the peer leaves it when it
  sees this robot's goal); when a peer heads for every frontier left and is nearer to each,
  none: the robot waits (without stopping) instead of following the peer into the same room
  (seed 1: both hunters drove to the office's last corner, 12 and 13 m away);
- with ``switch_distance`` > 0 it keeps the frontier it is heading for (the free frontier
  nearest its goal) unless another is cheaper by at least ``potential_scale * res *
  switch_distance``: the side a frontier falls on changes as the robots move, and with nearly
  equal costs explore_lite's replanning flipped the goal between two frontiers every plan
  (office, two hunters, seed 1: 45 of hunter1's 55 goals replaced before they were reached).

"Nearer" is by straight lines to the centroid, or (explore's ``path_costs``) by the distances
the robots drive (`fleetsim.nav.explore.path_costs`): each robot computes them for itself and
for its peers from the same merged map, so both share the frontiers out alike, each taking
those it reaches first along the floor, a division by travel cost as in Burgard et al.'s
coordinated exploration (a straight line through a wall gave a robot the next room's
frontiers, 15-20 m away by the door, and kept the nearer robot waiting at the end).

With no peers and ``switch_distance`` 0 the choice is explore_lite's: the cheapest frontier.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np

from fleetsim.msgs import geometry_msgs, std_msgs

from .frontier_search import Frontier

#: m: the frontier nearest the current goal (centroid or a cell this near) is still "the same"
TRACK_RADIUS = 1.0


def frontier_for_robot(
    candidates: Sequence[Frontier],
    robot: tuple[float, float],
    goal: tuple[float, float] | None,
    peer_goals: Sequence[tuple[float, float]],
    peer_positions: Sequence[tuple[float, float]],
    peer_radius: float,
    switch_margin: float = 0.0,
    distances: np.ndarray | None = None,
) -> Frontier | None:
    """The frontier this robot should head for; None: wait, the peers have the rest.

    Parameters
    ----------
    candidates : frontiers not blacklisted, cheapest first (explore_lite's cost); not empty.
    robot : this robot's (x, y), m, in the frontiers' frame.
    goal : the goal (x, y) it is heading for, or None.
    peer_goals : the peers' announced goals (x, y), m.
    peer_positions : where the peers are (x, y), m.
    peer_radius : m; frontiers with a centroid this near a peer's goal are that peer's.
    switch_margin : cost (explore_lite's units) by which another frontier must beat the one it
        heads for to replace it; 0 replaces it whenever another is cheapest.
    distances : (F, 1 + P) m, optional: how far this robot (column 0) and each peer (the next
        columns, in ``peer_positions``' order) drive to each candidate (inf: cannot reach it);
        when given, a frontier is this robot's when no peer's distance is shorter, instead of
        comparing straight lines to its centroid.
    """
    if distances is None:
        nearer = {id(f): _nearer_to_robot(f, robot, peer_positions) for f in candidates}
    else:
        distances = np.asarray(distances, dtype=float).reshape(len(candidates), -1)
        nearer = {id(f): bool(np.all(row[1:] >= row[0])) for f, row in zip(candidates, distances)}
    free = [
        f for f in candidates if all(math.dist(f.centroid, g) >= peer_radius for g in peer_goals)
    ]
    mine = [f for f in free if nearer[id(f)]]
    if mine or free:
        best = (mine or free)[0]
    else:
        ours = [f for f in candidates if nearer[id(f)]]
        if not ours:
            return None
        best = ours[0]
    if switch_margin <= 0.0 or goal is None:
        return best
    current = tracked_frontier(free, goal)
    if current is not None and current.cost < best.cost + switch_margin:
        return current
    return best


def _nearer_to_robot(
    frontier: Frontier, robot: tuple[float, float], others: Sequence[tuple[float, float]]
) -> bool:
    """Whether no other robot is nearer to the frontier's centroid than this one (ties mine)."""
    mine = math.dist(frontier.centroid, robot)
    return all(math.dist(frontier.centroid, o) >= mine for o in others)


def tracked_frontier(frontiers: Sequence[Frontier], goal: tuple[float, float]) -> Frontier | None:
    """The frontier the goal was sent to, as it is now: its centroid moves as it shrinks, so
    the one whose centroid, or a cell, lies within `TRACK_RADIUS` of the goal (nearest
    centroid first)."""
    near = [
        f
        for f in frontiers
        if math.dist(f.centroid, goal) < TRACK_RADIUS
        or ((f.points[:, 0] - goal[0]) ** 2 + (f.points[:, 1] - goal[1]) ** 2).min()
        < TRACK_RADIUS**2
    ]
    return min(near, key=lambda f: math.dist(f.centroid, goal), default=None)


# -- what the peers publish, read (explore subscribes to these) -------------------------------
def points(msg: geometry_msgs.PoseArray) -> list[tuple[float, float]]:
    """A peer's points (its blacklist, its view points stood at), x, y in m."""
    return [(q.position.x, q.position.y) for q in msg.poses]


def stamped_points(msg: geometry_msgs.PoseArray) -> list[tuple[float, float, float]]:
    """The points with the message's time (sim s)."""
    t = msg.header.stamp.sec + msg.header.stamp.nanosec * 1e-9
    return [(x, y, t) for x, y in points(msg)]


def first_heard(
    held: list[tuple[float, float, float]], new: list[tuple[float, float, float]]
) -> list[tuple[float, float, float]]:
    """``new`` (x, y, t) points, each one already ``held`` at the time it was held with: a peer
    republishes its whole list, stamped anew, whenever the list grows."""
    heard = {(x, y): t for x, y, t in held}
    return [(x, y, heard.get((x, y), t)) for x, y, t in new]


def peer_goal(msg: geometry_msgs.PointStamped) -> tuple[float, float] | None:
    """A peer's announced goal; None (NaN announced): it has none."""
    x, y = msg.point.x, msg.point.y
    return (x, y) if math.isfinite(x) and math.isfinite(y) else None


class PeerLink:
    """An explorer's traffic with its peers: what it tells them, on its latched ``~goal``
    (NaN: none), ``~blacklist`` and ``~observed`` (view points stood at and frontiers closed on
    the way), and what they tell it, by topic (``peer_goals``, ``peer_blacklists``,
    ``peer_observed``): their latest goals and blacklists, and their view points, each kept
    at the time it was first heard of (a peer republishes its whole list, stamped anew,
    whenever the list grows)."""

    def __init__(self, node: Any, params: Any) -> None:
        self.node = node
        self.goal_pub = node.create_publisher(geometry_msgs.PointStamped, "~goal", 1, latch=True)
        self.blacklist_pub = node.create_publisher(
            geometry_msgs.PoseArray, "~blacklist", 1, latch=True
        )
        self.observed_pub = node.create_publisher(
            geometry_msgs.PoseArray, "~observed", 1, latch=True
        )
        self.goals = self._listen(geometry_msgs.PointStamped, params.peer_goals, peer_goal, None)
        self.blacklists = self._listen(geometry_msgs.PoseArray, params.peer_blacklists, points)
        self.stood_at = self._listen(
            geometry_msgs.PoseArray, params.peer_observed, stamped_points, [], merge=first_heard
        )

    def _listen(self, kind, topics, read, empty: Any = (), merge=None) -> dict[str, Any]:
        """Subscribe to each of ``topics``; the dict returned holds each one's latest message
        as ``read`` gives it (``empty`` until one arrives), or ``merge(held, read(msg))``."""
        latest = {str(t): empty for t in topics}

        def on(topic: str, msg: Any) -> None:
            new = read(msg)
            latest[topic] = new if merge is None else merge(latest[topic], new)

        for topic in latest:
            self.node.create_subscription(kind, topic, lambda m, t=topic: on(t, m), 1)
        return latest

    def publish_points(self, pub: Any, points: list[tuple[float, float]], frame: str) -> None:
        """``points`` (x, y) as a PoseArray in ``frame`` on ``pub``."""
        pub.publish(
            geometry_msgs.PoseArray(
                header=std_msgs.Header(stamp=self.node.now_msg(), frame_id=frame),
                poses=[
                    geometry_msgs.Pose(position=geometry_msgs.Point(x=float(x), y=float(y)))
                    for x, y in points
                ],
            )
        )

    def announce(self, goal: tuple[float, float] | None, frame: str = "") -> None:
        """Publish the goal on ~goal (NaN: none)."""
        x, y = goal if goal is not None else (math.nan, math.nan)
        self.goal_pub.publish(
            geometry_msgs.PointStamped(
                header=std_msgs.Header(stamp=self.node.now_msg(), frame_id=frame),
                point=geometry_msgs.Point(x=float(x), y=float(y), z=0.0),
            )
        )
