"""``send_goals``: goals for several robots from parameters, like the lesson's send_goals program.

Each robot's goals are sent in order to its ``<ns>/move_base`` action; the next goal goes out
once the previous one has a result. Outcomes are logged and kept per robot (`results`), with
`done` once every robot has been through its list (never, with ``loop``).

Parameters (private namespace, e.g. ``/send_goals/goals``)::

    goals:            # {robot_ns: [[x, y, yaw], ...]}
      lizi1: [[35.0, 20.0, 0.0], [20.0, 15.0, 3.14]]
      lizi2: [[30.0, 40.0, 1.57]]
    # or a list:  [{ns: lizi1, x: 35.0, y: 20.0, yaw: 0.0}, ...]
    frame_id: map
    start_delay: 1.0  # sim seconds before the first goals
    loop: false       # start over after the last goal
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from fleetsim.errors import ParameterError
from fleetsim.nav.navigator import pose_stamped, task_result_of
from fleetsim.runtime import Node, names, param

#: how often the node checks whether it may send (start_delay, servers appearing), Hz
TICK_RATE = 10.0


@dataclass(frozen=True)
class SendGoalsParams:
    goals: dict | list = param(
        {}, help="{robot_ns: [[x, y, yaw], ...]} or [{ns, x, y, yaw}, ...] (m, rad)"
    )
    frame_id: str = param("map", help="frame of the goal poses")
    start_delay: float = param(0.0, unit="s", range=(0.0, None), help="sim time before sending")
    loop: bool = param(False, help="after a robot's last goal, start its list again")


@dataclass(frozen=True)
class GoalOutcome:
    """One goal's result: robot namespace, index in its list, goal (x, y, yaw), whether it
    was reached (SUCCEEDED), actionlib status name and text, sim time sent and taken (s)."""

    ns: str
    index: int
    goal: tuple[float, float, float]
    reached: bool
    status: str
    text: str
    sent_at: float
    duration: float


_STATUS = (
    "PENDING ACTIVE PREEMPTED SUCCEEDED ABORTED REJECTED PREEMPTING RECALLING RECALLED LOST"
).split()


def goals_from_param(value: Any, where: str = "~goals") -> dict[str, list[tuple[float, ...]]]:
    """``{"/lizi1": [(x, y, yaw), ...]}`` from the ``goals`` parameter (either form)."""
    out: dict[str, list[tuple[float, float, float]]] = {}

    def number(v: Any, what: str) -> float:
        if isinstance(v, bool) or not isinstance(v, int | float) or not math.isfinite(v):
            raise ParameterError(f"{what} must be a finite number (m or rad), got {v!r}")
        return float(v)

    def add(ns: Any, xyz: list[Any], what: str) -> None:
        if not isinstance(ns, str) or not ns.strip("/"):
            raise ParameterError(
                f"{what}: the robot namespace must be a name like lizi1, got {ns!r}"
            )
        key = names.validate_namespace("/" + ns.strip("/"))
        x, y = number(xyz[0], f"{what} x"), number(xyz[1], f"{what} y")
        yaw = number(xyz[2], f"{what} yaw") if len(xyz) > 2 else 0.0
        out.setdefault(key, []).append((x, y, yaw))

    if isinstance(value, dict):
        for ns, items in value.items():
            if not isinstance(items, list | tuple):
                raise ParameterError(
                    f"{where}[{ns!r}] must be a list of [x, y, yaw] goals, got {items!r}"
                )
            for i, g in enumerate(items):
                what = f"{where}[{ns!r}][{i}]"
                if not isinstance(g, list | tuple) or len(g) not in (2, 3):
                    raise ParameterError(f"{what} must be [x, y] or [x, y, yaw], got {g!r}")
                add(ns, list(g), what)
    elif isinstance(value, list | tuple):
        for i, g in enumerate(value):
            what = f"{where}[{i}]"
            if not isinstance(g, dict) or not {"ns", "x", "y"} <= set(g):
                raise ParameterError(f"{what} must be a mapping with ns, x, y (and yaw), got {g!r}")
            extra = set(g) - {"ns", "x", "y", "yaw"}
            if extra:
                raise ParameterError(f"{what}: unknown keys {sorted(extra)} (use ns, x, y, yaw)")
            add(g["ns"], [g["x"], g["y"], g.get("yaw", 0.0)], what)
    else:
        raise ParameterError(f"{where} must be a mapping or a list, got {value!r}")
    return out


class _Robot:
    """One robot's progress through its goals."""

    def __init__(self, ns: str, goals: list[tuple[float, float, float]], client: Any) -> None:
        self.ns = ns
        self.goals = goals
        self.client = client
        self.index = 0
        self.handle: Any = None
        self.sent_at = 0.0
        self.finished = False
        self.warned = False


class SendGoals(Node):
    """Sends each robot's goals in order through move_base and records the outcomes."""

    #: the launch run monitor waits for `done` before a run's goals can all be done
    sends_goals = True

    Params = SendGoalsParams

    def __init__(self, runtime, name: str = "send_goals", namespace: str = "/", **kw: Any):
        super().__init__(runtime, name, namespace, **kw)
        from fleetsim.msgs import move_base_msgs

        p = self.params
        goals = goals_from_param(p.goals, f"{self.full_name}/goals")
        if not goals:
            self.get_logger().warning("no goals given (parameter ~goals is empty)")
        self.results: dict[str, list[GoalOutcome]] = {ns: [] for ns in goals}
        self._robots = [
            _Robot(
                ns,
                g,
                self.create_action_client(move_base_msgs.MoveBase, names.join(ns, "move_base")),
            )
            for ns, g in goals.items()
        ]
        self._start = self.now() + p.start_delay
        self.create_timer(1.0 / TICK_RATE, self._tick)

    @property
    def done(self) -> bool:
        """True once every robot has had a result for each of its goals (never with loop)."""
        return all(r.finished for r in self._robots)

    @property
    def succeeded(self) -> bool:
        """True once done with every goal reached (the run monitor's `GoalSender`); a node
        given no goals did not succeed."""
        outcomes = [o for outs in self.results.values() for o in outs]
        return self.done and bool(outcomes) and all(o.reached for o in outcomes)

    def _tick(self) -> None:
        if self.now() < self._start - 1e-9:
            return
        for r in self._robots:
            if r.handle is None and not r.finished:
                self._send(r)

    def _send(self, r: _Robot) -> None:
        from fleetsim.msgs import move_base_msgs

        if not r.client.wait_for_server():
            if not r.warned:
                self.get_logger().warning(f"waiting for the action server {r.client.name}")
                r.warned = True
            return
        x, y, yaw = r.goals[r.index]
        goal = move_base_msgs.MoveBaseGoal(
            target_pose=pose_stamped(x, y, yaw, self.params.frame_id, self.now())
        )
        r.sent_at = self.now()
        self.get_logger().info(
            f"{r.ns}: goal {r.index + 1}/{len(r.goals)} ({x:.2f}, {y:.2f}, yaw {yaw:.2f})"
        )
        r.handle = r.client.send_goal(goal, done_cb=lambda h, r=r: self._on_done(r, h))

    def _on_done(self, r: _Robot, handle: Any) -> None:
        status = _STATUS[handle.status] if 0 <= handle.status < len(_STATUS) else str(handle.status)
        reached = task_result_of(handle.status).name == "SUCCEEDED"
        out = GoalOutcome(
            ns=r.ns,
            index=r.index,
            goal=r.goals[r.index],
            reached=reached,
            status=status,
            text=handle.text,
            sent_at=r.sent_at,
            duration=self.now() - r.sent_at,
        )
        self.results[r.ns].append(out)
        log = self.get_logger().info if reached else self.get_logger().warning
        log(
            f"{r.ns}: goal {r.index + 1}/{len(r.goals)} {'reached' if reached else status} "
            f"after {out.duration:.1f} s{': ' + handle.text if handle.text else ''}"
        )
        r.handle = None
        r.index += 1
        if r.index == len(r.goals):
            if self.params.loop:
                r.index = 0
            else:
                r.finished = True
                return
        self._send(r)

    def results_table(self) -> list[dict[str, Any]]:
        """One row per goal outcome, robots in parameter order: for a run's results table."""
        return [
            {
                "robot": o.ns.strip("/"),
                "goal": o.index + 1,
                "x": o.goal[0],
                "y": o.goal[1],
                "yaw": o.goal[2],
                "reached": o.reached,
                "status": o.status,
                "text": o.text,
                "time_s": round(o.duration, 3),
            }
            for outcomes in self.results.values()
            for o in outcomes
        ]
