"""Lasers cast only while their scans have subscribers, as gazebo_ros_laser activates its ray
sensor on the first connection ("sensor generation off by default")."""

from fleetsim.description import load_robot
from fleetsim.msgs import sensor_msgs
from fleetsim.runtime import Runtime
from fleetsim.sim.engine import Engine
from fleetsim.sim.node import Simulator

LIZI = "src/fleetsim/assets/robots/lizi/urdf/lizi.urdf.xacro"


def counted_casts(engine: Engine) -> list[int]:
    casts: list[int] = []
    original = engine.lasers.measure

    def measure(eng, lasers, t):
        casts.append(len(lasers))
        return original(eng, lasers, t)

    engine.lasers.measure = measure
    return casts


def test_scans_are_cast_only_while_subscribed():
    rt = Runtime()
    sim = Simulator(rt, "gazebo")
    sim.spawn_robot("a", load_robot(LIZI), namespace="/a")
    sim.spawn_robot("b", load_robot(LIZI), (2.0, 0, 0, 0, 0, 0), namespace="/b")
    casts = counted_casts(sim.engine)
    rt.run(duration=0.5)
    assert casts == []  # nobody listens: no ray is cast
    scans = []
    sub = rt.graph.subscribe("/b/base_scan", sensor_msgs.LaserScan, scans.append)
    rt.run(duration=1.0)
    assert 38 <= len(scans) <= 42  # the lizi's 40 Hz, from the first update on
    assert casts and set(casts) == {1}  # only b's laser
    assert scans[-1].header.frame_id == "b/laser_link" and len(scans[-1].ranges) == 720
    sub.destroy()
    n = len(casts)
    rt.run(duration=0.5)
    assert len(casts) == n  # the last subscriber gone: casting stops again


def test_an_engine_without_the_simulator_node_always_casts():
    engine = Engine(None)
    engine.spawn_robot("a", load_robot(LIZI))
    casts = counted_casts(engine)
    readings = engine.advance(0.2)
    assert casts and any(type(r).__name__ == "ScanReading" for r in readings)
