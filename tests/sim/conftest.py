"""Shared fixtures of the simulator tests: small robots and worlds in fixtures/."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

#: the shared data folder beside the repository (../shared from its root)
SHARED = Path(__file__).resolve().parents[2].parent / "shared"

os.environ.setdefault("MUJOCO_GL", "egl")

FIXTURES = Path(__file__).parent / "fixtures"
BARN = Path(SHARED, "data/barn/world_3.world")
WILLOW = Path(SHARED, "data/maps/willow-full.yaml")


def unread(engine) -> None:
    """Mark every sensor of the engine's models unread, as a simulator node does for topics
    with no subscriber: for tests of physics alone (the hunter's four cameras, rendered and
    noised every frame, were ~80 % of such a test's time)."""
    for entry in engine.models.values():
        for p in entry.plugins:
            if hasattr(p, "wanted"):
                p.wanted = lambda: False


@pytest.fixture
def in_tmp_dir(tmp_path, monkeypatch):
    """Run the test in its own folder (where MuJoCo would write MUJOCO_LOG.TXT) and fail if
    MuJoCo wrote that log. Modules opt in: ``pytestmark = pytest.mark.usefixtures(...)``."""
    monkeypatch.chdir(tmp_path)
    yield
    assert not (tmp_path / "MUJOCO_LOG.TXT").exists()


@pytest.fixture(scope="session")
def diffbot():
    from fleetsim.description import load_robot

    return load_robot(FIXTURES / "diffbot.urdf")


@pytest.fixture(scope="session")
def skidbot():
    from fleetsim.description import load_robot

    return load_robot(FIXTURES / "skidbot.urdf")


def robot_text(name: str) -> str:
    return (FIXTURES / name).read_text()


def replace_plugin_param(text: str, old: str, new: str) -> str:
    assert old in text, old
    return text.replace(old, new)
