"""Joint state publisher: the listed joints' state, one reading per plugin."""

import numpy as np

from fleetsim.description import parse_urdf
from fleetsim.sim import Engine
from fleetsim.sim.plugins.joint_state import JointStatePlugin

from ..conftest import robot_text


def test_joint_states_of_many_robots_at_once_equal_one_by_one(diffbot):
    one_joint = parse_urdf(
        robot_text("diffbot.urdf").replace(
            "<jointName>left_wheel_joint, right_wheel_joint</jointName>",
            "<jointName>right_wheel_joint</jointName><topicName>wheels</topicName>",
        )
    )
    e = Engine(None)
    entries = [e.spawn_robot("a", diffbot), e.spawn_robot("b", one_joint, (0, 2, 0, 0, 0, 0))]
    for ent, (vx, wz) in zip(entries, [(0.4, 0.5), (-0.3, 0.2)]):
        ent.plugins[0].command(vx, wz, e.time)
    e.advance(0.5)
    plugins = [next(p for p in ent.plugins if isinstance(p, JointStatePlugin)) for ent in entries]
    batch = JointStatePlugin.measure_each(e, plugins, e.time)
    assert [r.names for r in batch] == [
        ["left_wheel_joint", "right_wheel_joint"],
        ["right_wheel_joint"],
    ]
    assert [(r.topic, r.namespace) for r in batch] == [("joint_states", "/a"), ("wheels", "/b")]
    d = e.data
    for p, r in zip(plugins, batch):
        np.testing.assert_array_equal(r.position, d.qpos[p.qadr])
        np.testing.assert_array_equal(r.velocity, d.qvel[p.dadr])
        np.testing.assert_array_equal(r.effort, d.qfrc_actuator[p.dadr])
        one = p.measure(e, e.time)
        for field in ("position", "velocity", "effort"):
            np.testing.assert_array_equal(getattr(one, field), getattr(r, field))
    assert abs(batch[0].velocity).min() > 1.0  # the wheels turn
