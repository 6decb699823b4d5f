"""`fleetsim bag info|play`: output like ros2 bag, one-line errors with a non-zero exit."""

from __future__ import annotations

from typer.testing import CliRunner

from fleetsim.cli.bag import app


def test_info(recording):
    r = CliRunner().invoke(app, ["info", str(recording)])
    assert r.exit_code == 0, r.output
    assert "Messages:          51" in r.output
    assert "Topic: /robot0/odom | Type: nav_msgs/msg/Odometry" in r.output


def test_play_in_process(recording):
    r = CliRunner().invoke(app, ["play", str(recording), "--rate", "50", "--no-bridge"])
    assert r.exit_code == 0, r.output
    assert "playing 51 messages (1.000 s of sim time)" in r.output
    assert "played 51 messages" in r.output


def test_errors(recording, tmp_path):
    cut = tmp_path / "cut.mcap"
    cut.write_bytes(recording.read_bytes()[:3000])
    r = CliRunner().invoke(app, ["info", str(cut)])
    assert r.exit_code == 1 and "cut.mcap is truncated after" in r.output
    assert r.output.strip().count("\n") == 0
    r = CliRunner().invoke(app, ["play", str(recording), "--rate", "0", "--no-bridge"])
    assert r.exit_code == 1 and "error: --rate must be > 0" in r.output
    r = CliRunner().invoke(app, ["play", str(recording), "--topics", "/x", "--no-bridge"])
    assert r.exit_code == 1 and "has no topic /x" in r.output
