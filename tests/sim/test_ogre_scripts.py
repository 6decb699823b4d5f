"""OGRE material scripts: blocks, textures, colours, inheritance and errors with file:line."""

import pytest

from fleetsim.errors import SimulationError
from fleetsim.sim.ogre_scripts import materials_of_script, parse_ogre_script

SCRIPT = """// a comment { with a brace
material Base
{
  technique
  {
    pass
    {
      diffuse 0.2 0.4 0.6 1.0
      texture_unit
      {
        texture base.png
        filtering anisotropic
      }
    }
  }
}
material Child : Base
{
  technique { pass { diffuse 1 0 0 } }
}
material Plain { technique { pass { ambient 1 1 1 } } }
"""


def test_ogre_script_blocks_textures_colours_and_inheritance(tmp_path):
    mats = materials_of_script(SCRIPT, tmp_path / "a.material")
    assert set(mats) == {"Base", "Child", "Plain"}
    assert mats["Base"].texture == "base.png" and mats["Base"].diffuse == (0.2, 0.4, 0.6, 1.0)
    assert mats["Base"].line == 2
    assert mats["Child"].texture == "base.png" and mats["Child"].diffuse == (1.0, 0.0, 0.0, 1.0)
    assert mats["Plain"].texture is None and mats["Plain"].diffuse is None


def test_ogre_script_errors_name_file_and_line(tmp_path):
    with pytest.raises(SimulationError, match=r"b.material:1: block 'material M' is never closed"):
        parse_ogre_script("material M\n{\n pass {\n}\n", tmp_path / "b.material")
    with pytest.raises(SimulationError, match=r"c.material:2: '\}' closes no block"):
        parse_ogre_script("material M {}\n}\n", tmp_path / "c.material")
    with pytest.raises(SimulationError, match=r"d.material:1: 'diffuse' needs numbers"):
        materials_of_script(
            "material M { technique { pass { diffuse a b c } } }", tmp_path / "d.material"
        )
