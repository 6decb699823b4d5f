"""Skid-steer drive (``libgazebo_ros_skid_steer_drive.so``): four wheels, two per side.

Same wheel actuation as the diff drive (velocity actuators under a torque limit on real wheel
joints). Turning makes the wheels scrub sideways, so encoder odometry (the mean angle of each
side's wheels) over-estimates rotation and drifts: compare it with p3d ground truth.
"""

from __future__ import annotations

from dataclasses import dataclass

from fleetsim.runtime.params import param
from fleetsim.sim.plugins.base import register
from fleetsim.sim.plugins.diff_drive import WheeledDrive


@dataclass(frozen=True)
class SkidSteerParams:
    leftFrontJoint: str = param("left_front_joint", help="left front wheel joint")
    rightFrontJoint: str = param("right_front_joint", help="right front wheel joint")
    leftRearJoint: str = param("left_rear_joint", help="left rear wheel joint")
    rightRearJoint: str = param("right_rear_joint", help="right rear wheel joint")
    wheelSeparation: float = param(0.4, unit="m", range=(0.0, None), help="wheel track")
    wheelDiameter: float = param(0.15, unit="m", range=(0.0, None), help="wheel diameter")
    torque: float = param(5.0, unit="N m", range=(0.0, None), help="max wheel torque")
    commandTopic: str = param("cmd_vel", help="Twist command topic")
    odometryTopic: str = param("odom", help="Odometry topic")
    odometryFrame: str = param("odom", help="odometry frame (tf_prefix applied)")
    robotBaseFrame: str = param("base_footprint", help="child frame of the odometry")
    broadcastTF: bool = param(False, help="broadcast odom -> base on /tf")
    updateRate: float = param(100.0, unit="Hz", range=(0.0, None), help="odometry rate")
    covariance_x: float = param(0.0001, help="odometry x covariance")
    covariance_y: float = param(0.0001, help="odometry y covariance")
    covariance_yaw: float = param(0.01, help="odometry yaw covariance")
    commandTimeout: float = param(
        0.5,
        unit="s",
        range=(0.0, None),
        help="stop when no command arrives for this long (0: never)",
    )


@register("libgazebo_ros_skid_steer_drive.so")
class SkidSteerPlugin(WheeledDrive):
    Params = SkidSteerParams
    joint_params = ("leftFrontJoint", "leftRearJoint", "rightFrontJoint", "rightRearJoint")

    def __init__(self, ctx, spec, sensor=None) -> None:
        super().__init__(ctx, spec, sensor)
        p = self.params
        self.left = [p.leftFrontJoint, p.leftRearJoint]
        self.right = [p.rightFrontJoint, p.rightRearJoint]
        self.torque = p.torque
        self.accel = 0.0
        self.encoder = True
        self.publish_tf = p.broadcastTF
        self._setup()
