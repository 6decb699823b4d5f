"""``{effort,position,velocity}_controllers/JointTrajectoryController``.

As ros_controllers' joint_trajectory_controller: a trajectory arrives on the ``command`` topic
or as a ``follow_joint_trajectory`` action goal, is sampled every physics step
(``fleetsim.control.trajectory``) and sent to the joints: positions as they are (position
interface), or through a PID per joint (``gains/<joint>``) plus ``velocity_ff/<joint>`` times the
desired velocity (effort and velocity interfaces). Tolerances come from ``constraints/``
(``goal_time``, ``stopped_velocity_tolerance``, ``<joint>/trajectory``, ``<joint>/goal``; 0
means not checked) or from the goal. Result codes: INVALID_GOAL, INVALID_JOINTS,
OLD_HEADER_TIMESTAMP (rejections), PATH_TOLERANCE_VIOLATED, GOAL_TOLERANCE_VIOLATED,
SUCCESSFUL. A rejected goal ends as aborted with its code (fleetsim's action server holds one
goal at a time, as SimpleActionServer).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fleetsim.control.controllers.base import Controller, register
from fleetsim.control.pid import Pid, PidArray
from fleetsim.control.trajectory import Trajectory, sample
from fleetsim.errors import ControlError
from fleetsim.msgs import control_msgs, trajectory_msgs
from fleetsim.runtime import param

Result = control_msgs.FollowJointTrajectoryResult


@dataclass(frozen=True)
class JointTrajectoryControllerParams:
    joints: list = param([], help="the controlled joints (required)")
    gains: dict = param({}, help="per joint {p, i, d, i_clamp}; effort and velocity interfaces")
    velocity_ff: dict = param({}, help="per joint velocity feed-forward gain")
    constraints: dict = param(
        {}, help="goal_time, stopped_velocity_tolerance, <joint>/{trajectory,goal}"
    )
    state_publish_rate: float = param(50.0, unit="Hz", range=(0.0, None), help="state topic rate")
    action_monitor_rate: float = param(20.0, unit="Hz", range=(1e-3, None), help="action checks")
    stop_trajectory_duration: float = param(0.0, unit="s", range=(0.0, None), help="stop ramp")
    allow_partial_joints_goal: bool = param(False, help="goals may name a subset of joints")


@dataclass
class Tolerances:
    """Per-joint path and goal position tolerances (rad; 0: unchecked) and the rest."""

    path: np.ndarray
    goal: np.ndarray
    stopped_velocity: float
    goal_time: float


def _number(v, where: str) -> float:
    if isinstance(v, bool) or not isinstance(v, int | float) or v < 0:
        raise ControlError(f"{where}: must be a non-negative number, got {v!r}")
    return float(v)


class GoalError(Exception):
    def __init__(self, code: int, text: str) -> None:
        super().__init__(text)
        self.code = code


@register(
    "effort_controllers/JointTrajectoryController",
    "position_controllers/JointTrajectoryController",
    "velocity_controllers/JointTrajectoryController",
)
class JointTrajectoryController(Controller):
    Params = JointTrajectoryControllerParams

    def __init__(self, runtime, name, namespace, *, hw, type_name) -> None:
        super().__init__(runtime, name, namespace, hw=hw, type_name=type_name)
        p = self.params
        self.joints = [str(j) for j in self._require(p.joints, "joints")]
        hw.check_joints(self.joints, self.interface, self.full_name)
        pids: list[Pid] = []
        if self.interface != "position":
            gains = self._require(p.gains, "gains")
            for j in self.joints:
                if j not in gains:
                    raise ControlError(f"{self.full_name}: no gains/{j} (p, i, d, i_clamp)")
                pids.append(Pid.from_params(gains[j], f"{self.full_name}/gains/{j}"))
        self.pids = PidArray(pids)
        self.ff = np.array([float(p.velocity_ff.get(j, 0.0)) for j in self.joints])
        self.default_tol = self._tolerances(p.constraints)
        self.traj: Trajectory | None = None
        self.tol = self.default_tol
        self.goal_active = False
        self.outcome: tuple[int, str] | None = None
        self.state = control_msgs.JointTrajectoryControllerState(joint_names=list(self.joints))
        self.create_subscription(
            trajectory_msgs.JointTrajectory, "~command", self._on_command, queue_size=1
        )
        self.state_pub = self.create_publisher(
            control_msgs.JointTrajectoryControllerState, "~state", queue_size=1
        )
        self.action = self.create_action_server(
            control_msgs.FollowJointTrajectory,
            "~follow_joint_trajectory",
            goal_callback=self._on_goal,
            preempt_callback=self._on_cancel,
        )
        if p.state_publish_rate > 0:
            self.create_timer(1.0 / p.state_publish_rate, self._publish_state)
        self.create_timer(1.0 / p.action_monitor_rate, self._monitor)

    # ------------------------------------------------------------------ configuration
    def _tolerances(self, c: dict) -> Tolerances:
        where = f"{self.full_name}/constraints"
        known = {"goal_time", "stopped_velocity_tolerance", *self.joints}
        for k in c:
            if k not in known:
                raise ControlError(f"{where}: unknown key '{k}' (not a controller joint)")
        path, goal = np.zeros(len(self.joints)), np.zeros(len(self.joints))
        for i, j in enumerate(self.joints):
            jc = c.get(j, {}) or {}
            path[i] = _number(jc.get("trajectory", 0.0), f"{where}/{j}/trajectory")
            goal[i] = _number(jc.get("goal", 0.0), f"{where}/{j}/goal")
        return Tolerances(
            path,
            goal,
            _number(
                c.get("stopped_velocity_tolerance", 0.01), f"{where}/stopped_velocity_tolerance"
            ),
            _number(c.get("goal_time", 0.0), f"{where}/goal_time"),
        )

    def claimed(self) -> list[str]:
        return list(self.joints)

    # ------------------------------------------------------------------ incoming trajectories
    def _current_desired(self, t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        if self.traj is None:
            q = self.hw.positions(self.joints)
            return q, np.zeros_like(q), np.zeros_like(q)
        return sample(self.traj, t)

    def _trajectory(self, msg, t: float) -> Trajectory:
        """Validate a JointTrajectory and join it onto the current desired state at ``t``."""
        if not self.running:
            raise GoalError(
                Result.INVALID_GOAL, "Can't accept new trajectories. Controller is not running."
            )
        names = list(msg.joint_names)
        if len(set(names)) != len(names):
            raise GoalError(
                Result.INVALID_JOINTS, f"Joints on incoming goal repeat a name: {names}"
            )
        if (set(names) != set(self.joints) and not self.params.allow_partial_joints_goal) or (
            not set(names) <= set(self.joints)
        ):
            raise GoalError(
                Result.INVALID_JOINTS,
                "Joints on incoming goal don't match the controller joints. "
                f"Goal: {names}; controller: {self.joints}",
            )
        if not msg.points:
            raise GoalError(Result.INVALID_GOAL, "Trajectory has no points")
        idx = [names.index(j) if j in names else -1 for j in self.joints]
        stamp = msg.header.stamp.to_sec()
        start = stamp if stamp > 0 else t
        times, pos, vel, acc = [], [], [], []
        has_vel = all(len(pt.velocities) for pt in msg.points)
        has_acc = has_vel and all(len(pt.accelerations) for pt in msg.points)
        p0, v0, a0 = self._current_desired(t)
        last = -np.inf
        for k, pt in enumerate(msg.points):
            tk = pt.time_from_start.to_sec()
            if tk <= last:
                raise GoalError(
                    Result.INVALID_GOAL,
                    f"point {k}: time_from_start {tk} s is not after the previous point's",
                )
            last = tk
            for field in ("positions", "velocities", "accelerations"):
                n = len(getattr(pt, field))
                if n not in (0, len(names)):
                    raise GoalError(
                        Result.INVALID_GOAL, f"point {k}: {n} {field} for {len(names)} joints"
                    )
            if len(pt.positions) != len(names):
                raise GoalError(Result.INVALID_GOAL, f"point {k}: no positions")
            values = [
                np.asarray(getattr(pt, f), np.float64)
                for f in ("positions", "velocities", "accelerations")
            ]
            if not all(np.all(np.isfinite(v)) for v in values):
                raise GoalError(Result.INVALID_GOAL, f"point {k}: values must be finite")
            if start + tk <= t:
                continue  # already in the past: dropped, as the controller does
            row = [p0.copy(), np.zeros_like(p0), np.zeros_like(p0)]
            for i, src in enumerate(idx):
                if src >= 0:
                    row[0][i] = values[0][src]
                    row[1][i] = values[1][src] if has_vel else 0.0
                    row[2][i] = values[2][src] if has_acc else 0.0
            times.append(start + tk)
            pos.append(row[0])
            vel.append(row[1])
            acc.append(row[2])
        if not times:
            code = Result.OLD_HEADER_TIMESTAMP if stamp > 0 else Result.INVALID_GOAL
            raise GoalError(
                code, f"the trajectory ends at {start + last:.3f} s, before now ({t:.3f} s)"
            )
        return Trajectory(
            np.array([t, *times]),
            np.array([p0, *pos]),
            np.array([v0 if has_vel else np.zeros_like(v0), *vel]),
            np.array([a0 if has_acc else np.zeros_like(a0), *acc]),
            5 if has_acc else 3 if has_vel else 1,
        )

    def _on_command(self, msg) -> None:
        try:
            self.traj = self._trajectory(msg, self.now())
        except GoalError as e:
            self.get_logger().error("command rejected: %s", e)
            return
        if self.goal_active and self.action.is_active():
            self.action.set_aborted(Result(error_code=Result.INVALID_GOAL), "replaced by a command")
        self.goal_active = False

    def _goal_tolerances(self, goal) -> Tolerances:
        tol = Tolerances(
            self.default_tol.path.copy(),
            self.default_tol.goal.copy(),
            self.default_tol.stopped_velocity,
            self.default_tol.goal_time,
        )
        for field, arr in (("path_tolerance", tol.path), ("goal_tolerance", tol.goal)):
            for jt in getattr(goal, field):
                if jt.name not in self.joints:
                    raise GoalError(
                        Result.INVALID_GOAL, f"{field} names joint '{jt.name}', not ours"
                    )
                if jt.position > 0:
                    arr[self.joints.index(jt.name)] = jt.position
                elif jt.position < 0:
                    arr[self.joints.index(jt.name)] = 0.0
                if field == "goal_tolerance" and jt.velocity != 0:
                    tol.stopped_velocity = max(jt.velocity, 0.0)
        gt = goal.goal_time_tolerance.to_sec()
        if gt != 0:
            tol.goal_time = max(gt, 0.0)
        return tol

    def _on_goal(self) -> None:
        goal = self.action.accept_new_goal()
        try:
            tol = self._goal_tolerances(goal)
            traj = self._trajectory(goal.trajectory, self.now())
        except GoalError as e:
            self.get_logger().error("goal rejected: %s", e)
            self.goal_active = False
            self.action.set_aborted(Result(error_code=e.code, error_string=str(e)), str(e))
            return
        self.traj, self.tol, self.goal_active, self.outcome = traj, tol, True, None

    def _on_cancel(self) -> None:
        if self.action.next is not None:
            return  # a newer goal preempts this one: _on_goal takes over
        self._hold(self.now())
        self.goal_active = False
        if self.action.is_active():
            self.action.set_preempted(Result(), "canceled; holding position")

    def _hold(self, t: float) -> None:
        self.traj = Trajectory.hold(t, self.hw.positions(self.joints))

    # ------------------------------------------------------------------ control loop
    def starting(self, t: float) -> None:
        self.pids.reset()
        self._hold(t)  # as the controller: hold the current position on start

    def stopping(self, t: float) -> None:
        self.goal_active = False
        if self.action.is_active():
            self.action.set_aborted(Result(error_code=Result.INVALID_GOAL), "controller stopped")

    def update(self, t: float, dt: float) -> None:
        if self.traj is None:
            self._hold(t)
        des_p, des_v, des_a = sample(self.traj, t)
        q, qd = self.hw.states(self.joints)
        err, err_v = des_p - q, des_v - qd
        if self.interface == "position":
            cmd = des_p
        else:
            cmd = self.ff * des_v + self.pids.compute(err, err_v, dt)
        for j, c in zip(self.joints, cmd.tolist(), strict=True):
            self.hw.command(j, c)
        s = self.state
        s.desired.positions, s.desired.velocities, s.desired.accelerations = des_p, des_v, des_a
        s.actual.positions, s.actual.velocities = q, qd
        s.error.positions, s.error.velocities = err, err_v
        if self.goal_active and self.outcome is None:
            self._check(t, err, qd)

    def _check(self, t: float, err: np.ndarray, qd: np.ndarray) -> None:
        tol, end = self.tol, self.traj.end_time
        if t <= end:
            bad = np.nonzero((tol.path > 0) & (np.abs(err) > tol.path))[0]
            if bad.size:
                i = int(bad[0])
                self.outcome = (
                    Result.PATH_TOLERANCE_VIOLATED,
                    f"{self.joints[i]} path error {err[i]:.6f}",
                )
                self._hold(t)
            return
        pos_bad = (tol.goal > 0) & (np.abs(err) > tol.goal)
        vel_bad = (
            np.abs(qd) > tol.stopped_velocity
            if tol.stopped_velocity > 0
            else np.zeros_like(pos_bad)
        )
        if not pos_bad.any() and not vel_bad.any():
            self.outcome = (Result.SUCCESSFUL, "")
        elif t > end + tol.goal_time:
            i = int(np.nonzero(pos_bad | vel_bad)[0][0])
            if pos_bad[i]:
                what = f"goal error {err[i]:.6f} beyond constraints/{self.joints[i]}/goal "
                what += f"{tol.goal[i]:g}"
            else:  # the default 0.01 rad/s catches P-only gains still settling
                what = f"goal velocity {qd[i]:.6f} beyond constraints/stopped_velocity_tolerance "
                what += f"{tol.stopped_velocity:g}"
            what += f" at goal_time {tol.goal_time:g} s after the trajectory's end"
            self.outcome = (Result.GOAL_TOLERANCE_VIOLATED, f"{self.joints[i]} {what}")
            self._hold(t)

    def _monitor(self) -> None:
        if not self.goal_active or not self.action.is_active():
            return
        if self.outcome is None:
            fb = control_msgs.FollowJointTrajectoryFeedback(joint_names=list(self.joints))
            fb.header.stamp = self.now_msg()
            fb.desired, fb.actual, fb.error = (
                self.state.desired,
                self.state.actual,
                self.state.error,
            )
            self.action.publish_feedback(fb)
            return
        code, text = self.outcome
        self.goal_active = False
        result = Result(error_code=code, error_string=text)
        if code == Result.SUCCESSFUL:
            self.action.set_succeeded(result)
        else:
            self.get_logger().warning("goal aborted: %s", text)
            self.action.set_aborted(result, text)

    def _publish_state(self) -> None:
        if self.running:
            self.state.header.stamp = self.now_msg()
            self.state_pub.publish(self.state)
