"""SDF visual materials: Gazebo/* names, OGRE scripts by model://, file:// and media URIs."""

from pathlib import Path

import numpy as np
from PIL import Image

from fleetsim.sim.sdf import load_sdf_model
from fleetsim.sim.sdf_materials import GAZEBO_MATERIALS

VISUAL = """<sdf version="1.6"><model name="wall"><static>true</static><link name="link">
  <visual name="v"><geometry><box><size>4 0.2 2</size></box></geometry>
  <material><script>{uris}<name>{name}</name></script></material></visual>
  </link></model></sdf>"""


def material(name, uris=""):
    (g,) = load_sdf_model(VISUAL.format(name=name, uris=uris)).links[0].geoms
    return g.rgba, g.texture


def test_gazebo_bricks_from_fleetsims_media_with_or_without_the_uri():
    bricks = str(GAZEBO_MATERIALS.parents[1] / "textures" / "bricks.png")
    uri = "<uri>file://media/materials/scripts/gazebo.material</uri>"
    assert material("Gazebo/Bricks", uri) == (None, bricks)  # as Gazebo's own models write it
    assert material("Gazebo/Bricks") == (None, bricks)  # Gazebo/* needs no uri in Gazebo
    assert material("Gazebo/Grey", uri) == ((0.7, 0.7, 0.7, 1.0), None)
    assert material("Gazebo/NoSuchThing") == (None, None)  # unknown: drawn in the default grey


def test_relative_file_uris_search_gazebo_resource_path_first(tmp_path, monkeypatch):
    scripts = tmp_path / "media/materials/scripts"
    scripts.mkdir(parents=True)
    (scripts / "gazebo.material").write_text(
        "material Gazebo/Bricks { technique { pass { texture_unit { texture mine.png } } } }"
    )
    Image.fromarray(np.zeros((4, 4, 3), np.uint8)).save(scripts / "mine.png")
    monkeypatch.setenv("GAZEBO_RESOURCE_PATH", str(tmp_path))
    _, texture = material(
        "Gazebo/Bricks", "<uri>file://media/materials/scripts/gazebo.material</uri>"
    )
    assert Path(texture) == scripts / "mine.png"
