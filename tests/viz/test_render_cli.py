"""`fleetsim render`: writes the file, one line of errors, non-zero exit on bad input."""

from __future__ import annotations

import typer
from typer.testing import CliRunner

from fleetsim.cli.render import register


def _app() -> typer.Typer:
    app = typer.Typer()
    register(app)

    @app.command()
    def other() -> None:  # a second command, so typer keeps `render` as a sub-command
        pass

    return app


def test_render_png_and_mp4(room_recording, tmp_path):
    path, _ = room_recording
    runner = CliRunner()
    r = runner.invoke(
        _app(), ["render", str(path), "-o", str(tmp_path / "a.png"), "--width", "200"]
    )
    assert r.exit_code == 0, r.output
    assert "a.png (1 frame, 200x160)" in r.output and (tmp_path / "a.png").stat().st_size > 1000
    args = ["render", str(path), "-o", str(tmp_path / "a.mp4"), "--fps", "2", "--width", "128"]
    r = runner.invoke(_app(), [*args, "--no-progress"])
    assert r.exit_code == 0, r.output
    assert "a.mp4 (9 frames, 128x102)" in r.output


def test_render_errors_are_one_line(tmp_path):
    bad = tmp_path / "x.mcap"
    bad.write_text("not a recording")
    r = CliRunner().invoke(_app(), ["render", str(bad), "-o", str(tmp_path / "x.png")])
    assert r.exit_code == 1
    assert r.output.strip().count("\n") == 0
    assert "error: " in r.output and "x.mcap is not an MCAP file" in r.output
