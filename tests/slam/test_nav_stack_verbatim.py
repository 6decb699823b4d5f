"""The manual's nav_stack.launch exactly as the manual (``../shared/seeds/001_*``) types it: its
``$(find robocluedo_robot_hunter)/param/*.yaml`` files are shipped with the manual's values, so
the text copied from the manual runs: slam_gmapping maps while move_base drives the hunter."""

import logging
import os
import re
from pathlib import Path

import numpy as np
import pytest
import yaml

import fleetsim
from fleetsim.description.packages import PackageIndex
from fleetsim.launch.runner import LaunchSession, load_plan
from fleetsim.nav.navigator import Navigator, TaskResult
from fleetsim.slam import SlamGmapping

SEEDS = Path(__file__).resolve().parents[2] / ".." / "shared" / "seeds"
DASH = "\N{EN DASH}"  # the manual's headings read "param \N{EN DASH} <file>"
PARAM_FILES = (
    "base_local_planner_params.yaml",
    "costmap_common_params.yaml",
    "global_costmap_params.yaml",
    "local_costmap_params.yaml",
    "move_base_params.yaml",
)
#: keys where fleetsim's own copy (fleetsim_launch/params/hunter) differs from the manual,
#: each said why in that copy's comments
FLEETSIM_DIFFERENCES = {
    # the hunter's padded outline, and a TrajectoryPlannerROS set that drives it through doors
    "footprint": (None, [[0.28, 0.2], [0.28, -0.2], [-0.25, -0.2], [-0.25, 0.2]]),
    "footprint_padding": (None, 0.1),
    "robot_radius": (0.15, None),
    "TrajectoryPlannerROS/max_vel_x": (0.8, 0.5),
    "TrajectoryPlannerROS/min_vel_x": (0.4, 0.1),
    "TrajectoryPlannerROS/min_in_place_vel_theta": (-1.0, 0.4),
    "TrajectoryPlannerROS/acc_lim_theta": (1.0, 3.0),
    "TrajectoryPlannerROS/pdist_scale": (5.0, 0.6),
    "TrajectoryPlannerROS/gdist_scale": (0.0, 0.8),
    "TrajectoryPlannerROS/occdist_scale": (5.0, 0.01),
    "TrajectoryPlannerROS/heading_lookahead": (5.0, 0.325),
    "TrajectoryPlannerROS/dwa": (False, True),
    "TrajectoryPlannerROS/alignment_scale": (None, 0.6),
    "TrajectoryPlannerROS/forward_point_distance": (None, 0.325),
    "TrajectoryPlannerROS/escape_vel": (None, -0.1),
    "TrajectoryPlannerROS/global_costmap_check": (None, True),
    # TrajectoryPlannerROS does not read these
    "TrajectoryPlannerROS/max_vel_y": (0.0, None),
    "TrajectoryPlannerROS/min_vel_y": (0.0, None),
    "TrajectoryPlannerROS/vy_samples": (0, None),
}
#: the comment each changed value of the manual's carries in fleetsim's copy
SAYS_WHY = {
    "base_local_planner_params.yaml": [
        "the manual says 0.8",
        "the manual says 0.4",
        "the manual says -1.0",
        "acc_lim_theta 3.0 (manual 1.0)",
        "the manual says pdist 5, gdist 0, occdist 5",
        "the manual says 5.0",
        "the manual says false",
        "max_vel_y 0.0, min_vel_y 0.0 and vy_samples",
        "checked against gmapping's map",
    ],
    "costmap_common_params.yaml": ["the manual says robot_radius 0.15"],
}
#: what fleetsim says about the manual's files (TrajectoryPlannerROS does not read the three
#: y keys; the tolerance hint is fleetsim's own), and nothing else
EXPECTED_WARNINGS = [
    "unknown parameter 'max_vel_y'",
    "unknown parameter 'min_vel_y'",
    "unknown parameter 'vy_samples'",
    "more than twice xy_goal_tolerance 0.3 m",
]


def manual() -> str:
    (seed,) = SEEDS.glob("001_*.txt")
    return seed.read_text()


def manual_launch(name: str) -> str:
    """The launch file the manual introduces with "launch file <name>", as typed there."""
    text = manual().split(f"\nlaunch file {name}\n", 1)[1]
    start = text.index("<?xml")
    return text[start : text.index("</launch>", start) + len("</launch>")] + "\n"


def manual_params() -> dict[str, dict]:
    """The manual's "param <en dash> <file>" blocks, parsed."""
    text = manual()
    out = {}
    for name in PARAM_FILES:
        block = text.split(f"\nparam {DASH} {name}\n", 1)[1]
        block = re.split(rf"\n(?:param {DASH} |launch file )", block, maxsplit=1)[0]
        block = block.replace("see also move_base official wiki", "")
        out[name] = yaml.safe_load(block)
    return out


def flat(d: dict, prefix: str = "") -> dict:
    out = {}
    for k, v in d.items():
        if isinstance(v, dict):
            out.update(flat(v, f"{prefix}{k}/"))
        else:
            out[f"{prefix}{k}"] = v
    return out


def test_the_hunter_param_files_hold_the_manual_values():
    pkg = PackageIndex().find("robocluedo_robot_hunter")
    for name, values in manual_params().items():
        assert yaml.safe_load((pkg / "param" / name).read_text()) == values, name


def test_the_manual_nav_stack_launch_is_shipped_as_typed():
    """robocluedo_robot_hunter/launch/nav_stack.launch, which the manual's run2.launch includes."""
    pkg = PackageIndex().find("robocluedo_robot_hunter")
    shipped = (pkg / "launch" / "nav_stack.launch").read_text()
    assert shipped == manual_launch("nav_stack.launch")


def test_fleetsim_copy_differs_from_the_manual_only_where_it_says_why():
    own = Path(fleetsim.__file__).parent / "assets" / "launch" / "params" / "hunter"
    diffs = {}
    for name, values in manual_params().items():
        mine, theirs = flat(yaml.safe_load((own / name).read_text())), flat(values)
        for key in mine.keys() | theirs.keys():
            if mine.get(key) != theirs.get(key):
                diffs[key] = (theirs.get(key), mine.get(key))
    assert diffs == FLEETSIM_DIFFERENCES
    for name, phrases in SAYS_WHY.items():
        text = (own / name).read_text()
        assert [p for p in phrases if p not in text] == [], name


@pytest.mark.scenario
def test_the_manual_nav_stack_launch_runs_as_typed(tmp_path, caplog):
    os.environ.setdefault("MUJOCO_GL", "egl")
    nav_stack = tmp_path / "nav_stack.launch"
    nav_stack.write_text(manual_launch("nav_stack.launch"))
    assert "$(find robocluedo_robot_hunter)/param/costmap_common_params.yaml" in (
        nav_stack.read_text()
    )
    # the hunter in the office (hunter_run without its own nav stack), then the manual's file
    world = tmp_path / "hunter_with_manual_nav_stack.launch"
    world.write_text(
        "<launch>\n"
        '  <include file="$(find fleetsim_launch)/hunter_run.launch">\n'
        '    <arg name="launch_nav_stack" value="false"/>\n'
        "  </include>\n"
        f'  <include file="{nav_stack}"/>\n'
        "</launch>\n"
    )
    with caplog.at_level(logging.WARNING), LaunchSession(load_plan(world), seed=1) as s:
        slam = s.nodes["/slam_gmapping"]
        assert isinstance(slam, SlamGmapping) and slam.params.particles == 20
        mb = s.nodes["/move_base"]
        assert mb.local_costmap.params.transform_tolerance == 1.0  # the manual's files loaded
        nav = Navigator(s.runtime, "/")
        s.runtime.run(duration=1.0)
        nav.go_to_pose(6.5, 10.0, 0.0)  # 2.5 m down the office's corridor
        s.runtime.run(duration=20.0, until=nav.is_task_complete)
        assert nav.get_result() == TaskResult.SUCCEEDED, nav.get_status_text()
        pos, _ = s.monitor.sim.engine.model_pose("robocluedo_robot")
        grid = slam.grid_msg
    assert abs(pos[0] - 6.5) < 0.3 + 0.1
    assert slam.filter.updates >= 2 and grid.header.frame_id == "map"
    known = np.count_nonzero(np.asarray(grid.data) >= 0) * grid.info.resolution**2
    assert known > 20.0  # m^2 mapped
    warnings = [r.getMessage() for r in caplog.records]
    assert len(warnings) == len(EXPECTED_WARNINGS), warnings
    for text in EXPECTED_WARNINGS:
        assert any(text in w for w in warnings), (text, warnings)
    assert not Path("MUJOCO_LOG.TXT").exists()
