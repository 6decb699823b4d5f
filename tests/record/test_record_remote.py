"""Recording a simulation in another runtime over the Zenoh bridge (`fleetsim bag record`)."""

from __future__ import annotations

import socket
import threading

import pytest
from typer.testing import CliRunner

from fleetsim.cli.bag import app
from fleetsim.record import BagReader
from fleetsim.record.remote import record_remote


def _free_endpoint() -> str:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return f"tcp/127.0.0.1:{s.getsockname()[1]}"


@pytest.fixture
def running_sim(fake_run):
    """A simulation (one robot with the map) served on a free endpoint, at 4x real time."""
    from fleetsim.transport import ZenohBridge

    rt, robots = fake_run(1)
    endpoint = _free_endpoint()
    bridge = ZenohBridge(rt, listen=[endpoint])
    stop = threading.Event()
    thread = threading.Thread(target=lambda: rt.run(until=stop.is_set, rate=4.0), daemon=True)
    thread.start()
    yield endpoint, robots[0]
    stop.set()
    thread.join(10)
    bridge.close()
    rt.shutdown()


def test_records_remote_topics_on_sim_time(running_sim, tmp_path):
    endpoint, robot = running_sim
    path = tmp_path / "remote.mcap"
    rec = record_remote(path, ["/robot0/scan", "/map"], connect=endpoint, duration=1.0,
                        poll_period=0.2)  # fmt: skip
    assert rec.closed and rec.recorded_topics == ["/map", "/robot0/scan"]
    msgs = list(BagReader(path).messages())
    scans = [m for m in msgs if m.topic == "/robot0/scan"]
    assert len(scans) >= 5
    # log time: the recorder's clock (the simulation's /clock) on arrival, not wall time. The
    # /clock and scan samples reach the recorder's threads separately, so on a loaded machine
    # its clock can trail a scan by some updates (120 ms of sim time seen at 4x real time);
    # wall time would be ~1.7e18 ns off
    for m in scans:
        assert abs(m.log_time_ns - m.msg.header.stamp.to_nsec()) <= 500_000_000
    log_times = [m.log_time_ns for m in scans]
    assert log_times == sorted(log_times)
    assert [m.msg.info.width for m in msgs if m.topic == "/map"] == [20]  # latched, fetched


def test_no_simulation_is_one_line(tmp_path):
    r = CliRunner().invoke(app, ["record", "-o", str(tmp_path / "x.mcap"), "--connect",
                                 _free_endpoint(), "--duration", "1"])  # fmt: skip
    assert r.exit_code == 1 and r.output.startswith("error: ")
    assert r.output.strip().count("\n") == 0
