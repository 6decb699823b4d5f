"""Tests for the `fleetsim urdf` sub-app (check, graph, export) through typer's CliRunner."""

from __future__ import annotations

import pytest
from typer.testing import CliRunner

from fleetsim.cli.urdf import app
from fleetsim.description.packages import ASSET_ROBOTS
from fleetsim.description.urdf import load_robot

ROBOTS = ["hunter", "lizi", "pioneer3at", "turtlebot3_burger", "turtlebot3_waffle", "jackal"]
runner = CliRunner()


def top(name):
    return str(ASSET_ROBOTS / name / "urdf" / f"{name}.urdf.xacro")


@pytest.mark.parametrize("name", ROBOTS)
def test_every_model_checks_and_converts_to_pdf(name, tmp_path):
    res = runner.invoke(app, ["check", top(name)])
    assert res.exit_code == 0, res.output
    assert res.output.splitlines()[1] == "---------- Successfully Parsed XML ---------------"
    res = runner.invoke(app, ["graph", top(name), "-o", str(tmp_path)])
    assert res.exit_code == 0, res.output
    robot_name = load_robot(top(name)).name
    assert (tmp_path / f"{robot_name}.gv").read_text().startswith("digraph G {")
    assert (tmp_path / f"{robot_name}.pdf").read_bytes().startswith(b"%PDF")
    assert f"Created file {tmp_path / (robot_name + '.pdf')}" in res.output


def test_check_hunter_root_and_children():
    res = runner.invoke(app, ["check", top("hunter")])
    assert "root Link: base_link has 9 child(ren)" in res.output


def test_check_with_xacro_args(tmp_path):
    f = tmp_path / "a.urdf.xacro"
    f.write_text(
        '<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">'
        '<xacro:arg name="n" default="x"/><link name="$(arg n)"/></robot>'
    )
    res = runner.invoke(app, ["check", str(f), "n:=base_link"])
    assert res.exit_code == 0 and "root Link: base_link has 0 child(ren)" in res.output
    res = runner.invoke(app, ["check", str(f), "n=base_link"])
    assert res.exit_code == 1 and "'n=base_link' is not of the form name:=value" in res.output


def test_check_invalid_model_exits_nonzero_with_file_and_line(tmp_path):
    f = tmp_path / "bad.urdf"
    f.write_text(
        '<robot name="r">\n<link name="a"/>\n'
        '<joint name="j" type="fixed"><parent link="a"/><child link="b"/></joint>\n</robot>'
    )
    res = runner.invoke(app, ["check", str(f)])
    assert res.exit_code == 1
    assert f"{f}:3: joint 'j' names child link 'b', which is not defined" in res.output


def test_export_writes_plain_urdf(tmp_path):
    out = tmp_path / "lizi.urdf"
    res = runner.invoke(app, ["export", top("lizi"), "-o", str(out)])
    assert res.exit_code == 0, res.output
    text = out.read_text()
    assert "xacro" not in text and "libgazebo_ros_skid_steer_drive.so" in text
    again = load_robot(out)
    assert again.joints == load_robot(top("lizi")).joints
    res = runner.invoke(app, ["export", top("lizi")])
    assert res.output.startswith('<?xml version="1.0"')
