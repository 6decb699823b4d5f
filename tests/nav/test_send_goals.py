"""SendGoals: goals from parameters, in order per robot, outcomes and results table."""

import logging

import pytest
from fake_move_base import FakeMoveBase

from fleetsim.errors import ParameterError
from fleetsim.nav.send_goals import SendGoals, goals_from_param
from fleetsim.runtime import Runtime


@pytest.fixture
def rt():
    r = Runtime(seed=0)
    yield r
    r.shutdown()


def test_two_robots_in_order_with_an_abort(rt, caplog):
    a = FakeMoveBase(rt, "/lizi1", start=(0.0, 0.0))
    b = FakeMoveBase(rt, "/lizi2", start=(5.0, 0.0))
    rt.params.set(
        "/send_goals",
        {
            "goals": {
                "lizi1": [[1.0, 0.0, 0.0], [-2.0, 0.0], [1.0, 1.0, 1.57]],
                "/lizi2": [[5, 2]],
            },
            "start_delay": 1.0,
        },
    )
    caplog.set_level(logging.INFO, logger="fleetsim.node")
    sg = SendGoals(rt)
    rt.run(duration=0.95)
    assert a.goals == [] and b.goals == []  # start_delay
    rt.run(until=lambda: sg.done, duration=30.0)
    assert sg.done and rt.now() < 6.0
    assert a.goals == [(1.0, 0.0), (-2.0, 0.0), (1.0, 1.0)] and b.goals == [(5.0, 2.0)]
    r1 = sg.results["/lizi1"]
    assert [o.reached for o in r1] == [True, False, True]
    assert r1[1].status == "ABORTED" and "off the map" in r1[1].text
    assert r1[0].duration == pytest.approx(1.0, abs=0.21) and r1[0].sent_at >= 1.0
    table = sg.results_table()
    assert [(row["robot"], row["goal"], row["reached"]) for row in table] == [
        ("lizi1", 1, True), ("lizi1", 2, False), ("lizi1", 3, True), ("lizi2", 1, True),
    ]  # fmt: skip
    assert table[3]["time_s"] == pytest.approx(2.0, abs=0.21)
    assert "/lizi1: goal 2/3 ABORTED" in caplog.text and "/lizi2: goal 1/1 reached" in caplog.text


def test_list_form_frame_and_loop(rt):
    a = FakeMoveBase(rt, "/lizi1", start=(0.0, 0.0), speed=5.0)
    seen = []
    a.server.goal_callback = lambda: (
        seen.append(a.server.next.goal.target_pose.header.frame_id),
        FakeMoveBase.on_goal(a),
    )
    rt.params.set(
        "/send_goals",
        {
            "goals": [
                {"ns": "lizi1", "x": 1.0, "y": 0.0},
                {"ns": "lizi1", "x": 0, "y": 0, "yaw": 1},
            ],
            "frame_id": "world",
            "loop": True,
        },
    )
    sg = SendGoals(rt)
    rt.run(duration=3.0)
    assert not sg.done
    assert len(sg.results["/lizi1"]) >= 4 and all(o.reached for o in sg.results["/lizi1"])
    assert a.goals[:4] == [(1.0, 0.0), (0.0, 0.0), (1.0, 0.0), (0.0, 0.0)]
    assert set(seen) == {"world"}


def test_waits_for_a_missing_server(rt, caplog):
    rt.params.set("/send_goals/goals", {"lizi3": [[1.0, 0.0]]})
    sg = SendGoals(rt)
    rt.run(duration=1.0)
    assert "waiting for the action server /lizi3/move_base" in caplog.text
    FakeMoveBase(rt, "/lizi3")
    rt.run(until=lambda: sg.done, duration=5.0)
    assert sg.done and sg.results["/lizi3"][0].reached


@pytest.mark.parametrize(
    ("value", "match"),
    [
        ({"lizi1": [[1.0]]}, r"goals\['lizi1'\]\[0\] must be \[x, y\] or \[x, y, yaw\]"),
        ({"lizi1": [[1.0, "a"]]}, r"goals\['lizi1'\]\[0\] y must be a finite number"),
        ({"lizi1": 3}, r"goals\['lizi1'\] must be a list"),
        ([{"ns": "lizi1", "x": 1}], r"goals\[0\] must be a mapping with ns, x, y"),
        ([{"ns": "lizi1", "x": 1, "y": 2, "z": 0}], r"unknown keys \['z'\]"),
        ([{"ns": "", "x": 1, "y": 2}], r"robot namespace must be a name"),
        ("lizi1", r"must be a mapping or a list"),
    ],
)
def test_bad_goals_name_the_entry(value, match):
    with pytest.raises(ParameterError, match=match):
        goals_from_param(value)


def test_bad_param_at_node_creation(rt):
    rt.params.set("/send_goals/goals", {"lizi1": [[1.0, float("nan"), 0.0]]})
    with pytest.raises(ParameterError, match=r"/send_goals/goals\['lizi1'\]\[0\] y must be"):
        SendGoals(rt)
    rt.params.set("/sg2/start_delay", -1.0)
    with pytest.raises(ParameterError, match="start_delay"):
        SendGoals(rt, "sg2")
