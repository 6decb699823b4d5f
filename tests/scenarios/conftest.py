"""Fixtures shared by scenario tests."""

import logging

import pytest


@pytest.fixture
def quiet_run(tmp_path, monkeypatch, caplog):
    """Run in a folder of its own and fail on any WARNING (or worse) log record, or on a
    ``MUJOCO_LOG.TXT`` there. Modules opt in: ``pytest.mark.usefixtures("quiet_run")``."""
    monkeypatch.chdir(tmp_path)  # where MuJoCo would write MUJOCO_LOG.TXT
    caplog.set_level(logging.INFO)
    yield
    noise = [f"{r.name}: {r.getMessage()}" for r in caplog.records if r.levelno >= logging.WARNING]
    assert noise == []
    assert not (tmp_path / "MUJOCO_LOG.TXT").exists()
