"""``grobot_utilities/patrol_server``: drive a robot round a circle, open loop, lap by lap.

As the tutorial's script: the ``Patrol`` action (``grobot_utilities.Patrol``) is served under
the node's full name (``/karl/patrol_server``); a goal makes the node publish ``cmd_vel`` at
10 Hz with 0.1 m/s forward and ``(-1 if clockwise else 1) * 0.1 / radius`` rad/s, and count laps
from the yaw of ``odom``: a lap is done when the yaw has come within 1 degree of the yaw at the
goal's start plus pi, then of that plus pi again. After each lap it publishes a zero ``Twist``
and the feedback ``completed_patrols``; the goal succeeds after ``num_patrols`` laps, and
``num_patrols = 0`` (what patrol_client sends) patrols for ever.

Where fleetsim differs from the original, it is where the original breaks:
- A half lap also counts when the yaw steps over the 1 degree window between two cycles (yaw
  rates above 0.35 rad/s, i.e. radius under 0.29 m), where the original would circle for ever.
- A goal with a radius that is not a positive finite number is aborted with the reason (the
  original divides by it).
- A cancel or a newer goal stops the patrol (zero ``Twist``, goal PREEMPTED); the original never
  looks at preemption, so a patrol could not be stopped.
- The first lap waits for the first ``odom`` message instead of starting from yaw 0.
"""

from __future__ import annotations

import math

from fleetsim.msgs import geometry_msgs, grobot_utilities, nav_msgs
from fleetsim.runtime import Node
from fleetsim.tf.quaternions import yaw_from_quaternion

RATE = 10.0  # Hz, rospy.Rate(10) of run_patrol
SPEED = 0.1  # m/s
YAW_TOLERANCE = 0.0174533  # rad: numpy.isclose(..., atol=0.0174533), 1 degree


def shortest_angular_distance(a: float, b: float) -> float:
    """The signed angle (rad, in [-pi, pi)) to turn from ``a`` to ``b`` (``angles`` package)."""
    return (b - a + math.pi) % (2 * math.pi) - math.pi


def patrol_twist(radius: float, clockwise: bool) -> geometry_msgs.Twist:
    """The open-loop command of a circle of ``radius`` metres at 0.1 m/s."""
    sign = -1.0 if clockwise else 1.0
    return geometry_msgs.Twist(
        linear=geometry_msgs.Vector3(x=SPEED),
        angular=geometry_msgs.Vector3(z=sign * SPEED / radius),
    )


class PatrolServer(Node):
    """The patrol action server; state: the active goal, its laps and the yaw targets."""

    def __init__(self, runtime, name: str = "patrol_server", namespace: str = "/", **kw) -> None:
        super().__init__(runtime, name, namespace, **kw)
        self.yaw: float | None = None
        self.cmd_pub = self.create_publisher(geometry_msgs.Twist, "cmd_vel", queue_size=10)
        self.create_subscription(nav_msgs.Odometry, "odom", self._on_odom, queue_size=1)
        self.server = self.create_action_server(
            grobot_utilities.Patrol, self.full_name, goal_callback=self._on_goal
        )
        self.create_timer(1.0 / RATE, self._cycle)
        self._reset()

    def _reset(self) -> None:
        self.goal = None
        self.twist = None
        self.initial_yaw: float | None = None
        self.target_yaw = 0.0
        self.half_done = False
        self.last_error: float | None = None
        self.completed = 0

    def _on_odom(self, msg) -> None:
        q = msg.pose.pose.orientation
        self.yaw = yaw_from_quaternion([q.x, q.y, q.z, q.w])

    def _on_goal(self) -> None:
        if not self.server.is_active():
            self._accept()

    def _accept(self) -> None:
        self._reset()
        goal = self.server.accept_new_goal()
        radius = float(goal.radius)
        if not (math.isfinite(radius) and radius > 0):
            self.server.set_aborted(
                grobot_utilities.Patrol.Result(success=False),
                f"{self.full_name}: goal radius must be a positive number of metres, got {radius}",
            )
            self.get_logger().error("patrol goal aborted: radius %s is not positive", radius)
            return
        self.goal = goal
        self.twist = patrol_twist(radius, bool(goal.clockwise))
        self.get_logger().info(
            "patrolling: radius %.2f m, %s, %s",
            radius,
            "clockwise" if goal.clockwise else "counter-clockwise",
            f"{goal.num_patrols} laps" if goal.num_patrols else "for ever",
        )

    def _start_lap(self) -> None:
        self.target_yaw = self.initial_yaw + math.pi
        self.half_done = False
        self.last_error = None

    def _cycle(self) -> None:
        if self.goal is None:
            if self.server.is_new_goal_available():
                self._accept()
            return
        if self.server.is_preempt_requested():
            self.cmd_pub.publish(geometry_msgs.Twist())
            self.server.set_preempted(grobot_utilities.Patrol.Result(success=False))
            self._reset()
            if self.server.is_new_goal_available():
                self._accept()
            return
        if self.yaw is None:
            return  # no odometry yet
        if self.initial_yaw is None:
            self.initial_yaw = self.yaw
            self._start_lap()
        if self._reached_target():
            if self.half_done:
                self._lap_done()
                if self.goal is None:
                    return
            else:
                self.target_yaw += math.pi
                self.half_done = True
                self.last_error = None
        self.cmd_pub.publish(self.twist)

    def _reached_target(self) -> bool:
        error = shortest_angular_distance(self.yaw, self.target_yaw)
        stepped_over = (
            self.last_error is not None
            and abs(error) < math.pi / 2
            and math.copysign(1.0, error) != math.copysign(1.0, self.last_error)
        )
        self.last_error = error
        return abs(error) <= YAW_TOLERANCE or stepped_over

    def _lap_done(self) -> None:
        self.cmd_pub.publish(geometry_msgs.Twist())
        self.completed += 1
        self.server.publish_feedback(
            grobot_utilities.Patrol.Feedback(completed_patrols=self.completed)
        )
        if self.completed == self.goal.num_patrols:
            self.server.set_succeeded(grobot_utilities.Patrol.Result(success=True))
            self._reset()
            return
        self._start_lap()
