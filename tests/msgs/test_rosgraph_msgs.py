from __future__ import annotations

from fleetsim.msgs import builtin_interfaces, deserialize, rosgraph_msgs, serialize


def test_clock():
    clock = rosgraph_msgs.Clock(builtin_interfaces.Time.from_sec(12.5))
    data = serialize(clock)
    assert len(data) == 4 + 8
    assert deserialize(data, "rosgraph_msgs/Clock").clock.to_sec() == 12.5
