"""`fleetsim launch`: listing, exit status with --until-goals, clear errors."""

import re
from pathlib import Path

import pytest

from fleetsim.cli.main import main


def test_list_shows_the_shipped_scenarios(capsys):
    assert main(["launch", "--list"]) == 0
    out = capsys.readouterr().out
    for name in ("navigation_multi", "pioneer_multi", "hunter_run", "barn"):
        assert name in out


@pytest.mark.scenario
def test_until_goals_exits_zero_when_every_goal_is_reached(capsys):
    code = main(["launch", "pioneer_multi", "--until-goals", "--duration", "90", "--no-bridge"])
    assert code == 0
    err = capsys.readouterr().err
    assert "results" in err
    # captured, as piped: the table is not wrapped to 80 columns (its headers on one line)
    header = next(line for line in err.splitlines() if "goals reached" in line)
    assert "to goal [m] (truth)" in header and "last status" in header


@pytest.mark.scenario
def test_until_goals_exits_nonzero_when_a_goal_fails(tmp_path: Path, capsys):
    top = tmp_path / "bad_goal.launch"
    top.write_text(
        "<launch>\n"
        '  <include file="$(find fleetsim_launch)/pioneer_multi.launch"/>\n'
        '  <rosparam ns="send_goals">goals: {pioneer1: [[25.8, 15.8, 0.0]]}</rosparam>\n'
        "</launch>\n"
    )
    code = main(["launch", str(top), "--until-goals", "--duration", "90", "--no-bridge"])
    assert code == 1
    err = capsys.readouterr().err
    assert "is in an obstacle" in err.replace("\n", " ")
    # the exit status comes with its reasons
    assert "--until-goals: exit status 1:\n  /pioneer1: 0/1 goals reached; 1 failed\n" in err


def test_until_goals_with_no_goal_at_all_says_so(tmp_path: Path, capsys):
    quiet = tmp_path / "no_goals.launch"
    quiet.write_text(
        "<launch>\n"
        '  <node pkg="map_server" type="map_server" name="map_server"\n'
        '        args="$(find fleetsim_maps)/office.yaml"/>\n'
        "</launch>\n"
    )
    code = main(["launch", str(quiet), "--until-goals", "--duration", "1", "--no-bridge"])
    assert code == 1
    err = capsys.readouterr().err
    assert "--until-goals: exit status 1:\n  no goal was sent (no move_base goal, no goal " in err


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["launch", "no_such_scenario", "--duration", "1"], "neither a launch file nor"),
        (["launch", "pioneer_multi"], "give --duration S, --until-goals, or both"),
        (["launch", "pioneer_multi", "robot", "--duration", "1"], "not of the form name:=value"),
        (
            ["launch", "visual_servoing", "--until-goals", "--no-bridge"],
            r"--until-goals without --duration: /follow_marker is a follower",
        ),
        (
            ["launch", "robocluedo_robot_hunter", "run3.launch", "--duration", "1"],
            r"package 'robocluedo_robot_hunter' \(.*\) has no launch file 'run3.launch'; it has "
            r".*run2.launch",
        ),
        (["launch", "pioneer_multi", "nope:=1", "--duration", "1"], r"unused args \['nope'\]"),
        (
            ["launch", "pioneer_multi", "--connect", "tcp/127.0.0.1:9", "--realtime"],
            "--realtime has no effect with --connect",
        ),
        (
            ["launch", "pioneer_multi", "--connect", "tcp/127.0.0.1:9"],
            r"no simulation running at tcp/127.0.0.1:9",
        ),
    ],
)
def test_bad_invocations_are_one_line_errors(argv, message, capsys):
    assert main(argv) == 1
    err = capsys.readouterr().err
    assert re.search(message, err.replace("\n", " ")), err


def test_until_goals_fails_when_ground_truth_contradicts_a_reported_success(
    tmp_path, capsys, monkeypatch
):
    from fleetsim.cli import launch as launch_cli

    monkeypatch.setattr(launch_cli.console, "width", 200)  # one line per table row
    robot = Path(__file__).resolve().parents[1] / "sim" / "fixtures" / "diffbot.urdf"
    launch = tmp_path / "liar.launch"
    launch.write_text(
        f"""<launch>
  <include file="$(find gazebo_ros)/launch/empty_world.launch">
    <arg name="gui" value="false"/>
  </include>
  <group ns="r1">
    <param name="robot_description" textfile="{robot}"/>
    <node name="spawn" pkg="gazebo_ros" type="spawn_model"
          args="-urdf -param robot_description -model r1"/>
    <node name="move_base" pkg="test" type="lying_move_base:LyingMoveBase"/>
  </group>
</launch>
"""
    )
    code = main(["launch", str(launch), "--until-goals", "--duration", "5", "--no-bridge"])
    err = capsys.readouterr().err
    assert code == 1
    row = next(line for line in err.splitlines() if line.startswith("│ /r1 "))
    cells = [c.strip() for c in row.split("│") if c.strip()]
    assert cells[1] == "0/1"  # goals reached / sent
    assert cells[5] == "22.00"  # to goal [m] (truth): the robot never moved
    assert cells[-1] == "reported reached, 22.0 m away by ground truth"


def test_launch_help_says_where_until_goals_gets_its_goals(capsys):
    main(["launch", "--help"])
    text = " ".join(capsys.readouterr().out.replace("│", " ").split())
    for words in ("move_base action goals", "send_goals nodes", "'fleetsim goal'", "user nodes"):
        assert words in text, words


def test_roslaunchs_package_file_form(capsys):
    """``fleetsim launch robocluedo_robot_hunter run2.launch sim_type:=rviz``, as roslaunch."""
    argv = ["launch", "robocluedo_robot_hunter", "run2.launch", "sim_type:=rviz"]
    assert main([*argv, "--duration", "0.2", "--no-bridge"]) == 0, capsys.readouterr().err
