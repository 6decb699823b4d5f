"""Running plans: nodes in namespaces with tf_prefix, viewers skipped, clear failures."""

import logging
from pathlib import Path

import pytest

from fleetsim.errors import LaunchError
from fleetsim.launch.runner import LaunchSession, load_plan

ROBOTS = """<launch>
  <node pkg="rviz" type="rviz" name="rviz"/>
  <group ns="lizi1">
    <param name="tf_prefix" value="lizi1"/>
    <node pkg="tf" type="static_transform_publisher" name="laser"
          args="0.1 0 0.2 0 0 0 base_link laser_link 100"/>
  </group>
  <group ns="lizi2">
    <param name="tf_prefix" value="lizi2"/>
    <node pkg="tf2_ros" type="static_transform_publisher" name="laser"
          args="0.3 0 0.2 0 0 0 base_link laser_link"/>
  </group>
</launch>
"""


def test_group_ns_and_tf_prefix_give_prefixed_frames(tmp_path: Path):
    f = tmp_path / "robots.launch"
    f.write_text(ROBOTS)
    with LaunchSession(load_plan(f)) as s:
        buf = s.runtime.tf_buffer  # a listener hears what is published after it starts
        s.runtime.run(duration=0.5)
        assert {"lizi1/base_link", "lizi1/laser_link", "lizi2/laser_link"} <= set(buf.all_frames())
        t = buf.lookup_transform("lizi2/base_link", "lizi2/laser_link", 0.0)
        assert t.transform.translation.x == pytest.approx(0.3)
        assert s.skipped == ["/rviz"]
        assert sorted(s.nodes) == ["/lizi1/laser", "/lizi2/laser"]


def test_unknown_node_fails_with_file_and_line(tmp_path: Path):
    f = tmp_path / "bad.launch"
    f.write_text('<launch>\n<node pkg="tf" type="no_such" name="x"/>\n</launch>')
    with pytest.raises(LaunchError, match=r"bad.launch:2 <node>: node tf/no_such is unknown"):
        LaunchSession(load_plan(f))


def test_node_errors_name_the_node(tmp_path: Path):
    f = tmp_path / "bad.launch"
    f.write_text(
        '<launch>\n<node pkg="tf" type="static_transform_publisher" name="x" args="1 2"/>\n'
        "</launch>"
    )
    with pytest.raises(LaunchError, match=r"bad.launch:2 <node>: node /x failed to start"):
        LaunchSession(load_plan(f))


def test_a_node_twice_in_one_namespace_names_the_include_that_repeats_it(tmp_path: Path):
    """The lesson's robot file included twice with the same ns (a copy-paste slip): the error
    names the node's line and the <include> that brought the second copy, as two includes of
    one file are two places."""
    (tmp_path / "one.launch").write_text(
        '<launch>\n<node pkg="tf" type="static_transform_publisher" name="laser" '
        'args="0 0 0 0 0 0 base_link laser_link"/>\n</launch>'
    )
    f = tmp_path / "robots.launch"
    f.write_text(
        '<launch>\n<include file="$(dirname)/one.launch" ns="lizi1"/>\n'
        '<include file="$(dirname)/one.launch" ns="lizi2"/>\n'
        '<include file="$(dirname)/one.launch" ns="lizi1"/>\n</launch>'
    )
    with pytest.raises(
        LaunchError,
        match=rf"one.launch:2 <node> \(included from {f}:4 <include>\): node /lizi1/laser "
        r"failed to start: a node named /lizi1/laser already exists",
    ):
        LaunchSession(load_plan(f))


def test_missing_file():
    with pytest.raises(LaunchError, match="does not exist"):
        load_plan("/nope/x.launch")


def test_the_error_that_ended_a_run_is_not_hidden_by_shutdown_errors(tmp_path: Path, caplog):
    f = tmp_path / "robots.launch"
    f.write_text(ROBOTS)

    def broken_hook():
        raise RuntimeError("hook broke")

    with (
        pytest.raises(LaunchError, match="the run's own error"),
        LaunchSession(load_plan(f)) as s,
    ):
        s.runtime.on_shutdown(broken_hook)
        raise LaunchError("the run's own error")
    assert "while shutting down after 'the run's own error': hook broke" in caplog.text


def test_a_launch_file_that_starts_no_node_is_warned_about(tmp_path, caplog):
    """The manual's own run2.launch with a misspelt sim_type (no <choice> there): every group
    is skipped, and roslaunch runs on without a word."""
    f = tmp_path / "nothing.launch"
    f.write_text(
        '<launch><arg name="sim_type" default="gazbo"/>'
        "<group if=\"$(eval sim_type == 'gazebo')\">"
        '<node pkg="gazebo_ros" type="gzserver" name="gazebo"/></group></launch>'
    )
    with caplog.at_level(logging.WARNING), LaunchSession(load_plan(f), seed=1) as session:
        assert session.nodes == {}
    assert "the launch file starts no node and sets no parameter" in caplog.text
