"""The ``move_base`` node: global planner, local planner, two costmaps, recoveries, one goal.

Interface, as ROS move_base (names relative to the node's namespace, e.g. ``/lizi1``):

- action ``move_base`` (move_base_msgs/MoveBase, SimpleActionServer policy: a newer goal
  preempts the active one, a cancel preempts it); topic ``move_base_simple/goal``
  (PoseStamped, re-sent as an action goal);
- publishes ``cmd_vel`` (Twist), ``~current_goal``, ``~NavfnROS/plan``,
  ``~TrajectoryPlannerROS/global_plan`` and ``~TrajectoryPlannerROS/local_plan``, the costmaps
  under ``~global_costmap/`` and ``~local_costmap/``, feedback with the robot pose in the global
  frame; reads ``odom`` for the robot's velocity;
- services ``~make_plan`` (nav_msgs/GetPlan) and ``~clear_costmaps`` (std_srvs/Empty).

The control loop runs every ``1 / controller_frequency`` s and follows move_base.cpp's
``executeCycle``: PLANNING (wait for a plan), CONTROLLING (follow it; on a failure replan, after
``controller_patience`` go CLEARING), CLEARING (run the next recovery behaviour, then plan again;
when none is left, abort). A planning attempt runs at the start of a cycle when one is due:
every ``1 / planner_frequency`` s, or - with ``planner_frequency: 0`` - once per goal and then at
every cycle until a plan is found (ROS's planner thread retries as fast as it can; an attempt
whose inputs have not changed - same costmap update, start cell and goal - is not recomputed).
Planning failures count against ``planner_patience`` (and ``max_planning_retries``).

A goal inside an obstacle, outside the map or unreachable therefore ends ABORTED after the
recoveries, and the abort text carries the planner's typed failure, e.g. ``Failed to find a
valid plan. Even after executing recovery behaviors. navfn: the goal (9.000, 3.000) is off the
global costmap (...)``. The robot is sent a zero Twist on success, abort and preemption.

Differences from ROS, on purpose: nothing blocks, so a goal that arrives before the costmaps have
their map and tf waits (warned about) instead of move_base not yet existing; RotateRecovery turns
one control cycle at a time, so preemption is honoured during recoveries; after an oscillation
timeout no velocity is sent in the same cycle.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from fleetsim.errors import TransformError
from fleetsim.msgs import geometry_msgs, move_base_msgs, nav_msgs, std_msgs
from fleetsim.nav.controllers.global_guard import GlobalCostmapGuard
from fleetsim.nav.controllers.trajectory_planner import TrajectoryPlanner
from fleetsim.nav.costmap.costmap_ros import Costmap2DROS
from fleetsim.nav.move_base_cycle import PLANNING, PLANNING_R, ExecuteCycle
from fleetsim.nav.move_base_plugins import (
    global_planner,
    local_planner_namespace,
    make_local_planner,
    recovery_behaviors,
)
from fleetsim.nav.move_base_support import (
    MoveBaseServices,
    pose_of,
    pose_stamped,
    quaternion_problem,
)
from fleetsim.runtime import Node, load_params, param
from fleetsim.tf.names import normalize_frame
from fleetsim.tf.patience import TransformPatience


@dataclass(frozen=True)
class MoveBaseParams:
    """``move_base`` private parameters (ROS names and defaults)."""

    base_global_planner: str = param("navfn/NavfnROS", help="global planner plugin")
    base_local_planner: str = param(
        "base_local_planner/TrajectoryPlannerROS", help="local planner plugin"
    )
    planner_frequency: float = param(
        0.0, unit="Hz", range=(0.0, None), help="replanning rate (0: on a new goal or failure)"
    )
    controller_frequency: float = param(
        20.0, unit="Hz", range=(1e-6, None), help="control loop rate (cmd_vel rate)"
    )
    planner_patience: float = param(
        5.0, unit="s", range=(0.0, None), help="time to find a plan before recovering"
    )
    controller_patience: float = param(
        15.0, unit="s", range=(0.0, None), help="time without a valid command before recovering"
    )
    max_planning_retries: int | None = param(
        None, range=(0, None), help="failed plans before recovering (unset or -1: no limit)"
    )
    conservative_reset_dist: float = param(
        3.0, unit="m", range=(0.0, None), help="conservative_reset keeps obstacles this close"
    )
    recovery_behavior_enabled: bool = param(True, help="run recovery behaviours at all")
    clearing_rotation_allowed: bool = param(True, help="rotate in place among the defaults")
    shutdown_costmaps: bool = param(False, help="stop the costmaps while there is no goal")
    oscillation_timeout: float = param(
        0.0, unit="s", range=(0.0, None), help="time to move oscillation_distance (0: off)"
    )
    oscillation_distance: float = param(
        0.5, unit="m", range=(0.0, None), help="travel that resets the oscillation timer"
    )
    make_plan_clear_costmap: bool = param(True, help="make_plan clears around the start")
    make_plan_add_unreachable_goal: bool = param(
        True, help="make_plan appends the requested goal to a plan to a nearby one"
    )
    clearing_radius: float | None = param(
        None, unit="m", range=(0.0, None), help="make_plan's clearing (unset: circumscribed)"
    )
    recovery_behaviors: list | None = param(None, help="[{name, type}, ...] (unset: defaults)")


class MoveBase(ExecuteCycle, Node):
    """move_base for one robot namespace."""

    Params = MoveBaseParams
    PARAM_NAMESPACES = (
        "global_costmap",
        "local_costmap",
        "NavfnROS",
        "TrajectoryPlannerROS",
        "DWAPlannerROS",
        "CollvoidLocalPlanner",
        "MPPIController",
        "conservative_reset",
        "aggressive_reset",
        "rotate_recovery",
        "restore_defaults",
    )

    def __init__(self, runtime, name: str = "move_base", namespace: str = "/", **kw: Any):
        super().__init__(runtime, name, namespace, **kw)
        p: MoveBaseParams = self.params
        where = self.full_name
        ns = self._raw_params()
        self.global_costmap = Costmap2DROS(self, "global_costmap")
        self.local_costmap = Costmap2DROS(self, "local_costmap")
        self._unready = TransformPatience()  # an active goal waiting for them
        self._goal_tf = TransformPatience()  # a goal whose frame tf cannot place yet
        self.global_frame = self.global_costmap.global_frame
        self.planner_name, self.planner = global_planner(
            p.base_global_planner, ns, self.global_costmap, where
        )
        self.controller_name, planner_ns = local_planner_namespace(
            p.base_local_planner, ns, p.controller_frequency, where
        )
        self.controller = make_local_planner(
            self,
            self.controller_name,
            planner_ns,
            self.local_costmap,
            f"{where}/{self.controller_name}",
        )
        tp = self.controller
        if isinstance(tp, TrajectoryPlanner) and tp.params.global_costmap_check:
            tp.global_guard = GlobalCostmapGuard(self.global_costmap, self.local_costmap)
        self.recoveries = recovery_behaviors(
            p,
            ns,
            planner_ns,
            self.global_costmap.layered.circumscribed_radius,
            self.local_costmap,
            where,
        )
        self.cmd_pub = self.create_publisher(geometry_msgs.Twist, "cmd_vel", 1)
        self.current_goal_pub = self.create_publisher(geometry_msgs.PoseStamped, "~current_goal", 1)
        self.plan_pub = self.create_publisher(nav_msgs.Path, f"~{self.planner_name}/plan", 1)
        self.global_plan_pub = self.create_publisher(
            nav_msgs.Path, f"~{self.controller_name}/global_plan", 1
        )
        self.local_plan_pub = self.create_publisher(
            nav_msgs.Path, f"~{self.controller_name}/local_plan", 1
        )
        self.server = self.create_action_server(
            move_base_msgs.MoveBase,
            "move_base",
            goal_callback=self._poll_action,
            preempt_callback=self._poll_action,
        )
        self._action_goal_pub = self.create_publisher(
            move_base_msgs.MoveBase.ActionGoal, "move_base/goal", 1
        )
        self.create_subscription(
            geometry_msgs.PoseStamped, "move_base_simple/goal", self.on_simple_goal, 1
        )
        self.create_subscription(nav_msgs.Odometry, "odom", self.on_odom, 1)
        self.services = MoveBaseServices(self)
        self._odom_vel: tuple[float, float, float] | None = None
        self._prev_local: tuple[float, np.ndarray] | None = None
        self.goal_msg: geometry_msgs.PoseStamped | None = None
        self.goal: tuple[float, float, float] | None = None
        self.plan: np.ndarray | None = None
        self.new_plan: np.ndarray | None = None
        self.last_plan_error = ""
        self.last_control_error = ""
        self._goal_error = ""
        self._failed_key: Any = None
        self._reset_clocks()
        self._reset_state(publish=False)
        self.create_timer(1.0 / p.controller_frequency, self.control_cycle)

    # -- parameters ----------------------------------------------------------------------------
    def _raw_params(self) -> dict:
        raw = self.runtime.params.get(self.full_name, {})
        return raw if isinstance(raw, dict) else {}

    def _load_params(self) -> Any:
        """As Node's, reading ROS's -1 (no limit) as unset, and not warning about the
        namespaces of the recovery behaviours listed in ``recovery_behaviors``."""
        raw = self._raw_params()
        if raw.get("max_planning_retries") == -1:
            del raw["max_planning_retries"]
        listed = raw.get("recovery_behaviors")
        extra = [str(e.get("name")) for e in listed or [] if isinstance(e, dict)]
        extra += self._misplaced_planner_params(raw)
        return load_params(
            self.Params,
            raw,
            where=self.full_name,
            ignore=frozenset((*self.PARAM_NAMESPACES, *extra)),
            logger=self.get_logger(),
        )

    def _misplaced_planner_params(self, raw: dict) -> list[str]:
        """TrajectoryPlannerROS's parameters set in move_base's own namespace (a
        base_local_planner_params.yaml without its ``TrajectoryPlannerROS:`` line): each is
        said to be read only under the planner's name, which then runs on its defaults (where
        a plain "unknown parameter" left the why to the user); returns their keys."""
        from fleetsim.nav.controllers.trajectory_params import TrajectoryPlannerParams
        from fleetsim.runtime.params import describe_params

        planner_name = str(raw.get("base_local_planner", "base_local_planner/TrajectoryPlannerROS"))
        if planner_name.rsplit("/", 1)[-1] != "TrajectoryPlannerROS":
            return []  # other planners' names differ (DWA's, collvoid's, MPPI's): not guessed
        own = {i.name for i in describe_params(self.Params)}
        planner = {i.name for i in describe_params(TrajectoryPlannerParams)} - own
        misplaced = sorted(k for k in raw if k in planner)
        if misplaced:
            origin = (getattr(raw, "origins", None) or {}).get(misplaced[0])
            self.get_logger().warning(
                "%s: %s %s TrajectoryPlannerROS's, read only under %s/TrajectoryPlannerROS/ "
                "(put 'TrajectoryPlannerROS:' above %s in its YAML%s); the local planner runs "
                "on its defaults there",
                self.full_name,
                ", ".join(f"'{k}'" for k in misplaced),
                "is" if len(misplaced) == 1 else "are",
                self.full_name,
                "it" if len(misplaced) == 1 else "them",
                f"; '{misplaced[0]}' is set at {origin}" if origin else "",
            )
        return misplaced

    # -- small helpers -------------------------------------------------------------------------
    def publish_zero_velocity(self) -> None:
        self.cmd_pub.publish(geometry_msgs.Twist())

    def _reset_clocks(self) -> None:
        now = self.now()
        self.last_valid_plan = self.last_valid_control = self.last_oscillation_reset = now
        self.oscillation_pose: tuple[float, float, float] | None = None
        self.planning_retries = 0

    def _reset_state(self, publish: bool = True) -> None:
        """move_base's resetState: planner off, back to PLANNING, robot stopped."""
        self.run_planner = False
        self.state = PLANNING
        self.recovery_index = 0
        self.recovery_trigger = PLANNING_R
        self.next_plan_time = self.now()
        self._reset_rotations()
        if publish:
            self.publish_zero_velocity()
        if self.params.shutdown_costmaps:
            self.global_costmap.stop()
            self.local_costmap.stop()

    def _reset_rotations(self) -> None:
        for rec in self.recoveries:
            if rec.rotate is not None:
                rec.rotate.start_angle = None
            if rec.moveback is not None:
                rec.moveback.start = None

    def _wake_planner(self) -> None:
        self.run_planner = True
        self.next_plan_time = self.now()

    def to_global(
        self, ps: geometry_msgs.PoseStamped, warn: bool = True
    ) -> tuple[float, float, float] | None:
        """A PoseStamped as (x, y, yaw) in the global frame (newest tf), or None (reason kept;
        with ``warn``, the active goal's: warned once it has failed for tf's 5 s)."""
        x, y, yaw = pose_of(ps.pose)
        if not ps.header.frame_id:
            self._warn("frame", f"a pose with an empty frame_id is taken in '{self.global_frame}'")
            return x, y, yaw
        frame = normalize_frame(ps.header.frame_id)
        if frame == self.global_frame:
            return x, y, yaw
        try:
            tx, ty, tyaw = self.tf_buffer.lookup_pose2d(self.global_frame, frame, 0.0)
        except TransformError as err:
            self._goal_error = (
                f"Failed to transform the goal pose from {frame} into the {self.global_frame} "
                f"frame: {err}"
            )
            if self.global_frame.rpartition("/")[2] == frame:
                # a goal in the shared 'map' for a robot whose map is its own (gmapping in
                # its namespace: lizi1/map): said at once, not at the planner's patience
                self._goal_error += (
                    f"; this robot's global frame is {self.global_frame}: send the goal in that "
                    f"frame (send_goals' frame_id, fleetsim goal's --frame), or publish a "
                    f"transform linking {frame} and {self.global_frame}"
                )
            if warn and self._goal_tf.missing_too_long("goal", self.now()):
                self._warn("goal_tf", self._goal_error)
            return None
        if warn:
            self._goal_tf.found("goal")
        c, s = math.cos(tyaw), math.sin(tyaw)
        return tx + c * x - s * y, ty + s * x + c * y, math.remainder(tyaw + yaw, 2 * math.pi)

    # -- goals -----------------------------------------------------------------------------------
    def on_simple_goal(self, msg: geometry_msgs.PoseStamped) -> None:
        """``move_base_simple/goal``: wrap it into an action goal (move_base's goalCB)."""
        self._action_goal_pub.publish(
            move_base_msgs.MoveBase.ActionGoal(
                header=std_msgs.Header(stamp=self.now_msg()),
                goal=move_base_msgs.MoveBaseGoal(target_pose=msg),
            )
        )

    def _poll_action(self) -> None:
        """Accept a new goal, or end the active one on a cancel (executeCb's preempt check)."""
        srv = self.server
        if not (
            srv.is_preempt_requested() or (srv.is_new_goal_available() and not srv.is_active())
        ):
            return
        if srv.is_new_goal_available():
            self._start_goal(srv.accept_new_goal())
        elif srv.is_active():
            self._reset_state()
            srv.set_preempted(text="canceled")

    def _start_goal(self, goal: Any) -> None:
        problem = quaternion_problem(goal.target_pose.pose.orientation)
        if problem:
            self._reset_state()
            self.server.set_aborted(
                text=f"Aborting on goal because it was sent with an invalid quaternion: {problem}"
            )
            return
        if self.params.shutdown_costmaps:
            self.global_costmap.start()
            self.local_costmap.start()
        self._unready.found("costmaps")  # a new goal's wait starts now, not at an older one's
        self._goal_tf.found("goal")
        self.goal_msg = goal.target_pose
        self.goal = self.to_global(self.goal_msg)
        self.recovery_index = 0
        self.recovery_trigger = PLANNING_R
        self._reset_rotations()
        self.state = PLANNING
        self._wake_planner()
        self.plan = self.new_plan = None
        self._failed_key = None
        self.last_plan_error = self.last_control_error = ""
        self._reset_clocks()
        shown = self.goal_msg
        if self.goal is not None:
            shown = pose_stamped(*self.goal, self.global_frame, self.now_msg())
        self.current_goal_pub.publish(shown)

    def on_odom(self, msg: nav_msgs.Odometry) -> None:
        t = msg.twist.twist
        self._odom_vel = (t.linear.x, t.linear.y, t.angular.z)

    # -- the control loop ------------------------------------------------------------------------
    def costmaps_ready(self) -> bool:
        return self.global_costmap.initialized and self.local_costmap.initialized

    def control_cycle(self) -> None:
        self._poll_action()
        if not self.server.is_active():
            return
        if not self.costmaps_ready():
            # a goal sent as the robot comes up waits without a word, as ROS's move_base
            # waits for its costmaps' transforms; said once it has waited the costmaps' 5 s
            now = self.now()
            if self._unready.missing_too_long("costmaps", now):
                self._warn(
                    "ready",
                    f"waiting {self._unready.missing_for('costmaps', now):.1f} s for the "
                    "costmaps (map and tf) before acting on the goal; check the map topic(s) "
                    f"{self.global_costmap._map_topics()} and tf to {self.global_frame}",
                )
            self._reset_clocks()
            return
        self._unready.found("costmaps")
        if self.goal is None and self.goal_msg is not None:
            self.goal = self.to_global(self.goal_msg)
        if self.run_planner and (
            self.params.planner_frequency <= 0 or self.now() >= self.next_plan_time - 1e-9
        ):
            self._plan()
        self._execute_cycle()

    def destroy(self) -> None:
        self.global_costmap.destroy()
        self.local_costmap.destroy()
        super().destroy()
