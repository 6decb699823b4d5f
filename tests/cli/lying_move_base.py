"""A stand-in for a move_base that reports every goal reached at once, wherever the robot is:
what the results table and ``--until-goals`` must not believe (issue 13)."""

from __future__ import annotations

from fleetsim.msgs import actionlib_msgs, geometry_msgs, move_base_msgs
from fleetsim.runtime import Node


class LyingMoveBase(Node):
    """Sends itself one goal 22 m east of the origin at 0.3 s and reports it SUCCEEDED at 0.6 s."""

    sends_goals = True

    def __init__(self, runtime, name="move_base", namespace="/", **kw):
        super().__init__(runtime, name, namespace, **kw)
        mb = move_base_msgs.MoveBase
        self.goal_pub = self.create_publisher(mb.ActionGoal, "move_base/goal")
        self.result_pub = self.create_publisher(mb.ActionResult, "move_base/result")
        self.step = 0
        self.create_timer(0.3, self.on_timer)

    @property
    def done(self) -> bool:
        return self.step >= 2

    def on_timer(self) -> None:
        mb = move_base_msgs.MoveBase
        gid = actionlib_msgs.GoalID(id="lie")
        if self.step == 0:
            target = geometry_msgs.PoseStamped()
            target.header.frame_id = "map"
            target.pose.position.x = 22.0
            target.pose.orientation.w = 1.0
            self.goal_pub.publish(mb.ActionGoal(goal_id=gid, goal=mb.Goal(target_pose=target)))
        elif self.step == 1:
            status = actionlib_msgs.GoalStatus(
                goal_id=gid, status=actionlib_msgs.GoalStatus.SUCCEEDED, text="Goal reached."
            )
            self.result_pub.publish(mb.ActionResult(status=status))
        self.step += 1
