from __future__ import annotations

from fleetsim.msgs import actionlib_msgs, move_base_msgs


def test_layouts(own_def):
    assert own_def("move_base_msgs/MoveBaseGoal") == ["geometry_msgs/PoseStamped target_pose"]
    assert own_def("move_base_msgs/MoveBaseFeedback") == ["geometry_msgs/PoseStamped base_position"]
    assert own_def("move_base_msgs/MoveBaseResult") == []
    assert own_def("move_base_msgs/MoveBaseActionGoal") == [
        "std_msgs/Header header",
        "actionlib_msgs/GoalID goal_id",
        "move_base_msgs/MoveBaseGoal goal",
    ]
    assert own_def("move_base_msgs/MoveBaseActionResult") == [
        "std_msgs/Header header",
        "actionlib_msgs/GoalStatus status",
        "move_base_msgs/MoveBaseResult result",
    ]
    assert own_def("move_base_msgs/MoveBaseActionFeedback") == [
        "std_msgs/Header header",
        "actionlib_msgs/GoalStatus status",
        "move_base_msgs/MoveBaseFeedback feedback",
    ]


def test_module_names():
    mb = move_base_msgs.MoveBase
    assert move_base_msgs.MoveBaseActionGoal is mb.ActionGoal
    assert move_base_msgs.MoveBaseAction is mb.Action
    assert mb.Goal is move_base_msgs.MoveBaseGoal
    result = mb.ActionResult(
        status=actionlib_msgs.GoalStatus(status=actionlib_msgs.GoalStatus.ABORTED)
    )
    assert result.status.status == 4
