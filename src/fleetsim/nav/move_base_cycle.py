"""move_base's executeCycle: the PLANNING / CONTROLLING / CLEARING state machine.

`ExecuteCycle` is mixed into `fleetsim.nav.move_base.MoveBase`, which owns the costmaps, the
planner, the controller, the recoveries, the action server and the publishers; this module holds
one planning attempt (`_plan`, move_base's planThread body) and one control cycle
(`_execute_cycle`), as move_base.cpp writes them. See move_base.py for the behaviour.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from fleetsim.errors import FleetsimError, TransformError
from fleetsim.msgs import geometry_msgs, move_base_msgs
from fleetsim.nav.costmap import LETHAL_OBSTACLE
from fleetsim.nav.errors import ControllerError, GoalOccupied, GoalOutsideMap, PlannerError
from fleetsim.nav.move_base_support import path_msg, pose_stamped, poses_in_frame

PLANNING, CONTROLLING, CLEARING = "PLANNING", "CONTROLLING", "CLEARING"
PLANNING_R, CONTROLLING_R, OSCILLATION_R = "PLANNING_R", "CONTROLLING_R", "OSCILLATION_R"
ABORT_TEXT = {
    PLANNING_R: "Failed to find a valid plan. Even after executing recovery behaviors.",
    CONTROLLING_R: "Failed to find a valid control. Even after executing recovery behaviors.",
    OSCILLATION_R: "Robot is oscillating. Even after executing recovery behaviors.",
}


class ExecuteCycle:
    """The planning attempt and the control cycle of `MoveBase` (a mixin; see the module)."""

    def _in_a_map_wall(self, goal) -> bool:
        """Whether ``goal`` (x, y, ...) lies on a lethal cell of a static layer's map (the
        map itself, not another robot standing there or the inflation round a wall)."""
        for layer in self.global_costmap._static_layers():
            grid = layer.map_grid
            cell = grid.world_to_map(*goal[:2]) if grid is not None else None
            if cell is not None and grid.costs[cell[1], cell[0]] == LETHAL_OBSTACLE:
                return True
        return False

    def _plan(self) -> None:
        """One planning attempt (move_base's planThread body)."""
        p, now = self.params, self.now()
        if p.planner_frequency > 0:
            self.next_plan_time = now + 1.0 / p.planner_frequency
        path, err = None, ""
        start = self.global_costmap.robot_pose()
        if start is None:
            err = "Unable to get starting pose of robot, unable to create global plan"
        elif self.goal is None:
            err = self._goal_error
        else:
            res = self.global_costmap.costmap.resolution
            key = (
                self.global_costmap.update_count,
                round(start[0] / res),
                round(start[1] / res),
                self.goal,
            )
            if key == self._failed_key:
                err = self.last_plan_error
            else:
                try:
                    path = self.planner.create_plan(start, self.goal).poses
                except PlannerError as e:
                    err, self._failed_key = str(e), key
                    gc = self.global_costmap
                    # navfn_ros warns at once of a goal off a static map (not of one off its
                    # planning window, which moves with the robot)
                    if (
                        isinstance(e, GoalOutsideMap)
                        and not gc.layered.rolling_window
                        and gc.costmap.world_to_map(*self.goal[:2]) is None
                    ):
                        self._warn(
                            f"goal off map {self.goal}",  # once a goal
                            f"{err}: planning will always fail to this goal; move_base aborts "
                            "it after its planner_patience and recovery behaviors",
                            period=math.inf,
                        )
                    elif (
                        isinstance(e, GoalOccupied)
                        and not gc.layered.rolling_window
                        and self._in_a_map_wall(self.goal)
                    ):
                        # a fleetsim addition: navfn says nothing until move_base gives up
                        self._warn(
                            f"goal in map wall {self.goal}",  # once a goal
                            f"{err}: the goal is in a wall of the map, so planning fails while "
                            "the map holds it; move_base aborts it after its planner_patience "
                            "and recovery behaviors",
                            period=math.inf,
                        )
        if path is not None:
            self.last_valid_plan = now
            self.planning_retries = 0
            self.new_plan = path
            # the Path (a PoseStamped per cell, ~1 ms for a long plan) only for a subscriber
            frame, stamp = self.global_frame, self.now_msg()
            self.plan_pub.publish_lazily(lambda: path_msg(path, frame, stamp))
            if self.run_planner:
                self.state = CONTROLLING
            if p.planner_frequency <= 0:
                self.run_planner = False
            return
        self.last_plan_error = err
        if self.state != PLANNING:
            return
        self.planning_retries += 1
        retries = p.max_planning_retries
        if self.run_planner and (
            now > self.last_valid_plan + p.planner_patience
            or (retries is not None and self.planning_retries > retries)
        ):
            self.state = CLEARING
            self.run_planner = False
            self.publish_zero_velocity()
            self.recovery_trigger = PLANNING_R

    def _execute_cycle(self) -> None:
        p, now, srv = self.params, self.now(), self.server
        pose = self.global_costmap.robot_pose()
        if pose is not None:
            srv.publish_feedback(
                move_base_msgs.MoveBaseFeedback(
                    base_position=pose_stamped(*pose, self.global_frame, self.now_msg())
                )
            )
            osc = self.oscillation_pose
            if osc is None or math.dist(pose[:2], osc[:2]) >= p.oscillation_distance:
                self.last_oscillation_reset = now
                self.oscillation_pose = pose
                if self.recovery_trigger == OSCILLATION_R:
                    self.recovery_index = 0
        if not self.local_costmap.is_current():
            self._warn(
                "current",
                "Sensor data is out of date, we're not going to allow commanding of the base for "
                "safety",
            )
            self.publish_zero_velocity()
            return
        if self.new_plan is not None:
            self.plan, self.new_plan = self.new_plan, None
            try:
                self._give_plan(reset=True)
            except (ControllerError, TransformError) as err:
                self._reset_state()
                srv.set_aborted(text=f"Failed to pass global plan to the controller: {err}")
                return
            if self.recovery_trigger == PLANNING_R:
                self.recovery_index = 0
        if self.state == PLANNING:
            if not self.run_planner:
                self._wake_planner()
        elif self.state == CONTROLLING:
            self._control(now)
        else:
            self._clear(now)

    def _control(self, now: float) -> None:
        p, srv = self.params, self.server
        if self.controller.is_goal_reached():
            self._reset_state()
            srv.set_succeeded(text="Goal reached.")
            return
        if p.oscillation_timeout > 0 and self.last_oscillation_reset + p.oscillation_timeout < now:
            self.publish_zero_velocity()
            self.state, self.recovery_trigger = CLEARING, OSCILLATION_R
            return
        try:
            local = self.local_costmap.robot_pose()
            if local is None:
                raise ControllerError(
                    f"cannot get the robot pose in {self.local_costmap.global_frame}"
                )
            if self.local_costmap.global_frame != self.global_frame:
                self._give_plan(reset=False)
            cmd = self.controller.compute_velocity_commands(local, self._velocity(local))
        except (FleetsimError, TransformError) as err:
            self.last_control_error = str(err)
            if now > self.last_valid_control + p.controller_patience:
                self.publish_zero_velocity()
                self.state, self.recovery_trigger = CLEARING, CONTROLLING_R
            else:
                self.last_valid_plan = now
                self.planning_retries = 0
                self.state = PLANNING
                self.publish_zero_velocity()
                self._wake_planner()
            return
        self.last_valid_control = now
        twist = geometry_msgs.Twist(
            linear=geometry_msgs.Vector3(x=cmd.vx, y=cmd.vy),
            angular=geometry_msgs.Vector3(z=cmd.vtheta),
        )
        self.cmd_pub.publish(twist)
        if self.local_plan_pub.get_num_connections():
            frame = self.local_costmap.global_frame
            self.local_plan_pub.publish(path_msg(self.controller.local_plan, frame, self.now_msg()))
        if self.recovery_trigger == CONTROLLING_R:
            self.recovery_index = 0

    def _clear(self, now: float) -> None:
        p, srv = self.params, self.server
        if p.recovery_behavior_enabled and self.recovery_index < len(self.recoveries):
            if not self._run_recovery(self.recoveries[self.recovery_index]):
                return
            self.last_oscillation_reset = now
            self.state = PLANNING
            self._wake_planner()
            self.recovery_index += 1
            self.last_valid_plan = now
            self.planning_retries = 0
            return
        reason = {PLANNING_R: self.last_plan_error, CONTROLLING_R: self.last_control_error}.get(
            self.recovery_trigger, ""
        )
        text = ABORT_TEXT[self.recovery_trigger] + (f" {reason}" if reason else "")
        self.get_logger().error(text)
        self._reset_state()
        srv.set_aborted(text=text)

    def _run_recovery(self, rec: Any) -> bool:
        """Run (or continue) one recovery; True once it is finished."""
        if rec.clear is not None:
            which = rec.clear.params.affected_maps
            for cm in (self.global_costmap, self.local_costmap):
                if which != "both" and (cm is self.global_costmap) != (which == "global"):
                    continue
                pose = cm.robot_pose() or cm.last_pose
                if pose is not None:
                    rec.clear.run([cm.layered], pose[0], pose[1])
                    cm.mark_full_update()
            self.get_logger().info(f"recovery '{rec.name}': cleared the costmaps ({which})")
            return True
        pose = self.local_costmap.robot_pose()
        if pose is None:
            return True
        if rec.moveback is not None:
            cmd = rec.moveback.command(*pose, self.now())
            if cmd is None:  # moveback_recovery logs each ending at INFO
                self.get_logger().info(f"recovery '{rec.name}': {rec.moveback.outcome}")
                self.publish_zero_velocity()
                return True
            self.cmd_pub.publish(geometry_msgs.Twist(linear=geometry_msgs.Vector3(x=cmd.vx)))
            return False
        cmd = rec.rotate.command(*pose)
        if cmd is None:
            if rec.rotate.aborted:
                self.get_logger().warning(f"recovery '{rec.name}': {rec.rotate.aborted}")
            self.publish_zero_velocity()
            return True
        self.cmd_pub.publish(geometry_msgs.Twist(angular=geometry_msgs.Vector3(z=cmd.vtheta)))
        return False

    def _give_plan(self, reset: bool) -> None:
        """Hand the global plan to the controller in the local costmap's frame."""
        frame = self.local_costmap.global_frame
        poses = self.plan
        if frame != self.global_frame:
            poses = poses_in_frame(self.tf_buffer, poses, self.global_frame, frame)
        latch = self.controller.xy_tolerance_latch
        self.controller.set_plan(poses)
        if not reset:
            self.controller.xy_tolerance_latch = latch
        elif self.global_plan_pub.get_num_connections():
            self.global_plan_pub.publish(path_msg(poses, frame, self.now_msg()))

    def _velocity(self, local: tuple[float, float, float]) -> tuple[float, float, float]:
        """The robot's velocity in its base frame: from ``odom``, else from pose differences."""
        now = self.now()
        prev, self._prev_local = self._prev_local, (now, np.asarray(local))
        if self._odom_vel is not None:
            return self._odom_vel
        if prev is None or now <= prev[0]:
            return (0.0, 0.0, 0.0)
        dt = now - prev[0]
        dx, dy = local[0] - prev[1][0], local[1] - prev[1][1]
        c, s = math.cos(local[2]), math.sin(local[2])
        dyaw = math.remainder(local[2] - prev[1][2], 2 * math.pi)
        return ((c * dx + s * dy) / dt, (-s * dx + c * dy) / dt, dyaw / dt)
