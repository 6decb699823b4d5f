"""Parameters of nav2_mppi_controller::MPPIController, with Nav2's names and defaults.

In move_base they live in the plugin's namespace, as a Nav2 user writes them under the
controller's plugin name::

    move_base:
      base_local_planner: nav2_mppi_controller::MPPIController
      MPPIController:
        batch_size: 2000
        critics: [ConstraintCritic, CostCritic, GoalCritic, ...]
        CostCritic: {cost_weight: 3.81, consider_footprint: true}
        AckermannConstraints: {min_turning_r: 0.2}

The goal tolerances (Nav2's ``general_goal_checker``: SimpleGoalChecker) sit in the same
namespace, as move_base's local planners keep theirs. Each critic's parameters are in
`fleetsim.nav.controllers.mppi.critic_params`.
"""

from __future__ import annotations

from dataclasses import dataclass

from fleetsim.runtime import param

MOTION_MODELS = ("DiffDrive", "Omni", "Ackermann")


@dataclass(frozen=True)
class MPPIParams:
    """``MPPIController/`` parameters (nav2_mppi_controller README, plus the goal checker)."""

    motion_model: str = param("DiffDrive", choices=MOTION_MODELS, help="kinematics of the base")
    critics: list = param([], help="critic names, scored in this order (Nav2: none by default)")
    iteration_count: int = param(1, range=(1, None), help="optimisation iterations per cycle")
    batch_size: int = param(1000, range=(1, None), help="sampled control sequences")
    time_steps: int = param(56, range=(2, None), help="points in each sampled trajectory")
    model_dt: float = param(0.05, unit="s", range=(1e-6, None), help="time between points")
    vx_std: float = param(0.2, unit="m/s", range=(0.0, None), help="sampling std of vx")
    vy_std: float = param(0.2, unit="m/s", range=(0.0, None), help="sampling std of vy")
    wz_std: float = param(0.4, unit="rad/s", range=(0.0, None), help="sampling std of wz")
    vx_max: float = param(0.5, unit="m/s", help="maximum forward velocity")
    vx_min: float = param(-0.35, unit="m/s", help="minimum (reverse) velocity")
    vy_max: float = param(0.5, unit="m/s", range=(0.0, None), help="max |vy| (Omni)")
    wz_max: float = param(1.9, unit="rad/s", range=(0.0, None), help="max |wz|")
    ax_max: float = param(3.0, unit="m/s^2", range=(0.0, None), help="max x acceleration")
    ax_min: float = param(-3.0, unit="m/s^2", range=(None, 0.0), help="max x deceleration")
    ay_max: float = param(3.0, unit="m/s^2", range=(0.0, None), help="max |y acceleration|")
    az_max: float = param(3.5, unit="rad/s^2", range=(0.0, None), help="max |wz acceleration|")
    temperature: float = param(
        0.3, range=(0.0, None), help="softmax selectiveness (0: the best sample only)"
    )
    gamma: float = param(0.015, range=(0.0, None), help="control cost weight (smoothness)")
    visualize: bool = param(False, help="publish sampled trajectories (no effect here)")
    retry_attempt_limit: int = param(
        1, range=(0, None), help="soft resets when every sample collides, before failing"
    )
    reset_period: float = param(1.0, unit="s", range=(0.0, None), help="idle time that resets")
    regenerate_noises: bool = param(
        False, help="new noise every cycle (else one draw, kept until a reset)"
    )
    primitive_samples: bool = param(
        False,
        help="fleetsim addition: stand-still, straight, turn-on-the-spot and turn-then-drive "
        "sequences replace the batch's last samples (mppi.primitives); off: Nav2's sampling",
    )
    # path handler
    prune_distance: float = param(
        1.5, unit="m", range=(0.0, None), help="path kept ahead of the nearest path point"
    )
    max_robot_pose_search_dist: float | None = param(
        None, unit="m", range=(0.0, None), help="path searched for the nearest point (unset: "
        "half the costmap)"
    )  # fmt: skip
    transform_tolerance: float = param(0.1, unit="s", range=(0.0, None), help="tf tolerance")
    enforce_path_inversion: bool = param(False, help="stop at path cusps (not available)")
    inversion_xy_tolerance: float = param(0.2, unit="m", range=(0.0, None), help="cusp xy tol")
    inversion_yaw_tolerance: float = param(0.4, unit="rad", range=(0.0, None), help="cusp yaw")
    # goal checker (nav2_controller::SimpleGoalChecker)
    xy_goal_tolerance: float = param(0.25, unit="m", range=(0.0, None), help="xy tolerance")
    yaw_goal_tolerance: float = param(0.25, unit="rad", range=(0.0, None), help="yaw tolerance")
    stateful: bool = param(True, help="once within xy tolerance, only yaw is checked")
    controller_frequency: float = param(
        20.0, unit="Hz", range=(1e-6, None), help="cycle rate (searched upwards, as move_base's)"
    )


@dataclass(frozen=True)
class AckermannConstraints:
    """``MPPIController/AckermannConstraints/``."""

    min_turning_r: float = param(0.2, unit="m", range=(0.0, None), help="min turning radius")
