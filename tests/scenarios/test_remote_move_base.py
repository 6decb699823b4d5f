"""Across processes: lizis in one process, their move_base nodes in others, over Zenoh.

The simulation (``remote_nav/launch/sim.launch`` on fleetsim's office map: map_server, the
simulator, each lizi's spawn, state publishers and fake_localization, and the move_base
parameters from the shipped lizi YAML files) runs in this process with a `LaunchSession`
listening on a free loopback endpoint. move_base runs elsewhere: through ``fleetsim node run``
for one robot, or two host processes with half the robots' move_base nodes each. Goals go in
through a `Navigator` over a `SimulationClient` (a third Zenoh session); the pass criteria are
the simulator's ground truth (within lizi's goal tolerances), the monitor's contact count, and
where the graph says each move_base lives (which process, by pid).

Goals are 5-8 m away: through a door into a northern room, along the corridor, and through a
door into a southern office, so that no two robots cross paths.
"""

import math
import signal
import time

import pytest
from remote_nav_harness import (
    XY_GOAL_TOLERANCE,
    YAW_GOAL_TOLERANCE,
    RunningSimulation,
    free_endpoint,
    start_host,
    start_node_run,
    wait_for_action_servers,
)

from fleetsim.nav.navigator import Navigator, TaskResult
from fleetsim.transport import SimulationClient

pytestmark = pytest.mark.scenario

#: sim.launch's default starts (map frame, m), facing +x
STARTS = {"lizi1": (4.0, 10.0), "lizi2": (12.0, 10.0), "lizi3": (22.0, 10.0), "lizi4": (27.0, 10.0)}
#: goals (x, y, yaw): lizi1 through the door at x = 5 into the north-west room, lizi2 along the
#: corridor, lizi3 through the door at x = 21 into a southern office, lizi4 through the door at
#: x = 25 into the north-east room
GOALS = {
    "lizi1": (8.0, 15.0, math.pi / 2),
    "lizi2": (17.0, 10.0, 0.0),
    "lizi3": (21.0, 5.0, -math.pi / 2),
    "lizi4": (24.0, 15.0, math.pi / 2),
}
#: the goal is judged by the remote move_base on fake_localization's pose, which reaches it a
#: few control cycles late over Zenoh, and the robot coasts after the zero twist: margin (m, rad)
#: on top of the planner's tolerances for the ground truth
MARGIN_XY, MARGIN_YAW = 0.1, 0.1


def angle_between(a: float, b: float) -> float:
    return abs(math.atan2(math.sin(a - b), math.cos(a - b)))


def assert_reached(sim: RunningSimulation, model: str) -> None:
    x, y, yaw = sim.final[model]
    gx, gy, gyaw = GOALS[model]
    err = math.hypot(x - gx, y - gy)
    assert err < XY_GOAL_TOLERANCE + MARGIN_XY, f"{model} ended {err:.3f} m from its goal"
    assert angle_between(yaw, gyaw) < YAW_GOAL_TOLERANCE + MARGIN_YAW, f"{model} yaw {yaw:.2f}"
    sx, sy = STARTS[model]
    assert math.hypot(x - sx, y - sy) > 4.5, f"{model} hardly moved"
    result = {r.namespace: r for r in sim.session.monitor.results()}[f"/{model}"]
    assert result.collisions == 0, result
    assert result.path_length > 4.5, result
    # the monitor counts goals of a move_base that is not in the launch plan
    assert (result.goals_sent, result.goals_reached) == (1, 1), result


def send_and_wait(
    sim: RunningSimulation, navs: dict[str, Navigator], sim_budget: float, wall_cap: float = 300.0
) -> dict[str, tuple]:
    """Send every navigator its goal and wait until all are complete, or until ``sim_budget``
    sim seconds have passed since the goals went out (the pass criterion is the robots' own
    time: on a loaded 2-core machine the simulation can run well below its pace, and a wall
    clock budget then failed a robot that was still driving), or ``wall_cap`` wall seconds
    (a stalled simulation). Returns each model's result, status text and, for the unfinished,
    where it stands."""
    start = sim.runtime.now()
    for model, nav in navs.items():
        nav.go_to_pose(*GOALS[model])
    deadline = time.monotonic() + wall_cap
    while time.monotonic() < deadline and sim.runtime.now() - start < sim_budget:
        if all(nav.is_task_complete() for nav in navs.values()):
            break
        time.sleep(0.1)
    elapsed = sim.runtime.now() - start
    out = {}
    for m, nav in navs.items():
        where = ""
        if not nav.is_task_complete():
            where = f"after {elapsed:.1f} sim s: {nav.get_feedback()}, truth {sim.truth(m)}"
        out[m] = (nav.get_result(), nav.get_status_text(), where)
    return out


def test_move_base_in_another_process_drives_lizi_to_its_goal():
    endpoint = free_endpoint()
    with RunningSimulation(endpoint, {"robots": "1"}, rate=2.0) as sim:
        mb = start_node_run(endpoint, "/lizi1")
        try:
            with SimulationClient(endpoint, timeout=5.0) as client:
                missing = wait_for_action_servers(client, ["/lizi1"], 40.0, [mb])
                assert not missing, f"move_base never came up:\n{mb.stderr()[-3000:]}"
                # the action server is remote: the graph lists it, the simulation lacks it
                assert "/lizi1/move_base" in client.graph()["nodes"]
                assert "/lizi1/move_base" not in sim.runtime.graph.nodes
                results = send_and_wait(sim, {"lizi1": Navigator(client, "/lizi1")}, 60.0)
            # Ctrl-C stops it between scheduler steps (a stop event, not KeyboardInterrupt
            # raised inside a callback: that once left its Zenoh session unable to close); a
            # generous grace for a loaded 2-core machine, a node that ignores Ctrl-C still fails
            code = mb.stop(signal.SIGINT, timeout=45.0)
        finally:
            mb.close()
        sim.stop()
    assert results["lizi1"][0] is TaskResult.SUCCEEDED, results
    assert code == 130, f"fleetsim node run did not stop on Ctrl-C (status {code})"
    assert_reached(sim, "lizi1")


def test_two_processes_each_host_half_the_robots_move_base():
    endpoint = free_endpoint()
    halves = (["/lizi1", "/lizi2"], ["/lizi3", "/lizi4"])
    with RunningSimulation(endpoint, {"robots": "4"}, rate=1.0) as sim:
        hosts = [start_host(endpoint, half) for half in halves]
        try:
            with SimulationClient(endpoint, timeout=5.0) as client:
                missing = wait_for_action_servers(client, [*halves[0], *halves[1]], 40.0, hosts)
                errs = "\n".join(h.stderr()[-2000:] for h in hosts)
                assert not missing, f"no move_base for {missing}:\n{errs}"
                by_pid = {s["pid"]: set(s["nodes"]) for s in client.snapshots()}
                for host, half in zip(hosts, halves, strict=True):
                    assert by_pid.get(host.proc.pid) == {f"{ns}/move_base" for ns in half}
                navs = {ns.strip("/"): Navigator(client, ns) for half in halves for ns in half}
                results = send_and_wait(sim, navs, 60.0)
            codes = [h.stop(signal.SIGTERM) for h in hosts]
        finally:
            for h in hosts:
                h.close()
        sim.stop()
    failed = {m: r for m, r in results.items() if r[0] is not TaskResult.SUCCEEDED}
    assert not failed, failed
    assert codes == [0, 0], f"the host processes did not stop cleanly: {codes}"
    for model in GOALS:
        assert_reached(sim, model)


def test_a_launch_file_joins_a_running_simulation():
    """``fleetsim launch FILE --connect``: a robot spawned into the running simulation from
    another runtime, with its parameters in the simulation's tree and its tf from there."""
    from remote_nav_harness import PACKAGE

    from fleetsim.launch.runner import LaunchSession, load_plan

    endpoint = free_endpoint()
    with RunningSimulation(endpoint, {"robots": "1"}, rate=2.0) as sim:
        plan = load_plan(PACKAGE / "launch" / "join_robot.launch", {})
        with LaunchSession(plan, connect=endpoint) as joined:
            joined.run(duration=3.0)
            assert "/lizi9/robot_state_publisher" in joined.nodes
            with SimulationClient(endpoint, timeout=5.0) as client:
                # the plan's parameters went to the simulation's server
                assert client.param("get", "/lizi9/tf_prefix") == "lizi9"
                assert client.param("get", "/lizi9/move_base/controller_frequency") == 10.0
            frames = joined.runtime.tf_buffer.all_frames_as_string()
        sim.stop()
    assert "lizi9" in sim.robot_models() and "lizi1" in sim.robot_models()
    x, y, yaw = sim.final["lizi9"]
    assert math.hypot(x - 12.0, y - 10.0) < 0.1 and abs(yaw - 1.0) < 0.1
    assert "lizi9/base_link" in frames and "lizi9/odom" in frames
