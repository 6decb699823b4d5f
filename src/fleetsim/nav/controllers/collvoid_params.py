"""Parameters of ``collvoid_local_planner/CollvoidLocalPlanner``: collvoid's names where they
exist, base_local_planner's limits, and the deadlock rule's own."""

from __future__ import annotations

from dataclasses import dataclass

from fleetsim.runtime import param


@dataclass(frozen=True)
class CollvoidParams:
    """``CollvoidLocalPlanner/`` parameters."""

    # base_local_planner limits (TrajectoryPlannerROS's names and defaults)
    acc_lim_x: float = param(2.5, unit="m/s^2", range=(1e-6, None), help="x acceleration limit")
    acc_lim_y: float = param(2.5, unit="m/s^2", range=(1e-6, None), help="y acceleration limit")
    acc_lim_theta: float = param(
        3.2, unit="rad/s^2", range=(1e-6, None), aliases=("acc_lim_th",), help="rot. acc. limit"
    )
    max_vel_x: float = param(0.5, unit="m/s", range=(1e-6, None), help="maximum speed")
    min_vel_x: float = param(
        0.1, unit="m/s", range=(0.0, None), help="speed the robot slows to near its goal"
    )
    max_vel_theta: float = param(
        1.0, unit="rad/s", range=(1e-6, None), aliases=("max_rotational_vel",), help="max turn"
    )
    min_vel_theta: float = param(-1.0, unit="rad/s", help="minimum rotational velocity")
    min_in_place_vel_theta: float = param(
        0.4,
        unit="rad/s",
        range=(0.0, None),
        aliases=("min_in_place_rotational_vel",),
        help="minimum rotational velocity when rotating in place",
    )
    holonomic_robot: bool = param(
        False, aliases=("holo_robot",), help="the base moves sideways (collvoid's holo_robot)"
    )
    xy_goal_tolerance: float = param(0.10, unit="m", range=(0.0, None), help="xy tolerance")
    yaw_goal_tolerance: float = param(0.05, unit="rad", range=(0.0, None), help="yaw tolerance")
    latch_xy_goal_tolerance: bool = param(False, help="once within xy tolerance, only rotate")
    controller_frequency: float = param(
        20.0, unit="Hz", range=(1e-6, None), help="cycle rate (searched upwards, as move_base's)"
    )
    # collvoid
    max_neighbors: int = param(10, range=(0, None), help="robots taken into account")
    neighbor_dist: float = param(
        3.0, unit="m", range=(0.0, None), help="robots farther than this are ignored"
    )
    time_horizon: float = param(
        3.0, unit="s", range=(1e-3, None), help="robots: collisions later than this are ignored"
    )
    time_horizon_obst: float = param(
        1.0, unit="s", range=(1e-3, None), help="static obstacles: the same horizon"
    )
    orca: bool = param(True, help="ORCA half-planes + linear program (the only solver here)")
    clearpath: bool = param(False, help="collvoid's ClearPath solver (not available here)")
    use_truncation: bool = param(True, help="truncate the velocity obstacles at the horizons")
    type_vo: int = param(
        0, choices=(0, 1, 2), help="HRVO 0, RVO 1, VO 2: collvoid's sampling only, not ORCA"
    )
    left_pref: float = param(
        -0.6,
        unit="rad",
        help="turn of the preferred velocity while a robot is ahead (negative: keep right)",
    )
    time_to_holo: float = param(
        0.4, unit="s", range=(1e-3, None), help="time to reach the holonomic velocity's heading"
    )
    min_error_holo: float = param(
        0.01, unit="m", range=(0.0, None), help="tracking error always allowed"
    )
    max_error_holo: float = param(
        0.15, unit="m", range=(0.0, None), help="tracking error bound, added to the radius"
    )
    footprint_radius: float = param(
        0.0, unit="m", range=(0.0, None), help="robot radius (0: the footprint's circumscribed)"
    )
    eps: float = param(
        0.1, range=(0.0, 0.999), help="amcl particle weight allowed outside the own safety radius"
    )
    use_polygon_footprint: bool = param(
        False,
        help="robots' velocity obstacles from their footprints' Minkowski sum, not their "
        "circumscribed discs (collvoid's polygon mode)",
    )
    # fleetsim additions
    safety_margin: float = param(
        0.05, unit="m", range=(0.0, None), help="added to the robot radius against neighbours"
    )
    overlap_time: float = param(
        0.0,
        unit="s",
        range=(0.0, None),
        help="time to part two robots whose discs overlap (0: one control period, as RVO2); "
        "they close in on each other's bodies no faster than in this time",
    )
    robot_id: str = param("", help="this robot's id on /position_share (empty: tf_prefix)")
    carrot_distance: float = param(
        0.8, unit="m", range=(1e-3, None), help="look-ahead along the plan for the heading"
    )
    deadlock_time: float = param(
        10.0,
        unit="s",
        range=(0.0, None),
        help="no progress this long near a robot: stuck (the deadlock rule may yield, and the "
        "robots parked around count by their footprints)",
    )
    narrow_deadlock_time: float = param(
        1.0,
        unit="s",
        range=(0.0, None),
        help="a robot facing this one across a passage too narrow for two this long: stuck",
    )
    standoff_time: float = param(
        3.0,
        unit="s",
        range=(0.0, None),
        help="a robot ahead facing this one, neither drawing away, and no deadlock_progress "
        "this long: stuck, and it yields to that robot if it has priority (a fleetsim "
        "addition: robots abreast fill a passage wide enough for two by its walls)",
    )
    max_vel_x_backwards: float = param(
        0.5,
        unit="m/s",
        range=(0.0, None),
        help="backing out while yielding, at most max_vel_x (0: turn round, drive forwards)",
    )
    deadlock_progress: float = param(
        0.2, unit="m", range=(0.0, None), help="progress that resets the deadlock clock"
    )
    deadlock_radius: float = param(
        2.0, unit="m", range=(0.0, None), help="robots this close take part in a deadlock"
    )
    yield_time: float = param(
        30.0,
        unit="s",
        range=(0.0, None),
        help="longest a yield lasts (it ends when the robot yielded to has gone by or is out of "
        "the way)",
    )
