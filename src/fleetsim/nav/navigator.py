"""A Python API for driving robots, in the spirit of Nav2's ``nav2_simple_commander``.

`Navigator` sends goals to a robot's ``move_base`` action (the ROS 1 actionlib topics
``<ns>/move_base/{goal,cancel,status,feedback,result}``) and tracks them::

    nav = Navigator(runtime, namespace="/lizi1")
    nav.set_initial_pose(20.0, 15.0, 0.0)
    nav.go_to_pose(35.0, 20.0, yaw=1.57)
    nav.spin_until_complete(timeout=120.0)       # runs a local Runtime (sim seconds)
    if nav.get_result() is TaskResult.SUCCEEDED: ...
    print(nav.get_status_text())

It works with

* a `Runtime`: the navigator adds its own small node (``navigator`` in the namespace);
* a `Node`: it uses that node's publishers and subscriptions (a user node, or one in a process
  joined to a simulation with ``fleetsim node run``, whose runtime follows the simulation);
* a `fleetsim.transport.SimulationClient`: a connection to a running simulation in another
  process over Zenoh (see `fleetsim.nav.navigator_remote`); there ``spin_until_complete``
  waits in wall-clock seconds. ``with Navigator(...) as nav:`` destroys it at the end (its
  node, or its remote subscriptions; a client left open still closes when Python exits).

``follow_waypoints`` sends goals one after the other; the task fails at the first waypoint
that does not succeed. Results map actionlib statuses as Nav2 does: SUCCEEDED; PREEMPTED and
RECALLED are CANCELED; ABORTED, REJECTED and LOST are FAILED; anything else is UNKNOWN.
"""

from __future__ import annotations

import enum
import math
import threading
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from fleetsim.errors import ActionError

#: amcl's default initial covariance (initial_cov_xx, initial_cov_yy: 0.5^2 m^2;
#: initial_cov_aa: (pi/12)^2 rad^2), also what RViz's "2D Pose Estimate" sends
INITIAL_COV_XX = 0.5 * 0.5
INITIAL_COV_YY = 0.5 * 0.5
INITIAL_COV_AA = (math.pi / 12.0) ** 2


class TaskResult(enum.Enum):
    """How a navigation task ended (nav2_simple_commander's TaskResult)."""

    UNKNOWN = 0
    SUCCEEDED = 1
    CANCELED = 2
    FAILED = 3


def task_result_of(status: int) -> TaskResult:
    """The TaskResult of an actionlib GoalStatus code (terminal or not)."""
    if status == 3:  # SUCCEEDED
        return TaskResult.SUCCEEDED
    if status in (2, 8):  # PREEMPTED, RECALLED
        return TaskResult.CANCELED
    if status in (4, 5, 9):  # ABORTED, REJECTED, LOST
        return TaskResult.FAILED
    return TaskResult.UNKNOWN


@dataclass(frozen=True)
class NavigationFeedback:
    """What `Navigator.get_feedback` returns.

    pose : the robot's (x, y, yaw) from move_base's feedback (m, rad, in its frame), or None
        before the first feedback. frame_id : that pose's frame.
    current_waypoint : index of the goal being pursued; number_of_waypoints : goals in the task.
    navigation_time : sim seconds since the task started (wall seconds for a remote client).
    distance_remaining : straight-line distance from the robot to the current goal, m (None
        without a pose). goal : the current goal's (x, y, yaw).
    """

    pose: tuple[float, float, float] | None
    frame_id: str
    current_waypoint: int
    number_of_waypoints: int
    navigation_time: float
    distance_remaining: float | None
    goal: tuple[float, float, float]


def yaw_of(q: Any) -> float:
    """Yaw (rad) of a quaternion message."""
    return math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))


def pose_stamped(
    x: float, y: float, yaw: float, frame: str, stamp: float, what: str = "Navigator: pose"
) -> Any:
    """A geometry_msgs/PoseStamped at (x, y) m heading ``yaw`` rad in ``frame``.

    ``what`` names the pose in the error for a value that is not a finite number.
    """
    from fleetsim.msgs import builtin_interfaces, geometry_msgs, std_msgs

    for label, v in (("x", x), ("y", y), ("yaw", yaw)):
        if not isinstance(v, (int, float)) or not math.isfinite(v):
            raise ActionError(f"{what} {label} must be a finite number, got {v!r}")
    return geometry_msgs.PoseStamped(
        header=std_msgs.Header(stamp=builtin_interfaces.Time.from_sec(stamp), frame_id=frame),
        pose=geometry_msgs.Pose(
            position=geometry_msgs.Point(x=float(x), y=float(y), z=0.0),
            orientation=geometry_msgs.Quaternion(
                x=0.0, y=0.0, z=math.sin(yaw / 2.0), w=math.cos(yaw / 2.0)
            ),
        ),
    )


def initial_pose_msg(x: float, y: float, yaw: float, frame: str, stamp: float) -> Any:
    """geometry_msgs/PoseWithCovarianceStamped with amcl's default initial covariance."""
    from fleetsim.msgs import geometry_msgs

    ps = pose_stamped(x, y, yaw, frame, stamp)
    cov = [0.0] * 36
    cov[0], cov[7], cov[35] = INITIAL_COV_XX, INITIAL_COV_YY, INITIAL_COV_AA
    return geometry_msgs.PoseWithCovarianceStamped(
        header=ps.header, pose=geometry_msgs.PoseWithCovariance(pose=ps.pose, covariance=cov)
    )


class Navigator:
    """Send navigation goals to one robot's move_base and follow them.

    Parameters
    ----------
    runtime_or_node : a `Runtime` (a node named ``node_name`` is created in ``namespace``), a
        `Node` (used as it is), or a `fleetsim.transport.SimulationClient` (a remote run).
    namespace : the robot's namespace (``/lizi1``); the action is ``<namespace>/move_base``.
    action : the action's name relative to the namespace.
    node_name : name of the node created for a Runtime (made unique with a suffix if taken).
    """

    def __init__(
        self,
        runtime_or_node: Any,
        namespace: str = "/lizi1",
        action: str = "move_base",
        node_name: str = "navigator",
    ) -> None:
        from fleetsim.runtime import Node, Runtime, names

        ns = names.validate_namespace("/" + str(namespace).strip("/"))
        self.namespace = ns
        self._lock = threading.RLock()
        self._own_node = None
        if isinstance(runtime_or_node, Runtime):
            name, k = node_name, 1
            while names.join(ns, name) in runtime_or_node.graph.nodes:
                k += 1
                name = f"{node_name}_{k}"
            self._own_node = Node(runtime_or_node, name, ns)
            runtime_or_node = self._own_node
        action_name = names.join(ns, action)
        if isinstance(runtime_or_node, Node):
            from fleetsim.nav.navigator_local import LocalBackend

            self._backend: Any = LocalBackend(
                runtime_or_node, action_name, names.join(ns, "initialpose")
            )
        elif hasattr(runtime_or_node, "session") and hasattr(runtime_or_node, "publisher"):
            from fleetsim.nav.navigator_remote import RemoteBackend

            self._backend = RemoteBackend(runtime_or_node, action_name, ns)
        else:
            raise ActionError(
                "Navigator needs a fleetsim Runtime, a Node or a transport SimulationClient, "
                f"got {type(runtime_or_node).__name__}"
            )
        self._generation = 0
        self._reset([], "map")

    # -- tasks ------------------------------------------------------------------------------
    def _reset(self, goals: list[tuple[float, float, float]], frame: str) -> None:
        self._generation += 1  # callbacks of an older task's goals are ignored from now on
        self._goals = goals
        self._frame = frame
        self._index = 0
        self._started = self._backend.now() if goals else 0.0
        self._feedback: Any = None
        self._result = TaskResult.UNKNOWN
        self._text = ""
        self._complete = not goals
        self._canceled = False

    def go_to_pose(self, x: Any, y: float | None = None, yaw: float = 0.0, frame: str = "map"):
        """Send the robot to (x, y, yaw) in ``frame``, or to a geometry_msgs/PoseStamped.

        Replaces any running task (move_base preempts the old goal). Returns True when sent;
        raises `ActionError` when no move_base server runs in the namespace.
        """
        return self.follow_waypoints([x if y is None else (x, y, yaw)], frame)

    def follow_waypoints(self, poses: Sequence[Any], frame: str = "map") -> bool:
        """Visit ``poses`` in order: (x, y[, yaw]) tuples or PoseStamped messages.

        Each goal is sent once the previous one succeeded; the task fails at the first that
        does not (its status text says which). Returns True when the first goal was sent.
        """
        goals: list[tuple[float, float, float]] = []
        frames = []
        for i, p in enumerate(poses):
            if hasattr(p, "pose") and hasattr(p, "header"):
                q = p.pose
                goals.append((q.position.x, q.position.y, yaw_of(q.orientation)))
                frames.append(p.header.frame_id or frame)
                continue
            try:
                vals = [float(v) for v in p]
            except (TypeError, ValueError):
                vals = []
            if len(vals) not in (2, 3) or not all(math.isfinite(v) for v in vals):
                raise ActionError(
                    f"Navigator: waypoint {i} must be (x, y[, yaw]) finite numbers or a "
                    f"PoseStamped, got {p!r}"
                )
            goals.append((vals[0], vals[1], vals[2] if len(vals) == 3 else 0.0))
            frames.append(frame)
        if not goals:
            raise ActionError("Navigator: follow_waypoints needs at least one pose")
        if len(set(frames)) > 1:
            raise ActionError(f"Navigator: waypoints must share one frame, got {sorted(frames)}")
        with self._lock:
            self._reset(goals, frames[0])
            self._send_current()
        return True

    def _send_current(self) -> None:
        x, y, yaw = self._goals[self._index]
        msg = pose_stamped(x, y, yaw, self._frame, self._backend.now())
        gen = self._generation
        self._backend.send(
            msg,
            lambda fb: self._on_feedback(gen, fb),
            lambda status, text: self._on_done(gen, status, text),
        )

    def _on_feedback(self, gen: int, fb: Any) -> None:
        with self._lock:
            if gen == self._generation:
                self._feedback = fb

    def _on_done(self, gen: int, status: int, text: str) -> None:
        with self._lock:
            if self._complete or gen != self._generation:
                return
            result = task_result_of(status)
            last = self._index == len(self._goals) - 1
            if result is TaskResult.SUCCEEDED and not last and not self._canceled:
                self._index += 1
                self._feedback = None
                self._send_current()
                return
            self._result = result
            n = len(self._goals)
            where = f"waypoint {self._index + 1} of {n}: " if n > 1 else ""
            self._text = where + (text or _STATUS_NAMES.get(status, str(status)).lower())
            self._complete = True

    def is_task_complete(self) -> bool:
        """True when there is no task or the task has ended (any result)."""
        with self._lock:
            return self._complete

    def cancel_task(self) -> None:
        """Ask move_base to cancel the current goal; the task ends CANCELED once it has."""
        with self._lock:
            if self._complete:
                return
            self._canceled = True
            self._backend.cancel()

    def get_result(self) -> TaskResult:
        """The task's result (UNKNOWN while it runs or before any task)."""
        with self._lock:
            return self._result

    def get_status_text(self) -> str:
        """move_base's status text for the result (why a goal was aborted), with the waypoint."""
        with self._lock:
            return self._text

    def get_feedback(self) -> NavigationFeedback | None:
        """The latest feedback of the running (or last) task, None before any task."""
        with self._lock:
            if not self._goals:
                return None
            fb = self._feedback
            goal = self._goals[self._index]
            pose = None
            frame = self._frame
            dist = None
            if fb is not None:
                bp = fb.base_position
                pose = (bp.pose.position.x, bp.pose.position.y, yaw_of(bp.pose.orientation))
                frame = bp.header.frame_id or frame
                dist = math.hypot(goal[0] - pose[0], goal[1] - pose[1])
            return NavigationFeedback(
                pose=pose,
                frame_id=frame,
                current_waypoint=self._index,
                number_of_waypoints=len(self._goals),
                navigation_time=self._backend.now() - self._started,
                distance_remaining=dist,
                goal=goal,
            )

    def spin_until_complete(self, timeout: float | None = None) -> bool:
        """Run (a local Runtime) or wait (a remote client) until the task is complete.

        ``timeout``: sim seconds for a Runtime or Node, wall seconds for a remote client; None
        waits for ever. Returns `is_task_complete()`.
        """
        if timeout is not None and not timeout >= 0:
            raise ActionError(f"Navigator: timeout must be >= 0 s or None, got {timeout!r}")
        self._backend.spin(timeout, self.is_task_complete)
        return self.is_task_complete()

    def set_initial_pose(self, x: float, y: float, yaw: float = 0.0, frame: str = "map") -> None:
        """Publish ``<ns>/initialpose`` (PoseWithCovarianceStamped, amcl's default covariance)."""
        self._backend.publish_initial_pose(initial_pose_msg(x, y, yaw, frame, self._backend.now()))

    def destroy(self) -> None:
        """Remove the navigator's own node (Runtime) or close its subscriptions and publishers
        (remote; the SimulationClient stays open, it belongs to the caller)."""
        self._backend.close()
        if self._own_node is not None:
            self._own_node.destroy()
            self._own_node = None

    def __enter__(self) -> Navigator:
        return self

    def __exit__(self, *exc: object) -> None:
        self.destroy()


_STATUS_NAMES = {
    0: "PENDING",
    1: "ACTIVE",
    2: "PREEMPTED",
    3: "SUCCEEDED",
    4: "ABORTED",
    5: "REJECTED",
    6: "PREEMPTING",
    7: "RECALLING",
    8: "RECALLED",
    9: "LOST",
}
