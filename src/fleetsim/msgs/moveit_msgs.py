"""moveit_msgs (1.x layout, the fields fleetsim's move_group reads and fills): error codes, robot
state and trajectories, constraints, motion plan request/response, planning scene, and the
move_group / execute_trajectory actions with the planning, IK, FK, Cartesian path and scene
services."""

from __future__ import annotations

from typing import ClassVar

from fleetsim.msgs.builtin_interfaces import Duration
from fleetsim.msgs.fields import Seq, bool_, float64, int32, string, uint32
from fleetsim.msgs.geometry_msgs import Pose, PoseStamped, Quaternion, Vector3
from fleetsim.msgs.interfaces import make_action_type, make_srv_type
from fleetsim.msgs.registry import message
from fleetsim.msgs.sensor_msgs import JointState
from fleetsim.msgs.shape_msgs import SolidPrimitive
from fleetsim.msgs.std_msgs import Header
from fleetsim.msgs.trajectory_msgs import JointTrajectory


@message("moveit_msgs/msg/MoveItErrorCodes")
class MoveItErrorCodes:
    SUCCESS: ClassVar[int32] = 1
    FAILURE: ClassVar[int32] = 99999
    PLANNING_FAILED: ClassVar[int32] = -1
    INVALID_MOTION_PLAN: ClassVar[int32] = -2
    MOTION_PLAN_INVALIDATED_BY_ENVIRONMENT_CHANGE: ClassVar[int32] = -3
    CONTROL_FAILED: ClassVar[int32] = -4
    UNABLE_TO_AQUIRE_SENSOR_DATA: ClassVar[int32] = -5
    TIMED_OUT: ClassVar[int32] = -6
    PREEMPTED: ClassVar[int32] = -7
    START_STATE_IN_COLLISION: ClassVar[int32] = -10
    START_STATE_VIOLATES_PATH_CONSTRAINTS: ClassVar[int32] = -11
    GOAL_IN_COLLISION: ClassVar[int32] = -12
    GOAL_VIOLATES_PATH_CONSTRAINTS: ClassVar[int32] = -13
    GOAL_CONSTRAINTS_VIOLATED: ClassVar[int32] = -14
    INVALID_GROUP_NAME: ClassVar[int32] = -15
    INVALID_GOAL_CONSTRAINTS: ClassVar[int32] = -16
    INVALID_ROBOT_STATE: ClassVar[int32] = -17
    INVALID_LINK_NAME: ClassVar[int32] = -18
    INVALID_OBJECT_NAME: ClassVar[int32] = -19
    FRAME_TRANSFORM_FAILURE: ClassVar[int32] = -21
    COLLISION_CHECKING_UNAVAILABLE: ClassVar[int32] = -22
    ROBOT_STATE_STALE: ClassVar[int32] = -23
    SENSOR_INFO_STALE: ClassVar[int32] = -24
    COMMUNICATION_FAILURE: ClassVar[int32] = -25
    START_STATE_INVALID: ClassVar[int32] = -26
    GOAL_STATE_INVALID: ClassVar[int32] = -27
    UNRECOGNIZED_GOAL_TYPE: ClassVar[int32] = -28
    CRASH: ClassVar[int32] = -29
    ABORT: ClassVar[int32] = -30
    NO_IK_SOLUTION: ClassVar[int32] = -31

    val: int32


@message("moveit_msgs/msg/RobotState")
class RobotState:
    joint_state: JointState
    is_diff: bool_


@message("moveit_msgs/msg/RobotTrajectory")
class RobotTrajectory:
    joint_trajectory: JointTrajectory


@message("moveit_msgs/msg/JointConstraint")
class JointConstraint:
    joint_name: string
    position: float64
    tolerance_above: float64
    tolerance_below: float64
    weight: float64


@message("moveit_msgs/msg/BoundingVolume")
class BoundingVolume:
    primitives: Seq[SolidPrimitive]
    primitive_poses: Seq[Pose]


@message("moveit_msgs/msg/PositionConstraint")
class PositionConstraint:
    """The ``link_name`` point ``target_point_offset`` lies inside ``constraint_region``."""

    header: Header
    link_name: string
    target_point_offset: Vector3
    constraint_region: BoundingVolume
    weight: float64


@message("moveit_msgs/msg/OrientationConstraint")
class OrientationConstraint:
    header: Header
    orientation: Quaternion
    link_name: string
    absolute_x_axis_tolerance: float64
    absolute_y_axis_tolerance: float64
    absolute_z_axis_tolerance: float64
    parameterization: uint32
    weight: float64


@message("moveit_msgs/msg/Constraints")
class Constraints:
    name: string
    joint_constraints: Seq[JointConstraint]
    position_constraints: Seq[PositionConstraint]
    orientation_constraints: Seq[OrientationConstraint]


@message("moveit_msgs/msg/MotionPlanRequest")
class MotionPlanRequest:
    start_state: RobotState
    goal_constraints: Seq[Constraints]
    path_constraints: Constraints
    planner_id: string
    pipeline_id: string
    group_name: string
    num_planning_attempts: int32
    allowed_planning_time: float64
    max_velocity_scaling_factor: float64
    max_acceleration_scaling_factor: float64


@message("moveit_msgs/msg/MotionPlanResponse")
class MotionPlanResponse:
    trajectory_start: RobotState
    group_name: string
    trajectory: RobotTrajectory
    planning_time: float64
    error_code: MoveItErrorCodes


@message("moveit_msgs/msg/CollisionObject")
class CollisionObject:
    ADD: ClassVar[int32] = 0
    REMOVE: ClassVar[int32] = 1
    APPEND: ClassVar[int32] = 2
    MOVE: ClassVar[int32] = 3

    header: Header
    pose: Pose
    id: string
    primitives: Seq[SolidPrimitive]
    primitive_poses: Seq[Pose]
    operation: int32


@message("moveit_msgs/msg/PlanningSceneWorld")
class PlanningSceneWorld:
    collision_objects: Seq[CollisionObject]


@message("moveit_msgs/msg/PlanningScene")
class PlanningScene:
    name: string
    robot_state: RobotState
    robot_model_name: string
    world: PlanningSceneWorld
    is_diff: bool_


@message("moveit_msgs/msg/PlanningSceneComponents")
class PlanningSceneComponents:
    SCENE_SETTINGS: ClassVar[uint32] = 1
    ROBOT_STATE: ClassVar[uint32] = 2
    WORLD_OBJECT_NAMES: ClassVar[uint32] = 16
    WORLD_OBJECT_GEOMETRY: ClassVar[uint32] = 32

    components: uint32


@message("moveit_msgs/msg/PlanningOptions")
class PlanningOptions:
    planning_scene_diff: PlanningScene
    plan_only: bool_
    look_around: bool_
    look_around_attempts: int32
    max_safe_execution_cost: float64
    replan: bool_
    replan_attempts: int32
    replan_delay: float64


@message("moveit_msgs/msg/DisplayTrajectory")
class DisplayTrajectory:
    model_id: string
    trajectory: Seq[RobotTrajectory]
    trajectory_start: RobotState


@message("moveit_msgs/msg/MoveGroupGoal")
class MoveGroupGoal:
    request: MotionPlanRequest
    planning_options: PlanningOptions


@message("moveit_msgs/msg/MoveGroupResult")
class MoveGroupResult:
    error_code: MoveItErrorCodes
    trajectory_start: RobotState
    planned_trajectory: RobotTrajectory
    executed_trajectory: RobotTrajectory
    planning_time: float64


@message("moveit_msgs/msg/MoveGroupFeedback")
class MoveGroupFeedback:
    state: string


MoveGroup = make_action_type(
    "moveit_msgs", "MoveGroup", MoveGroupGoal, MoveGroupResult, MoveGroupFeedback
)


@message("moveit_msgs/msg/ExecuteTrajectoryGoal")
class ExecuteTrajectoryGoal:
    trajectory: RobotTrajectory


@message("moveit_msgs/msg/ExecuteTrajectoryResult")
class ExecuteTrajectoryResult:
    error_code: MoveItErrorCodes


@message("moveit_msgs/msg/ExecuteTrajectoryFeedback")
class ExecuteTrajectoryFeedback:
    state: string


ExecuteTrajectory = make_action_type(
    "moveit_msgs",
    "ExecuteTrajectory",
    ExecuteTrajectoryGoal,
    ExecuteTrajectoryResult,
    ExecuteTrajectoryFeedback,
)


@message("moveit_msgs/msg/PositionIKRequest")
class PositionIKRequest:
    group_name: string
    robot_state: RobotState
    avoid_collisions: bool_
    ik_link_name: string
    pose_stamped: PoseStamped
    timeout: Duration


@message("moveit_msgs/srv/GetPositionIK_Request")
class GetPositionIKRequest:
    ik_request: PositionIKRequest


@message("moveit_msgs/srv/GetPositionIK_Response")
class GetPositionIKResponse:
    solution: RobotState
    error_code: MoveItErrorCodes


GetPositionIK = make_srv_type(
    "moveit_msgs/srv/GetPositionIK", GetPositionIKRequest, GetPositionIKResponse
)


@message("moveit_msgs/srv/GetPositionFK_Request")
class GetPositionFKRequest:
    header: Header
    fk_link_names: Seq[string]
    robot_state: RobotState


@message("moveit_msgs/srv/GetPositionFK_Response")
class GetPositionFKResponse:
    pose_stamped: Seq[PoseStamped]
    fk_link_names: Seq[string]
    error_code: MoveItErrorCodes


GetPositionFK = make_srv_type(
    "moveit_msgs/srv/GetPositionFK", GetPositionFKRequest, GetPositionFKResponse
)


@message("moveit_msgs/srv/GetMotionPlan_Request")
class GetMotionPlanRequest:
    motion_plan_request: MotionPlanRequest


@message("moveit_msgs/srv/GetMotionPlan_Response")
class GetMotionPlanResponse:
    motion_plan_response: MotionPlanResponse


GetMotionPlan = make_srv_type(
    "moveit_msgs/srv/GetMotionPlan", GetMotionPlanRequest, GetMotionPlanResponse
)


@message("moveit_msgs/srv/GetPlanningScene_Request")
class GetPlanningSceneRequest:
    components: PlanningSceneComponents


@message("moveit_msgs/srv/GetPlanningScene_Response")
class GetPlanningSceneResponse:
    scene: PlanningScene


GetPlanningScene = make_srv_type(
    "moveit_msgs/srv/GetPlanningScene", GetPlanningSceneRequest, GetPlanningSceneResponse
)


@message("moveit_msgs/srv/ApplyPlanningScene_Request")
class ApplyPlanningSceneRequest:
    scene: PlanningScene


@message("moveit_msgs/srv/ApplyPlanningScene_Response")
class ApplyPlanningSceneResponse:
    success: bool_


ApplyPlanningScene = make_srv_type(
    "moveit_msgs/srv/ApplyPlanningScene", ApplyPlanningSceneRequest, ApplyPlanningSceneResponse
)


@message("moveit_msgs/srv/GetCartesianPath_Request")
class GetCartesianPathRequest:
    header: Header
    start_state: RobotState
    group_name: string
    link_name: string
    waypoints: Seq[Pose]
    max_step: float64
    jump_threshold: float64
    prismatic_jump_threshold: float64
    revolute_jump_threshold: float64
    avoid_collisions: bool_
    path_constraints: Constraints


@message("moveit_msgs/srv/GetCartesianPath_Response")
class GetCartesianPathResponse:
    start_state: RobotState
    solution: RobotTrajectory
    fraction: float64
    error_code: MoveItErrorCodes


GetCartesianPath = make_srv_type(
    "moveit_msgs/srv/GetCartesianPath", GetCartesianPathRequest, GetCartesianPathResponse
)
