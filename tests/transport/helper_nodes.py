"""Small nodes the transport tests run in simulations and in other processes."""

from __future__ import annotations

import math
from dataclasses import dataclass

from fleetsim.msgs import std_msgs, std_srvs
from fleetsim.runtime import Node, param


class Talker(Node):
    """Publishes ``chatter`` (String ``t=<sim time>``) at 10 Hz and a latched ``greeting``;
    keeps what arrives on ``back``; serves ``trigger`` (std_srvs/Trigger)."""

    def __init__(self, runtime, name="talker", namespace="/", **kw):
        super().__init__(runtime, name, namespace, **kw)
        self.pub = self.create_publisher(std_msgs.String, "chatter")
        self.greeting = self.create_publisher(std_msgs.String, "greeting", latch=True)
        self.greeting.publish(std_msgs.String(data="hello"))
        self.create_timer(0.1, self.on_timer)
        self.back: list = []
        self.create_subscription(std_msgs.String, "back", self.back.append)
        self.calls = 0
        self.create_service(std_srvs.Trigger, "trigger", self.on_trigger)

    def on_timer(self):
        self.pub.publish(std_msgs.String(data=f"t={self.now():.2f}"))

    def on_trigger(self, req):
        self.calls += 1
        return std_srvs.Trigger.Response(success=True, message=f"call {self.calls}")


@dataclass(frozen=True)
class EchoParams:
    prefix: str = param("echo:", help="text put before each echoed message")
    period: float = param(0.1, unit="s", range=(0.0, None), help="reply timer period")


class Echo(Node):
    """Republishes ``chatter`` on ``back`` with a prefix, and calls ``trigger`` once."""

    Params = EchoParams

    def __init__(self, runtime, name="echo", namespace="/", **kw):
        super().__init__(runtime, name, namespace, **kw)
        self.pub = self.create_publisher(std_msgs.String, "back")
        self.heard: list = []
        self.create_subscription(std_msgs.String, "chatter", self.on_chatter)
        self.client = self.create_client(std_srvs.Trigger, "trigger")
        self.answer = None
        self.create_timer(self.params.period, self.on_timer)

    def on_chatter(self, msg):
        self.heard.append((self.now(), msg.data))
        self.pub.publish(std_msgs.String(data=f"{self.params.prefix}{msg.data}"))

    def on_timer(self):
        if self.answer is None and self.client.service_is_ready():
            self.answer = self.client.call(None).message


@dataclass(frozen=True)
class GoToPointParams:
    goal_x: float = param(1.0, unit="m", help="goal x in the odometry frame")
    goal_y: float = param(0.0, unit="m", help="goal y in the odometry frame")
    xy_goal_tolerance: float = param(0.1, unit="m", range=(0.0, None), help="stop within this")


class GoToPoint(Node):
    """Drives a differential robot to a point from its odometry (a proportional controller):
    ``odom`` in, ``cmd_vel`` out at 10 Hz; publishes ``arrived`` (Bool) once there."""

    Params = GoToPointParams

    def __init__(self, runtime, name="go_to_point", namespace="/", **kw):
        from fleetsim.msgs import geometry_msgs, nav_msgs

        super().__init__(runtime, name, namespace, **kw)
        self._twist = geometry_msgs.Twist
        self.pose = None
        self.create_subscription(nav_msgs.Odometry, "odom", self.on_odom, queue_size=1)
        self.cmd = self.create_publisher(geometry_msgs.Twist, "cmd_vel")
        self.arrived = self.create_publisher(std_msgs.Bool, "arrived", latch=True)
        self.create_timer(0.1, self.on_timer)

    def on_odom(self, msg):
        p, q = msg.pose.pose.position, msg.pose.pose.orientation
        yaw = math.atan2(2 * (q.w * q.z + q.x * q.y), 1 - 2 * (q.y * q.y + q.z * q.z))
        self.pose = (p.x, p.y, yaw)

    def on_timer(self):
        if self.pose is None:
            return
        x, y, yaw = self.pose
        dx, dy = self.params.goal_x - x, self.params.goal_y - y
        dist = math.hypot(dx, dy)
        cmd = self._twist()
        if dist < self.params.xy_goal_tolerance:
            if self.arrived.last is None:
                self.arrived.publish(std_msgs.Bool(data=True))
        else:
            err = math.atan2(math.sin(math.atan2(dy, dx) - yaw), math.cos(math.atan2(dy, dx) - yaw))
            cmd.angular.z = max(-1.5, min(1.5, 2.0 * err))
            cmd.linear.x = min(0.4, dist) * max(0.0, math.cos(err))
        self.cmd.publish(cmd)
