"""A runtime on a remote /clock: never ahead, starts at the simulation's time, notices loss."""

import threading

import pytest

from fleetsim.errors import TransportError
from fleetsim.runtime import Node, Runtime
from fleetsim.transport import ZenohBridge


def test_follower_never_runs_ahead_of_the_simulation(sim):
    rt = Runtime()
    bridge = ZenohBridge(rt, mode="client", connect=[sim.endpoint], follow_clock=True)
    try:
        t0 = rt.now()
        assert 0.0 < t0 <= bridge.clock_time  # starts at the first clock received
        ahead = []
        ticks = []

        def tick():
            ticks.append(rt.now())
            ahead.append(rt.now() - sim.runtime.now())

        Node(rt, "ticker").create_timer(0.05, tick)
        bridge.run_following(until=t0 + 0.6)
        assert rt.now() == pytest.approx(t0 + 0.6)
        assert len(ticks) == 12 and ticks == sorted(ticks)
        assert max(ahead) <= 1e-9  # the simulation was always at or past the follower's time
    finally:
        rt.shutdown()


def test_run_following_needs_follow_clock(sim):
    rt = Runtime()
    bridge = ZenohBridge(rt, mode="client", connect=[sim.endpoint])
    try:
        with pytest.raises(TransportError, match="needs a bridge made with follow_clock=True"):
            bridge.run_following(until=1.0)
    finally:
        rt.shutdown()


def test_follow_clock_must_come_before_timers(sim):
    rt = Runtime()
    rt.create_timer(1.0, lambda: None)
    with pytest.raises(TransportError, match="before any node or timer of its runtime"):
        ZenohBridge(rt, mode="client", connect=[sim.endpoint], follow_clock=True)


def test_simulation_going_away_is_reported(endpoint):
    from transport.conftest import SimThread

    sim = SimThread(Runtime(), endpoint).__enter__()
    rt = Runtime()
    bridge = ZenohBridge(rt, mode="client", connect=[endpoint], follow_clock=True)
    errors = []

    def follow():
        try:
            bridge.run_following()
        except TransportError as e:
            errors.append(str(e))

    th = threading.Thread(target=follow)
    th.start()
    sim.stop()
    th.join(10)
    rt.shutdown()
    assert not th.is_alive()
    assert errors and errors[0].startswith(f"the simulation at {endpoint} went away at t = ")
