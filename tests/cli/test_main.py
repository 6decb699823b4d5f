"""The `fleetsim` entry point: help, version, one-line errors."""

import logging
import subprocess
import sys

from fleetsim import __version__
from fleetsim.cli.main import main


def test_version(capsys):
    assert main(["--version"]) == 0
    assert capsys.readouterr().out.strip() == f"fleetsim {__version__}"


def test_help_lists_commands(capsys):
    assert main(["--help"]) == 0
    out = capsys.readouterr().out
    assert "Usage" in out and "demo" in out


def test_unknown_command_is_a_usage_error(capsys):
    assert main(["no-such-command"]) == 2
    assert "No such command" in capsys.readouterr().err


def test_console_script_prints_errors_without_traceback(tmp_path):
    # A FleetsimError surfaces as one line on stderr, exit status 1, no traceback.
    code = (
        "import sys\n"
        "from fleetsim.cli import main as m\n"
        "from fleetsim.errors import FleetsimError\n"
        "@m.app.command('boom')\n"
        "def boom():\n"
        "    raise FleetsimError('bad thing in x.yaml:3')\n"
        "sys.exit(m.main(['boom']))\n"
    )
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=False)
    assert r.returncode == 1
    assert "error: bad thing in x.yaml:3" in r.stderr
    assert "Traceback" not in r.stderr


def test_other_libraries_info_lines_show_only_with_verbose(tmp_path):
    argv = ["batch", "no_such_scenario", "-o", str(tmp_path / "out")]  # fails before any run
    assert main(argv) == 1
    opengl = logging.getLogger("OpenGL")
    assert not opengl.isEnabledFor(logging.INFO) and opengl.isEnabledFor(logging.WARNING)
    assert logging.getLogger("fleetsim").isEnabledFor(logging.INFO)
    try:
        assert main(["-v", *argv]) == 1
        assert opengl.isEnabledFor(logging.DEBUG)
    finally:
        # quiet again: a worker left at DEBUG would log every numba compile step after this
        assert main(argv) == 1
    assert not logging.getLogger("numba").isEnabledFor(logging.INFO)
