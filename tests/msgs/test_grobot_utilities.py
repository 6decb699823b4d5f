from __future__ import annotations

from fleetsim.msgs import deserialize, get_action_type, get_type, grobot_utilities, serialize


def test_patrol_action_layout_as_the_tutorial_defines_it(own_def):
    assert own_def("grobot_utilities/PatrolGoal") == [
        "float32 radius",
        "bool clockwise",
        "uint32 num_patrols",
    ]
    assert own_def("grobot_utilities/PatrolResult") == ["bool success"]
    assert own_def("grobot_utilities/PatrolFeedback") == ["uint32 completed_patrols"]
    assert own_def("grobot_utilities/PatrolActionFeedback") == [
        "std_msgs/Header header",
        "actionlib_msgs/GoalStatus status",
        "grobot_utilities/PatrolFeedback feedback",
    ]


def test_patrol_names_and_round_trip():
    patrol = grobot_utilities.Patrol
    assert get_action_type("grobot_utilities/Patrol") is patrol
    assert get_type("grobot_utilities/PatrolGoal") is patrol.Goal  # ROS 1 spelling
    goal = patrol.ActionGoal(goal=patrol.Goal(radius=1.5, clockwise=True, num_patrols=0))
    back = deserialize(serialize(goal), "grobot_utilities/msg/PatrolActionGoal")
    assert back.goal.radius == 1.5 and back.goal.clockwise and back.goal.num_patrols == 0
