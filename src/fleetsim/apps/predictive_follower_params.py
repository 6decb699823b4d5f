"""The predictive follower's parameters, declared once (`fleetsim.apps.predictive_follower`)."""

from __future__ import annotations

import math
from dataclasses import dataclass

from fleetsim.runtime import param


@dataclass(frozen=True)
class PredictiveFollowerParams:
    """The predictive follower's private parameters (defaults: the waffle and the tutorial)."""

    marker_id: int = param(0, range=(0, None), help="the fiducial_id to follow")
    follow_distance: float = param(0.8, unit="m", range=(0.0, None), help="desired gap behind")
    controller_frequency: float = param(10.0, unit="Hz", range=(0.5, 100.0), help="cmd_vel rate")
    horizon: float = param(3.0, unit="s", range=(0.2, 10.0), help="MPC horizon")
    time_step: float = param(0.1, unit="s", range=(0.01, 1.0), help="MPC rollout step")
    max_vel_x: float = param(0.26, unit="m/s", range=(0.0, None), help="top forward speed")
    min_vel_x: float = param(-0.1, unit="m/s", range=(None, 0.0), help="top reverse speed")
    max_vel_theta: float = param(1.82, unit="rad/s", range=(0.0, None), help="top turn rate")
    acc_lim_x: float = param(2.5, unit="m/s^2", range=(1e-3, None), help="linear accel limit")
    acc_lim_theta: float = param(3.2, unit="rad/s^2", range=(1e-3, None), help="turn accel limit")
    vx_samples: int = param(8, range=(2, 200), help="linear velocity samples")
    vtheta_samples: int = param(21, range=(3, 400), help="turn rate samples")
    camera_hfov: float = param(
        1.3439, unit="rad", range=(0.01, math.pi), help="the camera's horizontal field of view"
    )
    camera_frame: str = param(
        "camera_rgb_optical_frame", help="the camera's frame (its offset ahead of the base)"
    )
    robot_frame: str = param("base_footprint", help="the robot's base frame (tf_prefix applied)")
    detection_range: float = param(
        3.75, unit="m", range=(0.1, None), help="farthest the detector finds the marker"
    )
    min_range: float = param(0.4, unit="m", range=(0.0, None), help="nearest it is kept")
    fov_margin: float = param(
        0.6, range=(0.05, 1.0), help="share of the half field of view that costs nothing"
    )
    face_angle: float = param(
        1.0, unit="rad", range=(0.0, math.pi), help="angle off the target's back that is free"
    )
    min_gap: float = param(
        0.45, unit="m", range=(0.0, None), help="closest the base may come to the target"
    )
    fov_weight: float = param(20.0, range=(0.0, None), help="cost per rad^2 off the free cone")
    out_of_view_cost: float = param(30.0, range=(0.0, None), help="cost per s out of view")
    follow_weight: float = param(4.0, range=(0.0, None), help="cost per m^2 from the desired pose")
    obstacle_weight: float = param(1.0, range=(0.0, None), help="cost of lethal-1 per s")
    smooth_weight: float = param(0.5, range=(0.0, None), help="cost per (m/s)^2 of change")
    face_weight: float = param(2.0, range=(0.0, None), help="cost per rad^2 off the back cone")
    uncertainty_scale: float = param(
        0.3, unit="m", range=(1e-3, None), help="prediction sd at which a step weighs half"
    )
    max_lead: float = param(
        1.5, unit="s", range=(0.0, None), help="how far past the last sighting to predict"
    )
    search_predicted_for: float = param(
        4.0, unit="s", range=(0.0, None), help="chase the prediction this long after a loss"
    )
    search_last_seen_for: float = param(
        4.0, unit="s", range=(0.0, None), help="then look where it was last seen this long"
    )
    tracker: dict = param({}, help="the target filter's noise model (TrackerParams)")
    exploration: dict = param(
        {"strategy": "rotate", "robot_frame": "base_footprint"},
        help="the tutorial's exploration, the last fallback (strategy, robot_frame, target_pose)",
    )
    local_costmap: dict = param({}, help="the follower's rolling costmap (costmap_2d params)")
    target_radius: float = param(
        0.2,
        unit="m",
        range=(0.0, None),
        help="lethal marks this near the target's track are its own",
    )
    trail_time: float = param(
        30.0, unit="s", range=(0.0, None), help="how long the target's track is remembered"
    )
