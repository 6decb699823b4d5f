"""Skid-steer drive (``libgazebo_ros_skid_steer_drive.so``): four wheels, two per side.

Same wheel actuation as the diff drive (velocity servos under a torque limit on real wheel
joints), plus a held rotor on every drive wheel (``sim.drives.rotor_armature``): Gazebo's wheel
motor is a velocity constraint solved with the contacts, and without that inertia MuJoCo's
contact solver spent most of the friction cone sideways, so the robots turned at 0.1-0.2 of the
commanded rate. Turning makes the wheels scrub: with isotropic Coulomb friction and four equally
loaded wheels the true yaw rate is ``b^2 / (a^2 + b^2)`` of the commanded one (``a`` half
wheelbase, ``b`` half track). Measured on flat ground (true / commanded yaw rate, steady
state): lizi 0.57 in place (1.0 and 0.4 rad/s) and 0.52 on a 0.3 m/s, 0.5 rad/s arc (Coulomb
0.60); pioneer3at 0.65-0.68 (Coulomb 0.68); jackal 0.65-0.69 (Coulomb 0.67). Straight runs
keep the commanded speed.

Odometry follows the Gazebo plugin: ``gazebo_ros_skid_steer_drive`` has no choice and reports
the model's true world pose (``parent->WorldPose()``) and world velocity, so its odometry
neither drifts nor slips. ``odometrySource encoder`` (a fleetsim addition, with the diff
drive's parameter name) reports wheel odometry instead, from the mean angle of each side's
wheels; it assumes rolling wheels, so it reports the commanded rotation: about 1/0.57 = 1.75x
lizi's true rotation, 1.5x pioneer3at's and jackal's, and it drifts. Compare it with p3d ground
truth; the torque also spins the held rotor, so a low ``torque`` slows starts.
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
    odometrySource: str = param(
        "world",
        choices=("world", "encoder"),
        help="world: true pose, as the Gazebo plugin (which has no choice); "
        "encoder: integrated wheel angles with slip (fleetsim addition)",
    )
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
    held_rotor = True

    def __init__(self, ctx, spec, sensor=None) -> None:
        super().__init__(ctx, spec, sensor)
        p = self.params
        self.left = [p.leftFrontJoint, p.leftRearJoint]
        self.right = [p.rightFrontJoint, p.rightRearJoint]
        self.torque = p.torque
        self.accel = 0.0
        self.encoder = p.odometrySource == "encoder"
        self.publish_tf = p.broadcastTF
        self._setup()
