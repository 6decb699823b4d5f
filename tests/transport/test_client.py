"""SimulationClient: scripts that forget ``close()`` still exit; ``with`` closes."""

from __future__ import annotations

import subprocess
import sys
import textwrap

import pytest

from fleetsim.runtime import Runtime
from fleetsim.transport import SimulationClient

from .conftest import SimThread

#: generous: the failure this guards against is a process that never exits
EXIT_TIMEOUT = 60.0  # s


def run_script(code: str) -> subprocess.CompletedProcess:
    """Run ``code`` in a fresh interpreter; a hang fails the test (TimeoutExpired)."""
    try:
        return subprocess.run(
            [sys.executable, "-c", textwrap.dedent(code)],
            capture_output=True,
            text=True,
            timeout=EXIT_TIMEOUT,
        )
    except subprocess.TimeoutExpired:
        pytest.fail(f"the script did not exit within {EXIT_TIMEOUT:g} s:\n{code}")


@pytest.mark.parametrize(
    "body",
    [
        "c = SimulationClient(EP)\nc.subscribe('/chatter', lambda r: None)\n",
        "nav = Navigator(SimulationClient(EP), '/lizi1')\n",
        "c = SimulationClient(EP)\np = c.publisher('/other', std_msgs.String)\n",
    ],
    ids=["subscriber", "navigator", "publisher"],
)
def test_a_script_that_does_not_close_its_client_exits(sim, body):
    code = f"""
        from fleetsim.msgs import std_msgs
        from fleetsim.nav.navigator import Navigator
        from fleetsim.transport import SimulationClient
        EP = {sim.endpoint!r}
        {body.replace(chr(10), chr(10) + " " * 8)}
        print("done", flush=True)
    """
    r = run_script(code)
    assert r.returncode == 0, r.stderr
    assert r.stdout.strip() == "done"


def test_with_closes_the_client_and_close_is_idempotent(sim):
    with SimulationClient(sim.endpoint) as c:
        got = []
        c.subscribe("/chatter", got.append, latched=False)
        assert not c.closed
    assert c.closed
    c.close()  # a second close (and the one at exit) does nothing
    assert c.closed


def test_a_failed_connection_leaves_nothing_open(endpoint):
    from fleetsim.errors import TransportError

    with pytest.raises(TransportError, match="no simulation running"):
        SimulationClient(endpoint, timeout=0.3)


def test_the_simulation_side_keeps_running_after_a_script_exits(endpoint):
    rt = Runtime(seed=1)
    with SimThread(rt, endpoint):
        code = f"""
            from fleetsim.transport import SimulationClient
            c = SimulationClient({endpoint!r})
            c.subscribe('/rosout', lambda r: None)
        """
        assert run_script(code).returncode == 0
        with SimulationClient(endpoint) as c:
            assert c.sim_time() >= 0.0


def test_a_script_with_many_open_subscriptions_exits_without_aborting(endpoint):
    """Closing at exit wakes each subscription's reader thread; one that re-entered Python
    after finalisation began was ended by a forced unwind through zenoh's Rust frames, and the
    process aborted ("FATAL: exception not rethrown", 6 of 15 such scripts before the readers
    were joined at close)."""
    rt = Runtime(seed=1)
    with SimThread(rt, endpoint):
        code = f"""
            from fleetsim.transport import SimulationClient
            c = SimulationClient({endpoint!r})
            for i in range(30):
                c.subscribe(f'/t{{i}}', lambda r: None, latched=False)
        """
        for _ in range(5):
            r = run_script(code)
            assert (r.returncode, r.stderr) == (0, "")


def test_a_navigator_used_with_with_closes_its_subscriptions_not_the_client(sim):
    from fleetsim.nav.navigator import Navigator

    with SimulationClient(sim.endpoint) as c:
        with Navigator(c, "/lizi1") as nav:
            assert len(c._subs) == 3  # move_base status, feedback, result
            assert nav.get_result().name == "UNKNOWN"
        assert c._subs == [] and not c.closed
        got = []
        sub = c.subscribe("/chatter", got.append, latched=False)
        assert wait_for(lambda: got)
        sub.close()
        sub.close()
        assert c._subs == []


def wait_for(condition, timeout: float = 10.0) -> bool:
    import time

    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if condition():
            return True
        time.sleep(0.02)
    return False
