"""Actions with ROS 1 actionlib semantics, over the five actionlib topics.

An action named ``move_base`` in namespace ``/lizi1`` uses ``/lizi1/move_base/goal``,
``cancel``, ``status``, ``feedback`` and ``result``, with actionlib's message layout, so a goal
published on ``move_base/goal`` from the command line or another process works as in ROS.

`ActionServer` follows actionlib's *SimpleActionServer* policy, which move_base uses: at most
one goal is active; a new goal preempts the active one (the owner sees
``is_preempt_requested()`` and accepts the new goal with `accept_new_goal`); a newer goal
replaces a pending one, which ends RECALLED. Cancel requests follow actionlib's rules: an empty
id and zero stamp cancel everything, an id cancels that goal, a stamp cancels every goal sent at
or before it.
"""

from __future__ import annotations

import itertools
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

from fleetsim.errors import ActionError

if TYPE_CHECKING:
    from fleetsim.runtime.node import Node

#: how long finished goals stay in the status list (actionlib's status_list_timeout)
STATUS_LIST_TIMEOUT = 5.0
#: how often the server publishes its status list (actionlib's status_frequency)
STATUS_FREQUENCY = 5.0


def _msgs():
    from fleetsim.msgs import actionlib_msgs, builtin_interfaces, std_msgs

    return actionlib_msgs, builtin_interfaces, std_msgs


class ServerGoal:
    """One goal as the server tracks it."""

    __slots__ = ("finished_at", "goal", "goal_id", "status", "text")

    def __init__(self, goal_id, goal) -> None:
        self.goal_id = goal_id
        self.goal = goal
        self.status = 0  # PENDING
        self.text = ""
        self.finished_at: float | None = None

    @property
    def id(self) -> str:
        return self.goal_id.id


class ActionServer:
    """The server end of an action, with SimpleActionServer's one-active-goal policy.

    Parameters
    ----------
    node : the node that owns the server.
    action_type : an ``ActionType`` (``move_base_msgs.MoveBase``).
    name : the action's name, resolved like a topic (``move_base``).
    goal_callback : called (no arguments) when a new goal arrives.
    preempt_callback : called (no arguments) when the active goal is asked to stop.
    """

    def __init__(
        self,
        node: Node,
        action_type: Any,
        name: str,
        goal_callback: Callable[[], None] | None = None,
        preempt_callback: Callable[[], None] | None = None,
    ) -> None:
        al, _bi, _std = _msgs()
        self._al = al
        self.node = node
        self.type = action_type
        self.name = node.resolve_name(name)
        self.goal_callback = goal_callback
        self.preempt_callback = preempt_callback
        self.current: ServerGoal | None = None
        self.next: ServerGoal | None = None
        self._preempt_requested = False
        self._new_goal_preempt_request = False
        self._finished: list[ServerGoal] = []
        self._last_cancel_stamp = 0
        self._status_pub = node.create_publisher(al.GoalStatusArray, f"{self.name}/status")
        self._feedback_pub = node.create_publisher(
            action_type.ActionFeedback, f"{self.name}/feedback"
        )
        self._result_pub = node.create_publisher(action_type.ActionResult, f"{self.name}/result")
        node.create_subscription(action_type.ActionGoal, f"{self.name}/goal", self._on_goal, 0)
        node.create_subscription(al.GoalID, f"{self.name}/cancel", self._on_cancel, 0)
        node.create_timer(1.0 / STATUS_FREQUENCY, self.publish_status)

    # -- incoming -------------------------------------------------------------------------
    def _on_goal(self, msg) -> None:
        goal_id = msg.goal_id
        if not goal_id.id:
            goal_id = self._al.GoalID(stamp=self.node.now_msg(), id=f"{self.name}-{id(msg)}")
        stamp_ns = goal_id.stamp.to_nsec()
        if stamp_ns != 0 and stamp_ns <= self._last_cancel_stamp:
            g = ServerGoal(goal_id, msg.goal)
            self._finish(g, self._al.GoalStatus.RECALLED, "canceled before it was received")
            return
        g = ServerGoal(goal_id, msg.goal)
        if self.next is not None:
            self._finish(
                self.next,
                self._al.GoalStatus.RECALLED,
                "canceled because a newer goal was received by the simple action server",
            )
        self.next = g
        if self.is_active():
            self._preempt_requested = True
            self._new_goal_preempt_request = True
            if self.preempt_callback is not None:
                self.preempt_callback()
        self.publish_status()
        if self.goal_callback is not None:
            self.goal_callback()

    def _on_cancel(self, msg) -> None:
        al = self._al
        stamp = msg.stamp.to_nsec()
        cancel_all = not msg.id and stamp == 0
        if stamp:
            self._last_cancel_stamp = max(self._last_cancel_stamp, stamp)

        def targeted(g: ServerGoal) -> bool:
            if cancel_all or (msg.id and g.id == msg.id):
                return True
            return bool(stamp) and g.goal_id.stamp.to_nsec() <= stamp

        if self.next is not None and targeted(self.next):
            self._finish(self.next, al.GoalStatus.RECALLED, "canceled")
            self.next = None
        if self.current is not None and self.is_active() and targeted(self.current):
            self.current.status = al.GoalStatus.PREEMPTING
            self._preempt_requested = True
            if self.preempt_callback is not None:
                self.preempt_callback()
        self.publish_status()

    # -- the owner's side -----------------------------------------------------------------
    def is_new_goal_available(self) -> bool:
        return self.next is not None

    def accept_new_goal(self, preempted_result: Any = None) -> Any:
        """Make the pending goal active (preempting the active one, whose result is
        ``preempted_result``, else an empty one); returns its goal message."""
        al = self._al
        if self.next is None:
            raise ActionError(f"action {self.name}: accept_new_goal() with no new goal pending")
        if self.is_active():
            self._finish(
                self.current,
                al.GoalStatus.PREEMPTED,
                "This goal was canceled because another goal was received by the simple action "
                "server",
                preempted_result,
            )
        self.current, self.next = self.next, None
        self.current.status = al.GoalStatus.ACTIVE
        self._preempt_requested = self._new_goal_preempt_request = False
        self.publish_status()
        return self.current.goal

    def is_active(self) -> bool:
        al = self._al
        return self.current is not None and self.current.status in (
            al.GoalStatus.ACTIVE,
            al.GoalStatus.PREEMPTING,
        )

    def is_preempt_requested(self) -> bool:
        return self._preempt_requested

    @property
    def current_goal(self) -> Any:
        return self.current.goal if self.current is not None else None

    def publish_feedback(self, feedback: Any) -> None:
        if not self.is_active():
            raise ActionError(f"action {self.name}: feedback with no active goal")
        al, _, std = _msgs()
        msg = self.type.ActionFeedback(
            header=std.Header(stamp=self.node.now_msg()),
            status=al.GoalStatus(goal_id=self.current.goal_id, status=self.current.status),
            feedback=feedback,
        )
        self._feedback_pub.publish(msg)

    def set_succeeded(self, result: Any = None, text: str = "") -> None:
        self._terminate(self._al.GoalStatus.SUCCEEDED, result, text)

    def set_aborted(self, result: Any = None, text: str = "") -> None:
        self._terminate(self._al.GoalStatus.ABORTED, result, text)

    def set_preempted(self, result: Any = None, text: str = "") -> None:
        self._terminate(self._al.GoalStatus.PREEMPTED, result, text)

    def _terminate(self, status: int, result: Any, text: str) -> None:
        if not self.is_active():
            raise ActionError(
                f"action {self.name}: cannot end a goal, none is active (status {status})"
            )
        self._finish(self.current, status, text, result)
        self._preempt_requested = False

    def _finish(self, g: ServerGoal, status: int, text: str, result: Any = None) -> None:
        al, _, std = _msgs()
        g.status, g.text = status, text
        g.finished_at = self.node.now()
        self._finished.append(g)
        msg = self.type.ActionResult(
            header=std.Header(stamp=self.node.now_msg()),
            status=al.GoalStatus(goal_id=g.goal_id, status=status, text=text),
            result=result if result is not None else self.type.Result(),
        )
        self._result_pub.publish(msg)
        self.publish_status()

    def publish_status(self) -> None:
        al, _, std = _msgs()
        now = self.node.now()
        self._finished = [
            g for g in self._finished if now - (g.finished_at or now) <= STATUS_LIST_TIMEOUT
        ]
        goals = list(self._finished)
        if self.current is not None and self.current.status in (
            al.GoalStatus.ACTIVE,
            al.GoalStatus.PREEMPTING,
        ):
            goals.append(self.current)
        if self.next is not None:
            goals.append(self.next)
        self._status_pub.publish(
            al.GoalStatusArray(
                header=std.Header(stamp=self.node.now_msg()),
                status_list=[
                    al.GoalStatus(goal_id=g.goal_id, status=g.status, text=g.text) for g in goals
                ],
            )
        )


class ClientGoalHandle:
    """What the client knows of one goal it sent."""

    def __init__(self, client: ActionClient, goal_id, goal, done_cb, feedback_cb) -> None:
        self.client = client
        self.goal_id = goal_id
        self.goal = goal
        self.status = 0  # PENDING
        self.heard = False  # a server has sent a status, feedback or result of this goal
        self.text = ""
        self.result: Any = None
        self.feedback: Any = None
        self.done_cb = done_cb
        self.feedback_cb = feedback_cb

    @property
    def id(self) -> str:
        return self.goal_id.id

    @property
    def done(self) -> bool:
        """True once the server sent this goal's result (its terminal status)."""
        return self.result is not None

    def cancel(self) -> None:
        al, _, _ = _msgs()
        self.client._cancel_pub.publish(al.GoalID(id=self.id))


class ActionClient:
    """The client end of an action."""

    _ids = itertools.count(1)

    def __init__(self, node: Node, action_type: Any, name: str) -> None:
        al, _, _ = _msgs()
        self.node = node
        self.type = action_type
        self.name = node.resolve_name(name)
        self.handles: dict[str, ClientGoalHandle] = {}
        self._count = itertools.count(1)
        self._server_heard = False
        self._goal_pub = node.create_publisher(action_type.ActionGoal, f"{self.name}/goal")
        self._cancel_pub = node.create_publisher(al.GoalID, f"{self.name}/cancel")
        node.create_subscription(al.GoalStatusArray, f"{self.name}/status", self._on_status, 0)
        node.create_subscription(
            action_type.ActionFeedback, f"{self.name}/feedback", self._on_feedback, 0
        )
        node.create_subscription(
            action_type.ActionResult, f"{self.name}/result", self._on_result, 0
        )

    def wait_for_server(self, timeout: float | None = None) -> bool:
        """True when a server publishes this action's status: one in this process, or one
        whose status messages have come (a server in another process, over the bridge: a
        node joined to a run with --connect sees none in its own graph). No waiting."""
        if self._server_heard:
            return True
        topic = self.node.runtime.graph.topics.get(f"{self.name}/status")
        return topic is not None and bool(topic.publishers)

    def send_goal(
        self,
        goal: Any,
        done_cb: Callable[[ClientGoalHandle], None] | None = None,
        feedback_cb: Callable[[ClientGoalHandle, Any], None] | None = None,
    ) -> ClientGoalHandle:
        al, _, std = _msgs()
        if type(goal) is not self.type.Goal:
            raise ActionError(
                f"action {self.name} takes {self.type.Goal.__msgtype__}, got "
                f"{getattr(goal, '__msgtype__', type(goal).__name__)}"
            )
        stamp = self.node.now_msg()
        goal_id = al.GoalID(
            stamp=stamp, id=f"{self.node.full_name}-{next(self._count)}-{stamp.to_sec():.3f}"
        )
        handle = ClientGoalHandle(self, goal_id, goal, done_cb, feedback_cb)
        self.handles[goal_id.id] = handle
        self._goal_pub.publish(
            self.type.ActionGoal(header=std.Header(stamp=stamp), goal_id=goal_id, goal=goal)
        )
        return handle

    def cancel_all_goals(self) -> None:
        al, _, _ = _msgs()
        self._cancel_pub.publish(al.GoalID())

    def _on_status(self, msg) -> None:
        self._server_heard = True  # actionlib: a server is there once its status comes
        for st in msg.status_list:
            h = self.handles.get(st.goal_id.id)
            if h is not None and h.result is None:
                h.status, h.text, h.heard = st.status, st.text, True

    def _on_feedback(self, msg) -> None:
        h = self.handles.get(msg.status.goal_id.id)
        if h is not None:
            h.feedback = msg.feedback
            h.status, h.heard = msg.status.status, True
            if h.feedback_cb is not None:
                h.feedback_cb(h, msg.feedback)

    def _on_result(self, msg) -> None:
        h = self.handles.get(msg.status.goal_id.id)
        if h is None or h.result is not None:
            return
        h.status, h.text, h.result = msg.status.status, msg.status.text, msg.result
        h.heard = True
        if h.done_cb is not None:
            h.done_cb(h)
