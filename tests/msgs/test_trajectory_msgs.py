from __future__ import annotations

import numpy as np

from fleetsim.msgs import deserialize, serialize, trajectory_msgs


def test_trajectory_round_trip():
    point = trajectory_msgs.JointTrajectoryPoint(positions=np.array([0.1, -0.2]))
    point.time_from_start.sec = 2
    traj = trajectory_msgs.JointTrajectory(joint_names=["a", "b"], points=[point])
    back = deserialize(serialize(traj), "trajectory_msgs/JointTrajectory")
    assert back.joint_names == ["a", "b"]
    assert back.points[0].positions.tolist() == [0.1, -0.2]
    assert back.points[0].time_from_start.sec == 2
