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
    assert "results" in capsys.readouterr().err


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
    assert "is in an obstacle" in capsys.readouterr().err.replace("\n", " ")


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["launch", "no_such_scenario", "--duration", "1"], "neither a launch file nor"),
        (["launch", "pioneer_multi"], "give --duration S, --until-goals, or both"),
        (["launch", "pioneer_multi", "robot", "--duration", "1"], "not of the form name:=value"),
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
