"""actionlib_msgs: the ROS 1 action protocol's goal ids and statuses."""

from __future__ import annotations

from typing import ClassVar

from fleetsim.msgs.builtin_interfaces import Time
from fleetsim.msgs.fields import Seq, string, uint8
from fleetsim.msgs.registry import message
from fleetsim.msgs.std_msgs import Header


@message("actionlib_msgs/msg/GoalID")
class GoalID:
    stamp: Time
    id: string


@message("actionlib_msgs/msg/GoalStatus")
class GoalStatus:
    """The state of one goal, with the ROS 1 actionlib status constants."""

    PENDING: ClassVar[uint8] = 0  # not yet processed by the action server
    ACTIVE: ClassVar[uint8] = 1  # being processed
    PREEMPTED: ClassVar[uint8] = 2  # cancelled after it started, and completed its execution
    SUCCEEDED: ClassVar[uint8] = 3  # achieved
    ABORTED: ClassVar[uint8] = 4  # aborted by the server during execution
    REJECTED: ClassVar[uint8] = 5  # rejected without being processed
    PREEMPTING: ClassVar[uint8] = 6  # cancel requested after it started; not yet done
    RECALLING: ClassVar[uint8] = 7  # cancel requested before it started; not yet confirmed
    RECALLED: ClassVar[uint8] = 8  # cancelled before it started
    LOST: ClassVar[uint8] = 9  # client-side only: the server lost track of the goal

    goal_id: GoalID
    status: uint8
    text: string


@message("actionlib_msgs/msg/GoalStatusArray")
class GoalStatusArray:
    header: Header
    status_list: Seq[GoalStatus]
