"""A fake move_base for client tests: an action server that drives a point robot.

The robot moves straight to the goal at ``speed`` m/s (10 Hz), publishing feedback with its
pose; it succeeds on arrival, aborts goals with x < 0 ("off the global costmap") at once,
and honours preemption and cancel as move_base does (PREEMPTED).
"""

import math

from fleetsim.msgs import geometry_msgs, move_base_msgs, std_msgs
from fleetsim.runtime import Node


class FakeMoveBase(Node):
    def __init__(self, runtime, namespace="/lizi1", start=(0.0, 0.0), speed=1.0):
        super().__init__(runtime, "move_base", namespace)
        self.x, self.y = start
        self.speed = speed
        self.goals = []  # (x, y) of every goal accepted
        self.initial_poses = []
        self.server = self.create_action_server(
            move_base_msgs.MoveBase, "move_base", goal_callback=self.on_goal
        )
        self.create_subscription(
            geometry_msgs.PoseWithCovarianceStamped, "initialpose", self.initial_poses.append
        )
        self.create_timer(0.1, self.step)

    def on_goal(self):
        goal = self.server.accept_new_goal()
        p = goal.target_pose.pose.position
        self.goals.append((p.x, p.y))
        if p.x < 0:
            self.server.set_aborted(text=f"the goal ({p.x:.3f}, {p.y:.3f}) is off the map")

    def step(self):
        s = self.server
        if not s.is_active():
            return
        if s.is_preempt_requested() and not s.is_new_goal_available():
            s.set_preempted(text="canceled")
            return
        p = s.current_goal.target_pose.pose.position
        d = math.hypot(p.x - self.x, p.y - self.y)
        step = self.speed * 0.1
        if d <= step:
            self.x, self.y = p.x, p.y
            s.set_succeeded(text="goal reached")
            return
        self.x += (p.x - self.x) / d * step
        self.y += (p.y - self.y) / d * step
        pose = geometry_msgs.PoseStamped(
            header=std_msgs.Header(stamp=self.now_msg(), frame_id="map"),
            pose=geometry_msgs.Pose(position=geometry_msgs.Point(x=self.x, y=self.y)),
        )
        s.publish_feedback(move_base_msgs.MoveBaseFeedback(base_position=pose))
