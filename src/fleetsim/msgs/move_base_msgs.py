"""move_base_msgs: the MoveBase action (ROS 1 layout, actionlib wrappers included).

``MoveBase.ActionGoal`` travels on ``move_base/goal``, ``MoveBase.ActionFeedback`` on
``move_base/feedback``, ``MoveBase.ActionResult`` on ``move_base/result``; ``move_base_simple/goal``
carries a bare ``geometry_msgs/PoseStamped``.
"""

from __future__ import annotations

from fleetsim.msgs.geometry_msgs import PoseStamped
from fleetsim.msgs.interfaces import make_action_type
from fleetsim.msgs.registry import message


@message("move_base_msgs/msg/MoveBaseGoal")
class MoveBaseGoal:
    target_pose: PoseStamped


@message("move_base_msgs/msg/MoveBaseResult")
class MoveBaseResult:
    pass


@message("move_base_msgs/msg/MoveBaseFeedback")
class MoveBaseFeedback:
    base_position: PoseStamped


MoveBase = make_action_type(
    "move_base_msgs", "MoveBase", MoveBaseGoal, MoveBaseResult, MoveBaseFeedback
)
MoveBaseActionGoal = MoveBase.ActionGoal
MoveBaseActionResult = MoveBase.ActionResult
MoveBaseActionFeedback = MoveBase.ActionFeedback
MoveBaseAction = MoveBase.Action
