"""slam_explore explores a world to the end: open_room (an empty 13 x 13 m room) with one hunter
and with two; the explorers stop with no frontier left, ``--until-goals`` exits 0 (the run
monitor's success), and the saved map is checked against the world's true occupancy."""

import logging
import os
from pathlib import Path

import pytest
from explore_runs import Records, precision_recall

import fleetsim
from fleetsim.cli.launch import resolve_launch_file
from fleetsim.cli.main import main
from fleetsim.launch.runner import LaunchSession, load_plan

pytestmark = pytest.mark.scenario

OPEN_ROOM = Path(fleetsim.__file__).parent / "assets" / "maps" / "open_room.yaml"


def test_one_hunter_explores_open_room_to_the_end_and_exits_zero(tmp_path):
    out = tmp_path / "open_room_slam"
    argv = ["launch", "slam_explore", "world:=open_room.yaml", f"map_out:={out}"]
    logger, records = logging.getLogger("fleetsim"), Records()
    logger.addHandler(records)
    try:
        code = main([*argv, "--until-goals", "--duration", "120", "--seed", "1", "--no-bridge"])
    finally:
        logger.removeHandler(records)
    assert code == 0
    log = [r.getMessage() for r in records.records]
    assert any("all frontiers traversed/tried out, stopping" in m for m in log)
    assert not any("gave up" in m for m in log)
    assert not [r.getMessage() for r in records.records if r.levelno >= logging.WARNING]
    precision, recall = precision_recall(out.with_suffix(".yaml"), OPEN_ROOM, (4.0, 10.0))
    assert precision >= 0.90 and recall >= 0.90, (precision, recall)  # the target
    assert not Path("MUJOCO_LOG.TXT").exists()


@pytest.fixture(scope="module")
def two_hunters(tmp_path_factory):
    """One run of slam_explore robots:=2 in open_room, shared by the tests below."""
    # the pair starts in opposite corners, out of each other's laser range (10 m), as measured
    # for the README (a start in view: test_two_hunters_starting_in_view_both_explore)
    tmp = tmp_path_factory.mktemp("two_hunters")
    out = tmp / "merged"
    starts = {"x1": "1.5", "y1": "1.5", "x2": "11.5", "y2": "11.5"}
    args = {"world": "open_room.yaml", "robots": "2", "map_out": str(out), **starts}
    plan = load_plan(resolve_launch_file("slam_explore"), args)
    records = Records()
    logging.getLogger().addHandler(records)
    cwd = Path.cwd()
    try:
        os.chdir(tmp)  # where MuJoCo would write MUJOCO_LOG.TXT
        with LaunchSession(plan, seed=1) as s:
            s.runtime.run(duration=90.0, until=s.monitor.all_goals_done)
            explorers = [s.nodes[f"/hunter{i}/explore"] for i in (1, 2)]
            results = {r.namespace: r for r in s.monitor.results()}
            success = s.monitor.success()
    finally:
        os.chdir(cwd)
        logging.getLogger().removeHandler(records)
    warnings = [r.getMessage() for r in records.records if r.levelno >= logging.WARNING]
    return explorers, results, success, warnings, out, tmp


def test_two_hunters_explore_open_room_to_the_end(two_hunters):
    explorers, results, success, warnings, _, tmp = two_hunters
    for ex in explorers:
        assert ex.finished and ex.succeeded and not ex.blacklist, ex.full_name
    assert success
    for ns in ("/hunter1", "/hunter2"):  # both explored
        assert results[ns].path_length > 5.0 and results[ns].collisions == 0, results[ns]
    assert not warnings, warnings
    assert not (tmp / "MUJOCO_LOG.TXT").exists()


def test_two_hunters_merged_map_of_open_room_is_right(two_hunters):
    # each hunter's gmapping leaves out the beams that end on the other (slam_gmapping's
    # peer_frames): 1.00 / 1.00 with it, 0.81 / 1.00 without (each hunter's body mapped by the
    # other, and hunter1's matcher, locked onto the moving peer, 0.18 m off at the end)
    out = two_hunters[4]
    precision, recall = precision_recall(out.with_suffix(".yaml"), OPEN_ROOM, (1.5, 1.5))
    assert precision >= 0.90 and recall >= 0.90, (precision, recall)  # the target


def test_two_hunters_starting_in_view_both_explore(tmp_path):
    # hunter2 starts 2.5 m in front of hunter1's laser: without slam_gmapping's peer_frames
    # hunter1 mapped it as an obstacle, the merged map made it lethal under hunter2 in the
    # global costmap it plans on ("not connected to the robot through free space"), and hunter2
    # never moved (0.12 m in 60 sim s, neither explorer finished; issue 17's audit)
    args = {"world": "open_room.yaml", "robots": "2", "x1": "1.5", "y1": "1.5", "x2": "4.0"}
    out = tmp_path / "merged"
    plan = load_plan(
        resolve_launch_file("slam_explore"), {**args, "y2": "1.5", "map_out": str(out)}
    )
    records = Records()
    logging.getLogger().addHandler(records)
    cwd = Path.cwd()
    try:
        os.chdir(tmp_path)
        with LaunchSession(plan, seed=1) as s:
            s.runtime.run(duration=60.0, until=s.monitor.all_goals_done)
            explorers = [s.nodes[f"/hunter{i}/explore"] for i in (1, 2)]
            results = {r.namespace: r for r in s.monitor.results()}
            dropped = [s.nodes[f"/hunter{i}/slam_gmapping"].peer_beams_dropped for i in (1, 2)]
    finally:
        os.chdir(cwd)
        logging.getLogger().removeHandler(records)
    assert dropped[0] > 0  # hunter1 saw hunter2 and left it out
    for ex in explorers:
        assert ex.finished and ex.succeeded, ex.full_name
    assert results["/hunter2"].path_length > 5.0, results["/hunter2"]
    warnings = [r.getMessage() for r in records.records if r.levelno >= logging.WARNING]
    assert not warnings, warnings
    assert not (tmp_path / "MUJOCO_LOG.TXT").exists()
    # hunter1 mostly sees one wall at a time here (10 m laser): without the matcher's
    # degeneracy_threshold it slid 1.6 m along one and the map scored precision 0.84
    precision, recall = precision_recall(out.with_suffix(".yaml"), OPEN_ROOM, (1.5, 1.5))
    assert precision >= 0.90 and recall >= 0.90, (precision, recall)
