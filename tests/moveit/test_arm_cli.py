"""``fleetsim arm list|go`` against a hunter simulation served over the Zenoh bridge."""

import socket
import threading

import pytest
from typer.testing import CliRunner

from fleetsim.cli.main import app
from fleetsim.errors import FleetsimError
from fleetsim.transport import ZenohBridge

from .conftest import Hunters

runner = CliRunner()


def free_endpoint() -> str:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return f"tcp/127.0.0.1:{s.getsockname()[1]}"


@pytest.fixture(scope="module")
def served(hunter_robot):
    ep = free_endpoint()
    h = Hunters(hunter_robot)
    ZenohBridge(h.rt, listen=[ep])
    stop = threading.Event()
    th = threading.Thread(target=lambda: h.rt.run(until=stop.is_set, rate=20.0), daemon=True)
    th.start()
    yield ep, h
    stop.set()
    th.join(10)
    h.rt.shutdown()


def run(*args):
    return runner.invoke(app, [str(a) for a in args])


def test_list_groups_and_poses(served):
    ep, _ = served
    r = run("arm", "list", "--ns", "hunter1", "-c", ep)
    assert r.exit_code == 0, r.output
    lines = r.stdout.splitlines()
    assert lines[0] == "arm_group: arm_joint_01, arm_joint_02, arm_joint_03, arm_joint_04"
    assert "  home: -1.57 0.1293 -0.4276 0.3481" in lines
    assert sum(line.startswith("  ") for line in lines) == 9


def test_go_to_a_named_pose_and_bad_targets(served):
    ep, h = served
    r = run("arm", "go", "cam_left", "--ns", "hunter1", "--timeout", 60, "-c", ep)
    assert r.exit_code == 0, (r.output, r.exception)
    assert r.stdout.strip().startswith("result: SUCCESS")
    q = h.move_group("hunter1").joint_positions["arm_joint_01"]
    assert q == pytest.approx(0.0867, abs=0.01)
    for args, message in (
        (("cam_up",), "no named state 'cam_up'"),
        (("0,0,0",), "group 'arm_group' has 4 joints"),
        (("0,2.5,0,0",), "'arm_joint_02' value 2.5000 is outside"),
        (("home", "--group", "arm"), "no planning group 'arm'"),
    ):
        r = run("arm", "go", *args, "--ns", "hunter1", "-c", ep)
        assert r.exit_code != 0 and isinstance(r.exception, FleetsimError), r.output
        assert message in str(r.exception)


def test_commander_from_another_process_over_the_bridge(served):
    from fleetsim.moveit import MoveGroupCommander

    ep, h = served
    arm = MoveGroupCommander("arm_group", ns="/hunter1", connect=ep)
    try:
        assert "cam_back" in arm.get_named_targets()
        arm.set_named_target("cam_back")
        assert arm.go(), arm.last_result()
        assert arm.get_current_joint_values()[0] == pytest.approx(1.6828, abs=0.02)
        ok, traj, planning_time, code = arm.plan("home")
        assert ok and code.val == 1 and traj.joint_trajectory.joint_names[0] == "arm_joint_01"
        with pytest.raises(FleetsimError, match="no named state 'up'"):
            arm.set_named_target("up")
        # move_group's compute_cartesian_path service, called over the bridge
        lower = arm.get_current_pose().pose
        lower.position.z -= 0.03
        traj, fraction = arm.compute_cartesian_path([lower], 0.01, 0.0)
        assert fraction == pytest.approx(1.0) and len(traj.joint_trajectory.points) >= 2
    finally:
        arm._c.close()


def test_a_commander_waiting_on_a_simulation_whose_clock_stopped_gives_up(
    hunter_robot, monkeypatch
):
    """A script's go() against a run that has ended (or stopped) had waited ~10 minutes (the
    600 s allowed a move plus margins); it now ends once the clock stands still."""
    import time

    import fleetsim.moveit.remote as remote
    from fleetsim.moveit import MoveGroupCommander

    monkeypatch.setattr(remote, "CLOCK_STALL", 2.0)
    ep = free_endpoint()
    h = Hunters(hunter_robot)
    bridge = ZenohBridge(h.rt, listen=[ep])
    stop = threading.Event()
    th = threading.Thread(target=lambda: h.rt.run(until=stop.is_set, rate=20.0), daemon=True)
    th.start()
    arm = MoveGroupCommander("arm_group", ns="/hunter1", connect=ep)
    try:
        stop.set()  # the run stops: nothing answers the goal, the clock stands
        th.join(10)
        t0 = time.monotonic()
        with pytest.raises(FleetsimError, match="the simulation's clock has stood at"):
            arm.go("cam_left")
        assert time.monotonic() - t0 < 15.0
    finally:
        arm._c.close()
        bridge.close()
        h.rt.shutdown()
