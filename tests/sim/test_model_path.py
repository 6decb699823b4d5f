"""``model://`` URIs: the gazebo_model_path a package exports, as gazebo_ros's launch adds it."""

from pathlib import Path

import pytest

from fleetsim.errors import SimulationError
from fleetsim.sim import sdf

BOX_MODEL = """<?xml version="1.0"?>
<sdf version="1.6"><model name="crate"><static>true</static>
  <link name="l"><collision name="c"><geometry><box><size>1 1 1</size></box></geometry>
  </collision></link></model></sdf>
"""
WORLD = """<?xml version="1.0"?>
<sdf version="1.6"><world name="default">
  <include><uri>model://crate</uri><pose>2 3 0.5 0 0 0</pose></include>
</world></sdf>
"""


def _package(root: Path, export: bool) -> Path:
    pkg = root / "my_worlds"
    (pkg / "models" / "crate").mkdir(parents=True)
    (pkg / "worlds").mkdir()
    exp = '<export><gazebo_ros gazebo_model_path="${prefix}/models"/></export>' if export else ""
    (pkg / "package.xml").write_text(
        f'<?xml version="1.0"?><package format="2"><name>my_worlds</name>{exp}</package>'
    )
    (pkg / "models" / "crate" / "model.sdf").write_text(BOX_MODEL)
    (pkg / "worlds" / "crate.world").write_text(WORLD)
    return pkg


def test_a_package_export_puts_its_models_on_the_path(tmp_path, monkeypatch):
    monkeypatch.delenv("GAZEBO_MODEL_PATH", raising=False)
    monkeypatch.delenv("FLEETSIM_MODEL_PATH", raising=False)
    pkg = _package(tmp_path, export=True)
    world = sdf.load_sdf_world(pkg / "worlds" / "crate.world")
    crate = next(m for m in world.models if m.name == "crate")
    assert crate.pose[:3] == (2.0, 3.0, 0.5)
    # outside the world file's reading, the package's export is not in force
    assert pkg / "models" not in sdf.model_path()


def test_a_package_on_the_package_path_exports_too(tmp_path, monkeypatch):
    monkeypatch.delenv("GAZEBO_MODEL_PATH", raising=False)
    pkg = _package(tmp_path / "ws", export=True)
    monkeypatch.setenv("ROS_PACKAGE_PATH", str(tmp_path / "ws"))
    assert pkg / "models" in sdf.model_path()


def test_without_the_export_the_error_says_how_to_add_it(tmp_path, monkeypatch):
    monkeypatch.delenv("GAZEBO_MODEL_PATH", raising=False)
    monkeypatch.delenv("FLEETSIM_MODEL_PATH", raising=False)
    monkeypatch.delenv("ROS_PACKAGE_PATH", raising=False)
    pkg = _package(tmp_path, export=False)
    with pytest.raises(SimulationError, match=r"model://crate not found.*gazebo_model_path"):
        sdf.load_sdf_world(pkg / "worlds" / "crate.world")
