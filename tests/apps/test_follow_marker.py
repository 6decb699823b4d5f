from __future__ import annotations

import itertools
import math

import pytest

from fleetsim.apps.follow_marker import FollowMarker
from fleetsim.errors import ParameterError
from fleetsim.runtime import Node, Runtime

from .follow_world import FollowWorld

MOVE_TO_TARGET = {
    "strategy": "move_to_target",
    "robot_frame": "base_footprint",
    "target_pose": {"x": 1.0, "y": 0.0, "yaw": 3.1416, "frame_id": "map"},
}


def world(exploration=None, start=(0.0, 0.0, 0.0)):
    rt = Runtime(seed=0)
    w = FollowWorld(rt, start)
    params = {"marker_id": 0, "marker_to_target_pose": {"x": -0.8, "y": 0.0}}
    if exploration is not None:
        params["exploration"] = exploration
    f = FollowMarker(rt, params=params)
    return rt, w, f


def test_goal_is_0_8_m_behind_the_marker_facing_its_way():
    rt, w, f = world()
    w.marker = (3.0, 0.5, 0.3)  # a burger ahead, driving away at heading 0.3
    rt.run(duration=0.35)
    assert len(w.simple_goals) >= 3 and w.action_goals == []
    gx, gy, gyaw = w.simple_goals[0]
    assert gx == pytest.approx(3.0 - 0.8 * math.cos(0.3), abs=1e-6)
    assert gy == pytest.approx(0.5 - 0.8 * math.sin(0.3), abs=1e-6)
    assert gyaw == pytest.approx(0.3, abs=1e-6)
    target = rt.tf_buffer.lookup_arrays("map", "target", 0.0)[0]
    assert target[:2] == pytest.approx([gx, gy], abs=0.05)


def test_too_close_sends_nothing_and_does_not_explore():
    rt, w, f = world()
    w.marker = (1.4, 0.0, 0.0)  # 1.4 m < 2 x 0.8 m
    rt.run(duration=6.0)
    assert w.simple_goals == [] and w.action_goals == []
    assert f.last_update == pytest.approx(rt.now(), abs=0.11)


def test_lost_for_4_s_then_rotates_in_120_degree_steps_until_seen():
    rt, w, f = world()
    w.marker = (3.0, 0.0, 0.0)
    rt.run(duration=1.0)
    seen_until = rt.now()
    n_goals = len(w.simple_goals)
    w.marker = None
    rt.run(duration=3.8)
    assert w.action_goals == []  # not yet 4 s
    rt.run(duration=0.4)
    assert len(w.action_goals) == 1  # lost for > 4 s of image time
    assert rt.now() - seen_until > 4.0
    rt.run(duration=8.0)  # each 120 deg turn takes ~2.1 s here
    yaws = [g[2] for g in w.action_goals]
    assert len(yaws) >= 3
    steps = [math.remainder(b - a, math.tau) for a, b in itertools.pairwise(yaws)]
    assert steps == pytest.approx([2 * math.pi / 3] * len(steps), abs=0.06)
    assert f.exploration.is_exploring()
    # seen again: the running step is cancelled, the next detections give goals again
    w.marker = (w.x + 3.0 * math.cos(w.yaw), w.y + 3.0 * math.sin(w.yaw), w.yaw)
    rt.run(duration=0.15)
    assert not f.exploration.is_exploring()
    assert len(w.simple_goals) == n_goals  # the detection that cancelled sends no goal
    rt.run(duration=0.3)
    assert len(w.simple_goals) > n_goals
    assert len(w.action_goals) == len(yaws)


def test_no_move_base_action_server_to_explore_with_is_warned_about_and_a_remap_mends_it(
    caplog,
):
    """follow_marker explores through the absolute /move_base (the original's name). With the
    follower's move_base in a namespace there is no server there: the original blocks for ever
    in waitForServer(); here a goal nobody answers for 5 s is warned about, naming the remap,
    sent again, and the follower goes on following. With ``/move_base`` remapped to the
    namespace's move_base it explores."""
    for remap in (False, True):
        rt = Runtime(seed=0)
        w = FollowWorld(rt, action="/hank/move_base")
        params = {"marker_id": 0, "marker_to_target_pose": {"x": -0.8, "y": 0.0}}
        remaps = {"/move_base": "/hank/move_base"} if remap else None
        f = FollowMarker(rt, params=params, remaps=remaps)
        w.marker = (3.0, 0.0, 0.0)
        caplog.clear()
        with caplog.at_level("WARNING"):
            rt.run(duration=1.0)
            w.marker = None
            rt.run(duration=15.0)  # lost: exploration is due from 4 s on
        warned = [r.getMessage() for r in caplog.records if "cannot explore" in r.getMessage()]
        if remap:
            assert warned == [] and len(w.action_goals) >= 2 and f.exploration.goals_sent >= 2
        else:
            assert w.action_goals == [] and f.exploration.goals_sent >= 2  # sent again
            assert len(warned) == 1  # once per 10 s, not at every detection
            assert "no move_base action server answers at /move_base" in warned[0]
            assert "remap /move_base to move_base" in warned[0]
            w.marker = (w.x + 3.0, w.y, 0.0)  # seen again: it still follows
            n = len(w.simple_goals)
            rt.run(duration=0.5)
            assert len(w.simple_goals) > n


def test_markers_seen_but_never_ours_are_warned_about_once(caplog):
    """The camera sees marker 0 for 12 s but the follower was told marker_id 7 (a typo, or an
    id outside the detector's dictionary): it explores, as the original does, and says once
    which ids it does see. Following marker 0, nothing is said."""
    for marker_id, warned in ((7, 1), (0, 0)):
        rt = Runtime(seed=0)
        w = FollowWorld(rt)
        params = {"marker_id": marker_id, "marker_to_target_pose": {"x": -0.8, "y": 0.0}}
        FollowMarker(rt, params=params)
        w.marker = (3.0, 0.0, 0.0)  # fiducial 0
        caplog.clear()
        with caplog.at_level("WARNING"):
            rt.run(duration=14.0)
        said = [r.getMessage() for r in caplog.records if "seen only marker ids" in r.getMessage()]
        assert len(said) == warned, said
        if warned:
            assert (
                "following marker_id 7, but for 10 s the camera has seen only marker ids 0"
                in (said[0])
            )


def test_move_to_target_goes_to_the_vantage_pose_once():
    rt, w, f = world(MOVE_TO_TARGET)
    rt.run(duration=4.0)
    assert w.action_goals == []  # never seen, but image time has not passed 4 s yet
    rt.run(duration=0.15)
    ((x, y, yaw),) = w.action_goals
    assert (x, y) == (1.0, 0.0) and math.remainder(yaw - 3.1416, math.tau) == pytest.approx(0)
    rt.run(duration=10.0)
    assert (w.x, w.y) == pytest.approx((1.0, 0.0), abs=1e-6)
    assert len(w.action_goals) == 1  # there: it waits for the marker to come by
    assert not f.exploration.is_exploring()


@pytest.mark.parametrize("frame", ["map", "/map"])
def test_move_to_target_keeps_the_target_frame_as_given_in_a_namespaced_follower(frame):
    """The tutorial's target_pose ``frame_id: map`` in a follower with tf_prefix hank is the
    shared map, as grobot copies it; it had become hank/map, which no one publishes."""
    rt = Runtime(seed=0)
    rt.params.set("/hank/tf_prefix", "hank")
    exploration = {**MOVE_TO_TARGET, "target_pose": {**MOVE_TO_TARGET["target_pose"]}}
    exploration["target_pose"]["frame_id"] = frame
    f = FollowMarker(rt, namespace="/hank", params={"marker_id": 0, "exploration": exploration})
    assert f.base_frame == "hank/base_footprint"  # the prefix is there
    assert f.exploration.target_frame == "map"


def test_a_missing_robot_pose_is_said_after_tfs_patience_then_every_5_s(caplog):
    """Exploring with no map -> robot transform (a follower without its tf_prefix): the
    warning had come at every image, 51 times in 11 s."""
    import logging

    rt = Runtime(seed=0)
    FollowWorld(rt, (0.0, 0.0, 0.0))
    exploration = {**MOVE_TO_TARGET, "robot_frame": "nowhere"}
    FollowMarker(rt, params={"marker_id": 0, "exploration": exploration})
    with caplog.at_level(logging.WARNING):
        rt.run(duration=16.0)
    said = [r for r in caplog.records if "no robot pose in map" in r.getMessage()]
    assert 1 <= len(said) <= 3, [r.getMessage() for r in said]


def test_a_bad_exploration_parameter_names_the_line_it_was_set_at():
    """``<rosparam param="exploration">{strategy: spin}</rosparam>``: the error names the
    launch file's line of the rosparam, as every other parameter error does."""
    rt = Runtime(seed=0)
    rt.params.set(
        "/follow_marker/exploration",
        {"strategy": "spin", "robot_frame": "base_footprint"},
        origin="p13.launch:15",
    )
    with pytest.raises(ParameterError, match=r"got 'spin' \(set at p13.launch:15\)"):
        FollowMarker(rt, params={"marker_id": 0})


def test_clear_costmaps_every_5_s():
    rt, w, f = world()
    rt.run(duration=16.0)
    assert w.clears == pytest.approx([5.0, 10.0, 15.0])


@pytest.mark.parametrize(
    ("params", "match"),
    [
        (
            {"exploration": {"strategy": "spin"}},
            r"/follow_marker/exploration: parameter 'strategy'",
        ),
        (
            {"exploration": "rotate"},
            r"/follow_marker: parameter 'exploration' must be dict, got str",
        ),
        (
            {"marker_to_target_pose": {"x": "far"}},
            r"/follow_marker/marker_to_target_pose: parameter 'x' must be float",
        ),
        (
            {"exploration": {**MOVE_TO_TARGET, "target_pose": {"yaw": "west"}}},
            r"/follow_marker/exploration/target_pose: parameter 'yaw' must be float",
        ),
        ({"marker_id": -1}, r"parameter 'marker_id' = -1 is out of range"),
    ],
)
def test_bad_parameters_name_the_parameter(params, match):
    with pytest.raises(ParameterError, match=match):
        FollowMarker(Runtime(), params=params)


def test_a_glimpse_of_another_marker_while_exploring_is_no_wrong_marker_id(caplog):
    """The watch both followers share: one image of another robot's marker, then 12 s of
    images with none, is not a wrong marker_id (found in review); ten such images are."""
    from fleetsim.apps.follow_marker import OtherMarkersWatch
    from fleetsim.msgs import fiducial_msgs as fm

    def frame(*ids):
        return fm.FiducialTransformArray(
            transforms=[fm.FiducialTransform(fiducial_id=i) for i in ids]
        )

    for glimpses, warned in ((1, 0), (10, 1)):
        watch = OtherMarkersWatch(Node(Runtime(seed=0), "follower"), 7)
        caplog.clear()
        with caplog.at_level("WARNING"):
            for k in range(130):
                watch.saw(frame(0) if k < glimpses else frame(), 0.1 * k, ours=False)
        said = [r.getMessage() for r in caplog.records if "seen only marker ids" in r.getMessage()]
        assert len(said) == warned, (glimpses, said)
