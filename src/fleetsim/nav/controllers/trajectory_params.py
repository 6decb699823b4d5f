"""Parameters of base_local_planner's TrajectoryPlannerROS, with ROS's names and defaults."""

from __future__ import annotations

import math
from dataclasses import dataclass

from fleetsim.runtime import param


@dataclass(frozen=True)
class TrajectoryPlannerParams:
    """``TrajectoryPlannerROS/`` parameters (base_local_planner)."""

    # robot configuration
    acc_lim_x: float = param(2.5, unit="m/s^2", range=(0.0, None), help="x acceleration limit")
    acc_lim_y: float = param(2.5, unit="m/s^2", range=(0.0, None), help="y acceleration limit")
    acc_lim_theta: float = param(  # acc_lim_th: the name of older releases and their tutorials
        3.2,
        unit="rad/s^2",
        range=(0.0, None),
        aliases=("acc_lim_th",),
        help="rotational acceleration limit",
    )
    max_vel_x: float = param(0.5, unit="m/s", help="maximum forward velocity")
    min_vel_x: float = param(0.1, unit="m/s", help="minimum forward velocity")
    max_vel_theta: float = param(
        1.0, unit="rad/s", aliases=("max_rotational_vel",), help="maximum rotational velocity"
    )
    min_vel_theta: float = param(-1.0, unit="rad/s", help="minimum rotational velocity")
    min_in_place_vel_theta: float = param(
        0.4,
        unit="rad/s",
        aliases=("min_in_place_rotational_vel",),
        help="minimum rotational velocity when rotating in place",
    )
    escape_vel: float = param(
        -0.1, unit="m/s", aliases=("backup_vel",), help="velocity when escaping (negative: back)"
    )
    holonomic_robot: bool = param(True, help="also sample strafing (y) velocities")
    y_vels: list = param([-0.3, -0.1, 0.1, 0.3], unit="m/s", help="strafing velocities tried")
    # goal tolerance
    yaw_goal_tolerance: float = param(0.05, unit="rad", range=(0.0, None), help="yaw tolerance")
    xy_goal_tolerance: float = param(0.10, unit="m", range=(0.0, None), help="xy tolerance")
    latch_xy_goal_tolerance: bool = param(
        False, help="once within xy tolerance, only rotate even if pushed out"
    )
    # forward simulation
    sim_time: float = param(1.0, unit="s", range=(1e-6, None), help="forward simulation time")
    sim_granularity: float = param(
        0.025, unit="m", range=(1e-6, None), help="step between trajectory points"
    )
    angular_sim_granularity: float | None = param(
        None, unit="rad", range=(1e-6, None), help="angular step (unset: sim_granularity)"
    )
    vx_samples: int = param(3, range=(1, None), help="x velocity samples")
    vtheta_samples: int = param(20, range=(1, None), help="rotational velocity samples")
    controller_frequency: float = param(
        20.0, unit="Hz", range=(1e-6, None), help="cycle rate (searched upwards, as move_base's)"
    )
    # scoring
    meter_scoring: bool = param(False, help="distances in metres (else cells)")
    pdist_scale: float = param(0.6, range=(0.0, None), help="weight of path distance")
    gdist_scale: float = param(0.8, range=(0.0, None), help="weight of goal distance")
    occdist_scale: float = param(0.01, range=(0.0, None), help="weight of obstacle cost")
    heading_lookahead: float = param(
        0.325, unit="m", help="look-ahead when scoring in-place rotations"
    )
    heading_scoring: bool = param(False, help="score by heading to the path, not distance")
    heading_scoring_timestep: float = param(
        0.8, unit="s", range=(0.0, None), help="look-ahead time for heading scoring"
    )
    # fleetsim addition: dwa_local_planner's alignment cost, which TrajectoryPlannerROS lacks
    alignment_scale: float = param(
        0.0,
        range=(0.0, None),
        help="weight of the path distance of a point ahead of the rollout's end (0: off)",
    )
    forward_point_distance: float = param(
        0.325, unit="m", range=(0.0, None), help="how far ahead that point is (dwa_local_planner)"
    )
    back_along_plan: bool = param(
        False,
        help="with alignment_scale: a robot facing away from its plan turns to it where it can "
        "turn all the way, else backs along it (false, the default: ROS's forward move first)",
    )
    # base_local_planner reads "dwa" with default true (trajectory_planner_ros.cpp; its wiki too)
    dwa: bool = param(True, help="Dynamic Window Approach (velocity window of one cycle)")
    simple_attractor: bool = param(False, help="follow the goal blindly (testing)")
    publish_cost_grid_pc: bool = param(False, help="publish the scoring grid as a cloud")
    global_frame_id: str = param("odom", help="frame for the published cost cloud")
    # oscillation prevention
    oscillation_reset_dist: float = param(
        0.05, unit="m", range=(0.0, None), help="travel that resets oscillation flags"
    )
    escape_reset_dist: float = param(
        0.10, unit="m", range=(0.0, None), help="travel that ends escaping"
    )
    escape_reset_theta: float = param(
        math.pi / 4, unit="rad", range=(0.0, None), help="rotation that ends escaping"
    )
    # fleetsim addition: ROS judges moves on the local costmap alone (see `global_guard`)
    global_costmap_check: bool = param(
        False,
        help="refuse a move that puts the robot's body on a lethal cell of the global "
        "costmap (false, the default: the local costmap alone, as ROS)",
    )
    prune_plan: bool = param(True, help="drop plan points more than 1 m behind the robot")
