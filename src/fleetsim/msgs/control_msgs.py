"""control_msgs: the FollowJointTrajectory action (ROS 1 layout) and JointTolerance."""

from __future__ import annotations

from typing import ClassVar

from fleetsim.msgs.builtin_interfaces import Duration
from fleetsim.msgs.fields import Seq, bool_, float64, int32, string
from fleetsim.msgs.interfaces import make_action_type
from fleetsim.msgs.registry import message
from fleetsim.msgs.std_msgs import Header
from fleetsim.msgs.trajectory_msgs import JointTrajectory, JointTrajectoryPoint


@message("control_msgs/msg/JointTolerance")
class JointTolerance:
    """Per-joint tolerance: 0 means the controller's default, negative means no limit."""

    name: string
    position: float64
    velocity: float64
    acceleration: float64


@message("control_msgs/msg/FollowJointTrajectoryGoal")
class FollowJointTrajectoryGoal:
    trajectory: JointTrajectory
    path_tolerance: Seq[JointTolerance]
    goal_tolerance: Seq[JointTolerance]
    goal_time_tolerance: Duration


@message("control_msgs/msg/FollowJointTrajectoryResult")
class FollowJointTrajectoryResult:
    SUCCESSFUL: ClassVar[int32] = 0
    INVALID_GOAL: ClassVar[int32] = -1
    INVALID_JOINTS: ClassVar[int32] = -2
    OLD_HEADER_TIMESTAMP: ClassVar[int32] = -3
    PATH_TOLERANCE_VIOLATED: ClassVar[int32] = -4
    GOAL_TOLERANCE_VIOLATED: ClassVar[int32] = -5

    error_code: int32
    error_string: string


@message("control_msgs/msg/FollowJointTrajectoryFeedback")
class FollowJointTrajectoryFeedback:
    header: Header
    joint_names: Seq[string]
    desired: JointTrajectoryPoint
    actual: JointTrajectoryPoint
    error: JointTrajectoryPoint


FollowJointTrajectory = make_action_type(
    "control_msgs",
    "FollowJointTrajectory",
    FollowJointTrajectoryGoal,
    FollowJointTrajectoryResult,
    FollowJointTrajectoryFeedback,
)
FollowJointTrajectoryActionGoal = FollowJointTrajectory.ActionGoal
FollowJointTrajectoryActionResult = FollowJointTrajectory.ActionResult
FollowJointTrajectoryActionFeedback = FollowJointTrajectory.ActionFeedback
FollowJointTrajectoryAction = FollowJointTrajectory.Action


@message("control_msgs/msg/JointTrajectoryControllerState")
class JointTrajectoryControllerState:
    """A JointTrajectoryController's ``state`` topic: desired, actual and error per joint."""

    header: Header
    joint_names: Seq[string]
    desired: JointTrajectoryPoint
    actual: JointTrajectoryPoint
    error: JointTrajectoryPoint


@message("control_msgs/msg/JointControllerState")
class JointControllerState:
    """A single-joint controller's ``state`` topic (JointPositionController)."""

    header: Header
    set_point: float64
    process_value: float64
    process_value_dot: float64
    error: float64
    time_step: float64
    command: float64
    p: float64
    i: float64
    d: float64
    i_clamp: float64
    antiwindup: bool_
