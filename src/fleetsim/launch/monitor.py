"""What a run achieved, per robot: goals reached, time, path length, collisions.

The monitor listens to each robot's move_base action topics (``<ns>/move_base/goal`` and
``result``), so it counts goals however they were sent (a send_goals node, the CLI, a user
node), and samples the simulator's ground truth for path length and contacts. It listens in the
namespace of every move_base in the plan and of every robot the simulator spawns, so a robot
whose move_base runs in another process (``fleetsim node run``, over the Zenoh bridge) is
counted too.

A goal counts as reached only when the simulator's ground truth agrees: when move_base reports
SUCCEEDED, the robot's true position must be within the local planner's ``xy_goal_tolerance``
(read from the parameter tree, default 0.1 m) plus `GOAL_MARGIN` of the goal. A SUCCEEDED
result that ground truth contradicts (or that no ground truth can confirm) is counted as
unconfirmed and fails the run. Ground truth is the engine when the simulator runs in this
process, else the latest ``/gazebo/model_states`` (the model named as the namespace).

Nodes that send goals for a purpose (send_goals' list, explore's frontiers) are *goal senders*
(`GoalSender`): the monitor finds them among the run's nodes by ``sends_goals = True``; a run's
goals are all done only once every sender is ``done``, and the run succeeds only if every
sender also ``succeeded`` (send_goals: every goal reached; explore: it stopped with no frontier
left, not with frontiers it had blacklisted). A goal a sender cancels itself because it no
longer wants it (explore_lite cancels its active goal when it stops) is listed in the sender's
``withdrawn_goals`` and counts as neither a goal nor a failure, like a goal replaced by
another; any other cancel fails the goal. A goal move_base aborted that its sender moved on
from (``handled_goals``: explore blacklists its frontier and takes the next) fails the goal
but not the run: the sender's own ``succeeded`` says whether it got there in the end (explore:
the frontier was mapped from elsewhere, or it gave up on it).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Protocol

from fleetsim.errors import FleetsimError
from fleetsim.launch.ground_truth import GroundTruth
from fleetsim.launch.model import LaunchPlan
from fleetsim.msgs import actionlib_msgs, gazebo_msgs, move_base_msgs
from fleetsim.runtime import names

SAMPLE_PERIOD = 0.1  # s of sim time between ground-truth samples
#: a contact with the same partner within this long of the last one is the same collision
COLLISION_GAP = 1.0  # s
#: m beyond the goal tolerance that ground truth may put a robot whose goal move_base reports
#: reached: move_base stops within the tolerance of the goal as *localized*, and a working
#: localizer is off by centimetres to a decimetre or two (amcl's particle spread)
GOAL_MARGIN = 0.25
#: base_local_planner's (and dwa_local_planner's) ``xy_goal_tolerance`` default, m
DEFAULT_XY_GOAL_TOLERANCE = 0.1
DEFAULT_LOCAL_PLANNER = "base_local_planner/TrajectoryPlannerROS"


class GoalSender(Protocol):
    """What a goal-sending node tells the monitor (send_goals, explore, a user's node).

    ``sends_goals`` (True) is how the monitor finds it; ``done``: it will send no more goals
    and has the results of those it sent; ``succeeded`` (read once done): it achieved what it
    sent the goals for, False when it gave up. Optional: ``withdrawn_goals``, the ids of goals
    it canceled itself as no longer wanted (their PREEMPTED result is no failure);
    ``handled_goals``, the ids of failed goals it moved on from (they do not fail the run); a node
    without ``succeeded`` counts as succeeded once done (its goals' results still count).
    """

    sends_goals: bool
    #: optional, True for a follower (follow_marker): it sends goals for as long as the run
    #: lasts, so it is never ``done`` (a run waiting for the goals lasts its whole duration)
    #: and that is no failure
    # follows: bool

    @property
    def done(self) -> bool: ...

    @property
    def succeeded(self) -> bool: ...


def _sender_name(sender: Any) -> str:
    """A goal sender's node name (its class name if it is not a node)."""
    return str(getattr(sender, "full_name", type(sender).__name__))


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
    #: each collision's onset: sim time (s), the other model, and this robot's x, y (m)
    collision_events: list[tuple[float, str, float, float]] = field(
        default_factory=list, repr=False
    )
    last_text: str = ""
    #: SUCCEEDED results whose goal ground truth did not confirm (too far, or no ground truth)
    goals_unconfirmed: int = 0
    #: the latest goal, x, y in the map (world) frame, m; None if its frame did not resolve
    goal: tuple[float, float] | None = None
    #: m, ground truth within this of ``goal`` confirms a SUCCEEDED result
    goal_tolerance: float = DEFAULT_XY_GOAL_TOLERANCE + GOAL_MARGIN
    #: m, ground-truth distance to ``goal`` (at the last `RunMonitor.results`)
    distance_to_goal: float | None = None
    #: m, map -> base tf against ground truth, where a localizer publishes map (else None)
    localization_error: float | None = None
    goals_by_id: dict[str, tuple[float, float] | None] = field(default_factory=dict, repr=False)
    #: goals whose frame did not resolve when given (id -> target pose), tried again each
    #: sample: a SLAM map's transform comes with the first processed scan
    unresolved: dict[str, Any] = field(default_factory=dict, repr=False)
    #: the id of the latest goal
    goal_id: str = ""
    #: the ids of the failed goals, in order
    failed_ids: list[str] = field(default_factory=list, repr=False)
    #: a follower (follow_marker) drives it: its newest goal is still going when the run ends,
    #: and that is no failure
    followed: bool = False

    @property
    def all_done(self) -> bool:
        finished = self.goals_reached + self.goals_failed + self.goals_unconfirmed
        return self.goals_sent > 0 and finished >= self.goals_sent

    @property
    def ok(self) -> bool:
        return self.ok_but_for(frozenset())

    def ok_but_for(self, handled: set[str] | frozenset[str]) -> bool:
        """`ok`, with the failed goals whose ids are in ``handled`` counted as no failure."""
        return (
            all(i in handled for i in self.failed_ids)
            and self.goals_unconfirmed == 0
            and self.collisions == 0
            and (self.all_done or self.followed)
        )


class RunMonitor(GroundTruth):
    def __init__(self, runtime, plan: LaunchPlan, nodes: dict[str, Any]) -> None:
        self.runtime = runtime
        self.robots: dict[str, RobotResult] = {}
        # goal senders (`GoalSender`: send_goals, explore, user nodes): a run waits for them
        # before its goals can all be done, and succeeds only if they succeeded
        self.senders = [n for n in nodes.values() if getattr(n, "sends_goals", False)]
        self.sim = next((n for n in nodes.values() if hasattr(n, "engine")), None)
        self._watched: set[str] = set()
        self._move_base: dict[str, str] = {}  # robot namespace -> move_base node name
        for spec in plan.nodes:
            if (spec.pkg, spec.type) == ("move_base", "move_base"):
                self._move_base.setdefault(spec.namespace, names.join(spec.namespace, spec.name))
                self._watch(spec.namespace)
        self._states: dict[str, tuple[float, float]] = {}  # /gazebo/model_states, no local sim
        self.tf = runtime.tf_buffer  # created now, so that it holds every frame from the start
        if self.sim is None:
            runtime.graph.subscribe(
                "/gazebo/model_states", gazebo_msgs.ModelStates, self._on_states, queue_size=1
            )
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
            lambda m, r=r: self._on_goal(r, m),
            queue_size=0,
        )
        graph.subscribe(
            f"{base}/result",
            move_base_msgs.MoveBase.ActionResult,
            lambda m, r=r: self._on_result(r, m),
            queue_size=0,
        )

    def _on_goal(self, r: RobotResult, msg) -> None:
        r.goals_sent += 1
        r.goal_id = msg.goal_id.id
        r.goal = self._goal_in_map(msg.goal.target_pose, r.namespace)
        r.goals_by_id[msg.goal_id.id] = r.goal
        if r.goal is None:
            r.unresolved[msg.goal_id.id] = msg.goal.target_pose
        r.goal_tolerance = self._goal_tolerance(r.namespace) + GOAL_MARGIN

    def _resolve(self, r: RobotResult) -> None:
        """Place the goals whose frames had no transform when they were given, now that
        they may have (tf's patience, as move_base's own)."""
        for goal_id, target in list(r.unresolved.items()):
            xy = self._goal_in_map(target, r.namespace)
            if xy is None:
                continue
            del r.unresolved[goal_id]
            r.goals_by_id[goal_id] = xy
            if goal_id == r.goal_id:
                r.goal = xy

    def _goal_tolerance(self, ns: str) -> float:
        """``xy_goal_tolerance`` of the robot's move_base local planner, from the parameters."""
        node = self._move_base.get(ns, names.join(ns, "move_base"))
        params = self.runtime.params
        try:
            planner = str(params.get(f"{node}/base_local_planner", DEFAULT_LOCAL_PLANNER))
            value = params.get(
                f"{node}/{planner.rsplit('/', 1)[-1]}/xy_goal_tolerance",
                DEFAULT_XY_GOAL_TOLERANCE,
            )
            return float(value)
        except (FleetsimError, TypeError, ValueError):
            return DEFAULT_XY_GOAL_TOLERANCE

    def _on_result(self, r: RobotResult, msg) -> None:
        S = actionlib_msgs.GoalStatus
        self._resolve(r)
        r.unresolved.pop(msg.status.goal_id.id, None)
        goal = r.goals_by_id.pop(msg.status.goal_id.id, r.goal)
        r.last_text = msg.status.text
        if msg.status.status == S.SUCCEEDED:
            self._confirm(r, goal, msg.status.text)
        elif msg.status.status == S.RECALLED or (
            msg.status.status == S.PREEMPTED and "another goal" in msg.status.text
        ):
            r.goals_sent -= 1  # replaced by a newer goal: not a failure, not a goal of its own
        elif msg.status.status == S.PREEMPTED and (
            sender := self._withdrawn_by(msg.status.goal_id.id)
        ):
            r.goals_sent -= 1  # its sender canceled it, no longer wanting it: not a failure
            r.last_text = f"withdrawn by {sender}"
        else:
            r.goals_failed += 1
            r.failed_ids.append(msg.status.goal_id.id)
        r.time_of_last_result = self.runtime.now()

    def _handled_goals(self) -> set[str]:
        """The ids of the failed goals the senders moved on from (``handled_goals``)."""
        handled: set[str] = set()
        for s in self.senders:
            handled.update(getattr(s, "handled_goals", ()))
        return handled

    def _withdrawn_by(self, goal_id: str) -> str:
        """The name of the sender that withdrew goal ``goal_id`` ("" if none did)."""
        for s in self.senders:
            if goal_id in getattr(s, "withdrawn_goals", ()):
                return _sender_name(s)
        return ""

    def all_goals_done(self) -> bool:
        """True once every sender has sent everything and every goal has a result (with
        senders, also when they finished without sending a goal)."""
        if any(not s.done for s in self.senders):
            return False
        active = [r for r in self.robots.values() if r.goals_sent > 0]
        return (bool(active) or bool(self.senders)) and all(r.all_done for r in active)

    def senders_failed(self) -> list[str]:
        """Names of the goal senders that are not done, or done and gave up (followers,
        never done, are not)."""
        return [
            _sender_name(s)
            for s in self.senders
            if not getattr(s, "follows", False)
            and (not s.done or not getattr(s, "succeeded", True))
        ]

    def _confirm(self, r: RobotResult, goal, text: str) -> None:
        """Count a SUCCEEDED result as reached only if ground truth puts the robot at ``goal``."""
        truth = self._true_xy(r.namespace)
        if goal is None:
            r.goals_unconfirmed += 1
            r.last_text = "reported reached; the goal's frame does not resolve to map"
        elif truth is None:
            r.goals_unconfirmed += 1
            r.last_text = "reported reached; no ground truth to confirm it"
        else:
            d = math.hypot(truth[0] - goal[0], truth[1] - goal[1])
            r.distance_to_goal = d
            if d <= r.goal_tolerance:
                r.goals_reached += 1
                r.last_text = text
            else:
                r.goals_unconfirmed += 1
                r.last_text = f"reported reached, {d:.1f} m away by ground truth"

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
            if r.unresolved:
                self._resolve(r)
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
                    r.collision_events.append((now, other, x, y))
                self._last_contact[(model, other)] = now

    # -- summary ------------------------------------------------------------------------
    def results(self) -> list[RobotResult]:
        """Every robot's result, with ground-truth distance and localization error as of now."""
        followed = {
            getattr(s, "namespace", "/").rstrip("/") or "/"
            for s in self.senders
            if getattr(s, "follows", False)
        }
        for ns, r in self.robots.items():
            r.followed = (ns.rstrip("/") or "/") in followed
            truth = self._true_xy(ns)
            if truth is None:
                continue
            if r.goal is not None:
                r.distance_to_goal = math.hypot(truth[0] - r.goal[0], truth[1] - r.goal[1])
            r.localization_error = self._localization_error(ns, truth)
        return [self.robots[k] for k in sorted(self.robots)]

    def failures(self) -> list[str]:
        """Why `success` is False, one line per reason (empty when it is True)."""
        results = self.results()
        rs = [r for r in results if r.goals_sent > 0]
        out = []
        if not rs and not self.senders:
            out.append("no goal was sent (no move_base goal, no goal sender in the run)")
        handled = self._handled_goals()
        for r in rs:
            if r.ok_but_for(handled):
                continue
            why = []
            failed = [i for i in r.failed_ids if i not in handled]
            if failed:
                why.append(f"{len(failed)} failed")
            if r.goals_unconfirmed:
                why.append(f"{r.goals_unconfirmed} reported reached but not confirmed")
            if not r.all_done and not r.followed:
                finished = r.goals_reached + r.goals_failed + r.goals_unconfirmed
                why.append(f"{r.goals_sent - finished} not finished when the run ended")
            if why:
                out.append(
                    f"{r.namespace}: {r.goals_reached}/{r.goals_sent} goals reached; "
                    + ", ".join(why)
                )
        for s in self.senders:
            if getattr(s, "follows", False):
                continue
            if not s.done:
                out.append(f"goal sender {_sender_name(s)} had not finished when the run ended")
            elif not getattr(s, "succeeded", True):
                out.append(f"goal sender {_sender_name(s)} gave up")
        for r in results:
            if r.collisions:
                out.append(f"{r.namespace}: {r.collisions} collision(s)")
        return out

    def success(self) -> bool:
        """Every goal reached (confirmed by ground truth), every goal sender done and
        succeeded, no collision; a run with neither goals nor senders did not succeed
        (`failures` names each reason it did not)."""
        return not self.failures()
