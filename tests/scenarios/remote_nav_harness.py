"""Test harness of the cross-process navigation scenarios (`remote_nav` test package).

The simulation half runs in the test process: ``remote_nav/launch/sim.launch`` (map_server, the
simulator on fleetsim's office map, up to four lizis with their state publishers and
fake_localization, and each robot's move_base parameters under ``<ns>/move_base`` but no
move_base) in a `LaunchSession` listening on a free loopback Zenoh endpoint, advanced in a
background thread (`RunningSimulation`). The robots' move_base nodes run in subprocesses:

* `start_node_run`: one move_base through the command line, ``fleetsim node run
  fleetsim.nav.move_base:MoveBase --ns /lizi1 --remap map:=/map --connect ENDPOINT``;
* `start_host`: two robots' move_base nodes in one process, ``fleetsim launch
  move_bases.launch ... --connect ENDPOINT``, which stops cleanly on SIGTERM.

Both copy the simulation's parameter tree, so the move_base nodes read the YAML files that the
launch file loaded. Every subprocess writes its stderr to a file (a pipe could fill and block
it) and is stopped by `stop_process`, killed if it does not exit in time.
"""

from __future__ import annotations

import math
import os
import signal
import socket
import subprocess
import sys
import tempfile
import threading
import time
from collections.abc import Sequence
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
PACKAGE = Path(__file__).resolve().parent / "remote_nav"
SIM_LAUNCH = PACKAGE / "launch" / "sim.launch"
#: lizi's goal tolerances in the shipped base_local_planner_params.yaml (m, rad)
XY_GOAL_TOLERANCE = 0.2
YAW_GOAL_TOLERANCE = 0.3


def free_endpoint() -> str:
    """A ``tcp/127.0.0.1:PORT`` locator on a port that was free a moment ago."""
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return f"tcp/127.0.0.1:{s.getsockname()[1]}"


class RunningSimulation:
    """``sim.launch`` in a `LaunchSession` listening on ``endpoint``, run in a thread.

    ``rate`` paces sim time to that multiple of the wall clock (the remote move_base nodes
    follow ``/clock`` and must keep up). `stop` ends the thread, closes the session (bridge
    included) and re-raises an error of the simulation thread; ``final`` then holds each
    robot's ground-truth (x, y, yaw), read on the simulation thread when it stopped.
    """

    def __init__(self, endpoint: str, args: dict[str, str], rate: float, seed: int = 1) -> None:
        os.environ.setdefault("MUJOCO_GL", "egl")
        from fleetsim.launch.runner import LaunchSession, load_plan

        self.endpoint = endpoint
        self.session = LaunchSession(load_plan(SIM_LAUNCH, args), seed=seed, listen=endpoint)
        self.runtime = self.session.runtime
        self._stop = threading.Event()
        self._errors: list[BaseException] = []
        self.final: dict[str, tuple[float, float, float]] = {}

        def run() -> None:
            try:
                self.runtime.run(until=self._stop.is_set, rate=rate)
                self.final = {m: self.truth(m) for m in self.robot_models()}
            except BaseException as e:  # surfaced by stop()
                self._errors.append(e)

        self.thread = threading.Thread(target=run, name="simulation", daemon=True)

    def __enter__(self) -> RunningSimulation:
        self.thread.start()
        return self

    def stop(self) -> None:
        if self._stop.is_set():
            return
        self._stop.set()
        self.thread.join(15)
        alive = self.thread.is_alive()
        self.session.close()
        assert not alive, "the simulation thread did not stop within 15 s"
        if self._errors:
            raise self._errors[0]

    def __exit__(self, *exc: object) -> None:
        self.stop()

    def robot_models(self) -> list[str]:
        engine = self.session.monitor.sim.engine
        return sorted(name for name, entry in engine.models.items() if entry.kind == "robot")

    def truth(self, model: str) -> tuple[float, float, float]:
        """The model's ground-truth (x, y, yaw) in the world (= map) frame, m and rad."""
        pos, q = self.session.monitor.sim.engine.model_pose(model)  # q: (w, x, y, z)
        w, x, y, z = (float(v) for v in q)
        yaw = math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))
        return float(pos[0]), float(pos[1]), yaw


class Subprocess:
    """A child process with its stderr in a temporary file."""

    def __init__(self, argv: list[str]) -> None:
        env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(ROOT / "src"), str(PACKAGE.parent)]))
        env.setdefault("MUJOCO_GL", "egl")
        self.argv = argv
        # lives as long as the process object; close() closes it
        self._err = tempfile.TemporaryFile(mode="w+")  # noqa: SIM115
        self.proc = subprocess.Popen(
            argv, env=env, stdout=subprocess.DEVNULL, stderr=self._err, text=True
        )

    def stderr(self) -> str:
        self._err.seek(0)
        return self._err.read()

    def stop(self, sig: int = signal.SIGTERM, timeout: float = 15.0) -> int | None:
        """Send ``sig`` (if still running) and wait; kill it after ``timeout`` s.

        Returns the exit status, or None when it had to be killed.
        """
        p = self.proc
        if p.poll() is None:
            p.send_signal(sig)
            try:
                p.wait(timeout)
            except subprocess.TimeoutExpired:
                p.kill()
                p.wait(10)
                return None
        return p.returncode

    def close(self) -> None:
        if self.proc.poll() is None:
            self.stop(signal.SIGKILL, 10)
        self._err.close()


def start_node_run(endpoint: str, namespace: str) -> Subprocess:
    """``fleetsim node run fleetsim.nav.move_base:MoveBase`` for one robot namespace."""
    return Subprocess(
        [
            sys.executable,
            "-m",
            "fleetsim.cli.main",
            "node",
            "run",
            "fleetsim.nav.move_base:MoveBase",
            "--ns",
            namespace,
            "--remap",
            "map:=/map",
            "--connect",
            endpoint,
        ]
    )


def start_host(endpoint: str, namespaces: list[str]) -> Subprocess:
    """A process hosting the move_base nodes of two robot ``namespaces``: ``fleetsim launch
    move_bases.launch first:=NS second:=NS --connect ENDPOINT`` (stops cleanly on SIGTERM)."""
    first, second = (ns.strip("/") for ns in namespaces)
    return Subprocess(
        [
            sys.executable,
            "-m",
            "fleetsim.cli.main",
            "launch",
            str(PACKAGE / "launch" / "move_bases.launch"),
            f"first:={first}",
            f"second:={second}",
            "--connect",
            endpoint,
        ]
    )


def wait_for_action_servers(
    client, namespaces: list[str], timeout: float, hosts: Sequence[Subprocess] = ()
) -> list[str]:
    """Wait (wall s) until each ``<ns>/move_base`` publishes its status somewhere in the
    graph; returns the namespaces still missing (empty when all are up). Gives up early when
    one of ``hosts`` has exited."""
    deadline = time.monotonic() + timeout
    missing = list(namespaces)
    while missing and time.monotonic() < deadline:
        if any(h.proc.poll() is not None for h in hosts):
            break
        topics = client.graph()["topics"]
        missing = [
            ns
            for ns in missing
            if not (topics.get(f"{ns}/move_base/status") or {}).get("publishers")
        ]
        if missing:
            time.sleep(0.2)
    return missing
