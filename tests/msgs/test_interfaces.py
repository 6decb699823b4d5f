from __future__ import annotations

import pytest

from fleetsim.errors import MessageError
from fleetsim.msgs import (
    actionlib_msgs,
    control_msgs,
    deserialize,
    geometry_msgs,
    get_action_type,
    get_srv_type,
    get_type,
    make_action_type,
    make_srv_type,
    message,
    move_base_msgs,
    msgs_equal,
    nav_msgs,
    serialize,
    std_srvs,
    type_name,
)
from fleetsim.msgs.fields import float64, string


def test_srv_types():
    assert nav_msgs.GetMap.name == "nav_msgs/srv/GetMap"
    assert type_name(nav_msgs.GetMap.Request) == "nav_msgs/srv/GetMap_Request"
    assert type_name(nav_msgs.GetMap.Response) == "nav_msgs/srv/GetMap_Response"
    assert get_srv_type("nav_msgs/GetMap") is nav_msgs.GetMap
    assert get_srv_type("/std_srvs/srv/Empty") is std_srvs.Empty
    assert get_type("std_srvs/TriggerResponse") is std_srvs.Trigger.Response
    assert repr(nav_msgs.GetPlan) == "SrvType('nav_msgs/srv/GetPlan')"


def test_unknown_srv_and_action():
    with pytest.raises(MessageError, match=r"unknown srv type 'nav_msgs/GetMapp' \(did you mean"):
        get_srv_type("nav_msgs/GetMapp")
    with pytest.raises(MessageError, match=r"unknown action type 'move_base_msgs/action/MoveBse'"):
        get_action_type("move_base_msgs/action/MoveBse")


def test_move_base_action():
    mb = move_base_msgs.MoveBase
    assert get_action_type("move_base_msgs/MoveBase") is mb
    assert get_action_type("move_base_msgs/MoveBaseAction") is mb
    assert get_action_type("move_base_msgs/action/MoveBase") is mb
    assert type_name(mb.ActionGoal) == "move_base_msgs/msg/MoveBaseActionGoal"
    assert type_name(mb.Goal) == "move_base_msgs/msg/MoveBaseGoal"
    assert get_type("move_base_msgs/action/MoveBase_Goal") is mb.Goal
    goal = mb.ActionGoal(
        goal_id=actionlib_msgs.GoalID(id="g1"),
        goal=mb.Goal(target_pose=geometry_msgs.PoseStamped()),
    )
    goal.goal.target_pose.pose.position.x = 3.0
    assert msgs_equal(deserialize(serialize(goal), "move_base_msgs/MoveBaseActionGoal"), goal)
    fb = mb.ActionFeedback()
    assert isinstance(fb.status, actionlib_msgs.GoalStatus)
    assert isinstance(fb.feedback.base_position, geometry_msgs.PoseStamped)
    assert [f for f, _ in mb.ActionResult.__msgfields__] == ["header", "status", "result"]
    assert [f for f, _ in mb.Action.__msgfields__] == [
        "action_goal",
        "action_result",
        "action_feedback",
    ]


def test_follow_joint_trajectory():
    fjt = control_msgs.FollowJointTrajectory
    assert fjt.name == "control_msgs/action/FollowJointTrajectory"
    assert fjt.Result.GOAL_TOLERANCE_VIOLATED == -5
    assert type_name(fjt.ActionFeedback) == "control_msgs/msg/FollowJointTrajectoryActionFeedback"


def test_make_types_for_user_packages():
    @message("fleetsim_test/msg/DockGoal")
    class DockGoal:
        station: string

    @message("fleetsim_test/msg/DockResult")
    class DockResult:
        pass

    @message("fleetsim_test/msg/DockFeedback")
    class DockFeedback:
        distance: float64

    dock = make_action_type("fleetsim_test", "Dock", DockGoal, DockResult, DockFeedback)
    assert dock.ActionGoal().goal == DockGoal()
    assert get_action_type("fleetsim_test/Dock") is dock

    @message("fleetsim_test/srv/Ping_Request")
    class PingRequest:
        pass

    with pytest.raises(MessageError, match=r"register it as 'fleetsim_test/srv/Pong_Request'"):
        make_srv_type("fleetsim_test/srv/Pong", PingRequest, PingRequest)
    with pytest.raises(MessageError, match="must look like 'pkg/srv/Name'"):
        make_srv_type("fleetsim_test/Ping", PingRequest, PingRequest)
