"""A batch on a two-node Ray cluster started on loopback gives the serial table.

The head and a worker node (one CPU each) are ``ray start --block`` processes in process
groups of their own, torn down by their ids after the test. The batch ships the fixtures folder
to the cluster as the runs' working directory (a Ray runtime environment), as it would to
machines that have only fleetsim installed.
"""

import os
import signal
import socket
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import pytest
from batch_sweep import comparable, tiny_spec

from fleetsim.batch import run_batch

pytestmark = [pytest.mark.scenario, pytest.mark.timeout(240)]
RAY = Path(sys.executable).parent / "ray"


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def ray_node(*args: str, log: Path) -> subprocess.Popen:
    env = dict(os.environ, RAY_USAGE_STATS_ENABLED="0", RAY_AUTH_MODE="token")
    with log.open("wb") as f:
        return subprocess.Popen(
            [str(RAY), "start", "--block", "--num-cpus=1", "--disable-usage-stats", *args],
            stdout=f, stderr=subprocess.STDOUT, env=env, start_new_session=True,
        )  # fmt: skip


def stop(proc: subprocess.Popen) -> None:
    """End a node: its ``ray start`` process group (Ctrl-C ends --block), then for good."""
    for sig, wait in ((signal.SIGINT, 10), (signal.SIGKILL, 5)):
        try:
            os.killpg(proc.pid, sig)
        except ProcessLookupError:
            return
        try:
            proc.wait(timeout=wait)
            return
        except subprocess.TimeoutExpired:
            continue


def cpus(address: str) -> float:
    import ray

    ray.init(address=address, log_to_driver=False)
    try:
        return ray.cluster_resources().get("CPU", 0)
    finally:
        ray.shutdown()


@pytest.fixture
def two_node_cluster(tmp_path: Path, monkeypatch):
    # the cluster and this driver authenticate with the local token (~/.ray/auth_token), as
    # an embedded Ray does by default
    monkeypatch.setenv("RAY_AUTH_MODE", "token")
    port = free_port()
    address = f"127.0.0.1:{port}"
    # Ray's socket paths must be short: a temp dir right under /tmp
    temp = tempfile.mkdtemp(prefix="fsray", dir="/tmp")
    head = ray_node(
        "--head", f"--port={port}", "--node-ip-address=127.0.0.1", "--include-dashboard=false",
        f"--temp-dir={temp}", log=tmp_path / "head.log",
    )  # fmt: skip
    nodes = [head]
    try:
        deadline = time.monotonic() + 60
        while b"Ray runtime started" not in (tmp_path / "head.log").read_bytes():
            assert head.poll() is None, (tmp_path / "head.log").read_text()
            assert time.monotonic() < deadline, "the Ray head did not start in 60 s"
            time.sleep(0.5)
        nodes.append(
            ray_node(f"--address={address}", "--node-ip-address=127.0.0.1", log=tmp_path / "w.log")
        )
        while cpus(address) < 2:
            assert nodes[1].poll() is None, (tmp_path / "w.log").read_text()
            assert time.monotonic() < deadline, "the second Ray node did not join in 60 s"
            time.sleep(1.0)
        yield address
    finally:
        for proc in reversed(nodes):
            stop(proc)


def test_two_node_cluster_gives_the_serial_table(serial, two_node_cluster, tmp_path: Path):
    table = run_batch(tiny_spec(), tmp_path / "cluster", address=two_node_cluster, progress=False)
    assert comparable(table.table()) == comparable(serial)
