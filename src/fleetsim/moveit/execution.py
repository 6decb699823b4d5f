"""Trajectory execution as MoveIt's TrajectoryExecutionManager does it.

Controllers come from ``controller_list`` (moveit_simple_controller_manager: each entry needs
``name``, ``joints``, ``action_ns`` and ``type``); a trajectory goes to the controller whose
joints cover it, as a FollowJointTrajectory goal on ``/<ns>/<name>/<action_ns>``. Before
sending, its first point must be within ``allowed_start_tolerance`` of the current state;
while it runs, it may take the expected duration times ``allowed_execution_duration_scaling``
plus ``allowed_goal_duration_margin``, after which it is cancelled (TIMED_OUT). Fake execution
(moveit_fake_controller_manager) instead replays the trajectory on
``~fake_controller_joint_states``.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from fleetsim.control.trajectory import Trajectory, sample
from fleetsim.errors import PlanningError
from fleetsim.msgs import control_msgs, moveit_msgs, sensor_msgs

E = moveit_msgs.MoveItErrorCodes
FAKE_RATE = 50.0  # Hz of fake_controller_joint_states


class ExecutionManager:
    """One trajectory at a time; ``done(code, text)`` is called when it ends."""

    def __init__(self, node, controllers: list, fake: bool, settings: dict) -> None:
        self.node = node
        self.fake = fake
        self.settings = settings
        self.controllers = []
        for k, c in enumerate(controllers):
            if fake:  # moveit_fake_controller_manager reads a name and joints (fake_controllers)
                if not isinstance(c, dict) or not all(key in c for key in ("name", "joints")):
                    raise PlanningError(
                        f"{node.full_name}: controller_list[{k}]: a fake controller needs a name "
                        "and joints"
                    )
            elif not isinstance(c, dict) or not all(
                key in c for key in ("name", "joints", "action_ns", "type")
            ):
                raise PlanningError(
                    f"{node.full_name}: controller_list[{k}]: name, joints, action_ns, and type "
                    "must be specifed for each controller"
                )
            self.controllers.append(c)
        self.clients: dict[str, object] = {}
        self.active = None  # (handle or None, deadline, done)
        self.fake_traj: Trajectory | None = None
        self.fake_joints: list[str] = []
        if fake:
            self.fake_pub = node.create_publisher(
                sensor_msgs.JointState, "~fake_controller_joint_states", queue_size=10
            )
            node.create_timer(1.0 / FAKE_RATE, self._fake_tick)
        node.create_timer(0.05, self._monitor)

    def controller_for(self, joints: list[str]) -> dict:
        for c in self.controllers:
            if set(joints) <= set(c["joints"]):
                return c
        raise PlanningError(
            f"Unable to identify any set of controllers that can actuate the specified joints: "
            f"[ {' '.join(joints)} ]"
        )

    def execute(self, traj, current: dict[str, float], done: Callable[[int, str], None]) -> None:
        jt = traj.joint_trajectory
        if self.active is not None:
            self.stop("preempted by a new trajectory", E.PREEMPTED)
        if not jt.points:
            done(E.SUCCESS, "empty trajectory")
            return
        standing = len(jt.points) == 1 and jt.points[0].time_from_start.to_sec() == 0.0
        if not self.fake:
            try:
                controller = self.controller_for(list(jt.joint_names))
            except PlanningError as e:
                done(E.CONTROL_FAILED, str(e))
                return
        tol = float(self.settings.get("allowed_start_tolerance", 0.01))
        first = np.asarray(jt.points[0].positions)
        if not self.fake:
            missing = [j for j in jt.joint_names if j not in current]
            if missing:
                done(
                    E.CONTROL_FAILED,
                    f"Failed to validate trajectory: couldn't receive full "
                    f"current joint state (missing {', '.join(missing)})",
                )
                return
            now = np.array([current[j] for j in jt.joint_names])
            if tol > 0 and np.abs(first - now).max() > tol:
                done(
                    E.CONTROL_FAILED,
                    f"Invalid Trajectory: start point deviates from current "
                    f"robot state more than {tol:g}",
                )
                return
        if standing:  # one point, at rest where the arm is (a plan of a goal already met)
            done(E.SUCCESS, "nothing to move")
            return
        duration = jt.points[-1].time_from_start.to_sec()
        limit = duration * float(
            self.settings.get("allowed_execution_duration_scaling", 1.2)
        ) + float(self.settings.get("allowed_goal_duration_margin", 0.5))
        deadline = self.node.now() + limit
        if self.fake:
            t0 = self.node.now()
            self.fake_joints = list(jt.joint_names)
            self.fake_traj = Trajectory(
                np.array([t0 + p.time_from_start.to_sec() for p in jt.points]),
                np.array([p.positions for p in jt.points], float),
                np.array(
                    [
                        p.velocities if len(p.velocities) else np.zeros(len(jt.joint_names))
                        for p in jt.points
                    ],
                    float,
                ),
                np.zeros((len(jt.points), len(jt.joint_names))),
                3,
            )
            self.active = (None, t0 + duration, done, limit)
            return
        c = controller
        action = f"{c['name']}/{c['action_ns']}"
        if action not in self.clients:
            self.clients[action] = self.node.create_action_client(
                control_msgs.FollowJointTrajectory, action
            )
        client = self.clients[action]
        if not client.wait_for_server():
            done(E.CONTROL_FAILED, f"controller action {client.name} is not available")
            return
        goal = control_msgs.FollowJointTrajectoryGoal(trajectory=jt)

        def on_done(h):
            if self.active is None or self.active[0] is not h:
                return
            self.active = None
            r = h.result
            if (
                r is not None
                and r.error_code == control_msgs.FollowJointTrajectoryResult.SUCCESSFUL
                and h.status == 3
            ):
                done(E.SUCCESS, "")
            else:
                text = (r.error_string if r is not None else "") or h.text
                done(E.CONTROL_FAILED, f"controller {c['name']} failed: {text}")

        handle = client.send_goal(goal, done_cb=on_done)
        self.active = (handle, deadline, done, limit)

    def stop(self, why: str = "stopped", code: int = E.PREEMPTED) -> None:
        if self.active is None:
            return
        handle, _, done, _ = self.active
        self.active = None
        if handle is not None:
            handle.cancel()
        else:
            self.fake_traj = None
        done(code, why)

    def _monitor(self) -> None:
        if self.active is None:
            return
        handle, deadline, done, limit = self.active
        if handle is None:
            if self.node.now() >= deadline:
                self.active = None
                done(E.SUCCESS, "")
            return
        if self.settings.get("execution_duration_monitoring", True) and self.node.now() > deadline:
            paused = getattr(self.node, "physics_paused", lambda: False)()
            self.stop(
                "Controller is taking too long to execute trajectory (the expected upper bound "
                f"for the trajectory execution was {limit:.4f} seconds). Stopping trajectory."
                + (
                    " The simulator's physics is paused (/gazebo/unpause_physics)."
                    if paused
                    else ""
                ),
                E.TIMED_OUT,
            )

    def hold(self, joints: list[str], q) -> None:
        """Fake execution: stand at ``q`` (the fake controllers' initial pose) until a
        trajectory moves the joints."""
        q = np.asarray(q, float)
        self.fake_joints = list(joints)
        z = np.zeros((1, len(joints)))
        self.fake_traj = Trajectory(np.array([self.node.now()]), q[None, :], z, z.copy(), 3)

    def _fake_tick(self) -> None:
        if self.fake_traj is None:
            return
        pos, vel, _ = sample(self.fake_traj, self.node.now())
        msg = sensor_msgs.JointState(name=list(self.fake_joints), position=pos, velocity=vel)
        msg.header.stamp = self.node.now_msg()
        self.fake_pub.publish(msg)
