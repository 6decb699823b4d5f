"""What a run achieved, per robot: goals reached, time, path length, collisions.

The monitor listens to each robot's move_base action topics (``<ns>/move_base/goal`` and
``result``), so it counts goals however they were sent (a send_goals node, the CLI, a user
node), and samples the simulator's ground truth for path length and contacts. It listens in the
namespace of every move_base in the plan and of every robot the simulator spawns, so a robot
whose move_base runs in another process (``fleetsim node run``, over the Zenoh bridge) is
counted too.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from fleetsim.launch.model import LaunchPlan
from fleetsim.msgs import actionlib_msgs, move_base_msgs
from fleetsim.runtime import names

SAMPLE_PERIOD = 0.1  # s of sim time between ground-truth samples
#: a contact with the same partner within this long of the last one is the same collision
COLLISION_GAP = 1.0  # s


@dataclass
class RobotResult:
    namespace: str
    model: str = ""
    goals_sent: int = 0
    goals_reached: int = 0
    goals_failed: int = 0
    time_of_last_result: float | None = None
    path_length: float = 0.0
    collisions: int = 0
    last_text: str = ""

    @property
    def all_done(self) -> bool:
        return self.goals_sent > 0 and self.goals_reached + self.goals_failed >= self.goals_sent

    @property
    def ok(self) -> bool:
        return self.goals_failed == 0 and self.collisions == 0 and self.all_done


class RunMonitor:
    def __init__(self, runtime, plan: LaunchPlan, nodes: dict[str, Any]) -> None:
        self.runtime = runtime
        self.robots: dict[str, RobotResult] = {}
        # nodes that send goals (send_goals, user nodes) say so with `sends_goals = True` and
        # a `done` property; a run waits for them before its goals can all be done
        self.senders = [n for n in nodes.values() if getattr(n, "sends_goals", False)]
        self.sim = next((n for n in nodes.values() if hasattr(n, "engine")), None)
        self._watched: set[str] = set()
        for spec in plan.nodes:
            if (spec.pkg, spec.type) == ("move_base", "move_base"):
                self._watch(spec.namespace)
        self._last_pos: dict[str, tuple[float, float]] = {}
        self._last_contact: dict[tuple[str, str], float] = {}
        if self.sim is not None:
            runtime.create_timer(SAMPLE_PERIOD, self._sample, priority=-40)

    # -- goals --------------------------------------------------------------------------
    def _watch(self, ns: str) -> None:
        """Count the goals and results of the move_base action in robot namespace ``ns``."""
        if ns in self._watched:
            return
        self._watched.add(ns)
        r = self.robots.setdefault(ns, RobotResult(ns))
        # move_base serves its action in the robot's namespace, whatever the node's name
        # (the lesson names the node move_base_node)
        base = names.join(ns, "move_base")
        graph = self.runtime.graph
        graph.subscribe(
            f"{base}/goal",
            move_base_msgs.MoveBase.ActionGoal,
            lambda _m, r=r: self._on_goal(r),
            queue_size=0,
        )
        graph.subscribe(
            f"{base}/result",
            move_base_msgs.MoveBase.ActionResult,
            lambda m, r=r: self._on_result(r, m),
            queue_size=0,
        )

    def _on_goal(self, r: RobotResult) -> None:
        r.goals_sent += 1

    def _on_result(self, r: RobotResult, msg) -> None:
        S = actionlib_msgs.GoalStatus
        if msg.status.status == S.SUCCEEDED:
            r.goals_reached += 1
        elif msg.status.status == S.RECALLED or (
            msg.status.status == S.PREEMPTED and "another goal" in msg.status.text
        ):
            r.goals_sent -= 1  # replaced by a newer goal: not a failure, not a goal of its own
        else:
            r.goals_failed += 1
        r.last_text = msg.status.text
        r.time_of_last_result = self.runtime.now()

    def all_goals_done(self) -> bool:
        """True once every sender has sent everything and every goal has a result."""
        if any(not s.done for s in self.senders):
            return False
        active = [r for r in self.robots.values() if r.goals_sent > 0]
        return bool(active) and all(r.all_done for r in active)

    # -- ground truth -------------------------------------------------------------------
    def _robot_models(self) -> dict[str, str]:
        engine = self.sim.engine
        out = {}
        for name, entry in engine.models.items():
            if entry.kind == "robot":
                out[entry.namespace.rstrip("/") or "/"] = name
        return out

    def _sample(self) -> None:
        engine = self.sim.engine
        models = self._robot_models()
        touching: dict[str, set[str]] = {m: set() for m in models.values()}
        for c in engine.contacts():
            for me, other in ((c.model1, c.model2), (c.model2, c.model1)):
                if me in touching:
                    touching[me].add(other)
        for ns, model in models.items():
            self._watch(ns)  # a spawned robot's move_base may live in another process
            r = self.robots[ns]
            r.model = model
            pos, _ = engine.model_pose(model)
            x, y = float(pos[0]), float(pos[1])
            last = self._last_pos.get(model)
            if last is not None:
                r.path_length += math.hypot(x - last[0], y - last[1])
            self._last_pos[model] = (x, y)
            now = self.runtime.now()
            for other in touching[model]:
                last = self._last_contact.get((model, other))
                if last is None or now - last > COLLISION_GAP:
                    r.collisions += 1  # a new collision, not the same one going on
                self._last_contact[(model, other)] = now

    # -- summary ------------------------------------------------------------------------
    def results(self) -> list[RobotResult]:
        return [self.robots[k] for k in sorted(self.robots)]

    def success(self) -> bool:
        rs = [r for r in self.results() if r.goals_sent > 0]
        return bool(rs) and all(r.ok for r in rs) and all(r.collisions == 0 for r in self.results())
