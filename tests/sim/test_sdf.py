import numpy as np
import pytest

from fleetsim.errors import SimulationError
from fleetsim.sim.sdf import load_sdf_model, load_sdf_world

from .conftest import BARN

WORLD = """<?xml version="1.0"?>
<sdf version="1.6">
  <world name="w">
    <include><uri>model://ground_plane</uri></include>
    <include><uri>model://sun</uri></include>
    <gravity>0 0 -9.81</gravity>
    <plugin name="attacher" filename="libgazebo_ros_link_attacher.so"/>
    <include><uri>model://crate</uri><name>crate_a</name><pose>1 2 0 0 0 1.57</pose></include>
    <model name="post">
      <static>true</static>
      <pose>3 0 0 0 0 0</pose>
      <link name="link">
        <collision name="c"><geometry><cylinder><radius>0.2</radius><length>2</length>
        </cylinder></geometry></collision>
        <visual name="v"><geometry><cylinder><radius>0.2</radius><length>2</length>
        </cylinder></geometry><material><script><name>Gazebo/Red</name></script></material>
        </visual>
      </link>
    </model>
  </world>
</sdf>
"""

CRATE = """<?xml version="1.0"?>
<sdf version="1.6"><model name="crate"><link name="body">
  <inertial><mass>2.0</mass></inertial>
  <collision name="c"><geometry><box><size>0.4 0.4 0.4</size></box></geometry></collision>
  <visual name="v"><geometry><box><size>0.4 0.4 0.4</size></box></geometry>
    <material><script><uri>model://crate/materials/scripts</uri>
    <uri>model://crate/materials/textures</uri><name>Crate/Face</name></script></material>
  </visual></link></model></sdf>
"""


@pytest.fixture
def model_dir(tmp_path, monkeypatch):
    crate = tmp_path / "models" / "crate"
    (crate / "materials" / "scripts").mkdir(parents=True)
    (crate / "materials" / "textures").mkdir(parents=True)
    (crate / "model.config").write_text("<model><name>crate</name><sdf>model.sdf</sdf></model>")
    (crate / "model.sdf").write_text(CRATE)
    (crate / "materials" / "scripts" / "crate.material").write_text(
        "material Crate/Face\n{\n  technique\n  {\n    pass\n    {\n      texture_unit\n"
        "      {\n        texture face.png\n      }\n    }\n  }\n}\n"
    )
    from PIL import Image

    Image.fromarray(np.zeros((8, 8, 3), np.uint8)).save(crate / "materials/textures/face.png")
    monkeypatch.setenv("GAZEBO_MODEL_PATH", str(tmp_path / "models"))
    (tmp_path / "w.world").write_text(WORLD)
    return tmp_path


def test_world_with_includes_and_textures(model_dir):
    w = load_sdf_world(model_dir / "w.world")
    assert [m.name for m in w.models] == ["ground_plane", "crate_a", "post"]
    assert [lt.name for lt in w.lights] == ["sun"]
    assert w.gravity == (0.0, 0.0, -9.81)
    assert w.plugins[0].filename == "libgazebo_ros_link_attacher.so"
    crate = w.models[1]
    assert crate.pose == (1, 2, 0, 0, 0, 1.57) and not crate.static
    vis = next(g for g in crate.links[0].geoms if not g.collide)
    assert vis.texture.endswith("face.png")
    post = w.models[2]
    assert post.static and [g.rgba for g in post.links[0].geoms][1] == (1.0, 0.0, 0.0, 1.0)


def test_barn_world_loads_as_it_is():
    w = load_sdf_world(BARN)
    cyl = [m for m in w.models if m.name.startswith("unit_cylinder")]
    assert len(cyl) > 100 and all(m.static for m in cyl)
    g = cyl[1].links[0].geoms[0]
    assert g.kind == "cylinder" and g.size == (0.075, 1.0)
    assert cyl[1].pose[:2] == (-0.225, 0.075)


def test_errors_name_file_and_line(tmp_path, monkeypatch):
    monkeypatch.setenv("GAZEBO_MODEL_PATH", str(tmp_path))
    bad = tmp_path / "bad.world"
    bad.write_text("<sdf>\n<world name='x'>\n<model name='m'>\n</world></sdf>")
    with pytest.raises(SimulationError, match=r"bad.world:4: SDF does not parse"):
        load_sdf_world(bad)
    missing = tmp_path / "missing.world"
    missing.write_text(
        "<sdf><world name='x'>\n<include><uri>model://nope</uri></include></world></sdf>"
    )
    with pytest.raises(SimulationError, match=r"missing.world:2: model://nope not found"):
        load_sdf_world(missing)
    pose = tmp_path / "pose.world"
    pose.write_text("<sdf><world name='x'>\n<model name='m'><pose>1 2</pose></model></world></sdf>")
    with pytest.raises(SimulationError, match=r"pose.world:2: <pose> needs 6 numbers"):
        load_sdf_world(pose)
    with pytest.raises(SimulationError, match=r"<string>:1: SDF does not parse"):
        load_sdf_model("<sdf><model name='x'>")
