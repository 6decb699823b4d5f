"""Fixtures: free loopback endpoints and a simulation runtime running in a background thread."""

from __future__ import annotations

import socket
import threading

import pytest

from fleetsim.runtime import Runtime
from fleetsim.transport import ZenohBridge


def free_endpoint() -> str:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return f"tcp/127.0.0.1:{s.getsockname()[1]}"


class SimThread:
    """A runtime with a listening bridge, run at ``rate`` x real time in a thread."""

    def __init__(self, runtime: Runtime, endpoint: str, rate: float = 1.0, **bridge_kw) -> None:
        self.runtime = runtime
        self.endpoint = endpoint
        self.bridge = ZenohBridge(runtime, listen=[endpoint], **bridge_kw)
        self._stop = threading.Event()
        self._error: list = []

        def run() -> None:
            try:
                runtime.run(until=self._stop.is_set, rate=rate)
            except BaseException as e:  # surfaced by stop()
                self._error.append(e)

        self.thread = threading.Thread(target=run, name="sim", daemon=True)

    def __enter__(self) -> SimThread:
        self.thread.start()
        return self

    def stop(self) -> None:
        self._stop.set()
        self.thread.join(10)
        assert not self.thread.is_alive(), "the simulation thread did not stop"
        self.runtime.shutdown()
        if self._error:
            raise self._error[0]

    def __exit__(self, *exc) -> None:
        self.stop()


@pytest.fixture
def endpoint() -> str:
    return free_endpoint()


@pytest.fixture
def sim(endpoint):
    """A running simulation with a `Talker` node (see helper_nodes)."""
    from transport.helper_nodes import Talker

    rt = Runtime(seed=1)
    rt.params.set("/talker/rate", 10)
    rt.params.set("/robots", {"lizi1": {"x": 1.5}})
    talker = Talker(rt)
    with SimThread(rt, endpoint) as s:
        s.talker = talker
        yield s
