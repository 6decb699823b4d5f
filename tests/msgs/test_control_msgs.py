from __future__ import annotations

from fleetsim.msgs import control_msgs


def test_layouts(own_def):
    assert own_def("control_msgs/FollowJointTrajectoryGoal") == [
        "trajectory_msgs/JointTrajectory trajectory",
        "control_msgs/JointTolerance[] path_tolerance",
        "control_msgs/JointTolerance[] goal_tolerance",
        "builtin_interfaces/Duration goal_time_tolerance",
    ]
    result = own_def("control_msgs/FollowJointTrajectoryResult")
    assert result[0] == "int32 SUCCESSFUL=0"
    assert result[-2:] == ["int32 error_code", "string error_string"]
    assert own_def("control_msgs/JointTolerance") == [
        "string name",
        "float64 position",
        "float64 velocity",
        "float64 acceleration",
    ]


def test_action():
    fjt = control_msgs.FollowJointTrajectory
    goal = fjt.Goal()
    goal.trajectory.joint_names.append("arm_joint")
    assert fjt.Goal().trajectory.joint_names == []  # no shared defaults
    assert fjt.Feedback().desired.positions.shape == (0,)
    assert fjt.Result.INVALID_JOINTS == -2
