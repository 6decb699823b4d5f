"""Small nodes the transport tests run in simulations and in other processes."""

from __future__ import annotations

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
