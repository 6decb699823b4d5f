"""The commander's link to a move_group in another process, over the Zenoh bridge.

What ``MoveGroupCommander`` uses of an in-process move_group, rebuilt on a
``fleetsim.transport.SimulationClient``: the robot model from the namespace's parameters, the
current joint values from ``joint_states``, and action clients speaking actionlib's topics
(``goal``, ``result``; callbacks arrive on Zenoh threads). Waiting is on the wall clock.
"""

from __future__ import annotations

import itertools
import logging
import os
import threading
import time as _wall
from typing import Any

import numpy as np

from fleetsim.errors import PlanningError, TransportError
from fleetsim.runtime import names

_ids = itertools.count(1)


def robot_model(client, ns: str):
    """The RobotModel of namespace ``ns`` from a running simulation's parameters."""
    from fleetsim.description.srdf import parse_srdf
    from fleetsim.description.urdf import parse_urdf
    from fleetsim.moveit.robot_model import RobotModel

    texts = {}
    for key in ("robot_description", "robot_description_semantic"):
        name = names.join(ns, key)
        try:
            texts[key] = client.param("get", name)
        except Exception as e:  # the parameter server answers a missing key with an error
            raise PlanningError(f"{name} is not set in the running simulation ({e})") from None
    robot = parse_urdf(texts["robot_description"], source=names.join(ns, "robot_description"))
    srdf = parse_srdf(
        texts["robot_description_semantic"], names.join(ns, "robot_description_semantic"), robot
    )
    try:
        planning = client.param("get", names.join(ns, "robot_description_planning"))
    except Exception:
        planning = {}
    return RobotModel(robot, srdf, planning if isinstance(planning, dict) else {})


#: wall seconds between checks that the simulation a commander waits on is still there
LIVENESS_PERIOD = 1.0
#: wall seconds the simulation's clock may stand still before a wait gives up (move_group
#: plans inside one callback, the clock standing meanwhile: this is well above a plan's time)
CLOCK_STALL = 60.0


class _Handle:
    def __init__(self) -> None:
        self.result: Any = None
        self.text = ""
        self.status = 0


class RemoteActionClient:
    def __init__(self, client, name: str, action_type) -> None:
        self.client, self.name, self.type = client, name, action_type
        self.handles: dict[str, _Handle] = {}
        self._lock = threading.Lock()
        client.subscribe(f"{name}/result", self._on_result, latched=False)
        self._pub = client.publisher(f"{name}/goal", action_type.ActionGoal)

    def wait_for_server(self) -> bool:
        return self._pub.wait_for_subscribers(self.client.timeout)

    def _on_result(self, received) -> None:
        msg = received.msg
        if isinstance(msg, Exception):
            return
        with self._lock:
            h = self.handles.get(msg.status.goal_id.id)
            if h is not None and h.result is None:
                h.status, h.text, h.result = msg.status.status, msg.status.text, msg.result

    def send_goal(self, goal) -> _Handle:
        from fleetsim.msgs import actionlib_msgs, builtin_interfaces, std_msgs

        now = self.client.sim_time()
        gid = actionlib_msgs.GoalID(
            stamp=builtin_interfaces.Time.from_sec(now),
            id=f"commander-{os.getpid()}-{next(_ids)}-{now:.3f}",
        )
        h = _Handle()
        with self._lock:
            self.handles[gid.id] = h
        self._pub.publish(
            self.type.ActionGoal(header=std_msgs.Header(stamp=gid.stamp), goal_id=gid, goal=goal)
        )
        return h


class RemoteMoveGroup:
    """The parts of a MoveGroup node the commander reads, for a remote robot namespace."""

    def __init__(self, client, ns: str) -> None:
        from fleetsim.moveit.pipeline import PlanningPipeline

        self.model = robot_model(client, ns)
        self.joint_positions: dict[str, float] = {}
        self.pipeline = PlanningPipeline(self.model, np.random.default_rng(0), {})
        self.ns = ns
        self._log = logging.getLogger("fleetsim.moveit.remote")
        client.subscribe(names.join(ns, "joint_states"), self._on_joints, latched=False)

    def _on_joints(self, received) -> None:
        msg = received.msg
        if not isinstance(msg, Exception):
            for n, q in zip(msg.name, msg.position, strict=False):
                self.joint_positions[n] = float(q)

    def current(self, group: str) -> np.ndarray:
        from fleetsim.moveit.planner import PlanFailure
        from fleetsim.msgs.moveit_msgs import MoveItErrorCodes as E

        joints = self.model.active_joints(group)
        missing = [j for j in joints if j not in self.joint_positions]
        if missing:
            raise PlanFailure(
                E.ROBOT_STATE_STALE,
                f"Didn't receive robot state (joint angles) for {', '.join(missing)} on "
                f"{names.join(self.ns, 'joint_states')}",
            )
        return np.array([self.joint_positions[j] for j in joints])

    def frame(self, link: str) -> str:
        return link

    def get_logger(self):
        return self._log


class RemoteSession:
    """Stands in for the in-process ``_Client``: ``move_group``, ``node``, ``wait``."""

    def __init__(self, connect: str | None, ns: str, timeout: float = 5.0) -> None:
        from fleetsim.transport.client import SimulationClient

        self.client = SimulationClient(connect, timeout=2.0)
        self.ns = names.validate_namespace(ns or "/")
        self.node = self
        self.move_group = RemoteMoveGroup(self.client, self.ns)
        deadline = _wall.monotonic() + timeout
        while not self.move_group.joint_positions and _wall.monotonic() < deadline:
            _wall.sleep(0.05)

    def create_action_client(self, action_type, name: str) -> RemoteActionClient:
        return RemoteActionClient(self.client, names.join(self.ns, name), action_type)

    def create_publisher(self, msg_type, name: str):
        pub = self.client.publisher(names.join(self.ns, name), msg_type)
        return pub

    def call(self, name: str, srv_type, request):
        return self.client.call_service(names.join(self.ns, name), request, srv_type)

    def wait(self, until, timeout: float) -> None:
        """Until ``until()`` or ``timeout`` wall seconds; a simulation that goes away or whose
        clock stops meanwhile ends the wait at once (a run that ended had kept a script
        waiting ~10 minutes for a move's answer)."""
        now = _wall.monotonic()
        deadline, next_check = now + timeout, now + LIVENESS_PERIOD
        last_time, advanced_at = None, now
        while not until():
            now = _wall.monotonic()
            if now > deadline:
                raise TransportError(f"no answer from {self.ns}/move_group within {timeout:g} s")
            if now >= next_check:
                next_check = now + LIVENESS_PERIOD
                try:
                    t = self.client.sim_time()
                except TransportError as e:
                    raise TransportError(
                        f"waiting for {self.ns}/move_group: the simulation is gone (its run "
                        f"ended?): {e}"
                    ) from None
                if t != last_time:
                    last_time, advanced_at = t, now
                elif now - advanced_at > CLOCK_STALL:
                    raise TransportError(
                        f"waiting for {self.ns}/move_group: the simulation's clock has stood at "
                        f"{t:.3f} s for {CLOCK_STALL:g} s of wall time"
                    )
            _wall.sleep(0.02)

    def close(self) -> None:
        self.client.close()
