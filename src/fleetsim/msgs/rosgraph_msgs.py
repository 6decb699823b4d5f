"""rosgraph_msgs: Clock, the type of ``/clock`` (sim time)."""

from __future__ import annotations

from fleetsim.msgs.builtin_interfaces import Time
from fleetsim.msgs.registry import message


@message("rosgraph_msgs/msg/Clock")
class Clock:
    clock: Time
