"""``fleetsim node run``: a node in another process, on the simulation's clock and parameters."""

import os
import subprocess
import sys
import time
from pathlib import Path

import pytest

from fleetsim.errors import LaunchError, TransportError
from fleetsim.transport import SimulationClient
from fleetsim.transport.noderun import load_node_class, parse_assignments, run_node

ROOT = Path(__file__).resolve().parents[2]


def test_parse_assignments():
    assert parse_assignments(["a:=1", "b:=[1, 2]", "c:=x", "d:="], "--param") == {
        "a": 1,
        "b": [1, 2],
        "c": "x",
        "d": "",
    }
    assert parse_assignments(["scan:=/lizi1/scan"], "--remap") == {"scan": "/lizi1/scan"}
    with pytest.raises(LaunchError, match=r"--remap 'scan' must look like NAME:=VALUE"):
        parse_assignments(["scan"], "--remap")
    with pytest.raises(LaunchError, match=r"--param 'a:=\[1': the value is not YAML"):
        parse_assignments(["a:=[1"], "--param")


def test_load_node_class_errors():
    from transport.helper_nodes import Echo

    assert load_node_class("transport.helper_nodes:Echo") is Echo
    with pytest.raises(LaunchError, match=r"has no Node subclass named 'Nope'"):
        load_node_class("transport.helper_nodes:Nope")
    with pytest.raises(LaunchError, match=r"has no Node subclass named 'param'"):
        load_node_class("transport.helper_nodes:param")


def test_no_clock_is_a_clear_error(endpoint):
    from fleetsim.runtime import Runtime
    from fleetsim.transport import ZenohBridge

    rt = Runtime()
    peer = ZenohBridge(rt, listen=[endpoint], publish_clock=False)
    try:
        with pytest.raises(TransportError, match=r"no /clock from a simulation at .* within 0.3 s"):
            run_node("transport.helper_nodes:Echo", connect=endpoint, clock_timeout=0.3)
    finally:
        peer.close()


def test_node_in_another_process_exchanges_messages(sim):
    sim.runtime.params.set("/lizi1/echo/prefix", "from-sim:")
    code = (
        "import logging, sys\n"
        "logging.basicConfig(level=logging.INFO, stream=sys.stdout)\n"
        "from fleetsim.transport.noderun import run_node\n"
        "from fleetsim.runtime import Runtime\n"
        f"run_node('transport.helper_nodes:Echo', '/lizi1', connect='{sim.endpoint}',\n"
        "         remaps={'chatter': '/chatter', 'back': '/back', 'trigger': '/trigger'},\n"
        "         params={'period': 0.05}, until=float(sys.argv[1]))\n"
    )
    env = dict(os.environ, PYTHONPATH=f"{ROOT / 'src'}{os.pathsep}{ROOT / 'tests'}")
    # the window counts from before the interpreter starts: its start-up and imports took ~3 s
    # on a loaded machine (the node joined at 2.9 s of a 3 s window and echoed twice)
    until = sim.runtime.now() + 8.0
    r = subprocess.run(
        [sys.executable, "-c", code, str(until)],
        env=env,
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert r.returncode == 0, r.stderr
    assert "/lizi1/echo joined the simulation at" in r.stdout
    # it ran until the sim time it was given (no wall-clock bound: the subprocess timeout
    # catches a hang; a loaded machine only makes it slower)
    assert sim.runtime.now() >= until, (sim.runtime.now(), until)
    back = [m.data for m in sim.talker.back]
    assert len(back) >= 5
    assert all(b.startswith("from-sim:t=") for b in back)  # the simulation's parameter
    assert sim.talker.calls >= 1  # the remote node called the simulation's service


@pytest.mark.parametrize(("sig", "status"), [("SIGINT", 130), ("SIGTERM", 0)])
def test_the_command_stops_cleanly_on_ctrl_c_and_sigterm(sim, sig, status):
    """``fleetsim node run`` joined to a simulation: Ctrl-C exits 130 (as a shell expects of an
    interrupted command), SIGTERM 0 (a supervisor's clean stop), both through a stop event."""
    import signal

    env = dict(os.environ, PYTHONPATH=f"{ROOT / 'src'}{os.pathsep}{ROOT / 'tests'}")
    cmd = [sys.executable, "-m", "fleetsim.cli.main", "node", "run"]
    cmd += ["transport.helper_nodes:Echo", "--ns", "/lizi1", "--connect", sim.endpoint]
    p = subprocess.Popen(cmd, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    try:
        with SimulationClient(sim.endpoint, timeout=5.0) as client:
            deadline = time.monotonic() + 60
            while time.monotonic() < deadline and "/lizi1/echo" not in client.graph()["nodes"]:
                assert p.poll() is None, p.communicate()[0]
                time.sleep(0.2)
            assert "/lizi1/echo" in client.graph()["nodes"], "the node never joined"
        p.send_signal(getattr(signal, sig))
        out, _ = p.communicate(timeout=45)
    finally:
        if p.poll() is None:
            p.kill()
            p.wait()
    assert p.returncode == status, out
    assert "Traceback" not in out


def test_a_node_module_in_the_working_directory_is_found(tmp_path, monkeypatch):
    """``fleetsim node run mygoals:Crosser`` beside mygoals.py, as rosrun finds a script: the
    console script's path does not hold the working directory."""
    (tmp_path / "fs_probe_noderun_mod.py").write_text(
        "from fleetsim.runtime import Node\n\nclass Crosser(Node):\n    pass\n"
    )
    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr("sys.path", [p for p in __import__("sys").path if p not in ("", ".")])
    assert load_node_class("fs_probe_noderun_mod:Crosser").__name__ == "Crosser"
    with pytest.raises(LaunchError, match="looked on the Python path and in the working"):
        load_node_class("fs_probe_noderun_none:Crosser")
