"""The `Navigator`'s backend for a simulation in another process, over the Zenoh transport.

It speaks the same ROS 1 actionlib topics as the in-process ActionClient, through a
`fleetsim.transport.SimulationClient`: goals and cancels are published on
``<action>/goal`` and ``<action>/cancel``; ``status``, ``feedback`` and ``result`` are
subscribed (their callbacks run on Zenoh threads; the Navigator locks its state).
Time is the simulation's sim time for stamps and wall time for waiting.
"""

from __future__ import annotations

import itertools
import os
import threading
import time as _wall
from collections.abc import Callable
from typing import Any

from fleetsim.errors import ActionError, TransportError


class RemoteBackend:
    """move_base over a SimulationClient (see `fleetsim.nav.navigator.Navigator`)."""

    _ids = itertools.count(1)

    def __init__(self, client: Any, action: str, namespace: str) -> None:
        from fleetsim.msgs import actionlib_msgs, geometry_msgs, move_base_msgs

        self.client = client
        self.action = action
        self.namespace = namespace
        self._act = move_base_msgs.MoveBase
        self._al = actionlib_msgs
        self._geo = geometry_msgs
        self._lock = threading.Lock()
        self._goal_id = ""
        self._status = (0, "")
        self._on_feedback: Callable[[Any], None] | None = None
        self._on_done: Callable[[int, str], None] | None = None
        self._done = True
        self._wall0 = _wall.monotonic()
        self._sim0 = client.sim_time()
        self._goal_pub = None
        self._cancel_pub = None
        self._pose_pub = None
        self._subs = [
            client.subscribe(f"{action}/{part}", self._dispatch(part), latched=False)
            for part in ("status", "feedback", "result")
        ]

    def now(self) -> float:
        """Sim time estimated from the last reading plus wall time (no query per call)."""
        return self._sim0 + (_wall.monotonic() - self._wall0)

    def _dispatch(self, part: str) -> Callable[[Any], None]:
        def on_msg(received: Any) -> None:
            msg = received.msg
            if isinstance(msg, Exception):
                return
            if part == "status":
                for st in msg.status_list:
                    self._update(st.goal_id.id, st.status, st.text, final=False)
            elif part == "feedback":
                gid = msg.status.goal_id.id
                with self._lock:
                    cb = self._on_feedback if gid == self._goal_id and not self._done else None
                if cb is not None:
                    cb(msg.feedback)
                self._update(gid, msg.status.status, msg.status.text, final=False)
            else:
                st = msg.status
                self._update(st.goal_id.id, st.status, st.text, final=True)

        return on_msg

    def _update(self, gid: str, status: int, text: str, final: bool) -> None:
        with self._lock:
            if gid != self._goal_id or self._done:
                return
            self._status = (status, text)
            done_cb = self._on_done if final else None
            if final:
                self._done = True
        if done_cb is not None:
            done_cb(status, text)

    def _server_running(self) -> bool:
        topic = self.client.graph()["topics"].get(f"{self.action}/status")
        return topic is not None and bool(topic["publishers"])

    def send(self, goal_pose: Any, on_feedback, on_done) -> None:
        from fleetsim.msgs import builtin_interfaces, std_msgs

        if self._goal_pub is None:
            if not self._server_running():
                raise ActionError(
                    f"Navigator: no move_base action server at {self.action} in the simulation "
                    f"at {self.client.endpoint}; start move_base there or fix the namespace"
                )
            self._goal_pub = self.client.publisher(f"{self.action}/goal", self._act.ActionGoal)
            if not self._goal_pub.wait_for_subscribers(self.client.timeout):
                raise TransportError(f"{self.action}/goal has no subscriber in the simulation")
        now = self.now()
        stamp = builtin_interfaces.Time.from_sec(now)
        gid = f"navigator-{os.getpid()}-{next(self._ids)}-{now:.3f}"
        goal_id = self._al.GoalID(stamp=stamp, id=gid)
        with self._lock:
            self._goal_id, self._status, self._done = gid, (0, ""), False
            self._on_feedback, self._on_done = on_feedback, on_done
        self._goal_pub.publish(
            self._act.ActionGoal(
                header=std_msgs.Header(stamp=stamp),
                goal_id=goal_id,
                goal=self._act.Goal(target_pose=goal_pose),
            )
        )

    def status(self) -> tuple[int, str]:
        with self._lock:
            return self._status

    def cancel(self) -> None:
        with self._lock:
            gid = "" if self._done else self._goal_id
        if not gid:
            return
        if self._cancel_pub is None:
            self._cancel_pub = self.client.publisher(f"{self.action}/cancel", self._al.GoalID)
            self._cancel_pub.wait_for_subscribers(self.client.timeout)
        self._cancel_pub.publish(self._al.GoalID(id=gid))

    def publish_initial_pose(self, msg: Any) -> None:
        topic = f"{self.namespace.rstrip('/')}/initialpose"
        if self._pose_pub is None:
            self._pose_pub = self.client.publisher(topic, self._geo.PoseWithCovarianceStamped)
            if not self._pose_pub.wait_for_subscribers(self.client.timeout):
                raise TransportError(f"nothing subscribes {topic} in the simulation (no amcl?)")
        self._pose_pub.publish(msg)

    def spin(self, timeout: float | None, until: Callable[[], bool]) -> None:
        deadline = None if timeout is None else _wall.monotonic() + timeout
        while not until():
            if deadline is not None and _wall.monotonic() >= deadline:
                return
            _wall.sleep(0.02)

    def close(self) -> None:
        """Close the navigator's publishers and subscriptions (the client stays open)."""
        for pub in (self._goal_pub, self._cancel_pub, self._pose_pub):
            if pub is not None:
                pub.close()
        self._goal_pub = self._cancel_pub = self._pose_pub = None
        for sub in self._subs:
            sub.close()
        self._subs.clear()
