"""``fleetsim goal`` and ``fleetsim initialpose``: a move_base action client and RViz's
"2D Pose Estimate", over the bridge.

The goal travels on the ROS 1 actionlib topics of ``/<ns>/move_base`` (``goal``, ``feedback``,
``result``, ``status``), so it reaches move_base in whichever process runs it.
"""

from __future__ import annotations

import math
import os
import queue
import time as _wall
from collections.abc import Callable
from typing import Any

from fleetsim.errors import GraphError, TransportError
from fleetsim.runtime import names
from fleetsim.transport.client import SimulationClient

#: RViz's "2D Pose Estimate" covariance: 0.5 m standard deviation in x and y, pi/12 in yaw
INITIALPOSE_COVARIANCE_XY = 0.25
INITIALPOSE_COVARIANCE_YAW = 0.06853891945200942


def pose_stamped(x: float, y: float, yaw: float, frame: str, stamp: float) -> Any:
    """A geometry_msgs/PoseStamped at ``(x, y)`` m heading ``yaw`` rad in ``frame``."""
    from fleetsim.nav.navigator import pose_stamped as navigator_pose

    return navigator_pose(x, y, yaw, frame, stamp, what="goal")


def initial_pose(x: float, y: float, yaw: float, frame: str, stamp: float) -> Any:
    """A geometry_msgs/PoseWithCovarianceStamped as RViz's 2D Pose Estimate sends it."""
    from fleetsim.msgs import geometry_msgs

    ps = pose_stamped(x, y, yaw, frame, stamp)
    cov = [0.0] * 36
    cov[0] = cov[7] = INITIALPOSE_COVARIANCE_XY
    cov[35] = INITIALPOSE_COVARIANCE_YAW
    return geometry_msgs.PoseWithCovarianceStamped(
        header=ps.header, pose=geometry_msgs.PoseWithCovariance(pose=ps.pose, covariance=cov)
    )


def yaw_of(q: Any) -> float:
    return math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))


def status_name(code: int) -> str:
    from fleetsim.msgs import actionlib_msgs

    for name, _spec, value in actionlib_msgs.GoalStatus.__msgconsts__:
        if value == code:
            return name
    return str(code)


def action_name(ns: str, action: str = "move_base") -> str:
    """``/<ns>/<action>`` for a robot namespace given as ``lizi1`` or ``/lizi1``."""
    return names.join(names.validate_namespace("/" + ns.strip("/")), action)


def send_goal(
    client: SimulationClient,
    ns: str,
    x: float,
    y: float,
    yaw: float = 0.0,
    frame: str = "map",
    wait: bool = False,
    on_feedback: Callable[[Any], None] | None = None,
    timeout: float | None = None,
    action: str = "move_base",
    action_type: str = "move_base_msgs/MoveBase",
) -> tuple[str, int, str]:
    """Send a goal to ``/<ns>/<action>``; returns ``(goal id, status, text)``.

    Without ``wait`` it returns once the server lists the goal (status PENDING or ACTIVE); with
    ``wait`` it returns the terminal status, calling ``on_feedback`` with each feedback message.
    ``timeout`` (wall seconds) bounds the wait (`TransportError`).
    """
    from fleetsim.msgs import actionlib_msgs, builtin_interfaces, get_action_type, std_msgs

    act = get_action_type(action_type)
    name = action_name(ns, action)
    topics = client.graph()["topics"]
    status_topic = topics.get(f"{name}/status")
    if status_topic is None or not status_topic["publishers"]:
        servers = sorted(t[: -len("/status")] for t in topics if t.endswith(f"/{action}/status"))
        raise GraphError(
            f"no {action} action server at {name} (servers running: "
            f"{', '.join(servers) or 'none'}); check the robot's namespace"
        )
    now = client.sim_time()
    goal = act.Goal(target_pose=pose_stamped(x, y, yaw, frame, now))
    goal_id = actionlib_msgs.GoalID(
        stamp=builtin_interfaces.Time.from_sec(now), id=f"fleetsim_goal-{os.getpid()}-{now:.3f}"
    )
    inbox: queue.SimpleQueue = queue.SimpleQueue()
    for part in ("status", "feedback", "result"):
        client.subscribe(f"{name}/{part}", lambda r, p=part: inbox.put((p, r.msg)), latched=False)
    pub = client.publisher(f"{name}/goal", act.ActionGoal)
    if not pub.wait_for_subscribers(client.timeout):
        raise TransportError(f"{name}/goal has no subscriber (is {name} running?)")
    pub.publish(
        act.ActionGoal(header=std_msgs.Header(stamp=goal_id.stamp), goal_id=goal_id, goal=goal)
    )
    deadline = None if timeout is None else _wall.monotonic() + timeout
    limit = client.timeout * 3 if not wait else None
    started = heard = _wall.monotonic()
    while True:
        if deadline is not None and _wall.monotonic() > deadline:
            raise TransportError(f"goal {goal_id.id} on {name}: no result within {timeout:g} s")
        if limit is not None and _wall.monotonic() - started > limit:
            raise TransportError(f"{name} did not acknowledge goal {goal_id.id}")
        try:
            part, msg = inbox.get(timeout=0.1)
        except queue.Empty:
            if _wall.monotonic() - heard > client.timeout:  # silent: is the server still there?
                heard = _wall.monotonic()
                _still_serving(client, name, goal_id.id)
            continue
        heard = _wall.monotonic()
        if isinstance(msg, Exception):
            continue
        if part == "status" and not wait:
            for st in msg.status_list:
                if st.goal_id.id == goal_id.id:
                    return goal_id.id, st.status, st.text
        elif part == "feedback" and msg.status.goal_id.id == goal_id.id:
            if on_feedback is not None:
                on_feedback(msg.feedback)
        elif part == "result" and msg.status.goal_id.id == goal_id.id:
            return goal_id.id, msg.status.status, msg.status.text


def _still_serving(client: SimulationClient, name: str, goal_id: str) -> None:
    """Raise `TransportError` when the action server ``name`` (or the whole simulation) has
    gone: a client waiting for a result would otherwise wait for ever after the run ended."""
    try:
        status = client.graph()["topics"].get(f"{name}/status")
    except TransportError as e:
        raise TransportError(
            f"the simulation went away before goal {goal_id} on {name} had a result ({e})"
        ) from None
    if status is None or not status["publishers"]:
        raise TransportError(f"{name} went away before goal {goal_id} had a result")


def cancel_goal(client: SimulationClient, ns: str, goal_id: str, action: str = "move_base") -> None:
    from fleetsim.msgs import actionlib_msgs

    pub = client.publisher(f"{action_name(ns, action)}/cancel", actionlib_msgs.GoalID)
    pub.wait_for_subscribers(client.timeout)
    pub.publish(actionlib_msgs.GoalID(id=goal_id))
    _wall.sleep(0.1)


def publish_initial_pose(
    client: SimulationClient, ns: str, x: float, y: float, yaw: float, frame: str = "map"
) -> str:
    """Publish the pose on ``/<ns>/initialpose``; returns the topic. Raises when nothing
    subscribes there within the client's timeout (no amcl in that namespace)."""
    from fleetsim.msgs import geometry_msgs

    topic = names.join(names.validate_namespace("/" + ns.strip("/")), "initialpose")
    pub = client.publisher(topic, geometry_msgs.PoseWithCovarianceStamped)
    if not pub.wait_for_subscribers(client.timeout):
        raise TransportError(f"nothing subscribes {topic} (is amcl running in /{ns.strip('/')}?)")
    pub.publish(initial_pose(x, y, yaw, frame, client.sim_time()))
    _wall.sleep(0.1)  # let the sample leave before the session closes
    return topic
