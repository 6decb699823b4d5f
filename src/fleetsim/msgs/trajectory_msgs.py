"""trajectory_msgs: joint trajectories."""

from __future__ import annotations

from fleetsim.msgs.builtin_interfaces import Duration
from fleetsim.msgs.fields import Seq, float64, string
from fleetsim.msgs.registry import message
from fleetsim.msgs.std_msgs import Header


@message("trajectory_msgs/msg/JointTrajectoryPoint")
class JointTrajectoryPoint:
    """One waypoint, per joint in the trajectory's ``joint_names`` order (rad or m, SI)."""

    positions: Seq[float64]
    velocities: Seq[float64]
    accelerations: Seq[float64]
    effort: Seq[float64]
    time_from_start: Duration


@message("trajectory_msgs/msg/JointTrajectory")
class JointTrajectory:
    header: Header
    joint_names: Seq[string]
    points: Seq[JointTrajectoryPoint]
